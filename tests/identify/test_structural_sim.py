"""The compiled RK4 of cubic structural models against the Python loop it replaced (kept here
as the reference): the same trajectory to round-off; divergence raised with its time."""

import numpy as np
import pytest

from benchmarks.bench_structural import numpy_rk4
from identify import _structural_sim
from identify._structural_sim import simulate_structural
from testbed.core.errors import DivergenceError
from testbed.numerics import linear_response


def _python_rk4(M, C, K, K3, x0, xd0, t, f, max_omega_h=0.1):
    """The replaced implementation, verbatim in substance: RK4 with sub-steps, force held (the
    loop itself is the benchmark's peer, ``benchmarks.bench_structural.numpy_rk4``)."""
    n = M.shape[0]
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    dt = t[1] - t[0]
    sub = max(1, int(np.ceil(float(np.max(np.abs(np.linalg.eigvals(A)))) * dt / max_omega_h)))
    return numpy_rk4(A, Minv @ K3, Minv @ f, np.concatenate([x0, xd0]), dt / sub, sub, t.size)


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


def _linear_case():
    M, C, K, _ = _system()
    t = np.arange(3000) / 5000.0
    B = np.array([[1.0], [0.0], [0.5]])
    u = 50.0 * np.sin(2 * np.pi * 30 * t)[None, :]
    return M, C, K, B, t, u


def _fresh(*args):
    """simulate_structural with nothing kept from an earlier call."""
    linear_response._LAST.value = None
    return simulate_structural(*args)


@pytest.mark.parametrize("forced", [True, False])
def test_linear_kept_propagator_gives_the_same_numbers_as_a_fresh_one(forced):
    """The scorer simulates one model from many starts: what does not depend on the start is
    kept between calls, and the trajectories are the same bit for bit as computed afresh."""
    M, C, K, B, t, u = _linear_case()
    if not forced:
        B = u = None
    starts = [(np.array([1e-3, 0, -1e-3]), np.zeros(3)), (np.zeros(3), np.array([0.1, -0.2, 0.05])),
              (np.array([2e-4, 5e-4, 0.0]), np.array([0.0, 0.3, 0.0]))]
    fresh = [_fresh(M, C, K, None, B, x0, xd0, t, u) for x0, xd0 in starts]
    linear_response._LAST.value = None
    kept = [simulate_structural(M, C, K, None, B, x0, xd0, t, u) for x0, xd0 in starts]
    assert linear_response._LAST.value is not None  # the second and third calls reused it
    for a, b in zip(fresh, kept, strict=True):
        for f in ("x", "xd", "xdd"):
            assert np.array_equal(getattr(a, f), getattr(b, f))
    # the trajectories differ between starts (the kept part is not the whole answer)
    assert not np.array_equal(kept[0].x, kept[1].x)


@pytest.mark.parametrize("change", ["K", "u", "t", "B"])
def test_linear_kept_propagator_is_not_used_for_other_inputs(change):
    M, C, K, B, t, u = _linear_case()
    x0, xd0 = np.array([1e-3, 0, -1e-3]), np.zeros(3)
    simulate_structural(M, C, K, None, B, x0, xd0, t, u)  # keeps this model's propagator
    if change == "K":
        K = K * (1 + 1e-12)  # one part in 1e12: a different model all the same
    elif change == "u":
        u = u.copy()
        u[0, -1] += 1e-9
    elif change == "t":
        t, u = t[:-1], u[:, :-1]
    else:
        B = B * 2.0
    got = simulate_structural(M, C, K, None, B, x0, xd0, t, u)
    want = _fresh(M, C, K, None, B, x0, xd0, t, u)
    for f in ("x", "xd", "xdd"):
        assert np.array_equal(getattr(got, f), getattr(want, f))


def test_linear_matches_a_direct_zoh_recursion():
    """The modal propagation is the exact ZOH recursion z_k = Phi z_{k-1} + G w_{k-1}."""
    from scipy.linalg import expm

    M, C, K, B, t, u = _linear_case()
    n, dt = 3, t[1] - t[0]
    x0, xd0 = np.array([1e-3, 0, -1e-3]), np.zeros(3)
    tr = _fresh(M, C, K, None, B, x0, xd0, t, u)
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    Bz = np.vstack([np.zeros((n, n)), Minv])
    aug = np.zeros((3 * n, 3 * n))
    aug[:2 * n, :2 * n], aug[:2 * n, 2 * n:] = A, Bz
    E = expm(aug * dt)
    Z = np.empty((2 * n, t.size))
    Z[:, 0] = np.concatenate([x0, xd0])
    f = B @ u
    for k in range(1, t.size):
        Z[:, k] = E[:2 * n, :2 * n] @ Z[:, k - 1] + E[:2 * n, 2 * n:] @ f[:, k - 1]
    # eigenbasis vs direct products: rounding over 3000 steps, measured 1e-11 of the peak; 100x margin
    for got, want in ((tr.x, Z[:n]), (tr.xd, Z[n:])):
        assert np.abs(got - want).max() <= 1e-9 * np.abs(want).max()


