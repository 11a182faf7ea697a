"""Compiled (numba) kernel of the SINDy-PI sweep: every candidate's thresholded least squares.

:func:`stlsq_chains` runs, for each candidate left-hand side, the sequentially thresholded
least-squares rounds of :func:`identify._implicit.stlsq_sweep` over all thresholds in one
compiled loop: no Python call and no LAPACK call per refit (at 100k x 97 there are about 1,290
refits of 2-96 columns; called from Python one batch per round they cost ~87 ms, mostly call
overhead and LU's twice-Cholesky flops).

Each refit solves ``(Gn[S, S] + ridge I) xi_S = Gn[j, S]`` on its support ``S`` by Cholesky
(right-looking, rows contiguous); if a pivot is not positive (the support is singular to
round-off) by LU with partial pivoting; if LU meets an exactly zero pivot the candidate is
flagged and the caller refits it by the minimum-norm path.  No ``fastmath``: the operations run
in source order in IEEE arithmetic, so the result does not depend on the CPU's vector width or
on a BLAS kernel.

Imported lazily (numba's import costs ~0.4 s); compiled code is cached on disk.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

_JIT = {"cache": True, "nogil": True, "fastmath": False, "error_model": "numpy"}


@njit(**_JIT)
def _cholesky_solve(A, b, n):
    """Solve ``A[:n, :n] x = b[:n]`` in place (x in ``b``) for symmetric ``A`` by Cholesky.

    Only the upper triangle of ``A`` is read; it is overwritten by the factor ``R`` (``A = R^T
    R``), so every inner loop runs along a row.  Returns False, with ``A`` and ``b`` spoiled,
    if a pivot is not positive (not numerically positive definite).
    """
    for k in range(n):
        d = A[k, k]
        if not d > 0.0:
            return False
        d = math.sqrt(d)
        A[k, k] = d
        for j in range(k + 1, n):
            A[k, j] /= d
        for i in range(k + 1, n):  # trailing update of the upper triangle
            rki = A[k, i]
            for j in range(i, n):
                A[i, j] -= rki * A[k, j]
    for k in range(n):  # R^T y = b, column-oriented along the rows of R
        yk = b[k] / A[k, k]
        b[k] = yk
        for i in range(k + 1, n):
            b[i] -= A[k, i] * yk
    for i in range(n - 1, -1, -1):  # R x = y
        s = b[i]
        for k in range(i + 1, n):
            s -= A[i, k] * b[k]
        b[i] = s / A[i, i]
    return True


@njit(**_JIT)
def _lu_solve(A, b, n):
    """Solve ``A[:n, :n] x = b[:n]`` in place by LU with partial pivoting (x in ``b``).

    Returns False on an exactly zero (or non-finite) pivot.
    """
    for k in range(n):
        piv = k
        big = abs(A[k, k])
        for i in range(k + 1, n):
            if abs(A[i, k]) > big:
                big = abs(A[i, k])
                piv = i
        if not (big > 0.0 and big < np.inf):
            return False
        if piv != k:
            for j in range(n):
                A[k, j], A[piv, j] = A[piv, j], A[k, j]
            b[k], b[piv] = b[piv], b[k]
        inv = 1.0 / A[k, k]
        for i in range(k + 1, n):
            f = A[i, k] * inv
            A[i, k] = f
            if f != 0.0:
                for j in range(k + 1, n):
                    A[i, j] -= f * A[k, j]
                b[i] -= f * b[k]
    for i in range(n - 1, -1, -1):
        s = b[i]
        for j in range(i + 1, n):
            s -= A[i, j] * b[j]
        b[i] = s / A[i, i]
    return True


@njit(**_JIT)
def _refit(Gn, j, mask, ridge, idx, A, A2, b, b2, x):
    """Least squares of column ``j`` on the columns ``mask`` into ``x`` (zero elsewhere).

    Returns 0 (Cholesky), 1 (LU: support singular to round-off) or 2 (exactly singular: ``x``
    not set).
    """
    p = mask.size
    n = np.int64(0)  # not a bare 0: that compiles the solvers once more for Literal[int](0)
    for q in range(p):
        if mask[q]:
            idx[n] = q
            n += 1
    for q in range(p):
        x[q] = 0.0
    if n == 0:
        return 0
    for r in range(n):
        gr = idx[r]
        for c in range(r, n):
            A[r, c] = Gn[gr, idx[c]]
        A[r, r] += ridge
        b[r] = Gn[j, gr]
        b2[r] = b[r]
    status = 0
    if not _cholesky_solve(A, b, n):
        for r in range(n):  # the full symmetric matrix again (Cholesky spoiled A)
            gr = idx[r]
            for c in range(n):
                A2[r, c] = Gn[gr, idx[c]]
            A2[r, r] += ridge
            b[r] = b2[r]
        if not _lu_solve(A2, b, n):
            return 2
        status = 1
    for r in range(n):
        x[idx[r]] = b[r]
    return status


@njit(**_JIT)
def stlsq_chains(Gn, cand, base, xi0, thr, ridge, max_iter):
    """Sequentially thresholded least squares of every candidate over all thresholds.

    For candidate ``c`` (left-hand side ``cand[c]``), starting from ``xi0[c]`` on ``base[c]``:
    at each threshold ``thr[t]`` (ascending), at most ``max_iter`` rounds of ``new = base[c] &
    (|xi| >= thr[t])``; stop when the support repeats, else refit on it.  The model at the end
    of threshold t is ``models[t, c]``.  Candidates are independent, so this equals the
    round-batched loop of :func:`identify._implicit.stlsq_sweep`'s reference path.

    Parameters
    ----------
    Gn : ndarray, shape (p, p)
        Normalised training Gram matrix.
    cand : ndarray of int, shape (C,)
        Left-hand-side column of each candidate.
    base : ndarray of bool, shape (C, p)
        Columns each candidate may use (alive, not its own).
    xi0 : ndarray, shape (C, p)
        Starting coefficients (zero outside ``base``).
    thr : ndarray, shape (T,)
        Thresholds on normalised coefficients, ascending.
    ridge : float
        Added to the diagonal of every support's Gram block.
    max_iter : int
        Rounds per threshold.

    Returns
    -------
    models : ndarray, shape (T, C, p)
        Coefficients (normalised units) at the end of each threshold.
    status : ndarray of int, shape (C,)
        Per candidate: 0 all refits by Cholesky, 1 some by LU, 2 a support exactly singular
        (the candidate's models are not valid and must be refitted by the caller).
    refits : ndarray of int, shape (C,)
        Number of refits of each candidate.
    """
    n_t = thr.size
    n_c, p = xi0.shape
    models = np.zeros((n_t, n_c, p))
    status = np.zeros(n_c, dtype=np.int64)
    refits = np.zeros(n_c, dtype=np.int64)
    idx = np.empty(p, dtype=np.int64)
    A = np.empty((p, p))
    A2 = np.empty((p, p))
    b = np.empty(p)
    b2 = np.empty(p)
    x = xi0[0].copy()
    mask = base[0].copy()
    new = base[0].copy()
    for c in range(n_c):
        j = cand[c]
        for q in range(p):
            x[q] = xi0[c, q]
            mask[q] = base[c, q]
        failed = False
        for t in range(n_t):
            lam = thr[t]
            if not failed:
                for _ in range(max_iter):
                    changed = False
                    for q in range(p):
                        new[q] = base[c, q] and abs(x[q]) >= lam
                        if new[q] != mask[q]:
                            changed = True
                    if not changed:
                        break
                    for q in range(p):
                        mask[q] = new[q]
                    s = _refit(Gn, j, mask, ridge, idx, A, A2, b, b2, x)
                    refits[c] += 1
                    if s > status[c]:
                        status[c] = s
                    if s == 2:
                        failed = True
                        break
            for q in range(p):
                models[t, c, q] = x[q]
    return models, status, refits


#: ``sqrt(a^2 + b^2)`` is accurate (relative error ~1 ulp, like ``hypot``) when the result lies
#: in (1e-150, 1e150): then ``a^2 + b^2`` lies in (1e-300, 1e300), clear of overflow (1.8e308),
#: and any subnormal square in it (< 2.2e-308) is rounded by at most 4.9e-324, a relative 5e-24.
#: The factor of a unit-diagonal Gram matrix has entries of magnitude <= ~1, so ``hypot`` (the
#: fallback outside) does not run in practice.
_TINY = 1e-150
_HUGE = 1e150

#: Storage columns left as gaps by deleted columns are closed up once they exceed this share of
#: the live columns (plus a few): until then rotating the gaps too (contiguous, vectorised) is
#: cheaper than moving every later column (a gather per entry).  Speed only: the kept entries
#: are the same to the bit either way.
_GAP_SHARE = 0.5


@njit(**_JIT)
def _retriangularise(R, cols, P, n, keep, z, pos):
    """Delete the columns ``~keep`` from a triangular factor stored by rows, by Givens rotations.

    Factor column l (of n) is library column ``cols[l]``, stored in ``R[:, P[l]]`` (``P``
    increasing: the storage may have gaps where columns were deleted) and valid in rows
    ``<= l`` (the rows below are stale, never read); ``z[:n]`` is a right-hand-side column
    carried along.  Kept column l (in order) is factor column ``pos[l] = k >= l``; its rows are
    rotated (rows ``r - 1, r`` together, r from k down to l + 1) until the kept columns form an
    upper-triangular factor in their first m rows; ``z[:m]`` is then ``Q^T z`` restricted to
    those rows.  ``cols``, ``P`` are updated to the kept columns; when the gaps exceed
    ``_GAP_SHARE`` of m the storage is closed up (``P[l] = l``).  Returns m.

    Each rotation runs along two contiguous row segments of storage (from the rotated column to
    the last kept one; gaps are rotated too and never read), which the compiler vectorises.
    Every kept entry meets the same rotations in the same order as in the column-stored kernel
    this replaced; a rotation's ``h = sqrt(a^2 + b^2)`` is taken with the correctly rounded
    square root rather than libm's ``hypot`` (a quarter of the kernel's time; the result
    differs by about one ulp, and no longer depends on the C library's version), which falls
    back to ``hypot`` outside ``(_TINY, _HUGE)``.  No ``fastmath``: no contraction to fused
    multiply-adds either.
    """
    m = 0
    for k in range(n):
        if keep[k]:
            pos[m] = k
            m += 1
    if m == 0:
        return 0
    end = P[pos[m - 1]] + 1  # storage past the last kept column
    for l in range(m):
        k = pos[l]
        sp = P[k]
        for r in range(k, l, -1):
            bb = R[r, sp]
            if bb == 0.0:
                continue
            a = R[r - 1, sp]
            h = math.sqrt(a * a + bb * bb)  # |entries| <= ~1 (unit-diagonal Gn): see above
            if not (_TINY < h < _HUGE):
                h = math.hypot(a, bb)
            c = a / h
            s = bb / h
            R[r - 1, sp] = h
            R[r, sp] = 0.0
            ra = R[r - 1, sp + 1:end]  # views indexed from 0: the loop vectorises (indexing
            rb = R[r, sp + 1:end]  # R[r - 1, q] directly, numba's index wraparound blocks it)
            for q in range(ra.size):
                x = ra[q]
                y = rb[q]
                ra[q] = c * x + s * y
                rb[q] = c * y - s * x
            x = z[r - 1]
            y = z[r]
            z[r - 1] = c * x + s * y
            z[r] = c * y - s * x
    for l in range(m):
        cols[l] = cols[pos[l]]
        P[l] = P[pos[l]]
    if end - m > _GAP_SHARE * m + 4:  # close up: R[r, l] = R[r, P[l]] for l >= r, row by row
        first = 0
        while P[first] == first:
            first += 1
        for r in range(m):
            for l in range(max(r, first), m):
                R[r, l] = R[r, P[l]]  # P[l] >= l: reads ahead of the writes
        for l in range(first, m):
            P[l] = l
    return m


@njit(**_JIT)
def stlsq_chains_downdate(Gn, cand, alive, base, xi0, thr, ridge, max_iter):
    """:func:`stlsq_chains` with one factorisation for all candidates, downdated per refit.

    ``R`` is the Cholesky factor of ``Gn[alive, alive] + ridge I`` (library order), computed
    once.  Along each candidate's path its supports only shrink (a threshold zeroes
    coefficients, never revives them), so its least squares on support S is read off ``R`` with
    the columns outside S deleted: Givens rotations retriangularise ``R[:, S]`` and carry the
    left-hand side's column ``R[:, j]`` along (``R[:, S]^T R[:, S] = Gn[S, S] + ridge I`` and
    ``R[:, S]^T R[:, j] = Gn[S, j]``: the normal equations of the refit), and one triangular
    solve gives the coefficients.  Each candidate keeps its own rotated copy, so a refit costs
    the rotations for the columns it drops, not a new factorisation.  Orthogonal rotations are
    backward stable: the solution differs from a fresh factorisation's by round-off times the
    support's condition number, as two fresh factorisations by different kernels do.

    The factor is stored by rows so that the rotations run along contiguous memory
    (:func:`_retriangularise`); the arithmetic is that of the column-stored version it
    replaced, operation by operation, but for the square root of each rotation (about one
    ulp; selected equations unchanged).

    Parameters
    ----------
    Gn, cand, base, xi0, thr, ridge, max_iter
        As in :func:`stlsq_chains`; ``base[c]`` must be ``alive`` without ``cand[c]``.
    alive : ndarray of bool, shape (p,)
        Columns not identically zero.

    Returns
    -------
    models : ndarray, shape (T, C, p)
    status : ndarray of int, shape (C,)
        0, or 2 where a support's factor has an exactly zero pivot (refit by the caller); all
        2 if ``Gn[alive, alive] + ridge I`` is not numerically positive definite (then use
        :func:`stlsq_chains`).
    refits : ndarray of int, shape (C,)
    """
    n_t = thr.size
    n_c, p = xi0.shape
    models = np.zeros((n_t, n_c, p))
    status = np.zeros(n_c, dtype=np.int64)
    refits = np.zeros(n_c, dtype=np.int64)
    acols = np.flatnonzero(alive)
    na = acols.size
    apos = np.full(p, -1, dtype=np.int64)  # position of each alive library column in R0
    for r in range(na):
        apos[acols[r]] = r
    R0 = np.zeros((na, na))  # upper triangle: the factor, rows contiguous; lower: zeros
    for r in range(na):
        for c in range(r, na):
            R0[r, c] = Gn[acols[r], acols[c]]
        R0[r, r] += ridge
    dummy = np.zeros(na)
    if not _cholesky_solve(R0, dummy, na):
        status[:] = 2
        return models, status, refits
    R = np.empty((na, na))
    z = np.empty(na)
    t_ = np.empty(na)
    cols = np.empty(na, dtype=np.int64)
    P = np.empty(na, dtype=np.int64)
    pos = np.empty(na, dtype=np.int64)
    keep = np.empty(na, dtype=np.bool_)
    x = np.empty(p)
    new = np.empty(p, dtype=np.bool_)
    mask = np.empty(p, dtype=np.bool_)
    for ci in range(n_c):
        j = cand[ci]
        for q in range(p):
            x[q] = xi0[ci, q]
            mask[q] = base[ci, q]
        n = -1  # factor not yet copied: the first refit starts from R0 with j as rhs
        failed = False
        for t in range(n_t):
            lam = thr[t]
            if not failed:
                for _ in range(max_iter):
                    changed = False
                    for q in range(p):
                        new[q] = base[ci, q] and abs(x[q]) >= lam
                        if new[q] != mask[q]:
                            changed = True
                    if not changed:
                        break
                    for q in range(p):
                        mask[q] = new[q]
                    refits[ci] += 1
                    if n < 0:
                        jp = apos[j]
                        for r in range(na):
                            cols[r] = acols[r]
                            P[r] = r
                            z[r] = R0[r, jp]  # zero below row jp
                            dst = R[r, r:]  # only rows <= the column's position
                            src = R0[r, r:]
                            for q in range(dst.size):
                                dst[q] = src[q]
                        n = na
                    for k in range(n):
                        keep[k] = mask[cols[k]]
                    m = _retriangularise(R, cols, P, n, keep, z, pos)
                    n = m
                    for q in range(p):
                        x[q] = 0.0
                    for l in range(m):
                        t_[l] = z[l]
                    for l in range(m - 1, -1, -1):  # R x = z, column-oriented
                        col = P[l]
                        d = R[l, col]
                        if d == 0.0:
                            failed = True
                            break
                        xl = t_[l] / d
                        x[cols[l]] = xl
                        for r in range(l):
                            t_[r] -= xl * R[r, col]
                    if failed:
                        status[ci] = 2
                        break
            for q in range(p):
                models[t, ci, q] = x[q]
    return models, status, refits
