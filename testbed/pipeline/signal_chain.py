"""The lab's signal chain: from a Dataset's measured signals to a Measurement.

``SIGNAL_SCHEMAS[kind]`` is the schema of a scenario's ``[signal]`` table for a
rig of that kind; :func:`measure` applies it.  Only ``dataset.measured``, ``dataset.fs``
and ``dataset.prior`` are read: never the truth or the noise-free reference, so what an
identifier is handed is what a lab would have.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from testbed.core import arguments as args
from testbed.core.dataset import Dataset, Signal
from testbed.core.errors import ArgumentError, RegistrationError, ScenarioError, show_names
from testbed.core.measurement import (
    MIN_FREE_SAMPLES,
    Measurement,
    declared_input_hold,
    nearest_within,
)
from testbed.core.schema import Field, KeyUse, validate_table
from testbed.core.schema import check_keys_used as schema_check_keys_used
from testbed.numerics import derivatives
from testbed.numerics import filters as sig
from testbed.numerics import noise as noise_est

#: A sensor within this distance [m] of the impact point receives the force.
IMPACT_TOLERANCE_M = 1e-3
#: With a low-pass, the free decay starts no earlier than where the filter's response to the
#: pulse has fallen below this fraction of its peak (:func:`~testbed.numerics.filters.lowpass_settling`).
#: Before that the smeared pulse still forces every mode, the unmodelled ones too, and a model
#: of the sensed modes fitted there is biased: measured on 2-sensor beams of the beams family
#: with the exact (reference) signals through the same low-pass, mode 2's frequency error was
#: 2.8 % from 1 ms after the pulse, 1.0 % from 2 ms, 0.1 % from 6 ms, where the 450 Hz
#: low-pass settles to 1 %.
LOWPASS_SETTLE_TOL = 0.01
#: The force pulse has ended once ``|force|`` falls below this fraction of its peak
#: (or below 5 robust noise standard deviations, whichever is larger).
PULSE_END_FRACTION = 1e-6

#: ``[signal]`` schema per rig kind (kept in step with :data:`SIGNAL_CHAINS` by
#: :func:`register_signal_chain`).
SIGNAL_SCHEMAS: dict[str, dict[str, Field]] = {}

STRUCTURAL_SIGNAL_SCHEMA: dict[str, Field] = {
    "highpass_hz": Field(float, 10.0, unit="Hz", min=0.0, min_inclusive=False,
                         also=Field(str, choices=("auto",)),
                         doc="cut-off of the zero-phase elliptic high-pass applied after each "
                             "integration (removes drift); acceleration, velocity and "
                             "displacement all end up filtered alike; 'auto': from the rig's "
                             "nominal geometry when the scenario is loaded (the cantilever: half "
                             "the Euler-Bernoulli estimate of mode 1 on its base, 0.1 Hz), the "
                             "value and its rule recorded in the scenario's rules; a cut-off of "
                             "a few Hz wants the hammer well after the record's start "
                             "(excitation.start): the zero-phase filter spreads the pulse about "
                             "1 / cut-off back in time (a 1.2 m beam at 2.9 Hz: TRAC 0.62 with "
                             "the hammer at 5 ms, the truth's own reduction too; 0.999 at 0.5 s)"),
    "highpass_order": Field(int, 5, min=1, max=12,
                            doc="order of the elliptic high-pass; odd orders have a zero at DC "
                                "and unit gain at high frequency; even orders pass DC at the "
                                "stop-band level and have -ripple_db gain at high frequency"),
    # 1e-9 dB and 300 dB: scipy designs every order 1-12 between them (checked on a grid of
    # cut-offs); a ripple of 1e-100 dB is an "improper transfer function", 5e-324 dB "cannot
    # design", and 10**(stop_db / 10) overflows above ~3,080 dB.  300 dB is below float64's
    # resolution anyway (20 log10(1 / eps) = 313 dB): a deeper stop band cannot show in data.
    "ripple_db": Field(float, 0.1, unit="dB", min=1e-9, max=300.0,
                       doc="pass-band ripple of the elliptic filter (the paper: 0.1 dB)"),
    "stop_db": Field(float, 30.0, unit="dB", min=0.0, min_inclusive=False, max=300.0,
                     doc="stop-band attenuation of the elliptic filter (the paper: 30 dB)"),
    "lowpass_hz": Field(float, 0.0, unit="Hz", min=0.0, also=Field(str, choices=("auto",)),
                        doc="optional zero-phase low-pass cut-off; 0 = off; 'auto': from the "
                            "rig's nominal geometry when the scenario is loaded (the "
                            "cantilever: between the last sensed mode n, one per sensor, and "
                            "mode n + 1, sqrt(f_n f_(n+1)) of the clamped Euler-Bernoulli "
                            "estimates, 0.1 Hz), the value and its rule recorded in the "
                            "scenario's rules; a model of n modes fitted without it meets "
                            "mode n + 1 ringing at the sensors"),
    "lowpass_order": Field(int, 8, min=1, max=16, doc="order of the optional Butterworth low-pass"),
    "free_margin_s": Field(float, 1e-3, unit="s", min=0.0,
                           doc="least time after the end of the force pulse before the free "
                               "vibration is taken to start; with a low-pass the chain also "
                               "waits until its response to the pulse has settled to 1 %"),
    "rest_offset": Field(bool, True,
                         doc="remove the post-pulse mean of each integral (free vibration of a "
                             "clamped structure is zero-mean; see integrate_acceleration)"),
    "filter_force": Field(bool, True,
                          doc="pass the force through the same filters as the acceleration, "
                              "so the equation of motion holds for the filtered signals"),
}

MECHANICAL_SIGNAL_SCHEMA: dict[str, Field] = {
    "derivatives": Field(str, "recorded", choices=("recorded", "estimated", "lowpass"),
                         doc="use the recorded joint rates and accelerations, or estimate "
                             "them from the measured angles: 'estimated' by a Savitzky-Golay "
                             "filter (window, polyorder), 'lowpass' by a zero-phase "
                             "Butterworth low-pass and central differences (cutoff_hz, "
                             "filter_order, edge_fit_s, edge_fit_order)"),
    "window": Field(int, 201, min=5, doc="Savitzky-Golay window [samples] for estimated "
                                         "derivatives (odd)"),
    "polyorder": Field(int, 4, min=2, max=8, doc="Savitzky-Golay polynomial order"),
    "cutoff_hz": Field(float, "auto", unit="Hz", min=0.0, min_inclusive=False,
                       also=Field(str, choices=("auto",)),
                       doc="'lowpass': -3 dB frequency of one pass of the zero-phase "
                           "Butterworth; just above the band of the motion (noise in the "
                           "acceleration grows as cutoff^2.5); 'auto': the lowest that passes "
                           "twice the angles' 99.9 % band with 99 % amplitude on noisy angles, "
                           "1 - 1e-12 on clean ones, continuous between (see auto_cutoff)"),
    "filter_order": Field(int, 8, min=1, max=16,
                          doc="'lowpass': Butterworth order of one pass"),
    "edge_fit_s": Field(float, "auto", unit="s", min=0.0, min_inclusive=False,
                        also=Field(str, choices=("auto",)),
                        doc="'lowpass': length of the end windows whose polynomial fits "
                            "anchor the record's ends (value, rate, acceleration); 'auto': "
                            "1.6 periods of the cut-off, at most a quarter of the record (see "
                            "auto_edge_fit)"),
    "edge_fit_order": Field(int, 5, min=2, max=8,
                            doc="'lowpass': order of the end-window polynomial fits"),
}

DYNAMICAL_SIGNAL_SCHEMA: dict[str, Field] = {
    "derivatives": Field(str, "recorded", choices=("recorded", "estimated"),
                         doc="use the recorded state derivatives ('dx'), or estimate them from "
                             "the measured states by a Savitzky-Golay filter (window, "
                             "polyorder), which also smooths the states"),
    "window": Field(int, 21, min=5, doc="Savitzky-Golay window [samples] for estimated "
                                        "derivatives (odd)"),
    "polyorder": Field(int, 3, min=2, max=8, doc="Savitzky-Golay polynomial order"),
}


def _filter_min_samples(order: int) -> int:
    """Fewest samples a zero-phase filter of this order (one pass) accepts: its second-order
    sections ``ceil(order / 2)`` set scipy's default padding, ``3 (2 n_sections + 1)``, and
    ``sosfiltfilt`` needs more samples than that (see :func:`testbed.numerics.filters._filtfilt`)."""
    return 3 * (2 * math.ceil(order / 2) + 1) + 1


ErrorFn = Callable[[str, Any, str], None]


@dataclass(frozen=True)
class SignalChain:
    """The signal chain of one rig kind: its ``[signal]`` schema, its checks, its function.

    Attributes
    ----------
    kind : str
        The rig kind it serves (``Rig.kind``, ``Scenario.kind``).
    schema : dict of str to Field
        Schema of a scenario's ``[signal]`` table for a rig of this kind.
    measure : callable
        ``measure(dataset, cfg) -> Measurement`` with ``cfg`` a validated table of ``schema``;
        reads only ``dataset.measured``, ``dataset.fs`` and ``dataset.prior``.
    check : callable, optional
        ``check(cfg, fs, n_samples, error)``: cross-key checks of a validated table against
        the record it will process (sample rate [Hz], samples); calls ``error(key, value,
        allowed)`` on the first problem.
    rig_auto : tuple of str
        Keys whose ``"auto"`` the rig resolves from its nominal geometry when the scenario is
        loaded (:func:`testbed.pipeline.scenario.resolve_auto_signal`), so ``measure`` and
        ``check`` see numbers; other ``"auto"`` values the chain resolves from the record.
    used_when : dict of str to KeyUse
        Keys that only one setting of another key makes the chain read (the Savitzky-Golay
        ``window`` only with ``derivatives = "estimated"``): :func:`check_keys_used` refuses
        them given otherwise.
    signals : tuple of str, optional
        Names of every measured signal ``measure`` may read, under any setting (None: not
        declared); a measured file holding another is refused
        (:func:`testbed.pipeline.importers.measurement_from_file`), not ignored in silence.
    """

    kind: str
    schema: dict[str, Field]
    measure: Callable[[Dataset, Mapping[str, Any]], Measurement]
    check: Callable[[Mapping[str, Any], float, int, ErrorFn], None] | None = None
    rig_auto: tuple[str, ...] = ()
    used_when: Mapping[str, KeyUse] = field(default_factory=dict)
    signals: tuple[str, ...] | None = None


#: Signal chain per rig kind, filled by :func:`register_signal_chain` (this module registers
#: "structural" and "mechanical"; a module defining a new kind registers its own).
SIGNAL_CHAINS: dict[str, SignalChain] = {}


def register_signal_chain(chain: SignalChain) -> SignalChain:
    """Make ``chain`` the signal chain of rigs of ``chain.kind`` (and its schema the ``[signal]``
    schema of their scenarios).

    Raises
    ------
    RegistrationError
        (a ValueError) if another chain is registered for that kind already.
    """
    have = SIGNAL_CHAINS.get(chain.kind)
    if have is not None and have != chain:
        raise RegistrationError(f"a signal chain for rig kind {chain.kind!r} is registered already")
    SIGNAL_CHAINS[chain.kind] = chain
    SIGNAL_SCHEMAS[chain.kind] = chain.schema
    return chain


def rig_auto_keys(kind: str) -> tuple[str, ...]:
    """Keys of the kind's ``[signal]`` table whose ``"auto"`` the rig resolves (:class:`SignalChain`)."""
    return _chain(kind).rig_auto


