"""The contract every rig fulfils."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, ClassVar, Protocol

from testbed.core.budget import Cost
from testbed.core.dataset import Dataset
from testbed.core.schema import Field
from testbed.core.truth import Truth, truth_type

ErrorFn = Callable[[str, Any, str], None]

#: MuJoCo's smallest mass [kg] and principal inertia [kg m^2] of a moving body (``mjMINVAL``):
#: its compiler refuses a model below it.
MJ_MINVAL = 1e-15


class ScenarioTables(Protocol):
    """What a rig reads of a validated scenario: its name, seed and the rig's own tables.

    :class:`testbed.pipeline.scenario.Scenario` is one; the contract names only what it needs,
    so the rigs do not depend on the layer that loads scenario files.
    """

    name: str
    seed: int
    rig_params: dict[str, Any]
    simulation: dict[str, Any]
    excitation: dict[str, Any]


class Rig:
    """A simulated test rig.

    Class attributes declare the scenario sections the rig accepts; an instance
    is built from a validated :class:`~testbed.pipeline.scenario.Scenario` and simulates
    noise-free data with its exact truth.  Noise and provenance are added by
    :func:`testbed.pipeline.generate.generate`, identically for every rig.

    Attributes
    ----------
    kind : str
        ``"structural"`` (linear/cubic M, C, K models from accelerations) or
        ``"mechanical"`` (multibody joint-space equations), or any kind registered with a
        truth type (:data:`testbed.core.truth.TRUTH_TYPES`), a signal chain
        (:data:`testbed.pipeline.signal_chain.SIGNAL_CHAINS`), a scorer
        (:data:`testbed.scoring.scorers.SCORERS`) and a score catalogue
        (:data:`testbed.core.kinds.METRICS`).  It is all the generic code knows of a rig:
        ``Scenario.kind`` carries it, and the registries of that kind do the rest.
    rig_schema, simulation_schema : dict of str to Field
        Schemas of the ``[rig]`` and ``[simulation]`` tables.
    excitation_schemas : dict of str to dict of str to Field
        ``[excitation]`` schema per ``type``.
    measured_signals : tuple of str
        Names in ``Dataset.measured``.
    noisy_signals : tuple of str
        Measured signals that get sensor noise by default.
    """

    name: ClassVar[str] = ""
    kind: ClassVar[str] = ""
    rig_schema: ClassVar[dict[str, Field]] = {}
    simulation_schema: ClassVar[dict[str, Field]] = {}
    excitation_schemas: ClassVar[dict[str, dict[str, Field]]] = {}
    default_excitation: ClassVar[str] = ""
    measured_signals: ClassVar[tuple[str, ...]] = ()
    noisy_signals: ClassVar[tuple[str, ...]] = ()

    @classmethod
    def check(cls, rig: dict[str, Any], simulation: dict[str, Any], excitation: dict[str, Any],
              error: ErrorFn) -> None:
        """Cross-field checks; call ``error(key, value, allowed)`` on the first problem.

        Parameters
        ----------
        rig, simulation, excitation : dict
            The scenario's ``[rig]``, ``[simulation]`` and ``[excitation]`` tables, each
            validated against its schema, defaults filled in.
        error : callable
            ``error(key, value, allowed)``: the dotted key (e.g. ``"rig.sensors"``), its value
            and what is allowed; it raises.
        """

    @classmethod
    def record(cls, simulation: dict[str, Any]) -> tuple[float, int] | None:
        """Sample rate [Hz] and number of samples of the record a ``[simulation]`` table asks for.

        The default reads ``sample_rate`` and ``duration`` (None if the rig has no such keys;
        a rig with other keys overrides it).  Used to check the signal chain against the
        record (cut-offs below Nyquist, windows shorter than the record) before anything is
        simulated.

        Parameters
        ----------
        simulation : dict
            The scenario's validated ``[simulation]`` table.

        Returns
        -------
        tuple of (float, int) or None
            Sample rate [Hz] and number of samples; None where the table does not say.
        """
        if "sample_rate" not in simulation or "duration" not in simulation:
            return None
        fs = float(simulation["sample_rate"])
        # capped before rounding: duration x sample_rate may overflow to inf (1e308 s), which
        # round() cannot take; the budget refuses such a record by its key
        return fs, round(min(simulation["duration"] * fs, 2**62))

    @classmethod
    def measurement_shape(cls, rig: dict[str, Any]) -> tuple[int, int] | None:
        """Channels and inputs of the measurement the signal chain makes of this rig's data
        (checked against an identifier's terms at load).

        Parameters
        ----------
        rig : dict
            The scenario's validated ``[rig]`` table.

        Returns
        -------
        tuple of (int, int) or None
            Number of channels and of inputs; None = unknown.
        """
        return None

    @classmethod
    def cost(cls, rig: dict[str, Any], simulation: dict[str, Any],
             excitation: dict[str, Any]) -> Cost | None:
        """Estimated memory and integration steps of a run (:class:`testbed.core.budget.Cost`).

        Called after :meth:`check`, before anything is simulated.

        Parameters
        ----------
        rig, simulation, excitation : dict
            The scenario's validated tables, as for :meth:`check`.

        Returns
        -------
        Cost or None
            Peak memory [bytes], integration steps and samples, each with the key that drives
            it; None = no estimate.
        """
        return None

    def __init__(self, scenario: ScenarioTables) -> None:
        self.scenario = scenario

    @classmethod
    def truth_type(cls) -> type[Truth]:
        """The typed truth a rig of this kind writes (:func:`testbed.core.truth.truth_type`)."""
        return truth_type(cls.kind)

    def simulate(self, progress: Callable[[float], None] | None = None) -> Dataset:
        """Noise-free measured and reference signals with every truth array.

        ``progress`` (if given) is called with the fraction done, 0..1.  ``Dataset.truth``
        holds the fields of :meth:`truth_type` (build one and store ``.to_dict()``), checked
        by :func:`testbed.pipeline.generate.simulate_clean`; an input signal that drives
        coordinates (not placed by ``positions``) names them in ``Signal.acts_on``.

        Parameters
        ----------
        progress : callable, optional
            ``progress(fraction)`` with the fraction done, in [0, 1].

        Returns
        -------
        Dataset
            ``measured`` (noise-free), ``reference`` and ``truth`` (``truth_type()(...).to_dict()``)
            at the scenario's sample rate; the caller records the kind and checks the truth.
        """
        raise NotImplementedError


def check_sample_steps(simulation: dict[str, Any], error: ErrorFn) -> None:
    """Timing a fixed-step rig needs: whole integration steps per sample, at least two samples.

    Parameters
    ----------
    simulation : dict
        The scenario's ``[simulation]`` table with ``sample_rate`` [Hz], ``dt`` [s] and
        ``duration`` [s].
    error : callable
        ``error(key, value, allowed)``.
    """
    product = simulation["sample_rate"] * simulation["dt"]
    # sample_rate x dt may underflow to 0 (5e-324 Hz) and its inverse overflow to inf: no
    # whole number of steps either way (round() cannot take inf)
    ratio = 1.0 / product if product > 0.0 else math.inf
    # 1e-6 relative: a ratio typed in decimal (e.g. 1 / (1000 * 1e-4)) is off its integer by
    # rounding only (~1e-15); anything larger is a real fraction of a step
    if not math.isfinite(ratio) or ratio < 1.0 - 1e-9 or abs(ratio - round(ratio)) > 1e-6 * ratio:
        error("simulation.sample_rate", simulation["sample_rate"],
              f"1/(sample_rate * dt) must be a whole number >= 1 (dt = {simulation['dt']:g} s gives "
              f"{ratio:.6g}): samples and input holds fall on integration steps")
    check_two_samples(simulation, error)


def check_two_samples(simulation: dict[str, Any], error: ErrorFn) -> None:
    """A record of at least two samples: ``round(duration * sample_rate) >= 2``.

    Parameters
    ----------
    simulation : dict
        The scenario's ``[simulation]`` table with ``sample_rate`` [Hz] and ``duration`` [s].
    error : callable
        ``error(key, value, allowed)``.
    """
    # compared before rounding: the product may overflow to inf (1e308 s), which round() cannot
    # take; round(x) < 2 exactly when x < 1.5 (round half to even: round(1.5) = 2)
    if simulation["duration"] * simulation["sample_rate"] < 1.5:
        error("simulation.duration", simulation["duration"],
              f"expected at least two samples (duration x sample_rate = "
              f"{simulation['duration'] * simulation['sample_rate']:.3g})")


def furthest_from_default(rig: dict[str, Any], keys: tuple[str, ...],
                          schema: dict[str, Field],
                          exponents: dict[str, float] | None = None) -> str:
    """The key of ``keys`` whose value lies furthest from its schema default by ratio
    (``|ln(value / default)|``, a ratio that over- or underflows counting as infinitely far;
    the first such key on a tie): the one a refusal of their combination names.

    Parameters
    ----------
    rig : dict
        The validated ``[rig]`` table (or any table of ``keys``' values).
    keys : tuple of str
        Keys with positive values and positive defaults.
    schema : dict of str to Field
        The rig's schema (the defaults).
    exponents : dict of str to float, optional
        Where the refused figure is a product of the keys' powers (``duration Vmax / Km``:
        ``{"duration": 1, "Vmax": 1, "Km": -1}``), the key whose factor ``ratio ** exponent``
        is largest, signed (the one that drives the figure up, ``e ln(ratio)``); a ratio that
        over- or underflows counts as infinitely far in its exponent's direction.
    """
    def distance(k: str) -> float:
        r = rig[k] / schema[k].default
        if exponents is None:
            return abs(math.log(r)) if 0.0 < r < math.inf else math.inf
        e = exponents[k]
        if not 0.0 < r < math.inf:  # underflow to 0 or overflow: infinitely far, signed
            return math.copysign(math.inf, e if r > 0.0 else -e)
        return e * math.log(r)

    return max(keys, key=distance)
