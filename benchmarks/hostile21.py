"""Twenty-first malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile21 [family ...]      # all families when none is named

Families (what rounds 1-20 did not try; their families: combos edges roundtrip extends dask
nyquist twice empty serve parts cache kill results study negzero family channels plugins env
full devices longpaths runfolder medians types concurrent index socket entrypoints envvars uff
requests longargs escapes texts tomlbytes bounds studies csvdata numopts cuts priors records
runfolders h5attrs mechunits extremes rates starts directions truncated toml environ api
outputs rlimits runformat conflicts h5links store tomlform studyform h5form uffform cliargs
apiuse csvform apihyper cliparam signals timecol paths storeedit hyperedge leaks):

``h5shape``
    A Michaelis-Menten dataset file (``testbed generate``) whose ``measured`` arrays have a
    storage or shape rounds 17-19 did not try, its content hash made anew: transposed (one
    column of samples), 3-D, a scalar, int16 / uint16, variable-length text, a compound type,
    fixed-length bytes; chunked and gzip- / shuffle-compressed (accepted: the same numbers),
    resizable, fletcher32-checksummed with a byte of the chunk flipped, gzip-compressed with a
    byte of the stream flipped; a declared shape of 2**40 samples (nothing stored: the fill
    value) and a gzip bomb of 5e6 zeros; ``x`` and ``dx`` swapped under their names, ``x``
    renamed, an extra signal, the truth group removed, a dimension scale attached, a unit text
    ``"mm"``.  ``testbed identify``.  A traceback, a hang, anything but one refusal line where a
    refusal is due, or a model that differs from the clean file's for the same numbers, is a
    finding.
``csvcells``
    The Michaelis-Menten record as CSV with one cell in a spelling Python's ``float`` reads but
    a lab's file should not hold, or one it refuses: ``infinity``, ``-Infinity``, ``nan`` in the
    time column, ``NA``, ``#N/A``, ``null``, a hexadecimal float, a value 1e308; and spellings of
    the same numbers (a leading ``+``, padded with blanks, an upper-case exponent, 17
    significant digits): a traceback, a non-finite value fitted, or a model that differs from
    the clean file's for the same numbers is a finding.
``jitter``
    The CSV time column with random jitter of up to 0.1 / 0.5 / 0.8 % of a step (accepted), 2 / 5 /
    30 % (refused: the reader's 1 % tolerance), one stamp 0.9 % and 1.1 % off, a clock 0.5 %
    fast (uniform: accepted, the rate read from it).  A refusal in more than one line, a
    jittered column beyond the tolerance accepted, or a uniform one refused, is a finding.
``paramedge``
    Every bounded numeric hyperparameter of every registered identifier through ``testbed
    identify --param`` just beyond each bound (the next float or integer past it; at an
    excluded bound, the bound itself), and each given as a number with a unit (``"0.1 mm"``):
    on a record of the identifier's kind.  Anything but one refusal line naming the key is a
    finding.
``fitedge``
    The three pysindy peers not in round 20's ``hyperedge`` (``pysindy_sr3``,
    ``pysindy_ensemble``, ``pysindy_weak``) with each numeric hyperparameter at the edges its
    declaration allows, through ``testbed identify --param`` on the stiff beam's record: a
    traceback, an internal error or a hang is a finding (a model or a named failure is not).
``latethreads``
    Round 20's open item (a): a ``--plugin`` identifier whose ``fit`` starts a thread, or a
    pool's worker, that calls ``os._exit(0)`` / ``os._exit(4)`` 0.3-1.5 s after the fit has
    returned (while the testbed scores, draws or writes): ``testbed run`` with and without
    figures, ``identify``, ``sweep --jobs 1``, each a real process.  Status 0 (or the thread's
    code) without the verdict, model or results line is a finding.
``interrupts``
    ``testbed run`` of the stiff beam with a cache of its own (it simulates, fits, scores,
    draws and writes) sent SIGINT or SIGTERM 0.5-12 s after its start, then run again: a
    process left in its session (a zombie whose parent is init aside: init reaps it), a
    traceback, more than one error line, a temporary file left, or a second run without a
    verdict is a finding.

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import json
import math
import shutil
import sys
from pathlib import Path

import numpy as np

try:
    from benchmarks import _hostile, hostile19, hostile20
except ImportError:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks import _hostile, hostile19, hostile20

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 240
CACHE = hostile19.CACHE
MM = hostile19.MM
BEAM = "cantilever_stiff_impact_lsq"
FIVEBAR = "fivebar_multisine"

cli_inprocess = _hostile.cli_inprocess
judged = _hostile.judged
_safe = hostile19._safe
_generated = hostile19._generated
_rehash = hostile19._rehash

#: A record of each identifier kind, for ``identify``.
KIND_RECORD = {"dynamical": MM, "structural": BEAM, "mechanical": FIVEBAR}


def _identify(path: Path, kind: str, method: str, *more: str) -> tuple[int, str, str]:
    return cli_inprocess(["identify", str(path), "--kind", kind, "--method", method, "-o",
                          f"{path}.model.json", *more])


def _equations(path: Path) -> object:
    return json.loads(Path(f"{path}.model.json").read_text()).get("equations")


# ------------------------------------------------------------------ h5shape

def h5shape_cases(work: Path) -> list[tuple[str, object]]:
    import h5py

    def clean_model() -> object:
        src = _generated(work, MM)
        clean = work / "clean.h5"
        if not Path(f"{clean}.model.json").exists():
            shutil.copy(src, clean)
            found = judged(*_identify(clean, "dynamical", "sindy_pi_dynamical"))
            if found:
                raise RuntimeError(f"the clean file: {found}")
        return _equations(clean)

    def replace(name: str, make, **create):
        """``name`` rewritten as ``make(data)`` (its attributes kept), created with ``create``."""
        def edit(f):
            d = f[name]
            attrs, data = dict(d.attrs), d[()]
            del f[name]
            value = make(data)
            new = (f.create_dataset(name, data=value, **create) if value is not None
                   else f.create_dataset(name, **create))
            for k, v in attrs.items():
                new.attrs[k] = v
        return edit

    def flip_stored_byte(name: str):
        """A byte in the middle of ``name``'s first chunk flipped in the file itself (after
        the hash is made)."""
        def after(path: Path):
            with h5py.File(path, "r") as f:
                d = f[name]
                offset = d.id.get_chunk_info(0).byte_offset
                size = d.id.get_chunk_info(0).size
            with open(path, "r+b") as fh:
                fh.seek(offset + size // 2)
                b = fh.read(1)
                fh.seek(offset + size // 2)
                fh.write(bytes([b[0] ^ 0xFF]))
        return after

    def swap(f):
        a, b = f["measured/x"][()], f["measured/dx"][()]
        f["measured/x"][...] = b
        f["measured/dx"][...] = a

    def rename(f):
        f.move("measured/x", "measured/y")

    def extra_signal(f):
        d = f.create_dataset("measured/z", data=f["measured/x"][()] * 2)
        for k, v in f["measured/x"].attrs.items():
            d.attrs[k] = v
        d.attrs["channels"] = ["z"]

    def no_truth(f):
        del f["truth"]

    def dim_scale(f):
        s = f.create_dataset("measured_time", data=np.arange(f["measured/x"].shape[1], dtype=float))
        s.make_scale("t")
        f["measured/x"].dims[1].attach_scale(s)

    def unit_mm(f):
        f["measured/x"].attrs["unit"] = "mm"

    x = "measured/x"
    # label -> (edit, refuse: True / False / None (either, in one line), compare the model with
    # the clean file's when read, a change to the file after the hash is made)
    rows = [
        ("x transposed (samples x 1)", replace(x, lambda a: a.T), True, False),
        ("x 3-D (1 x n x 1)", replace(x, lambda a: a[:, :, None]), True, False),
        ("x a scalar", replace(x, lambda a: a[0, 0]), True, False),
        ("x int16 (x 1000)", replace(x, lambda a: (a * 1000).astype(np.int16)), True, False),
        ("x uint16 (x 1000)", replace(x, lambda a: (a * 1000).astype(np.uint16)), True, False),
        ("x variable-length text", replace(x, lambda a: np.array([[repr(v) for v in a[0]]],
                                                                 dtype=h5py.string_dtype())),
         True, False),
        ("x compound (value, flag)", replace(x, lambda a: np.array(
            [[(v, 0) for v in a[0]]], dtype=[("v", "<f8"), ("flag", "<i1")])), True, False),
        ("x fixed-length bytes", replace(x, lambda a: a.astype("S24")), True, False),
        ("x chunked + gzip + shuffle (the same numbers)",
         replace(x, lambda a: a, chunks=(1, 64), compression="gzip", shuffle=True), False, True),
        ("x resizable (maxshape None)", replace(x, lambda a: a, maxshape=(None, None)), False, True),
        ("x lzf", replace(x, lambda a: a, chunks=(1, 128), compression="lzf"), False, True),
        ("x fletcher32, a stored byte flipped",
         replace(x, lambda a: a, chunks=(1, 128), fletcher32=True), True, False,
         flip_stored_byte(x)),
        ("x gzip, a stored byte flipped",
         replace(x, lambda a: a, chunks=(1, 128), compression="gzip"), True, False,
         flip_stored_byte(x)),
        ("x declared 2**40 samples (fill value)",
         replace(x, lambda a: None, shape=(1, 2**40), dtype="<f8", chunks=(1, 2**16)), True, False),
        ("x a gzip bomb of 5e6 zeros",
         replace(x, lambda a: np.zeros((1, 5_000_000)), chunks=(1, 2**18), compression="gzip"),
         True, False),
        ("x and dx swapped under their names", swap, True, False),
        ("x renamed y", rename, True, False),
        ("an extra signal z = 2 x", extra_signal, True, False),
        ("the truth group removed", no_truth, None, True),
        ("a dimension scale attached to x", dim_scale, True, False),
        ("x's unit 'mm' (a length for a concentration)", unit_mm, None, False),
    ]

    def case(label, edit, refuse, compare, after=None):
        def run():
            equations = clean_model()
            path = work / f"{_safe(label)}.h5"
            shutil.copy(_generated(work, MM), path)
            with h5py.File(path, "r+") as f:
                edit(f)
            _rehash(path)
            if after is not None:
                after(path)
            status, out, err = _identify(path, "dynamical", "sindy_pi_dynamical")
            found = judged(status, out, err, refuse=bool(refuse))
            if found:
                return found
            if refuse is False and status == 2:
                return f"refused: {err.strip()[:200]}"
            if compare and status != 2 and _equations(path) != equations:
                return "read, but its model differs from the clean file's (the same numbers)"
            return None
        return run

    return [(f"h5shape {label}", case(label, *how)) for label, *how in rows]


# ------------------------------------------------------------------ csvcells / jitter

def _mm_record(work: Path) -> tuple[float, np.ndarray, np.ndarray]:
    from testbed.core.dataset import Dataset

    ds = Dataset.load(_generated(work, MM))
    return ds.fs, ds.measured["x"].data[0], ds.measured["dx"].data[0]


def _csv(t, x, dx, fmt=repr) -> str:
    return "time [s],x [mM],dx [mM/s]\n" + "".join(
        f"{fmt(a)},{fmt(b)},{fmt(c)}\n" for a, b, c in zip(t.tolist(), x.tolist(), dx.tolist(),
                                                          strict=True))


def _clean_csv(work: Path) -> Path:
    clean = work / "clean.csv"
    if not Path(f"{clean}.model.json").exists():
        fs, x, dx = _mm_record(work)
        clean.write_text(_csv(np.arange(x.size) / fs, x, dx))
        found = judged(*_identify(clean, "dynamical", "sindy_pi_dynamical"))
        if found:
            raise RuntimeError(f"the clean file: {found}")
    return clean


def csvcells_cases(work: Path) -> list[tuple[str, object]]:
    def cell(row: int, col: int, text: str):
        def make(lines):
            cells = lines[row].split(",")
            cells[col] = text
            lines[row] = ",".join(cells)
            return lines
        return make

    def every(fn):
        def make(lines):
            return lines[:1] + [",".join(fn(c) for c in ln.split(",")) for ln in lines[1:]]
        return make

    def seventeen(c: str) -> str:
        return f"{float(c):.17g}"

    # label -> (edit of the clean file's lines, refuse, compare with the clean model)
    rows = [
        ("x 'infinity' mid-record", cell(300, 1, "infinity"), True, False),
        ("dx '-Infinity' at the end", cell(-1, 2, "-Infinity"), True, False),
        ("x 'inf' in the first row", cell(1, 1, "inf"), True, False),
        ("time 'nan' in one row", cell(200, 0, "nan"), True, False),
        ("x 'NA'", cell(100, 1, "NA"), True, False),
        ("x '#N/A'", cell(100, 1, "#N/A"), True, False),
        ("x 'null'", cell(100, 1, "null"), True, False),
        ("x a hexadecimal float '0x1p-3'", cell(100, 1, "0x1p-3"), True, False),
        ("x '1e308' in one row", cell(100, 1, "1e308"), None, False),
        ("x '1e400' (overflows to inf)", cell(100, 1, "1e400"), True, False),
        ("every number with a leading '+' where positive (the same numbers)",
         every(lambda c: c if c.startswith("-") else "+" + c), False, True),
        ("every number padded with blanks (the same numbers)", every(lambda c: f"  {c} "),
         False, True),
        ("upper-case exponents (the same numbers)", every(lambda c: c.replace("e", "E")), False, True),
        ("17 significant digits (the same numbers)", every(seventeen), False, True),
    ]

    def case(label, edit, refuse, compare):
        def run():
            clean = _clean_csv(work)
            path = work / f"{_safe(label)}.csv"
            lines = clean.read_text().splitlines()
            path.write_text("\n".join(edit(lines)) + "\n")
            status, out, err = _identify(path, "dynamical", "sindy_pi_dynamical")
            found = judged(status, out, err, refuse=bool(refuse))
            if found:
                return found
            if refuse is False and status == 2:
                return f"refused: {err.strip()[:200]}"
            if compare and _equations(path) != _equations(clean):
                return "read, but its model differs from the clean file's (the same numbers)"
            return None
        return run

    return [(f"csvcells {label}", case(label, *how)) for label, *how in rows]


def jitter_cases(work: Path) -> list[tuple[str, object]]:
    def jittered(share: float):
        def times(n: int, fs: float) -> np.ndarray:
            rng = np.random.default_rng(21)
            step = np.full(n - 1, 1 / fs) * (1 + share * rng.uniform(-1, 1, n - 1))
            return np.r_[0.0, np.cumsum(step)]
        return times

    def one_off(share: float):
        def times(n: int, fs: float) -> np.ndarray:
            t = np.arange(n) / fs
            t[n // 2] += share / fs
            return t
        return times

    def fast_clock(share: float):
        def times(n: int, fs: float) -> np.ndarray:
            return np.arange(n) / (fs * (1 + share))
        return times

    # share of a step: the reader's tolerance is 1 % of the median step against each step, and
    # a stamp off by s moves two steps by s: one stamp off by 0.9 % keeps both within 1 %
    rows = [(f"random jitter of up to {100 * s:g} % of a step", jittered(s), s > 0.01)
            for s in (0.001, 0.005, 0.008, 0.02, 0.05, 0.3)]  # each step off by up to s: 0.8 %
    # stays within the 1 % (the median moves by less than 0.2 %), 2 % exceeds it
    rows += [("one stamp 0.9 % of a step off", one_off(0.009), False),
             ("one stamp 1.1 % of a step off", one_off(0.011), True),
             ("a clock 0.5 % fast (uniform)", fast_clock(0.005), False)]

    def case(label, times, refuse):
        def run():
            fs, x, dx = _mm_record(work)
            path = work / f"{_safe(label)}.csv"
            path.write_text(_csv(times(x.size, fs), x, dx))
            status, out, err = _identify(path, "dynamical", "sindy_pi_dynamical")
            found = judged(status, out, err, refuse=refuse)
            if found:
                return found
            if not refuse and status == 2:
                return f"refused: {err.strip()[:200]}"
            return None
        return run

    return [(f"jitter {label}", case(label, *how)) for label, *how in rows]


# ------------------------------------------------------------------ paramedge / fitedge

def _beyond(field) -> list:
    """Values just past a numeric field's bounds (an excluded bound itself)."""
    out = []
    for bound, inclusive, sign in ((field.min, field.min_inclusive, -1),
                                   (field.max, field.max_inclusive, 1)):
        if bound is None:
            continue
        if not inclusive:
            out.append(field.type(bound))
        elif field.type is float:
            out.append(float(np.nextafter(float(bound), sign * math.inf)))
        else:
            out.append(int(bound) + sign)
    return out


