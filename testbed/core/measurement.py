"""What an identifier is given: measured signals after the lab's signal chain, nothing else."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np


@dataclass(frozen=True)
class Measurement:
    """Signals an identifier may fit, in channels x samples layout.

    Attributes
    ----------
    fs : float
        Sample rate [Hz].
    x, xd, xdd : ndarray, shape (n_channels, n_samples)
        Coordinate (sensor displacement [m] or joint angle [rad]) and its first
        and second time derivatives, as the signal chain estimated them.
    channels : tuple of str
        Name of each coordinate.
    u : ndarray, shape (n_inputs, n_samples), optional
        Measured inputs (force [N] at a sensor, joint torque [N m]).
    inputs : tuple of str
        Name of each input row.
    input_map : ndarray, shape (n_channels, n_inputs), optional
        Which coordinate each input acts on (e.g. impact at the tip sensor).
    prior : dict
        Declared prior knowledge (e.g. ``total_mass`` [kg]); never the answer.
    free_start : int
        First sample after the excitation pulse (0 if the input is continuous).
    passband : (float, float), optional
        Pass band [Hz] of the signal chain the signals went through, ``(low, high)``: ``low``
        the high-pass cut-off (its pass-band edge; 0 without a high-pass), ``high`` the
        low-pass cut-off (the Nyquist frequency without one).  None = not declared (signals
        not from a filtering chain).  Below ``low`` and near it a spectrum shows the filter,
        not the structure.
    drift_basis : ndarray, shape (n_drift, n_samples), optional
        Waveforms the signal chain's integration constants may have added to ``xd`` and ``x``
        of every channel in unknown amounts (e.g. a velocity offset left by integrating a
        sampled pulse, as it looks after the chain's filters).  They carry no dynamics: an
        identifier regressing ``xdd`` on ``xd`` and ``x`` should give each equation a free
        coefficient on every row, so that the offsets are estimated with the model rather
        than read as motion (see :func:`testbed.pipeline.signal_chain.measure_structural`).
        None = the chain declares none.
    integration : {"exact", "trapezoid"}
        How ``xd`` and ``x`` relate to ``xdd``.  ``"trapezoid"``: they are trapezoid-rule
        integrals of the sampled ``xdd`` (then filtered alike), so a model fitted to them is
        exact in the bilinear (Tustin) variable ``s_T = 2 fs tanh(s / (2 fs))``, not in ``s``:
        every mode comes out ``tan(w T / 2) / (w T / 2)`` too stiff.  A structural identifier maps its
        poles back (:func:`identify.structural.unwarp_trapezoid`).  ``"exact"``: true
        derivatives (simulated or differentiated signals).
    noise_std : ndarray, shape (n_channels,), optional
        White-noise standard deviation of each raw coordinate [unit of ``x``] as the signal
        chain estimated it from the record before any smoothing (e.g. robust finite
        differences, :func:`testbed.numerics.noise.noise_std`).  A chain that low-passes the
        coordinates hides that noise from anyone differencing ``x`` (what is left is
        band-limited), so it declares it here.  None = not declared (estimate it from ``x``).
    chain_poles : ndarray of complex, shape (n_poles,), optional
        Poles [1/s] of the transients the signal chain's filters add to ``xdd`` after an impact
        (one of each conjugate pair; a pole repeated ``m`` times also gives ``t^i exp(p t)``,
        ``i < m``): a free decay through the chain is the structure's modes plus these terms in
        unknown amounts (:func:`testbed.numerics.filters.chain_poles`).  A declared instrument
        property, like ``passband``.  None = not declared.
    input_hold : {"zoh", "linear"}, optional
        What the sampled inputs ``u`` stand for between samples, as the instrument declares it:
        ``"zoh"`` each sample held until the next (an actuator driven by a DAC), ``"linear"`` a
        continuous signal.  A simulation of an identified model needs it (taking held inputs
        for linear ones adds an impulse of half a sample at the start).  None = not declared.
    """

    fs: float
    x: np.ndarray
    xd: np.ndarray
    xdd: np.ndarray
    channels: tuple[str, ...]
    u: np.ndarray | None = None
    inputs: tuple[str, ...] = ()
    input_map: np.ndarray | None = None
    prior: dict[str, Any] = field(default_factory=dict)
    free_start: int = 0
    passband: tuple[float, float] | None = None
    drift_basis: np.ndarray | None = None
    integration: str = "exact"
    noise_std: np.ndarray | None = None
    chain_poles: np.ndarray | None = None
    input_hold: str | None = None

    @property
    def n_channels(self) -> int:
        return self.x.shape[0]

    @property
    def n_samples(self) -> int:
        return self.x.shape[1]

    @property
    def t(self) -> np.ndarray:
        return np.arange(self.n_samples) / self.fs


#: How a dataset's provenance declares zero-order-hold inputs: an ``attrs`` entry ``<input>_hold``
#: (the rigs write ``torque_hold``) with this value.
ZOH_DECLARATION = "zero-order hold over each sample interval"


def declared_input_hold(attrs: dict[str, Any]) -> str | None:
    """``"zoh"`` where a dataset's ``attrs`` declare its inputs held (an entry ending in
    ``_hold`` whose value is :data:`ZOH_DECLARATION`), else None (not declared)."""
    held = [k for k, v in attrs.items() if k.endswith("_hold") and v == ZOH_DECLARATION]
    return "zoh" if held else None


class Trajectory(NamedTuple):
    """A simulated response: each array has shape (n_channels, n_samples)."""

    x: np.ndarray
    xd: np.ndarray
    xdd: np.ndarray
