"""The platform commands: --version, help on every option, `list` piped (whole names, origins),
plugins from a file and from an entry point, `identify` on a data file, `runs ls`."""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from testbed.cli import EXIT_FAIL, EXIT_USAGE, build_parser, main
from testbed.pipeline.scenario import list_scenarios, load_scenario

ROOT = Path(__file__).resolve().parent.parent.parent
TIMEOUT_S = 120

PLUGIN = textwrap.dedent('''
    import numpy as np
    from testbed import IDENTIFIERS, StructuralIdentifier, Field


    @IDENTIFIERS.register("{name}", tags=("structural", "example"))
    class Plugin(StructuralIdentifier):
        """Nothing learned: unit matrices (a registration test only)."""

        name = "{name}"
        hyperparameters = {{"gain": Field(float, 1.0, doc="a number")}}

        def __init__(self, gain: float = 1.0):
            self.gain = gain

        def fit(self, data):
            n = data.n_channels
            self.M_, self.C_, self.K_, self.K3_ = np.eye(n), np.eye(n), self.gain * np.eye(n), None
            self.coef_, self.feature_names_, self.channels_ = np.zeros((n, 1)), ["x"], data.channels
            self.input_map_ = None
            self._finish_fit()
            return self
''')


def _env() -> dict[str, str]:
    return {**os.environ, "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg",
            "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}


def cli(*args: str, cwd: Path, extra_path: Path | None = None) -> subprocess.CompletedProcess:
    env = _env()
    if extra_path is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(extra_path), env["PYTHONPATH"]])
    return subprocess.run([sys.executable, "-m", "testbed.cli", *args], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=TIMEOUT_S)


def test_version(capsys):
    import testbed

    with pytest.raises(SystemExit) as e:
        main(["--version"])
    assert e.value.code == 0
    assert capsys.readouterr().out.split()[-1] == testbed.__version__


def test_every_option_has_help():
    def walk(parser: argparse.ArgumentParser, where: str):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                for name, sub in action.choices.items():
                    yield from walk(sub, f"{where} {name}")
            elif not isinstance(action, argparse._HelpAction):
                yield where, action

    missing = [f"{w}: {a.option_strings or a.dest}" for w, a in walk(build_parser(), "testbed")
               if not a.help]
    assert not missing, missing


def test_list_piped_keeps_every_field_whole(tmp_path):
    r = cli("list", cwd=tmp_path)  # stdout is a pipe here
    assert r.returncode == 0, r.stderr
    assert "…" not in r.stdout
    lines = r.stdout.splitlines()
    for sc in list_scenarios():
        assert any(ln.split("\t")[0] == sc.name and ln.endswith(sc.description) for ln in lines), sc.name
    assert "ls_sindy\tstructural\tbaseline, paper:000, structural\tbuiltin" in lines


