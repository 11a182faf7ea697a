"""Twenty-second malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile22 [family ...]      # all families when none is named

Families (what rounds 1-21 did not try; their families are listed in ``hostile21.py`` and
h5shape csvcells jitter paramedge fitedge latethreads interrupts):

``physcombo``
    Scenario files whose every number has the right type and lies within its own bounds, but
    whose combination is physically impossible or empty: a sensor beyond the beam, a hammer
    inboard of the root hinge, a sample rate below twice mode 1, a pulse longer than the
    record or starting after it, a beam thicker (or wider) than it is long, a record shorter
    than one period of mode 1, E = 1 Pa, a 1 mm beam, a step longer than the sample period,
    a five-bar whose links cannot close or whose start pose cannot, tones above the Nyquist
    frequency, f_min > f_max, a cart-pole or link mass of 1e-12 kg, kinetics started at its
    steady state or with Km = 1e-300, a record of 1 or 2 samples ... ``testbed generate``.
    A refusal in more than one line, an impossible combination accepted, or an accepted one
    whose dataset holds a non-finite sample, is a finding.
``tinyrec``
    Records of 1, 2, 3, 4, 5, 8 and 16 samples (the dataset file of a shipped scenario cut,
    its content hash made anew; the beam's cut from the hammer's impact on) and CSV files of
    1-3 rows, through ``testbed identify`` for every identifier of the kind; and records left
    with 1-4 samples by the identifier's own edge trim, stride, split or weak windows.  A traceback, an
    internal error, a status other than 0 / 1 / 2, or a refusal in more than one line, is a
    finding.
``argorder``
    The command line's order and repetition: options after positionals, a ``--`` before the
    data file or a scenario, an option given twice (same and different values), ``--param``
    / ``--prior`` with one key twice, ``--cache`` with ``--no-cache`` (either order), the
    global ``--debug`` after the command, a scenario named twice in one ``run``.  Anything but
    a result or one refusal line where the input is ambiguous is a finding.
``targets``
    The output of ``generate``, ``export`` (UFF and SEP-005) and ``identify`` aimed at a
    folder, a FIFO, ``/dev/null``, ``/dev/full``, a link to nothing, a link to a read-only
    file, a read-only file, a file in a read-only folder, a path under a file, a link to a
    folder, an empty name, a name ending in ``/``; and at a path of accents and spaces in a
    folder not yet made and a link to a writable file (both accepted: the link kept, its file
    written).  A read-only file changed, a link replaced, a refusal in more than one line, or
    an ambiguous target written, is a finding.
``studyedit``
    A sweep resumed after its study file was edited between runs (noise list grown, seeds
    replaced, the identifier's table changed, a local scenario file's rig edited, a scenario
    replaced by another) and ``--retry-failed`` after an edit: the results must then hold
    exactly the current study's cells, each from its current settings (never a row of the old
    settings counted as done); and two sweeps of different noise lists started together on
    one shared dataset cache (real processes): each must end with its own cells, the cache
    entries verified.

``paramshape``
    Every declared hyperparameter of every registered identifier through ``testbed identify
    --param`` in another shape or type than it declares (rounds 20-21 tried values and bounds):
    a list, a boolean or a quoted text where a number is; a number, a list or a text where a
    boolean is; a number, a boolean or a one-item list where a text is; a table, a boolean or
    a scalar of its items' type where a list is.  Anything but one refusal line naming the key
    is a finding.

``unicodetrip``
    ``generate`` -> ``export`` (UFF, SEP-005 as ``.json`` and as ``.sep005`` with ``--format``)
    -> ``identify`` in a folder of accents, CJK letters and spaces, and through a link: a read
    whose equations differ from the dataset file's, or any refusal, is a finding.

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

try:
    from benchmarks import _hostile, hostile19
except ImportError:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks import _hostile, hostile19

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


def _identify(path: Path, kind: str, method: str, *more: str) -> tuple[int, str, str]:
    return cli_inprocess(
        [
            "identify",
            str(path),
            "--kind",
            kind,
            "--method",
            method,
            "-o",
            f"{path}.{method}.model.json",
            *more,
        ]
    )


# ------------------------------------------------------------------ physcombo


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    return repr(v)


def _toml(raw: dict) -> str:
    return "".join(
        f"[{section}]\n" + "".join(f"{k} = {_toml_value(v)}\n" for k, v in table.items())
        for section, table in raw.items()
    )


#: The shipped scenario each rig's cases start from: (name, duration [s]).
PHYS_BASES = {
    "cantilever": ("cantilever_stiff_impact", 0.05),
    "soft": ("cantilever_soft_impact", 0.05),
    "fivebar": ("fivebar_multisine", 0.1),
    "cartpole": ("cartpole", 0.1),
    "kinetics": (MM, 4.0),
}


def physcombo_cases(work: Path) -> list[tuple[str, object]]:
    import h5py

    L, FS = 0.3175, 12800.0
    # label -> (base, duration [s] or None for the base's, edits {section: {key: value}},
    # refuse: True (the combination is impossible) / None (either, in one line))
    rows = [
        (
            "a sensor beyond the beam's length",
            "cantilever",
            None,
            {"rig": {"sensors": [0.1, 0.2, 0.4]}},
            True,
        ),
        (
            "the hammer inboard of the root hinge (segment 0, no sensor)",
            "cantilever",
            None,
            {"rig": {"sensors": [0.2, L]}, "excitation": {"location": 0.01}},
            True,
        ),
        ("the hammer beyond the tip", "cantilever", None, {"excitation": {"location": 0.4}}, True),
        (
            "sample rate 100 Hz, below twice mode 1 (83 Hz)",
            "cantilever",
            0.5,
            {"simulation": {"sample_rate": 100.0}},
            True,
        ),
        (
            "sample rate 150 Hz, below twice mode 1",
            "cantilever",
            0.5,
            {"simulation": {"sample_rate": 150.0}},
            True,
        ),
        ("a pulse longer than the record", "cantilever", None, {"excitation": {"pulse_duration": 0.1}}, True),
        ("the pulse starting after the record", "cantilever", None, {"excitation": {"start": 0.1}}, True),
        (
            "the pulse ending after the record",
            "cantilever",
            None,
            {"excitation": {"start": 0.0499, "pulse_duration": 0.001}},
            True,
        ),
        (
            "a beam thicker than it is long (0.5 m on 0.3175 m)",
            "cantilever",
            None,
            {"rig": {"thickness": 0.5}},
            True,
        ),
        ("a beam wider than it is long (1 m on 0.3175 m)", "cantilever", None, {"rig": {"width": 1.0}}, True),
        ("a record shorter than one period of mode 1", "cantilever", 0.005, {}, True),
        ("E = 1 Pa (the beam folds under the hammer)", "cantilever", None, {"rig": {"E": 1.0}}, True),
        ("a 1 mm beam (mode 1 at 8 MHz)", "cantilever", None, {"rig": {"length": 0.001}}, True),
        ("a record of 1 sample", "cantilever", 1 / FS, {}, True),
        ("a record of 2 samples", "cantilever", 2 / FS, {}, True),
        (
            "a step longer than the sample period",
            "cantilever",
            None,
            {"simulation": {"timestep": 1e-3}},
            True,
        ),
        ("a soft base of k3 = 1e30 N m/rad^3", "soft", None, {"rig": {"base_k3": 1e30}}, True),
        ("a hammer of 1e12 N", "cantilever", None, {"excitation": {"peak_force": 1e12}}, True),
        ("sensors at L/3, 2L/3, L, the tip struck (as shipped)", "cantilever", None, {}, None),
        (
            "five-bar links of 0.2 m on a 1 m base (cannot close)",
            "fivebar",
            None,
            {"rig": {"l1": 0.2, "l2": 0.2, "l3": 0.2, "l4": 0.2}},
            True,
        ),
        ("five-bar base 10 m (cannot close)", "fivebar", None, {"rig": {"L0": 10.0}}, True),
        ("five-bar l2 = 10 m (the start pose cannot close)", "fivebar", None, {"rig": {"l2": 10.0}}, True),
        ("five-bar sample rate above 1/dt", "fivebar", None, {"simulation": {"sample_rate": 1e5}}, True),
        ("five-bar record shorter than a step", "fivebar", 5e-5, {}, True),
        (
            "five-bar tones above the Nyquist frequency",
            "fivebar",
            1.0,
            {"simulation": {"sample_rate": 2.0, "dt": 1e-2}},
            True,
        ),
        ("five-bar f_min > f_max", "fivebar", None, {"excitation": {"f_min": 2.0, "f_max": 1.0}}, True),
        ("five-bar no tone", "fivebar", None, {"excitation": {"n_tones": 0}}, True),
        ("five-bar a link of 1e-9 kg", "fivebar", None, {"rig": {"m2": 1e-9}}, True),
        ("five-bar a record of 1 sample", "fivebar", 1e-4, {}, True),
        ("five-bar a record of 2 samples", "fivebar", 2e-4, {}, None),
        (
            "five-bar both cranks along the base (th1_0 = th4_0 = 0)",
            "fivebar",
            None,
            {"rig": {"th1_0": 0.0, "th4_0": 0.0}},
            None,
        ),
        ("five-bar start rates of 1e6 rad/s", "fivebar", None, {"rig": {"dth1_0": 1e6}}, True),
        ("cart-pole cart of 0 kg", "cartpole", None, {"rig": {"cart_mass": 0.0}}, True),
        ("cart-pole pole of 0 kg", "cartpole", None, {"rig": {"pole_mass": 0.0}}, True),
        ("cart-pole pole of 0 m", "cartpole", None, {"rig": {"pole_length": 0.0}}, True),
        (
            "cart-pole masses of 1e-12 kg",
            "cartpole",
            None,
            {"rig": {"cart_mass": 1e-12, "pole_mass": 1e-12}},
            True,
        ),
        ("cart-pole sample rate above 1/dt", "cartpole", None, {"simulation": {"sample_rate": 1e5}}, True),
        ("cart-pole a record of 1 sample", "cartpole", 1e-3, {}, True),
        ("cart-pole a record of 2 samples", "cartpole", 2e-3, {}, None),
        (
            "cart-pole tones above the Nyquist frequency",
            "cartpole",
            1.0,
            {"simulation": {"sample_rate": 2.0}},
            True,
        ),
        (
            "cart-pole pole started horizontal (th0 = pi/2)",
            "cartpole",
            None,
            {"rig": {"th0": 1.5707963267948966}},
            True,
        ),
        (
            "cart-pole no gravity, no damping, no centring",
            "cartpole",
            None,
            {
                "rig": {"gravity": 0.0, "cart_damping": 0.0, "pole_damping": 0.0},
                "excitation": {"kp": 0.0, "kd": 0.0},
            },
            None,
        ),
        ("cart-pole a start speed of 1e9 m/s", "cartpole", None, {"rig": {"dx0": 1e9}}, True),
        ("kinetics Km < 0", "kinetics", None, {"rig": {"Km": -0.3}}, True),
        ("kinetics Vmax < 0", "kinetics", None, {"rig": {"Vmax": -1.5}}, True),
        ("kinetics a negative dose (x0 < 0)", "kinetics", None, {"rig": {"x0": -2.0}}, True),
        ("kinetics x0 = -Km (the rate's pole)", "kinetics", None, {"rig": {"x0": -0.3}}, True),
        ("kinetics a negative influx", "kinetics", None, {"rig": {"jx": -0.6}}, True),
        ("kinetics Km = 0", "kinetics", None, {"rig": {"Km": 0.0}}, True),
        ("kinetics started at its steady state", "kinetics", None, {"rig": {"x0": 0.2}}, True),
        ("kinetics Km = 1e-300", "kinetics", None, {"rig": {"Km": 1e-300}}, True),
        ("kinetics influx 1e300 mM/s", "kinetics", None, {"rig": {"jx": 1e300}}, True),
        ("kinetics sampled at 1e-3 Hz", "kinetics", None, {"simulation": {"sample_rate": 1e-3}}, True),
        ("kinetics a record of 1 sample", "kinetics", 0.01, {}, True),
        ("kinetics a record of 2 samples", "kinetics", 0.02, {}, True),
        ("kinetics a record of 3 samples", "kinetics", 0.03, {}, True),
        ("kinetics Vmax < jx (no steady state: x grows)", "kinetics", None, {"rig": {"Vmax": 0.3}}, None),
        ("kinetics Vmax = jx", "kinetics", None, {"rig": {"Vmax": 0.6}}, None),
        ("kinetics started empty (x0 = 0)", "kinetics", None, {"rig": {"x0": 0.0}}, None),
    ]

    def case(label: str, base: str, duration, edits: dict, refuse):
        def run():
            _, raw = _hostile.base_scenario(PHYS_BASES, base)
            if duration is not None:
                raw["simulation"]["duration"] = duration
            for section, table in edits.items():
                raw.setdefault(section, {}).update(table)
            raw["scenario"]["name"] = f"h22_{_safe(label)}"[:100]
            path = work / f"{raw['scenario']['name']}.toml"
            path.write_text(_toml(raw))
            out = work / f"{path.stem}.h5"
            status, stdout, err = cli_inprocess(
                ["generate", str(path), "-o", str(out), "--cache", str(work / "cache")]
            )
            found = judged(status, stdout, err, refuse=bool(refuse))
            if found:
                return found
            if status == 2 and not re.search(r"key '[\w.]+|\(\w+\)|cantilever:|fivebar:|cartpole:", err):
                return f"refused without naming a key: {err.strip()[:200]}"
            if status == 0:
                with h5py.File(out, "r") as f:
                    bad = [n for n in f["measured"] if not np.isfinite(f["measured"][n][()]).all()]
                if bad:
                    return f"accepted, and its dataset holds non-finite samples in {bad}"
            return None

        return run

    return [(f"physcombo {label}", case(label, *how)) for label, *how in rows]


# ------------------------------------------------------------------ tinyrec


def _cut(src: Path, dst: Path, start: int, n: int) -> Path:
    """``src`` with every signal cut to samples ``[start, start + n)``, its hash made anew."""
    import h5py

    shutil.copy(src, dst)
    with h5py.File(dst, "r+") as f:
        for group in ("measured", "reference"):
            for name in list(f[group]):
                d = f[group][name]
                attrs, data = dict(d.attrs), d[()]
                del f[group][name]
                new = f[group].create_dataset(name, data=data[..., start : start + n])
                for k, v in attrs.items():
                    new.attrs[k] = v
    _rehash(dst)
    return dst


def tinyrec_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.plugins import IDENTIFIERS

    # the beam's hammer starts at 0.005 s (sample 64 at 12.8 kHz): cut from sample 62 on so
    # that even a few samples move
    records = {
        "dynamical": (MM, 0, (1, 2, 3, 4, 5, 8)),
        "structural": (BEAM, 62, (1, 2, 3, 5, 8, 16)),
        "mechanical": (FIVEBAR, 0, (1, 2, 3, 5, 8)),
    }
    #: a short fit of the slow identifiers: the round asks for a verdict, not a good model
    quick = {
        "sgd_sindy": ["--param", "epochs=2"],
        "sgd_sindy_coefficients": ["--param", "epochs=2"],
        "pysindy_pi": ["--param", "max_iter=2"],
    }

    def case(kind: str, method: str, n: int):
        def run():
            scenario, start, _ = records[kind]
            path = _cut(_generated(work, scenario), work / f"{kind}_{n}.h5", start, n)
            return judged(*_identify(path, kind, method, *quick.get(method, [])))

        return run

    def csv_case(rows: int):
        def run():
            path = work / f"rows{rows}.csv"
            path.write_text(
                "time [s],x [mM],dx [mM/s]\n"
                + "".join(f"{k / 100!r},{2.0 - 0.1 * k!r},{-1.0 + 0.01 * k!r}\n" for k in range(rows))
            )
            return judged(*_identify(path, "dynamical", "sindy_pi_dynamical"))

        return run

    out = []
    for kind, (_, _, lengths) in records.items():
        methods = [m for m in IDENTIFIERS.names() if IDENTIFIERS.get(m).kind == kind]
        for n in lengths:
            for method in methods:
                out.append((f"tinyrec {kind} {n} sample(s) {method}", case(kind, method, n)))
    out += [(f"tinyrec CSV of {r} row(s)", csv_case(r)) for r in (1, 2, 3)]

    def trimmed(kind: str, method: str, n: int, *params: str):
        """A record of ``n`` samples left with 1-4 after the identifier's own trim, stride
        or split."""

        def run():
            scenario, start, _ = records[kind]
            path = _cut(_generated(work, scenario), work / f"{kind}_{n}.h5", start, n)
            more = [x for p in params for x in ("--param", p)]
            return judged(*_identify(path, kind, method, *more))

        return run

    for method, params in (
        ("sindy_pi", ("edge_trim=0.0499",)),
        ("sindy_pi", ("edge_trim=0.04985",)),
        ("pysindy_pi", ("edge_trim=0.0499",)),
        ("pysindy_pi", ("stride=999",)),
        ("sindy_pi", ("val_fraction=0.99",)),
        ("sindy_pi", ('formulation="weak"', "weak_window_s=0.099")),
    ):
        out.append(
            (
                f"tinyrec mechanical 1000 samples, {method} {' '.join(params)}",
                trimmed("mechanical", method, 1000, *params),
            )
        )
    for params in (("val_fraction=0.995",), ('formulation="weak"', "weak_window_s=3.99")):
        out.append(
            (
                f"tinyrec dynamical 400 samples, sindy_pi_dynamical {' '.join(params)}",
                trimmed("dynamical", "sindy_pi_dynamical", 400, *params),
            )
        )
    return out


# ------------------------------------------------------------------ argorder


def argorder_cases(work: Path) -> list[tuple[str, object]]:
    def argv_for(mm: Path, out: Path) -> dict[str, tuple[list[str], bool | None]]:
        base = ["--kind", "dynamical", "--method", "sindy_pi_dynamical"]
        c = str(CACHE)
        # label -> (argv, refuse: True / False / None (either, in one line))
        return {
            "identify, options after the data file": (["identify", str(mm), *base, "-o", str(out)], False),
            "identify, -- before the data file": (["identify", *base, "-o", str(out), "--", str(mm)], False),
            "identify, --param one key twice (two values)": (
                ["identify", str(mm), *base, "-o", str(out), "--param", "degree=3", "--param", "degree=2"],
                True,
            ),
            "identify, --param one key twice (one value)": (
                ["identify", str(mm), *base, "-o", str(out), "--param", "degree=3", "--param", "degree=3"],
                True,
            ),
            "identify, --prior one key twice": (
                [
                    "identify",
                    str(mm),
                    *base,
                    "-o",
                    str(out),
                    "--prior",
                    "total_mass=1",
                    "--prior",
                    "total_mass=2",
                ],
                True,
            ),
            "identify, --method twice": (
                ["identify", str(mm), *base, "--method", "ls_sindy", "-o", str(out)],
                True,
            ),
            "identify, --kind twice": (
                ["identify", str(mm), "--kind", "structural", *base, "-o", str(out)],
                True,
            ),
            "identify, -o twice": (["identify", str(mm), *base, "-o", str(out), "-o", f"{out}2"], True),
            "identify, --fs twice": (
                ["identify", str(mm), *base, "-o", str(out), "--fs", "100", "--fs", "200"],
                True,
            ),
            "identify, the data file twice": (["identify", str(mm), str(mm), *base, "-o", str(out)], True),
            "identify, --debug after the command": (
                ["identify", "--debug", str(mm), *base, "-o", str(out)],
                True,
            ),
            "generate, --cache then --no-cache": (
                ["generate", MM, "-o", str(work / "a.h5"), "--cache", c, "--no-cache"],
                True,
            ),
            "generate, --no-cache then --cache": (
                ["generate", MM, "-o", str(work / "a.h5"), "--no-cache", "--cache", c],
                True,
            ),
            "generate, -o twice": (
                ["generate", MM, "-o", str(work / "a.h5"), "-o", str(work / "b.h5"), "--cache", c],
                True,
            ),
            "generate, -- before the scenario": (
                ["generate", "-o", str(work / "c.h5"), "--cache", c, "--", MM],
                False,
            ),
            "run, --cache then --no-cache": (
                ["run", MM, "--no-figures", "-o", str(work / "runs"), "--cache", c, "--no-cache"],
                True,
            ),
            "run, --seed twice": (
                [
                    "run",
                    MM,
                    "--seed",
                    "1",
                    "--seed",
                    "2",
                    "-o",
                    str(work / "runs"),
                    "--no-figures",
                    "--cache",
                    c,
                ],
                True,
            ),
            "run, an option name after --": (
                ["run", "--no-figures", "-o", str(work / "runs"), "--", MM, "--seed"],
                True,
            ),
            "run, options between two scenarios": (
                [
                    "run",
                    MM,
                    "--no-figures",
                    "--cache",
                    c,
                    "michaelis_menten_noise1",
                    "-o",
                    str(work / "runs"),
                ],
                False,
            ),
            "export, --format twice": (
                ["export", str(mm), "--format", "uff", "--format", "sep005", "-o", str(work / "e.x")],
                True,
            ),
            "sweep, --jobs twice": (
                ["sweep", "smoke", "--jobs", "1", "--jobs", "2", "--results", str(work / "r.parquet")],
                True,
            ),
            "list, --version after the command": (["list", "--version"], True),
        }

    def case(label: str):
        def run():
            mm = _generated(work, MM)
            argv, refuse = argv_for(mm, work / "m.json")[label]
            status, out, err = cli_inprocess(argv)
            found = judged(status, out, err, refuse=bool(refuse))
            if found:
                return found
            if refuse is False and status == 2:
                return f"refused: {err.strip()[:200]}"
            return None

        return run

    return [(f"argorder {label}", case(label)) for label in argv_for(Path("d"), Path("o"))]


# ------------------------------------------------------------------ targets


def targets_cases(work: Path) -> list[tuple[str, object]]:
    def make_targets(d: Path) -> dict[str, tuple[str, bool]]:
        """label -> (the target's text, refuse), each made fresh in ``d``."""
        d.mkdir(parents=True, exist_ok=True)
        (d / "adir").mkdir(exist_ok=True)
        if not (d / "fifo").exists():
            os.mkfifo(d / "fifo")
        ro = d / "ro.txt"
        if not ro.exists():
            ro.write_text("keep")
            ro.chmod(0o444)
        ro2 = d / "ro2.txt"
        if not ro2.exists():
            ro2.write_text("keep")
            ro2.chmod(0o444)
        rodir = d / "rodir"
        if not rodir.exists():
            rodir.mkdir()
            rodir.chmod(0o555)
        writable = d / "writable.txt"
        writable.write_text("keep")
        for link, to in (
            ("dangle", d / "nowhere" / "x"),
            ("to_ro", ro),
            ("to_dir", d / "adir"),
            ("to_writable", writable),
        ):
            if not os.path.lexists(d / link):
                os.symlink(to, d / link)
        return {
            "a folder": (str(d / "adir"), True),
            "a FIFO": (str(d / "fifo"), True),
            "/dev/null": ("/dev/null", True),
            "/dev/full": ("/dev/full", True),
            "a link to nothing": (str(d / "dangle"), True),
            "a link to a read-only file": (str(d / "to_ro"), True),
            "a read-only file": (str(ro2), True),
            "a new file in a read-only folder": (str(rodir / "x.out"), True),
            "a path under a file": (str(ro / "x.out"), True),
            "a link to a folder": (str(d / "to_dir"), True),
            "a name ending in '/'": (str(d / "newdir") + "/", True),
            "accents and spaces in a folder not yet made": (str(d / "résumé données ü" / "x y.out"), False),
            "a link to a writable file": (str(d / "to_writable"), False),
        }

    commands = {
        "generate": lambda o: ["generate", MM, "-o", o, "--cache", str(CACHE)],
        "export uff": lambda o: ["export", str(_generated(work, BEAM)), "--format", "uff", "-o", o],
        "export sep005": lambda o: ["export", str(_generated(work, BEAM)), "--format", "sep005", "-o", o],
        "identify": lambda o: [
            "identify",
            str(_generated(work, MM)),
            "--kind",
            "dynamical",
            "--method",
            "sindy_pi_dynamical",
            "-o",
            o,
        ],
    }

    def case(command: str, label: str):
        def run():
            d = work / _safe(command) / _safe(label)
            target, refuse = make_targets(d)[label]
            status, out, err = cli_inprocess(commands[command](target))
            found = judged(status, out, err, refuse=refuse)
            if found:
                return found
            for kept in ("ro.txt", "ro2.txt"):
                if (d / kept).read_text(errors="replace") != "keep":
                    return f"the read-only {kept} was changed"
            for link in ("dangle", "to_ro", "to_dir", "to_writable"):
                if not (d / link).is_symlink():
                    return f"the link {link} was replaced"
            if not refuse and status == 2:
                return f"refused: {err.strip()[:200]}"
            if (
                label == "a link to a writable file"
                and (d / "writable.txt").read_text(errors="replace") == "keep"
            ):
                return "the link's file was not written"
            if (d / "newdir").exists() and not (d / "newdir").is_dir():
                return "a file named as the folder 'newdir/' was written"
            return None

        return run

    labels = list(make_targets(work / "probe"))
    return [
        (f"targets {command} -o {label}", case(command, label)) for command in commands for label in labels
    ]


# ------------------------------------------------------------------ studyedit


def studyedit_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.studies.results import read_results

    def write_study(
        folder: Path, scenarios: str, noise: str = "[0.0]", seeds: str = "[0]", extra: str = ""
    ) -> Path:
        return hostile19._write(
            folder / "h22.toml",
            f'[study]\nname = "h22"\nscenarios = {scenarios}\nnoise = {noise}\n'
            f'seeds = {seeds}\nidentifiers = ["sindy_pi_dynamical"]\n{extra}',
        )

    def local_scenario(folder: Path, km: float) -> Path:
        from testbed.pipeline.scenario import SCENARIO_DIR

        text = (SCENARIO_DIR / f"{MM}.toml").read_text().replace(f'name = "{MM}"', 'name = "mm_h22"')
        return hostile19._write(folder / "mm_h22.toml", text.replace("Km = 0.3", f"Km = {km!r}"))

    def sweep(folder: Path, *more: str) -> tuple[int, str, str]:
        return cli_inprocess(
            [
                "sweep",
                str(folder / "h22.toml"),
                "--results",
                str(folder / "r.parquet"),
                "--jobs",
                "1",
                "--cache",
                str(CACHE),
                *more,
            ]
        )

    def rows(folder: Path) -> list[dict]:
        return read_results(folder / "r.parquet")

    def edited(label: str, first: dict, second: dict, want: set, check=None, more=(), fresh: bool = False):
        """Sweep with ``first``'s study, edit it to ``second``'s, sweep again: the results
        hold exactly the cells ``want`` ((scenario, noise, seed) triples), checked by
        ``check(rows)`` too; with ``fresh``, none from a dataset of the first sweep."""

        def run():
            folder = work / _safe(label)
            folder.mkdir(exist_ok=True)
            before: set = set()
            for step, kw in enumerate((first, second)):
                kw = dict(kw)
                if "km" in kw:
                    kw["scenarios"] = f'["{local_scenario(folder, kw.pop("km"))}"]'
                write_study(folder, **kw)
                found = judged(*sweep(folder, *(more if step else ())))
                if found:
                    return f"sweep {step + 1}: {found}"
                if step == 0:
                    before = {r["dataset_hash"] for r in rows(folder)}
            got = [(r["scenario"], float(r["noise"]), int(r["seed"])) for r in rows(folder)]
            if len(got) != len(set(got)) or set(got) != want:
                return f"results hold {sorted(got)}; the study's cells are {sorted(want)}"
            if fresh and {r["dataset_hash"] for r in rows(folder)} & before:
                return "a row of the edited scenario kept from the dataset before the edit"
            return check(rows(folder)) if check else None

        return run

    def params_are(degree: int):
        def check(rs):
            bad = [r["params"] for r in rs if json.loads(r["params"]).get("degree") != degree]
            return f"rows fitted with other settings: {bad}" if bad else None

        return check

    mm = f'["{MM}"]'
    cases = [
        edited(
            "noise list grown",
            {"scenarios": mm},
            {"scenarios": mm, "noise": "[0.0, 1.0]"},
            {(MM, 0.0, 0), (MM, 1.0, 0)},
        ),
        edited(
            "seeds replaced",
            {"scenarios": mm, "noise": "[1.0]"},
            {"scenarios": mm, "noise": "[1.0]", "seeds": "[3]"},
            {(MM, 1.0, 3)},
        ),
        edited(
            "identifier table added (degree 2)",
            {"scenarios": mm},
            {"scenarios": mm, "extra": "[identifiers.sindy_pi_dynamical]\ndegree = 2\n"},
            {(MM, 0.0, 0)},
            params_are(2),
        ),
        edited(
            "identifier table removed",
            {"scenarios": mm, "extra": "[identifiers.sindy_pi_dynamical]\ndegree = 2\n"},
            {"scenarios": mm},
            {(MM, 0.0, 0)},
            params_are(3),
        ),
        edited(
            "scenario replaced by its noisy twin",
            {"scenarios": mm},
            {"scenarios": '["michaelis_menten_noise1"]'},
            {("michaelis_menten_noise1", 0.0, 0)},
        ),
        edited("a local scenario's Km edited", {"km": 0.3}, {"km": 0.5}, {("mm_h22", 0.0, 0)}, fresh=True),
        edited(
            "a local scenario's Km edited, --retry-failed",
            {"km": 0.3},
            {"km": 0.4},
            {("mm_h22", 0.0, 0)},
            more=("--retry-failed",),
            fresh=True,
        ),
        edited(
            "noise list shrunk", {"scenarios": mm, "noise": "[0.0, 1.0]"}, {"scenarios": mm}, {(MM, 0.0, 0)}
        ),
    ]
    labels = [
        "noise list grown",
        "seeds replaced",
        "identifier table added (degree 2)",
        "identifier table removed",
        "scenario replaced by its noisy twin",
        "a local scenario's Km edited",
        "a local scenario's Km edited, --retry-failed",
        "noise list shrunk",
    ]
    out = [(f"studyedit {label}", fn) for label, fn in zip(labels, cases, strict=True)]

    def concurrent():
        """Two sweeps of different noise lists on one new shared cache, started together."""
        folder = work / "concurrent"
        cache = folder / "cache"
        procs = []
        for k, noise in enumerate(("[0.0, 1.0]", "[0.0, 5.0]")):
            sub = folder / f"s{k}"
            sub.mkdir(parents=True, exist_ok=True)
            write_study(sub, f'["{MM}"]', noise=noise, seeds="[0, 1]")
            procs.append(
                subprocess.Popen(
                    [
                        sys.executable,
                        "-m",
                        "testbed.cli",
                        "sweep",
                        str(sub / "h22.toml"),
                        "--results",
                        str(sub / "r.parquet"),
                        "--jobs",
                        "1",
                        "--cache",
                        str(cache),
                    ],
                    cwd=sub,
                    env=_hostile.ENV,
                    stdout=subprocess.PIPE,
                    stderr=subprocess.PIPE,
                    text=True,
                )
            )
        for k, p in enumerate(procs):
            try:
                out_text, err = p.communicate(timeout=TIMEOUT_S - 20)
            except subprocess.TimeoutExpired:
                for q in procs:
                    q.kill()
                return f"sweep {k}: still running"
            found = _hostile.cli_finding(subprocess.CompletedProcess(p.args, p.returncode, out_text, err))
            if found:
                return f"sweep {k}: {found}"
        for k, noise in enumerate(((0.0, 1.0), (0.0, 5.0))):
            got = {(float(r["noise"]), int(r["seed"])) for r in rows(folder / f"s{k}")}
            want = {(n, s) for n in noise for s in (0, 1)}
            if got != want:
                return f"sweep {k}: results hold {sorted(got)}, its cells are {sorted(want)}"
        time.sleep(0.1)
        temps = [p.name for p in cache.rglob("*") if p.name.endswith(".tmp")]
        return f"temporary files left in the cache: {temps}" if temps else None

    out.append(("studyedit two sweeps of different noise lists on one new cache, together", concurrent))
    return out


# ------------------------------------------------------------------ paramshape


def _wrong_shapes(field) -> list[str]:
    """``--param`` values (TOML) of another shape or type than ``field`` declares: a list or a
    boolean where a number is, a number or a list where a boolean or a text is, a scalar or a
    table where a list is (a form the field's ``also`` accepts left out)."""
    if field.type in (int, float):
        out = ["[1]", "true", '"1"']
    elif field.type is bool:
        out = ["1", "[true]", '"true"']
    elif field.type is str:
        first = json.dumps(str(field.default if field.default not in (None, "") else "x"))
        out = ["1", "true", f"[{first}]"]
    elif field.type is list:
        item = field.item_type
        out = ["{a = 1}", "true"] + (["0.1"] if item in (int, float) else ['"x"'] if item is str else [])
    else:
        out = []
    also = getattr(field, "also", None)
    if also is not None and also.type is list:
        out = [v for v in out if not v.startswith("[")]
    return out


def paramshape_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.plugins import IDENTIFIERS

    record = {"dynamical": MM, "structural": BEAM, "mechanical": FIVEBAR}

    def case(method: str, kind: str, key: str, text: str):
        def run():
            path = _generated(work, record[kind])
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
        if cls.kind not in record:
            continue
        for key, field in cls.declared_hyperparameters().items():
            out += [
                (f"paramshape {method} {key}={text}", case(method, cls.kind, key, text))
                for text in _wrong_shapes(field)
            ]
    return out


# ------------------------------------------------------------------ unicodetrip


def unicodetrip_cases(work: Path) -> list[tuple[str, object]]:
    """generate -> export (UFF, SEP-005) -> identify in a folder of accents, CJK letters and
    spaces, through a link too: each read must give the dataset file's equations (the UFF and
    SEP-005 files carry no prior: the dataset's reduced mass trace is given as ``--prior``)."""
    import h5py

    folder = work / "dossier é ü 漢字 sp"
    h5 = folder / "beam é.h5"
    method = ["--kind", "structural", "--method", "ls_sindy"]

    def equations(path: Path, *more: str) -> tuple[object, str | None]:
        status, out, err = cli_inprocess(["identify", str(path), *method, "-o", f"{path}.model.json", *more])
        found = judged(status, out, err, refuse=False)
        if found or status != 0:
            return None, found or f"status {status}: {err.strip()[:200]}"
        return json.loads(Path(f"{path}.model.json").read_text()).get("equations"), None

    def base() -> tuple[object, list[str]]:
        if not h5.exists():
            folder.mkdir(parents=True, exist_ok=True)
            status, _, err = cli_inprocess(["generate", BEAM, "-o", str(h5), "--cache", str(CACHE)])
            if status != 0:
                raise RuntimeError(err)
        with h5py.File(h5, "r") as f:
            trace = float(f["prior"].attrs["reduced_mass_trace"])
        eq, found = equations(h5)
        if found:
            raise RuntimeError(found)
        return eq, ["--prior", f"reduced_mass_trace={trace!r}"]

    def case(fmt: str, name: str, *more: str, link: bool = False):
        def run():
            want, prior = base()
            out = folder / name
            status, stdout, err = cli_inprocess(["export", str(h5), "--format", fmt, "-o", str(out)])
            found = judged(status, stdout, err, refuse=False)
            if found:
                return f"export: {found}"
            path = out
            if link:
                path = folder / f"lien vers {name}"
                if not path.is_symlink():
                    path.symlink_to(out)
            got, found = equations(path, *prior, *more)
            if found:
                return f"identify: {found}"
            return None if got == want else "the equations differ from the dataset file's"

        return run

    return [
        ("unicodetrip UFF", case("uff", "sortie é.uff")),
        ("unicodetrip SEP-005 (.json)", case("sep005", "sortie é.json")),
        (
            "unicodetrip SEP-005 as .sep005, --format sep005",
            case("sep005", "sortie é.sep005", "--format", "sep005"),
        ),
        ("unicodetrip UFF through a link", case("uff", "lié é.uff", link=True)),
        ("unicodetrip SEP-005 through a link", case("sep005", "lié é.json", link=True)),
    ]


# ------------------------------------------------------------------ main

FAMILIES = _hostile.families(
    {
        "physcombo": physcombo_cases,
        "tinyrec": tinyrec_cases,
        "argorder": argorder_cases,
        "targets": targets_cases,
        "studyedit": studyedit_cases,
        "paramshape": paramshape_cases,
        "unicodetrip": unicodetrip_cases,
    },
    TIMEOUT_S,
)


def main(argv: list[str]) -> int:
    return _hostile.main(argv, FAMILIES, "hostile22-")


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
