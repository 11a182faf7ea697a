"""Twenty-ninth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile29 [family ...]      # all families when none is named

Families (what rounds 1-28 did not try; their families are listed in ``hostile21.py`` to
``hostile28.py``):

``truncate``
    Valid files cut short at every byte boundary (the kinetics scenario's TOML) or at 48 evenly
    spread ones plus the first and last 16 bytes (the kinetics record's SEP-005 JSON and UFF
    exports, its HDF5 dataset, a sweep's Parquet results file), each read by the API's reader
    (``load_scenario``, ``read_measured``, ``read_results``): a result or one error line.
``edges``
    Every bounded numeric key of the kinetics scenario's sections (``[scenario]``, ``[rig]``,
    ``[simulation]``, ``[noise]``; walked from the schemas, so a key added later is tried) at
    its bound and one ulp (one integer) beyond it on either side: a bound the schema calls
    inclusive must load, one it calls exclusive and every value beyond must be refused in one
    line naming the key; an accepted edge of ``[noise]`` and ``seed`` is also run.
``names``
    Unicode and blanks in names, keys and paths: a scenario file and output folder named with a
    no-break space, a zero-width space, a right-to-left mark, combining marks, a trailing blank,
    an emoji, NFC vs NFD forms; a ``[rig]`` key with a trailing no-break space, a noise key in
    full-width letters; a tag of one zero-width space.
``envodd``
    Environment oddities, as processes: ``HOME`` unset, empty, a file; ``TESTBED_CACHE`` a file, a
    symbolic-link loop, a missing folder; ``-o``, ``--plugin`` and the scenario file a
    symbolic-link loop; the file size limit
    (``RLIMIT_FSIZE``, a full disk's quota) at 4 kB and 200 kB for ``generate`` and ``run``; the
    working folder removed under the process.
``plugarray``
    A ``--plugin`` identifier of the kinetics whose coefficients, after its own fit, are a masked
    array (some masked), a ``np.matrix``, float32, float16, an object array of floats, a
    read-only array, a list, a ``ndarray`` subclass, complex with zero imaginary part, or whose
    ``simulate`` returns one of those, or a ``Trajectory`` whose fields are float32, masked,
    complex, object, lists, text, of half the times, transposed, 1-D, None, all NaN, with an
    inf, ``np.matrix``, or a plain tuple: a verdict, never a traceback or NaN passing.
``apiforms``
    The API given numpy scalars (``np.float64`` noise, ``np.int64`` seed, ``np.str_`` names),
    ``pathlib.Path`` where a text is documented and the reverse, generators and tuples where a
    list is, ``os.PathLike`` objects of a user's own class, bytes paths.
``rehashed``
    A cache entry whose content hash is made anew after an edit that makes it disagree with its
    scenario (``fs``, half its samples, another rig kind, a channel renamed, another format),
    so its checksum matches: ``generate`` must write the fresh record (or refuse in one line);
    and a results file written with rows whose checksum matches but that say ``passed`` with a
    NaN score, ``passed`` with ``status`` "error", or an unknown ``status``: ``summary`` and
    ``report`` must not show a pass for them.

``apiwalk``
    Round 28's walk of the public API, with review 28b L8's mend: a ``TypeError`` raised inside
    the callable is a finding even when its text reads like a signature's ("positional
    argument"); only one raised by the call itself is the signature's refusal.
``ownmark``
    A file of the user's in the format a command writes, at the path it writes (review 28b
    M2): a matplotlib ``fit_time.png`` in a report's folder, a ``settings.json`` given to
    ``identify -o``, another tool's SEP-005 JSON, UFF (a header record) or HDF5 given to
    ``export`` / ``generate -o``, a dataset cut to its first 300 bytes: refused in one line and
    left byte for byte.
``sigint``
    Ctrl-C (SIGINT to the command's process group) at 5-95 % of the command's own span (timed
    once, uninterrupted) for ``report`` into the folder of an earlier report, ``export`` (UFF,
    SEP-005) and ``identify -o`` over an earlier output: a process left, a traceback, an
    interrupted command whose last line is not ``error: interrupted``, a temporary file left,
    an output changed but incomplete (PNG without IEND, HTML without its closing tag, JSON that
    does not parse, UFF without its last delimiter) or an earlier output removed is a finding.

Prints one line a finding and the counts; exits 1 if any finding.
"""
# ruff: noqa: E501 (the case tables: one case a line)

from __future__ import annotations

import contextlib
import json
import math
import os
import resource
import shutil
import signal
import subprocess
import sys
from pathlib import Path

try:
    from benchmarks import _hostile, hostile19, hostile27, hostile28
except ImportError:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks import _hostile, hostile19, hostile27, hostile28

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 240
MM = hostile19.MM
CACHE = hostile19.CACHE
cli_inprocess = _hostile.cli_inprocess
judged = _hostile.judged


def _one_line(e: BaseException) -> str | None:
    """None for the testbed's own one-line error, else a finding."""
    from testbed.core.errors import TestbedError

    if not isinstance(e, TestbedError):
        return f"{type(e).__name__}: {str(e)[:200]}"
    text = str(e)
    if "\n" in text or len(text) > _hostile.MAX_LINE_CHARS:
        return f"refused in {text.count(chr(10)) + 1} lines / {len(text)} chars"
    return None


def _reads(fn) -> str | None:
    """``fn()`` returns or raises the testbed's one-line error: None; anything else a finding."""
    try:
        fn()
    except Exception as e:
        return _one_line(e)
    return None


# ------------------------------------------------------------------ truncate

def _cuts(n: int, spread: int = 48) -> list[int]:
    """Cut points of an ``n``-byte file: the first and last 16 and ``spread`` evenly between."""
    points = set(range(min(16, n))) | set(range(max(0, n - 16), n))
    points |= {round(k * n / spread) for k in range(spread)}
    return sorted(p for p in points if 0 <= p < n)


