"""What an identifier is given: measured signals after the lab's signal chain, nothing else."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np

from testbed.core import arguments as args
from testbed.core.errors import ArgumentError

#: Range of a declared prior (a mass [kg] or a length [m]): a file's, ``--prior``'s and a
#: :class:`Measurement`'s.  A prior scales the identified matrices (M from a mass, then K = M w^2
#: with w^2 up to (pi fs)^2 ~ 1e9 rad^2/s^2, M^-1 K, and the eigen-solvers' products of them),
#: which must stay inside float64's 1e-308 .. 1e308:
#: ``total_mass`` 5e-324 kg made M singular, 1e-320 kg overflowed M^-1 K and 1e308 kg
#: overflowed K (round 15: internal errors).  1e-100 .. 1e100 leaves a factor of 1e100 to each
#: end, and holds every physical rig (an electron is 9e-31 kg, the Earth 6e24 kg).
PRIOR_RANGE = (1e-100, 1e100)


def prior_number(value: Any) -> float | None:
    """A declared prior's value as a float if it is a finite number (not a boolean, not a
    text; a 0-d array's number too) within :data:`PRIOR_RANGE`, else None."""
    if isinstance(value, np.ndarray) and value.ndim == 0:
        value = value.item()
    x = args.finite_real(value)  # (numpy reals are numbers.Real: read 26b)
    return x if x is not None and PRIOR_RANGE[0] <= x <= PRIOR_RANGE[1] else None


#: The one prior a list of numbers is given for (one length per link [m]), which
#: :class:`identify._mechsim.LoopClosure` reads; every other prior is one number.
LIST_PRIORS = frozenset({"link_lengths"})


def prior_ok(key: str, value: Any) -> bool:
    """A number :func:`prior_number` takes, or for a key of :data:`LIST_PRIORS` a non-empty
    flat list, tuple or 1-D array of them (review 26b: a ``total_mass`` of ``[0.7]`` was taken
    and a TypeError inside the fit)."""
    if key in LIST_PRIORS and (isinstance(value, (list, tuple))
                               or (isinstance(value, np.ndarray) and value.ndim == 1)):
        return len(value) > 0 and all(prior_number(v) is not None for v in value)
    return prior_number(value) is not None


