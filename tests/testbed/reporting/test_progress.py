"""The progress seam: phases drawn on a terminal with their steps, nothing when not a terminal,
and every phase of a scenario run reported in order."""

from __future__ import annotations

import io
import pickle
from contextlib import contextmanager

import pytest
from rich.console import Console
from sklearn.base import clone

import testbed
from testbed.reporting.progress import progress_bar, run_progress
from testbed.scoring.run import run_scenario


def _terminal() -> tuple[Console, io.StringIO]:
    buf = io.StringIO()
    return Console(file=buf, force_terminal=True, width=120, color_system=None), buf


def test_phases_are_drawn_with_fraction_and_step_on_a_terminal():
    # what a redraw shows, drawn on demand: the display's own redraw thread (10 a second) may
    # not run within any fixed sleep on a loaded machine, and its rate is rich's, not ours
    con, buf = _terminal()
    with run_progress("demo_scenario", console=con) as phase:
        with phase("simulate") as update:
            update(0.5)
            phase.prog.refresh()
        with phase("fit") as update:
            update(None, "epoch 7/10")
            phase.prog.refresh()
    out = buf.getvalue()
    assert "demo_scenario: simulate" in out and "50%" in out
    assert "demo_scenario: fit" in out and "epoch 7/10" in out


def test_nothing_is_printed_when_stdout_is_not_a_terminal(capsys):
    with run_progress("x") as phase:
        with phase("fit") as update:
            update(0.5, "step")
    with progress_bar("y") as bar:
        bar(0.5)
    captured = capsys.readouterr()
    assert captured.out == "" and captured.err == ""


def test_a_run_reports_every_phase_in_order(dataset_cache):
    seen: list[tuple[str, object, object]] = []

    @contextmanager
    def phase(name):
        seen.append((name, None, None))
        yield lambda fraction=None, step=None: seen.append((name, fraction, step))

    class Stepping(testbed.IDENTIFIERS.get("ls_sindy")):
        def fit(self, data, y=None):
            for k in range(3):
                self.report_progress((k + 1) / 3, f"step {k + 1}/3")
            return super().fit(data)

    sc = testbed.load_scenario("cantilever_stiff_impact_lsq")
    result = run_scenario(sc, cache=dataset_cache, phase=phase, model=Stepping())
    assert result.passed
    assert [n for n, f, s in seen if f is None and s is None] == \
        ["simulate", "signal chain", "fit", "score"]
    assert [(f, s) for n, f, s in seen if n == "fit" and s] == \
        [(1 / 3, "step 1/3"), (2 / 3, "step 2/3"), (1.0, "step 3/3")]
    assert "_progress_callback" not in vars(result.model), "the display left the model"


def test_progress_callback_is_no_hyperparameter_and_not_pickled():
    model = testbed.IDENTIFIERS.get("ls_sindy")()
    got = []
    model.report_progress(0.1, "nobody listens")  # no callback: nothing happens
    with model.progress_to(lambda f, s: got.append((f, s))):
        model.report_progress(0.5, "half")
        assert "_progress_callback" not in clone(model).__dict__
        assert "_progress_callback" not in pickle.loads(pickle.dumps(model)).__dict__
        assert "_progress_callback" not in model.get_params()
    model.report_progress(0.9, "after")
    assert got == [(0.5, "half")]


def test_cli_run_piped_prints_only_the_table_and_the_folder(tmp_path, dataset_cache, capsys):
    from testbed.cli import main

    out = tmp_path / "runs"
    assert main(["run", "cantilever_stiff_impact_lsq", "--no-figures", "--cache",
                 str(dataset_cache.directory), "-o", str(out)]) == 0
    text = capsys.readouterr()
    assert text.err == ""
    for phase_name in ("simulate", "signal chain", ": fit", "score", "figures", "\r", "\x1b"):
        assert phase_name not in text.out, phase_name
    last = text.out.splitlines()[-1]
    assert last.startswith("run written to ") and str(out / "cantilever_stiff_impact_lsq") in last


@pytest.mark.parametrize("bad", [float("nan")])
def test_a_nan_fraction_leaves_the_bar_as_it_was(bad):
    con, buf = _terminal()
    with run_progress("n", console=con) as phase:
        with phase("fit") as update:
            update(0.25)
            update(bad)
            phase.prog.refresh()  # drawn on demand, not by the redraw thread's clock
    assert "25%" in buf.getvalue() and "nan" not in buf.getvalue().lower()


def test_identify_file_reports_its_phases(tmp_path, dataset_cache):
    from testbed.pipeline.fit import identify_file

    names: list[str] = []

    @contextmanager
    def phase(name):
        names.append(name)
        yield lambda fraction=None, step=None: None

    sc = testbed.load_scenario("cantilever_stiff_impact_lsq")
    dataset_cache.get(sc).save(tmp_path / "d.h5")
    fitted = identify_file(tmp_path / "d.h5", scenario=sc.name, phase=phase)
    assert names == ["read and signal chain", "fit"] and fitted.model.is_fitted()
