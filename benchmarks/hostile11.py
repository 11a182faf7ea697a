"""Eleventh malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile11 [family ...]      # all families when none is named

Families (where rounds 1-10 went least):

``nyquist``
    The clamped beam's ``E``, ``rho``, ``thickness``, ``length`` and ``simulation.sample_rate``
    at values that put mode 1 on either side of the Nyquist frequency (round 10 left ``E =
    2**63`` open): a scenario accepted whose compiled chain's mode 1 lies above ``sample_rate /
    2`` is a finding (the record holds none of the beam's modes, only aliases).
``twice``
    Every option of every subcommand that takes one value, given twice with two different
    values (the choices of a choice, two numbers, two paths): parsed by the command line's own
    parser; accepted is a finding (the first value ignored in silence).
``empty``
    Every name or address argument given as ``""`` (a script's ``"$NAME"`` with the variable
    unset): scenario and study names, ``--scenario``, ``--dask``, ``--warm-up``; a command that
    runs, or a refusal naming another file (``scenarios/..toml``), is a finding.
``serve``
    A ``testbed serve`` on a private socket sent requests its forked child cannot apply (umask
    out of range, a relative or missing folder, NUL bytes, environment names with ``=``), a
    request trickled a byte at a time while a real command waits, 300 idle connections, then a
    real command: an "internal error" on the request's stderr, or a real command waiting more
    than 5 s, is a finding.
``parts``
    A sweep's results file beside one row file (``<results>.parts/<cell>.json``) edited by hand
    (noise text, NaN, -1, null; status, passed, seed, a score of the wrong type), then
    ``testbed summary``, ``testbed report`` and the sweep resumed: an internal error, or a
    report or summary made over the edited row, is a finding.
``cache``
    ``testbed cache clear`` (``DatasetCache.clear``) in a loop while another thread fills the
    same cache folder: a write that fails is a finding.
``kill``
    A small sweep (two rigs, two identifiers, two noise levels, two seeds; ``--jobs`` 1 and 2)
    interrupted by SIGINT, SIGTERM or SIGKILL at a random moment, then resumed: a process left
    in the sweep's session, a traceback, a cell lost or twice, a temporary file left, or a row
    that differs from the uninterrupted sweep's (every column but the timings, versions and
    commit, compared to the bit) is a finding.

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import argparse
import array
import contextlib
import copy
import io
import json
import math
import os
import random
import shutil
import signal
import socket
import struct
import subprocess
import sys
import threading
import time
from collections import Counter
from pathlib import Path

from benchmarks import _hostile

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 300  # a case longer than this is a hang (a resumed sweep below takes about 60 s)
PYTHON = sys.executable
#: The environment of the commands started here: one BLAS thread, never a resident server; the
#: caller's PYTHONPATH (another checkout's code, to count its findings), else this checkout.
ENV = {**os.environ, "PYTHONPATH": os.environ.get("PYTHONPATH") or str(ROOT), "OMP_NUM_THREADS": "1",
       "OPENBLAS_NUM_THREADS": "1", "TESTBED_NO_SERVER": "1", "MPLBACKEND": "Agg"}


def _testbed(argv: list[str], cwd: Path, env: dict | None = None,
             timeout: float = TIMEOUT_S) -> subprocess.CompletedProcess:
    return subprocess.run([PYTHON, "-m", "testbed.cli", *argv], cwd=cwd, env=env or ENV,
                          capture_output=True, text=True, timeout=timeout)


def _cli_finding(p: subprocess.CompletedProcess) -> str | None:
    """An internal error, a traceback or a multi-line error of a finished command, else None."""
    if "Traceback" in p.stderr or "internal error" in p.stderr or p.returncode not in (0, 1, 2):
        lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
        return f"status {p.returncode}: {lines[-1][:200] if lines else ''}"
    return None


# ------------------------------------------------------------------ nyquist

def nyquist_cases() -> list[tuple[str, object]]:
    from models.cantilever.model import build_model
    from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml, scenario_from_dict

    base = _read_toml(SCENARIO_DIR / "cantilever_stiff_impact.toml")
    base.pop("score", None)
    base["simulation"]["duration"] = 0.05
    edits = [("rig", "E", v) for v in (1e12, 1e14, 1e15, 1.3e15, 1.6e15, 2e15, 5e15, 1e16, 1e18,
                                       2**63, 2**64, 1e30)]
    edits += [("rig", "rho", v) for v in (1.0, 10.0, 1e-2, 1e-4)]
    edits += [("rig", "thickness", v) for v in (0.1, 0.5, 2.0)]
    edits += [("rig", "length", v) for v in (0.05, 0.02, 0.01)]
    edits += [("simulation", "sample_rate", v) for v in (3200.0, 400.0, 200.0, 150.0, 100.0)]

    def case(section: str, key: str, value: float):
        def run() -> str | None:
            raw = copy.deepcopy(base)
            raw[section][key] = value
            if key == "sample_rate":  # a pulse the record can see (not this family's subject)
                raw["excitation"]["pulse_duration"] = 3.0 / value
            sc = scenario_from_dict(raw)  # a refusal in one line ends the case ok
            b = build_model(sc.rig_params, sc.simulation, sc.excitation)
            nyq = sc.simulation["sample_rate"] / 2
            if b.freqs[0] > nyq:
                return f"accepted with the chain's mode 1 at {b.freqs[0]:.4g} Hz above {nyq:g} Hz"
            return None
        return (f"{section}.{key} = {value:g}", run)

    return [case(*e) for e in edits]


# ------------------------------------------------------------------ twice

def _two_values(action: argparse.Action) -> tuple[str, str]:
    if action.choices:
        c = list(action.choices)
        return c[0], c[1] if len(c) > 1 else c[0]
    return ("1", "2")  # numbers, and paths or names alike


def twice_cases() -> list[tuple[str, object]]:
    from testbed.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    cases = []
    for name, sp in sub.choices.items():
        positional = [("x" if not a.choices else next(iter(a.choices)))
                      for a in sp._actions if not a.option_strings]
        single = [a for a in sp._actions if a.option_strings and a.nargs is None
                  and isinstance(a, argparse._StoreAction)]
        for a in single:
            first, second = _two_values(a)
            if first == second:
                continue
            opt = a.option_strings[-1]
            others = [x for r in single if r.required and r is not a
                      for x in (r.option_strings[0], _two_values(r)[0])]
            argv = [name, *positional, *others, opt, first, opt, second]

            def run(argv=argv) -> str | None:
                err = io.StringIO()
                with contextlib.redirect_stderr(err):
                    try:
                        build_parser().parse_args(argv)
                    except SystemExit:
                        text = err.getvalue().strip()
                        return None if "\n" not in text else f"two lines: {text[:160]!r}"
                return "accepted: the first value ignored in silence"
            cases.append((" ".join(argv), run))
    return cases


# ------------------------------------------------------------------ empty

def empty_cases(work: Path) -> list[tuple[str, object]]:
    """Every name or address argument given as "" (a script's ``"$NAME"`` with the variable
    unset): one line naming the empty value is ok; a command that ran, or a refusal naming
    another file (``scenarios/..toml``), is a finding."""
    folder = work / "srv"
    folder.mkdir(mode=0o700, exist_ok=True)
    env = {**ENV, "TESTBED_SERVER_SOCKET": str(folder / "s.sock")}
    (work / "x.csv").write_text("time [s],x [mM],dx [mM/s]\n" + "".join(
        f"{k / 100},{math.exp(-k / 100)},{-math.exp(-k / 100)}\n" for k in range(400)))
    argvs = [["run", ""], ["generate", ""], ["sweep", ""], ["sweep", " "],
             ["family", "write", "", "-o", "f"], ["identify", "x.csv", "--scenario", ""],
             ["sweep", "h11.toml", "--dask", ""], ["serve", "--warm-up", "", "--idle", "5"]]

    def case(argv: list[str]):
        def run() -> str | None:
            (work / "h11.toml").write_text(STUDY)
            p = _testbed(argv, work, env, timeout=120)
            bad = _cli_finding(p)
            if bad:
                return bad
            last = (p.stderr.strip().splitlines() or [""])[-1]
            if p.returncode in (0, 1) or "listening" in p.stderr:  # 1: a verdict, a sweep with failures
                return f"ran (status {p.returncode}): {last[:120]!r}"
            if "..toml" in last or "empty" not in last:
                return f"refused naming another thing: {last[:160]!r}"
            return None
        return run

    return [(" ".join(repr(a) if not a.strip() else a for a in argv), case(argv)) for argv in argvs]


# ------------------------------------------------------------------ serve

def serve_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.server import server_key

    folder = work / "srv"
    folder.mkdir(mode=0o700)
    sock = folder / "s.sock"
    env = {**ENV, "TESTBED_SERVER_SOCKET": str(sock)}
    env.pop("TESTBED_NO_SERVER")
    state: dict = {}

    def start() -> str | None:
        log = open(folder / "log", "w")
        state["proc"] = subprocess.Popen([PYTHON, "-m", "testbed.cli", "serve", "--idle", "300",
                                          "--warm-up", "none"], env=env, stderr=log,
                                         stdout=subprocess.DEVNULL, start_new_session=True)
        t0 = time.monotonic()
        while not sock.exists():
            if state["proc"].poll() is not None or time.monotonic() - t0 > 120:
                return "the server did not start"
            time.sleep(0.2)
        return None

    def raw(request: dict) -> tuple[bytes, str]:
        """Send ``request`` with a file as the command's stdout and stderr; (reply, stderr)."""
        out = folder / "out.txt"
        with open(out, "w+") as fh, socket.socket(socket.AF_UNIX) as s:
            s.connect(str(sock))
            data = json.dumps(request).encode()
            fds = array.array("i", (0, fh.fileno(), fh.fileno()))
            s.sendmsg([struct.pack("!I", len(data)) + data],
                      [(socket.SOL_SOCKET, socket.SCM_RIGHTS, fds)])
            s.settimeout(60)
            reply = b""
            with contextlib.suppress(OSError):
                while chunk := s.recv(4096):
                    reply += chunk
        return reply, out.read_text(errors="replace")

    def request(**change) -> dict:
        r = {"argv": ["list", "--plain"], "cwd": str(work), "env": dict(env), "umask": 0o022,
             "key": server_key(env)}
        r.update(change)
        return r

    def applied(change: dict):
        def run() -> str | None:
            reply, err = raw(request(**change))
            if "internal error" in err:
                return f"served, and the child said {err.strip()[:160]!r}"
            if b'"refused"' not in reply and b'"status": 0' not in reply and b'"status": 2' not in reply:
                return f"reply {reply[:120]!r}"
            return None
        return run

    def client_waits(during: str):
        def run() -> str | None:
            stop = threading.Event()
            held: list[socket.socket] = []
            if during == "trickle":
                def trickle():
                    with socket.socket(socket.AF_UNIX) as s:
                        s.connect(str(sock))
                        s.sendmsg([struct.pack("!I", 100)], [(socket.SOL_SOCKET, socket.SCM_RIGHTS,
                                                               array.array("i", (0, 1, 2)))])
                        while not stop.wait(1.5):
                            try:
                                s.send(b" ")
                            except OSError:
                                return
                th = threading.Thread(target=trickle, daemon=True)
                th.start()
                time.sleep(0.5)
            else:
                for _ in range(300):
                    c = socket.socket(socket.AF_UNIX)
                    c.connect(str(sock))
                    held.append(c)
            t0 = time.monotonic()
            p = _testbed(["list", "--plain"], work, env, timeout=120)
            dt = time.monotonic() - t0
            stop.set()
            for c in held:
                c.close()
            if p.returncode != 0:
                return f"status {p.returncode}"
            return f"a real command waited {dt:.1f} s" if dt > 5.0 else None
        return run

    def stop_server() -> str | None:
        proc = state.get("proc")
        if proc is None:
            return None
        proc.terminate()
        proc.wait(30)
        return None if not sock.exists() else "the socket was left"

    cases = [("start", start)]
    for label, change in [("umask 2**40", {"umask": 2**40}), ("umask -1", {"umask": -1}),
                          ("umask true", {"umask": True}),
                          ("cwd missing", {"cwd": str(work / "gone")}),
                          ("cwd relative", {"cwd": "relative/x"}), ("cwd NUL", {"cwd": "/tmp\0x"}),
                          ("env NUL value", {"env": {**env, "X": "a\0b"}}),
                          ("env '=' in a name", {"env": {**env, "A=B": "c"}}),
                          ("env empty name", {"env": {**env, "": "c"}}),
                          ("argv NUL", {"argv": ["list", "--pl\0ain"]})]:
        cases.append((f"request {label}", applied(change)))
    cases += [("a request trickled a byte each 1.5 s", client_waits("trickle")),
              ("300 idle connections", client_waits("idle")), ("stop", stop_server)]
    return cases


