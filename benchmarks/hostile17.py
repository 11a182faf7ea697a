"""Seventeenth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile17 [family ...]      # all families when none is named

Families (what rounds 1-16 did not try):

``h5attrs``
    A dataset file (``testbed generate``) edited with h5py and its content hash made anew (as a
    user's edit would), then ``testbed identify`` and ``testbed export``: measured data of dtype
    float16, int8, uint64, bool, 1-D, no rows, no samples, two rows for one channel name,
    subnormal, 1e-200, 1e300, NaN at the start only, constant, shorter than its rate; the root
    ``fs`` as text, bytes, an array, complex, boolean, integer, 1e300, missing; ``fs_unit`` kHz;
    a signal's ``channels`` as integers, empty, too many, a scalar, one name twice; ``unit`` an
    integer, empty, another quantity's; positions as text or NaN; ``prior`` text, an array, an
    unknown key; ``kind``, ``rig``, ``format`` and ``json_attrs`` edited; ``measured`` empty, with
    a group or a soft link.  A traceback, an internal error, a refusal in more than one line,
    or status 0 for a file whose attributes contradict what is read, is a finding.
``mechunits``
    A cart-pole dataset file edited and rehashed: ``theta``'s units swapped or one unit for
    both coordinates, a unit list too long or with an empty part, ``acts_on`` missing, naming
    no coordinate, the pole or two coordinates for one input, the force in N m, ``theta``'s
    channel names or rows swapped, a signal the chain does not read.  Status 0 for a record
    whose units disagree channel by channel (a rate against its coordinate, a load against
    the coordinate it drives) is a finding.
``extremes``
    Every number of the ``[rig]`` table of the two fast rigs (Michaelis-Menten, cart-pole) set
    to 1e-300, 1e100, 1e200 and 1e308 (keys without a declared bound: round 14 set the bounded
    ones at their bounds), run and scored: an exception other than one refusal line, or NaN
    passing, is a finding.  (The Michaelis-Menten rig's ``jx`` at 1e200 and 1e308 is one,
    the rig's own: known-gaps.)
``rates``
    A Michaelis-Menten record as SEP-005 relabelled to 1e-300 .. 1e300 Hz, its rate channel left
    as it was (then no rate of the signal) or scaled with it (consistent): anything but a
    verdict, a model or one refusal line is a finding.
``starts``
    Channels whose first samples were taken at other times: a SEP-005 channel's ``time`` and a
    UFF58 record's abscissa starting 0.3 s, one and 0.6 samples later (0.4 samples: a time
    stamp's rounding, accepted).  A record so skewed fitted with status 0 is a finding.
``directions``
    A UFF58 record's response direction (+-1 .. +-6) against its unit (translation or
    rotation): a contradiction accepted is a finding.
``truncated``
    A dataset file cut at every 10 % of its length: anything but one refusal line is a finding.
``toml``
    Every value of four shipped scenarios replaced by a TOML value of another type (a boolean,
    a date-time, a date, a time of day, an inline table, an array, text holding a number or
    fullwidth digits, 2**70, NaN, inf, 5e-324, 1e308, -1): loaded.  A value of another type
    accepted, NaN accepted, or anything but one refusal line, is a finding.
``environ``
    ``testbed run michaelis_menten`` (and ``list``, ``sweep``) under a hostile environment:
    ``PYTHONWARNINGS=error``, ``COLUMNS=0``, ``LINES`` text, ``HOME`` ``/dev/null``, unset or
    missing, ``PYTHONIOENCODING=ascii``, ``TZ`` garbage, ``MPLCONFIGDIR`` and ``XDG_CACHE_HOME``
    ``/dev/null``, a deleted working folder, ``TESTBED_SCENARIOS`` / ``TESTBED_STUDIES`` a
    file.  A traceback, an internal error, a hang or a refusal in more than one line is a
    finding.
``api``
    The import API (:func:`~testbed.pipeline.importers.read_measured`,
    :func:`~testbed.pipeline.importers.from_sep005`,
    :func:`~testbed.pipeline.importers.measurement_from_file`) given ``units``, ``channels``,
    ``path``, ``fs``, ``kind`` and ``signal`` of the wrong type or empty, and in-memory channel
    data as float16, bool, complex, text, object, datetime64, structured, masked, a range, a
    tuple, a dict, a string or an iterator; ``ImportedData.to_dataset`` given groups and priors
    of the wrong type, a channel twice, a signal named ``""``, ``"a/b"`` or ``5``;
    :func:`~testbed.reporting.export.export_dataset` given an unknown format, an output of the
    wrong type or a folder: an exception other than one refusal line, or a masked sample or a
    value of the wrong kind accepted, is a finding.
``outputs``
    An output that is one of the command's inputs or that its own second output replaces:
    ``identify -o m.md`` and ``m.MD`` (its report is the output with ``.md``), ``-o`` the data
    file or a link to it, ``-o`` the ``--scenario`` file; ``generate -o`` the scenario file or a
    file it extends; ``export -o`` the dataset; ``report -o`` a run folder or its ``run.json``;
    ``sweep --results`` the study or a scenario file.  Status 0, or any given file changed, is
    a finding.
``rlimits``
    ``testbed run`` (and ``generate``, ``sweep``) under a resource limit: open files
    (``ulimit -n``) 6, 8, 10, 12, 16 and 32; a file size of 20 kB (``ulimit -f``, a full disk's
    stand-in); 600 MB of address space.  A traceback, an internal error or a refusal in more than
    one line is a finding.  (At 5 descriptors or fewer the interpreter's own imports fail before
    the command line: known-gaps.)
``runformat``
    A run folder (store format ``/2``) whose ``run.json`` says format ``/1`` (no checksums) with
    a score edited, keeping both, one or none of ``/2``'s checksum keys: listed or reported as
    the run's own while a ``/2`` key betrays the edit is a finding.  (Without either key the
    file is a ``/1`` run as written: known-gaps.)

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import datetime
import functools
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import warnings
from pathlib import Path

try:
    from benchmarks import _hostile
except ImportError:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks import _hostile

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 180
#: The shipped dataset cache: no case simulates anything new.
CACHE = ROOT / ".cache" / "datasets"


#: ``testbed argv`` in this process: (status, stdout, stderr).
cli_inprocess = _hostile.cli_inprocess


judged = functools.partial(_hostile.judged, warnings=True)


def _identify(path: Path, kind: str, method: str, *extra: str, refuse: bool = False) -> str | None:
    return judged(*cli_inprocess(["identify", str(path), "--kind", kind, "--method", method,
                                  "-o", f"{path}.model.json", *extra]), refuse=refuse)


def _generated(work: Path, scenario: str) -> Path:
    """The shipped scenario's dataset file (from the shipped cache), made once."""
    path = work / f"{scenario}.h5"
    if not path.exists():
        status, _, err = cli_inprocess(["generate", scenario, "-o", str(path), "--cache", str(CACHE)])
        if status != 0:
            raise RuntimeError(f"generate {scenario}: {err[-300:]}")
    return path


