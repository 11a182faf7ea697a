"""Seventh malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each family of cases is generated here and run in-process (loads) or as a ``testbed`` process
(commands); a case is a *finding* when it ends in anything but one error line naming the file
(status 2) or a verdict: a traceback, an internal error, a hang past its timeout, a file left
behind, or a value accepted that the rules refuse.  Run from the repository root::

    python -m benchmarks.hostile7 [family ...]      # all families when none is named

Families: ``specs`` (a study's family ranges set to odd distributions), ``members`` (member
counts and seeds at their edges, drawn), ``importers`` (CSV and SEP-005 user data: times
unsorted, repeated, reversed, rescaled; zero and one rows; mixed units; optional keys of the
wrong kind; read and turned into a dataset), ``env`` (the environment: umask, TZ, LANG, junk
in the variables the testbed reads), ``paths`` (links, loops and long names for every path
option), ``concurrent`` (several runs sharing one cold cache entry and output folder).
Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import copy
import math
import os
import subprocess
import sys
import tomllib
from collections import Counter
from pathlib import Path

from benchmarks import _hostile

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 60  # a case longer than this is a hang (the slowest load below takes about 5 s)

#: Odd distributions for a range key: each is either refused at load or drawn.
ODD_SPECS = [
    {"uniform": []}, {"uniform": [1.0]}, {"uniform": [1.0, 2.0, 3.0]}, {"uniform": [2.0, 1.0]},
    {"uniform": [-1e308, 1e308]}, {"uniform": [0.0, 1e308]}, {"uniform": [1e308, 1e308]},
    {"uniform": [5e-324, 1e-300]}, {"uniform": [-0.0, 0.0]}, {"uniform": [math.nan, 1.0]},
    {"uniform": [1.0, math.inf]}, {"uniform": ["nan", "inf"]}, {"uniform": [True, False]},
    {"uniform": [1, 2]}, {"uniform": [[1], [2]]}, {"uniform": {"lo": 1}},
    {"log_uniform": [0.0, 1.0]}, {"log_uniform": [-1.0, 1.0]}, {"log_uniform": [5e-324, 1e308]},
    {"log_uniform": [1e-300, 1e-299]},
    {"integers": [0.5, 2]}, {"integers": [-2**63, 2**63 - 1]}, {"integers": [0, 2**64]},
    {"integers": [2**70, 2**71]}, {"integers": [3, 3]}, {"integers": [5, 1]},
    {"log_integers": [0, 5]}, {"log_integers": [1, 2**62]}, {"log_integers": [2**62, 2**63 - 1]},
    {"choices": []}, {"choices": [math.nan]}, {"choices": [[1]]}, {"choices": [{}]},
    {"choices": ["a", 1, 2.0, True]}, {"choices": list(range(100_000))}, {"choices": "abc"},
    {"uniform": [0.0, 1.0], "choices": [1]}, {"normal": [0.0, 1.0]}, {}, {"choices": [None] * 0},
    math.nan, math.inf, -math.inf, "nan", "inf", "", [], {"uniform": [1e-12, 1e-12]},
]


def _nonfinite(study) -> str | None:
    """The first non-finite number in a loaded study's scenarios (a NaN never passes)."""
    def walk(v, where):
        if isinstance(v, float) and not math.isfinite(v):
            return where
        if isinstance(v, dict):
            return next((w for k, x in v.items() if (w := walk(x, f"{where}.{k}"))), None)
        if isinstance(v, (list, tuple)):
            return next((w for i, x in enumerate(v) if (w := walk(x, f"{where}[{i}]"))), None)
        return None

    for sc in getattr(study, "scenarios", ()):
        for part in ("rig_params", "simulation", "excitation", "signal", "noise"):
            w = walk(getattr(sc, part, None), f"{sc.name}.{part}")
            if w:
                return w
    return None


