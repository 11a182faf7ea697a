"""What a lab does to raw sampled signals: integration, zero-phase filters, derivatives.

Every function works along the last axis of an array of shape ``(n_channels, n_samples)``
(a 1-D array is one channel) and returns arrays of the same shape, vectorised over channels.
Filters are zero-phase (forward-backward, ``scipy.signal.sosfiltfilt``): the magnitude
response is that of the designed filter squared and there is no phase shift, so the
filtered acceleration, velocity and displacement stay aligned in time.

The chain follows the SGD-SINDy cantilever paper (seed 000, "Experimental Setup and Data
Processing"): trapezoid integration, with an elliptic high-pass of 0.1 dB pass-band ripple
and 30 dB stop-band attenuation after each integration to remove drift.
"""

from __future__ import annotations

import functools

import numpy as np


def _as_signal(x: np.ndarray) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    if x.ndim not in (1, 2):
        raise ValueError(f"expected shape (n_channels, n_samples) or (n_samples,), got {x.shape}")
    if x.shape[-1] < 2:
        raise ValueError(f"need at least 2 samples, got {x.shape[-1]}")
    return x


#: Smallest cut-off of a zero-phase filter as a fraction of the Nyquist frequency: sqrt(eps).
#: A second-order section at normalised cut-off ``w`` has poles about ``w`` from 1, and its
#: start-up state solves ``(I - A) zi = ...`` whose determinant is about ``w**2``, lost in
#: float64 round-off (eps = 2.2e-16) once ``w < sqrt(eps) = 1.5e-8``.  Measured (orders 2-16,
#: elliptic high-pass and Butterworth low-pass, 4,000 samples): "Singular matrix" from a
#: fraction of 5.6e-9 down, filtered at 1e-8 and above.
MIN_CUTOFF_FRACTION = float(np.sqrt(np.finfo(float).eps))


def cutoff_problem(cutoff_hz: float, fs: float) -> str | None:
    """What a zero-phase filter's cut-off ``cutoff_hz`` [Hz] > 0 lacks at ``fs`` [Hz], as the
    "expected ..." of an error line; None if a design can take it.

    Below the Nyquist frequency, and a fraction of it that is a float64 > 0: 5e-324 Hz passes
    "> 0" but its normalised cut-off underflows to 0, which scipy's design refuses ("filter
    critical frequencies must be greater than 0", an internal error where a setting said it);
    and a fraction of at least :data:`MIN_CUTOFF_FRACTION` (1e-300 Hz and 1e-15 Hz at 12.8 kHz
    were numpy's "Singular matrix" in the signal chain).
    """
    nyq = fs / 2.0
    if not cutoff_hz < nyq:
        return f"expected below the Nyquist frequency {nyq:g} Hz (sample rate {fs:g} Hz)"
    if not cutoff_hz / nyq > 0.0:
        return (f"expected a cut-off whose fraction of the Nyquist frequency {nyq:g} Hz is a "
                "float64 > 0 (it underflows to 0)")
    if not cutoff_hz / nyq >= MIN_CUTOFF_FRACTION:
        return (f"expected at least {MIN_CUTOFF_FRACTION * nyq:.3g} Hz, {MIN_CUTOFF_FRACTION:.3g} "
                f"of the Nyquist frequency {nyq:g} Hz (below it a second-order section's poles "
                "lie within float64 round-off of 1 and the zero-phase filter's start-up solve is "
                "singular)")
    return None


def _check_cutoff(cutoff_hz: float, fs: float, what: str) -> None:
    if not fs > 0:
        raise ValueError(f"sample rate must be > 0 Hz, got {fs}")
    nyq = fs / 2.0
    if not 0.0 < cutoff_hz < nyq:
        raise ValueError(f"{what} cut-off {cutoff_hz} Hz must lie strictly between 0 Hz and the "
                         f"Nyquist frequency {nyq:g} Hz (fs = {fs:g} Hz)")


def _check_design(cutoff_hz: float, fs: float, order: int, what: str) -> int:
    """The filter order as an int, once the sample rate, cut-off and order are valid."""
    _check_cutoff(cutoff_hz, fs, what)
    if int(order) < 1:
        raise ValueError(f"filter order must be >= 1, got {order}")
    return int(order)


