"""Five-bar rig: geometry, input checks and clear errors (fast, no long simulations)."""

import math

import numpy as np
import pytest

from models import RIGS
from models.fivebar import geometry as geo
from models.fivebar.params import FiveBarParams
from models.fivebar.rig import RIG_SCHEMA, FiveBarRig
from testbed.core.dataset import Dataset
from testbed.core.errors import RigError, ScenarioError
from testbed.core.schema import validate_table
from testbed.pipeline.scenario import load_scenario, scenario_from_dict

PAPER_POSE = {"th1_0": 1.78, "th4_0": 1.36}  # the shipped scenarios' start pose


def _scenario(rig=None, simulation=None, excitation=None):
    raw = {"scenario": {"name": "t", "rig": "fivebar"}, "rig": {**PAPER_POSE, **(rig or {})},
           "simulation": simulation or {}}
    if excitation is not None:
        raw["excitation"] = excitation
    return scenario_from_dict(raw)


def _params(**rig):
    return FiveBarParams.from_rig(validate_table(rig, RIG_SCHEMA, file="<t>", section="rig"))


def test_registered_with_contract():
    cls = RIGS.get("fivebar")
    assert cls is FiveBarRig and cls.kind == "mechanical"
    assert RIGS.tags("fivebar") >= {"mechanical", "pinocchio", "closed-loop"}
    assert cls.measured_signals == ("theta", "dtheta", "ddtheta", "torque")
    assert cls.noisy_signals == ("theta",) and cls.default_excitation == "sine_replay"
    assert set(cls.excitation_schemas) == {"sine_replay", "multisine", "chirp", "pd"}


@pytest.mark.parametrize("name", ["fivebar_sine_replay", "fivebar_multisine"])
def test_scenarios_load(name):
    sc = load_scenario(name)
    assert sc.rig == "fivebar" and sc.noise["rms_percent"] == 0.0
    assert sc.simulation["dt"] == 1e-4 and sc.simulation["duration"] == 10.0


@pytest.mark.parametrize("branch", ["up", "down"])
def test_closure_both_branches(branch):
    p = _params(branch=branch, l2=0.9, l3=1.2, L0=0.8)
    rng = np.random.default_rng(1)
    th1, th4 = rng.uniform(1.4, 2.0, 200), rng.uniform(1.0, 1.6, 200)
    theta = geo.assemble(th1, th4, p)
    ok = np.isfinite(theta).all(axis=1)
    assert ok.sum() > 150
    # circle intersection is closed-form: the residual is round-off only
    assert np.abs(geo.closure_residual(theta[ok], p)).max() < 1e-14
    C, D = geo.elbows(th1[ok], th4[ok], p)
    E = geo.endpoint(theta[ok], p)
    cross = (D - C)[:, 0] * (E - C)[:, 1] - (D - C)[:, 1] * (E - C)[:, 0]
    assert (np.sign(cross) == (1 if branch == "up" else -1)).all()


def test_default_pose_is_well_conditioned():
    p = _params()
    theta = geo.assemble(1.78, 1.36, p)
    assert abs(math.degrees(geo.transmission_angle(theta)) - 90.0) < 0.5
    # rigs.md: L0 = 1 m at th1 = th4 gives 60 deg
    assert math.degrees(geo.transmission_angle(geo.assemble(1.5, 1.5, p))) == pytest.approx(60.0, abs=1e-9)


def test_constraint_jacobian_and_rates_match_finite_differences():
    p = _params(l1=1.1, l2=0.9, l3=1.0, l4=0.8)
    theta = geo.assemble(1.7, 1.3, p)
    J = geo.constraint_jacobian(theta, p)
    h = 1e-6
    f = geo.closure_residual
    Jfd = np.stack([(f(theta + h * e, p) - f(theta - h * e, p)) / (2 * h) for e in np.eye(4)], axis=1)
    assert np.abs(J - Jfd).max() < 1e-9  # central difference, O(h^2) + round-off / h
    assert np.linalg.det(J[:, [1, 2]]) == pytest.approx(p.l[1] * p.l[2] * math.sin(theta[1] - theta[2]))
    # passive rates from the closure equal the derivative of the assembled pose along the motion
    dth_a, dd_a = np.array([0.3, -0.2]), np.array([0.5, 0.7])
    dtheta, ddtheta = geo.complete_rates(theta, dth_a, dd_a, p)

    def pose(t):
        th_a = np.array([1.7, 1.3]) + dth_a * t + dd_a * t**2 / 2
        return geo.assemble(th_a[0], th_a[1], p)

    h = 1e-4
    assert np.abs((pose(h) - pose(-h)) / (2 * h) - dtheta).max() < 1e-7
    assert np.abs((pose(h) - 2 * pose(0.0) + pose(-h)) / h**2 - ddtheta).max() < 1e-5


def _error(**kw) -> ScenarioError:
    with pytest.raises(ScenarioError) as e:
        _scenario(**kw)
    return e.value


