"""Poles identified on trapezoid-rule integrals, mapped back (identify.structural.unwarp_trapezoid)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import linalg

from identify.structural import modal, on_trapezoid_cut, unwarp_trapezoid, warp_frequency
from testbed.numerics import filters as sig

FS = 12800.0  # the paper's sample rate [Hz]


def two_dof(f1: float, f2: float, zeta: tuple[float, float], nonproportional: float = 0.0):
    """A 2-DOF M, C, K with modes at f1, f2 [Hz] and modal damping ratios ``zeta``, plus an
    optional non-proportional damper between the masses [N s/m]."""
    M = np.array([[2.0, 0.3], [0.3, 1.0]])
    phi = np.array([[1.0, 0.6], [0.8, -1.2]])
    m_modal = np.diag(phi.T @ M @ phi)
    phi = phi / np.sqrt(m_modal)  # mass-normalised: phi^T M phi = I
    w = 2 * np.pi * np.array([f1, f2])
    inv = np.linalg.inv(phi)
    K = inv.T @ np.diag(w**2) @ inv
    C = inv.T @ np.diag(2 * np.array(zeta) * w) @ inv
    C = C + nonproportional * np.array([[1.0, -1.0], [-1.0, 1.0]])
    return M, 0.5 * (C + C.T), 0.5 * (K + K.T)


def fit_on_trapezoid_integrals(M, C, K, seconds: float = 0.05):
    """Free decay sampled exactly (matrix exponential), integrated by the trapezoid rule and
    regressed: the model the paper's chain identifies, with M given."""
    n = M.shape[0]
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    step = linalg.expm(A / FS)
    z = np.empty((2 * n, int(seconds * FS)))
    z[:, 0] = [1e-3, -2e-3, 0.5, 0.1]
    for k in range(1, z.shape[1]):
        z[:, k] = step @ z[:, k - 1]
    a = A[n:] @ z  # exact sampled accelerations
    v = sig.trapezoid(a, FS)
    x = sig.trapezoid(v, FS)
    k = np.arange(z.shape[1], dtype=float)
    # integration constants: a constant in v, a constant and a ramp in x, free per equation
    lib = np.vstack([v, x, np.ones_like(k), k])
    coef = np.linalg.lstsq(lib.T, -(M @ a).T, rcond=None)[0].T
    return coef[:, :n], coef[:, n:2 * n]


@pytest.mark.parametrize("f1,f2,zeta,nonprop", [
    (98.5, 617.0, (0.027, 0.166), 0.0),      # beams_stiff__000 of studies/families.toml
    (300.0, 1500.0, (0.02, 0.30), 0.0),      # a heavily damped mode at 0.12 fs
    (150.0, 2500.0, (0.01, 0.05), 40.0),     # non-proportional damping
])
def test_unwarp_recovers_the_continuous_model(f1, f2, zeta, nonprop):
    M, C, K = two_dof(f1, f2, zeta, nonprop)
    C_w, K_w = fit_on_trapezoid_integrals(M, C, K)
    f_true = modal(M, K)[0]
    f_warped = modal(M, K_w)[0]
    # the paper's chain: every mode too stiff, by about the bilinear map's stretch
    assert np.all(f_warped > f_true * (1 + 0.5 * (warp_frequency(f_true, FS) / f_true - 1)))
    C_u, K_u = unwarp_trapezoid(M, C_w, K_w, FS)
    # mapped back: the exact model, to the regression's rounding (the data are exact samples
    # of the continuous system, so only floating point separates them; 1e-7 relative)
    np.testing.assert_allclose(K_u, K, rtol=0, atol=1e-7 * np.abs(K).max())
    np.testing.assert_allclose(C_u, C, rtol=0, atol=1e-7 * np.abs(C).max())


def test_warp_frequency_is_the_tangent_map():
    f = np.array([0.0, 617.0, 1500.0])
    np.testing.assert_allclose(warp_frequency(f, FS), FS / np.pi * np.tan(np.pi * f / FS))
    # 0.0077149 exactly: the quoted 0.0077 to its last digit
    assert warp_frequency(np.array([617.0]), FS)[0] / 617.0 - 1 == pytest.approx(0.0077, abs=1e-4)