def check_keys_used(kind: str, given: Mapping[str, Any], cfg: Mapping[str, Any],
                    error: ErrorFn) -> None:
    """Refuse a key the table gives which the chain will not read (:attr:`SignalChain.used_when`).

    Parameters
    ----------
    kind : str
        The rig kind whose chain runs.
    given : mapping
        The ``[signal]`` table as written (before defaults are filled in).
    cfg : mapping
        The same table validated, defaults filled in.
    error : callable
        ``error(key, value, allowed)``, called on the first problem (it raises).

    Notes
    -----
    Rule: a key given with a value other than its default, while the key it depends on is set
    so that the chain does not read it, is refused (``signal.window = 301`` with recorded
    derivatives was accepted and ignored).  A key given at its default is accepted: a table
    written out whole (a family member, a run read back) lists every key at its default.
    """
    chain = _chain(kind)
    schema_check_keys_used(given, cfg, chain.schema, chain.used_when, "signal",
                           lambda key, value, allowed: error(f"signal.{key}", value, allowed))


def check_signal(kind: str, cfg: Mapping[str, Any], fs: float, n_samples: int,
                 error: ErrorFn) -> None:
    """Cross-key checks of a validated ``[signal]`` table against the record it will process.

    Parameters
    ----------
    kind : str
        A rig kind with a registered chain (:data:`SIGNAL_CHAINS`).
    cfg : mapping
        A validated ``SIGNAL_SCHEMAS[kind]`` table.
    fs : float
        Sample rate of the record [Hz].
    n_samples : int
        Samples in the record.
    error : callable
        ``error(key, value, allowed)``, called on the first problem (it raises).

    Notes
    -----
    The chains of this module check: cut-offs strictly below the Nyquist frequency ``fs / 2``
    (a digital filter cannot be designed at or above it), a high-pass below the low-pass,
    pass-band ripple below the stop-band attenuation, records long enough for every zero-phase
    filter and polynomial window, odd Savitzky-Golay windows with ``polyorder < window``, and
    margins shorter than the record.
    """
    check = _chain(kind).check
    if check is not None:
        check(cfg, fs, n_samples, error)


