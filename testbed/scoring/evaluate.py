"""Score any fitted model against a simulated dataset's exact truth (``testbed.score``), and run a
scenario given by name (``testbed.run_scenario``): the conveniences of the Python API.

The identifier's own ``score(data)`` is truth-free (R^2 on a measurement, as a scikit-learn
regressor's); this is the testbed's score, which opens the truth, so it lives in the scoring
layer and never in ``identify/``.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from typing import Any

from testbed.core.dataset import Dataset
from testbed.pipeline import plugins
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.scenario import Scenario, load_scenario
from testbed.pipeline.signal_chain import measure
from testbed.scoring import run as _run
from testbed.scoring.scorers import Scores, bar_failures, score


def _scenario(scenario: Scenario | str | os.PathLike) -> Scenario:
    return scenario if isinstance(scenario, Scenario) else load_scenario(scenario)


def score_model(model: Any, dataset: Dataset, scenario: Scenario | str | os.PathLike) -> Scores:
    """Score a fitted identifier against ``dataset``'s truth, as ``testbed run`` would.

    Parameters
    ----------
    model : Identifier
        Fitted (on this dataset's measurements, or on any data of the same channels).
    dataset : Dataset
        A simulated dataset with its truth (``testbed.generate`` or a cache).
    scenario : Scenario, str or path-like
        The scenario it belongs to (its rig kind and ``[signal]`` chain; a name or a path).

    Returns
    -------
    Scores
        ``values`` (metric -> float, e.g. ``trac``, ``mac``, ``freq_error``) and ``failures``.

    Raises
    ------
    ValueError
        If ``model`` is not fitted.
    """
    sc = _scenario(scenario)
    if hasattr(model, "is_fitted") and not model.is_fitted():
        raise ValueError(f"{type(model).__name__} is not fitted; call fit(data) first")
    kind = plugins.rig_kind(sc.rig)
    data = measure(dataset, sc.signal, kind)
    clean = measure(_run.noise_free(dataset), sc.signal, kind)
    scores = score(kind, dataset, data, clean, model)
    scores.failures.update(bar_failures(scores, sc.score))  # as run_scenario
    return scores


def run_scenario(scenario: Scenario | str | os.PathLike, *, model: Any = None,
                 seed: int | None = None, cache: DatasetCache | str | os.PathLike | bool = True,
                 progress: Callable[[float], None] | None = None) -> _run.RunResult:
    """Generate (or reuse) a scenario's data, identify, and score against the truth.

    Parameters
    ----------
    scenario : Scenario, str or path-like
        A scenario, a shipped scenario's name (``"cantilever_stiff_impact"``) or a ``.toml`` path.
    model : Identifier, optional
        An unfitted identifier to use instead of the scenario's ``[identify]``.
    seed : int, optional
        Noise seed instead of the scenario's.
    cache : bool, DatasetCache or path-like
        ``True``: the default dataset cache (``$TESTBED_CACHE`` or ``./.cache/datasets``);
        ``False``: generate afresh and store nothing; a folder or a cache: that one.
    progress : callable, optional
        Called with the fraction of the simulation done.

    Returns
    -------
    RunResult
        ``scores``, ``checks``, ``verdict``, ``passed``, the fitted ``model``, the ``dataset``.
    """
    sc = _scenario(scenario)
    if seed is not None:
        sc = sc.replace(seed=seed)
    if cache is True:
        cache = DatasetCache()
    elif cache is False:
        cache = None
    elif not isinstance(cache, DatasetCache):
        cache = DatasetCache(cache)
    return _run.run_scenario(sc, cache=cache, model=model, progress=progress)