def family_specs() -> list[tuple[str, object]]:
    """Every range key of every family of the shipped studies set to every odd spec."""
    from testbed.studies.study import study_from_dict

    cases = []
    for path in sorted((ROOT / "studies").glob("*.toml")):
        raw = tomllib.loads(path.read_text())
        for fname, fam in raw.get("families", {}).items():
            for table in ("rig", "simulation", "excitation", "signal"):
                for key in [*fam.get(table, {}), "__new__"]:
                    for spec in ODD_SPECS:
                        mod = copy.deepcopy(raw)
                        f = mod["families"][fname]
                        f["members"] = 2
                        for other in list(mod["families"]):
                            if other != fname:
                                del mod["families"][other]
                        f.setdefault(table, {})[key if key != "__new__" else "length"] = spec
                        name = f"{path.stem}:{fname}.{table}.{key}={str(spec)[:40]}"
                        cases.append((name, lambda mod=mod, path=path: study_from_dict(
                            mod, file=str(path), base=path.parent, stem=path.stem)))
    return cases


def family_members() -> list[tuple[str, object]]:
    """Member counts, seeds, names and bases at their edges, expanded."""
    from testbed.studies.study import study_from_dict

    path = ROOT / "studies" / "families.toml"
    raw = tomllib.loads(path.read_text())
    cases = []
    edits = [("members", v) for v in (0, -1, 1, 10_000, 10_001, 2**63, 1.5, "3", math.nan, True)]
    edits += [("seed", v) for v in (-1, 0, 2**63 - 1, 2**64, 2**70, 2**200, 1.0, "0", math.inf)]
    edits += [("base", v) for v in ("", ".", "..", "/", "/dev/null", "families", "cartpole.toml",
                                    "../studies/families.toml", "x" * 5000, "cartpole\0", 1, [])]
    edits += [("description", v) for v in ("\n", "x" * 100_000, 1)]
    for fname in raw["families"]:
        for key, value in edits:
            mod = copy.deepcopy(raw)
            for other in list(mod["families"]):
                if other != fname:
                    del mod["families"][other]
            if key != "members":
                mod["families"][fname]["members"] = 2
            mod["families"][fname][key] = value
            cases.append((f"{fname}.{key}={str(value)[:30]}",
                          lambda mod=mod: study_from_dict(mod, file=str(path), base=path.parent,
                                                          stem=path.stem)))
        for new in ("", "a b", "x" * 300, "cantilever_stiff_impact", "beams_stiff.m0001", "ünï"):
            mod = copy.deepcopy(raw)
            fam = mod["families"].pop(fname)
            fam["members"] = 2
            mod["families"] = {new: fam}
            cases.append((f"families.{new[:30]!r}",
                          lambda mod=mod: study_from_dict(mod, file=str(path), base=path.parent,
                                                          stem=path.stem)))
    return cases


