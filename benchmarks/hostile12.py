"""Twelfth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile12 [family ...]      # all families when none is named

Families (where rounds 1-11 went least):

``results``
    A results file written with :func:`testbed.studies.results.write_rows` and edited: a row
    copied under another cell key (in the Parquet file or as a row file), rows of two
    studies, the file's study other than its rows', rows of two commits or versions, no rows,
    only the row files of a sweep killed before its first consolidation; then ``testbed
    summary`` and ``testbed report``.  A summary or report counting more cells than the grid
    has (one per scenario, noise, seed and identifier) or merging two studies' rows, a refusal
    of rows that exist, or an internal error is a finding.
``study``
    A study's keys at their edges: noise levels as text, NaN, inf, -0.0, subnormal, beyond
    100; seeds negative, beyond int64, repeated, as floats; bars inverted, impossible, NaN;
    families of 0, 1, -1 members; a scenario twice by name and path.  Accepted, a noise level
    whose cells hash to other data than the same level written plainly (-0.0 against 0.0) is
    a finding; so is a bar no score can pass.
``negzero``
    Every float of the ``[rig]``, ``[simulation]``, ``[excitation]``, ``[noise]`` and
    ``[signal]`` tables of four shipped scenarios set to -0.0 where 0.0 loads: a scenario whose
    data hash differs from the one with 0.0 is a finding (the same record cached twice).
``family``
    ``testbed family write`` into a folder holding a larger draw of the same family, into a
    file, under a file, into ``/proc`` and ``/dev/null``, twice into one folder: stale member
    files left beside the new draw in silence are a finding.
``channels``
    ``testbed identify`` on CSV records (Michaelis-Menten, dynamical) with a channel beside
    ``x`` and ``dx`` (an exact copy, all zeros, integers, another state), channels all zero or
    constant, one or two samples, repeated or jittered time stamps, ``--fs`` disagreeing with
    the time column: a model fitted while a channel of the file was left out in silence is a
    finding; and a beam record (SEP-005) with a fourth sensor whose column is a copy, a double
    or a sum of the others: identified is a finding.
``plugins``
    A plugin registering an identifier or a rig under a name no scenario or file can spell
    (an int, empty, blank, with a space, a slash, ``../`` or a newline, 129 characters) or a
    built-in's name, then `testbed list --plugin`: registered, or an internal error, is a
    finding.
``env``
    `run` and `sweep` under ``TESTBED_CACHE``, ``TESTBED_SCENARIOS``, ``TESTBED_STUDIES``,
    ``TESTBED_NO_SERVER``, ``TESTBED_SERVER_SOCKET`` and ``HOME`` malformed (``/proc/x``,
    ``/dev/null``, empty, blank, 5,000 characters): an internal error, an errno line naming no
    option or variable, or a sweep whose every cell fails for the setting is a finding.
``full``
    Every writing command (`run`, `generate`, `sweep`, `family write`, `report`, `identify
    -o`, `export`) with its output on a 200 kB tmpfs filled to its last 8 kB (skipped where
    ``mount`` is refused): an internal error, a traceback, or a file of 0 bytes or a
    temporary file left is a finding.

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import copy
import json
import math
import os
import shutil
import subprocess
import sys
from collections import Counter
from pathlib import Path

from benchmarks import _hostile

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 300
PYTHON = sys.executable
ENV = _hostile.ENV


def _testbed(argv: list[str], cwd: Path, timeout: float = TIMEOUT_S) -> subprocess.CompletedProcess:
    return _hostile.testbed_cli(argv, cwd, timeout)


_cli_finding = _hostile.cli_finding


# ------------------------------------------------------------------ results

_row = _hostile.results_row


def _grid() -> list[dict]:
    return [_row(cell=f"c{i}", noise=n, seed=s, coef_error=0.01 * (i + 1))
            for i, (n, s) in enumerate([(0.0, 0), (0.0, 1), (1.0, 0), (1.0, 1)])]


def results_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.studies.results import parts_dir, write_part, write_rows

    def copied(rows):
        return [*rows, {**rows[0], "cell": "c9"}]

    # name -> (edit of the rows, a row file to add, the grid's cells: None for two studies'
    # rows, which only a refusal ends well; a copied row may also be refused)
    edits = {
        "a row copied under another cell key": (copied, None, 4),
        "a row copied into a row file": (None, lambda rows: {**rows[0], "cell": "c9"}, 4),
        "rows of two studies": (lambda rows: [{**r, "study": "s" if i % 2 else "t"}
                                              for i, r in enumerate(rows)], None, None),
        "a row of another study in a row file": (None, lambda rows: {**rows[0], "cell": "c9",
                                                                     "study": "t"}, None),
        "the file's study other than its rows'": ("meta", None, None),
        "rows of two commits": (lambda rows: [{**r, "commit": "a" if i % 2 else "b"}
                                              for i, r in enumerate(rows)], None, 4),
        "rows of two versions": (lambda rows: [{**r, "versions": json.dumps({"numpy": f"1.{i}"})}
                                               for i, r in enumerate(rows)], None, 4),
        "no rows": (lambda rows: [], None, 0),
        "only the row files of a killed sweep": ("parts", None, 4),
    }

    def case(name: str, rows_edit, part_edit, cells: int | None):
        def run() -> str | None:
            d = work / f"r{abs(hash(name)) % 10**8}"
            shutil.rmtree(d, ignore_errors=True)
            d.mkdir()
            res = d / "r.parquet"
            rows = _grid()
            if rows_edit == "parts":
                for r in rows:
                    write_part(res, r)
            elif rows_edit == "meta":
                write_rows(res, rows, study="other")
            else:
                write_rows(res, rows_edit(rows) if rows_edit else rows, study="s")
            if part_edit:
                write_part(res, part_edit(rows))
            found = []
            for argv in (["summary", "r.parquet"], ["report", "r.parquet", "-o", "rep"]):
                p = _testbed(argv, d, timeout=120)
                bad = _cli_finding(p)
                if bad:
                    found.append(f"{argv[0]}: {bad}")
                elif p.returncode == 0 and cells is None:
                    found.append(f"{argv[0]} made over rows of two studies")
                elif p.returncode == 0 and argv[0] == "summary" and cells and \
                        f": {cells} cells from" not in p.stdout.replace("\n", " "):
                    head = p.stdout.splitlines()[0] if p.stdout else ""
                    found.append(f"summary of {cells} cells said {head[:80]!r}")
                elif (p.returncode == 0 and argv[0] == "summary"
                      and name.startswith(("rows of two commits", "rows of two versions"))
                      and "versions of the code" not in p.stdout.replace("\n", " ")):
                    found.append("summary pooled two versions of the code in silence")
                elif p.returncode != 0 and cells is not None and not name.startswith("a row copied"):
                    found.append(f"{argv[0]} refused a file of one grid: {p.stderr.strip()[-160:]!r}")
            assert parts_dir(res) is not None
            return "; ".join(found) or None
        return (name, run)

    return [case(n, *e) for n, e in edits.items()]


# ------------------------------------------------------------------ study

STUDY = {"study": {"name": "h12", "scenarios": ["michaelis_menten", "cartpole"], "noise": [0.0, 1.0],
                   "seeds": [0], "identifiers": ["sindy_pi_dynamical", "sindy_pi"]}}


def study_cases() -> list[tuple[str, object]]:
    from testbed.studies.study import study_from_dict

    edits = []
    for v in ["1", math.nan, math.inf, -math.inf, -0.0, 5e-324, 1e-320, 100.0000001, True, [1.0],
              2**70, 100, 0]:
        edits.append((f"study.noise = [{v!r}]", lambda r, v=v: r["study"].__setitem__("noise", [v])))
    for v in ([-1], [2**63], [2**63 - 1], [2**64], [0, 0], [True], [1.0], [0, -0.0], [0, 1, 0]):
        edits.append((f"study.seeds = {v!r}", lambda r, v=v: r["study"].__setitem__("seeds", v)))
    for v in ([0.0, -0.0], [1, 1.0], [0.0, 5e-324]):
        edits.append((f"study.noise = {v!r}", lambda r, v=v: r["study"].__setitem__("noise", v)))
    for bar in [{"coef_error_max": -1.0}, {"support_f1_min": 2.0}, {"support_f1_min": math.nan},
                {"coef_error_max": math.inf}, {"coef_error_max": 0.0}, {"angle_rmse_max": -0.0},
                {"support_f1_min": -1.0}, {"support_f1_min": 0.5, "support_f1_max": 0.4},
                {"coef_error_max": 5e-324}, {"support_f1_max": -0.0}, {"trac_min": 0.9},
                {"coef_error_max": "0.1"}, {"coef_error": 0.1}]:
        edits.append((f"thresholds.sindy_pi = {bar}",
                      lambda r, bar=bar: r.__setitem__("thresholds", {"sindy_pi": bar})))
    for m in [0, 1, -1, 1.5, True, "3", 10001]:
        edits.append((f"families.f.members = {m!r}", lambda r, m=m: r.__setitem__(
            "families", {"f": {"base": "cartpole", "members": m}})))
    edits.append(("a scenario by name and by path", lambda r: r["study"].__setitem__(
        "scenarios", ["michaelis_menten", "cartpole", str(ROOT / "scenarios" / "cartpole.toml")])))

    def case(name, edit):
        def run() -> str | None:
            raw = copy.deepcopy(STUDY)
            edit(raw)
            st = study_from_dict(raw, stem="h12")
            if any(math.copysign(1.0, n) < 0 for n in st.noise):
                return f"accepted a noise level of -0.0 ({st.noise}): other cells than 0.0's"
            for sc, _m in st.combinations():
                for metric, bar in sc.score.items():
                    for bound, v in bar.items():
                        if v < 0 and bound == "max":  # every score here is >= 0
                            return f"accepted {metric} {bound} {v!r}: no score can pass"
            return None
        return (name, run)

    return [case(n, e) for n, e in edits]


# ------------------------------------------------------------------ negzero

def negzero_cases() -> list[tuple[str, object]]:
    from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml, scenario_from_dict

    cases = []
    for base in ("michaelis_menten", "cartpole", "fivebar_multisine", "cantilever_stiff_impact"):
        raw = _read_toml(SCENARIO_DIR / f"{base}.toml")
        raw["scenario"].pop("extends", None)
        raw.pop("score", None)
        for sec in ("rig", "simulation", "excitation", "noise", "signal"):
            for key, v in raw.get(sec, {}).items():
                if not isinstance(v, float):
                    continue

                def run(raw=raw, sec=sec, key=key) -> str | None:
                    a, b = copy.deepcopy(raw), copy.deepcopy(raw)
                    a[sec][key], b[sec][key] = 0.0, -0.0
                    try:
                        sa = scenario_from_dict(a)
                    except Exception:
                        return None  # 0.0 refused: -0.0 is judged against it below
                    sb = scenario_from_dict(b)
                    if sa.data_hash() != sb.data_hash() or sa.signal != sb.signal:
                        return "-0.0 hashes to other data than 0.0"
                    return None
                cases.append((f"{base} {sec}.{key} = -0.0", run))
    return cases


# ------------------------------------------------------------------ family

FAMILY = """[study]
name = "fam"
scenarios = []
noise = [0.0]
seeds = [0]
identifiers = ["sindy_pi"]
[families.cp]
base = "cartpole"
members = {members}
[families.cp.rig]
pole_length = {{uniform = [0.4, 0.6]}}
"""


def family_cases(work: Path) -> list[tuple[str, object]]:
    def case(name: str, first: int | None, second: int, out: str):
        def run() -> str | None:
            d = work / f"f{abs(hash(name)) % 10**8}"
            shutil.rmtree(d, ignore_errors=True)
            (d / "a").mkdir(parents=True)
            (d / "b").mkdir()
            (d / "a" / "fam.toml").write_text(FAMILY.format(members=first or 1))
            (d / "b" / "fam.toml").write_text(FAMILY.format(members=second))
            (d / "afile").write_text("x")
            if first:
                p = _testbed(["family", "write", "a/fam.toml", "-o", out], d, timeout=120)
                if p.returncode:
                    return f"first write refused: {p.stderr.strip()[-120:]!r}"
            p = _testbed(["family", "write", "b/fam.toml", "-o", out], d, timeout=120)
            bad = _cli_finding(p)
            if bad:
                return bad
            target = d / out if not out.startswith("/") else Path(out)
            if p.returncode == 0 and target.is_dir():
                members = sorted(f.name for f in target.glob("cp__*.toml"))
                if len(members) != second:
                    return f"wrote {second} members; the folder holds {len(members)}: {members[:6]}"
            return None
        return (name, run)

    return [case("10 members, then 2, into one folder", 10, 2, "out"),
            case("2 members, then 2 again", 2, 2, "out"),
            case("2 members, then 10", 2, 10, "out"),
            case("into a file", None, 2, "afile"),
            case("under a file", None, 2, "afile/x"),
            case("into /proc", None, 2, "/proc/x"),
            case("into /dev/null", None, 2, "/dev/null")]


# ------------------------------------------------------------------ channels

def _csv(path: Path, header: list[str], rows: list[tuple]) -> None:
    path.write_text(",".join(header) + "\n" + "".join(",".join(repr(v) if isinstance(v, float) else str(v)
                                                               for v in r) + "\n" for r in rows))


def channels_cases(work: Path) -> list[tuple[str, object]]:
    n = 400
    t = [k / 100 for k in range(n)]
    x = [math.exp(-k / 100) for k in range(n)]
    base = ["time [s]", "x [mM]", "dx [mM/s]"]
    files = {
        "a copy of x beside x and dx": ([*base, "y [mM]"], [(t[k], x[k], -x[k], x[k]) for k in range(n)]),
        "a zero channel beside x and dx": ([*base, "y [mM]"], [(t[k], x[k], -x[k], 0.0) for k in range(n)]),
        "an integer channel beside x and dx": ([*base, "y [mM]"], [(t[k], x[k], -x[k], int(1000 * x[k]))
                                                                   for k in range(n)]),
        "a second signal 'z' beside x and dx": ([*base, "z [mM]"], [(t[k], x[k], -x[k], x[k] ** 2)
                                                                    for k in range(n)]),
        "x and dx only": (base, [(t[k], x[k], -x[k]) for k in range(n)]),
        "x, dx all zero": (base, [(t[k], 0.0, 0.0) for k in range(n)]),
        "x constant": (base, [(t[k], 1.0, 0.0) for k in range(n)]),
        "x of integers": (base, [(t[k], int(1000 * x[k]), -int(1000 * x[k])) for k in range(n)]),
        "one sample": (base, [(0.0, 1.0, -1.0)]),
        "two samples": (base, [(0.0, 1.0, -1.0), (0.01, 0.99, -0.99)]),
        "repeated time stamps": (base, [(t[k] // 0.02 * 0.02, x[k], -x[k]) for k in range(n)]),
        "time stamps reversed": (base, [(t[n - 1 - k], x[k], -x[k]) for k in range(n)]),
        "jittered time stamps": (base, [(t[k] + (1e-4 if k % 2 else 0), x[k], -x[k]) for k in range(n)]),
        "a channel cut short": (base, [(t[k], x[k], -x[k]) if k < 200 else (t[k], x[k], "")
                                       for k in range(n)]),
    }
    cases = []
    for name, (header, rows) in files.items():
        for extra in ([], ["--fs", "50"], ["--fs", "100"]):
            def run(name=name, header=header, rows=rows, extra=extra) -> str | None:
                d = work / "ch"
                d.mkdir(exist_ok=True)
                f = d / f"c{abs(hash(name)) % 10**8}.csv"
                _csv(f, header, rows)
                out = f.with_suffix(".json")
                out.unlink(missing_ok=True)
                p = _testbed(["identify", f.name, "--scenario", "michaelis_menten", *extra, "-o",
                              out.name], d, timeout=200)
                bad = _cli_finding(p)
                if bad:
                    return bad
                if p.returncode == 0:
                    model = json.loads(out.read_text())
                    channels = set(model.get("channels") or [])
                    given = {h.split(" [")[0] for h in header} - {"time", "dx"}
                    if channels and given - channels:
                        return f"fitted on {sorted(channels)}; left out {sorted(given - channels)}"
                return None
            cases.append((f"{name} {' '.join(extra)}".strip(), run))
    # a beam (structural) record with a fourth sensor whose column is another's pasted, doubled
    # or the sum of two: accepted (a model of four modes, one of them an artefact) is a finding
    for how in ("none", "copy", "double", "sum"):
        def beam(how=how) -> str | None:
            d = work / "ch"
            d.mkdir(exist_ok=True)
            f = d / f"beam_{how}.json"
            _beam_sep005(f, how)
            p = _testbed(["identify", f.name, "--kind", "structural", "--method", "ls_sindy",
                          "--prior", "reduced_mass_trace=0.5", "-o", f"{f.stem}.model.json"], d,
                         timeout=200)
            bad = _cli_finding(p)
            if bad:
                return bad
            if how != "none" and p.returncode in (0, 1):
                return f"identified a record whose acc4 is {how} of others (status {p.returncode})"
            return None
        cases.append((f"beam: acc4 a {how} of other channels", beam))
    return cases


def _beam_sep005(path: Path, how: str) -> None:
    """A three-sensor beam record (decaying sines, 2 kHz, 1 s) as SEP-005, with a fourth sensor
    at 0.4 m whose column is ``how`` of the others ("none": no fourth)."""
    import numpy as np

    fs, n = 2000.0, 2000
    t = np.arange(n) / fs
    acc = [np.exp(-2 * t) * (np.sin(2 * np.pi * (30 + 40 * k) * t) + 0.3 * np.sin(2 * np.pi * 170 * t))
           for k in range(3)]
    extra = {"copy": acc[0], "double": 2 * acc[0], "sum": acc[0] + acc[1]}.get(how)
    pos = [0.1, 0.2, 0.3]
    if extra is not None:
        acc.append(extra)
        pos.append(0.4)
    force = np.zeros(n)
    force[:10] = 50.0
    chans = [{"name": f"acceleration/acc{i + 1}", "data": a.tolist(), "unit_str": "m/s^2", "fs": fs,
              "position_m": p} for i, (a, p) in enumerate(zip(acc, pos, strict=True))]
    chans.append({"name": "force/force", "data": force.tolist(), "unit_str": "N", "fs": fs,
                  "position_m": 0.3})
    path.write_text(json.dumps(chans))


# ------------------------------------------------------------------ plugins

def plugins_cases(work: Path) -> list[tuple[str, object]]:
    """A plugin file registering an identifier or a rig under a name no scenario or file can
    spell (an int, empty, blank, a space, a slash, ``../``, a newline, a leading dot or dash,
    129 characters) or under a built-in's name, then `testbed list --plugin`: an internal
    error, or the name listed, is a finding."""
    names = [5, "", " ", "a b", "a/b", "../up", "x\ny", ".hidden", "-x", "a" * 129, "ok_name.v2-x"]
    cases = []
    for reg, base, builtin in (
            ("IDENTIFIERS", "from identify.ls_sindy import LeastSquaresSINDy as B", "ls_sindy"),
            ("RIGS", "from models.michaelis_menten.rig import MichaelisMentenRig as B", "cantilever")):
        for name in [*names, builtin]:
            def run(reg=reg, base=base, name=name) -> str | None:
                f = work / f"p{abs(hash((reg, repr(name)))) % 10**8}.py"
                pkg = "identify" if reg == "IDENTIFIERS" else "models"
                f.write_text(f"from {pkg} import {reg}\n{base}\n\n@{reg}.register({name!r})\n"
                             "class Mine(B):\n    pass\n")
                p = _testbed(["list", "--plugin", f.name], work, timeout=120)
                bad = _cli_finding(p)
                if bad:
                    return bad
                if p.returncode == 0 and name != "ok_name.v2-x":
                    return f"registered and listed: {name!r:.40}"
                if p.returncode != 0 and name == "ok_name.v2-x":
                    return f"a good name refused: {p.stderr.strip()[-120:]!r}"
                return None
            cases.append((f"{reg}.register({name!r:.40})", run))
    return cases


# ------------------------------------------------------------------ env

def env_cases(work: Path) -> list[tuple[str, object]]:
    """`run` and `sweep` under ``TESTBED_*`` variables malformed and cache folders where nothing
    can be created: an internal error, an errno line naming no option or variable, or a sweep
    whose cells all fail for the user's setting (rows to rerun by hand) is a finding."""
    (work / "h12.toml").write_text("[study]\nname = \"h12\"\nscenarios = [\"michaelis_menten\"]\n"
                                   "noise = [0.0]\nseeds = [0]\nidentifiers = [\"sindy_pi_dynamical\"]\n")
    settings = [{"TESTBED_CACHE": v} for v in ("/proc/x", "/proc/x/y", "/sys/x", "/dev/null", "/dev/null/x",
                                               "", " ", "\x7f", "a" * 5000)]
    settings += [{"TESTBED_SCENARIOS": v} for v in ("/nonexistent", "/dev/null", "", "/proc")]
    settings += [{"TESTBED_STUDIES": v} for v in ("/nonexistent", "/dev/null", "")]
    settings += [{"TESTBED_NO_SERVER": v} for v in ("0", "no", "")]
    settings += [{"TESTBED_SERVER_SOCKET": v} for v in ("rel.sock", "/proc/s.sock", "")]
    settings += [{"TESTBED_CACHE": "/proc/x", "HOME": "/proc/x"}, {"HOME": "/dev/null"}, {"HOME": ""}]
    argvs = [["run", "michaelis_menten", "--out", "o"],
             ["sweep", "h12.toml", "--jobs", "1", "--results", "r.parquet"]]

    def case(env: dict, argv: list[str]):
        def run() -> str | None:
            shutil.rmtree(work / "r.parquet.parts", ignore_errors=True)
            (work / "r.parquet").unlink(missing_ok=True)
            p = subprocess.run([PYTHON, "-m", "testbed.cli", *argv], cwd=work, env={**ENV, **env},
                               capture_output=True, text=True, timeout=TIMEOUT_S)
            bad = _cli_finding(p)
            if bad:
                return bad
            last = (p.stderr.strip().splitlines() or [""])[-1]
            if p.returncode == 2 and last.startswith("error: [Errno"):
                return f"an errno line naming no option or variable: {last[:120]!r}"
            if argv[0] == "sweep" and p.returncode == 1 and "failed" in p.stderr:
                return f"every cell failed: {last[:120]!r}"
            return None
        return run

    return [(f"{' '.join(f'{k}={v[:20]!r}' for k, v in env.items())} {a[0]}", case(env, a))
            for env in settings for a in argvs]


