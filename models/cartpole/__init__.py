"""Underactuated cart-pole rig (MuJoCo): a horizontal force on the cart, the pole passive.

Modules: :mod:`.equations` (the Lagrange equations of motion in library terms, the truth),
:mod:`.rig` (the MJCF model, the multisine force with cart centring, the registered rig).
"""

from models.cartpole.equations import CartPoleParams, true_equations, unnormalised_equations
from models.cartpole.rig import CartPoleRig, build_mjcf

__all__ = ["CartPoleParams", "CartPoleRig", "build_mjcf", "true_equations",
           "unnormalised_equations"]
