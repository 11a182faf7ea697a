"""The direction form of sgd_sindy's cubic block (issue #15): its rule and its algebra."""

import numpy as np

from identify._sgd_matrix import MatrixSGDSettings, cubic_direction, cubic_feature


def _two_mode_motion(n: int = 4, N: int = 2000) -> tuple[np.ndarray, np.ndarray]:
    """Displacements (n, N) [m]: a dominant slow mode along ``phi`` and a weak fast one."""
    rng = np.random.default_rng(3)
    phi = np.abs(rng.normal(size=n)) + 0.1
    psi = rng.normal(size=n)
    t = np.arange(N) / 1000.0
    q1 = 1e-3 * np.exp(-2.0 * t) * np.cos(2 * np.pi * 20 * t)
    q2 = 1e-5 * np.exp(-5.0 * t) * np.cos(2 * np.pi * 170 * t)
    return np.outer(phi, q1) + np.outer(psi, q2), phi / np.linalg.norm(phi)


def test_direction_is_the_dominant_shape_and_does_not_depend_on_scale():
    x, phi = _two_mode_motion()
    w = cubic_direction(x)
    assert abs(np.linalg.norm(w) - 1.0) < 1e-12  # unit length, to rounding
    # the weak mode (1 % of the dominant one's amplitude) tilts w by about that much
    assert abs(w @ phi) > 0.999
    for scale in (1e-3, 1.0, 1e4):  # a stiffer beam or a harder impact: the same direction
        # rounding of an SVD of rescaled data: 1e-12 relative is ~1e4 machine epsilons
        np.testing.assert_allclose(cubic_direction(scale * x), w, rtol=0, atol=1e-12)
    np.testing.assert_allclose(cubic_direction(-x), w, rtol=0, atol=1e-12)  # sign fixed by rule


def test_feature_is_the_rank_one_K3_applied_to_the_cubes():
    x, _ = _two_mode_motion()
    w = cubic_direction(x)
    b = np.array([2.0, -1.0, 0.5, 3.0])
    K3 = np.outer(b, w**3)  # what fit_matrix_sgd returns for coefficients b of the feature
    # the simulation and the scorer evaluate K3 @ x^3: it must be b s exactly (rounding only)
    np.testing.assert_allclose(K3 @ x**3, np.outer(b, cubic_feature(x, w)), rtol=1e-12, atol=0)


def test_settings_refuse_an_unknown_cubic_form():
    base = dict(epochs=1, batch_size=8, learning_rate=1e-4, alpha_init=0.1, epsilon=0.01,
                beta=0.1, cubic=True, l1=True, l1_threshold=0.2, l1_debias=0.5,
                steps_per_epoch=None, init="lstsq", anneal=True, alpha_max=1.0,
                random_state=0, fit_duration=0.0, gradient="minibatch", iterate_average=0.25)
    assert MatrixSGDSettings(**base).cubic_form == "diagonal"
    try:
        MatrixSGDSettings(**base, cubic_form="tensor")
    except ValueError as e:
        assert "cubic_form" in str(e)
    else:
        raise AssertionError("an unknown cubic_form was accepted")
