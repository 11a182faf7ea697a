"""The signal chain against signals whose integrals and derivatives are known exactly."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest
from scipy import signal as ss

from testbed.numerics import derivatives as der
from testbed.numerics import filters as sig

FS = 12800.0  # the paper's sample rate [Hz]
MODES = ((89.6, 0.01, 1e-4), (576.3, 0.01, 1e-5))  # (f [Hz], zeta, amplitude [m]): the paper's beam
T0, TR = 0.1, 0.002  # onset time and rise time [s] of the smooth start


def decay_from_rest(t: np.ndarray, n_channels: int = 2):
    """Sum of decaying sines times a smooth onset g = (1 - exp(-tau/TR))^3, with exact derivatives.

    g, g', g'' vanish at the onset, so the motion starts from rest like an impact response
    and integrating the exact acceleration from t = 0 needs no integration constants.
    """
    tau = np.maximum(t - T0, 0.0)
    on = t > T0
    e = np.exp(-tau / TR)
    q = 1.0 - e
    g, g1, g2 = q**3 * on, 3 * q**2 * e / TR * on, (6 * q * e**2 - 3 * q**2 * e) / TR**2 * on
    d, v, a = (np.zeros((n_channels, t.size)) for _ in range(3))
    for ch in range(n_channels):
        for k, (f, z, amp) in enumerate(MODES):
            w = 2 * np.pi * f
            s = -z * w + 1j * w * np.sqrt(1 - z * z)
            ex = amp * (1 + ch) * (-1) ** (k * ch) * np.exp(s * tau)
            s0, s1, s2 = ex.imag, (s * ex).imag, (s * s * ex).imag
            d[ch] += g * s0
            v[ch] += g1 * s0 + g * s1
            a[ch] += g2 * s0 + 2 * g1 * s1 + g * s2
    return d, v, a


def trapezoid_bias(f: float, fs: float) -> float:
    """Relative amplitude loss of one trapezoid integration at f: 1 - x / tan x, x = pi f / fs."""
    x = np.pi * f / fs
    return 1.0 - x / np.tan(x)


def rel_err(got: np.ndarray, ref: np.ndarray) -> np.ndarray:
    return np.abs(got - ref).max(axis=-1) / np.abs(ref).max(axis=-1)


def test_trapezoid_exact_on_linear_and_starts_at_zero():
    t = np.arange(1000) / FS
    x = np.stack([np.full_like(t, 3.0), 2.0 * t])
    y = sig.trapezoid(x, FS)
    assert y.shape == x.shape and np.all(y[:, 0] == 0.0)
    np.testing.assert_allclose(y[0], 3.0 * t, rtol=1e-12, atol=1e-15)  # trapezoid exact for linear
    np.testing.assert_allclose(y[1], t**2, rtol=1e-2, atol=1e-12)  # quadratic: error dt^2 / 6 per unit
    np.testing.assert_allclose(sig.trapezoid(x[1], FS), y[1])  # 1-D is one channel


def test_trapezoid_of_cosine_within_known_bias():
    t = np.arange(int(FS)) / FS
    f = 576.3
    y = sig.trapezoid(np.cos(2 * np.pi * f * t)[None], FS)[0]
    exact = np.sin(2 * np.pi * f * t) / (2 * np.pi * f)
    # the local error of the trapezoid rule is at most the per-integration bias of a sine
    # (x^2 / 3, 0.67 % here) of the amplitude, plus rounding
    assert np.abs(y - exact).max() <= 1.1 * trapezoid_bias(f, FS) / (2 * np.pi * f)


def test_highpass_passes_band_removes_offset_and_slow_drift_zero_phase():
    t = np.arange(int(4 * FS)) / FS
    fast = np.sin(2 * np.pi * 200.0 * t)
    x = np.stack([fast + 5.0 + 2.0 * np.sin(2 * np.pi * 1.0 * t), fast])
    y = sig.elliptic_highpass(x, FS, 10.0, order=5)
    # the end transients of a drifting record ring for ~10 cut-off periods (the elliptic
    # poles near the cut-off have a high Q): judge the middle second only
    mid = slice(int(1.5 * FS), int(2.5 * FS))
    # 1 Hz lies deep in the stop band (>= 30 dB per pass, 60 dB forward-backward): the drift
    # of amplitude 2 leaves at most 2e-3; the 200 Hz line is in the pass band (<= 0.2 dB zero-phase
    # ripple, 2.3 %) and keeps its phase (zero-phase), so y ~ g * fast with g in [0.977, 1]
    for ch in range(2):
        g = np.dot(y[ch, mid], fast[mid]) / np.dot(fast[mid], fast[mid])
        assert 0.977 <= g <= 1.0 + 1e-6
        assert np.abs(y[ch, mid] - g * fast[mid]).max() < 3e-3


def test_even_order_highpass_still_removes_dc():
    # an even-order elliptic high-pass passes DC at the stop-band level; the mean removal fixes it
    s = np.sin(2 * np.pi * 500.0 * np.arange(4000) / FS)[None]
    with_offset = sig.elliptic_highpass(s + 7.0, FS, 10.0, order=4)
    # without the mean removal the offset would leak at the -60 dB DC gain: 7e-3
    np.testing.assert_allclose(with_offset, sig.elliptic_highpass(s, FS, 10.0, order=4), atol=1e-9)


@pytest.mark.parametrize("cutoff", [0.0, -1.0, FS / 2, FS])
def test_filters_reject_bad_cutoff(cutoff):
    x = np.zeros((1, 1000))
    with pytest.raises(ValueError, match="Nyquist"):
        sig.elliptic_highpass(x, FS, cutoff)
    with pytest.raises(ValueError, match="Nyquist"):
        sig.lowpass(x, FS, cutoff)


def test_filters_reject_short_signal_and_bad_design():
    with pytest.raises(ValueError, match="too short"):
        sig.elliptic_highpass(np.zeros((1, 10)), FS, 10.0, order=4)
    with pytest.raises(ValueError, match="ripple"):
        sig.elliptic_highpass(np.zeros((1, 1000)), FS, 10.0, ripple_db=40.0, stop_db=30.0)


def test_lowpass_keeps_band_kills_noise():
    t = np.arange(8000) / FS
    low, high = np.sin(2 * np.pi * 50.0 * t), 0.5 * np.sin(2 * np.pi * 4000.0 * t)
    y = sig.lowpass(np.stack([low + high, low]), FS, 1000.0, order=8)
    mid = slice(1000, 7000)
    # Butterworth |H|^2 at f/fc = 0.05 is 1 - O(0.05^16): exact to rounding; at f/fc = 4 the
    # zero-phase gain is 4^-16 ~ 2e-10, so the 4 kHz line leaves < 1e-9
    np.testing.assert_allclose(y[:, mid], np.stack([low, low])[:, mid], atol=1e-8)


def test_integrate_acceleration_matches_filtered_exact_integrals():
    t = np.arange(int(2 * FS)) / FS
    d, v, a = decay_from_rest(t)
    acc_f, vel, disp = sig.integrate_acceleration(a, FS, 10.0, order=5)
    assert acc_f.shape == vel.shape == disp.shape == a.shape

    def h2(z):
        return sig.elliptic_highpass(sig.elliptic_highpass(z, FS, 10.0, 5), FS, 10.0, 5)

    # The filters commute with exact integration, so the chain must equal H^2 applied to the
    # exact signals up to the trapezoid bias: per integration at most 1 - x/tan x at the highest
    # mode (0.67 % at 576.3 Hz), i.e. 0.67 % for velocity and 1.34 % for displacement.
    b = trapezoid_bias(MODES[-1][0], FS)
    np.testing.assert_allclose(acc_f, h2(a), rtol=0, atol=1e-12 * np.abs(a).max())
    assert np.all(rel_err(vel, h2(v)) <= b)
    assert np.all(rel_err(disp, h2(d)) <= 2 * b)
    # Against the raw exact signals add the filter's own effect: the zero-phase gain |H|^4 at
    # the modes (0.07 dB at 89.6 Hz for order 5) and the removed static (DC) part of the decay,
    # whose area A / w spread over ~1 / f_c is below 0.5 % of the amplitude here.
    _, h = ss.sosfreqz(ss.ellip(5, 0.1, 30.0, 10.0, "highpass", output="sos", fs=FS),
                       worN=[m[0] for m in MODES], fs=FS)
    gain_loss = 1.0 - np.min(np.abs(h) ** 4)
    assert np.all(rel_err(acc_f, a) <= gain_loss + 0.005)
    assert np.all(rel_err(vel, v) <= gain_loss + b + 0.005)
    assert np.all(rel_err(disp, d) <= gain_loss + 2 * b + 0.005)


def test_integrate_acceleration_vectorised_over_channels():
    t = np.arange(int(0.5 * FS)) / FS
    _, _, a = decay_from_rest(t, n_channels=3)
    together = sig.integrate_acceleration(a, FS, 10.0, 5)
    for ch in range(3):
        alone = sig.integrate_acceleration(a[ch:ch + 1], FS, 10.0, 5)
        for x, y in zip(together, alone, strict=True):
            # the same filters on each row: equal to rounding (atol for the samples still at rest, 0)
            np.testing.assert_allclose(x[ch:ch + 1], y, rtol=1e-12, atol=1e-18)


def test_noise_does_not_drift():
    rng = np.random.default_rng(0)
    sigma, fc, n = 0.01, 10.0, int(2 * FS)
    acc = rng.normal(0.0, sigma, (3, n))
    _, _, disp = sig.integrate_acceleration(acc, FS, fc, 5)
    # White noise of one-sided PSD S = sigma^2 / (fs/2), integrated twice and high-passed at fc,
    # has variance ~ int_fc^inf S / (2 pi f)^4 df = S / (3 (2 pi)^4 fc^3); allow 3x for the
    # transition band and the sampling spread of a 1 s estimate.  Unfiltered, the double
    # integral wanders ~ sigma t^1.5 / sqrt(3 fs), three orders of magnitude more.
    s = sigma**2 / (FS / 2)
    expected = np.sqrt(s / (3 * (2 * np.pi) ** 4 * fc**3))
    assert np.all(disp[:, n // 4:-n // 4].std(axis=1) < 3 * expected)
    raw = sig.trapezoid(sig.trapezoid(acc, FS), FS)
    assert np.abs(raw).max() > 100 * expected


@pytest.mark.parametrize("fc,order", [(5.0, 4), (8.0, 5), (10.0, 5)])
def test_consistent_filtering_removes_regression_bias(fc, order):
    """Regress a on (v, d) with the force: consistent filtering recovers k and c, the raw chain not."""
    fs, f0, zeta = 2000.0, 14.0, 0.02  # a mode 1.4-2.8 x the cut-off, where the mismatch shows
    w = 2 * np.pi * f0
    k, c = w * w, 2 * zeta * w  # per unit mass
    t = np.arange(int(4 * fs)) / fs
    force = np.where((t >= 0.2) & (t < 0.21), np.sin(np.pi * (t - 0.2) / 0.01), 0.0)
    sdof = ss.lti([[0, 1], [-k, -c]], [[0], [1]], [[0, 0]], [[0]])
    _, _, state = ss.lsim(sdof, force, t)  # exact for the piecewise-linear force
    a = (force - c * state[:, 1] - k * state[:, 0])[None]

    def hp(z):
        return sig.elliptic_highpass(z, fs, fc, order)

    def fit(acc, vel, disp, f):
        sl = slice(int(0.3 * fs), int(3.5 * fs))
        coef = np.linalg.lstsq(np.stack([vel[0, sl], disp[0, sl]], 1), f[0, sl] - acc[0, sl], rcond=None)[0]
        return abs(coef[0] / c - 1), abs(coef[1] / k - 1)

    acc_f, vel, disp = sig.integrate_acceleration(a, fs, fc, order)
    c_err, k_err = fit(acc_f, vel, disp, hp(hp(force[None])))
    # left: the trapezoid bias x^2/3 ~ 2e-4 per integration at 14 Hz; 2e-3 is 4x that
    assert c_err < 2e-3 and k_err < 2e-3
    v1 = hp(sig.trapezoid(a, fs))  # the paper's chain: raw a, v filtered once, d twice
    c_raw, k_raw = fit(a, v1, hp(sig.trapezoid(v1, fs)), force[None])
    assert max(c_raw, k_raw) > 5 * max(c_err, k_err)


def test_differentiate_exact_on_polynomials():
    fs = 100.0
    t = np.arange(400) / fs
    x = np.stack([1.0 + 2.0 * t - 3.0 * t**2 + 0.5 * t**3, t**4])
    xs, xd, xdd = der.differentiate(x, fs, window=31, polyorder=4)
    # a local polynomial of order 4 reproduces any polynomial up to order 4 exactly
    np.testing.assert_allclose(xs, x, atol=1e-9)
    np.testing.assert_allclose(xd[0], 2.0 - 6.0 * t + 1.5 * t**2, atol=1e-8)
    np.testing.assert_allclose(xdd[0], -6.0 + 3.0 * t, atol=1e-6)
    np.testing.assert_allclose(xd[1], 4 * t**3, atol=1e-8)
    np.testing.assert_allclose(xdd[1], 12 * t**2, atol=1e-6)


def test_differentiate_noisy_sine():
    fs = 1e4  # the five-bar's dt = 1e-4 s and its 1 rad/s drive
    t = np.arange(int(10 * fs)) / fs
    rng = np.random.default_rng(1)
    x = 0.0698 * np.sin(t + np.pi / 2) + rng.normal(0, 1e-4, t.size)
    xs, xd, xdd = der.differentiate(x[None], fs, window=2001, polyorder=4)
    mid = slice(2000, -2000)
    # noise 1e-4 rad through a 0.2 s quartic window: derivative noise ~ sigma / T^k times a
    # filter factor of order 10 (k = 1, 2); the sine's own curvature over 0.2 s is fit exactly
    assert np.abs(xs[0, mid] - 0.0698 * np.cos(t[mid])).max() < 5e-5
    assert np.abs(xd[0, mid] + 0.0698 * np.sin(t[mid])).max() < 5e-3
    assert np.abs(xdd[0, mid] + 0.0698 * np.cos(t[mid])).max() < 0.1


@pytest.mark.parametrize("window,polyorder,match", [(30, 4, "odd"), (31, 1, "polyorder"),
                                                     (31, 31, "polyorder"), (501, 4, "exceeds")])
def test_differentiate_rejects_bad_settings(window, polyorder, match):
    with pytest.raises(ValueError, match=match):
        der.differentiate(np.zeros((2, 400)), 100.0, window, polyorder)


@pytest.mark.parametrize("window,polyorder", [(3001, 4), (6001, 4), (1001, 6), (301, 8), (2001, 8)])
def test_differentiate_long_windows_and_high_orders_keep_the_offset(window, polyorder):
    # regression: scipy's savgol_coeffs fits monomials of raw sample offsets; for these settings
    # its smoothing weights sum to ~0 instead of 1 and an angle of 1.78 rad came back as ~0
    fs = 1e4
    t = np.arange(20000) / fs
    x = np.stack([1.78 + 0.3 * np.sin(2 * np.pi * 0.5 * t), 1.36 + 0.2 * np.cos(2 * np.pi * 0.3 * t)])
    xs, xd, xdd = der.differentiate(x, fs, window, polyorder)
    w = 2 * np.pi * 0.5
    # the local fit's own bias: at most (w T)^(p+1)-order terms of the slow sines; the bounds
    # are 10x the worst measured (window 6001, order 4: 9e-4 rad, 0.04 rad/s, 0.4 rad/s^2)
    assert np.abs(xs - x).max() < 1e-2
    assert np.abs(xd[0] - 0.3 * w * np.cos(w * t)).max() < 0.5
    assert np.abs(xdd[0] + 0.3 * w**2 * np.sin(w * t)).max() < 5.0
    # a constant is reproduced exactly by any order, whatever the window
    c = np.full((1, 20000), 1.78)
    cs, cd, cdd = der.differentiate(c, fs, window, polyorder)
    np.testing.assert_allclose(cs, c, rtol=0, atol=1e-12)
    assert np.abs(cd).max() < 1e-8 and np.abs(cdd).max() < 1e-4


@pytest.mark.parametrize("shape,window,polyorder", [((2, 8000), 1501, 4), ((1, 500), 31, 3),
                                                     ((500,), 31, 3), ((3, 301), 301, 8)])
def test_differentiate_equals_the_weights_of_every_derivative_at_once(shape, window, polyorder):
    # differentiate builds the edge rows of one derivative at a time in one reused array; the
    # rows of all derivatives at once (_local_poly_rows, as it was built before) give the same
    # bits: the same products, only not held together
    x = np.random.default_rng(5).normal(size=shape).cumsum(axis=-1)
    half = window // 2
    edge = der._local_poly_rows(window, polyorder, np.arange(half))  # (p+1, half, window)
    xc = x - x.mean(axis=-1, keepdims=True)
    for d, y in enumerate(der.differentiate(x, 1e4, window, polyorder)):
        head = (xc[..., :window] @ edge[d].T) * 1e4**d
        tail = (xc[..., ::-1][..., :window] @ edge[d].T)[..., ::-1] * (-1) ** d * 1e4**d
        if d == 0:
            head, tail = head + x.mean(axis=-1, keepdims=True), tail + x.mean(axis=-1, keepdims=True)
        assert np.array_equal(y[..., :half], head) and np.array_equal(y[..., -half:], tail)


def test_differentiate_does_not_hold_every_edge_weight_at_once():
    # window 6001, order 4: the edge weights of all 5 derivatives are (5, 3000, 6001) floats,
    # 687 MiB (957 MB resident with their temporaries, 2.4 s of CPU mostly page faults); one
    # derivative's are 137 MiB.  The bound allows one more array of that size for temporaries.
    window, polyorder = 6001, 4
    one = (window // 2) * window * 8
    x = np.random.default_rng(6).normal(size=(1, window))
    tracemalloc.start()
    try:
        der.differentiate(x, 1e4, window, polyorder)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 2 * one, f"peak {peak / 2**20:.0f} MiB, one derivative's edge weights {one / 2**20:.0f} MiB"


def test_differentiate_matches_scipy_where_scipy_is_well_conditioned():
    fs = 100.0
    rng = np.random.default_rng(3)
    x = rng.normal(size=(2, 500)).cumsum(axis=1)
    ours = der.differentiate(x, fs, 31, 3)
    for d, got in enumerate(ours):
        ref = ss.savgol_filter(x, 31, 3, deriv=d, delta=1 / fs, axis=-1, mode="interp")
        # two computations of the same local fit (ours: Legendre and QR on a scaled abscissa; scipy's
        # monomials, well conditioned at window 31, order 3): rounding of the fit, times fs^d per derivative
        np.testing.assert_allclose(got, ref, rtol=0, atol=1e-9 * fs**d * np.abs(x).max())


def sines(t, phase=1.0):
    """Two slow sines, not at rest at the ends (a record cut mid-motion), with derivatives."""
    w = 2 * np.pi * np.array([[1.0], [0.37]])
    a = np.array([[0.3], [0.5]])
    ph = np.array([[phase], [2.0]])
    return (1.8 + a * np.sin(w * t + ph), a * w * np.cos(w * t + ph), -a * w**2 * np.sin(w * t + ph))


def test_lowpass_differentiate_clean_signal_cut_mid_motion():
    fs = 1e4
    t = np.arange(int(10 * fs)) / fs
    x, v, a = sines(t)
    xs, xd, xdd = der.lowpass_differentiate(x, fs, 6.0)
    mid = slice(int(1.5 * fs), -int(1.5 * fs))
    # interior: pass-band gain 1 - (1/6)^16 / 2 per pass and central differences (w/fs)^2 / 6:
    # both ~1e-9 relative; 1e-6 leaves room for the filter's round-off
    assert np.abs(xs - x)[:, mid].max() < 1e-6
    assert np.abs(xd - v)[:, mid].max() < 1e-5
    assert np.abs(xdd - a)[:, mid].max() < 1e-4
    # ends: the quintic bridge removes value, slope and curvature, the remaining kink is in
    # the 4th derivative (a w^4 = 47 rad/s^4): measured 2.0e-3 rad/s and 2.4e-6 rad; bounds
    # 2.5x and 4x
    assert np.abs(xd - v)[:, [0, -1]].max() < 5e-3
    assert np.abs(xs - x)[:, [0, -1]].max() < 1e-5
    # without the bridge (odd reflection of the raw record) the first rate is ~20x worse
    sos = ss.butter(8, 6.0, output="sos", fs=fs)
    raw = np.gradient(ss.sosfiltfilt(sos, x, axis=-1, padtype="odd", padlen=int(8 / 6 * fs)),
                      1 / fs, axis=-1, edge_order=2)
    assert np.abs(raw - v)[:, 0].max() > 10 * np.abs(xd - v)[:, 0].max()
    # one channel in, one channel out
    one = der.lowpass_differentiate(x[0], fs, 6.0)
    assert one[1].shape == (t.size,)
    # same numbers up to round-off (the end fits' slope weights carry a factor fs = 1e4)
    np.testing.assert_allclose(one[1], xd[0], rtol=0, atol=1e-7)


def test_lowpass_differentiate_beats_savitzky_golay_on_noise():
    fs = 1e4
    t = np.arange(int(10 * fs)) / fs
    x, v, a = sines(t)
    rng = np.random.default_rng(5)
    noisy = x + rng.normal(0.0, 2e-3, x.shape)  # ~1 % of the angles' RMS, as on the five-bar
    mid = slice(int(1.5 * fs), -int(1.5 * fs))
    _, xd, xdd = der.lowpass_differentiate(noisy, fs, 4.0)
    _, _, sdd = der.differentiate(noisy, fs, 1001, 2)
    # predicted noise RMS, brick-wall at fc: sigma (2 pi)^k sqrt(fc^(2k+1) / ((2k+1) fs / 2)):
    # 8.2e-4 rad/s (k = 1), 1.6e-2 rad/s^2 (k = 2) at 4 Hz; measured 7.4e-4 and 1.4e-2;
    # bounds 2x the prediction
    rms = lambda e: np.sqrt(np.mean(e[:, mid] ** 2))  # noqa: E731
    assert rms(xd - v) < 1.6e-3 and rms(xdd - a) < 3.2e-2
    # Savitzky-Golay 0.1 s quadratic (the previous five-bar setting): its side lobes pass far
    # more noise into the acceleration (measured 0.17 rad/s^2, 12x)
    assert rms(sdd - a) > 5 * rms(xdd - a)


def test_lowpass_differentiate_pads_about_zero_not_about_the_end_sample():
    # the paper's five-bar sine (0.07 rad at 1 rad/s), 0.8 Hz, 2 s end fits; one end sample
    # off by 1 mrad (about twice the 1 % noise std there).  Padding by odd reflection about that
    # sample (scipy's padtype="odd") puts the whole pad 2 mrad off: a step the filter turns into
    # a rate error of 3.3e-3 rad/s (measured; 5 % of the rate amplitude) spread over seconds.
    # Reflected about zero, the remainder's end value, the sample only moves the end fits and
    # raises the level against which the filter's end transients are read (the clean record's
    # are removed, derivatives._end_transients; here partly kept): rate error against the
    # truth measured 4.1e-4 rad/s at the ends and 1.8e-5 rad/s 2 s in (before the transients'
    # removal 5.0e-4 and 2.6e-5; the clean record's now 3e-8); bounds 2x
    fs = 1e3
    t = np.arange(int(10 * fs)) / fs
    x = 0.07 * np.cos(t)[None]
    y = x.copy()
    y[:, 0] += 1e-3
    y[:, -1] -= 1e-3
    b = der.lowpass_differentiate(y, fs, 0.8, 8, 2.0, 5)[1]
    err = np.abs(b + 0.07 * np.sin(t)[None])
    assert err.max() < 8.2e-4
    assert err[:, int(2 * fs):-int(2 * fs)].max() < 3.6e-5
    r = np.arange(1.0, 6.0)[None]
    np.testing.assert_array_equal(der._odd_about_zero(r, 2), [[-3, -2, 1, 2, 3, 4, 5, -4, -3]])


@pytest.mark.parametrize("kw,match", [({"cutoff_hz": 6000.0}, "Nyquist"), ({"order": 0}, "order"),
                                      ({"edge_fit_s": 1e-4}, "edge fit"),
                                      ({"edge_fit_order": 1}, "edge fit")])
def test_lowpass_differentiate_rejects_bad_settings(kw, match):
    args = {"cutoff_hz": 4.0} | kw
    with pytest.raises(ValueError, match=match):
        der.lowpass_differentiate(np.zeros((2, 5000)), 1e4, **args)


def test_a_filter_design_is_computed_once_and_handed_out_as_a_copy(monkeypatch):
    """The designs are cached per parameter set (a run asks for the same few ~30 times); each
    caller gets its own copy, equal to scipy's design, that it may change without harm."""
    sig._ellip_sos.cache_clear()
    sig._butter_sos.cache_clear()
    calls = []
    real = ss.ellip
    monkeypatch.setattr(ss, "ellip", lambda *a, **k: calls.append(a) or real(*a, **k))
    want = real(4, 0.1, 30.0, 20.0, btype="highpass", output="sos", fs=12800.0)
    a = sig._highpass_sos(12800.0, 20.0, 4, 0.1, 30.0)
    a[:] = 0.0  # a caller's change stays its own
    b = sig._highpass_sos(np.float64(12800.0), 20, 4, 0.1, 30)
    assert len(calls) == 1 and np.array_equal(b, want) and b.flags.writeable
    lp = sig._lowpass_sos(12800.0, 450.0, 8)
    lp[:] = 0.0
    assert np.array_equal(sig._lowpass_sos(12800.0, 450.0, 8),
                          ss.butter(8, 450.0, btype="lowpass", output="sos", fs=12800.0))