def _sources(work: Path) -> dict[str, Path]:
    """The valid files cut: the kinetics dataset, its SEP-005 and UFF exports, a results file."""
    h5 = hostile19._generated(work, MM)
    out = {"hdf5": h5}
    for fmt, suffix in (("sep005", ".json"), ("uff", ".uff")):
        p = work / f"mm{suffix}"
        if not p.exists():
            status, _, err = cli_inprocess(["export", str(h5), "--format", fmt, "-o", str(p)])
            if status != 0:
                raise RuntimeError(f"export {fmt}: {err[-300:]}")
        out[fmt] = p
    res = work / "results.parquet"
    if not res.exists():
        from testbed.studies.results import write_rows
        write_rows(res, [_hostile.results_row(cell=f"c{k}", seed=k) for k in range(3)])
    out["parquet"] = res
    return out


def truncate_cases(work: Path) -> list[tuple[str, object]]:
    import testbed
    from testbed.pipeline.scenario import SCENARIO_DIR

    toml = (SCENARIO_DIR / f"{MM}.toml").read_bytes()
    cases = []

    def toml_case(k: int):
        def run():
            d = work / "toml" / f"cut{k}"
            d.mkdir(parents=True, exist_ok=True)
            p = d / f"{MM}.toml"
            p.write_bytes(toml[:k])
            return _reads(lambda: testbed.load_scenario(str(p)))
        return run

    cases += [(f"truncate toml at byte {k}", toml_case(k)) for k in range(len(toml))]
    state: dict = {}

    def file_case(kind: str, k: int | None):
        def run():
            if "src" not in state:
                state["src"] = _sources(work)
            src = state["src"][kind]
            data = src.read_bytes()
            if k is None:  # (the cut points of this file, as cases of their own)
                return None
            p = work / "cut" / f"{kind}_{k}{src.suffix}"
            p.parent.mkdir(exist_ok=True)
            p.write_bytes(data[: k * len(data) // 1000])
            if kind == "parquet":
                return _reads(lambda: testbed.read_results(p))
            return _reads(lambda: testbed.read_measured(p))
        return run

    # cut points as thousandths of each file (the files' sizes are not known before they exist)
    for kind in ("hdf5", "sep005", "uff", "parquet"):
        cases += [(f"truncate {kind} at {k / 10:.1f} %", file_case(kind, k))
                  for k in sorted(set(range(0, 1000, 20)) | {1, 2, 3, 5, 995, 998, 999})]
    return cases


# ------------------------------------------------------------------ edges

def _bounded_fields() -> list[tuple[str, str, object]]:
    """``(section, key, Field)`` of every bounded number of the kinetics scenario."""
    from testbed import RIGS
    from testbed.pipeline.scenario import HEADER_SCHEMA, NOISE_SCHEMA

    rig = RIGS.get(MM)
    tables = {"scenario": HEADER_SCHEMA, "rig": rig.rig_schema,
              "simulation": rig.simulation_schema, "noise": NOISE_SCHEMA}
    return [(s, k, f) for s, schema in tables.items() for k, f in schema.items()
            if f.type in (int, float) and (f.min is not None or f.max is not None)]


def _edge_values(f) -> list[tuple[str, object, bool]]:
    """``(label, value, accepted?)`` at and beyond a field's bounds."""
    import numpy as np

    out = []
    for bound, inclusive, outward in ((f.min, f.min_inclusive, -np.inf),
                                      (f.max, f.max_inclusive, np.inf)):
        if bound is None or not math.isfinite(bound):
            continue
        if f.type is int:
            step = -1 if outward < 0 else 1
            out += [("at", int(bound), inclusive), ("one beyond", int(bound) + step, False),
                    ("one inside", int(bound) - step, True)]
        else:
            out += [("at", float(bound), inclusive),
                    ("one ulp beyond", float(np.nextafter(bound, outward)), False),
                    ("one ulp inside", float(np.nextafter(bound, -outward)), True)]
    return out


def _toml_value(v: object) -> str:
    if isinstance(v, float):
        return repr(v) if math.isfinite(v) else ("inf" if v > 0 else "-inf")
    return str(v)


def edges_cases(work: Path) -> list[tuple[str, object]]:
    import testbed

    base = hostile19._mm_text()

    def case(section: str, key: str, label: str, value: object, accepted: bool):
        def run():
            import re

            text = base
            line = f"{key} = {_toml_value(value)}"
            pat = re.compile(rf"^{re.escape(key)} = .*$", re.M)
            head = f"[{section}]"
            block = text.split(head, 1)
            if len(block) != 2:
                return f"no [{section}] in the scenario"
            rest = block[1]
            nxt = rest.find("\n[")
            body, tail = (rest, "") if nxt < 0 else (rest[:nxt], rest[nxt:])
            body = pat.sub(line, body, count=1) if pat.search(body) else f"\n{line}{body}"
            d = work / hostile19._safe(f"{section}_{key}_{label}_{value}")
            d.mkdir(exist_ok=True)
            p = d / f"{MM}.toml"
            p.write_text(block[0] + head + body + tail)
            try:
                sc = testbed.load_scenario(str(p))
            except Exception as e:
                found = _one_line(e)
                if found:
                    return found
                said = str(e).partition("expected")[2]
                if accepted and any(b in said for b in ("<=", ">=", "< ", "> ")):
                    # the schema refused a value its own bounds allow (another rule's refusal,
                    # a step budget or two samples at least, is one line: not a finding)
                    return f"refused a value the schema allows: {str(e)[:200]}"
                if key not in str(e):
                    return f"refused without naming {key}: {str(e)[:200]}"
                return None
            if not accepted:
                return f"accepted {value!r}, beyond the schema's bound"
            if section in ("noise",) or key == "seed":
                r = testbed.run_scenario(sc, cache=str(CACHE))
                return _hostile.scored_finding(r)
            return None
        return run

    return [(f"edges [{s}] {k} {label} ({v!r})", case(s, k, label, v, acc))
            for s, k, f in _bounded_fields() for label, v, acc in _edge_values(f)]


# ------------------------------------------------------------------ names

_ODD_NAMES = {
    "no-break space": "mm\u00a0x",
    "zero-width space": "mm\u200bx",
    "right-to-left mark": "mm\u200fx",
    "combining acute": "mme\u0301",
    "trailing blank": "mm ",
    "emoji": "mm\U0001f600",
    "NFD of an NFC name": "m\u0065\u0301",
    "full-width letters": "\uff4d\uff4d",
}


def names_cases(work: Path) -> list[tuple[str, object]]:
    text = hostile19._mm_text()
    cases = []

    def named(label: str, name: str, in_file: bool):
        def run():
            d = work / hostile19._safe(label) / f"dir {name}"
            d.mkdir(parents=True, exist_ok=True)
            stem = name if in_file else MM
            p = d / f"{stem}.toml"
            p.write_text(text.replace(f'name = "{MM}"', f'name = "{stem}"'))
            out = d / f"out {name}"
            status, o, err = cli_inprocess(["run", str(p), "--cache", str(CACHE), "-o", str(out),
                                            "--no-figures"])
            found = judged(status, o, err, refuse=in_file)
            if found or status != 0:
                return found and f"run: {found}"
            runs = sorted(q for q in out.rglob("run.json"))
            if not runs:
                return f"run: status 0, no run.json under {out}"
            status, o, err = cli_inprocess(["report", str(runs[0].parent), "-o", str(d / f"rep {name}")])
            found = judged(status, o, err)
            if found or status != 0:
                return f"report: {found or err.strip()[:160]}"
            status, o, err = cli_inprocess(["runs", "ls", "--runs", str(out)])
            return judged(status, o, err) and f"runs ls: {judged(status, o, err)}"
        return run

    def keyed(label: str, old: str, new: str, refuse: bool = True):
        def run():
            d = work / hostile19._safe(label)
            d.mkdir(exist_ok=True)
            p = d / f"{MM}.toml"
            p.write_text(text.replace(old, new, 1))
            status, o, err = cli_inprocess(["generate", str(p), "--cache", str(CACHE), "-o",
                                            str(d / "o.h5")])
            return judged(status, o, err, refuse=refuse)
        return run

    def output_named(label: str, name: str):
        def run():
            out = work / "outs" / name
            out.parent.mkdir(exist_ok=True)
            status, o, err = cli_inprocess(["generate", MM, "--cache", str(CACHE), "-o", str(out)])
            found = judged(status, o, err)
            if found or status != 0:
                return found
            return None if out.exists() else f"wrote no {out.name!r}: {o.strip()[-120:]!r}"
        return run

    cases += [(f"names scenario named with a {label}", named(label, n, True))
              for label, n in _ODD_NAMES.items()]
    cases += [(f"names folders named with a {label}", named(label, n, False))
              for label, n in _ODD_NAMES.items()]
    cases += [
        ("names [rig] key with a trailing no-break space", keyed("k1", "\nKm = 0.3", "\nKm\u00a0 = 0.3")),
        ("names [rig] key quoted with a trailing blank", keyed("k2", "\nKm = 0.3", '\n"Km " = 0.3')),
        ("names [noise] key in full-width letters", keyed("k3", "rms_percent", "\uff52ms_percent")),
        ("names a tag of one zero-width space", keyed("k4", '"implicit"]', '"implicit", "\u200b"]')),  # invisible
        ("names a tag of one no-break space", keyed("k5", '"implicit"]', '"implicit", "\u00a0"]')),
        ("names rig name with a zero-width space", keyed("k6", 'rig = "michaelis_menten"',
                                                          'rig = "michaelis\u200b_menten"')),
        ("names method with a trailing newline escape", keyed("k7", 'method = "sindy_pi_dynamical"',
                                                                'method = "sindy_pi_dynamical\\n"')),
    ]
    cases += [(f"names output file named with a {label}", output_named(label, f"{n}.h5"))
              for label, n in _ODD_NAMES.items()]
    return cases


# ------------------------------------------------------------------ envodd

def _fsize(limit: int):
    def pre():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))
    return pre