def _prior_args(path: Path) -> list[str]:
    import h5py

    with h5py.File(path, "r") as f:
        return [a for k, v in f["prior"].attrs.items() for a in ("--prior", f"{k}={float(v)!r}")]


def _rehash(path: Path) -> None:
    """Make a dataset file's content hash anew after an edit (when it still reads)."""
    import h5py

    from testbed.core.dataset import Dataset

    try:
        with warnings.catch_warnings():  # a complex rate's cast: the readers' to name
            warnings.simplefilter("ignore")
            ds = Dataset.load(path, verify=False)
    except Exception:
        return  # unreadable: the readers say so
    with h5py.File(path, "r+") as f:
        f.attrs["content_hash"] = ds.content_hash()


# ------------------------------------------------------------------ h5attrs

def _h5_edits():
    """name -> (edit of an open h5py file, must be refused)."""
    import h5py
    import numpy as np

    def data(name, make):
        def edit(f):
            d = f[name]
            attrs, old = dict(d.attrs), d[()]
            del f[name]
            new = f.create_dataset(name, data=make(old))
            for k, v in attrs.items():
                new.attrs[k] = v
        return edit

    def attr(obj, key, value):
        return lambda f: f[obj].attrs.__setitem__(key, value)

    def drop(obj, key):
        return lambda f: f[obj].attrs.__delitem__(key)

    def text(*names):
        return np.array(names, dtype=h5py.string_dtype())

    x = "measured/x"
    return {
        "x float16": (data(x, lambda a: a.astype(np.float16)), False),
        "x int8": (data(x, lambda a: (a * 50).astype(np.int8)), True),  # no longer dx's integral
        "x uint64 max": (data(x, lambda a: np.full(a.shape, 2**64 - 1, dtype=np.uint64)), True),
        "x bool": (data(x, lambda a: a > 1), True),
        "x 1-D": (data(x, lambda a: a[0]), False),
        "x no rows": (data(x, lambda a: a[:0]), True),
        "x no samples": (data(x, lambda a: a[:, :0]), True),
        "x two rows, one name": (data(x, lambda a: np.vstack([a, a])), True),
        "x subnormal": (data(x, lambda a: a * 1e-310), True),
        "x 1e-200": (data(x, lambda a: a * 1e-200), True),
        "x 1e300": (data(x, lambda a: a * 1e300), True),
        "x NaN at the start only": (data(x, lambda a: np.where(np.arange(a.shape[1]) < 5, np.nan, a)), True),
        "x constant": (data(x, lambda a: np.full_like(a, 0.7)), True),
        "x shorter than dx": (data(x, lambda a: a[:, :300]), True),
        "fs text '100'": (attr("/", "fs", "100"), True),
        "fs bytes": (attr("/", "fs", np.bytes_(b"abc")), True),
        "fs array": (attr("/", "fs", np.array([100.0, 200.0])), True),
        "fs complex": (attr("/", "fs", np.complex128(100 + 1j)), True),
        "fs bool": (attr("/", "fs", np.bool_(True)), True),
        "fs int": (attr("/", "fs", np.int64(100)), False),
        "fs 1e300": (attr("/", "fs", 1e300), True),
        "fs missing": (drop("/", "fs"), True),
        "fs_unit kHz": (attr("/", "fs_unit", "kHz"), True),
        "channels integers": (attr(x, "channels", np.array([1])), False),
        "channels empty": (attr(x, "channels", text()), True),
        "channels two": (attr(x, "channels", text("x", "y")), True),
        "channels a scalar": (attr(x, "channels", "x"), False),
        "channels x of dx": (attr("measured/dx", "channels", text("x")), False),
        "unit an integer": (attr(x, "unit", 5), True),
        "unit empty": (attr(x, "unit", ""), True),
        "unit m/s^2": (attr(x, "unit", "m/s^2"), True),
        "unit missing": (drop(x, "unit"), True),
        "positions text": (attr(x, "positions", "abc"), True),
        "positions NaN": (attr(x, "positions", np.array([np.nan])), True),
        "prior text": (attr("prior", "total_mass", "heavy"), True),
        "prior an array": (attr("prior", "total_mass", np.array([1.0, 2.0])), True),
        "prior unknown key": (attr("prior", "flux", 1.21), False),
        "kind structural": (attr("/", "kind", "structural"), True),
        "rig unknown": (attr("/", "rig", "warp_drive"), False),
        "format /9": (attr("/", "format", "sysid-testbed-dataset/9"), True),
        "json_attrs not JSON": (attr("/", "json_attrs", "{not json"), True),
        "measured empty": (lambda f: [f["measured"].__delitem__(k) for k in list(f["measured"])], True),
        "measured holds a group": (lambda f: f["measured"].create_group("sub"), True),
        "measured holds a soft link": (lambda f: f["measured"].__setitem__(
            "y", h5py.SoftLink("/measured/x")), True),
    }