def _steps_and_multisine(fs=1000.0, seconds=3.0):
    """A 2-level step input held 0.5 s (a 1/f spectrum through any band) and a 3-tone
    multisine to 1.5 Hz (nothing above its band), both [N]."""
    t = np.arange(int(seconds * fs)) / fs
    steps = 2.0 * np.where(np.floor(t / 0.5) % 2 == 0, 1.0, -1.0)
    ms = sum(np.sin(2 * np.pi * f * t + p) for f, p in ((0.5, 0.3), (1.0, 1.1), (1.5, 2.0)))
    return t, steps, ms


def test_zero_phase_gain_is_the_lowpass_response():
    """The forward-backward Butterworth's gain on a tone (mid-record, clear of the ends) is
    :func:`zero_phase_gain` to the digital design's warping, ``O((f / fs)^2)``: 1e-4 here."""
    fs, fc = 1000.0, 6.85
    t = np.arange(20000) / fs
    for f in (2.0, 5.0, 6.8, 9.0):  # whole periods in the 10 s read
        y = sig.lowpass(np.sin(2 * np.pi * f * t), fs, fc, 8)[5000:15000]
        amp = np.sqrt(2.0 * np.mean(y**2))
        assert amp == pytest.approx(sig.zero_phase_gain(f, fc, 8), abs=1e-4), f


