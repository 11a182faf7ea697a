"""Spectra of measured signals, and natural frequencies read from their peaks.

This is how an identifier obtains "measured natural frequencies": from the data, the way a
lab reads them off an FFT, never from the truth.
"""

from __future__ import annotations

import numpy as np

from testbed.core.lazy import lazy_module

sfft = lazy_module("scipy.fft")  # imported on first use: `testbed list` does not pay for it

# Half-width of each window's main lobe in bins of the unpadded transform: peaks closer than
# this are one lobe, not two modes.
_MAIN_LOBE_BINS = {"boxcar": 1.0, "rectangular": 1.0, "hann": 2.0, "hamming": 2.0,
                   "blackman": 3.0, "flattop": 5.0}


def fft_resolution(n: int, fs: float) -> float:
    """Frequency spacing of an ``n``-point DFT [Hz].

    Parameters
    ----------
    n : int
        Number of samples (record length ``n / fs`` [s]).
    fs : float
        Sample rate [Hz].

    Returns
    -------
    float
        ``fs / n`` [Hz], the inverse of the record length.
    """
    if n < 1 or not fs > 0:
        raise ValueError(f"need n >= 1 and fs > 0, got n={n}, fs={fs}")
    return fs / n


def amplitude_spectrum(x: np.ndarray, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """Single-sided amplitude spectrum (rectangular window).

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        Signal in any unit ``[U]``; a 1-D array is one channel.
    fs : float
        Sample rate [Hz].

    Returns
    -------
    freqs : ndarray, shape (n_samples // 2 + 1,)
        Frequencies [Hz].
    amp : ndarray, shape (n_channels, n_samples // 2 + 1)
        Amplitude [U]: a sine of amplitude A on a bin frequency gives A at that bin; the DC
        (and, for even n, the Nyquist) line is the mean (the alternating component) itself.
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    n = x.shape[-1]
    amp = np.abs(sfft.rfft(x, axis=-1)) / n
    amp[:, 1:(n + 1) // 2] *= 2.0
    return sfft.rfftfreq(n, 1.0 / fs), amp


def peak_frequencies(x: np.ndarray, fs: float, n_peaks: int, fmin: float = 0.0,
                     fmax: float | None = None, window: str = "boxcar", pad: int = 4,
                     min_prominence_db: float = 6.0, dynamic_range_db: float = 40.0,
                     min_rel_separation: float = 0.0) -> np.ndarray:
    """Natural frequencies from the peaks of the summed power spectrum of measured signals.

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        Measured responses (e.g. free-decay accelerations); a 1-D array is one channel.
    fs : float
        Sample rate [Hz].
    n_peaks : int
        Number of frequencies wanted.
    fmin, fmax : float
        Search band [Hz]; ``fmax=None`` means the Nyquist frequency.
    window : str
        ``scipy.signal.get_window`` name.  The default ``"boxcar"`` suits the free decay after
        an impact: the transient dies within the record (no leakage) and is largest at its
        start, which a Hann window would suppress (a fast-decaying high mode then vanishes).
        Use ``"hann"`` for steady (e.g. sine or random) responses.
    pad : int
        Zero-padding factor: the transform length is at least ``pad * n_samples``; it
        interpolates the spectrum (resolution stays ``fs / n_samples``).
    min_prominence_db : float
        A candidate must rise at least this much [dB] above its surroundings
        (``scipy.signal.find_peaks`` prominence on the dB spectrum), so noise ripples do
        not count.
    dynamic_range_db : float
        Candidates more than this [dB] below the highest one are dropped.
    min_rel_separation : float
        Keep only the highest of candidates closer than this fraction of their frequency
        (0 = off): the peak of a nonlinear mode, whose frequency drifts as it decays, smears
        into neighbouring maxima.

    Returns
    -------
    ndarray, shape (n_peaks,)
        Frequencies [Hz], ascending.  Each is the highest power among candidates, refined by a
        parabola through the peak bin and its neighbours on the dB spectrum.

    Raises
    ------
    ValueError
        If fewer than ``n_peaks`` peaks are found in the band, or the band is empty.

    Notes
    -----
    The channel power spectra are summed, so a mode with a node at one sensor still shows at
    the others.  Candidates closer than the window's main-lobe half-width plus two bins (of the
    unpadded transform) are merged, keeping the higher: the first two side lobes of a steady
    sine are not taken for modes, and with ``dynamic_range_db = 40`` the further Hann side
    lobes (below -46 dB) are dropped too.  Two modes closer than that (4 bins, ``4 fs / n`` Hz,
    for Hann) are not resolved.  Among the remaining candidates the ``n_peaks`` highest are
    chosen, not the most prominent: side lobes sit between deep nulls and can be very
    prominent.  A rectangular window's side lobes (-13 dB, 6 dB per octave) survive these
    rules, so use it only for transients that decay within the record.  Asking for more peaks
    than the signal has modes returns noise peaks or side lobes, or raises.
    """
    n_peaks = int(n_peaks)
    if n_peaks < 1:
        raise ValueError(f"n_peaks must be >= 1, got {n_peaks}")
    if int(pad) < 1:
        raise ValueError(f"pad must be >= 1, got {pad}")
    freqs, _ = peak_candidates(x, fs, fmin, fmax, window, pad, min_prominence_db, dynamic_range_db,
                               min_rel_separation)
    if freqs.size < n_peaks:
        sep = f", at least {min_rel_separation:.0%} apart," if min_rel_separation > 0 else ""
        hi = fs / 2.0 if fmax is None else fmax
        raise ValueError(f"found {freqs.size} spectral peak(s) with prominence >= {min_prominence_db} dB "
                         f"within {dynamic_range_db} dB of the highest{sep} in [{fmin:g}, {hi:g}] Hz, "
                         f"asked for {n_peaks}")
    return np.sort(freqs[:n_peaks])  # candidates come strongest first


def peak_candidates(x: np.ndarray, fs: float, fmin: float = 0.0, fmax: float | None = None,
                    window: str = "boxcar", pad: int = 4, min_prominence_db: float = 6.0,
                    dynamic_range_db: float = 40.0, min_rel_separation: float = 0.0
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Every spectral peak :func:`peak_frequencies` chooses from, with its power (the one
    implementation of the peak rules: that function takes the strongest of these).

    Parameters
    ----------
    x, fs, fmin, fmax, window, pad, min_prominence_db, dynamic_range_db, min_rel_separation
        As :func:`peak_frequencies`.

    Returns
    -------
    freqs : ndarray, shape (k,)
        Candidate frequencies [Hz] (parabolic refinement), strongest first; k may be 0.
    power_db : ndarray, shape (k,)
        Summed channel power of each [dB, relative to the strongest candidate].
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    n = x.shape[-1]
    nyq = fs / 2.0
    fmax = nyq if fmax is None else float(fmax)
    if not 0.0 <= fmin < fmax <= nyq:
        raise ValueError(f"need 0 <= fmin < fmax <= Nyquist ({nyq:g} Hz), got fmin={fmin}, fmax={fmax}")
    from scipy import signal as ss  # lazy: scipy.signal costs ~0.7 s of import

    w = ss.get_window(window, n, fftbins=True)
    nfft = sfft.next_fast_len(int(pad) * n, real=True)
    power = (np.abs(sfft.rfft((x - x.mean(axis=-1, keepdims=True)) * w, n=nfft, axis=-1)) ** 2).sum(0)
    freqs = sfft.rfftfreq(nfft, 1.0 / fs)
    floor = power.max() * 1e-30 if power.max() > 0 else 1e-300
    db = 10.0 * np.log10(power + floor)
    band = np.flatnonzero((freqs >= fmin) & (freqs <= fmax))
    if band.size < 3:
        return np.empty(0), np.empty(0)
    lo, hi = band[0], band[-1] + 1
    lobe = (_MAIN_LOBE_BINS.get(window, 2.0) + 2.0) * nfft / n
    idx, _ = ss.find_peaks(db[lo:hi], prominence=min_prominence_db, distance=max(1.0, lobe))
    idx = idx + lo
    if idx.size:
        idx = idx[db[idx] >= db[idx].max() - dynamic_range_db]
    idx = idx[np.argsort(power[idx])[::-1]]
    if min_rel_separation > 0 and idx.size:
        kept: list[int] = []
        for k in idx:
            if all(abs(freqs[k] - freqs[j]) > min_rel_separation * freqs[j] for j in kept):
                kept.append(k)
        idx = np.asarray(kept, dtype=int)
    df = freqs[1] - freqs[0]
    out = np.empty(idx.size)
    for i, k in enumerate(idx):
        a, b, c = db[k - 1], db[k], db[min(k + 1, len(db) - 1)]
        den = a - 2.0 * b + c
        p = 0.5 * (a - c) / den if den != 0 else 0.0
        out[i] = freqs[k] + float(np.clip(p, -0.5, 0.5)) * df
    top = db[idx].max() if idx.size else 0.0
    return out, db[idx] - top


def harmonic_amplitude_law(x: np.ndarray, fs: float, f_fund: float, k: int, n_segments: int = 8,
                           search: float = 0.15, rel_halfwidth: float = 0.03
                           ) -> tuple[float, float, float]:
    """How a candidate harmonic at ``k`` times a fundamental follows that fundamental.

    The record is cut into ``n_segments`` equal segments (Hann window, 4x zero padding).  In
    each, the fundamental is the strongest line within ``f_fund (1 +- search)``
    (its frequency ``f_s`` and amplitude ``A_s``: a hardening mode's frequency falls as it
    decays), and the candidate's amplitude ``B_s`` is the strongest line within
    ``k f_s (1 +- rel_halfwidth)``, i.e. it is tracked at ``k`` times the fundamental's
    *instantaneous* frequency.

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        Free-decay signals.
    fs : float
        Sample rate [Hz].
    f_fund : float
        Fundamental's peak frequency over the whole record [Hz].
    k : int
        Harmonic order (2 or 3).
    n_segments : int
        Segments; each resolves ``n_segments fs / n_samples`` [Hz].
    search, rel_halfwidth : float
        Relative half-widths of the fundamental's and the harmonic's search bands.

    Returns
    -------
    slope : float
        Least-squares slope of ``log B_s`` against ``log A_s``: ``k`` for a harmonic generated
        by a polynomial restoring force (``B ~ A^k``); ``sigma_c / sigma_f`` (the decay rates'
        ratio) for an independent mode.
    drift : float
        Relative change of the fundamental's frequency from the first to the last segment,
        ``(f_first - f_last) / f_last`` (0 for a linear mode, > 0 for a hardening one).
    line : float
        Spacing of the segments' (padded) spectral lines relative to ``f_last``: a drift of a
        line or two is the resolution, not the structure.
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    n = x.shape[-1]
    seg = n // int(n_segments)
    nfft = sfft.next_fast_len(4 * seg, real=True)
    f_axis = sfft.rfftfreq(nfft, 1.0 / fs)
    # Hann window per segment: a rectangular one leaks the fundamental's side lobes (-36 dB
    # twenty lines away) over a harmonic that has decayed three times faster, and flattened
    # the measured law (slope 1.5 instead of 3 on an exact A^3 harmonic)
    w = np.hanning(seg + 2)[1:-1]
    la, lb, fs_seg = [], [], []
    for s in range(int(n_segments)):
        z = x[:, s * seg:(s + 1) * seg]
        p = (np.abs(sfft.rfft((z - z.mean(axis=-1, keepdims=True)) * w, n=nfft, axis=-1)) ** 2).sum(0)
        sel = np.flatnonzero((f_axis >= f_fund * (1 - search)) & (f_axis <= f_fund * (1 + search)))
        if sel.size == 0:
            return float("nan"), float("nan"), float("nan")
        j = sel[np.argmax(p[sel])]
        fj = f_axis[j]
        lo_h, hi_h = k * fj * (1 - rel_halfwidth), k * fj * (1 + rel_halfwidth)
        hs = np.flatnonzero((f_axis >= lo_h) & (f_axis <= hi_h))
        if hs.size == 0:
            return float("nan"), float("nan"), float("nan")
        la.append(0.5 * np.log(max(p[j], 1e-300)))
        lb.append(0.5 * np.log(max(p[hs].max(), 1e-300)))
        fs_seg.append(fj)
    la, lb = np.asarray(la), np.asarray(lb)
    da = la - la.mean()
    slope = float(da @ (lb - lb.mean()) / (da @ da)) if da @ da > 0 else float("nan")
    return slope, float((fs_seg[0] - fs_seg[-1]) / fs_seg[-1]), float((f_axis[1] - f_axis[0]) / fs_seg[-1])