# ------------------------------------------------------------------ parts and kill

#: The small study the ``parts`` and ``kill`` families sweep (two fast rigs, 8 cells).
STUDY = """[study]
name = "h11"
description = "round 11: resumed sweeps"
scenarios = ["michaelis_menten", "cartpole"]
noise = [0.0, 1.0]
seeds = [0, 1]
identifiers = ["sindy_pi_dynamical", "sindy_pi"]
"""
#: Columns that differ between two runs of one cell by design.
UNCOMPARED = {"fit_time", "data_time", "cell_time", "versions", "commit"}


def _reference(work: Path) -> Path:
    """The uninterrupted sweep of :data:`STUDY` (made once)."""
    ref = work / "ref.parquet"
    if not ref.exists():
        (work / "h11.toml").write_text(STUDY)
        p = _testbed(["sweep", "h11.toml", "--jobs", "1", "--results", "ref.parquet",
                      "--cache", "cache"], work)
        if p.returncode not in (0, 1):
            raise RuntimeError(f"the reference sweep failed: {p.stderr[-300:]}")
    return ref


def _same(a: dict, b: dict) -> list[str]:
    out = []
    for k in sorted(set(a) | set(b)):
        x, y = a.get(k), b.get(k)
        if k in UNCOMPARED or x == y or (isinstance(x, float) and isinstance(y, float)
                                         and math.isnan(x) and math.isnan(y)):
            continue
        out.append(f"{k}: {x!r} != {y!r}")
    return out


