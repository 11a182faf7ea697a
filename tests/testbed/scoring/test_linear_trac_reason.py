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
             share: float | None = 0.26, bars: dict = BARS, **failed: str) -> dict[str, str]:
    details = {"trac": np.array(trac), "channels": CHANNELS}
    if linear is not None:
        details["truth_linear_trac"] = np.array(linear)
    if share is not None:
        details["truth_cubic_share"] = share
    return bar_failures(Scores({"trac": float(np.min(trac)), "K3_norm": k3_norm}, details,
                               dict(failed)), bars)


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
    # the bar met, or no TRAC bar: nothing to explain
    assert failures([0.95, 0.96, 0.97], [0.806, 0.671, 0.790]) == {}
    assert failures([0.941, 0.899, 0.935], [0.806, 0.671, 0.790],
                    bars={"mac": {"min": 0.9}}) == {}


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
