"""Run a scenario end to end: dataset (cached) -> signal chain -> identify -> score.

The identifier is given only the :class:`~testbed.core.measurement.Measurement` of the
measured signals; scoring alone opens the truth.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, replace
from typing import Any

from testbed.core.dataset import Dataset
from testbed.core.errors import IdentificationError, ScenarioError
from testbed.core.measurement import Measurement
from testbed.pipeline import plugins
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.fit import fit_or_fail
from testbed.pipeline.generate import generate
from testbed.pipeline.scenario import Scenario
from testbed.pipeline.signal_chain import measure
from testbed.scoring.scorers import (
    PASS,
    Check,
    Scores,
    bar_failures,
    check_thresholds,
    failed_scores,
    record_details,
    score,
    verdict,
)


@dataclass
class RunResult:
    """Everything one scenario run produced.

    Attributes
    ----------
    scores : Scores
        Its ``failures`` say why the model fails whatever its scores (fit failed, diverged,
        non-physical); empty for a model that was scored normally.
    checks : list of Check
        The scenario's ``[score]`` thresholds against the scores; empty if it declares none.
    fit_time : float
        Wall time of the fit [s] (up to the failure for a failed fit).
    """

    scenario: Scenario
    dataset: Dataset
    data: Measurement
    model: Any
    scores: Scores
    checks: list[Check]
    fit_time: float

    @property
    def failure(self) -> str | None:
        """Why the model failed whatever its scores (one line), or None."""
        return self.scores.failure

    @property
    def verdict(self) -> str:
        """:data:`~testbed.scoring.scorers.PASS`, ``FAIL`` or ``NO_VERDICT`` (no thresholds declared)."""
        return verdict(self.checks, self.scores.failures)

    @property
    def passed(self) -> bool:
        """True only when thresholds were declared, all are met, and nothing failed."""
        return self.verdict == PASS


def noise_free(dataset: Dataset) -> Dataset:
    """The dataset with every measured signal replaced by its noise-free reference."""
    measured = {k: dataset.reference.get(k, s) for k, s in dataset.measured.items()}
    return replace(dataset, measured=measured)


def make_identifier(scenario: Scenario) -> Any:
    """A fresh identifier of the scenario's ``[identify]`` table."""
    return plugins.make_identifier(scenario.identify, scenario.name)


@contextlib.contextmanager
def no_phase(name: str) -> Iterator[Callable[..., None]]:
    """The silent ``phase`` of :func:`run_scenario`: yields an ``update`` that does nothing."""
    yield lambda fraction=None, step=None: None


def run_scenario(scenario: Scenario, *, cache: DatasetCache | None = None,
                 dataset: Dataset | None = None, model: Any = None,
                 progress: Callable[[float], None] | None = None,
                 phase: Callable[[str], Any] | None = None) -> RunResult:
    """Generate (or reuse) the data, identify, and score against the truth.

    Parameters
    ----------
    scenario : Scenario
    cache : DatasetCache, optional
        Reuse / store the dataset there; without it the data are generated afresh.
    dataset : Dataset, optional
        Use these data instead (must belong to ``scenario``).
    model : Identifier, optional
        Use this (unfitted) identifier instead of the scenario's ``[identify]``.
    progress : callable, optional
        ``progress(fraction)`` of the simulation done (with ``phase``, both are called).
    phase : callable, optional
        ``phase(name)`` returns a context manager around each phase ("simulate", "signal
        chain", "fit", "score") that yields ``update(fraction=None, step=None)``: the
        simulation reports its fraction done, the fit the steps its identifier reports
        (:meth:`identify.Identifier.report_progress`); the reporting layer's
        :func:`testbed.reporting.progress.run_progress` draws them.

    Returns
    -------
    RunResult
        Always scored: a fit that raises :class:`~testbed.core.errors.IdentificationError` ("fit
        failed: <reason>", every score NaN), a model that diverges, blows up, loses its loop
        closure or is physically impossible are failures in ``result.scores.failures``, and
        ``result.passed`` is False.  ``result.passed`` is also False without thresholds
        (``result.verdict`` is then "no verdict").

    Raises
    ------
    ScenarioError
        A configuration error of the user's (never scored).
    """

    phase = phase or no_phase
    if dataset is None:
        with phase("simulate") as update:
            def simulated(fraction: float) -> None:
                update(fraction)
                if progress is not None:
                    progress(fraction)

            dataset = cache.get(scenario, simulated) if cache is not None \
                else generate(scenario, simulated)
    kind = scenario.kind
    with phase("signal chain"):
        data = measure(dataset, scenario.signal, kind)
        clean = measure(noise_free(dataset), scenario.signal, kind)
    model = model if model is not None else make_identifier(scenario)
    with phase("fit") as update:
        t0 = time.perf_counter()
        try:
            with _reporting(model, update):
                fit_or_fail(model, data, scenario.identify.get("method"))
        except ScenarioError:  # the user's configuration: raised, not scored
            raise
        except IdentificationError as e:  # data the identifier cannot handle: a scored failure
            scores = failed_scores(kind, f"fit failed: {e}")
            scores.details.update(record_details(kind, dataset, data))
            scores.failures.update(bar_failures(scores, scenario.score))  # a mode out of reach
        else:
            scores = None
        fit_time = time.perf_counter() - t0
    if scores is None:
        with phase("score"):
            scores = score(kind, dataset, data, clean, model)
            scores.failures.update(bar_failures(scores, scenario.score))
    return RunResult(scenario, dataset, data, model, scores,
                     check_thresholds(scores.values, scenario.score), fit_time)


def _reporting(model: Any, update: Callable[..., None]) -> Any:
    """The identifier's progress reported to ``update`` during the fit (a plugin without
    :meth:`~identify.Identifier.progress_to` reports nothing)."""
    to = getattr(model, "progress_to", None)
    return to(update) if callable(to) else contextlib.nullcontext()
