"""The product: every scenario file with [identify] and [score] runs end to end and meets its
thresholds.  Thresholds live in the scenario files, each with the reason for its value."""

import pytest

from testbed.pipeline.scenario import list_scenarios
from testbed.reporting.console import print_score_table

SCORED = [s for s in list_scenarios() if s.identify is not None and s.score]
#: Runs that tests/scenarios/test_cubic_contrast.py reads too: group ``eq21`` runs each once, on
#: one worker (conftest's ``scenario_run``).
SHARED = ("cantilever_stiff_impact_cubic", "cantilever_soft_impact")


#: Verdicts measured to fail on a bar that stays (the lead decides how each is carried); strict:
#: the mark trips when the scenario passes again.  None at present: ``cantilever_soft_impact``
#: (``K3_force_error`` 0.213 against the corrected cubic truth, the identified mass's error
#: over the bar) passes again at 0.088 since a cubic model shares its mass by the free decay's
#: gain at the driving point (``identify.structural.driving_point_scaling``; docs/known-gaps.md,
#: "A cubic model's mass from the free decay's driving-point gain").
KNOWN_FAILING: dict[str, str] = {}


def _param(s):
    marks = [pytest.mark.xdist_group("eq21")] if s.name in SHARED else []
    if s.name in KNOWN_FAILING:
        marks.append(pytest.mark.xfail(strict=True, raises=AssertionError,
                                       reason=KNOWN_FAILING[s.name]))
    return pytest.param(s, marks=marks)


@pytest.mark.parametrize("scenario", [_param(s) for s in SCORED], ids=[s.name for s in SCORED])
def test_scenario_meets_its_thresholds(scenario, scenario_run):
    result = scenario_run(scenario)
    print_score_table(result)
    failed = [f"{c.metric} = {c.value:.5g} (needs {'>=' if c.bound == 'min' else '<='} {c.threshold:g})"
              for c in result.checks if not c.passed]
    assert not failed, f"{scenario.name}: " + "; ".join(failed)
    assert not result.scores.failures, f"{scenario.name}: {result.failure}"
    assert result.passed
