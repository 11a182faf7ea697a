"""Reference for tests only: the Python implementation of identified-model simulation that the
compiled kernels (identify/_compiled.py) replaced, kept verbatim to check them to round-off."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.interpolate import CubicHermiteSpline

from identify.library import Library
from testbed.core.errors import IdentificationError
from testbed.core.measurement import Trajectory

#: A closure fitted or declared must close the measured loop to this fraction of the longest
#: link: 1e-3 covers angle noise of about 1e-3 rad, while a wrong sign convention or a wrong
#: link length leaves a residual of order one.
CLOSURE_RTOL = 1e-3


def _solve2(j11, j12, j21, j22, r1, r2):
    """Solve [[j11, j12], [j21, j22]] z = r sample-wise (arrays of shape (N,))."""
    det = j11 * j22 - j12 * j21
    if np.any(np.abs(det) < 1e-12 * max(np.abs(j11).max(), np.abs(j22).max(), 1e-300)):
        raise IdentificationError("loop closure is singular (passive links collinear)")
    return (j22 * r1 - j12 * r2) / det, (j11 * r2 - j21 * r1) / det


@dataclass
class LoopClosure:
    """A planar single-loop closure ``sum_i a_i e(th_i) = b`` in absolute link angles.

    Attributes
    ----------
    a : ndarray, shape (n,)
        Signed link lengths [m] (or ratios if fitted from data).
    b : ndarray, shape (2,)
        Base vector in the same units.
    passive : ndarray of int, shape (2,)
        The coordinates solved from the closure.
    source : str
        ``"prior"`` or ``"data"`` and why.
    """

    a: np.ndarray
    b: np.ndarray
    passive: np.ndarray
    source: str

    @classmethod
    def from_prior(cls, prior: dict[str, Any], passive: np.ndarray) -> LoopClosure | None:
        """Paper convention (its Eqs. 2-3): ``l1 e1 + l2 e2 - l3 e3 - l4 e4 = (L0, 0)``.

        Keys: ``l1``..``l4`` and ``L0`` [m] (what the five-bar rig declares), or
        ``link_lengths`` [l1, l2, l3, l4] and ``base_length`` (``l0`` also accepted).  None if
        the link lengths or the base length are absent.
        """
        if all(f"l{i}" in prior for i in range(1, 5)):
            ll, src = np.array([float(prior[f"l{i}"]) for i in range(1, 5)]), "l1..l4"
        elif "link_lengths" in prior:
            ll, src = np.asarray(prior["link_lengths"], dtype=float).ravel(), "link_lengths"
        else:
            return None
        key = next((k for k in ("L0", "base_length", "l0") if k in prior), None)
        if key is None or ll.size != 4:
            return None
        return cls(ll * np.array([1.0, 1.0, -1.0, -1.0]), np.array([float(prior[key]), 0.0]),
                   np.asarray(passive), f"prior ({src}, {key})")

    @classmethod
    def from_data(cls, x: np.ndarray, passive: np.ndarray, strict: bool = True) -> LoopClosure:
        """Fit ``a`` and ``b`` (up to scale) as the null vector of the stacked closure rows.

        With ``strict`` (default) raise unless the smallest singular value is below 1e-3 of the
        next (a clear null direction); ``strict=False`` returns the least-squares fit anyway (to
        measure the noise floor of the closure residual).
        """
        n, N = x.shape
        stride = max(1, N // 20000)  # 20k samples determine 6 numbers amply
        xs = x[:, ::stride]
        rows = np.concatenate([np.hstack([np.cos(xs).T, -np.ones((xs.shape[1], 1)),
                                          np.zeros((xs.shape[1], 1))]),
                               np.hstack([np.sin(xs).T, np.zeros((xs.shape[1], 1)),
                                          -np.ones((xs.shape[1], 1))])])
        _, sv, Vt = np.linalg.svd(rows, full_matrices=False)
        if strict and sv[-1] > 1e-3 * sv[-2]:
            raise IdentificationError(
                "no loop closure fits the measured angles (smallest singular values "
                f"{sv[-2]:.3g}, {sv[-1]:.3g})")
        v = Vt[-1] / np.abs(Vt[-1, :n]).max()
        v = v * np.sign(v[0])  # sign convention: first link positive
        return cls(v[:n], v[n:], np.asarray(passive), "data (null vector of the closure rows)")

    def __post_init__(self) -> None:
        self.active = np.setdiff1d(np.arange(self.a.size), self.passive)

    def residual(self, x: np.ndarray, rms: bool = False) -> float:
        """Largest (or with ``rms`` the RMS) closure error on the samples, relative to the
        longest link."""
        gx = self.a @ np.cos(x) - self.b[0]
        gy = self.a @ np.sin(x) - self.b[1]
        if rms:
            return float(np.sqrt(np.mean(gx**2 + gy**2)) / np.abs(self.a).max())
        return float(max(np.abs(gx).max(), np.abs(gy).max()) / np.abs(self.a).max())

    def _jac(self, q: np.ndarray) -> tuple[np.ndarray, ...]:
        c, s = np.cos(q), np.sin(q)
        return c, s, -self.a[:, None] * s, self.a[:, None] * c  # columns a_i n(th_i) = (jx, jy)

    def solve(self, q: np.ndarray, tol: float = 1e-13, max_iter: int = 30) -> np.ndarray:
        """Passive angles for the actuated ones in ``q`` (n, N), passive rows as the guess."""
        q = np.array(q, dtype=float)
        p0, p1 = self.passive
        for _ in range(max_iter):
            c, s, jx, jy = self._jac(q)
            z0, z1 = _solve2(jx[p0], jx[p1], jy[p0], jy[p1],
                             self.a @ c - self.b[0], self.a @ s - self.b[1])
            q[p0] -= z0
            q[p1] -= z1
            if max(np.abs(z0).max(), np.abs(z1).max()) < tol:
                return q
        raise IdentificationError("loop closure Newton solve did not converge (no assembly)")

    def velocity(self, q: np.ndarray, dq: np.ndarray) -> np.ndarray:
        """``dq`` with the passive rows replaced by the rates consistent with the closure."""
        dq = np.array(dq, dtype=float)
        _, _, jx, jy = self._jac(q)
        p0, p1 = self.passive
        act = self.active
        dq[p0], dq[p1] = _solve2(jx[p0], jx[p1], jy[p0], jy[p1], -(jx[act] * dq[act]).sum(0),
                                 -(jy[act] * dq[act]).sum(0))
        return dq

    def reconcile(self, q: np.ndarray, dq: np.ndarray, ddq: np.ndarray
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Measured (n, N) angles, rates, accelerations with the passive rows replaced by those
        the closure implies from the actuated rows (measured passive angles as Newton guess).

        Data reconciliation with the known geometry: the returned samples lie exactly on the
        loop manifold, so its kinematic identities hold exactly among library columns again
        (on noisy, smoothed angles they hold only to the noise level and cannot be told apart
        from genuine near-dependencies).
        """
        q = self.solve(q)
        dq = self.velocity(q, dq)
        ddq = np.array(ddq, dtype=float)
        P, r = self.acceleration_map(q, dq)
        ddq[self.passive] = ((P @ ddq[self.active].T[..., None])[..., 0] + r).T
        return q, dq, ddq

    def acceleration_map(self, q: np.ndarray, dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``ddq_p = P ddq_a + r``: P (N, 2, n_a), r (N, 2)."""
        c, s, jx, jy = self._jac(q)
        p0, p1 = self.passive
        J = (jx[p0], jx[p1], jy[p0], jy[p1])
        w2 = self.a[:, None] * dq**2
        r = _solve2(*J, (w2 * c).sum(0), (w2 * s).sum(0))
        P = np.empty((q.shape[1], 2, self.active.size))
        for m, j in enumerate(self.active):
            P[:, 0, m], P[:, 1, m] = _solve2(*J, -jx[j], -jy[j])
        return P, np.stack(r, axis=1)


class ImplicitModel:
    """Implicit equations ``coef @ Theta(q, dq, ddq, u) = 0`` solved for accelerations.

    Parameters
    ----------
    library : Library
        The terms used by ``coef`` (columns of coef).
    coef : ndarray, shape (n_eq, n_terms)
        One implicit equation per actuated coordinate.
    actuated : ndarray of int, shape (n_eq,)
        Coordinates whose accelerations the equations are solved for.
    closure : LoopClosure or None
        Required when there are coordinates that are not actuated.
    """

    def __init__(self, library: Library, coef: np.ndarray, actuated: np.ndarray,
                 closure: LoopClosure | None):
        used = np.flatnonzero(np.any(coef != 0, axis=0))
        self.library = library.subset([library.names[c] for c in used])
        self.coef = np.asarray(coef, dtype=float)[:, used]
        self.actuated = np.asarray(actuated, dtype=np.intp)
        self.closure = closure
        n = library.n_coords
        rest = np.setdiff1d(np.arange(n), self.actuated)
        if closure is None and rest.size:
            raise IdentificationError(f"coordinates {rest.tolist()} are neither actuated nor "
                                      "given by a loop closure: the model cannot be simulated")
        if self.coef.shape[0] != self.actuated.size:
            raise IdentificationError(f"{self.coef.shape[0]} equations for "
                                      f"{self.actuated.size} actuated coordinates")

    def accelerations(self, q: np.ndarray, dq: np.ndarray, u: np.ndarray | None) -> np.ndarray:
        """Accelerations (n, N) at consistent states q, dq (n, N) under inputs u (m, N)."""
        free, acc = self.library.evaluate_parts(q, dq, u)
        f = free @ self.coef.T                                   # (N, n_eq)
        A = np.einsum("knp,ep->nek", acc, self.coef)             # (N, n_eq, n)
        act = self.actuated
        Ared, rhs = A[:, :, act], -f
        if self.closure is not None:
            pas = self.closure.passive
            P, r = self.closure.acceleration_map(q, dq)
            Ared = Ared + A[:, :, pas] @ P
            rhs = rhs - np.einsum("nep,np->ne", A[:, :, pas], r)
        try:
            dda = np.linalg.solve(Ared, rhs[..., None])[..., 0]
        except np.linalg.LinAlgError as exc:
            raise IdentificationError("identified equations are singular in the "
                                      "accelerations") from exc
        ddq = np.zeros_like(np.asarray(q, dtype=float))
        ddq[act] = dda.T
        if self.closure is not None:
            ddq[self.closure.passive] = (P @ dda[..., None])[..., 0].T + r.T
        return ddq

    def _complete(self, q: np.ndarray, dq: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if self.closure is None:
            return q, dq
        q = self.closure.solve(q)
        return q, self.closure.velocity(q, dq)

    def simulate(self, x0: np.ndarray, xd0: np.ndarray, t: np.ndarray, u: np.ndarray | None,
                 dt: float, input_hold: str = "linear") -> Trajectory:
        """Free simulation by RK4 with step <= dt [s]; output at the times t (cubic Hermite).

        ``input_hold`` says what the sampled inputs stand for: ``"linear"`` a continuous signal
        (linear interpolation between samples); ``"zoh"`` a zero-order hold (each sample held
        until the next, as an actuator driven by a DAC does).  A hold of a smooth signal is
        that signal delayed by half a sample plus zero-mean ripple, so ``"zoh"`` interpolates
        the samples delayed by half an interval: the input's integral over every RK4 step is
        then right to O(interval^2), whatever the step.  Taking a held input for a linear one
        adds an impulse ``u(0) / (2 fs)`` at the start; on the five-bar multisine record
        (10 kHz) the exact equations then drift by 5e-4 rad over 10 s; with ``"zoh"`` they stay
        within 6e-7 rad at dt = 1 ms (8e-8 rad at 0.25 ms: what is left is RK4 sampling the input).
        """
        t = np.asarray(t, dtype=float)
        n_steps = max(1, int(np.ceil((t[-1] - t[0]) / dt - 1e-9)))
        h = (t[-1] - t[0]) / n_steps
        tt = t[0] + 0.5 * h * np.arange(2 * n_steps + 1)
        if input_hold not in ("linear", "zoh"):
            raise ValueError(f"input_hold must be 'linear' or 'zoh', got {input_hold!r}")
        delay = 0.5 * (t[1] - t[0]) if input_hold == "zoh" and t.size > 1 else 0.0
        uu = None if u is None else np.stack([np.interp(tt - delay, t, row) for row in np.atleast_2d(u)])
        act = self.actuated
        q, dq = self._complete(np.array(x0, float)[:, None], np.array(xd0, float)[:, None])
        Q = np.empty((n_steps + 1, q.shape[0]))
        DQ, DDQ = np.empty_like(Q), np.empty_like(Q)

        def rhs(qa, dqa, k):
            q[act, 0], dq[act, 0] = qa, dqa
            qc, dqc = self._complete(q, dq)
            q[:], dq[:] = qc, dqc
            ddq = self.accelerations(qc, dqc, None if uu is None else uu[:, k:k + 1])
            return dqc[act, 0].copy(), ddq[act, 0], ddq[:, 0]

        ya, va = q[act, 0].copy(), dq[act, 0].copy()
        for s in range(n_steps):
            k1x, k1v, full = rhs(ya, va, 2 * s)
            Q[s], DQ[s], DDQ[s] = q[:, 0], dq[:, 0], full
            k2x, k2v, _ = rhs(ya + 0.5 * h * k1x, va + 0.5 * h * k1v, 2 * s + 1)
            k3x, k3v, _ = rhs(ya + 0.5 * h * k2x, va + 0.5 * h * k2v, 2 * s + 1)
            k4x, k4v, _ = rhs(ya + h * k3x, va + h * k3v, 2 * s + 2)
            ya = ya + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x)
            va = va + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
            if not (np.all(np.isfinite(ya)) and np.all(np.isfinite(va))):
                raise IdentificationError(f"simulation diverged at t = {t[0] + s * h:.4g} s")
        _, _, full = rhs(ya, va, 2 * n_steps)
        Q[-1], DQ[-1], DDQ[-1] = q[:, 0], dq[:, 0], full
        tg = t[0] + h * np.arange(n_steps + 1)
        qa = CubicHermiteSpline(tg, Q[:, act], DQ[:, act])(t).T
        va_ = CubicHermiteSpline(tg, DQ[:, act], DDQ[:, act])(t).T
        x = np.empty((Q.shape[1], t.size))
        xd = np.empty_like(x)
        for j in range(Q.shape[1]):  # passive rows: linear guesses, refined by the closure
            x[j], xd[j] = np.interp(t, tg, Q[:, j]), np.interp(t, tg, DQ[:, j])
        x[act], xd[act] = qa, va_
        x, xd = self._complete(x, xd)
        u_t = None if u is None else np.atleast_2d(u)
        return Trajectory(x, xd, self.accelerations(x, xd, u_t))
