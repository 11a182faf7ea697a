"""Twenty-fifth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile25 [family ...]      # all families when none is named

Families (what rounds 1-24 did not try; their families are listed in ``hostile21.py`` to
``hostile24.py``):

``sepkeys``
    A SEP-005 record (the Michaelis-Menten dataset exported) whose optional and required keys
    hold values of a kind no exporter writes, one key at a time: ``fs`` an integer of 400
    digits; ``time`` as texts of numbers, booleans, ``null`` entries; ``direction`` a float,
    a boolean, an unknown word, a list, a table, ``0``, ``"+z"``; ``node`` an integer of 400
    digits; ``quantity``, ``group`` and ``content_hash`` of another kind (not read: accepted,
    the clean model), an unknown key (accepted).  ``testbed identify``.  A traceback, anything
    but one refusal line for a value that cannot be read, a value of the wrong kind dropped in
    silence, or an accepted file read to another model than the clean file's, is a finding.
``optgrid``
    Every option and positional of the commands that names a thing (``generate`` / ``run``
    scenario, ``sweep`` study, ``summary`` results, ``export`` dataset, ``report`` source and
    ``--runs``, ``identify --method`` / ``--scenario`` / ``--units``, ``family write
    --family``, ``runs ls`` scenario, ``cache ls --cache``, ``list --plugin``) given each value
    of one table: empty, a blank, ``-1``, ``nan``, ``inf``, ``1e308``, a folder, a text holding a
    newline, Unicode, 300 characters, ``-`` and ``/dev/null``.  A traceback, an internal error,
    a refusal in more than one line, or a value that names nothing accepted with status 0, is
    a finding.
``serveopts``
    ``testbed serve --idle`` and ``--warm-up`` with the same table (real processes, a socket of
    the round's own): anything but one refusal line for a value that is not a number of
    seconds or a scenario is a finding.
``tomllists``
    The list-valued scenario keys (``[scenario] tags``, a beam's ``[rig] sensors``, the
    cart-pole's ``[identify] library``) given an empty list where items are needed, a nested
    list, a list of tables, of booleans, of texts where numbers are, of numbers where texts
    are, mixed items, NaN / inf / 1e308 items, an item twice, 10,000 items: loaded
    (:func:`testbed.pipeline.scenario.load_scenario`).  A traceback, anything but one refusal
    line naming the key, or a value of the wrong kind accepted, is a finding.

``edgesamples``
    A non-finite or overflowing sample (NaN, +inf, -inf, 1e308) at the *last* sample only (rounds
    17-23 tried the first, the middle and the Michaelis-Menten dataset's end), and at the first
    and the last together: the Michaelis-Menten record as CSV (``x`` and the time column), the
    stiff beam's UFF58 export (an acceleration and the force, written in ASCII with the value's
    text: pyuff's writer turns NaN into 0) and SEP-005 export, and the beam's dataset file
    (rehashed); and every UFF58 record cut to two or three samples.  ``testbed
    identify``.  A traceback, anything but one refusal line, or a model fitted with status 0, is
    a finding.

``measapi``
    The Python API's :class:`~testbed.core.measurement.Measurement` (what a user builds by hand
    or edits with ``dataclasses.replace``) fitted by ``ls_sindy``: a declared prior
    (``reduced_mass_trace``, the one it reads) of an integer of 400 digits, a text ``"0.7"``,
    ``True``, ``[0.7]``, ``None``, a complex, 5e-324, 1e-300 and 1e308 kg (the command line's
    ``--prior`` refuses each); a prior the identifier does not read as a text; ``x`` and ``u`` as
    masked arrays with a masked sample; a channel or an input name holding a newline or an
    ESC.  A raw exception, or a fit of a value the command line refuses, is a finding.

``fittedapi``
    A fitted structural model's ``score``, ``predict_acceleration`` and ``simulate`` (``ls_sindy``
    and ``sgd_sindy`` on the stiff beam's lab record) given arguments of the right type but the
    wrong extent: inputs of two rows for a model of one, ``free_start`` at or past the record's
    end, a record of one sample, a cross-validation window that ends before the impact's
    end; ``simulate``'s ``u`` of five rows or seven samples for two times, ``xd0`` of two
    channels, NaN, None or a text; and a mechanical (``sindy_pi`` on the cart-pole) and a
    dynamical model's (``sindy_pi_dynamical``) ``simulate`` given ``x0`` of a channel more,
    ``u`` of other rows or length, NaN or a text, ``xd0`` of a channel more, NaN or None,
    ``t`` of one sample or spanning 1e308 s.  A raw exception, or a number returned for a window that
    holds no sample to score, is a finding.

``dsapi``
    The Python API's :class:`~testbed.core.dataset.Dataset` and ``Signal`` built by hand from the
    Michaelis-Menten record, then :func:`testbed.measure`: ``fs`` a text, 10**400 or True, a prior
    as a text, a signal's samples masked (one sample), complex or boolean, its
    channels one text instead of a tuple, its unit 5, a measured table of bare arrays or
    empty, a signal named ``x/y``, NaN at the last sample.  A raw exception, or a value of the
    wrong kind measured in silence (a masked sample read as its value, a complex one's imaginary
    part dropped), is a finding.

``fileapi``
    :func:`testbed.identify_file` (the Python API's ``testbed identify``) given ``params`` as a
    list, ``prior`` as a list of pairs, ``phase`` a number, ``kind`` a number, ``method`` a
    number or empty: a raw exception, or a value read as something else (a list of pairs as
    prior keys), is a finding.

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import copy
import hashlib
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

try:
    from benchmarks import _hostile, hostile19, hostile24
except ImportError:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks import _hostile, hostile19, hostile24

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 240
MM = hostile19.MM

cli_inprocess = _hostile.cli_inprocess
judged = _hostile.judged
_generated = hostile19._generated
_safe = hostile19._safe
_model = hostile24._model
_same = hostile24._same


# ------------------------------------------------------------------ sepkeys

def sepkeys_cases(work: Path) -> list[tuple[str, object]]:
    def exported() -> Path:
        out = work / "mm.json"
        if not out.exists():
            status, _, err = cli_inprocess(["export", str(_generated(work, MM)), "--format", "sep005",
                                            "-o", str(out)])
            if status != 0:
                raise RuntimeError(f"export: {err[-300:]}")
        return out

    def identify(path: Path) -> tuple[int, str, str]:
        return cli_inprocess(["identify", str(path), "--scenario", MM, "-o", f"{path}.model.json"])

    def clean_model() -> dict | None:
        clean = work / "clean.json"
        if not clean.exists():
            shutil.copy(exported(), clean)
            found = judged(*identify(clean))
            if found:
                raise RuntimeError(f"clean file: {found}")
        return _model(Path(f"{clean}.model.json"))

    def case(label: str, key: str, value, expect: str, channel: int = 0):
        """``expect``: "refuse" or "same" (the clean file's model)."""
        def run():
            doc = json.loads(exported().read_text())
            c = doc[channel]
            if value is _DROP:
                c.pop(key, None)
            else:
                c[key] = value(len(c["data"]), c) if callable(value) else copy.deepcopy(value)
            path = work / f"{_safe(label)}.json"
            path.write_text(json.dumps(doc))
            status, out, err = identify(path)
            found = judged(status, out, err, refuse=expect == "refuse")
            if found:
                return found
            if expect == "same":
                if status == 2:
                    return f"refused an equivalent file: {err.strip()[:200]!r}"
                if not _same(_model(Path(f"{path}.model.json")), clean_model(), 1e-9):
                    return "read to another model than the clean file's"
            return None
        return run

    big = 10 ** 400

    def times(fn):
        return lambda n, c: [fn(k, c["fs"]) for k in range(n)]

    table = [
        ("fs an integer of 400 digits", "fs", big, "refuse"),
        ("fs 2**1024 (one past float64)", "fs", 2 ** 1024, "refuse"),
        ("fs the integer 100 (accepted)", "fs", 100, "same"),
        ("time as texts of numbers", "time", times(lambda k, fs: repr(k / fs)), "refuse"),
        ("time as booleans", "time", times(lambda k, fs: bool(k % 2)), "refuse"),
        ("time with a null entry", "time", lambda n, c: [None] + [k / c["fs"] for k in range(1, n)],
         "refuse"),
        ("time of integers 400 digits long", "time", lambda n, c: [big + k for k in range(n)],
         "refuse"),
        ("time as a table", "time", {"start": 0.0}, "refuse"),
        ("time as one number", "time", 0.0, "refuse"),
        ("time the rate's own stamps (accepted)",
         "time", times(lambda k, fs: k / fs), "same"),
        ("direction the float 3.0", "direction", 3.0, "refuse"),
        ("direction true", "direction", True, "refuse"),
        ("direction an unknown word", "direction", "up", "refuse"),
        ("direction a list [3]", "direction", [3], "refuse"),
        ("direction a table", "direction", {"axis": "Z"}, "refuse"),
        ("direction an empty text", "direction", "", "refuse"),
        ("direction Z with a trailing word", "direction", "+Z axis", "refuse"),
        ("direction an integer of 400 digits", "direction", big, "refuse"),
        ("direction +z lower case (accepted)", "direction", "+z", "same"),
        ("direction 3 (accepted: +Z)", "direction", 3, "same"),
        ("direction null (accepted: none)", "direction", None, "same"),
        ("direction dropped (accepted: none)", "direction", _DROP, "same"),
        ("node an integer of 400 digits (an integer >= 1: accepted)", "node", big, "same"),
        ("node null (accepted: none)", "node", None, "same"),
        ("position_m an integer of 400 digits", "position_m", big, "refuse"),
        ("position_m a list", "position_m", [0.1], "refuse"),
        ("unit_str a text with a trailing newline (read past as a blank)", "unit_str", "mM/s\n",
         "same"),
        ("unit_str a NUL", "unit_str", "mM/s\x00", "refuse"),
        ("name with a trailing newline", "name", "dx/dx\n", "refuse"),
        ("name an integer", "name", 5, "refuse"),
        ("data an empty list", "data", [], "refuse"),
        ("data a table", "data", {"0": 1.0}, "refuse"),
        ("data of integers 400 digits long", "data", lambda n, c: [big] * n, "refuse"),
        ("data with a null sample", "data", lambda n, c: [None, *c["data"][1:]], "refuse"),
        ("data with a nested sample", "data", lambda n, c: [[c["data"][0]], *c["data"][1:]], "refuse"),
        ("quantity a number (not read: accepted)", "quantity", 5, "same"),
        ("quantity an unknown word (not read: accepted)", "quantity", "nonsense", "same"),
        ("group a number (not read: accepted)", "group", 1, "same"),
        ("content_hash of other data (not read: accepted)", "content_hash", "deadbeef", "same"),
        ("an unknown key (accepted)", "gain", 2.0, "same"),
    ]
    return [(f"sepkeys {label}", case(label, key, value, expect)) for label, key, value, expect in table]


class _Drop:
    """The key removed from the channel."""


_DROP = _Drop()


# ------------------------------------------------------------------ optgrid

def _values(work: Path) -> dict[str, str]:
    folder = work / "a_folder"
    folder.mkdir(exist_ok=True)
    return {"empty": "", "blank": " ", "-1": "-1", "nan": "nan", "inf": "inf", "1e308": "1e308",
            "a folder": str(folder), "a newline": "a\nb", "unicode": "\u00fc\u2713\u540d",
            "300 chars": "x" * 300, "dash": "-", "/dev/null": "/dev/null"}


def optgrid_cases(work: Path) -> list[tuple[str, object]]:
    values = _values(work)
    study = ROOT / "studies" / "families.toml"
    runs = work / "runs"
    runs.mkdir(exist_ok=True)

    def data() -> str:
        return str(_generated(work, MM))

    # option -> (argv of the value, what is allowed: "refuse" (the value names nothing that
    # exists) or "any" (a result or one refusal line))
    grid = {
        "generate SCENARIO": (lambda v: ["generate", v, "-o", str(work / "g.h5")], "refuse"),
        "run SCENARIO": (lambda v: ["run", v, "--no-figures", "-o", str(runs)], "refuse"),
        "sweep STUDY": (lambda v: ["sweep", v, "--results", str(work / "r.parquet")], "refuse"),
        "summary RESULTS": (lambda v: ["summary", v], "refuse"),
        "export DATASET": (lambda v: ["export", v, "--format", "uff", "-o", str(work / "e.uff")],
                           "refuse"),
        "report SOURCE": (lambda v: ["report", v, "-o", str(work / "rep"), "--runs", str(runs)],
                          "refuse"),
        "report --runs": (lambda v: ["report", MM, "-o", str(work / "rep"), "--runs", v], "refuse"),
        "identify --method": (lambda v: ["identify", data(), "--kind", "dynamical", "--method", v,
                                         "-o", str(work / "m.json")], "refuse"),
        "identify --scenario": (lambda v: ["identify", data(), "--scenario", v,
                                           "-o", str(work / "m.json")], "refuse"),
        "identify --units": (lambda v: ["identify", data(), "--scenario", MM, "--units", v,
                                        "-o", str(work / "m.json")], "refuse"),
        "family write --family": (lambda v: ["family", "write", str(study), "--family", v,
                                             "-o", str(work / "fam")], "refuse"),
        "runs ls SCENARIO": (lambda v: ["runs", "ls", v, "-o", str(runs)], "any"),
        "cache ls --cache": (lambda v: ["cache", "ls", "--cache", v], "any"),
        "list --plugin": (lambda v: ["list", "--plugin", v], "refuse"),
    }

    def case(argv, expect):
        def run():
            status, out, err = cli_inprocess(argv)
            found = judged(status, out, err, refuse=expect == "refuse")
            if found:
                return found
            if status == 0 and argv[:2] == ["runs", "ls"] and "no runs of" not in err:
                # a scenario nobody ran listed as an empty table in silence: a typo unseen
                return f"status 0 listing nothing, saying nothing: {out.strip()[-160:]!r}"
            return None
        return run

    return [(f"optgrid {opt} = {label}", case(make(v), expect))
            for opt, (make, expect) in grid.items() for label, v in values.items()]


# ------------------------------------------------------------------ serveopts

def serveopts_cases(work: Path) -> list[tuple[str, object]]:
    values = _values(work)
    env = {**_hostile.ENV, "TESTBED_SERVER_SOCKET": str(work / "s.sock")}
    env.pop("TESTBED_NO_SERVER", None)

    def case(argv):
        def run():
            try:
                p = subprocess.run([sys.executable, "-m", "testbed.cli", *argv], cwd=work, env=env,
                                   capture_output=True, text=True, timeout=90,
                                   stdin=subprocess.DEVNULL)
            except subprocess.TimeoutExpired:
                return "still serving after 90 s (a value that is not allowed accepted)"
            found = _hostile.cli_finding(p)
            if found:
                return found
            return None if p.returncode == 2 else f"accepted with status {p.returncode}"
        return run

    cases = [(f"serveopts --idle {label}", case(["serve", "--idle", v, "--warm-up", "none"]))
             for label, v in values.items()]
    cases += [(f"serveopts --warm-up {label}", case(["serve", "--idle", "1", "--warm-up", v]))
              for label, v in values.items() if label != "empty"]  # (round 11's)
    return cases


# ------------------------------------------------------------------ tomllists

def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "nan" if v != v else ("inf" if v == float("inf") else "-inf" if v == -float("inf")
                                     else repr(v))
    if isinstance(v, (int, str)):
        return json.dumps(v) if isinstance(v, str) else str(v)
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return "{" + ", ".join(f"{json.dumps(k)} = {_toml_value(x)}" for k, x in v.items()) + "}"


def _toml(raw: dict, prefix: str = "") -> str:
    """A table of scalars, lists and tables as TOML text (no TOML writer is installed)."""
    lines = [f"{json.dumps(k)} = {_toml_value(v)}" for k, v in raw.items() if not isinstance(v, dict)]
    text = (f"[{prefix}]\n" if prefix and lines else "") + "".join(ln + "\n" for ln in lines)
    for k, v in raw.items():
        if isinstance(v, dict):
            text += _toml(v, f"{prefix}.{json.dumps(k)}" if prefix else json.dumps(k))
    return text


def tomllists_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml

    def case(base: str, table: str, key: str, value, expect: str):
        def run():
            from testbed.pipeline.scenario import load_scenario

            raw = _read_toml(SCENARIO_DIR / f"{base}.toml")
            raw.setdefault(table, {})[key] = value
            # a name that holds no key (the refusal must name the key, not the file)
            path = work / f"t{hashlib.sha1(repr((base, table, key, value)).encode()).hexdigest()[:12]}.toml"
            raw["scenario"]["name"] = path.stem
            path.write_text(_toml(raw))
            try:
                load_scenario(path)
            except Exception as e:
                from testbed.core.errors import TestbedError
                if isinstance(e, TestbedError) and key not in str(e):
                    return f"refused naming no key {key!r}: {str(e)[:200]!r}"
                raise
            return "accepted" if expect == "refuse" else None
        return run

    beam, cart = "cantilever_stiff_impact", "cartpole"
    lib = _read_toml(SCENARIO_DIR / f"{cart}.toml")["identify"]["library"]
    table = [
        (beam, "rig", "sensors", [], "accept"),  # (the rig's default: L/3, 2L/3, L)
        (beam, "rig", "sensors", [[0.2, 0.4]], "refuse"),
        (beam, "rig", "sensors", [{"x": 0.2}], "refuse"),
        (beam, "rig", "sensors", [True, False], "refuse"),
        (beam, "rig", "sensors", ["0.2", "0.4"], "refuse"),
        (beam, "rig", "sensors", [0.2, "0.4"], "refuse"),
        (beam, "rig", "sensors", [0.2, float("nan")], "refuse"),
        (beam, "rig", "sensors", [0.2, float("inf")], "refuse"),
        (beam, "rig", "sensors", [0.2, 1e308], "refuse"),
        (beam, "rig", "sensors", [0.2, 5e-324], "refuse"),
        (beam, "rig", "sensors", [0.2, -0.0], "refuse"),
        (beam, "rig", "sensors", [0.2 + k * 1e-5 for k in range(10_000)], "refuse"),
        (beam, "scenario", "tags", [1, 2], "refuse"),
        (beam, "scenario", "tags", [["a"]], "refuse"),
        (beam, "scenario", "tags", [{"a": "b"}], "refuse"),
        (beam, "scenario", "tags", [True], "refuse"),
        (beam, "scenario", "tags", [""], "refuse"),
        (beam, "scenario", "tags", ["a\nb"], "refuse"),
        (beam, "scenario", "tags", [" "], "refuse"),
        (beam, "scenario", "tags", ["beam", "\u00a0"], "refuse"),
        (cart, "identify", "library", [], "refuse"),
        (cart, "identify", "library", [1.0, 2.0], "refuse"),
        (cart, "identify", "library", [[t] for t in lib], "refuse"),
        (cart, "identify", "library", [{"term": t} for t in lib], "refuse"),
        (cart, "identify", "library", [*lib, lib[0]], "refuse"),
        (cart, "identify", "library", ["", *lib[1:]], "refuse"),
        (cart, "identify", "library", ["nonsense_term", *lib[1:]], "refuse"),
        (cart, "identify", "library", [True, *lib[1:]], "refuse"),
        (cart, "identify", "library", "ddth1", "refuse"),
    ]
    return [(f"tomllists {base} [{tab}] {key} = {repr(value)[:60]}", case(base, tab, key, value, expect))
            for base, tab, key, value, expect in table]


# ------------------------------------------------------------------ edgesamples

LAB = "cantilever_stiff_impact_lab"


def edgesamples_cases(work: Path) -> list[tuple[str, object]]:
    import h5py
    import numpy as np
    import pyuff

    from testbed.core.dataset import Dataset

    beam = ["--kind", "structural", "--method", "ls_sindy"]

    def uff_export() -> tuple[Path, list[str]]:
        out, prior_file = work / "lab.uff", work / "lab.prior"
        if not out.exists():
            status, stdout, err = cli_inprocess(["export", str(_generated(work, LAB)), "--format",
                                                 "uff", "-o", str(out)])
            if status != 0:
                raise RuntimeError(f"export: {err[-300:]}")
            prior_file.write_text(json.dumps([a for a in (stdout + err).split()
                                              if "=" in a and not a.startswith("-")]))
        return out, [x for p in json.loads(prior_file.read_text()) for x in ("--prior", p)]

    def sep_export() -> Path:
        out = work / "lab.json"
        if not out.exists():
            status, _, err = cli_inprocess(["export", str(_generated(work, LAB)), "--format",
                                            "sep005", "-o", str(out)])
            if status != 0:
                raise RuntimeError(f"export: {err[-300:]}")
        return out

    def at(where: str, value: float):
        def edit(a: np.ndarray) -> np.ndarray:
            a = np.array(a, dtype=float)
            if where in ("last", "both"):
                a[-1] = value
            if where in ("first", "both"):
                a[0] = value
            return a
        return edit

    def refused(argv: list[str]) -> str | None:
        return judged(*cli_inprocess(argv), refuse=True)

    def csv_case(column: str, edit):
        def run():
            ds = Dataset.load(_generated(work, MM))
            x, dx = ds.measured["x"].data[0], ds.measured["dx"].data[0]
            t = np.arange(x.size) / ds.fs
            cols = {"t": t, "x": x, "dx": dx}
            cols[column] = edit(cols[column])
            path = work / f"mm_{_safe(repr((column, edit.__qualname__, id(edit))))}.csv"
            path.write_text("time [s],x [mM],dx [mM/s]\n" + "".join(
                f"{a!r},{b!r},{c!r}\n" for a, b, c in zip(cols["t"].tolist(), cols["x"].tolist(),
                                                       cols["dx"].tolist(), strict=True)))
            return refused(["identify", str(path), "--scenario", MM, "-o", f"{path}.model.json"])
        return run

    def uff_case(label: str, edit_sets, tokens: dict[str, str] | None = None):
        """The UFF58 export rewritten in ASCII (pyuff's writer turns NaN into 0 and inf into
        1.8e308: a sentinel sample is written and its text replaced by ``tokens``' text)."""
        def run():
            src, prior = uff_export()
            sets = pyuff.UFF(str(src)).read_sets()
            sets = sets if isinstance(sets, list) else [sets]
            for r in sets:
                if r.get("type") == 58:
                    r["binary"] = 0
            edit_sets([s for s in sets if s.get("type") == 58])
            path = work / f"{_safe(label)}.uff"
            path.unlink(missing_ok=True)
            pyuff.UFF(str(path)).write_sets(sets, mode="add")
            text = path.read_text()
            for sentinel, token in (tokens or {}).items():
                if text.count(sentinel) != 1:
                    raise RuntimeError(f"sentinel {sentinel} written {text.count(sentinel)} times")
                text = text.replace(sentinel, token.rjust(len(sentinel)))
            path.write_text(text)
            return refused(["identify", str(path), "-o", f"{path}.model.json", *prior, *beam])
        return run

    #: sentinels of the first and the last sample, as pyuff's ASCII UFF58 writer prints them
    first_s, last_s = 2424.2424, 4242.4242
    first_t, last_t = "2.42424240000e+03", "4.24242420000e+03"

    def uff_sample(channel: str, where: str):
        def edit_sets(records):
            for r in records:
                if r["id1"].strip().endswith(channel):
                    r["data"] = np.array(r["data"], dtype=float)
                    if where in ("last", "both"):
                        r["data"][-1] = last_s
                    if where in ("first", "both"):
                        r["data"][0] = first_s
        return edit_sets

    def uff_tokens(where: str, token: str) -> dict[str, str]:
        return {**({last_t: token} if where in ("last", "both") else {}),
                **({first_t: token} if where in ("first", "both") else {})}

    def uff_cut(n: int):
        def edit_sets(records):
            for r in records:
                r["data"], r["x"], r["num_pts"] = r["data"][:n], r["x"][:n], n
        return edit_sets

    def sep_case(label: str, channel: str, edit):
        def run():
            doc = json.loads(sep_export().read_text())
            for c in doc:
                if c["name"].endswith(channel):
                    c["data"] = edit(c["data"]).tolist()
            path = work / f"{_safe(label)}.json"
            # json writes NaN / Infinity tokens, as Python's own json and numpy-based writers do
            path.write_text(json.dumps(doc))
            _, prior = uff_export()
            return refused(["identify", str(path), "-o", f"{path}.model.json", *prior, *beam])
        return run

    def h5_case(label: str, signal: str, edit):
        def run():
            path = work / f"{_safe(label)}.h5"
            shutil.copy(_generated(work, LAB), path)
            with h5py.File(path, "r+") as f:
                d = f[f"measured/{signal}"]
                a = d[()].astype(float)
                a[0] = edit(a[0])
                d[...] = a
            hostile19._rehash(path)
            return refused(["identify", str(path), "-o", f"{path}.model.json", *beam])
        return run

    values = {"NaN": float("nan"), "+inf": float("inf"), "-inf": -float("inf"), "1e308": 1e308}
    tokens = {"NaN": "NaN", "+inf": "inf", "-inf": "-inf", "1e308": "1e308"}  # as C's printf
    cases: list[tuple[str, object]] = []
    said = {"last": "the last sample", "both": "the first and the last samples"}
    for vlabel, v in values.items():
        for where in ("last", "both"):
            for column in ("x", "t"):
                cases.append((f"edgesamples CSV {column} {vlabel} at {said[where]}",
                              csv_case(column, at(where, v))))
            for channel in ("acc2", "force"):
                cases.append((f"edgesamples UFF58 {channel} {vlabel} at {said[where]}",
                              uff_case(f"uff {channel} {vlabel} {where}", uff_sample(channel, where),
                                       uff_tokens(where, tokens[vlabel]))))
        cases.append((f"edgesamples SEP-005 acc3 {vlabel} at the last sample",
                      sep_case(f"sep acc3 {vlabel}", "acc3", at("last", v))))
        cases.append((f"edgesamples dataset acceleration row 0 {vlabel} at the last sample",
                      h5_case(f"h5 acc {vlabel}", "acceleration", at("last", v))))
        cases.append((f"edgesamples dataset force {vlabel} at the last sample",
                      h5_case(f"h5 force {vlabel}", "force", at("last", v))))
    # (pyuff's writer fails on records of one sample or none: two and three are the least)
    cases += [("edgesamples UFF58 every record of two samples", uff_case("uff two", uff_cut(2))),
              ("edgesamples UFF58 every record of three samples", uff_case("uff three", uff_cut(3)))]
    return cases


# ------------------------------------------------------------------ measapi

def measapi_measurement(work: Path, state: dict):
    """The stiff beam's lab record through its scenario's signal chain, made once per family."""
    if "m" not in state:
        import testbed
        from testbed.core.dataset import Dataset
        from testbed.pipeline.scenario import load_scenario

        sc = load_scenario(LAB)
        state["m"] = testbed.measure(Dataset.load(_generated(work, LAB)), sc.signal, sc.kind)
    return state["m"]


def measapi_cases(work: Path) -> list[tuple[str, object]]:
    import dataclasses

    import numpy as np

    state: dict = {}

    def fit(change):
        def run():
            from testbed.pipeline.plugins import identifier_class

            m = measapi_measurement(work, state)
            data = dataclasses.replace(m, **change(m))
            model = identifier_class("ls_sindy")().fit(data)
            return f"fitted (mass trace {np.trace(model.M_):.4g} kg)"
        return run

    def prior(key, value):
        return lambda m: {"prior": {**m.prior, key: value}}

    def masked(field):
        def change(m):
            a = np.ma.masked_array(np.array(getattr(m, field)), mask=False)
            a.mask[0, 5], a.data[0, 5] = True, 1e3
            return {field: a}
        return change

    def renamed(field, name):
        return lambda m: {field: (name, *getattr(m, field)[1:])}

    cases = [(f"measapi prior reduced_mass_trace = {v!r:.24}", fit(prior("reduced_mass_trace", v)))
             for v in (10 ** 400, "0.7", True, [0.7], None, 0.7 + 0j, 5e-324, 1e-300, 1e308)]
    cases += [("measapi prior total_mass (not read by ls_sindy) a text",
               fit(prior("total_mass", "0.75 kg"))),
              ("measapi prior of an unknown key an integer of 400 digits",
               fit(prior("whatever", 10 ** 400))),
              ("measapi x masked at one sample", fit(masked("x"))),
              ("measapi xdd masked at one sample", fit(masked("xdd"))),
              ("measapi u masked at one sample", fit(masked("u"))),
              ("measapi a channel named with a newline", fit(renamed("channels", "acc1\nacc9"))),
              ("measapi a channel named with an ESC sequence",
               fit(renamed("channels", "\x1b[2Jacc1"))),
              ("measapi an input named with a newline", fit(renamed("inputs", "force\nx")))]
    return cases


# ------------------------------------------------------------------ fittedapi

def fittedapi_cases(work: Path) -> list[tuple[str, object]]:
    import dataclasses

    import numpy as np

    state: dict = {}

    def fitted(method: str):
        key = f"model {method}"
        if key not in state:
            from testbed.pipeline.plugins import identifier_class

            measured = measapi_measurement(work, state)
            state[key] = identifier_class(method)().fit(measured)
        return state[key], measapi_measurement(work, state)

    def call(method: str, how):
        def run():
            model, m = fitted(method)
            out = how(model, m)
            return f"returned {type(out).__name__} {out if np.ndim(out) == 0 else ''}"
        return run

    def scored(change):
        return lambda model, m: model.score(dataclasses.replace(m, **change(m)))

    def predicted(change):
        return lambda model, m: model.predict_acceleration(dataclasses.replace(m, **change(m)))

    def simulated(x0=None, xd0=None, u=None, nt=2):
        def how(model, m):
            n = m.n_channels
            return model.simulate(np.zeros(n) if x0 is None else x0,
                                  np.zeros(n) if xd0 is None else (None if xd0 is _DROP else xd0),
                                  np.arange(nt) / m.fs, u)
        return how

    def two_inputs(m):
        return {"u": np.vstack([m.u, m.u]), "inputs": ("force", "f2"),
                "input_map": np.hstack([m.input_map, m.input_map])}

    def one_sample(m):
        return {"x": m.x[:, :1], "xd": m.xd[:, :1], "xdd": m.xdd[:, :1], "u": m.u[:, :1],
                "free_start": 0, "drift_basis": None}

    def cv_window_before_impact(model, m):
        from identify._base import MeasurementSamples

        return model.score(MeasurementSamples.of(m)[20:40])

    hows = {
        "score with inputs of two rows": scored(two_inputs),
        "predict_acceleration with inputs of two rows": predicted(two_inputs),
        "score with free_start at the end": scored(lambda m: {"free_start": m.n_samples}),
        "score with free_start past the end": scored(lambda m: {"free_start": m.n_samples + 5}),
        "score of a one-sample record": scored(one_sample),
        "score of a CV window ending before the impact's end": cv_window_before_impact,
        "simulate with u of five rows": simulated(u=np.ones((5, 2))),
        "simulate with u of seven samples for two times": simulated(u=np.ones((1, 7))),
        "simulate with xd0 of two channels": simulated(xd0=np.zeros(2)),
        "simulate with xd0 NaN": simulated(xd0=np.full(3, np.nan)),
        "simulate with xd0 None": simulated(xd0=_DROP),
        "simulate with xd0 a text": simulated(xd0="0 0 0"),
    }
    cases = [(f"fittedapi {method} {label}", call(method, how))
             for method in ("ls_sindy", "sgd_sindy") for label, how in hows.items()]

    def other(scenario: str):
        """The scenario's identifier fitted to its record (a mechanical or dynamical model)."""
        key = f"other {scenario}"
        if key not in state:
            import testbed
            from testbed.core.dataset import Dataset
            from testbed.pipeline.plugins import identifier_class
            from testbed.pipeline.scenario import load_scenario

            sc = load_scenario(scenario)
            m = testbed.measure(Dataset.load(_generated(work, scenario)), sc.signal, sc.kind)
            cfg = dict(sc.identify)
            state[key] = (identifier_class(cfg.pop("method"))(**cfg).fit(m), m)
        return state[key]

    def sim(scenario: str, nx=0, xd0="zeros", u="fit", nt=5, t=None):
        def run():
            model, m = other(scenario)
            n = m.n_channels
            x0 = np.full(n + nx, 0.1)
            tt = np.arange(nt) / m.fs if t is None else t
            xd = {"zeros": np.zeros(n), "n+1": np.zeros(n + 1), "NaN": np.full(n, np.nan),
                  "None": None}[xd0]
            uu = (None if m.u is None else np.ones((m.u.shape[0], tt.size))) if isinstance(u, str) \
                and u == "fit" else u
            out = model.simulate(x0, xd, tt, uu)
            return None if (nx == 0 and xd0 == "zeros" and isinstance(u, str)) else \
                f"returned {type(out).__name__}"
        return run

    for scenario, kind in (("cartpole", "mechanical"), (MM, "dynamical")):
        cases += [(f"fittedapi {kind} simulate {label}", sim(scenario, **kw)) for label, kw in {
            "as fitted (accepted)": {},
            "x0 of one channel more": {"nx": 1},
            "u of three rows": {"u": np.ones((3, 5))},
            "u of nine samples for five times": {"u": np.ones((1, 9))},
            "u NaN": {"u": np.full((1, 5), np.nan)},
            "u a text": {"u": "1"},
        }.items()]
    cases += [(f"fittedapi mechanical simulate {label}", sim("cartpole", **kw)) for label, kw in {
        "xd0 of one channel more": {"xd0": "n+1"},
        "xd0 NaN": {"xd0": "NaN"},
        "xd0 None": {"xd0": "None"},
        "t of one sample": {"nt": 1},
        "t spanning 1e308 s": {"t": np.array([0.0, 1e308])},
    }.items()]
    return cases


# ------------------------------------------------------------------ dsapi

def dsapi_cases(work: Path) -> list[tuple[str, object]]:
    import numpy as np

    def case(make):
        def run():
            import testbed
            from testbed.core.dataset import Dataset, Signal
            from testbed.pipeline.scenario import load_scenario

            base = Dataset.load(_generated(work, MM))
            x, dx = base.measured["x"], base.measured["dx"]
            sc = load_scenario(MM)
            ds = make(Dataset, Signal, base, x, dx)
            m = testbed.measure(ds, sc.signal, sc.kind)
            return f"measured (x of shape {m.x.shape})"
        return run

    def sig(data=None, channels=None, unit="keep"):
        def make(Dataset, Signal, base, x, dx):
            return Dataset(base.fs, {"x": Signal(x.data if data is None else data(x.data),
                                                 x.channels if channels is None else channels,
                                                 x.unit if unit == "keep" else unit), "dx": dx})
        return make

    def masked(a):
        out = np.ma.masked_array(a, mask=False)
        out.mask[0, 3] = True
        return out

    def last_nan(a):
        a = a.copy()
        a[0, -1] = np.nan
        return a

    table = {
        "fs a text": lambda D, S, b, x, dx: D("100", {"x": x, "dx": dx}),
        "fs an integer of 400 digits": lambda D, S, b, x, dx: D(10 ** 400, {"x": x, "dx": dx}),
        "fs True": lambda D, S, b, x, dx: D(True, {"x": x, "dx": dx}),
        "a prior as a text": lambda D, S, b, x, dx: D(b.fs, {"x": x, "dx": dx},
                                                      prior={"total_mass": "0.7"}),
        "a masked sample": sig(masked),
        "complex samples": sig(lambda a: a.astype(complex) + 1j),
        "boolean samples": sig(lambda a: a > np.median(a)),
        "channels one text instead of a tuple": sig(channels="x"),
        "a unit of 5": sig(unit=5),
        "a measured table of bare arrays": lambda D, S, b, x, dx: D(b.fs, {"x": x.data, "dx": dx}),
        "an empty measured table": lambda D, S, b, x, dx: D(b.fs, {}),
        "a signal named x/y": lambda D, S, b, x, dx: D(b.fs, {"x/y": x, "dx": dx}),
        "NaN at the last sample": sig(last_nan),
    }
    return [(f"dsapi {label}", case(make)) for label, make in table.items() if make is not None]


# ------------------------------------------------------------------ fileapi

def fileapi_cases(work: Path) -> list[tuple[str, object]]:
    def case(**kw):
        def run():
            import testbed

            testbed.identify_file(_generated(work, MM), scenario=MM, **kw)
            return "fitted"
        return run

    table = {"params a list": {"params": [1]}, "params a text": {"params": "degree=2"},
             "prior a list of pairs": {"prior": [("total_mass", 1.0)]},
             "prior a number": {"prior": 0.7}, "phase a number": {"phase": 5},
             "kind a number": {"kind": 5}, "method a number": {"method": 5},
             "method empty": {"method": ""}}
    return [(f"fileapi {label}", case(**kw)) for label, kw in table.items()]


# ------------------------------------------------------------------ main

FAMILIES = _hostile.families(
    {
        "sepkeys": sepkeys_cases,
        "optgrid": optgrid_cases,
        "serveopts": serveopts_cases,
        "tomllists": tomllists_cases,
        "edgesamples": edgesamples_cases,
        "measapi": measapi_cases,
        "fittedapi": fittedapi_cases,
        "dsapi": dsapi_cases,
        "fileapi": fileapi_cases,
    },
    TIMEOUT_S,
)


def main(argv: list[str]) -> int:
    os.environ.setdefault("TESTBED_NO_SERVER", "1")
    return _hostile.main(argv, FAMILIES, "hostile25-")


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
