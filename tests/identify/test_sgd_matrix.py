"""The cubic-term selection of SGD-SINDy's matrix parametrisation (identify/_sgd_matrix.py):
the warm start's lasso, on the partial-correlation scale, and the SGD's proximal step."""

import dataclasses
import functools

import numpy as np
import pytest

from benchmarks import bench_sgd_sindy as bench
from identify._sgd_matrix import (
    _sym,
    complex_stiffness_pair,
    cubic_profile,
    fit_matrix_sgd,
    lowest_peak_unpaired,
    unresolved_warm_start,
    warm_start,
)
from identify.sgd_sindy import SGDSINDy
from identify.structural import check_physical, mass_prior_value, modal, state_matrix

# One worker runs the module: each chain record below is integrated once (10 calls made 3
# records; 4-6 s each on a loaded 2-core machine).
pytestmark = pytest.mark.xdist_group("tests/identify/test_sgd_matrix.py")


@functools.cache
def _signals(k3):
    """The coupled chain's record and its signals, integrated once per process and ``k3``;
    read-only, so that no test can change what the next one reads."""
    d = bench.chain_measurement(bench.chain_system(coupled=True, k3=k3))
    sig = (d.xdd, d.xd, d.x, d.x**3)
    for a in sig:
        a.flags.writeable = False
    return d, sig


def _partial_corr(xdd, xd, x, x3):
    pr = cubic_profile(xdd, xd, x, x3)
    g = pr["Er"].T @ pr["Zr"] / xdd.shape[1]
    return g / np.outer(pr["rho"], pr["sigma"])


@pytest.mark.parametrize("k3", [0.0, 2.0e10, 2.0e12])
def test_lasso_keeps_a_row_empty_exactly_below_its_partial_correlation(k3):
    """Lasso optimality: a row's cubic block is zero iff every partial correlation of the row
    is at most the threshold.  Thresholds 1 % either side of the row's largest one."""
    _, sig = _signals(k3)
    corr = np.abs(_partial_corr(*sig))
    for row in range(3):
        top = corr[row].max()
        above = warm_start(*sig, m_hat=1.0, l1_threshold=1.01 * top)
        below = warm_start(*sig, m_hat=1.0, l1_threshold=0.99 * top)
        # K3 = M0 A3 mixes rows, so compare the uncoupled block A3 = M0^-1 K3 (the solve
        # leaves round-off, 1e-16 relative, where the lasso put exact zeros)
        a3_above = np.abs(np.linalg.solve(above[0], above[3])[row]).max()
        a3_below = np.abs(np.linalg.solve(below[0], below[3])[row]).max()
        assert a3_below > 0.0 and a3_above <= 1e-12 * a3_below


def test_partial_correlation_scale_is_free_of_units():
    """Rescaling the signals (other units, other amplitudes) changes no partial correlation."""
    _, (xdd, xd, x, x3) = _signals(2.0e12)
    c1 = _partial_corr(xdd, xd, x, x3)
    c2 = _partial_corr(7.0 * xdd, 7.0 * xd, 7.0 * x, 343.0 * x3)
    # correlations lie in [-1, 1] and do not depend on scale: the rescaled signals give them to
    # rounding
    assert np.allclose(c1, c2, atol=1e-9)


def test_sgd_holds_the_lasso_zero_pattern_and_debiases():
    """From the warm start, the SGD keeps rejected terms at zero, and with debiasing the kept
    term ends closer to least squares than with the lasso throughout."""
    data, _ = _signals(2.0e12)
    deb = SGDSINDy(epochs=40, cubic=True).fit(data)
    raw = SGDSINDy(epochs=40, cubic=True, l1_debias=0.0).fit(data)
    ls = SGDSINDy(epochs=40, cubic=True, l1="none").fit(data)
    assert np.all(deb.K3_[:, 1:] == 0.0) and np.all(raw.K3_[:, 1:] == 0.0)
    assert np.all(ls.K3_[:, 1:] != 0.0)  # least squares spreads onto every column
    want = np.linalg.solve(ls.M_, ls.K3_)[:, 0]
    err = [np.linalg.norm(np.linalg.solve(m.M_, m.K3_)[:, 0] - want) for m in (deb, raw)]
    assert err[0] < err[1]
    assert deb.history_["alpha_l1"][-1] == 0.0 and raw.history_["alpha_l1"][-1] > 0.0