def _below_nyquist(cfg: Mapping[str, Any], key: str, fs: float, error: ErrorFn) -> None:
    problem = sig.cutoff_problem(cfg[key], fs)
    if problem:
        error(f"signal.{key}", cfg[key], problem)


def _long_enough(cfg: Mapping[str, Any], key: str, order: int, n_samples: int,
                 error: ErrorFn) -> None:
    need = _filter_min_samples(order)
    if n_samples < need:
        error(f"signal.{key}", cfg[key], f"the record has {n_samples} samples; a zero-phase "
                                         f"filter of order {order} needs at least {need}")


def check_structural(cfg: Mapping[str, Any], fs: float, n_samples: int, error: ErrorFn) -> None:
    """:func:`check_signal` of the structural chain."""
    duration = n_samples / fs
    _below_nyquist(cfg, "highpass_hz", fs, error)
    _long_enough(cfg, "highpass_order", cfg["highpass_order"], n_samples, error)
    if cfg["lowpass_hz"] > 0:
        _below_nyquist(cfg, "lowpass_hz", fs, error)
        _long_enough(cfg, "lowpass_order", cfg["lowpass_order"], n_samples, error)
        if not cfg["highpass_hz"] < cfg["lowpass_hz"]:
            error("signal.highpass_hz", cfg["highpass_hz"],
                  f"expected below lowpass_hz ({cfg['lowpass_hz']:g} Hz): the pass band "
                  "would be empty")
    if not cfg["ripple_db"] < cfg["stop_db"]:
        error("signal.ripple_db", cfg["ripple_db"],
              f"expected below stop_db ({cfg['stop_db']:g} dB)")
    if not cfg["free_margin_s"] < duration:
        error("signal.free_margin_s", cfg["free_margin_s"],
              f"expected shorter than the record ({duration:g} s)")


def _check_polynomial_window(cfg: Mapping[str, Any], n_samples: int, error: ErrorFn) -> None:
    """The local-polynomial derivative window: odd, above the polynomial order, within the record."""
    if cfg["window"] % 2 == 0:
        error("signal.window", cfg["window"], "expected an odd number of samples")
    if not cfg["polyorder"] < cfg["window"]:
        error("signal.polyorder", cfg["polyorder"], f"expected below window ({cfg['window']})")
    if cfg["derivatives"] == "estimated" and cfg["window"] > n_samples:
        error("signal.window", cfg["window"], f"expected at most the record's {n_samples} samples")


def check_mechanical(cfg: Mapping[str, Any], fs: float, n_samples: int, error: ErrorFn) -> None:
    """:func:`check_signal` of the mechanical chain."""
    duration = n_samples / fs
    _check_polynomial_window(cfg, n_samples, error)
    if cfg["derivatives"] == "lowpass":
        if cfg["cutoff_hz"] != "auto":
            _below_nyquist(cfg, "cutoff_hz", fs, error)
        _long_enough(cfg, "filter_order", cfg["filter_order"], n_samples, error)
        if cfg["edge_fit_s"] == "auto":
            return  # at most a quarter of the record; its length is checked when measured
        span = cfg["edge_fit_s"] * fs  # may overflow to inf (1e308 s), which round() cannot take
        n_fit = round(span) if math.isfinite(span) else span
        if not cfg["edge_fit_order"] < n_fit <= n_samples:
            error("signal.edge_fit_s", cfg["edge_fit_s"],
                  f"the end windows of {n_fit} samples must be longer than edge_fit_order "
                  f"({cfg['edge_fit_order']}) and at most the record ({n_samples} samples, "
                  f"{duration:g} s)")


def _chain(kind: str) -> SignalChain:
    try:
        return SIGNAL_CHAINS[kind]
    except KeyError:
        raise ValueError(f"unknown rig kind {kind!r}; expected one of "
                         f"{', '.join(SIGNAL_CHAINS) or '(none registered)'}") from None


def measure(dataset: Dataset, signal_cfg: Mapping[str, Any], kind: str) -> Measurement:
    """Run the lab's signal chain on a dataset's measured signals.

    Parameters
    ----------
    dataset : Dataset
        Only ``measured``, ``fs`` and ``prior`` are read.
    signal_cfg : mapping
        The scenario's ``[signal]`` table for this kind; missing keys take the defaults of
        ``SIGNAL_SCHEMAS[kind]``, unknown keys or bad values raise ScenarioError.
    kind : str
        The rig kind (``Scenario.kind``), whose registered chain (:data:`SIGNAL_CHAINS`) runs.

    Returns
    -------
    Measurement
        See the chain's function, e.g. :func:`measure_structural`, :func:`measure_mechanical`.

    Raises
    ------
    ValueError
        If no chain is registered for ``kind``.
    """
    made = getattr(dataset, "kind", None)
    if made is not None and made != kind:
        # a beam's record through the mechanical chain was "dataset has no measured signal
        # 'theta'", a plain ValueError (round 18, the API)
        raise ArgumentError("measure", "kind", kind, f"the dataset was made by a rig of kind "
                            f"{made!r}; its signals go through that kind's chain")
    # a Dataset built or loaded with fs 0, NaN, inf, True, "100" or complex (Dataset.load reads
    # the file's fs with float(); its content hash can be made anew): ZeroDivisionError,
    # TypeError or a plain ValueError from inside the filters, or 1 Hz / 100 Hz in silence
    # (hostile round 19)
    chain = _chain(kind)
    if isinstance(dataset, Dataset):
        _check_measured_table(dataset, chain)  # (before the table is read: read 26b)
        fs = args.real("measure", "dataset.fs", dataset.fs, low=0.0, low_open=True)
        n = max((np.shape(s.data)[-1] for s in dataset.measured.values()), default=0)
        if not math.isfinite(max(n - 1, 0) / fs):
            raise ArgumentError("measure", "dataset.fs", fs, f"a rate at which the record's {n} "
                                "samples last a finite time (the duration overflows)")
    cfg = validate_table(dict(signal_cfg), chain.schema, file="<signal config>", section="signal")
    m = chain.measure(dataset, cfg)
    # the kind whose chain made it, for an identifier of another kind to refuse
    return dataclasses.replace(m, kind=kind) if isinstance(m, Measurement) and m.kind is None else m


def _check_measured_table(dataset: Dataset, chain: SignalChain) -> None:
    """Refuse a hand-built Dataset's ``measured`` table that no chain can read: not a mapping
    of :class:`~testbed.core.dataset.Signal`, empty, or with a signal name holding ``"/"``
    (the files' ``<signal>/<channel>``: the channel belongs in ``Signal.channels``).  Round 25
    (the API): a bare array was AttributeError inside the chain, an empty table and a signal
    named ``x/y`` a raw "dataset has no measured signal 'x'"."""
    reads = f"the {chain.kind} chain reads {', '.join(chain.signals or ()) or 'its own signals'}"
    table = dataset.measured
    if not isinstance(table, Mapping):
        raise ArgumentError("measure", "dataset.measured", args.describe(table),
                            f"expected a mapping of signal names to Signal ({reads})", described=True)
    if not table:
        raise ArgumentError("measure", "dataset.measured", "an empty table",
                            f"expected the measured signals ({reads})", described=True)
    for name, signal in table.items():
        if not isinstance(signal, Signal):
            raise ArgumentError("measure", f"dataset.measured[{name!r}]", args.describe(signal),
                                "expected a Signal(data, channels, unit)", described=True)
        if not isinstance(name, str) or "/" in name:
            raise ArgumentError("measure", "dataset.measured", f"a signal named {name!r}",
                                "expected signal names without '/' (a file's '<signal>/<channel>' "
                                f"is Signal.channels' business; {reads})", described=True)


