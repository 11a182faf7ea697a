"""Seventh malformed-input round: MuJoCo's C-level log, matplotlib's folders, and the new
families of hostile input of ``benchmarks/hostile7.py`` (docs/history.md, malformed-input audits).

The tests of what reaches a real standard stream or the current folder start a real process:
MuJoCo's log is written by C code, matplotlib's folders are read at its import.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent.parent
TIMEOUT_S = 180  # a process start, a 0.05 s simulation or one Michaelis-Menten fit, under load


def _env(**extra: str | None) -> dict[str, str]:
    env = {**os.environ, "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg",
           "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    for key, value in extra.items():
        if value is None:
            env.pop(key, None)
        else:
            env[key] = value
    return env


def cli(*args: str, cwd: Path, **env: str | None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "testbed.cli", *args], cwd=cwd, env=_env(**env),
                          capture_output=True, text=True, timeout=TIMEOUT_S)


# ------------------------------------------------------------------ MuJoCo's C-level log

def test_a_mujoco_reset_leaves_one_line_and_no_log_file(tmp_path):
    # A cart-pole pushed with 1e9 N: MuJoCo resets the state, printed "WARNING: Nan, Inf or
    # huge value in QACC ..." to stdout before our line and wrote MUJOCO_LOG.TXT into the
    # current folder.
    text = (ROOT / "scenarios" / "cartpole.toml").read_text()
    text = (text.replace('name = "cartpole"', 'name = "cp_huge"')
            .replace("amplitude = 1.0", "amplitude = 1e9").replace("duration = 10.0", "duration = 0.05"))
    (tmp_path / "cp_huge.toml").write_text(text)
    r = cli("run", "cp_huge.toml", "--no-cache", "--no-figures", "--out", str(tmp_path / "runs"),
            cwd=tmp_path)
    assert r.returncode == 2, (r.stdout, r.stderr)
    assert r.stdout == ""
    lines = r.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: cp_huge.toml: cartpole: the simulation "
                                                   "is unstable"), r.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cp_huge.toml"]


PLUGIN_STEPPING_MUJOCO = textwrap.dedent('''
    import mujoco  # imported by the plugin itself, not through the testbed's lazy proxy

    XML = "<mujoco><worldbody><body><joint type='hinge'/><geom size='.1'/></body></worldbody></mujoco>"


    def step_too_fast():
        """One step from a velocity beyond MuJoCo's 1e10 limit: it resets and warns."""
        m = mujoco.MjModel.from_xml_string(XML)
        d = mujoco.MjData(m)
        d.qvel[:] = 1e11
        mujoco.mj_step(m, d)
        return int(d.warning[mujoco.mjtWarning.mjWARN_BADQVEL].number)
