"""Thirteenth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile13 [family ...]      # all families when none is named

Families (where rounds 1-12 went least):

``devices``
    A device node (a copy of ``/dev/null``'s, ``mknod`` in the round's own folder: as root only)
    and a FIFO at every path a command writes (``generate -o``, ``export -o``, ``identify -o``,
    ``sweep --results``, ``family write -o``, ``report -o``), and the library's own writes
    (:func:`~testbed.core.atomic.atomic_write_text`, :func:`~testbed.studies.sweep.run_sweep`,
    the drawing process's warm-up): a node replaced, renamed or turned into a regular file is a
    finding (as root the machine's ``/dev/null`` was, by the warm-up).  The real ``/dev/null``
    is checked to be a character device after every case.
``longpaths``
    Every path argument and option of every subcommand at 5,000 characters (longer than the
    file system's 255 a component): an internal error is a finding.
``runfolder``
    A saved run's ``run.json``, ``run.npz`` and ``latest.json`` cut at 0-99 % of their length
    and with one bit flipped there, then ``testbed report`` of the run folder and of the
    scenario, and ``testbed runs ls``: an internal error or a report drawn from a damaged
    ``run.json`` is a finding.
``medians``
    Results files with infinite scores (a true coefficient of 0 missed), NaN scores beside
    finite ones, only failed cells, one row: ``testbed summary`` and ``testbed report``.  A
    median other than the quartiles of the ok cells' values with the infinities counted, or a
    median over fewer cells than ran without saying how many, is a finding.
``types``
    Every key at every depth of six shipped scenarios (the four rigs, a replayed
    five-bar, a lab beam) and three studies set to a table, a list, a string, a boolean, -1,
    1e308, 5e-324, NaN, 2**63 and blanks, and an unknown key added to every table: an
    exception other than one refusal line, a hang, or an unknown key accepted is a finding.
``concurrent``
    Two sweeps started 3 s apart on one results file, the second of the study edited (seeds
    0-11 against 0-5 and 12-19): both running, or a file holding fewer rows than the grid of
    the sweep that finished last, is a finding.

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import functools
import json
import math
import os
import shutil
import stat
import subprocess
import sys
import time
from collections import Counter
from pathlib import Path

from benchmarks import _hostile

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 300
PYTHON = sys.executable
ENV = _hostile.ENV
#: The shipped dataset cache: the cells of the `concurrent` family simulate nothing new.
CACHE = ROOT / ".cache" / "datasets"


def _testbed(argv: list[str], cwd: Path, timeout: float = TIMEOUT_S) -> subprocess.CompletedProcess:
    return _hostile.testbed_cli(argv, cwd, timeout)


_cli_finding = _hostile.cli_finding


def _dev_null_problem() -> str | None:
    """A finding if the machine's /dev/null is no longer the character device it is."""
    try:
        st = os.stat("/dev/null")
    except OSError as e:
        return f"/dev/null: {e}"
    return None if stat.S_ISCHR(st.st_mode) else "/dev/null is no longer a character device"


# ------------------------------------------------------------------ devices

#: The nodes a case writes at: a FIFO, and as root a character device like /dev/null's (1, 3).
NODES = ("fifo", "null") if os.geteuid() == 0 else ("fifo",)


