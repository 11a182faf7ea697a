"""Sensor-noise level and signal band estimated from a record itself.

Two estimators, for signals sampled far above their band (a mechanism's angles at kHz rates
against motions of a few Hz):

- :func:`noise_std`: white-noise standard deviation from the ``k``-th finite differences.  The
  ``k``-th difference of a smooth signal of frequency ``f`` is ``(2 pi f / fs)^k`` times its
  amplitude (negligible when ``f << fs``), while that of white noise of standard deviation
  ``sigma`` has standard deviation ``sigma sqrt(C(2k, k))``; the median absolute deviation
  (times 1.4826, the Gaussian consistency factor) makes it robust to the few samples where
  the signal itself is rough (a zero-order-hold step, a start transient).
- :func:`signal_band`: the frequency below which a given share of the signal's power lies,
  after the white-noise floor (from :func:`noise_std`) is subtracted from the periodogram, or
  above which the power left is no longer significant against that floor's fluctuation.

Both are pure functions of the samples (no model, no truth).
"""

from __future__ import annotations

from math import comb

import numpy as np

#: Gaussian consistency factor of the median absolute deviation: sigma = 1.4826 MAD.
MAD_TO_STD = 1.482602218505602


def _rows(x: np.ndarray) -> np.ndarray:
    a = np.atleast_2d(np.asarray(x, dtype=float))
    if a.ndim != 2:
        raise ValueError(f"expected a signal of shape (n_channels, n_samples), got shape {a.shape}")
    return a


def noise_std(x: np.ndarray, order: int = 4) -> np.ndarray:
    """Robust standard deviation of additive white noise in each row of ``x``.

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples) or (n_samples,)
        Uniformly sampled signals (any unit; the result has the same unit).
    order : int
        Finite-difference order ``k`` (>= 1).  Higher orders annihilate more of the smooth
        signal (it enters as ``(2 pi f / fs)^k``) but average fewer independent samples;
        4 leaves 1e-11 of a 2 Hz motion at 10 kHz.

    Returns
    -------
    ndarray, shape (n_channels,)
        ``1.4826 * MAD(diff^k x) / sqrt(C(2k, k))`` per row.

    Raises
    ------
    ValueError
        Fewer than ``order + 2`` samples, a bad order, or non-finite samples.
    """
    a = _rows(x)
    k = int(order)
    if k < 1:
        raise ValueError(f"difference order must be >= 1, got {order}")
    if a.shape[1] < k + 2:
        raise ValueError(f"{a.shape[1]} samples are too few for differences of order {k}")
    if not np.all(np.isfinite(a)):
        raise ValueError("the signal has non-finite samples")
    d = np.diff(a, n=k, axis=1)
    mad = np.median(np.abs(d - np.median(d, axis=1, keepdims=True)), axis=1)
    return MAD_TO_STD * mad / np.sqrt(comb(2 * k, k))


def signal_band(x: np.ndarray, fs: float, share: float = 0.99,
                noise: np.ndarray | None = None) -> np.ndarray:
    """Frequency below which ``share`` of each row's signal power lies [Hz].

    The row is made zero-mean and detrended (a straight line through its ends removed, so the
    record's jump between its ends does not leak as a 1/f tail), tapered by a Hann window, and
    its periodogram's expected white-noise floor (``noise**2`` spread evenly over 0..fs/2)
    subtracted (unclipped).  The band is the lowest frequency ``f`` whose remaining power
    ``R(f)`` (the noise-corrected bins above ``f``) is at most ``(1 - share)`` of the total
    ``T`` (the cumulative share reached) or no longer significant against the noise (at
    least one bin above 0 Hz): ``R(f) <= SIGNIFICANCE_Z sd(f)``, where ``sd(f)`` is the
    standard deviation of the same sum over noise alone,
    ``floor * sqrt(WINDOW_VAR K + (FLOOR_REL_ERR K)^2 / n)`` for ``K`` bins above ``f`` and
    ``n`` samples: the periodogram's own fluctuation (one bin's is its floor; the Hann
    window's neighbouring bins correlate, ``WINDOW_VAR = n sum w^4 / (sum w^2)^2 = 35/18``,
    :func:`window_var`) and the floor's estimation error, which every bin shares.  The second
    test stops the band earlier only where the noise's fluctuation exceeds the ``1 - share``
    left out.  Without it the noise above a slow motion carried the cumulative share: a
    five-bar's 2 s record (a third of a sine period) at 5 % noise gave 1.7 kHz, not 1-1.5 Hz.

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples) or (n_samples,)
    fs : float
        Sample rate [Hz].
    share : float
        Share of the signal power, in (0, 1).
    noise : ndarray, shape (n_channels,), optional
        White-noise standard deviation of each row; default :func:`noise_std`.

    Returns
    -------
    ndarray, shape (n_channels,)
        [Hz]; 0 for a row without signal power above the noise floor.
    """
    a = _rows(x)
    if not 0.0 < share < 1.0:
        raise ValueError(f"share must lie in (0, 1), got {share}")
    if not fs > 0:
        raise ValueError(f"sample rate must be positive, got {fs}")
    n = a.shape[1]
    sig = noise_std(a) if noise is None else np.broadcast_to(np.asarray(noise, float), a.shape[:1])
    ramp = np.linspace(0.0, 1.0, n)
    z = a - a[:, :1] - (a[:, -1:] - a[:, :1]) * ramp
    z = z - z.mean(axis=1, keepdims=True)
    w = np.hanning(n)
    P = np.abs(np.fft.rfft(z * w, axis=1)) ** 2
    # expected periodogram of white noise through the window: sigma^2 sum(w^2) in every bin
    floor = sig[:, None] ** 2 * np.sum(w**2)
    # no clipping at zero per bin: a noise-only bin's periodogram is exponentially distributed
    # about the floor, and clipping would keep 1/e of the noise power (at 5 % noise, 1e-3 of the
    # signal's: the 99.9 % band then runs off to hundreds of Hz); unclipped, the noise bins sum
    # to zero up to the fluctuations the significance test below allows for
    P = P - floor
    f = np.fft.rfftfreq(n, 1.0 / fs)
    cum = np.cumsum(P, axis=1)
    # bins above each frequency, and the std of their noise-only sum in units of the floor
    k_above = np.arange(P.shape[1] - 1, -1, -1, dtype=float)
    var = window_var(w) * k_above + (FLOOR_REL_ERR * k_above) ** 2 / n
    out = np.zeros(a.shape[0])
    for r in range(a.shape[0]):
        total = cum[r, -1]
        if total > 0:
            reached = int(np.searchsorted(cum[r], share * total))  # the share reached
            # nothing significant left above: stops earlier only where the noise's fluctuation
            # exceeds the (1 - share) left out
            insignificant = total - cum[r] <= SIGNIFICANCE_Z * floor[r, 0] * np.sqrt(var)
            # never at 0 Hz: a row with power above its floor has a band of at least one bin
            # (1 / record; the window spreads even a slow bow over bins 0 and 1), and callers
            # read 0 as "no power above the floor" (SINDy-PI: the exact-data recipe)
            out[r] = f[max(min(reached, int(np.argmax(insignificant))), 1)]
    return out