def _cantilever_edits():
    """Edits of a cantilever record: name -> (edit, must be refused)."""
    import h5py
    import numpy as np

    acc = "measured/acceleration"

    def rows(edit):
        def run(f):
            d = f[acc][()]
            edit(d)
            f[acc][...] = d
        return run

    return {
        "a channel named twice": (lambda f: f[acc].attrs.__setitem__(
            "channels", np.array(["acc1", "acc1", "acc3"], dtype=h5py.string_dtype())), True),
        "sensors at one position": (lambda f: f[acc].attrs.__setitem__(
            "positions", np.array([0.1] * 3)), True),
        "positions 1e300 times": (lambda f: f[acc].attrs.__setitem__(
            "positions", f[acc].attrs["positions"] * 1e300), True),
        "a row copied": (rows(lambda d: d.__setitem__(1, d[0])), True),
    }


def h5attrs_cases(work: Path) -> list[tuple[str, object]]:
    def case(base: str, edit, refuse: bool, kind: str, method: str, prior: bool):
        def run() -> str | None:
            import h5py

            src = _generated(work, base)
            path = work / f"edit_{abs(hash(edit)) % 10**9}.h5"
            shutil.copyfile(src, path)
            with h5py.File(path, "r+") as f:
                edit(f)
            _rehash(path)
            found = [_identify(path, kind, method, *(_prior_args(src) if prior else []), refuse=refuse)]
            status, out, err = cli_inprocess(["export", str(path), "--format", "sep005",
                                              "-o", f"{path}.json"])
            found.append(judged(status, out, err))
            return "; ".join(f for f in found if f) or None
        return run

    cases = [(f"michaelis_menten: {name}", case("michaelis_menten", e, r, "dynamical",
                                                "sindy_pi_dynamical", False))
             for name, (e, r) in _h5_edits().items()]
    cases += [(f"cantilever: {name}", case("cantilever_stiff_impact", e, r, "structural",
                                           "ls_sindy", True))
              for name, (e, r) in _cantilever_edits().items()]
    return cases


# ------------------------------------------------------------------ mechunits

def mechunits_cases(work: Path) -> list[tuple[str, object]]:
    import h5py
    import numpy as np

    text = h5py.string_dtype()

    def attr(obj, key, value):
        return lambda f: f[obj].attrs.__setitem__(key, value)

    def swap_rows(f):
        f["measured/theta"][...] = f["measured/theta"][()][::-1]

    def extra(f):
        d = f["measured"].create_dataset("extra", data=np.zeros((1, f["measured/theta"].shape[1])))
        d.attrs.update({"channels": np.array(["e"], dtype=text), "unit": "m"})

    edits = {  # name -> (edit, must be refused)
        "theta 'rad, m'": (attr("measured/theta", "unit", "rad, m"), True),
        "theta 'm' for both": (attr("measured/theta", "unit", "m"), True),
        "theta 'm, rad, rad'": (attr("measured/theta", "unit", "m, rad, rad"), True),
        "theta 'm, '": (attr("measured/theta", "unit", "m, "), True),
        "acts_on missing": (lambda f: f["measured/torque"].attrs.__delitem__("acts_on"), True),
        "acts_on a name of none": (attr("measured/torque", "acts_on", np.array(["nope"], dtype=text)), True),
        "acts_on the pole": (attr("measured/torque", "acts_on", np.array(["th"], dtype=text)), True),
        "acts_on two for one input": (attr("measured/torque", "acts_on", np.array(["x", "th"], dtype=text)),
                                      True),
        "force in N m": (attr("measured/torque", "unit", "N m"), True),
        "theta's names swapped": (attr("measured/theta", "channels", np.array(["th", "x"], dtype=text)),
                                  True),
        "theta's rows swapped": (swap_rows, True),
        "a signal the chain does not read": (extra, True),
        "as generated": (lambda f: None, False),
    }

    def case(edit, refuse: bool):
        def run() -> str | None:
            src = _generated(work, "cartpole")
            path = work / f"cp_{abs(hash(edit)) % 10**9}.h5"
            shutil.copyfile(src, path)
            with h5py.File(path, "r+") as f:
                edit(f)
            _rehash(path)
            return judged(*cli_inprocess(["identify", str(path), "--kind", "mechanical", "--scenario",
                                          "cartpole", "-o", f"{path}.model.json"]), refuse=refuse)
        return run

    return [(f"cartpole: {name}", case(e, r)) for name, (e, r) in edits.items()]


