"""Start-up cost of the command line, checked by what is imported (deterministic), not by a clock.

``testbed list`` imports every rig and identifier module (the registries import their packages)
and validates every scenario file; none of that may import an engine or a heavy library: they
are imported where a command computes (``testbed.core.lazy``).  ``benchmarks/bench_cli.py``
times the same commands.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from testbed.core import stamped
from testbed.core.lazy import LazyModule, lazy_module

ROOT = Path(__file__).resolve().parent.parent.parent
TIMEOUT_S = 120

#: Modules ``testbed list`` must not import (each costs 0.07-0.4 s of start-up, measured).
HEAVY = ("mujoco", "pinocchio", "h5py", "matplotlib", "numba", "scipy.linalg", "scipy.signal",
         "scipy.optimize", "scipy.fft", "sklearn", "pysindy", "joblib", "pyarrow")


def _in_fresh_process(code: str, **env_vars: str) -> dict:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg", **env_vars}
    r = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], cwd=ROOT, env=env,
                       capture_output=True, text=True, timeout=TIMEOUT_S)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_list_imports_no_engine_and_no_heavy_library():
    """Listed by importing every module (no index: testbed.core.stamped)."""
    out = _in_fresh_process(f"""
        import contextlib, io, json, sys
        from testbed.cli import main
        buf = io.StringIO()
        with contextlib.redirect_stdout(buf):
            code = main(["list", "--plain"])
        print(json.dumps({{"code": code, "listing": buf.getvalue(),
                          "heavy": [m for m in {HEAVY!r} if m in sys.modules]}}))
    """, TESTBED_INDEX="")
    assert out["code"] == 0
    # the listing is whole: every built-in rig and a scored scenario of each engine
    for name in ("cantilever", "fivebar", "cartpole", "sgd_sindy", "cantilever_stiff_impact"):
        assert f"\n{name}\t" in out["listing"], name
    assert out["heavy"] == [], f"`testbed list` imported {out['heavy']}"


#: A plugin distribution's module: an identifier registered with the tag ``{tag}``.
EP_PLUGIN = """
from testbed import IDENTIFIERS, StructuralIdentifier


@IDENTIFIERS.register("my_ep_method", tags=("structural", "{tag}"))
class Plugin(StructuralIdentifier):
    \"\"\"Registration only.\"\"\"

    name = "my_ep_method"
"""
LIST_CODE = """
    import contextlib, io, json, sys
    from testbed.cli import main
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main(["list", "--plain"])
    print(json.dumps({"code": code, "listing": buf.getvalue(),
                      "imported": [m for m in ("identify", "models", "numpy") if m in sys.modules]}))
"""


def _backdate(*paths: Path) -> None:
    """Older than the index's racy window (testbed.core.stamped.RACY_S)."""
    t = time.time() - 3600
    for p in paths:
        os.utime(p, (t, t))


