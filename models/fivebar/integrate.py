"""Fixed-step RK4 of the constrained Pinocchio dynamics with zero-order-hold torques.

RK4 at 1e-4 s keeps the loop-closure drift below 1e-13 m over 10 s with no Baumgarte
correction (semi-implicit Euler drifts ~1e-5 m), so none is used: the recorded motion
is the exact constrained motion up to the integrator's O(dt^4) error.

A simulation that diverges (non-finite torque, state or record) or whose loop-closure
solve stops unconverged raises :class:`~testbed.core.errors.RigError` with a one-line
message naming the time, instead of writing the garbage to a dataset.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from models.fivebar import geometry as geo
from models.fivebar.dynamics import FiveBarDynamics
from models.fivebar.excitation import TorqueProgram
from testbed.core.errors import RigError

#: Samples between two transmission-angle / finiteness checks (and progress calls).
CHECK_EVERY = 1000
#: Largest relative residual of the proximal loop-closure solve accepted when it stops at its
#: iteration limit (it converges in 3 iterations to < 1e-12 in every usable pose, measured); a
#: relative error of 1e-8 in the accelerations stays far below the tightest five-bar score
#: (angle RMSE 1e-5 rad over 10 s).
RESIDUAL_REFUSE = 1e-8


class BlowUpError(RigError):
    """The linkage's simulation blew up (a non-finite signal, or MuJoCo resetting its state):
    the integration step is a suspect besides the excitation (:func:`models.fivebar.rig`)."""


def check_finite(t: np.ndarray, engine: str, dt: float, **signals: np.ndarray) -> None:
    """Raise :class:`BlowUpError` (one line) at the first sample where a recorded signal is not finite.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Sample times [s].
    engine : str
        Named in the message.
    dt : float
        Integration step [s], named in the message.
    **signals : ndarray, shape (n, k)
        Recorded arrays by name.
    """
    for name, x in signals.items():
        bad = ~np.isfinite(x).all(axis=1)
        if bad.any():
            k = int(np.argmax(bad))
            raise BlowUpError(f"fivebar ({engine}): the simulation diverged, {name} is not finite at "
                           f"t = {t[k]:.4f} s (RK4, dt = {dt:g} s); reduce the excitation amplitude or "
                           "simulation.dt")


def check_transmission(theta: np.ndarray, t: np.ndarray, engine: str) -> None:
    """Raise :class:`RigError` at the first sample whose transmission angle leaves the safe range.

    Parameters
    ----------
    theta : ndarray, shape (n, 4)
        Absolute angles [rad].
    t : ndarray, shape (n,)
        Their times [s].
    engine : str
        Named in the message.
    """
    lo, hi = geo.TRANSMISSION_RANGE_DEG
    mu = np.degrees(geo.transmission_angle(theta))
    bad = ~np.isfinite(mu) | (mu < lo) | (mu > hi) | ~np.isfinite(theta).all(axis=1)
    if bad.any():
        k = int(np.argmax(bad))
        raise RigError(f"fivebar ({engine}): at t = {t[k]:.4f} s the transmission angle (links 2-3 at E) "
                       f"is {mu[k]:.2f} deg; allowed {lo:g}-{hi:g} deg (outside it the linkage is near a "
                       "Type II singularity). Drive the linkage less far (the keys named) or start "
                       "from a better-conditioned pose.")


def simulate(dyn: FiveBarDynamics, theta0: np.ndarray, dtheta0: np.ndarray, program: TorqueProgram,
             dt: float, fs: float, n_samples: int,
             progress: Callable[[float], None] | None = None) -> dict[str, np.ndarray]:
    """Integrate from a consistent start state and record every sample.

    Parameters
    ----------
    dyn : FiveBarDynamics
    theta0, dtheta0 : ndarray, shape (4,)
        Absolute start angles [rad] and rates [rad/s], satisfying the loop closure.
    program : TorqueProgram
        Torques held over each sample interval.
    dt : float
        RK4 step [s]; ``1 / (fs dt)`` must be an integer.
    fs : float
        Sample rate [Hz].
    n_samples : int
        Samples to record (at t = k / fs, k = 0 .. n_samples - 1).

    Returns
    -------
    dict
        ``theta``, ``dtheta``, ``ddtheta`` (n, 4) absolute [rad, rad/s, rad/s^2];
        ``torque`` (n, 2) [N m]; ``constraint_force`` (n, 2) [N] on link 2 at E.
        The acceleration and constraint force of sample k are those of the state at
        t_k under the torque held from t_k.
    """
    import pinocchio as pin  # lazy: ~0.1 s of import, only when simulating

    sps = round(1.0 / (fs * dt))
    model, data, cms, cds, prox = dyn.model, dyn.data, dyn.cmodels, dyn.cdatas, dyn.prox
    cd = pin.constraintDynamics
    damp = dyn.damping
    h, h2, h6 = dt, dt / 2.0, dt / 6.0
    q = geo.to_joint(np.asarray(theta0, float))
    v = geo.to_joint(np.asarray(dtheta0, float))
    Q, V, A = (np.empty((n_samples, 4)) for _ in range(3))
    U, LAM = np.empty((n_samples, 2)), np.empty((n_samples, 2))
    tau_u = np.zeros(4)
    t = np.arange(n_samples) / fs
    max_iter = prox.max_iter

    # One right-hand side: ``cd(..., tau_u - damp * v, ...)`` written into two preallocated
    # buffers (the same two floating-point operations, without their allocations); the solver's
    # iteration count is read after every call and the residual only when it hit the limit.
    tau, dv = np.empty(4), np.empty(4)
    mul, sub = np.multiply, np.subtract

    def refuse(q: np.ndarray, v: np.ndarray, a: np.ndarray, tk: float) -> None:
        """Raise if the solve that just stopped at its iteration limit did not converge."""
        # ``not <=``: a NaN residual is a failed solve too.
        if prox.relative_residual <= RESIDUAL_REFUSE:
            return
        if not (np.isfinite(q).all() and np.isfinite(v).all() and np.isfinite(tau_u).all()
                and np.isfinite(a).all()):  # overflow, not a slow solve
            raise BlowUpError(f"fivebar (pinocchio): the simulation diverged, the accelerations are not "
                              f"finite at t = {tk:.4f} s (RK4, dt = {dt:g} s, largest torque "
                              f"{np.abs(tau_u).max():.3g} N m); reduce the excitation amplitude or "
                              "simulation.dt")
        raise RigError(f"fivebar (pinocchio): the loop-closure solve did not converge at t = {tk:.4f} s "
                       f"(relative residual {prox.relative_residual:.3g} after {max_iter} iterations, "
                       f"accepted <= {RESIDUAL_REFUSE:g}); the linkage is at or near a singularity: "
                       "reduce the excitation amplitude or choose another start pose")

    for k in range(n_samples):
        u = program.torque(k, q[0::2], v[0::2])  # the actuated joints 0 and 2 (views)
        tau_u[0], tau_u[2] = u
        tk = t[k]
        a1 = cd(model, data, q, v, sub(tau_u, mul(damp, v, out=dv), out=tau), cms, cds, prox).copy()
        if prox.iter >= max_iter:
            refuse(q, v, a1, tk)
        Q[k], V[k], A[k], U[k], LAM[k] = q, v, a1, u, data.lambda_c[:2]
        if (k + 1) % CHECK_EVERY == 0 or k == n_samples - 1:
            k0 = (k // CHECK_EVERY) * CHECK_EVERY
            blk = slice(k0, k + 1)
            check_finite(t[blk], "pinocchio", dt, torque=U[blk], angles=Q[blk], rates=V[blk],
                         accelerations=A[blk], constraint_force=LAM[blk])
            check_transmission(geo.to_absolute(Q[blk]), t[blk], "pinocchio")
            if progress is not None:
                progress((k + 1) / n_samples)
        if k == n_samples - 1:
            break
        for s in range(sps):
            ts = tk + s * h
            if s:
                a1 = cd(model, data, q, v, sub(tau_u, mul(damp, v, out=dv), out=tau), cms, cds, prox).copy()
                if prox.iter >= max_iter:
                    refuse(q, v, a1, ts)
            v2 = v + h2 * a1
            q2 = q + h2 * v
            a2 = cd(model, data, q2, v2, sub(tau_u, mul(damp, v2, out=dv), out=tau), cms, cds, prox).copy()
            if prox.iter >= max_iter:
                refuse(q2, v2, a2, ts)
            v3 = v + h2 * a2
            q3 = q + h2 * v2
            a3 = cd(model, data, q3, v3, sub(tau_u, mul(damp, v3, out=dv), out=tau), cms, cds, prox).copy()
            if prox.iter >= max_iter:
                refuse(q3, v3, a3, ts)
            v4 = v + h * a3
            q4 = q + h * v3
            a4 = cd(model, data, q4, v4, sub(tau_u, mul(damp, v4, out=dv), out=tau), cms, cds, prox)
            if prox.iter >= max_iter:
                refuse(q4, v4, a4, ts)
            q = q + h6 * (v + 2.0 * (v2 + v3) + v4)
            v = v + h6 * (a1 + 2.0 * (a2 + a3) + a4)
    return {"theta": geo.to_absolute(Q), "dtheta": geo.to_absolute(V), "ddtheta": geo.to_absolute(A),
            "torque": U, "constraint_force": LAM}