# ------------------------------------------------------------------ full

def full_cases(work: Path) -> list[tuple[str, object]]:
    mnt = work / "full"
    mnt.mkdir(exist_ok=True)
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=200k", "tmpfs", str(mnt)],
                       capture_output=True, text=True)
    if r.returncode:
        print(f"  (full: mount refused, skipped: {r.stderr.strip()[:80]})", file=sys.stderr)
        return []
    from testbed.studies.results import write_rows

    (work / "fam.toml").write_text(FAMILY.format(members=2))
    (work / "h12.toml").write_text("[study]\nname = \"h12\"\nscenarios = [\"michaelis_menten\"]\n"
                                   "noise = [0.0]\nseeds = [0]\nidentifiers = [\"sindy_pi_dynamical\"]\n")
    write_rows(work / "r.parquet", _grid(), study="s")
    n = 400
    _csv(work / "d.csv", ["time [s]", "x [mM]", "dx [mM/s]"],
         [(k / 100, math.exp(-k / 100), -math.exp(-k / 100)) for k in range(n)])
    cache = work / "cache"
    gen = _testbed(["generate", "michaelis_menten", "--cache", str(cache)], work)
    h5 = next(cache.glob("*.h5"), None) if gen.returncode == 0 else None
    argvs = [["run", "michaelis_menten", "--cache", "full/c", "--out", "full/o"],
             ["run", "michaelis_menten", "--cache", str(cache), "--out", "full/o"],
             ["generate", "michaelis_menten", "--cache", "full/c"],
             ["sweep", "h12.toml", "--jobs", "1", "--results", "full/r.parquet", "--cache", str(cache)],
             ["family", "write", "fam.toml", "-o", "full/fam"],
             ["report", "r.parquet", "-o", "full/rep"],
             ["identify", "d.csv", "--scenario", "michaelis_menten", "-o", "full/m.json"]]
    if h5 is not None:
        argvs += [["export", str(h5), "--format", "uff", "-o", "full/x.uff"],
                  ["export", str(h5), "--format", "sep005", "-o", "full/x.json"]]

    def case(argv: list[str]):
        def run() -> str | None:
            for p in mnt.iterdir():
                shutil.rmtree(p) if p.is_dir() else p.unlink()
            (mnt / "fill").write_bytes(b"\0" * 190 * 1024)  # the last 8 kB free
            p = _testbed(argv, work)
            bad = _cli_finding(p)
            left = [str(f.relative_to(mnt)) for f in mnt.rglob("*") if f.is_file() and f.name != "fill"
                    and (f.stat().st_size == 0 or f.name.endswith(".tmp"))]
            return bad or (f"left {left[:3]}" if left else None)
        return (" ".join(argv), run)

    return [case(a) for a in argvs]  # unmounted by the family's wrapper below