def envodd_cases(work: Path) -> list[tuple[str, object]]:
    env0 = dict(_hostile.ENV)

    def proc(argv: list[str], env: dict, cwd: Path, pre=None, timeout: float = 200):
        return subprocess.run([sys.executable, "-m", "testbed.cli", *argv], cwd=cwd, env=env,
                              capture_output=True, text=True, timeout=timeout, preexec_fn=pre)

    def case(label: str, make, argv_of, pre=None, refuse_ok: bool = True, want_out=None):
        def run():
            d = work / hostile19._safe(label)
            shutil.rmtree(d, ignore_errors=True)
            d.mkdir()
            env = dict(env0)
            make(d, env)
            argv = argv_of(d)
            p = proc(argv, env, d, pre)
            found = _hostile.cli_finding(p)
            if found:
                return found
            if p.returncode == 2 and not refuse_ok:
                return f"refused: {p.stderr.strip()[:200]!r}"
            if p.returncode != 2 and want_out is not None and not want_out(d):
                return f"status {p.returncode} without its output"
            left = [f for f in d.rglob(".*.tmp")]
            if left:
                return f"temporary files left: {[f.name for f in left][:3]}"
            return None
        return run

    def unset(key):
        return lambda d, env: env.pop(key, None)

    def setenv(key, value):
        return lambda d, env: env.__setitem__(key, value(d) if callable(value) else value)

    def home_file(d, env):
        (d / "homefile").write_text("x")
        env["HOME"] = str(d / "homefile")

    def cache_file(d, env):
        (d / "cachefile").write_text("x")
        env["TESTBED_CACHE"] = str(d / "cachefile")

    def cache_loop(d, env):
        os.symlink(d / "loopB", d / "loopA")
        os.symlink(d / "loopA", d / "loopB")
        env["TESTBED_CACHE"] = str(d / "loopA")

    def out_loop(d, env):
        os.symlink(d / "oB.h5", d / "oA.h5")
        os.symlink(d / "oA.h5", d / "oB.h5")

    def plugin_loop(d, env):
        os.symlink(d / "p.py", d / "p.py")

    def scenario_loop(d, env):
        os.symlink(d / "s.toml", d / "s.toml")

    gen = lambda d: ["generate", MM, "-o", str(d / "o.h5"), "--cache", str(CACHE)]  # noqa: E731
    gen_nocache = lambda d: ["generate", MM, "-o", str(d / "o.h5")]  # noqa: E731
    run = lambda d: ["run", MM, "-o", str(d / "runs"), "--cache", str(CACHE)]  # noqa: E731
    has_h5 = lambda d: (d / "o.h5").is_file()  # noqa: E731
    cases = [
        ("HOME unset", unset("HOME"), gen_nocache, None, False, has_h5),
        ("HOME empty", setenv("HOME", ""), gen_nocache, None, False, has_h5),
        ("HOME a file", home_file, gen_nocache, None, False, has_h5),
        ("HOME missing", setenv("HOME", lambda d: str(d / "nohome")), run, None, False, None),
        ("TESTBED_CACHE a file", cache_file, gen_nocache, None, True, has_h5),
        ("TESTBED_CACHE a link loop", cache_loop, gen_nocache, None, True, has_h5),
        ("TESTBED_CACHE a missing folder", setenv("TESTBED_CACHE", lambda d: str(d / "no" / "c")),
         gen_nocache, None, False, has_h5),
        ("-o a link loop", out_loop, lambda d: ["generate", MM, "-o", str(d / "oA.h5"), "--cache",
                                                str(CACHE)], None, True, None),
        ("--plugin a symbolic link to itself", plugin_loop,
         lambda d: ["run", MM, "--plugin", str(d / "p.py"), "--no-figures", "-o", str(d / "r")],
         None, True, None),
        ("a scenario file that is a symbolic link to itself", scenario_loop,
         lambda d: ["run", str(d / "s.toml"), "--no-figures", "-o", str(d / "r")], None, True, None),
        ("generate, files limited to 4 kB", lambda d, env: None, gen, _fsize(4096), True, has_h5),
        ("generate, files limited to 200 kB", lambda d, env: None, gen, _fsize(200_000), True, has_h5),
        ("run, files limited to 4 kB", lambda d, env: None, run, _fsize(4096), True, None),
        ("run, files limited to 200 kB", lambda d, env: None, run, _fsize(200_000), True, None),
        ("run --no-figures, files limited to 30 kB", lambda d, env: None,
         lambda d: [*run(d), "--no-figures"], _fsize(30_000), True, None),
    ]
    out = [(f"envodd {label}", case(label, make, argv, pre, ok, want))
           for label, make, argv, pre, ok, want in cases]

    def cwd_removed():
        d = work / "gone"
        shutil.rmtree(d, ignore_errors=True)
        d.mkdir()
        code = ("import os, shutil, sys; d = os.getcwd(); shutil.rmtree(d); "
                "from testbed import cli; sys.exit(cli.main(['generate', 'michaelis_menten', "
                f"'-o', 'o.h5', '--cache', {str(CACHE)!r}]))")
        p = subprocess.run([sys.executable, "-c", code], cwd=d, env=env0, capture_output=True,
                           text=True, timeout=200)
        return _hostile.cli_finding(p)
    out.append(("envodd the working folder removed under the process", cwd_removed))
    return out


