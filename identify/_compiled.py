"""Compiled (numba) kernels for the inner loops that interpreted numpy cannot run fast.

Imported lazily (numba's import costs ~0.4 s): by :meth:`identify._mechsim.ImplicitModel.simulate`,
:meth:`identify._mechsim.LoopClosure` methods, :func:`identify._structural_sim.simulate_structural`
(cubic models) and the SGD-SINDy optimiser (:mod:`identify._sgd_matrix`).  Compiled code is
cached on disk (``cache=True``): the first call in a fresh checkout compiles (a few seconds),
later processes load it.

Status codes returned by the simulation kernels (the callers turn them into
:class:`testbed.core.errors.DivergenceError` with the time at which they happened):
``OK`` 0, ``SINGULAR_CLOSURE`` 1 (passive links collinear), ``NO_ASSEMBLY`` 2 (loop-closure
Newton solve did not converge), ``SINGULAR_EQUATIONS`` 3 (identified equations singular in the
accelerations), ``NON_FINITE`` 4 (state not finite).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

OK, SINGULAR_CLOSURE, NO_ASSEMBLY, SINGULAR_EQUATIONS, NON_FINITE = 0, 1, 2, 3, 4
MESSAGES = {
    SINGULAR_CLOSURE: "loop closure is singular (passive links collinear)",
    NO_ASSEMBLY: "loop closure Newton solve did not converge (no assembly)",
    SINGULAR_EQUATIONS: "identified equations are singular in the accelerations",
    NON_FINITE: "simulation diverged (state not finite)",
}

_JIT = {"cache": True, "nogil": True, "fastmath": False, "error_model": "numpy"}


# --------------------------------------------------------------------------------------------
# Planar loop closure  sum_i a_i e(th_i) = b,  per sample (q, dq of shape (n,))
# --------------------------------------------------------------------------------------------

@njit(**_JIT)
def _put(dst, src):
    """``dst[:] = src`` for 1-D arrays of one size, as a loop: numba's slice assignment
    compiles its broadcasting checks (about 3.7 s on a cold cache) for values that cannot differ."""
    for i in range(dst.size):
        dst[i] = src[i]


@njit(**_JIT)
def _solve2(j11, j12, j21, j22, r1, r2, out):
    """Solve [[j11, j12], [j21, j22]] z = r into out[0:2]; False if singular.

    Singular: ``|det| < 1e-12 max(|j11|, |j22|)`` (passive links collinear).
    """
    det = j11 * j22 - j12 * j21
    if not abs(det) >= 1e-12 * max(abs(j11), abs(j22), 1e-300):
        return False
    out[0] = (j22 * r1 - j12 * r2) / det
    out[1] = (j11 * r2 - j21 * r1) / det
    return True


@njit(**_JIT)
def closure_solve(a, b, p0, p1, q, tol, max_iter, z):
    """Newton solve of the closure for the passive angles q[p0], q[p1] (in place).

    The passive entries of ``q`` are the initial guess; ``z`` (2,) is scratch.  Returns a
    status code (``OK``, ``SINGULAR_CLOSURE`` or ``NO_ASSEMBLY``).
    """
    n = a.size
    for _ in range(max_iter):
        gx, gy = 0.0, 0.0
        for i in range(n):
            gx += a[i] * math.cos(q[i])
            gy += a[i] * math.sin(q[i])
        gx -= b[0]
        gy -= b[1]
        # Jacobian columns a_i n(th_i) = a_i (-sin, cos)
        if not _solve2(-a[p0] * math.sin(q[p0]), -a[p1] * math.sin(q[p1]),
                       a[p0] * math.cos(q[p0]), a[p1] * math.cos(q[p1]), gx, gy, z):
            return SINGULAR_CLOSURE
        q[p0] -= z[0]
        q[p1] -= z[1]
        if max(abs(z[0]), abs(z[1])) < tol:
            return OK
    return NO_ASSEMBLY


@njit(**_JIT)
def closure_velocity(a, p0, p1, q, dq, z):
    """Passive rates dq[p0], dq[p1] (in place) consistent with the closure; status code."""
    sx, sy = 0.0, 0.0
    for i in range(a.size):
        if i != p0 and i != p1:
            sx += -a[i] * math.sin(q[i]) * dq[i]
            sy += a[i] * math.cos(q[i]) * dq[i]
    if not _solve2(-a[p0] * math.sin(q[p0]), -a[p1] * math.sin(q[p1]),
                   a[p0] * math.cos(q[p0]), a[p1] * math.cos(q[p1]), -sx, -sy, z):
        return SINGULAR_CLOSURE
    dq[p0], dq[p1] = z[0], z[1]
    return OK


@njit(**_JIT)
def closure_acceleration_map(a, p0, p1, active, q, dq, P, r, z):
    """``ddq_p = P ddq_a + r`` at one state: P (2, n_a), r (2,) filled in place; status code."""
    j11, j12 = -a[p0] * math.sin(q[p0]), -a[p1] * math.sin(q[p1])
    j21, j22 = a[p0] * math.cos(q[p0]), a[p1] * math.cos(q[p1])
    wx, wy = 0.0, 0.0
    for i in range(a.size):
        w2 = a[i] * (dq[i] * dq[i])
        wx += w2 * math.cos(q[i])
        wy += w2 * math.sin(q[i])
    if not _solve2(j11, j12, j21, j22, wx, wy, z):
        return SINGULAR_CLOSURE
    r[0], r[1] = z[0], z[1]
    for m in range(active.size):
        j = active[m]
        _solve2(j11, j12, j21, j22, a[j] * math.sin(q[j]), -a[j] * math.cos(q[j]), z)
        P[0, m], P[1, m] = z[0], z[1]
    return OK


@njit(**_JIT)
def closure_solve_many(a, b, p0, p1, Q, tol, max_iter):
    """:func:`closure_solve` for every column of Q (n, N) in place; first bad status or OK."""
    z = np.empty(2)
    qs = np.empty(Q.shape[0])
    for s in range(Q.shape[1]):
        _put(qs, Q[:, s])
        st = closure_solve(a, b, p0, p1, qs, tol, max_iter, z)
        if st != OK:
            return st
        _put(Q[:, s], qs)
    return OK


@njit(**_JIT)
def closure_velocity_many(a, p0, p1, Q, DQ):
    """:func:`closure_velocity` for every column of (Q, DQ) (n, N), DQ in place."""
    z = np.empty(2)
    qs, ds = np.empty(Q.shape[0]), np.empty(Q.shape[0])
    for s in range(Q.shape[1]):
        _put(qs, Q[:, s])
        _put(ds, DQ[:, s])
        st = closure_velocity(a, p0, p1, qs, ds, z)
        if st != OK:
            return st
        DQ[p0, s], DQ[p1, s] = ds[p0], ds[p1]
    return OK


@njit(**_JIT)
def closure_acceleration_map_many(a, p0, p1, active, Q, DQ, P, R):
    """:func:`closure_acceleration_map` per column: P (N, 2, n_a), R (N, 2) filled."""
    z = np.empty(2)
    qs, ds = np.empty(Q.shape[0]), np.empty(Q.shape[0])
    for s in range(Q.shape[1]):
        _put(qs, Q[:, s])
        _put(ds, DQ[:, s])
        st = closure_acceleration_map(a, p0, p1, active, qs, ds, P[s], R[s], z)
        if st != OK:
            return st
    return OK


# --------------------------------------------------------------------------------------------
# Identified implicit equations  coef @ Theta(q, dq, ddq, u) = 0,  per sample
# --------------------------------------------------------------------------------------------

@njit(**_JIT)
def term_values(q, dq, u, arg, is_sin, idx, F, out):
    """Library terms at one state with zero accelerations (a :class:`identify.library.Library`
    factor table): F (3n + m + n_trig + 1,) scratch, out (n_terms,) filled.

    Factor rows ``[q (n); dq (n); ddq = 0 (n); u (m); trig (n_trig); 1]``; term c is the
    product of the rows ``idx[c]`` in order (the acceleration factor replaced by 1 in
    ``Library._idx_noacc``).
    """
    n, m, nt = q.size, u.size, arg.shape[0]
    for i in range(n):
        F[i] = q[i]
        F[n + i] = dq[i]
        F[2 * n + i] = 0.0
    for i in range(m):
        F[3 * n + i] = u[i]
    for k in range(nt):
        ang = 0.0
        for i in range(n):
            if arg[k, i] != 0.0:
                ang += arg[k, i] * q[i]
        F[3 * n + m + k] = math.sin(ang) if is_sin[k] else math.cos(ang)
    F[3 * n + m + nt] = 1.0
    for c in range(idx.shape[0]):
        v = F[idx[c, 0]]
        for j in range(1, idx.shape[1]):
            v *= F[idx[c, j]]
        out[c] = v


@njit(**_JIT)
def _lu_solve(A, x):
    """Solve A x = b in place (A (k, k) overwritten, x holds b); partial pivoting; False if
    a pivot is exactly zero or not finite."""
    k = A.shape[0]
    for c in range(k):
        p = c
        for i in range(c + 1, k):
            if abs(A[i, c]) > abs(A[p, c]):
                p = i
        if not (A[p, c] != 0.0 and math.isfinite(A[p, c])):
            return False
        if p != c:
            for j in range(k):
                A[c, j], A[p, j] = A[p, j], A[c, j]
            x[c], x[p] = x[p], x[c]
        for i in range(c + 1, k):
            f = A[i, c] / A[c, c]
            for j in range(c, k):
                A[i, j] -= f * A[c, j]
            x[i] -= f * x[c]
    for c in range(k - 1, -1, -1):
        s = x[c]
        for j in range(c + 1, k):
            s -= A[c, j] * x[j]
        x[c] = s / A[c, c]
    return True


@njit(**_JIT)
def accelerations(q, dq, u, coef, acc_index, arg, is_sin, idx, actuated, has_closure, a, p0, p1,
                  active, ddq, work):
    """Accelerations ddq (n,) at a consistent state under input u (m,); status code.

    ``coef`` (n_eq, n_terms) multiplies the terms; ``acc_index[c]`` is the coordinate whose
    acceleration multiplies term c (-1: none).  With a closure the passive accelerations
    ``ddq_p = P ddq_a + r`` are eliminated: ``(A_a + A_p P) ddq_a = -(f + A_p r)``.
    ``work`` is a :class:`Work` tuple of scratch arrays.
    """
    F, vals, A, Ared, rhs, P, r, z = work
    n_eq, p = coef.shape
    n = q.size
    term_values(q, dq, u, arg, is_sin, idx, F, vals)
    for e in range(n_eq):
        f = 0.0
        for k in range(n):
            A[e, k] = 0.0
        for c in range(p):
            ak = acc_index[c]
            if ak < 0:
                f += coef[e, c] * vals[c]
            else:
                A[e, ak] += coef[e, c] * vals[c]
        rhs[e] = -f
        for m in range(n_eq):
            Ared[e, m] = A[e, actuated[m]]
    if has_closure:
        st = closure_acceleration_map(a, p0, p1, active, q, dq, P, r, z)
        if st != OK:
            return st
        for e in range(n_eq):
            for m in range(n_eq):
                Ared[e, m] += A[e, p0] * P[0, m] + A[e, p1] * P[1, m]
            rhs[e] -= A[e, p0] * r[0] + A[e, p1] * r[1]
    if not _lu_solve(Ared, rhs):
        return SINGULAR_EQUATIONS
    for k in range(n):
        ddq[k] = 0.0
    for m in range(n_eq):
        ddq[actuated[m]] = rhs[m]
    if has_closure:
        s0, s1 = 0.0, 0.0
        for m in range(n_eq):
            s0 += P[0, m] * rhs[m]
            s1 += P[1, m] * rhs[m]
        ddq[p0] = s0 + r[0]
        ddq[p1] = s1 + r[1]
    return OK


@njit(**_JIT)
def make_work(n, n_eq, n_terms, n_factors):
    """Scratch arrays for :func:`accelerations`."""
    return (np.empty(n_factors), np.empty(n_terms), np.empty((n_eq, n)), np.empty((n_eq, n_eq)),
            np.empty(n_eq), np.empty((2, n_eq)), np.empty(2), np.empty(2))


@njit(**_JIT)
def accelerations_many(Q, DQ, U, coef, acc_index, arg, is_sin, idx, actuated, has_closure, a,
                       p0, p1, active, DDQ):
    """:func:`accelerations` per column of Q, DQ (n, N), U (m, N) into DDQ (n, N)."""
    n, N = Q.shape
    work = make_work(n, coef.shape[0], coef.shape[1], arg.shape[0] + 3 * n + U.shape[0] + 1)
    qs, ds, us, dd = np.empty(n), np.empty(n), np.empty(U.shape[0]), np.empty(n)
    for s in range(N):
        _put(qs, Q[:, s])
        _put(ds, DQ[:, s])
        _put(us, U[:, s])
        st = accelerations(qs, ds, us, coef, acc_index, arg, is_sin, idx, actuated, has_closure,
                           a, p0, p1, active, dd, work)
        if st != OK:
            return st, s
        _put(DDQ[:, s], dd)
    return OK, -1


@njit(**_JIT)
def rk4_implicit(q, dq, UU, h, n_steps, coef, acc_index, arg, is_sin, idx, actuated,
                 has_closure, a, b, p0, p1, active, Q, DQ, DDQ):
    """Fixed-step RK4 of the actuated state of an identified implicit model.

    ``q, dq`` (n,): consistent initial state (passive rows solved).  ``UU`` (m, 2 n_steps + 1):
    inputs at the half-step times.  Every stage sets the actuated state, completes the passive
    angles (Newton from the previous stage's) and rates, and evaluates the accelerations.
    Fills Q, DQ, DDQ (n_steps + 1, n) with the state at the start of each step (and the end).

    Returns
    -------
    (status, step)
        ``OK, -1`` or the status code and the step at which it occurred.
    """
    n = q.size
    n_eq = actuated.size
    work = make_work(n, n_eq, coef.shape[1], arg.shape[0] + 3 * n + UU.shape[0] + 1)
    z = np.empty(2)
    ya, va = np.empty(n_eq), np.empty(n_eq)
    kx, kv = np.empty((4, n_eq)), np.empty((4, n_eq))
    dd = np.empty(n)
    # the inputs of one stage copied into a contiguous row, so that :func:`accelerations` and
    # :func:`term_values` are compiled for one array layout only (a column view is another)
    us = np.empty(UU.shape[0])
    for m in range(n_eq):
        ya[m], va[m] = q[actuated[m]], dq[actuated[m]]
    for s in range(n_steps + 1):
        last = s == n_steps
        for stage in range(1 if last else 4):
            c = 0.0 if stage == 0 else (0.5 * h if stage < 3 else h)
            for m in range(n_eq):
                q[actuated[m]] = ya[m] + c * kx[stage - 1, m] if stage else ya[m]
                dq[actuated[m]] = va[m] + c * kv[stage - 1, m] if stage else va[m]
            if has_closure:
                # np.int64: a bare 30 compiles closure_solve a second time for Literal[int](30)
                st = closure_solve(a, b, p0, p1, q, 1e-13, np.int64(30), z)
                if st == OK:
                    st = closure_velocity(a, p0, p1, q, dq, z)
                if st != OK:
                    return st, s
            k = 2 * s + (0 if stage == 0 else (1 if stage < 3 else 2))
            _put(us, UU[:, k])
            st = accelerations(q, dq, us, coef, acc_index, arg, is_sin, idx, actuated,
                               has_closure, a, p0, p1, active, dd, work)
            if st != OK:
                return st, s
            if stage == 0:
                _put(Q[s], q)
                _put(DQ[s], dq)
                _put(DDQ[s], dd)
            for m in range(n_eq):
                kx[stage, m] = dq[actuated[m]]
                kv[stage, m] = dd[actuated[m]]
        if last:
            break
        for m in range(n_eq):
            ya[m] = ya[m] + h / 6 * (kx[0, m] + 2 * kx[1, m] + 2 * kx[2, m] + kx[3, m])
            va[m] = va[m] + h / 6 * (kv[0, m] + 2 * kv[1, m] + 2 * kv[2, m] + kv[3, m])
            if not (math.isfinite(ya[m]) and math.isfinite(va[m])):
                return NON_FINITE, s
    return OK, -1


# --------------------------------------------------------------------------------------------
# Cubic structural models  x'' = -M^-1 (C x' + K x + K3 x^3) + M^-1 f
# --------------------------------------------------------------------------------------------

@njit(**_JIT)
def _cubic_rhs(A, MK3, z, fk, out):
    """``out = A z + [0; fk - MK3 z[:n]^3]`` for the state z (2n,)."""
    nz = z.size
    n = nz // 2
    for i in range(nz):
        s = 0.0
        for j in range(nz):
            s += A[i, j] * z[j]
        out[i] = s
    for i in range(n):
        s = 0.0
        for j in range(n):
            s += MK3[i, j] * (z[j] * z[j] * z[j])
        out[n + i] += fk[i] - s


@njit(**_JIT)
def rk4_cubic(A, MK3, MF, z0, h, sub, Z):
    """Classical RK4 of ``z' = A z + [0; MF[:, k-1] - MK3 x^3]`` with ``sub`` steps of h [s] per
    sample interval, the force held over each interval; Z (2n, n_t) filled from Z[:, 0] = z0.

    Returns the first sample index at which the state is not finite, or -1.
    """
    nz = z0.size
    z = z0.copy()
    k1, k2, k3, k4, y = np.empty(nz), np.empty(nz), np.empty(nz), np.empty(nz), np.empty(nz)
    _put(Z[:, 0], z0)
    for k in range(1, Z.shape[1]):
        fk = MF[:, k - 1]
        for _ in range(sub):
            _cubic_rhs(A, MK3, z, fk, k1)
            for i in range(nz):
                y[i] = z[i] + 0.5 * h * k1[i]
            _cubic_rhs(A, MK3, y, fk, k2)
            for i in range(nz):
                y[i] = z[i] + 0.5 * h * k2[i]
            _cubic_rhs(A, MK3, y, fk, k3)
            for i in range(nz):
                y[i] = z[i] + h * k3[i]
            _cubic_rhs(A, MK3, y, fk, k4)
            for i in range(nz):
                z[i] = z[i] + (h / 6.0) * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i])
        for i in range(nz):
            if not math.isfinite(z[i]):
                return k
        _put(Z[:, k], z)
    return -1


# --------------------------------------------------------------------------------------------
# SGD-SINDy, matrix parametrisation (identify/_sgd_matrix.py): loss and gradients from a
# second-moment matrix, Adam steps over mini-batches
# --------------------------------------------------------------------------------------------

@njit(**_JIT)
def _theta(L, P, Q, R, m0, c0, k0, sc3, T):
    """Rows ``T_i = [M_i, C_i, K_i, K3_i, e_i]`` (n, 5n): the residual of row i at a sample is
    ``r_i = T_i z`` with z the sample's features ``[x'', x', x, x^3, -B u]`` (5n,)."""
    n = L.shape[0]
    for i in range(n):
        for j in range(n):
            s = 0.0
            for k in range(n):
                s += L[i, k] * L[j, k]
            T[i, j] = m0 * s
            T[i, n + j] = c0 * (0.5 * (Q[i, j] + Q[j, i]))
            T[i, 2 * n + j] = k0 * (0.5 * (P[i, j] + P[j, i]))
            T[i, 3 * n + j] = sc3[i, j] * R[i, j]
            T[i, 4 * n + j] = 1.0 if i == j else 0.0


@njit(**_JIT)
def _grads(TS, e2, b, T, L, m0, c0, k0, sc3, s_a, gL, gP, gQ, gR):
    """Data loss and gradients from ``TS[i, j] = sum_t r_i z_j`` and ``e2[i] = sum_t r_i^2``
    over b samples.

    The loss is ``sum_i w_i^2 e2_i / (b n)`` with ``w_i = 1 / (M_ii s_a_i)`` (the paper's
    per-row reconstruction error, standardised).  Gradients (n, n) with respect to ``L``
    (lower triangular, ``M = m0 L L^T``), ``P``, ``Q`` (``K = k0 sym(P)``, ``C = c0 sym(Q)``)
    and ``R`` (``K3 = sc3 * R``) are written in place.
    """
    return _grads_into(TS, e2, b, T, L, m0, c0, k0, sc3, s_a, gL, gP, gQ, gR,
                       np.empty((L.shape[0], L.shape[0])))


@njit(**_JIT)
def _grads_into(TS, e2, b, T, L, m0, c0, k0, sc3, s_a, gL, gP, gQ, gR, gM):
    """:func:`_grads` with the scratch gM (n, n) (the gradient with respect to M)."""
    n = L.shape[0]
    c = 2.0 / (b * n)
    loss = 0.0
    for i in range(n):
        w2 = 1.0 / (T[i, i] * s_a[i]) ** 2
        ei = w2 * e2[i]  # sum_t E_i(t)^2
        loss += ei
        g = c * w2
        for j in range(n):
            gM[i, j] = g * TS[i, j]
            gQ[i, j] = g * TS[i, n + j]
            gP[i, j] = g * TS[i, 2 * n + j]
            gR[i, j] = sc3[i, j] * (g * TS[i, 3 * n + j])
        gM[i, i] -= c * ei / T[i, i]
    for i in range(n):
        for j in range(i, n):
            q = c0 * (0.5 * (gQ[i, j] + gQ[j, i]))
            p = k0 * (0.5 * (gP[i, j] + gP[j, i]))
            gQ[i, j], gQ[j, i], gP[i, j], gP[j, i] = q, q, p, p
    for i in range(n):
        for j in range(n):
            if j > i:
                gL[i, j] = 0.0
                continue
            s = 0.0
            for k in range(n):
                s += (gM[i, k] + gM[k, i]) * L[k, j]
            gL[i, j] = m0 * s
    return loss / (b * n)


@njit(**_JIT)
def batch_loss_grad(Zb, L, P, Q, R, m0, c0, k0, sc3, s_a, T, TS, e2, r, gL, gP, gQ, gR):
    """Data loss and gradients (:func:`_grads`) over the samples (rows) of Zb (b, nfa).

    Zb holds the first ``nfa`` feature columns (the trailing ones are identically zero:
    ``B u`` without input, and x^3 too without a cubic term); T, TS (n, 5n), e2, r (n,) are
    scratch.
    """
    _theta(L, P, Q, R, m0, c0, k0, sc3, T)
    _batch_moments(Zb, 0, Zb.shape[0], T, TS, e2, r)
    return _grads(TS, e2, Zb.shape[0], T, L, m0, c0, k0, sc3, s_a, gL, gP, gQ, gR)


@njit(**_JIT)
def _batch_moments(Zb, lo, hi, T, TS, e2, r):
    """``TS[i, k] = sum_s r_i z_k`` and ``e2[i] = sum_s r_i^2`` over the samples ``z = Zb[s]``,
    lo <= s < hi, with ``r_i = sum_k T[i, k] z_k`` over the ``nfa = Zb.shape[1]`` columns.

    Every sum runs from 0.0 in ascending index order (k for r_i, s for TS and e2), so the
    results do not depend on how the loops are nested; each residual is summed in a register
    (``r`` only holds the n residuals of one sample).  The rows are read in place (a slice
    ``Zb[lo:hi]`` is typed by numba as a non-contiguous array).
    """
    n = T.shape[0]
    for i in range(n):
        e2[i] = 0.0
        for k in range(T.shape[1]):
            TS[i, k] = 0.0
    nfa = Zb.shape[1]
    for s in range(lo, hi):
        for i in range(n):
            ri = 0.0
            for k in range(nfa):
                ri += T[i, k] * Zb[s, k]
            r[i] = ri
            e2[i] += ri * ri
        for i in range(n):
            ri = r[i]
            for k in range(nfa):
                TS[i, k] += ri * Zb[s, k]


@njit(**_JIT)
def window_loss_grad(S, b, L, P, Q, R, m0, c0, k0, sc3, s_a, T, TS, e2, gL, gP, gQ, gR):
    """Data loss and gradients (:func:`_grads`) over a whole window from its second moments
    ``S = sum_t z z^T`` (5n, 5n) of b samples: ``sum_t r_i z = T_i S``, ``sum_t r_i^2 =
    T_i S T_i^T`` -- O(n^3) whatever b.  (The loss value then carries a cancellation error
    of ~1e-16 relative to the squared size of the terms, not of the residual.)"""
    _theta(L, P, Q, R, m0, c0, k0, sc3, T)
    _window_moments(S, T, TS, e2)
    return _grads(TS, e2, b, T, L, m0, c0, k0, sc3, s_a, gL, gP, gQ, gR)


@njit(**_JIT)
def _window_moments(S, T, TS, e2):
    """``TS = T S`` and ``e2[i] = T_i S T_i^T`` (sums from 0.0 in ascending index order)."""
    n = T.shape[0]
    nf = S.shape[0]
    for i in range(n):
        e = 0.0
        for j in range(nf):
            s = 0.0
            for k in range(nf):
                s += T[i, k] * S[k, j]
            TS[i, j] = s
            e += s * T[i, j]
        e2[i] = e


@njit(**_JIT)
def eig_work(n):
    """Scratch arrays for :func:`_gen_eigh_into` and :func:`_eig_loss_grad_into` at size n:
    ``(C, Ci, B, A, V, W, U, lam, order, M, K, gK, gM)``, allocated once per caller instead of
    once per step (numba allocates every temporary on the heap)."""
    return (np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty((n, n)),
            np.empty((n, n)), np.empty((n, n)), np.empty((n, n)), np.empty(n),
            np.empty(n, dtype=np.int64), np.empty((n, n)), np.empty((n, n)), np.empty((n, n)),
            np.empty((n, n)))


@njit(**_JIT)
def _gen_eigh_into(K, M, w):
    """Generalised symmetric eigenproblem ``K u = lam M u`` (M positive definite), small n,
    into the scratch ``w`` (:func:`eig_work`): U (n, n; columns sorted by ascending eigenvalue,
    ``U^T M U = I``) in ``w[6]``, the eigenvalues (n,) in ``w[7]``.

    Cholesky ``M = C C^T``, cyclic Jacobi on ``C^-1 K C^-T`` (rotations until every
    off-diagonal entry is below 1e-15 of the diagonal's norm), ``U = C^-T V`` so that
    ``U^T M U = I``.  Jacobi on an n = 3 matrix costs ~1 us against ~8 us for LAPACK's calls and
    allocations.  The products and the sort are plain loops (sums from 0.0 in ascending index
    order; an insertion sort, stable): numba's ``@`` calls BLAS, whose rounding moves with the
    CPU's kernel, and ``@`` and ``np.argsort`` took 4.6 of this function's 7.5 s of first
    compile.
    """
    C, Ci, B, A, V, W, U, lam, order = w[0], w[1], w[2], w[3], w[4], w[5], w[6], w[7], w[8]
    n = K.shape[0]
    for i in range(n):
        for j in range(n):
            C[i, j] = 0.0
            Ci[i, j] = 0.0
            V[i, j] = 1.0 if i == j else 0.0
    for j in range(n):
        d = M[j, j]
        for k in range(j):
            d -= C[j, k] * C[j, k]
        C[j, j] = math.sqrt(d) if d > 0.0 else math.nan
        for i in range(j + 1, n):
            v = M[i, j]
            for k in range(j):
                v -= C[i, k] * C[j, k]
            C[i, j] = v / C[j, j]
    for j in range(n):  # inverse of the lower-triangular factor
        Ci[j, j] = 1.0 / C[j, j]
        for i in range(j + 1, n):
            v = 0.0
            for k in range(j, i):
                v -= C[i, k] * Ci[k, j]
            Ci[i, j] = v / C[i, i]
    for i in range(n):  # B = Ci K
        for j in range(n):
            v = 0.0
            for k in range(n):
                v += Ci[i, k] * K[k, j]
            B[i, j] = v
    for i in range(n):  # A = B Ci^T
        for j in range(n):
            v = 0.0
            for k in range(n):
                v += B[i, k] * Ci[j, k]
            A[i, j] = v
    for _sweep in range(50):
        off, diag = 0.0, 0.0
        for i in range(n):
            diag += A[i, i] * A[i, i]
            for j in range(i + 1, n):
                off += A[i, j] * A[i, j]
        if not off > 1e-30 * diag:  # also stops on NaN
            break
        for p in range(n - 1):
            for q in range(p + 1, n):
                if A[p, q] == 0.0:
                    continue
                theta = (A[q, q] - A[p, p]) / (2.0 * A[p, q])
                t = math.copysign(1.0, theta) / (abs(theta) + math.sqrt(theta * theta + 1.0))
                c = 1.0 / math.sqrt(t * t + 1.0)
                sn = t * c
                for k in range(n):  # A <- J^T A J, V <- V J
                    akp, akq = A[k, p], A[k, q]
                    A[k, p], A[k, q] = c * akp - sn * akq, sn * akp + c * akq
                for k in range(n):
                    apk, aqk = A[p, k], A[q, k]
                    A[p, k], A[q, k] = c * apk - sn * aqk, sn * apk + c * aqk
                for k in range(n):
                    vkp, vkq = V[k, p], V[k, q]
                    V[k, p], V[k, q] = c * vkp - sn * vkq, sn * vkp + c * vkq
    for i in range(n):  # ascending eigenvalues; equal ones keep their index order
        order[i] = i
    for i in range(1, n):
        o = order[i]
        j = i
        while j > 0 and A[order[j - 1], order[j - 1]] > A[o, o]:
            order[j] = order[j - 1]
            j -= 1
        order[j] = o
    for i in range(n):  # W = Ci^T V
        for j in range(n):
            v = 0.0
            for k in range(n):
                v += Ci[k, i] * V[k, j]
            W[i, j] = v
    for c in range(n):  # U: W's columns in eigenvalue order
        oc = order[c]
        lam[c] = A[oc, oc]
        for i in range(n):
            U[i, c] = W[i, oc]


@njit(**_JIT)
def eig_loss_grad(L, P, m0, k0, lam_hat, eL, eP):
    """Eigenvalue penalty ``sum_k ((lam_hat_k - lam_k) / lam_hat_k)^2`` over the generalised
    eigenvalues of ``(K, M)`` in ascending order and its exact first-order gradient (with the
    mass-normalised modes u: ``d lam = u^T (dK - lam dM) u``), chained to L and P (in place).
    ``lam_hat[k]`` is the target of the k-th lowest mode; a target <= 0 means "none" (the
    mode is left to the data).  :func:`_eig_loss_grad_into` with its own scratch.
    """
    return _eig_loss_grad_into(L, P, m0, k0, lam_hat, eL, eP, eig_work(L.shape[0]))


@njit(**_JIT)
def _eig_loss_grad_into(L, P, m0, k0, lam_hat, eL, eP, w):
    """:func:`eig_loss_grad` with the scratch ``w`` (:func:`eig_work`)."""
    n = L.shape[0]
    nk = lam_hat.size
    M, K, gK, gM = w[9], w[10], w[11], w[12]
    for i in range(n):
        for j in range(n):
            s = 0.0
            for k in range(n):
                s += L[i, k] * L[j, k]
            M[i, j] = m0 * s
            K[i, j] = k0 * (0.5 * (P[i, j] + P[j, i]))
            gK[i, j] = 0.0
            gM[i, j] = 0.0
    _gen_eigh_into(K, M, w)
    U, lam = w[6], w[7]
    loss = 0.0
    for k in range(nk):
        if not lam_hat[k] > 0.0:
            continue
        r = (lam_hat[k] - lam[k]) / lam_hat[k]
        loss += r * r
        a, bb = -2.0 * r / lam_hat[k], 2.0 * r * lam[k] / lam_hat[k]
        for i in range(n):
            for j in range(n):
                gK[i, j] += a * U[i, k] * U[j, k]
                gM[i, j] += bb * U[i, k] * U[j, k]
    for i in range(n):
        for j in range(n):
            eP[i, j] = k0 * (0.5 * (gK[i, j] + gK[j, i]))
            if j > i:
                eL[i, j] = 0.0
            else:
                s = 0.0
                for k in range(n):
                    s += (gM[i, k] + gM[k, i]) * L[k, j]
                eL[i, j] = m0 * s
    return loss


@njit(**_JIT)
def _adam(X, g, m, v, t, lr, b1, b2, eps, scale):
    """One Adam step on X in place (moments m, v in place); ``scale`` gets the per-entry step
    size ``lr / (sqrt(v_hat) + eps)`` (the metric of the lasso's proximal step)."""
    _adam_c(X, g, m, v, 1.0 - b1**t, 1.0 - b2**t, lr, b1, b2, eps, scale)


@njit(**_JIT)
def _adam_c(X, g, m, v, c1, c2, lr, b1, b2, eps, scale):
    """:func:`_adam` with its bias corrections ``c1 = 1 - b1^t``, ``c2 = 1 - b2^t`` given (one
    step's four updates share them)."""
    for i in range(X.shape[0]):
        for j in range(X.shape[1]):
            m[i, j] = b1 * m[i, j] + (1.0 - b1) * g[i, j]
            v[i, j] = b2 * v[i, j] + (1.0 - b2) * g[i, j] * g[i, j]
            sc = lr / (math.sqrt(v[i, j] / c2) + eps)
            scale[i, j] = sc
            X[i, j] += -sc * (m[i, j] / c1)


@njit(**_JIT)
def project(L, P, Q, R, m0, m_hat):
    """Eq. 5 at its fixed point, in place: all matrices scaled together so that
    ``trace(M) = trace(m0 L L^T) = m_hat``."""
    n = L.shape[0]
    tr = 0.0
    for i in range(n):
        for j in range(n):
            tr += L[i, j] * L[i, j]
    sc = m_hat / (m0 * tr)
    sq = math.sqrt(sc)
    for i in range(n):
        for j in range(n):
            L[i, j] *= sq
            P[i, j] *= sc
            Q[i, j] *= sc
            R[i, j] *= sc


@njit(**_JIT)
def sgd_steps(Z, nfa, S_full, n_full, perm, bs, n_steps, params, adam, t0, lr, m0, c0, k0, sc3, s_a,
              lam_hat, eig_gain, has_R, support, use_support, lam_l1, prox, m_hat):
    """``n_steps`` Adam steps of the matrix-parametrised SGD-SINDy, in place.

    Parameters
    ----------
    Z : ndarray, shape (N, 5n)
        Features ``[x'', x', x, x^3, -B u]`` of each sample of the fit window; columns from
        ``nfa`` on are identically zero (not read).
    S_full : ndarray, shape (5n, 5n)
        Their second moments over the window; used for every step when ``bs <= 0`` (the exact
        full-window gradient), ``n_full`` the number of samples.
    perm : ndarray of int, shape (N,)
        This epoch's sample order; step s takes ``perm[(s bs) % N : (s bs) % N + bs]`` (the
        first ``bs`` if that is empty).
    params : tuple of ndarray (n, n)
        ``L, P, Q, R`` (``M = m0 L L^T``, ``K = k0 sym(P)``, ``C = c0 sym(Q)``,
        ``K3 = sc3 * R``); updated in place.
    adam : tuple of ndarray
        ``(m, v, scale)`` per parameter, each (4, n, n), and the step count starts at ``t0``.
    eig_gain : float
        ``alpha_eig * epsilon`` (0: no eigenvalue term; ``lam_hat`` empty likewise).
    has_R, support, use_support, lam_l1, prox
        The cubic block: R updated only if ``has_R``; its gradient and value masked by
        ``support`` if ``use_support``; soft-thresholded by ``lam_l1 * scale`` if ``prox``.
    m_hat : float
        Total mass [kg]; after every step all matrices are scaled so that trace(M) = m_hat.
    """
    L, P, Q, R = params
    am, av, asc = adam
    n = L.shape[0]
    N = Z.shape[0]
    nf = 5 * n
    T, TS = np.empty((n, nf)), np.empty((n, nf))
    e2, r = np.empty(n), np.empty(n)
    g = np.zeros((4, n, n))
    eL, eP = np.zeros((n, n)), np.zeros((n, n))
    use_eig = eig_gain != 0.0 and lam_hat.size > 0
    b1, b2, eps = 0.9, 0.999, 1e-12
    # This epoch's samples in order, Z's first nfa columns: the batches are then contiguous.
    # They are gathered in two passes, a sequential copy of those columns (Zc) and the
    # permutation of its rows: an epoch reads every sample once in random order, and from the
    # full (N, 5n) rows, which have left the caches between epochs, the gather took about half
    # of the steps' time (cantilever_stiff_impact, in the fit: 0.23 -> 0.18 s of CPU for the
    # 10,000 steps, the same work otherwise, at load 11).
    Zc = np.empty((N if bs > 0 else 0, nfa))
    for s in range(Zc.shape[0]):
        for k in range(nfa):
            Zc[s, k] = Z[s, k]
    Zp = np.empty((Zc.shape[0], nfa))
    for s in range(Zc.shape[0]):
        z = perm[s]
        for k in range(nfa):
            Zp[s, k] = Zc[z, k]
    ew = eig_work(n)
    gM = np.empty((n, n))
    for s in range(n_steps):
        if bs > 0:
            lo = (s * bs) % N
            hi = min(lo + bs, N)
            if hi <= lo:
                lo, hi = 0, min(bs, N)
            _theta(L, P, Q, R, m0, c0, k0, sc3, T)
            _batch_moments(Zp, lo, hi, T, TS, e2, r)
            _grads_into(TS, e2, hi - lo, T, L, m0, c0, k0, sc3, s_a, g[0], g[1], g[2], g[3], gM)
        else:
            _theta(L, P, Q, R, m0, c0, k0, sc3, T)
            _window_moments(S_full, T, TS, e2)
            _grads_into(TS, e2, n_full, T, L, m0, c0, k0, sc3, s_a, g[0], g[1], g[2], g[3], gM)
        if use_eig:
            _eig_loss_grad_into(L, P, m0, k0, lam_hat, eL, eP, ew)
            for i in range(n):
                for j in range(n):
                    g[0, i, j] += eig_gain * eL[i, j]
                    g[1, i, j] += eig_gain * eP[i, j]
        t = t0 + s + 1
        c1, c2 = 1.0 - b1**t, 1.0 - b2**t
        _adam_c(L, g[0], am[0], av[0], c1, c2, lr, b1, b2, eps, asc[0])
        _adam_c(P, g[1], am[1], av[1], c1, c2, lr, b1, b2, eps, asc[1])
        _adam_c(Q, g[2], am[2], av[2], c1, c2, lr, b1, b2, eps, asc[2])
        if has_R:
            if use_support:
                for i in range(n):
                    for j in range(n):
                        g[3, i, j] *= support[i, j]
            _adam_c(R, g[3], am[3], av[3], c1, c2, lr, b1, b2, eps, asc[3])
            for i in range(n):
                for j in range(n):
                    if prox:
                        a = abs(R[i, j]) - lam_l1[i, j] * asc[3, i, j]
                        R[i, j] = math.copysign(a, R[i, j]) if a > 0.0 else 0.0
                    if use_support:
                        R[i, j] *= support[i, j]
        project(L, P, Q, R, m0, m_hat)
