"""The compiled SINDy-PI sweep (identify._pi_kernels) against an obviously correct reference.

The reference below runs sequentially thresholded least squares one candidate at a time and
solves every refit afresh with ``np.linalg.solve(Gn[S, S] + ridge I, Gn[S, j])``.  The compiled
paths (one factor downdated by Givens rotations per candidate; a fresh Cholesky per refit) do
the same arithmetic in another order, so they agree up to round-off times the condition number.

Comparison rule (documented here, used by every test): supports are compared exactly only for
models that are *not tie-decided* -- every coefficient the reference thresholded on the model's
path is farther than ``MARGIN`` (relative) from the threshold -- on problems whose normalised
Gram matrix is *well-conditioned* (cond <= 1e6; every support's block is then at least as well
conditioned, by eigenvalue interlacing).  Coefficients are compared to the forward-error bound
of a backward-stable solve, ``FWD * cond``.  On exact data (rank-deficient supports, paths
decided by round-off) only the selected equations are compared.
"""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks import sindy_pi_problems as P
from identify._implicit import (
    DEFAULT_THRESHOLDS,
    grams,
    select_models,
    split_index,
    stlsq_sweep,
)
from identify._pi_kernels import stlsq_chains, stlsq_chains_downdate
from identify.library import Library, generic_mechanical_library

#: A coefficient within 1e-6 (relative) of its threshold may fall either side under a relative
#: perturbation of cond * eps <= 1e6 * 1.1e-16 ~ 1e-10 times a modest growth factor: 1e-6 leaves
#: four orders of headroom, and such models are left out of the exact support comparison.
MARGIN = 1e-6
#: Forward error of a backward-stable solve of size p <= 40 relative to the largest
#: coefficient: ~ p * eps * cond; 1e3 * eps covers p * (a growth factor of 10) with room.
FWD = 1e3 * np.finfo(float).eps


def reference_sweep(Gn, cand, thr, ridge=1e-14, max_iter=20):
    """Models (T, C, p) and, per model, the smallest relative distance of a thresholded
    coefficient to its threshold on the model's path (inf if none was thresholded)."""
    p = Gn.shape[0]
    models = np.zeros((len(thr), len(cand), p))
    margin = np.full((len(thr), len(cand)), np.inf)
    B = np.linalg.inv(Gn + ridge * np.eye(p))
    for c, j in enumerate(cand):
        base = np.ones(p, dtype=bool)
        base[j] = False
        x = np.where(base, -B[:, j] / B[j, j], 0.0)
        mask = base.copy()
        path_margin = np.inf
        for t, lam in enumerate(thr):
            for _ in range(max_iter):
                if lam > 0:
                    near = np.abs(np.abs(x[mask]) - lam) / lam
                    path_margin = min(path_margin, near.min(initial=np.inf))
                new = base & (np.abs(x) >= lam)
                if np.array_equal(new, mask):
                    break
                mask = new
                S = np.flatnonzero(mask)
                x = np.zeros(p)
                if S.size:
                    x[S] = np.linalg.solve(Gn[np.ix_(S, S)] + ridge * np.eye(S.size), Gn[S, j])
            models[t, c] = x
            margin[t, c] = path_margin
    return models, margin


def planted_problem(seed, n=3000, p=30, noise=0.05):
    """Random library columns with three planted sparse linear relations plus noise (so the
    Gram matrix is well-conditioned: noise 0.05 puts its smallest eigenvalue near 2.5e-3)."""
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(n, p)) * rng.uniform(0.1, 10.0, p)
    for k, (a, b) in enumerate(((3, 7), (11, 20), (5, 25))):
        X[:, k] = 0.8 * X[:, a] - 0.3 * X[:, b] + noise * np.abs(X[:, a]).mean() * rng.normal(size=n)
    return X


def _relative(new, ref):
    """|new - ref| relative to the largest |ref| of the model (absolute for an empty model,
    whose reference is all zero)."""
    scale = np.abs(ref).max(axis=-1, keepdims=True)
    return np.abs(new - ref) / np.where(scale > 0, scale, 1.0)


