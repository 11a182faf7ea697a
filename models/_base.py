"""The contract every rig fulfils."""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING, Any, ClassVar

from testbed.schema import Field

if TYPE_CHECKING:
    from testbed.dataset import Dataset
    from testbed.scenario import Scenario

ErrorFn = Callable[[str, Any, str], None]


class Rig:
    """A simulated test rig.

    Class attributes declare the scenario sections the rig accepts; an instance
    is built from a validated :class:`~testbed.scenario.Scenario` and simulates
    noise-free data with its exact truth.  Noise and provenance are added by
    :func:`testbed.generate.generate`, identically for every rig.

    Attributes
    ----------
    kind : str
        ``"structural"`` (linear/cubic M, C, K models from accelerations) or
        ``"mechanical"`` (multibody joint-space equations); selects the signal
        chain and the scorer.
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
        """Cross-field checks; call ``error(key, value, allowed)`` on the first problem."""

    def __init__(self, scenario: Scenario) -> None:
        self.scenario = scenario

    def simulate(self, progress: Callable[[float], None] | None = None) -> Dataset:
        """Noise-free measured and reference signals with every truth array.

        ``progress`` (if given) is called with the fraction done, 0..1.
        """
        raise NotImplementedError
