"""The cubic force's forms (issue #15): ``K3 (A x)^3``, diagonal or rank one, and the rank-one fit."""

import numpy as np

from identify._cubic_form import (
    canonical_sign,
    cubic_features,
    cubic_force,
    cubic_jacobian,
    fit_rank_one,
)


def _two_modes(n: int = 3, N: int = 4000) -> np.ndarray:
    """Displacements (n, N) [m]: decaying modes of comparable amplitude (as many as ``n``, so
    that the motion spans every direction), so that the cross terms ``x_i^2 x_j`` of one
    spring's ``(a . x)^3`` matter."""
    t = np.arange(N) / 2000.0
    shapes = np.array([[1.0, 0.6, 0.3], [-0.4, 0.5, 1.0], [0.3, -0.9, 0.4]])[:n, :n]
    amp = (1e-3 * np.exp(-1.5 * t) * np.cos(2 * np.pi * 23 * t),
           6e-4 * np.exp(-4.0 * t) * np.cos(2 * np.pi * 171 * t + 0.3),
           3e-4 * np.exp(-9.0 * t) * np.cos(2 * np.pi * 467 * t + 1.1))
    return sum(np.outer(shapes[k], amp[k]) for k in range(n))


def test_diagonal_form_is_the_cube_bit_for_bit():
    x = _two_modes()
    K3 = np.arange(9.0).reshape(3, 3)
    assert np.array_equal(cubic_features(x), x**3)
    assert np.array_equal(cubic_force(K3, x), K3 @ x**3)


def test_jacobian_matches_finite_differences_in_both_forms():
    rng = np.random.default_rng(0)
    x0 = 1e-3 * rng.normal(size=3)
    for K3, A in ((rng.normal(size=(3, 3)), None), (rng.normal(size=(3, 1)), rng.normal(size=(1, 3)))):
        h = 1e-9
        num = np.column_stack([(cubic_force(K3, x0 + h * e, A) - cubic_force(K3, x0 - h * e, A)) / (2 * h)
                               for e in np.eye(3)])
        # central difference of a cubic: truncation h^2 * (6 K3 A^3) ~ 1e-17, rounding ~1e-16 / h
        np.testing.assert_allclose(cubic_jacobian(K3, x0, A), num, rtol=1e-5, atol=1e-12)


def test_rank_one_fit_recovers_one_spring_and_the_diagonal_cannot():
    x = _two_modes()
    c = np.array([0.8, -0.5, 0.33])
    c /= np.linalg.norm(c)
    d = np.array([2.0, 1.0, -0.5])
    y = np.outer(d, (c @ x) ** 3) * 1e9
    a, b = fit_rank_one(x, y)
    # noiseless data of the form itself: the optimiser's tolerance, far below any physics
    np.testing.assert_allclose(a, c, atol=1e-7)
    np.testing.assert_allclose(b, d * 1e9, rtol=1e-6)
    # the n features x_j^3 miss the cross terms x_i^2 x_j: a residual of order one
    K3 = np.linalg.lstsq((x**3).T, y.T, rcond=None)[0].T
    assert np.linalg.norm(K3 @ x**3 - y) / np.linalg.norm(y) > 0.05


def test_symmetric_fit_and_the_nuisance_columns():
    x = _two_modes()
    c = np.array([0.3, 0.9, -0.2])
    c /= np.linalg.norm(c)
    N = x.shape[1]
    W = np.column_stack([np.ones(N), np.linspace(0.0, 1.0, N)])  # offsets and drifts, free
    Q = np.linalg.qr(W)[0]
    y = np.outer(c, 5e8 * (c @ x) ** 3) + np.outer([1.0, -2.0, 3.0], W[:, 1])
    y = y - (y @ Q) @ Q.T  # the target with W's span removed, as an identifier gives it
    a, b = fit_rank_one(x, y, Q=Q, symmetric=True)
    np.testing.assert_allclose(a, c * np.sign(c[np.argmax(np.abs(c))]), atol=1e-7)
    np.testing.assert_allclose(b, 5e8 * a, rtol=1e-6)  # b = g a: a conservative spring


def test_a_direction_the_motion_does_not_span_leaves_the_force_along_it_exact():
    x = _two_modes(2)
    x = np.vstack([x, 0.5 * x[0] - 0.25 * x[1]])  # a third sensor on the same two modes
    c = np.array([0.8, -0.5, 0.33])
    y = np.outer([1.0, 2.0, -1.0], 1e9 * (c @ x) ** 3)
    a, b = fit_rank_one(x, y)
    # a is fixed only within the motion's span; the force along the motion is (optimiser tol.)
    np.testing.assert_allclose(np.outer(b, (a @ x) ** 3), y, rtol=0, atol=1e-7 * np.abs(y).max())


def test_transform_and_the_sign_rule():
    x = _two_modes(2)
    c = np.array([-0.6, 0.8])  # its largest entry positive already
    y = np.diff(np.outer(3e8 * c, (c @ x) ** 3), 1, axis=-1)
    a, b = fit_rank_one(x, y, transform=lambda z: np.diff(z, 1, axis=-1))
    np.testing.assert_allclose(a, c, atol=1e-7)
    np.testing.assert_allclose(b, 3e8 * c, rtol=1e-6)
    a2, b2 = canonical_sign(-2.0 * a, -b / 8.0)  # the same force: (-2a . x)^3 (-b / 8)
    np.testing.assert_allclose(a2, a, rtol=0, atol=1e-15)
    np.testing.assert_allclose(b2, b, rtol=1e-15)
