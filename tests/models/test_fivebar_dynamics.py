"""Five-bar rig on the 10 s multisine case: Pinocchio's dynamics against themselves, the true
library equations and the independent MuJoCo twin.  One simulation per engine, shared."""

import numpy as np
import pytest

from models.fivebar import geometry as geo
from models.fivebar.equations import true_equations, true_library_residual
from models.fivebar.excitation import TorqueProgram
from models.fivebar.rig import FiveBarRig
from models.fivebar.twin import MujocoTwin
from testbed.pipeline.scenario import load_scenario, scenario_from_dict

# Samples checked one by one with Pinocchio calls (spread over the whole record).
IDX = np.linspace(0, 99_999, 157).astype(int)


@pytest.fixture(scope="module")
def rig():
    return FiveBarRig(load_scenario("fivebar_multisine"))


@pytest.fixture(scope="module")
def ds(dataset_cache):
    # the shared test cache: bit-identical to generate() (tests/testbed/pipeline/test_cache.py) and keyed on
    # the rig's source, and the same record test_sindy_pi_fivebar and the scored five-bar scenarios use
    return dataset_cache.get(load_scenario("fivebar_multisine"))


@pytest.fixture(scope="module")
def twin_run(rig, ds):
    """The MuJoCo twin driven by exactly the zero-order-hold torques Pinocchio recorded."""
    theta0, dtheta0 = rig.start_state()
    u = ds.measured["torque"].data.T
    return MujocoTwin(rig.params, 1e-4).simulate(theta0, dtheta0, TorqueProgram.open_loop(u), ds.fs, len(u))


def _state(ds, k):
    th, dth = ds.measured["theta"].data[:, k], ds.measured["dtheta"].data[:, k]
    return geo.to_joint(th), geo.to_joint(dth)


def test_motion_is_rich_but_safe(ds):
    th = ds.measured["theta"].data
    swing = np.degrees(th.max(axis=1) - th.min(axis=1))
    assert (swing[[0, 3]] > 20).all()  # tens of degrees at the actuated joints
    mu = np.degrees(ds.reference["transmission_angle"].data)
    assert mu.min() > 45 and mu.max() < 135  # well inside 30-150 deg


def test_loop_closure_over_10s(ds, rig):
    # RK4 at 1e-4 s with no Baumgarte term: only integration error, ~1e-13 m (rigs.md)
    res = geo.closure_residual(ds.measured["theta"].data.T, rig.params)
    assert np.abs(res).max() < 1e-10


def test_reduced_mass_matrix_spd_and_reduced_dynamics(ds, rig):
    dyn = rig.dynamics
    u, dd = ds.measured["torque"].data, ds.measured["ddtheta"].data
    for k in IDX:
        q, v = _state(ds, k)
        Mr, hr = dyn.reduced_dynamics(q, v)
        assert np.abs(Mr - Mr.T).max() < 1e-14
        assert np.linalg.eigvalsh(Mr).min() > 0.1  # well away from singular (>= ~1/10 of the link inertia)
        # tau = Mr qdd + hr: both sides O(1) N m, the constrained solve converges to round-off
        assert np.abs(Mr @ dd[[0, 3], k] + hr - u[:, k]).max() < 1e-10


def test_inverse_dynamics_returns_the_recorded_torque_and_constraint_force(ds, rig):
    th, dth, dd = (ds.measured[n].data.T for n in ("theta", "dtheta", "ddtheta"))
    u, theta, lam = rig.dynamics.inverse_dynamics(th[IDX][:, [0, 3]], dth[IDX][:, [0, 3]], dd[IDX][:, [0, 3]])
    assert np.abs(theta - th[IDX]).max() < 1e-10  # closure vs integrated pose (drift < 1e-13 m)
    assert np.abs(u - ds.measured["torque"].data.T[IDX]).max() < 1e-9
    assert np.abs(lam - ds.reference["constraint_force"].data.T[IDX]).max() < 1e-9


def test_true_library_equations_vanish_on_the_data(ds):
    t = ds.truth
    args = (ds.measured["theta"].data, ds.measured["dtheta"].data, ds.measured["ddtheta"].data,
            ds.measured["torque"].data)
    res = true_library_residual(t["equation_terms"], t["equation_coef"], *args)
    # exact algebra on Pinocchio's constrained accelerations: round-off plus proximal-solver error
    assert np.abs(res).max() < 1e-9
    assert np.abs(t["equation_coef"]).max(axis=1) == pytest.approx([1.0, 1.0])
    # not vacuous: a 1 % error in the coupling coefficient is seen at the 1e-3 level
    wrong = t["equation_coef"].copy()
    wrong[0, t["equation_terms"].index("cos(th1-th2)*sin(th2-th3)*ddth2")] *= 1.01
    assert np.abs(true_library_residual(t["equation_terms"], wrong, *args)).max() > 1e-4