#: One-sided significance of the remaining power in :func:`signal_band`: 3 standard deviations
#: of a noise-only sum (a Gaussian's 0.13 % upper tail; the sum of thousands of bins is near
#: Gaussian), so the band runs on past its true end by chance in about 1 record of 700.
SIGNIFICANCE_Z = 3.0
#: Relative standard deviation of :func:`noise_std`'s variance, times sqrt(n samples): 3.2.
#: Measured on white Gaussian noise (200 rows each): 3.19 / 3.08 / 3.16 at n = 2e3 / 2e4 / 1e5
#: (the median absolute deviation of 4th differences, of which neighbours correlate, against
#: 1.41 for the sample variance of independent samples); rounded up.
FLOOR_REL_ERR = 3.2


def window_var(w: np.ndarray) -> float:
    """Variance of a sum of many neighbouring periodogram bins of white noise tapered by ``w``,
    per bin and in units of one bin's squared mean: ``n sum w^4 / (sum w^2)^2`` (Parseval on
    the bins' correlations ``|sum w^2 e^(-2 pi i m t / n)|^2 / (sum w^2)^2``; 35/18 for Hann).

    Parameters
    ----------
    w : ndarray, shape (n_samples,)
        The taper.

    Returns
    -------
    float
    """
    w2 = np.asarray(w, dtype=float) ** 2
    return float(w2.size * np.sum(w2**2) / np.sum(w2) ** 2)


#: Gaps between codes are integer multiples of the record's smallest gap to this [-]: a
#: quantised float record's codes ``k q`` carry a rounding error ~ eps |y| / q (5e-7 at 32
#: bits); a float record's gaps are integers to it by chance with probability 2e-4 each (7
#: gaps: ~1e-26)
LATTICE_TOL = 1e-4


def on_lattice(values: np.ndarray, step: float) -> bool:
    """Whether distinct values lie on a quantiser's lattice of ``step``: every gap between
    them is an integer multiple of ``step`` to :data:`LATTICE_TOL`.

    Parameters
    ----------
    values : ndarray, shape (n,)
        Distinct values (any order; fewer than 2: False).
    step : float
        The record's smallest gap between two of its distinct values (a quantised record's
        step, a float record's chance closest pair).
    """
    gaps = np.diff(np.sort(np.asarray(values, dtype=float)))
    if gaps.size < 1 or not step > 0:
        return False
    r = gaps / step
    return bool(np.all(np.abs(r - np.round(r)) <= LATTICE_TOL))


def smallest_gap(y: np.ndarray) -> float:
    """The smallest gap between a record's distinct finite values (0 with fewer than two)."""
    u = np.unique(y[np.isfinite(y)])
    return float(np.diff(u).min()) if u.size > 1 else 0.0


def quantisation_std(x: np.ndarray) -> np.ndarray:
    """The white-noise std of a quantiser's rounding in each row of ``x``: ``q / sqrt(12)``
    where the row's distinct values lie on one lattice of step ``q`` (:func:`on_lattice` with
    the row's :func:`smallest_gap`), else 0.

    An encoder sampled far above its motion repeats its codes, so most ``k``-th differences are
    exactly 0 and :func:`noise_std` reads 0 (review 27d: a 12-bit encoder at 10 kHz, 0.52 % of
    RMS of rounding, read as clean angles); a float record's gaps are no lattice's (the chance
    is ~0, :data:`LATTICE_TOL`).

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples) or (n_samples,)
        The record (any unit; the result has the same unit).

    Returns
    -------
    ndarray, shape (n_channels,)
    """
    out = []
    for row in _rows(x):
        values = np.unique(row[np.isfinite(row)])  # sorted and distinct
        step = float(np.diff(values).min()) if values.size > 1 else 0.0
        out.append(step / np.sqrt(12.0) if values.size > 2 and on_lattice(values, step) else 0.0)
    return np.asarray(out, dtype=float)


def record_noise_std(x: np.ndarray) -> np.ndarray:
    """The white-noise std a record shows in each row [x's unit]: :func:`noise_std`'s robust
    estimate, at least the quantiser's rounding (:func:`quantisation_std`).

    Raises
    ------
    ValueError
        As :func:`noise_std`.
    """
    return np.maximum(noise_std(x), quantisation_std(x))
