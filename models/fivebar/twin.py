"""Independent MuJoCo twin of the five-bar linkage (same links, same torques, RK4).

The loop is closed by an equality ``connect`` between a site at the tip of link 2 and
one at the tip of link 3.  MuJoCo's equality constraints are soft: ``solref`` sets the
time constant of the constraint's error dynamics; at 2 dt (the smallest stable value)
and ``solimp`` close to 1 the drift stays below 1e-10 m and the motion agrees with the
hard Pinocchio constraint to ~3e-11 rad RMS over the 10 s multisine case.  The
stabilisation adds ~1e-3 rad/s^2 (and ~2e-3 N) of ripple to the recorded accelerations
and constraint forces; it acts through the constraint Jacobian, so the true library
equations (which eliminate the constraint force) still hold to ~1e-12 on MuJoCo data.
Coordinates: MuJoCo's qpos is the relative joint vector in the same tree order
A, C, B, D as Pinocchio.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from models.fivebar import geometry as geo
from models.fivebar.dynamics import link_inertia_diag
from models.fivebar.excitation import TorqueProgram
from models.fivebar.integrate import CHECK_EVERY, BlowUpError, check_finite, check_transmission
from models.fivebar.params import FiveBarParams
from testbed.core.lazy import lazy_module

mujoco = lazy_module("mujoco")  # imported on first use: `testbed list` does not pay for it

#: Constraint impedance: (dmin, dmax, width).  Close to 1 = nearly hard constraint.
SOLIMP = (0.9999, 0.9999, 0.001)


def _f(x: float) -> str:
    """Shortest exact text of a float (round-trips through the XML parser)."""
    return repr(float(x))


def _body(name: str, pos: tuple[float, float, float], joint: str, mass: float, com: float,
          izz: float, damping: float, inner: str = "") -> str:
    ixx, iyy, izz = link_inertia_diag(izz)
    x, y, z = pos
    return (f'<body name="{name}" pos="{_f(x)} {_f(y)} {_f(z)}">'
            f'<joint name="{joint}" type="hinge" axis="0 0 1" damping="{_f(damping)}"/>'
            f'<inertial pos="{_f(com)} 0 0" mass="{_f(mass)}" diaginertia="{_f(ixx)} {_f(iyy)} {_f(izz)}"/>'
            f"{inner}</body>")


def mjcf(p: FiveBarParams, dt: float) -> str:
    """MJCF text of the linkage: two hinge chains, tip sites, a site ``connect``, two motors.

    Parameters
    ----------
    p : FiveBarParams
    dt : float
        Time step [s]; also sets ``solref`` = (2 dt, 1).
    """
    l, m, c, J, d = p.l, p.m, p.com, p.inertia, p.damping  # damping order A, C, B, D
    chain1 = _body("link1", (0.0, 0.0, 0.0), "A", m[0], c[0], J[0], d[0],
                   _body("link2", (l[0], 0.0, 0.0), "C", m[1], c[1], J[1], d[1],
                         f'<site name="tip2" pos="{_f(l[1])} 0 0"/>'))
    chain2 = _body("link4", (p.L0, 0.0, 0.0), "B", m[3], c[3], J[3], d[2],
                   _body("link3", (l[3], 0.0, 0.0), "D", m[2], c[2], J[2], d[3],
                         f'<site name="tip3" pos="{_f(l[2])} 0 0"/>'))
    imp = " ".join(_f(x) for x in SOLIMP)
    return f"""<mujoco model="fivebar_twin">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{_f(dt)}" integrator="RK4" gravity="0 {_f(-p.g)} 0" tolerance="1e-12"
          iterations="50">
    <flag contact="disable"/>
  </option>
  <worldbody>{chain1}{chain2}</worldbody>
  <equality>
    <connect site1="tip2" site2="tip3" solref="{_f(2 * dt)} 1" solimp="{imp}"/>
  </equality>
  <actuator>
    <motor name="uA" joint="A" gear="1"/>
    <motor name="uB" joint="B" gear="1"/>
  </actuator>