def _full_family(work: Path) -> Counter:
    try:
        return run_inprocess(full_cases(work))
    finally:
        subprocess.run(["umount", str(work / "full")], capture_output=True)


def run_inprocess(cases) -> Counter:
    """Each case returns a finding's description or None (a verdict, or refused in one line)."""
    return _hostile.run_inprocess(cases, TIMEOUT_S, lambda finding: finding)


FAMILIES = {
    "results": lambda work: run_inprocess(results_cases(_hostile.subfolder(work, "results"))),
    "study": lambda work: run_inprocess(study_cases()),
    "negzero": lambda work: run_inprocess(negzero_cases()),
    "family": lambda work: run_inprocess(family_cases(_hostile.subfolder(work, "family"))),
    "channels": lambda work: run_inprocess(channels_cases(_hostile.subfolder(work, "channels"))),
    "plugins": lambda work: run_inprocess(plugins_cases(_hostile.subfolder(work, "plugins"))),
    "env": lambda work: run_inprocess(env_cases(_hostile.subfolder(work, "env"))),
    "full": lambda work: _full_family(_hostile.subfolder(work, "fullwork")),
}


def main(argv: list[str]) -> int:
    os.environ.setdefault("MPLBACKEND", "Agg")
    return _hostile.main(argv, FAMILIES, "hostile12-")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
