"""A cubic model's modal masses from the free decay's gain at the driving point.

An impact's samples hold, besides the kept modes' response, the quasi-static response of the
modes a reduced model leaves out (it ends with the pulse).  A gain fitted on them takes it for
the kept modes'; :func:`identify.structural.free_decay_gain` reads the gain from the free decay
after the pulse only, and :func:`identify.structural.driving_point_scaling` shares a cubic
model's mass by it.  The truth here is constructed: a 3-DOF model with known ``M, C, K``, its
exact linear response to a half-sine pulse at sensor 3, and a feedthrough added to the
accelerations during the pulse (what the truncated modes would add).
"""

from __future__ import annotations

import dataclasses

import numpy as np
from scipy import linalg

from identify._structural_sim import simulate_structural
from identify.structural import (
    correlation_factor,
    driving_point_scaling,
    free_decay_fit,
    free_decay_gain,
    held_share,
    modal_spread,
)
from testbed.core.measurement import Measurement

FS = 4000.0                    # Hz: the modes (about 33-150 Hz) well resolved
PULSE = 8                      # samples of the half-sine pulse (2 ms)
M3 = np.array([[2.0, 0.3, 0.0], [0.3, 1.5, 0.2], [0.0, 0.2, 1.0]])
K3M = np.array([[6e5, -2e5, 0.0], [-2e5, 4e5, -1.5e5], [0.0, -1.5e5, 1.5e5]])
C3 = 2e-4 * K3M
DECLARED = np.array([[0.0], [0.0], [1.0]])   # the force at sensor 3


def _record(fs: float = FS, K3: np.ndarray | None = None) -> Measurement:
    """The exact response to a 2 ms pulse from rest, plus a feedthrough during the pulse
    (with ``K3``: the cubic model's RK4 response)."""
    pulse = round(PULSE * fs / FS)
    n = round(0.5 * fs)
    t = np.arange(n) / fs
    u = np.zeros((1, n))
    u[0, 1:pulse + 1] = 40.0 * np.sin(np.pi * np.arange(1, pulse + 1) / (pulse + 1))
    z = np.zeros(3)
    traj = simulate_structural(M3, C3, K3M, K3, DECLARED, z, z, t, u)
    # the truncated modes' quasi-static share: proportional to the force, gone with it
    xdd = traj.xdd + np.outer([0.5, -1.0, 2.0], u[0])
    return Measurement(fs=fs, x=traj.x, xd=traj.xd, xdd=xdd, channels=("s1", "s2", "s3"),
                       u=u, inputs=("hammer",), input_map=DECLARED,
                       prior={"reduced_mass_trace": float(np.trace(M3))}, free_start=pulse + 2)


def _wrong_sharing() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The same ``M^-1 K``, ``M^-1 C`` and trace as the truth, other modal masses."""
    _, phi = linalg.eigh(K3M, M3)
    pinv = np.linalg.inv(phi)
    wrong = pinv.T @ np.diag([0.5, 1.0, 2.0]) @ pinv
    wrong *= np.trace(M3) / np.trace(wrong)
    return wrong, wrong @ np.linalg.solve(M3, C3), wrong @ np.linalg.solve(M3, K3M)


def test_free_decay_gain_is_the_kept_modes_gain():
    data = _record()
    Mf, Cf, Kf = _wrong_sharing()
    g = free_decay_gain(data, Mf, Cf, Kf, None, 0)
    want = np.linalg.solve(M3, DECLARED[:, 0])
    # the model's own exact response fits the decay exactly: rounding of the least squares
    # only (the feedthrough, 1.5-2x the pulse's own acceleration, lies before free_start)
    np.testing.assert_allclose(g, want, rtol=1e-7, atol=1e-7 * np.abs(want).max())


def test_free_decay_gain_takes_the_cubic_force_as_the_models():
    """A hardening mode's phase shifts with its amplitude; read with the linear part alone the
    gain is off by the cubic's share, with the model's cubic force (on the measured
    displacement) it is the kept modes' again."""
    K3 = np.diag([0.0, 0.0, 3e12])                   # cubic force 18 % of the linear at the peak
    data = _record(16000.0, K3)
    want = np.linalg.solve(M3, DECLARED[:, 0])
    err = [np.abs(free_decay_gain(data, M3, C3, K3M, k3, 0) - want).max() / np.abs(want).max()
           for k3 in (None, K3)]
    # measured 0.178 without the cubic force; with it 0.004: the cubic force enters as a
    # sample-held input, half a sample late against RK4's continuous one (0.016 at 4 kHz)
    assert err[0] > 0.1
    assert err[1] < 0.01