</mujoco>"""


#: The warnings of a state or control MuJoCo reset (names: MuJoCo is imported on first use).
_RESETS = ("mjWARN_BADQACC", "mjWARN_BADQVEL", "mjWARN_BADQPOS", "mjWARN_BADCTRL")


def check_resets(m: mujoco.MjModel, d: mujoco.MjData, t: float) -> None:
    """Raise :class:`~models.fivebar.integrate.BlowUpError` (one line) if MuJoCo reset the
    state or zeroed a control.

    MuJoCo answers a huge or non-finite acceleration, state or control by resetting
    (or zeroing) it and carrying on; the record would go on from the reset pose.
    """
    for name in _RESETS:
        w = getattr(mujoco.mjtWarning, name)
        n = d.warning[w].number
        if n:
            what = mujoco.mjtWarning(w).name.removeprefix("mjWARN_BAD").lower()
            raise BlowUpError(f"fivebar (mujoco): the simulation is unstable, MuJoCo reset it {n} time(s) "
                           f"after a huge or non-finite {what} by t = {t:.4f} s (RK4, timestep "
                           f"{m.opt.timestep:g} s); reduce the excitation amplitude or simulation.dt")


class MujocoTwin:
    """The compiled MuJoCo model and data of one linkage."""

    def __init__(self, p: FiveBarParams, dt: float) -> None:
        self.p = p
        self.model = mujoco.MjModel.from_xml_string(mjcf(p, dt))
        self.data = mujoco.MjData(self.model)

    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """Joint-space mass matrix (4, 4) [kg m^2] at relative coordinates ``q`` (tree order)."""
        self.data.qpos[:] = q
        mujoco.mj_forward(self.model, self.data)
        M = np.zeros((4, 4))
        mujoco.mj_fullM(self.model, self.data, M)  # MuJoCo 4.0 signature (d.qM is gone)
        return M

    def simulate(self, theta0: np.ndarray, dtheta0: np.ndarray, program: TorqueProgram, fs: float,
                 n_samples: int, progress: Callable[[float], None] | None = None) -> dict[str, np.ndarray]:
        """Integrate with ``mj_step`` (RK4) and record every sample; same outputs as
        :func:`models.fivebar.integrate.simulate`.

        The acceleration and constraint force of sample k come from ``mj_forward`` at the
        state of t_k with the torque held from t_k.  The constraint force is
        ``efc_force`` of the connect rows (world x, y), the force on link 2 at E.
        """
        m, d = self.model, self.data
        sps = round(1.0 / (fs * m.opt.timestep))
        mujoco.mj_resetData(m, d)
        d.qpos[:] = geo.to_joint(np.asarray(theta0, float))
        d.qvel[:] = geo.to_joint(np.asarray(dtheta0, float))
        Q, V, A = (np.empty((n_samples, 4)) for _ in range(3))
        U, LAM = np.empty((n_samples, 2)), np.empty((n_samples, 2))
        t = np.arange(n_samples) / fs
        for k in range(n_samples):
            q, v = d.qpos.copy(), d.qvel.copy()
            u = program.torque(k, q[[0, 2]], v[[0, 2]])
            d.ctrl[:] = u
            mujoco.mj_forward(m, d)
            Q[k], V[k], A[k], U[k] = q, v, d.qacc, u
            LAM[k] = d.efc_force[:2]
            if (k + 1) % CHECK_EVERY == 0 or k == n_samples - 1:
                k0 = (k // CHECK_EVERY) * CHECK_EVERY
                blk = slice(k0, k + 1)
                check_resets(m, d, t[k])
                check_finite(t[blk], "mujoco", m.opt.timestep, torque=U[blk], angles=Q[blk],
                             rates=V[blk], accelerations=A[blk], constraint_force=LAM[blk])
                check_transmission(geo.to_absolute(Q[blk]), t[blk], "mujoco")
                if progress is not None:
                    progress((k + 1) / n_samples)
            if k == n_samples - 1:
                break
            for _ in range(sps):
                mujoco.mj_step(m, d)
        return {"theta": geo.to_absolute(Q), "dtheta": geo.to_absolute(V), "ddtheta": geo.to_absolute(A),
                "torque": U, "constraint_force": LAM}

