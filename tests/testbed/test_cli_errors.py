"""The CLI never shows a traceback for a user's mistake: one line ``error: ...``, exit status 2.

In-process through :func:`testbed.cli.main` for speed, and a sample of malformed files
through the real command (``python -m testbed.cli run <file>``, started concurrently) to
check what a user sees: status 2, one line on stderr, no "Traceback", nothing on stdout.
An internal error prints one line naming ``--debug`` (status 3); ``--debug`` re-raises it.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import threading
from pathlib import Path

import h5py
import numpy as np
import pytest

from testbed import cli
from testbed.cli import EXIT_INTERNAL, EXIT_USAGE, main
from testbed.core.exit_guard import no_process_exit

ROOT = Path(__file__).resolve().parent.parent.parent
DATA = ROOT / "tests" / "data" / "malformed"

#: One subprocess imports numpy, scipy and MuJoCo (about 3 s of CPU); 60 s bounds a hang
#: even on the shared 2-core machine with all of them running at once.
SUBPROCESS_TIMEOUT_S = 60


def one_error_line(err: str) -> str:
    assert "Traceback" not in err, err
    lines = err.splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("error: "), err
    return lines[0]


@pytest.mark.parametrize(("argv", "fragment"), [
    (["run", "no_such_scenario"], "no scenario named 'no_such_scenario'; known: "),
    (["run", "--seed", "-3", "cantilever_stiff_impact"], "--seed: expected an integer >= 0, got -3"),
    (["generate", "--seed", "x", "cantilever_stiff_impact"], "--seed: expected an integer >= 0"),
    # 2**63: datasets and results store seeds as 64-bit signed integers (was an internal error)
    (["generate", "--seed", "9223372036854775808", "michaelis_menten", "-o", "{tmp}/x.h5"],
     "--seed: expected an integer <= 9223372036854775807"),
    (["sweep", "--jobs", "0", "smoke"], "--jobs: expected an integer >= 1"),
    # hostile round 19: int() and float() read other scripts' digits and underscores, so a
    # fullwidth --seed ３ ran seed 3 and --fs 1_000 read 1000 Hz (a scenario's TOML refuses both)
    (["generate", "--seed", "３", "michaelis_menten", "-o", "{tmp}/x.h5"],
     "--seed: expected an integer >= 0, got '３'"),
    (["generate", "--seed", "1_0", "michaelis_menten", "-o", "{tmp}/x.h5"],
     "--seed: expected an integer >= 0, got '1_0'"),
    (["sweep", "--jobs", "٢", "smoke", "--results", "{tmp}/r.parquet"],
     "--jobs: expected an integer >= 1, got '٢'"),
    (["identify", "{tmp}/text.txt", "--kind", "dynamical", "--fs", "１００"],
     "--fs: expected a number (ASCII digits), got '１００'"),
    (["identify", "{tmp}/text.txt", "--kind", "dynamical", "--fs", "1_000"],
     "--fs: expected a number (ASCII digits), got '1_000'"),
    # at most 4 workers a CPU: 100000 started workers until the machine stalled
    (["sweep", "--jobs", "100000", "smoke"], "--jobs: expected an integer <= "),
    # the selector's longest wait: inf was an internal error (OverflowError) after the warm-up
    (["serve", "--idle", "inf", "--warm-up", "none"], "--idle inf: expected a positive number of "
                                                      "seconds, at most 2.14748e+06 (2^31 - 1 ms)"),
    (["serve", "--idle", "1e300", "--warm-up", "none"], "--idle 1e+300: expected a positive number"),
    (["report", "{tmp}/no_such_run", "-o", "{tmp}/report"], "no such run folder or results file"),
    (["report", "{tmp}", "-o", "{tmp}/report"], "not a run folder"),
    (["report", "{tmp}/text.txt", "-o", "{tmp}/report"], "not a sweep results file"),
    (["export", "{tmp}/no_such.h5", "--format", "uff"], "no such file"),
    (["export", "{tmp}/text.txt", "--format", "uff"], "not an HDF5 file"),
    (["export", "{tmp}/other.h5", "--format", "sep005"], "not a testbed dataset"),
    (["export", "{tmp}", "--format", "uff"], "is a folder"),
    (["summary", "{tmp}/no_such.parquet"], "no such file"),
    (["run", str(DATA / "binary.toml")], "not UTF-8"),
    (["run", str(ROOT / "studies" / "smoke.toml")], "testbed sweep"),
    (["sweep", str(ROOT / "scenarios" / "fivebar_multisine.toml")], "testbed run"),
    (["sweep", "smoke", "--dask", "tcp://127.0.0.1:1"], "cannot reach a Dask scheduler"),
    (["sweep", "smoke", "--dask", "not an address"], "expected a scheduler address"),
    (["no-such-command"], "invalid choice"),
    (["run", "{tmp}"], "is a folder"),
    (["sweep", "no_such_study"], "no study named 'no_such_study'; known: "),
    (["cache", "ls", "--cache", "{tmp}/text.txt"], "--cache"),
    (["run", "cantilever_stiff_impact", "--cache", "{tmp}/text.txt"], "not a folder"),
    # output paths are checked before any work (were OSErrors after it, naming no option)
    (["generate", "michaelis_menten", "-o", "{tmp}"], "--output {tmp}: is a folder"),
    (["run", "michaelis_menten", "--out", "{tmp}/text.txt"],
     "--out {tmp}/text.txt: exists and is not a folder"),
    (["report", "{tmp}", "-o", "{tmp}/text.txt"], "--output {tmp}/text.txt: exists and is not a folder"),
    (["sweep", "smoke", "--results", "{tmp}"], "--results {tmp}: is a folder"),
    (["family", "write", "smoke", "-o", "{tmp}/text.txt"],
     "--out {tmp}/text.txt: exists and is not a folder"),
    (["demo", "--out", "{tmp}/text.txt"], "--out {tmp}/text.txt: exists and is not a folder"),
    (["runs", "ls", "-o", "{tmp}/text.txt"], "--out {tmp}/text.txt: not a folder"),
    # a folder the user named that does not exist listed an empty history with exit 0
    (["runs", "ls", "-o", "{tmp}/no_such_folder"], "--out {tmp}/no_such_folder: no such folder"),
    (["identify", "{tmp}/text.txt", "--kind", "structural", "--method", "ls_sindy", "-o",
      "{tmp}/text.txt/m.json"], "{tmp}/text.txt is a file, not a folder"),
    # a later unit was silently ignored
    (["identify", "{tmp}/text.txt", "--kind", "structural", "--method", "ls_sindy", "--units", "g",
      "--units", "a=mm"], "--units g a=mm: expected one unit for every channel"),
    # every scenario is checked before the first runs (the first one ran, then the error)
    (["run", "michaelis_menten", "{tmp}/no_such.toml", "--out", "{tmp}/o"], "no such scenario file"),
    # an output inside a run folder was lost when the run store saved that run again
    (["run", "michaelis_menten", "--out", "{tmp}/a_run/more"],
     "--out {tmp}/a_run/more: inside the run folder {tmp}/a_run, which the run store replaces whole"),
    (["report", "{tmp}", "-o", "{tmp}/a_run"], "--output {tmp}/a_run: inside the run folder"),
    # nothing the user gave is overwritten
    (["identify", "{tmp}/text.txt", "--kind", "structural", "--method", "ls_sindy", "-o",
      "{tmp}/text.txt"], "is the input file"),
])
def test_user_mistakes_give_one_line_and_status_2(tmp_path, capsys, argv, fragment):
    (tmp_path / "text.txt").write_text("not a dataset\n")
    (tmp_path / "a_run").mkdir()
    (tmp_path / "a_run" / "run.json").write_text("{}")
    with h5py.File(tmp_path / "other.h5", "w") as f:
        f["x"] = np.zeros(3)
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    with pytest.raises(SystemExit) as exc:  # argparse's own errors exit; main returns otherwise
        sys.exit(main(argv))
    assert exc.value.code == EXIT_USAGE
    captured = capsys.readouterr()
    assert fragment.replace("{tmp}", str(tmp_path)) in one_error_line(captured.err), captured.err


def test_internal_error_is_one_line_and_debug_reraises(monkeypatch, capsys):
    def broken(args):
        raise ZeroDivisionError("a bug")

    monkeypatch.setattr(cli, "cmd_list", broken)
    assert main(["list"]) == EXIT_INTERNAL
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.splitlines()) == 1
    assert err.startswith("internal error") and "--debug" in err and "ZeroDivisionError" in err
    with pytest.raises(ZeroDivisionError):
        main(["--debug", "list"])


def test_a_key_error_from_a_bug_is_internal_not_a_user_error(monkeypatch, capsys):
    def broken(args):
        return {}["missing"]

    monkeypatch.setattr(cli, "cmd_list", broken)
    assert main(["list"]) == EXIT_INTERNAL
    assert capsys.readouterr().err.startswith("internal error")


@pytest.mark.parametrize(("outcome", "status"), [("error", EXIT_USAGE), ("bug", EXIT_INTERNAL),
                                                 ("fail", cli.EXIT_FAIL), ("pass", 0)])
def test_library_warnings_never_precede_the_error_line(monkeypatch, capsys, outcome, status):
    # numpy's and MuJoCo's warnings came before the one error line (several lines); they wait
    # for the command's end: dropped under its error line, shown after its verdict
    import warnings

    from testbed.core.errors import IdentificationError

    def command(args):
        warnings.warn("overflow encountered in multiply", RuntimeWarning, stacklevel=1)
        if outcome == "error":
            raise IdentificationError("x.csv: no model")
        if outcome == "bug":
            raise ZeroDivisionError("a bug")
        print("verdict")
        return status

    monkeypatch.setattr(cli, "cmd_list", command)
    with warnings.catch_warnings(record=True) as shown:  # what reaches stderr in a process
        warnings.simplefilter("always")
        assert main(["list"]) == status
    captured = capsys.readouterr()
    if status in (EXIT_USAGE, EXIT_INTERNAL):
        assert shown == [] and len(captured.err.splitlines()) == 1, (shown, captured.err)
    else:
        assert captured.out == "verdict\n"
        assert [str(w.message) for w in shown] == ["overflow encountered in multiply"]


#: Eight files of the corpus (the whole corpus runs in-process in test_malformed.py).
SAMPLE = ["binary.toml", "utf16.toml", "a_study.toml", "..toml", "highpass_above_nyquist.toml",
          "kind_mismatch.toml", "duration_1e6.toml", "score_without_identify.toml"]


def test_real_command_on_a_sample_of_the_corpus(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1",
           "OPENBLAS_NUM_THREADS": "1", "MPLBACKEND": "Agg"}
    procs = {name: subprocess.Popen([sys.executable, "-m", "testbed.cli", "run", str(DATA / name),
                                     "-o", str(tmp_path / "runs")],
                                    cwd=tmp_path, env=env, stdout=subprocess.PIPE,
                                    stderr=subprocess.PIPE, text=True)
             for name in SAMPLE}
    for name, proc in procs.items():
        try:
            out, err = proc.communicate(timeout=SUBPROCESS_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            proc.kill()
            pytest.fail(f"{name}: no answer within {SUBPROCESS_TIMEOUT_S} s")
        assert proc.returncode == EXIT_USAGE, (name, proc.returncode, err)
        line = one_error_line(err)
        assert name in line, line
        assert out == "", out
    assert not (tmp_path / "runs").exists()  # refused before anything was run or written


def test_export_onto_its_own_dataset_is_refused_and_the_dataset_kept(tmp_path, capsys):
    # `testbed export x.h5 --format uff -o x.h5` used to replace the dataset with the UFF file
    h5 = tmp_path / "mm.h5"
    assert main(["generate", "michaelis_menten", "--no-cache", "-o", str(h5)]) == 0
    before = h5.read_bytes()
    capsys.readouterr()
    assert main(["export", str(h5), "--format", "uff", "-o", str(h5)]) == EXIT_USAGE
    assert "is the input file" in one_error_line(capsys.readouterr().err)
    assert h5.read_bytes() == before


def test_a_rig_that_cannot_simulate_the_scenario_names_its_file(tmp_path, monkeypatch, capsys):
    # e.g. a five-bar whose RK4 diverges under a 1e6 N m torque: the error named no file
    from testbed.core.errors import RigError
    from testbed.pipeline.scenario import SCENARIO_DIR
    from testbed.scoring import run

    def diverges(*args, **kwargs):
        raise RigError("fivebar (pinocchio): the simulation diverged")

    monkeypatch.setattr(run, "run_scenario", diverges)
    assert main(["run", "michaelis_menten", "--no-figures", "--out", str(tmp_path)]) == EXIT_USAGE
    line = one_error_line(capsys.readouterr().err)
    assert line == f"error: {SCENARIO_DIR / 'michaelis_menten.toml'}: fivebar (pinocchio): the " \
                   "simulation diverged"


def test_a_five_bar_leaving_its_workspace_names_file_keys_and_values(tmp_path, capsys):
    # valid at load (only the simulation can tell), refused during generation: the line named
    # the file but no key, so a user could not tell what to change
    text = (ROOT / "scenarios" / "fivebar_multisine.toml").read_text()
    text = text.replace("amplitude = 1.0", "amplitude = 8.0").replace("duration = 10.0", "duration = 2.5")
    path = tmp_path / "fivebar_multisine.toml"
    path.write_text(text)
    assert main(["generate", str(path), "-o", str(tmp_path / "x.h5")]) == EXIT_USAGE
    line = one_error_line(capsys.readouterr().err)
    assert line.startswith(f"error: {path}: key 'excitation.amplitude, excitation.f_max, "
                           "excitation.kp, excitation.kd': value [8.0, 1.5, 10.0, 2.0]: "), line
    assert "transmission angle" in line and "allowed 30-150 deg" in line


def test_a_testbed_cache_that_is_a_file_is_refused_naming_the_variable(tmp_path, monkeypatch, capsys):
    # was "[Errno 17] File exists" after the simulation, naming no setting
    (tmp_path / "text.txt").write_text("x\n")
    monkeypatch.setenv("TESTBED_CACHE", str(tmp_path / "text.txt"))
    assert main(["run", "michaelis_menten", "--no-figures", "--out", str(tmp_path / "o")]) == EXIT_USAGE
    assert f"$TESTBED_CACHE {tmp_path / 'text.txt'}: not a folder" in one_error_line(capsys.readouterr().err)


def test_a_reader_that_goes_away_ends_the_command_quietly(tmp_path):
    """`testbed list | head -1`: the reader closes the pipe while the command still writes; that
    was sometimes "internal error ... BrokenPipeError" (status 3).  Now no line on stderr and
    the shell's status for a command ended by SIGPIPE (or 0 if it had finished writing)."""
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    for _ in range(3):  # the race is the point: whichever side wins, the outcome is quiet
        p = subprocess.Popen([sys.executable, "-m", "testbed.cli", "list"], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, env=env, cwd=tmp_path)
        p.stdout.read(1)
        p.stdout.close()  # the reader goes away
        err = p.stderr.read().decode()
        assert p.wait(timeout=60) in (0, cli.EXIT_BROKEN_PIPE)
        assert err == "", err


