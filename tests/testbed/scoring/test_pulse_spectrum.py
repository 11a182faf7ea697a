"""The hammer pulse's spectrum and the "unexcited" reason it gives (round 12's 2 ms contact)."""

from types import SimpleNamespace

import numpy as np

from testbed.scoring.scorers import FAIL, UNEXCITED_RATIO, Scores, pulse_spectrum, unexcited_failures, verdict


def _dataset(force: np.ndarray, fs: float) -> SimpleNamespace:
    return SimpleNamespace(fs=fs, measured={"force": SimpleNamespace(data=force[None, :])})


def test_half_sine_spectrum_is_the_analytic_one():
    fs, T = 51_200.0, 2e-3
    n = round(T * fs)
    t = (np.arange(n) + 0.5) / fs
    force = np.r_[np.zeros(100), 200.0 * np.sin(np.pi * t / T), np.zeros(5000)]
    f = np.array([0.0, 370.8, 750.0, 2318.1])  # 750 Hz: the first null, f T = 3/2
    fT = f * T
    expect = np.abs(np.cos(np.pi * fT) / (1.0 - (2.0 * fT) ** 2))
    got = pulse_spectrum(_dataset(force, fs), f)
    # the sampled sum against the integral: the midpoint rule's error at 102 samples a pulse
    # is ~(pi f / fs)^2 / 24 relative, under 1e-3 at 2.3 kHz, plus 1e-3 absolute for the nulls
    np.testing.assert_allclose(got, expect, rtol=1e-3, atol=1e-3)
    assert got[3] < UNEXCITED_RATIO < got[1]


def test_no_pulse_no_claim():
    fs = 12_800.0
    t = np.arange(12_800) / fs
    shaker = np.sin(2 * np.pi * 40.0 * t)  # a continuous input: not one pulse
    assert np.isnan(pulse_spectrum(_dataset(shaker, fs), np.array([100.0, 500.0]))).all()
    assert np.isnan(pulse_spectrum(_dataset(np.zeros(100), fs), np.array([100.0]))).all()
    assert np.isnan(pulse_spectrum(SimpleNamespace(fs=fs, measured={}), np.array([1.0]))).all()


def test_a_pulse_too_long_for_a_mode_names_the_pulse_duration():
    bars = {"freq_error_mode2": {"max": 0.026}}
    details = {"force_participation": np.array([1.0, 0.98]), "f_true": np.array([370.8, 2318.1]),
               "scored_modes": 2, "pulse_spectrum": np.array([0.574, 0.0052])}
    why = unexcited_failures(Scores({"freq_error_mode1": 0.001, "freq_error_mode2": 0.6},
                                    details), bars)
    assert set(why) == {"unexcited"} and verdict([], why) == FAIL
    text = why["unexcited"]
    assert "mode 2 (2318 Hz) meets the pulse's spectrum at 0.0052" in text
    assert "excitation.pulse_duration" in text and "excitation.location" not in text
    # the same mode struck at 0.02 of the area: 0.98 x 0.02 is above the ratio, no claim
    near = {**details, "pulse_spectrum": np.array([0.574, 0.02])}
    assert unexcited_failures(Scores({"freq_error_mode2": 0.6}, near), bars) == {}
    # both factors small: the smaller one is the cause named, both are given
    both = {**details, "force_participation": np.array([1.0, 0.05]),
            "pulse_spectrum": np.array([0.574, 0.1])}
    text = unexcited_failures(Scores({"freq_error_mode2": 0.6}, both), bars)["unexcited"]
    assert "excitation.location" in text and "0.1 of its area" in text
    # a bar that passed is not explained
    assert unexcited_failures(Scores({"freq_error_mode2": 0.001}, details), bars) == {}


def test_round12_short_beam_under_a_2ms_contact_fails_named_unexcited():
    import dataclasses

    import testbed
    from testbed import load_scenario

    sc = load_scenario("benchmarks/unseen/round12/b12_short0p15_p2ms.toml")
    sc = dataclasses.replace(sc, identify={"method": "ls_sindy"},
                             noise={**sc.noise, "rms_percent": 2.0}, seed=31)
    res = testbed.run_scenario(sc)
    spec = res.scores.details["pulse_spectrum"]
    assert spec[1] < UNEXCITED_RATIO < spec[0]  # mode 2 at 2.32 kHz: 0.0052 of the area
    assert res.verdict == "FAIL" and "unexcited" in res.scores.failures
    assert "excitation.pulse_duration" in res.scores.failures["unexcited"]
