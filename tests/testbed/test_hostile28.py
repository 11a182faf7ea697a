"""Round 28's findings (``benchmarks/hostile28.py``) and review 27e's open items: a report's
outputs checked before any is written, its markdown recognised by a mark, the one refusal of a
foreign output, the public API walked with odd values, a plugin's unprintable exception."""

from __future__ import annotations

import os

import numpy as np
import pytest

import testbed
from testbed.core import atomic
from testbed.core.atomic import PNG_FILE, REPORT_MARKDOWN_FILE, refuse_foreign
from testbed.core.errors import ArgumentError, InputError, exception_text
from testbed.reporting.report import Page

PNG = b"\x89PNG\r\n\x1a\n" + bytes(32)
MINE = b"my own notes\n"


def _files(folder) -> dict[str, bytes]:
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())}


def _page(folder, *names: str) -> Page:
    page = Page("Study s", folder)
    for n in names:
        page.figure(page.png(n, PNG), n)
    return page


def test_a_report_refuses_a_foreign_output_before_writing_any(tmp_path):
    # review 27e M1: each figure was checked as it was written, so a user's fit_time.png was
    # refused after the score figures (written first) had been replaced
    (tmp_path / "fit_time.png").write_bytes(MINE)
    with pytest.raises(InputError, match=r"fit_time\.png: exists and is not a PNG figure"):
        _page(tmp_path, "score_a.png", "score_b.png", "fit_time.png").write()
    assert _files(tmp_path) == {"fit_time.png": MINE}  # nothing written, the user's file kept


def test_a_run_figure_copied_beside_the_report_does_not_replace_a_users_file(tmp_path):
    # round 28: a run's own figures were copied (shutil.copyfile) over a user's file of that
    # name in the report folder, unchecked; they are now the page's files like any other
    (tmp_path / "report.md").write_bytes(MINE)
    with pytest.raises(InputError, match=r"report\.md: exists and is not a markdown report"):
        _page(tmp_path, "reconstruction.png").write()
    assert _files(tmp_path) == {"report.md": MINE}


def test_a_report_replaces_its_own_earlier_output(tmp_path):
    _page(tmp_path, "fit_time.png").write()
    before = _files(tmp_path)
    assert before["fit_time.png"] == PNG and set(before) == {"fit_time.png", "report.html", "report.md"}
    _page(tmp_path, "fit_time.png").write()  # an earlier report of the folder: replaced
    assert _files(tmp_path) == before


@pytest.mark.parametrize("notes", [b"# Study notes\n\nmine\n", b"# Run notes: mine\n"])
def test_a_users_markdown_titled_as_a_report_is_not_taken_for_one(tmp_path, notes):
    # review 27e M2: report.md was recognised by its title line alone ("# Run " / "# Study ")
    (tmp_path / "report.md").write_bytes(notes)
    with pytest.raises(InputError, match=r"report\.md: exists and is not a markdown report"):
        refuse_foreign(tmp_path / "report.md", REPORT_MARKDOWN_FILE)
    page = _page(tmp_path / "new")
    page.out_dir.mkdir()
    page.write()
    refuse_foreign(page.out_dir / "report.md", REPORT_MARKDOWN_FILE)  # the report's own passes
    assert (page.out_dir / "report.md").read_text().splitlines()[1] == "# Study s"


@pytest.mark.parametrize("legacy", [
    "# Study leg\n\n2 cells: 2 scenario(s), 1 identifier(s) (sindy_pi_dynamical), noise levels 0 %",
    "# Run michaelis_menten: sindy_pi_dynamical\n\nPASS: 3 of 3 threshold(s) met; identifier "
    "sindy_pi_dynamical, fit 0.792 s.\n\n## Scores\n",
    "# Run m: x\n\nNO VERDICT: no thresholds declared in the scenario's [score] table (not a "
    "pass); identifier x, fit 1e+03 s.\n",
])
def test_a_report_written_before_the_mark_is_still_replaced(tmp_path, legacy):
    # (the first lines of reports written by the code before, 50cdb26): their title and the
    # fixed paragraph under it, which a user's "# Study notes" does not repeat
    (tmp_path / "report.md").write_text(legacy + "\nmore\n")
    refuse_foreign(tmp_path / "report.md", REPORT_MARKDOWN_FILE)
    (tmp_path / "report.md").write_text(legacy.replace("\n\n", "\n\nmine: ", 1))
    with pytest.raises(InputError):
        refuse_foreign(tmp_path / "report.md", REPORT_MARKDOWN_FILE)