def test_list_from_its_index_shows_a_plugin_or_scenario_added_edited_or_removed_at_once(tmp_path):
    """`testbed list` prints from its index (no rig, identifier or numpy imported) while every
    file it was computed from holds its stamp, and lists afresh as soon as a plugin module is
    edited, an entry point removed or a scenario file added (testbed.core.stamped)."""
    site, scenarios = tmp_path / "site", tmp_path / "scenarios"
    dist = site / "ep_plugin-0.1.dist-info"
    dist.mkdir(parents=True)
    scenarios.mkdir()
    (site / "ep_plugin.py").write_text(EP_PLUGIN.format(tag="example"))
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: ep-plugin\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text("[sysid_testbed.identifiers]\nmy_ep_method = ep_plugin\n")
    for name in ("cartpole", "michaelis_menten"):  # neither extends another file
        (scenarios / f"{name}.toml").write_bytes((ROOT / "scenarios" / f"{name}.toml").read_bytes())
    _backdate(*site.rglob("*"), site, *scenarios.rglob("*"), scenarios)
    env = {"PYTHONPATH": f"{ROOT}{os.pathsep}{site}", "TESTBED_SCENARIOS": str(scenarios),
           "TESTBED_INDEX": str(tmp_path / "index")}

    def stale() -> list[str]:
        """The kept indexes' stamps that no longer hold (what made a listing afresh): shown
        only when a listing expected from the index was not (session 20: once in a full run
        under load, not reproduced alone)."""
        out = []
        for f in (tmp_path / "index").glob("*.json"):
            kept = json.loads(f.read_text())
            out += [p for p, st in kept["files"] if stamped._file_stamp(p) != st]
            out += [p for p, st in kept["folders"] if stamped._folder_stamp(p) != st]
            out += [p for p, st in kept["paths"] if stamped._path_stamp(p) != st]
        return out

    def listing(fresh: bool) -> str:
        out = _in_fresh_process(LIST_CODE, **env)
        assert out["code"] == 0, out
        assert (out["imported"] == []) != fresh, (out["imported"], "stale stamps:", stale())
        return out["listing"]

    def settle() -> str:
        """The test's files made older than the racy window, listed afresh (the index rewritten)
        and then from the index: each change below is made to an index that holds.

        The index is removed before the fresh listing, so whether that listing kept one is
        seen: a file the index stamps that changed in the last ``RACY_S`` (another test's
        file, a ``__pycache__`` written by a worker) keeps none, and the listing is made again
        once that window has passed.  (Before session 21 only the first call could see it:
        later calls found the earlier index's folder, kept the stale index and failed.)"""
        index = tmp_path / "index"
        for _ in range(3):  # three racy windows in a row: the suite is writing that often
            _backdate(*site.rglob("*"), site, *scenarios.rglob("*"), scenarios)
            shutil.rmtree(index, ignore_errors=True)
            fresh = listing(fresh=True)
            if any(index.glob("*.json")):
                break
            time.sleep(stamped.RACY_S + 0.5)
        assert listing(fresh=False) == fresh
        return fresh

    first = settle()
    assert "\nmy_ep_method\tstructural\texample, structural\tentry point my_ep_method (ep-plugin)\n" in first
    assert "\ncartpole\t" in first and "\ncantilever_stiff_impact\t" not in first
    # the plugin's module edited: listed afresh, at once
    (site / "ep_plugin.py").write_text(EP_PLUGIN.format(tag="edited"))
    assert "\tedited, structural\t" in listing(fresh=True)
    # a scenario file added
    assert "cartpole_copy" not in settle()
    (scenarios / "cartpole_copy.toml").write_text('[scenario]\nname = "cartpole_copy"\n'
                                                  'extends = "cartpole.toml"\n')
    assert "\ncartpole_copy\tcartpole\t" in listing(fresh=True)
    # the distribution removed
    assert "my_ep_method" in settle()
    for f in dist.iterdir():
        f.unlink()
    dist.rmdir()
    assert "my_ep_method" not in listing(fresh=True)


def test_version_imports_nothing_of_the_project_below_the_cli():
    out = _in_fresh_process("""
        import contextlib, io, json, sys
        from testbed.cli import main
        with contextlib.redirect_stdout(io.StringIO()):
            try:
                main(["--version"])
            except SystemExit:
                pass
        print(json.dumps({"loaded": sorted(m for m in sys.modules
                                           if m.split(".")[0] in ("models", "identify", "numpy"))}))
    """)
    assert out["loaded"] == []


def test_the_modules_of_a_run_import_no_figure_and_no_table_library():
    """`testbed run --no-figures` imports what `cmd_run` imports; matplotlib (a figure) and
    pyarrow (a sweep's results table) are imported where they are used."""
    out = _in_fresh_process("""
        import json, sys
        import testbed.reporting.console, testbed.reporting.report, testbed.scoring.run
        import testbed.studies.runstore
        print(json.dumps({"loaded": [m for m in ("matplotlib", "pyarrow") if m in sys.modules]}))
    """)
    assert out["loaded"] == []


def test_the_budget_is_still_checked_when_a_scenario_is_loaded_for_a_run():
    """The listing skips the simulation budget (it builds the rig's MuJoCo model); loading a
    scenario to run it does not."""
    from testbed.core.errors import BudgetError
    from testbed.pipeline.scenario import scenario_from_dict

    raw = {"scenario": {"name": "huge", "rig": "cantilever"},
           "simulation": {"duration": 1e5, "sample_rate": 12800.0}}
    with pytest.raises(BudgetError):
        scenario_from_dict(raw)
    assert scenario_from_dict(raw, check_cost=False).name == "huge"