def _param_text(v) -> str:
    return repr(float(v)) if isinstance(v, float) else str(v)


def paramedge_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.plugins import IDENTIFIERS

    def case(method: str, kind: str, key: str, text: str):
        def run():
            path = _generated(work, KIND_RECORD[kind])
            status, out, err = _identify(path, kind, method, "--param", f"{key}={text}")
            found = judged(status, out, err, refuse=True)
            if found:
                return found
            if key not in err:
                return f"refused without naming {key!r}: {err.strip()[:200]}"
            return None
        return run

    out = []
    for method in IDENTIFIERS.names():
        cls = IDENTIFIERS.get(method)
        kind = cls.kind
        if kind not in KIND_RECORD:
            continue
        for key, field in cls.declared_hyperparameters().items():
            if field.type not in (int, float):
                continue
            for v in _beyond(field):
                out.append((f"paramedge {method} {key}={_param_text(v)}",
                            case(method, kind, key, _param_text(v))))
            if field.min is not None or field.max is not None:
                out.append((f"paramedge {method} {key}='0.1 mm'",
                            case(method, kind, key, '"0.1 mm"')))
    return out


FIT_EDGE = ("pysindy_sr3", "pysindy_ensemble", "pysindy_weak")


def fitedge_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.plugins import IDENTIFIERS

    def case(method: str, key: str, value):
        def run():
            path = _generated(work, BEAM)
            return judged(*_identify(path, "structural", method, "--param",
                                     f"{key}={_param_text(value)}"))
        return run

    out = []
    for method in FIT_EDGE:
        for key, field in IDENTIFIERS.get(method).declared_hyperparameters().items():
            if field.type in (int, float):
                out += [(f"fitedge {method} {key}={_param_text(v)}", case(method, key, v))
                        for v in hostile20.edge_values(field)]
    return out