def test_unwarp_refuses_a_pole_beyond_the_map():
    M = np.eye(1)
    # an overdamped mode with a real pole at -3 fs: tanh never reaches it
    C, K = np.array([[3.0 * FS + 1.0]]), np.array([[3.0 * FS]])
    assert unwarp_trapezoid(M, C, K, FS) is None


def test_chain_declares_trapezoid_integration_and_identifiers_map_back(dataset_cache):
    from identify.ls_sindy import LeastSquaresSINDy
    from testbed import load_scenario, measure

    sc = load_scenario("cantilever_stiff_impact_lsq")
    data = measure(dataset_cache.get(sc), sc.signal, "structural")
    assert data.integration == "trapezoid"
    est = LeastSquaresSINDy().fit(data)
    assert est.integration_rule_.startswith("trapezoid integrals: poles mapped back")


def critically_damped_top(ratio: float, angle: float):
    """A 2-DOF model whose mode 1 rings at 300 Hz (2 % damped) and whose mode 2 is critically
    damped, a double real pole at ``p = -ratio 2 fs`` (on the trapezoid map's cut for
    ``ratio >= 1``), shapes rotated by ``angle`` [rad]."""
    M = 1.7 * np.eye(2)
    phi = np.array([[np.cos(angle), -np.sin(angle)], [np.sin(angle), np.cos(angle)]]) / np.sqrt(1.7)
    inv = np.linalg.inv(phi)
    w = np.array([2 * np.pi * 300.0, ratio * 2 * FS])
    K = inv.T @ np.diag(w**2) @ inv
    C = inv.T @ np.diag(2 * np.array([0.02, 1.0]) * w) @ inv
    return M, 0.5 * (C + C.T), 0.5 * (K + K.T)


def test_unwarp_keeping_the_cut_maps_the_resolved_mode_whatever_round_off_returns():
    """A double real pole beyond the map's range comes back from the eigensolver as two real
    poles or as a complex pair 1e-8 off the axis, decided by round-off (on this machine 442 of
    753 such models were two reals, left warped whole, and 311 a pair, mapped with the pair at
    the Nyquist frequency).  With ``keep_cut`` the poles on the cut are kept as fitted and mode
    1 is mapped back in every one of them."""
    p1 = complex(-0.02 * 2 * np.pi * 300.0, 2 * np.pi * 300.0 * np.sqrt(1 - 0.02**2))
    f1_mapped = abs((2 * FS * np.arctanh(p1 / (2 * FS))).imag) / (2 * np.pi)
    for ratio in np.linspace(1.05, 1.3, 51):
        for angle in (0.3, 0.7, 1.1):
            M, C, K = critically_damped_top(ratio, angle)
            out = unwarp_trapezoid(M, C, K, FS, keep_cut=True)
            assert out is not None, (ratio, angle)
            p = linalg.eigvals(np.block([[np.zeros((2, 2)), np.eye(2)],
                                         [-np.linalg.solve(M, out[1]), -np.linalg.solve(M, out[0])]]))
            p = p[np.argsort(np.abs(p))]
            # mode 1 mapped exactly (the map of its pole; 1e-9: the eigensolver's round-off on a
            # 1.8e3 rad/s pole beside a 3e4 rad/s double one)
            assert abs(p[0].imag) / (2 * np.pi) == pytest.approx(f1_mapped, rel=1e-9)
            # the double pole kept: its two poles within round-off of a defective pair's
            # sqrt(eps) splitting (1e-4 relative) of the fitted -ratio 2 fs
            np.testing.assert_allclose(p[2:].real, -ratio * 2 * FS, rtol=1e-4)
            assert np.all(np.abs(p[2:].imag) <= 1e-4 * ratio * 2 * FS)


def test_on_trapezoid_cut():
    q = np.array([-1.2, -1.2 + 1e-8j, -1.2 + 0.5j, -0.99, 1.0, 0.3 + 1e-9j])
    assert on_trapezoid_cut(q).tolist() == [True, True, False, False, True, False]
