"""What ``sgd_sindy``'s soft-base cubic is scored against: is the truth's cubic the motion's?

``K3_force_error`` and ``K3_accel_error`` compare the identified ``K3 x^3`` with the reduced
truth's ``k3 d (c . x)^3`` (``cubic_direction`` ``d``, ``cubic_map`` ``c = T^T e0``).  SEREP's
``T^T e0`` alone, the Galerkin projection of the base's moment, left out the truncated modes'
static response to it, which the sensors see: on the exact signals of
``cantilever_soft_impact`` (MuJoCo's, no signal chain) the reduced truth's own equation left a
residual of 0.296 x its cubic force.  With ``d = T^T e0 + Kr Js R e0`` (``R`` the full model's
residual flexibility beyond the sensed modes; ``models/cantilever/model.py``,
``CantileverModel.cubic_direction``; its 3-DOF chain check in
``tests/models/test_cantilever_model.py``) it is 0.031 (docs/known-gaps.md, "The soft base's
cubic truth, corrected").  A truth whose own residual exceeds the issue's 0.1 could not score an
identifier's cubic at that bar.
"""

from __future__ import annotations

import numpy as np

from testbed.core.truth import StructuralTruth
from testbed.pipeline.scenario import load_scenario

#: Issue #15's bar on the cubic force: the reduced truth's own residual on the exact motion must
#: be below it for the cubic scores to mean what they say (measured 0.031; 0.296 with SEREP's
#: ``T^T e0`` alone; what remains is second order in the cubic, the argument's shift by the
#: base's residual flexibility, 0.002 without it).
CUBIC_BAR = 0.1
#: Samples after the impact's end before the comparison starts (the pulse's quasi-static
#: response of the unmodelled modes decays within them; known-gaps' measurement used the same).
AFTER_PULSE = 200


def reduced_truth_residual(truth: StructuralTruth, x: np.ndarray, xd: np.ndarray,
                           xdd: np.ndarray) -> float:
    """``||Mr^-1 r|| / ||Mr^-1 f||`` [-]: the reduced truth's equation residual ``r = Mr x'' +
    Cr x' + Kr x + f`` relative to its cubic force ``f = k3 d (c . x)^3`` (arrays (n, N), SI)."""
    f = np.outer(truth.cubic_direction, float(truth.k3) * (truth.cubic_map @ x) ** 3)
    r = truth.Mr @ xdd + truth.Cr @ xd + truth.Kr @ x + f
    return float(np.linalg.norm(np.linalg.solve(truth.Mr, r))
                 / np.linalg.norm(np.linalg.solve(truth.Mr, f)))


def test_reduced_truth_cubic_is_the_motions(dataset_cache):
    ds = dataset_cache.get(load_scenario("cantilever_soft_impact"))
    truth = ds.truth_as(StructuralTruth)
    i0 = int(ds.attrs["free_start"]) + AFTER_PULSE
    x, xd, xdd = (np.asarray(ds.reference[k].data, dtype=float)[:, i0:]
                  for k in ("displacement", "velocity", "acceleration"))
    assert reduced_truth_residual(truth, x, xd, xdd) <= CUBIC_BAR

