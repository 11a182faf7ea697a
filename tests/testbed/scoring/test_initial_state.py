"""The start a model is scored from: fitted to the reference response (testbed.scoring.initial_state)."""

import numpy as np

from identify._structural_sim import simulate_structural
from testbed.core.errors import DivergenceError
from testbed.scoring.initial_state import fit_initial_state

M = np.array([[2.0, 0.3], [0.3, 1.0]])
K = np.array([[4e5, -1.5e5], [-1.5e5, 1.5e5]])
C = 2e-4 * K
T = np.arange(3000) / 12800.0


def _sim(x0, xd0, K3=None):
    return simulate_structural(M, C, K, K3, None, x0, xd0, T)


def test_linear_model_start_recovered_from_a_wrong_measured_start():
    x0, xd0 = np.array([1e-4, -2e-4]), np.array([0.05, 0.02])
    ref = _sim(x0, xd0).xdd
    # the measured start off by 30 % and an offset, as the chain's integration constants leave it
    fx, fxd = fit_initial_state(lambda a, b: _sim(a, b), 1.3 * x0 + 2e-5, xd0 - 0.01, ref)
    # linear model: one Gauss-Newton step is exact up to the rounding of the 3000-sample
    # least-squares solve (condition of the Jacobian ~1e4 -> ~1e-11 relative)
    np.testing.assert_allclose(fx, x0, rtol=1e-7)
    np.testing.assert_allclose(fxd, xd0, rtol=1e-7)


def test_a_wrong_model_stays_wrong():
    """Two free numbers per channel cannot make wrong frequencies fit: the residual stays."""
    x0, xd0 = np.array([1e-4, -2e-4]), np.array([0.05, 0.02])
    ref = _sim(x0, xd0).xdd

    def wrong(a, b):  # stiffness 10 % high: frequencies 5 % high
        return simulate_structural(M, C, 1.1 * K, None, None, a, b, T)

    fx, fxd = fit_initial_state(wrong, x0, xd0, ref)
    rel = np.linalg.norm(wrong(fx, fxd).xdd - ref) / np.linalg.norm(ref)
    assert rel > 0.3  # 5 % frequency error over ~60 periods of mode 1: the phase drifts apart


def test_cubic_model_converges_from_the_measured_start():
    K3 = np.array([[3e11, 0.0], [0.0, 0.0]])
    x0, xd0 = np.array([3e-4, 1e-4]), np.array([0.1, -0.05])
    ref = _sim(x0, xd0, K3).xdd
    fx, fxd = fit_initial_state(lambda a, b: _sim(a, b, K3), 1.1 * x0, 0.9 * xd0, ref)
    rel = np.linalg.norm(_sim(fx, fxd, K3).xdd - ref) / np.linalg.norm(ref)
    before = np.linalg.norm(_sim(1.1 * x0, 0.9 * xd0, K3).xdd - ref) / np.linalg.norm(ref)
    assert rel < 1e-3 * before  # three Gauss-Newton steps on a mildly nonlinear response


def test_a_failing_simulation_keeps_the_measured_start():
    x0, xd0 = np.array([1e-4, -2e-4]), np.array([0.05, 0.02])

    def boom(a, b):
        raise DivergenceError("state not finite", time=0.01)

    fx, fxd = fit_initial_state(boom, x0, xd0, np.zeros((2, T.size)))
    assert np.array_equal(fx, x0) and np.array_equal(fxd, xd0)