def check_prior_values(where: str, prior: Mapping[str, Any]) -> None:
    """Refuse a prior value :func:`prior_ok` does not take, naming its key and value.

    The command line refuses these in a file or ``--prior`` (``check_prior``); the API read a
    text "0.7" as 0.7 kg and True as 1 kg, and [0.7], None, a complex, 5e-324 or 1e308 were raw
    errors inside the fit (round 25).  Run when a :class:`Measurement` is made and again when
    it is fitted (its ``prior`` is a plain dict a caller may change in between: review 26b).
    """
    for k, v in prior.items():
        if not prior_ok(k, v):
            lo, hi = PRIOR_RANGE
            listed = " (link_lengths: a list of them)" if k in LIST_PRIORS else ""
            raise ArgumentError(where, f"prior[{k!r}]", v, f"expected a finite number from "
                                f"{lo:g} to {hi:g} (a mass [kg] or a length [m]){listed}")


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
    kind : str, optional
        The rig kind whose signal chain made it (``"structural"``, ``"mechanical"``,
        ``"dynamical"``: :func:`testbed.pipeline.signal_chain.measure` sets it); an identifier
        of another kind refuses it in one line, as the command line refuses the pairing.  None =
        not declared (a measurement built by hand).
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
    kind: str | None = None

    def __post_init__(self) -> None:
        """Check every field once, where a measurement is made (the shared rules of
        :mod:`testbed.core.arguments`): arrays real, finite and of the shapes above (returned as
        float64), ``fs`` a finite rate > 0, ``free_start`` an integer >= 0,
        ``channels`` and ``inputs`` distinct names matching the rows of ``x`` and ``u`` (given;
        ``inputs`` may be empty: unnamed inputs),
        ``input_map`` (n_channels, n_inputs), the pass
        band ``0 <= low < high <= fs / 2``, ``integration`` and ``input_hold`` among their
        values.

        Raises
        ------
        ArgumentError
            Naming the field, its value (an array by shape and dtype) and what is allowed.
        """
        where = type(self).__name__
        put = object.__setattr__  # frozen: store the checked (float64) forms
        put(self, "fs", args.real(where, "fs", self.fs, low=0.0, low_open=True))
        x = args.array(where, "x", self.x, (None, None))
        n_ch, n_s = x.shape
        if n_ch < 1 or n_s < 1:
            raise ArgumentError(where, "x", args.describe(x), "expected at least one channel and "
                                "one sample (channels x samples)", described=True)
        put(self, "x", x)
        put(self, "xd", args.array(where, "xd", self.xd, (n_ch, n_s)))
        put(self, "xdd", args.array(where, "xdd", self.xdd, (n_ch, n_s)))
        put(self, "channels", args.names(where, "channels", self.channels, count=n_ch))
        if self.u is None:
            # names without their signals are allowed: a copy that drops u for a step that
            # does not use it keeps them (identify.sindy_pi's loop closure)
            put(self, "inputs", args.names(where, "inputs", self.inputs))
            n_in = None
        else:
            u = args.array(where, "u", self.u, (None, n_s))
            n_in = u.shape[0]
            put(self, "u", u)
            # names are optional (a record built in code may leave its inputs unnamed, as the
            # identifiers' own tests do); given, one per row of u
            if isinstance(self.inputs, (tuple, list)) and len(self.inputs) == 0:
                put(self, "inputs", ())
            else:
                put(self, "inputs", args.names(where, "inputs", self.inputs, count=n_in))
        if self.input_map is not None:
            put(self, "input_map", args.array(where, "input_map", self.input_map, (n_ch, n_in)))
        put(self, "prior", args.mapping(where, "prior", self.prior))
        check_prior_values(where, self.prior)
        # no upper bound: a window cut before the excitation ends keeps the record's free_start
        # (MeasurementSamples.window), a record that ends before its free decay starts
        put(self, "free_start", args.integer(where, "free_start", self.free_start, low=0))
        if self.passband is not None:
            nyquist = self.fs / 2.0
            band = self.passband
            ok = isinstance(band, (tuple, list)) and len(band) == 2
            if ok:
                low = args.real(where, "passband[0]", band[0], low=0.0)
                # 1e-9: a cut-off computed as fs / 2 in another order of operations
                high = args.real(where, "passband[1]", band[1], low=low, low_open=True,
                                 high=nyquist * (1 + 1e-9))
                put(self, "passband", (low, high))
            else:
                raise ArgumentError(where, "passband", band, "expected None or (low, high) [Hz], "
                                    f"0 <= low < high <= the Nyquist frequency {nyquist:g} Hz")
        if self.drift_basis is not None:
            put(self, "drift_basis", args.array(where, "drift_basis", self.drift_basis, (None, n_s)))
        if self.noise_std is not None:
            std = args.array(where, "noise_std", self.noise_std, (n_ch,))
            if np.any(std < 0):
                raise ArgumentError(where, "noise_std", std.tolist(), "expected values >= 0")
            put(self, "noise_std", std)
        if self.chain_poles is not None:
            put(self, "chain_poles", args.array(where, "chain_poles", self.chain_poles, (None,),
                                                complex_ok=True))
        args.choice(where, "integration", self.integration, ("exact", "trapezoid"))
        args.choice(where, "input_hold", self.input_hold, (None, "zoh", "linear"))
        if self.kind is not None and not isinstance(self.kind, str):
            raise ArgumentError(where, "kind", self.kind, "expected a rig kind's name or None")

    @property
    def n_channels(self) -> int:
        return self.x.shape[0]

    @property
    def n_samples(self) -> int:
        return self.x.shape[1]

    @property
    def t(self) -> np.ndarray:
        return np.arange(self.n_samples) / self.fs


#: Fewest samples a structural identifier fits after ``free_start``: the library's own floor
#: (:func:`identify.structural.build_library`), checked before the fit's band and decay rules
#: (which divided by the empty window's length: ZeroDivisionError, API round of session 15).
#: Here, not in ``identify._base``, so that a scenario's load check (an impact that leaves the
#: record no free decay, ``testbed.pipeline.scenario``) and the fit use one number.
MIN_FREE_SAMPLES = 4

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


def nearest_within(point: float, positions: np.ndarray, tol: float) -> tuple[int, float, bool]:
    """The position nearest ``point``, its distance, and whether it lies within ``tol``.

    The one rule for an impact on a sensor (the cantilever rig's check at load and the
    structural chain's force map): within ``tol`` [m] up to the pair's own round-off, ``4 eps``
    of the larger of the two magnitudes (0.3175 - 0.3165 is 1.0000000000000009 mm in floats;
    hostile round 18 had it refused "within 1 mm").

    Parameters
    ----------
    point : float
        Position [m], e.g. the hammer's.
    positions : ndarray, shape (n,)
        Candidate positions [m], e.g. the sensors'; n >= 1.
    tol : float
        Largest distance allowed [m].

    Returns
    -------
    index : int
        Index of the nearest position (the first of equals).
    gap : float
        Its distance from ``point`` [m].
    within : bool
        ``gap <= tol + 4 eps max(|point|, |positions[index]|)``.
    """
    positions = np.asarray(positions, dtype=float).ravel()
    dist = np.abs(positions - float(point))
    i = int(np.argmin(dist))
    slack = 4 * np.finfo(float).eps * max(abs(float(point)), abs(float(positions[i])))
    return i, float(dist[i]), bool(dist[i] <= tol + slack)

