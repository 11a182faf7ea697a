"""Physical parameters of the five-bar linkage and the lumped inertia coefficients.

Conventions used throughout :mod:`models.fivebar`:

- Links: 1 = A-C (actuated at A = (0, 0)), 2 = C-E, 3 = D-E, 4 = B-D (actuated at
  B = (L0, 0)); the loop closes at E.  Angles ``th1..th4`` are ABSOLUTE (from the
  world x axis, counter-clockwise), as in the paper: ``C = L1 e(th1)``,
  ``E = C + L2 e(th2) = D + L3 e(th3)``, ``D = B + L4 e(th4)``.
- Pinocchio / MuJoCo use RELATIVE joint coordinates in tree order
  ``q = (qA, qC, qB, qD) = (th1, th2 - th1, th4, th3 - th4)``.
- Every link is a rod along its own x axis from its proximal joint, centre of mass
  at ``com`` (uniform rod: half the length) on that axis, inertia ``inertia`` about
  the centre of mass for rotation in the plane.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

#: Standard gravity [m/s^2], acting along -y of the linkage plane when switched on.
G0 = 9.80665

@dataclass(frozen=True)
class FiveBarParams:
    """Geometry, inertia and damping of the linkage.

    Attributes
    ----------
    l : ndarray, shape (4,)
        Link lengths L1..L4 [m] (index 0 is link 1).
    L0 : float
        Base length |AB| [m].
    m : ndarray, shape (4,)
        Link masses [kg].
    inertia : ndarray, shape (4,)
        Link inertia about its centre of mass, about the plane normal [kg m^2].
    com : ndarray, shape (4,)
        Distance of each link's centre of mass from its proximal joint [m].
    damping : ndarray, shape (4,)
        Viscous damping [N m s/rad] of the four modelled revolute joints in the
        order A, C, B, D (on the RELATIVE joint rates).  The closing joint E is the
        loop constraint and is frictionless.
    g : float
        Gravity [m/s^2] along -y of the plane (0 for the horizontal plane).
    branch : str
        ``"up"`` (E to the left of the directed segment C->D, i.e. above it for
        C left of D) or ``"down"``.
    """

    l: np.ndarray
    L0: float
    m: np.ndarray
    inertia: np.ndarray
    com: np.ndarray
    damping: np.ndarray
    g: float = 0.0
    branch: str = "up"

    @classmethod
    def from_rig(cls, rig: dict[str, Any]) -> FiveBarParams:
        """Build from a validated ``[rig]`` table (see :data:`models.fivebar.rig.RIG_SCHEMA`)."""
        l = np.array([rig[f"l{i}"] for i in range(1, 5)], dtype=float)
        m = np.array([rig[f"m{i}"] for i in range(1, 5)], dtype=float)
        with np.errstate(over="ignore"):  # a link beyond ~1e154 m: inf, which the rig refuses
            inertia = np.array([rig[f"I{i}"] if rig[f"I{i}"] > 0 else m[i - 1] * l[i - 1] ** 2 / 12.0
                                for i in range(1, 5)])
        return cls(l=l, L0=float(rig["L0"]), m=m, inertia=inertia, com=l / 2.0,
                   damping=np.full(4, float(rig["damping"])), g=G0 if rig["gravity"] else 0.0,
                   branch=rig["branch"])

    @property
    def lumped(self) -> dict[str, float]:
        """Lumped coefficients of the two chains' Lagrange equations (absolute angles).

        ``a1 = I1 + m1 c1^2 + m2 l1^2``, ``a2 = I2 + m2 c2^2``, ``b1 = m2 l1 c2`` (chain A-C-E);
        ``a4 = I4 + m4 c4^2 + m3 l4^2``, ``a3 = I3 + m3 c3^2``, ``b2 = m3 l4 c3`` (chain B-D-E);
        ``g1 = g (m1 c1 + m2 l1)``, ``g2 = g m2 c2``, ``g3 = g m3 c3``, ``g4 = g (m4 c4 + m3 l4)``
        [kg m^2, N m].
        """
        l, m, c, J, g = self.l, self.m, self.com, self.inertia, self.g
        return {
            "a1": J[0] + m[0] * c[0] ** 2 + m[1] * l[0] ** 2, "a2": J[1] + m[1] * c[1] ** 2,
            "b1": m[1] * l[0] * c[1],
            "a4": J[3] + m[3] * c[3] ** 2 + m[2] * l[3] ** 2, "a3": J[2] + m[2] * c[2] ** 2,
            "b2": m[2] * l[3] * c[2],
            "g1": g * (m[0] * c[0] + m[1] * l[0]), "g2": g * m[1] * c[1], "g3": g * m[2] * c[2],
            "g4": g * (m[3] * c[3] + m[2] * l[3]),
        }

    def truth(self) -> tuple[dict[str, Any], dict[str, str]]:
        """Truth arrays and their units for a :class:`~testbed.core.dataset.Dataset`."""
        values = {"link_lengths": self.l.copy(), "base_length": np.float64(self.L0),
                  "link_masses": self.m.copy(), "link_inertias": self.inertia.copy(),
                  "link_com": self.com.copy(), "joint_damping": self.damping.copy(),
                  "gravity": np.float64(self.g)}
        units = {"link_lengths": "m", "base_length": "m", "link_masses": "kg",
                 "link_inertias": "kg m^2", "link_com": "m", "joint_damping": "N m s/rad",
                 "gravity": "m/s^2"}
        return values, units
