"""Synthetic implicit-identification problems with exact truth, for SINDy-PI tests and benchmarks.

- :func:`double_pendulum`: a forced, damped double pendulum under gravity (point masses,
  absolute angles; inertia coupling through ``cos(th1-th2)`` as in the five-bar's chains).
- :func:`fivebar`: a planar five-bar of uniform rods, no gravity, absolute joint damping,
  torques u1 on th1 and u2 on th4, integrated as an index-1 DAE (KKT system with Baumgarte
  stabilisation).  Its reduced equation of actuated joint k, obtained by eliminating the two
  loop forces with the passive rows, is
  ``a2 a3 sin(th2-th3) R_k = a_k a3 sin(th_k-th3) R2 - a_k a2 sin(th_k-th2) R3``
  (``a = (l1, l2, -l3, -l4)``, R_i the open-chain Lagrange expressions minus inputs); it holds
  exactly at every sample because the recorded accelerations solve the KKT system.

Both integrate with scipy's DOP853 (rtol = atol = 1e-11) and record exact rates and
accelerations (from the right-hand side) at ``fs``.  Truth: term names (canonical) and
coefficient rows scaled to max |coef| = 1 with that entry positive.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from testbed.core.measurement import Measurement
from testbed.core.terms import canonical


@dataclass
class Problem:
    """Measurement plus exact implicit equations (``truth_coef @ Theta[truth_terms] = 0``)."""

    data: Measurement
    truth_terms: list[str]
    truth_coef: np.ndarray


@functools.cache
def _phases(seed: int, n: int) -> np.ndarray:
    """The ``n`` seeded phases [rad] of :func:`multisine`, drawn once per (seed, n): the
    right-hand sides call it at every sample, where seeding a generator each time was most of
    the cost of a record.  Read-only, shape (n,)."""
    ph = np.random.default_rng(seed).uniform(0, 2 * np.pi, n)
    ph.flags.writeable = False
    return ph


def multisine(t: np.ndarray, amp: float, freqs: np.ndarray, seed: int) -> np.ndarray:
    """Sum of sines with seeded phases: amp * sum_f sin(2 pi f t + phi_f) / sqrt(n_f)."""
    ph = _phases(seed, freqs.size)
    return amp * np.sin(2 * np.pi * freqs[:, None] * np.atleast_1d(t)[None] + ph[:, None]).sum(0) \
        / np.sqrt(freqs.size)


def _truth(eqs: list[dict[str, float]]) -> tuple[list[str], np.ndarray]:
    names = sorted({k for e in eqs for k in e})
    coef = np.array([[e.get(k, 0.0) for k in names] for e in eqs])
    coef /= coef[np.arange(len(eqs)), np.argmax(np.abs(coef), axis=1)][:, None]
    return names, coef


def _add(eq: dict[str, float], term: str, c: float) -> None:
    name, sign = canonical(term)
    eq[name] = eq.get(name, 0.0) + sign * c


def _record(rhs, y0, fs, duration):
    t = np.arange(round(duration * fs) + 1) / fs
    sol = solve_ivp(rhs, (0, t[-1]), y0, method="DOP853", t_eval=t, rtol=1e-11, atol=1e-11)
    if not sol.success:
        raise RuntimeError(sol.message)
    dy = np.stack([rhs(tk, yk) for tk, yk in zip(t, sol.y.T, strict=True)], axis=1)
    n = len(y0) // 2
    return t, sol.y[:n], sol.y[n:], dy[n:]


def double_pendulum(duration: float = 3.0, fs: float = 1e4, amp: float = 4.0, seed: int = 0,
                    m=(1.0, 0.8), l=(1.0, 0.7), c=(0.3, 0.2), g: float = 9.81) -> Problem:
    """Forced damped double pendulum (u1 on th1, u2 on th2), exact signals at fs [Hz]."""
    m1, m2 = m
    l1, l2 = l
    freqs = np.array([0.3, 0.7, 1.3, 2.1])

    def u_of(t):
        return np.array([multisine(t, amp, freqs, seed), multisine(t, 0.6 * amp, freqs, seed + 1)])

    def rhs(t, y):
        th1, th2, w1, w2 = y
        u1, u2 = u_of(t)[:, 0] if np.ndim(t) == 0 else u_of(t)
        d = th1 - th2
        M = np.array([[(m1 + m2) * l1**2, m2 * l1 * l2 * np.cos(d)],
                      [m2 * l1 * l2 * np.cos(d), m2 * l2**2]])
        f = np.array([u1 - m2 * l1 * l2 * np.sin(d) * w2**2 - (m1 + m2) * g * l1 * np.sin(th1) - c[0] * w1,
                      u2 + m2 * l1 * l2 * np.sin(d) * w1**2 - m2 * g * l2 * np.sin(th2) - c[1] * w2])
        return np.concatenate(([w1, w2], np.linalg.solve(M, f)))  # (np.r_ is slower per call)

    t, x, xd, xdd = _record(rhs, np.zeros(4), fs, duration)
    k = m2 * l1 * l2
    eq1 = {"ddth1": (m1 + m2) * l1**2, "cos(th1-th2)*ddth2": k, "sin(th1-th2)*dth2^2": k,
           "sin(th1)": (m1 + m2) * g * l1, "dth1": c[0], "u1": -1.0}
    eq2 = {"ddth2": m2 * l2**2, "cos(th1-th2)*ddth1": k, "sin(th1-th2)*dth1^2": -k,
           "sin(th2)": m2 * g * l2, "dth2": c[1], "u2": -1.0}
    names, coef = _truth([eq1, eq2])
    data = Measurement(fs=fs, x=x, xd=xd, xdd=xdd, channels=("th1", "th2"), u=u_of(t),
                       inputs=("u1", "u2"), input_map=np.eye(2))
    return Problem(data, names, coef)


FIVEBAR_CHAINS = ((0, 1), (3, 2))  # (base, distal) coordinates of chains A and B, 0-based


def fivebar(duration: float = 3.0, fs: float = 1e4, amp: float = 0.4, seed: int = 0,
            lengths=(1.0, 1.0, 1.0, 1.0), base: float = 1.0, masses=(1.0, 1.0, 1.0, 1.0),
            damping=(0.05, 0.05, 0.05, 0.05), q0=(2.0, 1.1)) -> Problem:
    """Planar five-bar (see the module docstring); ``q0`` = initial (th1, th4) [rad]."""
    L, ms, cd = np.asarray(lengths, float), np.asarray(masses, float), np.asarray(damping, float)
    a = L * np.array([1.0, 1.0, -1.0, -1.0])
    b = np.array([base, 0.0])
    freqs = np.array([0.2, 0.45, 0.9, 1.6])

    def u_of(t):
        return np.array([multisine(t, amp, freqs, seed), multisine(t, amp, freqs, seed + 1)])

    def rhs(t, y):
        q, w = y[:4], y[4:]
        u = u_of(t)[:, 0]
        M, h = np.zeros((4, 4)), cd * w
        for (i, j) in FIVEBAR_CHAINS:
            k = ms[j] * L[i] * L[j] / 2
            M[i, i] += ms[i] * L[i] ** 2 / 3 + ms[j] * L[i] ** 2
            M[j, j] += ms[j] * L[j] ** 2 / 3
            M[i, j] = M[j, i] = k * np.cos(q[i] - q[j])
            h[i] += k * np.sin(q[i] - q[j]) * w[j] ** 2
            h[j] -= k * np.sin(q[i] - q[j]) * w[i] ** 2
        e, n = np.stack([np.cos(q), np.sin(q)]), np.stack([-np.sin(q), np.cos(q)])
        J = a * n
        g = e @ a - b
        gamma = (a * e) @ w**2 - 2 * 20.0 * (J @ w) - 20.0**2 * g  # Baumgarte, alpha = 20 1/s
        K = np.block([[M, -J.T], [J, np.zeros((2, 2))]])
        tau = np.array([u[0], 0.0, 0.0, u[1]])
        return np.concatenate((w, np.linalg.solve(K, np.concatenate((tau - h, gamma)))[:4]))

    q = np.array([q0[0], 1.0, 2.0, q0[1]])
    for _ in range(50):  # assemble the passive angles th2, th3 (Newton)
        e, n = np.stack([np.cos(q), np.sin(q)]), np.stack([-np.sin(q), np.cos(q)])
        q[1:3] -= np.linalg.solve((a * n)[:, 1:3], e @ a - b)
    t, x, xd, xdd = _record(rhs, np.r_[q, np.zeros(4)], fs, duration)
    eqs = []
    for k, uk in ((0, "u1"), (3, "u2")):
        R: list[dict[str, float]] = [{} for _ in range(4)]
        for (i, j) in FIVEBAR_CHAINS:
            kk = ms[j] * L[i] * L[j] / 2
            cij, sij = f"cos(th{i + 1}-th{j + 1})", f"sin(th{i + 1}-th{j + 1})"
            for tgt, terms in ((i, [(f"ddth{i + 1}", ms[i] * L[i] ** 2 / 3 + ms[j] * L[i] ** 2),
                                    (f"{cij}*ddth{j + 1}", kk), (f"{sij}*dth{j + 1}^2", kk)]),
                               (j, [(f"ddth{j + 1}", ms[j] * L[j] ** 2 / 3),
                                    (f"{cij}*ddth{i + 1}", kk), (f"{sij}*dth{i + 1}^2", -kk)])):
                for term, cval in terms:
                    _add(R[tgt], term, cval)
        for i in range(4):
            _add(R[i], f"dth{i + 1}", cd[i])
        _add(R[k], uk, -1.0)
        eq: dict[str, float] = {}
        for fac, Ri, w in (("sin(th2-th3)", R[k], a[1] * a[2]),
                           (f"sin(th{k + 1}-th3)", R[1], -a[k] * a[2]),
                           (f"sin(th{k + 1}-th2)", R[2], a[k] * a[1])):
            for term, cval in Ri.items():
                _add(eq, f"{fac}*{term}", w * cval)
        eqs.append({n_: v for n_, v in eq.items() if v != 0.0})
    names, coef = _truth(eqs)
    imap = np.zeros((4, 2))
    imap[0, 0] = imap[3, 1] = 1.0
    data = Measurement(fs=fs, x=x, xd=xd, xdd=xdd, channels=("th1", "th2", "th3", "th4"),
                       u=u_of(t), inputs=("u1", "u2"), input_map=imap,
                       prior={"link_lengths": list(L), "base_length": base})
    return Problem(data, names, coef)


def aligned_errors(names: list[str], coef: np.ndarray, truth_terms: list[str],
                   truth_coef: np.ndarray) -> tuple[float, float]:
    """Support F1 and largest relative coefficient error of identified vs true rows.

    Each identified row is matched to its true row by order (one per input) and scaled by the
    least-squares factor onto the true row (implicit equations have no scale or sign).
    """
    col = {n: i for i, n in enumerate(names)}
    tp = fp = fn = 0
    worst = 0.0
    for r in range(truth_coef.shape[0]):
        full = np.zeros(len(names))
        for n_, v in zip(truth_terms, truth_coef[r], strict=True):
            full[col[n_]] = v
        est = coef[r]
        alpha = (est @ full) / max(est @ est, 1e-300)
        est = alpha * est
        s_true, s_est = full != 0, est != 0
        tp += int(np.sum(s_true & s_est))
        fp += int(np.sum(~s_true & s_est))
        fn += int(np.sum(s_true & ~s_est))
        worst = max(worst, float(np.max(np.abs(est[s_true] - full[s_true]) / np.abs(full[s_true]))))
    f1 = 2 * tp / max(2 * tp + fp + fn, 1)
    return f1, worst
