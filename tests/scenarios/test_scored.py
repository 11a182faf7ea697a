"""The product: every scenario file with [identify] and [score] runs end to end and meets its
thresholds.  Thresholds live in the scenario files, each with the reason for its value."""

import pytest

from testbed.pipeline.scenario import list_scenarios
from testbed.reporting.console import print_score_table

SCORED = [s for s in list_scenarios() if s.identify is not None and s.score]
#: Runs that tests/scenarios/test_cubic_contrast.py reads too: group ``eq21`` runs each once, on
#: one worker (conftest's ``scenario_run``).
SHARED = ("cantilever_stiff_impact_cubic", "cantilever_soft_impact")


@pytest.mark.parametrize("scenario", [
    pytest.param(s, marks=pytest.mark.xdist_group("eq21")) if s.name in SHARED else s for s in SCORED],
    ids=[s.name for s in SCORED])
def test_scenario_meets_its_thresholds(scenario, scenario_run):
    result = scenario_run(scenario)
    print_score_table(result)
    failed = [f"{c.metric} = {c.value:.5g} (needs {'>=' if c.bound == 'min' else '<='} {c.threshold:g})"
              for c in result.checks if not c.passed]
    assert not failed, f"{scenario.name}: " + "; ".join(failed)
    assert not result.scores.failures, f"{scenario.name}: {result.failure}"
    assert result.passed
