"""SINDy-PI's open-chain form comparison (:meth:`identify.sindy_pi.SINDyPI._open_chain_form`,
``formulation_rule_``): on an open chain (a cart-pole) whose rates a declared low-pass chain
derived, the strong fit the noise rule chose is redone in the weak form and the weak one kept
only where its segmented rollout error is smaller beyond the rollout selection's tie
(``selection_rtol``, ``ROLLOUT_ATOL``) over the span both fits keep.

The cases are cells of the unseen rounds' studies (benchmarks/unseen/), run as the sweep runs
them: round 11's ``cp11_near_rest`` at 3 % (seed 21), which the strong form failed (the cart
drifted: 0.054 m) and the weak form passes, and round 5's family cart-pole ``cpchain__000`` at
3 % (seed 0), a 4.3 s record whose weak fit scores 12.3 rad while the strong one passes its
rollout bar: the comparison keeps the strong one there."""

import dataclasses
from pathlib import Path

from testbed.scoring.run import run_scenario
from testbed.studies.study import load_study
from testbed.studies.sweep import expand

UNSEEN = Path(__file__).resolve().parents[2] / "benchmarks" / "unseen"


def _run_cell(dataset_cache, study_file: str, name: str, noise: float, seed: int, **identify):
    """The scored run of one cell of an unseen round's study (identify settings overridden)."""
    study = load_study(UNSEEN / study_file)
    cell = next(c for c in expand(study)
                if c.scenario.name == name and c.noise == noise and c.seed == seed)
    sc = cell.scenario
    if identify:
        sc = dataclasses.replace(sc, identify={**sc.identify, **identify})
    return run_scenario(sc, dataset=dataset_cache.get(sc))


def test_weak_form_kept_where_its_rollout_is_smaller(dataset_cache):
    # before the comparison: the strong form, 0.0539 (the cart drifting under the replayed
    # force; the pole 5e-4 rad); the weak form's rollout 0.0013 against the strong's 0.0148
    r = _run_cell(dataset_cache, "round11_linkages_cartpoles.toml", "cp11_near_rest", 3.0, 21)
    m = r.model
    assert m.formulation_ == "weak"
    assert "weak form kept (smaller beyond the tie)" in m.formulation_rule_
    assert "open chain's form comparison" in m.noise_rule_ and "user setting" not in m.noise_rule_
    # measured 0.0107; the bar is the round's (the paper's 0.0501)
    assert r.passed and r.scores.values["angle_rmse"] < 0.0501


def test_strong_form_kept_where_the_weak_rollout_is_larger(dataset_cache):
    # the weak fit of this short record (4.3 s: test functions capped at 0.35 s) rolls out at
    # 0.059 against the strong's 6.9e-4 and scores 12.3 rad from the true start
    r = _run_cell(dataset_cache, "round5_other.toml", "cpchain__000", 3.0, 0)
    m = r.model
    assert m.formulation_ == "strong"
    assert "strong form kept (the weak not smaller beyond the tie)" in m.formulation_rule_
    # the rollout as before the comparison (measured 0.0131; 0.0063 since session 23).  From
    # round 14 to session 22 the cart-pole's law bar failed the cell (law_error 0.287, models/
    # cartpole/rig.py EQUATION_BARS): the pole's selected row was the identity of nearly equal
    # columns 0.98 ddth1 - cos(th2)*ddth1 (the pole swings little under the heavy cart), ranked
    # first per unit of its left-hand side; tested per unit of the part holding ddth2
    # (identify._implicit.select_passive_models) it is refuted: law_error 0.166, the cell passes
    assert r.scores.values["angle_rmse"] < 0.0501
    assert r.scores.values["law_error"] < 0.25
    assert r.passed, r.scores.failures
    # nothing of the weak trial stays on the strong model (review: its weak-only attributes did)
    assert not hasattr(m, "weak_strong_columns_") and not hasattr(m, "_weak_trial")


def test_user_set_form_is_not_compared(dataset_cache):
    r = _run_cell(dataset_cache, "round11_linkages_cartpoles.toml", "cp11_near_rest", 3.0, 21,
                  formulation="strong")
    assert r.model.formulation_ == "strong"
    assert r.model.formulation_rule_ == "not applied: formulation user-set"


def test_a_user_s_column_low_pass_is_not_compared(dataset_cache):
    # the weak form refuses a user's column low-pass: the comparison raised ValueError
    # ("column_lowpass_hz applies to the strong form only") instead of fitting
    r = _run_cell(dataset_cache, "round11_linkages_cartpoles.toml", "cp11_near_rest", 3.0, 21,
                  column_lowpass_hz=3.0)
    assert r.model.formulation_ == "strong"
    assert r.model.formulation_rule_ == "not applied: column_lowpass_hz user-set"


def test_closed_chain_never_compared(dataset_cache):
    # the paper's sine at 1.5 %, seed 13 (round 10's inputs): a five-bar, its loop closed
    r = _run_cell(dataset_cache, "round10_linkages_inputs.toml", "fivebar_sine_replay_noise1",
                  1.5, 13)
    assert r.model.formulation_ == "strong"
    assert r.model.formulation_rule_.startswith("not applied: no open chain")