def test_an_unreadable_output_is_refused_not_replaced(tmp_path, monkeypatch):
    # review 27e low: foreign_head passed a file it could not read, which was then replaced
    # (as root every file reads: the refusal is simulated by os.open's PermissionError)
    target = tmp_path / "fig.png"
    target.write_bytes(MINE)
    real_open = os.open

    def denied(path, flags, *a, **k):
        if os.fspath(path) == os.fspath(target):
            raise PermissionError(13, "Permission denied")
        return real_open(path, flags, *a, **k)

    monkeypatch.setattr(atomic.os, "open", denied)
    with pytest.raises(InputError, match=r"fig\.png: exists and cannot be read"):
        refuse_foreign(target, PNG_FILE)
    monkeypatch.undo()
    assert target.read_bytes() == MINE
    refuse_foreign(tmp_path / "new.png", PNG_FILE)  # nothing there: passes


def test_the_refusal_of_a_foreign_output_is_one_text_everywhere(tmp_path):
    # review 27e low: the Parquet head check of `sweep` and three refusal texts were copies
    from testbed.core.atomic import PARQUET_FILE

    p = tmp_path / "r.parquet"
    p.write_bytes(b"\x89HDF\r\n\x1a\n" + bytes(8))
    with pytest.raises(InputError) as e:
        refuse_foreign(p, PARQUET_FILE, "results r.parquet", "a results file of study 's'")
    assert str(e.value).startswith("results r.parquet: exists and is not a Parquet results file "
                                   "(it begins with b'\\x89HDF")
    assert str(e.value).endswith("expected a results file of study 's' (the file is left as it is)")


@pytest.mark.parametrize("call", [
    lambda: testbed.list_scenarios(True),
    lambda: testbed.list_scenarios(5),
    lambda: testbed.list_scenarios("x" * 5000),
    lambda: testbed.list_scenarios(check_cost=np.array([1.0, 2.0])),
    lambda: testbed.read_results("x" * 5000),
    lambda: testbed.list_runs("x" * 5000),
    lambda: testbed.resolve_run("michaelis_menten", "x" * 5000),
    lambda: testbed.run_scenario("michaelis_menten", cache="x" * 5000),
    lambda: testbed.read_measured("data.csv", format=np.array([np.nan, 1.0])),
    lambda: testbed.measurement_from_file("data.csv", "dynamical", format=5),
    lambda: testbed.load_scenario("michaelis_menten", check_cost=np.array([1.0, 2.0])),
    lambda: testbed.scenario_from_dict({}, stem=np.array([1.0, 2.0])),
    lambda: testbed.truth_field(("n",), "m", "a length", required=np.array([1.0, 2.0])),
    lambda: testbed.Scenario(name="s", rig="michaelis_menten", kind=np.array([1.0, 2.0])),
])
def test_the_apis_odd_arguments_are_refused_naming_them(call):
    # round 28 (apiwalk): TypeError / OSError 36 / numpy's "truth value ... ambiguous" from inside
    with pytest.raises(ArgumentError) as e:
        call()
    assert "\n" not in str(e.value) and len(str(e.value)) < 600


@pytest.mark.parametrize("arg", ["figures", "index"])
def test_save_new_run_refuses_a_writer_that_is_not_callable(tmp_path, arg):
    # round 28 (apiwalk): figures=5 / index="x" were TypeErrors "... is not callable" from inside
    from tests.testbed import _synthetic_runs as synth

    with pytest.raises(ArgumentError, match=f"argument '{arg}'"):
        testbed.save_new_run(synth.structural_result(n_samples=400), tmp_path, **{arg: 5})
    assert not any(tmp_path.iterdir())  # refused before anything was written


def test_a_long_unit_is_shown_cut(tmp_path):
    # round 28: a 5,000-character unit was shown three times in a 15,000-character refusal
    t = np.arange(50) / 100
    rows = "".join(f"{a!r},{b!r},{-b!r}\n" for a, b in zip(t.tolist(), np.exp(-t).tolist(),
                                                          strict=True))
    path = tmp_path / "d.csv"
    path.write_text("time [s],x [mM],dx [mM/s]\n" + rows)
    with pytest.raises(testbed.TestbedError) as e:
        testbed.measurement_from_file(path, "dynamical", units="u" * 5000)
    assert "is in uuuu" in str(e.value) and len(str(e.value)) < 600


class _Unprintable(Exception):
    def __str__(self) -> str:
        raise RuntimeError("no text")


def test_an_exception_whose_str_raises_is_named_by_its_type(tmp_path):
    # round 28 (plugstate): a plugin's exception whose __str__ raised turned its failed fit
    # (and its failed import) into an internal error
    assert exception_text(_Unprintable()) == "(no message: _Unprintable.__str__ failed)"
    assert exception_text(ValueError("a\n  b")) == "a b"
    from testbed.core.registry import PluginError, import_plugin

    plugin = tmp_path / "h28_unprintable.py"
    plugin.write_text("class E(Exception):\n    def __str__(self):\n        raise RuntimeError('x')\n"
                      "raise E()\n")
    with pytest.raises(PluginError, match=r"importing it failed: E: \(no message: E.__str__ failed\)"):
        import_plugin(str(plugin))


