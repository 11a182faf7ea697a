"""Exact response of linear structures ``M x'' + C x' + K x = B u``: the state matrix and the
zero-order-hold discretisation, propagated in the transition's eigenbasis without a Python loop
over time.

One implementation, below the layers that use it: the structural identifiers' simulation
(:func:`identify._structural_sim.simulate_structural`, whose linear branch this is) and the
scorer's floor, the truth's own reduced model simulated as an identified one would be
(:func:`testbed.scoring.scorers.truth_trac`).
"""

from __future__ import annotations

import threading
from dataclasses import dataclass

import numpy as np

from testbed.core.lazy import lazy_module
from testbed.core.measurement import Trajectory

linalg = lazy_module("scipy.linalg")  # imported on first use: `testbed list` does not pay for it

__all__ = ["prepare_inputs", "simulate_linear", "state_matrix", "zoh_free_and_forced"]

#: Largest modal power table kept between calls [bytes] (a 3-sensor beam at 12.8 kHz for 1 s
#: needs 1.2 MB; a sweep's longest records stay far below this bound, beyond it nothing is kept).
KEEP_BYTES = 1 << 26

@dataclass
class _Propagator:
    """What :func:`zoh_free_and_forced` computes from the model, step and input alone (not the
    start): the transition, its eigen-decomposition, the modal powers and the modal forced
    response.  The scorer's initial-state fit simulates one model from 2n + 3 starts over the
    same window and input; each start then costs a solve and a product."""

    A: np.ndarray
    Bz: np.ndarray | None
    dt: float
    n_t: int
    w: np.ndarray | None
    E: np.ndarray
    d: np.ndarray | None = None        # eigenvalues of the transition, (nz,); None: defective
    V: np.ndarray | None = None        # its eigenvectors, (nz, nz)
    powers: np.ndarray | None = None   # d_i^k, (nz, n_t)
    forced: np.ndarray | None = None   # modal response to the input from rest, (nz, n_t)

    def same(self, A: np.ndarray, Bz: np.ndarray | None, dt: float, n_t: int,
             w: np.ndarray | None) -> bool:
        """True if built from exactly these inputs (bit for bit)."""
        def eq(a: np.ndarray | None, b: np.ndarray | None) -> bool:
            return (a is None) == (b is None) and (a is None or (
                a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()))
        return dt == self.dt and n_t == self.n_t and eq(A, self.A) and eq(Bz, self.Bz) and eq(w, self.w)


_LAST = threading.local()  # the last propagator of this thread (sweeps may run cells in threads)


def _propagator(A: np.ndarray, Bz: np.ndarray | None, dt: float, n_t: int,
                w: np.ndarray | None) -> _Propagator:
    """The :class:`_Propagator` of these inputs: the last one if built from the same, else new."""
    last = getattr(_LAST, "value", None)
    if last is not None and last.same(A, Bz, dt, n_t, w):
        return last
    nz = A.shape[0]
    if Bz is None or w is None:
        aug = A
    else:
        aug = np.zeros((nz + Bz.shape[1], nz + Bz.shape[1]))
        aug[:nz, :nz], aug[:nz, nz:] = A, Bz
    E = linalg.expm(aug * dt)
    p = _Propagator(A.copy(), None if Bz is None else Bz.copy(), dt, n_t,
                    None if w is None else w.copy(), E)
    d, V = linalg.eig(E[:nz, :nz])
    if not np.linalg.cond(V) > 1e10:  # else defective (repeated) modes: stepped directly
        p.d, p.V = d, V
        p.powers = d[:, None] ** np.arange(n_t)[None, :]
        if w is not None:
            r = linalg.solve(V, E[:nz, nz:] @ w.astype(complex))  # modal input, (nz, n_t)
            from scipy import signal  # lazy: scipy.signal costs ~0.7 s of import

            # q_k = d q_{k-1} + r_{k-1}: a first-order IIR filter per mode
            p.forced = np.array([signal.lfilter([0.0, 1.0], [1.0, -d[i]], r[i]) for i in range(nz)])
    _LAST.value = p if p.powers is None or p.powers.nbytes <= KEEP_BYTES else None
    return p


