"""Time stepping of the cantilever with ``mujoco.rollout``: integrator, timestep, impact, sampling.

Timestep
--------
The step is the sample period divided by an integer number of substeps, so every
sample falls on a step.  Both integrators are analysed on the linear model
``M q'' + C q' + K q = 0`` (exact for the stiff beam, the small-motion limit of
the soft one); with ``C = beta K`` every mode ``(omega_i, zeta_i)`` decouples.

``RK4`` is limited by stability, ``dt <= 2.0 / max|eig(A)|`` of the damped state
matrix ``A`` (the limit is about 2.5-2.8 depending on the eigenvalue's angle; 2.0
keeps a 20 % margin; with stiffness-proportional damping the overdamped top
modes, ``~ -beta omega^2``, usually set it), and by accuracy: RK4's relative
eigenvalue error is about ``(omega dt)^4 / 120``, held below 0.05 % for every
mode under the sample Nyquist frequency (``omega_Ny dt <= 0.49``).

``implicitfast`` is MuJoCo's semi-implicit Euler with the velocity derivatives of
the forces, here the joint damping, taken implicitly: per mode
``(1 + 2 zeta omega dt) v' = v - omega^2 dt q``, ``q' = q + dt v'``.  Its
amplification matrix has determinant ``1 / (1 + 2 zeta omega dt)`` and is stable
for ``omega dt < 2 zeta + 2 sqrt(1 + zeta^2)``: the implicit damping stabilises
the overdamped top modes (``zeta = beta omega / 2`` makes every step
``dt < 2 beta`` stable whatever N), so the step is set by accuracy alone.  The
step keeps 80 % of the most restrictive mode's limit and ``omega_Ny dt <= 0.109``
(undamped frequency error ``(omega dt)^2 / 24 = 5e-4`` at the Nyquist frequency).
Damping enters to first order: a mode's eigenvalue moves by about
``zeta omega dt`` relative (0.03 %, 0.2 %, 0.9 % on modes 2, 3, 4 of the default
beam at 29 substeps); :func:`mode_errors` gives the exact figure per mode and
the rig stores it.

``auto`` takes RK4 (fourth order) while it costs at most
:data:`AUTO_RK4_PREMIUM` times implicitfast, an RK4 step counting
:data:`RK4_STEP_COST` implicitfast steps (measured); beyond, implicitfast.  The
default 10-segment beams stay on RK4 (17 and 7 substeps); from about 20 segments
the RK4 step falls as N^-2 (N = 60 would need 22,000 substeps, implicitfast 29).

``auto`` at a requested ``timestep`` (rounded to the sample period over an integer)
takes RK4 wherever RK4 is stable there (the exact test of :func:`unstable_modes`;
as before, so those runs keep their data bit for bit).  Where RK4 is unstable it
takes implicitfast if the step meets the rule ``auto`` applies to its own
implicitfast step (:func:`implicit_step_bound`: within :data:`IMPLICIT_MARGIN` of
the tightest mode's stability limit and ``omega_Ny dt <= IMPLICIT_ACCURACY``), and
says so in the stored rule; otherwise it keeps RK4 and the rig refuses the step in
one line naming both integrators' reasons (:func:`implicit_unfit`).  A stable RK4
step is never swapped for accuracy's sake: RK4's accuracy bound
(``omega_Ny dt <= 0.49``) is 4.5 x looser than implicitfast's, so a step too coarse
for RK4's accuracy is too coarse for implicitfast's as well.  To take a step
implicitfast integrates but ``auto`` would not choose, name the integrator.
So asking ``auto`` for the step it would choose itself reproduces its data only where
that step is one RK4 cannot take: where RK4 is stable there but ``auto``'s own cost
rule took implicitfast (40 segments at 1e-4 damping: implicitfast at 61 substeps),
the requested step is integrated with RK4 (the promise above: a step the old code
accepted keeps its data).

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

Failure
-------
MuJoCo does not stop an unstable simulation: it resets the state, counts a
warning and carries on, so the data would be silently wrong.  :func:`rollout_sensors`
checks the warning counters after every rollout call and raises
:class:`~testbed.core.errors.RigError`; :func:`unstable_modes` refuses a requested step
the linear analysis already shows to be unstable, before any stepping.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from testbed.core.errors import RigError
from testbed.core.lazy import lazy_module

# imported on first use: `testbed list` does not pay for them
mujoco = lazy_module("mujoco")
rollout = lazy_module("mujoco.rollout")
sla = lazy_module("scipy.linalg")

RK4_STABILITY = 2.0        # dt * max|eig(A)| for RK4 (stable to ~2.5; 20 % margin)
RK4_ACCURACY = 0.49        # omega_Nyquist dt: (0.49)^4 / 120 = 4.8e-4 relative frequency error
IMPLICIT_MARGIN = 0.8      # fraction of implicitfast's per-mode stability limit used (20 % margin)
IMPLICIT_ACCURACY = 0.109  # omega_Nyquist dt: (0.109)^2 / 24 = 5.0e-4 (undamped frequency error)
RK4_STEP_COST = 2.8        # one RK4 step in implicitfast steps (2.7-2.9 measured at N = 10-60)
AUTO_RK4_PREMIUM = 2.0     # auto keeps RK4 (4th order) while it costs at most 2x implicitfast
CHUNK_BYTES = 1 << 26      # rollout output per call, 64 MiB (states + sensors of every step)
PROPORTIONAL_TOL = 1e-9    # off-diagonal / diagonal of Phi^T C Phi below this: modal damping


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
    rule : str
        How the choice was made, in words (printed and stored with the dataset).
    """

    integrator: str
    timestep: float
    substeps: int
    rule: str = ""


