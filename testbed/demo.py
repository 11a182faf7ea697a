"""`make demo`: the main job, scored scenario runs end to end and their report."""

from __future__ import annotations

from pathlib import Path

from testbed.cache import DatasetCache
from testbed.run import run_scenario
from testbed.scenario import load_scenario
from testbed.summaries import print_score_table, print_truth_summary

DEMO_SCENARIOS = ("cantilever_stiff_impact", "cantilever_soft_impact")


def run_demo(out: Path, scenarios: tuple[str, ...] = DEMO_SCENARIOS) -> int:
    """Run each scenario (data cached), print truth and scores, write runs and reports.

    Returns 0 when every scenario passes its thresholds, else 1.
    """
    from testbed.report import write_report
    from testbed.runstore import save_run

    cache = DatasetCache()
    ok = True
    for name in scenarios:
        sc = load_scenario(name)
        result = run_scenario(sc, cache=cache)
        print_truth_summary(result.dataset)
        print_score_table(result)
        run_dir = save_run(result, out / "runs" / sc.name)
        html = write_report(run_dir, out / "reports" / sc.name)
        print(f"report: {html.resolve()}")
        ok &= result.passed
    return 0 if ok else 1
