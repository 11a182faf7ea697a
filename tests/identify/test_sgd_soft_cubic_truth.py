"""What ``sgd_sindy``'s soft-base cubic is scored against: is the truth's cubic the motion's?

``K3_force_error`` and ``K3_accel_error`` compare the identified ``K3 x^3`` with the reduced
truth's ``k3 d (c . x)^3`` (``cubic_direction`` ``d``, ``cubic_map`` ``c = T^T e0``).  SEREP's
``T^T e0`` alone, the Galerkin projection of the base's moment, left out the truncated modes'
static response to it, which the sensors see: on the exact signals of
``cantilever_soft_impact`` (MuJoCo's, no signal chain) the reduced truth's own equation left a
residual of 0.296 x its cubic force.  With ``d = T^T e0 + Kr Js R e0`` (``R`` the full model's
residual flexibility beyond the sensed modes; ``models/cantilever/model.py``,
``CantileverModel.cubic_direction``) it is 0.031 (docs/known-gaps.md, "The soft base's cubic
truth, corrected").  A truth whose own residual exceeds the issue's 0.1 could not score an
identifier's cubic at that bar.
"""

from __future__ import annotations

import numpy as np
import pytest

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


def _chain(n: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """A fixed-free spring-mass chain of ``n`` unequal masses [kg] and springs [N/m]."""
    M = np.diag([1.0, 0.7, 0.4][:n])
    k = np.array([3.0e4, 2.0e4, 1.5e4][:n])
    K = np.diag(k + np.append(k[1:], 0.0)) - np.diag(k[1:], 1) - np.diag(k[1:], -1)
    return M, K


def test_truncated_static_load_on_a_chain():
    """The correction on a 3-DOF chain reduced to 2 sensed masses, against the exact response.

    A load on the root mass at frequency ``w`` well below the truncated mode: the full chain's
    steady state at the sensors, ``Js (K - w^2 M)^-1 l`` (computed directly), against the
    reduced model's ``(Kr - w^2 Mr)^-1 b`` with SEREP's ``b = T^T l`` and with
    ``b = T^T l + Kr Js R l``.  Static (``w = 0``) the corrected load is exact to round-off;
    quasi-static its error is second order in ``w / w_3`` (the neglected ``Mr s''``), SEREP's
    is not.
    """
    from models.cantilever.truth import residual_flexibility, serep, truncated_static_load

    M, K = _chain()
    lam, phi = np.linalg.eigh(np.linalg.solve(np.linalg.cholesky(M), np.linalg.solve(
        np.linalg.cholesky(M), K).T))
    phi = np.linalg.solve(np.linalg.cholesky(M).T, phi)  # mass-normalised, ascending
    Js = np.eye(3)[1:]  # the two outer masses are sensed
    red = serep(M, np.zeros_like(K), K, Js, phi)
    R = residual_flexibility(K, phi, 2)
    load = np.array([1.0, 0.0, 0.0])
    b_serep = red.T.T @ load
    b_corr = b_serep + truncated_static_load(red.Kr, Js, R, load)
    w3 = np.sqrt(lam[2])
    errs = {}
    for ratio in (0.0, 0.05, 0.1):
        w2 = (ratio * w3) ** 2
        exact = Js @ np.linalg.solve(K - w2 * M, load)
        errs[ratio] = [np.linalg.norm(np.linalg.solve(red.Kr - w2 * red.Mr, b) - exact)
                       / np.linalg.norm(exact) for b in (b_serep, b_corr)]
    assert errs[0.0][1] < 1e-12, errs  # static condensation: exact (round-off)
    assert errs[0.0][0] > 1e-3, errs  # SEREP's Galerkin load misses the truncated mode (0.146)
    # quasi-static: the corrected error is (w / w3)^2 (measured 0.0025 and 0.0100: x4 from 0.05 to
    # 0.1, 10 % for the higher-order terms), far below SEREP's (0.142, 0.131)
    assert errs[0.1][1] / errs[0.05][1] == pytest.approx(4.0, rel=0.1), errs
    assert errs[0.1][1] < 0.1 * errs[0.1][0], errs
