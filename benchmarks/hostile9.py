"""Ninth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case runs in-process and is a *finding* as in ``benchmarks/hostile8.py`` (the harness,
``benchmarks/_hostile.py``, runs both).  Run from the repository root::

    python -m benchmarks.hostile9 [family ...]      # all families when none is named

Families (where rounds 1-8 went least):

``hyper``
    Every hyperparameter of every registered identifier (the pysindy peers,
    ``sgd_sindy_coefficients``, ``sindy_pi_linear`` and ``pysindy_pi`` included, which no
    shipped scenario but one uses) set to a value of the wrong type (booleans, lists, tables,
    the strings "nan", "inf", "1e300", "", " 1") or to a finite extreme, in the ``[identify]``
    table of a scenario of the identifier's kind; loaded, and run on a short record when
    accepted (the wrong types and the identifiers round 8 did not run).
``study_params``
    The same values in a study's ``[identifiers.<name>]`` table (loaded).
``cli``
    Every subcommand in-process (``testbed.cli.main``): ``-h``, an unknown flag, empty
    strings, a folder, ``/dev/null`` and ``/dev/zero`` where a file goes, ``--jobs`` 0, -1,
    2**63 and text, ``--results`` in a read-only folder, ``--param`` values of the wrong type
    for ``identify``; a finding is status 3 (internal error), a traceback, a status 0 with an
    error line, or an error of more than one line.
``resume``
    ``testbed sweep`` resumed over a results file cut short, emptied, from another study,
    edited by hand (a row's scenario, identifier, noise or status), a folder, and a row part
    file damaged; a finding is an internal error or a resumed file without one row per cell.

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import contextlib
import copy
import io
import math
import os
import sys
from collections import Counter
from pathlib import Path

from benchmarks import _hostile

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 120  # a case longer than this is a hang (the slowest run below takes about 30 s)

#: The scenario each kind's identifiers are tried on, and the record it is cut to [s].
BASES = {"structural": ("cantilever_stiff_impact", 0.1), "mechanical": ("cartpole", 1.0),
         "dynamical": ("michaelis_menten", 4.0)}
#: Identifiers round 8's extremes ran (through the shipped scenarios' [identify] tables):
#: here only their wrong types are run.
RUN_BEFORE = {"ls_sindy", "sgd_sindy", "sindy_pi", "sindy_pi_dynamical"}
WRONG = [True, False, [], [1.0], [[1]], {"a": 1}, "nan", "inf", "-inf", "1e300", "", " 1",
         math.nan, math.inf, -math.inf]
FLOATS = [1e300, -1e300, 1e-300, 5e-324, -0.0, 0.0, 1e15, -1.0]
INTS = [0, -1, 2**53 + 1, 2**62, 10**9]


def _values(f) -> list:
    out = list(WRONG)
    if f.choices is not None:
        out += [c.upper() if isinstance(c, str) else c for c in f.choices]
    if f.type is float:
        out += FLOATS
    elif f.type is int:
        out += INTS
    elif f.type is list:
        out += [[1e300], [5e-324, 1e300], ["x"] * 3, list(range(200))]
    return out


def _run(raw: dict, base: str, run: bool) -> str | None:
    from testbed.pipeline.scenario import scenario_from_dict
    from testbed.scoring.run import run_scenario

    sc = scenario_from_dict(raw, file="x.toml", stem=base)
    if not run:
        return None
    return _hostile.scored_finding(run_scenario(sc))


def _raw(kind: str) -> tuple[str, dict]:
    return _hostile.base_scenario(BASES, kind)


def hyper_cases() -> list[tuple[str, object]]:
    from testbed.pipeline.plugins import IDENTIFIERS

    cases = []
    only = os.environ.get("HOSTILE9_IDENTIFIERS", "")  # comma-separated, to rerun a few
    for m in IDENTIFIERS.names():
        if only and m not in only.split(","):
            continue
        cls = IDENTIFIERS.get(m)
        base, raw0 = _raw(cls.kind)
        for key, f in cls.hyperparameters.items():
            for value in _values(f):
                raw = copy.deepcopy(raw0)
                raw["identify"] = {"method": m, key: value}
                run = m not in RUN_BEFORE or value in WRONG
                cases.append((f"{m}: identify.{key} = {value!r}"[:160],
                              lambda raw=raw, base=base, run=run: _run(raw, base, run)))
    return cases


def study_param_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.plugins import IDENTIFIERS
    from testbed.studies.study import study_from_dict

    cases = []
    for m in IDENTIFIERS.names():
        cls = IDENTIFIERS.get(m)
        base, _ = _raw(cls.kind)
        for key, f in cls.hyperparameters.items():
            for value in _values(f):
                raw = {"study": {"name": "s", "scenarios": [base], "noise": [0.0], "seeds": [0],
                                 "identifiers": [m]},
                       "identifiers": {m: {key: value}}}
                cases.append((f"study [identifiers.{m}] {key} = {value!r}"[:160],
                              lambda raw=raw: study_from_dict(raw, file="s.toml", base=work)
                              and None))
    return cases


# ------------------------------------------------------------------ the command line

def _cli(argv: list[str]) -> str | None:
    """A finding of the command ``testbed <argv>`` run in-process, or None."""
    return _cli_status(argv)[0]


def _cli_status(argv: list[str]) -> tuple[str | None, int]:
    """A finding of the command ``testbed <argv>`` run in-process, or None; and its status."""
    from testbed.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = main(argv)
        except SystemExit as e:  # argparse's own refusal or -h
            status = e.code if isinstance(e.code, int) else 2
    text = err.getvalue()
    errors = [x for x in text.splitlines() if x.strip()]
    if status == 3 or "internal error" in text:
        return f"internal error (status {status}): {text.strip()[:200]}", status
    if "Traceback" in text:
        return f"traceback: {text.strip()[-200:]}", status
    if status == 0 and any(x.startswith("error") for x in errors):
        return f"status 0 with an error: {text.strip()[:200]}", status
    if status == 2 and len(errors) != 1 and not argv[-1:] == ["-h"]:
        # argparse prints its usage line(s) before its error line: one error line is asked of
        # the testbed's own refusals, the usage is argparse's
        if not any(x.startswith("usage:") for x in errors):
            return f"{len(errors)} lines: {text.strip()[:200]!r}", status
    return None, status


def cli_cases(work: Path) -> list[tuple[str, object]]:
    ro = work / "readonly"
    ro.mkdir(exist_ok=True)
    ro.chmod(0o555)
    d = work / "adir"
    d.mkdir(exist_ok=True)
    mm = str(ROOT / "scenarios" / "michaelis_menten.toml")
    study = work / "tiny.toml"
    study.write_text('[study]\nname = "tiny"\nscenarios = ["michaelis_menten"]\nnoise = [0.0]\n'
                     'seeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')
    csv = work / "mm.csv"
    csv.write_text("t,x,u\n" + "".join(f"{k / 100},{math.exp(-k / 100)},0\n" for k in range(400)))
    paths = ["", " ", str(d), "/dev/null", "/dev/zero", str(work / "missing.toml"), "-", "\x7f",
             "é" * 300]
    argvs: list[list[str]] = []
    for sub in ("list", "generate", "run", "identify", "report", "export", "sweep", "summary",
                "family", "cache", "runs", "demo", "serve"):
        argvs += [[sub, "-h"], [sub, "--bogus"], [sub, "--bogus=1"], [sub, ""]]
    argvs += [["generate", p] for p in paths] + [["run", p] for p in paths]
    argvs += [["sweep", p] for p in paths] + [["summary", p] for p in paths]
    argvs += [["report", p] for p in paths] + [["export", p] for p in paths]
    argvs += [["family", p, "--out", str(work / "fam")] for p in paths]
    argvs += [["sweep", str(study), "--jobs", j] for j in ("0", "-1", str(2**63), "x", "", "1.5")]
    argvs += [["sweep", str(study), "--results", r] for r in (
        str(ro / "r.parquet"), str(d), "/dev/null", str(work / "r.csv"), str(ro))]
    argvs += [["run", mm, "--out", o, "--no-figures"] for o in (str(ro), "/dev/null", str(csv))]
    argvs += [["run", mm, "--cache", c, "--no-figures"] for c in ("/dev/null", str(csv))]
    argvs += [["cache", a] for a in ("ls", "clear", "bogus", "")]
    argvs += [["cache", "ls", "--cache", c] for c in ("/dev/null", str(csv), str(ro))]
    argvs += [["runs", "--out", o] for o in ("/dev/null", str(csv), str(d))]
    for kv in ("ridge=true", "ridge=[1]", "ridge=nan", "ridge=inf", "ridge=", "ridge",
               "=1", "degree=1.5", "degree=1e300", "degree=2**62", "library=x", "lhs=[]",
               "thresholds=[-1]", "max_iter=-1", "sim_dt=0", "formulation=WEAK",
               "weak_windows=true", "refit=1", "refit=yes", "method=ls_sindy", "é=1",
               "ridge=1e-400", "ridge=0x10", "ridge=1_0"):
        argvs.append(["identify", str(csv), "--kind", "dynamical", "--method",
                      "sindy_pi_dynamical", "--param", kv])
    for m in ("", "ls_sindy", "LS_SINDY", "nope"):
        argvs.append(["identify", str(csv), "--kind", "dynamical", "--method", m])
    for k in ("", "nope", "structural", "mechanical"):
        argvs.append(["identify", str(csv), "--kind", k, "--method", "sindy_pi_dynamical"])
    return [(f"testbed {' '.join(repr(a) if not a or ' ' in a else a for a in argv)}"[:160],
             lambda argv=argv: _cli(argv)) for argv in argvs]


# ------------------------------------------------------------------ resumed sweeps

def _resume(study_path: Path, results: Path, edit) -> str | None:
    import shutil

    from testbed.studies.results import read_results
    from testbed.studies.study import load_study
    from testbed.studies.sweep import expand

    clean = study_path.with_suffix(".clean.parquet")
    if not clean.exists():
        if _cli(["sweep", str(study_path), "--jobs", "1", "--results", str(clean)]) is not None:
            return "the clean sweep did not end in its verdict"
    if results.is_dir():
        shutil.rmtree(results)
    elif results.exists():
        results.unlink()
    shutil.copyfile(clean, results)
    edit(results)
    finding, status = _cli_status(["sweep", str(study_path), "--jobs", "1", "--results",
                                   str(results)])
    if finding is not None:
        return finding
    if status == 2 or not results.is_file():
        return None  # refused in one line
    rows = read_results(results)
    if any(r["study"] != load_study(study_path).name for r in rows):
        return None  # refused in one line, another study's file left as it was
    grid = {c.key: c for c in expand(load_study(study_path))}
    cells = set(grid)
    keys = [r["cell"] for r in rows]
    for r in rows:  # a row must describe the cell it is kept for
        c = grid.get(r["cell"])
        if c is not None and (r["scenario"], r["identifier"], r["noise"], r["seed"]) != (
                c.scenario.name, c.identifier, c.noise, c.seed):
            return f"row of cell {r['cell']} kept as {r['scenario']!r}, {r['identifier']!r}"
    if len(keys) != len(set(keys)):
        return f"a cell twice after the resume: {sorted(keys)}"
    if set(keys) != cells:
        return f"cells after the resume {sorted(keys)} are not the study's {sorted(cells)}"
    return None


def resume_cases(work: Path) -> list[tuple[str, object]]:
    import pyarrow.parquet as pq

    study = work / "tiny2.toml"
    study.write_text('[study]\nname = "tiny2"\nscenarios = ["michaelis_menten"]\n'
                     'noise = [0.0, 1.0]\nseeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')
    other = work / "other.toml"
    other.write_text('[study]\nname = "other"\nscenarios = ["michaelis_menten"]\n'
                     'noise = [0.0]\nseeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')
    results = work / "resume.parquet"

    def cut(frac):
        def edit(p: Path):
            data = p.read_bytes()
            p.write_bytes(data[: int(len(data) * frac)])
        return edit

    def column(name, value, row=0):
        def edit(p: Path):
            t = pq.read_table(p)
            rows = t.to_pylist()
            rows[row][name] = value
            import pyarrow as pa
            pq.write_table(pa.Table.from_pylist(rows, schema=t.schema), p)
        return edit

    def dup(p: Path):
        import pyarrow as pa
        t = pq.read_table(p)
        pq.write_table(pa.concat_tables([t, t]), p)

    def drop_row(p: Path):
        t = pq.read_table(p)
        pq.write_table(t.slice(0, 1), p)

    def no_metadata(p: Path):
        t = pq.read_table(p)
        pq.write_table(t.replace_schema_metadata(None), p)

    def from_other(p: Path):
        r = _cli(["sweep", str(other), "--jobs", "1", "--results", str(p.with_suffix(".o.parquet"))])
        if r is None:
            os.replace(p.with_suffix(".o.parquet"), p)

    def to_dir(p: Path):
        p.unlink()
        p.mkdir()

    def part(text):
        def edit(p: Path):
            parts = p.with_name(p.name + ".parts")
            parts.mkdir(exist_ok=True)
            (parts / "x.json").write_text(text)
        return edit

    edits = {"cut 10 %": cut(0.1), "cut 50 %": cut(0.5), "cut 99 %": cut(0.99), "empty": cut(0.0),
             "scenario renamed": column("scenario", "ghost"), "identifier unknown":
             column("identifier", "nope"), "noise 7": column("noise", 7.0), "noise NaN":
             column("noise", math.nan), "status weird": column("status", "weird"),
             "status failed": column("status", "failed"), "cell renamed": column("cell", "zz"),
             "study renamed": column("study", "other"), "a row twice": dup, "a row dropped":
             drop_row, "no metadata": no_metadata, "another study's file": from_other,
             "a folder": to_dir, "a part of junk": part("{"), "a part of another cell":
             part('{"cell": "zz", "study": "tiny2"}'), "a part that is a list": part("[]")}
    return [(f"sweep resumed over {name}", lambda e=e: _resume(study, results, e))
            for name, e in edits.items()]


def run_inprocess(cases) -> Counter:
    """Each case returns a finding's description or None (a verdict, or refused in one line)."""
    return _hostile.run_inprocess(cases, TIMEOUT_S, lambda finding: finding)


def main(argv: list[str]) -> int:
    os.environ.setdefault("MPLBACKEND", "Agg")
    return _hostile.main(argv, {
        "hyper": lambda work: run_inprocess(hyper_cases()),
        "study_params": lambda work: run_inprocess(study_param_cases(work)),
        "cli": lambda work: run_inprocess(cli_cases(work)),
        "resume": lambda work: run_inprocess(resume_cases(work)),
    }, "hostile9-")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