@pytest.fixture
def probe_module(tmp_path, monkeypatch):
    """A module on ``sys.path`` that nothing has imported, counting its own imports."""
    (tmp_path / "lazy_probe_mod.py").write_text(
        "import builtins\n"
        "builtins.lazy_probe_imports = getattr(builtins, 'lazy_probe_imports', 0) + 1\n"
        "VALUE = 42\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "lazy_probe_mod", raising=False)
    import builtins
    monkeypatch.setattr(builtins, "lazy_probe_imports", 0, raising=False)
    yield "lazy_probe_mod"
    sys.modules.pop("lazy_probe_mod", None)


def test_lazy_module_imports_on_first_attribute_only(probe_module):
    import builtins

    mod = lazy_module(probe_module)
    assert isinstance(mod, LazyModule)
    repr(mod)
    assert not hasattr(mod, "__wrapped__")  # a dunder probe (copy, inspect) does not import
    assert probe_module not in sys.modules and builtins.lazy_probe_imports == 0
    assert mod.VALUE == 42
    assert probe_module in sys.modules and builtins.lazy_probe_imports == 1
    assert mod.VALUE == 42 and builtins.lazy_probe_imports == 1  # once
    sys.modules[probe_module].LATER = "added after the import"
    assert mod.LATER == "added after the import"  # found through the module, not the copy
    with pytest.raises(AttributeError):
        _ = mod.MISSING


def test_lazy_module_of_a_missing_module_fails_at_first_use():
    mod = lazy_module("no_such_module_for_testbed_xyz")
    with pytest.raises(ModuleNotFoundError):
        _ = mod.anything


def _mujoco_import_in_fresh_process(env_value: str | None) -> dict:
    """Load the cantilever scenario (its budget check builds the MuJoCo model) in a fresh
    process, with ``MUJOCO_GL`` unset or set to ``env_value``."""
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    env.pop("MUJOCO_GL", None)
    if env_value is not None:
        env["MUJOCO_GL"] = env_value
    code = """
        import json, os, sys
        from testbed.pipeline.scenario import load_scenario
        load_scenario("cantilever_stiff_impact")
        print(json.dumps({"mujoco": "mujoco" in sys.modules, "glfw": "glfw" in sys.modules,
                          "MUJOCO_GL": os.environ.get("MUJOCO_GL")}))
    """
    r = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], cwd=ROOT, env=env,
                       capture_output=True, text=True, timeout=TIMEOUT_S)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_mujoco_is_imported_without_its_renderer():
    """MuJoCo's OpenGL renderer (the glfw package, which starts a second Python process to read
    the library's version) is not imported: the testbed never renders."""
    out = _mujoco_import_in_fresh_process(None)
    assert out == {"mujoco": True, "glfw": False, "MUJOCO_GL": "disable"}


def test_a_users_mujoco_gl_setting_is_kept():
    out = _mujoco_import_in_fresh_process("off")  # a synonym of "disable": no GL library needed
    assert out["MUJOCO_GL"] == "off" and not out["glfw"]


def _blas_after_cli_in_fresh_process(user: dict[str, str]) -> dict:
    """Run ``testbed --version`` in a fresh process whose environment sets only ``user`` of the
    BLAS thread variables, then load numpy: the thread variables and OpenBLAS's thread count."""
    from testbed.cli import BLAS_THREAD_VARIABLES

    env = {k: v for k, v in os.environ.items() if k not in BLAS_THREAD_VARIABLES}
    env.update(PYTHONPATH=str(ROOT), MPLBACKEND="Agg", **user)
    code = f"""
        import contextlib, io, json, os
        from testbed.cli import main
        with contextlib.redirect_stdout(io.StringIO()):
            try:
                main(["--version"])
            except SystemExit:
                pass
        import numpy
        from threadpoolctl import threadpool_info
        print(json.dumps({{"env": {{v: os.environ.get(v) for v in {BLAS_THREAD_VARIABLES!r}}},
                          "threads": [i["num_threads"] for i in threadpool_info()
                                      if i["user_api"] == "blas"]}}))
    """
    r = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], cwd=ROOT, env=env,
                       capture_output=True, text=True, timeout=TIMEOUT_S)
    assert r.returncode == 0, r.stderr
    return json.loads(r.stdout.strip().splitlines()[-1])


def test_a_command_runs_blas_on_one_thread():
    """Unset, the command's BLAS runs one thread (small matrices: a second one only spins)."""
    out = _blas_after_cli_in_fresh_process({})
    assert set(out["env"].values()) == {"1"}
    assert out["threads"] and set(out["threads"]) == {1}


def test_a_users_blas_thread_setting_is_kept():
    out = _blas_after_cli_in_fresh_process({"OPENBLAS_NUM_THREADS": "2"})
    assert out["env"] == {"OPENBLAS_NUM_THREADS": "2", "MKL_NUM_THREADS": None, "OMP_NUM_THREADS": None}


def test_a_command_runs_with_the_raised_gc_threshold_and_main_restores_it(monkeypatch):
    """`main` raises the young-generation threshold for the command (imports make hundreds of
    thousands of objects) and gives the caller's back, also when the command raises."""
    import gc

    from testbed import cli

    seen = []

    def command(args):
        seen.append(gc.get_threshold())
        raise RuntimeError("a bug")

    monkeypatch.setattr(cli, "cmd_list", command)
    before = gc.get_threshold()
    assert cli.main(["list"]) == cli.EXIT_INTERNAL
    assert seen == [cli.GC_THRESHOLD]
    assert gc.get_threshold() == before


