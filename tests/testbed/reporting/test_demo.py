"""`make demo`'s job: scored runs, their reports and the Eq. 21 contrast line."""

import pytest

from testbed.reporting import demo
from testbed.reporting.demo import EQ21_PAIR, run_demo


# Group ``eq21`` (conftest ``scenario_run``): the demo's two runs are the fits the scored tests of
# the same two scenarios and the Eq. 21 contrast read, made once on one worker.  Measured warm
# (2026-11-26): the two fits are 11.5 s of the demo's 14.1 s of CPU; what the demo adds (its lines,
# the run history, figures and reports) is what this test checks.
@pytest.mark.xdist_group("eq21")
def test_demo_runs_scores_reports_and_states_the_contrast(tmp_path, dataset_cache, capsys,
                                                          scenario_run, monkeypatch):
    asked = []

    def shared_run(sc, *, cache=None, phase=None):
        """The demo's call, answered with the group's run of the same scenario (the same
        ``run_scenario(sc, cache=dataset_cache)``), after checking what the demo passed."""
        assert cache is dataset_cache and phase is not None
        asked.append(sc.name)
        return scenario_run(sc)

    monkeypatch.setattr(demo, "run_scenario", shared_run)
    assert run_demo(tmp_path, scenarios=EQ21_PAIR, cache=dataset_cache) == 0
    assert asked == list(EQ21_PAIR)
    for name in EQ21_PAIR:
        assert (tmp_path / "reports" / name / "report.html").is_file()
    out = capsys.readouterr().out
    assert "Eq. 21 contrast" in out and "cubic matrix norm 0 " in out
    # which step it is at: a line before each scenario's tables
    starts = [out.index(f"[{k}/2] {name}:") for k, name in enumerate(EQ21_PAIR, 1)]
    assert starts == sorted(starts) and out.index("report:") > starts[0]
    # the runs join the run history, with their index page
    index = (tmp_path / "runs" / "index.html").read_text()
    assert all(name in index for name in EQ21_PAIR) and index.count("<tr>") == 1 + 2