def _node(work: Path, case: str, kind: str) -> Path:
    """A fresh node ``kind`` in the case's own folder (a case that replaced one leaves the next
    case's intact)."""
    d = work / case.replace(" ", "_").replace("/", "_")
    shutil.rmtree(d, ignore_errors=True)
    d.mkdir()
    node = d / kind
    if kind == "fifo":
        os.mkfifo(node)
    else:
        os.mknod(node, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    return node


def _node_problem(node: Path, kind: int) -> str | None:
    try:
        mode = os.lstat(node).st_mode
    except FileNotFoundError:
        return f"{node.name} was removed or renamed"
    if stat.S_IFMT(mode) != kind:
        return f"{node.name} was replaced by a {'regular file' if stat.S_ISREG(mode) else 'node'}"
    leftovers = [p.name for p in node.parent.iterdir()
                 if p.name.startswith((f"{node.name}.", f".{node.name}"))]
    return f"left beside {node.name}: {leftovers}" if leftovers else None


def devices_cases(work: Path) -> list[tuple[str, object]]:
    h5 = work / "mm.h5"
    csv = work / "mm.csv"
    csv.write_text("t,x,dx\n" + "".join(f"{i * 0.1},{1 + i},{0.5}\n" for i in range(40)))

    def ensure_h5() -> None:
        if not h5.exists():
            _testbed(["generate", "michaelis_menten", "-o", str(h5), "--cache", str(CACHE)], work)

    def cli(opt: str, argv_of, kind_name: str):
        def run() -> str | None:
            ensure_h5()
            node = _node(work, f"{opt} {kind_name}", kind_name)
            kind = stat.S_IFMT(os.lstat(node).st_mode)
            p = _testbed(argv_of(node), work, timeout=120)
            return _cli_finding(p) or _node_problem(node, kind) or _dev_null_problem()
        return run

    outputs = {
        "generate -o": lambda n: ["generate", "michaelis_menten", "-o", str(n), "--no-cache"],
        "export -o": lambda n: ["export", str(h5), "--format", "uff", "-o", str(n)],
        "identify -o": lambda n: ["identify", str(csv), "--kind", "dynamical", "-o", str(n)],
        "sweep --results": lambda n: ["sweep", "smoke", "--results", str(n)],
        "family write -o": lambda n: ["family", "write", "families", "-o", str(n)],
        "report -o": lambda n: ["report", "michaelis_menten", "-o", str(n)],
    }
    cases = [(f"{opt} at a {n}", cli(opt, fn, n)) for n in NODES for opt, fn in outputs.items()]

    def library(what: str, kind_name: str):
        def run() -> str | None:
            from testbed.core.atomic import atomic_write_text
            from testbed.studies.sweep import run_sweep

            node = _node(work, f"{what} {kind_name}", kind_name)
            kind = stat.S_IFMT(os.lstat(node).st_mode)
            if what == "atomic_write_text":
                atomic_write_text(node, "x")
            else:
                run_sweep("smoke", results=node, cache_dir=CACHE, verbose=False)
            return _node_problem(node, kind) or _dev_null_problem()
        return run

    cases += [(f"{w} at a {n}", library(w, n)) for n in NODES
              for w in ("atomic_write_text", "run_sweep")]

    def warm_up() -> str | None:
        from testbed.reporting import drawer, figures

        saved = []
        real = figures.save_figure
        figures.save_figure = lambda fig, path: saved.append(str(path)) or Path(path)
        try:
            drawer._warm_up()
        finally:
            figures.save_figure = real
        return f"the drawing warm-up saved a file: {saved}" if saved else _dev_null_problem()

    cases.append(("the drawing process's warm-up", warm_up))
    return cases


# ------------------------------------------------------------------ longpaths

LONG = "x" * 5000


def longpaths_cases(work: Path) -> list[tuple[str, object]]:
    argvs = [
        ["run", LONG], ["run", "michaelis_menten", "-o", LONG], ["run", "michaelis_menten", "--cache", LONG],
        ["run", "michaelis_menten", "--plugin", LONG], ["generate", LONG],
        ["generate", "michaelis_menten", "-o", LONG],
        ["identify", LONG, "--kind", "dynamical"], ["identify", "x.csv", "--scenario", LONG],
        ["identify", "x.csv", "--kind", "dynamical", "-o", LONG], ["report", LONG, "-o", "rep"],
        ["report", "michaelis_menten", "--runs", LONG, "-o", "rep"],
        ["report", "michaelis_menten", "-o", LONG],
        ["export", LONG, "--format", "uff"], ["sweep", LONG], ["sweep", "smoke", "--results", LONG],
        ["sweep", "smoke", "--cache", LONG], ["summary", LONG], ["family", "write", LONG, "-o", "f"],
        ["family", "write", "families", "-o", LONG], ["cache", "ls", "--cache", LONG],
        ["runs", "ls", "-o", LONG], ["runs", "ls", LONG], ["demo", "--out", LONG], ["list", "--plugin", LONG],
    ]
    (work / "x.csv").write_text("t,x,dx\n0,1,0.5\n0.1,1.05,0.5\n")

    def case(argv):
        def run() -> str | None:
            return _cli_finding(_testbed(argv, work, timeout=120))
        return (" ".join(a if a != LONG else "<5000 chars>" for a in argv), run)

    return [case(a) for a in argvs]


# ------------------------------------------------------------------ runfolder

def runfolder_cases(work: Path) -> list[tuple[str, object]]:
    src = work / "runs"

    def ensure_run() -> str:
        if not (src / "michaelis_menten" / "latest.json").is_file():
            _testbed(["run", "michaelis_menten", "-o", str(src), "--cache", str(CACHE), "--no-figures"],
                     work)
        return json.loads((src / "michaelis_menten" / "latest.json").read_text())["run"]

    def case(fname: str, mode: str, frac: float):
        def run() -> str | None:
            run_id = ensure_run()
            w = work / f"rf_{fname}_{mode}_{frac}"
            shutil.rmtree(w, ignore_errors=True)
            shutil.copytree(src, w)
            folder = w / "michaelis_menten"
            p = folder / fname if fname == "latest.json" else folder / run_id / fname
            b = p.read_bytes()
            k = min(int(len(b) * frac), len(b) - 1)
            p.write_bytes(b[:k] if mode == "cut" else b[:k] + bytes([b[k] ^ 0x10]) + b[k + 1:])
            found = []
            for argv in (["report", str(folder / run_id), "-o", str(w / "rep")],
                         ["report", "michaelis_menten", "--runs", str(w), "-o", str(w / "rep2")],
                         ["runs", "ls", "-o", str(w), "--plain"]):
                q = _testbed(argv, work, timeout=120)
                bad = _cli_finding(q)
                if bad:
                    found.append(f"{argv[0]}: {bad}")
                elif fname == "run.json" and argv[0] == "report" and q.returncode == 0:
                    try:
                        json.loads(p.read_text())
                    except ValueError:
                        found.append("a report drawn from a run.json that is not JSON")
            return "; ".join(found) or None
        return (f"{fname} {mode} at {frac:.0%}", run)

    return [case(f, m, x) for f in ("run.json", "run.npz", "latest.json") for m in ("cut", "flip")
            for x in (0.0, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99)]


# ------------------------------------------------------------------ medians

_row = functools.partial(_hostile.results_row, passed=False)


FAILED = {"status": "failed", "error": "IdentificationError: diverged (x.py:1)", "passed": False,
          "fit_time": math.nan, "coef_error": math.nan}


def _expected(values: list[float]) -> tuple[float, float, float, int]:
    """The quartiles the tables should show, derived here (not by the code under test): numpy's
    linear rule on the non-NaN values, an infinite neighbour with a positive weight giving
    itself (the cases hold no -inf)."""
    v = sorted(x for x in values if not math.isnan(x))

    def q(p: float) -> float:
        h = (len(v) - 1) * p
        lo, t = int(h), h - int(h)
        a, b = v[lo], v[min(lo + 1, len(v) - 1)]
        return a if t == 0 or a == b else b if math.isinf(b) else a + (b - a) * t

    return q(0.25), q(0.5), q(0.75), len(v)


def medians_cases(work: Path) -> list[tuple[str, object]]:
    grids = {
        "half the cells inf": [1.0, 2.0, math.inf, math.inf],
        "one cell inf": [1.0, 2.0, 3.0, 4.0, 5.0, math.inf],
        "every cell inf": [math.inf, math.inf],
        "one NaN beside finite ones": [1.0, 2.0, math.nan],
        "inf and NaN": [1.0, 2.0, 3.0, math.inf, math.nan],
        "one row": [0.5],
        "only failed cells": None,
    }

    def case(name: str, values):
        def run() -> str | None:
            from testbed.studies.results import write_rows

            d = work / name.replace(" ", "_")
            shutil.rmtree(d, ignore_errors=True)
            d.mkdir()
            rows = ([_row(cell=f"c{i}", seed=i, **FAILED) for i in range(3)] if values is None else
                    [_row(cell=f"c{i}", seed=i, coef_error=v) for i, v in enumerate(values)])
            write_rows(d / "r.parquet", rows, study="s")
            found = []
            for argv in (["summary", "r.parquet"], ["report", "r.parquet", "-o", "rep"]):
                p = _testbed(argv, d, timeout=120)
                bad = _cli_finding(p)
                if bad:
                    found.append(f"{argv[0]}: {bad}")
            if values is None:
                return "; ".join(found) or None
            q25, med, q75, n = _expected(values)
            out = _testbed(["summary", "r.parquet"], d).stdout
            md = (d / "rep" / "report.md").read_text() if (d / "rep" / "report.md").is_file() else ""
            want = f"{med:.3g}" if q25 == q75 else f"{med:.3g} [{q25:.3g}, {q75:.3g}]"
            if want not in md:
                found.append(f"report: median not {want!r}")
            if f"{med:.3g}" not in out:
                found.append(f"summary: median not {med:.3g}")
            if n < len(values) and f"{n} of {len(values)} cells" not in (out + md).replace("\n", " "):
                found.append(f"a median over {n} of {len(values)} cells without saying so")
            return "; ".join(found) or None
        return (name, run)

    return [case(n, v) for n, v in grids.items()]


# ------------------------------------------------------------------ concurrent

def concurrent_cases(work: Path) -> list[tuple[str, object]]:
    def run() -> str | None:
        from testbed.studies.results import read_results

        d = work / "two"
        shutil.rmtree(d, ignore_errors=True)
        (d / "b").mkdir(parents=True)
        study = ('[study]\nname = "two"\nscenarios = ["cantilever_stiff_impact"]\nnoise = [1.0]\n'
                 'identifiers = ["ls_sindy"]\nseeds = {}\n')
        (d / "two.toml").write_text(study.format([0, 1, 2, 3, 4, 5, 12, 13, 14, 15, 16, 17, 18, 19]))
        (d / "b" / "two.toml").write_text(study.format(list(range(12))))
        argv = [PYTHON, "-m", "testbed.cli", "sweep", "{}", "--results", "r.parquet", "--cache", str(CACHE)]
        first = subprocess.Popen([a.format("two.toml") for a in argv], cwd=d, env=ENV,
                                 stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        time.sleep(3)
        second = subprocess.run([a.format("b/two.toml") for a in argv], cwd=d, env=ENV,
                                capture_output=True, text=True, timeout=TIMEOUT_S)
        first.communicate(timeout=TIMEOUT_S)
        if second.returncode == 2 and "another sweep" in second.stderr:
            return _cli_finding(second)
        last = 12 if second.returncode == 0 else 14
        rows = read_results(d / "r.parquet")
        return f"both sweeps ran; the file holds {len(rows)} rows, the last sweep's grid {last}" \
            if len(rows) < last else None

    return [("two sweeps on one results file, the second of an edited study", run)]


# ------------------------------------------------------------------ types

TYPE_VALUES = [{}, {"a": 1}, [], [[]], "x", True, -1, 1e308, 5e-324, math.nan, 2**63, [{}], "", " "]
TYPE_SCENARIOS = ["michaelis_menten", "cartpole", "fivebar_multisine", "cantilever_soft_impact",
                  "fivebar_sine_replay", "cantilever_stiff_impact_lab"]
TYPE_STUDIES = ["smoke", "families", "default"]


def _key_paths(d, pre=()):
    """Every key path of a TOML table, into tables and lists."""
    for k, v in d.items():
        yield (*pre, k), v
        if isinstance(v, dict):
            yield from _key_paths(v, (*pre, k))
        elif isinstance(v, list):
            for i, x in enumerate(v):
                yield (*pre, k, i), x
                if isinstance(x, dict):
                    yield from _key_paths(x, (*pre, k, i))


def types_cases() -> list[tuple[str, object]]:
    import copy
    import tomllib

    from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml, scenario_from_dict
    from testbed.studies.study import study_from_dict

    def at(raw, path):
        for k in path:
            raw = raw[k]
        return raw

    def edited(raw, path, value):
        r = copy.deepcopy(raw)
        at(r, path[:-1])[path[-1]] = value
        return r

    def unknown(raw, path):
        r = copy.deepcopy(raw)
        at(r, path)["bogus_key"] = 1
        return r

    def case(label, load, raw, must_refuse):
        def run() -> str | None:
            from testbed.core.errors import TestbedError

            try:
                load(raw)
            except TestbedError:
                raise
            return f"an unknown key accepted: {label}" if must_refuse else None
        return (label, run)

    loads = []
    for name in TYPE_SCENARIOS:
        raw = _read_toml(SCENARIO_DIR / f"{name}.toml")
        raw["scenario"].pop("extends", None)
        loads.append((name, raw, lambda r, name=name: scenario_from_dict(r, file=f"{name}.toml", stem=name)))
    for name in TYPE_STUDIES:
        raw = tomllib.loads((ROOT / "studies" / f"{name}.toml").read_text())
        loads.append((name, raw, lambda r, name=name: study_from_dict(
            r, file=f"{name}.toml", base=ROOT / "studies", stem=name)))
    cases = []
    for name, raw, load in loads:
        for path, old in list(_key_paths(raw)):
            dotted = ".".join(map(str, path))
            if path[-1] != "name":
                cases += [case(f"{name} {dotted} = {v!r}", load, edited(raw, path, v), False)
                          for v in TYPE_VALUES]
            if isinstance(old, dict):
                cases.append(case(f"{name} [{dotted}] bogus_key = 1", load, unknown(raw, path), True))
    return cases


def run_inprocess(cases) -> Counter:
    """Each case returns a finding's description or None (a verdict, or refused in one line)."""
    return _hostile.run_inprocess(cases, TIMEOUT_S, lambda finding: finding)


FAMILIES = {
    "devices": lambda work: run_inprocess(devices_cases(_hostile.subfolder(work, "devices"))),
    "longpaths": lambda work: run_inprocess(longpaths_cases(_hostile.subfolder(work, "longpaths"))),
    "runfolder": lambda work: run_inprocess(runfolder_cases(_hostile.subfolder(work, "runfolder"))),
    "medians": lambda work: run_inprocess(medians_cases(_hostile.subfolder(work, "medians"))),
    "types": lambda work: run_inprocess(types_cases()),
    "concurrent": lambda work: run_inprocess(concurrent_cases(_hostile.subfolder(work, "concurrent"))),
}


def main(argv: list[str]) -> int:
    os.environ.setdefault("MPLBACKEND", "Agg")
    return _hostile.main(argv, FAMILIES, "hostile13-")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