@pytest.mark.parametrize("var", ["TESTBED_SCENARIOS", "TESTBED_STUDIES"])
@pytest.mark.parametrize(("value", "fragment"), [
    # a typo left every command without scenarios (`testbed list` empty, exit 0)
    ("{tmp}/no_such", "'{tmp}/no_such': no such folder; expected the folder of"),
    ("{tmp}/text.txt", "'{tmp}/text.txt': not a folder; expected the folder of"),
    # a name too long for the file system was an internal error (OSError)
    ("/" + "x" * 5000, "not a usable path (a file name too long for the file system)"),
], ids=["missing", "file", "too-long"])
def test_a_scenario_or_study_folder_variable_that_is_no_folder_is_named(tmp_path, capsys, monkeypatch,
                                                                       var, value, fragment):
    (tmp_path / "text.txt").write_text("not a folder\n")
    monkeypatch.setenv(var, value.replace("{tmp}", str(tmp_path)))
    assert main(["list"]) == EXIT_USAGE
    line = one_error_line(capsys.readouterr().err)
    assert line.startswith(f"error: ${var} ") and fragment.replace("{tmp}", str(tmp_path)) in line, line


@pytest.mark.parametrize(("source", "fragment"), [
    # sys.exit(0) at import ended `testbed run` with status 0, no verdict and no line
    ("import sys\nsys.exit(0)\n", "importing it failed: SystemExit: 0"),
    ("import sys\nsys.exit('bye')\n", "importing it failed: SystemExit: bye"),
    # hostile round 19: another BaseException (GeneratorExit; pytest's Skipped from a plugin
    # written as a test helper) was a traceback with status 1
    ("raise GeneratorExit('done')\n", "importing it failed: GeneratorExit: done"),
    ("class Skipped(BaseException):\n    pass\nraise Skipped('no mujoco')\n",
     "importing it failed: Skipped: no mujoco"),
])
def test_a_plugin_that_exits_at_import_is_one_line(tmp_path, capsys, source, fragment):
    plugin = tmp_path / "exits.py"
    plugin.write_text(source)
    assert main(["run", "michaelis_menten", "--plugin", str(plugin), "-o", str(tmp_path / "o")]) == EXIT_USAGE
    line = one_error_line(capsys.readouterr().err)
    assert line == f"error: plugin {plugin}: {fragment}", line
    assert not (tmp_path / "o").exists()


