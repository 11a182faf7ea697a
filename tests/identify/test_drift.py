"""The chain's integration constants are fitted with the model, not read as motion."""

import dataclasses

import numpy as np

from identify._structural_sim import simulate_structural
from identify.ls_sindy import LeastSquaresSINDy
from identify.structural import remove_drift
from testbed.core.measurement import Measurement
from testbed.pipeline.signal_chain import drift_basis

FS = 12800.0
M = np.array([[2.0, 0.3], [0.3, 1.0]])
K = np.array([[4e5, -1.5e5], [-1.5e5, 1.5e5]])
C = 2e-4 * K


def _measurement(e: np.ndarray, c: np.ndarray) -> Measurement:
    """Exact free decay of the 2-DOF model from sample 80, with a velocity offset ``e`` [m/s]
    and a displacement offset ``c`` [m] through the chain's high-pass (drift_basis rows)."""
    n, rest = 6400, 80
    t = np.arange(n - rest) / FS
    traj = simulate_structural(M, C, K, None, None, np.zeros(2), np.array([0.05, 0.02]), t)
    x, xd, xdd = (np.hstack([np.zeros((2, rest)), a]) for a in (traj.x, traj.xd, traj.xdd))
    basis = drift_basis(n, FS, rest, (10.0, 5, 0.1, 30.0))
    # unit-RMS rows: velocity offsets as H^2 s in xd and H I H s in x
    xd = xd + e[:, None] * basis[0]
    x = x + e[:, None] * basis[1] + c[:, None] * basis[0]
    return Measurement(fs=FS, x=x, xd=xd, xdd=xdd, channels=("s1", "s2"),
                       prior={"reduced_mass_trace": float(np.trace(M))}, free_start=rest,
                       drift_basis=basis)


def test_drift_rows_make_least_squares_exact_again():
    data = _measurement(np.array([3e-3, -2e-3]), np.array([2e-6, -1e-6]))
    true = np.linalg.solve(M, K)
    # the regression's property: the holds off (they read the measured decay, which has no
    # offsets, and took the model without drift rows from 2.2e-3 to 8.4e-4: measured)
    plain = {"eigen_hold": False, "decay_hold": False}
    with_drift = LeastSquaresSINDy(**plain).fit(data)
    without = LeastSquaresSINDy(**plain).fit(dataclasses.replace(data, drift_basis=None))
    err = lambda m: np.linalg.norm(np.linalg.solve(m.M_, m.K_) - true) / np.linalg.norm(true)  # noqa: E731
    # exact signals of the model plus offsets in the span of the rows: the regression is
    # exact up to rounding of the standardised least-squares solve (~1e-9 here)
    assert err(with_drift) < 1e-6
    assert err(without) > 1e-3  # the offsets read as motion bias the stiffness
    assert with_drift.coef_.shape == without.coef_.shape  # the drift rows are not model terms
    assert with_drift.drift_coef_.shape == (2, 2)
    assert "drift1" not in with_drift.feature_names_


def test_no_pulse_no_drift_rows():
    assert drift_basis(1000, FS, None, (10.0, 5, 0.1, 30.0)) is None
    assert drift_basis(1000, FS, 0, (10.0, 5, 0.1, 30.0)) is None


def test_remove_drift_recovers_the_offsets_and_the_signals():
    e, c = np.array([3e-3, -2e-3]), np.array([2e-6, -1e-6])
    data = _measurement(e, c)
    exact = _measurement(np.zeros(2), np.zeros(2))
    clean, offsets = remove_drift(data)
    # the linear fit is exact on these signals: rounding of the standardised solve only
    np.testing.assert_allclose(offsets, np.vstack([e, c]), rtol=1e-6)
    s = data.free_start
    for name in ("x", "xd"):
        got, want = getattr(clean, name)[:, s:], getattr(exact, name)[:, s:]
        assert np.linalg.norm(got - want) < 1e-6 * np.linalg.norm(want)
    assert clean.drift_basis is None
    assert remove_drift(clean) == (clean, None)


def test_driving_point_scaling_recovers_the_mass_sharing():
    """Same M^-1 K and trace, wrong modal masses; the gain at the driving point restores M, K, C."""
    from scipy import linalg

    from identify.structural import driving_point_scaling

    M3 = np.array([[2.0, 0.3, 0.0], [0.3, 1.5, 0.2], [0.0, 0.2, 1.0]])
    K3m = np.array([[6e5, -2e5, 0.0], [-2e5, 4e5, -1.5e5], [0.0, -1.5e5, 1.5e5]])
    C3 = 2e-4 * K3m
    _, phi = linalg.eigh(K3m, M3)
    pinv = np.linalg.inv(phi)
    wrong = pinv.T @ np.diag([0.5, 1.0, 2.0]) @ pinv          # other modal masses ...
    wrong *= np.trace(M3) / np.trace(wrong)                     # ... same total (the prior)
    Mf, Kf, Cf = wrong, wrong @ np.linalg.solve(M3, K3m), wrong @ np.linalg.solve(M3, C3)
    declared = np.array([[0.0], [0.0], [1.0]])                  # the force at sensor 3
    B = Mf @ np.linalg.solve(M3, declared)                      # what the fit's gain says
    (M2, C2, K2, K32, B2), rule = driving_point_scaling(Mf, Cf, Kf, None, B, declared)
    assert "driving point" in rule and K32 is None
    # exact algebra on 3x3 matrices: rounding only
    for got, want in ((M2, M3), (K2, K3m), (C2, C3), (B2, declared)):
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * np.abs(want).max())
    # a cubic model keeps the prior's scale, as does a model without an input
    assert driving_point_scaling(Mf, Cf, Kf, np.eye(3), B, declared)[0][0] is Mf
    assert driving_point_scaling(Mf, Cf, Kf, None, None, declared)[0][0] is Mf
