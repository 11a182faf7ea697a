"""The cart-pole rig: its Lagrange equations against MuJoCo's own accelerations, its truth,
its registration and its scenario checks."""

import mujoco
import numpy as np
import pytest

from models.cartpole import CartPoleParams, CartPoleRig, build_mjcf, unnormalised_equations
from testbed.core.truth import MechanicalTruth
from testbed.pipeline.plugins import RIGS
from testbed.pipeline.scenario import ScenarioError, load_scenario, scenario_from_dict
from testbed.scoring.equation_basis import evaluate_terms


@pytest.fixture(scope="module")
def scenario():
    return load_scenario("scenarios/cartpole.toml")


@pytest.fixture(scope="module")
def dataset(scenario, dataset_cache):
    return dataset_cache.get(scenario)  # bit-identical to generate() (tests/testbed/pipeline/test_cache.py)


def signals(ds):
    m = ds.measured
    return {"th": m["theta"].data, "dth": m["dtheta"].data, "ddth": m["ddtheta"].data,
            "u": m["torque"].data}


def test_registered_as_an_underactuated_mechanical_rig(scenario):
    assert RIGS.get("cartpole") is CartPoleRig
    assert scenario.kind == "mechanical"
    assert CartPoleRig.measurement_shape(scenario.rig_params) == (2, 1)


def test_lagrange_equations_hold_on_mujocos_accelerations(scenario, dataset):
    """Both equations of models/cartpole/equations.py, evaluated on the recorded state, force
    and MuJoCo's qacc, vanish to round-off relative to their largest term (an independent
    derivation: a sign, a factor l or I about the wrong point leaves 1e-2..1)."""
    p = CartPoleParams.from_rig(scenario.rig_params)
    sig = signals(dataset)
    for eq in unnormalised_equations(p):
        names = list(eq)
        c = np.array([eq[n] for n in names])
        T = evaluate_terms(names, sig)
        # 1e-9 relative: MuJoCo's forward dynamics in float64 leaves ~1e-16; 1e-9 still
        # resolves a damping coefficient wrong by 1e-6 of itself
        assert np.abs(T @ c).max() < 1e-9 * np.abs(T * c).max()
    # the pole equation has no input: the pole is passive
    assert not any("u" in t for t in unnormalised_equations(p)[1])


def test_truth_is_the_normalised_equations_and_the_engine_mass_matrix(scenario, dataset):
    tr = dataset.typed_truth
    assert isinstance(tr, MechanicalTruth)
    p = CartPoleParams.from_rig(scenario.rig_params)
    T = evaluate_terms(tr.equation_terms, signals(dataset))
    for row in tr.equation_coef:
        assert np.abs(row).max() == 1.0
        assert np.abs(T @ row).max() < 1e-9 * np.abs(T * row).max()
    m, l = p.pole_mass, p.com
    M = np.array([[p.cart_mass + m, m * l * np.cos(tr.theta0[1])],
                  [m * l * np.cos(tr.theta0[1]), p.inertia + m * l**2]])
    # the engine's inertia assembly in float64: 1e-12 relative is ~1e4 eps
    np.testing.assert_allclose(tr.mass_matrix_q0, M, rtol=1e-12)


def test_engine_mass_matrix_away_from_rest_matches_the_derivation(scenario):
    """The cos(th) coupling at a tilted pole (sign of the hinge axis: a positive angle puts the
    pole's end towards +x)."""
    p = CartPoleParams.from_rig(scenario.rig_params)
    model = mujoco.MjModel.from_xml_string(build_mjcf(p, 1e-4))
    data = mujoco.MjData(model)
    data.qpos[:] = [0.2, 0.7]
    mujoco.mj_forward(model, data)
    M = np.zeros((2, 2))
    mujoco.mj_fullM(model, data, M)
    ml = p.pole_mass * p.com
    np.testing.assert_allclose(M, [[p.cart_mass + p.pole_mass, ml * np.cos(0.7)],
                                   [ml * np.cos(0.7), p.inertia + p.pole_mass * p.com**2]],
                               rtol=1e-12)
    com_x = data.xipos[model.body("pole").id, 0]
    assert com_x == pytest.approx(0.2 + p.com * np.sin(0.7), rel=1e-12)