def _get(dataset: Dataset, name: str, rows: int | None = None) -> np.ndarray:
    if name not in dataset.measured:
        raise ValueError(f"dataset has no measured signal {name!r} (has {show_names(dataset.measured)})")
    data = np.array(dataset.measured[name].data, dtype=float)
    if rows is not None and data.shape[0] != rows:
        raise ValueError(f"measured {name!r} has {data.shape[0]} channels, expected {rows}")
    return data


def free_start_after(cfg: Mapping[str, Any], fs: float, end: int, n_samples: int, *,
                     settle: bool = True) -> int:
    """The first sample of the structural chain's free decay: ``free_margin_s`` after the pulse's
    end, or later where the low-pass's response to the pulse has settled
    (:data:`LOWPASS_SETTLE_TOL`; left out with ``settle=False``: its rule imports SciPy's
    filter design, which loading a scenario does not); 0 for a record without a pulse.

    Parameters
    ----------
    cfg : mapping
        A validated ``SIGNAL_SCHEMAS["structural"]`` table (cut-offs resolved).
    fs : float
        Sample rate [Hz].
    end : int
        First sample after the force pulse (:func:`pulse_end`); 0 for none.
    n_samples : int
        The record's length [samples]: the result is at most this.

    Returns
    -------
    int
    """
    margin = int(np.ceil(cfg["free_margin_s"] * fs))
    if settle and cfg["lowpass_hz"] > 0:
        margin = max(margin, sig.lowpass_settling(fs, cfg["lowpass_hz"], cfg["lowpass_order"],
                                                  LOWPASS_SETTLE_TOL))
    return 0 if end <= 0 else min(n_samples, end + margin)


def check_free_decay(cfg: Mapping[str, Any], fs: float, n_samples: int, pulse_start_s: float,
                     pulse_s: float, error: ErrorFn) -> None:
    """Refuse an impact that leaves the record fewer than ``MIN_FREE_SAMPLES`` samples of free
    decay after :func:`free_start_after`, naming the key at fault.

    The pulse's end is taken as the first sample at or after ``pulse_start_s + pulse_s`` (the
    nominal pulse; the measured one, :func:`pulse_end`, ends no later on a noise-free force).
    The key named is ``excitation.start`` when the pulse itself ends fewer than
    ``MIN_FREE_SAMPLES`` before the record's end (no margin could help), else
    ``signal.free_margin_s`` (hostile round 18: a pulse ending
    on the record's last samples, and a margin one sample short of the record, were scored
    failures "fit window from sample 3200 (free_start) holds 0 samples", naming no key).

    Parameters
    ----------
    cfg : mapping
        A validated structural ``[signal]`` table.
    fs : float
        Sample rate [Hz].
    n_samples : int
        The record's length [samples].
    pulse_start_s, pulse_s : float
        The impact's start and duration [s].
    error : callable
        ``error(key, value, allowed)`` (it raises).
    """
    end = min(n_samples, math.ceil((pulse_start_s + pulse_s) * fs))
    # the margin alone: `testbed list` loads every scenario and imports no SciPy; a low-pass
    # whose settling alone empties the window is the fit's to refuse (MIN_FREE_SAMPLES)
    free = n_samples - free_start_after(cfg, fs, max(end, 1), n_samples, settle=False)
    if free >= MIN_FREE_SAMPLES:
        return
    after = (f"the free decay starts {cfg['free_margin_s']:g} s (signal.free_margin_s) after "
             "the pulse's end "
             f"({pulse_start_s:.6g} + {pulse_s:.6g} s) and holds {max(free, 0)} of the record's "
             f"{n_samples} samples ({n_samples / fs:g} s); allowed: at least {MIN_FREE_SAMPLES} "
             "samples after it (an earlier excitation.start, a shorter signal.free_margin_s or a "
             "longer simulation.duration)")
    if end + MIN_FREE_SAMPLES > n_samples:  # no margin could help: the pulse ends too late
        error("excitation.start", pulse_start_s, after)
    error("signal.free_margin_s", cfg["free_margin_s"], after)


def pulse_end(force: np.ndarray) -> int:
    """Index of the first sample after the force pulse.

    Parameters
    ----------
    force : ndarray, shape (n_inputs, n_samples)
        Measured force [N].

    Returns
    -------
    int
        First sample after the peak of ``max_j |force_j|`` at which the magnitude falls below
        ``max(PULSE_END_FRACTION * peak, 5 sigma)``, sigma a robust (median absolute deviation)
        estimate of the force noise (0 for a noise-free record, whose samples are mostly exact
        zeros); 0 for an all-zero force, ``n_samples`` if the force never falls back.  Only
        the contiguous run of above-threshold samples from the peak on counts as the pulse, so
        a later noise spike does not postpone the end.
    """
    return pulse_span(force)[1]


def pulse_span(force: np.ndarray) -> tuple[int, int]:
    """First and one-past-last sample of the force pulse: ``(start, pulse_end(force))``.

    The contiguous run of samples around the peak of ``max_j |force_j|`` above
    :func:`pulse_end`'s threshold; ``(0, 0)`` for an all-zero force.

    Parameters
    ----------
    force : ndarray, shape (n_inputs, n_samples)
        Measured force [N].

    Returns
    -------
    (int, int)
    """
    mag = np.max(np.abs(np.atleast_2d(force)), axis=0)
    peak = mag.max(initial=0.0)
    if peak == 0:
        return 0, 0
    sigma = 1.4826 * np.median(np.abs(mag - np.median(mag)))
    above = mag > max(PULSE_END_FRACTION * peak, 5.0 * sigma)
    k = int(np.argmax(mag))
    below = np.flatnonzero(~above[k:])
    before = np.flatnonzero(~above[:k])
    return (0 if before.size == 0 else int(before[-1]) + 1,
            len(mag) if below.size == 0 else k + int(below[0]))