def test_zero_phase_droop_keeps_what_one_minus_the_gain_rounds_away():
    """``zero_phase_droop`` is ``1 - zero_phase_gain`` where that is exact, and keeps a droop far
    below the double's resolution of 1: a decade below an order-8 cut-off it is
    ``10^-16 / (1 + 10^-16)``, where ``1 - gain`` rounds to 0."""
    f = np.array([0.0, 2.0, 4.0, 8.0, 40.0])
    np.testing.assert_allclose(sig.zero_phase_droop(f, 4.0, 8), 1 - sig.zero_phase_gain(f, 4.0, 8),
                               rtol=1e-12, atol=0)
    assert 1 - sig.zero_phase_gain(np.array([0.4]), 4.0, 8)[0] == 0.0
    assert sig.zero_phase_droop(np.array([0.4]), 4.0, 8)[0] == pytest.approx(1e-16, rel=1e-12)


def test_chain_mismatch_share_rises_with_the_column_cutoff_and_reads_steps():
    """The share never falls as the column cut-off rises; a step input's is orders above a
    multisine's at the clean column cut-off (0.75 x a 6.85 Hz chain): the steps carry the
    chain's transition band, the tones' leakage through the window stays below 1e-12."""
    fs = 1000.0
    _, steps, ms = _steps_and_multisine(fs)
    cuts = np.geomspace(1.0, 6.0, 40)
    for u in (steps, ms):
        f, p = sig.input_power(u, fs)
        share = [sig.chain_mismatch_share(f, p, 6.85, 8, c, 4) for c in cuts]
        assert np.all(np.diff(share) >= 0), share
    f, p = sig.input_power(steps, fs)
    assert sig.chain_mismatch_share(f, p, 6.85, 8, 5.13, 4) > 1e-6
    f, p = sig.input_power(ms, fs)
    assert sig.chain_mismatch_share(f, p, 6.85, 8, 5.13, 4) < 1e-12
    # two rows: the larger share counts (units of one input never hide another's tail)
    f, p = sig.input_power(np.vstack([100.0 * ms, steps]), fs)
    assert sig.chain_mismatch_share(f, p, 6.85, 8, 5.13, 4) == pytest.approx(
        sig.chain_mismatch_share(*sig.input_power(steps, fs), 6.85, 8, 5.13, 4))


