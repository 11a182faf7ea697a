"""Metrics on cases computed by hand, plus a few properties."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from testbed.scoring import metrics as mt

finite = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)


# ------------------------------------------------------------------ TRAC
def test_trac_hand_cases():
    t = np.linspace(0, 1, 1000, endpoint=False)
    s, c = np.sin(2 * np.pi * 3 * t), np.cos(2 * np.pi * 3 * t)
    x = np.stack([s, s, s, s])
    y = np.stack([2 * s, -0.5 * s, c, s + c])
    # x vs 2x: 1; vs -x/2: 1 (squared); orthogonal sines over whole periods: 0;
    # s vs s + c: (s.s)^2 / (s.s * 2 s.s) = 1/2
    np.testing.assert_allclose(mt.trac(x, y), [1.0, 1.0, 0.0, 0.5], atol=1e-12)
    assert mt.trac(s, 2 * s).shape == (1,)


def test_trac_complex_and_zero():
    x = np.array([1 + 1j, 2 - 1j, 0.5j])
    np.testing.assert_allclose(mt.trac(x, (3 - 2j) * x), [1.0], atol=1e-12)  # complex scale
    np.testing.assert_allclose(mt.trac(np.array([1.0, 0]), np.array([0, 1j])), [0.0])
    assert np.isnan(mt.trac(np.zeros(5), np.ones(5))[0])
    with pytest.raises(ValueError):
        mt.trac(np.ones((2, 5)), np.ones((2, 6)))


@settings(max_examples=60, deadline=None)
@given(arrays(float, (3, 20), elements=finite), arrays(float, (3, 20), elements=finite),
       st.floats(0.01, 100.0), st.floats(0.01, 100.0))
def test_trac_bounded_and_scale_invariant(x, y, a, b):
    r = mt.trac(x, y)
    ok = ~np.isnan(r)
    assert np.all((r[ok] >= 0) & (r[ok] <= 1))
    # scale invariance up to rounding, where both channels are clearly nonzero
    big = (np.abs(x).max(axis=1) > 1e-3) & (np.abs(y).max(axis=1) > 1e-3)
    np.testing.assert_allclose(mt.trac(a * x, -b * y)[big], r[big], atol=1e-9)


# ------------------------------------------------------------------ MAC and pairing
def test_mac_hand_cases():
    phi = np.array([[1.0, 1.0], [1.0, -1.0]])
    np.testing.assert_allclose(mt.mac_matrix(phi, phi), np.eye(2), atol=1e-15)  # orthogonal shapes
    np.testing.assert_allclose(mt.mac_matrix(phi, -3 * phi), np.eye(2), atol=1e-15)
    # [1, 0] vs [1, 1]: 1 / (1 * 2)
    np.testing.assert_allclose(mt.mac_matrix(np.array([1.0, 0.0]), phi), [[0.5, 0.5]])
    assert mt.mac_matrix(np.ones((4, 3)), np.ones((4, 2))).shape == (3, 2)
    z = np.array([1.0, 1j])
    np.testing.assert_allclose(mt.mac_matrix(z, (2 + 1j) * z), [[1.0]], atol=1e-15)


@settings(max_examples=60, deadline=None)
@given(arrays(float, (4, 3), elements=finite), arrays(float, (4, 2), elements=finite))
def test_mac_symmetric_and_bounded(a, b):
    m = mt.mac_matrix(a, b)
    np.testing.assert_array_equal(np.isnan(m), np.isnan(mt.mac_matrix(b, a).T))
    # MAC values lie in [0, 1]: the same products in the transposed order agree to rounding
    np.testing.assert_allclose(m, mt.mac_matrix(b, a).T, atol=1e-12)
    ok = ~np.isnan(m)
    assert np.all((m[ok] >= 0) & (m[ok] <= 1))


def test_pair_modes_beats_greedy():
    mac = np.array([[0.9, 0.8], [0.85, 0.1]])
    # row-wise argmax gives [0, 0] (reuse); the best assignment is 0.8 + 0.85 = 1.65 > 0.9 + 0.1
    np.testing.assert_array_equal(mt.pair_modes(mac), [1, 0])
    np.testing.assert_array_equal(mt.pair_modes(np.array([[0.1, 0.9, 0.0], [0.95, 0.2, 0.3]])), [1, 0])
    np.testing.assert_array_equal(mt.pair_modes(np.array([[0.9], [0.2], [0.95]])), [-1, -1, 0])
    np.testing.assert_array_equal(mt.pair_modes(np.array([[np.nan, 0.5], [0.7, np.nan]])), [1, 0])



def test_pair_modes_by_shape_and_frequency_on_alike_shapes():
    # A soft-based family beam seen by three sensors (beams_soft__004, sgd_sindy, 2026-11-26):
    # rows true modes 28.06 / 317.98 / 1002.3 Hz, columns identified 28.64 / 74.23 (an
    # overdamped pole pair) / 305.7 Hz.  The summed MAC alone pairs true mode 1 with the 74 Hz
    # pair (0.959 + 0.979 + 0.648 beats 1.000 + 1.000 + 0.312).
    mac = np.array([[1.0, 0.9592, 0.9781], [0.9795, 0.8898, 1.0], [0.5016, 0.3124, 0.6477]])
    f_true, f_id = np.array([28.0592, 317.9815, 1002.3005]), np.array([28.6354, 74.2255, 305.7356])
    np.testing.assert_array_equal(mt.pair_modes(mac), [1, 0, 2])
    np.testing.assert_array_equal(mt.pair_modes(mac, f_true, f_id), [0, 2, 1])
    # an unstable identified mode (NaN frequency) is paired last, with what no other mode took
    np.testing.assert_array_equal(
        mt.pair_modes(np.ones((2, 2)), [10.0, 20.0], [np.nan, 10.5]), [1, 0])
    # shapes still decide between modes of like frequency
    np.testing.assert_array_equal(
        mt.pair_modes(np.array([[0.2, 0.99], [0.99, 0.2]]), [10.0, 10.2], [10.1, 10.1]), [1, 0])
    with pytest.raises(ValueError, match="do not match"):
        mt.pair_modes(mac, f_true[:2], f_id)

# ------------------------------------------------------------------ relative errors
def test_frequency_and_damping_errors():
    np.testing.assert_allclose(mt.frequency_error([89.7, 591.2], [89.6, 576.3]),
                               [0.1 / 89.6, 14.9 / 576.3])  # the paper's Table 2: 0.1 %, 2.6 %
    np.testing.assert_allclose(mt.damping_error([0.011, 0.018], [0.01, 0.02]), [0.1, 0.1])
    assert np.isinf(mt.frequency_error([1.0], [0.0]))[0]


def test_relative_error():
    a = np.array([[3.0, 0.0], [0.0, 4.0]])
    assert mt.relative_error(a, a) == 0.0
    assert mt.relative_error(a + np.array([[0.0, 0.5], [0.0, 0.0]]), a) == pytest.approx(0.5 / 5.0)
    assert mt.relative_error(np.zeros(2), np.zeros(2)) == 0.0
    assert mt.relative_error(np.ones(2), np.zeros(2)) == np.inf


def test_rmse():
    x = np.array([[0.0, 0.0, 0.0, 0.0], [1.0, 1.0, 1.0, 1.0]])
    y = np.array([[1.0, -1.0, 1.0, -1.0], [1.0, 1.0, 1.0, 3.0]])
    np.testing.assert_allclose(mt.rmse(x, y), [1.0, 1.0])  # sqrt(4/4), sqrt(4/4)
    np.testing.assert_allclose(mt.rmse(x, y, axis=0), np.sqrt([0.5, 0.5, 0.5, 2.5]))


# ------------------------------------------------------------------ sparse support
def test_support_scores_counted_by_hand():
    true = np.array([[1.0, 0.0, -2.0], [0.0, 0.0, 3.0]])
    ident = np.array([[0.9, 0.1, 0.0], [0.0, 0.0, 2.5]])
    # nonzero true: (0,0) (0,2) (1,2); identified: (0,0) (0,1) (1,2)
    # tp = 2 [(0,0) (1,2)], fp = 1 [(0,1)], fn = 1 [(0,2)] -> p = r = 2/3, F1 = 2/3
    s = mt.support_scores(ident, true)
    assert (s["tp"], s["fp"], s["fn"]) == (2, 1, 1)
    assert s["precision"] == pytest.approx(2 / 3) and s["recall"] == pytest.approx(2 / 3)
    assert s["f1"] == pytest.approx(2 / 3)
    # with tol = 0.2 the 0.1 entry counts as zero: tp 2, fp 0, fn 1 -> p 1, r 2/3, F1 0.8
    s = mt.support_scores(ident, true, tol=0.2)
    assert (s["precision"], s["recall"], s["f1"]) == pytest.approx((1.0, 2 / 3, 0.8))


def test_support_scores_degenerate():
    z, o = np.zeros(4), np.array([0.0, 1.0, 0.0, 0.0])
    assert mt.support_scores(z, z) == {"precision": 1.0, "recall": 1.0, "f1": 1.0,
                                       "tp": 0, "fp": 0, "fn": 0}
    for ident, true in ((z, o), (o, z)):
        s = mt.support_scores(ident, true)
        assert (s["precision"], s["recall"], s["f1"]) == (0.0, 0.0, 0.0)


def test_coefficient_error():
    true = np.array([2.0, 0.0, -4.0])
    assert mt.coefficient_error(np.array([2.2, 5.0, -4.0]), true) == pytest.approx(0.1)
    assert mt.coefficient_error(np.array([2.0, 0.0, 0.0]), true) == 1.0  # dropped term
    assert np.isnan(mt.coefficient_error(np.ones(3), np.zeros(3)))


# ------------------------------------------------------------------ modal analysis
M2 = np.eye(2) * 2.0
K2 = np.array([[2.0, -1.0], [-1.0, 2.0]]) * 800.0  # chain of two 2 kg masses, springs 800 N/m


def test_two_dof_undamped_by_hand():
    # det(K - w^2 M) = 0 with M = 2 I, K = 800 [[2, -1], [-1, 2]]: w^2 = 400 (in phase), 1200
    f, z, phi = mt.modal_from_matrices(M2, None, K2)
    np.testing.assert_allclose(f, np.sqrt([400.0, 1200.0]) / (2 * np.pi), rtol=1e-12)
    np.testing.assert_array_equal(z, [0.0, 0.0])
    # mass-normalised: [1, 1] / sqrt(2 * 2) and [1, -1] / 2, largest entry positive
    np.testing.assert_allclose(np.abs(phi), 0.5, rtol=1e-12)
    np.testing.assert_allclose(phi[:, 0], [0.5, 0.5], rtol=1e-12)
    np.testing.assert_allclose(phi.T @ M2 @ phi, np.eye(2), atol=1e-12)


def test_two_dof_proportional_damping_by_hand():
    alpha, beta = 2.0, 1e-3
    f, z, _ = mt.modal_from_matrices(M2, alpha * M2 + beta * K2, K2)
    w = np.sqrt([400.0, 1200.0])
    # Rayleigh damping: zeta_i = alpha / (2 w_i) + beta w_i / 2, frequencies unchanged
    np.testing.assert_allclose(f, w / (2 * np.pi), rtol=1e-10)
    np.testing.assert_allclose(z, alpha / (2 * w) + beta * w / 2, rtol=1e-10)


def test_overdamped_and_nonproportional():
    # SDOF k = 100, m = 1, c = 2 * 2 * 10: zeta = 2, two real eigenvalues
    f, z, _ = mt.modal_from_matrices(np.eye(1), np.array([[40.0]]), np.array([[100.0]]))
    np.testing.assert_allclose(f, [10 / (2 * np.pi)], rtol=1e-10)
    np.testing.assert_allclose(z, [2.0], rtol=1e-10)
    # a damper on DOF 1 only: frequencies and damping from the complex eigenvalues directly
    c = np.array([[4.0, 0.0], [0.0, 0.0]])
    f, z, _ = mt.modal_from_matrices(M2, c, K2)
    a = np.block([[np.zeros((2, 2)), np.eye(2)], [-K2 / 2.0, -c / 2.0]])
    lam = np.linalg.eigvals(a)
    lam = np.sort_complex(lam[lam.imag > 0])
    lam = lam[np.argsort(np.abs(lam))]
    np.testing.assert_allclose(f, np.abs(lam) / (2 * np.pi), rtol=1e-10)
    np.testing.assert_allclose(z, -lam.real / np.abs(lam), rtol=1e-10)


def test_bad_mass_matrix():
    bad = np.array([[1.0, 0.0], [0.0, -1.0]])
    with pytest.raises(ValueError, match="positive definite"):
        mt.modal_from_matrices(bad, None, K2)
    f, z, phi = mt.modal_from_matrices(bad, None, K2, strict=False)
    assert np.all(np.isnan(f)) and np.all(np.isnan(z)) and np.all(np.isnan(phi))
    with pytest.raises(ValueError, match="negative"):
        mt.modal_from_matrices(M2, None, -K2)
    f, _, _ = mt.modal_from_matrices(M2, None, np.diag([800.0, -800.0]), strict=False)
    assert np.isnan(f[-1]) and np.isfinite(f[0])  # the unstable mode is NaN and sorted last


def test_cross_orthogonality_identity_for_perfect_modes():
    _, _, phi = mt.modal_from_matrices(M2, None, K2)
    ident = phi * np.array([-7.0, 0.3])  # arbitrary scale and sign
    np.testing.assert_allclose(mt.cross_orthogonality(ident, phi, M2), np.eye(2), atol=1e-12)
    # a mode mixing both true modes equally: off-diagonals 1/sqrt(2) in magnitude
    mixed = np.stack([phi[:, 0] + phi[:, 1], phi[:, 1]], axis=1)
    xo = mt.cross_orthogonality(mixed, phi, M2)
    np.testing.assert_allclose(np.abs(xo), [[2**-0.5, 2**-0.5], [0.0, 1.0]], atol=1e-12)


def test_modes_of_a_nonsymmetric_identified_stiffness_are_the_right_eigenvectors():
    """A model with diagonal M and K = M A (A = M_true^-1 K_true, not symmetric in these coordinates)
    vibrates in the eigenvectors of A; symmetrising K would report other shapes."""
    import numpy as np

    from testbed.scoring.metrics import mac_matrix, modal_from_matrices

    m_true = np.array([[2.0, 0.5], [0.5, 1.0]])
    k_true = np.array([[300.0, -100.0], [-100.0, 200.0]])
    a = np.linalg.solve(m_true, k_true)
    m_id = np.eye(2) * 1.5
    k_id = m_id @ a
    assert not np.allclose(k_id, k_id.T)
    f_true, _, phi_true = modal_from_matrices(m_true, None, k_true)
    f_id, _, phi_id = modal_from_matrices(m_id, None, k_id)
    # one eigenproblem (M^-1 K = A for both models) solved twice: equal to rounding
    np.testing.assert_allclose(f_id, f_true, rtol=1e-12)
    np.testing.assert_allclose(np.diag(mac_matrix(phi_id, phi_true)), 1.0, rtol=1e-12)


def test_cubic_acceleration_error_ignores_the_mass_sharing():
    """M^-1 K3 x^3 is what the data fix: an equation left-multiplied by any invertible S (another
    modal-mass sharing) scores alike, while the force error sees the sharing."""
    rng = np.random.default_rng(0)
    A = rng.normal(size=(3, 3))
    Mr = A @ A.T + 3 * np.eye(3)
    f_true = rng.normal(size=(3, 200))
    S = np.diag([1.0, 2.0, 0.5]) + 0.1 * rng.normal(size=(3, 3))
    # S cancels exactly in (S Mr)^-1 (S f): zero to rounding
    assert mt.cubic_acceleration_error(S @ Mr, S @ f_true, Mr, f_true) == pytest.approx(0.0, abs=1e-12)
    assert mt.relative_error(S @ f_true, f_true) > 0.3  # K3_force_error's view of the same model
    # a 10 % too large cubic acceleration scores 0.1, whatever the sharing
    assert mt.cubic_acceleration_error(S @ Mr, 1.1 * S @ f_true, Mr, f_true) == pytest.approx(0.1)
    assert np.isnan(mt.cubic_acceleration_error(np.zeros((3, 3)), f_true, Mr, f_true))


def test_identify_summary_reports_the_scorer_modes():
    # `testbed identify`'s printed modes and the scorer's come from one routine: an overdamped
    # mode is one mode with a ratio above 1 (not two real poles printed as two modes), an
    # unstable mode is None (JSON null), and frequencies are the undamped w_n / 2 pi.
    from testbed.pipeline.fit import modal_parameters

    M, K = np.diag([1.0, 2.0]), np.diag([(2 * np.pi * 10.0) ** 2, 2.0 * (2 * np.pi * 30.0) ** 2])
    C = np.diag([2 * 0.02 * 2 * np.pi * 10.0, 2.0 * 2 * 1.5 * 2 * np.pi * 30.0])  # zeta 0.02, 1.5
    got = modal_parameters(M, C, K)
    f, z, _ = mt.modal_from_matrices(M, C, K)
    np.testing.assert_allclose(got["frequency_hz"], f, rtol=1e-12)  # the same numbers, rounding
    np.testing.assert_allclose(got["damping_ratio"], z, rtol=1e-12)
    np.testing.assert_allclose(got["frequency_hz"], [10.0, 30.0], rtol=1e-9)  # exact: decoupled
    np.testing.assert_allclose(got["damping_ratio"], [0.02, 1.5], rtol=1e-9)
    unstable = modal_parameters(M, C, np.diag([-1.0, 4.0]))
    assert unstable["frequency_hz"][1] is None and unstable["damping_ratio"][1] is None


def _poles(M, C, K):
    n = M.shape[0]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-np.linalg.solve(M, K), -np.linalg.solve(M, C)]])
    return np.linalg.eigvals(A)


def test_a_conjugate_pole_pair_is_never_split_across_modes():
    # round 8's soft beam, three sensors, 3 % noise, ls_sindy's model (rounded to 5 digits):
    # underdamped poles near 17.6 Hz and 227.6 Hz and one overdamped mode (two real poles).
    # Assigned by MAC slot by slot, the 17.6 Hz pole went with a real pole and mode 1 was
    # reported at 2.89 Hz, zeta 6.6.
    M = 0.4397 * np.eye(3)
    C = np.array([[382.12, -302.45, 76.850], [-428.13, 512.15, -201.27], [599.75, -827.81, 359.96]])
    K = np.array([[746580.0, -139090.0, -139630.0], [177740.0, 42542.0, -79409.0],
                  [-731860.0, -182250.0, 351410.0]])
    p = _poles(M, C, K)
    up = p[p.imag > 0]
    real = p[p.imag == 0]
    assert up.size == 2 and real.size == 2  # the case: two underdamped modes, one overdamped
    f, z, _ = mt.modal_from_matrices(M, C, K)
    # each underdamped pole is one mode: w_n = |lambda|, zeta = -Re / |lambda| (to rounding)
    for lam in up:
        k = np.argmin(np.abs(f - abs(lam) / (2 * np.pi)))
        assert f[k] == pytest.approx(abs(lam) / (2 * np.pi), rel=1e-9)
        assert z[k] == pytest.approx(-lam.real / abs(lam), rel=1e-9)
    # the two real poles are the third mode: w_n^2 = l1 l2, 2 zeta w_n = -(l1 + l2)
    wn = np.sqrt(np.prod(real.real))
    k = np.argmin(np.abs(f - wn / (2 * np.pi)))
    assert f[k] == pytest.approx(wn / (2 * np.pi), rel=1e-9)
    assert z[k] == pytest.approx(-real.real.sum() / (2 * wn), rel=1e-9) and z[k] > 1.0


def test_modes_reproduce_the_poles_of_random_damped_models():
    # every model's n modes give back its 2n poles: no conjugate pair split, whatever the
    # damping (light to overdamped, non-proportional) and however alike the shapes
    rng = np.random.default_rng(8)
    for _ in range(200):
        n = int(rng.integers(2, 6))
        A = rng.normal(size=(n, n))
        M = A @ A.T + n * np.eye(n)
        B = rng.normal(size=(n, n))
        K = B @ B.T + 0.1 * np.eye(n)
        if rng.random() < 0.5:  # a non-symmetric identified K
            K = K + 0.2 * rng.normal(size=(n, n)) * np.abs(K).max()
        D = rng.normal(size=(n, n))
        C = 10.0 ** rng.uniform(-2, 1.5) * (D @ D.T)
        p = _poles(M, C, K)
        if np.any(p.real >= 0) or np.any(np.linalg.eigvals(np.linalg.solve(M, K)).real <= 0):
            continue  # scored as unstable elsewhere
        f, z, _ = mt.modal_from_matrices(M, C, K, strict=False)
        got = []
        for fk, zk in zip(f, z, strict=True):
            wn = 2 * np.pi * fk
            got += list(np.roots([1.0, 2 * zk * wn, wn**2]))
        got, want = np.sort_complex(np.array(got)), np.sort_complex(p)
        np.testing.assert_allclose(got, want, rtol=1e-6, atol=1e-9 * np.abs(p).max())
