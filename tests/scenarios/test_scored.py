"""The product: every scenario file with [identify] and [score] runs end to end and meets its
thresholds.  Thresholds live in the scenario files, each with the reason for its value."""

import pytest

from testbed.pipeline.scenario import list_scenarios
from testbed.reporting.console import print_score_table
from testbed.scoring.run import run_scenario

SCORED = [s for s in list_scenarios() if s.identify is not None and s.score]


@pytest.mark.parametrize("scenario", SCORED, ids=[s.name for s in SCORED])
def test_scenario_meets_its_thresholds(scenario, dataset_cache):
    result = run_scenario(scenario, cache=dataset_cache)
    print_score_table(result)
    failed = [f"{c.metric} = {c.value:.5g} (needs {'>=' if c.bound == 'min' else '<='} {c.threshold:g})"
              for c in result.checks if not c.passed]
    assert not failed, f"{scenario.name}: " + "; ".join(failed)
    assert not result.scores.failures, f"{scenario.name}: {result.failure}"
    assert result.passed
