"""The compiled RK4 of cubic structural models against the Python loop it replaced (kept here
as the reference): the same trajectory to round-off; divergence raised with its time."""

import numpy as np
import pytest

from identify._structural_sim import simulate_structural
from testbed.core.errors import DivergenceError


def _python_rk4(M, C, K, K3, x0, xd0, t, f, max_omega_h=0.1):
    """The replaced implementation, verbatim in substance: RK4 with sub-steps, force held."""
    n = M.shape[0]
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    MK3, MF = Minv @ K3, Minv @ f
    dt = t[1] - t[0]
    sub = max(1, int(np.ceil(float(np.max(np.abs(np.linalg.eigvals(A)))) * dt / max_omega_h)))
    h = dt / sub
    Z = np.empty((2 * n, t.size))
    z = Z[:, 0] = np.concatenate([x0, xd0])

    def rhs(z, fk):
        return A @ z + np.concatenate([np.zeros(n), fk - MK3 @ z[:n] ** 3])

    for k in range(1, t.size):
        fk = MF[:, k - 1]
        for _ in range(sub):
            k1 = rhs(z, fk)
            k2 = rhs(z + 0.5 * h * k1, fk)
            k3 = rhs(z + 0.5 * h * k2, fk)
            k4 = rhs(z + h * k3, fk)
            z = z + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        Z[:, k] = z
    return Z


def _system():
    rng = np.random.default_rng(3)
    n = 3
    A0 = rng.normal(size=(n, n))
    M = A0 @ A0.T + n * np.eye(n)
    K = np.array([[4e4, -2e4, 0], [-2e4, 9e4, -3e4], [0, -3e4, 2e5]])
    C = 1e-4 * K + 0.5 * np.eye(n)
    K3 = np.diag([1e9, 0.0, 5e8])
    return M, C, K, K3


def test_cubic_same_trajectory_as_python_loop():
    M, C, K, K3 = _system()
    t = np.arange(2000) / 5000.0
    B = np.array([[1.0], [0.0], [0.5]])
    u = 50.0 * np.sin(2 * np.pi * 30 * t)[None, :]
    x0, xd0 = np.array([1e-3, 0, -1e-3]), np.zeros(3)
    tr = simulate_structural(M, C, K, K3, B, x0, xd0, t, u)
    Z = _python_rk4(M, C, K, K3, x0, xd0, t, B @ u)
    # measured ~1e-15: only the order of the matrix-vector sums differs
    for got, want in ((tr.x, Z[:3]), (tr.xd, Z[3:])):
        assert np.abs(got - want).max() <= 1e-12 * np.abs(want).max()


def test_cubic_divergence_raises_with_time():
    M, C, K, _ = _system()
    t = np.arange(200) / 5000.0
    with pytest.raises(DivergenceError) as err:
        simulate_structural(M, C, K, -1e15 * np.eye(3), None, np.full(3, 1e-2), np.zeros(3), t)
    assert 0.0 <= err.value.time < t[-1]
