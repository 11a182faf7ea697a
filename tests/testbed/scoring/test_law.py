"""An open chain's identified law over the record's state box (testbed/scoring/law.py)."""

import numpy as np
import pytest

from models.cartpole.equations import CartPoleParams, true_equations
from testbed.pipeline.scenario import load_scenario
from testbed.scoring.equation_basis import compare_equations, evaluate_terms
from testbed.scoring.law import (
    accelerations,
    free_coordinates,
    law_error,
    law_errors,
    law_rollout,
    linear_split,
    state_box,
)

P = CartPoleParams(cart_mass=1.0, pole_mass=0.5, pole_length=0.6, cart_damping=0.1,
                   pole_damping=0.005, gravity=9.81)


def record(n: int = 3000) -> dict:
    """A stand-in record: only its ranges matter to the box (x 0.3 m, the pole 0.4 rad)."""
    t = np.linspace(0.0, 10.0, n)
    th = np.vstack([0.3 * np.sin(0.7 * t), 0.4 * np.sin(2.1 * t + 0.3)])
    dth = np.vstack([0.21 * np.cos(0.7 * t), 0.84 * np.cos(2.1 * t + 0.3)])
    return {"th": th, "dth": dth, "ddth": np.zeros_like(th), "u": np.atleast_2d(2.0 * np.sin(1.3 * t))}


def test_a_combination_of_the_true_rows_is_the_same_law_that_coefficients_call_wrong(dataset_cache):
    """The cart's equation plus 3x the passive pole's, the pole's doubled: the same
    accelerations everywhere (law_error at round-off), while the row-by-row comparison
    reads it as another equation (round 13's cp13_two_tones: coef_error 2.98, support F1
    0.43 on a law 2.3 % off over its box)."""
    names, coef, _ = true_equations(P)
    mixed = np.vstack([coef[0] + 3.0 * coef[1], 2.0 * coef[1]])
    m = dataset_cache.get(load_scenario("scenarios/cartpole.toml")).measured
    sig = {"th": m["theta"].data, "dth": m["dtheta"].data, "ddth": m["ddtheta"].data,
           "u": m["torque"].data}
    assert law_error(names, mixed, names, coef, sig) < 1e-12
    cmp = compare_equations(names, mixed, names, coef, sig)
    assert cmp["f1"] < 1.0 and cmp["coef_error_norm"] > 1.0  # spurious terms, 3x the pole row


def test_the_box_solves_the_true_law_for_its_accelerations():
    """At every drawn state the true equations vanish at the solved accelerations."""
    names, coef, _ = true_equations(P)
    box = state_box(record(), samples=64)
    ddq = accelerations(names, coef, box)
    resid = evaluate_terms(names, {**box, "ddth": ddq}) @ coef.T
    assert np.abs(resid).max() < 1e-12
    assert box["th"].shape == (2, 64) and box["u"].shape == (1, 64)
    assert np.all(np.abs(box["th"][1]) <= 0.4)  # within the record's own range


def test_a_wrong_law_is_far_and_a_singular_or_non_finite_one_is_nan():
    names, coef, _ = true_equations(P)
    _, wrong, _ = true_equations(CartPoleParams(1.0, 0.5, 1.2, 0.1, 0.005, 9.81))  # twice the pole
    sig = record()
    assert law_error(names, wrong, names, coef, sig) > 0.3
    assert np.isnan(law_error(names, np.vstack([coef[1], coef[1]]), names, coef, sig))
    assert np.isnan(law_error(names, np.full_like(coef, np.nan), names, coef, sig))


def test_no_box_off_an_open_chain():
    """A closed chain (fewer equations than coordinates: the five-bar's 2 for 4 angles) has
    states on its loop closure only: no law_error."""
    names, coef, _ = true_equations(P)
    sig = record()
    sig4 = {k: np.vstack([v, v]) if k != "u" else v for k, v in sig.items()}
    assert law_error(names, coef, names, coef, sig4) is None


def test_the_cartpole_holds_every_run_to_its_law_bar_and_names_a_nan_law():
    """The rig's own bar (models/cartpole/rig.py EQUATION_BARS) on a run held to any bar: round
    6's 10 kg cart at 1 % passed the rollout bar (0.029 < 0.0501) with law_error 0.617; now a
    scored failure naming the law.  A law singular somewhere in the box is named, not "nan"."""
    from models.cartpole.rig import EQUATION_BARS, CartPoleRig
    from testbed.scoring.scorers import FAIL, Scores, equation_failures, verdict

    assert CartPoleRig.equation_bars == EQUATION_BARS == {"law_error": {"max": 0.25}}
    run_bars = {"angle_rmse": {"max": 0.0501}}
    for law, expect in ((0.617, "wrong equation: law_error 0.617 above 0.25"),
                        (float("nan"), "law_error not finite (the identified law gives no finite")):
        sc = Scores({"angle_rmse": 0.029, "law_error": law}, {"equation_bars": EQUATION_BARS})
        failures = equation_failures(sc, run_bars)
        assert expect in failures["equation"]
        assert verdict([], failures) == FAIL
    ok = Scores({"angle_rmse": 0.004, "law_error": 0.011}, {"equation_bars": EQUATION_BARS})
    assert equation_failures(ok, run_bars) == {}
    assert equation_failures(ok, {}) == {}  # no bars at all: "no verdict" stays