def test_mismatch_cutoff_holds_steps_down_and_keeps_smooth_inputs():
    """Between the bounds: a multisine keeps the high cut-off; steps get the crossing of the
    bound (their share there equals it to the bisection's width), strictly inside; a bound no
    cut-off meets gives the low one, as does a NaN input; the cut-off moves little when the
    input moves little (continuity: a 1e-3 change of the step level times a slow ramp)."""
    fs, bound = 1000.0, 1e-10
    t, steps, ms = _steps_and_multisine(fs)
    assert sig.mismatch_cutoff(ms, fs, 6.85, 8, 4, 2.5, 5.13, bound) == 5.13
    c = sig.mismatch_cutoff(steps, fs, 6.85, 8, 4, 1.0, 5.13, bound)
    assert 1.0 < c < 5.13
    assert sig.chain_mismatch_share(*sig.input_power(steps, fs), 6.85, 8, c, 4) == pytest.approx(
        bound, rel=1e-6)
    assert sig.mismatch_cutoff(steps, fs, 6.85, 8, 4, 4.0, 5.13, bound) == 4.0
    bad = steps.copy()
    bad[10] = np.nan
    assert sig.mismatch_cutoff(bad, fs, 6.85, 8, 4, 2.5, 5.13, bound) == 2.5
    c2 = sig.mismatch_cutoff(steps * (1 + 1e-3 * t / t[-1]), fs, 6.85, 8, 4, 1.0, 5.13, bound)
    assert abs(np.log(c2 / c)) < 1e-2
