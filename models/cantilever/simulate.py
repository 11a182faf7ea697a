"""Time stepping of the cantilever with ``mujoco.rollout``: timestep, impact, sampling.

Timestep
--------
The step is the sample period divided by an integer number of substeps, so every
sample falls on a step.  ``RK4`` (the default) is limited by stability,
``dt <= 2.0 / max|eig(A)|`` of the damped state matrix ``A`` (the limit is about
2.5-2.8 depending on the eigenvalue's angle; 2.0 keeps a 20 % margin; with
stiffness-proportional damping the overdamped top modes, ``~ -beta omega^2``,
usually set it), and by accuracy: RK4's relative frequency error is about
``(omega dt)^4 / 120``, held below 0.05 % for every mode under the sample Nyquist
frequency (``omega_Ny dt <= 0.49``).  ``implicitfast`` (damping implicit,
stiffness explicit, first order) has a frequency error of about
``(omega dt)^2 / 24``: the same 0.05 % target needs ``omega_Ny dt <= 0.11``, and
stability ``omega_max dt <= 1.6``.

Impact
------
A half-sine ``F(t) = P sin(pi (t - t0) / Tp)`` on ``[t0, t0 + Tp]`` drives the
``hammer`` motor (world +z at the hit site).  MuJoCo holds a control over a step,
so each step gets ``F`` at its midpoint (midpoint rule: second-order accurate
impulse).  The measured force is ``F`` at the sample instants, as a load cell
would read it.

Sampling
--------
Sensor data of step k belong to the state before step k (time ``k dt``).  Every
``substeps``-th reading is kept: the instantaneous value at the sample time (an
ideal sampler; modes above the Nyquist frequency are heavily damped by
``C = beta K`` and barely excited by the pulse, see the tests).  Accelerometer
readings within a pulse include the mid-step force: leave the pulse window out
when comparing against a model driven by the continuous force.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import mujoco
import mujoco.rollout
import numpy as np

RK4_STABILITY = 2.0        # dt * max|eig(A)| for RK4 (stable to ~2.5; 20 % margin)
RK4_ACCURACY = 0.49        # omega_Nyquist dt: (0.49)^4 / 120 = 4.8e-4 relative frequency error
IMPLICIT_STABILITY = 1.6   # omega_max dt for implicitfast (explicit stiffness, limit 2)
IMPLICIT_ACCURACY = 0.109  # omega_Nyquist dt: (0.109)^2 / 24 = 5.0e-4
CHUNK_SAMPLES = 2048       # samples per rollout call (bounds memory at ~ 2048 x substeps steps)


@dataclass(frozen=True)
class Stepping:
    """Chosen integrator and step.

    Attributes
    ----------
    integrator : str
        ``"RK4"`` or ``"implicitfast"``.
    timestep : float
        Integration step [s].
    substeps : int
        Steps per sample period.
    """

    integrator: str
    timestep: float
    substeps: int


def state_matrix(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> np.ndarray:
    """First-order state matrix ``[[0, I], [-M^-1 K, -M^-1 C]]``, shape (2n, 2n)."""
    n = M.shape[0]
    minv = np.linalg.inv(M)
    return np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ K, -minv @ C]])


def choose_stepping(M: np.ndarray, C: np.ndarray, K: np.ndarray, fs: float, integrator: str,
                    timestep: float = 0.0) -> Stepping:
    """Integrator and timestep for sample rate ``fs`` [Hz] (see the module docstring).

    Parameters
    ----------
    M, C, K : ndarray, shape (n, n)
        Full joint-space matrices.
    fs : float
        Sample rate [Hz].
    integrator : str
        ``"auto"`` (= RK4), ``"RK4"`` or ``"implicitfast"``.
    timestep : float
        Requested step [s]; 0 chooses it.  A requested step is rounded to the
        sample period over the nearest integer substep count.
    """
    integ = "RK4" if integrator == "auto" else integrator
    period = 1.0 / fs
    if timestep > 0:
        substeps = max(1, round(period / timestep))
        return Stepping(integ, period / substeps, substeps)
    w_ny = math.pi * fs
    if integ == "RK4":
        eig_max = float(np.abs(np.linalg.eigvals(state_matrix(M, C, K))).max())
        dt = min(RK4_STABILITY / eig_max, RK4_ACCURACY / w_ny)
    else:
        w_max = float(np.sqrt(np.abs(np.linalg.eigvals(np.linalg.solve(M, K))).max()))
        dt = min(IMPLICIT_STABILITY / w_max, IMPLICIT_ACCURACY / w_ny)
    substeps = max(1, math.ceil(period / dt * (1 - 1e-12)))
    return Stepping(integ, period / substeps, substeps)


def half_sine(peak: float, duration: float, start: float) -> Callable[[np.ndarray], np.ndarray]:
    """The impact force ``F(t)`` [N] as a vectorised function of time [s]."""

    def force(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, float)
        tau = (t - start) / duration
        return np.where((tau >= 0) & (tau <= 1), peak * np.sin(np.pi * np.clip(tau, 0, 1)), 0.0)

    return force


def rollout_sensors(model: mujoco.MjModel, qpos0: np.ndarray, control: np.ndarray,
                    substeps: int, progress: Callable[[float], None] | None = None) -> np.ndarray:
    """Step ``model`` from rest at ``qpos0`` and keep every ``substeps``-th sensor reading.

    Parameters
    ----------
    model : MjModel
    qpos0 : ndarray, shape (nq,)
        Initial joint angles [rad] (zero velocity).
    control : ndarray, shape (nstep,)
        Hammer force per step [N]; ``nstep`` a multiple of ``substeps``.
    substeps : int
    progress : callable, optional
        Called with the fraction done after each chunk.

    Returns
    -------
    ndarray, shape (nstep // substeps, nsensordata)
        Sensor readings at the sample instants (reading ``n`` at time ``n * substeps * dt``).
    """
    nstep = control.size
    if nstep % substeps:
        raise ValueError("the number of steps must be a multiple of the substep count")
    data = mujoco.MjData(model)
    data.qpos[:] = qpos0
    mujoco.mj_forward(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.zeros(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state, spec)
    chunk = CHUNK_SAMPLES * substeps
    out = np.empty((nstep // substeps, model.nsensordata))
    for start in range(0, nstep, chunk):
        ctrl = control[start:start + chunk]
        states, sens = mujoco.rollout.rollout(model, data, state[None, :], ctrl[None, :, None])
        out[start // substeps:(start + ctrl.size) // substeps] = sens[0, ::substeps]
        state = states[0, -1]
        if progress is not None:
            progress(min(1.0, (start + ctrl.size) / nstep))
    return out


def static_equilibrium(model: mujoco.MjModel, K: np.ndarray, iterations: int = 50) -> np.ndarray:
    """Joint angles [rad] at rest under gravity, shape (nq,), by fixed-point iteration.

    Solves ``K q = -qfrc_bias(q)`` at zero velocity (linear joint springs; the
    gravity load varies only with the segments' small rotations, so the
    iteration contracts fast).  Returns zeros when gravity is off.
    """
    data = mujoco.MjData(model)
    q = np.zeros(model.nq)
    for _ in range(iterations):
        data.qpos[:] = q
        data.qvel[:] = 0.0
        mujoco.mj_forward(model, data)
        q_new = np.linalg.solve(K, -data.qfrc_bias)
        if np.max(np.abs(q_new - q)) <= 1e-15 + 1e-13 * np.max(np.abs(q_new)):
            return q_new
        q = q_new
    return q
