"""Simulation of identified structural models ``M x'' + C x' + K x + K3 x^3 = B u``.

The linear part is discretised exactly (matrix exponential, zero-order-hold input) and
propagated without a Python loop over time; a cubic term switches to RK4 with sub-steps, run
by a compiled loop (:func:`identify._compiled.rk4_cubic`).
"""

from __future__ import annotations

import numpy as np

from testbed.core.errors import DivergenceError, UnresolvedModelError
from testbed.core.measurement import Trajectory
from testbed.numerics.linear_response import prepare_inputs, simulate_linear, state_matrix

__all__ = ["pole_radius", "sample_rate_pole", "simulate_structural", "state_matrix"]


#: Where classical RK4's region of absolute stability meets the negative real axis:
#: ``|1 + z + z^2/2 + z^3/6 + z^4/24| = 1`` at ``z = -2.785`` (on the imaginary axis the bound
#: is ``2 sqrt 2``).  A pole with ``|lambda| dt`` beyond it (``dt`` the sample interval) is
#: faster than one RK4 step per sample can follow: an overdamped pole there leaves less than
#: ``exp(-2.785)`` = 6 % of its amplitude after one sample, a lightly damped mode lies above
#: 0.44 ``fs``.  :func:`simulate_structural` still integrates such a cubic model (its sub-steps
#: grow with ``|lambda| dt``, e.g. 2478 per sample for a pole at -3.2e6 rad/s at 12.8 kHz);
#: :func:`sample_rate_pole` lets a caller refuse one before paying for that.
RK4_STABILITY_BOUND = 2.785

#: Most RK4 sub-steps (summed over the record) one simulation of a cubic model may take when its
#: fastest pole lies beyond :data:`RK4_STABILITY_BOUND` per sample, i.e. is unresolved by the
#: record.  Measured 0.3 us per step (3 sensors, 2 busy cores): 1.5 s per simulation, and the
#: scorer's start fit simulates a model 2 n + 3 times and more.  A 0.5 s record at 12.8 kHz
#: then takes poles up to |lambda| dt = 78 (an amplitude e^-78 after one sample); round 5's
#: critically damped beam (``damping_ratio`` 0.999999999) gave a model with a pole at
#: -1.4e9 rad/s, |lambda| dt = 1.1e5, which needed 7e9 steps per simulation (hours).  A pole
#: the record resolves is simulated at any cost (its sub-steps are at most 28 per sample).
MAX_UNRESOLVED_RK4_STEPS = 5_000_000


def pole_radius(A: np.ndarray) -> float:
    """The fastest pole's magnitude ``max |eig(A)|`` [rad/s] of a state matrix
    (:func:`state_matrix`)."""
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def sample_rate_pole(M: np.ndarray, C: np.ndarray, K: np.ndarray, dt: float) -> float:
    """The linear part's fastest pole per sample, ``max |lambda| dt`` [-].

    Beyond :data:`RK4_STABILITY_BOUND` one RK4 step per sample interval cannot follow that
    pole; the record cannot resolve it either.

    Parameters
    ----------
    M, C, K : ndarray, shape (n, n)
        [kg], [N s/m], [N/m].
    dt : float
        Sample interval [s].

    Returns
    -------
    float
        ``max |lambda| dt`` over the poles of :func:`state_matrix`; inf if they are not finite.
    """
    with np.errstate(over="ignore", invalid="ignore"):
        A = state_matrix(M, C, K)
    if not np.all(np.isfinite(A)):
        return float("inf")
    return pole_radius(A) * float(dt)


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
    per-sample Python loop: :func:`testbed.numerics.linear_response.simulate_linear`).
    With a cubic term the full model is integrated with classical
    RK4 at sub-steps of the sample interval; the input is held over each interval.

    Raises
    ------
    DivergenceError
        Cubic model only: the state became non-finite; ``time`` [s] is the start of the
        sample interval in which it happened.
    """
    if K3 is None or not np.any(np.asarray(K3) != 0.0):
        return simulate_linear(M, C, K, B, x0, xd0, t, u)
    M, C, K, x0, xd0, t, dt, Minv, f = prepare_inputs(M, C, K, B, x0, xd0, t, u)
    n, n_t = M.shape[0], t.size
    A = state_matrix(M, C, K)
    z0 = np.concatenate([x0, xd0])
    MK3 = Minv @ np.asarray(K3, dtype=float)
    MF = Minv @ f if f is not None else np.zeros((n, n_t))
    rho = pole_radius(A) if n_t > 1 else 0.0
    if not np.isfinite(rho):
        raise DivergenceError("cubic structural model: non-finite poles")
    steps = float(np.ceil(rho * dt / max_omega_h)) * n_t
    if rho * dt > RK4_STABILITY_BOUND and steps > MAX_UNRESOLVED_RK4_STEPS:
        raise UnresolvedModelError(
            f"a cubic model whose linear part has a pole of {rho:.3g} rad/s (|lambda| dt = "
            f"{rho * dt:.3g} per sample, beyond RK4's stability bound {RK4_STABILITY_BOUND:g}: "
            f"the record cannot resolve it) needs {steps:.3g} RK4 steps, more than "
            f"{MAX_UNRESOLVED_RK4_STEPS:.3g} (identify._structural_sim.MAX_UNRESOLVED_RK4_STEPS)")
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
