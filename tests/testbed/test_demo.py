"""`make demo`'s job: scored runs, their reports and the Eq. 21 contrast line."""

from testbed.reporting.demo import EQ21_PAIR, run_demo


def test_demo_runs_scores_reports_and_states_the_contrast(tmp_path, dataset_cache, capsys):
    assert run_demo(tmp_path, scenarios=EQ21_PAIR, cache=dataset_cache) == 0
    for name in EQ21_PAIR:
        assert (tmp_path / "reports" / name / "report.html").is_file()
    out = capsys.readouterr().out
    assert "Eq. 21 contrast" in out and "cubic matrix norm 0 " in out
