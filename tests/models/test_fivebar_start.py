"""Five-bar: the automatic start pose over several geometries, and refused divergent simulations."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from scipy.ndimage import distance_transform_edt

from models.fivebar import geometry as geo
from models.fivebar.params import FiveBarParams
from models.fivebar.rig import RIG_SCHEMA, FiveBarRig
from testbed.core.errors import RigError, ScenarioError
from testbed.core.schema import validate_table
from testbed.pipeline.scenario import scenario_from_dict

# Link lengths 0.6-1.4 m, base 0.4-1.6 m: long and short couplers, short and long bases.
GEOMETRIES = [
    {},  # the paper's four 1 m links on L0 = 1 m
    {"l1": 0.6, "l2": 1.4, "l3": 1.4, "l4": 0.6, "L0": 1.0},
    {"l1": 1.4, "l2": 0.6, "l3": 0.6, "l4": 1.4, "L0": 0.4},
    {"l1": 0.8, "l2": 1.2, "l3": 0.9, "l4": 1.1, "L0": 1.6},
    {"l1": 1.2, "l2": 0.7, "l3": 1.3, "l4": 0.9, "L0": 0.7},
    {"l1": 1.0, "l2": 1.0, "l3": 1.0, "l4": 1.0, "L0": 1.4, "branch": "down"},
]


def _scenario(rig=None, simulation=None, excitation=None):
    raw = {"scenario": {"name": "t", "rig": "fivebar"}, "rig": rig or {},
           "simulation": {"duration": 0.2, **(simulation or {})},
           "excitation": excitation or {"type": "multisine", "kp": 10.0, "kd": 2.0}}
    return scenario_from_dict(raw)


def _params(rig):
    return FiveBarParams.from_rig(validate_table(rig, RIG_SCHEMA, file="<t>", section="rig"))


@pytest.mark.parametrize("rig", GEOMETRIES)
def test_auto_pose_is_the_most_central_usable_pose(rig):
    p = _params(rig)
    th1, th4, margin = geo.auto_start_pose(p)
    assert geo.usable(th1, th4, p)
    mu = np.degrees(geo.transmission_angle(geo.assemble(th1, th4, p)))
    assert 30.0 < mu < 150.0
    # An independent check of the rule on the same 1 deg grid: no usable pose lies farther
    # from the unusable set (brute force over the unusable poses, periodic in both angles).
    n = 360
    g = np.arange(n) * 2 * np.pi / n
    ok = geo.usable(g[:, None], g[None, :], p)
    bad = np.argwhere(~ok)
    i, j = round(th1 / (2 * np.pi / n)), round(th4 / (2 * np.pi / n))
    di = np.abs(bad[:, 0] - i)
    dj = np.abs(bad[:, 1] - j)
    brute = np.sqrt(np.minimum(di, n - di) ** 2 + np.minimum(dj, n - dj) ** 2).min() * 2 * np.pi / n
    assert margin == pytest.approx(brute, rel=1e-12)
    dist = distance_transform_edt(np.tile(ok, (3, 3)))[n:2 * n, n:2 * n] * 2 * np.pi / n
    assert margin == pytest.approx(dist.max(), rel=1e-12)
    # Deterministic: the same pose again, also with the cache cleared.
    geo._auto_pose.cache_clear()
    assert geo.auto_start_pose(p) == (th1, th4, margin)


@pytest.mark.parametrize("rig", GEOMETRIES)
def test_scenario_without_a_pose_runs_from_the_auto_pose(rig):
    ds = FiveBarRig(_scenario(rig)).simulate()
    th1, th4, _ = geo.auto_start_pose(_params(rig))
    assert ds.attrs["start_pose"].startswith("auto")
    assert (ds.attrs["th1_0"], ds.attrs["th4_0"]) == (th1, th4)
    assert ds.truth["theta0"][[0, 3]] == pytest.approx([th1, th4], abs=0)


def test_auto_pose_is_the_centre_of_sine_replay():
    ds = FiveBarRig(_scenario(excitation={"type": "sine_replay"})).simulate()
    th1, th4, _ = geo.auto_start_pose(_params({}))
    pres = ds.reference["theta_prescribed"].data
    # th = th_0 + A sin(t + pi/2): the centre is th_0 (amplitude 0.0698 rad)
    assert pres[0, 0] == pytest.approx(th1 + 0.0698, abs=1e-12)
    assert pres[1, 0] == pytest.approx(th4 + 0.0698, abs=1e-12)


def test_given_pose_is_kept():
    ds = FiveBarRig(_scenario({"th1_0": 1.78, "th4_0": 1.36})).simulate()
    assert ds.attrs["start_pose"] == "given" and ds.truth["theta0"][0] == 1.78


def test_one_angle_alone_is_refused():
    with pytest.raises(ScenarioError) as e:
        _scenario({"th1_0": 1.78})
    assert "th4_0" in e.value.key and "neither" in e.value.allowed


def test_geometry_without_a_usable_pose_is_refused():
    # 0.2 m couplers on L0 = 2.39 m (< 2.4 m, the loop can close): |CD| >= 0.39 m, so the
    # transmission angle 2 asin(|CD| / 0.4) is at least 154 deg in every closed pose.
    with pytest.raises(ScenarioError) as e:
        _scenario({"l2": 0.2, "l3": 0.2, "L0": 2.39})
    assert "th1_0" in e.value.key and "has none" in e.value.allowed


@pytest.mark.parametrize("engine", ["pinocchio", "mujoco"])
def test_divergent_simulation_raises_one_line(engine):
    sc = _scenario({"th1_0": 1.78, "th4_0": 1.36}, {"engine": engine})
    sc = sc.replace(excitation={**sc.excitation, "amplitude": 1e300})  # past any validation
    with pytest.raises(RigError) as e:
        FiveBarRig(sc).simulate()
    msg = str(e.value)
    assert "\n" not in msg and f"fivebar ({engine})" in msg
    assert "not finite" in msg or "unstable" in msg
    # a blow-up names the step besides the excitation's keys
    assert msg.startswith("key 'excitation.amplitude, excitation.f_max, excitation.kp, "
                          "excitation.kd, simulation.dt': value [1e+300, "), msg


def test_unconverged_loop_closure_raises_one_line():
    rig = FiveBarRig(_scenario({"th1_0": 1.78, "th4_0": 1.36}))
    # One proximal iteration cannot reach the 1e-8 residual (3 are needed).
    rig.dynamics.prox = pin.ProximalSettings(1e-12, 1e-8, 1)
    with pytest.raises(RigError, match=r"did not converge at t = 0\.0000 s") as e:
        rig.simulate()
    assert "\n" not in str(e.value)