def test_negative_mass_is_rejected():
    e = _error(rig={"m2": -1.0})
    assert e.key == "rig.m2" and "> 0" in e.allowed and "kg" in e.allowed


def test_links_that_cannot_close_are_rejected():
    e = _error(rig={"l2": 0.5, "l3": 0.5}, excitation={"type": "multisine"})  # |CD| = 1.417 m > 1 m
    assert "th1_0" in e.key and "closes only" in e.allowed and "1.417" in e.allowed
    e = _error(rig={"L0": 5.0})
    assert e.key == "rig.L0" and "cannot close" in e.allowed


@pytest.mark.parametrize("th1, th4", [(2.0708, 1.0708), (1.0, 2.3)])  # ~151 deg and ~13 deg
def test_start_near_type_ii_singularity_is_rejected(th1, th4):
    e = _error(rig={"th1_0": th1, "th4_0": th4}, excitation={"type": "multisine"})
    assert "transmission angle" in e.allowed and "30-150 deg" in e.allowed and "Type II" in e.allowed


def test_sine_replay_path_leaving_workspace_is_rejected():
    # the start th_0 + A is usable, but the +-0.3 rad sweep passes 155.6 deg at th_0
    e = _error(rig={"th1_0": 2.2, "th4_0": 1.2}, excitation={"type": "sine_replay", "amplitude": 0.3})
    assert e.key == "excitation.amplitude" and "prescribed motion" in e.allowed


def test_timing_and_start_rate_checks():
    e = _error(simulation={"sample_rate": 3000.0})
    assert e.key == "simulation.sample_rate" and "whole number" in e.allowed
    e = _error(rig={"dth1_0": 0.1})
    assert "dth1_0" in e.key and "sine_replay" in e.allowed


def test_transmission_leaving_range_during_simulation_raises_rig_error():
    sc = _scenario(simulation={"duration": 3.0, "dt": 5e-4, "sample_rate": 2000.0},
                   excitation={"type": "multisine", "amplitude": 5.0, "f_min": 0.2, "f_max": 0.5})
    with pytest.raises(RigError, match=r"transmission angle .* allowed 30-150 deg") as e:
        FiveBarRig(sc).simulate()
    assert "at t = " in str(e.value)
    # only the simulation can tell, so the error names the keys that drive the motion and
    # their values (it named none: the user could not tell what to change)
    assert str(e.value).startswith("key 'excitation.amplitude, excitation.f_max, excitation.kp, "
                                   "excitation.kd': value [5.0, 0.5, 0.0, 0.0]: ")


def test_a_linkage_falling_under_gravity_names_gravity_among_the_keys():
    sc = _scenario(rig={"gravity": True}, simulation={"duration": 2.0, "dt": 5e-4, "sample_rate": 2000.0},
                   excitation={"type": "multisine", "amplitude": 1.0, "f_min": 0.2, "f_max": 0.5})
    with pytest.raises(RigError, match=r"transmission angle") as e:
        FiveBarRig(sc).simulate()
    assert str(e.value).startswith("key 'excitation.amplitude, excitation.f_max, excitation.kp, "
                                   "excitation.kd, rig.gravity': value [1.0, 0.5, 0.0, 0.0, True]: ")


def test_a_sine_replay_falling_under_gravity_is_told_to_change_only_keys_it_has():
    """Round 11's fb11_gravity_asym: the replayed torques let the linkage fall off the sine's
    path; the message advised "add centring feedback (kp, kd)", which sine_replay refuses."""
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "benchmarks/unseen/round11/fb11_gravity_asym.toml"
    with pytest.raises(RigError, match=r"transmission angle") as e:
        FiveBarRig(load_scenario(path)).simulate()
    msg = str(e.value)
    assert msg.startswith("key 'excitation.amplitude, excitation.frequency, rig.gravity'")
    assert "kp" not in msg and "the keys named" in msg


def test_short_dataset_layout_and_roundtrip(tmp_path):
    sc = _scenario(simulation={"duration": 0.05}, excitation={"type": "chirp"})
    ds = FiveBarRig(sc).simulate()
    assert ds.fs == 1e4 and ds.n_samples == 500
    assert ds.measured["theta"].data.shape == (4, 500) and ds.measured["theta"].unit == "rad"
    assert ds.measured["torque"].channels == ("u1", "u2")
    assert ds.reference["constraint_force"].unit == "N" and ds.reference["E"].data.shape == (2, 500)
    assert ds.truth["mass_matrix_q0"].shape == (4, 4) and ds.truth_units["mass_matrix_q0"] == "kg m^2"
    assert ds.truth["equation_coef"].shape == (2, len(ds.truth["equation_terms"]))
    assert np.allclose(ds.truth["theta0"], ds.measured["theta"].data[:, 0], rtol=0, atol=0)
    back = Dataset.load(ds.save(tmp_path / "fb.h5"))
    assert back.truth["equation_terms"] == ds.truth["equation_terms"]
    np.testing.assert_array_equal(back.measured["ddtheta"].data, ds.measured["ddtheta"].data)
