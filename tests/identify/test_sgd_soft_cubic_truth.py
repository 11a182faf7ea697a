"""What ``sgd_sindy``'s soft-base cubic is scored against: is the truth's cubic the motion's?

``K3_force_error`` and ``K3_accel_error`` compare the identified ``K3 x^3`` with the reduced
truth's ``k3 d (c . x)^3`` (``cubic_direction`` ``d``, ``cubic_map`` ``c``, both SEREP's ``T^T
e0``).  On the exact signals of ``cantilever_soft_impact`` (MuJoCo's, no signal chain) the
reduced truth's own equation leaves a residual of 0.30 x that cubic force: SEREP's ``T^T e0`` is
the Galerkin projection of the base's moment and leaves out the truncated modes' static response
to it, which the sensors see (docs/known-gaps.md, "The soft base's cubic truth in sensor
coordinates"; with ``d = T^T e0 + Kr Js R e0``, ``R`` the full model's residual flexibility, the
residual is 0.031).  A truth whose own residual exceeds the issue's 0.1 cannot score an
identifier's cubic at that bar.  The correction is the truth's (``models/cantilever/model.py``),
not this identifier's: strict xfail until it is made, so that the fix is seen here.
"""

from __future__ import annotations

import numpy as np
import pytest

from testbed.core.truth import StructuralTruth
from testbed.pipeline.scenario import load_scenario

#: Issue #15's bar on the cubic force: the reduced truth's own residual on the exact motion must
#: be below it for the cubic scores to mean what they say (measured 0.296; corrected 0.031).
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


@pytest.mark.xfail(strict=True, raises=AssertionError,
                   reason="SEREP's cubic direction T^T e0 leaves out the truncated modes' static "
                          "response (docs/known-gaps.md): residual 0.30 of the cubic force")
def test_reduced_truth_cubic_is_the_motions(dataset_cache):
    ds = dataset_cache.get(load_scenario("cantilever_soft_impact"))
    truth = ds.truth_as(StructuralTruth)
    i0 = int(ds.attrs["free_start"]) + AFTER_PULSE
    x, xd, xdd = (np.asarray(ds.reference[k].data, dtype=float)[:, i0:]
                  for k in ("displacement", "velocity", "acceleration"))
    assert reduced_truth_residual(truth, x, xd, xdd) <= CUBIC_BAR