def _normalised(Theta):
    n_tr = split_index(Theta.shape[0], 0.2)
    G, Gv = grams(Theta, n_tr)
    s = np.sqrt(np.diag(G))
    return G, Gv, G / np.outer(s, s)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_compiled_sweep_matches_reference_on_well_conditioned_problems(seed):
    Theta = planted_problem(seed)
    G, Gv, Gn = _normalised(Theta)
    cond = np.linalg.cond(Gn)
    assert cond <= 1e6, cond  # the rule's precondition: the problem is well-conditioned
    cand = np.arange(Gn.shape[0])
    thr = DEFAULT_THRESHOLDS
    ref, margin = reference_sweep(Gn, cand, thr)
    sw = stlsq_sweep(G, Gv, cand, thr)
    new = -sw.W
    new[:, np.arange(cand.size), cand] = 0.0
    compared = margin > MARGIN
    assert compared.mean() > 0.9  # the rule leaves most models in: the test is not vacuous
    np.testing.assert_array_equal((new != 0)[compared], (ref != 0)[compared])
    err = _relative(new, ref)[compared]
    assert np.all(np.isfinite(err)) and err.max() <= FWD * cond, err.max()
    # the thresholds really prune: each planted left-hand side reaches its 3-term equation
    for c, (a, b) in enumerate(((3, 7), (11, 20), (5, 25))):
        supports = {tuple(np.flatnonzero(w)) for w in sw.W[:, c]}
        assert (c, a, b) in supports


def _kernel_inputs(Gn):
    """A well-conditioned normalised Gram matrix's condition number and kernel inputs: every
    column a candidate,
    the reference sweep and its margin, the base masks and the ridge-free starting models."""
    cond = np.linalg.cond(Gn)
    assert cond <= 1e6, cond
    p = Gn.shape[0]
    cand = np.arange(p)
    ref, margin = reference_sweep(Gn, cand, DEFAULT_THRESHOLDS)
    B = np.linalg.inv(Gn + 1e-14 * np.eye(p))
    base = ~np.eye(p, dtype=bool)
    xi = np.where(base, -(B[:, cand] / B[cand, cand]).T, 0.0)
    return cond, p, cand, ref, margin, base, xi


@pytest.mark.parametrize("seed", [0, 3])
def test_fresh_cholesky_kernel_matches_reference(seed):
    """The fallback kernel (a new Cholesky, else LU, per refit) under the same rule."""
    Gn = _normalised(planted_problem(seed))[2]
    cond, p, cand, ref, margin, base, xi = _kernel_inputs(Gn)
    for kernel in ("fresh", "downdate"):
        if kernel == "fresh":
            models, status, refits = stlsq_chains(Gn, cand, base, xi, DEFAULT_THRESHOLDS, 1e-14, 20)
        else:
            models, status, refits = stlsq_chains_downdate(Gn, cand, np.ones(p, dtype=bool), base,
                                                           xi, DEFAULT_THRESHOLDS, 1e-14, 20)
        assert (status == 0).all() and refits.sum() > p
        ok = margin > MARGIN
        assert ok.mean() > 0.9
        np.testing.assert_array_equal((models != 0)[ok], (ref != 0)[ok])
        err = _relative(models, ref)[ok]
        assert err.max() <= FWD * cond, (kernel, err.max())


def test_downdate_kernel_declines_a_singular_gram_matrix():
    """An exactly dependent column (zero pivot) without ridge: the shared factor does not
    exist, every candidate is flagged for the fresh-refit path, and the sweep still matches
    the reference on the candidates that path can fit."""
    rng = np.random.default_rng(5)
    X = rng.normal(size=(500, 6))
    X[:, 5] = X[:, 4]
    G = X.T @ X
    Gn = G / np.outer(np.sqrt(np.diag(G)), np.sqrt(np.diag(G)))
    p = 6
    base = ~np.eye(p, dtype=bool)
    xi = np.zeros((p, p))
    _, status, _ = stlsq_chains_downdate(Gn, np.arange(p), np.ones(p, dtype=bool), base, xi,
                                         np.array([0.1]), 0.0, 20)
    assert (status == 2).all()