def _filtfilt(sos: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Forward-backward filter with scipy's default end handling.

    That handling (a short odd extension, then initial states in steady state for the first
    value) amounts to assuming the signal was constant before the record, which is exact for
    a response that starts at rest (an impact test).  A long odd extension was tried: it
    settles faster on a strongly drifting record but adds a slow error of 1 % of the
    amplitude after the impact, so it is not used.
    """
    minimum = 3 * (2 * len(sos) + 1)
    if x.shape[-1] <= minimum:
        raise ValueError(f"signal of {x.shape[-1]} samples is too short for a zero-phase filter of "
                         f"order {2 * len(sos)} (needs more than {minimum} samples)")
    from scipy import signal as ss  # lazy: scipy.signal costs ~0.7 s of import

    return ss.sosfiltfilt(sos, x, axis=-1)


def trapezoid(x: np.ndarray, fs: float) -> np.ndarray:
    """Cumulative trapezoid integral, starting at 0.

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        Signal in any unit ``[U]``.
    fs : float
        Sample rate [Hz].

    Returns
    -------
    ndarray, shape (n_channels, n_samples)
        ``y[..., k] = sum_{i<k} (x[i] + x[i+1]) / (2 fs)`` in ``[U s]``; ``y[..., 0] = 0``.

    Notes
    -----
    The trapezoid rule's frequency response is ``(w T / 2) / tan(w T / 2)`` times that of
    exact integration (no phase error): 0.66 % low at 576 Hz for fs = 12.8 kHz, 2.6 % low at
    a tenth of the sample rate.  Each integration multiplies the bias.
    """
    x = _as_signal(x)
    from scipy import integrate  # lazy, as scipy.signal

    return integrate.cumulative_trapezoid(x, dx=1.0 / fs, axis=-1, initial=0.0)


def elliptic_highpass(x: np.ndarray, fs: float, cutoff_hz: float, order: int = 4,
                      ripple_db: float = 0.1, stop_db: float = 30.0) -> np.ndarray:
    """Zero-phase elliptic high-pass filter.

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        Signal in any unit.
    fs : float
        Sample rate [Hz].
    cutoff_hz : float
        Pass-band edge [Hz] (where the single-pass gain leaves the ripple band), in (0, fs/2).
    order : int
        Order of the elliptic design (the zero-phase response has twice this order).
    ripple_db : float
        Peak-to-peak pass-band ripple of one pass [dB] (0.2 dB after forward-backward).
    stop_db : float
        Minimum stop-band attenuation of one pass [dB] (twice that after forward-backward).

    Returns
    -------
    ndarray, shape (n_channels, n_samples)
        The filtered signal, same unit.

    Notes
    -----
    The mean of each channel is subtracted first.  An even-order elliptic high-pass does not
    have a zero at DC: its DC gain is the stop-band level (-30 dB per pass), so without the
    mean removal an offset would pass at -60 dB and integrate into drift.  Mean removal is an
    affine step that commutes with differentiation, so it does not disturb the consistency
    of acceleration, velocity and displacement.
    """
    x = _as_signal(x)
    order = _check_design(cutoff_hz, fs, order, "high-pass")
    if not (0 < ripple_db < stop_db):
        raise ValueError(f"need 0 < ripple_db < stop_db, got ripple_db={ripple_db}, stop_db={stop_db}")
    return _filtfilt(_highpass_sos(fs, cutoff_hz, order, ripple_db, stop_db),
                     x - x.mean(axis=-1, keepdims=True))


def _highpass_sos(fs: float, cutoff_hz: float, order: int, ripple_db: float, stop_db: float
                  ) -> np.ndarray:
    """Second-order sections of :func:`elliptic_highpass`'s design (one pass).

    Designed once per parameter set and copied out (:func:`_ellip_sos`): a run asks for the
    same few designs about 30 times (the chain's two passes on two records, the fit band on
    every feature block), 3 ms of ``scipy.signal.ellip`` each.
    """
    return _ellip_sos(float(fs), float(cutoff_hz), int(order), float(ripple_db),
                      float(stop_db)).copy()


def _lowpass_sos(fs: float, cutoff_hz: float, order: int) -> np.ndarray:
    """Second-order sections of :func:`lowpass`'s design (one pass), designed once per
    parameter set (:func:`_butter_sos`) and copied out."""
    return _butter_sos(float(fs), float(cutoff_hz), int(order)).copy()


# The cached designs are never handed out (scipy's sosfilt needs a writable array, and a
# caller could change it): the functions above return copies.
@functools.lru_cache(maxsize=64)
def _ellip_sos(fs: float, cutoff_hz: float, order: int, ripple_db: float, stop_db: float
               ) -> np.ndarray:
    from scipy import signal as ss

    return ss.ellip(order, ripple_db, stop_db, cutoff_hz, btype="highpass", output="sos", fs=fs)


@functools.lru_cache(maxsize=64)
def _butter_sos(fs: float, cutoff_hz: float, order: int) -> np.ndarray:
    from scipy import signal as ss

    return ss.butter(order, cutoff_hz, btype="lowpass", output="sos", fs=fs)


def chain_poles(fs: float, highpass: tuple[float, int, float, float] | None = None,
                highpass_passes: int = 2, lowpass: tuple[float, int] | None = None
                ) -> np.ndarray:
    """Continuous-time poles of the transients a zero-phase filter chain adds after an impact.

    A zero-phase (forward-backward) filter's forward pass answers the onset of an impact
    response with its own free response, ``sum_j d_j exp(p_j t)`` over its poles ``p_j``; the
    backward pass only scales those terms (in reversed time they are growing exponentials, in
    its steady state), and adds nothing after the onset.  So after an impact a record through
    the chain is the structure's modes plus these terms in unknown amounts; a filter applied
    ``m`` times gives ``t^i exp(p t)``, ``i < m``, for each of its poles.

    Parameters
    ----------
    fs : float
        Sample rate [Hz].
    highpass : (cutoff_hz, order, ripple_db, stop_db), optional
        The elliptic high-pass (:func:`elliptic_highpass`), None without one.
    highpass_passes : int
        How many times the signal went through it (:func:`integrate_acceleration`: 2).
    lowpass : (cutoff_hz, order), optional
        The Butterworth low-pass (:func:`lowpass`, applied once), None without one.

    Returns
    -------
    ndarray of complex, shape (n_poles,)
        ``fs log z`` [1/s] of each z-plane pole of the designs, one of each conjugate pair
        (imaginary part >= 0), repeated once per pass.
    """
    from scipy import signal as ss

    out: list[complex] = []
    designs = []
    if highpass is not None:
        designs.append((_highpass_sos(fs, *highpass), highpass_passes))
    if lowpass is not None:
        designs.append((_lowpass_sos(fs, *lowpass), 1))
    for sos, passes in designs:
        z = ss.sos2zpk(sos)[1].astype(complex)
        z = z[np.abs(z) > 0]  # a pole at z = 0 (an odd order's padding) is a delay, no transient
        s = fs * np.log(z)
        s = s[s.imag >= -1e-9 * np.abs(s)]
        out += [complex(v.real, max(v.imag, 0.0)) for v in s] * passes
    return np.asarray(out, dtype=complex)


def lowpass(x: np.ndarray, fs: float, cutoff_hz: float, order: int = 8) -> np.ndarray:
    """Zero-phase Butterworth low-pass filter.

    Parameters
    ----------
    x, fs
        Signal (n_channels, n_samples) and sample rate [Hz], as for :func:`elliptic_highpass`.
    cutoff_hz : float
        -3 dB frequency of one pass [Hz] (-6 dB after forward-backward), in (0, fs/2).
    order : int
        Butterworth order of one pass.

    Returns
    -------
    ndarray, shape (n_channels, n_samples)
        ``x`` low-passed, in its unit.

    Notes
    -----
    Butterworth rather than elliptic: its pass band is maximally flat, so modes well below
    the cut-off keep their relative amplitudes exactly (an elliptic pass-band ripple would
    weight modes differently), and a low-pass here only suppresses broadband noise above the
    modes of interest, where a sharp transition is not needed.
    """
    x = _as_signal(x)
    order = _check_design(cutoff_hz, fs, order, "low-pass")
    return _filtfilt(_lowpass_sos(fs, cutoff_hz, order), x)


def integrate_acceleration(acc: np.ndarray, fs: float, highpass_hz: float, order: int = 4,
                           ripple_db: float = 0.1, stop_db: float = 30.0, rest_from: int | None = None
                           ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Velocity and displacement from acceleration, all three filtered alike.

    Parameters
    ----------
    acc : ndarray, shape (n_channels, n_samples)
        Measured acceleration [m/s^2].
    fs : float
        Sample rate [Hz].
    highpass_hz, order, ripple_db, stop_db
        The elliptic high-pass (see :func:`elliptic_highpass`): cut-off [Hz], order,
        pass-band ripple [dB], stop-band attenuation [dB].

    Returns
    -------
    acc_f : ndarray, shape (n_channels, n_samples)
        Acceleration [m/s^2] passed through the high-pass twice.
    vel : ndarray, shape (n_channels, n_samples)
        Velocity [m/s]: high-pass of the trapezoid integral of ``acc``, then high-passed again.
    disp : ndarray, shape (n_channels, n_samples)
        Displacement [m]: high-pass of the trapezoid integral of the first velocity.

    Notes
    -----
    The paper high-passes after each integration: ``v1 = H I a`` and ``d = H I H I a = H^2 I^2 a``
    (``I`` integration, ``H`` the zero-phase high-pass).  Used as is, the three signals would
    carry different filters (``a``: none, ``v1``: ``H``, ``d``: ``H^2``), and near the cut-off the
    gain mismatch biases a regression of acceleration on velocity and displacement.  Because
    ``H`` is linear and time-invariant it commutes with integration and differentiation in the
    steady state, so we give every signal the same total filter ``H^2``: ``acc_f = H^2 a``,
    ``vel = H v1 = H^2 I a``, ``disp = H^2 I^2 a``.  Then ``d/dt disp = vel`` and
    ``d/dt vel = acc_f`` hold (up to the trapezoid bias and the end transients of the filter),
    and the equation of motion ``M a + C v + K d = f`` holds for the filtered signals when the
    force is filtered with ``H^2`` too.  The price is a 0.4 dB pass-band ripple shared by all
    three signals (harmless to the regression) and a slightly wider transition band.

    ``rest_from`` (a sample index, e.g. the end of an impact pulse) corrects the velocity
    integral from that sample on so that its mean is ``-x(t0) / T``: after the pulse the
    structure moves freely from ``x(t0)`` back to rest over the remaining time ``T``, with
    ``x(t0)`` the integral of the velocity up to the pulse end.  The trapezoid integral of a
    pulse only a few samples long carries a constant velocity offset (then a ramp in
    displacement), which this removes.  The
    displacement is not treated alike: a decaying mode's displacement has a genuine nonzero
    mean (``v0 / (omega^2 T)``).  The elliptic high-pass, with its 30 dB stop band, leaves about
    3 % of such an offset, and because the sensors' higher modes carry little motion that
    residue dominates their direction: measured on the default stiff cantilever, the correction
    cuts the displacement error along the true sensor modes 1 / 2 / 3 from 2.4 / 103 / 1834 %
    to 0.8 / 1.1 / 12 % (tests/testbed/pipeline/test_rest_offset.py).

    The commutation is exact only for a record that starts at rest and ends with the motion
    decayed (an impact test with enough post-trigger time); a record cut mid-motion carries
    end transients of the order of the motion left, for a few ``1 / highpass_hz``.
    """
    acc = _as_signal(acc)

    def hp(z: np.ndarray) -> np.ndarray:
        return elliptic_highpass(z, fs, highpass_hz, order, ripple_db, stop_db)

    def remove_velocity_offset(v: np.ndarray) -> np.ndarray:
        if rest_from is None or rest_from >= v.shape[1] - 1:
            return v
        # After the pulse the structure moves freely from x(t0) back to rest, so the velocity's
        # mean over the rest of the record is -x(t0) / T (exact for a record that ends at rest).
        x_t0 = trapezoid(v[:, : rest_from + 1], fs)[:, -1:]
        span = (v.shape[1] - 1 - rest_from) / fs
        v = v.copy()
        v[:, rest_from:] -= v[:, rest_from:].mean(axis=1, keepdims=True) + x_t0 / span
        return v

    v1 = hp(remove_velocity_offset(trapezoid(acc, fs)))
    disp = hp(trapezoid(v1, fs))
    return hp(hp(acc)), hp(v1), disp


def lowpass_settling(fs: float, cutoff_hz: float, order: int = 8, tol: float = 0.01) -> int:
    """Samples after an impulse until :func:`lowpass`'s response stays below ``tol`` of its peak.

    Parameters
    ----------
    fs : float
        Sample rate [Hz].
    cutoff_hz, order
        The zero-phase Butterworth low-pass (see :func:`lowpass`).
    tol : float
        Fraction of the response's peak magnitude, in (0, 1).

    Returns
    -------
    int
        The last sample (counted from the impulse) at which the magnitude of the
        forward-backward impulse response exceeds ``tol`` times its peak.  E.g. 81 samples
        (6.3 ms, 2.9 periods of the cut-off) for order 8 at 450 Hz and fs = 12.8 kHz, 21 at
        2 kHz: a sharp low-pass rings for a few of its periods, and a pulse smeared that far
        is still forcing the structure.
    """
    if not 0 < tol < 1:
        raise ValueError(f"tol must be in (0, 1), got {tol}")
    _check_cutoff(cutoff_hz, fs, "low-pass")
    from scipy import signal as ss

    sos = _lowpass_sos(fs, cutoff_hz, order)
    # the response has decayed far below 1e-6 of its peak after 100 periods of the cut-off
    half = int(np.ceil(100 * fs / cutoff_hz))
    imp = np.zeros(2 * half + 1)
    imp[half] = 1.0
    h = np.abs(ss.sosfiltfilt(sos, imp))
    return int(np.flatnonzero(h > tol * h.max()).max() - half)


def zero_phase_gain(f: np.ndarray, cutoff_hz: float, order: int) -> np.ndarray:
    """Amplitude gain of the zero-phase Butterworth low-pass (:func:`lowpass`) at ``f`` [Hz]:
    ``1 / (1 + (f / fc)^(2 order))`` (the analogue prototype's magnitude squared; the digital
    design's frequency warping is ``O((f / fs)^2)``, below 1e-4 relative for ``f < fs / 100``).

    Parameters
    ----------
    f : ndarray
        Frequencies [Hz], >= 0.
    cutoff_hz : float
        -3 dB frequency of one pass [Hz], > 0.
    order : int
        Butterworth order of one pass (>= 1).

    Returns
    -------
    ndarray, shape of ``f``
        Gain in (0, 1].
    """
    return 1.0 / (1.0 + (np.asarray(f, dtype=float) / float(cutoff_hz)) ** (2 * int(order)))


def zero_phase_droop(f: np.ndarray, cutoff_hz: float, order: int) -> np.ndarray:
    """Droop ``1 -`` :func:`zero_phase_gain` of the zero-phase Butterworth low-pass at ``f``
    [Hz], computed as ``r / (1 + r)``, ``r = (f / fc)^(2 order)``: exact to the last bit where
    the droop is far below 1 (``1 - gain`` leaves a relative error ``eps / droop``: 1e-4 at
    1e-12).

    Parameters
    ----------
    f : ndarray
        Frequencies [Hz], >= 0.
    cutoff_hz : float
        -3 dB frequency of one pass [Hz], > 0.
    order : int
        Butterworth order of one pass (>= 1).

    Returns
    -------
    ndarray, shape of ``f``
        Droop in [0, 1).
    """
    r = (np.asarray(f, dtype=float) / float(cutoff_hz)) ** (2 * int(order))
    return r / (1.0 + r)


def input_power(u: np.ndarray, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """Periodogram of each row about its mean, tapered by a 4-term Blackman-Harris window.

    The window's side lobes lie 92 dB down (Hann's: 31 dB, falling as ``1/f^3``): a band-limited
    input's tones then leak less than 1e-9 of their power to the far bins
    :func:`chain_mismatch_share` weighs, so a smooth input reads as smooth on a record of a few
    periods (a 3 s five-bar multisine: mismatch share 3.5e-14 at the clean column cut-off
    with this window, 2.4e-11 with Hann's).

    Parameters
    ----------
    u : ndarray, shape (n_rows, n_samples) or (n_samples,)
        The signal [U].
    fs : float
        Sample rate [Hz].

    Returns
    -------
    f : ndarray, shape (n_samples // 2 + 1,)
        Frequencies [Hz].
    power : ndarray, shape (n_rows, n_samples // 2 + 1)
        Power per bin [U^2, unnormalised].
    """
    from scipy.signal import windows

    u = _as_signal(u)
    n = u.shape[-1]
    w = windows.blackmanharris(n, sym=False) if n > 1 else np.ones(n)
    p = np.abs(np.fft.rfft((u - u.mean(axis=-1, keepdims=True)) * w, axis=-1)) ** 2
    return np.fft.rfftfreq(n, 1.0 / fs), p


def chain_mismatch_share(f: np.ndarray, power: np.ndarray, chain_hz: float, chain_order: int,
                         column_hz: float, column_order: int) -> float:
    """Largest over rows of the share of a signal's column-filtered power that a zero-phase
    low-pass chain at ``chain_hz`` would have changed: ``sum G_k^2 (1 - G_c)^2 P / sum G_k^2 P``
    over the bins, ``G_c`` the chain's and ``G_k`` the column filter's
    :func:`zero_phase_gain`, ``P`` a row of :func:`input_power`.

    A signal the chain did not filter (a measured input) paired with rates the chain derived
    differs from what the chain would have made of it by ``(1 - G_c) U``; this is that
    difference's power after the column low-pass, relative to the signal's.  It never falls
    as ``column_hz`` rises (the weights ``G_k^2`` at a higher cut-off shift towards higher
    bins, where ``(1 - G_c)^2`` is larger), so a bisection finds where it crosses a bound.

    Parameters
    ----------
    f, power
        :func:`input_power`'s frequencies [Hz] and rows.
    chain_hz, chain_order
        The chain's low-pass cut-off [Hz] and Butterworth order.
    column_hz, column_order
        The column low-pass's.

    Returns
    -------
    float
        The share, in [0, 1]; 0 for a row without power, NaN if ``power`` is not finite.
    """
    power = np.atleast_2d(power)
    if not np.all(np.isfinite(power)):
        return float("nan")
    gk2 = zero_phase_gain(f, column_hz, column_order) ** 2
    mis = (1.0 - zero_phase_gain(f, chain_hz, chain_order)) ** 2
    den = power @ gk2
    num = power @ (gk2 * mis)
    share = np.where(den > 0, num / np.where(den > 0, den, 1.0), 0.0)
    return float(share.max(initial=0.0))


def mismatch_cutoff(u: np.ndarray, fs: float, chain_hz: float, chain_order: int,
                    column_order: int, low_hz: float, high_hz: float, bound: float,
                    steps: int = 60) -> float:
    """Highest column cut-off in ``[low_hz, high_hz]`` [Hz] at which
    :func:`chain_mismatch_share` of ``u`` is at most ``bound``.

    ``high_hz`` if its share is within the bound (or ``high_hz <= low_hz``); ``low_hz`` if even
    that one's share exceeds it (or the share is NaN); else the crossing, by ``steps``
    bisections in ``log f`` (60: relative width ``(high / low)^(2^-60)``, far below any bin),
    so the cut-off moves continuously with the signal (the share is monotone in the cut-off).

    Parameters
    ----------
    u : ndarray, shape (n_rows, n_samples)
        The signal [U] (e.g. the measured inputs).
    fs : float
        Sample rate [Hz].
    chain_hz, chain_order, column_order
        As :func:`chain_mismatch_share`.
    low_hz, high_hz : float
        The range of the column cut-off [Hz], > 0.
    bound : float
        Largest share allowed, in [0, 1].
    steps : int
        Bisection steps.

    Returns
    -------
    float
        Cut-off [Hz].
    """
    if not high_hz > low_hz:
        return float(high_hz)
    f, p = input_power(u, fs)

    def share(fc: float) -> float:
        return chain_mismatch_share(f, p, chain_hz, chain_order, fc, column_order)

    top = share(high_hz)
    if top <= bound:
        return float(high_hz)
    bottom = share(low_hz)
    if not bottom <= bound or not np.isfinite(top):
        return float(low_hz)
    lo, hi = np.log(low_hz), np.log(high_hz)
    for _ in range(int(steps)):
        mid = 0.5 * (lo + hi)
        if share(float(np.exp(mid))) <= bound:
            lo = mid
        else:
            hi = mid
    return float(np.exp(lo))
