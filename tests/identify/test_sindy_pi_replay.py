"""SINDy-PI's replay rule on exact data (:meth:`identify.sindy_pi.SINDyPI._replay_check`): the
held-out choice must replay the record; where it does not (the record leaves the equations
non-unique), the equations are chosen again by rollout over the unpruned library.

The case: the paper's sine replay on an unseen five-bar (benchmarks/unseen/unseen_linkages.toml,
member fb_sine__004, 0.89 Hz, clean, recorded rates).  The equations the held-out error picks fit
the rates to round-off (held-out error 1e-15) and lose the loop closure at 1.3 s of the record;
the data came from the study's own member, so the test runs what the sweep runs."""

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from identify._implicit import NoModelError, Sweep, select_models
from identify.sindy_pi import EXACT_REPLAY_MAX, REPLAY_NOISE_FACTOR, SINDyPI
from testbed.core.errors import DivergenceError, IdentificationError
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure
from testbed.studies.study import load_study

UNSEEN = Path(__file__).resolve().parents[2] / "benchmarks" / "unseen" / "unseen_linkages.toml"


def _data(dataset_cache, scenario):
    ds = dataset_cache.get(scenario)
    return measure(ds, scenario.signal, "mechanical")


@pytest.fixture(scope="module")
def member004():
    """The study's member fb_sine__004 (clean, recorded rates), as the sweep draws it."""
    return {m.name: m for m in load_study(UNSEEN).scenarios}["fb_sine__004"]


def _replay(model, data, i0=0):
    """RMSE [rad] of the model's simulation of the record trimmed by ``i0`` samples at each
    end, from its first state."""
    sl = slice(i0, data.n_samples - i0)
    tr = model.simulate(data.x[:, i0], data.xd[:, i0], data.t[sl], data.u[:, sl])
    return float(np.sqrt(np.mean((tr.x - data.x[:, sl]) ** 2, axis=1)).max())


def test_rich_record_keeps_the_held_out_choice(dataset_cache):
    data = _data(dataset_cache, load_scenario("fivebar_multisine"))
    m = SINDyPI(input_hold="zoh").fit(data)
    assert m.selection_ == "holdout" and m.replay_rule_.endswith(": kept")
    # measured 6.1e-7 rad (the integration error); the check's bar is 1e-4
    assert m.replay_rmse_ < 1e-5
    assert len(m.pruned_terms_) == 2  # the two kinematic identities only


def test_angles_only_simulation_is_the_same_simulation(dataset_cache):
    """The replay rule's simulations skip the rates and accelerations at the output times;
    the angles are those of the full simulation, bit for bit."""
    data = _data(dataset_cache, load_scenario("fivebar_multisine"))
    m = SINDyPI(input_hold="zoh").fit(data)
    sl = slice(0, 5000)  # 0.5 s of the record
    args = (data.x[:, 0], data.xd[:, 0], data.t[sl], data.u[:, sl], m.sim_dt_, m.input_hold_)
    full, fast = m.model_.simulate(*args), m.model_.simulate(*args, angles_only=True)
    np.testing.assert_array_equal(fast.x, full.x)
    assert fast.xd is None and fast.xdd is None


@pytest.mark.slow
def test_sine_replay_with_non_unique_equations_is_chosen_by_rollout(member004, dataset_cache):
    data = _data(dataset_cache, member004)
    hold = SINDyPI(input_hold="zoh", selection="holdout").fit(data)  # user setting: no rule
    assert hold.replay_rmse_ is None and hold.replay_rule_.startswith("no replay check")
    assert float(np.max(hold.validation_errors_)) < 1e-12  # exact in derivative space ...
    with pytest.raises(DivergenceError, match="loop closure"):  # ... yet loses the loop (1.3 s)
        _replay(hold, data)
    m = SINDyPI(input_hold="zoh").fit(data)
    assert m.selection_ == "rollout" and "chosen again by rollout" in m.replay_rule_
    assert m.pruned_terms_ == []  # the pool is the unpruned library
    # the attribute is the replay of the record from its first state (same simulation)
    assert m.replay_rmse_ == pytest.approx(_replay(m, data), rel=1e-9)
    # measured 1.04e-4 rad over the 8 s record: bar 1e-3, 10x that (a replay over 8 s of a model
    # exact only on the record amplifies round-off), 50x below the paper's 0.0501 rad
    assert m.replay_rmse_ < 1e-3


