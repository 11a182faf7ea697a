"""The noise-level and signal-band estimators on synthetic signals with known noise."""

import numpy as np
import pytest

from testbed.numerics import noise_std, signal_band


def _tones(t, freqs, amp=0.3):
    return sum(amp * np.sin(2 * np.pi * f * t + k) for k, f in enumerate(freqs))


@pytest.mark.parametrize("sigma", [1e-4, 1.5e-3, 1e-2])
def test_noise_std_recovers_known_white_noise(sigma):
    fs, n = 1e4, 50_000
    t = np.arange(n) / fs
    clean = np.vstack([1.78 + _tones(t, [0.3, 0.9, 1.7]), _tones(t, [0.2, 1.1], amp=0.5)])
    rng = np.random.default_rng(3)
    est = noise_std(clean + sigma * rng.standard_normal(clean.shape))
    # 5 %: a MAD-based std has relative standard error 1.17 / sqrt(n_eff); 4th differences are
    # correlated over 9 samples, so n_eff >= 5e4 / 9 and the error <= 1.6 %: 5 % is 3 standard
    # errors.  A wrong scale (sqrt(C(8, 4)) = 8.4 missed) or leaked signal fails it.
    np.testing.assert_allclose(est, sigma, rtol=0.05)


def test_noise_std_of_a_smooth_signal_is_negligible():
    fs = 1e4
    t = np.arange(20_000) / fs
    est = noise_std(1.78 + _tones(t, [0.5, 2.0]))
    # the 4th difference of a 2 Hz, 0.3 rad tone at 10 kHz is 0.3 (2 pi 2 / 1e4)^4 = 1e-12 rad;
    # float64 round-off of a 1.8 rad angle differenced 4 times adds ~1e-15
    assert np.all(est < 1e-10)


def test_noise_std_rejects_bad_input():
    with pytest.raises(ValueError, match="non-finite"):
        noise_std(np.array([0.0, 1.0, np.nan, 2.0, 3.0, 4.0, 5.0]))
    with pytest.raises(ValueError, match="too few"):
        noise_std(np.zeros(4))


def test_signal_band_sees_through_the_noise_floor():
    fs, n = 1e3, 20_000
    t = np.arange(n) / fs
    x = _tones(t, [0.5, 1.0, 3.0])[None, :]
    noisy = x + 3e-3 * np.random.default_rng(0).standard_normal(x.shape)
    # the three equal tones: 99.9 % of the power is reached at the 3 Hz tone (Hann leakage
    # spreads each over +-2 bins of 0.05 Hz); without the floor subtracted, the white noise
    # (9e-6 rad^2 over 500 Hz, 0.02 % of the power) would push the band far above 3 Hz
    band = signal_band(noisy, fs, 0.999)
    assert 2.9 <= band[0] <= 3.2
    # 20x the noise (0.3 % of the power, beyond the 0.1 % left out): clipping the floor per bin
    # kept 1/e of it and sent this band to hundreds of Hz
    louder = x + 6e-2 * np.random.default_rng(1).standard_normal(x.shape)
    assert 2.9 <= signal_band(louder, fs, 0.999)[0] <= 3.2
    assert signal_band(np.zeros((1, 100)) + 1.0, fs)[0] == 0.0


def _bow(t):
    """Four angles over a third of a 6 s sine period (a five-bar's 2 s record of the paper's
    sine): after the end-to-end detrend only a small bow is left, 1-1.5 Hz of band."""
    return np.vstack([1.8 + 0.4 * np.sin(2 * np.pi * t / 6.0 + p) for p in (0.0, 1.0, 2.0, 3.0)])


def test_signal_band_of_a_short_slow_record_under_heavy_noise():
    fs, n = 1e4, 20_000
    t = np.arange(n) / fs
    clean = _bow(t)
    truth = signal_band(clean, fs, 0.999).max()  # the band the noisy estimate aims at
    assert truth == 1.5
    for seed in range(20):
        rng = np.random.default_rng(seed)
        x = clean + 0.05 * clean.std(axis=1, keepdims=True) * rng.standard_normal(clean.shape)
        band = signal_band(x, fs, 0.999).max()
        # within one bin (1 / 2 s = 0.5 Hz) below the truth: the last 1e-3 of the bow's power
        # lies under the noise's significance.  The cumulative share alone let the noise's
        # fluctuations above the motion carry it: 11 of these 20 records gave 52 Hz-4.9 kHz
        assert truth - 0.5 <= band <= truth, (seed, band)


def test_signal_band_keeps_tones_at_ten_percent_noise():
    fs, n = 1e4, 20_000
    t = np.arange(n) / fs
    clean = np.vstack([_tones(t, [0.5, 1.0, 1.5]) + 0.1 * np.sin(2 * np.pi * 1.5 * t + p)
                       for p in (0.0, 1.0)])
    truth = signal_band(clean, fs, 0.999)
    for seed in range(10):
        rng = np.random.default_rng(seed)
        x = clean + 0.1 * clean.std(axis=1, keepdims=True) * rng.standard_normal(clean.shape)
        # the tones stand far above the noise: the significance test must not cut them (the
        # cumulative share alone gave 239-713 Hz on one channel of seeds 4, 7 and 9)
        np.testing.assert_array_equal(signal_band(x, fs, 0.999), truth)


def test_window_var_of_hann_is_35_over_18():
    from testbed.numerics.noise import window_var
    # Hann^2 = 3/8 - cos/2 + cos(2.)/8: bin correlations 2/3 and 1/6, 1 + 2 (4/9 + 1/36)
    assert window_var(np.hanning(100_001)) == pytest.approx(35 / 18, rel=1e-4)
    assert window_var(np.ones(64)) == pytest.approx(1.0)


def test_signal_band_of_a_slow_drift_buried_in_noise_is_at_least_one_bin():
    """A 4 s record at 1 kHz of a slow drift with little curvature (a kinetics state's approach
    to its steady state) at 5 % noise: after the end-to-end detrend little is left above the
    noise.  The cumulative share alone ran off to hundreds of Hz; the significance test without
    its one-bin floor stopped at 0 Hz on 10 of these 20 records, which callers read as "no
    power above the floor" (SINDy-PI: the exact-data recipe).  A row with power above its
    floor has a band of at least one bin (1 / 4 s)."""
    fs, n = 1e3, 4000
    t = np.arange(n) / fs
    clean = (10.0 - 2.0 * t + 0.05 * t**2)[None, :]
    for seed in range(20):
        x = clean + 0.05 * clean.std() * np.random.default_rng(seed).standard_normal(clean.shape)
        # one bin of a 4 s record; the share alone gave up to 499 Hz on these records
        assert 0.25 <= signal_band(x, fs, 0.999)[0] <= 0.75, seed
