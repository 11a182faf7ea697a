"""The cart-pole's exact implicit equations of motion (Lagrange), in library terms.

Coordinates (the library's spelling, :mod:`testbed.core.terms`): ``th1`` = cart position x
[m] along the rail, ``th2`` = pole angle [rad] from the downward vertical (0: hanging), positive
when the pole's tip swings towards +x; ``u1`` = horizontal force on the cart [N].

The pole is a rigid body of mass ``m`` [kg], centre of mass at ``l`` [m] from the hinge, inertia
``I`` [kg m^2] about its centre of mass; the cart has mass ``M`` [kg].  Centre of mass of the
pole: ``(x + l sin th, -l cos th)``.  With ``T = M xd^2 / 2 + m |d(com)/dt|^2 / 2 + I thd^2 / 2``,
``V = -m g l cos th`` and viscous joint damping ``b_x`` [N s/m], ``b_th`` [N m s/rad]:

    (M + m) xdd + m l cos(th) thdd - m l sin(th) thd^2 + b_x xd = u
    m l cos(th) xdd + (I + m l^2) thdd + m g l sin(th) + b_th thd = 0

i.e. ``0 = (M+m) ddth1 + m l cos(th2)*ddth2 - m l sin(th2)*dth2^2 + b_x dth1 - u1`` and
``0 = m l cos(th2)*ddth1 + (I + m l^2) ddth2 + m g l sin(th2) + b_th dth2``.  The second
equation (the passive pole's) has no input term.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np


@dataclass(frozen=True)
class CartPoleParams:
    """Physical parameters (SI units).

    Attributes
    ----------
    cart_mass : float
        M [kg].
    pole_mass : float
        m [kg].
    pole_length : float
        Length of the uniform pole [m]; centre of mass at ``l = pole_length / 2``, inertia about
        it ``m pole_length^2 / 12`` [kg m^2].
    cart_damping : float
        b_x [N s/m].
    pole_damping : float
        b_th [N m s/rad].
    gravity : float
        g [m/s^2].
    """

    cart_mass: float
    pole_mass: float
    pole_length: float
    cart_damping: float
    pole_damping: float
    gravity: float

    @classmethod
    def from_rig(cls, rig: dict[str, Any]) -> CartPoleParams:
        """From a validated ``[rig]`` table."""
        return cls(*(float(rig[k]) for k in ("cart_mass", "pole_mass", "pole_length",
                                             "cart_damping", "pole_damping", "gravity")))

    @property
    def com(self) -> float:
        """Hinge to the pole's centre of mass, l [m]."""
        return 0.5 * self.pole_length

    @property
    def inertia(self) -> float:
        """Pole inertia about its centre of mass, I = m L^2 / 12 [kg m^2]."""
        return self.pole_mass * self.pole_length**2 / 12.0


def unnormalised_equations(p: CartPoleParams) -> list[dict[str, float]]:
    """The two equations as {term: coefficient} (row 1 [N], row 2 [N m]); zero terms left out."""
    m, l, g = p.pole_mass, p.com, p.gravity
    cart = {"ddth1": p.cart_mass + m, "cos(th2)*ddth2": m * l, "sin(th2)*dth2^2": -m * l,
            "dth1": p.cart_damping, "u1": -1.0}
    pole = {"cos(th2)*ddth1": m * l, "ddth2": p.inertia + m * l**2, "sin(th2)": m * g * l,
            "dth2": p.pole_damping}
    return [{t: c for t, c in eq.items() if c != 0.0} for eq in (cart, pole)]


def true_equations(p: CartPoleParams) -> tuple[list[str], np.ndarray, np.ndarray]:
    """Term names, normalised coefficients and the divisors of the true equations.

    Each row is divided by its largest-magnitude coefficient, sign included (an implicit
    equation is defined only up to scale); the term list is the sorted union of both rows.

    Returns
    -------
    terms : list of str
        Canonical term names, length t.
    coef : ndarray, shape (2, t)
        Normalised coefficients [-].
    scale : ndarray, shape (2,)
        The divisor of each row [N for row 1, N m for row 2].
    """
    eqs = unnormalised_equations(p)
    terms = sorted({t for eq in eqs for t in eq})
    coef = np.array([[eq.get(t, 0.0) for t in terms] for eq in eqs])
    scale = coef[np.arange(2), np.argmax(np.abs(coef), axis=1)]
    return terms, coef / scale[:, None], scale