# ------------------------------------------------------------------ plugarray

_ODD_ARRAYS = {
    "a masked array, one coefficient masked":
        "c = np.asarray(self.coef_, float); m = np.zeros(c.shape, bool); m.flat[0] = True; "
        "self.coef_ = np.ma.masked_array(c, m)",
    "a masked array, nothing masked": "self.coef_ = np.ma.masked_array(np.asarray(self.coef_, float))",
    "np.matrix": "self.coef_ = np.asmatrix(np.atleast_2d(np.asarray(self.coef_, float)))",
    "float32": "self.coef_ = np.asarray(self.coef_, np.float32)",
    "float16": "self.coef_ = np.asarray(self.coef_, np.float16)",
    "an object array of floats": "self.coef_ = np.asarray(self.coef_, float).astype(object)",
    "read-only": "c = np.array(self.coef_, float); c.flags.writeable = False; self.coef_ = c",
    "a list": "self.coef_ = np.asarray(self.coef_, float).tolist()",
    "an ndarray subclass": "class Sub(np.ndarray): pass\n        "
                           "self.coef_ = np.asarray(self.coef_, float).view(Sub)",
    "complex, zero imaginary part": "self.coef_ = np.asarray(self.coef_, float).astype(complex)",
    "longdouble": "self.coef_ = np.asarray(self.coef_, np.longdouble)",
    "int64 (rounded)": "self.coef_ = np.rint(np.asarray(self.coef_, float)).astype(np.int64)",
}

_ODD_SIMULATE = {
    "float32": "np.asarray(out, np.float32)",
    "a masked array, one sample masked": "np.ma.masked_array(out, np.eye(1, out.size, out.size // 2, dtype=bool).reshape(out.shape))",
    "a list": "np.asarray(out).tolist()",
    "an object array": "np.asarray(out).astype(object)",
    "complex": "np.asarray(out).astype(complex)",
    "a generator of rows": "(row for row in np.asarray(out))",
    "np.matrix": "np.asmatrix(np.atleast_2d(out))",
}