@pytest.mark.parametrize("bad", [{"l1_threshold": -0.1}, {"l1_debias": 1.0}, {"l1_debias": -0.5}])
def test_bad_l1_settings_are_refused(bad):
    data, _ = _signals(0.0)
    with pytest.raises(ValueError, match=next(iter(bad))):
        SGDSINDy(epochs=1, cubic=True, **bad).fit(data)


def test_window_gradient_from_second_moments_is_exact():
    """The full-window loss and gradient from the 15 x 15 second-moment matrix (O(n^3) per
    step) equal the sample-by-sample sums over every sample."""
    from identify import _compiled as cc

    _, (xdd, xd, x, x3) = _signals(2.0e12)
    rng = np.random.default_rng(0)
    n = 3
    L = np.linalg.cholesky(np.eye(n) + 0.1 * np.ones((n, n)))
    P, Q, R = (rng.normal(size=(n, n)) for _ in range(3))
    sc3, s_a = rng.uniform(0.5, 2.0, size=(n, n)), rng.uniform(0.5, 2.0, size=n)
    Z = np.ascontiguousarray(np.vstack([xdd, xd, x, x3, np.zeros_like(x)]).T)
    scr = [np.empty((n, 5 * n)), np.empty((n, 5 * n)), np.empty(n)]
    g_win, g_all = np.empty((4, n, n)), np.empty((4, n, n))
    args = (L, P, Q, R, 0.2, 3.0, 4e4, sc3, s_a)
    lw = cc.window_loss_grad(Z.T @ Z, Z.shape[0], *args, *scr, *g_win)
    la = cc.batch_loss_grad(np.ascontiguousarray(Z[:, :4 * n]), *args, *scr, np.empty(n),
                            *g_all)
    # the parameters are far from the fit (random), so no cancellation: round-off only
    assert lw == pytest.approx(la, rel=1e-10)
    for a, b in zip(g_win, g_all, strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-12 * np.abs(b).max())


def test_full_window_gradient_option():
    """gradient="full": one exact step per epoch by default, deterministic, and fits the chain."""
    data, _ = _signals(0.0)
    a = SGDSINDy(epochs=200, gradient="full").fit(data)
    b = SGDSINDy(epochs=200, gradient="full").fit(data)
    assert a.n_steps_ == 200 and np.array_equal(a.K_, b.K_)
    assert np.all(np.isfinite(a.K_)) and np.allclose(np.trace(a.M_), np.trace(b.M_))
    with pytest.raises(ValueError, match="gradient"):
        SGDSINDy(epochs=1, gradient="exact").fit(data)


# --------------------------------------------------------------------------------------------
# Measured frequencies held (eigen_targets, hold_eigenvalues); force and drift profiled out
# --------------------------------------------------------------------------------------------
def _pencil(seed=0, n=3):
    """A coupled (M, K) whose generalised eigenvalues are 1e4 x (1, 9, 25): modes a factor
    3-5 apart in frequency, like a beam's."""
    rng = np.random.default_rng(seed)
    A = rng.normal(size=(n, n))
    M = A @ A.T + n * np.eye(n)
    V = np.linalg.qr(rng.normal(size=(n, n)))[0]
    C = np.linalg.cholesky(M)
    K = C @ (V * (1e4 * np.array([1.0, 9.0, 25.0])[:n])) @ V.T @ C.T
    return M, _sym(K)