def test_a_server_socket_path_too_long_is_one_line(tmp_path, capsys, monkeypatch):
    # was "internal error (a bug, not your input): OSError: AF_UNIX path too long"
    path = tmp_path / ("x" * 120) / "s.sock"
    monkeypatch.setenv("TESTBED_SERVER_SOCKET", str(path))
    assert main(["serve", "--warm-up", "none", "--idle", "1"]) == EXIT_USAGE
    line = one_error_line(capsys.readouterr().err)
    assert line.startswith(f"error: socket path {path} ($TESTBED_SERVER_SOCKET or the default): ")
    assert line.endswith("bytes; expected at most 107 (the longest Unix socket address)"), line


def test_an_interrupt_python_could_not_raise_still_ends_the_command(tmp_path, capsys):
    # a Ctrl-C landing in a weak reference's callback (the import system's module locks, in the
    # first second of `testbed run`) printed "Exception ignored in ... KeyboardInterrupt" and
    # was lost: the run went on to its verdict, status 0; it is now delivered again.  The
    # delivery is a SIGINT: as an interactive shell hands it to a command (a suite started in
    # the background of a non-interactive shell inherits SIGINT ignored)
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        _interrupt_is_delivered_again(tmp_path, capsys)
    finally:
        signal.signal(signal.SIGINT, previous)


