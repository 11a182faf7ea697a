"""Where a served ``testbed run cantilever_stiff_impact`` spends its time: CPU per phase, per figure.

A command served by ``testbed serve`` is a fork of a process that has imported the libraries and
run the scenario once (:func:`testbed.server._preload`, :func:`testbed.server._warm_up`).  This
benchmark makes such a process and forks the command from it ``REPEATS`` times through the
server's own child function (:func:`testbed.server._child`, standard streams on /dev/null), with
three wrappers installed before the fork (so the command and its drawing processes inherit them):

- each phase of the run (simulate, signal chain, fit, score, figures), its CPU and wall time in
  the command's process (:func:`testbed.reporting.progress.run_progress`);
- each figure, its CPU time in the drawing process that drew it
  (:func:`testbed.reporting.drawer._draw`, one stem at a time);
- the command's own CPU time at its end (:func:`testbed.server._exit_work`), and the whole
  command's with its drawing processes (``wait4`` of the child);
- the figure frames made ahead in the drawing process while the command fits
  (:func:`testbed.reporting.drawer.prepare_frames`): their CPU, and whether they were made
  before the first figure was drawn (off the critical path).  A served command inherits the
  frames the server made after its warm-up run, and so makes none.

Each round also runs the command once without any frame made ahead (the server's pool emptied,
the drawing process not asked to make any), interleaved: the per-round ratio of the critical
paths is what the frames save, at whatever load the machine has.

CPU time is what the work costs whatever else runs on the machine; wall time is reported with
the load.  The *critical path* is the command's own CPU plus the larger of the two drawing
groups' CPU (the figures are drawn by two processes after the fit, while the command waits): the
wall time a served run would take on two idle cores, less the client's start-up (about 0.1 s)
and the forks.  It is what the 1.5 s target of ``bench_cli`` has to fit in.

Run: ``.venv/bin/python -m benchmarks bench_cli_phases``.
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks._timing import machine, ratio_spread, spread

ROOT = Path(__file__).resolve().parents[1]
SCENARIO = "cantilever_stiff_impact"
REPEATS = 7
TARGET_RUN_S = 1.5  # bench_cli's target for the served run, wall [s]


def _cpu(who: int = resource.RUSAGE_SELF) -> float:
    """User + system CPU time [s] of this process (or of its reaped children)."""
    r = resource.getrusage(who)
    return r.ru_utime + r.ru_stime


def _recorder(log: Path):
    """``record(**fields)``: append one JSON line to ``log`` (one ``write`` per line: the
    processes that share the file do not interleave within a line)."""
    def record(**fields) -> None:
        fd = os.open(log, os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o600)
        try:
            os.write(fd, (json.dumps({"pid": os.getpid(), **fields}) + "\n").encode())
        finally:
            os.close(fd)
    return record


def _instrument(record) -> None:
    """Install the three wrappers (see the module docstring) in this process."""
    from testbed import server
    from testbed.reporting import drawer, progress

    @contextlib.contextmanager
    def run_progress(label, console=None):
        @contextlib.contextmanager
        def phase(name):
            w, c = time.perf_counter(), _cpu()
            try:
                yield lambda *a, **k: None
            finally:
                record(kind="phase", name=name, cpu=_cpu() - c, wall=time.perf_counter() - w)
        yield phase

    draw = drawer._draw
    prepare = drawer.prepare_frames

    def prepare_recorded(folder):
        if _NO_FRAMES:
            return 0
        c = _cpu()
        n = prepare(folder)
        record(kind="prepare", name="frames", cpu=_cpu() - c, made=n, end=time.time())
        return n

    def draw_each(run, folder, stems):
        record(kind="draw start", name="", start=time.time())
        out = []
        for stem in stems:
            c = _cpu()
            out += draw(run, folder, [stem])
            record(kind="figure", name=stem, cpu=_cpu() - c)
        return out

    exit_work = server._exit_work

    def exit_work_recorded():
        record(kind="command", name="own", cpu=_cpu())
        exit_work()

    progress.run_progress = run_progress
    drawer._draw = draw_each
    drawer.prepare_frames = prepare_recorded
    server._exit_work = exit_work_recorded


def _served_run(out: str) -> tuple[float, float]:
    """Fork one served ``testbed run`` (as :func:`testbed.server._start` does); its wall time
    [s] and CPU time [s] with its drawing processes."""
    from testbed import cli, server

    devnull = [os.open(os.devnull, os.O_RDWR) for _ in range(3)]
    request = {"argv": ["run", SCENARIO, "--out", out], "cwd": str(ROOT), "env": dict(os.environ),
               "umask": 0o022}
    before = _cpu(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    pid = os.fork()
    if pid == 0:
        server._child(request, devnull, [], os.getppid(), cli.main)  # never returns (as
        # `testbed serve` runs a client's command: the command line's main)
    _, status = os.waitpid(pid, 0)
    wall = time.perf_counter() - t0
    for fd in devnull:
        os.close(fd)
    if os.waitstatus_to_exitcode(status) != 0:  # a failed run is not the run measured
        raise RuntimeError(f"testbed run {SCENARIO} ended with wait status {status}")
    return wall, _cpu(resource.RUSAGE_CHILDREN) - before


#: Set while a command runs without frames made ahead (:func:`_rounds`).
_NO_FRAMES = False


def _rounds(log: Path, out: str) -> tuple[list[dict], list[dict]]:
    """``REPEATS`` rounds after one untimed one, each a served run as shipped and one without
    frames made ahead; per run its records and totals."""
    global _NO_FRAMES
    from testbed.reporting import frames

    pool = {k: list(v) for k, v in frames._POOL.items()}  # the server's, made at its warm-up
    rounds: tuple[list[dict], list[dict]] = ([], [])
    try:
        for i in range(REPEATS + 1):
            for without in (False, True):
                frames.clear()
                if not without:
                    frames._POOL.update({k: list(v) for k, v in pool.items()})
                _NO_FRAMES = without
                log.write_text("")
                wall, cpu = _served_run(f"{out}-{int(without)}")
                recs = [json.loads(line) for line in log.read_text().splitlines()]
                if i:
                    rounds[without].append({"wall": wall, "cpu": cpu, "load": os.getloadavg()[0],
                                            "records": recs})
    finally:
        _NO_FRAMES = False
        frames.clear()
        frames._POOL.update(pool)
    return rounds


def _summary(rounds: list[dict]) -> dict[str, np.ndarray]:
    """Per-run series: each phase's CPU and wall, each figure's CPU, the groups, the path."""
    s: dict[str, list[float]] = {}
    for r in rounds:
        groups: dict[int, float] = {}
        own = 0.0
        prep, prep_end, starts = 0.0, None, []
        for rec in r["records"]:
            if rec["kind"] == "prepare":
                prep, prep_end = rec["cpu"], rec["end"]
                s.setdefault("frames made ahead", []).append(rec["made"])
                continue
            if rec["kind"] == "draw start":
                starts.append(rec["start"])
                continue
            if rec["kind"] == "phase":
                s.setdefault(f"phase {rec['name']} cpu", []).append(rec["cpu"])
                s.setdefault(f"phase {rec['name']} wall", []).append(rec["wall"])
            elif rec["kind"] == "figure":
                s.setdefault(f"figure {rec['name']}", []).append(rec["cpu"])
                groups[rec["pid"]] = groups.get(rec["pid"], 0.0) + rec["cpu"]
            else:
                own = rec["cpu"]
        g = [*sorted(groups.values(), reverse=True), 0.0, 0.0]
        s.setdefault("command own cpu", []).append(own)
        s.setdefault("larger drawing group", []).append(g[0])
        s.setdefault("smaller drawing group", []).append(g[1])
        s.setdefault("critical path", []).append(own + g[0])
        s.setdefault("frames ahead cpu", []).append(prep)
        s.setdefault("frames ahead in time", []).append(
            float(prep_end is None or not starts or prep_end <= min(starts)))
        s.setdefault("wall", []).append(r["wall"])
        s.setdefault("cpu", []).append(r["cpu"])
        s.setdefault("load", []).append(r["load"])
    return {k: np.asarray(v) for k, v in s.items()}


def _measure() -> dict[str, list[float]]:
    """The measurement, in a process started with the served environment (:func:`run`)."""
    from testbed import cli, server

    with contextlib.redirect_stderr(io.StringIO()):
        server._preload()
        server._warm_up(SCENARIO, lambda text: None, cli._main)
    # not a TemporaryDirectory: its finalizer is an atexit function, which each served command
    # runs at its end (testbed.server._exit_work), removing the folder under the next command
    tmp = Path(tempfile.mkdtemp(prefix="bench_cli_phases."))
    try:
        log = tmp / "records.jsonl"
        _instrument(_recorder(log))
        shipped, without = _rounds(log, str(tmp / "runs"))
        out = {k: v.tolist() for k, v in _summary(shipped).items()}
        out.update({f"none {k}": v.tolist() for k, v in _summary(without).items()})
        return out
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def run() -> list[dict]:
    # a process of its own, started as bench_cli starts its server: one BLAS thread and the
    # other import-time variables set before numpy loads (set later, they do not hold)
    from benchmarks.bench_cli import _env

    proc = subprocess.run([sys.executable, "-m", "benchmarks.bench_cli_phases", "--measure"],
                          cwd=ROOT, env=_env(), check=True, capture_output=True, text=True)
    s = {k: np.asarray(v) for k, v in json.loads(proc.stdout.splitlines()[-1]).items()}
    med = {k: float(np.median(v)) for k, v in s.items()}
    loads = f"load average during the runs {spread(s['load'], fmt='.2f')}; {machine()}"
    r_path, n_path = ratio_spread(s["critical path"], s["none critical path"])
    _, n_group = ratio_spread(s["larger drawing group"], s["none larger drawing group"])
    rows = [{"name": f"served {SCENARIO}: critical path (command's own CPU + larger drawing group)",
             "value": med["critical path"], "unit": "s", "target": "report", "ok": None,
             "note": f"{spread(s['critical path'])} s: command's own CPU {spread(s['command own cpu'])} s "
                     f"(phases below, its start and end), drawing groups {spread(s['larger drawing group'])} "
                     f"and {spread(s['smaller drawing group'])} s; bench_cli's target for the whole "
                     f"served run is < {TARGET_RUN_S} s wall; {loads}"},
            {"name": f"served {SCENARIO}: critical path, frames made ahead / none", "value": r_path,
             "unit": "x", "target": "report", "ok": None,
             "note": f"{n_path}, interleaved; larger drawing group {n_group}; without frames: "
                     f"critical path {spread(s['none critical path'])} s, drawing groups "
                     f"{spread(s['none larger drawing group'])} and "
                     f"{spread(s['none smaller drawing group'])} s, "
                     f"whole command {spread(s['none cpu'])} s CPU (with them: {spread(s['cpu'])})"},
            {"name": f"served {SCENARIO}: figure frames made ahead during the fit",
             "value": med["frames ahead cpu"], "unit": "s CPU", "target": "report", "ok": None,
             "note": f"{spread(s['frames ahead cpu'])} s CPU in the drawing process, "
                     f"{spread(s.get('frames made ahead', np.zeros(1)), fmt='.0f')} frames made "
                     f"(a served command inherits the server's), done before the first figure in "
                     f"{int(sum(s['frames ahead in time']))} of {len(s['frames ahead in time'])} runs"},
            {"name": f"served {SCENARIO}: whole command", "value": med["cpu"], "unit": "s CPU",
             "target": "report", "ok": None,
             "note": f"drawing processes included, {spread(s['cpu'])} s; wall {spread(s['wall'])} s "
                     f"(forked from a warm process, no client)"}]
    for k in [k for k in s if k.startswith("phase ") and k.endswith(" cpu")]:
        name = k[len("phase "):-len(" cpu")]
        rows.append({"name": f"served {SCENARIO}: phase {name}", "value": med[k], "unit": "s CPU",
                     "target": "report", "ok": None,
                     "note": f"{spread(s[k])} s CPU, wall {spread(s[f'phase {name} wall'])} s"
                             + (" (the command waits for its two drawing processes)"
                                if name == "figures" else "")})
    for k in sorted(k for k in s if k.startswith("figure ")):
        rows.append({"name": f"served {SCENARIO}: {k}", "value": med[k], "unit": "s CPU",
                     "target": "report", "ok": None, "note": f"{spread(s[k])} s CPU"})
    return rows


if __name__ == "__main__":
    if sys.argv[1:] == ["--measure"]:
        print(json.dumps(_measure()))
        sys.exit(0)
    for r in run():
        print(f"{r['name']}: {r['value']:.4g} {r['unit']}  {r['note']}", file=sys.stdout)