''')


@pytest.mark.parametrize("through_testbed", [False, True])
def test_a_plugin_stepping_mujoco_itself_is_quiet(tmp_path, through_testbed):
    # Without the testbed (the control), MuJoCo prints (to stderr) and files its warning; a plugin imported
    # by the testbed gets MuJoCo's log turned off as MuJoCo through the lazy proxy does.
    (tmp_path / "plug.py").write_text(PLUGIN_STEPPING_MUJOCO)
    load = ("from testbed.core.registry import import_plugin; m = import_plugin('plug.py')"
            if through_testbed else "import plug as m")
    r = subprocess.run([sys.executable, "-c", f"{load}; print('resets', m.step_too_fast())"],
                       cwd=tmp_path, env=_env(), capture_output=True, text=True, timeout=TIMEOUT_S)
    assert r.returncode == 0, r.stderr
    assert r.stdout.splitlines()[-1] == "resets 1"  # MuJoCo did meet the bad state
    log = tmp_path / "MUJOCO_LOG.TXT"
    if through_testbed:
        assert r.stdout == "resets 1\n" and r.stderr == "" and not log.exists(), (r.stdout, r.stderr)
    else:
        assert "WARNING" in r.stdout + r.stderr and log.exists()


# ------------------------------------------------------------------ matplotlib's folders

def test_usable_folder(tmp_path):
    from testbed.reporting.mplconfig import usable_folder

    (tmp_path / "file").write_text("x")
    (tmp_path / "loop").symlink_to("loop")
    assert usable_folder(tmp_path)
    assert usable_folder(tmp_path / "not" / "yet")  # made by matplotlib's mkdir -p
    assert not usable_folder(tmp_path / "file")
    assert not usable_folder(tmp_path / "file" / "matplotlib")
    assert not usable_folder(tmp_path / "loop" / "matplotlib")
    assert not usable_folder("a\0b")


@pytest.fixture(scope="module")
def run_with_mplconfig_a_file(tmp_path_factory):
    """`testbed run michaelis_menten` (figures drawn by forked processes) with MPLCONFIGDIR a
    file and TMPDIR a folder of the test's own, to see what is left in it."""
    d = tmp_path_factory.mktemp("mpl")
    (d / "afile").write_text("not a folder")
    (d / "tmp").mkdir()
    r = cli("run", "michaelis_menten", "--no-cache", "--out", str(d / "runs"), cwd=d,
            MPLCONFIGDIR=str(d / "afile"), TMPDIR=str(d / "tmp"))
    return d, r


def test_an_unusable_mplconfigdir_still_draws_in_silence(run_with_mplconfig_a_file):
    # Before: matplotlib's "mkdir -p failed ..." and "Matplotlib created a temporary cache
    # directory ..." lines on stderr, and one /tmp/matplotlib-* folder left per drawing process
    # (ended by os._exit, matplotlib's atexit removal never ran).
    d, r = run_with_mplconfig_a_file
    assert r.returncode == 0, r.stderr
    assert r.stderr == ""
    assert r.stdout.splitlines()[-1].startswith("run written to")
    assert sorted((d / "runs" / "michaelis_menten").glob("*/*.png"))
    assert list((d / "tmp").iterdir()) == []


@pytest.mark.parametrize("home", ["afile", "loop/x"])
def test_a_home_matplotlib_cannot_use_still_reports(run_with_mplconfig_a_file, tmp_path, home):
    # `testbed report` of sweep results draws its figures in-process.  HOME a file, or under a
    # loop of links (as HOME under an unreadable folder, whose lookup raised "[Errno 13]
    # Permission denied: '/proc/1/root'" naming nothing).
    sys.path.insert(0, str(Path(__file__).parent))
    import _synthetic_runs as synth

    from testbed.studies.results import write_rows

    rows = [{**row, "status": "failed" if row["status"] == "error" else row["status"]}
            for row in synth.sweep_rows()]  # the statuses a results file holds
    results = write_rows(tmp_path / "results.parquet", rows, study="noise_study")
    (tmp_path / "afile").write_text("x")
    (tmp_path / "loop").symlink_to("loop")
    (tmp_path / "tmp").mkdir()
    r = cli("report", str(results), "-o", str(tmp_path / "rep"), cwd=tmp_path, MPLCONFIGDIR=None,
            XDG_CONFIG_HOME=None, XDG_CACHE_HOME=None, HOME=str(tmp_path / home),
            TMPDIR=str(tmp_path / "tmp"))
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert sorted((tmp_path / "rep").glob("*.png"))
    assert list((tmp_path / "tmp").iterdir()) == []


# ------------------------------------------------------------------ family ranges

FAMILY_STUDY = """
[study]
name = "fam"
noise = [0.0]
seeds = [0]
identifiers = ["ls_sindy"]

[families.beams]
base = "cantilever_stiff_impact"
members = 2

[families.beams.rig]
{line}
"""


@pytest.mark.parametrize("line, key", [
    # numpy's Generator draws int64: these were "ValueError: high is out of bounds for int64",
    # an internal error naming nothing, in 47 of 3,120 generated specs
    ("n_segments = {integers = [8, 18446744073709551616]}", "families.beams.rig.n_segments.integers"),
    ("length = {integers = [0, 9223372036854775808]}", "families.beams.rig.length.integers"),
    ("n_segments = {log_integers = [1180591620717411303424, 2361183241434822606848]}",
     "families.beams.rig.n_segments.log_integers"),
])
def test_integer_ranges_beyond_int64_are_refused_naming_the_key(tmp_path, line, key):
    from testbed.core.errors import ScenarioError
    from testbed.studies.study import load_study

    p = tmp_path / "fam.toml"
    p.write_text(FAMILY_STUDY.format(line=line))
    with pytest.raises(ScenarioError, match="integers within int64") as e:
        load_study(p)
    assert e.value.file == str(p) and e.value.key == key


def test_an_integer_range_at_int64s_end_passes_to_the_rigs_own_bound(tmp_path):
    # 2**63 - 1 is numpy's to draw: refused by the rig's bound on n_segments, not as beyond int64
    from testbed.core.errors import ScenarioError
    from testbed.studies.study import load_study

    p = tmp_path / "fam.toml"
    p.write_text(FAMILY_STUDY.format(line="n_segments = {integers = [8, 9223372036854775807]}"))
    with pytest.raises(ScenarioError) as e:
        load_study(p)
    assert "integers within int64" not in str(e.value) and "<= 400" in str(e.value)
    assert e.value.key == "families.beams.rig.n_segments.integers"


# ------------------------------------------------------------------ SEP-005 channels

def _channel(**extra):
    import numpy as np

    t = np.arange(200) / 100.0  # 100 Hz
    return {"name": "acceleration/acc1", "data": list(np.sin(2 * np.pi * 3 * t)), "unit_str": "m/s^2",
            **extra}


@pytest.mark.parametrize("extra, fragment", [
    # fs won in silence over a time column saying otherwise (every frequency halved)
    ({"fs": 50.0, "time": [i / 100.0 for i in range(200)]}, "fs=50 Hz but its time says 100 Hz"),
    # optional keys of the wrong kind were dropped (NaN, text, 1.5) or kept (-1) in silence
    ({"fs": 100.0, "position_m": float("nan")}, "position_m=nan; expected a finite number"),
    ({"fs": 100.0, "position_m": "0.3"}, "position_m='0.3'; expected a finite number"),
    ({"fs": 100.0, "position_m": True}, "position_m=True; expected a finite number"),
    ({"fs": 100.0, "node": 1.5}, "node=1.5; expected an integer >= 1"),
    ({"fs": 100.0, "node": -1}, "node=-1; expected an integer >= 1"),
    ({"fs": 100.0, "node": True}, "node=True; expected an integer >= 1"),
])
def test_sep005_channel_keys_that_contradict_or_mistype_are_refused(extra, fragment):
    from testbed.pipeline.importers import MeasuredDataError, from_sep005

    with pytest.raises(MeasuredDataError, match=re.escape(fragment)):
        from_sep005([_channel(**extra)], source="x.json")


def test_sep005_fs_and_time_agreeing_are_read():
    from testbed.pipeline.importers import from_sep005

    # time printed to 4 significant digits: within the 1e-3 a declared rate may differ by
    times = [float(f"{i / 100.0:.4g}") for i in range(200)]
    d = from_sep005([_channel(fs=100.0, time=times, node=3, position_m=0.25)], source="x.json")
    assert d.fs == 100.0
    assert d.nodes == {"acceleration/acc1": 3} and d.positions == {"acceleration/acc1": 0.25}


def test_a_family_grid_over_the_cell_budget_is_refused_before_its_members_are_drawn(tmp_path,
                                                                                    monkeypatch):
    # 10,000 members x 11 noise levels = 110,000 cells: the members were drawn and validated
    # first (36 ms each on a quiet machine, 0.27 s under load: 6 to 45 minutes), then refused
    from testbed.core.budget import STUDY_CELL_BUDGET
    from testbed.core.errors import BudgetError
    from testbed.studies import study as study_module

    def no_drawing(fam):
        raise AssertionError("members drawn before the grid's budget was checked")

    monkeypatch.setattr(study_module, "family_members", no_drawing)
    p = tmp_path / "fam.toml"
    p.write_text(FAMILY_STUDY.format(line="length = {uniform = [0.3, 0.5]}")
                 .replace("members = 2", "members = 10000")
                 .replace("noise = [0.0]", "noise = [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0]"))
    with pytest.raises(BudgetError, match=f"110000 cells .*the budget is {STUDY_CELL_BUDGET}") as e:
        study_module.load_study(p)
    assert e.value.key == "families.beams.members" and e.value.file == str(p)


# ------------------------------------------------------------------ the environment

def test_a_warning_of_many_lines_is_shown_after_the_verdict_as_its_first_line(monkeypatch, capsys):
    # NUMBA_NUM_THREADS=nan (or '', or any text): numba's warning carries the traceback of its
    # failed parse, 9 lines with "Traceback (most recent call last)" after the verdict
    import warnings

    from testbed import cli

    def command(args):
        warnings.warn("Environment variable 'NUMBA_NUM_THREADS' is defined but its associated "
                      "value 'nan' could not be parsed.\nThe parse failed with exception:\n"
                      "Traceback (most recent call last):\n  File \"config.py\", line 185\n"
                      "ValueError: invalid literal for int() with base 10: 'nan'",
                      RuntimeWarning, stacklevel=1)
        print("verdict")
        return 0

    monkeypatch.setattr(cli, "cmd_list", command)
    with warnings.catch_warnings(record=True) as shown:  # what reaches stderr in a process
        warnings.simplefilter("always")
        assert cli.main(["list"]) == 0
    assert capsys.readouterr().out == "verdict\n"
    assert [str(w.message) for w in shown] == [
        "Environment variable 'NUMBA_NUM_THREADS' is defined but its associated value 'nan' could "
        "not be parsed. [4 more line(s): `testbed --debug ...` shows them]"]


@pytest.mark.parametrize("socket", ["x" * 10_000, "loop/s.sock"])
def test_a_server_socket_path_that_cannot_be_looked_up_runs_the_command_alone(tmp_path, socket):
    # 10,000 characters: ENAMETOOLONG from Path.exists, a traceback before any command ran
    (tmp_path / "loop").symlink_to("loop")
    # (`runs ls`: `list` is never served, so it would not look the socket up)
    r = cli("runs", "ls", cwd=tmp_path, TESTBED_SERVER_SOCKET=socket, TESTBED_NO_SERVER=None)
    assert r.returncode == 0 and r.stderr == "", r.stderr[-500:]
    assert r.stdout.startswith("scenario\tseed\t")


def test_a_mujoco_gl_mujoco_refuses_is_one_line_naming_it(tmp_path):
    # MUJOCO_GL=bogus: "internal error ... RuntimeError: invalid value for environment variable
    # MUJOCO_GL"; osmesa without its library an AttributeError, both "please report it"
    text = (ROOT / "scenarios" / "cartpole.toml").read_text()
    (tmp_path / "cp_short.toml").write_text(text.replace('name = "cartpole"', 'name = "cp_short"')
                                            .replace("duration = 10.0", "duration = 0.05"))
    r = cli("run", "cp_short.toml", "--no-cache", "--no-figures", "--out", str(tmp_path / "runs"),
            cwd=tmp_path, MUJOCO_GL="bogus")
    assert r.returncode == 2, r.stderr
    assert r.stderr.startswith("error: $MUJOCO_GL 'bogus': importing mujoco failed with it "
                               "(RuntimeError:") and len(r.stderr.splitlines()) == 1, r.stderr


def test_an_mplbackend_matplotlib_refuses_is_one_line_naming_it(tmp_path):
    # MPLBACKEND=bogus: "internal error ... ValueError: Key backend: 'bogus' is not a valid value
    # for backend ..." from the drawing process (run) or the command (report)
    sys.path.insert(0, str(Path(__file__).parent))
    import _synthetic_runs as synth

    from testbed.studies.results import write_rows

    rows = [{**row, "status": "failed" if row["status"] == "error" else row["status"]}
            for row in synth.sweep_rows()]
    results = write_rows(tmp_path / "results.parquet", rows, study="noise_study")
    r = cli("report", str(results), "-o", str(tmp_path / "rep"), cwd=tmp_path, MPLBACKEND="bogus")
    assert r.returncode == 2, r.stderr
    assert r.stderr.startswith("error: $MPLBACKEND 'bogus': matplotlib refuses it as a backend")
    assert len(r.stderr.splitlines()) == 1