def test_cubic_model_shares_its_mass_by_the_free_decay():
    K3_true = np.diag([0.0, 0.0, 3e12])
    data = _record(16000.0, K3_true)
    Mf, Cf, Kf = _wrong_sharing()
    K3f = Mf @ np.linalg.solve(M3, K3_true)            # the same cubic acceleration M^-1 K3
    B_pulse = Mf @ np.array([[0.3], [-0.2], [1.4]])      # a gain the pulse's samples spoiled
    (M2, C2, K2, K32, B2), rule = driving_point_scaling(Mf, Cf, Kf, K3f, B_pulse, DECLARED, data)
    assert "free decay" in rule
    # the gain is read to 0.4 % (the sample-held cubic force, above); the modal masses follow
    for got, want in ((M2, M3), (K2, K3M), (C2, C3), (K32, K3_true)):
        np.testing.assert_allclose(got, want, rtol=0.02, atol=0.02 * np.abs(want).max())
    # the input map keeps the fitted gain M^-1 B (the scored simulation under the force's tail)
    np.testing.assert_allclose(np.linalg.solve(M2, B2), np.linalg.solve(Mf, B_pulse), rtol=1e-9)
    # without its record a cubic model keeps the prior's scale
    assert driving_point_scaling(Mf, Cf, Kf, K3f, B_pulse, DECLARED)[0][0] is Mf


def test_free_decay_gain_fits_every_inputs_response():
    """A second hammer (at sensor 1, before ``free_start``) rings in the same free decay; its
    response gets its own columns, so input 0's gain is read as with one hammer (review 28e
    M1: with input 0's columns alone it was 25 % off)."""
    fs = 16000.0
    n_t, pulse = 8000, 32
    t = np.arange(n_t) / fs
    shape = 40.0 * np.sin(np.pi * np.arange(1, pulse + 1) / (pulse + 1))
    u = np.zeros((2, n_t))
    u[0, 1:pulse + 1] = shape
    u[1, 60:60 + pulse] = 0.7 * shape
    D = np.array([[0.0, 1.0], [0.0, 0.0], [1.0, 0.0]])
    z = np.zeros(3)
    traj = simulate_structural(M3, C3, K3M, None, D, z, z, t, u)
    data = Measurement(fs=fs, x=traj.x, xd=traj.xd, xdd=traj.xdd, channels=("s1", "s2", "s3"),
                       u=u, inputs=("A", "B"), input_map=D,
                       prior={"reduced_mass_trace": float(np.trace(M3))}, free_start=60 + pulse + 2)
    Mf, Cf, Kf = _wrong_sharing()
    for j in (0, 1):
        want = np.linalg.solve(M3, D[:, j])
        g = free_decay_gain(data, Mf, Cf, Kf, None, j)
        # the model's exact response: least-squares rounding only
        np.testing.assert_allclose(g, want, rtol=1e-6, atol=1e-6 * np.abs(want).max())


def test_free_decay_gain_needs_a_free_decay():
    """``free_start`` 0 (a continuous input, or a window cut after the pulse) holds no free
    decay: no gain is read (review 28e L2), and a cubic model keeps the prior's scale."""
    data = _record(16000.0, np.diag([0.0, 0.0, 3e12]))
    data0 = dataclasses.replace(data, free_start=0)
    Mf, Cf, Kf = _wrong_sharing()
    K3f = Mf @ np.linalg.solve(M3, np.diag([0.0, 0.0, 3e12]))
    assert free_decay_gain(data0, Mf, Cf, Kf, K3f, 0) is None
    (M2, *_), rule = driving_point_scaling(Mf, Cf, Kf, K3f, Mf @ DECLARED, DECLARED, data0)
    assert M2 is Mf and "no free decay" in rule


def test_held_share_weights_a_reading_by_its_standard_error():
    """A reading with no spread is taken, one whose spread dwarfs it falls back to the fitted
    model's own modal mass (1), continuously in between (review 28e M2)."""
    a = np.array([0.5, 2.0, 0.3])
    np.testing.assert_allclose(held_share(a, np.zeros(3)), a, rtol=1e-15)
    np.testing.assert_allclose(held_share(a, 1e6 * np.ones(3)), np.ones(3), rtol=1e-9)
    # equal signal and error: halfway, w = 1/2
    np.testing.assert_allclose(held_share(a, np.abs(a)), 0.5 * a + 0.5, rtol=1e-12)
    path = [held_share(a[:1], np.array([s]))[0] for s in np.linspace(0.0, 5.0, 51)]
    assert np.all(np.diff(path) > 0)   # 0.5 rises monotonically towards 1 as the error grows


