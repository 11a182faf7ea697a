"""Harmonics of a stronger peak are not modes (:func:`identify.structural.modal_peaks`).

Two known answers: a cubic (Duffing) oscillator, whose free response has odd harmonics of its
own frequency, seen by two sensors; and a linear 2-DOF system whose mode 2 sits at exactly
3x mode 1 with the same damping ratio (so even its amplitude follows the fundamental's cube
and it stays phase-locked to it): both modes are kept, told apart by their deflection shapes.
Short records (0.5 s) of lightly damped modes, where the fundamental's frequency barely drifts.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from identify.structural import HARMONIC_LOCK, HARMONIC_SHAPE_MAC, deflection_shapes, modal_peaks
from testbed.core.measurement import Measurement
from testbed.numerics.shapes import mac_matrix
from testbed.numerics.spectral import harmonic_lock

FS = 4000.0  # Hz
T = 0.5      # s: the family beams' record


def _measurement(xdd: np.ndarray) -> Measurement:
    z = np.zeros_like(xdd)
    return Measurement(fs=FS, x=z, xd=z, xdd=xdd, channels=tuple(f"s{i}" for i in range(len(xdd))),
                       passband=(10.0, FS / 2))


def _duffing_acceleration(f0: float, zeta: float, eps: float) -> np.ndarray:
    """Free decay of ``x'' + 2 zeta w x' + w^2 (x + eps x^3) = 0`` from ``x = 1`` [m/s^2],
    shape (n,): ``eps`` is the cubic force's share of the linear one at the start."""
    w = 2 * np.pi * f0

    def rhs(_t, y):
        return [y[1], -2 * zeta * w * y[1] - w**2 * (y[0] + eps * y[0] ** 3)]

    t = np.arange(round(T * FS)) / FS
    sol = solve_ivp(rhs, (0.0, t[-1]), [1.0, 0.0], t_eval=t, rtol=1e-10, atol=1e-12, method="DOP853")
    x, xd = sol.y
    return -2 * zeta * w * xd - w**2 * (x + eps * x**3)


def test_third_harmonic_of_a_cubic_oscillator_is_not_a_mode():
    a = _duffing_acceleration(30.0, 0.003, 0.3)
    ps = modal_peaks(_measurement(np.vstack([a, 0.6 * a])))
    f1 = ps.peaks[0]
    assert ps.peaks.size == 1 and not ps.nonlinear  # no drift seen: the amplitude law stays silent
    assert len(ps.harmonics) == 1
    f, k, f0 = ps.harmonics[0]
    assert k == 3 and f0 == f1 and f == pytest.approx(3 * f1, rel=0.01)
    assert "= 3 x" in ps.harmonic_rule
    assert any(r.startswith("harmonic 3") for _, r in ps.rejected)


def test_a_mode_at_exactly_three_times_mode_one_is_kept():
    """M = I, K with modes at 30 and 90 Hz (shapes (1, 2) and (2, -1): MAC 0), both 0.3 %
    damped: mode 2's phase stays locked to 3x mode 1's, and its amplitude falls as mode 1's
    cube, as a harmonic's would; only its shape says it is a mode."""
    t = np.arange(round(T * FS)) / FS
    shapes = np.array([[1.0, 2.0], [2.0, -1.0]]) / np.sqrt(5.0)  # rows: modes
    out = np.zeros((2, t.size))
    for f, amp, phi in zip((30.0, 90.0), (1.0, 0.05), shapes, strict=True):
        w, zeta = 2 * np.pi * f, 0.003
        out += np.outer(phi, amp * np.exp(-zeta * w * t) * np.cos(w * np.sqrt(1 - zeta**2) * t))
    data = _measurement(out)
    ps = modal_peaks(data)
    assert ps.peaks == pytest.approx([30.0, 90.0], abs=0.3)
    assert ps.harmonics == []
    sh = deflection_shapes(out, FS, ps.peaks)
    assert harmonic_lock(out, FS, ps.peaks[0], ps.peaks[1], 3, sh[0], sh[1]) >= HARMONIC_LOCK
    assert mac_matrix(sh[0], sh[1])[0, 0] < HARMONIC_SHAPE_MAC