def importer_cases(work: Path) -> list[tuple[str, object]]:
    """User data files at the edges of what the importers accept, each read and turned into a
    dataset (an accepted file must give finite data at a finite positive rate)."""
    import json

    import numpy as np

    from testbed.pipeline.importers import read_measured

    d = work / "importers"
    d.mkdir(exist_ok=True)
    t = np.arange(200) / 100.0
    x = np.sin(2 * np.pi * 3 * t)

    def csv(name, header, rows):
        with open(d / name, "w") as f:
            f.write(header + "\n")
            for r in rows:
                f.write(",".join(v if isinstance(v, str) else repr(float(v)) for v in r) + "\n")
        return d / name

    def sep(name, chans):
        (d / name).write_text(json.dumps(chans))
        return d / name

    def cols(*columns):
        return list(zip(*columns, strict=True))

    def cell5(value):  # sample 5 of the channel replaced by the text ``value``
        return [(a, value if i == 5 else b) for i, (a, b) in enumerate(cols(t, x))]

    head, head2 = "t,acc1 [m/s^2]", "t,acc1 [m/s^2],acc2 [m/s^2]"
    files = {
        "t_ms": csv("t_ms.csv", "t [ms],acc1 [m/s^2]", cols(t * 1000, x)),
        "t_hz": csv("t_hz.csv", "t [Hz],acc1 [m/s^2]", cols(t, x)),
        "unsorted": csv("unsorted.csv", head, cols(np.r_[t[:100], t[150:], t[100:150]], x)),
        "reversed": csv("reversed.csv", head, cols(t[::-1], x)),
        "repeat_all": csv("repeat_all.csv", head, cols(np.repeat(t[:100], 2), x)),
        "one_repeat": csv("one_repeat.csv", head, cols(np.r_[t[:100], t[99], t[100:199]], x)),
        "zero_rows": csv("zero_rows.csv", head, []),
        "one_row": csv("one_row.csv", head, [(0.0, 1.0)]),
        "two_same_t": csv("two_same.csv", head, [(0.0, 1.0), (0.0, 2.0)]),
        "mixed_units": csv("mixed.csv", "t,acc1 [g],acc2 [m/s^2],f [N]", cols(t, x, x, x)),
        "neg_time": csv("negt.csv", head, cols(t - 1e6, x)),
        "huge_t": csv("huge_t.csv", head, cols(t * 1e300, x)),
        "tiny_t": csv("tiny_t.csv", head, cols(t * 1e-300, x)),
        "two_time": csv("two_time.csv", "t,time,acc1 [m/s^2]", cols(t, t, x)),
        "time_only": csv("time_only.csv", "t", cols(t)),
        "dup_name": csv("dup.csv", "t,acc1 [m/s^2],acc1 [g]", cols(t, x, x)),
        "nan_cell": csv("nan.csv", head, cell5("nan")),
        "inf_cell": csv("inf.csv", head, cell5("-Infinity")),
        "empty_cell": csv("empty.csv", head, cell5("")),
        "ragged": csv("ragged.csv", head2, [r if i == 5 else (*r, r[1]) for i, r in enumerate(cols(t, x))]),
    }
    ch = {"name": "acc1", "data": list(x), "unit_str": "m/s^2"}
    for k, extra in {
            "sep_unsorted": {"time": list(np.r_[t[:100], t[150:], t[100:150]])},
            "sep_repeat": {"time": list(np.repeat(t[:100], 2))},
            "sep_fs_time": {"fs": 50.0, "time": list(t)}, "sep_fs_str": {"fs": "100"},
            "sep_fs_bool": {"fs": True}, "sep_pos_nan": {"fs": 100.0, "position_m": math.nan},
            "sep_pos_str": {"fs": 100.0, "position_m": "0.3"}, "sep_node_neg": {"fs": 100.0, "node": -1},
            "sep_node_float": {"fs": 100.0, "node": 1.5}, "sep_unit_none": {"fs": 100.0, "unit_str": None},
            "sep_empty": {"fs": 100.0, "data": []}, "sep_nested": {"fs": 100.0, "data": [list(x)]},
            "sep_text": {"fs": 100.0, "data": [str(v) for v in x]},
            "sep_bools": {"fs": 100.0, "data": [True, False] * 100}}.items():
        files[k] = sep(f"{k}.json", [{**ch, **extra}])
    files["sep_rates"] = sep("rates.json", [{**ch, "fs": 100.0}, {**ch, "name": "acc2", "fs": 100.05}])
    (d / "nan.json").write_text('[{"name": "a", "data": [1, 2, NaN, 3], "unit_str": "m/s^2", "fs": 100}]')
    files["sep_NaN"] = d / "nan.json"

    def case(path):
        data = read_measured(path)
        ds = data.to_dataset()
        bad = [n for n, (_, v) in data.signals.items() if not np.all(np.isfinite(v))]
        if bad or not (math.isfinite(data.fs) and data.fs > 0):
            raise AssertionError(f"accepted non-finite data or rate: {bad}, fs {data.fs}")
        return ds

    return [(f"importer {k}", lambda p=p: case(p)) for k, p in files.items()]