def test_hold_moves_the_targeted_eigenvalues_exactly_and_keeps_the_modes():
    from scipy import linalg

    from identify._sgd_matrix import hold_eigenvalues

    M, K = _pencil()
    lam, U = linalg.eigh(K, M)
    target = np.array([0.0, 1.05 * lam[1], 0.97 * lam[2]])  # mode 1 left alone
    L, P = np.linalg.cholesky(M / 2.0), K / 3.0  # M = m0 L L^T with m0 = 2, K = k0 P, k0 = 3
    shift = hold_eigenvalues(L, P, 2.0, 3.0, target)
    lam2, U2 = linalg.eigh(3.0 * P, M)
    # eigh's relative accuracy on a 3 x 3 pencil (cond ~ 10): 1e-12 is 1e3 x the rounding
    assert np.allclose(lam2, [lam[0], target[1], target[2]], rtol=1e-12)
    assert np.allclose(np.abs(np.sum(U2 * (M @ U), axis=0)), 1.0, atol=1e-10)  # same modes
    assert np.isclose(shift, np.sqrt(1.05) - 1.0, rtol=1e-9)
    assert np.allclose(P, P.T)


def test_targets_pair_only_near_peaks_and_in_mode_order():
    from scipy import linalg

    from identify._sgd_matrix import eigen_targets

    M, K = _pencil(1)
    lam = linalg.eigh(K, M, eigvals_only=True)
    # a spurious low peak (far from every mode), modes 1 and 3 seen 3 % off, mode 2 missing
    hat = np.array([0.01 * lam[0], 1.03**2 * lam[0], 0.97**2 * lam[2]])
    t = eigen_targets(M, K, hat)
    assert np.allclose(t, [hat[1], 0.0, hat[2]])
    # a peak 20 % off every mode (beyond MODE_SEPARATION, 15 %) is not a target
    assert np.all(eigen_targets(M, K, np.array([1.2**2 * lam[1]])) == 0.0)


def test_drift_columns_do_not_change_the_fit_when_profiled_out():
    """Adding the chain's drift waveforms to x, x' with unknown offsets, and declaring them as
    drift_basis, leaves the identified model as without them (Frisch-Waugh-Lovell)."""
    import dataclasses

    data = bench.chain_measurement(bench.chain_system(coupled=True))
    t = np.arange(data.n_samples) / data.fs
    w0, w1 = np.exp(-3.0 * t), t * np.exp(-3.0 * t)  # smooth, independent of the motion
    e = np.array([1e-4, -2e-4, 5e-5])  # velocity offsets [m/s]
    drifted = dataclasses.replace(data, xd=data.xd + e[:, None] * w0, x=data.x + e[:, None] * w1,
                                  drift_basis=np.vstack([w0, w1]))
    clean_basis = dataclasses.replace(data, drift_basis=np.vstack([w0, w1]))
    # decay_hold=False: the offsets' coefficients belong to the fit's C and K (drift_coef_),
    # which the decay hold then changes; this checks the fit's projection
    a = SGDSINDy(epochs=4, decay_hold=False).fit(drifted)
    b = SGDSINDy(epochs=4, decay_hold=False).fit(clean_basis)
    # the two fits see the same projected signals up to the offsets' round-off (1e-4 m/s
    # beside ~1e-2 m/s motion, projected out to ~1e-12 relative)
    assert np.allclose(a.natural_frequencies_, b.natural_frequencies_, rtol=1e-7)
    assert np.allclose(a.drift_coef_[:, 0], b.drift_coef_[:, 0] + a.C_ @ e, rtol=1e-5, atol=1e-9)
    assert np.allclose(a.drift_coef_[:, 1], b.drift_coef_[:, 1] + a.K_ @ e, rtol=1e-5)


def _assert_same(a, b, path="result"):
    """Every field of two results (dataclasses, dicts, arrays, numbers) equal bit for bit."""
    if dataclasses.is_dataclass(a):
        for f in dataclasses.fields(a):
            if f.name != "warm":
                _assert_same(getattr(a, f.name), getattr(b, f.name), f"{path}.{f.name}")
    elif isinstance(a, dict):
        assert a.keys() == b.keys(), path
        for k in a:
            _assert_same(a[k], b[k], f"{path}[{k!r}]")
    elif isinstance(a, np.ndarray):
        assert a.shape == b.shape and np.array_equal(a, b, equal_nan=True), path
    else:
        assert a == b or (a != a and b != b), (path, a, b)


