"""Derivatives of noisy coordinates (e.g. joint angles): what a lab does without a rate sensor.

Arrays are (n_channels, n_samples); a 1-D array is one channel.  Two estimators:
:func:`differentiate` (Savitzky-Golay, weights computed in a well-conditioned basis) and
:func:`lowpass_differentiate` (zero-phase low-pass, central differences, polynomial end bridges
and the filter's end transients read from the record),
whose cut-off :func:`harmonic_cutoff` can choose from the signal's band.
"""

from __future__ import annotations

import functools

import numpy as np

from testbed.numerics.filters import _as_signal, _check_cutoff, _lowpass_sos


def _local_poly_fit(window: int, polyorder: int) -> tuple[np.ndarray, float]:
    """The least-squares fit of a polynomial of order ``polyorder`` to a window of samples.

    Returns ``pinv`` of shape ``(polyorder + 1, window)`` (the Legendre coefficients of the fit
    are ``pinv @ x[:window]``) and the half width ``(window - 1) / 2`` [samples].  The abscissa is
    scaled to [-1, 1] and the fit is solved by QR: the monomials of raw sample offsets (what
    ``scipy.signal.savgol_coeffs`` uses) reach ``1500**8`` for a 3001-sample window and the fit
    loses every digit.
    """
    half = (window - 1) / 2.0
    z = (np.arange(window) - half) / half
    V = np.polynomial.legendre.legvander(z, polyorder)            # (window, p+1), cond ~ p
    Q, R = np.linalg.qr(V)
    return np.linalg.solve(R, Q.T), half                            # Legendre coefficients


def _derivative_rows(fit: tuple[np.ndarray, float], positions: np.ndarray, d: int,
                     out: np.ndarray | None = None) -> np.ndarray:
    """Weights of the ``d``-th derivative of the fit ``fit`` (:func:`_local_poly_fit`).

    Returns ``W`` of shape ``(len(positions), window)``: ``W[i] @ x[:window]`` is the ``d``-th
    derivative (per sample**d) at sample ``positions[i]`` of the polynomial fitted to the window.
    Written into ``out`` (C-contiguous, that shape) when given: a caller that needs several
    derivatives of many positions reuses one array instead of holding them all.
    """
    pinv, half = fit
    polyorder = pinv.shape[0] - 1
    zp = (np.asarray(positions, dtype=float) - half) / half
    E = np.polynomial.legendre.legvander(zp, polyorder)
    if d:
        E = np.stack([np.polynomial.legendre.legval(zp, np.polynomial.legendre.legder(
            np.eye(polyorder + 1)[k], d)) for k in range(polyorder + 1)], axis=1)
    out = np.matmul(E, pinv, out=out)
    return np.divide(out, half**d, out=out)


def _local_poly_rows(window: int, polyorder: int, positions: np.ndarray,
                     n_derivatives: int | None = None) -> np.ndarray:
    """Least-squares polynomial weights on a window of samples, in a well-conditioned basis.

    Returns ``W`` of shape ``(n_derivatives, len(positions), window)`` (``n_derivatives``
    defaults to ``polyorder + 1``, all of them): ``W[d, i] @ x[:window]`` is the ``d``-th
    derivative (per sample**d) at sample ``positions[i]`` of the polynomial of order
    ``polyorder`` fitted to the window (:func:`_local_poly_fit`, :func:`_derivative_rows`).
    """
    fit = _local_poly_fit(window, polyorder)
    n_derivatives = polyorder + 1 if n_derivatives is None else int(n_derivatives)
    out = np.empty((n_derivatives, np.size(positions), window))
    for d in range(n_derivatives):
        _derivative_rows(fit, positions, d, out=out[d])
    return out