def concurrent_cases(work: Path) -> Counter:
    """Three `testbed run` of one scenario at once on one cold cache and one output folder,
    three times: every run ends in its verdict, one cache entry, no temporary file."""
    counts = Counter()
    for round_ in range(3):
        base = work / f"conc{round_}"
        base.mkdir()
        args = ["run", "michaelis_menten", "--no-figures", "--out", str(base / "runs"),
                "--cache", str(base / "cache")]
        e = {**os.environ, "OMP_NUM_THREADS": "1", "PYTHONPATH": str(ROOT)}
        procs = [subprocess.Popen([sys.executable, "-m", "testbed.cli", *args], cwd=base, env=e,
                                  stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                 for _ in range(3)]
        outs = [p.communicate(timeout=600) for p in procs]
        counts["cases"] += 1
        problems = [f"status {p.returncode}: {err.strip()[-200:]!r}" for p, (_, err) in
                    zip(procs, outs, strict=True) if p.returncode != 0 or err.strip()]
        entries = sorted(q.name for q in (base / "cache").iterdir())
        runs = sorted(q for q in (base / "runs" / "michaelis_menten").iterdir() if q.is_dir())
        stray = [str(q) for q in base.rglob("*") if ".tmp" in q.name or q.name.startswith("tmp")]
        if len(entries) != 1 or len(runs) != 3 or stray or problems:
            counts["findings"] += 1
            print(f"FINDING concurrent round {round_}: entries {entries}, {len(runs)} runs, "
                  f"stray {stray}, {problems}", flush=True)
    return counts


def _check_study(study) -> str | None:
    """A loaded study holding a non-finite number is a finding (a NaN never passes)."""
    bad = _nonfinite(study)
    return f"accepted a non-finite value: {bad}" if bad else None


def run_inprocess(cases) -> Counter:
    return _hostile.run_inprocess(cases, TIMEOUT_S, _check_study)


def tb(args: list[str], cwd: Path, env: dict[str, str] | None = None, umask: int | None = None,
       timeout: float = 300) -> subprocess.CompletedProcess:
    e = {**os.environ, "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg", "PYTHONPATH": str(ROOT)}
    e.update(env or {})
    e = {k: v for k, v in e.items() if v is not None}
    pre = (lambda: os.umask(umask)) if umask is not None else None
    return subprocess.run([sys.executable, "-m", "testbed.cli", *args], cwd=cwd, env=e,
                          capture_output=True, text=True, timeout=timeout, preexec_fn=pre)


def judge_process(name: str, r: subprocess.CompletedProcess, cwd: Path, before: set[str]) -> str:
    """``ok`` or a finding: a traceback, an internal error, more than one error line, a file
    left in the current folder."""
    err = r.stderr.strip().splitlines()
    if "Traceback" in r.stderr or "internal error" in r.stderr:
        return f"traceback/internal (status {r.returncode}): {r.stderr.strip()[-300:]!r}"
    if r.returncode not in (0, 1) and len(err) != 1:
        return f"status {r.returncode} with {len(err)} stderr lines: {r.stderr[-300:]!r}"
    if r.returncode in (0, 1) and len(err) > 4:  # a verdict with a library warning or two after it
        return f"status {r.returncode} with {len(err)} stderr lines: {r.stderr[-300:]!r}"
    left = {p.name for p in cwd.iterdir()} - before
    stray = {n for n in left if n.startswith(("tmp", ".tmp", "MUJOCO_LOG")) or n.endswith(".tmp")}
    if stray:
        return f"left in the current folder: {sorted(stray)}"
    return "ok"


def env_cases(work: Path) -> list[tuple[str, list[str], dict, int | None]]:
    """(name, args, environment, umask) of commands under odd environments."""
    fast = ["run", "michaelis_menten", "--no-figures", "--out", str(work / "runs"),
            "--cache", str(work / "cache")]
    cases = []
    for umask in (0o077, 0o777, 0o000, 0o222):
        cases.append((f"umask {umask:o} run", fast, {}, umask))
        cases.append((f"umask {umask:o} list", ["list"], {}, umask))
    # a run that imports MuJoCo (a 0.05 s cart-pole) and one that draws (figures on)
    text = (ROOT / "scenarios" / "cartpole.toml").read_text()
    (work / "cp_short.toml").write_text(text.replace('name = "cartpole"', 'name = "cp_short"')
                                        .replace("duration = 10.0", "duration = 0.05"))
    mujoco_run = ["run", str(work / "cp_short.toml"), "--no-figures", "--no-cache", "--out",
                  str(work / "runs")]
    drawn = ["run", "michaelis_menten", "--out", str(work / "runs"), "--cache", str(work / "cache")]
    for value in ("", "bogus", "egl", "osmesa", "glfw", "disable", "x" * 10_000):
        cases.append((f"MUJOCO_GL={value[:12]!r} run", mujoco_run, {"MUJOCO_GL": value}, None))
    for value in ("", "bogus", "module://nowhere", "TkAgg", "pdf", "x" * 10_000):
        cases.append((f"MPLBACKEND={value[:12]!r} run with figures", drawn, {"MPLBACKEND": value}, None))
    for tz in ("", "UTC", "Asia/Kathmandu", "NOT/A_ZONE", "x" * 5000, ":/etc/passwd", "<+14>-14"):
        cases.append((f"TZ={tz[:20]!r} run", fast, {"TZ": tz}, None))
    for lang in ("tr_TR.UTF-8", "C", "az_AZ.UTF-8", "xx_XX.bogus"):
        cases.append((f"LC_ALL={lang} run", fast, {"LC_ALL": lang, "LANG": lang}, None))
    names = set()
    for tree in ("testbed", "models", "identify"):
        for p in (ROOT / tree).rglob("*.py"):
            text = p.read_text()
            for token in ("os.environ.get(\"", "os.environ[\"", "getenv(\""):
                i = 0
                while (i := text.find(token, i)) >= 0:
                    i += len(token)
                    names.add(text[i:text.index('"', i)])
    # and those the libraries read that the testbed sets or relies on
    names |= {"MUJOCO_GL", "MPLBACKEND", "NUMBA_CACHE_DIR", "NUMBA_NUM_THREADS", "OMP_NUM_THREADS"}
    names = sorted(n for n in names if n and n.isupper())
    for n in names:
        for junk in ("", " ", "\x01", "-1", "0", "nan", "1e400", "x" * 10_000, "/dev/null",
                     "/nonexistent/x", "../../..", "ünï"):
            cases.append((f"{n}={junk[:12]!r} list", ["list"], {n: junk}, None))
            if junk in ("", "\x01", "nan", "x" * 10_000, "/nonexistent/x"):
                cases.append((f"{n}={junk[:12]!r} run", fast, {n: junk}, None))
    return cases


def path_cases(work: Path) -> list[tuple[str, list[str], dict, int | None]]:
    """Odd paths for the output, cache and results options."""
    (work / "loop").unlink(missing_ok=True)
    os.symlink("loop", work / "loop")
    (work / "dangling").unlink(missing_ok=True)
    os.symlink("nowhere/x", work / "dangling")
    long_dir = work / ("d" * 200) / ("e" * 200) / ("f" * 200) / ("g" * 200) / ("h" * 200)
    deep = work / "/".join(["z"] * 2100)  # over PATH_MAX (4096)
    odd = [work / "loop" / "x", work / "dangling", long_dir, deep, work / ("n" * 256),
           Path("/proc/self/fd/1"), Path("/dev/stdout"), work / "a\nb", work / "-rf"]
    cases = []
    for p in odd:
        s = str(p)
        label = s if len(s) < 40 else s[:20] + f"...({len(s)} chars)"
        cases.append((f"--out {label}", ["run", "michaelis_menten", "--no-figures", "--out", s,
                                         "--cache", str(work / "cache")], {}, None))
        cases.append((f"--cache {label}", ["run", "michaelis_menten", "--no-figures", "--out",
                                           str(work / "runs"), "--cache", s], {}, None))
        cases.append((f"TESTBED_CACHE {label}", ["cache", "ls"], {"TESTBED_CACHE": s}, None))
        cases.append((f"report -o {label}", ["report", str(work / "runs"), "-o", s], {}, None))
        cases.append((f"export {label}", ["export", "michaelis_menten", "-o", s, "--cache",
                                          str(work / "cache")], {}, None))
    return cases


def run_processes(cases, work: Path) -> Counter:
    counts = Counter()
    cwd = work / "cwd"
    cwd.mkdir(exist_ok=True)
    for name, args, env, umask in cases:
        before = {p.name for p in cwd.iterdir()}
        counts["cases"] += 1
        try:
            r = tb(args, cwd, env, umask)
        except subprocess.TimeoutExpired:
            counts["findings"] += 1
            print(f"FINDING {name}: hang", flush=True)
            continue
        verdict = judge_process(name, r, cwd, before)
        if verdict != "ok":
            counts["findings"] += 1
            print(f"FINDING {name}: {verdict}", flush=True)
    return counts


def main(argv: list[str]) -> int:
    return _hostile.main(argv, {
        "specs": lambda work: run_inprocess(family_specs()),
        "members": lambda work: run_inprocess(family_members()),
        "importers": lambda work: run_inprocess(importer_cases(work)),
        "env": lambda work: run_processes(env_cases(work), work),
        "paths": lambda work: run_processes(path_cases(work), work),
        "concurrent": concurrent_cases,
    }, "hostile7-")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
