"""A failed TRAC bar with one channel at the record's floor and another off it names each."""

import numpy as np

from testbed.scoring.scorers import FAIL, Check, Scores, at_floor, bar_failures, verdict

BARS = {"trac": {"min": 0.9}}
CHANNELS = ["acc1", "acc2"]


def failures(trac: list[float], floor: list[float], bars: dict = BARS) -> dict[str, str]:
    details = {"trac": np.array(trac), "truth_trac": np.array(floor), "channels": CHANNELS}
    return bar_failures(Scores({"trac": float(np.min(trac))}, details), bars)


def test_a_channel_at_its_floor_neither_hides_nor_excuses_another():
    # held-out beams_stiff__036 at 1 %, ls_sindy: the TRAC shown (0.0885) is acc1's, at the
    # truth's own 0.0907 there; acc2 fails at 0.541 where the truth's own scores 0.973.  The old
    # scorer gave no reason at all.
    got = failures([0.0885, 0.541], [0.0907, 0.973])
    assert set(got) == {"trac_channels"}  # not the floor: acc2 is off it
    why = got["trac_channels"]
    assert why.startswith("TRAC by channel against the bar 0.9: the identified model's own "
                          "failure on acc2 0.541 (the truth's own 0.973)")
    assert why.endswith("not excused by the record's floor (the model within 0.05 of the "
                        "truth's own or above it) on acc1 0.0885 (the truth's own 0.0907)")
    assert "; " not in why  # one reason (Scores.failure joins reasons with "; ")
    # the verdict was a failure already (the bar failed): the reason changes no verdict
    check = Check("trac", 0.0885, "min", 0.9)
    assert verdict([check], {}) == verdict([check], got) == FAIL


def test_the_floor_and_the_models_own_failure_stay_as_they_were():
    # every failing channel at its floor: the floor, claimed as before, and nothing more
    assert set(failures([0.0885, 0.95], [0.0907, 0.973])) == {"floor"}
    assert set(failures([0.0885, 0.06], [0.0907, 0.08])) == {"floor"}
    # no channel at its floor: the failed bar shows the failing channel itself; no reason
    assert failures([0.5, 0.541], [0.95, 0.973]) == {}
    # the model further than FLOOR_MARGIN below the truth's own on a low-floor channel: not at
    # the floor, so nothing at the floor to hide the other
    assert failures([0.03, 0.541], [0.0907, 0.973]) == {}
    # the bar met, a NaN TRAC (the simulation's failure says why), no truth TRAC, no TRAC bar
    assert failures([0.95, 0.96], [0.0907, 0.973]) == {}
    assert failures([0.0885, float("nan")], [0.0907, 0.973]) == {}
    assert bar_failures(Scores({"trac": 0.0885}, {"trac": np.array([0.0885, 0.541])}), BARS) == {}
    assert failures([0.0885, 0.541], [0.0907, 0.973], {"mac": {"min": 0.9}}) == {}


def test_unnamed_channels_are_numbered():
    details = {"trac": np.array([0.0885, 0.541]), "truth_trac": np.array([0.0907, 0.973])}
    why = bar_failures(Scores({"trac": 0.0885}, details), BARS)["trac_channels"]
    assert "failure on channel 2 0.541" in why
    assert why.endswith("on channel 1 0.0885 (the truth's own 0.0907)")


def test_at_floor_is_judged_per_channel():
    trac, floor = np.array([0.0885, 0.541, 0.95, np.nan]), np.array([0.0907, 0.973, 0.5, 0.1])
    assert at_floor(trac, floor, 0.9).tolist() == [True, False, False, False]
    # at the margin's edge (0.05 below the truth's own) still the floor, beyond it not
    assert at_floor(np.array([0.0407 + 1e-9, 0.0407 - 1e-3]), np.array([0.0907, 0.0907]),
                    0.9).tolist() == [True, False]
