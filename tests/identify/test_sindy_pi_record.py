"""SINDy-PI's record rule (:meth:`identify.sindy_pi._ImplicitMechanical._record_rule`,
``record_rule_``): the rollout selection does not choose a shortlisted combination whose
simulation of the whole record, from its first measured state, loses its loop closure or
diverges, while another can simulate it; where none can, the fit is redone over the unpruned
library (:meth:`identify.sindy_pi.SINDyPI._unpruned_refit`).

The case: the paper's sine input on family geometry 024 at 1 % angle noise with the rates the
chain's low-pass estimated (benchmarks/unseen/round5_linkages_sine.toml, member fbsine__024).
Its rollout selection chose a pair that predicted every sixth of the trimmed record within 1e-4
rad, yet lost its loop closure at 6.5 s of the record from the measured start (and at 2.0 s
from the true one: a scored divergence); the data came from the study's own member, so the
test runs what the sweep runs."""

from pathlib import Path

import numpy as np
import pytest

from identify import sindy_pi as sp
from identify.sindy_pi import SINDyPI
from testbed.core.errors import DivergenceError, IdentificationError
from testbed.core.measurement import Trajectory
from testbed.pipeline.signal_chain import measure
from testbed.studies.study import load_study

ROUND5 = Path(__file__).resolve().parents[2] / "benchmarks" / "unseen" / "round5_linkages_sine.toml"


class _Model:
    """A stand-in identified model: simulates to zeros, or diverges."""

    def __init__(self, diverges: bool):
        self.diverges = diverges
        self.calls = 0

    def simulate(self, x0, xd0, t, u, dt, hold, angles_only=False):
        self.calls += 1
        if self.diverges:
            raise DivergenceError("loop closure Newton solve did not converge", time=1.0)
        return Trajectory(np.zeros((x0.size, t.size)), None, None)


class _Data:
    def __init__(self, n=50):
        self.t = np.arange(n) / 100.0
        self.x = np.zeros((4, n))
        self.xd = np.zeros((4, n))
        self.u = np.zeros((2, n))


def _rule(scores, diverge, **params):
    m = SINDyPI(**params)
    m.input_hold_ = "zoh"
    models = [_Model(d) for d in diverge]
    out = m._record_rule(list(scores), list(models), _Data())
    return m, out, models


def test_combinations_that_lose_the_record_are_left_out():
    m, out, models = _rule([1e-4, 2e-4, np.inf, 3e-4], [True, False, False, False])
    assert out == [np.inf, 2e-4, np.inf, 3e-4]
    assert m.record_replays_.tolist() == [False, True, False, True]
    assert models[2].calls == 0  # a combination whose rollout failed is not simulated again
    assert m.record_rule_.startswith("2 of 4 shortlisted combinations simulate the whole record")
    assert "excluded" in m.record_rule_


def test_no_combination_left_keeps_the_rollout_scores():
    m, out, _ = _rule([1e-4, 2e-4], [True, True])
    assert out == [1e-4, 2e-4]
    assert not m.record_replays_.any() and "none excluded" in m.record_rule_


class _Replay:
    """A stand-in model whose simulation of the record is a fixed array."""

    def __init__(self, sim):
        self.sim = sim

    def simulate(self, x0, xd0, t, u, dt, hold, angles_only=False):
        return Trajectory(self.sim.copy(), None, None)


def test_a_finite_replay_farther_than_rest_is_not_a_replay():
    # round 9's fb9_asym3 at 1 % (seed 9): the one pair that did not diverge followed the
    # record 4.7 x worse than rest and lost its loop from the true start; the divergence test
    # alone kept it (this test fails on that rule: every array below is finite)
    data = _Data(200)
    data.x = 1.5 + 0.07 * np.cos(np.outer([1.0, 0.3, 0.2, 1.0], data.t * 2.0))
    rest = np.repeat(data.x[:, :1], data.t.size, axis=1)
    mirrored = 2.0 * rest - data.x              # RMSE 2 x rest's on every coordinate
    one_off = data.x.copy()
    one_off[2] = 2.0 * rest[2] - data.x[2]       # only one coordinate farther than rest
    m = SINDyPI()
    m.input_hold_ = "zoh"
    m.closure_ = None          # an open chain (a cart-pole): the rest baseline does not apply
    assert m._replays_record(_Replay(mirrored), data)
    m.closure_ = object()      # a closed chain: the loop holds every coordinate near the record
    assert m._replays_record(_Replay(data.x), data)
    assert m._replays_record(_Replay(rest), data)       # rest itself: the bar, met
    assert not m._replays_record(_Replay(mirrored), data)
    assert not m._replays_record(_Replay(one_off), data)
    out = m._record_rule([1e-4, 2e-4], [_Replay(mirrored), _Replay(data.x)], data)
    assert out == [np.inf, 2e-4] and m.record_replays_.tolist() == [False, True]
    # none nearer than rest: the divergence test alone (the rule before), and record_replays_
    # all False, so the unpruned library is tried (SINDyPI._unpruned_refit)
    out = m._record_rule([1e-4, 2e-4], [_Replay(mirrored), _Model(diverges=True)], data)
    assert out == [1e-4, np.inf] and not m.record_replays_.any()
    assert "1 simulate it without diverging: the others excluded" in m.record_rule_