def band_trim(fs: float, f: float, rel_band: float) -> int:
    """Samples dropped at a demodulated band's end, where its cut rings: ``1 / (rel_band f)``
    s at ``fs`` [Hz], rounded up (:func:`harmonic_lock`, :func:`own_lock`,
    :func:`band_power_fall`, :func:`noise_lock_bar`)."""
    return int(np.ceil(fs / (rel_band * f)))


def band_analytic(x: np.ndarray, fs: float, lo: float, hi: float,
                  weights: np.ndarray | None = None) -> np.ndarray:
    """Analytic signal of the band ``[lo, hi]`` of ``x``, channels combined by ``weights``.

    The band is cut out of the record's transform (a one-sided brick wall, so the result is
    the analytic signal of the band-limited part: its modulus is the envelope, its unwrapped
    angle the phase [rad]).

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        Signals (mean removed here).
    fs : float
        Sample rate [Hz].
    lo, hi : float
        Band edges [Hz], ``0 <= lo < hi``.
    weights : ndarray, shape (n_channels,), optional
        Complex channel weights (e.g. the conjugate of a deflection shape, which adds the
        channels in phase); default every channel by 1.

    Returns
    -------
    ndarray, shape (n_samples,), complex
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    n = x.shape[-1]
    spec = sfft.fft(x - x.mean(axis=-1, keepdims=True), axis=-1)
    f = sfft.fftfreq(n, 1.0 / fs)
    spec[:, ~((f >= lo) & (f <= hi))] = 0.0
    z = sfft.ifft(2.0 * spec, axis=-1)
    w = np.ones(x.shape[0]) if weights is None else np.asarray(weights)
    return w @ z


def harmonic_lock(x: np.ndarray, fs: float, f_fund: float, f_cand: float, k: int,
                  w_fund: np.ndarray, w_cand: np.ndarray, rel_band: float = 1.0 / 3.0) -> float:
    """How firmly a candidate at ``k`` times a fundamental keeps ``k`` times its phase.

    Both are demodulated (:func:`band_analytic`, bands ``f (1 +- rel_band)``, channels added in
    phase by the conjugate deflection shapes), and ``1 / (rel_band f_fund)`` s (three periods,
    twice the fundamental band's impulse response) are dropped at each end, where the band's
    cut rings.  A harmonic is driven by the fundamental's motion, so its phase is ``k`` times the
    fundamental's plus the structure's lag at ``k f``: ``psi = phi_c - k phi_p`` stays put.  A
    mode rings at its own frequency: ``psi`` turns by ``2 pi delta T`` over ``T`` s when it is
    ``delta`` Hz from ``k f``.

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        Free-decay signals.
    fs : float
        Sample rate [Hz].
    f_fund, f_cand : float
        Peak frequencies [Hz] of the fundamental and the candidate.
    k : int
        Harmonic order.
    w_fund, w_cand : ndarray, shape (n_channels,), complex
        Deflection shapes of the two peaks (their conjugates weight the channels).
    rel_band : float
        Relative half-width of the demodulation bands; 1/3 makes the fundamental's band and
        its second harmonic's touch (``f (1 + 1/3) = 2 f (1 - 1/3)``).

    Returns
    -------
    float
        Mean resultant length of ``psi`` [-], weighted by ``|z_c| |z_p|^k`` (where the harmonic
        is strong): 1 for a fixed ``psi``, ``|sinc(delta T)|`` for a steady mode ``delta`` Hz
        off, ``2 / pi`` for a ``psi`` spread evenly over pi rad; NaN if nothing is left after
        the ends are dropped.
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    zp = band_analytic(x, fs, f_fund * (1 - rel_band), f_fund * (1 + rel_band), np.conj(w_fund))
    zc = band_analytic(x, fs, f_cand * (1 - rel_band), f_cand * (1 + rel_band), np.conj(w_cand))
    trim = band_trim(fs, f_fund, rel_band)
    zp, zc = zp[trim:x.shape[-1] - trim], zc[trim:x.shape[-1] - trim]
    # zc conj(zp)^k has angle psi and modulus |z_c| |z_p|^k
    prod = zc * np.conj(zp) ** int(k)
    tot = np.abs(prod).sum()
    return float(np.abs(prod.sum()) / tot) if tot > 0 else float("nan")


def own_lock(x: np.ndarray, fs: float, f: float, shape: np.ndarray, rel_band: float = 1.0 / 3.0
             ) -> float:
    """How firmly a peak rings at its own frequency [-].

    The channels, added in phase by the conjugate deflection shape, are demodulated in the band
    ``f (1 +- rel_band)`` (:func:`band_analytic`; ``1 / (rel_band f)`` s dropped at each end,
    where the band's cut rings, as :func:`harmonic_lock` does), and the phase of
    ``z(t) exp(-2 pi i f t)`` is averaged, weighted by ``|z|``.

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        Free-decay signals.
    fs : float
        Sample rate [Hz].
    f : float
        Peak frequency [Hz].
    shape : ndarray, shape (n_channels,), complex
        Its deflection shape across the channels (complex amplitudes at ``f``).
    rel_band : float
        Relative half-width of the demodulation band.

    Returns
    -------
    float
        Mean resultant length: ``|sinc(delta T)|`` for a mode ringing ``delta`` Hz from ``f``
        (about 1 at a refined peak), about ``1 / sqrt(2 rel_band f T)`` for noise over ``T``
        s; NaN if nothing is left after the ends are dropped.
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    z = band_analytic(x, fs, f * (1 - rel_band), f * (1 + rel_band), np.conj(shape))
    trim = band_trim(fs, f, rel_band)
    z = z[trim:x.shape[-1] - trim]
    tot = np.abs(z).sum()
    t = (trim + np.arange(z.size)) / fs
    return float(np.abs((z * np.exp(-2j * np.pi * f * t)).sum()) / tot) if tot > 0 else float("nan")


def band_power_fall(x: np.ndarray, fs: float, f: float, shape: np.ndarray, start: int,
                    rel_band: float = 1.0 / 3.0, k: float = 3.0) -> tuple[float, float]:
    """How much a peak's band loses of its power over the window ``x[:, start:]``, and the most
    white noise alone shows.

    The band ``f (1 +- rel_band)`` is cut from the whole record (:func:`band_analytic`, the
    channels added in phase by the conjugate deflection shape), so the window's start is no
    cut and a mode that decays within a few of its periods keeps its power there; the last
    ``1 / (rel_band f)`` s, where the brick wall's wrap rings, are dropped.  The ratio is the
    mean squared envelope of the window's first half over its second half: a mode's response
    decays (measured on round 22 and the families' beams: 4.6-257), stationary noise's stays
    near 1 (round 22's magnesium at 5 %: 1.04-1.24).  Over ``m = 2 rel_band f T / 2``
    independent complex samples a half's mean has a relative spread ``1 / sqrt(m)``, their
    ratio about ``sqrt(2 / m)``, so noise stays below ``1 + k sqrt(2 / m)`` but for a chance of
    about 1e-2 at ``k`` = 3 (not the normal tail's 1e-3: the ratio of two means of squared
    Gaussian envelopes is F(2m, 2m)-distributed, right-skewed; measured 0.9 % of 4000 draws at
    m = 54.7, F's tail 9.2e-3, review 23f; 9 % at m = 2.5, where the test has little power).
    A bar at the F quantile is the sharper statement, left for a measured change: it keeps
    round 22's documented outcomes (171.1 Hz at 1.14 under 1.77,
    489.6 Hz at 1.48 over 1.41).

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        The whole record (not only its window).
    fs : float
        Sample rate [Hz].
    f : float
        Peak frequency [Hz], > 0.
    shape : ndarray, shape (n_channels,), complex
        Its deflection shape across the channels.
    start : int
        The window's first sample.
    rel_band, k : float
        Relative half-width of the band; standard deviations of noise's ratio.

    Returns
    -------
    ratio, bar : float
        The first half's power over the second's [-], and noise's bar ``1 + k sqrt(2 / m)``;
        NaN and inf where the window keeps fewer than two samples.
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    z = band_analytic(x, fs, f * (1.0 - rel_band), f * (1.0 + rel_band), np.conj(shape))[int(start):]
    z = z[: max(z.size - band_trim(fs, f, rel_band), 0)]
    h = z.size // 2
    if h < 1:
        return float("nan"), float("inf")
    late = float(np.mean(np.abs(z[h:2 * h]) ** 2))
    ratio = float(np.mean(np.abs(z[:h]) ** 2)) / late if late > 0 else float("inf")
    m = 2.0 * rel_band * f * h / fs
    return ratio, float(1.0 + k * np.sqrt(2.0 / m))


def noise_lock_bar(f: float, fs: float, n_samples: int, rel_band: float = 1.0 / 3.0,
                   k: float = 3.0) -> float:
    """The :func:`own_lock` that white noise alone passes with a chance of about 1e-3 (``k`` 3).

    :func:`own_lock` keeps ``n = 2 rel_band f T`` independent complex samples of its band
    (``T`` [s] the window after its ends, ``1 / (rel_band f)`` s each, are dropped); the mean
    resultant length of ``n`` random phasors exceeds ``r`` with probability about
    ``exp(-n r^2)`` (Rayleigh), so noise stays below ``k / sqrt(n)``.  Measured (white noise on
    two channels, 1.8 kHz, 1760 samples, 171 and 508 Hz, 400 draws each): the weights and the
    band's overlap leave about ``0.78 n`` of them, the chance 0.45-0.49 at ``k`` = 1 and
    0.035-0.048 at 2, so about 1e-3 at 3.

    Parameters
    ----------
    f : float
        Peak frequency [Hz], > 0.
    fs : float
        Sample rate [Hz].
    n_samples : int
        Samples of the window :func:`own_lock` is given.
    rel_band, k : float
        :func:`own_lock`'s relative half-width of the band; standard deviations of noise's lock.

    Returns
    -------
    float
        The bar ``k / sqrt(n)`` [-]; ``inf`` where the window keeps nothing.
    """
    trim = band_trim(fs, f, rel_band)
    n = 2.0 * rel_band * f * (int(n_samples) - 2 * trim) / fs
    return float(k / np.sqrt(n)) if n > 0 else float("inf")
