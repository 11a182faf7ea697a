"""Michaelis-Menten enzyme kinetics with a constant influx (the SINDy-PI paper's rational ODE).

Modules: :mod:`.rig` (the registered rig ``michaelis_menten``: the ODE, its simulation and its
implicit-form truth).
"""

from models.michaelis_menten.rig import MichaelisMentenRig, implicit_equation, rate

__all__ = ["MichaelisMentenRig", "implicit_equation", "rate"]