def parts_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.studies.results import read_results, write_part, write_rows

    edits = {"noise text": ("noise", "abc"), "noise NaN": ("noise", math.nan),
             "noise -1": ("noise", -1.0), "noise null": ("noise", None),
             "status bogus": ("status", "bogus"), "passed text": ("passed", "yes"),
             "passed 1": ("passed", 1), "seed text": ("seed", "x"), "seed 1.5": ("seed", 1.5),
             "seed 2**70": ("seed", 2**70), "a score text": ("coef_error", "high"),
             "a score a list": ("coef_error", [1, 2]), "identifier 3": ("identifier", 3),
             "fit_time text": ("fit_time", "slow"), "error 5": ("error", 5)}

    def case(key: str, value):
        def run() -> str | None:
            ref = read_results(_reference(work))
            name = f"p_{key}_{abs(hash(repr(value))) % 10**6}"
            res = work / f"{name}.parquet"
            write_rows(res, ref[1:], study="h11")
            row = dict(ref[0])
            row[key] = value
            write_part(res, row)
            found = []
            for argv in (["summary", res.name], ["report", res.name, "-o", f"{name}.rep"],
                         ["sweep", "h11.toml", "--jobs", "1", "--results", res.name,
                          "--cache", "cache"]):
                p = _testbed(argv, work)
                bad = _cli_finding(p)
                if bad:
                    found.append(f"{argv[0]}: {bad}")
                elif argv[0] in ("summary", "report") and p.returncode == 0 \
                        and "damaged" not in p.stderr:
                    found.append(f"{argv[0]}: made over the edited row, no word of it")
            return "; ".join(found) or None
        return run

    return [(f"row file {label}", case(*kv)) for label, kv in edits.items()]