def test_a_law_missing_for_want_of_equations_is_named_as_such():
    """An identified set with another number of equations than coordinates has no law to solve:
    the failure said "no finite acceleration ... singular" (review of round 14); it names the
    count."""
    from testbed.scoring.scorers import Scores, equation_failures

    reason = "1 identified equations for 2 coordinates: no accelerations to compare"
    scores = Scores({"law_error": float("nan")},
                    {"equation_bars": {"law_error": {"max": 0.25}}, "law_error_reason": reason}, {})
    (said,) = equation_failures(scores, {"angle_rmse": {"max": 0.05}}).values()
    assert reason in said and "singular" not in said


def test_a_coordinate_the_true_law_never_accelerates_is_not_a_singular_law():
    """0 / 0 gave NaN, read as "no finite acceleration" (review of round 14): where the true
    accelerations of a coordinate are zero over the box, an identified law that agrees scores 0
    and one that accelerates it scores inf."""
    from testbed.scoring.law import law_errors

    names = ["ddth1", "ddth2", "th1", "u1"]
    true = np.array([[1.0, 0.0, 1.0, -1.0], [0.0, 1.0, 0.0, 0.0]])  # ddth2 = 0 everywhere
    sig = record()
    assert np.allclose(law_errors(names, true, names, true, sig), 0.0)
    pushed = np.array([[1.0, 0.0, 1.0, -1.0], [0.0, 1.0, 0.5, 0.0]])
    err = law_errors(names, pushed, names, true, sig)
    assert err[0] == 0.0 and err[1] == np.inf


def test_terms_split_at_their_acceleration():
    rest, which = linear_split(("cos(th2)*ddth1", "ddth2", "sin(th2)*dth2^2", "u1"))
    assert rest == ("cos(th2)", "1", "sin(th2)*dth2^2", "u1") and which.tolist() == [0, 1, -1, -1]
    with pytest.raises(ValueError, match="not linear in the accelerations"):
        linear_split(("ddth1*ddth2",))


def test_a_law_with_a_term_not_linear_in_the_accelerations_scores_nan_not_a_crash():
    """A plugin's identified terms are free: ``ddth1*ddth2`` or ``ddth3`` on two coordinates
    raised ValueError / was dropped in silence (review of session 20); unused (zero) it is left
    out, used it gives no accelerations to compare: NaN, never a pass."""
    names, true = ["ddth1", "ddth2", "th1", "th2"], np.array([[1.0, 0, 1, 0], [0, 1.0, 0, 1]])
    t = np.linspace(0, 1, 50)
    sig = {"th": np.vstack([np.sin(t), np.cos(t)]), "dth": np.vstack([np.cos(t), -np.sin(t)]),
           "u": np.zeros((0, 50))}
    for extra in ("ddth1*ddth2", "ddth3"):
        unused = np.hstack([true, np.zeros((2, 1))])
        assert np.all(law_errors([*names, extra], unused, names, true, sig) == 0.0)
        used = np.hstack([true, np.array([[0.1], [0.0]])])
        assert np.all(np.isnan(law_errors([*names, extra], used, names, true, sig)))


def test_substeps_are_the_finer_step():
    """``substeps`` RK4 steps per sample are the rollout at that finer step, read every
    ``substeps``-th sample (the witness steps no longer than the model: scorers.witness_substeps)."""
    names, coef = ["ddth1", "sin(th1)", "dth1"], np.array([[1.0, 9.81, 0.1]])
    u = np.zeros((0, 201))
    fine = law_rollout(names, coef, np.array([1.0]), np.array([0.0]), np.zeros((0, 401)),
                       5e-3, (1.0,))
    sub = law_rollout(names, coef, np.array([1.0]), np.array([0.0]), u, 1e-2, (1.0,), 2)
    assert np.array_equal(sub[0], fine[0][:, ::2])
    coarse = law_rollout(names, coef, np.array([1.0]), np.array([0.0]), u, 1e-2, (1.0,))
    assert not np.array_equal(coarse[0], sub[0])


def test_the_true_law_rolled_out_follows_the_engine_and_a_scaled_one_does_not(dataset_cache):
    """The scorer's RK4 of the rig's own law at the record's 1 ms step, the recorded force held
    over each sample, from the true start, follows the engine (its 0.1 ms steps with the
    force's feedback inside) over 2 s of the shipped cart-pole to within 1e-9 (the shipped
    scenario's own rollout bar, 30x its measured 3.2e-11; here 3.5e-12 m / 3.1e-11 rad); a law
    off by 5 % (its accelerations scaled) leaves it by 0.031 m / 0.107 rad."""
    ds = dataset_cache.get(load_scenario("scenarios/cartpole.toml"))
    names, coef, _ = true_equations(P)
    th = ds.measured["theta"].data[:, :2000]
    u = ds.measured["torque"].data[:, :2000]
    x = law_rollout(names, coef, th[:, 0], ds.measured["dtheta"].data[:, 0], u, 1e-3, (1.0, 1.05))
    assert x.shape == (2, 2, 2000)
    assert np.max(np.abs(x[0] - th)) < 1e-9
    assert np.max(np.abs(x[1] - th)) > 0.01


def test_the_cart_is_the_true_laws_free_coordinate_and_the_pole_is_not():
    """The cart-pole's true law holds the cart's rate and acceleration, never its position; the
    pole's angle is in its sines and cosines.  A term with no coefficient does not count."""
    names, coef, _ = true_equations(P)
    assert free_coordinates(names, coef, 2) == [0]
    held = np.hstack([coef, np.array([[0.0], [1.0]])])
    assert free_coordinates([*names, "th1"], held, 2) == []
    assert free_coordinates([*names, "th1"], np.hstack([coef, np.zeros((2, 1))]), 2) == [0]
    assert free_coordinates(["sin(th1-th3)*ddth2"], np.array([[1.0]]), 3) == [1]
