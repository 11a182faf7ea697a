"""A held input is paired with the chain's differenced accelerations half a sample late
(identify/sindy_pi.py :func:`regression_inputs`; docs/known-gaps.md "SINDy-PI: the held input
half a sample late in the regression (session 23, pi24)").

Round 22's ``fb22_ms_down`` (the multisine on the five-bar's down branch, the low-pass chain):
clean s133 failed its bar, angle_rmse 0.0741 rad.  A held torque acts as ``u[k]`` over
``[t_k, t_k+1)``; the chain's accelerations are central differences of the (filtered) angles,
which at ``t_k`` average the motion under ``u[k-1]`` and ``u[k]`` for half a sample each.
Paired with ``u[k]`` the true equations left a residual of 1.5e-4 of their scale on that
record with the chain's cut-off at 40 Hz (5.7e-8 paired with ``(u[k-1] + u[k]) / 2``), as large
as the joints' damping (1.5e-4), which the fit then dropped."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

import testbed
from identify.sindy_pi import regression_inputs
from testbed.core.measurement import Measurement

UNSEEN = Path(__file__).resolve().parents[2] / "benchmarks" / "unseen"
#: The study's bar (benchmarks/unseen/round22_linkages_inputs.toml): the paper's figure [rad].
ANGLE_BAR = 0.0501


def _held_double_integrator(fs: float, passband):
    """q'' = u with u held per sample: exact samples of q; the chain's central differences."""
    rng = np.random.default_rng(0)
    u = rng.standard_normal((1, 200))
    h = 1.0 / fs
    q, v = np.zeros(u.shape[1]), 0.0
    for k in range(1, u.shape[1]):  # exact over each held interval
        q[k] = q[k - 1] + v * h + 0.5 * u[0, k - 1] * h * h
        v += u[0, k - 1] * h
    xdd = np.zeros((1, u.shape[1]))
    xdd[0, 1:-1] = (q[2:] - 2.0 * q[1:-1] + q[:-2]) / h**2
    data = Measurement(fs=fs, x=q[None], xd=np.gradient(q, h)[None], xdd=xdd, channels=("q",),
                       u=u, inputs=("u",), input_map=np.ones((1, 1)), passband=passband)
    return data, u


def test_a_held_input_is_paired_with_the_differenced_acceleration():
    """The central difference of a held input's motion is (u[k-1] + u[k]) / 2 exactly (to
    round-off: 1e-9 of u's scale at h = 1 ms, the differences' cancellation)."""
    data, u = _held_double_integrator(1000.0, (0.0, 100.0))
    paired = regression_inputs(data, "zoh")
    assert np.allclose(paired[0, 1:-1], data.xdd[0, 1:-1], rtol=0, atol=1e-6)
    # the sample itself is half a sample off: the old pairing
    assert not np.allclose(u[0, 1:-1], data.xdd[0, 1:-1], rtol=0, atol=1e-2)


def test_recorded_accelerations_and_linear_inputs_keep_their_samples():
    """No pass band declared (recorded rates: the engine's accelerations under u[k]) or a
    continuous input: the samples as given."""
    data, u = _held_double_integrator(1000.0, None)
    assert np.array_equal(regression_inputs(data, "zoh"), u)
    data, u = _held_double_integrator(1000.0, (0.0, 100.0))
    assert np.array_equal(regression_inputs(data, "linear"), u)


def test_the_down_branch_multisine_clean_meets_its_bar():
    """Was angle_rmse 0.0741 rad (bar 0.0501) on clean angles, s133; now 0.0475."""
    sc = testbed.load_scenario(UNSEEN / "round22" / "fb22_ms_down.toml")
    sc = dataclasses.replace(sc, seed=133, noise={**sc.noise, "rms_percent": 0.0})
    res = testbed.run_scenario(sc)
    assert res.scores.values["angle_rmse"] <= ANGLE_BAR
