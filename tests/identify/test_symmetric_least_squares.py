"""identify.structural.symmetric_least_squares and SGD-SINDy's warm-start damping built on it."""

from __future__ import annotations

import numpy as np

from identify._sgd_matrix import symmetric_damping
from identify.structural import symmetric_least_squares


def _sym(rng, n):
    a = rng.standard_normal((n, n))
    return a + a.T


def test_recovers_symmetric_matrices_from_exact_signals():
    rng = np.random.default_rng(0)
    n, N = 4, 500
    C, K = _sym(rng, n), 100.0 * _sym(rng, n)
    v, x = rng.standard_normal((n, N)), 1e-2 * rng.standard_normal((n, N))
    got_C, got_K = symmetric_least_squares([v, x], C @ v + K @ x)
    # exact data: only rounding of a well-conditioned least squares (1e-10 relative)
    np.testing.assert_allclose(got_C, C, atol=1e-10 * np.abs(C).max())
    np.testing.assert_allclose(got_K, K, atol=1e-10 * np.abs(K).max())
    assert np.array_equal(got_C, got_C.T) and np.array_equal(got_K, got_K.T)


def test_symmetric_damping_given_mass_and_stiffness():
    rng = np.random.default_rng(1)
    n, N = 3, 400
    M = np.diag([1.0, 2.0, 0.5])
    K, C = 1e4 * np.eye(n) + 50 * _sym(rng, n), np.abs(_sym(rng, n)) + 3 * np.eye(n)
    x, xd = 1e-3 * rng.standard_normal((n, N)), rng.standard_normal((n, N))
    xdd = -np.linalg.solve(M, C @ xd + K @ x)  # the equation of motion holds exactly
    np.testing.assert_allclose(symmetric_damping(M, K, xdd, xd, x), C, atol=1e-9 * np.abs(C).max())
