"""Fifteenth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile15 [family ...]      # all families when none is named

Families (where rounds 1-14 went least):

``studies``
    A study file (``[study]``, ``[identifiers.<name>]``, ``[thresholds.<name>]``) over the fast
    rigs with its grid's axes empty, duplicated (``1`` and ``1.0``, ``0.0`` and ``-0.0``, a
    scenario by name and by path), a million seeds, seeds as floats, negative, ``2**63 - 1``,
    noise subnormal, ``1e308``, NaN, infinite; an identifier's hyperparameters of the wrong
    type (text, float, boolean, list, table, NaN, negative, ``2**63 - 1``) and unknown ones:
    loaded (:func:`testbed.studies.study.load_study`).  An exception other than one refusal
    line, a hang, or a value that is not allowed accepted is a finding.
``extends``
    A scenario's ``extends`` chain: a two-file and a three-file cycle, a chain of 30, a parent
    that is a folder, missing, a FIFO, ``/dev/full``, a link loop, a study file, a file that is
    not TOML, the child itself through a symbolic link; a child that changes types at several
    depths (a table to a number, a number to a table, a list to text).  Anything but a
    scenario or one refusal line is a finding.
``csvdata``
    A Michaelis-Menten record as CSV with time stamps out of order, repeated, decreasing,
    jittered beyond the tolerance, a declared ``--fs`` the stamps contradict, a row short or
    long, NaN / infinite / ``1e309`` inside, a constant channel, one or two samples, a time
    column in ms, two time columns, Unicode digits, a header only, then read
    (:func:`testbed.pipeline.importers.measurement_from_file`): anything but a measurement or one
    refusal line, or a damaged record accepted, is a finding.
``numopts``
    Every numeric option of the command line (``run --seed``, ``generate --seed``,
    ``sweep --jobs``, ``identify --fs``, ``--param``, ``--prior``) at 0, -1, NaN, inf, ``1e309``,
    ``2**64``, blank, Unicode digits, ``1_0``: a traceback, an internal error, a refusal in more
    than one line, or a value that is not allowed accepted, is a finding.
``cuts``
    A results file and a row file cut at every 10 % of their length and one bit flipped
    there: read and summarized.  Rows other than the undamaged ones, or anything but one
    refusal line, is a finding.
``dask``
    ``sweep --dask`` addresses: an unclosed IPv6 bracket, host names the idna codec cannot
    encode (an empty label, 64 characters, a lone surrogate), other schemes, ports out of
    range, nothing listening: anything but one refusal line is a finding.
``priors``
    A cantilever record identified with its mass from ``--prior total_mass`` at 5e-324,
    1e-320, 1e-300, 1e300, 1e308 kg: anything but a model or one refusal line is a finding.
``results``
    ``summary`` and ``report`` of an empty file, a foreign Parquet file, a CSV under the
    ``.parquet`` suffix, a results file of format ``/1`` (no checksums: another version) holding
    values no sweep writes (``checks`` or ``params`` not JSON, a passed row whose status is
    ``failed``, a negative seed or time, NaN ``fit_time``), a file with only failed cells, one
    row, NaN metrics with reasons: a traceback, an internal error or NaN shown without a reason
    is a finding.
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
from pathlib import Path

try:
    from benchmarks import _hostile
except ImportError:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks import _hostile

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 120
PYTHON = sys.executable


def _testbed(argv: list[str], cwd: Path, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run(
        [PYTHON, "-m", "testbed.cli", *argv],
        cwd=cwd,
        env=_hostile.ENV,
        capture_output=True,
        text=True,
        timeout=timeout,
    )


def _cli(argv: list[str], cwd: Path, refuse: bool = False, timeout: float = 120) -> str | None:
    """A finding of ``testbed argv``, or None; ``refuse``: it must end with status 2."""
    try:
        p = _testbed(argv, cwd, timeout)
    except subprocess.TimeoutExpired:
        return f"hang > {timeout} s"
    found = _hostile.cli_finding(p)
    if found:
        return found
    if refuse and p.returncode != 2:
        return f"accepted (status {p.returncode}): {p.stdout.strip().splitlines()[-1:] if p.stdout else ''}"
    if "nan" in p.stdout.lower().split() and "reason" not in p.stdout.lower():
        return "NaN in the output"
    return None


def _toml(value) -> str:
    """``value`` as a TOML value."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list):
        return "[" + ", ".join(_toml(v) for v in value) + "]"
    if isinstance(value, dict):
        return "{" + ", ".join(f"{k} = {_toml(v)}" for k, v in value.items()) + "}"
    raise TypeError(value)


# ------------------------------------------------------------------ studies

