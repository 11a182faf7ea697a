"""Rigs nobody tuned, round 11 (benchmarks/unseen/round11_*.toml): regression tests of the
findings, each fast."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

UNSEEN = Path(__file__).resolve().parents[2] / "benchmarks" / "unseen"


# ------------------------------------------- a mode that dies out before the free decay says so
def test_decayed_failures_explain_only_a_failed_bar_on_a_mode_gone_at_the_window():
    from testbed.scoring.scorers import (
        DECAYED_RATIO,
        FAIL,
        Scores,
        bar_failures,
        decayed_failures,
        verdict,
    )
    # round11/b11_z10_s2: the shipped clamped beam at 10 % damping, two sensors; mode 2 (517.4
    # Hz, 62.5 % damped) keeps 1.3e-3 of its amplitude at the fit window's start, and both
    # identifiers put it 3.0-3.1 % off with every other score right and no word of why
    details = {"window_decay": np.array([0.843, 1.27e-3]), "f_true": np.array([82.77, 517.4]),
               "z_true": np.array([0.1, 0.625]), "scored_modes": 2}
    bars = {"freq_error_mode1": {"max": 0.026}, "freq_error_mode2": {"max": 0.026}}
    s = Scores({"freq_error_mode1": 3e-4, "freq_error_mode2": 0.031}, details)
    why = decayed_failures(s, bars)
    assert set(why) == {"decayed"} and verdict([], why) == FAIL
    assert why["decayed"].startswith("decayed: mode 2 (517.4 Hz, 62.5 % damped) keeps 0.0013 of "
                                     "its amplitude where the free decay begins")
    assert "rig.damping_ratio" in why["decayed"] and "mode 1" not in why["decayed"]
    assert bar_failures(s, bars) == why  # the run's bars add it
    # a bar met on that mode, or a failed bar on a mode still ringing: nothing to explain
    assert decayed_failures(Scores({"freq_error_mode1": 3e-4, "freq_error_mode2": 0.004},
                                   details), bars) == {}
    assert decayed_failures(Scores({"freq_error_mode1": 0.5, "freq_error_mode2": 0.004},
                                   details), bars) == {}
    # the worst-over-modes bar names the decayed mode only; at the ratio itself: not decayed
    why = decayed_failures(Scores({"mac": 0.5}, details), {"mac": {"min": 0.9}})
    assert "mode 2" in why["decayed"] and "mode 1" not in why["decayed"]
    edge = {**details, "window_decay": np.array([0.843, DECAYED_RATIO])}
    assert decayed_failures(Scores({"freq_error_mode2": 0.031}, edge), bars) == {}
    # other kinds (no window decay in the details), NaN: nothing
    assert decayed_failures(Scores({"freq_error_mode2": 9.0}), bars) == {}
    nan = {**details, "window_decay": np.array([0.843, np.nan])}
    assert decayed_failures(Scores({"freq_error_mode2": 0.031}, nan), bars) == {}


def test_window_decay_of_an_overdamped_mode_is_its_slower_pole():
    from types import SimpleNamespace

    from testbed.scoring.scorers import window_decay
    # a 1 N pulse over samples 10-12 of a 1 kHz record, the free decay from sample 22: 10 ms
    force = SimpleNamespace(data=np.r_[np.zeros(10), np.ones(3), np.zeros(87)][None, :])
    dataset = SimpleNamespace(measured={"force": force})
    data = SimpleNamespace(free_start=23, fs=1000.0)
    truth = SimpleNamespace(frequencies_hz=np.array([10.0, 100.0]),
                            damping_ratios=np.array([0.1, 2.0]))
    left = window_decay(truth, dataset, data, 2)
    w = 2 * np.pi * np.array([10.0, 100.0])
    expect = np.exp(-np.array([0.1 * w[0], w[1] * (2.0 - np.sqrt(3.0))]) * 0.010)
    assert np.allclose(left, expect, rtol=1e-12)
    # no free decay (a continuous input): nothing has decayed
    assert np.all(window_decay(truth, dataset, SimpleNamespace(free_start=0, fs=1000.0), 2) == 1)


def test_heavily_damped_mode_2_fails_named_decayed():
    import testbed
    from testbed import load_scenario
    # the round-11 rig in a 0.25 s record: mode 2 62.5 % damped, gone where the fit begins
    sc = load_scenario(UNSEEN / "round11" / "b11_z10_s2.toml")
    sc = dataclasses.replace(sc, identify={"method": "ls_sindy"},
                             simulation={**sc.simulation, "duration": 0.25})
    res = testbed.run_scenario(sc)
    left = res.scores.details["window_decay"]
    assert left[1] < 2e-3 and left[0] > 0.8
    assert res.verdict == "FAIL" and set(res.scores.failures) == {"decayed"}
    assert res.scores.values["freq_error_mode2"] > 0.026  # the bar it explains failed
    assert res.scores.values["freq_error_mode1"] < 0.026  # mode 1 meets its bar


# ------------------------------------------- the round's studies load
@pytest.mark.parametrize(("name", "cells"), [("round11_beams", 70), ("round11_beams_noise", 240)])
def test_round11_studies_load(name, cells):
    from testbed.studies.study import load_study
    from testbed.studies.sweep import expand
    assert len(expand(load_study(UNSEEN / f"{name}.toml"))) == cells


# ------------------------------------------- a third harmonic of the lowest mode is a cubic's mark
@pytest.mark.xdist_group("b11_soft_z0p1")  # its record: test_unseen13's hardened-peak test's
def test_third_harmonic_of_the_lowest_peak_puts_the_cubic_in(dataset_cache):
    """round11/b11_soft_z0p1 at 2 % noise (seed 21): the shipped soft base at 0.1 % damping
    over 2 s.  The flat correlation 0.21 and the tilted 0.44 left the cubic out, and both
    identifiers held mode 1 at its hardened peak, 3.1 % high; the peak search had recognised
    a third harmonic of mode 1 (122.8 Hz = 3 x 40.77 Hz).  Rule (4) puts the cubic in (both
    then pass at 2 %, mode 1 0.48 %)."""
    from identify._cubic_rule import cubic_rule
    from identify.structural import modal_peaks
    from testbed.pipeline.signal_chain import measure

    sc = load_scenario_file(UNSEEN / "round11" / "b11_soft_z0p1.toml")
    sc = dataclasses.replace(sc, noise={**sc.noise, "rms_percent": 2.0}, seed=21)
    data = measure(dataset_cache.get(sc), sc.signal, sc.kind)
    ps = modal_peaks(data)
    assert [k for _, k, _ in ps.harmonics] == [3]
    on, why = cubic_rule(data, None, None, ps.peaks)
    assert on is True and "tilted" in why and "third harmonic of the lowest peak" in why, why
    # the user's setting wins; a linear (clamped) record has no harmonic: out as before
    assert cubic_rule(data, False, None, ps.peaks) == (False, "user setting")
    lin = load_scenario_file(UNSEEN / "round11" / "b11_z0p05_short.toml")
    lin = dataclasses.replace(lin, noise={**lin.noise, "rms_percent": 2.0}, seed=21)
    data = measure(dataset_cache.get(lin), lin.signal, lin.kind)
    ps = modal_peaks(data)
    on, why = cubic_rule(data, None, None, ps.peaks)
    assert on is False and not ps.harmonics, why


def load_scenario_file(path):
    from testbed.pipeline.scenario import load_scenario
    return load_scenario(path)