#: A plugin's simulate returning a Trajectory whose fields are odd (``t`` its own trajectory)
_ODD_FIELDS = {
    "float32 fields": "Trajectory(*(np.asarray(f, np.float32) for f in t))",
    "masked fields, one sample masked": "Trajectory(*(np.ma.masked_array(f, np.eye(1, f.size, f.size // 2, dtype=bool).reshape(f.shape)) for f in t))",
    "complex fields": "Trajectory(*(np.asarray(f).astype(complex) for f in t))",
    "complex fields with an imaginary part": "Trajectory(*(np.asarray(f) + 1j for f in t))",
    "object fields": "Trajectory(*(np.asarray(f).astype(object) for f in t))",
    "list fields": "Trajectory(*(np.asarray(f).tolist() for f in t))",
    "fields of half the times": "Trajectory(*(np.asarray(f)[..., : np.shape(f)[-1] // 2] for f in t))",
    "fields transposed": "Trajectory(*(np.asarray(f).T for f in t))",
    "fields 1-D": "Trajectory(*(np.asarray(f).ravel() for f in t))",
    "x None": "Trajectory(None, t.xd, t.xdd)",
    "fields of text": "Trajectory(*(np.asarray(f).astype(str) for f in t))",
    "fields all NaN": "Trajectory(*(np.full(np.shape(f), np.nan) for f in t))",
    "fields with one inf": "Trajectory(*(np.where(np.arange(np.size(f)).reshape(np.shape(f)) == 3, np.inf, f) for f in t))",
    "np.matrix fields": "Trajectory(*(np.asmatrix(np.atleast_2d(f)) for f in t))",
    "a plain tuple of the fields": "tuple(t)",
}


def plugarray_cases(work: Path) -> list[tuple[str, object]]:
    import testbed
    from testbed.core.errors import exception_text

    def case(k: int, label: str, after: str = "", methods: str = ""):
        def run():
            name = f"h29_a{k}"
            plugin = work / f"{name}.py"
            plugin.write_text(hostile28._PLUGIN.replace("NAME", name).replace("#BEFORE", "")
                              .replace("#AFTER", after).replace("#METHODS", methods))
            testbed.load_plugins([str(plugin)])
            try:
                r = testbed.run_scenario(str(hostile28._scenario(work, name)), cache=str(CACHE))
            except testbed.TestbedError as e:
                return _one_line(e)
            except Exception as e:
                return f"{type(e).__name__}: {exception_text(e)[:200]}"
            return _hostile.scored_finding(r)
        return run

    cases = [(f"plugarray coefficients {label}", case(k, label, after=code))
             for k, (label, code) in enumerate(_ODD_ARRAYS.items())]
    cases += [(f"plugarray simulate returns {label}", case(
        100 + k, label, methods=("    def simulate(self, *a, **k):\n"
                                 "        out = super().simulate(*a, **k)\n"
                                 f"        return {code}\n")))
        for k, (label, code) in enumerate(_ODD_SIMULATE.items())]
    cases += [(f"plugarray simulate returns a Trajectory of {label}", case(
        200 + k, label, methods=("    def simulate(self, *a, **k):\n"
                                 "        from testbed.core.measurement import Trajectory\n"
                                 "        t = super().simulate(*a, **k)\n"
                                 f"        return {code}\n")))
        for k, (label, code) in enumerate(_ODD_FIELDS.items())]
    return cases


# ------------------------------------------------------------------ apiforms

class _MyPath:
    """A user's own ``os.PathLike``."""

    def __init__(self, p):
        self.p = str(p)

    def __fspath__(self):
        return self.p


def apiforms_cases(work: Path) -> list[tuple[str, object]]:
    import numpy as np

    import testbed
    from testbed.pipeline.scenario import SCENARIO_DIR

    state: dict = {}

    def plain():
        if "plain" not in state:
            state["plain"] = hostile28._scores(testbed.run_scenario(MM, cache=str(CACHE)))
        return state["plain"]

    def same_as_plain(make):
        def run():
            want = plain()
            try:
                r = make()
            except Exception as e:
                return _one_line(e)
            found = _hostile.scored_finding(r)
            if found:
                return found
            got = hostile28._scores(r)
            return None if hostile28._same(got, want) else "scored otherwise than the plain call"
        return run

    def reads(make):
        return lambda: _reads(make)

    mm_file = SCENARIO_DIR / f"{MM}.toml"
    h5 = lambda: hostile19._generated(work, MM)  # noqa: E731

    def study_text(**kw):
        d = {"scenarios": f'["{MM}"]', "noise": "[0.0]", "seeds": "[0]",
             "identifiers": '["sindy_pi_dynamical"]', **kw}
        p = work / "study.toml"
        p.write_text('[study]\nname = "s"\n' + "".join(f"{k} = {v}\n" for k, v in d.items()))
        return p

    cases = [
        ("run_scenario(np.str_ name)", same_as_plain(lambda: testbed.run_scenario(np.str_(MM), cache=str(CACHE)))),
        ("run_scenario(Path of the file)", same_as_plain(lambda: testbed.run_scenario(mm_file, cache=str(CACHE)))),
        ("run_scenario(cache=Path)", same_as_plain(lambda: testbed.run_scenario(MM, cache=CACHE))),
        ("run_scenario(cache=own PathLike)", same_as_plain(lambda: testbed.run_scenario(MM, cache=_MyPath(CACHE)))),
        ("run_scenario(own PathLike file)", same_as_plain(lambda: testbed.run_scenario(_MyPath(mm_file), cache=str(CACHE)))),
        ("run_scenario(bytes path)", reads(lambda: testbed.run_scenario(os.fsencode(mm_file), cache=str(CACHE)))),
        ("run_scenario(cache=bytes)", reads(lambda: testbed.run_scenario(MM, cache=os.fsencode(CACHE)))),
        ("load_scenario(np.str_)", reads(lambda: testbed.load_scenario(np.str_(MM)))),
        ("load_scenario(own PathLike)", reads(lambda: testbed.load_scenario(_MyPath(mm_file)))),
        ("read_measured(own PathLike)", reads(lambda: testbed.read_measured(_MyPath(h5())))),
        ("read_measured(bytes)", reads(lambda: testbed.read_measured(os.fsencode(h5())))),
        ("read_measured(fs=np.float64)", reads(lambda: testbed.read_measured(h5(), fs=np.float64(100.0)))),
        ("read_measured(fs=np.int64)", reads(lambda: testbed.read_measured(h5(), fs=np.int64(100)))),
        ("read_measured(fs=np.float32 NaN)", reads(lambda: testbed.read_measured(h5(), fs=np.float32("nan")))),
        ("read_measured(fs=np.bool_)", reads(lambda: testbed.read_measured(h5(), fs=np.bool_(True)))),
        ("identify_file(own PathLike)", reads(lambda: testbed.identify_file(
            _MyPath(h5()), scenario=MM))),
        ("identify_file(scenario=np.str_)", reads(lambda: testbed.identify_file(h5(), scenario=np.str_(MM)))),
        ("identify_file(params= a generator of pairs)", reads(lambda: testbed.identify_file(
            h5(), scenario=MM, params=((k, v) for k, v in [("degree", 3)])))),
        ("identify_file(prior= numpy values)", reads(lambda: testbed.identify_file(
            h5(), scenario=MM, prior={"Km": np.float32(0.3)}))),
        ("list_scenarios(directory=own PathLike)", reads(lambda: testbed.list_scenarios(directory=_MyPath(SCENARIO_DIR)))),
        ("list_scenarios(directory=bytes)", reads(lambda: testbed.list_scenarios(directory=os.fsencode(SCENARIO_DIR)))),
        ("load_plugins(a generator)", reads(lambda: testbed.load_plugins(p for p in []))),
        ("load_plugins(a tuple of Paths)", reads(lambda: testbed.load_plugins((work / "none.py",)))),
        ("load_plugins(one Path, not a list)", reads(lambda: testbed.load_plugins(work / "none.py"))),
        ("load_study(own PathLike)", reads(lambda: testbed.load_study(_MyPath(study_text())))),
        ("load_study(seeds np.int64 as text)", reads(lambda: testbed.load_study(study_text(seeds="[9223372036854775807]")))),
        ("load_study(noise at 1 ulp below 0)", reads(lambda: testbed.load_study(study_text(noise="[-5e-324]")))),
        ("read_results(own PathLike)", reads(lambda: testbed.read_results(_MyPath(work / "none.parquet")))),
        ("scenario_from_dict(numpy values)", reads(lambda: testbed.scenario_from_dict(
            {"scenario": {"name": "x", "rig": MM, "seed": np.int64(3)},
             "rig": {"Km": np.float64(0.3), "Vmax": np.float32(1.5)},
             "noise": {"rms_percent": np.float16(0.0)}}))),
        ("scenario_from_dict(a tuple for tags)", reads(lambda: testbed.scenario_from_dict(
            {"scenario": {"name": "x", "rig": MM, "tags": ("a", "b")}}))),
        ("scenario_from_dict(np.bool_ flag)", reads(lambda: testbed.scenario_from_dict(
            {"scenario": {"name": "x", "rig": MM}, "noise": {"rms_percent": np.bool_(True)}}))),
    ]
    return [(f"apiforms {label}", fn) for label, fn in cases]