def state_matrix(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> np.ndarray:
    """First-order state matrix ``[[0, I], [-M^-1 K, -M^-1 C]]``, shape (2n, 2n)."""
    n = M.shape[0]
    minv = np.linalg.inv(M)
    return np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ K, -minv @ C]])


def modal_damping(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Undamped angular frequencies [rad/s] and modal damping ratios [-], each shape (n,).

    ``zeta_i = (Phi^T C Phi)_ii / (2 omega_i)``.  A damping matrix the undamped modes
    do not diagonalise (off-diagonal above :data:`PROPORTIONAL_TOL` of the diagonal)
    gives ``zeta = 0``: the modes do not decouple, and the undamped limit is used.
    """
    lam, phi = sla.eigh(K, M)
    omega = np.sqrt(np.clip(lam, 0.0, None))
    d = phi.T @ C @ phi
    diag = np.diag(d).copy()
    off = d - np.diag(diag)
    if np.abs(off).max(initial=0.0) > PROPORTIONAL_TOL * max(np.abs(diag).max(initial=0.0), 1e-300):
        return omega, np.zeros_like(omega)
    return omega, diag / (2.0 * np.where(omega > 0, omega, np.inf))


def implicit_limits(omega: np.ndarray, zeta: np.ndarray) -> np.ndarray:
    """Per-mode stability limit of implicitfast, ``dt < (2 zeta + 2 sqrt(1 + zeta^2)) / omega`` [s]."""
    return (2.0 * zeta + 2.0 * np.sqrt(1.0 + zeta**2)) / np.where(omega > 0, omega, np.inf)


def _rk4_poly(z: np.ndarray) -> np.ndarray:
    return 1 + z + z**2 / 2 + z**3 / 6 + z**4 / 24


def _mode_eigs(omega: float, zeta: float, dt: float, integrator: str) -> tuple[np.ndarray, np.ndarray]:
    """Continuous eigenvalues of one mode and those the step reproduces, ``log(z) / dt`` [1/s]."""
    lam = np.roots([1.0, 2.0 * zeta * omega, omega**2]).astype(complex)
    if integrator == "RK4":
        z = _rk4_poly(lam * dt)
    else:
        a = 1.0 / (1.0 + 2.0 * zeta * omega * dt)
        amp = np.array([[1 - a * (omega * dt) ** 2, a * dt], [-a * omega**2 * dt, a]])
        z = np.linalg.eigvals(amp).astype(complex)
        order = [int(np.argmin(np.abs(np.log(z) / dt - lam[0])))]
        z = z[[order[0], 1 - order[0]]]
    return lam, np.log(z) / dt


def mode_errors(M: np.ndarray, C: np.ndarray, K: np.ndarray, stepping: Stepping,
                n_modes: int) -> np.ndarray:
    """Relative eigenvalue error ``|lam_step - lam| / |lam|`` of the first modes, shape (n_modes,).

    ``lam_step = log(z) / dt`` with ``z`` the eigenvalue of one step of the linear
    scheme for that mode (:func:`modal_damping`; the larger of the pair's errors).
    This is the integrator's error on the modes' frequency and decay rate: the
    simulated free decay of mode i is ``exp(lam_step t)`` instead of the truth's
    ``exp(lam t)``.
    """
    omega, zeta = modal_damping(M, C, K)
    out = np.empty(min(n_modes, omega.size))
    for i in range(out.size):
        lam, lam_h = _mode_eigs(float(omega[i]), float(zeta[i]), stepping.timestep, stepping.integrator)
        out[i] = float(np.max(np.abs(lam_h - lam) / np.abs(lam)))
    return out


def unstable_modes(M: np.ndarray, C: np.ndarray, K: np.ndarray, integrator: str,
                   timestep: float) -> str | None:
    """Why ``timestep`` [s] is unstable for the linear model, or None if it is stable.

    RK4: some eigenvalue ``lam`` of the state matrix has ``|R(lam dt)| > 1``
    (``R`` the RK4 stability polynomial).  implicitfast: some mode exceeds its limit
    of :func:`implicit_limits`.
    """
    if integrator == "RK4":
        lam = np.linalg.eigvals(state_matrix(M, C, K))
        amp = np.abs(_rk4_poly(lam * timestep))
        if amp.max() > 1.0 + 1e-12:
            k = int(np.argmax(amp))
            limit = RK4_STABILITY / float(np.abs(lam).max())
            return (f"the eigenvalue {lam[k]:.4g} 1/s grows by {amp[k]:.3g} per step "
                    f"(RK4 needs about dt <= {limit:.3g} s here)")
        return None
    omega, zeta = modal_damping(M, C, K)
    lim = implicit_limits(omega, zeta)
    if (timestep >= lim).any():
        k = int(np.argmin(lim))
        return (f"mode {k + 1} ({omega[k] / (2 * math.pi):.4g} Hz, damping ratio {zeta[k]:.3g}) "
                f"needs dt < {lim[k]:.3g} s with {integrator}")
    return None


def implicit_step_bound(M: np.ndarray, C: np.ndarray, K: np.ndarray, fs: float) -> float:
    """Largest implicitfast step ``auto`` accepts at sample rate ``fs`` [Hz], in s.

    ``min(IMPLICIT_MARGIN * min_i limit_i, IMPLICIT_ACCURACY / omega_Ny)`` with the
    per-mode limits of :func:`implicit_limits` and ``omega_Ny = pi fs`` [rad/s].
    """
    omega, zeta = modal_damping(M, C, K)
    return min(IMPLICIT_MARGIN * float(implicit_limits(omega, zeta).min()),
               IMPLICIT_ACCURACY / (math.pi * fs))


def implicit_accurate(fs: float, timestep: float) -> bool:
    """Whether an implicitfast step [s] meets ``auto``'s accuracy rule at sample rate ``fs`` [Hz],
    ``omega_Ny dt <= IMPLICIT_ACCURACY`` (1e-12 of rounding allowed)."""
    return math.pi * fs * timestep <= IMPLICIT_ACCURACY * (1 + 1e-12)


def implicit_unfit(M: np.ndarray, C: np.ndarray, K: np.ndarray, fs: float,
                   timestep: float) -> str | None:
    """Why ``auto`` would not integrate a requested ``timestep`` [s] with implicitfast, or None.

    The step must meet :func:`implicit_step_bound` (the rule ``auto`` applies to its own
    implicitfast step): stable with a 20 % margin on every mode, and an undamped frequency
    error ``(omega_Ny dt)^2 / 24`` at the Nyquist frequency of at most 5e-4.
    """
    w_ny_dt = math.pi * fs * timestep
    if not implicit_accurate(fs, timestep):
        return (f"implicitfast is not accurate there (omega_Nyquist dt = {w_ny_dt:.3g} > "
                f"{IMPLICIT_ACCURACY:g}: frequency error {w_ny_dt**2 / 24:.2%} at the Nyquist "
                f"frequency, auto's bound {IMPLICIT_ACCURACY**2 / 24:.2%}; it needs dt <= "
                f"{IMPLICIT_ACCURACY / (math.pi * fs):.3g} s)")
    bound = implicit_step_bound(M, C, K, fs)
    if timestep > bound * (1 + 1e-12):
        why = unstable_modes(M, C, K, "implicitfast", timestep)
        return (f"implicitfast is {'unstable' if why else 'within 20 % of its stability limit'} "
                f"there ({why or f'auto needs dt <= {bound:.3g} s'})")
    return None


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
        ``"auto"``, ``"RK4"`` or ``"implicitfast"``.  ``auto`` compares both
        choices' costs (RK4 while it costs at most :data:`AUTO_RK4_PREMIUM` times
        implicitfast; an RK4 step counts :data:`RK4_STEP_COST`); at a requested
        ``timestep`` it takes RK4 where RK4 is stable there, else implicitfast where
        :func:`implicit_unfit` finds nothing against it, else RK4 (which the rig then
        refuses, naming both reasons).
    timestep : float
        Requested step [s]; 0 chooses it.  A requested step is rounded to the
        sample period over the nearest integer substep count.
    """
    period = 1.0 / fs
    if timestep > 0:
        integ = "RK4" if integrator == "auto" else integrator
        substeps = max(1, round(period / timestep))
        dt = period / substeps
        rule = f"{integ}, requested timestep {timestep:.4g} s -> {substeps} per sample"
        if integrator == "auto":
            rk4_why = unstable_modes(M, C, K, "RK4", dt)
            if rk4_why and implicit_unfit(M, C, K, fs, dt) is None:
                integ = "implicitfast"
                rule = (f"auto at the requested timestep {timestep:.4g} s ({substeps} per sample, "
                        f"dt = {dt:.4g} s): RK4 is unstable there ({rk4_why}); implicitfast is "
                        f"stable and accurate there (omega_Nyquist dt = {math.pi * fs * dt:.3g} <= "
                        f"{IMPLICIT_ACCURACY:g}, dt <= {IMPLICIT_MARGIN:g} of its stability "
                        "limit) -> implicitfast")
        return Stepping(integ, dt, substeps, rule)
    w_ny = math.pi * fs

    def count(dt: float) -> int:
        return max(1, math.ceil(period / dt * (1 - 1e-12)))

    rk4 = imp = 0
    if integrator in ("auto", "RK4"):
        eig_max = float(np.abs(np.linalg.eigvals(state_matrix(M, C, K))).max())
        rk4 = count(min(RK4_STABILITY / eig_max, RK4_ACCURACY / w_ny))
    if integrator in ("auto", "implicitfast"):
        imp = count(implicit_step_bound(M, C, K, fs))
    if integrator == "auto":
        use_rk4 = RK4_STEP_COST * rk4 <= AUTO_RK4_PREMIUM * imp
        why = (f"auto: RK4 needs {rk4}, implicitfast {imp} steps per sample; an RK4 step costs "
               f"{RK4_STEP_COST:g} implicitfast steps, RK4 kept while at most "
               f"{AUTO_RK4_PREMIUM:g}x the cost -> ")
    else:
        use_rk4 = integrator == "RK4"
        why = f"{integrator} requested -> "
    integ, substeps = ("RK4", rk4) if use_rk4 else ("implicitfast", imp)
    dt = period / substeps
    return Stepping(integ, dt, substeps, why + f"{integ}, dt = {dt:.4g} s ({substeps} per sample)")


def half_sine(peak: float, duration: float, start: float) -> Callable[[np.ndarray], np.ndarray]:
    """The impact force ``F(t)`` [N] as a vectorised function of time [s]."""

    def force(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, float)
        tau = (t - start) / duration
        return np.where((tau >= 0) & (tau <= 1), peak * np.sin(np.pi * np.clip(tau, 0, 1)), 0.0)

    return force


_WARNINGS = {  # MuJoCo's warnings that mean the state was reset or the input refused (by name:
    "mjWARN_BADQACC": "accelerations",  # MuJoCo is imported on first use)
    "mjWARN_BADQVEL": "velocities",
    "mjWARN_BADQPOS": "positions",
    "mjWARN_BADCTRL": "hammer force (control)",
}


#: MuJoCo's largest accepted control (mjMAXVAL): a larger one counts as huge and is zeroed
#: (mjWARN_BADCTRL).  The hammer's motor has gear 1, so this is the largest force [N].
MUJOCO_MAX_CONTROL = 1e10


def check_warnings(model: mujoco.MjModel, data: mujoco.MjData, when: str = "") -> None:
    """Raise :class:`RigError` if MuJoCo counted a reset (bad state or control) in ``data``.

    ``when`` (e.g. ``"near t = 0.005 s"``) is added to the message.

    MuJoCo resets the state after a non-finite or huge (> 1e10) acceleration,
    velocity or position, and zeroes a non-finite or huge control, then carries on:
    the data after it are garbage (or zeros) that a finiteness check never sees.
    """
    integ = mujoco.mjtIntegrator(model.opt.integrator).name.removeprefix("mjINT_")
    integ = {"IMPLICITFAST": "implicitfast", "IMPLICIT": "implicit", "EULER": "Euler"}.get(integ, integ)
    for name, what in _WARNINGS.items():
        w = getattr(mujoco.mjtWarning, name)
        n = data.warning[w].number
        if not n:
            continue
        if w == mujoco.mjtWarning.mjWARN_BADCTRL:
            raise RigError(f"cantilever: MuJoCo refused the {what} {n} time(s) as non-finite or "
                           f"above its limit of {MUJOCO_MAX_CONTROL:g} and zeroed it; reduce "
                           "excitation.peak_force")
        raise RigError(f"cantilever: the simulation is unstable with {integ} at timestep "
                       f"{model.opt.timestep:.4g} s (MuJoCo reset it {n} time(s) after huge or "
                       f"non-finite {what}{', ' + when if when else ''}); set simulation.timestep = 0 "
                       "(automatic) or another simulation.integrator")


def peak_segment_angle(qpos: np.ndarray) -> tuple[float, int, int]:
    """The largest absolute angle of any segment from the beam's axis in a run of states.

    The hinges all turn about one axis, so segment ``j`` lies at ``sum_{i <= j} q_i`` from the
    undeformed beam's axis (a soft base's hinge is ``q_0``): the angle whose sine and cosine the
    exact chain uses where the linear truth (all at ``q = 0``) takes ``phi`` and 1.

    Parameters
    ----------
    qpos : ndarray, shape (n_steps, nq)
        Joint angles [rad] per step.

    Returns
    -------
    (angle, step, segment)
        The largest ``|phi|`` [rad], the index of its step, and its segment (1-based).
    """
    phi = np.abs(np.cumsum(qpos, axis=1))
    k = int(np.argmax(phi))
    step, seg = divmod(k, phi.shape[1])
    return float(phi.flat[k]), step, seg + 1


def rollout_sensors(model: mujoco.MjModel, qpos0: np.ndarray, control: np.ndarray,
                    substeps: int, progress: Callable[[float], None] | None = None,
                    peak_angle: list[tuple[float, float, int]] | None = None) -> np.ndarray:
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
    peak_angle : list, optional
        If given, receives one tuple ``(angle, time, segment)``: the largest absolute angle
        [rad] of any segment of the chain from the beam's axis (the running sum of the hinge
        angles, :func:`peak_segment_angle`) over every step, the time [s] and the segment
        (1-based, counting a soft base's stub) where it occurred.

    Returns
    -------
    ndarray, shape (nstep // substeps, nsensordata)
        Sensor readings at the sample instants (reading ``n`` at time ``n * substeps * dt``).

    Raises
    ------
    RigError
        If MuJoCo reset the simulation or refused the control (:func:`check_warnings`,
        after every rollout call, whose output is at most :data:`CHUNK_BYTES`), or the
        readings are not finite.
    """
    nstep = control.size
    if nstep % substeps:
        raise ValueError("the number of steps must be a multiple of the substep count")
    data = mujoco.MjData(model)
    data.qpos[:] = qpos0
    mujoco.mj_forward(model, data)
    check_warnings(model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state = np.zeros(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, state, spec)
    per_step = 8 * (state.size + model.nsensordata)  # bytes of rollout output per step
    chunk = max(1, CHUNK_BYTES // (per_step * substeps)) * substeps  # whole samples per call
    out = np.empty((nstep // substeps, model.nsensordata))
    for start in range(0, nstep, chunk):
        ctrl = control[start:start + chunk]
        states, sens = rollout.rollout(model, data, state[None, :], ctrl[None, :, None])
        times = states[0, :, 0]  # the state starts with the time; a reset sets it back to 0
        back = np.flatnonzero(np.diff(times) < 0)
        check_warnings(model, data, f"near t = {times[back[0]]:.4g} s" if back.size else
                       f"between t = {start * model.opt.timestep:.4g} and {times[-1]:.4g} s")
        out[start // substeps:(start + ctrl.size) // substeps] = sens[0, ::substeps]
        if peak_angle is not None:
            peak = peak_segment_angle(states[0, :, 1:1 + model.nq])
            if not peak_angle or peak[0] > peak_angle[0][0]:
                peak_angle[:] = [(peak[0], float(states[0, peak[1], 0]), peak[2])]
        state = states[0, -1]
        if progress is not None:
            progress(min(1.0, (start + ctrl.size) / nstep))
    if not np.all(np.isfinite(out)):
        raise RigError(f"cantilever: non-finite sensor readings at timestep {model.opt.timestep:.4g} s; "
                       "set simulation.timestep = 0 (automatic)")
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