def _interrupt_is_delivered_again(tmp_path, capsys):
    plugin = tmp_path / "swallows.py"
    plugin.write_text("import gc, time\n"
                      "class Swallowed:\n"
                      "    def __del__(self):\n"
                      "        raise KeyboardInterrupt\n"
                      "Swallowed()\n"
                      "gc.collect()\n"
                      "time.sleep(1.5)  # the interrupt is sent again 10 ms later, during this\n"
                      "raise SystemExit('the interrupt was lost')\n")
    assert main(["list", "--plugin", str(plugin)]) == cli.EXIT_INTERRUPTED
    assert one_error_line(capsys.readouterr().err) == "error: interrupted"


@pytest.mark.parametrize(("interrupt", "status", "line"), [
    (KeyboardInterrupt(), cli.EXIT_INTERRUPTED, "error: interrupted"),
    (cli.Terminated(15), 143, "error: interrupted by SIGTERM"),
])
def test_an_import_interrupted_is_an_interrupt_not_an_internal_error(monkeypatch, capsys, interrupt,
                                                                     status, line):
    # a C extension interrupted while it initialises (pybind11's: MuJoCo, matplotlib) raises
    # "ImportError: initialization failed" from the interrupt: a SIGTERM at a run's start
    # was "internal error (a bug, not your input): ImportError: initialization failed"
    def cmd_list(args):
        raise ImportError("initialization failed") from interrupt

    monkeypatch.setattr(cli, "cmd_list", cmd_list)
    assert main(["list"]) == status
    assert one_error_line(capsys.readouterr().err) == line