# ------------------------------------------------------------------ rehashed

def rehashed_cases(work: Path) -> list[tuple[str, object]]:
    import h5py
    import numpy as np

    state: dict = {}
    pristine = work / "pristine"

    def setup():
        if "entry" not in state:
            pristine.mkdir(exist_ok=True)
            state["entry"] = hostile27._mm_entry(pristine)
            out = work / "clean.h5"
            status, _, err = cli_inprocess(["generate", MM, "--no-cache", "-o", str(out)])
            if status != 0:
                raise RuntimeError(err[-300:])
            state["hash"] = hostile27._content_hash(out)
        return state["entry"]

    def attr(name, value):
        def w(p):
            with h5py.File(p, "r+") as f:
                f.attrs[name] = value
        return w

    def halve(p):
        with h5py.File(p, "r+") as f:
            def cut(name, obj):
                if isinstance(obj, h5py.Dataset) and obj.ndim >= 1 and obj.shape[-1] > 10:
                    a = obj[()]
                    del f[name]
                    f.create_dataset(name, data=a[..., : a.shape[-1] // 2])
                    for k, v in obj.attrs.items():
                        f[name].attrs[k] = v
            names = []
            f.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) else None)
            for n in names:
                cut(n, f[n])

    def rename_channel(p):
        with h5py.File(p, "r+") as f:
            def ren(name, obj):
                if isinstance(obj, h5py.Dataset) and "channels" in obj.attrs:
                    ch = [c.decode() if isinstance(c, bytes) else str(c) for c in obj.attrs["channels"]]
                    obj.attrs["channels"] = [c + "_other" for c in ch]
                    return True
                return None
            f.visititems(ren)

    def scale(p):
        with h5py.File(p, "r+") as f:
            def first(name, obj):
                if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f" and obj.size > 3 \
                        and "measured" in name:
                    obj[...] = np.asarray(obj[()]) * 2.0
                    return True
                return None
            f.visititems(first)

    variants = {
        "fs 123": attr("fs", 123.0),
        "half its samples": halve,
        "another rig kind": attr("kind", "structural"),
        "a channel renamed": rename_channel,
        "another format version": attr("format", "sysid-testbed-dataset/1"),
        "another scenario's name": attr("scenario", "cartpole"),
        "another noise seed": attr("seed", 7),
        "its measured samples doubled": scale,
    }

    def case(label):
        def run():
            entry = setup()
            cache = work / f"c_{hostile19._safe(label)}"
            shutil.rmtree(cache, ignore_errors=True)
            shutil.copytree(entry.parent, cache)
            variants[label](cache / entry.name)
            hostile19._rehash(cache / entry.name)
            out = work / f"o_{hostile19._safe(label)}.h5"
            out.unlink(missing_ok=True)
            status, o, err = cli_inprocess(["generate", MM, "--cache", str(cache), "-o", str(out)])
            found = judged(status, o, err)
            if found or status != 0:
                return found
            got = hostile27._content_hash(out)
            if got != state["hash"]:
                return f"generate wrote another dataset than a fresh one ({got[:12]} != {state['hash'][:12]})"
            return None
        return run

    def row_case(label, change):
        def run():
            from testbed.studies.results import write_rows
            res = work / f"r_{hostile19._safe(label)}.parquet"
            res.unlink(missing_ok=True)
            try:
                write_rows(res, [_hostile.results_row(**change)])
            except Exception as e:
                return _one_line(e)
            status, o, err = cli_inprocess(["summary", str(res)])
            found = judged(status, o, err)
            if found:
                return f"summary: {found}"
            if status == 0 and ("PASS" in o or " 1/1" in o or "1 passed" in o):
                return f"summary shows a pass: {o.strip()[-200:]!r}"
            rep = work / f"rep_{hostile19._safe(label)}"
            status, o2, err = cli_inprocess(["report", str(res), "-o", str(rep)])
            found = judged(status, o2, err)
            if found:
                return f"report: {found}"
            md = rep / "report.md"
            if status == 0 and md.exists() and "1 passed" in md.read_text():
                return "report counts the cell as passed"
            return None
        return run

    cases = [(f"rehashed cache entry: {label}", case(label)) for label in variants]
    cases += [(f"rehashed row: {label}", row_case(label, change)) for label, change in [
        ("passed with a NaN score", {"coef_error": float("nan")}),
        ("passed with status error", {"status": "error", "error": "boom"}),
        ("passed with an unknown status", {"status": "maybe"}),
        ("passed with an infinite score", {"coef_error": float("inf")}),
        ("passed with a negative time", {"fit_time": -1.0}),
    ]]
    return cases


