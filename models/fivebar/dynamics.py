"""Pinocchio model of the five-bar linkage: constrained forward dynamics, inverse dynamics,
reduced dynamics in the actuated coordinates, energy.

Two revolute-z chains (A-C-E from A = (0, 0), B-D-E from B = (L0, 0)) are closed by a
``RigidConstraintModel(CONTACT_3D, LOCAL_WORLD_ALIGNED)`` between the tips of links 2
and 3.  Coordinates here are Pinocchio's relative joint coordinates ``q`` in tree order
A, C, B, D (see :mod:`models.fivebar.params`); :mod:`models.fivebar.geometry` converts.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from models.fivebar import geometry as geo
from models.fivebar.params import FiveBarParams

if TYPE_CHECKING:
    import pinocchio as pin

#: Proximal solver settings (absolute accuracy, mu, max iterations).  With the default
#: settings constraintDynamics returns NaN: the z row of the planar loop's 3D contact
#: Jacobian is zero, so the Delassus matrix is singular and needs the proximal term.
PROX = (1e-12, 1e-8, 10)
#: Joint indices (in q and v) of the actuated joints A, B and the passive joints C, D.
ACT, PAS = [0, 2], [1, 3]


def _inertia(mass: float, com: float, izz: float) -> pin.Inertia:
    import pinocchio as pin  # lazy: ~0.1 s of import, only when the dynamics are built

    # A rod along x: only I_zz acts in the plane; I_xx small but positive and
    # I_yy = I_zz keep the 3-D tensor valid (MuJoCo's twin uses the same tensor).
    return pin.Inertia(mass, np.array([com, 0.0, 0.0]), np.diag([1e-2 * izz, izz, izz]))


def link_inertia_diag(izz: float) -> tuple[float, float, float]:
    """Principal inertia about the centre of mass used for a link in both engines [kg m^2]."""
    return 1e-2 * izz, izz, izz


class FiveBarDynamics:
    """Pinocchio model, constraint and solver state of one linkage.

    Parameters
    ----------
    p : FiveBarParams
    """

    def __init__(self, p: FiveBarParams) -> None:
        import pinocchio as pin  # lazy: ~0.1 s of import, only when the dynamics are built

        self.p = p
        model = pin.Model()
        model.name = "fivebar"
        bases = {"A": (0, np.zeros(3)), "B": (0, np.array([p.L0, 0.0, 0.0]))}
        ids: dict[str, int] = {}
        # (joint, parent joint name or base, link index 0..3 driven by the joint)
        for name, parent, link in (("A", None, 0), ("C", "A", 1), ("B", None, 3), ("D", "B", 2)):
            if parent is None:
                pid, xyz = bases[name]
            else:
                plink = {"A": 0, "B": 3}[parent]
                pid, xyz = ids[parent], np.array([p.l[plink], 0.0, 0.0])
            jid = model.addJoint(pid, pin.JointModelRZ(), pin.SE3(np.eye(3), xyz), f"joint_{name}")
            model.appendBodyToJoint(jid, _inertia(p.m[link], p.com[link], p.inertia[link]),
                                    pin.SE3.Identity())
            ids[name] = jid
        model.gravity.linear[:] = (0.0, -p.g, 0.0)
        tip2 = pin.SE3(np.eye(3), np.array([p.l[1], 0.0, 0.0]))
        tip3 = pin.SE3(np.eye(3), np.array([p.l[2], 0.0, 0.0]))
        self.frame_E2 = model.addFrame(pin.Frame("E_link2", ids["C"], 0, tip2, pin.FrameType.OP_FRAME))
        self.frame_E3 = model.addFrame(pin.Frame("E_link3", ids["D"], 0, tip3, pin.FrameType.OP_FRAME))
        self.model, self.data = model, model.createData()
        self.ids = ids
        cm = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, ids["C"], tip2, ids["D"], tip3,
                                      pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        cm.name = "loop_E"
        self.cmodels = pin.StdVec_RigidConstraintModel()
        self.cmodels.append(cm)
        self.cdatas = pin.StdVec_RigidConstraintData()
        self.cdatas.append(cm.createData())
        pin.initConstraintDynamics(model, self.data, self.cmodels, self.cdatas)
        self.prox = pin.ProximalSettings(*PROX)
        self.damping = np.asarray(p.damping, float)

    # ------------------------------------------------------------ matrices
    def mass_matrix(self, q: np.ndarray) -> np.ndarray:
        """Joint-space mass matrix (4, 4) [kg m^2] in relative coordinates, tree order."""
        import pinocchio as pin  # lazy: ~0.1 s of import, only when the dynamics are built

        M = pin.crba(self.model, self.data, q)
        return np.triu(M) + np.triu(M, 1).T

    def mass_matrix_absolute(self, theta: np.ndarray) -> np.ndarray:
        """Mass matrix (4, 4) [kg m^2] in the absolute angles th1..th4: ``P^T M(q) P``."""
        return geo.P.T @ self.mass_matrix(geo.to_joint(theta)) @ geo.P

    def loop_jacobian(self, q: np.ndarray, v: np.ndarray | None = None
                      ) -> tuple[np.ndarray, np.ndarray]:
        """Planar loop Jacobian ``d(p_E2 - p_E3)/dq`` (2, 4) [m/rad] and ``Jdot v`` (2,) [m/s^2].

        Computed by Pinocchio (frame Jacobians and classical frame accelerations at zero
        joint acceleration), independently of :func:`geometry.constraint_jacobian`.
        """
        import pinocchio as pin  # lazy: ~0.1 s of import, only when the dynamics are built

        v = np.zeros(4) if v is None else v
        m, d = self.model, self.data
        pin.forwardKinematics(m, d, q, v, np.zeros(4))
        pin.computeJointJacobians(m, d, q)
        pin.updateFramePlacements(m, d)
        lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
        J = (pin.getFrameJacobian(m, d, self.frame_E2, lwa)[:2]
             - pin.getFrameJacobian(m, d, self.frame_E3, lwa)[:2])
        bias = (pin.getFrameClassicalAcceleration(m, d, self.frame_E2, lwa).linear[:2]
                - pin.getFrameClassicalAcceleration(m, d, self.frame_E3, lwa).linear[:2])
        return J, np.array(bias)

    def reduced_dynamics(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Dynamics in the actuated coordinates (th1, th4): ``u = Mr qdd_a + hr``.

        With ``J = [J_a J_p]`` the loop Jacobian, ``S = [I; -J_p^-1 J_a]`` (rows placed at
        the actuated / passive joints) maps actuated rates to all rates and
        ``gamma = [0; -J_p^-1 Jdot v]`` is the acceleration offset; projecting
        ``M a + nle + C v = B u + J^T lambda`` on S (``S^T J^T = 0``, ``S^T B = I``) gives
        ``Mr = S^T M S`` and ``hr = S^T (M gamma + nle + C v)`` (C: joint damping).

        Returns
        -------
        Mr : ndarray, shape (2, 2) [kg m^2]
        hr : ndarray, shape (2,) [N m]
        """
        import pinocchio as pin  # lazy: ~0.1 s of import, only when the dynamics are built

        J, bias = self.loop_jacobian(q, v)
        M = self.mass_matrix(q)
        nle = pin.nonLinearEffects(self.model, self.data, q, v)
        Jp_inv = np.linalg.inv(J[:, PAS])
        S = np.zeros((4, 2))
        S[ACT] = np.eye(2)
        S[PAS] = -Jp_inv @ J[:, ACT]
        gamma = np.zeros(4)
        gamma[PAS] = -Jp_inv @ bias
        return S.T @ M @ S, S.T @ (M @ gamma + nle + self.damping * v)

    # ------------------------------------------------------------ inverse dynamics
    def inverse_dynamics(self, th_act: np.ndarray, dth_act: np.ndarray, ddth_act: np.ndarray
                         ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Actuator torques for a prescribed motion of the actuated joints (vectorised).

        The passive motion follows from the loop closure (branch ``p.branch``); Pinocchio's
        RNEA gives the joint-space force ``Q`` of the full motion (damping included); in
        absolute angles ``Q = B u + J^T lambda``, and the passive rows give ``lambda``.

        Parameters
        ----------
        th_act, dth_act, ddth_act : ndarray, shape (n, 2)
            Prescribed (th1, th4) [rad], rates [rad/s], accelerations [rad/s^2].

        Returns
        -------
        u : ndarray, shape (n, 2)
            Torques at A and B [N m].
        theta : ndarray, shape (n, 4)
            The full absolute pose [rad].
        lam : ndarray, shape (n, 2)
            Force on link 2 from link 3 at E [N] (world x, y).
        """
        import pinocchio as pin  # lazy: ~0.1 s of import, only when the dynamics are built

        p = self.p
        theta = geo.assemble(th_act[:, 0], th_act[:, 1], p)
        dtheta, ddtheta = geo.complete_rates(theta, dth_act, ddth_act, p)
        q, v, a = geo.to_joint(theta), geo.to_joint(dtheta), geo.to_joint(ddtheta)
        tau = np.empty_like(q)
        m, d = self.model, self.data
        for k in range(len(q)):
            tau[k] = pin.rnea(m, d, q[k], v[k], a[k])
        tau += self.damping * v
        Q = tau @ geo.P  # generalised forces on the absolute angles: P^T tau, row-wise
        J = geo.constraint_jacobian(theta, p)
        lam = np.linalg.solve(np.swapaxes(J[..., list(geo.PASSIVE)], -1, -2),
                              Q[:, list(geo.PASSIVE), None])[..., 0]
        u = Q[:, list(geo.ACTUATED)] - np.einsum("nij,ni->nj", J[..., list(geo.ACTUATED)], lam)
        return u, theta, lam

    # ------------------------------------------------------------ energy
    def energy(self, q: np.ndarray, v: np.ndarray) -> float:
        """Kinetic plus potential energy [J] (potential zero at y = 0)."""
        import pinocchio as pin  # lazy: ~0.1 s of import, only when the dynamics are built

        T = pin.computeKineticEnergy(self.model, self.data, q, v)
        V = pin.computePotentialEnergy(self.model, self.data, q)
        return float(T + V)