# ------------------------------------------------------------------ extremes

def extremes_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml

    def case(base: str, key: str, value: float):
        def run() -> str | None:
            from testbed.pipeline.scenario import scenario_from_dict
            from testbed.scoring.run import run_scenario

            raw = _read_toml(SCENARIO_DIR / f"{base}.toml")
            raw["scenario"].pop("extends", None)
            raw["rig"][key] = value
            sc = scenario_from_dict(raw, file=f"{base}.toml", stem=base)  # one refusal line: ok
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # the integrators' overflow warnings
                return _hostile.scored_finding(run_scenario(sc))
        return run

    cases = []
    for base in ("michaelis_menten", "cartpole"):
        rig = _read_toml(SCENARIO_DIR / f"{base}.toml")["rig"]
        for key, old in rig.items():
            if isinstance(old, float):
                cases += [(f"{base} rig.{key} = {v:g}", case(base, key, v))
                          for v in (1e-300, 1e100, 1e200, 1e308)]
    return cases


# ------------------------------------------------------------------ rates

def rates_cases(work: Path) -> list[tuple[str, object]]:
    def case(fs: float, consistent: bool):
        def run() -> str | None:
            src = _generated(work, "michaelis_menten")
            base = work / "mm.json"
            if not base.exists():
                status, _, err = cli_inprocess(["export", str(src), "--format", "sep005", "-o", str(base)])
                if status != 0:
                    raise RuntimeError(err)
            chans = json.loads(base.read_text())
            for c in chans:
                scale = fs / c["fs"] if consistent and c["name"].startswith("dx") else 1.0
                c["fs"], c["data"] = fs, [v * scale for v in c["data"]]
            path = work / f"r_{fs:g}_{consistent}.json"
            path.write_text(json.dumps(chans))
            return _identify(path, "dynamical", "sindy_pi_dynamical", refuse=not consistent)
        return run

    return [(f"fs {fs:g} Hz, rate {'scaled' if c else 'left'}", case(fs, c))
            for fs in (1e-300, 1e-150, 1e-20, 1e20, 1e150, 1e160, 1e200, 1e300) for c in (False, True)]


# ------------------------------------------------------------------ starts

def starts_cases(work: Path) -> list[tuple[str, object]]:
    def sep005(lag_s: float, lag_steps: float, refuse: bool):
        def run() -> str | None:
            import numpy as np

            src = _generated(work, "cantilever_stiff_impact")
            base = work / "cs.json"
            if not base.exists():
                cli_inprocess(["export", str(src), "--format", "sep005", "-o", str(base)])
            chans = json.loads(base.read_text())
            for c in chans:
                fs = c.pop("fs")
                t = np.arange(len(c["data"])) / fs
                if c["name"].startswith("force"):
                    t = t + lag_s + lag_steps / fs
                c["time"] = t.tolist()
            path = work / f"s_{lag_s:g}_{lag_steps:g}.json"
            path.write_text(json.dumps(chans))
            return _identify(path, "structural", "ls_sindy", *_prior_args(src), refuse=refuse)
        return run

    def uff(lag_s: float, refuse: bool):
        def run() -> str | None:
            import pyuff

            src, sets = _stiff_impact_uff_sets(work)
            for s in sets:
                if s["type"] == 58 and s["id1"].startswith("force"):
                    s["x"] = s["x"] + lag_s
            path = work / f"s_{lag_s:g}.uff"
            pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")
            return _identify(path, "structural", "ls_sindy", *_prior_args(src), refuse=refuse)
        return run

    return [("SEP-005 force 0.3 s late", sep005(0.3, 0, True)),
            ("SEP-005 force 1 sample late", sep005(0.0, 1.0, True)),
            ("SEP-005 force 0.6 sample late", sep005(0.0, 0.6, True)),
            ("SEP-005 force 0.4 sample late (rounding)", sep005(0.0, 0.4, False)),
            ("SEP-005 time stamps, one start", sep005(0.0, 0.0, False)),
            ("UFF force 0.3 s late", uff(0.3, True)),
            ("UFF force 1e-3 s late", uff(1e-3, True))]