def test_exact_double_pendulum_selects_the_reference_equations():
    """Exact data: supports along the path are rank-deficient (round-off decides them), so
    only the selected equations are compared -- support exactly, coefficients to 1e-12 of the
    largest (both are the exact equation, fitted on a support that holds it and nothing else,
    where the fit is well-conditioned)."""
    pr = P.double_pendulum(duration=5.0, fs=1e3, amp=10.0)
    d = pr.data
    full = generic_mechanical_library(2, 2).names
    lib = Library(pr.truth_terms + [n for n in full if n not in pr.truth_terms][:18], 2, 2)
    Theta = lib.evaluate(d.x, d.xd, d.xdd, d.u)
    G, Gv, Gn = _normalised(Theta)
    cand = np.arange(len(lib))
    sw = stlsq_sweep(G, Gv, cand, DEFAULT_THRESHOLDS)
    ref, _ = reference_sweep(Gn, cand, DEFAULT_THRESHOLDS)
    sw_ref = stlsq_sweep(G, Gv, cand, DEFAULT_THRESHOLDS)
    W = -ref
    W[:, np.arange(cand.size), cand] = 1.0
    sw_ref.W = W
    from identify._implicit import _errors
    sw_ref.val_error = _errors(W, Gv / np.outer(sw.scale, sw.scale), cand)
    sw_ref.nnz = np.count_nonzero(W, axis=2)
    inputs = [lib.input_columns(k) for k in range(2)]
    for a, b in zip(select_models(sw, inputs), select_models(sw_ref, inputs), strict=True):
        wa, wb = sw.W[a[0]], sw_ref.W[b[0]]
        np.testing.assert_array_equal(wa != 0, wb != 0)
        # 1e-12: the selected support holds one exact equation and is well-conditioned
        assert np.abs(sw.coef(*a[0]) - sw_ref.coef(*b[0])).max() <= 1e-12
    f1, _ = P.aligned_errors(lib.names, np.array([sw.coef(*q[0]) for q in select_models(sw, inputs)]),
                             pr.truth_terms, pr.truth_coef)
    assert f1 == 1.0


def test_downdate_kernel_matches_reference_on_a_larger_random_problem():
    """The row-stored downdating kernel on 60 columns (long paths: many refits leave gaps in
    its storage, some close them up) against the masked least-squares reference, under the
    module's rule.  FWD still covers p = 60: p * (growth 10) = 600 < 1e3."""
    Gn = _normalised(planted_problem(7, n=4000, p=60))[2]
    cond, p, cand, ref, margin, base, xi = _kernel_inputs(Gn)
    models, status, refits = stlsq_chains_downdate(Gn, cand, np.ones(p, dtype=bool), base, xi,
                                                   DEFAULT_THRESHOLDS, 1e-14, 20)
    assert (status == 0).all() and refits.sum() > 3 * p
    ok = margin > MARGIN
    assert ok.mean() > 0.9
    np.testing.assert_array_equal((models != 0)[ok], (ref != 0)[ok])
    err = _relative(models, ref)[ok]
    assert err.max() <= FWD * cond, err.max()


def test_retriangularise_keeps_the_normal_equations_with_and_without_gaps():
    """Deleting columns from a row-stored factor in steps: after each step the kept columns'
    factor reproduces their Gram block and right-hand side, ``R_S^T R_S = G[S, S]`` and
    ``R_S^T z = G[S, j]``.  A small deletion leaves gaps in the storage, a large one closes
    them up (both paths run).

    Tolerance 1e-12 of max |G|: every entry meets at most n = 40 rotations (a few eps each)
    and each product sums 40 terms, so the error is ~ (6 + 1) * 40 * eps ~ 3e-14 of the
    largest entry; 1e-12 leaves 30x headroom and still catches any misplaced entry (O(1)).
    """
    from identify._pi_kernels import _retriangularise

    rng = np.random.default_rng(11)
    n = 40
    X = rng.normal(size=(400, n + 1))
    G = X.T @ X
    R0 = np.linalg.cholesky(G).T  # upper; column n is the right-hand side
    R = np.zeros((n, n))
    R[:, :] = np.triu(R0[:n, :n])
    z = R0[:n, n].copy()
    cols = np.arange(n)
    P = np.arange(n)
    pos = np.empty(n, dtype=np.int64)
    live = np.arange(n)
    m = n
    for step, n_del in enumerate((2, 15, 1, 6)):
        keep = np.ones(m, dtype=bool)
        keep[rng.choice(m, n_del, replace=False)] = False
        live = live[keep]
        m = _retriangularise(R, cols, P, m, keep, z, pos)
        assert m == live.size
        np.testing.assert_array_equal(cols[:m], live)
        Rs = np.triu(R[:m, P[:m]])
        S = live
        tol = 1e-12 * np.abs(G).max()
        assert np.abs(Rs.T @ Rs - G[np.ix_(S, S)]).max() <= tol
        assert np.abs(Rs.T @ z[:m] - G[S, n]).max() <= tol
        if step == 0:
            assert not np.array_equal(P[:m], np.arange(m))  # 2 gaps kept
        if step == 1:
            np.testing.assert_array_equal(P[:m], np.arange(m))  # 17 gaps: closed up
