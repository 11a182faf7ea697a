"""SINDy-PI's simulation settings chosen from the data: the inputs' hold as the data declare it
(``input_hold_rule_``) and the RK4 step by Richardson's test on the fitted model
(``sim_dt_rule_``); a user's setting overrides each rule."""

import dataclasses
import itertools

import numpy as np
import pytest

from benchmarks import sindy_pi_problems as P
from identify.sindy_pi import SIM_DT_REL_TOL, SIM_DT_START, SINDyPI, choose_sim_dt, sim_dt_candidates
from testbed.core.errors import IdentificationError
from testbed.core.measurement import ZOH_DECLARATION, declared_input_hold


def test_a_declared_hold_is_read_from_the_provenance():
    assert declared_input_hold({"torque_hold": ZOH_DECLARATION, "rig": "fivebar"}) == "zoh"
    assert declared_input_hold({"torque_hold": "something else"}) is None
    assert declared_input_hold({}) is None


def test_candidates_go_onto_the_sample_grid_where_it_is_finer():
    assert sim_dt_candidates(1e4)[:4] == pytest.approx([1e-3, 5e-4, 1e-4, 5e-5])
    # a slow record: halves of the start (its grid is coarser than 0.5 ms)
    assert sim_dt_candidates(1e3)[:4] == pytest.approx([1e-3, 5e-4, 2.5e-4, 1.25e-4])
    steps = sim_dt_candidates(1e4)
    assert all(a > b for a, b in itertools.pairwise(steps))


def _fake(error_per_dt2: float, fail_above: float = np.inf):
    """A 'simulation' whose error is ``error_per_dt2 * dt^2`` (motion range 1)."""
    x = np.vstack([np.linspace(0.0, 1.0, 50)])

    def simulate(dt: float) -> np.ndarray:
        if dt > fail_above:
            raise IdentificationError("diverged")
        return x + error_per_dt2 * dt ** 2

    return simulate, x


def test_the_first_step_the_next_does_not_move_is_kept():
    # error 1 * dt^2: 1 ms -> 0.5 ms moves 7.5e-7 <= 2.5e-6: 1 ms kept
    dt, rule = choose_sim_dt(*_fake(1.0), fs=1e4)
    assert dt == SIM_DT_START and "<= 2.5e-06" in rule
    # 100x the error: 1 -> 0.5 ms moves 7.5e-5, 0.5 -> 0.1 ms 2.4e-5, 0.1 -> 0.05 ms 7.5e-7
    dt, rule = choose_sim_dt(*_fake(100.0), fs=1e4)
    assert dt == pytest.approx(1e-4)
    moved = 100.0 * (1e-4 ** 2 - 5e-5 ** 2)
    assert moved <= SIM_DT_REL_TOL and f"{moved:.2g}" in rule


def test_a_step_at_which_the_model_fails_is_refined_and_never_kept():
    # fails at 1 ms only: 0.5 ms, which 0.1 ms moves by 2.4e-7, is kept
    dt, rule = choose_sim_dt(*_fake(1.0, fail_above=7e-4), fs=1e4)
    assert "0.0005 s" in rule
    assert dt == pytest.approx(5e-4)


def test_a_model_failing_at_two_successive_steps_is_not_refined_further():
    calls = []
    simulate, x = _fake(1.0, fail_above=2e-4)

    def counted(dt):
        calls.append(dt)
        return simulate(dt)

    dt, rule = choose_sim_dt(counted, x, fs=1e4)
    assert dt == SIM_DT_START and "alike" in rule
    assert calls == pytest.approx([1e-3, 5e-4])  # no finer (costlier) failing simulation


def test_not_converged_keeps_the_finest_and_says_so():
    dt, rule = choose_sim_dt(*_fake(1e9), fs=1e4)
    assert dt == pytest.approx(sim_dt_candidates(1e4)[-1]) and "not converged" in rule


@pytest.fixture(scope="module")
def fivebar():
    # 1 kHz, exact rates: the torques are sampled signals interpolated linearly (no hold declared)
    return P.fivebar(duration=4.0, fs=1e3, amp=1.0).data


def test_rules_on_a_fit_and_user_settings_override_them(fivebar):
    m = SINDyPI().fit(fivebar)
    assert m.input_hold_ == "linear" and "declare no hold" in m.input_hold_rule_
    assert m.sim_dt_ in sim_dt_candidates(fivebar.fs) and "motion's range" in m.sim_dt_rule_
    held = SINDyPI().fit(dataclasses.replace(fivebar, input_hold="zoh"))
    assert held.input_hold_ == "zoh" and "as the data declare" in held.input_hold_rule_
    user = SINDyPI(sim_dt=2e-3, input_hold="linear").fit(dataclasses.replace(fivebar,
                                                                              input_hold="zoh"))
    assert (user.sim_dt_, user.input_hold_) == (2e-3, "linear")
    assert user.sim_dt_rule_ == user.input_hold_rule_ == "user-set"
    # the chosen step is the one scoring simulates with: the same trajectory as set by hand
    n = 1001
    a = m.simulate(fivebar.x[:, 0], fivebar.xd[:, 0], fivebar.t[:n], fivebar.u[:, :n])
    b = SINDyPI(sim_dt=m.sim_dt_, input_hold="linear").fit(fivebar).simulate(
        fivebar.x[:, 0], fivebar.xd[:, 0], fivebar.t[:n], fivebar.u[:, :n])
    np.testing.assert_array_equal(a.x, b.x)