def test_the_pole_swings_in_a_sane_range_and_the_force_acts_on_the_cart(dataset):
    th = dataset.measured["theta"].data
    assert 0.2 < np.abs(th[1]).max() < 1.2  # excited, but well below horizontal (pi / 2)
    assert np.abs(th[0]).max() < 1.0        # the centring keeps the cart within 1 m
    assert dataset.measured["torque"].acts_on == ("x",)


def test_a_bad_scenario_is_refused_in_one_line():
    raw = {"scenario": {"name": "bad", "rig": "cartpole", "description": "bad"},
           "simulation": {"duration": 1.0, "dt": 3e-4, "sample_rate": 1000.0}}
    with pytest.raises(ScenarioError, match="sample_rate"):
        scenario_from_dict(raw, file="<test>")
    raw["simulation"]["dt"] = 1e-4
    raw["excitation"] = {"type": "multisine", "f_max": 600.0}
    with pytest.raises(ScenarioError, match="Nyquist"):
        scenario_from_dict(raw, file="<test>")


def test_an_unstable_simulation_is_a_rig_error_not_garbage_data():
    # gravity 1e9 m/s^2: MuJoCo resets the exploding state and carries on; the run used to score
    # an identifier on the garbage record (and a non-finite state was a bare FloatingPointError)
    from testbed.core.errors import RigError
    from testbed.pipeline.generate import generate

    sc = scenario_from_dict({"scenario": {"name": "x", "rig": "cartpole"}, "rig": {"gravity": 1e9},
                             "simulation": {"duration": 0.05}})
    with pytest.raises(RigError, match=r"cartpole: the simulation is unstable at t = .*rig\.gravity"):
        generate(sc)


def test_the_chirp_and_the_steps_drive_the_cart_and_the_equations_still_hold():
    """Round 14's inputs (a linear chirp, seeded held steps): the recorded force is the input's
    feed-forward minus the centring feedback, and the Lagrange equations hold on the record."""
    from models.cartpole.rig import chirp, steps
    from testbed.pipeline.generate import generate

    t = np.arange(2000) / 1000.0
    sweep = chirp(t, {"amplitude": 2.0, "f0": 0.5, "f1": 4.5}, 2.0)
    # instantaneous frequency f0 + (f1 - f0) t / T: 0.5 Hz at the start, 4.5 Hz at the end
    assert sweep[0] == 0.0 and np.abs(sweep).max() <= 2.0
    held = steps(t, {"amplitude": 2.0, "hold": 0.25, "level_seed": 3})
    assert len(np.unique(held)) == 8 and np.all(np.abs(held) <= 2.0)
    assert np.all(held[:250] == held[0]) and held[250] != held[249]
    for exc in ({"type": "chirp", "f0": 0.1, "f1": 3.0}, {"type": "steps", "hold": 0.5}):
        sc = scenario_from_dict({"scenario": {"name": "x", "rig": "cartpole"}, "excitation": exc,
                                 "simulation": {"duration": 2.0}})
        ds = generate(sc)
        ff = ds.reference["feedforward"].data[0]
        th, dth = ds.measured["theta"].data, ds.measured["dtheta"].data
        u = ds.measured["torque"].data[0]
        # the recorded force is the feed-forward and the centring, to round-off
        assert np.allclose(u, ff - 5.0 * th[0] - 2.0 * dth[0], rtol=0, atol=1e-12)
        assert np.abs(ff).max() > 1.0
        p = CartPoleParams.from_rig(sc.rig_params)
        for eq in unnormalised_equations(p):
            c, T = np.array(list(eq.values())), evaluate_terms(list(eq), signals(ds))
            assert np.abs(T @ c).max() < 1e-9 * np.abs(T * c).max()  # as for the multisine above


def test_a_bad_chirp_or_step_input_is_refused_in_one_line():
    base = {"scenario": {"name": "bad", "rig": "cartpole", "description": "bad"}}
    for exc, match in (({"type": "chirp", "f0": 2.0, "f1": 1.0}, "excitation.f0"),
                       ({"type": "chirp", "f1": 600.0}, "Nyquist"),
                       ({"type": "steps", "hold": 20.0}, "excitation.hold"),
                       ({"type": "steps", "hold": 1e-12}, "at least one sample period"),
                       ({"type": "steps", "f_min": 0.1}, "unknown key")):
        with pytest.raises(ScenarioError, match=match):
            scenario_from_dict({**base, "excitation": exc}, file="<test>")
