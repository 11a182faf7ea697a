"""SINDy-PI's damped refit of the replay rule (identify/sindy_pi.py ``_damped_refit``,
``_damped_ridge``, ``UNPRUNED_RIDGE_PER_TOL``): on exact data, where the held-out choice does not
replay the record and the unpruned library's fit at the noise rule's ridge (1e-14) replays no
better, the unpruned library is fitted again with the ridge 10 x ``prune_tol``, which damps the
directions of the Gram matrix the pruning calls dependent.

The case: round 18's ``fb18_f0p5_rec`` (benchmarks/unseen/round18 on main; the shipped sine
replay at 0.5 Hz, clean, recorded rates), built here from ``fivebar_sine_replay``.  Before the
rule: the held-out choice replayed 0.0157 rad, no pair of the unpruned shortlist at ridge 1e-14
could be simulated, and the first fit was kept (scored 0.0157 rad against the clean bar 1e-4).
A shorter record of the rig does not show the cause (2 / 4 / 6 s: the held-out choice replays
within 1e-4 rad, or the rule-ridge refit does)."""

from types import SimpleNamespace

import numpy as np
import pytest

from identify.sindy_pi import RIDGE_EXACT, UNPRUNED_RIDGE_PER_TOL, SINDyPI
from testbed.pipeline.scenario import load_scenario
from testbed.scoring.run import run_scenario


def _sine_0p5hz():
    base = load_scenario("fivebar_sine_replay")
    return base.replace(name="fb18_f0p5_rec", excitation={**base.excitation, "frequency": 0.5})


def test_clean_sine_at_half_a_hertz_is_chosen_again_with_the_damped_ridge(dataset_cache):
    sc = _sine_0p5hz()
    result = run_scenario(sc, dataset=dataset_cache.get(sc))
    m = result.model
    assert m.selection_ == "rollout"
    assert "equations non-unique on this record" in m.replay_rule_
    assert f"chosen again by rollout with ridge {UNPRUNED_RIDGE_PER_TOL * 1e-9:.3g}" in m.replay_rule_
    # the reported replay is the returned model's (one segment over the untrimmed record)
    assert m.replay_rmse_ == pytest.approx(m._rollout_error(m.model_, result.data, 0, 1), rel=1e-9)
    # scored against the rig's truth: measured 9.8e-6 rad (0.0157 before); the bar is the
    # issue's clean 1e-4 rad, the scenario's own
    rmse = result.scores.values["angle_rmse"]
    assert np.isfinite(rmse) and rmse <= 1e-4
    assert result.passed


@pytest.mark.parametrize(("ridge", "prune_tol", "rule_ridge", "expected"), [
    (None, 1e-9, RIDGE_EXACT, 1e-8),   # exact data: the rule's 1e-14 is raised to 10 x 1e-9
    (None, 1e-9, 1.2e-6, None),        # a chain's ridge (1 % floor) already damps more
    (1e-14, 1e-9, RIDGE_EXACT, None),  # the user's ridge is kept
    (None, None, RIDGE_EXACT, None),   # no pruning asked for: nothing to damp
])
def test_damped_ridge_only_raises_the_rule_ridge(ridge, prune_tol, rule_ridge, expected):
    fit = SINDyPI(ridge=ridge, prune_tol=prune_tol)
    fit.ridge_ = rule_ridge
    got = fit._damped_ridge()
    assert got == (None if expected is None else pytest.approx(expected, rel=1e-12))


def test_damped_refit_keeps_nothing_that_does_not_beat_the_first_fit(monkeypatch):
    """A damped fit that replays no better than the first fit (tie rule) leaves the state as it
    was; one that fails to fit leaves it too."""
    fit = SINDyPI()
    fit.ridge_ = RIDGE_EXACT
    fit.selection_rtol = 0.1
    fit.edge_trim_ = 0.0
    fit.marker_ = "before"

    def fake_fit(self, data):
        self.marker_ = "damped"
        self.model_ = None
        return self

    monkeypatch.setattr("identify.sindy_pi._ImplicitMechanical.fit", fake_fit)
    monkeypatch.setattr(SINDyPI, "_rollout_error", lambda self, *a: 0.0105)
    data = SimpleNamespace(fs=1000.0)
    assert not fit._damped_refit(data, 0.011, "head", np.inf)  # 0.011 <= 0.0105 x 1.1 + 1e-4
    assert fit.marker_ == "before" and not getattr(fit, "_damped", False)
    assert fit._damped_refit(data, 0.02, "head", np.inf)
    assert fit.marker_ == "damped" and fit.replay_rmse_ == 0.0105
    assert "chosen again by rollout with ridge 1e-08" in fit.replay_rule_