STUDY = {
    "name": "s15",
    "scenarios": ["michaelis_menten", "cartpole"],
    "noise": [0.0],
    "seeds": [0],
    "identifiers": ["sindy_pi_dynamical"],
}


def _study_text(head: dict, extra: str = "") -> str:
    return "[study]\n" + "".join(f"{k} = {_toml(v)}\n" for k, v in head.items()) + extra


def study_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.studies.study import load_study

    def case(name: str, text: str, allowed: bool | None):
        def fn():
            p = work / "s15.toml"
            p.write_text(text)
            try:
                load_study(p)
            except Exception as e:
                from testbed.core.errors import TestbedError

                if isinstance(e, TestbedError) and allowed is not True:
                    return None if "\n" not in str(e) else f"two lines: {str(e)[:200]!r}"
                raise
            return "accepted" if allowed is False else None

        return name, fn

    axes = {
        "noise": [
            ([], False),
            ([1.0, 1], False),
            ([0.0, -0.0], False),
            ([5e-324], True),
            ([1e308], False),
            ([math.nan], False),
            ([math.inf], False),
            ([-0.0], True),
            ([100.0], True),
            ([100.00000000000001], False),
            (["1"], False),
            ([True], False),
            ([[1.0]], False),
            (1.0, False),
        ],
        "seeds": [
            ([], False),
            ([0, 0], False),
            ([1.0], False),
            ([-1], False),
            ([2**63 - 1], None),
            ([0.5], False),
            ([True], False),
            (["0"], False),
            (0, False),
            (list(range(1_000_000)), False),
        ],
        "scenarios": [
            ([], False),
            (["michaelis_menten", "michaelis_menten"], False),
            (["michaelis_menten", str(ROOT / "scenarios" / "michaelis_menten.toml")], False),
            ([""], False),
            (["."], False),
            (["/dev/full"], False),
            ([str(ROOT / "scenarios")], False),
        ],
        "identifiers": [
            ([], False),
            (["sindy_pi_dynamical", "sindy_pi_dynamical"], False),
            ([""], False),
            (["ls_sindy"], False),
        ],
    }
    cases = []
    for key, values in axes.items():
        for v, allowed in values:
            label = f"{len(v)} entries" if isinstance(v, list) and len(v) > 10 else repr(v)
            cases.append(case(f"study.{key} = {label}", _study_text({**STUDY, key: v}), allowed))
    hyper = [
        ("degree", v, ok)
        for v, ok in [
            ("3", False),
            (3.0, False),
            (True, False),
            (-1, False),
            (0, False),
            (2**63 - 1, False),
            ([3], False),
            ({"a": 1}, False),
            (math.nan, False),
            (2, True),
        ]
    ]
    hyper += [
        ("sim_dt", v, ok)
        for v, ok in [
            ("1e-3", False),
            (0.0, False),
            (-1e-3, False),
            (math.nan, False),
            (math.inf, False),
            (1e308, False),
            (5e-324, None),
            (True, False),
        ]
    ]
    hyper += [
        ("ridge", v, ok) for v, ok in [(math.nan, False), (-1.0, False), ("0", False), (math.inf, False)]
    ]
    hyper += [("no_such_hyperparameter", 1, False), ("method", "sindy_pi", False)]
    for k, v, allowed in hyper:
        extra = f"\n[identifiers.sindy_pi_dynamical]\n{k} = {_toml(v)}\n"
        cases.append(
            case(f"identifiers.sindy_pi_dynamical.{k} = {v!r:.40}", _study_text(STUDY, extra), allowed)
        )
    for extra, allowed in [
        ("\n[identifiers]\nsindy_pi_dynamical = 3\n", False),
        ("\n[identifiers.sindy_pi_dynamical.sub]\ndegree = 3\n", False),
        ("\n[identifiers.ls_sindy]\ndegree = 3\n", False),
        ('\n[thresholds.sindy_pi_dynamical]\ncoef_error = "1"\n', False),
        ("\n[thresholds.sindy_pi_dynamical]\ncoef_error = {max = nan}\n", False),
        ("\n[thresholds.sindy_pi_dynamical]\nno_such_score = {max = 1.0}\n", False),
        ("\n[thresholds.sindy_pi_dynamical]\ncoef_error = {max = -1.0}\n", None),
        ("\n[thresholds.sindy_pi_dynamical]\ncoef_error = {max = 1.0, min = 2.0}\n", None),
        ("\n[thresholds.sindy_pi_dynamical]\ncoef_error = {}\n", False),
        ("\n[thresholds]\n", True),
        ("\n[study.sub]\nx = 1\n", False),
        ("\n[other]\nx = 1\n", False),
        ("\n[families]\n", True),
    ]:
        cases.append(case(f"study with {extra.strip()!r}", _study_text(STUDY, extra), allowed))
    return cases