@pytest.mark.parametrize("k3, cubic", [(0.0, False), (2.0e12, True)])
def test_the_held_warm_start_comes_with_the_fit(k3, cubic):
    """``with_warm`` returns, besides the SGD's result, the held warm start the SGD started
    from: bit for bit the result ``epochs = 0`` gives (not fitted a second time), hold and
    projections included; the SGD's result is unchanged by asking for it."""
    data, _ = _signals(k3)
    model = SGDSINDy(epochs=5, cubic=cubic)
    lam_hat, peaks = model._start_fit(data)
    m_hat = mass_prior_value(data, model.mass_prior)
    est = model.settings()
    out = fit_matrix_sgd(data, est, m_hat, lam_hat, peaks=peaks, with_warm=True)
    assert out.warm is not None and out.warm.n_steps == 0 and out.n_steps > 0
    _assert_same(out.warm, fit_matrix_sgd(data, dataclasses.replace(est, epochs=0), m_hat,
                                          lam_hat, peaks=peaks), "warm")
    _assert_same(out, fit_matrix_sgd(data, est, m_hat, lam_hat, peaks=peaks), "sgd")
    assert fit_matrix_sgd(data, est, m_hat, lam_hat, peaks=peaks).warm is None
    assert fit_matrix_sgd(data, dataclasses.replace(est, epochs=0), m_hat, lam_hat,
                          peaks=peaks, with_warm=True).warm is None  # nothing to compare


def test_an_epoch_that_leaves_a_non_finite_iterate_stops_the_epochs(monkeypatch):
    """Round 12's ``b12_tip_cluster_L1`` (sensors within 0.15 m of a 1 m beam's tip): the mass
    matrix's factor lost rank, an epoch's steps turned the iterate NaN, and the K projection's
    eigensolver raised ("numerical breakdown", no model) while the held warm start passes
    (TRAC 0.999).  Now the epochs stop and the result is the last finite epoch's iterate
    (``BREAKDOWN_RULE``); the breakdown is forced here at epoch 3 (the old code raised
    LinAlgError)."""
    from identify import _compiled
    from identify._sgd_matrix import BREAKDOWN_RULE

    data, _ = _signals(0.0)
    model = SGDSINDy(epochs=5)
    lam_hat, peaks = model._start_fit(data)
    m_hat = mass_prior_value(data, model.mass_prior)
    est = model.settings()
    assert fit_matrix_sgd(data, est, m_hat, lam_hat, peaks=peaks).stop_rule == ""
    steps, calls = _compiled.sgd_steps, []

    def breaking_steps(Z, nfa, S, Nz, perm, bs, spe, params, *rest):
        steps(Z, nfa, S, Nz, perm, bs, spe, params, *rest)
        calls.append(spe)
        if len(calls) == 3:
            params[1][...] = np.nan  # P, the stiffness factor

    monkeypatch.setattr(_compiled, "sgd_steps", breaking_steps)
    out = fit_matrix_sgd(data, est, m_hat, lam_hat, peaks=peaks, with_warm=True)
    assert out.stop_rule == BREAKDOWN_RULE.format(epoch=3, last=2)
    assert out.n_steps == 2 * calls[0] and len(out.history["epoch"]) == 3  # epochs 0-2
    assert all(np.isfinite(a).all() for a in (out.M, out.C, out.K))
    assert out.warm is not None and out.warm.stop_rule == ""