def test_an_interrupt_while_the_options_are_parsed_is_one_line(monkeypatch, capsys):
    # a Ctrl-C in a busy machine's first second landed in argparse (building the parser
    # imports shutil): a 30-line traceback, and the process ended by SIGINT
    def build_parser():
        raise KeyboardInterrupt

    monkeypatch.setattr(cli, "build_parser", build_parser)
    assert main(["list"]) == cli.EXIT_INTERRUPTED
    assert one_error_line(capsys.readouterr().err) == "error: interrupted"


# ------------------------------------------------------------------ round 6: hostile stdio, cwd
@pytest.mark.parametrize(("redirect", "reason"), [
    ({"stdout": "/dev/full"}, "No space left on device"),
    ({"stdout_mode": os.O_RDONLY}, "Bad file descriptor"),  # `testbed ... 1</dev/null`
], ids=["dev-full", "read-only"])
def test_a_standard_output_that_refuses_writes_is_one_line(tmp_path, redirect, reason):
    # an internal error ("OSError: [Errno 28] ... please report it") before
    fd = os.open(redirect.get("stdout", os.devnull), redirect.get("stdout_mode", os.O_WRONLY))
    try:
        r = subprocess.run([sys.executable, "-m", "testbed.cli", "cache", "ls", "--cache", str(tmp_path)],
                           cwd=ROOT, stdout=fd, stderr=subprocess.PIPE, text=True,
                           env={**os.environ, "PYTHONPATH": str(ROOT), "TESTBED_NO_SERVER": "1"},
                           timeout=SUBPROCESS_TIMEOUT_S)
    finally:
        os.close(fd)
    assert r.returncode == EXIT_USAGE, r.stderr
    assert one_error_line(r.stderr) == (
        f"error: cannot write to standard output: {reason} (a full disk or /dev/full, or a file "
        "descriptor not open for writing)")


