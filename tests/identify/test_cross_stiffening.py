"""A cubic model's linear target below the record's peak by the stiffening the other modes' motion
adds over the mode's life (identify._sgd_matrix.cross_stiffening; session 16, round 14's
b14_soft_r2p5_cf0p5_n40_s4_z0p1)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from identify._sgd_matrix import backbone_targets, cross_stiffening
from identify.structural import modal
from testbed.core.measurement import Measurement

FS = 2000.0  # Hz
M = np.eye(2)
K = np.array([[5000.0 + 30000.0, -30000.0], [-30000.0, 30000.0]])  # N/m: modes 7.7 / 46.3 Hz
K3 = np.array([[5.0e6, 0.0], [0.0, 0.0]])  # N/m^3: a cubic spring on coordinate 1 (the base)


@pytest.fixture(scope="module")
def record():
    """Free decay over 1 s, mode 1 large (0.02 m on coordinate 1: mode 1 +12 %, mode 2 +1.2 %)
    and lightly damped (0.1 %), mode 2 small (3 mm modal) and damped 1 %: mode 2 rings at a
    constant hardened frequency; integrated independently (solve_ivp, rtol 1e-8)."""
    f, Phi = modal(M, K)
    w = 2 * np.pi * f
    C = M @ Phi @ np.diag(2 * np.array([0.001, 0.01]) * w) @ Phi.T @ M  # modal damping
    q0 = np.array([0.02 / Phi[0, 0], 3e-3])  # modal amplitudes (Phi orthonormal: M = I)

    def rhs(_, y):
        x, v = y[:2], y[2:]
        return np.concatenate([v, -C @ v - K @ x - K3 @ x ** 3])  # M = I

    t = np.arange(int(1.0 * FS)) / FS
    sol = solve_ivp(rhs, (0, t[-1]), np.concatenate([Phi @ q0, np.zeros(2)]), t_eval=t,
                    rtol=1e-8, atol=1e-11, method="DOP853")
    x, v = sol.y[:2], sol.y[2:]
    a = np.array([rhs(0, y)[2:] for y in sol.y.T]).T
    return f, Phi, Measurement(FS, x, v, a, ("c1", "c2"))


def _peak_hz(q: np.ndarray, lo: float, hi: float) -> float:
    """The highest line of ``q``'s spectrum in [lo, hi] Hz, zero-padded 64x."""
    n = 64 * q.size
    spec = np.abs(np.fft.rfft(q * np.hanning(q.size), n))
    fr = np.fft.rfftfreq(n, 1 / FS)
    band = (fr >= lo) & (fr <= hi)
    return float(fr[band][np.argmax(spec[band])])


def test_the_record_peak_less_the_cross_stiffening_is_the_linear_frequency(record):
    f, Phi, data = record
    q2 = np.linalg.solve(Phi, data.x)[1]
    peak = _peak_hz(q2, 30.0, 70.0)
    assert peak / f[1] - 1.0 > 0.01  # the record's mode 2 is hardened by mode 1's motion
    lam = (2 * np.pi * peak) ** 2 - cross_stiffening(data, M, K, K3, (0, data.n_samples))[1]
    # first order in the stiffening, read from a line of a 1 s record (64x padded): within a
    # tenth of the shift (measured: 40.31 Hz -> 39.81 against 39.82, 3 % of it)
    assert np.sqrt(lam) / (2 * np.pi) == pytest.approx(f[1], abs=0.1 * (peak - f[1]))


def test_backbone_targets_lower_a_peak_by_the_cross_stiffening(record):
    """The old backbone_targets kept mode 2's hardened peak as its linear target."""
    f, Phi, data = record
    q2 = np.linalg.solve(Phi, data.x)[1]
    peaks = (2 * np.pi * np.array([f[0], _peak_hz(q2, 30.0, 70.0)])) ** 2
    C = np.zeros((2, 2))
    lam, moved, rule = backbone_targets(data, M, C, K, (0, data.n_samples), peaks, K3)
    assert moved[1] and "other modes' motion" in rule
    peak_hz = np.sqrt(peaks[1]) / (2 * np.pi)
    assert np.sqrt(lam[1]) / (2 * np.pi) == pytest.approx(f[1], abs=0.1 * (peak_hz - f[1]))
    lam0, _, _ = backbone_targets(data, M, C, K, (0, data.n_samples), peaks)
    assert lam0[1] > lam[1]  # without the cubic: the peak or its backbone limit, as before


def test_the_cross_stiffening_subtracted_is_returned_for_an_outlived_mode(record):
    """``cross_out`` holds the shift subtracted from mode 2 (outlived by mode 1: damped 1 %
    against 0.1 %), which the decay hold takes off mode 2's measured decay frequency too."""
    f, Phi, data = record
    q2 = np.linalg.solve(Phi, data.x)[1]
    peaks = (2 * np.pi * np.array([f[0], _peak_hz(q2, 30.0, 70.0)])) ** 2
    cross = np.zeros(2)
    backbone_targets(data, M, np.zeros((2, 2)), K, (0, data.n_samples), peaks,
                                     K3, cross)
    shift = cross_stiffening(data, M, K, K3, (0, data.n_samples))
    assert cross[0] == 0.0 and cross[1] == pytest.approx(shift[1], rel=1e-12)