def test_a_double_dash_ends_the_options_before_a_positional():
    # review 27e low: `runs ls -o DIR -- NAME` was "unrecognized arguments: -- NAME"
    from testbed import cli

    parse = cli.build_parser().parse_args
    assert parse(["runs", "ls", "-o", "x", "--", "michaelis_menten"]).scenario == "michaelis_menten"
    assert parse(["runs", "ls", "-o", "x", "--", "-o"]).scenario == "-o"  # a name, after `--`
    assert parse(["run", "a", "--no-figures", "--", "-b"]).scenario == ["a", "-b"]
    with pytest.raises(SystemExit):
        parse(["runs", "ls", "-o", "x", "--", "a", "b"])  # two names: still refused


def test_an_internal_error_whose_message_cannot_be_shown_is_still_one_line(capsys):
    # round 28: the internal-error line itself called str(e), so a plugin's exception whose
    # __str__ raises (from its simulate, through the scorer) ended `testbed run` in a traceback
    import argparse

    from testbed import cli

    status = cli._internal(_Unprintable(), argparse.Namespace(debug=False, command="run"))
    err = capsys.readouterr().err
    assert status == cli.EXIT_INTERNAL and len(err.strip().splitlines()) == 1
    assert "_Unprintable: (no message: _Unprintable.__str__ failed)" in err


@pytest.mark.parametrize("body", [
    "raise Exception('mine')",
    "class E(Exception):\n        def __str__(self):\n            raise RuntimeError('x')\n"
    "    raise E()",
])
def test_a_plugins_simulate_that_raises_is_a_scored_failure(tmp_path, body):
    # round 28 (plugstate): a plugin's simulate raising its own exception was "internal error
    # ... please report it" (status 3); its fit's was already a scored failed fit
    from identify._base import _called
    from identify.ls_sindy import LeastSquaresSINDy
    from testbed.core.errors import PluginMethodError
    from testbed.scoring.scorers import simulate_scored

    ns: dict = {}
    exec(f"class Mine(LeastSquaresSINDy):\n    pass\n\ndef simulate(self, *a, **k):\n    {body}\n",
         {"LeastSquaresSINDy": LeastSquaresSINDy, "__name__": "h28_plugin"}, ns)
    model = ns["Mine"]()  # a class outside identify: a plugin's
    with pytest.raises(PluginMethodError, match=r"^Mine\.simulate raised (Exception: mine|E)"):
        _called(model, "Mine.simulate", ns["simulate"])
    t = np.linspace(0.0, 1.0, 5)
    traj, why, _ = simulate_scored(lambda: _called(model, "Mine.simulate", ns["simulate"]),
                                   t, "x", np.zeros((1, 5)))
    assert traj is None and why.startswith("simulation failed: Mine.simulate raised ")


def test_a_builtin_identifiers_own_exception_is_not_relabelled():
    # the wrap is for plugins only: a built-in's exception is a testbed bug and stays one
    from identify._base import _called
    from identify.ls_sindy import LeastSquaresSINDy

    def boom(self):
        raise RuntimeError("bug")
    with pytest.raises(RuntimeError, match="bug"):
        _called(LeastSquaresSINDy(), "LeastSquaresSINDy.simulate", boom)


def test_a_plugins_failed_prediction_is_a_scored_prediction_failure():
    # review 28a: prediction_r2 took a built-in's LinAlgError as "no R^2" (None) but let a
    # plugin's, wrapped by _called, end `testbed identify` with no verdict
    from types import SimpleNamespace

    from testbed.core.errors import PluginMethodError
    from testbed.scoring.scorers import fitted_model_failures, prediction_r2

    def fails(data):
        raise PluginMethodError("Mine.predict_acceleration raised LinAlgError: Singular matrix")
    eye = np.eye(2)
    model = SimpleNamespace(M_=eye, C_=0.01 * eye, K_=eye, predict_acceleration=fails)
    r2 = prediction_r2(model, SimpleNamespace(free_start=0, xdd=np.ones((2, 4))))
    assert np.isnan(r2)
    assert "not finite" in fitted_model_failures(model, r2)["prediction"]


def test_a_score_column_that_is_a_path_is_refused_on_read(tmp_path):
    # review 28b: a score column "x/../../../escaped" made `testbed report` write its figure
    # outside the -o folder (score_<name>.png)
    from benchmarks._hostile import results_row
    from testbed.reporting.report import Page
    from testbed.studies.results import ResultsError, read_results, write_rows

    with pytest.raises(ValueError, match="plain file name"):
        Page("t", tmp_path).png("score_x/../../escaped.png", b"")
    row = results_row()
    row["x/../../../escaped"] = 1.5
    try:
        path = write_rows(tmp_path / "r.parquet", [row], study="s")
    except ResultsError:
        return  # refused on write: nothing to read
    with pytest.raises(ResultsError, match="expected a name without a path separator"):
        read_results(path)