# ------------------------------------------------------------------ extends


def extends_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.scenario import load_scenario

    base = (ROOT / "scenarios" / "michaelis_menten.toml").read_text()

    def child(name: str, parent: str, body: str = "") -> str:
        return f'[scenario]\nname = "{name}"\nextends = {json.dumps(parent)}\n{body}'

    def case(name: str, files: dict[str, str], load: str, allowed: bool | None, setup=None):
        def fn():
            d = work / f"c{abs(hash(name)) % 10**8}"
            d.mkdir(exist_ok=True)
            for f, text in files.items():
                (d / f).write_text(text)
            if setup:
                setup(d)
            try:
                load_scenario(d / load)
            except Exception as e:
                from testbed.core.errors import TestbedError

                if isinstance(e, TestbedError) and allowed is not True:
                    return None if "\n" not in str(e) else f"two lines: {str(e)[:200]!r}"
                raise
            return "accepted" if allowed is False else None

        return name, fn

    mm = {"michaelis_menten.toml": base}
    cases = [
        case("a parent", {**mm, "k.toml": child("k", "michaelis_menten.toml")}, "k.toml", True),
        case(
            "a two-file cycle",
            {"a.toml": child("a", "b.toml"), "b.toml": child("b", "a.toml")},
            "a.toml",
            False,
        ),
        case(
            "a three-file cycle",
            {"a.toml": child("a", "b.toml"), "b.toml": child("b", "c.toml"), "c.toml": child("c", "a.toml")},
            "a.toml",
            False,
        ),
        case("itself by ./", {"a.toml": child("a", "./a.toml")}, "a.toml", False),
        case(
            "itself by ../",
            {"a.toml": child("a", "../x/a.toml")},
            "a.toml",
            False,
            setup=lambda d: (
                (d.parent / "x").mkdir(exist_ok=True)
                or (d.parent / "x" / "a.toml").write_text(child("a", "../x/a.toml"))
            ),
        ),
        case(
            "a chain of 30",
            {
                **mm,
                **{f"k{i}.toml": child(f"k{i}", f"k{i + 1}.toml") for i in range(30)},
                "k30.toml": child("k30", "michaelis_menten.toml"),
            },
            "k0.toml",
            True,
        ),
        case(
            "a chain of 33",
            {
                **mm,
                **{f"k{i}.toml": child(f"k{i}", f"k{i + 1}.toml") for i in range(33)},
                "k33.toml": child("k33", "michaelis_menten.toml"),
            },
            "k0.toml",
            False,
        ),
        case("a missing parent", {"k.toml": child("k", "nope.toml")}, "k.toml", False),
        case(
            "a folder parent",
            {"k.toml": child("k", "sub")},
            "k.toml",
            False,
            setup=lambda d: (d / "sub").mkdir(exist_ok=True),
        ),
        case(
            "a folder parent named .toml",
            {"k.toml": child("k", "sub.toml")},
            "k.toml",
            False,
            setup=lambda d: (d / "sub.toml").mkdir(exist_ok=True),
        ),
        case("/dev/full parent", {"k.toml": child("k", "/dev/full")}, "k.toml", False),
        case("/dev/zero parent", {"k.toml": child("k", "/dev/zero")}, "k.toml", False),
        case(
            "a FIFO parent",
            {"k.toml": child("k", "p.toml")},
            "k.toml",
            False,
            setup=lambda d: (d / "p.toml").exists() or os.mkfifo(d / "p.toml"),
        ),
        case(
            "a link-loop parent",
            {"k.toml": child("k", "l.toml")},
            "k.toml",
            False,
            setup=lambda d: (d / "l.toml").is_symlink() or os.symlink("l.toml", d / "l.toml"),
        ),
        case(
            "a link to the child",
            {"k.toml": child("k", "l.toml")},
            "k.toml",
            False,
            setup=lambda d: (d / "l.toml").is_symlink() or os.symlink("k.toml", d / "l.toml"),
        ),
        case("a study parent", {"k.toml": child("k", str(ROOT / "studies" / "smoke.toml"))}, "k.toml", False),
        case(
            "a non-TOML parent",
            {"p.toml": "not = toml = at all", "k.toml": child("k", "p.toml")},
            "k.toml",
            False,
        ),
        case("an empty parent", {"p.toml": "", "k.toml": child("k", "p.toml")}, "k.toml", False),
        case("an empty extends", {"k.toml": child("k", "")}, "k.toml", False),
        case("extends a number", {"k.toml": '[scenario]\nname = "k"\nextends = 3\n'}, "k.toml", False),
        case(
            "extends a list",
            {**mm, "k.toml": '[scenario]\nname = "k"\nextends = ["michaelis_menten.toml"]\n'},
            "k.toml",
            False,
        ),
        case(
            "a parent without a name",
            {"p.toml": base.replace('name = "michaelis_menten"\n', ""), "k.toml": child("k", "p.toml")},
            "k.toml",
            None,
        ),
        case("a parent naming another", {"p.toml": base, "k.toml": child("k", "p.toml")}, "k.toml", None),
        case(
            "a parent of another rig",
            {**mm, "k.toml": child("k", "michaelis_menten.toml", '[scenario]\nrig = "cartpole"\n')},
            "k.toml",
            False,
        ),
    ]
    changes = {
        "rig a number": "rig = 3\n",
        "rig.x0 a table": "[rig.x0]\na = 1\n",
        "rig.x0 text": '[rig]\nx0 = "2"\n',
        "rig.x0 a list": "[rig]\nx0 = [2.0]\n",
        "simulation a list": "simulation = [1]\n",
        "identify.degree text": '[identify]\ndegree = "3"\n',
        "identify a string": 'identify = "ls_sindy"\n',
        "tags text": '[scenario]\ntags = "a"\n',
        "score a number": "score = 1\n",
        "score.coef_error text": '[score]\ncoef_error = "x"\n',
        "signal.derivatives 3": "[signal]\nderivatives = 3\n",
        "noise.rms_percent nan": "[noise]\nrms_percent = nan\n",
        "unknown nested": "[rig.extra]\nq = 1\n",
        "unknown in identify": "[identify]\nnope = 1\n",
        "identify.method other kind": '[identify]\nmethod = "ls_sindy"\n',
        "seed a float": "[scenario]\nseed = 1.0\n",
        "seed 2**63-1": "[scenario]\nseed = 9223372036854775807\n",
        "seed -1": "[scenario]\nseed = -1\n",
    }
    # a parent refused on its own, its malformed key overridden or replaced by the child
    fix = '[rig]\nx0 = 2.0\n[identify]\nmethod = "sindy_pi_dynamical"\n'
    for what, (a, b) in {
        "a description with a tab": ('description = "Michaelis', 'description = "a\\tb" #'),
        "x0 text": ("x0 = 2.0", 'x0 = "two"'),
        "degree text": ("degree = 3", 'degree = "3"'),
        "tags text": ("tags = [", 'tags = "a"\nx = ['),
        "an unknown key": ("x0 = 2.0", "x0 = 2.0\nnope = 1"),
    }.items():
        assert a in base, a
        cases.append(
            case(
                f"a parent with {what}, overridden",
                {"p.toml": base.replace(a, b, 1), "k.toml": child("k", "p.toml", fix)},
                "k.toml",
                False,
            )
        )
    for what, body in changes.items():
        text = child("k", "michaelis_menten.toml")
        if body.startswith("[scenario]\n"):  # keys of the child's own [scenario] table
            text += body.split("\n", 1)[1]
        else:
            text += "\n" + body
        allowed = None if what.startswith("seed 2") else False
        cases.append(case(f"a child with {what}", {**mm, "k.toml": text}, "k.toml", allowed))
        # the same change one level further: a grandchild
        cases.append(
            case(
                f"a grandchild of a child with {what}",
                {**mm, "k.toml": text, "g.toml": child("g", "k.toml")},
                "g.toml",
                allowed,
            )
        )
    return cases