def measure_structural(dataset: Dataset, cfg: Mapping[str, Any]) -> Measurement:
    """Accelerations and impact force to sensor displacements, velocities and accelerations.

    Parameters
    ----------
    dataset : Dataset
        Measured ``"acceleration"`` (n_sensors x n [m/s^2], ``positions`` = sensor positions
        [m]) and ``"force"`` (1 x n [N], ``positions`` = impact location [m]).
    cfg : mapping
        A validated ``SIGNAL_SCHEMAS["structural"]`` table.

    Returns
    -------
    Measurement
        ``x`` displacement [m], ``xd`` velocity [m/s], ``xdd`` acceleration [m/s^2] per sensor,
        all through the same filters (optional Butterworth low-pass, then the elliptic
        high-pass twice; see :func:`testbed.numerics.filters.integrate_acceleration`); ``u`` the force
        [N] (through the same filters if ``filter_force``); ``input_map`` (n_sensors x 1) with
        1 at the sensor within ``IMPACT_TOLERANCE_M`` of the impact; ``free_start`` the
        first sample ``free_margin_s`` after the end of the raw force pulse, or later, where
        the low-pass's response to the pulse has settled (:data:`LOWPASS_SETTLE_TOL`); ``prior`` a copy
        of ``dataset.prior``; ``passband`` ``(highpass_hz, lowpass_hz or fs / 2)`` [Hz];
        ``integration`` ``"trapezoid"`` (identifiers map their poles back from the bilinear
        variable: see :attr:`testbed.core.measurement.Measurement.integration`);
        ``chain_poles`` the poles of the low-pass (once) and of the high-pass (twice), whose
        transients follow the impact in ``xdd`` (:func:`testbed.numerics.filters.chain_poles`).

    Notes
    -----
    With ``filter_force`` the equation of motion ``M xdd + C xd + K x = B u`` holds for the
    filtered signals as it does for the raw ones (every filter is linear and time-invariant
    and all signals get the same one).  After ``free_start`` the raw force is zero but the
    filtered ``u`` is not: it carries the high-pass's response to the pulse, a tail lasting a
    few ``1 / highpass_hz``.  An identifier fitting the "free" decay should keep ``u`` in
    its regression (or start later); dropping it biases damping most.

    Raises
    ------
    ValueError
        If no sensor lies within 1 mm of the impact.  A model in sensor coordinates cannot
        place a force between sensors, and spreading it (e.g. by shape functions) would be a
        modelling choice the identifier should make, not the signal chain.
    """
    for key in ("highpass_hz", "lowpass_hz"):
        if cfg[key] == "auto":  # resolved by the rig when a scenario is loaded; here no rig
            raise ScenarioError("<signal config>", f"signal.{key}", "auto",
                                "a frequency [Hz]: 'auto' is resolved from a rig's nominal "
                                "geometry when a scenario is loaded, and this chain has no rig")
    acc_sig = dataset.measured.get("acceleration")
    acc = _get(dataset, "acceleration")
    force = _get(dataset, "force")
    fs = float(dataset.fs)
    n_sensors = acc.shape[0]
    if force.shape[1] != acc.shape[1]:
        raise ValueError(f"force has {force.shape[1]} samples, acceleration {acc.shape[1]}")

    input_map = np.zeros((n_sensors, force.shape[0]))
    f_sig = dataset.measured["force"]
    if acc_sig.positions is None or f_sig.positions is None:
        raise ValueError("structural data need sensor positions and the impact position "
                         "(Signal.positions of 'acceleration' and 'force')")
    sensors = np.asarray(acc_sig.positions, dtype=float).ravel()
    for j, p in enumerate(np.asarray(f_sig.positions, dtype=float).ravel()[:force.shape[0]]):
        i, gap, within = nearest_within(p, sensors, IMPACT_TOLERANCE_M)  # the rig's own rule
        if not within:
            raise ValueError(f"impact at {p:g} m is {gap * 1e3:.6g} mm from the nearest sensor "
                             f"(at {sensors[i]:g} m); it must lie within "
                             f"{IMPACT_TOLERANCE_M * 1e3:g} mm of a sensor")
        input_map[i, j] = 1.0

    def chain_lowpass(z: np.ndarray) -> np.ndarray:
        if cfg["lowpass_hz"] > 0:
            return sig.lowpass(z, fs, cfg["lowpass_hz"], cfg["lowpass_order"])
        return z

    hp_args = (cfg["highpass_hz"], cfg["highpass_order"], cfg["ripple_db"], cfg["stop_db"])
    n = acc.shape[1]
    pad = rest_padding(cfg, fs, force)
    if pad:  # the rest the rig was at before the trigger, cut off again below
        start = pulse_span(force)[0]
        acc, force = rest_before(acc, start, pad), rest_before(force, start, pad)
    end = pulse_end(force)
    rest_from = end if (cfg["rest_offset"] and end > 0) else None
    xdd, xd, x = sig.integrate_acceleration(chain_lowpass(acc), fs, *hp_args, rest_from=rest_from)
    u = force
    if cfg["filter_force"]:
        u = chain_lowpass(force)
        for _ in range(2):
            u = sig.elliptic_highpass(u, fs, *hp_args)
    drift = drift_basis(acc.shape[1], fs, rest_from, hp_args)
    if pad:
        xdd, xd, x, u = (z[:, pad:] for z in (xdd, xd, x, u))
        drift = None if drift is None else drift[:, pad:]
        end -= pad

    free_start = free_start_after(cfg, fs, end, n)
    return Measurement(fs=fs, x=x, xd=xd, xdd=xdd, channels=tuple(acc_sig.channels), u=u,
                       inputs=tuple(f_sig.channels), input_map=input_map,
                       prior=dict(dataset.prior), free_start=free_start,
                       passband=(float(cfg["highpass_hz"]),
                                 float(cfg["lowpass_hz"]) if cfg["lowpass_hz"] > 0 else fs / 2.0),
                       drift_basis=drift,
                       integration="trapezoid",
                       chain_poles=sig.chain_poles(
                           fs, hp_args, 2,
                           (cfg["lowpass_hz"], cfg["lowpass_order"]) if cfg["lowpass_hz"] > 0
                           else None))


