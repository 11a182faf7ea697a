"""What a user waits for at the command line: ``testbed`` start-up and one scored run with figures.

Whole processes (``python -m testbed.cli ...``), as a user starts them, timed interleaved with
their peers in the same run (:func:`benchmarks._timing.interleaved`), medians with spread:

1. ``testbed --version`` and ``testbed list`` against ``python -c "import numpy"``, the floor of
   any Python command of ours.  Target: each under 0.5 s (the issue's absolute goal).
   ``testbed list`` prints from its index (:mod:`testbed.core.stamped`) while every file it
   was computed from holds its stamp, as in a user's second and later listings (the warm-up
   round writes it); the listing without it (``TESTBED_INDEX=""``: every rig and identifier
   imported, every scenario validated, as after an edit) is reported beside it.
2. ``testbed run cantilever_stiff_impact`` with a warm dataset cache, with figures, against the
   same run without figures (``--no-figures``) and against the numpy start-up; and the same run
   served by a resident ``testbed serve`` (:mod:`testbed.server`: forked from a process that
   has the libraries loaded).  Target: under 1.5 s (the issue's absolute goal), met only
   served: a command alone spends most of its time importing the libraries.  The ratio to the
   run without figures is what the figures cost; the ratio to the numpy start-up scales out the
   machine's speed.

The run draws its figures in processes it forks (``testbed.reporting.drawer``): one imports
matplotlib during the fit, then it and one more draw half of the figures each; their CPU time is
in the run's (both are reaped before the command exits, so ``getrusage`` of the child counts them).

Bytecode is written and reused as in a user's checkout (``PYTHONDONTWRITEBYTECODE`` is dropped
from the environment; the warm-up round writes it).  Each process's CPU time (user + sys, from
``getrusage`` of the reaped child) is reported beside the wall time: on a shared machine the
wall time of a single-threaded command also holds the time it waited for a core.

Run: ``.venv/bin/python -m benchmarks bench_cli``.
"""

from __future__ import annotations

import contextlib
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks._timing import interleaved, machine, ratio_spread, spread

ROOT = Path(__file__).resolve().parents[1]
TARGET_START_S = 0.5   # testbed --version / list, wall [s]
TARGET_RUN_S = 1.5     # testbed run cantilever_stiff_impact, warm cache, with figures, wall [s]
REPEATS = 5
SCENARIO = "cantilever_stiff_impact"


def _env() -> dict[str, str]:
    env = dict(os.environ, PYTHONPATH=str(ROOT), OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1",
               MKL_NUM_THREADS="1", MPLBACKEND="Agg")
    # A user's Python writes the project's bytecode on its first run (the warm-up round here)
    # and loads it after; with PYTHONDONTWRITEBYTECODE inherited every command would compile
    # the project's modules afresh (0.1 s of `testbed list`, 0.26 s of a run, measured).
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["TESTBED_NO_SERVER"] = "1"  # each command alone, unless it asks for the bench's server
    return env


def _served_env(sock: Path) -> dict[str, str]:
    env = _env()
    del env["TESTBED_NO_SERVER"]
    return {**env, "TESTBED_SERVER_SOCKET": str(sock)}


@contextlib.contextmanager
def _server(folder: Path):
    """A ``testbed serve`` on a private socket in ``folder``, listening when entered."""
    (folder / "sock").mkdir(mode=0o700)
    sock = folder / "sock" / "s.sock"
    with open(folder / "server.log", "w+") as log:
        proc = subprocess.Popen([sys.executable, "-m", "testbed.cli", "serve", "--idle", "3600"],
                                cwd=ROOT, env=_served_env(sock), stdout=log, stderr=subprocess.STDOUT)
        try:
            while "listening" not in (folder / "server.log").read_text():
                if proc.poll() is not None:
                    raise RuntimeError(f"testbed serve ended: {(folder / 'server.log').read_text()}")
                time.sleep(0.1)
            yield sock
        finally:
            proc.terminate()
            proc.wait(timeout=60)