# ------------------------------------------------------------------ CSV data


def _mm_rows(work: Path) -> list[tuple[float, float, float]]:
    """(t, x, dx) of a Michaelis-Menten record (the cached simulation, 400 samples at 100 Hz)."""
    path = work / "mm.h5"
    if not path.exists():
        p = subprocess.run(
            [PYTHON, "-m", "testbed.cli", "generate", "michaelis_menten", "-o", str(path)],
            cwd=ROOT,
            env=_hostile.ENV,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert p.returncode == 0, p.stderr
    from testbed.core.dataset import Dataset

    ds = Dataset.load(path)
    x, dx = ds.measured["x"].data[0], ds.measured["dx"].data[0]
    return [(k / ds.fs, float(a), float(b)) for k, (a, b) in enumerate(zip(x, dx, strict=True))]


def _csv(rows, head="t,x [m],dx [m/s]") -> str:
    return (
        head
        + "\n"
        + "".join(",".join(c if isinstance(c, str) else repr(float(c)) for c in r) + "\n" for r in rows)
    )


def csv_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.importers import measurement_from_file

    rows = _mm_rows(work)

    def case(name: str, text: str, allowed: bool | None, **kw):
        def fn():
            p = work / "d.csv"
            p.write_text(text)
            try:
                m = measurement_from_file(p, "dynamical", **kw)
            except Exception as e:
                from testbed.core.errors import TestbedError

                if isinstance(e, TestbedError) and allowed is not True:
                    return None if "\n" not in str(e) else f"two lines: {str(e)[:200]!r}"
                raise
            import numpy as np

            if not all(np.all(np.isfinite(np.asarray(v))) for v in (m.x, m.xd) if v is not None):
                return "a measurement with NaN or inf"
            return "accepted" if allowed is False else None

        return name, fn

    swapped = list(rows)
    swapped[100], swapped[101] = swapped[101], swapped[100]
    dup = [r if k != 50 else (rows[49][0], *r[1:]) for k, r in enumerate(rows)]
    repeated = rows[:200] + rows[199:]
    jitter = [(t + (0.0002 if k % 2 else 0.0), *r) for k, (t, *r) in enumerate(rows)]
    cases = [
        case("the record", _csv(rows), True),
        case("two stamps swapped", _csv(swapped), False),
        case("a stamp repeated (values differ)", _csv(dup), False),
        case("a row repeated", _csv(repeated), False),
        case("decreasing stamps", _csv(rows[::-1]), False),
        case("stamps jittered 2 %", _csv(jitter), False),
        case("stamps at 100 Hz, --fs 50", _csv(rows), False, fs=50.0),
        case("stamps at 100 Hz, --fs 100.05", _csv(rows), True, fs=100.05),
        case("no stamps, --fs 100", _csv([r[1:] for r in rows], "x [m],dx [m/s]"), True, fs=100.0),
        case("a short row", _csv(rows).replace(f"{rows[10][2]!r}\n", "\n", 1), False),
        case("a long row", _csv(rows).replace(f"{rows[10][2]!r}\n", f"{rows[10][2]!r},1.0\n", 1), False),
        case("a trailing comma", _csv(rows).replace(f"{rows[10][2]!r}\n", f"{rows[10][2]!r},\n", 1), False),
        case("a NaN", _csv([r if k != 7 else (r[0], "nan", r[2]) for k, r in enumerate(rows)]), False),
        case(
            "a run of NaN",
            _csv([r if not 7 <= k < 60 else (r[0], "NaN", r[2]) for k, r in enumerate(rows)]),
            False,
        ),
        case("an inf", _csv([r if k != 7 else (r[0], r[1], "-inf") for k, r in enumerate(rows)]), False),
        case("1e309", _csv([r if k != 7 else (r[0], "1e309", r[2]) for k, r in enumerate(rows)]), False),
        case("a NaN stamp", _csv([r if k != 7 else ("nan", *r[1:]) for k, r in enumerate(rows)]), False),
        case("a constant x", _csv([(r[0], 2.0, r[2]) for r in rows]), False),
        case("a constant dx", _csv([(r[0], r[1], 0.0) for r in rows]), None),
        case("one sample", _csv(rows[:1]), False),
        case("two samples", _csv(rows[:2]), None),
        case("a header only", _csv([]), False),
        case("time in ms", _csv([(r[0] * 1000, *r[1:]) for r in rows], "t [ms],x [m],dx [m/s]"), False),
        case("two time columns", _csv([(r[0], r[0], *r[1:]) for r in rows], "t,time,x [m],dx [m/s]"), False),
        case("T upper-case", _csv(rows, "T,x [m],dx [m/s]"), True),
        case("Arabic-Indic digits", _csv(rows).replace("0.0,", "\u0660.\u0660,", 1), None),
        case(
            "underscores in a number",
            _csv([r if k != 3 else (r[0], "1_000.0", r[2]) for k, r in enumerate(rows)]),
            None,
        ),
        case("stamps starting at 1e17", _csv([(1e17 + r[0], *r[1:]) for r in rows]), False),
        case("stamps of 5e-324 s", _csv([(k * 5e-324, *r[1:]) for k, r in enumerate(rows)]), False),
        case("stamps of 1e300 s", _csv([(k * 1e300, *r[1:]) for k, r in enumerate(rows)]), None),
        case("a subnormal channel", _csv([(r[0], r[1] * 1e-310, r[2] * 1e-310) for r in rows]), False),
        case("x in g", _csv(rows, "t,x [g],dx [m/s]"), None),
        case("an empty unit", _csv(rows, "t,x [],dx [m/s]"), False),
        case("a unit with no bracket", _csv(rows, "t,x [m,dx [m/s]"), None),
    ]
    return cases


# ------------------------------------------------------------------ numeric options

NUMBERS = [
    "0",
    "-1",
    "nan",
    "inf",
    "-inf",
    "1e309",
    str(2**64),
    str(2**63),
    "",
    " ",
    "1.5",
    "\u0661",
    "\uff11",
    "1_0",
    "+1",
    "0x10",
    "1e-320",
]


def numopts_cases(work: Path) -> list[tuple[str, object]]:
    rows = _mm_rows(work)
    data = work / "mm.csv"
    data.write_text(_csv([r[1:] for r in rows], "x [m],dx [m/s]"))
    study = work / "s15.toml"
    study.write_text(_study_text({**STUDY, "scenarios": ["michaelis_menten"]}))
    out = work / "o"
    quick = ["--param", "max_iter=1"]
    cmds = {
        "run --seed": lambda v: ["run", "michaelis_menten", "--no-figures", "-o", str(out), "--seed", v],
        "generate --seed": lambda v: ["generate", "michaelis_menten", "-o", str(work / "g.h5"), "--seed", v],
        "sweep --jobs": lambda v: ["sweep", str(study), "--results", str(work / "r.parquet"), "--jobs", v],
        "identify --fs": lambda v: [
            "identify",
            str(data),
            "--kind",
            "dynamical",
            "--method",
            "sindy_pi_dynamical",
            *quick,
            "-o",
            str(work / "m.json"),
            "--fs",
            v,
        ],
        "identify --param sim_dt": lambda v: [
            "identify",
            str(data),
            "--kind",
            "dynamical",
            "--fs",
            "100",
            "--method",
            "sindy_pi_dynamical",
            *quick,
            "-o",
            str(work / "m.json"),
            "--param",
            f"sim_dt={v}",
        ],
        "identify --prior total_mass": lambda v: [
            "identify",
            str(data),
            "--kind",
            "dynamical",
            "--fs",
            "100",
            "--method",
            "sindy_pi_dynamical",
            *quick,
            "-o",
            str(work / "m.json"),
            "--prior",
            f"total_mass={v}",
        ],
    }
    # Python's int() and float() read Unicode digits and TOML's underscores (1_0 is 10 in a
    # scenario file too); the value read is shown (a run folder's "-s1", the dataset's hash)
    read = {"\u0661", "\uff11", "1_0", "+1"}
    allowed = {
        "run --seed": {"0", *read},
        "generate --seed": {"0", *read},
        "sweep --jobs": read,
        "identify --fs": {"1.5", str(2**64), str(2**63), *read},
        "identify --param sim_dt": {"+1", "1.5"},
        "identify --prior total_mass": {"1.5", *read},  # 1e-320 kg: outside PRIOR_RANGE
    }
    cases = []
    for cmd, argv in cmds.items():
        for v in NUMBERS:
            must_refuse = v not in allowed[cmd]
            cases.append(
                (f"{cmd} {v!r}", lambda argv=argv, v=v, r=must_refuse: _cli(argv(v), work, refuse=r))
            )
    prior_forms = [
        "",
        "=",
        "total_mass",
        "total_mass=",
        "=1",
        "total_mass=1=2",
        "nosuchkey=1",
        "total_mass=1,total_mass=2",
        "total_mass=[1]",
        'total_mass="1"',
        "total_mass=true",
        "Total_Mass=1",
    ]
    for form in prior_forms:
        argv = [
            "identify",
            str(data),
            "--kind",
            "dynamical",
            "--fs",
            "100",
            "--method",
            "sindy_pi_dynamical",
            *quick,
            "-o",
            str(work / "m.json"),
            "--prior",
            form,
        ]
        cases.append((f"--prior {form!r}", lambda argv=argv: _cli(argv, work, refuse=True)))
    twice = [
        "identify",
        str(data),
        "--kind",
        "dynamical",
        "--fs",
        "100",
        "--method",
        "sindy_pi_dynamical",
        *quick,
        "-o",
        str(work / "m.json"),
        "--prior",
        "total_mass=1",
        "--prior",
        "total_mass=2",
    ]
    cases.append(("--prior twice", lambda: _cli(twice, work, refuse=True)))
    ptwice = [
        "identify",
        str(data),
        "--kind",
        "dynamical",
        "--fs",
        "100",
        "--method",
        "sindy_pi_dynamical",
        "--param",
        "max_iter=1",
        "--param",
        "max_iter=2",
        "-o",
        str(work / "m.json"),
    ]
    cases.append(("--param twice", lambda: _cli(ptwice, work, refuse=True)))
    return cases


# ------------------------------------------------------------------ results files


def results_cases(work: Path) -> list[tuple[str, object]]:
    import pyarrow as pa
    import pyarrow.parquet as pq

    from testbed.studies.results import write_rows

    def v1(path: Path, rows: list[dict]) -> Path:
        table = pa.Table.from_pylist(rows)
        cols = {}
        from testbed.studies.results import BASE_COLUMNS, TAIL_COLUMNS

        for name, t in {**BASE_COLUMNS, **TAIL_COLUMNS}.items():
            if name == "row_sha256":
                continue
            cols[name] = pa.array([r.get(name) for r in rows], getattr(pa, t)())
        for name in table.column_names:
            if name not in cols:
                cols[name] = pa.array([r.get(name) for r in rows], pa.float64())
        t = pa.table(cols).replace_schema_metadata({"format": "sysid-testbed-results/1", "study": "s"})
        pq.write_table(t, path)
        return path

    row = _hostile.results_row
    files = {
        "an empty file": lambda p: p.write_bytes(b"") or p,
        "a foreign parquet": lambda p: pq.write_table(pa.table({"a": [1, 2]}), p) or p,
        "a CSV": lambda p: p.write_text("study,cell\ns,c1\n") or p,
        "a folder": lambda p: p.mkdir() or p,
        "an empty parts folder (a sweep killed at once)": lambda p: (
            p.with_name(p.name + ".parts").mkdir() or p
        ),
        "a v1 file, checks not JSON": lambda p: v1(p, [row(checks="not json")]),
        "a v1 file, checks a JSON number": lambda p: v1(p, [row(checks="3")]),
        "a v1 file, checks a list of numbers": lambda p: v1(p, [row(checks="[1, 2]")]),
        "a v1 file, params not JSON": lambda p: v1(p, [row(params="{")]),
        "a v1 file, params a list": lambda p: v1(p, [row(params="[1]")]),
        "a v1 file, passed but failed": lambda p: v1(p, [row(status="failed", passed=True, error="boom")]),
        "a v1 file, passed, NaN coef_error": lambda p: v1(p, [row(coef_error=math.nan)]),
        "a v1 file, negative seed": lambda p: v1(p, [row(seed=-5)]),
        "a v1 file, NaN fit_time": lambda p: v1(p, [row(fit_time=math.nan)]),
        "a v1 file, negative cell_time": lambda p: v1(p, [row(cell_time=-1.0)]),
        "a v1 file, noise 1e308": lambda p: v1(p, [row(noise=1e308)]),
        "a v1 file, rig blank": lambda p: v1(p, [row(rig="")]),
        "a v1 file, identifier blank": lambda p: v1(p, [row(identifier="")]),
        "a v1 file, an unknown identifier": lambda p: v1(p, [row(identifier="nope")]),
        "a v1 file, an ESC in the scenario": lambda p: v1(p, [row(scenario="mm\x1b[31m")]),
        "a v1 file, a newline in the identifier": lambda p: v1(p, [row(identifier="a\nb")]),
        "a v1 file, a score column inf": lambda p: v1(p, [row(coef_error=math.inf, passed=False)]),
        "a v2 file, passed but failed": lambda p: write_rows(
            p, [row(status="failed", passed=True, error="boom")], study="s"
        ),
        "a v2 file, checks not JSON": lambda p: write_rows(p, [row(checks="not json")], study="s"),
        "a v2 file, NaN fit_time": lambda p: write_rows(p, [row(fit_time=math.nan)], study="s"),
        "a v2 file, only failed, NaN scores": lambda p: write_rows(
            p,
            [
                row(
                    cell=f"c{k}", seed=k, status="failed", passed=False, error="diverged", coef_error=math.nan
                )
                for k in range(3)
            ],
            study="s",
        ),
        "a v2 file, zero rows": lambda p: write_rows(p, [], study="s"),
        "a v2 file, passed and NaN score with a failed check": lambda p: write_rows(
            p,
            [
                row(
                    coef_error=math.nan,
                    passed=False,
                    checks=json.dumps(
                        [
                            {
                                "metric": "coef_error",
                                "op": "<=",
                                "bound": 0.1,
                                "value": None,
                                "passed": False,
                                "reason": "the model diverged",
                            }
                        ]
                    ),
                )
            ],
            study="s",
        ),
    }
    cases = []
    for what, make in files.items():
        for cmd in ("summary", "report"):

            def fn(what=what, make=make, cmd=cmd):
                d = work / f"r{abs(hash((what, cmd))) % 10**8}"
                d.mkdir(exist_ok=True)
                p = d / "x.parquet"
                make(p)
                argv = ["summary", str(p)] if cmd == "summary" else ["report", str(p), "-o", str(d / "rep")]
                # a report of no row is refused (round 15); summary says "no results"
                nothing = what in ("a v2 file, zero rows", "an empty parts folder (a sweep killed at once)")
                return _cli(argv, d, refuse=nothing and cmd == "report")

            cases.append((f"{cmd} of {what}", fn))
    return cases


def cut_cases(work: Path) -> list[tuple[str, object]]:
    """A results file of 3 rows and one row file (``<results>.parts/``) cut at every 10 % of
    their length and with one bit flipped there: read (:func:`read_results`) and summarized.
    Anything but the undamaged rows or one refusal line (a damaged row file is skipped with
    a warning) is a finding."""
    from testbed.studies.results import read_results, write_part, write_rows
    from testbed.studies.statistics import summarize

    rows = [_hostile.results_row(cell=f"c{k}", seed=k, coef_error=0.01 * (k + 1)) for k in range(3)]
    good = work / "good.parquet"
    write_rows(good, rows, study="s")
    part = write_part(work / "p.parquet", _hostile.results_row(cell="c9", seed=9))
    want = read_results(good)
    cases = []
    for what, src in (("results file", good), ("row file", part)):
        data = src.read_bytes()
        for pct in range(0, 100, 10):
            at = len(data) * pct // 100
            for how, damaged in (
                ("cut", data[:at]),
                ("flipped", data[:at] + bytes([data[at] ^ 0x10]) + data[at + 1 :]),
            ):

                def fn(what=what, pct=pct, how=how, damaged=damaged):
                    d = work / f"{what[:3]}{pct}{how}"
                    d.mkdir(exist_ok=True)
                    if what == "results file":
                        path = d / "r.parquet"
                        path.write_bytes(damaged)
                    else:
                        path = d / "p.parquet"
                        (d / "p.parquet.parts").mkdir(exist_ok=True)
                        (d / "p.parquet.parts" / part.name).write_bytes(damaged)
                    got = read_results(path)
                    summarize(path)
                    if what == "results file" and got != want:
                        return f"read {len(got)} rows other than the file's {len(want)}"
                    if what == "row file" and got and got[0]["cell"] != "c9":
                        return f"read a row of cell {got[0]['cell']!r}"
                    return None

                cases.append((f"{what} {how} at {pct} %", fn))
    return cases


def prior_cases(work: Path) -> list[tuple[str, object]]:
    """A cantilever record identified by ``pysindy_sr3`` with its mass taken from ``--prior
    total_mass`` at the edges of "a finite number > 0": anything but a model or one refusal
    line is a finding (5e-324, 1e-320 and 1e308 were three internal errors, now refused as
    outside ``testbed.pipeline.importers.PRIOR_RANGE``: docs/history.md, round 15)."""
    data = work / "cl.h5"

    def fn(v):
        if not data.exists():
            p = _testbed(["generate", "cantilever_stiff_impact_lsq", "-o", str(data)], work, 600)
            assert p.returncode == 0, p.stderr
        argv = [
            "identify",
            str(data),
            "--scenario",
            "cantilever_stiff_impact_lsq",
            "--method",
            "pysindy_sr3",
            "--param",
            'mass_prior="total_mass"',
            "--prior",
            f"total_mass={v}",
            "-o",
            str(work / "m.json"),
        ]
        return _cli(argv, work, timeout=600)

    return [
        (f"--prior total_mass={v}", lambda v=v: fn(v))
        for v in ("5e-324", "1e-320", "1e-300", "1e300", "1e308")
    ]


DASK_ADDRESSES = [
    "tcp://[::1",
    "tcp://" + "a" * 64 + ":1",
    "tcp://a..b:1",
    "tcp://.:1",
    "tcp://\udcff:1",
    "[::1",
    "tcp://[zz]:1",
    "tcp://h:99999",
    "tcp://h:-1",
    "nonsense://x",
    "inproc://",
    "",
    "tcp://\u202e1:1",
    "tcp://127.0.0.1:1",
    "tcp://[::1]:1",
    "tls://127.0.0.1:1",
    ":1",
    "tcp://:1",
    "tcp://127.0.0.1:",
    "tcp://127.0.0.1:0",
    "tcp://127.0.0.1:1/path?q#f",
    "tcp://user:pw@127.0.0.1:1",
    "tcp://127.0.0.1:1 ",
    " tcp://127.0.0.1:1",
]


def dask_cases() -> list[tuple[str, object]]:
    """``sweep --dask`` addresses Python cannot parse or encode, or where nothing listens
    (:func:`testbed.cli.check_dask_address`): anything but one refusal line is a finding."""
    from testbed.cli import check_dask_address

    def fn(a):
        check_dask_address(a)
        return "accepted"

    return [(f"--dask {a!r:.50}", lambda a=a: fn(a)) for a in DASK_ADDRESSES]


FAMILIES = _hostile.families({
    "studies": study_cases, "extends": extends_cases, "csvdata": csv_cases,
    "numopts": numopts_cases, "results": results_cases, "cuts": cut_cases,
    "dask": lambda work: dask_cases(), "priors": prior_cases,
}, TIMEOUT_S)


def main(argv: list[str]) -> int:
    os.environ.setdefault("MPLBACKEND", "Agg")
    return _hostile.main(argv, FAMILIES, "hostile15-")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