def rest_padding(cfg: Mapping[str, Any], fs: float, force: np.ndarray) -> int:
    """Samples of rest the structural chain puts before a record whose hammer falls too early.

    Rule: a zero-phase filter (``sosfiltfilt``) extends the record's start by an odd mirror of
    its first ``padlen = 3 (2 n_sections + 1)`` samples; that is the rest the rig was at only if
    those samples are rest.  The low-pass reads the raw record there; the high-pass reads the
    low-passed one, which the zero-phase low-pass has spread back from the pulse by its
    settling span (:func:`~testbed.numerics.filters.lowpass_settling` at
    :data:`LOWPASS_SETTLE_TOL`).  So the chain needs ``span = max(padlen_lowpass, settling +
    padlen_highpass)`` samples of rest before the force pulse's first sample
    (:func:`pulse_span`); a record with fewer (a triggered acquisition with no pre-trigger,
    ``excitation.start = 0``) gets the missing ones, ``span + 1 - start``, as rest
    (a structure at rest before the hammer: each channel's level before the pulse, 0 on a
    simulated record; :func:`rest_before`), filtered with it and cut off again.  A record
    with enough pre-trigger, or without a pulse, is filtered as it is (bit for bit as before).

    Measured on ``round17/b17_st_start0.toml`` (2 kHz low-pass, span 42), the truth's own
    reduced model's TRAC, worst channel, hammer at 0 / 10 / 13 / 20 / 24 / 28 samples:
    0.450 / 0.082 / 0.180 / 0.999 / 0.941 / 0.984 unpadded, 1.000 padded; at 64 (5 ms) 1.000
    unpadded.  With a 450 Hz low-pass (span 102) the hammer at 64 samples: 0.997 -> 0.9995.

    Parameters
    ----------
    cfg : mapping
        A validated ``SIGNAL_SCHEMAS["structural"]`` table (frequencies resolved).
    fs : float
        Sample rate [Hz].
    force : ndarray, shape (n_inputs, n_samples)
        Measured force [N].

    Returns
    -------
    int
        Samples of rest to put before the record, 0 when none are needed.
    """
    if not np.any(force):
        return 0
    lowpass_on = cfg["lowpass_hz"] > 0
    pad_lp = _filter_min_samples(cfg["lowpass_order"]) - 1 if lowpass_on else 0
    pad_hp = _filter_min_samples(cfg["highpass_order"]) - 1
    settling = (sig.lowpass_settling(fs, cfg["lowpass_hz"], cfg["lowpass_order"],
                                     LOWPASS_SETTLE_TOL) if lowpass_on else 0)
    span = max(pad_lp, settling + pad_hp)
    start = pulse_span(force)[0]
    return span + 1 - start if start <= span else 0


#: Fewest samples before the pulse whose median :func:`rest_before` takes as a channel's rest
#: level (fewer: 0, the simulated rig's exact rest).  8: the median then ignores up to three
#: samples of response onset before the force's first nonzero sample.
REST_LEVEL_MIN_SAMPLES = 8


def rest_before(z: np.ndarray, start: int, pad: int) -> np.ndarray:
    """``z`` with ``pad`` samples of rest put before it (:func:`rest_padding`).

    The rest is each channel's level before the pulse, the median of its ``start`` samples
    there (a bias of the sensor or of an imported record continues into the padding instead of
    a step at the join; review, session 19: a 1 % bias moved the chain's ``xdd`` by 1.6e-3 with
    zeros), where there are at least :data:`REST_LEVEL_MIN_SAMPLES` of them, else 0.  The
    median, not the mean: the sample just before the force's first nonzero one can already
    hold the response (a half-sine's first sample is 0; on round 17's ``b17_st_start0`` the
    mean of that one sample took the truth's own TRAC from 0.9999 to 0.765).

    Parameters
    ----------
    z : ndarray, shape (n_channels, n_samples)
        A raw channel set (accelerations [m/s^2] or forces [N]).
    start : int
        The pulse's first sample.
    pad : int
        Samples to put before the record.

    Returns
    -------
    ndarray, shape (n_channels, pad + n_samples)
    """
    level = (np.median(z[:, :start], axis=1, keepdims=True) if start >= REST_LEVEL_MIN_SAMPLES
             else np.zeros((z.shape[0], 1)))
    return np.concatenate([np.broadcast_to(level, (z.shape[0], pad)), z], axis=1)


def drift_basis(n_samples: int, fs: float, rest_from: int | None,
                hp_args: tuple[float, int, float, float]) -> np.ndarray | None:
    """What an unknown integration constant from ``rest_from`` on looks like after the chain.

    Parameters
    ----------
    n_samples : int
    fs : float
        Sample rate [Hz].
    rest_from : int or None
        The sample from which :func:`~testbed.numerics.filters.integrate_acceleration`
        corrects the velocity integral (the end of the impact pulse); None = no correction.
    hp_args : tuple
        The high-pass ``(highpass_hz, order, ripple_db, stop_db)``.

    Returns
    -------
    ndarray, shape (2, n_samples), or None
        Rows ``H^2 s`` [-] and ``H I H s`` [s], with ``s`` the unit step at ``rest_from``,
        ``I`` trapezoid integration and ``H`` the zero-phase high-pass: a velocity offset ``e``
        [m/s] from ``rest_from`` on reaches ``xd`` as ``e H^2 s`` and ``x`` as ``e H I H s``; a
        displacement offset ``c`` [m] left by integrating the pulse reaches ``x`` as
        ``c H^2 s`` (``I`` and ``H`` commute).  None
        when there is no pulse to correct after.

    Notes
    -----
    Why: the trapezoid integral of a pulse a few samples long carries a velocity offset, which
    the chain removes assuming the structure is back at rest at the end of the record (see
    ``integrate_acceleration``).  When the record ends mid-motion (a lightly damped mode
    1 over a short record) the estimate is off by about ``x(T) / T``, whose integral is a ramp
    of the order of the displacement itself; the high-pass turns it into a slow ringing near its
    cut-off.  Measured on the beams family (studies/families.toml, 2-sensor clamped beams,
    0.5 s): the true reduced model's equation residual on the chain's signals was 15-30 %.
    Those errors lie exactly in the span of these rows, as every step of the chain is linear,
    so an identifier that regresses ``xdd`` on ``xd``, ``x`` and these rows estimates the
    offsets together with the model instead of reading them as motion.  ``xdd`` is not
    affected (an integration constant does not reach the acceleration).
    """
    if rest_from is None or not 0 < rest_from < n_samples - 1:
        return None

    def hp(z: np.ndarray) -> np.ndarray:
        return sig.elliptic_highpass(z, fs, *hp_args)

    step = np.zeros((1, n_samples))
    step[0, rest_from:] = 1.0
    h1 = hp(step)
    rows = np.vstack([hp(h1), hp(sig.trapezoid(h1, fs))])
    return rows if np.all(np.any(rows != 0.0, axis=1)) else None


#: Share of the angles' noise-corrected power whose band sets ``cutoff_hz = "auto"``: 99.9 %
#: (1.5 Hz on the five-bar multisine of 0.1-1.5 Hz tones, at 0-5 % noise alike); 99 % misses
#: the top tones (0.8-1.1 Hz there).
AUTO_BAND_SHARE = 0.999
#: Highest automatic cut-off as a share of the sample rate: a digital filter needs its cut-off
#: below the Nyquist frequency (0.5); 0.45 leaves the design a margin.
AUTO_CUTOFF_MAX_SHARE = 0.45


