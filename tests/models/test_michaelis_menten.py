"""The Michaelis-Menten rig against its closed-form time-of-state and its implicit truth."""

import numpy as np
import pytest

from models.michaelis_menten import implicit_equation, rate
from testbed.core.errors import ScenarioError
from testbed.core.truth import DynamicalTruth
from testbed.pipeline.plugins import rig_class
from testbed.pipeline.scenario import load_scenario, scenario_from_dict


@pytest.fixture(scope="module")
def dataset():
    return rig_class("michaelis_menten")(load_scenario("michaelis_menten")).simulate()


def test_trajectory_matches_the_closed_form_time_of_state(dataset):
    # dt/dx = (Km + x) / (a x + b), a = jx - Vmax, b = jx Km, integrates to
    # t(x) = (x - x0) / a + (Km - b / a) / a * ln((a x + b) / (a x0 + b)): independent of solve_ivp
    jx, vmax, km = dataset.truth["parameter_values"]
    x0 = float(dataset.truth["x0"][0])
    a, b = jx - vmax, jx * km
    x = dataset.measured["x"].data[0]
    t_exact = (x - x0) / a + (km - b / a) / a * np.log((a * x + b) / (a * x0 + b))
    # 1e-9 s: the integrator's rtol 1e-12 on x, amplified by 1 / |dx/dt| >= 1 / 1.4 s/mM and by
    # the log's condition near the steady state (x(4 s) - x* = 0.045 mM)
    np.testing.assert_allclose(t_exact, dataset.t, atol=1e-9)


def test_truth_is_the_odes_implicit_form_and_holds_on_the_data(dataset):
    truth = DynamicalTruth.from_dict(dataset.truth, dataset.truth_units)
    assert truth.equation_terms == ["dx", "x*dx", "1", "x"] and truth.state_names == ["x"]
    # (Km, 1, -jx Km, Vmax - jx) up to scale, for the paper's 0.6, 1.5, 0.3
    np.testing.assert_allclose(truth.equation_coef, [[0.3, 1.0, -0.18, 0.9]], rtol=1e-15)
    x, dx = dataset.measured["x"].data[0], dataset.measured["dx"].data[0]
    cols = np.stack([dx, x * dx, np.ones_like(x), x])
    resid = truth.equation_coef[0] @ cols
    assert np.max(np.abs(resid)) < 1e-14 * 10  # round-off of four O(1) products
    np.testing.assert_allclose(dx, rate(x, 0.6, 1.5, 0.3))


def test_implicit_equation_scale_is_the_largest_raw_coefficient():
    terms, coef, scale = implicit_equation(jx=0.1, vmax=2.0, km=3.0)
    assert scale == 3.0 and terms[0] == "dx"
    np.testing.assert_allclose(coef[0] * scale, [3.0, 1.0, -0.3, 1.9])


def test_a_rate_the_enzyme_cannot_match_is_refused():
    with pytest.raises(ScenarioError, match=r"rig\.Vmax"):
        scenario_from_dict({"scenario": {"name": "x", "rig": "michaelis_menten"},
                            "rig": {"jx": 2.0, "Vmax": 1.5}})


def test_a_start_at_the_steady_state_is_refused_naming_x0():
    # x0 = jx Km / (Vmax - jx) = 0.2 mM: the record was constant and the fit a scored
    # "singular" divergence at t = 0 instead of a load-time error
    with pytest.raises(ScenarioError, match=r"key 'rig\.x0': value 0\.2: .*steady state"):
        scenario_from_dict({"scenario": {"name": "mm", "rig": "michaelis_menten"},
                            "rig": {"x0": 0.2}})
    scenario_from_dict({"scenario": {"name": "mm", "rig": "michaelis_menten"}, "rig": {"x0": 0.21}})


def test_a_stiff_rate_law_is_refused_by_the_step_budget_naming_vmax():
    # Vmax / Km = 3.3e9 /s: the explicit DOP853 would need ~2e9 steps over 4 s (it hung for
    # minutes before the budget counted stiffness); the shipped rates cost 25 steps per second
    from testbed.core.errors import BudgetError

    with pytest.raises(BudgetError, match=r"key 'rig\.Vmax'.*integration steps"):
        scenario_from_dict({"scenario": {"name": "x", "rig": "michaelis_menten"},
                            "rig": {"Vmax": 1e9}})
    scenario_from_dict({"scenario": {"name": "x", "rig": "michaelis_menten"}, "rig": {"Vmax": 1e3}})


@pytest.mark.parametrize("simulation", [{"sample_rate": 1e-6}, {"duration": 1e-6}])
def test_a_record_of_fewer_than_two_samples_is_refused(simulation):
    # no sample at all was an internal error (IndexError) in the simulation
    with pytest.raises(ScenarioError, match=r"'simulation\.duration'.*at least two samples"):
        scenario_from_dict({"scenario": {"name": "x", "rig": "michaelis_menten"},
                            "simulation": simulation})