def test_user_turns_the_rule_off():
    m, out, models = _rule([1e-4, 2e-4], [True, False], record_replay=False)
    assert out == [1e-4, 2e-4] and m.record_replays_ is None
    assert m.record_rule_.startswith("user-set") and sum(x.calls for x in models) == 0


def test_held_out_selection_states_the_rule_unused(dataset_cache):
    from testbed.pipeline.scenario import load_scenario

    data = measure(dataset_cache.get(load_scenario("fivebar_multisine")),
                   load_scenario("fivebar_multisine").signal, "mechanical")
    m = SINDyPI(input_hold="zoh").fit(data)
    assert m.selection_ == "holdout" and m.record_rule_.startswith("not applied")


@pytest.mark.slow
def test_sine_replay_pair_that_loses_the_record_is_not_chosen(dataset_cache):
    member = {s.name: s for s in load_study(ROUND5).scenarios}["fbsine__024"]
    data = measure(dataset_cache.get(member), member.signal, "mechanical")

    def whole(model):  # the whole record from its first measured state (the rule's simulation)
        return model.model_.simulate(data.x[:, 0], data.xd[:, 0], data.t, data.u, model.sim_dt_,
                                     model.input_hold_, angles_only=True).x

    off = SINDyPI(input_hold="zoh", record_replay=False).fit(data)
    assert off.selection_ == "rollout" and off.record_rule_.startswith("user-set")
    with pytest.raises(DivergenceError, match="loop closure"):  # measured: at 6.5 s
        whole(off)
    m = SINDyPI(input_hold="zoh").fit(data)
    assert "excluded" in m.record_rule_ and not m.record_replays_.all()
    assert np.isfinite(whole(m)).all()


def test_no_combination_simulating_its_segments_is_fitted_again_unpruned(monkeypatch):
    # the record rule's second fit, where the first left not even the rollout segments
    # simulated (it used to end the fit: "no shortlisted model combination could be simulated")
    from identify.sindy_pi import NoSimulationError, _ImplicitMechanical

    def first_fails(self, data, kept):
        self.record_replays_ = np.zeros(9, dtype=bool) if not self._unpruned else np.array(kept)
        self.record_rule_ = "not reached" if not self._unpruned else "1 of 1 simulate"
        if not self._unpruned:
            raise NoSimulationError("no shortlisted model combination could be simulated")
        return self

    from testbed.core.measurement import Measurement

    # a Measurement (the identifiers' fit takes no other object since session 15's API round)
    # of _Data's shape: four angles and two inputs at rest
    z = _Data()
    data = Measurement(fs=100.0, x=z.x, xd=z.xd, xdd=np.zeros_like(z.x),
                       channels=("th1", "th2", "th3", "th4"), u=z.u, inputs=("u1", "u2"))
    for kept, ok in (([True], True), ([False], False)):
        monkeypatch.setattr(_ImplicitMechanical, "fit",
                            lambda self, data, kept=kept: first_fails(self, data, kept))
        m = SINDyPI(input_hold="zoh", selection="rollout")
        if ok:
            assert m.fit(data) is m
            assert "fitted again over the unpruned library" in m.record_rule_
        else:   # nor the unpruned library: a fit failure naming both
            with pytest.raises(IdentificationError, match="nor over the unpruned library"):
                m.fit(data)


def _run_cell(dataset_cache, study_file: str, name: str, noise: float, seed: int):
    """The scored run of one cell of an unseen round's study (benchmarks/unseen/)."""
    from testbed.scoring.run import run_scenario
    from testbed.studies.sweep import expand

    study = load_study(ROUND5.parent / study_file)
    cell = next(c for c in expand(study)
                if c.scenario.name == name and c.noise == noise and c.seed == seed)
    return run_scenario(cell.scenario, dataset=dataset_cache.get(cell.scenario))


@pytest.mark.slow
def test_sine_replay_at_3_percent_whose_segments_never_simulated(dataset_cache):
    # round 7's fbsine__002 at 3 %, seed 4 (benchmarks/unseen/round7_linkages_sine_seeds.toml):
    # no pair of the pruned library simulated its segments (a fit failure until 2026-11-27);
    # the unpruned library's pair scores 0.0078 rad (the bar: the paper's 0.0501)
    r = _run_cell(dataset_cache, "round7_linkages_sine_seeds.toml", "fbsine__002", 3.0, 4)
    assert "fitted again over the unpruned library" in r.model.record_rule_
    assert r.passed and r.scores.values["angle_rmse"] < 0.0501