def test_the_identifier_states_why_its_epochs_stopped(monkeypatch):
    """``sgd_sindy`` keeps what stopped the SGD on the fitted model, whichever of the SGD's
    result and the held warm start it keeps (``sgd_stop_rule_``)."""
    from identify import _compiled
    from identify._sgd_matrix import BREAKDOWN_RULE

    data, _ = _signals(0.0)
    assert SGDSINDy(epochs=5).fit(data).sgd_stop_rule_ == "every epoch ran"
    steps, calls = _compiled.sgd_steps, []

    def breaking_steps(Z, nfa, S, Nz, perm, bs, spe, params, *rest):
        steps(Z, nfa, S, Nz, perm, bs, spe, params, *rest)
        calls.append(spe)
        if len(calls) == 3:
            params[1][...] = np.nan

    monkeypatch.setattr(_compiled, "sgd_steps", breaking_steps)
    model = SGDSINDy(epochs=5).fit(data)
    assert model.sgd_stop_rule_ == BREAKDOWN_RULE.format(epoch=3, last=2)
    assert np.isfinite(model.K_).all()


def test_a_breakdown_inside_the_iterate_averaging_names_the_averaged_epochs(monkeypatch):
    """With the iterate averaging on (the last quarter of 8 epochs: from epoch 7), a breakdown
    at epoch 8 leaves the average of epoch 7's iterate alone, and the rule says so."""
    import dataclasses

    from identify import _compiled
    from identify._sgd_matrix import BREAKDOWN_AVERAGED_RULE

    data, _ = _signals(0.0)
    model = SGDSINDy(epochs=8)
    lam_hat, peaks = model._start_fit(data)
    m_hat = mass_prior_value(data, model.mass_prior)
    est = dataclasses.replace(model.settings(), iterate_average=0.25)
    steps, calls = _compiled.sgd_steps, []

    def breaking_steps(Z, nfa, S, Nz, perm, bs, spe, params, *rest):
        steps(Z, nfa, S, Nz, perm, bs, spe, params, *rest)
        calls.append(spe)
        if len(calls) == 8:
            params[1][...] = np.nan

    monkeypatch.setattr(_compiled, "sgd_steps", breaking_steps)
    out = fit_matrix_sgd(data, est, m_hat, lam_hat, peaks=peaks)
    assert out.stop_rule == BREAKDOWN_AVERAGED_RULE.format(epoch=8, first=7, last=7)
    assert all(np.isfinite(a).all() for a in (out.M, out.C, out.K))


def _uncoupled_signals(A: np.ndarray, B: np.ndarray, n_samples: int = 400, seed: int = 0):
    """Signals on which the uncoupled regression is exactly ``x'' = -B x' - A x``: random
    ``x``, ``x'`` (unit RMS) and ``x''`` from them."""
    rng = np.random.default_rng(seed)
    xd, x = rng.standard_normal((2, A.shape[0], n_samples))
    return -B @ xd - A @ x, xd, x


def test_the_unresolved_warm_start_places_the_mode_and_keeps_each_modes_damping():
    """``A = M^-1 K`` with modes at 100 and 500 Hz and one fitted with a negative stiffness
    (its real pole 3000 Hz x 2 pi beyond the 2000 Hz top), ``B = M^-1 C`` with modal damping
    and a non-symmetric coupling: the warm start is symmetric, physical, with ``trace(M)``
    the prior, modes 100 / 500 / 2000 Hz (to rounding), the resolved modes' own damping
    kept and the placed one damped to 1/sqrt(2); with every mode resolved, None."""
    rng = np.random.default_rng(7)
    Phi = np.linalg.qr(rng.standard_normal((3, 3)))[0] + 0.3 * np.eye(3)
    Pinv = np.linalg.inv(Phi)
    w = 2 * np.pi * np.array([100.0, 500.0])
    A = Phi @ np.diag([-(2 * np.pi * 3000.0) ** 2, *w**2]) @ Pinv
    D = np.diag([50.0, 2 * 0.01 * w[0], 2 * 0.05 * w[1]])
    D[1, 2] = 40.0  # a coupling no symmetric damping with equal modal masses holds
    B = Phi @ D @ Pinv
    sig = _uncoupled_signals(A, B)
    M0, C0, K0, rule = unresolved_warm_start(*sig, 0.3, 2000.0, np.array([100.0, 500.0]))
    assert "1 mode(s)" in rule and "negative stiffness" in rule
    for X in (M0, C0, K0):
        np.testing.assert_allclose(X, X.T, atol=0.0)
    assert np.trace(M0) == pytest.approx(0.3, rel=1e-12)
    check_physical(M0, C0, K0)
    np.testing.assert_allclose(modal(M0, K0)[0], [100.0, 500.0, 2000.0], rtol=1e-8)
    poles = np.linalg.eigvals(state_matrix(M0, C0, K0))
    low = poles[(poles.imag > 0) & (np.abs(poles) < 2 * np.pi * 1000.0)]
    low = low[np.argsort(low.imag)]
    # the resolved modes' own damping (the coupling dropped): -zeta w, to rounding
    np.testing.assert_allclose(-low.real, [0.01 * w[0], 0.05 * w[1]], rtol=1e-6)
    top = poles[np.abs(poles) > 2 * np.pi * 1000.0]
    # damped to 1/sqrt(2) (identify._unresolved.UNRESOLVED_ZETA): a simple complex pair
    wt = 2 * np.pi * 2000.0
    np.testing.assert_allclose(top.real, -wt * 2**-0.5, rtol=1e-8)
    np.testing.assert_allclose(np.sort(top.imag), [-wt * 2**-0.5, wt * 2**-0.5], rtol=1e-8)
    assert unresolved_warm_start(*sig, 0.3, 4000.0, np.array([100.0, 500.0])) is None