def test_rk4_stability_bound_is_where_rk4_meets_the_negative_real_axis():
    """RK4_STABILITY_BOUND: one classical RK4 step amplifies ``z' = lambda z`` by
    ``R(z) = 1 + z + z^2/2 + z^3/6 + z^4/24`` (``z = lambda h``); |R| = 1 at z = -2.7853 (the
    bound is quoted to 4 digits: |R| within 1e-3 of 1 there, below 1 just inside, above 1
    just outside)."""
    def amplification(z):
        return abs(1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24)

    b = _structural_sim.RK4_STABILITY_BOUND
    # b = 2.785, 4 digits: |dR/dz| = 1.5 there, so a half unit of the 4th digit moves |R| by 7.5e-4
    assert abs(amplification(-b) - 1.0) < 1e-3
    assert amplification(-0.99 * b) < 1.0 < amplification(-1.01 * b)


def test_sample_rate_pole_is_the_fastest_pole_per_sample():
    """``max |lambda| dt`` over the poles of ``[[0, I], [-M^-1 K, -M^-1 C]]``: a single
    oscillator ``m = 2, c = 4, k = 800`` has poles ``-1 +- i sqrt(399)``, |lambda| = 20 rad/s;
    an overdamped one (c = 2000) a pole near -c/m = -1000 rad/s; inf for non-finite matrices."""
    one = np.array([[2.0]])
    # |lambda| = sqrt(1 + 399) = 20 rad/s exactly: to rounding
    assert _structural_sim.sample_rate_pole(one, 4 * one / 2, 800 * one / 2, 1e-3) == \
        pytest.approx(20.0e-3, rel=1e-12)
    assert _structural_sim.sample_rate_pole(one, 1000 * one, 400 * one, 1.0) == \
        pytest.approx(1000.0 - 0.4, rel=1e-3)  # the fast root of 2 s^2 + 2000 s + 800
    assert _structural_sim.sample_rate_pole(one, np.array([[np.inf]]), one, 1.0) == np.inf
    M, C, K, _ = _system()
    A = _structural_sim.state_matrix(M, C, K)
    n = M.shape[0]
    np.testing.assert_array_equal(A[:n, n:], np.eye(n))
    np.testing.assert_allclose(M @ A[n:, :n], -K, rtol=1e-12, atol=1e-9 * np.abs(K).max())


def test_cubic_model_with_an_unresolved_pole_is_not_simulated_beyond_the_budget():
    # round 5 (fuzz): a critically damped beam gave a cubic model with a pole at -1.4e9 rad/s;
    # its RK4 sub-steps (|lambda| dt / 0.1 per sample) made one simulation take hours.  Beyond
    # RK4's stability bound per sample and MAX_UNRESOLVED_RK4_STEPS it is refused with its
    # reason (scored "not simulated"), in no time; the same pole resolved by the record is not.
    from identify._structural_sim import MAX_UNRESOLVED_RK4_STEPS, RK4_STABILITY_BOUND
    from testbed.core.errors import UnresolvedModelError
    from testbed.scoring.scorers import simulate_scored

    fs, n_t = 12800.0, 6400
    t = np.arange(n_t) / fs
    M, K3 = np.eye(2), np.eye(2) * 1e9
    K = np.diag([1e5, 4e5])
    fast = 1.0e8  # [1/s]: an overdamped pole at about -C/M = -1e8 rad/s, |lambda| dt = 7.8e3
    C = np.diag([fast, 10.0])
    steps = np.ceil(fast / fs / 0.1) * n_t
    assert fast / fs > RK4_STABILITY_BOUND and steps > MAX_UNRESOLVED_RK4_STEPS
    with pytest.raises(UnresolvedModelError, match=r"pole of 1e\+08 rad/s .* needs 5e\+08 RK4"):
        simulate_structural(M, C, K, K3, None, np.full(2, 1e-4), np.zeros(2), t)
    traj, why, _ = simulate_scored(
        lambda: simulate_structural(M, C, K, K3, None, np.full(2, 1e-4), np.zeros(2), t),
        t, "xdd", np.zeros((2, n_t)))
    assert traj is None and why.startswith("not simulated: a cubic model whose linear part")
    # a pole the record resolves (|lambda| dt = 2.3 < 2.785) is simulated, finite
    C[0, 0] = 2.3 * fs
    ok = simulate_structural(M, C, K, K3, None, np.full(2, 1e-4), np.zeros(2), t[:200])
    assert np.all(np.isfinite(ok.xdd))