def test_equations_with_gravity_damping_and_unequal_links():
    sc = scenario_from_dict({
        "scenario": {"name": "g", "rig": "fivebar"},
        "rig": {"gravity": True, "damping": 0.05, "l1": 0.9, "l2": 1.1, "l3": 1.0, "l4": 0.8, "L0": 0.7,
                "m1": 0.8, "m2": 1.3, "m3": 0.6, "m4": 1.1, "I2": 0.2, "th1_0": 1.9, "th4_0": 1.3},
        "simulation": {"duration": 1.0},
        "excitation": {"type": "pd", "kp": 60.0, "kd": 10.0, "amplitude": 0.2, "frequency": 1.0}})
    rig = FiveBarRig(sc)
    d = rig.simulate()
    terms, coef, _ = true_equations(rig.params)
    assert "cos(th1)*sin(th2-th3)" in terms and "sin(th1-th3)*dth1" in terms
    res = true_library_residual(terms, coef, d.measured["theta"].data, d.measured["dtheta"].data,
                                d.measured["ddtheta"].data, d.measured["torque"].data)
    assert np.abs(res).max() < 1e-9


def test_pinocchio_and_mujoco_twin_agree_over_10s(ds, twin_run):
    err = twin_run["theta"] - ds.measured["theta"].data.T
    rmse = np.sqrt(np.mean(err**2, axis=0))
    # Independent engines, same ZOH torques: differ by MuJoCo's soft constraint (solref 2 dt,
    # drift ~1e-10 m) and solver tolerances; measured ~3e-11 rad, the limit leaves 4 decades.
    assert rmse.max() < 1e-6
    # Constraint forces agree up to MuJoCo's constraint-stabilisation ripple (~2e-3 N of ~1 N).
    lam_p, lam_m = ds.reference["constraint_force"].data.T, twin_run["constraint_force"]
    assert np.abs(lam_m - lam_p).max() < 1e-2 * np.abs(lam_p).max()


def test_full_mass_matrix_equal_between_engines(ds, rig):
    twin = MujocoTwin(rig.params, 1e-4)
    for k in IDX[::10]:
        q, _ = _state(ds, k)
        # same inertias, same tree: both are exact CRBA sums, equal to round-off
        assert np.abs(twin.mass_matrix(q) - rig.dynamics.mass_matrix(q)).max() < 1e-10
    M0 = ds.truth["mass_matrix_q0"]
    p = rig.params
    c12 = np.cos(ds.truth["theta0"][0] - ds.truth["theta0"][1])
    # absolute angles: block-diagonal per chain, a1 = 1/12 + 1/4 + 1, b1 = m2 l1 l2 / 2
    assert M0[0, 0] == pytest.approx(p.lumped["a1"]) and M0[0, 0] == pytest.approx(4 / 3)
    assert M0[0, 1] == pytest.approx(0.5 * c12) and M0[0, 3] == 0.0


def test_mujoco_engine_is_selectable():
    raw = {"scenario": {"name": "m", "rig": "fivebar"}, "simulation": {"duration": 0.5},
           "excitation": {"type": "multisine", "kp": 10.0, "kd": 2.0}}
    pin_ds = FiveBarRig(scenario_from_dict(raw)).simulate()
    raw["simulation"]["engine"] = "mujoco"
    mj_ds = FiveBarRig(scenario_from_dict(raw)).simulate()
    assert mj_ds.attrs["engine"] == "mujoco"
    # each engine closes its own feedback loop from its own state; they stay within ~1e-11 rad
    assert np.abs(mj_ds.measured["theta"].data - pin_ds.measured["theta"].data).max() < 1e-8
    # MuJoCo's soft-constraint ripple acts through J^T, which the equations eliminate (~1e-12)
    t = mj_ds.truth
    res = true_library_residual(t["equation_terms"], t["equation_coef"],
                                *(mj_ds.measured[n].data for n in ("theta", "dtheta", "ddtheta", "torque")))
    assert np.abs(res).max() < 1e-9