def test_plugin_file_on_list_and_identify(tmp_path, dataset_cache, cli_in_process):
    """In this process (``cli_in_process``) but for the last command, a real ``identify``
    process with a plugin file: its failure reaches a real stderr without a traceback."""
    plugin = tmp_path / "my_method.py"
    plugin.write_text(PLUGIN.format(name="my_file_method"))
    r = cli_in_process("list", "--plugin", str(plugin), cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    (row,) = [ln for ln in r.stdout.splitlines() if ln.startswith("my_file_method\t")]
    assert row.endswith(f"\tfile {plugin}")
    # without the plugin the name is unknown: one line, status 2
    data = dataset_cache.get(load_scenario("cantilever_stiff_impact_lsq")).save(tmp_path / "d.h5")
    r = cli_in_process("identify", str(data), "--kind", "structural", "--method", "my_file_method",
                       cwd=tmp_path)
    assert r.returncode == EXIT_USAGE and r.stderr.startswith("error: unknown identifier 'my_file_method'")
    r = cli_in_process("identify", str(data), "--kind", "structural", "--method", "my_file_method",
                       "--plugin", str(plugin), "--param", "gain=4", "-o", "m.json", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    model = json.loads((tmp_path / "m.json").read_text())
    assert model["identifier"]["params"] == {"gain": 4.0}
    assert model["matrices"]["K"][0][0] == 4.0
    assert model["physical_failures"] == {}
    # a negative stiffness grows: written (to be looked at) with its reasons, but a failure
    r = cli("identify", str(data), "--kind", "structural", "--method", "my_file_method",
            "--plugin", str(plugin), "--param", "gain=-4", "-o", "m.json", cwd=tmp_path)
    assert r.returncode == EXIT_FAIL, r.stderr
    assert r.stdout.splitlines()[-1].startswith("FAIL: physically impossible model: unstable")
    assert "Traceback" not in r.stderr
    assert "stability" in json.loads((tmp_path / "m.json").read_text())["physical_failures"]


def test_entry_point_plugin(tmp_path):
    site = tmp_path / "site"
    (site / "ep_plugin-0.1.dist-info").mkdir(parents=True)
    (site / "ep_plugin.py").write_text(PLUGIN.format(name="my_ep_method"))
    (site / "ep_plugin-0.1.dist-info" / "METADATA").write_text(
        "Metadata-Version: 2.1\nName: ep-plugin\nVersion: 0.1\n")
    (site / "ep_plugin-0.1.dist-info" / "entry_points.txt").write_text(
        "[sysid_testbed.identifiers]\nmy_ep_method = ep_plugin:Plugin\n")
    r = cli("list", cwd=tmp_path, extra_path=site)
    assert r.returncode == 0, r.stderr
    (row,) = [ln for ln in r.stdout.splitlines() if ln.startswith("my_ep_method\t")]
    assert row.endswith("\tentry point my_ep_method (ep-plugin)")
    # a broken entry point is the user's problem: one line naming it, status 2
    (site / "ep_plugin-0.1.dist-info" / "entry_points.txt").write_text(
        "[sysid_testbed.identifiers]\nbroken = ep_plugin_missing:Nothing\n")
    r = cli("list", cwd=tmp_path, extra_path=site)
    assert r.returncode == EXIT_USAGE, r.stderr
    assert r.stderr.startswith("error: identifier entry point broken = ep_plugin_missing:Nothing")
    assert len(r.stderr.splitlines()) == 1


def test_identify_with_a_scenario_writes_model_and_report(tmp_path, dataset_cache, capsys):
    data = dataset_cache.get(load_scenario("cantilever_stiff_impact_lsq")).save(tmp_path / "beam.h5")
    out = tmp_path / "fit" / "beam.json"
    assert main(["identify", str(data), "--scenario", "cantilever_stiff_impact_lsq", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    model = json.loads(out.read_text())
    assert model["method"] == "ls_sindy" and model["kind"] == "structural"
    # the run's model on its measurement: measured R^2 0.99942
    assert len(model["modal"]["frequency_hz"]) == 3 and model["r2"] > 0.99
    assert "## Modes" in text and out.with_suffix(".md").read_text() in text
    # another method of the same kind, with a prior the file does not state
    assert main(["identify", str(data), "--scenario", "cantilever_stiff_impact_lsq", "--method",
                 "pysindy_sr3", "--param", "mass_prior=\"total_mass\"", "--prior", "total_mass=2.5",
                 "-o", str(out)]) == 0
    model = json.loads(out.read_text())
    assert model["method"] == "pysindy_sr3"
    assert sum(model["matrices"]["M"][i][i] for i in range(3)) == pytest.approx(2.5)


def test_identify_mechanical(tmp_path, dataset_cache, capsys):
    # what `identify` writes and prints for a mechanical model, which any fitted sindy_pi model
    # gives: the first 3 s of the 10 s record (fitted in 1.2 s of CPU against 3.8-4.3 s for the
    # whole record, its simulation 0.8 s once; measured 2026-11-29: 1 s is refused as not
    # separating the inputs, 2 s and 3 s are fitted)
    sc = load_scenario("fivebar_multisine")
    sc = sc.replace(simulation={**sc.simulation, "duration": 3.0})
    data = dataset_cache.get(sc).save(tmp_path / "fb.h5")
    out = tmp_path / "fb.json"
    assert main(["identify", str(data), "--kind", "mechanical", "--method", "sindy_pi", "-o", str(out)]) == 0
    model = json.loads(out.read_text())
    assert model["kind"] == "mechanical" and model["r2"] is None and "matrices" not in model
    coef = model["coefficients"]
    assert len(coef["coef"][0]) == len(coef["feature_names"]) and len(model["equations"]) == 2
    assert "not defined (implicit equations" in capsys.readouterr().out


def test_identify_reads_a_dynamical_rigs_own_dataset_by_kind(tmp_path, capsys):
    # --kind offered structural and mechanical only, and the file's "mM" was an unknown unit
    from testbed.pipeline.generate import simulate_clean

    sc = load_scenario("michaelis_menten")
    data = simulate_clean(sc).save(tmp_path / "mm.h5")
    out = tmp_path / "mm.json"
    assert main(["identify", str(data), "--kind", "dynamical", "--method", "sindy_pi_dynamical",
                 "-o", str(out)]) == 0
    model = json.loads(out.read_text())
    assert model["kind"] == "dynamical" and len(model["equations"]) == 1


@pytest.mark.parametrize(("argv", "fragment"), [
    (["identify", "{data}"], "--kind structural|mechanical|dynamical"),
    (["identify", "{data}", "--kind", "structural"], "--method NAME"),
    (["identify", "{data}", "--kind", "structural", "--method", "sindy_pi"], "is for mechanical rigs"),
    (["identify", "{data}", "--kind", "mechanical", "--scenario", "cantilever_stiff_impact_lsq"],
     "is of the structural kind"),
    (["identify", "{data}", "--kind", "structural", "--method", "ls_sindy", "--prior", "m"],
     "expected KEY=VALUE"),
    (["identify", "{data}", "--kind", "structural", "--method", "ls_sindy", "--prior", "totl_mass=1"],
     "--prior totl_mass: identifier ls_sindy reads no such prior; it reads: reduced_mass_trace, total_mass"),
    (["identify", "{tmp}/none.csv", "--kind", "structural", "--method", "ls_sindy"], "no such file"),
    (["identify", "{data}", "--kind", "structural", "--method", "ls_sindy", "--param", "rcond=2"],
     "identify.rcond"),
    (["list", "--plugin", "{tmp}/none.py"], "plugin"),
    (["run", "cantilever_stiff_impact_lsq", "--plugin", "{tmp}/empty.py"], "registers no identifier"),
])
def test_user_mistakes_are_one_line(argv, fragment, tmp_path, capsys):
    (tmp_path / "empty.py").write_text("x = 1\n")
    data = tmp_path / "d.txt"
    data.write_text("t,a\n0,1\n")
    argv = [a.format(tmp=tmp_path, data=data) for a in argv]
    assert main(argv) == EXIT_USAGE
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and err.startswith("error: ") and fragment in err, err


def test_runs_ls_and_report_by_scenario_name(tmp_path, capsys):
    sys.path.insert(0, str(ROOT / "tests" / "testbed"))
    try:
        from _synthetic_runs import structural_result
    finally:
        sys.path.pop(0)
    from testbed.reporting.figures import save_run_figures
    from testbed.reporting.report import runs_index_html
    from testbed.studies.runstore import run_folder, save_new_run, save_run

    result = structural_result(n_samples=800)
    legacy = save_run(result, run_folder(tmp_path, "written_before_run_history"))
    first = save_new_run(result, tmp_path, index=runs_index_html)
    # the latest run with its figures, as `testbed run` saves it: the two reports of it (by name
    # and by folder) take its figures, the report of `first` draws the ones it lacks (each of the
    # three reports drew all 6 before: 18 figures, about 2/3 of the test's CPU, now 12)
    second = save_new_run(result, tmp_path, index=runs_index_html, figures=save_run_figures)
    (tmp_path / "not_a_run").mkdir()
    assert main(["runs", "ls", "-o", str(tmp_path)]) == 0
    out, err = capsys.readouterr()
    assert err == ""  # no damaged run folder to warn about
    lines = out.splitlines()
    # piped: a header and one tab-separated line per run, every field whole, oldest first
    assert lines[0].split("\t") == ["scenario", "seed", "time (UTC)", "identifier", "verdict", "path"]
    rows = [line.split("\t") for line in lines[1:]]
    assert sorted(r[5] for r in rows) == sorted([str(legacy), str(first), str(second)])
    assert [r[2] for r in rows] == sorted(r[2] for r in rows)
    assert [r[5] for r in rows if r[5] != str(legacy)] == [str(first), str(second)]
    for r in rows:
        assert r[0] == result.scenario.name and r[1] == str(result.scenario.seed)
        assert r[3] == result.scenario.identify["method"] and r[4] == result.verdict and r[2].endswith("Z")
    assert main(["runs", "ls", "no_such_scenario", "-o", str(tmp_path)]) == 0
    assert capsys.readouterr().out.splitlines()[1:] == []
    # a damaged run.json is left out of the table, and said so on one line
    damaged = tmp_path / result.scenario.name / "damaged_run"
    damaged.mkdir()
    (damaged / "run.json").write_text('{"format": ')
    assert main(["runs", "ls", "-o", str(tmp_path)]) == 0
    out, err = capsys.readouterr()
    assert len(out.splitlines()) == 4 and str(damaged) not in out
    assert len(err.splitlines()) == 1 and err.startswith("warning: 1 run folder(s) left out")
    assert str(damaged) in err
    damaged.joinpath("run.json").unlink()
    damaged.rmdir()
    # a scenario's name or folder means its latest run
    assert main(["report", result.scenario.name, "--runs", str(tmp_path), "-o", str(tmp_path / "r1")]) == 0
    assert main(["report", str(tmp_path / result.scenario.name), "-o", str(tmp_path / "r2")]) == 0
    assert main(["report", str(first), "-o", str(tmp_path / "r3")]) == 0
    capsys.readouterr()
    for r in ("r1", "r2", "r3"):
        assert (tmp_path / r / "report.html").is_file()
    assert main(["report", "no_such_scenario", "--runs", str(tmp_path), "-o", str(tmp_path / "r4")]) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "no such run folder or results file" in err


def test_sweep_with_a_plugin_identifier(tmp_path, dataset_cache, cli_in_process):
    """`sweep --plugin`: the study may name the plugin's identifier, and its cells run with it
    (in loky workers too: the plugin travels with the study).  The command runs in this process
    (``cli_in_process``; its loky workers are processes all the same); a real ``testbed sweep``
    process is killed and resumed in test_sweep.py."""
    plugin = tmp_path / "my_method.py"
    plugin.write_text(PLUGIN.format(name="my_sweep_method"))
    study = tmp_path / "plug.toml"
    study.write_text(textwrap.dedent(f'''
        [study]
        name = "plug"
        scenarios = ["{ROOT / 'scenarios' / 'cantilever_stiff_impact_lsq.toml'}"]
        noise = [0.0]
        seeds = [0]
        identifiers = ["my_sweep_method", "ls_sindy"]
    '''))
    results = tmp_path / "plug.parquet"
    r = cli_in_process("sweep", str(study), "--results", str(results), cwd=tmp_path)
    assert r.returncode == EXIT_USAGE and "my_sweep_method" in r.stderr, r.stderr
    r = cli_in_process("sweep", str(study), "--plugin", str(plugin), "--jobs", "2", "--results",
                       str(results), "--cache", str(dataset_cache.directory), cwd=tmp_path)
    assert r.returncode in (0, 1), r.stdout[-2000:] + r.stderr[-2000:]  # 1: a cell failed its bars
    from testbed.studies.results import read_results

    rows = read_results(results)
    assert sorted(row["identifier"] for row in rows) == ["ls_sindy", "my_sweep_method"]


def test_generate_takes_a_plugin_rig(tmp_path, cli_in_process):
    # `testbed generate` had no --plugin: a plugin rig's scenario could not be generated
    (tmp_path / "spring.toml").write_text(
        '[scenario]\nname = "spring"\nrig = "springmass"\n[simulation]\nduration = 0.05\n'
        'sample_rate = 8192.0\n[excitation]\ntype = "impulse"\n')
    plugin = str(ROOT / "tests" / "springmass_rig.py")
    r = cli_in_process("generate", "spring.toml", "--plugin", plugin, "--no-cache", "-o", "s.h5",
                       cwd=tmp_path)
    assert r.returncode == 0 and (tmp_path / "s.h5").is_file(), r.stderr[-2000:]
    r = cli_in_process("generate", "spring.toml", "--no-cache", "-o", "t.h5", cwd=tmp_path)
    assert r.returncode == 2 and "springmass" in r.stderr and len(r.stderr.splitlines()) == 1
