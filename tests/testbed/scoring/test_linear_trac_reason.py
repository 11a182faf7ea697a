"""A linear model's failed TRAC bar on a cubic truth whose own linear part fails it too is named
"linear model" (round 26); where the linear part meets the bar, the model's own failure is not."""

from pathlib import Path
from types import SimpleNamespace

import numpy as np

from testbed.core.truth import StructuralTruth
from testbed.numerics.linear_response import simulate_linear
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure
from testbed.scoring.run import noise_free
from testbed.scoring.scorers import FAIL, Check, Scores, bar_failures, score, verdict
from testbed.studies.statistics import failure_kind

ROOT = Path(__file__).resolve().parents[3]
BARS = {"trac": {"min": 0.9}}
CHANNELS = ["acc1", "acc2", "acc3"]


def failures(trac: list[float], linear: list[float] | None, k3_norm: float = 0.0,
             share: float | None = 0.26, bars: dict = BARS, values: dict | None = None,
             **failed: str) -> dict[str, str]:
    details = {"trac": np.array(trac), "channels": CHANNELS}
    if linear is not None:
        details["truth_linear_trac"] = np.array(linear)
    if share is not None:
        details["truth_cubic_share"] = share
    return bar_failures(Scores({"trac": float(np.min(trac)), "K3_norm": k3_norm, **(values or {})},
                               details, dict(failed)), bars)


def test_a_linear_models_failed_trac_under_the_truths_linear_part_is_named():
    # round 26's b26_soft_r1p3_cf0p25_s5u_hit0p55 at 2 % s172, sgd_sindy (three of its five
    # channels): the model 0.941 / 0.899 / 0.935, the truth's linear part 0.806 / 0.671 / 0.790
    got = failures([0.941, 0.899, 0.935], [0.806, 0.671, 0.790])
    assert set(got) == {"cubic_trac"}
    why = got["cubic_trac"]
    assert why.startswith("linear model: TRAC 0.899 against the bar 0.9 with no cubic term, where "
                          "the truth's cubic base force is 0.26 x its linear force")
    assert "on every failing channel: acc2 0.899 (the linear part 0.671):" in why
    assert "; " not in why and failure_kind(why) == ["linear model"]
    check = Check("trac", 0.899, "min", 0.9)
    assert verdict([check], {}) == verdict([check], got) == FAIL  # no verdict changes


def test_no_claim_where_the_linear_part_meets_the_bar_or_the_model_is_not_linear():
    # a failing channel the truth's linear part meets: the model's own failure
    assert failures([0.95, 0.85, 0.95], [0.99, 0.97, 0.98]) == {}
    # one failing channel under the linear part, another not: no claim for either
    assert failures([0.85, 0.85, 0.95], [0.70, 0.97, 0.98]) == {}
    # the model further than FLOOR_MARGIN below the linear part: its own failure
    assert failures([0.95, 0.60, 0.95], [0.99, 0.671, 0.98]) == {}
    # a model with a cubic term, no cubic truth, no witness, a NaN TRAC, a failed simulation
    assert failures([0.941, 0.899, 0.935], [0.806, 0.671, 0.790], k3_norm=1e9) == {}
    assert failures([0.941, 0.899, 0.935], [0.806, 0.671, 0.790], share=None) == {}
    assert failures([0.941, 0.899, 0.935], None) == {}
    assert failures([0.941, float("nan"), 0.935], [0.806, 0.671, 0.790]) == {}
    assert failures([0.941, 0.899, 0.935], [0.806, 0.671, 0.790],
                    simulation="diverged: ...") == {}
    # a cubic share that cannot move a frequency by the run's bar (review 27b: 3e-21 by the
    # clamp was named "linear model"): no claim, and the linear part is the floor instead
    assert set(failures([0.941, 0.899, 0.935], [0.806, 0.671, 0.790], share=1e-6)) == {"floor"}
    assert failures([0.941, 0.899, 0.935], [0.806, 0.671, 0.790], share=0.04,
                    bars={**BARS, "freq_error": {"max": 0.01}},
                    values={"freq_error": 0.005}) != {}  # 0.04 >= 0.0201 (the bar met)
    assert failures([0.941, 0.899, 0.935], [0.806, 0.671, 0.790],
                    growth="non-physical: ...") == {}
    # the bar met, or no TRAC bar: nothing to explain
    assert failures([0.95, 0.96, 0.97], [0.806, 0.671, 0.790]) == {}
    assert failures([0.941, 0.899, 0.935], [0.806, 0.671, 0.790],
                    bars={"mac": {"min": 0.9}}) == {}