# ------------------------------------------------------------------ latethreads

_LATE_FIT = """import os, threading, time
        def _late():
            time.sleep(DELAY)
            os._exit(CODE)
        threading.Thread(target=_late, daemon=True).start()"""

_LATE_POOL = """import os, time
        from concurrent.futures import ThreadPoolExecutor
        global _POOL
        _POOL = ThreadPoolExecutor(1)
        _POOL.submit(lambda: (time.sleep(DELAY), os._exit(CODE)))"""


def latethreads_cases(work: Path) -> list[tuple[str, object]]:
    """Round 20's open item (a): a plugin's ``fit`` starts a thread (or a pool's worker) that
    calls ``os._exit`` after the fit has returned, while the testbed scores, draws or writes:
    ``testbed run`` (with and without figures), ``testbed identify``, ``testbed sweep --jobs
    1``, each a real process.  Status 0 (or the thread's code) without the verdict or the model,
    a traceback, or a status other than 0 / 1 / 2 is a finding."""
    from testbed.pipeline.scenario import SCENARIO_DIR

    def plugin(name: str, body: str, delay: float, code: int) -> tuple[Path, Path]:
        path = work / f"{name}.py"
        path.write_text(hostile19._PLUGIN.replace("NAME", name).replace("#AT_IMPORT", "")
                        .replace("#IN_FIT", body.replace("DELAY", repr(delay))
                                 .replace("CODE", str(code)))
                        .replace("#SIMULATE", hostile19._SIMULATE))
        scen = hostile19._write(work / f"{name}.toml",
                                f'[scenario]\nname = "{name}"\nextends = '
                                f'"{SCENARIO_DIR / (BEAM + ".toml")}"\n'
                                f'[identify]\nmethod = "{name}"\n')
        return path, scen

    def case(k: int, command: str, body: str, delay: float, code: int):
        def run():
            name = f"h21_late{k}"
            plug, scen = plugin(name, body, delay, code)
            if command == "identify":
                data = _generated(work, BEAM)
                argv = ["identify", str(data), "--kind", "structural", "--method", name,
                        "--plugin", str(plug), "-o", str(work / f"{name}.model.json")]
                done = "model written to"
            elif command == "sweep":
                study = hostile19._write(work / f"{name}_study.toml",
                                         f'[study]\nname = "{name}_study"\nscenarios = ["{scen}"]\n'
                                         f'noise = [0.0]\nseeds = [0, 1]\nidentifiers = ["{name}"]\n'
                                         f'plugins = ["{plug}"]\n')
                argv = ["sweep", str(study), "--results", str(work / f"{name}.parquet"),
                        "--jobs", "1", "--cache", str(CACHE)]
                done = "results: "
            else:
                argv = ["run", str(scen), "--plugin", str(plug), "-o", str(work / "runs"),
                        "--cache", str(CACHE)] + (["--no-figures"] if command == "run" else [])
                done = "run written to"
            p = _hostile.testbed_cli(argv, work, TIMEOUT_S)
            found = _hostile.cli_finding(p)
            if found:
                return found
            if done not in p.stdout:
                return (f"status {p.returncode} without the verdict or model ({done!r} not in "
                        f"its output): {(p.stdout.strip().splitlines() or [''])[-1][:160]!r}")
            return None
        return run

    rows = [(cmd, body, d, c) for cmd in ("run", "run+figures", "identify", "sweep")
            for body in (_LATE_FIT, _LATE_POOL) for d, c in ((0.3, 0), (1.5, 0), (0.6, 4))]
    return [(f"latethreads {cmd} {'pool' if body is _LATE_POOL else 'thread'} os._exit({c}) "
             f"{d} s after the fit", case(k, cmd, body, d, c))
            for k, (cmd, body, d, c) in enumerate(rows)]