def test_free_decay_spread_follows_the_noise():
    """The gain's standard error is the least squares' (residual variance over the free
    samples): on the model's own response it is rounding, with white noise on the
    accelerations it scales with the noise."""
    data = _record()
    Mf, Cf, Kf = _wrong_sharing()
    _, phi = linalg.eigh(Kf, Mf)
    spreads = []
    for level in (0.0, 1e-3, 1e-2):
        rng = np.random.default_rng(3)
        xdd = data.xdd + level * data.xdd.std(axis=1, keepdims=True) * rng.standard_normal(data.xdd.shape)
        noisy = dataclasses.replace(data, xdd=xdd)
        _, cov = free_decay_fit(noisy, Mf, Cf, Kf, None, 0)
        spreads.append(modal_spread(phi, cov, phi[2]))
    assert np.all(spreads[0] < 1e-6)
    # tenfold noise, tenfold error (the same seed's draw scaled: exact up to the rounding)
    np.testing.assert_allclose(spreads[2], 10.0 * spreads[1], rtol=0.01)
    assert np.all(spreads[2] > 1e-5) and np.all(spreads[2] < 0.05)   # read, not lost


def test_a_model_whose_cubic_is_all_zero_is_shared_as_a_linear_one():
    """Review 28e L6: a cubic library whose every term was dropped (``K3`` all zero) has no
    cubic force; it is shared by ``B``'s gain as a linear model is (before, by the free decay),
    and gives back a zero ``K3``."""
    data = _record()
    Mf, Cf, Kf = _wrong_sharing()
    B = Mf @ np.linalg.solve(M3, DECLARED)  # the gain a linear fit would give (M^-1 B kept)
    lin, rule_lin = driving_point_scaling(Mf, Cf, Kf, None, B, DECLARED, data)
    zero, rule_zero = driving_point_scaling(Mf, Cf, Kf, np.zeros((3, 3)), B, DECLARED, data)
    assert rule_zero == rule_lin and "input gain" in rule_zero
    for a, b in zip(lin[:3] + lin[4:], zero[:3] + zero[4:], strict=True):
        np.testing.assert_array_equal(a, b)
    assert zero[3] is not None and not np.any(zero[3])


def test_a_correlated_residual_widens_the_spread_by_its_effective_sample_size():
    """Review 28e M2: the free decay's residual on a clean record is model error, smooth at
    the sample rate.  ``correlation_factor``: an AR(1) residual with ``rho`` 0.9 widens the
    variance by about ``(1 + rho) / (1 - rho)`` = 19; white noise by 1 (never under 1); a
    residual of one value per channel, or none, by its length and by 1."""
    rng = np.random.default_rng(7)
    e = rng.standard_normal((3, 20000))
    ar = np.zeros_like(e)
    for t in range(1, e.shape[1]):
        ar[:, t] = 0.9 * ar[:, t - 1] + e[:, t]
    # the sample lag-1 autocorrelation of 60,000 samples: within 0.01 of 0.9, so 19 within 2
    assert abs(correlation_factor(ar) - 19.0) <= 2.0
    assert 1.0 <= correlation_factor(e) <= 1.05  # white: rho within 0.01 of 0
    assert correlation_factor(np.ones((2, 50))) == 50.0
    assert correlation_factor(np.zeros((2, 50))) == 1.0
    assert correlation_factor(ar * (-1.0) ** np.arange(20000)) == 1.0  # alternating: rho < 0


def test_free_decay_fit_widens_its_covariance_by_the_residuals_correlation_factor(monkeypatch):
    """Review 29c L1: the gain's covariance is the least squares' times
    :func:`identify.structural.correlation_factor` of the fit's residual, one row a channel
    (the factor replaced by a spy: the gain does not move, the covariance scales by it)."""
    import identify.structural as structural
    data = _record()
    rng = np.random.default_rng(3)
    noisy = dataclasses.replace(
        data, xdd=data.xdd + 1e-2 * data.xdd.std(axis=1, keepdims=True) * rng.standard_normal(data.xdd.shape))
    Mf, Cf, Kf = _wrong_sharing()
    shapes: list[tuple[int, ...]] = []
    monkeypatch.setattr(structural, "correlation_factor", lambda r: shapes.append(r.shape) or 1.0)
    g1, cov1 = free_decay_fit(noisy, Mf, Cf, Kf, None, 0)
    monkeypatch.setattr(structural, "correlation_factor", lambda r: 7.0)
    g7, cov7 = free_decay_fit(noisy, Mf, Cf, Kf, None, 0)
    np.testing.assert_array_equal(g7, g1)
    np.testing.assert_allclose(cov7, 7.0 * cov1, rtol=1e-12)  # one multiplication's rounding
    assert len(shapes) == 1 and shapes[0][0] == 3 and shapes[0][1] > 100  # channels x samples