def zoh_free_and_forced(A: np.ndarray, Bz: np.ndarray | None, z0: np.ndarray, dt: float, n_t: int,
                         w: np.ndarray | None) -> np.ndarray:
    """Exact ZOH discretisation of ``z' = A z + Bz w``, propagated in modal coordinates.

    ``A`` (nz, nz), ``Bz`` (nz, m) or None, ``z0`` (nz,), ``w`` (m, n_t) or None; ``dt`` [s].
    Returns the states, shape (nz, n_t), at the sample times ``k dt``.  Everything but the
    start is kept from the previous call of the thread when its inputs are the same bit for bit
    (:class:`_Propagator`): the result is the same number for number as computed afresh.
    """
    if Bz is None or w is None:
        Bz = w = None
    p = _propagator(A, Bz, dt, n_t, w)
    nz = A.shape[0]
    if p.powers is None:  # defective (repeated) modes: step the recursion directly
        Phi = p.E[:nz, :nz]
        Z = np.empty((nz, n_t))
        Z[:, 0] = z0
        G = p.E[:nz, nz:] if w is not None else None
        for k in range(1, n_t):
            Z[:, k] = Phi @ Z[:, k - 1] + (G @ w[:, k - 1] if G is not None else 0.0)
        return Z
    q = linalg.solve(p.V, z0.astype(complex))[:, None] * p.powers
    if p.forced is not None:
        q += p.forced
    return (p.V @ q).real


def state_matrix(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> np.ndarray:
    """The first-order form ``A = [[0, I], [-M^-1 K, -M^-1 C]]`` of ``M x'' + C x' + K x``.

    Parameters
    ----------
    M, C, K : ndarray, shape (n, n)
        [kg], [N s/m], [N/m] (``M`` invertible).

    Returns
    -------
    ndarray, shape (2 n, 2 n)
        [1/s] and [1/s^2] blocks; its eigenvalues are the linear model's poles [rad/s].
    """
    M, C, K = (np.asarray(a, dtype=float) for a in (M, C, K))
    n = M.shape[0]
    Minv = np.linalg.inv(M)
    return np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])


def prepare_inputs(M: np.ndarray, C: np.ndarray, K: np.ndarray, B: np.ndarray | None,
                   x0: np.ndarray, xd0: np.ndarray, t: np.ndarray, u: np.ndarray | None
                   ) -> tuple[np.ndarray, ...]:
    """A structural simulation's inputs checked and converted (one rule for every integrator).

    Parameters are those of :func:`simulate_linear`.

    Returns
    -------
    tuple
        ``(M, C, K, x0, xd0, t, dt, Minv, f)``: float arrays, the sample interval ``dt`` [s]
        (1 for a single sample), ``M^-1`` and the force ``f = B u`` [N], shape (n, n_t), or
        None without an input.

    Raises
    ------
    ValueError
        Unequally spaced ``t``, an input without an input map, or ``u`` of the wrong shape.
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
    return M, C, K, x0, xd0, t, dt, Minv, f


def simulate_linear(M: np.ndarray, C: np.ndarray, K: np.ndarray, B: np.ndarray | None,
                    x0: np.ndarray, xd0: np.ndarray, t: np.ndarray,
                    u: np.ndarray | None = None) -> Trajectory:
    """Exact response of ``M x'' + C x' + K x = B u`` from ``(x0, xd0)`` at the times ``t``.

    Parameters
    ----------
    M, C, K : ndarray, shape (n, n)
        [kg], [N s/m], [N/m] (``M`` invertible).
    B : ndarray, shape (n, n_inputs) or None
        Input map; required when ``u`` is given.
    x0, xd0 : ndarray, shape (n,)
        Initial displacement [m] and velocity [m/s] at ``t[0]``.
    t : ndarray, shape (n_t,)
        Equally spaced sample times [s].
    u : ndarray, shape (n_inputs, n_t), optional
        Input [N], held constant over each sample interval (zero-order hold).

    Returns
    -------
    Trajectory
        ``x`` [m], ``xd`` [m/s], ``xdd`` [m/s^2], each (n, n_t); ``xdd`` from the equation of
        motion at each sample.
    """
    M, C, K, x0, xd0, t, dt, Minv, f = prepare_inputs(M, C, K, B, x0, xd0, t, u)
    n, n_t = M.shape[0], t.size
    A = state_matrix(M, C, K)
    Bz = np.vstack([np.zeros((n, n)), Minv]) if f is not None else None
    Z = zoh_free_and_forced(A, Bz, np.concatenate([x0, xd0]), dt, n_t, f)
    x, xd = Z[:n], Z[n:]
    xdd = -Minv @ (C @ xd + K @ x) + (Minv @ f if f is not None else 0.0)
    return Trajectory(x, xd, xdd)
