"""The paper's Eq. 21 contrast, across two scenario files: with the same identifier and the same
hyperparameters, the clamped (linear) beam's cubic matrix is at least 100x smaller in norm
than the soft (cubic-spring) base's.  Each file is also scored on its own in test_scored.py;
this test ties the two together so that neither can drift.  It reads the very runs those two
scored tests made (:func:`conftest.scenario_run`, group ``eq21``: one worker), not fits of its own."""

import numpy as np
import pytest

from testbed.pipeline.scenario import load_scenario

LINEAR, NONLINEAR = "cantilever_stiff_impact_cubic", "cantilever_soft_impact"


def test_same_identifier_and_hyperparameters():
    assert load_scenario(LINEAR).identify == load_scenario(NONLINEAR).identify


@pytest.mark.xdist_group("eq21")
def test_linear_beam_cubic_matrix_hundredfold_smaller(scenario_run):
    lin = scenario_run(LINEAR).model
    soft = scenario_run(NONLINEAR).model
    # measured: 0 against 2.2e13 N/m^3 (the paper's Eq. 21: one entry of 3.1e10 against 1.9e12)
    assert np.linalg.norm(soft.K3_) > 0
    assert np.linalg.norm(lin.K3_) <= 0.01 * np.linalg.norm(soft.K3_)