def _command(args: list[str], cpu: list[float], env: dict[str, str] | None = None):
    """A callable running ``python args`` from the repository root; appends its CPU time [s]
    (of the process itself: a served command's work is done by the server's child)."""
    def run() -> None:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        subprocess.run([sys.executable, *args], cwd=ROOT, env=env or _env(), check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpu.append(after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime)
    return run


def run() -> list[dict]:
    rows = []
    with tempfile.TemporaryDirectory(prefix="bench_cli.") as out, _server(Path(out)) as sock:
        cpu: dict[str, list[float]] = {k: [] for k in ("numpy", "version", "list", "list_fresh",
                                                       "run", "run_nofig", "served")}
        cmds = {
            "numpy": _command(["-c", "import numpy"], cpu["numpy"]),
            "version": _command(["-m", "testbed.cli", "--version"], cpu["version"]),
            "list": _command(["-m", "testbed.cli", "list"], cpu["list"]),
            "list_fresh": _command(["-m", "testbed.cli", "list"], cpu["list_fresh"],
                                   {**_env(), "TESTBED_INDEX": ""}),
            "run": _command(["-m", "testbed.cli", "run", SCENARIO, "--out", out], cpu["run"]),
            "run_nofig": _command(["-m", "testbed.cli", "run", SCENARIO, "--out", out, "--no-figures"],
                                  cpu["run_nofig"]),
            "served": _command(["-m", "testbed.cli", "run", SCENARIO, "--out", out], cpu["served"],
                               _served_env(sock)),
        }
        # the warm-up round generates the dataset if the cache lacks it and loads numba's cache
        t = interleaved(cmds, REPEATS)
    c = {k: np.asarray(v[-REPEATS:]) for k, v in cpu.items()}  # without the warm-up round
    for k in ("version", "list"):
        ratio, rs = ratio_spread(t[k], t["numpy"])
        med = float(np.median(t[k]))
        rows.append({"name": f"testbed {'--version' if k == 'version' else k} start-up", "value": med,
                     "unit": "s", "target": f"< {TARGET_START_S}", "ok": med < TARGET_START_S,
                     "note": f"whole process, wall {spread(t[k])} s, CPU {spread(c[k])} s; "
                             f"/ `python -c 'import numpy'` (wall {spread(t['numpy'])} s): "
                             f"{ratio:.2f}x, {rs}"})
    med = float(np.median(t["list_fresh"]))
    ratio, rs = ratio_spread(t["list"], t["list_fresh"])
    rows.append({"name": "testbed list start-up without its index (every rig and identifier imported)",
                 "value": med, "unit": "s", "target": "report", "ok": None,
                 "note": f"whole process, TESTBED_INDEX=\"\" (as the first listing after an edit), "
                         f"wall {spread(t['list_fresh'])} s, CPU {spread(c['list_fresh'])} s; "
                         f"from the index / without: {ratio:.2f}x, {rs}"})
    med = float(np.median(t["served"]))
    r_served, rs_served = ratio_spread(t["served"], t["run"])
    rows.append({"name": f"testbed run {SCENARIO} served by `testbed serve` (warm cache, figures)",
                 "value": med, "unit": "s", "target": f"< {TARGET_RUN_S}", "ok": med < TARGET_RUN_S,
                 "note": f"whole client process, wall {spread(t['served'])} s; / the same command "
                         f"alone: {r_served:.2f}x, {rs_served}; {machine()}"})
    med = float(np.median(t["run"]))
    r_nofig, rs_nofig = ratio_spread(t["run"], t["run_nofig"])
    r_np, _ = ratio_spread(t["run"], t["numpy"])
    rows.append({"name": f"testbed run {SCENARIO} alone (warm cache, figures)", "value": med, "unit": "s",
                 "target": "report", "ok": None,
                 "note": f"whole process, wall {spread(t['run'])} s, CPU {spread(c['run'])} s; "
                         f"without figures wall {spread(t['run_nofig'])} s, CPU "
                         f"{spread(c['run_nofig'])} s; {r_np:.1f}x the numpy start-up; {machine()}"})
    rows.append({"name": f"testbed run {SCENARIO}: with / without figures", "value": r_nofig, "unit": "x",
                 "target": "report", "ok": None,
                 "note": f"what the six figures add to the wall time (drawn in two forked processes "
                         f"after the fit), same run, interleaved; {rs_nofig}"})
    return rows


if __name__ == "__main__":
    for r in run():
        mark = {True: "ok", False: "MISSED", None: "-"}[r["ok"]]
        print(f"{r['name']}: {r['value']:.4g} {r['unit']}  target {r['target']}  [{mark}]  {r['note']}")