def test_below_the_share_that_matters_the_linear_part_is_the_floor():
    """Continuous in k3 -> 0 (review 27b): a linear model at the linear part's TRAC, under a cubic
    share too small to move a frequency by the bar, is named "floor" as with ``base_k3 = 0``."""
    got = failures([0.564, 1.0, 1.0], [0.564, 1.0, 1.0], share=3e-21)
    assert set(got) == {"floor"} and failure_kind(got["floor"]) == ["floor"]
    assert set(failures([0.564, 1.0, 1.0], [0.564, 1.0, 1.0], share=0.3)) == {"cubic_trac"}


def test_the_truths_linear_part_scored_on_a_round_26_record_is_named_linear_model(dataset_cache):
    # The clean record of round 26's five-sensor soft base (1.3 EI/L, cubic fraction 0.25).  The
    # "model" is the truth's own reduced linear part (Mr, Cr, Kr at the sensors, no cubic), so
    # the witness is the model itself: it fails TRAC where the cubic matters and the reason
    # names it, whatever the identifiers do.
    sc = load_scenario(ROOT / "benchmarks/unseen/round26/b26_soft_r1p3_cf0p25_s5u_hit0p55.toml")
    ds = dataset_cache.get(sc)
    data = measure(ds, sc.signal, "structural")
    clean = measure(noise_free(ds), sc.signal, "structural")
    truth = ds.truth_as(StructuralTruth)
    B = np.asarray(truth.force_map, float).reshape(-1, 1)
    model = SimpleNamespace(M_=truth.Mr, C_=truth.Cr, K_=truth.Kr, K3_=None,
                            simulate=lambda x0, xd0, t, u: simulate_linear(
                                truth.Mr, truth.Cr, truth.Kr, B, x0, xd0, t, u))
    s = score("structural", ds, data, clean, model)
    bars = {"trac": {"min": 0.9}}
    # the model is the witness: the same TRAC per channel (both start fits are the same fit)
    np.testing.assert_allclose(s.details["trac"], s.details["truth_linear_trac"], atol=1e-9)
    assert s.values["trac"] < 0.9  # the cubic matters here (measured 0.945 / 0.924 / 0.806 / 0.671 / 0.790)
    why = bar_failures(s, bars)
    assert set(why) == {"cubic_trac"} and why["cubic_trac"].startswith("linear model: TRAC")


def soft_r1p4(freq2: float, mac1: float = 1.0, linear3: float = 0.321) -> dict[str, str]:
    """Round 27's ``b27_soft_r1p4_cf0p55_s4u_hit0p45`` clean s181, ``ls_sindy`` (four sensors, a
    linear model): TRAC 0.859 on acc3 (the truth's linear part 0.321 there), mode 1 3.06 % off
    (within the cubic's reach, 0.329), mode 2 ``freq2`` off; the families' bars."""
    bars = {**BARS, "mac_mode1": {"min": 0.9}, "freq_error_mode1": {"max": 0.026},
            "freq_error_mode2": {"max": 0.026}}
    values = {"trac": 0.859, "K3_norm": 0.0, "mac_mode1": mac1, "freq_error_mode1": 0.0306,
              "freq_error_mode2": freq2}
    details = {"trac": np.array([0.95, 0.93, 0.859, 0.92]),
               "truth_linear_trac": np.array([0.90, 0.80, linear3, 0.85]),
               "channels": ["acc1", "acc2", "acc3", "acc4"], "truth_cubic_share": 0.355,
               "truth_cubic_reach": np.array([0.329, 0.1, 0.05, 0.05]),
               "freq_error_per_mode": np.array([0.0306, freq2, 0.29, 0.84])}
    return bar_failures(Scores(values, details, {}), bars)


