"""Compiled RK4 of identified first-order implicit laws ``A(z) dx + b(z) = 0`` (numba).

The simulation of :class:`identify.sindy_pi_dynamical.SINDyPIDynamical`: each library term is
a monomial of the states and inputs ``z = (x, u)`` (``powers``), times one state's derivative
or none (``deriv``); at each RK4 stage the terms are evaluated, ``A`` (n_states, n_states) and
``b`` (n_states,) assembled from the identified coefficients and ``dx = -A^-1 b`` solved, in
compiled code: the interpreted path paid about 60 us of numpy per derivative call, so the step
rule's whole-record simulations of a stiff law at 0.1 ms took minutes (docs/known-gaps.md,
session 18).

Imported lazily by the identifier (numba's import costs ~0.4 s); compiled code is cached on
disk (``cache=True``).  Status codes (the caller turns them into
:class:`testbed.core.errors.DivergenceError` with the time they happened at): ``OK`` 0,
``NON_FINITE_STATE`` 1, ``NON_FINITE_TERMS`` 2, ``SINGULAR`` 3 (the derivatives' coefficient
``A`` has its smallest singular value at or below the tolerance; the value is returned).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from identify._compiled import _lu_solve

OK, NON_FINITE_STATE, NON_FINITE_TERMS, SINGULAR = 0, 1, 2, 3

_JIT = {"cache": True, "nogil": True, "fastmath": False, "error_model": "numpy"}


@njit(**_JIT)
def _inputs_at(s, t, U, out):
    """The inputs at time ``s`` [s], linearly interpolated on the samples ``t`` as
    ``numpy.interp`` does (held at the end values outside the record), into ``out``."""
    n = t.size
    if U.shape[0] == 0:
        return
    if s <= t[0]:
        for i in range(U.shape[0]):
            out[i] = U[i, 0]
        return
    if s >= t[n - 1]:
        for i in range(U.shape[0]):
            out[i] = U[i, n - 1]
        return
    lo, hi = 0, n - 1   # t[lo] <= s < t[hi]
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if t[mid] <= s:
            lo = mid
        else:
            hi = mid
    for i in range(U.shape[0]):
        slope = (U[i, hi] - U[i, lo]) / (t[hi] - t[lo])
        out[i] = slope * (s - t[lo]) + U[i, lo]


@njit(**_JIT)
def _smallest_singular_value(A, S):
    """The smallest singular value of the square ``A`` (n, n), by one-sided Jacobi (Hestenes)
    rotations of its copy in the scratch ``S`` until every pair of columns is orthogonal to
    round-off (at most 60 sweeps; a few suffice for the few states it is used for): the
    singular values are then the column norms, each to its own relative accuracy.  Not
    LAPACK's SVD: numba's binding of it compiled for 40 s on a cold cache."""
    n = A.shape[0]
    for r in range(n):
        for c in range(n):
            S[r, c] = A[r, c]
    for _ in range(60):
        rotated = False
        for p in range(n - 1):
            for q in range(p + 1, n):
                alpha, beta, gamma = 0.0, 0.0, 0.0
                for i in range(n):
                    alpha += S[i, p] * S[i, p]
                    beta += S[i, q] * S[i, q]
                    gamma += S[i, p] * S[i, q]
                if not abs(gamma) > 2.2e-16 * math.sqrt(alpha * beta):
                    continue
                rotated = True
                zeta = (beta - alpha) / (2.0 * gamma)
                t = math.copysign(1.0, zeta) / (abs(zeta) + math.sqrt(1.0 + zeta * zeta))
                cs = 1.0 / math.sqrt(1.0 + t * t)
                sn = cs * t
                for i in range(n):
                    a, b = S[i, p], S[i, q]
                    S[i, p] = cs * a - sn * b
                    S[i, q] = sn * a + cs * b
        if not rotated:
            break
    low = math.inf
    for c in range(n):
        v = 0.0
        for i in range(n):
            v += S[i, c] * S[i, c]
        low = min(low, math.sqrt(v))
    return low


@njit(**_JIT)
def derivative(x, u, coef, powers, deriv, sing_tol, z, m, A, b, S, out):
    """``dx`` (into ``out``) of the implicit equations ``coef`` (n_states, p) at state ``x``
    (n_states,) and input ``u`` (n_inputs,); ``z``, ``m``, ``A``, ``b``, ``S`` are scratch of
    sizes n_states + n_inputs, p, (n_states, n_states), n_states, (n_states, n_states).

    Returns
    -------
    (int, float)
        A status code and, for ``SINGULAR``, the smallest singular value of ``A``.
    """
    n = x.size
    for i in range(n):
        z[i] = x[i]
    for i in range(u.size):
        z[n + i] = u[i]
    for i in range(z.size):
        if not math.isfinite(z[i]):
            return NON_FINITE_STATE, 0.0
    p = powers.shape[0]
    for j in range(p):
        v = 1.0
        for i in range(z.size):
            k = powers[j, i]
            if k != 0:
                v *= z[i] ** float(k)
        m[j] = v
    for r in range(n):
        b[r] = 0.0
        for c in range(n):
            A[r, c] = 0.0
        for j in range(p):
            cm = coef[r, j] * m[j]
            if not math.isfinite(cm):
                return NON_FINITE_TERMS, 0.0
            if deriv[j] >= 0:
                A[r, deriv[j]] += cm
            else:
                b[r] += cm
    if n == 1:
        smin = abs(A[0, 0])
        if not smin > sing_tol:
            return SINGULAR, smin
        out[0] = -b[0] / A[0, 0]
        return OK, 0.0
    smin = _smallest_singular_value(A, S)
    if not smin > sing_tol:
        return SINGULAR, smin
    for r in range(n):
        out[r] = -b[r]
        for c in range(n):
            S[r, c] = A[r, c]
    if not _lu_solve(S, out):
        return SINGULAR, 0.0
    return OK, 0.0


@njit(**_JIT)
def rk4(x0, t, U, dt, coef, powers, deriv, sing_tol, X, XD):
    """RK4 of the implicit equations from ``x0`` over the samples ``t`` (n_samples,) [s] in
    steps of at most ``dt`` [s] (``ceil(interval / dt - 1e-9)`` equal steps per sample
    interval), inputs ``U`` (n_inputs, n_samples; n_inputs may be 0) interpolated linearly;
    the states into ``X`` and the equations' derivatives at them into ``XD`` (n_states,
    n_samples).

    Returns
    -------
    (int, float, float)
        Status, the time [s] it happened at, and the smallest singular value for ``SINGULAR``.
    """
    n = x0.size
    nu = U.shape[0]
    p = powers.shape[0]
    z = np.empty(n + nu)
    m = np.empty(p)
    A = np.empty((n, n))
    S = np.empty((n, n))
    b = np.empty(n)
    u = np.empty(nu)
    x = x0.copy()
    y = np.empty(n)
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    for i in range(n):
        X[i, 0] = x[i]
    for k in range(t.size - 1):
        h_total = t[k + 1] - t[k]
        steps = max(1, math.ceil(h_total / dt - 1e-9))
        h = h_total / steps
        s = t[k]
        for _ in range(steps):
            _inputs_at(s, t, U, u)
            st, sv = derivative(x, u, coef, powers, deriv, sing_tol, z, m, A, b, S, k1)
            if st != OK:
                return st, s, sv
            for i in range(n):
                y[i] = x[i] + h / 2 * k1[i]
            _inputs_at(s + h / 2, t, U, u)
            st, sv = derivative(y, u, coef, powers, deriv, sing_tol, z, m, A, b, S, k2)
            if st != OK:
                return st, s + h / 2, sv
            for i in range(n):
                y[i] = x[i] + h / 2 * k2[i]
            st, sv = derivative(y, u, coef, powers, deriv, sing_tol, z, m, A, b, S, k3)
            if st != OK:
                return st, s + h / 2, sv
            for i in range(n):
                y[i] = x[i] + h * k3[i]
            _inputs_at(s + h, t, U, u)
            st, sv = derivative(y, u, coef, powers, deriv, sing_tol, z, m, A, b, S, k4)
            if st != OK:
                return st, s + h, sv
            for i in range(n):
                x[i] = x[i] + h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i])
            s += h
        for i in range(n):
            X[i, k + 1] = x[i]
    for k in range(t.size):
        _inputs_at(t[k], t, U, u)
        st, sv = derivative(X[:, k].copy(), u, coef, powers, deriv, sing_tol, z, m, A, b, S, k1)
        if st != OK:
            return st, t[k], sv
        for i in range(n):
            XD[i, k] = k1[i]
    return OK, 0.0, 0.0


#: RK4's stability bound on the negative real axis: ``h |lambda|`` where ``|1 + z + z^2/2 +
#: z^3/6 + z^4/24| = 1`` at ``z = -h |lambda|`` (2.785...; the brief's "2.79").  A decaying
#: mode faster than ``RK4_STABILITY / h`` grows under RK4 at step ``h`` whatever the law.
RK4_STABILITY = 2.785293563405282


def stiffness(coef: np.ndarray, powers: np.ndarray, deriv: np.ndarray, x: np.ndarray,
              u: np.ndarray | None, sing_tol: float) -> float:
    """The largest ``|eigenvalue|`` of the implicit law's Jacobian ``d(dx)/dx`` [1/s] over the
    states ``x`` (n_states, n_samples) and inputs ``u`` (n_inputs, n_samples), vectorised.

    ``dx = -A^-1 b`` with ``A``, ``b`` as :func:`derivative` assembles them, so ``d(dx)/dx_v =
    -A^-1 (dA/dx_v dx + db/dx_v)``, each term's derivative from its powers (``k x^(k-1)``).
    Samples where ``A`` is singular (smallest singular value <= ``sing_tol``) or a figure is not
    finite are left out (the simulation names those); 0.0 if none is left.

    Parameters
    ----------
    coef : ndarray, shape (n_states, p)
    powers : ndarray of int, shape (p, n_states + n_inputs)
    deriv : ndarray of int, shape (p,)
        As :func:`rk4` takes them.
    x, u : ndarray
        The record's states and inputs (u None or empty for none).
    sing_tol : float

    Returns
    -------
    float
        The largest ``|lambda|`` [1/s].
    """
    n = x.shape[0]
    z = x if u is None or np.size(u) == 0 else np.vstack([x, u])
    D = np.zeros((powers.shape[0], n))
    has = deriv >= 0
    D[np.flatnonzero(has), deriv[has]] = 1.0
    C_d, C_f = coef * has, coef * ~has   # the derivative terms' and the others' coefficients

    def monomials(P: np.ndarray) -> np.ndarray:   # (p, n_samples)
        return np.prod(z[None, :, :] ** P[:, :, None], axis=1)

    with np.errstate(all="ignore"):
        m = monomials(powers)
        A = np.einsum("kj,jN,ji->Nki", C_d, m, D)
        b = (C_f @ m).T
        ok = np.all(np.isfinite(A), axis=(1, 2)) & np.all(np.isfinite(b), axis=1)
        smin = np.full(A.shape[0], -np.inf)
        smin[ok] = np.abs(A[ok, 0, 0]) if n == 1 else np.linalg.svd(A[ok], compute_uv=False).min(axis=1)
        ok &= smin > sing_tol
        if not ok.any():
            return 0.0
        A, b, zs = A[ok], b[ok], z[:, ok]
        f = np.linalg.solve(A, -b[:, :, None])[:, :, 0]   # (N, n)
        J = np.empty((A.shape[0], n, n))
        for v in range(n):
            lower = powers.copy()
            lower[:, v] = np.maximum(lower[:, v] - 1, 0)
            dm = powers[:, v][:, None] * np.prod(zs[None, :, :] ** lower[:, :, None], axis=1)
            dA = np.einsum("kj,jN,ji->Nki", C_d, dm, D)
            db = (C_f @ dm).T
            rhs = np.einsum("Nki,Ni->Nk", dA, f) + db
            J[:, :, v] = -np.linalg.solve(A, rhs[:, :, None])[:, :, 0]
        J = J[np.all(np.isfinite(J), axis=(1, 2))]
        lam = np.abs(J[:, 0, 0]) if n == 1 else np.abs(np.linalg.eigvals(J)).max(axis=1)
    return float(lam.max()) if lam.size else 0.0