# ------------------------------------------------------------------ apiwalk

def apiwalk_cases(work: Path) -> list[tuple[str, object]]:
    """Round 28's walk of the public API (``hostile28.apiwalk_cases``: each parameter of each
    callable given each odd value in turn), with review 28b L8's mend: a ``TypeError`` is set
    aside as the signature's own refusal only when it was raised by the call itself (its
    traceback ends in the calling frame), not when a text like "positional argument" came from
    inside the callable."""
    import inspect

    import testbed
    from testbed.core.errors import TestbedError

    odd = hostile28._odd_values(work)
    state: dict = {}
    skip = {"run_sweep", "TestbedError", "IdentificationError", "ArgumentError", "NotFittedError"}

    def case(name: str, param: str, label: str):
        def run():
            if "v" not in state:
                state["v"] = hostile28._valid_values(work)
            fn = getattr(testbed, name)
            kwargs = {}
            for p in inspect.signature(fn).parameters.values():
                if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
                    continue
                if p.name == param:
                    kwargs[p.name] = odd[label]
                elif p.default is p.empty:
                    given = hostile28._valid_for(name, state["v"])
                    if p.name not in given:
                        return None  # no plain value to give: not tried
                    kwargs[p.name] = given[p.name]
            here = os.getcwd()
            os.chdir(work)
            try:
                fn(**kwargs)
            except TestbedError:
                raise
            except TypeError as e:
                if e.__traceback__ is not None and e.__traceback__.tb_next is None:
                    return None  # the signature's own refusal, raised by the call itself
                raise
            finally:
                os.chdir(here)
            return None
        return run

    cases = []
    for name in testbed.__all__:
        if name in skip or name.startswith("_"):
            continue
        obj = getattr(testbed, name)
        if not callable(obj) or name.startswith("register") or name in ("IDENTIFIERS", "RIGS"):
            continue
        try:
            sig = inspect.signature(obj)
        except (TypeError, ValueError):
            continue
        for p in sig.parameters.values():
            if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD) or p.name in ("self", "cls"):
                continue
            cases += [(f"apiwalk {name}({p.name}={label})", case(name, p.name, label)) for label in odd]
    return cases


# ------------------------------------------------------------------ ownmark

def ownmark_cases(work: Path) -> list[tuple[str, object]]:
    """A file of the user's in the format a command writes, at the path it writes (review 28b
    M2): refused in one line and left byte for byte, or a finding."""
    import io

    def user_png() -> bytes:
        import matplotlib.pyplot as plt

        fig = plt.figure(figsize=(1, 1))
        buf = io.BytesIO()
        fig.savefig(buf, format="png")
        plt.close(fig)
        return buf.getvalue()

    def user_h5(path: Path) -> None:
        import h5py

        with h5py.File(path, "w") as f:
            f.attrs["title"] = "my measurement"
            f["x"] = [1.0, 2.0]

    def case(label: str, name: str, make, argv_of):
        def run():
            src = _sources(work)
            d = work / hostile19._safe(label)
            shutil.rmtree(d, ignore_errors=True)
            d.mkdir()
            target = d / name
            target.parent.mkdir(parents=True, exist_ok=True)
            if callable(make):
                make(target)
            else:
                target.write_bytes(make)
            before = target.read_bytes()
            status, o, err = cli_inprocess(argv_of(d, src))
            found = judged(status, o, err, refuse=True)
            if found:
                return found
            return None if target.read_bytes() == before else "refused, but the user's file changed"
        return run

    cases = [
        ("a user's matplotlib fit_time.png in the report folder", "rep/fit_time.png", lambda p: p.write_bytes(user_png()),
         lambda d, src: ["report", str(src["parquet"]), "-o", str(d / "rep")]),
        ("a user's settings.json given to identify -o", "settings.json", b'{"theme": "dark"}\n',
         lambda d, src: ["identify", str(src["hdf5"]), "--scenario", MM, "-o", str(d / "settings.json")]),
        ("someone's SEP-005 JSON given to export -o", "x.json", b'[{"name": "a", "data": [1, 2], "fs": 10}]',
         lambda d, src: ["export", str(src["hdf5"]), "--format", "sep005", "-o", str(d / "x.json")]),
        ("someone's UFF given to export -o", "x.uff", b"    -1\n   151\nmodel\n    -1\n",
         lambda d, src: ["export", str(src["hdf5"]), "--format", "uff", "-o", str(d / "x.uff")]),
        ("another tool's HDF5 given to generate -o", "x.h5", user_h5,
         lambda d, src: ["generate", MM, "--cache", str(CACHE), "-o", str(d / "x.h5")]),
        ("a dataset cut to its first 300 bytes given to generate -o", "cut.h5",
         lambda p: p.write_bytes(_sources(work)["hdf5"].read_bytes()[:300]),
         lambda d, src: ["generate", MM, "--cache", str(CACHE), "-o", str(d / "cut.h5")]),
    ]
    return [(f"ownmark {label}", case(label, name, make, argv)) for label, name, make, argv in cases]