def _stiff_impact_uff_sets(work: Path) -> tuple[Path, list]:
    """The shipped stiff cantilever's dataset (generated once in ``work``) and its UFF export's
    sets, read afresh (each case edits its own copy)."""
    import pyuff

    src = _generated(work, "cantilever_stiff_impact")
    base = work / "cs.uff"
    if not base.exists():
        cli_inprocess(["export", str(src), "--format", "uff", "-o", str(base)])
    return src, pyuff.UFF(str(base)).read_sets()


# ------------------------------------------------------------------ directions

def directions_cases(work: Path) -> list[tuple[str, object]]:
    def case(channel: str, direction: int):
        def run() -> str | None:
            import pyuff

            src, sets = _stiff_impact_uff_sets(work)
            for s in sets:
                if s["type"] == 58 and s["id1"].endswith(channel):
                    s["rsp_dir"] = direction
            path = work / f"d_{channel}_{direction}.uff"
            pyuff.UFF(str(path)).write_sets(sets, mode="overwrite")
            # the cantilever's channels are translations (m/s^2, N): a rotation's code contradicts
            return _identify(path, "structural", "ls_sindy", *_prior_args(src),
                             refuse=abs(direction) in (4, 5, 6))
        return run

    return [(f"{ch} direction {d}", case(ch, d)) for ch in ("acc1", "force")
            for d in (1, -2, 3, 4, -5, 6)]


# ------------------------------------------------------------------ truncated

def truncated_cases(work: Path) -> list[tuple[str, object]]:
    def case(frac: float):
        def run() -> str | None:
            src = _generated(work, "michaelis_menten")
            path = work / f"cut_{int(frac * 100)}.h5"
            data = src.read_bytes()
            path.write_bytes(data[:int(len(data) * frac)])
            return _identify(path, "dynamical", "sindy_pi_dynamical", refuse=True)
        return run

    return [(f"dataset cut at {k * 10} %", case(k / 10)) for k in range(10)]


# ------------------------------------------------------------------ toml

def _toml(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, (datetime.datetime, datetime.date, datetime.time)):
        return v.isoformat()
    if isinstance(v, list):
        return "[" + ", ".join(_toml(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {_toml(x)}" for k, x in v.items()) + "}"
    raise TypeError(v)


#: TOML values of other types than a scenario's (a label -> the value)
TOML_VALUES = {"true": True, "false": False,
               "date-time": datetime.datetime(1979, 5, 27, 7, 32, tzinfo=datetime.UTC),
               "date": datetime.date(2020, 1, 1), "time": datetime.time(7, 32), "table": {},
               "array": [], "array [1.0]": [1.0], "text '10'": "10", "fullwidth '１０'": "１０",
               "2**70": 2**70, "NaN": math.nan, "inf": math.inf, "5e-324": 5e-324, "1e308": 1e308,
               "-1": -1, "-0.0": -0.0}


def toml_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml

    def case(base: str, raw: dict, table: str, key: str, label: str, old):
        def run() -> str | None:
            from testbed.pipeline.scenario import load_scenario

            folder = work / f"{base}.{table}.{key}.{abs(hash(label)) % 10**6}"
            folder.mkdir(exist_ok=True)
            path = folder / f"{base}.toml"  # the name must be the file's
            path.write_text("".join(f"[{t}]\n" + "".join(f"{json.dumps(k)} = {_toml(v)}\n"
                                                         for k, v in tab.items())
                                    for t, tab in raw.items()))
            load_scenario(path)  # a refusal in one line ends the case ok (the harness)
            new = raw[table][key]
            if isinstance(new, float) and math.isnan(new):
                return "NaN accepted"
            numbers = all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (new, old))
            if type(new) is not type(old) and not numbers:
                return f"a {type(new).__name__} accepted where the scenario has a {type(old).__name__}"
            return None
        return run

    cases = []
    for base in ("michaelis_menten", "cartpole", "cantilever_stiff_impact", "fivebar_multisine"):
        raw0 = _read_toml(SCENARIO_DIR / f"{base}.toml")
        raw0["scenario"].pop("extends", None)
        for table, tab in raw0.items():
            for key, old in tab.items():
                if (table, key) == ("scenario", "name"):
                    continue
                for label, value in TOML_VALUES.items():
                    raw = json.loads(json.dumps(raw0))
                    raw[table][key] = value
                    cases.append((f"{base} {table}.{key} = {label}", case(base, raw, table, key, label, old)))
    return cases


# ------------------------------------------------------------------ environ

