"""The MuJoCo cantilever rig with exact ground truth.

Modules: :mod:`~models.cantilever.beam` (discretisation, MJCF),
:mod:`~models.cantilever.euler_bernoulli` (continuous-beam frequencies),
:mod:`~models.cantilever.truth` (M, C, K, modes, SEREP, reduced-model simulation),
:mod:`~models.cantilever.simulate` (timestep, impact, ``mujoco.rollout``),
:mod:`~models.cantilever.model` (compiled model + truth),
:mod:`~models.cantilever.rig` (the registered ``cantilever`` rig).
"""

from models.cantilever.beam import BeamParams, build_mjcf
from models.cantilever.euler_bernoulli import eb_frequencies
from models.cantilever.model import CantileverModel, build_model
from models.cantilever.rig import CantileverRig
from models.cantilever.truth import Serep, serep, simulate_reduced

__all__ = ["BeamParams", "CantileverModel", "CantileverRig", "Serep", "build_mjcf", "build_model",
           "eb_frequencies", "serep", "simulate_reduced"]