@pytest.mark.slow
def test_noisy_angles_with_recorded_rates_are_checked_too(member004, dataset_cache):
    """fb_sine__004 at 1 % angle noise (rates recorded): the held-out choice (held-out error
    2e-11) loses the loop; the rule's bar is 1e-4 + 20 x the noise std, so the replay check
    must flag the record's non-unique equations on noisy data too.

    What the second fit then finds is decided by the noise draw, not by the rule: measured
    (2026-11-28, numpy 2.4.6 / pin 4.1.0) over noise seeds 0 / 1 / 2, no shortlisted pair
    simulates (the first fit kept, its divergence named) / re-chosen at 0.969 rad / re-chosen at
    2.2e-3 rad (an earlier environment re-chose seed 0 at 1.9e-3).  So the test asserts the rule
    and that the reported replay is the returned model's own, never which way the draw fell."""
    noisy = dataclasses.replace(member004, noise={**member004.noise, "rms_percent": 1.0})
    data = _data(dataset_cache, noisy)
    hold = SINDyPI(input_hold="zoh", selection="holdout").fit(data)
    i0 = round(hold.edge_trim_ * data.fs)
    with pytest.raises(DivergenceError, match="loop closure"):
        _replay(hold, data, i0)
    m = SINDyPI(input_hold="zoh").fit(data)
    bar = EXACT_REPLAY_MAX + REPLAY_NOISE_FACTOR * float(np.max(m.noise_std_))
    head = f"held-out selection: replay of the record inf rad (<= {bar:.3g} required"
    assert m.replay_rule_.startswith(head) and "equations non-unique on this record" in m.replay_rule_
    if m.selection_ == "rollout":
        assert "chosen again by rollout" in m.replay_rule_
        assert m.replay_rmse_ == pytest.approx(_replay(m, data, i0), rel=1e-9)
    else:  # the first fit kept: its replay is the divergence the rule found, and it is named
        assert m.selection_ == "holdout" and "first fit kept" in m.replay_rule_
        assert m.replay_rmse_ == np.inf
        with pytest.raises(DivergenceError, match="loop closure"):
            _replay(m, data, i0)


def test_no_eligible_model_is_a_typed_error():
    """select_models' "no model for input k" is a NoModelError (the replay rule catches it)."""
    p, n_t = 4, 2
    W = np.zeros((n_t, 2, p))
    W[:, 0, 0] = W[:, 1, 1] = 1.0
    W[:, :, 3] = 0.5  # every model carries input 2 (column 3), none input 1 (column 2)
    sw = Sweep(scale=np.ones(p), candidates=np.array([0, 1]), thresholds=np.array([0.0, 0.1]),
               W=W, val_error=np.full((n_t, 2), 1e-3), train_error=np.full((n_t, 2), 1e-3),
               nnz=np.count_nonzero(W, axis=2))
    with pytest.raises(NoModelError, match="input 1"):
        select_models(sw, [np.array([2]), np.array([3])])
    assert issubclass(NoModelError, IdentificationError)


def _sweep_of(rows, errs, candidates):
    """A one-threshold Sweep of the given normalised equations (rows) and held-out errors."""
    W = np.array(rows, dtype=float)[None]
    return Sweep(scale=np.ones(W.shape[2]), candidates=np.array(candidates),
                 thresholds=np.array([0.0]), W=W, val_error=np.array([errs], dtype=float),
                 train_error=np.array([errs], dtype=float), nnz=np.count_nonzero(W, axis=2))