#: The console script pip writes for ``testbed`` (``[project.scripts]``), with ``before`` run
#: first and ``after`` run once ``main`` has returned.
CONSOLE_SCRIPT = """\
import os, signal, sys, time
# the signals as an interactive shell hands them to a command: a suite started as a background
# job of a non-interactive shell (`... &`, nohup) passes SIGINT / SIGHUP on ignored, and Python
# then installs no KeyboardInterrupt handler (the interrupt tests saw status 0 there)
signal.signal(signal.SIGINT, signal.default_int_handler)
signal.signal(signal.SIGHUP, signal.SIG_DFL)
{before}
from testbed.cli import main
status = main()
{after}
sys.exit(status)
"""


def _console(tmp_path: Path, before: str = "", after: str = "", args=("--version",)):
    script = tmp_path / "testbed"  # the console program is known by its name
    script.write_text(CONSOLE_SCRIPT.format(before=before, after=after))
    env = dict(os.environ, PYTHONPATH=str(ROOT), TESTBED_NO_SERVER="1")
    return subprocess.run([sys.executable, str(script), *args], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=TIMEOUT_S)


# a Ctrl-C, SIGTERM or SIGHUP while `testbed` imports its modules (0.05 s idle, 0.1-0.2 s on a
# loaded machine) printed Python's traceback and ended the process by the signal (status
# -2): 110 of 500 timings from 0.01 s to 0.5 s on the loaded machine, 25 after (the
# interpreter's own start, before any code of the testbed runs, is left)
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_a_signal_while_the_command_imports_is_one_line(tmp_path, signum):
    # sent when testbed.cli imports argparse, its first module not loaded at start-up
    hook = ("sys.addaudithook(lambda event, args: event == 'import' and args[0] == 'argparse' "
            f"and os.kill(os.getpid(), {int(signum)}))")
    r = _console(tmp_path, before=hook)
    name = "interrupted" if signum == signal.SIGINT else f"interrupted by {signal.Signals(signum).name}"
    assert (r.returncode, r.stdout, r.stderr) == (
        130 if signum == signal.SIGINT else 128 + signum, "", f"error: {name}\n")


def test_a_ctrl_c_as_the_command_exits_is_one_line(tmp_path):
    # a Ctrl-C after the command's verdict, as the interpreter shut down, printed "Exception
    # ignored in: <module 'threading'> ... KeyboardInterrupt" and the command ended with 0;
    # what the command printed is kept
    r = _console(tmp_path, after="os.kill(os.getpid(), signal.SIGINT); time.sleep(5)",
                 args=("cache", "ls", "--cache", str(tmp_path)))
    assert (r.returncode, r.stderr) == (130, "error: interrupted\n")
    assert r.stdout == f"0 dataset(s) in {tmp_path}\n"


def test_a_signal_the_caller_ignores_stays_ignored(tmp_path):
    # `nohup testbed ...` or a shell's background job: SIGHUP or SIGINT set to be ignored
    r = _console(tmp_path, before="signal.signal(signal.SIGINT, signal.SIG_IGN); "
                                  "sys.addaudithook(lambda e, a: e == 'import' and a[0] == 'argparse' "
                                  "and os.kill(os.getpid(), signal.SIGINT))")
    assert (r.returncode, r.stderr) == (0, "")


def test_importing_the_library_leaves_the_signals_as_python_has_them():
    # only the console program is armed: a Python session importing testbed (this test
    # process) keeps Ctrl-C's KeyboardInterrupt
    import testbed.cli  # noqa: F401
    from testbed.core import interrupts

    assert not interrupts._console_program()
    assert signal.getsignal(signal.SIGINT) is not interrupts.exit_at_once
    assert signal.getsignal(signal.SIGTERM) is not interrupts.exit_at_once



def test_list_without_a_plugin_is_never_served(tmp_path, monkeypatch):
    """Alone, `list` prints from its index (or lists and rewrites it); a served `list` forks the
    server and lists afresh, slower, and never refreshes the index (measured at load 11: served
    0.46-0.80 s wall, alone from the index 0.22-0.45 s).  With a plugin file it is served."""
    from testbed import cli, server

    sock = tmp_path / "s.sock"
    sock.write_text("")  # a server's socket as far as the client looks
    monkeypatch.delenv("TESTBED_NO_SERVER", raising=False)
    monkeypatch.setenv("TESTBED_SERVER_SOCKET", str(sock))
    asked = []
    monkeypatch.setattr(server, "try_server", lambda argv: asked.append(argv) or 0)
    for argv, served in ((["list"], False), (["list", "--plain"], False),
                         (["list", "--plugin", "p.py"], True), (["list", "--plugin=p.py"], True),
                         (["run", "x"], True)):
        asked.clear()
        assert cli._served(argv) == (0 if served else None)
        assert asked == ([argv] if served else [])
