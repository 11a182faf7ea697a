"""`make demo`'s job: scored runs, their reports and the Eq. 21 contrast line."""

from testbed.reporting.demo import EQ21_PAIR, run_demo


def test_demo_runs_scores_reports_and_states_the_contrast(tmp_path, dataset_cache, capsys):
    assert run_demo(tmp_path, scenarios=EQ21_PAIR, cache=dataset_cache) == 0
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
