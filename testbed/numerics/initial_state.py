"""The initial state a simulated model is compared from: fitted to the reference response.

An identified model's time response (TRAC) is simulated from a state at the start of the
scored window.  The measured state there is what the signal chain estimated, and for an
impact record its displacement and velocity carry the chain's integration constants (a
velocity offset left by integrating a pulse a few samples long, see
:func:`testbed.pipeline.signal_chain.drift_basis`).  Started from it, a model with exact
modes and damping can score a TRAC of 0.5 (measured on 2-sensor beams of the beams family,
studies/families.toml): the score then grades the chain, not the model.

So the start is estimated, as system-identification practice compares a model with data
(MATLAB's ``compare`` estimates the initial condition by default): the ``2 n`` numbers of
``(x0, xd0)`` minimising the squared error of the simulated response against the reference
over the whole window, by Gauss-Newton from the measured state.  ``2 n`` free numbers
against ``n`` x thousands of samples cannot make a wrong model right: the response's
frequencies and decay rates are the model's own.

Here in :mod:`testbed.numerics` since ``sgd_sindy`` compares its candidate models with the
measured record the same way (:func:`identify._record.record_agreement`);
:mod:`testbed.scoring.initial_state` re-exports it for the scorers.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from testbed.core.errors import TestbedError
from testbed.core.measurement import Trajectory

__all__ = ["fit_initial_state"]

#: Finite-difference step of each state component, relative to the largest magnitude of
#: its kind (displacements, velocities) at the measured start.  The response of a linear
#: model is affine in the start, so any step gives its Jacobian to rounding (relative error
#: ~ eps / 1e-3 ~ 1e-13); for a cubic model 1e-3 keeps the truncation error of the
#: one-sided difference at ~1e-3 of the cubic term's share, far below what a Gauss-Newton
#: step needs.
STEP = 1e-3
#: Gauss-Newton iterations: one is exact for a linear model; a cubic one converges in two
#: or three from the measured start (its nonlinearity is a fraction of the linear force).
MAX_ITERATIONS = 3
#: Stop when an iteration lowers the squared error by less than this fraction.
RTOL = 1e-6

_FAILURES = (TestbedError, np.linalg.LinAlgError, ValueError, FloatingPointError)


def _cost(traj: Trajectory, field: str, ref: np.ndarray) -> float:
    r = getattr(traj, field) - ref
    c = float(np.sum(r * r))
    return c if np.isfinite(c) else float("inf")


def fit_initial_state(simulate: Callable[[np.ndarray, np.ndarray], Trajectory], x0: np.ndarray,
                      xd0: np.ndarray, ref: np.ndarray, field: str = "xdd",
                      max_iterations: int = MAX_ITERATIONS) -> tuple[np.ndarray, np.ndarray]:
    """The start ``(x0, xd0)`` whose simulated response best matches ``ref``.

    Parameters
    ----------
    simulate : callable
        ``simulate(x0, xd0) -> Trajectory`` over the scored window (the model, its times and
        inputs bound).
    x0, xd0 : ndarray, shape (n,)
        The measured start: displacement [m] (or angle) and velocity; the first iterate.
    ref : ndarray, shape (n, n_t)
        The reference of ``field`` over the window.
    field : {"x", "xd", "xdd"}
        The trajectory field compared.
    max_iterations : int
        Gauss-Newton iterations at most (each costs ``2 n + 1`` simulations); one is exact
        for a linear model.

    Returns
    -------
    x0, xd0 : ndarray, shape (n,)
        The fitted start; the measured one if no iterate does better, or if a simulation
        fails (a diverging model is then scored from the measured start, where its failure
        is recorded with its reason).
    """
    x0 = np.asarray(x0, dtype=float)
    xd0 = np.asarray(xd0, dtype=float)
    n = x0.size
    z = np.concatenate([x0, xd0])
    span = np.concatenate([np.full(n, np.abs(x0).max(initial=0.0)),
                           np.full(n, np.abs(xd0).max(initial=0.0))])
    span[span == 0] = 1.0
    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            base = simulate(z[:n], z[n:])
            cost = _cost(base, field, ref)
            if not np.isfinite(cost):
                return x0, xd0
            for _ in range(max_iterations):
                y0 = getattr(base, field)
                jac = np.empty((y0.size, 2 * n))
                for k in range(2 * n):
                    dz = np.zeros(2 * n)
                    dz[k] = STEP * span[k]
                    jac[:, k] = ((getattr(simulate(*np.split(z + dz, 2)), field) - y0) / dz[k]).ravel()
                if not np.all(np.isfinite(jac)):
                    break
                r0 = (ref - y0).ravel()
                step, *_ = np.linalg.lstsq(jac, r0, rcond=None)
                predicted = float(np.sum((r0 - jac @ step) ** 2))
                trial = simulate(*np.split(z + step, 2))
                new = _cost(trial, field, ref)
                if not new < cost:
                    break
                # an affine response (a linear model) lands where the linearisation said: done
                done = cost - new < RTOL * cost or abs(new - predicted) <= RTOL * cost
                z, base, cost = z + step, trial, new
                if done:
                    break
    except _FAILURES:
        pass
    return z[:n].copy(), z[n:].copy()