def differentiate(x: np.ndarray, fs: float, window: int, polyorder: int
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Savitzky-Golay smoothing and first and second derivatives.

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        Noisy coordinate, e.g. joint angles [rad].
    fs : float
        Sample rate [Hz].
    window : int
        Window length [samples]; odd, greater than ``polyorder`` and at most ``n_samples``.
    polyorder : int
        Polynomial order of the local fit; at least 2 so that the second derivative exists.

    Returns
    -------
    xs : ndarray, shape (n_channels, n_samples)
        Smoothed ``x`` [unit of x].
    xd : ndarray, shape (n_channels, n_samples)
        First derivative [unit of x / s].
    xdd : ndarray, shape (n_channels, n_samples)
        Second derivative [unit of x / s^2].

    Notes
    -----
    The same local polynomial gives all three, so they are mutually consistent.  The ends use
    the polynomial fitted to the first/last window (scipy's ``mode="interp"``), which has no
    padding artefacts but is noisier over the last ``window // 2`` samples.

    The filter weights are computed here, not by ``scipy.signal.savgol_coeffs``: scipy fits
    monomials of the raw sample offsets, whose Vandermonde matrix is hopelessly ill-conditioned
    for long windows or high orders (scipy 1.17: the smoothing weights of window 3001, order 4
    or window 1001, order 6 sum to ~4e-12 instead of 1, so an angle of 1.8 rad came back as
    ~0, "wrong by 2 rad").  Here the abscissa is scaled to [-1, 1], the fit uses Legendre
    polynomials and QR (condition number of order ``polyorder``), and the channel mean is
    removed before filtering and added back (an exact step: the weights reproduce constants).
    """
    x = _as_signal(x)
    window, polyorder = int(window), int(polyorder)
    if window % 2 == 0 or window < 3:
        raise ValueError(f"Savitzky-Golay window must be odd and >= 3 samples, got {window}")
    if not 2 <= polyorder < window:
        raise ValueError(f"Savitzky-Golay polyorder must satisfy 2 <= polyorder < window ({window}), "
                         f"got {polyorder}")
    n = x.shape[-1]
    if window > n:
        raise ValueError(f"Savitzky-Golay window {window} exceeds the signal length {n}")
    half = window // 2
    mean = x.mean(axis=-1, keepdims=True)
    xc = x - mean
    fit = _local_poly_fit(window, polyorder)
    # the edge rows of one derivative at a time, in one reused (half, window) array: all of them
    # at once were (p+1, half, window), 957 MB resident for window 6001, order 4
    edge = np.empty((half, window))
    from scipy import signal as ss  # lazy: scipy.signal costs ~0.7 s of import

    out = []
    for d in (0, 1, 2):
        # correlation with the centre weights = convolution with the reversed weights
        centre = _derivative_rows(fit, np.array([half]), d)[0]                   # (window,)
        y = ss.oaconvolve(xc, centre[::-1][None, :] if xc.ndim == 2 else centre[::-1],
                          mode="same", axes=-1) if n > window else np.zeros_like(xc)
        _derivative_rows(fit, np.arange(half), d, out=edge)
        y[..., :half] = xc[..., :window] @ edge.T
        y[..., n - half:] = (xc[..., ::-1][..., :window] @ edge.T)[..., ::-1] * (-1) ** d
        y = y * fs**d
        out.append(y + mean if d == 0 else y)
    return out[0], out[1], out[2]


def _edge_jets(x: np.ndarray, fs: float, n_fit: int, order: int) -> tuple[np.ndarray, np.ndarray]:
    """Value, slope and curvature at the first and last sample from end-anchored polynomial fits.

    Returns two arrays of shape ``(3, n_channels)`` ([U], [U/s], [U/s^2]) for the start and
    the end of the record: the least-squares polynomial of order ``order`` over the first
    (last) ``n_fit`` samples, evaluated at the end sample.
    """
    W = _local_poly_rows(n_fit, order, np.array([0]), 3)[:, 0]                    # (3, n_fit)
    scale = np.array([1.0, fs, fs**2])[:, None]
    start = (W @ x[:, :n_fit].T) * scale
    end = (W @ x[:, ::-1][:, :n_fit].T) * scale * np.array([1.0, -1.0, 1.0])[:, None]
    return start, end


def _odd_about_zero(r: np.ndarray, pad: int) -> np.ndarray:
    """``r`` extended by ``pad`` samples at each end, point-symmetric about zero at its end samples.

    ``r[..., -k] = -r[..., k]`` (and alike at the far end): the odd reflection about the value
    zero, which the bridged remainder has at its ends to the edge fit's accuracy.  scipy's
    ``padtype="odd"`` reflects about the end SAMPLE instead (``2 r[0] - r[k]``), so the pad sits
    at twice that one sample's noise: a step of ``2 sigma`` the filter turns into a rate error
    lasting about ``1 / fc`` (3.7 % of the rate's std in the first second of the five-bar sine
    replay at 1 % noise and 0.8 Hz, 2 s edge fits: 0.9 % with this extension).

    Parameters
    ----------
    r : ndarray, shape (n_channels, n_samples)
    pad : int
        Samples added at each end (< n_samples).

    Returns
    -------
    ndarray, shape (n_channels, n_samples + 2 pad)
    """
    if pad == 0:
        return r
    return np.concatenate([-r[..., pad:0:-1], r, -r[..., -2:-pad - 2:-1]], axis=-1)


def _quintic_bridge(start: np.ndarray, end: np.ndarray, n: int, fs: float) -> np.ndarray:
    """Quintic per channel with the given value, slope, curvature at both ends of the record.

    Returns shape ``(3, n_channels, n)``: the quintic and its first two time derivatives.
    """
    T = (n - 1) / fs
    tau = np.arange(n) / (n - 1)
    basis = np.array([[1, 0, 0, -10, 15, -6], [0, 1, 0, -6, 8, -3], [0, 0, 0.5, -1.5, 1.5, -0.5],
                      [0, 0, 0, 10, -15, 6], [0, 0, 0, -4, 7, -3], [0, 0, 0, 0.5, -1, 0.5]])
    w = np.concatenate([start * np.array([1.0, T, T**2])[:, None],
                        end * np.array([1.0, T, T**2])[:, None]])              # (6, n_channels)
    coef = w.T @ basis                                                      # (n_channels, 6) in tau
    out = np.empty((3, coef.shape[0], n))
    for d in range(3):
        c = np.array([np.polynomial.polynomial.polyder(row, d) for row in coef])
        out[d] = np.array([np.polynomial.polynomial.polyval(tau, row) for row in c]) / T**d
    return out


#: An end transient's coefficient (:func:`_end_transients`) counts by
#: ``max(0, 1 - (TRANSIENT_Z s / |a|)^2)``, ``s`` the RMS of what the filter removed beyond the
#: transients (noise, quantisation, motion above the cut-off) weighed by the coefficient's own
#: column (``s^2 = sum_i q_i^2 e_i^2``: white noise of that local level gives a coefficient on
#: the unit vector ``q`` a std of ``s``), at least the whole record's, so 10 is 10 of those
#: stds.  Measured with the whole record's RMS for ``s`` (pi28; the column's weighing, review
#: 26a, equals it on white noise) with automatic cut-off and end fits, pi27's 104 records at 0.5-3 % angle
#: noise, 41 five-bars and 63 cart-poles): 100 bit-identical to the filter without the removal,
#: 4 five-bars at 0.5 % moved by at most 2.2e-3 of the accelerations' peak (fb20_chirp_2nm);
#: clean five-bars' largest |a| / s 278-9400.  At 3 (a least-squares coefficient's usual
#: significance) the noisy five-bars' accelerations moved by up to +30 % of their error
#: (fb14_base_1p49 0.5 %: 1.22 -> 1.59 % of RMS): a coefficient fitted to noise carries it at
#: the filter's corner, where the acceleration weighs it by ``(2 pi fc)^2``.
TRANSIENT_Z = 10.0


@functools.lru_cache(maxsize=4)
def _transient_basis(sos_bytes: bytes, sos_shape: tuple[int, int], n: int) -> np.ndarray:
    """Orthonormal basis of the forward-backward filter's end transients over ``n`` samples.

    The output of ``sosfiltfilt`` over the record depends on what lies beyond its ends (the
    pad) only through the forward pass's state at the first sample and the backward pass's
    state at the last: its free responses, the forward ones carried through the backward pass.
    Returns shape ``(n, k)``, ``k`` <= twice the filter's order (the columns' rank), read-only
    (cached per filter and length: a record's channels and a run's chains share it).
    Directions whose singular value is below 1e-10 of the largest are dropped: the columns'
    rank is twice the order of the filter's poles (an odd order's real pole gives one state
    less, its extra column a combination of the others at ~1e-14), and a direction that small
    carries 1e-10 of any transient's content, far below the record's float64 precision after
    the gain ``(2 pi fc)^2`` of the second derivative.
    """
    from scipy import signal as ss

    sos = np.frombuffer(sos_bytes, dtype=float).reshape(sos_shape).copy()
    m = 2 * sos.shape[0]
    zi = np.zeros((sos.shape[0], m, 2))
    zi[np.arange(m) // 2, np.arange(m), np.arange(m) % 2] = 1.0
    free, _ = ss.sosfilt(sos, np.zeros((m, n)), axis=-1, zi=zi)
    cols = np.concatenate([ss.sosfilt(sos, free[:, ::-1], axis=-1)[:, ::-1], free[:, ::-1]])
    cols = cols / np.linalg.norm(cols, axis=1, keepdims=True)
    u, sv, _ = np.linalg.svd(cols.T, full_matrices=False)
    q = u[:, sv > sv[0] * 1e-10]
    q.flags.writeable = False
    return q


def _end_transients(r: np.ndarray, ys: np.ndarray, sos: np.ndarray) -> np.ndarray:
    """The end transients of the low-passed ``ys`` that the record ``r`` itself determines.

    The pad (a reflection) is not the motion's continuation, and the filter turns the
    difference into transients that decay with the slowest pole's time constant ``0.81 /
    fc`` (order 8) from each end.  They lie in the span of :func:`_transient_basis`; their
    coefficients ``a`` are read by least squares from ``r - ys`` and each kept in proportion
    ``max(0, 1 - (TRANSIENT_Z s / |a|)^2)`` (continuous in the noise: no switch), ``s^2`` the
    mean square of ``r - ys`` beyond them weighed by the coefficient's column (where it
    lives: a step or kink near an end counts against the coefficients it would feed), at least
    the whole record's.

    Parameters
    ----------
    r, ys : ndarray, shape (n_channels, n_samples)
        Record before and after the low-pass [U].
    sos : ndarray, shape (n_sections, 6)
        The low-pass's second-order sections (one pass).

    Returns
    -------
    ndarray, shape (n_channels, n_samples)
        The correction to add to ``ys`` [U]; zero where ``r`` holds fewer samples than four
        times the basis' size.
    """
    n = r.shape[-1]
    if n < 8 * sos.shape[0] * 2:
        return np.zeros_like(ys)
    q = _transient_basis(sos.tobytes(), sos.shape, n)
    e = r - ys
    a = e @ q                                                    # (n_channels, k)
    # Each coefficient's noise variance: white noise of local variance s_i^2 gives a
    # coefficient on the unit vector q a variance of sum_i q_i^2 s_i^2, so the residual is
    # weighed where its column lives (a step or kink near an end, which the whole-record RMS
    # would dilute, counts against the coefficients it feeds: review 26a), and never below the
    # whole record's mean square (pi28's measured rule: where the ends are quieter than the
    # interior, the local weight alone kept more and the clean down-branch multisine's
    # SINDy-PI fit went 0.026 -> 0.096 rad)
    res2 = (e - a @ q.T) ** 2
    s2 = np.maximum(res2 @ (q**2), np.mean(res2, axis=-1, keepdims=True))  # (n_channels, k)
    with np.errstate(divide="ignore", invalid="ignore"):
        keep = np.where(a != 0, np.clip(1.0 - TRANSIENT_Z**2 * s2 / a**2, 0.0, 1.0), 0.0)
    return (keep * a) @ q.T


#: Harmonic of the band the low-pass must pass (:func:`harmonic_cutoff`): a mechanism's
#: kinematics (trig factors of the angles) and any feedback double the frequencies of the
#: motion, so its accelerations carry second harmonics of the angles' band.
CUTOFF_HARMONIC = 2.0
#: Smallest amplitude gain of the zero-phase filter over that harmonic: a 1 % loss there, where
#: the motion's acceleration keeps ~1e-4 of its energy (five-bar multisine), biases the
#: acceleration by well under 1 % of its RMS.
CUTOFF_GAIN = 0.99
#: Droop (1 - zero-phase amplitude gain) at that harmonic asked of the low-pass on clean angles:
#: with no noise to pass, the cut-off need not stop at ``1 - CUTOFF_GAIN`` (1 %).  The chain's
#: error is its transition band: after an identifier's column filter it reaches the rates as
#: a bias the library's conditioning amplifies into the coefficients, and a five-bar model must
#: hold them to about 1e-5 relative for 1e-4 rad (session 28, pi32: the true equations
#: perturbed by 1e-5 simulate 7e-7 - 3.6e-5 rad off), so the droop must lie far below 1e-5.
#: 1e-12: order 8, the cut-off
#: ``(1e-2 / 1e-12)^(1/16) = 4.22`` x the noisy rule's (on a 1.2 Hz band 13.5 Hz at 10 kHz,
#: far below ``AUTO_CUTOFF_MAX_SHARE fs``).  Measured (session 28, pi33, SINDy-PI's clean
#: chain-derived five-bars, angle RMSE within 1e-4 rad): the 30 held-out members of
#: ``benchmarks/heldout/fivebar_noise_validation.toml`` 19 at 1e-5 (session 27's value, 1.54 x),
#: 22 at 1e-6 (pi32), 28 / 29 / 30 / 29 at 1e-8 / 1e-10 / 1e-12 / 1e-14; every droop from 1e-8
#: to 1e-14 gains 9-11 of the 11 misses of 1e-5, the one or two left move from member to member
#: (``fbv41__001``: 5.1e-6 / 0.302 / 5.8e-5 / 3.2e-6 / 6.3e-5 / 0.318 rad from 1e-5 to 1e-14, a
#: knife edge not diagnosed).  1e-12, the best of that grid, read on the held-out members: the
#: rounds' 57 clean five-bars and 66 clean cart-poles are its second gate (docs/known-gaps.md).
CLEAN_DROOP = 1e-12
#: Relative noise (white-noise std / channel RMS about its mean) at or below which the clean
#: droop holds.  1e-5, the droop of session 27 it was equal to: not lowered with the droop,
#: since review 24d asks the cut-off not to move with noise this far below the motion
#: (0 - 1e-5 of RMS within one periodogram bin, ``test_auto_cutoff_is_continuous_in_the_noise_level``);
#: a record in 1e-12 - 1e-5 passes its noise up to 4.22 x the 99 % cut-off (accelerations'
#: noise ``~ fc^2.5``), what an 18-20-bit encoder would see: on 15 five-bars and cart-poles at
#: relative noise 1e-6 / 1e-5, within 1e-4 rad 11 -> 14 / 6 -> 8 against droop 1e-5, one lost at
#: 1e-5 (``cp23_L0p8`` 1.5e-5 -> 1.2e-4 rad; docs/known-gaps.md, session 28).
CLEAN_NOISE_REL = 1e-5
#: Relative noise from which the droop is ``1 - CUTOFF_GAIN`` unchanged (the rule measured on
#: 0.5-5 % noise): a tenth of the 1 % noise asked of the identifiers, which keeps the estimate
#: of the lowest noisy level studied (0.5 %) five-fold clear of it.
NOISY_NOISE_REL = 1e-3


def relative_noise(x: np.ndarray, sigma: np.ndarray) -> float:
    """Largest over channels of the white-noise std over the channel's RMS about its mean.

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        The record [U].
    sigma : ndarray, shape (n_channels,)
        White-noise std of each channel [U].

    Returns
    -------
    float
        The relative noise (0 on channels that do not move).
    """
    rms = np.std(x, axis=1)
    rel_ch = np.where(rms > 0, np.asarray(sigma, dtype=float) / np.where(rms > 0, rms, 1.0), 0.0)
    return float(rel_ch.max(initial=0.0))


def noise_weight(noise_rel: float) -> float:
    """Weight of the noisy rule, from the relative noise: 0 at or below ``CLEAN_NOISE_REL``, 1
    at or above ``NOISY_NOISE_REL`` (and for a NaN level: the noisy rule is the safe one),
    linear in ``log(noise_rel)`` between, so that nothing the chain or an identifier chooses
    from it jumps with the noise level.

    Parameters
    ----------
    noise_rel : float
        Largest over channels of the white-noise std over the channel's RMS about its mean.

    Returns
    -------
    float
        In [0, 1].
    """
    rel = float(noise_rel)
    if not rel < NOISY_NOISE_REL:
        return 1.0
    if rel <= CLEAN_NOISE_REL:
        return 0.0
    return float(np.log(rel / CLEAN_NOISE_REL) / np.log(NOISY_NOISE_REL / CLEAN_NOISE_REL))


def harmonic_droop(noise_rel: float) -> float:
    """The droop ``1 -`` gain that :func:`harmonic_cutoff` asks at the harmonic, from the
    relative noise: ``CLEAN_DROOP^(1 - w) (1 - CUTOFF_GAIN)^w``, ``w`` = :func:`noise_weight`:
    ``CLEAN_DROOP`` on clean angles, ``1 - CUTOFF_GAIN`` from ``NOISY_NOISE_REL`` up, geometric
    between (the cut-off then moves by a constant factor per decade of noise).  Carried as a
    droop, not a gain: ``1 - (1 - 1e-12)`` is 8.9e-5 relative off in double precision.

    Parameters
    ----------
    noise_rel : float
        Relative noise, as :func:`noise_weight`.

    Returns
    -------
    float
        Droop in (0, 1).
    """
    w = noise_weight(noise_rel)
    if w >= 1.0:
        return float(1.0 - CUTOFF_GAIN)
    return float(CLEAN_DROOP ** (1.0 - w) * (1.0 - CUTOFF_GAIN) ** w)


def harmonic_gain(noise_rel: float) -> float:
    """The zero-phase gain :func:`harmonic_cutoff` asks at the harmonic, from the relative noise:
    ``1 -`` :func:`harmonic_droop` (exactly ``CUTOFF_GAIN`` from ``NOISY_NOISE_REL`` up).  Where
    the droop is far below 1 the gain loses its digits (at 1e-12, 9e-5 relative): pass
    :func:`harmonic_droop` itself (``harmonic_cutoff(droop=)``).  The chain's automatic cut-off
    (``testbed.pipeline.signal_chain.auto_cutoff``) still passes the gain: switching it moves
    the clean cut-off by 5.6e-6 relative, a data change not yet measured on the gate.

    Parameters
    ----------
    noise_rel : float
        Relative noise, as :func:`noise_weight`.

    Returns
    -------
    float
        Gain in (0, 1).
    """
    if noise_weight(noise_rel) >= 1.0:
        return CUTOFF_GAIN
    return float(1.0 - harmonic_droop(noise_rel))


def harmonic_cutoff(band_hz: float, order: int, harmonic: float = CUTOFF_HARMONIC,
                    gain: float = CUTOFF_GAIN, *, droop: float | None = None) -> float:
    """Lowest -3 dB cut-off of a zero-phase Butterworth that passes ``harmonic x band_hz``.

    The forward-backward filter's amplitude gain is ``1 / (1 + (f / fc)^(2 order))``; the
    cut-off is where that gain equals ``gain`` at ``f = harmonic * band_hz``:
    ``fc = harmonic band_hz / (1 / gain - 1)^(1 / (2 order))``.  Order 8, band 1.5 Hz (the
    five-bar multisine's 99.9 % band): 4.0 Hz.  Any higher cut-off only passes more noise,
    whose share of the second derivative grows as ``fc^5``.

    Parameters
    ----------
    band_hz : float
        Band of the signal [Hz] (e.g. :func:`testbed.numerics.noise.signal_band`), > 0.
    order : int
        Butterworth order of one pass (>= 1).
    harmonic : float
        Multiple of the band that must pass (>= 1).
    gain : float
        Least amplitude gain of the zero-phase filter there, in (0, 1).
    droop : float, optional
        ``1 - gain`` given as such, in (0, 1) (then ``gain`` is not read): ``1 / gain - 1`` is
        taken as ``droop / (1 - droop)``, exact where the droop is far below 1
        (:func:`harmonic_droop`).

    Returns
    -------
    float
        Cut-off [Hz].
    """
    if not band_hz > 0:
        raise ValueError(f"band must be positive, got {band_hz}")
    if droop is not None:
        if not 0 < droop < 1:
            raise ValueError(f"need 0 < droop < 1; got {droop}")
        ratio = droop / (1.0 - droop)
    else:
        if not 0 < gain < 1:
            raise ValueError(f"need 0 < gain < 1; got {gain}")
        ratio = 1.0 / gain - 1.0
    if int(order) < 1 or not harmonic >= 1:
        raise ValueError(f"need order >= 1, harmonic >= 1; got {order}, {harmonic}")
    return float(harmonic * band_hz / ratio ** (1.0 / (2 * int(order))))


def lowpass_differentiate(x: np.ndarray, fs: float, cutoff_hz: float, order: int = 8,
                          edge_fit_s: float = 0.1, edge_fit_order: int = 5
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Zero-phase Butterworth low-pass, then central differences: x, dx/dt, d2x/dt2.

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        Noisy coordinate, e.g. joint angles [rad], sampled far above its band.
    fs : float
        Sample rate [Hz].
    cutoff_hz : float
        -3 dB frequency of one pass [Hz] (-6 dB after forward-backward), in (0, fs/2); put it
        just above the band of the motion.
    order : int
        Butterworth order of one pass.
    edge_fit_s : float
        Length [s] of the end windows whose polynomial fits anchor the record's ends (below).
    edge_fit_order : int
        Order of those fits (>= 2).

    Returns
    -------
    xs, xd, xdd : ndarray, shape (n_channels, n_samples)
        Filtered ``x`` [U], its first [U/s] and second [U/s^2] derivatives.

    Notes
    -----
    Differentiation commutes with the (linear, time-invariant) filter, so the three outputs
    are the low-passed true signal and derivatives plus the low-passed noise.  Against
    Savitzky-Golay the Butterworth has a flat pass band and a stop band that falls as
    ``f^-2 order``, so white noise contributes to the second derivative only
    ``sigma^2 (2 pi)^4 fc^5 / (5 fs / 2)``; on the five-bar multisine record (motion below
    ~3 Hz, fs 10 kHz, 1 % angle noise) that is 0.6-0.9 % of the acceleration RMS at 4 Hz against
    9 % for a 0.1 s quadratic Savitzky-Golay filter.  Central differences (``np.gradient``) are
    exact to ``(2 pi f / fs)^2 / 6`` (2e-6 at 5 Hz, 10 kHz).

    Ends.  A record cut mid-motion cannot be padded by reflection without a kink: an odd
    reflection keeps value and slope but flips the curvature, and the filter smears that kink
    into a velocity error ``~ a(0) / (2 pi fc)`` (0.02 rad/s on the five-bar at 4 Hz).  So a
    quintic "bridge" with the value, slope and curvature of polynomial fits over the first and
    last ``edge_fit_s`` is subtracted first and its exact derivatives added back afterwards: the
    remainder starts and ends with zero value, slope and curvature to the fit's accuracy, its
    odd reflection about zero (:func:`_odd_about_zero`; not about the noisy end sample) is
    smooth to the third derivative, and the filter (padded by ``8 / fc``, the Butterworth's
    settling time) is nearly exact up to the ends.  Measured on the noise-free five-bar record
    at 4 Hz: rate error at the ends 2-2.5e-3 rad/s (without the bridge 0.02).  On noisy data
    the fits' noise makes the ends noisier than the interior for about ``1 / fc``: their
    curvature's noise falls as ``edge_fit_s^-2.5`` while their misfit of the motion grows with
    ``edge_fit_s fc`` (see ``signal_chain.EDGE_FIT_PERIODS`` for the rule that balances them).
    Even a smooth pad is not the motion's continuation: the filter leaves a transient at each
    end decaying with its slowest pole (``0.81 / fc`` per e-fold at order 8), which the record
    determines and :func:`_end_transients` removes where it stands clear of what the filter
    removed (noise): clean round 22 down-branch multisine at 6.8 Hz, accelerations' error in
    the first and last 0.2 s 9.7e-3 -> 2.3e-5 of RMS (interior 6.6e-6); records at 0.5-1 % noise
    unchanged (``TRANSIENT_Z``).
    """
    x = _as_signal(x)
    one = x.ndim == 1
    x2 = np.atleast_2d(x)
    _check_cutoff(cutoff_hz, fs, "low-pass")
    if int(order) < 1:
        raise ValueError(f"filter order must be >= 1, got {order}")
    n = x2.shape[-1]
    n_fit = round(edge_fit_s * fs)
    if not 2 <= int(edge_fit_order) < n_fit <= n:
        raise ValueError(f"edge fit of order {edge_fit_order} over {n_fit} samples: need "
                         f"2 <= order < samples <= {n}")
    start, end = _edge_jets(x2, fs, n_fit, int(edge_fit_order))
    bridge = _quintic_bridge(start, end, n, fs)
    from scipy import signal as ss  # lazy: scipy.signal costs ~0.7 s of import

    sos = _lowpass_sos(fs, cutoff_hz, order)
    pad = min(n - 1, round(8.0 / cutoff_hz * fs))
    r = x2 - bridge[0]
    ys = ss.sosfiltfilt(sos, _odd_about_zero(r, pad), axis=-1, padtype=None)[..., pad:pad + n]
    ys = ys + _end_transients(r, ys, sos)
    yd = np.gradient(ys, 1.0 / fs, axis=-1, edge_order=2)
    ydd = np.gradient(yd, 1.0 / fs, axis=-1, edge_order=2)
    out = (ys + bridge[0], yd + bridge[1], ydd + bridge[2])
    return tuple(o[0] for o in out) if one else out