def test_a_closed_standard_output_is_one_line(tmp_path, capsys, monkeypatch):
    # `testbed run x >&-` was an internal error (AttributeError: 'NoneType' object has no
    # attribute 'isatty'), `testbed list >&-` printed nothing with status 0
    monkeypatch.setattr(sys, "stdout", None)
    assert main(["cache", "ls", "--cache", str(tmp_path)]) == EXIT_USAGE
    assert one_error_line(capsys.readouterr().err) == (
        "error: standard output is closed (file descriptor 1); give the command somewhere to "
        "write (> /dev/null to discard what it prints)")


def test_a_deleted_current_folder_is_named(tmp_path, capsys, monkeypatch):
    # "error: [Errno 2] No such file or directory", naming nothing, for the default cache
    gone = tmp_path / "gone"
    gone.mkdir()
    monkeypatch.chdir(gone)
    gone.rmdir()
    assert main(["run", "michaelis_menten", "--no-figures"]) == EXIT_USAGE
    assert one_error_line(capsys.readouterr().err) == (
        "error: the current folder no longer exists (deleted?); cd to a folder that exists, or "
        "give absolute paths and --out/--cache")


@pytest.mark.parametrize("argv", [
    ["sweep", "x.toml", "--jobs", "9" * 5000],   # not read: over Python's 4300 digits
    ["sweep", "x.toml", "--jobs", "9" * 4000],   # read, and over the bound
    ["run", "michaelis_menten", "--seed", "-" + "9" * 4000],
], ids=["jobs-5000", "jobs-4000", "seed"])
def test_an_option_value_of_thousands_of_characters_is_cut_in_its_line(cli_in_process, tmp_path, argv):
    # the value was printed whole: a 5 kB error line
    r = cli_in_process(*argv, cwd=tmp_path)
    assert r.returncode == EXIT_USAGE
    line = one_error_line(r.stderr)
    assert len(line) < 400 and "[...]" in line, line[:500]