def kill_cases(work: Path, n: int = 8, seed: int = 11) -> list[tuple[str, object]]:
    from testbed.studies.results import read_results

    rng = random.Random(seed)
    plan = [(rng.choice([signal.SIGINT, signal.SIGTERM, signal.SIGKILL]), rng.choice(["1", "2"]),
             rng.uniform(0.5, 25.0)) for _ in range(n)]

    def session(sid: int) -> list[str]:
        out = subprocess.run(["ps", "-eo", "pid=,sid=,args="], capture_output=True, text=True).stdout
        return [ln.strip() for ln in out.splitlines() if ln.split()[1] == str(sid)]

    def case(i: int, sig: signal.Signals, jobs: str, at: float):
        def run() -> str | None:
            ref = {r["cell"]: r for r in read_results(_reference(work))}
            res = f"k{i}.parquet"
            cmd = [PYTHON, "-m", "testbed.cli", "sweep", "h11.toml", "--jobs", jobs,
                   "--results", res, "--cache", "cache"]
            p = subprocess.Popen(cmd, env=ENV, cwd=work, start_new_session=True,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
            try:
                p.wait(at)
            except subprocess.TimeoutExpired:
                p.send_signal(sig)
            _, err = p.communicate()
            time.sleep(3.0)
            found = []
            left = session(p.pid)
            for ln in left:
                with contextlib.suppress(ProcessLookupError):
                    os.kill(int(ln.split()[0]), signal.SIGKILL)
            if left:
                found.append(f"{len(left)} process(es) left: {left[0][:100]}")
            if "Traceback" in err or "internal error" in err:
                found.append(f"killed run printed {err.strip().splitlines()[-1][:120]!r}")
            r = subprocess.run(cmd, env=ENV, cwd=work, capture_output=True, text=True,
                               timeout=TIMEOUT_S)
            if r.returncode not in (0, 1):
                return f"resumed: status {r.returncode} {r.stderr[-200:]!r}"
            got = {row["cell"]: row for row in read_results(work / res)}
            if set(got) != set(ref):
                found.append(f"cells lost or added: {sorted(set(got) ^ set(ref))}")
            diffs = {c: _same(ref[c], got[c]) for c in ref if c in got}
            diffs = {c: d for c, d in diffs.items() if d}
            if diffs:
                c, d = next(iter(diffs.items()))
                found.append(f"{len(diffs)} row(s) differ from the uninterrupted sweep, {c}: {d[:2]}")
            extra = [q.name for q in work.glob(f".k{i}.parquet*")] + \
                    [q.name for q in work.glob(f"k{i}.parquet.parts")]
            if extra:
                found.append(f"left {extra}")
            return "; ".join(found) or None
        return (f"sweep --jobs {jobs} {sig.name} at {at:.1f} s, resumed", run)

    return [case(i, *c) for i, c in enumerate(plan)]


# ------------------------------------------------------------------ cache

def cache_cases(work: Path) -> list[tuple[str, object]]:
    import dataclasses

    import testbed
    from testbed.pipeline.cache import DatasetCache

    def run() -> str | None:
        sc = testbed.load_scenario("cantilever_stiff_impact")
        sc = dataclasses.replace(sc, simulation={**sc.simulation, "duration": 0.1})
        cache = DatasetCache(work / "race")
        stop = threading.Event()

        def clearer():
            while not stop.is_set():
                cache.clear()

        th = threading.Thread(target=clearer)
        th.start()
        failed: Counter = Counter()
        try:
            for _ in range(15):
                try:
                    cache.clean(sc)
                except Exception as e:  # a finding: the write of a finished simulation failed
                    failed[type(e).__name__] += 1
        finally:
            stop.set()
            th.join()
        return f"{sum(failed.values())} of 15 writes failed: {dict(failed)}" if failed else None

    return [("cache clear in a loop while 15 entries are written", run)]


def run_inprocess(cases) -> Counter:
    """Each case returns a finding's description or None (a verdict, or refused in one line)."""
    return _hostile.run_inprocess(cases, TIMEOUT_S, lambda finding: finding)


FAMILIES = {
    "nyquist": lambda work: run_inprocess(nyquist_cases()),
    "twice": lambda work: run_inprocess(twice_cases()),
    "empty": lambda work: run_inprocess(empty_cases(_hostile.subfolder(work, "empty"))),
    "serve": lambda work: run_inprocess(serve_cases(_hostile.subfolder(work, "serve"))),
    "parts": lambda work: run_inprocess(parts_cases(_hostile.subfolder(work, "sweeps"))),
    "cache": lambda work: run_inprocess(cache_cases(_hostile.subfolder(work, "cache"))),
    "kill": lambda work: run_inprocess(kill_cases(_hostile.subfolder(work, "sweeps"))),
}


def main(argv: list[str]) -> int:
    os.environ.setdefault("MPLBACKEND", "Agg")
    return _hostile.main(argv, FAMILIES, "hostile11-")


if __name__ == "__main__":
    shutil.which("ps")  # (the kill family lists the sweep's session with ps)
    sys.exit(main(sys.argv[1:]))