def auto_cutoff(theta: np.ndarray, fs: float, order: int, noise: np.ndarray | None = None
                ) -> float:
    """``cutoff_hz = "auto"``: the derivative low-pass's cut-off from the raw angles.

    Rule: the band ``B`` = the largest over channels of the frequency holding
    ``AUTO_BAND_SHARE`` of the angle's power above its white-noise floor
    (:func:`testbed.numerics.noise.signal_band`); the cut-off is the lowest that passes
    ``2 B`` (the linkage's second harmonics) with the zero-phase gain
    :func:`testbed.numerics.derivatives.harmonic_gain` of the angles' relative noise
    (:func:`testbed.numerics.derivatives.relative_noise` of ``noise``): 99 % from 0.1 %
    noise up, ``1 - 1e-12`` on clean angles (``CLEAN_DROOP``; order 8: 4.22 x the 99 %
    cut-off; 1e-5 and 1.54 x before session 28), geometric in the droop between, so continuous in the noise
    (:func:`testbed.numerics.derivatives.harmonic_cutoff`), at most ``AUTO_CUTOFF_MAX_SHARE
    fs``.  Five-bar multisine (band 1.5 Hz), order 8, 1 % noise: 4.0 Hz, the hand-found value.

    Parameters
    ----------
    theta : ndarray, shape (n_joints, n_samples)
        Raw measured angles [rad].
    fs : float
        Sample rate [Hz].
    order : int
        Butterworth order of one pass of the derivative filter.
    noise : ndarray, shape (n_joints,), optional
        White-noise std of each angle [rad]; default
        :func:`testbed.numerics.noise.record_noise_std` (an encoder's rounding counted).

    Returns
    -------
    float
        Cut-off [Hz].

    Notes
    -----
    A record whose angles hold no power above their noise floor (a linkage at rest, a sine of
    1e-12 Hz) has no band to keep: the cut-off is then the widest, ``AUTO_CUTOFF_MAX_SHARE
    fs``, so the identifier sees the record as recorded derivatives would show it, and its
    verdict is the fit's failure or the scorer's "uninformative" bar, as with recorded
    derivatives (review 29b: it raised, an internal error, on inputs the schema allows).
    """
    sigma = noise_est.record_noise_std(theta) if noise is None else noise
    band = float(noise_est.signal_band(theta, fs, AUTO_BAND_SHARE, sigma).max(initial=0.0))
    if not band > 0:
        return AUTO_CUTOFF_MAX_SHARE * fs
    gain = derivatives.harmonic_gain(derivatives.relative_noise(theta, sigma))
    return min(derivatives.harmonic_cutoff(band, order, gain=gain), AUTO_CUTOFF_MAX_SHARE * fs)


#: ``edge_fit_s = "auto"``: the end fits span EDGE_FIT_PERIODS periods of the low-pass cut-off.
#: The fits' noise reaches the bridge's end curvature as ``edge_fit_s^-2.5`` and the filter
#: spreads a wrong curvature over ``~1 / fc``; their misfit of the motion (a quintic over more
#: than a couple of periods of the pass band) grows with ``edge_fit_s fc``.  Measured at 1 %
#: angle noise, rate error over the whole record (largest channel, share of its std; seeds 0 /
#: 1): five-bar multisine, 4.0 Hz, fits of 0.2 / 0.3 / 0.4 / 0.5 / 0.6 s (0.8-2.4 periods):
#: 0.76 / 0.27 / 0.26 / 0.22 / 0.57 % and 1.0 / 0.46 / 0.23 / 0.29 / 0.64 %; the paper's sine
#: replay, 0.8 Hz, 1.0 / 1.5 / 2.0 / 2.5 / 3.0 s (0.8-2.4 periods): 0.45 / 0.17 / 0.20 / 0.19 /
#: 0.25 % and 0.88 / 0.26 / 0.17 / 0.24 / 0.33 % (all with the zero-centred pad,
#: ``derivatives._odd_about_zero``); the former fixed 0.1 s (scipy's pad): 4.0 % (multisine)
#: and 112 % (sine: 0.08 periods; its 0.1 s fits leave an end curvature wrong by the order of
#: the motion's).  1.6 periods is inside both minima.
EDGE_FIT_PERIODS = 1.6
#: The two end fits take at most this share of the record each (they must not overlap).
EDGE_FIT_MAX_SHARE = 0.25
#: ... and at least this many samples per coefficient of their polynomial: a least-squares fit
#: needs more samples than coefficients to average its noise at all.  It binds only where the
#: automatic cut-off runs up to the Nyquist frequency (once a five-bar at 50 % angle noise:
#: cut-off 4.5 kHz, 1.6 periods = 4 samples for 6 coefficients, which the fit cannot take,
#: before :func:`testbed.numerics.noise.signal_band` tested its tail's significance; a user's
#: cut-off near Nyquist still does); the run then goes on to a scored verdict.
EDGE_FIT_MIN_SAMPLES_PER_COEF = 2


def auto_edge_fit(cutoff_hz: float, fs: float, n_samples: int, edge_fit_order: int = 5) -> float:
    """``edge_fit_s = "auto"``: ``EDGE_FIT_PERIODS / cutoff_hz``, at least
    ``EDGE_FIT_MIN_SAMPLES_PER_COEF`` samples per polynomial coefficient, at most
    ``EDGE_FIT_MAX_SHARE`` of the record.

    Parameters
    ----------
    cutoff_hz : float
        The derivative low-pass's cut-off [Hz].
    fs : float
        Sample rate [Hz].
    n_samples : int
        Samples in the record.
    edge_fit_order : int
        Order of the end fits' polynomial.

    Returns
    -------
    float
        Length of each end fit [s].
    """
    floor = EDGE_FIT_MIN_SAMPLES_PER_COEF * (edge_fit_order + 1) / fs
    return min(max(EDGE_FIT_PERIODS / cutoff_hz, floor), EDGE_FIT_MAX_SHARE * n_samples / fs)