# ------------------------------------------------------------------ sigint

def _whole(path: Path) -> bool:
    """Whether an output file is complete by its format's end (PNG's IEND chunk, the HTML's
    closing tag, JSON that parses, a UFF's last record delimiter, an HDF5 that opens)."""
    data = path.read_bytes()
    if path.suffix == ".png":
        return data.endswith(b"IEND\xaeB`\x82")
    if path.suffix == ".html":
        return data.rstrip().endswith(b"</html>")
    if path.suffix == ".json":
        try:
            json.loads(data)
        except ValueError:
            return False
        return True
    if path.suffix == ".uff":
        return data.rstrip().endswith(b"-1")
    if path.suffix == ".md":
        return data.endswith(b"\n")
    return True


def sigint_cases(work: Path) -> list[tuple[str, object]]:
    import time

    state: dict = {}

    def setup():
        if "src" not in state:
            src = _sources(work)
            rep = work / "rep0"
            status, _, err = cli_inprocess(["report", str(src["parquet"]), "-o", str(rep)])
            if status != 0:
                raise RuntimeError(err[-300:])
            state["src"], state["rep"] = src, rep
        return state["src"]

    commands = {
        "report over an earlier report": lambda d, src: ["report", str(src["parquet"]), "-o", str(d / "rep")],
        "export uff over an earlier export": lambda d, src: ["export", str(src["hdf5"]), "--format", "uff", "-o", str(d / "x.uff")],
        "export sep005 over an earlier export": lambda d, src: ["export", str(src["hdf5"]), "--format", "sep005", "-o", str(d / "x.json")],
        "identify over an earlier model": lambda d, src: ["identify", str(src["hdf5"]), "--scenario", MM, "-o", str(d / "m.json")],
    }

    def prepare(label: str, d: Path, src: dict) -> None:
        shutil.rmtree(d, ignore_errors=True)
        d.mkdir(parents=True)
        if label.startswith("report"):
            shutil.copytree(state["rep"], d / "rep")
        else:  # the earlier output: the command run once, to completion
            status, _, err = cli_inprocess(commands[label](d, src))
            if status != 0:
                raise RuntimeError(err[-300:])

    def snapshot(d: Path) -> dict[str, bytes]:
        return {str(p.relative_to(d)): p.read_bytes() for p in sorted(d.rglob("*")) if p.is_file()}

    def case(label: str, fraction: float):
        def run():
            src = setup()
            d = work / hostile19._safe(label) / f"{fraction:.2f}"
            if (label, "span") not in state:  # the command's own span, timed once
                prepare(label, d, src)
                t0 = time.perf_counter()
                p = subprocess.run([sys.executable, "-m", "testbed.cli", *commands[label](d, src)],
                                   cwd=d, env=_hostile.ENV, capture_output=True, text=True, timeout=200)
                state[(label, "span")] = time.perf_counter() - t0
                if p.returncode != 0:
                    return f"the uninterrupted command: status {p.returncode}: {p.stderr[-200:]!r}"
                state[(label, "after")] = snapshot(d)
            prepare(label, d, src)
            before = snapshot(d)
            log = d.parent / f"{fraction:.2f}.err"
            with open(log, "w") as err:
                p = subprocess.Popen([sys.executable, "-m", "testbed.cli", *commands[label](d, src)],
                                     cwd=d, env=_hostile.ENV, stdout=subprocess.DEVNULL, stderr=err,
                                     start_new_session=True)
                time.sleep(fraction * state[(label, "span")])
                with contextlib.suppress(ProcessLookupError):
                    os.killpg(p.pid, signal.SIGINT)  # Ctrl-C: the whole foreground group
                try:
                    p.wait(timeout=60)
                except subprocess.TimeoutExpired:
                    os.killpg(p.pid, signal.SIGKILL)
                    p.wait()
                    return "still running 60 s after SIGINT"
            time.sleep(0.2)
            left = hostile27._session_alive(p.pid)
            if left:
                return f"processes left behind: {left}"
            text = log.read_text()
            lines = [ln for ln in text.splitlines() if ln.strip()]
            if "Traceback" in text or p.returncode not in (0, 1, 130):
                return f"status {p.returncode}: {(lines or [''])[-1][:200]!r}"
            if p.returncode == 130 and lines[-1:] != ["error: interrupted"]:
                return f"interrupted, its last line {lines[-1:]!r}"
            now = snapshot(d)
            tmp = [k for k in now if k.rsplit("/", 1)[-1].startswith(".") and k.endswith(".tmp")]
            if tmp:
                return f"temporary files left: {tmp[:3]}"
            for k, data in now.items():
                if data != before.get(k) and not _whole(d / k):
                    return f"{k} left incomplete ({len(data)} bytes)"
            lost = [k for k in before if k not in now]
            if lost:
                return f"earlier outputs removed: {lost[:3]}"
            return None
        return run

    return [(f"sigint {label} at {f:.0%} of its span", case(label, f))
            for label in commands for f in (0.05, 0.2, 0.35, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95)]


FAMILIES = _hostile.families({"truncate": truncate_cases, "edges": edges_cases,
                              "names": names_cases, "envodd": envodd_cases,
                              "plugarray": plugarray_cases, "apiforms": apiforms_cases,
                              "rehashed": rehashed_cases, "ownmark": ownmark_cases,
                              "apiwalk": apiwalk_cases,
                              "sigint": sigint_cases}, TIMEOUT_S)

if __name__ == "__main__":
    sys.exit(_hostile.main(sys.argv[1:], FAMILIES, "hostile29_"))