@pytest.mark.slow
def test_round9_pair_farther_than_rest_is_not_chosen(dataset_cache):
    # round 9's fb9_asym3 (links 0.5 / 1.5 / 1.2 / 0.8 m, base 1.1 m) under the paper's sine at
    # 1 %, seed 9: the divergence test left one pair of 9, 0.157 rad from the record on a 0.07
    # rad swing, which lost its loop from the true start at 9.06 s (scored "diverged"); with
    # the rest baseline none is left and the unpruned library's pair scores 0.0030 rad
    r = _run_cell(dataset_cache, "round9_linkages_geometry.toml", "fb9_asym3", 1.0, 9)
    assert "fitted again over the unpruned library" in r.model.record_rule_
    assert r.passed and r.scores.values["angle_rmse"] < 0.0501


@pytest.mark.slow
def test_wider_search_where_no_shortlisted_pair_replays_the_record(dataset_cache, monkeypatch):
    # round 15's fb15_cranks_0p8_1p5_3s (cranks 0.8 / 1.5 m, couplers 1.2 m, the paper's sine,
    # 3 s) at 2 %, seed 63: none of the shortlist's 3 x 3 pairs nor the unpruned library's
    # replays the record from its first measured state; without the wider search the first
    # fit's choice was kept and lost its loop closure from the true start at 0.32 s (a scored
    # "diverged"); among the 10 best per input, two more pairs replay it and the one chosen
    # scores 0.017 rad (measured; the bar: the paper's 0.0501)
    # The edge trim as it was then (a quarter of the record, 0.75 s): since session 21 the
    # excitation cap (EDGE_KEEP_EXCITATION) trims this record 0.388 s and its shortlist
    # replays (0.0063 rad, no wider search); the search is tested on the case it was made for
    monkeypatch.setattr(sp, "EDGE_KEEP_EXCITATION", 0.0)
    r = _run_cell(dataset_cache, "round15_linkages_sine_seeds.toml", "fb15_cranks_0p8_1p5_3s",
                  2.0, 63)
    assert "best per input searched" in r.model.record_rule_
    assert "that replay the record scored" in r.model.record_rule_
    assert r.passed and r.scores.values["angle_rmse"] < 0.0501
    assert r.model._replays_record(r.model.model_, r.data)  # the rule's own test, on the choice
    # the rule without its wider search (as before it): the first fit kept, a scored divergence
    monkeypatch.setattr(SINDyPI, "_wide_record_on", False)
    old = _run_cell(dataset_cache, "round15_linkages_sine_seeds.toml", "fb15_cranks_0p8_1p5_3s",
                    2.0, 63)
    assert old.model.record_rule_.endswith("first fit kept (no wider search: off for this "
                                           "identifier)")
    # how it diverges is decided by rounding: the loop's closure lost ("no assembly") on one
    # BLAS kernel, the state not finite at 0.32 s under OPENBLAS_CORETYPE=Haswell
    assert not old.passed and old.scores.failures["simulation"].startswith("diverged")


def test_wider_search_not_for_open_chains_nor_ensembles():
    # the rest baseline of the record rule is a closed chain's (an open chain's free
    # coordinate drifts under replayed forces), and an ensemble's aggregate is none of the
    # combinations compared: the search states why it did not run, and nothing is adopted
    m = SINDyPI(ensemble=3)
    m._wide_ctx, m.closure_ = object(), object()
    assert not m._wide_record(None, "head")
    assert m.record_rule_ == "head: first fit kept (no wider search: ensemble)"
    m = SINDyPI()
    m._wide_ctx, m.closure_ = object(), None
    assert not m._wide_record(None, "head")
    assert m.record_rule_ == "head: first fit kept (no wider search: an open chain)"
    m._wide_ctx = None   # a fit that made no rollout selection
    assert not m._wide_record(None, "head")
    assert m.record_rule_ == "head: first fit kept (no wider search: no rollout selection)"
    assert not hasattr(m, "coef_")


def test_the_step_budget_counts_the_wider_search():
    """The load-time step budget counts the wider search's worst case (one simulation of the
    record per pair of the 10 best per input not yet simulated: 100 - 9 = 91) where it can run
    (no ensemble); before (review of session 20) it counted the shortlist's 9 alone, admitting
    records about 3x longer than its worst case fits in."""
    from identify.sindy_pi import SIM_DT_START, WIDE_ROLLOUT, SINDyPI

    p = SINDyPI.validate_hyperparameters({}, file="x", section="identify")
    record_s = 10.0
    one = record_s / SIM_DT_START  # one simulation of the record at the rule's first step
    plain = SINDyPI.simulation_steps(dict(p, ensemble=5), record_s)[0]
    wide = SINDyPI.simulation_steps(p, record_s)[0]
    assert wide - plain == pytest.approx(one * (WIDE_ROLLOUT**2 - p["n_rollout"] ** 2), rel=1e-12)