def measure_mechanical(dataset: Dataset, cfg: Mapping[str, Any]) -> Measurement:
    """Joint angles, rates and accelerations, and the actuator torques.

    Parameters
    ----------
    dataset : Dataset
        Measured ``"theta"`` (n_joints x n [rad]), ``"dtheta"`` [rad/s], ``"ddtheta"``
        [rad/s^2] (n_joints rows each) and ``"torque"`` (n_inputs x n [N m]) whose
        ``Signal.acts_on`` names, per input, the ``theta`` channel it drives.
    cfg : mapping
        A validated ``SIGNAL_SCHEMAS["mechanical"]`` table.  ``derivatives = "recorded"``
        uses the recorded rates; ``"estimated"`` smooths and differentiates the angles with a
        Savitzky-Golay filter (``window``, ``polyorder``; :func:`testbed.numerics.derivatives.differentiate`),
        ``"lowpass"`` with a zero-phase Butterworth low-pass and central differences
        (``cutoff_hz``, ``filter_order``, ``edge_fit_s``, ``edge_fit_order``;
        :func:`testbed.numerics.derivatives.lowpass_differentiate`; ``cutoff_hz = "auto"`` by
        :func:`auto_cutoff`, ``edge_fit_s = "auto"`` by :func:`auto_edge_fit`); both ignore
        the recorded rates.

    Returns
    -------
    Measurement
        Channels and inputs named as the data name them, ``input_map`` (n_joints x n_inputs)
        with 1 where input j acts on joint i (from ``acts_on``; the five-bar: u1 on th1, u2
        on th4), ``free_start`` 0 (the input is continuous), ``prior`` a copy of the dataset's,
        ``noise_std`` the raw angles' white-noise std [rad] before any smoothing
        (:func:`testbed.numerics.noise.noise_std`; the smoothed angles no longer show it),
        ``passband`` ``(0, cutoff_hz)`` [Hz] for ``"lowpass"`` (None otherwise), ``input_hold``
        as the dataset's provenance declares it (:func:`testbed.core.measurement.declared_input_hold`).

    Raises
    ------
    ValueError
        A missing signal, row counts that disagree, or torques that do not declare (or
        misname) the joints they act on.
    """
    fs = float(dataset.fs)
    theta = _get(dataset, "theta")
    n_joints = theta.shape[0]
    channels = tuple(dataset.measured["theta"].channels)
    torque = _get(dataset, "torque")
    t_sig = dataset.measured["torque"]
    if t_sig.acts_on is None:
        raise ValueError("measured 'torque' does not declare the joints its inputs act on "
                         "(Signal.acts_on: one 'theta' channel per input); the mechanical chain "
                         "builds the input map from it")
    input_map = np.zeros((n_joints, torque.shape[0]))
    for j, name in enumerate(t_sig.acts_on):
        if name not in channels:
            raise ValueError(f"input {t_sig.channels[j]!r} acts on {name!r}, not a channel of "
                             f"'theta' ({', '.join(channels)})")
        input_map[channels.index(name), j] = 1.0
    # declared only for finite records (the estimator refuses NaN; the identifier then
    # sees an undeclared level, as for any chain that does not know it)
    # (an encoder's rounding counted: review 27d, a 12-bit encoder read as clean angles)
    noise = noise_est.record_noise_std(theta) if np.all(np.isfinite(theta)) else None
    passband = None
    if cfg["derivatives"] == "recorded":
        x, xd, xdd = theta, _get(dataset, "dtheta", n_joints), _get(dataset, "ddtheta", n_joints)
    elif cfg["derivatives"] == "lowpass":
        cut = cfg["cutoff_hz"]
        if cut == "auto":
            cut = auto_cutoff(theta, fs, cfg["filter_order"], noise)
        edge = cfg["edge_fit_s"]
        if edge == "auto":
            edge = auto_edge_fit(cut, fs, theta.shape[1], cfg["edge_fit_order"])
        x, xd, xdd = derivatives.lowpass_differentiate(theta, fs, cut, cfg["filter_order"],
                                                       edge, cfg["edge_fit_order"])
        passband = (0.0, float(cut))
    else:
        x, xd, xdd = derivatives.differentiate(theta, fs, cfg["window"], cfg["polyorder"])
    return Measurement(fs=fs, x=x, xd=xd, xdd=xdd, channels=channels, u=torque,
                       inputs=tuple(t_sig.channels), input_map=input_map, prior=dict(dataset.prior),
                       passband=passband, noise_std=noise,
                       input_hold=declared_input_hold(dataset.attrs))


def check_dynamical(cfg: Mapping[str, Any], fs: float, n_samples: int, error: ErrorFn) -> None:
    """:func:`check_signal` of the dynamical chain."""
    _check_polynomial_window(cfg, n_samples, error)


def measure_dynamical(dataset: Dataset, cfg: Mapping[str, Any]) -> Measurement:
    """States and their time derivatives, and the inputs if any.

    Parameters
    ----------
    dataset : Dataset
        Measured ``"x"`` (n_states x n [unit of each state]), optionally ``"dx"`` (the
        recorded derivatives, same rows [unit / s]) and ``"input"`` (n_inputs x n).
    cfg : mapping
        A validated ``SIGNAL_SCHEMAS["dynamical"]`` table.  ``derivatives = "recorded"`` uses
        ``"dx"``; ``"estimated"`` smooths and differentiates the states with a Savitzky-Golay
        filter (:func:`testbed.numerics.derivatives.differentiate`) and ignores ``"dx"``.

    Returns
    -------
    Measurement
        ``x`` the states (smoothed when estimated), ``xd`` their derivatives, ``xdd`` the
        second derivatives (recorded: central differences of ``dx``, ``numpy.gradient``; a
        first-order identifier does not use them), channels named as the data name them,
        ``u`` / ``inputs`` the inputs (None / () for an autonomous system), ``prior`` a copy,
        ``noise_std`` the raw states' white-noise std [unit of each state] before any smoothing
        (:func:`testbed.numerics.noise.noise_std`, 4th differences: it needs 6 samples; None
        for fewer or for non-finite samples).

    Raises
    ------
    ValueError
        A missing signal or row counts that disagree.
    """
    fs = float(dataset.fs)
    x = _get(dataset, "x")
    n = x.shape[0]
    channels = tuple(dataset.measured["x"].channels)
    # the raw states' white noise, before the smoothing below hides it (as measure_mechanical)
    noise = (noise_est.record_noise_std(x) if x.shape[1] >= 6 and np.all(np.isfinite(x)) else None)
    if cfg["derivatives"] == "recorded":
        xd = _get(dataset, "dx", n)
        xdd = np.gradient(xd, 1.0 / fs, axis=1)
    else:
        x, xd, xdd = derivatives.differentiate(x, fs, cfg["window"], cfg["polyorder"])
    u, inputs = None, ()
    if "input" in dataset.measured:
        u, inputs = _get(dataset, "input"), tuple(dataset.measured["input"].channels)
    return Measurement(fs=fs, x=x, xd=xd, xdd=xdd, channels=channels, u=u, inputs=inputs,
                       prior=dict(dataset.prior), input_hold=declared_input_hold(dataset.attrs),
                       noise_std=noise)


_ESTIMATED = KeyUse("derivatives", lambda v: v == "estimated", "derivatives = 'estimated'")
_LOWPASS = KeyUse("derivatives", lambda v: v == "lowpass", "derivatives = 'lowpass'")

register_signal_chain(SignalChain(
    "structural", STRUCTURAL_SIGNAL_SCHEMA, measure_structural, check_structural,
    rig_auto=("highpass_hz", "lowpass_hz"), signals=("acceleration", "force"),
    used_when={"lowpass_order": KeyUse("lowpass_hz", lambda v: v == "auto" or v > 0,
                                       "lowpass_hz > 0 (0 = no low-pass)")}))
register_signal_chain(SignalChain(
    "mechanical", MECHANICAL_SIGNAL_SCHEMA, measure_mechanical, check_mechanical,
    signals=("theta", "dtheta", "ddtheta", "torque"),
    used_when={"window": _ESTIMATED, "polyorder": _ESTIMATED, "cutoff_hz": _LOWPASS,
               "filter_order": _LOWPASS, "edge_fit_s": _LOWPASS, "edge_fit_order": _LOWPASS}))
register_signal_chain(SignalChain(
    "dynamical", DYNAMICAL_SIGNAL_SCHEMA, measure_dynamical, check_dynamical,
    signals=("x", "dx", "input"),
    used_when={"window": _ESTIMATED, "polyorder": _ESTIMATED}))
