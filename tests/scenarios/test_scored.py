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
#: the mark trips when the scenario passes again.  ``cantilever_soft_impact``: against the
#: corrected cubic truth (``models/cantilever/model.py``, ``cubic_direction``; the stored
#: ``T^T e0`` left a residual of 0.30 x the cubic force on the exact motion) ``sgd_sindy``'s
#: cubic acceleration error falls 0.218 -> 0.096 but its ``K3_force_error`` rises 0.059 ->
#: 0.213 (bar 0.10): the identified mass's error alone, ``(M - Mr) Mr^-1 f``, is 0.145 of the
#: cubic force (``Mr_error`` 0.124); the stored truth's 0.059 was a cancellation of 0.19 and
#: 0.16 (docs/known-gaps.md, "The soft base's cubic truth, corrected").
KNOWN_FAILING = {
    "cantilever_soft_impact": "K3_force_error 0.213 > 0.10 against the corrected cubic truth: "
                              "the identified mass's error (0.145 of the force) is over the bar",
}


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