def test_no_trac_reason_that_would_hide_a_bar_the_missing_term_does_not_explain():
    # measured: mode 2 86 % off (MAC 1.000), beyond what the cubic force moves it: the model's
    # own failure, which "linear model" for the TRAC alone hid (and counted as the term's)
    assert soft_r1p4(0.8595) == {}
    # mode 2 within its reach: both frequency bars and the TRAC are named the missing term's
    got = soft_r1p4(0.05)
    assert set(got) == {"cubic", "cubic_trac"}
    assert failure_kind("; ".join(got.values())) == ["linear model"]
    # mode 2 met, mode 1 within its reach: the same
    assert set(soft_r1p4(0.01)) == {"cubic", "cubic_trac"}
    # a failed MAC bar, which no cubic reason explains: nothing claimed for the TRAC
    assert "cubic_trac" not in soft_r1p4(0.01, mac1=0.85)


def test_no_frequency_reason_that_would_hide_a_bar_the_missing_term_does_not_explain():
    # the same cell with the truth's linear part meeting the TRAC bar on acc3: that channel's
    # failure is the model's own (linear_trac_failures), which "linear model" for mode 1 alone
    # (within its reach) would hide
    assert soft_r1p4(0.01, linear3=0.95) == {}
    # a failed MAC bar beside it: nothing claimed for the frequencies either
    assert soft_r1p4(0.01, mac1=0.85) == {}
    # the TRAC named the missing term's: the frequencies too
    assert set(soft_r1p4(0.01)) == {"cubic", "cubic_trac"}


def test_an_unpaired_modes_mac_is_named_by_the_frequency_reason_not_hidden():
    """Review 26d's unpaired mode (NaN MAC and frequency error) under the families' MAC bars:
    the frequency reason names it ("no partner"), so its failed MAC hides nothing."""
    bars = {"mac_mode1": {"min": 0.9}, "mac_mode2": {"min": 0.9},
            "freq_error_mode1": {"max": 0.026}, "freq_error_mode2": {"max": 0.026}}
    details = {"truth_cubic_share": 0.531, "truth_cubic_reach": np.array([0.27, 0.033])}
    nan = float("nan")
    s = Scores({"K3_norm": 0.0, "mac_mode1": nan, "freq_error_mode1": nan, "mac_mode2": 0.99,
                "freq_error_mode2": 0.03}, details)
    why = bar_failures(s, bars)
    assert set(why) == {"cubic"} and "mode 1 has no partner" in why["cubic"]
    # a paired mode's failed MAC is no frequency's: withheld
    s = Scores({**s.values, "mac_mode1": 0.5, "freq_error_mode1": 0.01}, details)
    assert bar_failures(s, bars) == {}


def test_a_bar_another_reason_names_does_not_withhold_the_linear_model_reason():
    # review 28a: mode 2's failed MAC, named "unexcited" (the hammer at 0.001 of its largest
    # amplitude) or "band" (above the low-pass), withheld the cubic reason for mode 1's
    # frequency, which nothing then named
    bars = {"freq_error_mode1": {"max": 0.026}, "freq_error_mode2": {"max": 0.026},
            "mac_mode1": {"min": 0.9}, "mac_mode2": {"min": 0.9}, "trac": {"min": 0.9}}
    values = {"K3_norm": 0.0, "freq_error_mode1": 0.05, "freq_error_mode2": 0.01,
              "mac_mode1": 0.99, "mac_mode2": 0.5, "trac": 0.95}
    common = {"truth_cubic_share": 0.5, "truth_cubic_reach": np.array([0.10, 0.10]),
              "freq_error_per_mode": np.array([0.05, 0.01]), "scored_modes": 2,
              "f_true": np.array([10.0, 60.0])}
    unexcited = {**common, "force_participation": np.array([1.0, 0.001])}
    assert sorted(bar_failures(Scores(dict(values), unexcited), bars)) == ["cubic", "unexcited"]
    band = {**common, "passband": (1.0, 40.0)}
    assert sorted(bar_failures(Scores(dict(values), band), bars)) == ["band", "cubic"]
    # a MAC no other reason names still withholds it (the change's own rule)
    assert sorted(bar_failures(Scores(dict(values), dict(common)), bars)) == []
    # mode 2 beyond its reach but named unexcited: it neither hides nor vetoes mode 1's
    # cubic reason (read 28b: the shared reason still counted it)
    far = {**values, "freq_error_mode2": 0.3}
    far_details = {**unexcited, "freq_error_per_mode": np.array([0.05, 0.3])}
    assert sorted(bar_failures(Scores(dict(far), far_details), bars)) == ["cubic", "unexcited"]
