"""SINDy-PI's inertia rule (identify/sindy_pi.py ``_inertia_rule``, ``gain_crossing``;
identify/_mechsim.py ``ImplicitModel.gain_determinants``): a model whose input gain's
determinant changes sign on the record's states (its reduced inertia vanishes there) is not
simulated, and where no candidate is left the fit fails with that reason."""

from types import SimpleNamespace

import numpy as np
import pytest

from benchmarks import sindy_pi_problems
from identify._mechsim import ImplicitModel
from identify.library import Library
from identify.sindy_pi import INERTIA_FAILURE, NoSimulationError, SINDyPI, gain_crossing

# eq 1: ddth1 = u1; eq 2: w(th1) ddth2 = u2, so det(d ddq / du) = s1 s2 / w(th1)
LIB = Library(["ddth1", "ddth2", "cos(th1)*ddth2", "u1", "u2"], n_coords=2, n_inputs=2)


def _model(w_cos: float, w_one: float) -> ImplicitModel:
    coef = np.array([[1.0, 0.0, 0.0, -1.0, 0.0],
                     [0.0, w_one, w_cos, 0.0, -1.0]])
    return ImplicitModel(LIB, coef, np.array([0, 1]), None)


def _states(th1_end: float, n: int = 201):
    q = np.vstack([np.linspace(0.0, th1_end, n), np.linspace(0.0, 0.3, n)])
    return q, np.ones_like(q)


def test_gain_determinant_is_the_analytic_inverse_inertia():
    q, dq = _states(1.2)
    scale = np.array([2.0, 0.5])
    det, index, why = _model(1.0, 0.0).gain_determinants(q, dq, scale)
    assert why == "" and index == -1
    # exact but for the rounding of the affine differences: 1e-15 relative
    np.testing.assert_allclose(det, scale.prod() / np.cos(q[0]), rtol=1e-12)
    assert gain_crossing(det) == -1


def test_a_determinant_crossing_zero_is_found_where_it_changes_sign():
    q, dq = _states(2.0)  # th1 passes pi/2: cos(th1) ddth2 has no inertia there
    det, _, why = _model(1.0, 0.0).gain_determinants(q, dq, np.ones(2))
    assert why == ""
    j = gain_crossing(det)
    assert j == int(np.argmax(q[0] > np.pi / 2))
    assert gain_crossing(np.array([1.0, 2.0, np.nan])) == 2
    assert gain_crossing(np.array([0.0, 1.0])) == 0
    assert gain_crossing(np.array([-1.0, -3.0])) == -1


def test_a_determinant_touching_zero_at_round_off_is_zero_whichever_its_sign():
    # zero is a band (GAIN_ZERO_EPS eps of the largest |det|), so the last bit's sign decides
    # nothing: +1e-17 and -1e-17 against a largest 1 both exclude the pair at that state
    assert gain_crossing(np.array([1.0, 0.5, 1e-17, 0.7])) == 2
    assert gain_crossing(np.array([1.0, 0.5, -1e-17, 0.7])) == 2
    assert gain_crossing(np.array([-1.0, -0.5, 1e-17, -0.7])) == 2
    assert gain_crossing(np.array([1.0, 0.5, 1e-12, 0.7])) == -1  # above the band: a sign
    assert gain_crossing(np.array([1e-17, 0.5, 0.7])) == 0


def test_equations_singular_at_a_state_are_named():
    q, dq = _states(1.0)
    det, index, why = _model(0.0, 0.0).gain_determinants(q, dq, np.ones(2))  # no ddth2 at all
    assert det is None and why == "singular" and index == 0


def _rule(models, wide_models=()):
    fit = SINDyPI()
    fit._library_ = LIB
    q, dq = _states(2.0)
    data = SimpleNamespace(x=q, xd=dq, u=np.ones((2, q.shape[1])), t=np.arange(q.shape[1]) * 0.01,
                           fs=100.0)
    combos = [(("s", i),) for i in range(len(models))]
    wide = [[("w", i) for i in range(len(wide_models))]]
    made = dict(zip(wide[0], wide_models, strict=True))
    return fit, fit._inertia_rule(combos, list(models), data, lambda: wide,
                                  lambda c: made[c[0]])


def test_a_constructed_model_whose_determinant_crosses_zero_is_excluded():
    crossing, physical = _model(1.0, 0.0), _model(0.5, 1.0)  # w = 1 + cos(th1) / 2 > 0
    fit, (_, models, keep) = _rule([crossing, physical])
    assert keep.tolist() == [False, True] and models == [crossing, physical]
    assert fit.inertia_rule_.startswith("1 of 2 shortlisted")


def test_none_left_searches_wider_then_names_the_failure():
    crossing, physical = _model(1.0, 0.0), _model(0.5, 1.0)
    _, (combos, models, keep) = _rule([crossing], [crossing, physical])
    assert models == [physical] and keep.tolist() == [True] and combos == [(("w", 1),)]
    with pytest.raises(NoSimulationError, match=INERTIA_FAILURE):
        _rule([crossing], [crossing])


def test_where_the_rule_excludes_nothing_the_fit_is_unchanged(monkeypatch):
    # the synthetic five-bar (exact, 1 kHz, 4 s) chosen by rollout: every shortlisted pair
    # keeps its reduced inertia, and the pair, its coefficients and its score are those of the
    # selection without the rule, bit for bit
    data = sindy_pi_problems.fivebar(duration=4.0, fs=1e3, amp=1.0).data
    on = SINDyPI(selection="rollout").fit(data)
    assert on.inertia_rule_.endswith("none excluded")
    monkeypatch.setattr(SINDyPI, "_inertia_rule_on", False)
    off = SINDyPI(selection="rollout").fit(data)
    assert off.inertia_rule_ == "not applied: off for this identifier"
    assert np.array_equal(on.coef_, off.coef_) and on.rollout_rmse_ == off.rollout_rmse_


def test_held_out_selection_states_the_rule_unused():
    data = sindy_pi_problems.fivebar(duration=4.0, fs=1e3, amp=1.0).data
    m = SINDyPI().fit(data)
    assert m.selection_ == "holdout" and m.inertia_rule_.startswith("not applied: models chosen")