def _testbed(argv: list[str], cwd: Path, env: dict,
             timeout: float = 120) -> subprocess.CompletedProcess | str:
    try:
        return subprocess.run([sys.executable, "-m", "testbed.cli", *argv], cwd=cwd, env=env,
                              capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return f"hang > {timeout} s"


def environ_cases(work: Path) -> list[tuple[str, object]]:
    file = work / "a_file"
    file.write_text("x")
    study = work / "h17.toml"
    study.write_text('[study]\nname = "h17"\nscenarios = ["michaelis_menten"]\nnoise = [0.0]\n'
                     'seeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')

    def case(argv: list[str], change: dict, unset: tuple = (), deleted_cwd: bool = False):
        def run() -> str | None:
            env = {**_hostile.ENV, "TESTBED_CACHE": str(CACHE), **change}
            for k in unset:
                env.pop(k, None)
            if not deleted_cwd:
                p = _testbed(argv, work, env)
            else:  # the command's folder removed under it before it runs
                gone = tempfile.mkdtemp(dir=work)
                code = (f"import os, sys; os.chdir({gone!r}); os.rmdir({gone!r}); "
                        "from testbed.cli import main; sys.exit(main(sys.argv[1:]))")
                try:
                    p = subprocess.run([sys.executable, "-c", code, *argv], cwd=work, env=env,
                                       capture_output=True, text=True, timeout=120)
                except subprocess.TimeoutExpired:
                    return "hang > 120 s"
            if isinstance(p, str):
                return p
            return _hostile.cli_finding(p)
        return run

    run = ["run", "michaelis_menten", "--out", str(work / "out"), "--no-figures"]
    cases = [
        ("PYTHONWARNINGS=error", case(run, {"PYTHONWARNINGS": "error"})),
        ("COLUMNS=0 LINES=abc", case(run, {"COLUMNS": "0", "LINES": "abc"})),
        ("COLUMNS=-5", case(run, {"COLUMNS": "-5"})),
        ("HOME=/dev/null", case(run, {"HOME": "/dev/null"})),
        ("HOME unset", case(run, {}, unset=("HOME",))),
        ("HOME missing", case(run, {"HOME": str(work / "nohome" / "x")})),
        ("PYTHONIOENCODING=ascii LC_ALL=C", case(run, {"PYTHONIOENCODING": "ascii:strict", "LC_ALL": "C"})),
        ("TZ garbage", case(run, {"TZ": "Garbage/Zone"})),
        ("MPLCONFIGDIR=/dev/null", case(["run", "michaelis_menten", "--out", str(work / "out")],
                                        {"MPLCONFIGDIR": "/dev/null"})),
        ("XDG_CACHE_HOME a file", case(["run", "michaelis_menten", "--out", str(work / "out")],
                                       {"XDG_CACHE_HOME": str(file), "MPLCONFIGDIR": ""})),
        ("TESTBED_SCENARIOS a file", case(run, {"TESTBED_SCENARIOS": str(file)})),
        ("TESTBED_STUDIES a file", case(["sweep", "default", "--results", str(work / "r.parquet")],
                                        {"TESTBED_STUDIES": str(file)})),
        ("TESTBED_INDEX a file's child", case(["list", "--plain"], {"TESTBED_INDEX": str(file / "x")})),
        ("the cwd deleted: run", case(run, {}, deleted_cwd=True)),
        ("the cwd deleted: sweep by path", case(["sweep", str(study), "--results",
                                                 str(work / "r2.parquet")], {}, deleted_cwd=True)),
    ]
    return cases


# ------------------------------------------------------------------ api

def api_cases(work: Path) -> list[tuple[str, object]]:
    import numpy as np

    from testbed.pipeline.importers import from_sep005, measurement_from_file, read_measured

    def rec() -> Path:
        path = work / "r.json"
        if not path.exists():
            t = np.arange(400) / 100.0
            x = 2.0 * np.exp(-t)
            path.write_text(json.dumps([{"name": "x/x", "data": x.tolist(), "unit_str": "mM", "fs": 100.0},
                                        {"name": "dx/dx", "data": (-x).tolist(), "unit_str": "mM/s",
                                         "fs": 100.0}]))
        return path

    def refused(fn):
        def run() -> str | None:
            fn()  # a refusal in one line ends the case ok (the harness)
            return "accepted"
        return run

    def accepted(fn):
        return lambda: fn() and None

    def chan(data):
        return [{"name": "a", "data": data, "unit_str": "m/s^2", "fs": 100.0}]

    cases = []
    for fs in (True, "100", math.nan, -1.0, [100], 100 + 0j, 0):
        cases.append((f"read_measured fs={fs!r}", refused(lambda fs=fs: read_measured(rec(), fs=fs))))
    for units in (5, {"x/x": 5}, ["mM"], b"mM"):
        cases.append((f"read_measured units={units!r}",
                      refused(lambda u=units: read_measured(rec(), units=u))))
    for ch in ("x/x", [], [5], ("x/x", "x/x"), {"x/x": 1}, [b"x/x"]):
        cases.append((f"read_measured channels={ch!r}",
                      refused(lambda c=ch: read_measured(rec(), channels=c))))
    for path in (5, None, b"r.json", ""):
        cases.append((f"read_measured path={path!r}", refused(lambda p=path: read_measured(p))))
    for fmt in ("HDF5", 5, ""):
        cases.append((f"read_measured format={fmt!r}", refused(lambda f=fmt: read_measured(rec(), format=f))))
    for kind in ("", "STRUCTURAL", 5, None):
        cases.append((f"measurement_from_file kind={kind!r}",
                      refused(lambda k=kind: measurement_from_file(rec(), k))))
    for sig in (5, [], "recorded", {"derivatives": 5}, {"nope": 1}):
        cases.append((f"measurement_from_file signal={sig!r}",
                      refused(lambda g=sig: measurement_from_file(rec(), "dynamical", g))))
    bad = {"bool": np.ones(10, dtype=bool), "complex": np.ones(10, dtype=complex),
           "text": np.array(["1"] * 10), "object": np.ones(10, dtype=object),
           "datetime64": np.arange(10).astype("datetime64[s]"),
           "structured": np.ones(10, dtype=[("a", float)]),
           "masked": np.ma.masked_array(np.arange(10.0), mask=[True] + [False] * 9),
           "dict": {1: 2}, "str": "0123456789", "iterator": iter(range(10))}
    for label, data in bad.items():
        cases.append((f"from_sep005 data {label}", refused(lambda d=data: from_sep005(chan(d)))))
    good = {"float16": np.ones(10, dtype=np.float16) * np.arange(10), "range": range(10),
            "tuple": tuple(float(k) for k in range(10)), "int8": np.arange(10, dtype=np.int8),
            "masked, none masked": np.ma.masked_array(np.arange(10.0), mask=False)}
    for label, data in good.items():
        cases.append((f"from_sep005 data {label}", accepted(lambda d=data: from_sep005(chan(d)))))
    both = ["x/x", "dx/dx"]
    for groups in (5, [], {"x": ["x/x", "x/x"]}, {"x": ["x/x"], "dx": ["x/x"]}, {"": both}, {"a/b": both},
                   {5: both}, {"x": "x/x"}):
        cases.append((f"to_dataset groups={groups!r}",
                      refused(lambda g=groups: read_measured(rec()).to_dataset(g))))
    for prior in (5, [], {"total_mass": 10**400}, {"total_mass": "heavy"}, {"": 1.0}):
        cases.append((f"to_dataset prior={str(prior)[:40]}",
                      refused(lambda p=prior: read_measured(rec()).to_dataset(None, p))))
    cases.append(("to_dataset groups by hand",
                  accepted(lambda: read_measured(rec()).to_dataset({"x": ["x/x"]}))))
    return cases + _export_api_cases(work)


def _export_api_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.reporting.export import export_dataset

    folder = work / "a_folder"
    folder.mkdir(exist_ok=True)

    def refused(**change):
        def run() -> str | None:
            args = {"path": _generated(work, "michaelis_menten"), "fmt": "uff", "out": work / "e.uff",
                    **change}
            export_dataset(args["path"], args["fmt"], args["out"])  # one refusal line: ok
            return "accepted"
        return run

    return [(f"export_dataset {k}={v!r}", refused(**{k: v}))
            for k, v in (("fmt", "UFF"), ("fmt", None), ("fmt", "csv"), ("out", 5), ("out", b"e.uff"),
                         ("out", folder), ("path", None), ("path", 5))]


# ------------------------------------------------------------------ outputs

def outputs_cases(work: Path) -> list[tuple[str, object]]:
    def case(argv_of, setup):
        def run() -> str | None:
            folder = Path(tempfile.mkdtemp(dir=work))
            given = setup(folder)
            before = {p: p.read_bytes() for p in given}
            argv = argv_of(folder)
            status, out, err = cli_inprocess(argv)
            found = judged(status, out, err, refuse=True)
            changed = [p.name for p, b in before.items() if not p.exists() or p.read_bytes() != b]
            if changed:
                found = f"{found + '; ' if found else ''}changed {changed}"
            return found
        return run

    def mm_record(folder: Path) -> list[Path]:
        src = _generated(work, "michaelis_menten")
        rec = folder / "r.json"
        cli_inprocess(["export", str(src), "--format", "sep005", "-o", str(rec)])
        (folder / "link.json").symlink_to(rec)
        scen = folder / "michaelis_menten.toml"
        scen.write_text((ROOT / "scenarios" / "michaelis_menten.toml").read_text())
        (folder / "child.toml").write_text('[scenario]\nname = "child"\nextends = "michaelis_menten.toml"\n')
        (folder / "s.toml").write_text('[study]\nname = "s"\nscenarios = ["michaelis_menten"]\n'
                                       'noise = [0.0]\nseeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')
        shutil.copyfile(src, folder / "d.h5")
        return [rec, scen, folder / "child.toml", folder / "s.toml", folder / "d.h5"]

    def run_folder(folder: Path) -> list[Path]:
        given = mm_record(folder)
        cli_inprocess(["run", "michaelis_menten", "--out", str(folder / "runs"), "--no-figures",
                       "--cache", str(CACHE)])
        run = next((folder / "runs" / "michaelis_menten").glob("2*"))
        (folder / "run").symlink_to(run)
        return [*given, run / "run.json", run / "run.npz"]

    ident = ["identify", "{r}", "--kind", "dynamical", "--method", "sindy_pi_dynamical", "-o"]
    cases = {
        "identify -o m.md": [*ident, "{f}/m.md"],
        "identify -o m.MD": [*ident, "{f}/m.MD"],
        "identify -o the data": [*ident, "{r}"],
        "identify -o a link to the data": [*ident, "{f}/link.json"],
        "identify -o its --scenario": ["identify", "{r}", "--scenario", "{f}/michaelis_menten.toml",
                                       "--kind", "dynamical", "-o", "{f}/michaelis_menten.toml"],
        "generate -o the scenario": ["generate", "{f}/child.toml", "-o", "{f}/child.toml",
                                     "--cache", str(CACHE)],
        "generate -o the file it extends": ["generate", "{f}/child.toml", "-o",
                                            "{f}/michaelis_menten.toml", "--cache", str(CACHE)],
        "export -o the dataset": ["export", "{f}/d.h5", "--format", "sep005", "-o", "{f}/d.h5"],
        "sweep --results the study": ["sweep", "{f}/s.toml", "--results", "{f}/s.toml",
                                      "--cache", str(CACHE)],
        "sweep --results a scenario": ["sweep", "{f}/s.toml", "--results", "{f}/michaelis_menten.toml",
                                       "--cache", str(CACHE)],
    }
    out = [(name, case(lambda f, a=argv: [x.format(f=f, r=f / "r.json") for x in a], mm_record))
           for name, argv in cases.items()]
    out += [("report -o its run folder", case(lambda f: ["report", str(f / "run"), "-o", str(f / "run")],
                                              run_folder)),
            ("report -o its run.json", case(lambda f: ["report", str(f / "run"), "-o",
                                                       str(f / "run" / "run.json")], run_folder))]
    return out


# ------------------------------------------------------------------ rlimits

def rlimits_cases(work: Path) -> list[tuple[str, object]]:
    import resource

    def case(argv: list[str], which: int, value: int):
        def run() -> str | None:
            out = Path(tempfile.mkdtemp(dir=work))
            env = {**_hostile.ENV, "TESTBED_CACHE": str(CACHE)}
            try:
                p = subprocess.run([sys.executable, "-m", "testbed.cli", *argv], cwd=out, env=env,
                                   capture_output=True, text=True, timeout=180,
                                   preexec_fn=lambda: resource.setrlimit(which, (value, value)))
            except subprocess.TimeoutExpired:
                return "hang > 180 s"
            return _hostile.cli_finding(p)
        return run

    study = work / "h17r.toml"
    study.write_text('[study]\nname = "h17r"\nscenarios = ["michaelis_menten"]\nnoise = [0.0]\n'
                     'seeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')
    run = ["run", "michaelis_menten"]
    cases = [(f"ulimit -n {n}: run", case(run, resource.RLIMIT_NOFILE, n)) for n in (6, 8, 10, 12, 16, 32)]
    cases += [(f"ulimit -f 20 kB: {' '.join(a[:1])}", case(a, resource.RLIMIT_FSIZE, 20 * 1024))
              for a in (run, ["generate", "michaelis_menten", "-o", "g.h5"],
                        ["sweep", str(study), "--results", "r.parquet"])]
    cases.append(("600 MB of address space: run", case(run, resource.RLIMIT_AS, 600 * 2**20)))
    return cases


# ------------------------------------------------------------------ runformat

def runformat_cases(work: Path) -> list[tuple[str, object]]:
    def case(keep: tuple[str, ...], must_refuse: bool):
        def run() -> str | None:
            from testbed.studies.runstore import list_runs, load_run, save_new_run

            sys.path.insert(0, str(ROOT / "tests" / "testbed"))
            import _synthetic_runs

            out = work / f"runs_{'_'.join(keep) or 'none'}"
            if out.exists():
                shutil.rmtree(out)
            saved = save_new_run(_synthetic_runs.structural_result(n_samples=200), out)
            meta = json.loads((saved / "run.json").read_text())
            meta["format"] = "sysid-testbed-run/1"
            meta["scores"][next(iter(meta["scores"]))] = 123.0
            for k in {"sha256", "npz_sha256"} - set(keep):
                del meta[k]
            (saved / "run.json").write_text(json.dumps(meta, indent=2))
            listed = list_runs(out)
            try:
                load_run(saved)
                loaded = True
            except ValueError:
                loaded = False
            if must_refuse and (listed or loaded):
                return "the edited run was listed or read as the run's own"
            return None
        return run

    return [("format /1 with both /2 checksums", case(("sha256", "npz_sha256"), True)),
            ("format /1 with sha256", case(("sha256",), True)),
            ("format /1 with npz_sha256", case(("npz_sha256",), True)),
            ("format /1 without either (a /1 run as written: known-gaps)", case((), False))]


FAMILIES = _hostile.families({
    "h5attrs": h5attrs_cases,
    "mechunits": mechunits_cases,
    "extremes": extremes_cases,
    "rates": rates_cases,
    "starts": starts_cases,
    "directions": directions_cases,
    "truncated": truncated_cases,
    "toml": toml_cases,
    "environ": environ_cases,
    "api": api_cases,
    "outputs": outputs_cases,
    "rlimits": rlimits_cases,
    "runformat": runformat_cases,
}, TIMEOUT_S)


def main(argv: list[str]) -> int:
    os.environ.setdefault("MPLBACKEND", "Agg")
    return _hostile.main(argv, FAMILIES, "hostile17-")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