def test_an_uncoupled_stiffness_with_a_complex_pair_places_no_mode_and_says_why():
    """``A = M^-1 K`` with a real mode at 100 Hz and two modes coalesced into a complex pair
    (eigenvalues (2 pi 530)^2 +- (2 pi 120)^2 j: round 20's ``b20_st_hit0p1`` at 3 %, s113,
    fitted modes 2-3 as 532.5 +- 11.7j Hz) and one negative stiffness beyond the 2000 Hz
    top: the real parts of the pair's shapes are one vector, so no mode can be placed.  The
    old code solved with that singular shape matrix (``identify._unresolved
    .stiffness_eigenvalues``): on the cell's ``A`` LAPACK's LU met an exact zero pivot
    ("LinAlgError: Singular matrix", the cell's "numerical breakdown", test_sgd_cantilever),
    on this one rounding left a tiny pivot and eigenvalues of +-2.4e22 (None, no reason
    stated): which of the two depends on rounding.  Now the placement states why it does
    not act, before any solve, and a real ``A`` gives ""."""
    rng = np.random.default_rng(3)
    V = np.linalg.qr(rng.standard_normal((4, 4)))[0] + 0.3 * np.eye(4)
    a, b = (2 * np.pi * 530.0) ** 2, (2 * np.pi * 120.0) ** 2
    blocks = np.zeros((4, 4))
    blocks[0, 0] = (2 * np.pi * 100.0) ** 2
    blocks[1:3, 1:3] = [[a, b], [-b, a]]  # the real form of a +- b j
    blocks[3, 3] = -(2 * np.pi * 3000.0) ** 2
    A = V @ blocks @ np.linalg.inv(V)
    B = V @ np.diag([5.0, 60.0, 60.0, 50.0]) @ np.linalg.inv(V)
    why = complex_stiffness_pair(A)
    assert why.startswith("none placed") and "complex eigenvalue pair" in why
    sig = _uncoupled_signals(A, B)
    placed = unresolved_warm_start(*sig, 0.3, 2000.0, np.array([100.0, 530.0]))
    assert isinstance(placed, str) and "complex eigenvalue pair" in placed
    real = V @ np.diag(np.diag(blocks) * [1, 1, 1.5, 1]) @ np.linalg.inv(V)
    assert complex_stiffness_pair(real) == ""


