"""Five-bar linkage rig (two actuated revolute chains closed at E), Pinocchio truth + MuJoCo twin.

Modules: :mod:`.params` (parameters, lumped coefficients), :mod:`.geometry` (loop
closure, kinematics, transmission angle), :mod:`.dynamics` (Pinocchio constrained,
inverse and reduced dynamics), :mod:`.excitation` (schemas and torque programs),
:mod:`.integrate` (RK4), :mod:`.twin` (MuJoCo twin), :mod:`.equations` (true library
equations), :mod:`.rig` (the registered rig).
"""

from models.fivebar.dynamics import FiveBarDynamics
from models.fivebar.equations import evaluate_terms, true_equations, true_library_residual
from models.fivebar.params import FiveBarParams
from models.fivebar.rig import FiveBarRig

__all__ = ["FiveBarDynamics", "FiveBarParams", "FiveBarRig", "evaluate_terms", "true_equations",
           "true_library_residual"]