@pytest.mark.parametrize("share_1", [0.967, 1.059])
def test_a_near_tie_of_input_shares_is_eligible_for_both_inputs(share_1):
    """Session 29 (pi34): a dense equation that mixes both inputs' equations carried input 1's
    terms at 0.967 of input 2's share under one BLAS kernel and 1.059 under another (round 20's
    fb20_ms_short_cranks, clean: 1.8e-6 against 1.2e-4 rad).  Within the tie ``rtol`` it is
    eligible for either input, so input 2's pick (the mix, held-out error at the round-off
    floor, against a sparse equation 1e-9 off) does not depend on which side of 1 the
    round-off put the ratio; input 1 keeps its sparse exact equation (parsimony)."""
    cols = [np.array([2]), np.array([3])]  # input 1's term: column 2; input 2's: column 3
    rows = [[1, 0, 1, 0, 0],               # input 1's equation
            [0, 1, share_1, 1, 0.3],       # the mix, written on column 1
            [0, 0, 0, 0.8, 1]]             # input 2's sparse equation, farther held out
    sw = _sweep_of(rows, [1e-14, 1e-14, 1e-9], [0, 1, 4])
    assert select_models(sw, cols) == [[(0, 0)], [(0, 1)]]


def test_one_equation_is_not_picked_for_two_inputs():
    """The mix eligible for both inputs and the best held out for input 1 is input 1's pick;
    input 2 then takes its next eligible equation, and without one it has none (a typed
    error), never the same first pick twice."""
    cols = [np.array([2]), np.array([3])]
    sw = _sweep_of([[0, 1, 1.059, 1, 0.3], [0, 0, 0, 0.8, 1]], [1e-14, 1e-9], [1, 4])
    assert select_models(sw, cols) == [[(0, 0)], [(0, 1)]]
    alone = _sweep_of([[0, 1, 1.059, 1, 0.3]], [1e-14], [1])
    with pytest.raises(NoModelError, match=r"input 2 .*earlier input"):
        select_models(alone, cols)


def test_cartpole_with_a_barely_excited_pole_gets_its_equations(dataset_cache):
    """benchmarks/unseen/unseen_other.toml, cartpoles__000 (3.8 kg cart, 64 g pole), clean: the
    fit ends with the exact pair on every CPU, by the replay rule where the held-out choice does
    not replay the record.

    Which input equation the held-out error picks is decided by round-off on this record: the
    7-term pole equation plus a 1e-6 input admixture has an input part of 2.7e-17 (normalised
    Gram units) and a residual whose Gram value is round-off of either sign (-3.2e-17 on this
    machine's AVX-512 BLAS kernels, clipped to an input error 0: ranked first by fewest terms,
    replaying to 1.8e-3 rad; positive under an AVX2 kernel, where the exact cart row is ranked
    first and replays to 1.2e-11 rad).  docs/known-gaps.md "Portability (session 18)"."""
    other = Path(__file__).resolve().parents[2] / "benchmarks" / "unseen" / "unseen_other.toml"
    member = {m.name: m for m in load_study(other).scenarios}["cartpoles__000"]
    data = _data(dataset_cache, member)
    kw = {k: v for k, v in member.identify.items() if k != "method"}
    m = SINDyPI(**kw).fit(data)
    bar = EXACT_REPLAY_MAX + REPLAY_NOISE_FACTOR * float(np.max(m.noise_std_))
    hold = SINDyPI(**kw, selection="holdout").fit(data)
    if _replay(hold, data, round(m.edge_trim_ * data.fs)) > bar:  # wrong equations held out
        assert "chosen again by rollout" in m.replay_rule_
    else:  # the held-out choice replays the record: kept by the rule
        assert m.selection_ == "holdout" and m.replay_rule_.endswith(": kept")
    # measured 1.2e-11 rad either way: an exact pair replays to round-off (the shipped
    # cartpole's bar 1e-9)
    assert m.replay_rmse_ < 1e-9
