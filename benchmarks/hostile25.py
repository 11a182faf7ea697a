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


# ------------------------------------------------------------------ main

FAMILIES = _hostile.families(
    {
        "sepkeys": sepkeys_cases,
        "optgrid": optgrid_cases,
        "serveopts": serveopts_cases,
        "tomllists": tomllists_cases,
    },
    TIMEOUT_S,
)


def main(argv: list[str]) -> int:
    os.environ.setdefault("TESTBED_NO_SERVER", "1")
    return _hostile.main(argv, FAMILIES, "hostile25-")


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