def test_key_values_and_a_dask_address_of_thousands_of_characters_are_cut():
    from testbed.core.errors import InputError

    for call in (lambda: cli._key_values(["m=" + "9" * 5000], "--prior", numbers=True),
                 lambda: cli.check_dask_address("x" * 5000)):
        with pytest.raises(InputError) as e:
            call()
        assert len(str(e.value)) < 300 and "[...]" in str(e.value), str(e.value)[:500]


@pytest.mark.parametrize("argv", [
    ["run", "michaelis_menten", "--out", ""],      # wrote the run and index.html in the cwd
    ["run", "michaelis_menten", "--cache", ""],    # wrote the datasets in the cwd
    ["runs", "ls", "--out", ""],
    ["sweep", "x.toml", "--results", ""],
    ["generate", "michaelis_menten", "-o", ""],
    ["cache", "clear", "--cache", ""],
    ["run", "michaelis_menten", "--plugin", ""],
], ids=lambda a: f"{a[0]} {a[-2]}")
def test_an_empty_path_option_is_refused(cli_in_process, tmp_path, argv):
    r = cli_in_process(*argv, cwd=tmp_path)
    assert r.returncode == EXIT_USAGE
    assert "an empty path; expected a file or folder name" in one_error_line(r.stderr)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(("make", "fragment"), [
    (lambda d: (d / "c").symlink_to(d / "nowhere"),
     "c: a symbolic link to {d}/nowhere, which does not exist"),
    (lambda d: (d / "f").write_text(""), "f/c: {d}/f is a file, not a folder"),
    (lambda d: None, None),
], ids=["dangling-link", "file-on-the-way", "empty-env"])
def test_a_cache_folder_that_cannot_be_made_is_named(cli_in_process, tmp_path, monkeypatch, make, fragment):
    # "[Errno 17] File exists" and "[Errno 20] Not a directory", naming no option, after the
    # simulation; TESTBED_CACHE="" wrote the datasets in the current folder
    make(tmp_path)
    if fragment is None:
        monkeypatch.setenv("TESTBED_CACHE", "")
        argv, expected = [], ("error: $TESTBED_CACHE '': an empty path; expected the dataset cache "
                              "folder (unset it for the default)")
    else:
        cache = tmp_path / ("c" if "link" in fragment else "f/c")
        argv = ["--cache", str(cache)]
        expected = (f"error: --cache {tmp_path}/{fragment.format(d=tmp_path)}; expected the dataset "
                    "cache folder")
    r = cli_in_process("cache", "ls", *argv, cwd=tmp_path)
    assert (r.returncode, one_error_line(r.stderr)) == (EXIT_USAGE, expected)


def test_a_late_exit_of_a_thread_a_plugin_left_running_is_one_warning_line(capsys):
    # hostile round 21: such a call ended `testbed run` / `identify` / a sequential sweep with
    # the thread's status and no verdict; now it ends the thread and the command says it
    real, go, ended = os._exit, threading.Event(), []

    def late() -> None:
        go.wait(30)
        try:
            os._exit(4)
        except SystemExit as e:  # a plain SystemExit ends the thread (pytest's hook reports it)
            ended.append((type(e), e.code))

    with no_process_exit():
        t = threading.Thread(target=late, name="plugin-timer")
        t.start()
    go.set()
    t.join(30)
    assert ended == [(SystemExit, 4)]
    with no_process_exit():  # puts the real os._exit back (the thread has ended)
        pass
    assert os._exit is real
    cli._say_late_exits()
    cli._say_late_exits()  # said once
    err = capsys.readouterr().err
    assert err.splitlines() == [
        "warning: 1 thread(s) a plugin's code left running called os._exit after its fit had "
        "returned (plugin-timer os._exit(4)): each ended its own thread, not this command"], err