def test_a_warm_start_that_misses_the_lowest_peak_is_named_and_one_that_carries_it_is_not():
    """Modes at 40 and 390 Hz (``M = I``, ``K = diag(w^2)``) carry peaks at 39.8 / 389.5 Hz
    (within 15 %); modes at 81.8 / 283.5 Hz (round 20's ``b20_soft_r1p2_cf0p3_root2`` at 1 %:
    the projected tilted warm start) miss the lowest, named; modes at 40 / 283.5 Hz miss only
    the highest (a heavily damped mode the SGD puts right): not named; no peak, nothing to
    contradict."""
    def k(*f):
        return np.diag((2 * np.pi * np.asarray(f)) ** 2)

    lam_hat = (2 * np.pi * np.array([39.8, 389.5])) ** 2
    assert lowest_peak_unpaired(np.eye(2), k(40.0, 390.0), lam_hat) == ""
    why = lowest_peak_unpaired(np.eye(2), k(81.76, 283.5), lam_hat)
    assert "lowest measured peak 39.8 Hz" in why and "its stiffness, not its damping" in why
    assert lowest_peak_unpaired(np.eye(2), k(40.0, 283.5), lam_hat) == ""
    assert lowest_peak_unpaired(np.eye(2), k(81.76, 283.5), np.empty(0)) == ""


def test_near_coalesced_modes_are_decided_on_the_shapes_the_placement_uses():
    """Two modes near coalescence (a Jordan-like block ``a, 1e-3 a; 0, a`` at 530 Hz) split
    into a real or a complex pair by rounding, differently in LAPACK's standard and
    generalised solvers; decided by the standard one, 9 of 300 such warm starts passed the
    check and the placement's solve with the generalised solver's parallel shapes raised
    "Singular matrix" (session 22's review).  Now the shapes the placement uses decide
    (:data:`identify.structural.SHAPES_COND_MAX`): none raises, and a repeated eigenvalue
    with independent shapes (no coalescence; named a complex pair on 48 of 300 before) is no
    reason at all."""
    a = (2 * np.pi * 530.0) ** 2
    raised = 0
    for seed in range(300):
        rng = np.random.default_rng(seed)
        V = np.linalg.qr(rng.standard_normal((4, 4)))[0] + 0.3 * np.eye(4)
        J = np.diag([(2 * np.pi * 100.0) ** 2, a, a, -(2 * np.pi * 3000.0) ** 2])
        J[1, 2] = 1e-3 * a
        A = V @ J @ np.linalg.inv(V)
        B = V @ np.diag([5.0, 60.0, 60.0, 50.0]) @ np.linalg.inv(V)
        xd, x = rng.standard_normal((2, 4, 400))
        try:
            unresolved_warm_start(-B @ xd - A @ x, xd, x, 0.3, 2000.0, np.array([100.0, 530.0]))
        except np.linalg.LinAlgError:
            raised += 1
        W = rng.standard_normal((4, 4))
        repeated = W @ np.diag(np.diag(J)) @ np.linalg.inv(W)
        assert complex_stiffness_pair(repeated) == "", seed
    assert raised == 0


def test_a_growing_pole_is_a_located_mode_only_where_a_measured_peak_locates_it():
    """``growing_mode_located``: the fastest-growing pole, oscillating, within MODE_SEPARATION
    of a measured peak (the record holds that mode's ringing); a real growing pole, one at no
    peak, a stable model or no peak at all is not."""
    from identify._sgd_matrix import growing_mode_located

    M, K = np.diag([1.0, 1.0]), np.diag([(2 * np.pi * 50.0) ** 2, (2 * np.pi * 400.0) ** 2])
    grows_1 = np.diag([-2.0, 10.0])  # mode 1 (50 Hz) grows at +1 1/s, mode 2 decays
    peaks = (2 * np.pi * np.array([52.0, 405.0])) ** 2  # mode 1 4 % from its peak
    assert growing_mode_located(M, grows_1, K, peaks)
    assert not growing_mode_located(M, grows_1, K, (2 * np.pi * np.array([405.0])) ** 2)
    assert not growing_mode_located(M, grows_1, K, np.empty(0))
    assert not growing_mode_located(M, np.diag([2.0, 10.0]), K, peaks)  # stable: grows nowhere
    # a negative stiffness: a real growing pole, no ringing mode
    assert not growing_mode_located(M, np.diag([2.0, 10.0]), np.diag([-100.0, K[1, 1]]), peaks)
