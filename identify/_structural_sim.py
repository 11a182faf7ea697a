"""Simulation of identified structural models ``M x'' + C x' + K x + K3 x^3 = B u``.

The linear part is discretised exactly (matrix exponential, zero-order-hold input) and
propagated without a Python loop over time; a cubic term switches to RK4 with sub-steps, run
by a compiled loop (:func:`identify._compiled.rk4_cubic`).
"""

from __future__ import annotations

import numpy as np

from testbed.core.errors import DivergenceError
from testbed.core.lazy import lazy_module
from testbed.core.measurement import Trajectory

linalg = lazy_module("scipy.linalg")  # imported on first use: `testbed list` does not pay for it


def _zoh_free_and_forced(A: np.ndarray, Bz: np.ndarray | None, z0: np.ndarray, dt: float, n_t: int,
                         w: np.ndarray | None) -> np.ndarray:
    """Exact ZOH discretisation of ``z' = A z + Bz w``, propagated in modal coordinates.

    Returns the states, shape (2n, n_t), at the sample times ``k dt``.
    """
    nz = A.shape[0]
    if Bz is None or w is None:
        aug = A
    else:
        aug = np.zeros((nz + Bz.shape[1], nz + Bz.shape[1]))
        aug[:nz, :nz], aug[:nz, nz:] = A, Bz
    E = linalg.expm(aug * dt)
    Phi = E[:nz, :nz]
    d, V = linalg.eig(Phi)
    if np.linalg.cond(V) > 1e10:  # defective (repeated) modes: step the recursion directly
        Z = np.empty((nz, n_t))
        Z[:, 0] = z0
        G = E[:nz, nz:] if w is not None else None
        for k in range(1, n_t):
            Z[:, k] = Phi @ Z[:, k - 1] + (G @ w[:, k - 1] if G is not None else 0.0)
        return Z
    q0 = linalg.solve(V, z0.astype(complex))
    q = q0[:, None] * d[:, None] ** np.arange(n_t)[None, :]
    if w is not None:
        G = E[:nz, nz:]
        r = linalg.solve(V, G @ w.astype(complex))  # modal input, (nz, n_t)
        from scipy import signal  # lazy: scipy.signal costs ~0.7 s of import

        for i in range(nz):  # q_k = d q_{k-1} + r_{k-1}: a first-order IIR filter per mode
            q[i] += signal.lfilter([0.0, 1.0], [1.0, -d[i]], r[i])
    return (V @ q).real


def simulate_structural(M: np.ndarray, C: np.ndarray, K: np.ndarray, K3: np.ndarray | None,
                        B: np.ndarray | None, x0: np.ndarray, xd0: np.ndarray, t: np.ndarray,
                        u: np.ndarray | None = None, max_omega_h: float = 0.1) -> Trajectory:
    """Integrate ``M x'' + C x' + K x + K3 x^3 = B u`` from ``(x0, xd0)`` at the times ``t``.

    Parameters
    ----------
    M, C, K : ndarray, shape (n, n)
        [kg], [N s/m], [N/m].
    K3 : ndarray, shape (n, n) or None
        Cubic stiffness [N/m^3]; None or all zero gives the linear model.
    B : ndarray, shape (n, n_inputs) or None
        Input map; required when ``u`` is given.
    x0, xd0 : ndarray, shape (n,)
        Initial displacement [m] and velocity [m/s] at ``t[0]``.
    t : ndarray, shape (n_t,)
        Equally spaced sample times [s].
    u : ndarray, shape (n_inputs, n_t), optional
        Input [N], held constant over each sample interval (zero-order hold).
    max_omega_h : float
        Cubic model only: RK4 sub-steps are chosen so that ``h * max|eig(A)| <= max_omega_h``
        (phase error per step ~ (omega h)^5 / 120).

    Returns
    -------
    Trajectory
        ``x`` [m], ``xd`` [m/s], ``xdd`` [m/s^2], each (n, n_t); ``xdd`` is evaluated from the
        equation of motion at each sample.

    Notes
    -----
    The linear model is discretised exactly (matrix exponential with a zero-order-hold input)
    and propagated in the eigenbasis of the transition matrix, vectorised over time (no
    per-sample Python loop).  With a cubic term the full model is integrated with classical
    RK4 at sub-steps of the sample interval; the input is held over each interval.

    Raises
    ------
    DivergenceError
        Cubic model only: the state became non-finite; ``time`` [s] is the start of the
        sample interval in which it happened.
    """
    M, C, K = (np.asarray(a, dtype=float) for a in (M, C, K))
    n = M.shape[0]
    t = np.asarray(t, dtype=float)
    n_t = t.size
    x0 = np.asarray(x0, dtype=float).reshape(n)
    xd0 = np.asarray(xd0, dtype=float).reshape(n)
    dt = float(t[1] - t[0]) if n_t > 1 else 1.0
    if n_t > 2 and not np.allclose(np.diff(t), dt, rtol=1e-6, atol=0.0):
        raise ValueError("t must be equally spaced")
    Minv = np.linalg.inv(M)
    f = None
    if u is not None:
        if B is None:
            raise ValueError("the model has no input map (no input in the fitted data); cannot apply u")
        u = np.atleast_2d(np.asarray(u, dtype=float))
        if u.shape != (B.shape[1], n_t):
            raise ValueError(f"u must have shape {(B.shape[1], n_t)}, got {u.shape}")
        f = np.asarray(B, dtype=float) @ u  # (n, n_t) force [N]
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    z0 = np.concatenate([x0, xd0])
    nonlinear = K3 is not None and np.any(np.asarray(K3) != 0.0)
    if not nonlinear:
        Bz = np.vstack([np.zeros((n, n)), Minv]) if f is not None else None
        Z = _zoh_free_and_forced(A, Bz, z0, dt, n_t, f)
        x, xd = Z[:n], Z[n:]
        xdd = -Minv @ (C @ xd + K @ x) + (Minv @ f if f is not None else 0.0)
        return Trajectory(x, xd, xdd)
    MK3 = Minv @ np.asarray(K3, dtype=float)
    MF = Minv @ f if f is not None else np.zeros((n, n_t))
    rho = float(np.max(np.abs(np.linalg.eigvals(A)))) if n_t > 1 else 0.0
    sub = max(1, int(np.ceil(rho * dt / max_omega_h)))
    h = dt / sub
    from identify._compiled import rk4_cubic  # lazy: numba's import costs ~0.4 s

    Z = np.empty((2 * n, n_t))
    bad = rk4_cubic(np.ascontiguousarray(A), np.ascontiguousarray(MK3), np.ascontiguousarray(MF),
                    z0, h, sub, Z)
    if bad >= 0:
        raise DivergenceError("cubic structural model diverged (state not finite)",
                              time=float(t[bad - 1]))
    x, xd = Z[:n], Z[n:]
    xdd = -Minv @ (C @ xd + K @ x) - MK3 @ x**3 + MF
    return Trajectory(x, xd, xdd)
