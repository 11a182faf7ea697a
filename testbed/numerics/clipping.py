"""A clipped (saturated) sensor told from its record alone, with no truth.

A smooth record passes through each of its peaks once: near an apex ``y = A - a t^2`` the
samples are all distinct (a float record) or, quantised with a step ``q``, the top code holds
the samples whose value lies within one step below the apex.  A sensor that saturates holds
its rail on runs of consecutive samples while the record around it moves fast.

The rule (:func:`clipped_levels`), per channel and per extreme (the record's maximum, and its
minimum):

1. ``n_at``: the samples exactly at the extreme, counted only in runs that touch neither the
   first nor the last sample (a record that starts or ends at rest holds its value there);
2. ``n_next``: the samples exactly at the next distinct value toward the record's inside (the
   next code of a quantised record);
3. the extreme is a clip level where some run is at least :data:`MIN_RUN` samples long and
   either the record is a float record resolved finer than its motion there (the next
   :data:`RESOLVED` distinct values toward the inside are each met exactly once and their
   gaps are not integer multiples of the record's smallest gap, as a quantiser's codes are:
   :func:`on_lattice`),
   or ``n_at >= MIN_HELD`` and ``n_at > RATIO * n_next`` (a quantised record).

Why the ratio holds a quantised smooth record: the time a parabolic apex spends in the top
code (depth ``d0`` below the apex, ``0 < d0 <= q``) is ``~ sqrt(d0)``, in the next code ``~
sqrt(d0 + q) - sqrt(d0)``; their ratio is at most ``1 / (sqrt(2) - 1) = 2.41`` (at ``d0 =
q``), and pooled over peaks sharing the two codes it stays below that bound.  :data:`RATIO` =
4 leaves room for a count off by one sample at each of the codes' crossings.  A float record
meets a value twice by chance with probability ~0, so there two consecutive samples at the
extreme are a clip; a quantised clipped record holds the code below the
rail a few samples only, as the record crosses it fast on its way to the rail.  A clip held by
one sample per peak (a rail just below the peaks) cannot be told from a peak, and is not.

A record and its recorded rate (a pair such as a kinetics state ``x`` and ``dx``, a five-bar's
angles and rates) tell more (:func:`rate_contradicted_levels`): where either holds its extreme
on a run of :data:`MIN_RUN` samples or more (at the record's start or end too: a kinetics
decay clipped from its first sample, which the rule above leaves out), the signal's change
over the run less the trapezoid integral of the rate over it must stay within
:data:`RATE_HOLD_TOL` of the signal's motion and within the two channels' quantisation there;
beyond, the held channel was clipped (a signal cannot stand still while its rate integrates to
a motion, nor a rate stand at a value the signal does not follow).  At rest both are ~0.

Checked (docs/known-gaps.md, "clipped sensor"): no alarm on the records of the shipped
scenarios and the rounds' records in the run cache, nor on a sine quantised to 16 bits;
the stiff beam's accelerometer clipped at 10-50 % of its peak is told.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from testbed.numerics.noise import noise_std, on_lattice, smallest_gap

#: A clip level is held on at least one run of this many consecutive samples [samples]: a
#: smooth float record meets each value once.
MIN_RUN = 2
#: A float record resolved finer than its motion near the extreme: the next this many distinct
#: values toward the inside are each met exactly once and are no quantiser's codes [-]; there,
#: one run of :data:`MIN_RUN` samples at the extreme is a clip (a float record meets a value
#: twice by chance with probability ~0; a 16-bit code is met twice at a fast apex: measured on
#: the test records, 11 alarms of 1566 channels without the codes' test)
RESOLVED = 8
#: Otherwise (a quantised record) the extreme is held by at least this many samples in all (runs
#: touching the record's ends left out) [samples]
MIN_HELD = 3
#: ... and by more than this many times the samples of the next code toward the inside [-]:
#: a quantised parabolic apex holds its top code at most 2.41 times as long as the next one.
RATIO = 4.0
#: A held run's signal change less its rate's trapezoid integral, relative to the signal's
#: motion (RMS about its mean), beyond which the held channel was clipped [-]: the largest
#: whole-record misfit of the caches' rate pairs is 0.021 (the trapezoid rule's own error,
#: ``testbed.pipeline.importers.RATE_MISFIT_MAX``'s measurement); the 24 held runs of the 598
#: rate-pair records of the dataset cache (2,709 channel pairs) and their 16-bit copies give no
#: alarm (``benchmarks/clip_ends21.py``, docs/known-gaps.md)
RATE_HOLD_TOL = 0.05
#: ... or, taken step by step, more than this many times the run's steps times the largest
#: misfit of one step (the signal's step less the rate's trapezoid, less their mean or not,
#: whichever is larger) on the steps no held run touches [-]: the trapezoid rule errs by
#: h^3 |third derivative| / 12 a step, and a rate held at its extreme holds where that
#: derivative peaks; a sine's outside the run is cos(phase) of its peak, so 4 covers runs to
#: +-75 degrees of phase
LOCAL_STEPS = 4.0
#: Standard deviations of the channels' white noise (:func:`testbed.numerics.noise.noise_std`,
#: of differences of this order) the held run's change and the rate's integral may differ by
#: on top: a Gaussian's chance beyond 5 sigma is 6e-7 a run
NOISE_SIGMAS = 5.0
NOISE_ORDER = 4
#: The quantisation term: a held code's true change is within a step on either side and one
#: inside it, and each rate sample within its step [steps]
HOLD_STEPS = 3.0


@dataclass(frozen=True)
class Clipping:
    """One channel held at a clip level.

    Attributes
    ----------
    channel : str
        The channel's name.
    level : float
        The value held [the channel's unit].
    n_held : int
        Samples at ``level`` (runs touching the record's ends left out).
    n_samples : int
        Samples of the channel.
    runs : int
        Runs of consecutive samples at ``level`` (same count).
    unit : str
        The channel's unit ("" where unknown).
    """

    channel: str
    level: float
    n_held: int
    n_samples: int
    runs: int
    unit: str = ""

    @property
    def share(self) -> float:
        """Fraction of the channel's samples at the clip level [-]."""
        return self.n_held / self.n_samples

    def describe(self) -> str:
        """``sensor acc1 is clipped at +31.2 m/s^2: 57 of 25600 samples (0.223 %) held there
        in 6 run(s) ...``."""
        u = f" {self.unit}" if self.unit else ""
        return (f"sensor {self.channel} is clipped at {self.level:+.6g}{u}: {self.n_held} of "
                f"{self.n_samples} samples ({100 * self.share:.3g} %) held there in {self.runs} "
                "run(s) of consecutive samples, where a smooth record passes its peak once")

    def as_dict(self) -> dict[str, float | int | str]:
        """JSON-ready: channel, level, unit, n_held, n_samples, share, runs."""
        return {"channel": self.channel, "level": self.level, "unit": self.unit,
                "n_held": self.n_held, "n_samples": self.n_samples, "share": self.share,
                "runs": self.runs}


def _runs(mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Start indices and lengths of the runs of True in a 1-D boolean array."""
    d = np.diff(np.r_[0, mask.astype(np.int8), 0])
    starts = np.flatnonzero(d == 1)
    return starts, np.flatnonzero(d == -1) - starts


def clipped_levels(y: np.ndarray) -> list[tuple[float, int, int]]:
    """The clip levels of one channel by the module's rule.

    Parameters
    ----------
    y : ndarray, shape (n_samples,)
        The channel's samples (any unit); non-finite samples are never a level.

    Returns
    -------
    list of (float, int, int)
        ``(level, n_held, runs)`` for the maximum and / or the minimum where the rule fires
        (at most two, the maximum first).
    """
    y = np.asarray(y, dtype=float).ravel()
    n = y.size
    finite = y[np.isfinite(y)]
    if finite.size < 2 * MIN_HELD:
        return []
    out = []
    hi, lo = float(finite.max()), float(finite.min())
    if hi == lo:
        return []  # a constant channel: said elsewhere (a dead sensor), not a clip
    step = smallest_gap(finite)  # a quantiser's step (on_lattice)
    for level, inside in ((hi, finite[finite < hi]), (lo, finite[finite > lo])):
        starts, lengths = _runs(y == level)
        keep = (starts > 0) & (starts + lengths < n)  # not at the record's ends
        starts, lengths = starts[keep], lengths[keep]
        if not lengths.size or lengths.max() < MIN_RUN:
            continue
        held = int(lengths.sum())
        codes, counts = np.unique(inside, return_counts=True)  # ascending
        near = counts[::-1][:RESOLVED] if level == hi else counts[:RESOLVED]
        values = codes[::-1][:RESOLVED] if level == hi else codes[:RESOLVED]
        resolved = (near.size == RESOLVED and bool(np.all(near == 1))
                    and not on_lattice(values, step))
        if resolved or (held >= MIN_HELD and held > RATIO * near[0]):
            out.append((level, held, int(lengths.size)))
    return out


def rate_contradicted_levels(a: np.ndarray, d: np.ndarray, fs: float
                             ) -> list[tuple[str, float, int, int]]:
    """Extremes held by a signal or its recorded rate that the other channel contradicts.

    Parameters
    ----------
    a, d : ndarray, shape (n_samples,)
        One channel of a signal and its recorded rate (``d`` in ``a``'s unit per second).
    fs : float
        Sample rate [Hz].

    Returns
    -------
    list of (str, float, int, int)
        ``(which, level, n_held, runs)``: ``which`` is ``"signal"`` or ``"rate"``, the held
        channel; ``level`` its clip level; the samples held there on the contradicted runs and
        their count.  A constant or non-finite channel gives none.
    """
    a, d = np.asarray(a, dtype=float).ravel(), np.asarray(d, dtype=float).ravel()
    n = a.size
    if n != d.size or n < 2 * MIN_HELD or not (np.all(np.isfinite(a)) and np.all(np.isfinite(d))
                                               and fs > 0):
        return []
    if a.max() == a.min() or d.max() == d.min():
        # a constant channel: a dead sensor (said elsewhere), or a signal whose motion lies
        # within one quantisation step (a 16-bit copy of a five-bar at rest within 1.6e-7 rad
        # of 1.78 rad: four alarms on its rate, which no signal step can confirm)
        return []
    # the held runs of each extreme first: a float record holds none, and the record-wide
    # figures below (two sorts, two noise estimates) are then not needed
    held_runs = []
    for which, y in (("signal", a), ("rate", d)):
        for level in (float(y.max()), float(y.min())):
            starts, lengths = _runs(y == level)
            long = lengths >= MIN_RUN
            if np.any(long):
                held_runs.append((which, level, starts[long].tolist(), lengths[long].tolist()))
    if not held_runs:
        return []
    motion = float(np.sqrt(np.mean((a - a.mean()) ** 2)))
    qa, qd = smallest_gap(a), smallest_gap(d)
    # the rate's own offset (a sensor's bias, which the importer accepts up to RATE_BIAS_MAX
    # of its RMS) from the whole record's drift: a run of tau seconds then drifts bias * tau
    # (session 22's review: an angle at rest at its lowest, its gyro offset by 2 % of its RMS,
    # was called clipped); a clip's own share of that drift only widens the tolerance
    bias = (float(np.sum(d[1:] + d[:-1])) * 0.5 / fs - float(a[-1] - a[0])) / ((n - 1) / fs)
    # white noise on either channel: the change of a over the run and the rate's integral
    # wander by sqrt(2) sa and sqrt(m) sd / fs (session 22's review: a 12-bit encoder with
    # gyro noise of 20 % of the rate's RMS alarmed on 19-24 of 50 draws)
    sa, sd = (float(noise_std(y, order=NOISE_ORDER)[0]) if n > NOISE_ORDER + 2 else 0.0
              for y in (a, d))
    # round 21's open item (b): the pair's misfit step by step (the signal's step less the
    # rate's trapezoid) on the steps no held run touches, its mean (the rate's offset, free of
    # what a clip took away) out; a run of k steps that was not clipped misfits by at most
    # LOCAL_STEPS x k x the largest of these beside that offset, or beside nothing: the mean
    # may be the trapezoid rule's own error in motion, which a run at rest does not make
    # (review 23a: a record at rest, then a = s^3 (constant jerk: every free step misfits
    # alike, their spread ~0), was called clipped on both channels by |offset| k)
    steps = np.diff(a) - (d[1:] + d[:-1]) * 0.5 / fs
    free = np.ones(n - 1, dtype=bool)
    for _, _, starts, lengths in held_runs:
        for s0, m in zip(starts, lengths, strict=True):
            free[max(s0 - 1, 0):min(s0 + m, n - 1)] = False
    sf = steps[free]
    offset, step_misfit = 0.0, np.inf
    if sf.size:
        offset = float(np.mean(sf))
        step_misfit = float(np.max(np.maximum(np.abs(sf - offset), np.abs(sf))))
    out = []
    for which, level, starts, lengths in held_runs:
        held = runs = 0
        for s0, m in zip(starts, lengths, strict=True):
            i, j = max(s0 - 1, 0), min(s0 + m + 1, n)  # one sample past each side
            change = float(a[j - 1] - a[i])
            raw = float(np.sum(d[i + 1:j] + d[i:j - 1]) * 0.5 / fs)
            integral = raw - bias * (j - 1 - i) / fs
            noise = NOISE_SIGMAS * np.sqrt(2.0 * sa * sa + (j - i) * (sd / fs) ** 2)
            floor = HOLD_STEPS * qa + (j - i) * qd / fs + noise
            tol = max(RATE_HOLD_TOL * motion + noise, floor)
            # step by step over the run's own steps: the trapezoid errs on a step by at most
            # half its rate's change (a rest joined to a motion whose rate jumps, a dose given
            # at once), allowed twice; a rate held at a rail changes by nothing there
            k = m - 1
            local = abs(float(np.sum(steps[s0:s0 + k])) - offset * k)
            jumps = float(np.sum(np.abs(np.diff(d[s0:s0 + m])))) / fs
            if abs(change - integral) > tol or (k > 0 and local > max(
                    LOCAL_STEPS * k * step_misfit + jumps + noise, floor)):
                held, runs = held + m, runs + 1
        if runs:
            out.append((which, level, held, runs))
    return out


def clipped_channels(signals: Mapping[str, np.ndarray],
                     units: Mapping[str, str] | None = None) -> list[Clipping]:
    """Every channel held at a clip level (:func:`clipped_levels`), in the given order.

    Parameters
    ----------
    signals : mapping of str to ndarray
        Channel name -> samples, shape (n_samples,).
    units : mapping of str to str, optional
        Channel name -> unit, for the description.

    Returns
    -------
    list of Clipping
        One per clip level found (a channel clipped on both sides gives two).
    """
    out = []
    for name, y in signals.items():
        y = np.asarray(y, dtype=float).ravel()
        out += [Clipping(str(name), level, held, y.size, runs, (units or {}).get(name, ""))
                for level, held, runs in clipped_levels(y)]
    return out


def measured_clipping(measured: Mapping[str, Any], fs: float | None = None,
                      rate_pairs: Sequence[tuple[str, str]] = ()) -> list[Clipping]:
    """The clipped channels of a record's measured signals (a dataset's ``measured``).

    Parameters
    ----------
    measured : mapping of str to Signal
        :class:`testbed.core.dataset.Signal` objects (``data`` of shape (n_channels,
        n_samples), ``channels``, ``channel_units()``, ``acts_on``).  A commanded input that
        declares the coordinates it drives (``acts_on``: the five-bar's torques) is left out:
        a step or a square wave holds its extremes by design.
    fs : float, optional
        Sample rate [Hz], for ``rate_pairs``.
    rate_pairs : sequence of (str, str)
        ``(signal, its recorded rate)`` names (``testbed.pipeline.importers.RATE_PAIRS`` of
        the record's kind): their held extremes are also judged by
        :func:`rate_contradicted_levels`, channel row by row.

    Returns
    -------
    list of Clipping
    """
    signals: dict[str, np.ndarray] = {}
    units: dict[str, str] = {}
    for sig in measured.values():
        if getattr(sig, "acts_on", None) is not None:
            continue
        for row, name, unit in zip(np.atleast_2d(sig.data), sig.channels, sig.channel_units(),
                                   strict=True):
            signals[name], units[name] = row, unit
    out = clipped_channels(signals, units)
    seen = {(c.channel, c.level) for c in out}
    for g, dg in rate_pairs if fs else ():
        sig, rate = measured.get(g), measured.get(dg)
        if sig is None or rate is None or np.shape(sig.data) != np.shape(rate.data):
            continue
        for a, d, names, rnames, units_a, units_d in zip(
                np.atleast_2d(sig.data), np.atleast_2d(rate.data), sig.channels, rate.channels,
                sig.channel_units(), rate.channel_units(), strict=True):
            for which, level, held, runs in rate_contradicted_levels(a, d, float(fs)):
                name, unit = (names, units_a) if which == "signal" else (rnames, units_d)
                if (name, level) not in seen:
                    seen.add((name, level))
                    out.append(Clipping(str(name), level, held, a.size, runs, unit))
    return out


#: The fields of :func:`clipping_table`, in order.
TABLE_FIELDS = ("channel", "level", "unit", "n_held", "n_samples", "runs")


def clipping_table(clipped: list[Clipping]) -> dict[str, list[Any]]:
    """Column form of ``clipped`` (one list per field of :data:`TABLE_FIELDS`): what a run
    stores with its details (arrays of one kind each); :func:`from_table` reads it back."""
    return {k: [getattr(c, k) for c in clipped] for k in TABLE_FIELDS}


def from_table(table: Mapping[str, Any]) -> list[Clipping]:
    """The :class:`Clipping` list of a :func:`clipping_table` (lists or arrays)."""
    if not table:
        return []
    cols = [list(np.asarray(table[k]).tolist()) for k in TABLE_FIELDS]
    return [Clipping(str(ch), float(lv), int(nh), int(ns), int(r), str(u))
            for ch, lv, u, nh, ns, r in zip(*cols, strict=True)]