# ------------------------------------------------------------------ interrupts

def interrupts_cases(work: Path) -> list[tuple[str, object]]:
    """``testbed run`` of the stiff beam with a cache of its own (so it simulates, fits,
    scores, draws and writes) interrupted by SIGINT or SIGTERM at 0.5-12 s, then run again.
    A process left in the command's session, a traceback, a status other than 0 / 1 / 2 /
    130 / 143, more than one error line, a temporary file left in the cache or the runs
    folder, or a second run without a verdict, is a finding."""
    import contextlib
    import os
    import signal
    import subprocess
    import time

    def left_in_session(sid: int) -> list[str]:
        """Processes of the session ``sid`` still there within 5 s, but zombies whose parent
        is init (its to reap, at its own pace: the command that forked them has ended)."""
        for _ in range(10):
            out = subprocess.run(["ps", "-eo", "pid=,ppid=,sid=,stat=,args="], capture_output=True,
                                 text=True).stdout
            left = [ln.strip() for ln in out.splitlines() if len(ln.split()) >= 4
                    and ln.split()[2] == str(sid)
                    and not (ln.split()[3].startswith("Z") and ln.split()[1] == "1")]
            if not left:
                return []
            time.sleep(0.5)
        return left

    def temporaries(folder: Path) -> list[str]:
        return [str(p.relative_to(folder)) for p in folder.rglob("*")
                if p.is_file() and (".tmp" in p.name or p.name.startswith((".", "tmp")))
                and p.name not in (".lock",)]

    def case(sig: int, delay: float):
        def run():
            d = work / f"{signal.Signals(sig).name}_{delay}"
            d.mkdir(exist_ok=True)
            argv = [sys.executable, "-m", "testbed.cli", "run", BEAM, "-o", str(d / "runs"),
                    "--cache", str(d / "cache")]
            p = subprocess.Popen(argv, cwd=d, env=_hostile.ENV, stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True, start_new_session=True)
            time.sleep(delay)
            p.send_signal(sig)
            try:
                _, err = p.communicate(timeout=60)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.communicate()
                return f"{signal.Signals(sig).name} at {delay} s: still running 60 s later"
            time.sleep(1.0)
            left = left_in_session(p.pid)
            if left:
                for ln in left:
                    with contextlib.suppress(ProcessLookupError):
                        os.kill(int(ln.split()[0]), signal.SIGKILL)
                return f"processes left in its session: {left[:3]}"
            lines = [ln for ln in err.splitlines() if ln.strip()]
            if "Traceback" in err or "internal error" in err:
                return f"status {p.returncode}: {(lines or [''])[-1][:200]}"
            if p.returncode not in (0, 1, 2, 130, 143, -sig):
                return f"status {p.returncode}: {(lines or [''])[-1][:200]}"
            errors = [ln for ln in lines if ln.startswith("error")]
            if p.returncode in (130, 143, -sig, 2) and len(errors) > 1:
                return f"interrupted in {len(lines)} lines: {err[:200]!r}"
            temps = [t for f in (d / "cache", d / "runs") if f.exists() for t in temporaries(f)]
            if temps:
                return f"temporary files left: {temps[:4]}"
            again = _hostile.testbed_cli(argv[3:], d, TIMEOUT_S)
            found = _hostile.cli_finding(again)
            if found:
                return f"run again: {found}"
            if "run written to" not in again.stdout:
                return f"run again: status {again.returncode} without a verdict"
            return None
        return run

    return [(f"interrupts {signal.Signals(sig).name} at {delay} s", case(sig, delay))
            for sig in (signal.SIGINT, signal.SIGTERM) for delay in (0.5, 1.5, 3.0, 5.0, 8.0, 12.0)]


# ------------------------------------------------------------------ main

FAMILIES = _hostile.families({
    "h5shape": h5shape_cases,
    "csvcells": csvcells_cases,
    "jitter": jitter_cases,
    "paramedge": paramedge_cases,
    "fitedge": fitedge_cases,
    "latethreads": latethreads_cases,
    "interrupts": interrupts_cases,
}, TIMEOUT_S)


def main(argv: list[str]) -> int:
    return _hostile.main(argv, FAMILIES, "hostile21-")


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
