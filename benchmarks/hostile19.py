"""Nineteenth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile19 [family ...]      # all families when none is named

Families (what rounds 1-18 did not try):

``tomlform``
    Scenario files whose TOML *form* is hostile, not a value's type (round 17's ``toml``): a
    byte-order mark, a UTF-16 file, a NUL byte, CRLF line ends, names in other scripts, a table
    given twice, ``[rig]`` as an inline table or an array of tables, ``[[scenario]]``, dotted keys
    reaching into another table, a key that is itself a table, the whole file empty or a comment,
    ``seed`` as 2**64, -0, -0.0 or an integer of 5,000 digits, ``duration`` x ``sample_rate``
    overflowing the sample count, numbers at 1e308, 5e-324 and -0.0, booleans where numbers are
    expected.  A traceback, anything but one refusal line, or a hostile value accepted
    silently, is a finding.
``studyform``
    Study files with empty grids (no scenario, noise level, seed or identifier), duplicate cells
    (a seed twice, noise 0.0 and -0.0, a scenario twice, an identifier twice), a parameter table
    for an identifier the study does not run, a parameter table of the wrong type, a study
    resumed after a seed was removed, and ``--retry-failed`` on a results file of another study:
    a traceback, rows of two cells under one key, or a parameter table ignored in silence, is a
    finding.
``h5form``
    A dataset file (``testbed generate``) rewritten with a measured array as complex, int8,
    big-endian float64 (accepted: the same numbers), NaN or inf samples, channels of unequal
    length across signals, zero-length, one sample; the path a folder, a symlink loop, a FIFO
    (no writer: a reader that opens it blocks) and ``/dev/null``: ``testbed identify`` and
    ``export``.  A hang, a traceback, anything but one refusal line, or a record of mixed
    lengths or non-finite samples fitted, is a finding.
``uffform``
    A UFF58 export of the stiff beam edited with pyuff: one channel's abscissa spacing doubled,
    zero, negative, NaN; one acceleration in g beside the others in m/s^2 (a mixed-unit record,
    accepted when converted), a non-ASCII header, one channel shorter: ``testbed identify``.
``cliargs``
    The command line: unknown flags, ``--jobs`` 0, -1, 1e3, ``2**70``, text; ``--seed`` -1, 2**64,
    1.5, NaN, text; ``-o`` inside a file (``Not a directory``), ``-o`` an existing folder where
    a file is written, ``--results`` a folder, ``--cache`` a file, an empty ``--plugin``.  A
    traceback, a status other than 0/1/2, or more than one error line, is a finding.
``apiuse``
    The Python API used out of order or with the wrong types: an identifier fitted twice (the
    second fit must equal a fresh one), ``score`` / ``predict_acceleration`` / ``equations``
    before ``fit``, a fit on a 3-sample record, hyperparameters of the wrong type stored by
    ``__init__`` or ``set_params`` (a text ``degree``, a list ``rcond``, NaN, a boolean where
    a number is expected), ``run_scenario`` given a dict, a Dataset or a list.  A raw
    exception from inside, a wrong-typed hyperparameter fitted in silence, or a refit that
    differs from a fresh fit, is a finding.
``csvform``
    The Michaelis-Menten record as CSV text in spreadsheet and logger forms: decimal commas,
    tabs, a byte-order mark, CRLF, time in ms (declared, and declared as s), swapped or repeated
    time stamps, a header repeated mid-file, blank lines, NaN and empty cells, ragged rows, a
    trailing empty column, quoted numbers, thousands separators, Latin-1 text, a column named
    twice, a header alone, ``--fs`` contradicting the time column or at 1e-320 Hz.  A form read
    whose model differs from the clean file's, or anything but one refusal line, is a finding.
``plugins``
    A user's ``--plugin`` identifier that raises GeneratorExit, a BaseException subclass or
    ``sys.exit(0)`` at import or in ``fit``, leaves ``simulate`` out, returns None, or leaves
    its matrices NaN, of another size, complex, float16, boolean, text, 1e308 times too large,
    zero or negative; and ``os._exit(0)`` in ``fit`` through a real command.  A traceback, an
    internal error, a pass of a broken model, or status 0 without a verdict, is a finding.

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import sys
from pathlib import Path

import numpy as np

try:
    from benchmarks import _hostile
except ImportError:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks import _hostile

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 180
#: The shipped dataset cache: most cases simulate nothing new.
CACHE = ROOT / ".cache" / "datasets"

cli_inprocess = _hostile.cli_inprocess


judged = _hostile.judged


def _safe(label: str) -> str:
    return "".join(c if c.isalnum() else "_" for c in label)[:80]


# ------------------------------------------------------------------ tomlform

MM = "michaelis_menten"


def _mm_text() -> str:
    from testbed.pipeline.scenario import SCENARIO_DIR

    return (SCENARIO_DIR / f"{MM}.toml").read_text()


def tomlform_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.scenario import load_scenario

    base = _mm_text()

    def case(label: str, make, accept: bool = False, check=None):
        def run():
            folder = work / _safe(label)
            folder.mkdir(exist_ok=True)
            path = folder / f"{MM}.toml"
            content = make(base)
            if isinstance(content, str):
                path.write_text(content, encoding="utf-8")
            else:
                path.write_bytes(content)
            sc = load_scenario(path, check_cost=True)
            if check is not None:
                return check(sc)
            return None if accept else "loaded: the hostile form was accepted in silence"
        return run

    def sub(old: str, new: str):
        """Replace ``old`` where it starts a line (the shipped file's comments quote values)."""
        def make(t: str) -> str:
            assert "\n" + old in t, old
            return t.replace("\n" + old, "\n" + new, 1)
        return make

    def seed_is(want):
        return lambda sc: None if sc.seed == want and type(sc.seed) is int else f"seed read as {sc.seed!r}"

    def rig_is(key, want):
        return lambda sc: None if sc.rig_params[key] == want else f"{key} read as {sc.rig_params[key]!r}"

    rig_block = "[rig]\njx = 0.6\nVmax = 1.5\nKm = 0.3\nx0 = 2.0\n"
    cases = [
        ("byte-order mark (read past, as a UTF-8 file's)", lambda t: "\ufeff" + t, True),
        ("UTF-16 file", lambda t: t.encode("utf-16"), False),
        ("NUL byte in a comment", lambda t: t.replace("# Michaelis", "# Mich\0aelis", 1), False),
        ("CRLF line ends (accepted)", lambda t: t.replace("\n", "\r\n"), True),
        ("lone CR line ends", lambda t: t.replace("\n", "\r"), False),
        ("description in Greek and CJK (accepted)",
         sub('description = "Michaelis', 'description = "κινητική 動力学 Michaelis'), True),
        ("name with a right-to-left override", sub('name = "michaelis_menten"',
                                                    'name = "michaelis\u202e_menten"'), False),
        ("[rig] twice", lambda t: t + "\n[rig]\njx = 0.7\n", False),
        ("[rig] as an inline table",
         lambda t: t.replace(rig_block, "rig = {jx = 0.6, Vmax = 1.5, Km = 0.3, x0 = 2.0}\n"), False),
        ("[[rig]] array of tables", lambda t: t.replace("[rig]", "[[rig]]", 1), False),
        ("[[scenario]] array of tables", lambda t: t.replace("[scenario]", "[[scenario]]", 1), False),
        ("dotted key reaching into [rig] from [simulation]",
         sub("sample_rate = 100.0", "sample_rate = 100.0\nrig.jx = 0.7"), False),
        ("dotted key rig.jx at the top (the table then redefined)",
         lambda t: "rig.jx = 0.7\n" + t, False),
        ("a rig key that is a table", sub("jx = 0.6", "jx = {value = 0.6}"), False),
        ("empty file", lambda t: "", False),
        ("only a comment", lambda t: "# nothing\n", False),
        ("seed 2**64", sub("seed = 0", f"seed = {2**64}"), False),
        ("seed -0 (an integer zero)", sub("seed = 0", "seed = -0"), True, seed_is(0)),
        ("seed -0.0", sub("seed = 0", "seed = -0.0"), False),
        ("seed of 5,000 digits", sub("seed = 0", "seed = " + "9" * 5000), False),
        ("seed 0x10 (hex, accepted as 16)", sub("seed = 0", "seed = 0x10"), True, seed_is(16)),
        ("seed 1_000 (accepted)", sub("seed = 0", "seed = 1_000"), True, seed_is(1000)),
        ("duration x sample_rate overflowing the count",
         sub("duration = 4.0\nsample_rate = 100.0", "duration = 1e300\nsample_rate = 1e300"), False),
        ("duration 1e308", sub("duration = 4.0", "duration = 1e308"), False),
        ("sample_rate 5e-324", sub("sample_rate = 100.0", "sample_rate = 5e-324"), False),
        ("duration -0.0", sub("duration = 4.0", "duration = -0.0"), False),
        ("Km -0.0", sub("Km = 0.3", "Km = -0.0"), False),
        ("jx -0.0 (no influx: accepted as 0)", sub("jx = 0.6", "jx = -0.0"), True),
        ("x0 5e-324", sub("x0 = 2.0", "x0 = 5e-324"), True),
        ("Vmax true", sub("Vmax = 1.5", "Vmax = true"), False),
        ("rms_percent false", sub("rms_percent = 0.0", "rms_percent = false"), False),
        ("degree true", sub("degree = 3", "degree = true"), False),
        ("Vmax as an integer 2 (accepted as 2.0)", sub("Vmax = 1.5", "Vmax = 2"), True,
         rig_is("Vmax", 2.0)),
        ("Km as 1e400 (TOML inf)", sub("Km = 0.3", "Km = 1e400"), False),
        ("tags with a NUL escape", sub('tags = ["michaelis_menten"', 'tags = ["mm\\u0000"'), False),
        ("a key with a trailing space in quotes", sub("jx = 0.6", '"jx " = 0.6'), False),
    ]
    return [(f"tomlform {label}", case(label, make, accept, *rest))
            for label, make, accept, *rest in cases]


# ------------------------------------------------------------------ studyform

def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def studyform_cases(work: Path) -> list[tuple[str, object]]:
    def study(folder: Path, scenarios='["michaelis_menten"]', noise="[0.0]", seeds="[0]",
              identifiers='["sindy_pi_dynamical"]', extra: str = "", name: str = "h19") -> Path:
        return _write(folder / "h19.toml",
                      f'[study]\nname = "{name}"\nscenarios = {scenarios}\nnoise = {noise}\n'
                      f"seeds = {seeds}\nidentifiers = {identifiers}\n{extra}")

    def sweep(folder: Path, *more: str) -> tuple[int, str, str]:
        return cli_inprocess(["sweep", str(folder / "h19.toml"), "--results",
                              str(folder / "results.parquet"), "--cache", str(CACHE), *more])

    def rows(folder: Path) -> list[dict]:
        from testbed.studies.results import read_results

        p = folder / "results.parquet"
        return read_results(p) if p.exists() else []

    def refused(label: str, **kw):
        def run():
            folder = work / _safe(label)
            shutil.rmtree(folder, ignore_errors=True)
            study(folder, **kw)
            return judged(*sweep(folder), refuse=True)
        return run

    def once_each(label: str, expect_cells: int, **kw):
        """Accepted or refused in one line; if accepted, one row per distinct cell."""
        def run():
            folder = work / _safe(label)
            shutil.rmtree(folder, ignore_errors=True)
            study(folder, **kw)
            status, out, err = sweep(folder)
            found = judged(status, out, err)
            if found or status == 2:
                return found
            keys = [(r["cell"]) for r in rows(folder)]
            if len(keys) != len(set(keys)):
                return f"two rows under one cell key: {sorted(keys)}"
            if len(keys) != expect_cells:
                return f"{len(keys)} rows for {expect_cells} distinct cells"
            return None
        return run

    def resumed_seed_removed():
        folder = work / "resume_seed_removed"
        shutil.rmtree(folder, ignore_errors=True)
        study(folder, seeds="[0, 1]")
        found = judged(*sweep(folder))
        if found:
            return f"first sweep: {found}"
        study(folder, seeds="[1]")
        found = judged(*sweep(folder))
        if found:
            return f"resumed: {found}"
        seeds = sorted(int(r["seed"]) for r in rows(folder))
        return None if seeds == [1] else f"rows of seeds {seeds} for a study of seed [1]"

    def retry_other_study():
        folder = work / "retry_other"
        shutil.rmtree(folder, ignore_errors=True)
        study(folder)
        found = judged(*sweep(folder))
        if found:
            return f"first sweep: {found}"
        other = _write(folder / "other.toml", (folder / "h19.toml").read_text().replace(
            'name = "h19"', 'name = "other"'))
        status, out, err = cli_inprocess(["sweep", str(other), "--results",
                                          str(folder / "results.parquet"), "--cache", str(CACHE),
                                          "--retry-failed"])
        found = judged(status, out, err)
        if found or status == 2:
            return found
        studies = {r["study"] for r in rows(folder)}
        return None if studies == {"other"} else f"rows of studies {sorted(studies)} kept as study other's"

    def params_for_unlisted():
        folder = work / "params_unlisted"
        shutil.rmtree(folder, ignore_errors=True)
        study(folder, extra="[identifiers.ls_sindy]\nrcond = 1e-8\n")
        return judged(*sweep(folder), refuse=True)

    return [(f"studyform {label}", fn) for label, fn in [
        ("no scenario", refused("no scenario", scenarios="[]")),
        ("no noise level", refused("no noise", noise="[]")),
        ("no seed", refused("no seed", seeds="[]")),
        ("no identifier", refused("no identifier", identifiers="[]")),
        ("seeds as a table", refused("seeds table", seeds="{a = 1}")),
        ("noise as text", refused("noise text", noise='"0"')),
        ("noise NaN", refused("noise nan", noise="[nan]")),
        ("noise -1", refused("noise neg", noise="[-1.0]")),
        ("seed 2**63", refused("seed big", seeds=f"[{2**63}]")),
        ("a seed twice", once_each("seed twice", 1, seeds="[0, 0]")),
        ("noise 0.0 and -0.0", once_each("noise zero twice", 1, noise="[0.0, -0.0]")),
        ("a scenario twice", once_each("scenario twice", 1,
                                       scenarios='["michaelis_menten", "michaelis_menten"]')),
        ("an identifier twice", once_each("identifier twice", 1,
                                          identifiers='["sindy_pi_dynamical", "sindy_pi_dynamical"]')),
        ("a parameter table for an identifier not run", params_for_unlisted),
        ("a parameter table that is a number", refused("params number",
                                                      extra="[identifiers]\nsindy_pi_dynamical = 3\n")),
        ("an unknown parameter", refused("params unknown",
                                         extra="[identifiers.sindy_pi_dynamical]\nflux = 3\n")),
        ("resumed after a seed was removed", resumed_seed_removed),
        ("--retry-failed on another study's results", retry_other_study),
    ]]


# ------------------------------------------------------------------ h5form

def _generated(work: Path, scenario: str) -> Path:
    """The shipped scenario's dataset file (from the shipped cache), made once."""
    path = work / f"{scenario}.h5"
    if not path.exists():
        status, _, err = cli_inprocess(["generate", scenario, "-o", str(path), "--cache", str(CACHE)])
        if status != 0:
            raise RuntimeError(f"generate {scenario}: {err[-300:]}")
    return path


def _rehash(path: Path) -> None:
    """Make a dataset file's content hash anew after an edit (when it still reads)."""
    import h5py

    from testbed.core.dataset import Dataset

    try:
        ds = Dataset.load(path, verify=False)
    except Exception:
        return  # unreadable: the readers say so
    with h5py.File(path, "r+") as f:
        f.attrs["content_hash"] = ds.content_hash()


def h5form_cases(work: Path) -> list[tuple[str, object]]:
    import h5py

    def rewrite(name: str, make):
        def edit(f):
            d = f[name]
            attrs, data = dict(d.attrs), d[()]
            del f[name]
            new = f.create_dataset(name, data=make(data))
            for k, v in attrs.items():
                new.attrs[k] = v
        return edit

    def both(f_edit_x, f_edit_dx):
        def edit(f):
            f_edit_x(f)
            f_edit_dx(f)
        return edit

    def with_nan(where: str, value: float):
        def make(a):
            a = a.astype(float).copy()
            a[0, {"start": 0, "middle": a.shape[1] // 2, "end": -1}[where]] = value
            return a
        return make

    # name -> (edit, must `identify` refuse it, must `export` refuse it): an exporter writes a
    # record as it is (integers, 3 samples, values beyond the identifiers' magnitude bound)
    mm_edits = {
        "x complex": (rewrite("measured/x", lambda a: a.astype(complex)), True),
        "x int8 (export: integers as they are)":
            (rewrite("measured/x", lambda a: (a * 10).astype(np.int8)), True, False),
        "x big-endian float64 (accepted: the same numbers)":
            (rewrite("measured/x", lambda a: a.astype(">f8")), False),
        "x little-endian float32": (rewrite("measured/x", lambda a: a.astype("<f4")), False),
        "x NaN in the middle": (rewrite("measured/x", with_nan("middle", math.nan)), True),
        "x inf at the end": (rewrite("measured/x", with_nan("end", math.inf)), True),
        "x -inf at the start": (rewrite("measured/x", with_nan("start", -math.inf)), True),
        "x one sample shorter than dx": (rewrite("measured/x", lambda a: a[:, :-1]), True),
        "x and dx zero-length": (both(rewrite("measured/x", lambda a: a[:, :0]),
                                      rewrite("measured/dx", lambda a: a[:, :0])), True),
        "x and dx one sample": (both(rewrite("measured/x", lambda a: a[:, :1]),
                                     rewrite("measured/dx", lambda a: a[:, :1])), True),
        "x and dx three samples (export: a record of 3 samples)":
            (both(rewrite("measured/x", lambda a: a[:, :3]),
                  rewrite("measured/dx", lambda a: a[:, :3])), True, False),
        "x of 1e300 (overflows the fit; export: as it is)":
            (rewrite("measured/x", lambda a: a * 1e300), True, False),
    }

    def edited(label: str, edit, refuse: bool, refuse_export: bool | None = None):
        refuse_export = refuse if refuse_export is None else refuse_export

        def run():
            src = _generated(work, MM)
            path = work / f"{_safe(label)}.h5"
            shutil.copy(src, path)
            with h5py.File(path, "r+") as f:
                edit(f)
            _rehash(path)
            found = judged(*cli_inprocess(["identify", str(path), "--kind", "dynamical", "--method",
                                           "sindy_pi_dynamical", "-o", f"{path}.model.json"]),
                           refuse=refuse)
            if found:
                return f"identify: {found}"
            found = judged(*cli_inprocess(["export", str(path), "--format", "sep005", "-o",
                                           f"{path}.json"]), refuse=refuse_export)
            return f"export: {found}" if found else None
        return run

    def path_case(label: str, make):
        def run():
            path = make()
            for argv in (["identify", str(path), "--kind", "dynamical", "--method",
                          "sindy_pi_dynamical", "-o", str(work / "p.model.json")],
                         ["export", str(path), "--format", "sep005", "-o", str(work / "p.json")]):
                found = judged(*cli_inprocess(argv), refuse=True)
                if found:
                    return f"{argv[0]}: {found}"
            return None
        return run

    def folder():
        p = work / "folder.h5"
        p.mkdir(exist_ok=True)
        return p

    def loop():
        a, b = work / "loop_a.h5", work / "loop_b.h5"
        for x, y in ((a, b), (b, a)):
            if not x.is_symlink():
                x.symlink_to(y)
        return a

    def fifo():
        p = work / "fifo.h5"
        if not p.exists():
            os.mkfifo(p)
        return p

    def dangling():
        p = work / "dangling.h5"
        if not p.is_symlink():
            p.symlink_to(work / "nowhere.h5")
        return p

    def zero_bytes():
        p = work / "empty.h5"
        p.write_bytes(b"")
        return p

    def hdf5_no_dataset():
        p = work / "plain.h5"
        with h5py.File(p, "w") as f:
            f["x"] = np.arange(10.0)
        return p

    cases = [(f"h5form {label}", edited(label, *how)) for label, how in mm_edits.items()]
    cases += [(f"h5form {label}", path_case(label, make)) for label, make in [
        ("the path a folder", folder),
        ("a symlink loop", loop),
        ("a FIFO without a writer", fifo),
        ("a dangling symlink", dangling),
        ("/dev/null", lambda: Path("/dev/null")),
        ("a zero-byte file", zero_bytes),
        ("an HDF5 file that is no dataset", hdf5_no_dataset),
    ]]
    return cases


# ------------------------------------------------------------------ uffform

def uffform_cases(work: Path) -> list[tuple[str, object]]:
    import pyuff

    beam = ["--kind", "structural", "--method", "ls_sindy"]

    def exported() -> tuple[Path, list[str]]:
        src = _generated(work, "cantilever_stiff_impact_lab")
        out = work / "lab.uff"
        prior_file = work / "lab.prior"
        if not out.exists():
            status, stdout, err = cli_inprocess(["export", str(src), "--format", "uff", "-o", str(out)])
            if status != 0:
                raise RuntimeError(f"export: {err[-300:]}")
            prior_file.write_text(json.dumps([a for a in (stdout + err).split()
                                              if "=" in a and not a.startswith("-")]))
        prior = json.loads(prior_file.read_text())
        return out, [x for p in prior for x in ("--prior", p)]

    def edited(label: str, edit, refuse: bool, refuse_export: bool | None = None):
        refuse_export = refuse if refuse_export is None else refuse_export

        def run():
            src, prior = exported()
            sets = pyuff.UFF(str(src)).read_sets()
            sets = sets if isinstance(sets, list) else [sets]
            records = [i for i, s in enumerate(sets) if s.get("type") == 58]
            edit(sets, records)
            path = work / f"{_safe(label)}.uff"
            path.unlink(missing_ok=True)
            pyuff.UFF(str(path)).write_sets(sets, mode="add")
            return judged(*cli_inprocess(["identify", str(path), "-o", f"{path}.model.json",
                                          *prior, *beam]), refuse=refuse)
        return run

    def on(k: int, key: str, value):
        def edit(sets, records):
            sets[records[k]][key] = value
        return edit

    def shorter(k: int):
        def edit(sets, records):
            s = sets[records[k]]
            s["data"] = s["data"][:-10]
            if "x" in s:
                s["x"] = s["x"][:-10]
            s["num_pts"] = len(s["data"])
        return edit

    def in_g(k: int):
        def edit(sets, records):
            s = sets[records[k]]
            s["data"] = s["data"] / 9.80665
            s["ordinate_spec_data_type"] = 12  # acceleration
            s["orddenom_spec_data_type"] = 0
            s["ordinate_axis_units_lab"] = "g"
            s["ordinate_axis_lab"] = "acceleration"
        return edit

    def header(k: int, text: str):
        def edit(sets, records):
            sets[records[k]]["id1"] = text
        return edit

    def scaled(k: int, factor: float):
        """One record's abscissa (pyuff writes the spacing from ``x``) times ``factor``."""
        def edit(sets, records):
            s = sets[records[k]]
            s["x"] = factor * np.asarray(s["x"], dtype=float)
            s["abscissa_inc"] = factor * s["abscissa_inc"]
        return edit

    def foreign(*edits):
        """ID lines 3-5 blanked (no rate, scenario or hash: another tool's file), then ``edits``."""
        def edit(sets, records):
            for i in records:
                for key in ("id3", "id4", "id5"):
                    sets[i][key] = "NONE"
            for e in edits:
                e(sets, records)
        return edit

    return [(f"uffform {label}", edited(label, edit, refuse)) for label, edit, refuse in [
        ("another tool's file (accepted)", foreign(), False),
        ("another tool's file, one channel's spacing doubled", foreign(scaled(1, 2.0)), True),
        ("another tool's file, one channel's spacing 1 % longer", foreign(scaled(1, 1.01)), True),
        ("another tool's file, the force's spacing 1 ppm longer (a rounding: accepted)",
         foreign(scaled(3, 1.000001)), False),
        ("another tool's file, one acceleration in g", foreign(in_g(1)), False),
        ("another tool's file, one channel shorter", foreign(shorter(2)), True),
        ("one channel's spacing doubled", scaled(1, 2.0), True),
        ("one channel's spacing 0", scaled(1, 0.0), True),
        ("one channel's spacing negative", scaled(1, -1.0), True),
        ("one channel's spacing NaN", scaled(1, math.nan), True),
        ("one channel's spacing 1 % longer", scaled(1, 1.01), True),
        ("one channel 10 samples shorter", shorter(1), True),
        ("one acceleration in g beside m/s^2 (mixed, converted)", in_g(1), False),
        ("a header in Greek", header(0, "επιτάχυνση 加速度"), False),
        ("a header with a control character", header(0, "acc\x1b[2Jx"), False),
    ]]


# ------------------------------------------------------------------ cliargs

def cliargs_cases(work: Path) -> list[tuple[str, object]]:
    a_file = work / "a_file.txt"
    a_file.write_text("x")
    a_folder = work / "a_folder"
    a_folder.mkdir(exist_ok=True)
    study = _write(work / "s19.toml", '[study]\nname = "s19"\nscenarios = ["michaelis_menten"]\n'
                                      'noise = [0.0]\nseeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')
    res = str(work / "s19.parquet")

    def cmd(argv: list[str], refuse: bool):
        return lambda: judged(*cli_inprocess(argv), refuse=refuse)

    def gen(*more: str) -> list[str]:
        return ["generate", MM, "--cache", str(CACHE), *more]

    def sweep(*more: str) -> list[str]:
        return ["sweep", str(study), "--results", res, "--cache", str(CACHE), *more]

    def run(*more: str) -> list[str]:
        return ["run", MM, "--cache", str(CACHE), "--no-figures", "-o", str(work / "runs"), *more]

    return [(f"cliargs {label}", cmd(argv, refuse)) for label, argv, refuse in [
        ("an unknown flag", [*run(), "--fast"], True),
        ("an unknown command", ["runn", MM], True),
        ("a flag given twice (--seed 1 --seed 2)", [*run(), "--seed", "1", "--seed", "2"], False),
        ("--jobs 0", [*sweep(), "--jobs", "0"], True),
        ("--jobs -1", [*sweep(), "--jobs", "-1"], True),
        ("--jobs 1e3", [*sweep(), "--jobs", "1e3"], True),
        ("--jobs 2**70", [*sweep(), "--jobs", str(2**70)], True),
        ("--jobs two", [*sweep(), "--jobs", "two"], True),
        ("--seed -1", [*run(), "--seed", "-1"], True),
        ("--seed 2**64", [*run(), "--seed", str(2**64)], True),
        ("--seed 1.5", [*run(), "--seed", "1.5"], True),
        ("--seed nan", [*run(), "--seed", "nan"], True),
        ("--seed ' 3' (spaces: accepted)", [*run(), "--seed", " 3"], False),
        ("--seed ３ (fullwidth digit)", [*run(), "--seed", "３"], True),
        ("generate -o inside a file", gen("-o", str(a_file / "d.h5")), True),
        ("generate -o an existing folder", gen("-o", str(a_folder)), True),
        ("generate -o ''", gen("-o", ""), True),
        ("run -o a file", ["run", MM, "--cache", str(CACHE), "--no-figures", "-o", str(a_file)], True),
        ("sweep --results a folder", ["sweep", str(study), "--results", str(a_folder), "--cache",
                                      str(CACHE)], True),
        ("sweep --results inside a file", ["sweep", str(study), "--results",
                                           str(a_file / "r.parquet"), "--cache", str(CACHE)], True),
        ("--cache a file", ["run", MM, "--cache", str(a_file), "--no-figures", "-o",
                            str(work / "runs")], True),
        ("--plugin ''", [*run(), "--plugin", ""], True),
        ("--plugin a folder", [*run(), "--plugin", str(a_folder)], True),
        ("export --format xls", ["export", str(a_file), "--format", "xls"], True),
        ("report -o inside a file", ["report", MM, "-o", str(a_file / "rep"), "--runs",
                                     str(work / "runs")], True),
        ("summary of a text file", ["summary", str(a_file)], True),
        ("identify --fs -100", ["identify", str(a_file), "--fs", "-100"], True),
        ("identify --fs 1%", ["identify", str(a_file), "--fs", "1%"], True),
    ]]


# ------------------------------------------------------------------ apiuse

def apiuse_cases(work: Path) -> list[tuple[str, object]]:
    import testbed
    from testbed.core.measurement import Measurement
    from testbed.pipeline.cache import DatasetCache
    from testbed.pipeline.scenario import load_scenario
    from testbed.pipeline.signal_chain import measure

    cache = DatasetCache(CACHE)

    def mm_data():
        sc = load_scenario(MM)
        return measure(cache.get(sc), sc.signal, sc.kind)

    def beam_data():
        sc = load_scenario("cantilever_stiff_impact_lsq")
        return measure(cache.get(sc), sc.signal, sc.kind)

    def equal_models(a, b) -> bool:
        pa, pb = a.get_params(), b.get_params()
        if pa != pb:
            return False
        ea = a.equations() if hasattr(a, "equations") else None
        eb = b.equations() if hasattr(b, "equations") else None
        return ea == eb

    def fitted_twice(method: str, data_fn):
        def run():
            data = data_fn()
            m = testbed.IDENTIFIERS.get(method)()
            m.fit(data)
            m.fit(data)
            fresh = testbed.IDENTIFIERS.get(method)().fit(data)
            if not equal_models(m, fresh):
                return "a second fit differs from a fresh one"
            return None
        return run

    def before_fit(method: str, call: str, data_fn):
        def run():
            m = testbed.IDENTIFIERS.get(method)()
            data = data_fn()
            getattr(m, call)(*([data] if call in ("score", "predict_acceleration") else []))
            return f"{call} before fit returned a value"
        return run

    def short(method: str, data_fn, n: int):
        def run():
            cut = testbed.MeasurementSamples.of(data_fn()).window(0, n)
            testbed.IDENTIFIERS.get(method)().fit(cut)
            return f"fitted a {n}-sample record"
        return run

    def hyper(method: str, data_fn, how: str, **params):
        def run():
            cls = testbed.IDENTIFIERS.get(method)
            m = cls(**params) if how == "init" else cls().set_params(**params)
            m.fit(data_fn())
            return f"fitted with {params} in silence"
        return run

    def hand_measurement(n: int):
        def make():
            t = np.arange(n) / 100.0
            x = np.exp(-t)[None, :]
            return Measurement(100.0, x, -x, x, ("x",))
        return make

    mm = load_scenario(MM)

    def uff_names(channels: tuple[str, ...]):
        """``write_uff`` of a record whose channel names a UFF58 ID line cannot hold as they are:
        a file read back under other names is a finding."""
        def run():
            from testbed.core.dataset import Dataset, Signal
            from testbed.pipeline.importers import read_measured
            from testbed.reporting.export import write_uff

            t = np.arange(200) / 1000.0
            acc = np.vstack([np.sin(2 * np.pi * f * t) for f in (7.0, 11.0)])
            ds = Dataset(1000.0, {"acceleration": Signal(acc, channels, "m/s^2",
                                                         positions=np.array([0.1, 0.2])),
                                  "force": Signal(np.exp(-t / 0.01)[None, :], ("force",), "N",
                                                  positions=np.array([0.2]))})
            out = work / f"names_{len(channels[0])}.uff"
            write_uff(ds, out)
            back = list(read_measured(out).signals)[:2]
            want = [f"acceleration/{c}" for c in channels]
            return None if back == want else f"written, read back as {back}"
        return run

    def empty_part(name: str):
        """``from_sep005`` of a channel named with an empty part around ``/``: a signal or a
        channel named "" accepted is a finding."""
        def run():
            from testbed.pipeline.importers import from_sep005

            t = np.arange(100) / 1000.0
            ds = from_sep005([{"name": name, "data": list(np.sin(40 * t)), "fs": 1000.0,
                               "unit_str": "m/s^2"}]).to_dataset()
            return f"read as {{signal: channels}} {({k: v.channels for k, v in ds.measured.items()})}"
        return run

    def measured_at(fs):
        """``measure`` of a hand-built kinetics Dataset whose rate is ``fs``: anything but one
        refusal line is a finding (a measurement at a rate read from text or a boolean too)."""
        def run():
            from testbed.core.dataset import Dataset, Signal

            x = (2.0 * np.exp(-np.arange(400) / 100.0))[None, :]
            ds = Dataset(fs, {"x": Signal(x, ("x",), "mM"), "dx": Signal(-x, ("dx",), "mM/s")})
            m = measure(ds, {}, "dynamical")
            return f"measured at {m.fs!r} Hz"
        return run

    def api(fn):
        def run():
            fn()
            return "accepted"
        return run

    return [(f"apiuse {label}", fn) for label, fn in [
        ("sindy_pi_dynamical fitted twice", fitted_twice("sindy_pi_dynamical", mm_data)),
        ("ls_sindy fitted twice", fitted_twice("ls_sindy", beam_data)),
        ("score before fit", before_fit("sindy_pi_dynamical", "score", mm_data)),
        ("equations before fit", before_fit("sindy_pi_dynamical", "equations", mm_data)),
        ("ls_sindy predict_acceleration before fit", before_fit("ls_sindy", "predict_acceleration",
                                                                beam_data)),
        ("ls_sindy simulate before fit", before_fit("ls_sindy", "simulate", beam_data)),
        ("sindy_pi_dynamical on 3 samples", short("sindy_pi_dynamical", mm_data, 3)),
        ("ls_sindy on 3 samples", short("ls_sindy", beam_data, 3)),
        ("sindy_pi_dynamical on a hand-made 3-sample record",
         lambda: (testbed.IDENTIFIERS.get("sindy_pi_dynamical")().fit(hand_measurement(3)()),
                  "fitted a 3-sample record")[1]),
        ("degree as text (init)", hyper("sindy_pi_dynamical", mm_data, "init", degree="3")),
        ("degree as text (set_params)", hyper("sindy_pi_dynamical", mm_data, "set", degree="3")),
        ("degree True", hyper("sindy_pi_dynamical", mm_data, "init", degree=True)),
        ("degree 2.5", hyper("sindy_pi_dynamical", mm_data, "init", degree=2.5)),
        ("ridge NaN", hyper("sindy_pi_dynamical", mm_data, "init", ridge=math.nan)),
        ("ridge a list", hyper("sindy_pi_dynamical", mm_data, "init", ridge=[1e-14])),
        ("max_iter 2**70", hyper("sindy_pi_dynamical", mm_data, "init", max_iter=2**70)),
        ("val_fraction 1.0", hyper("sindy_pi_dynamical", mm_data, "init", val_fraction=1.0)),
        ("formulation unknown", hyper("sindy_pi_dynamical", mm_data, "init", formulation="weakk")),
        ("ls_sindy rcond text", hyper("ls_sindy", beam_data, "init", rcond="1e-10")),
        ("ls_sindy rcond -1", hyper("ls_sindy", beam_data, "init", rcond=-1.0)),
        ("ls_sindy eigen_hold 'yes'", hyper("ls_sindy", beam_data, "set", eigen_hold="yes")),
        ("ls_sindy cubic 5", hyper("ls_sindy", beam_data, "init", cubic=5)),
        ("ls_sindy an unknown parameter", hyper("ls_sindy", beam_data, "set", flux=1.0)),
        ("run_scenario of a dict", api(lambda: testbed.run_scenario(mm.to_dict()))),
        ("run_scenario of a list", api(lambda: testbed.run_scenario([MM]))),
        ("run_scenario of a Dataset", api(lambda: testbed.run_scenario(cache.get(mm)))),
        ("run_scenario with a model class, not an instance",
         api(lambda: testbed.run_scenario(mm, model=testbed.IDENTIFIERS.get("sindy_pi_dynamical"),
                                          cache=cache))),
        ("run_scenario with a fitted model",
         lambda: _hostile.scored_finding(testbed.run_scenario(
             mm, model=testbed.IDENTIFIERS.get("sindy_pi_dynamical")().fit(mm_data()), cache=cache))),
        ("score of an unfitted model", api(lambda: testbed.score(
            testbed.IDENTIFIERS.get("sindy_pi_dynamical")(), cache.get(mm), mm))),
        ("write_uff of two names sharing the 80 characters of the ID line",
         uff_names(("a" * 90 + "1", "a" * 90 + "2"))),
        ("write_uff of a name with a trailing blank", uff_names(("acc1 ", "acc2"))),
        ("measure of a Dataset at 0 Hz", measured_at(0.0)),
        ("measure of a Dataset at NaN Hz", measured_at(math.nan)),
        ("measure of a Dataset at True Hz", measured_at(True)),
        ("measure of a Dataset at '100' Hz", measured_at("100")),
        ("measure of a Dataset at 100+0j Hz", measured_at(100 + 0j)),
        ("a SEP-005 channel named 'acceleration/'", empty_part("acceleration/")),
        ("a SEP-005 channel named '/acc1'", empty_part("/acc1")),
        ("score of a dataset of another scenario's record (1 kHz against 100 Hz)",
         api(lambda: testbed.score(
             testbed.IDENTIFIERS.get("sindy_pi_dynamical")(degree=3).fit(mm_data()),
             cache.get(load_scenario("michaelis_menten_noise1")), mm))),
    ]]


# ------------------------------------------------------------------ csvform

def csvform_cases(work: Path) -> list[tuple[str, object]]:
    """The Michaelis-Menten record written as CSV text in the forms spreadsheets and loggers
    produce; ``testbed identify --kind dynamical``.  Each label says whether the form must be
    refused (an ambiguous or damaged file) or read (then the model must equal the clean file's)."""
    from testbed.core.dataset import Dataset

    def record():
        ds = Dataset.load(_generated(work, MM))
        return ds.fs, ds.measured["x"].data[0], ds.measured["dx"].data[0]

    def plain(fs, x, dx, sep=",", time=True, header=None, fmt=repr) -> str:
        head = header or (["time [s]"] if time else []) + ["x [mM]", "dx [mM/s]"]
        rows = [sep.join(([fmt(k / fs)] if time else []) + [fmt(a), fmt(b)])
                for k, (a, b) in enumerate(zip(x.tolist(), dx.tolist(), strict=True))]
        return sep.join(head) + "\n" + "\n".join(rows) + "\n"

    def identify(path: Path, *more: str) -> tuple[int, str, str]:
        return cli_inprocess(["identify", str(path), "--kind", "dynamical", "--method",
                              "sindy_pi_dynamical", "-o", f"{path}.model.json", *more])

    def equations(path: Path) -> list:
        return json.loads(Path(f"{path}.model.json").read_text()).get("equations")

    def case(label: str, make, refuse: bool, *more: str):
        def run():
            fs, x, dx = record()
            clean = work / "clean.csv"
            if not Path(f"{clean}.model.json").exists():
                clean.write_text(plain(fs, x, dx))
                found = judged(*identify(clean))
                if found:
                    return f"the clean file: {found}"
            path = work / f"{_safe(label)}.csv"
            content = make(fs, x, dx)
            if isinstance(content, bytes):
                path.write_bytes(content)
            else:
                path.write_text(content, encoding="utf-8")
            status, out, err = identify(path, *more)
            found = judged(status, out, err, refuse=refuse)
            if found or status != 0:
                return found
            if equations(path) != equations(clean):
                return "read, but its model differs from the clean file's (the form changed the data)"
            return None
        return run

    def decimal_comma(fs, x, dx):
        return plain(fs, x, dx, sep=";", fmt=lambda v: repr(v).replace(".", ","))

    def ms_time(fs, x, dx):
        return plain(fs, x, dx, header=["time [ms]", "x [mM]", "dx [mM/s]"],
                     fmt=repr).replace("\n", "\n", 1)

    def ms_values(fs, x, dx):
        head = "time [ms],x [mM],dx [mM/s]\n"
        return head + "".join(f"{1000 * k / fs!r},{a!r},{b!r}\n"
                              for k, (a, b) in enumerate(zip(x.tolist(), dx.tolist(), strict=True)))

    def edit_rows(fn):
        def make(fs, x, dx):
            lines = plain(fs, x, dx).splitlines()
            return "\n".join(fn(lines)) + "\n"
        return make

    def swap_times(lines):
        a, b = lines[10].split(",", 1), lines[11].split(",", 1)
        lines[10], lines[11] = f"{b[0]},{a[1]}", f"{a[0]},{b[1]}"
        return lines

    def repeat_time(lines):
        lines[11] = lines[10].split(",", 1)[0] + "," + lines[11].split(",", 1)[1]
        return lines

    return [(f"csvform {label}", case(label, make, refuse, *more)) for label, make, refuse, *more in [
        ("decimal comma, semicolon separated", decimal_comma, False),
        ("tab separated", lambda fs, x, dx: plain(fs, x, dx, sep="\t"), False),
        ("a byte-order mark", lambda fs, x, dx: "\ufeff" + plain(fs, x, dx), False),
        ("CRLF line ends", lambda fs, x, dx: plain(fs, x, dx).replace("\n", "\r\n"), False),
        ("time in ms, declared", ms_values, False),
        ("time in ms, declared as s", lambda fs, x, dx: ms_values(fs, x, dx).replace(
            "time [ms]", "time [s]"), False),
        ("two time stamps swapped", edit_rows(swap_times), True),
        ("a time stamp repeated", edit_rows(repeat_time), True),
        ("the header repeated mid-file (two files concatenated)",
         edit_rows(lambda ls: ls[:200] + ls[:1] + ls[200:]), True),
        ("a blank line mid-file", edit_rows(lambda ls: [*ls[:200], "", *ls[200:]]), False),
        ("a cell 'NaN'", edit_rows(lambda ls: [*ls[:100], ls[100].rsplit(",", 1)[0] + ",NaN",
                                               *ls[101:]]), True),
        ("an empty cell", edit_rows(lambda ls: [*ls[:100], ls[100].rsplit(",", 1)[0] + ",",
                                                *ls[101:]]), True),
        ("a row with an extra cell", edit_rows(lambda ls: [*ls[:100], ls[100] + ",1.0", *ls[101:]]),
         True),
        ("a trailing empty column", edit_rows(lambda ls: [ln + "," for ln in ls]), True),
        ("quoted numbers", edit_rows(lambda ls: ls[:1] + [",".join(f'"{c}"' for c in ln.split(","))
                                                            for ln in ls[1:]]), False),
        ("numbers with a thousands separator", edit_rows(
            lambda ls: ls[:1] + [ln.replace("0.0", "0,000.0", 1) for ln in ls[1:]]), True),
        ("Latin-1 degree sign in a header", lambda fs, x, dx: plain(
            fs, x, dx, header=["time [s]", "x [mM]", "dx [mM/s] \u00b0"]).encode("latin-1"), True),
        ("x column named twice", lambda fs, x, dx: plain(
            fs, x, dx, header=["time [s]", "x [mM]", "x [mM]"]), True),
        ("header only", lambda fs, x, dx: "time [s],x [mM],dx [mM/s]\n", True),
        ("--fs contradicting the time column", lambda fs, x, dx: plain(fs, x, dx), True, "--fs",
         "50"),
        ("--fs 1e-320 with no time column", lambda fs, x, dx: plain(fs, x, dx, time=False), True,
         "--fs", "1e-320"),
    ]]


# ------------------------------------------------------------------ plugins

_PLUGIN = """from __future__ import annotations
from typing import ClassVar
import numpy as np
from testbed import IDENTIFIERS, Field, Identifier, Measurement, Trajectory

#AT_IMPORT

@IDENTIFIERS.register("NAME")
class Bad(Identifier):
    name = "NAME"
    kind = "structural"
    hyperparameters: ClassVar[dict[str, Field]] = {}
    prior_keys = ("total_mass",)
    deterministic = True

    def __init__(self) -> None:
        pass

    def fit(self, data: Measurement):
        n = data.n_channels
        s = slice(data.free_start, None)
        theta = np.vstack([data.x[:, s], data.xd[:, s], data.u[:, s]]).T
        xi, *_ = np.linalg.lstsq(theta, data.xdd[:, s].T, rcond=1e-12)
        self.M_ = float(data.prior.get("total_mass", n)) / n * np.eye(n)
        self.K_ = -self.M_ @ xi[:n].T
        self.C_ = -self.M_ @ xi[n:2 * n].T
        self.B_ = self.M_ @ xi[2 * n:].T
        self.input_map_ = data.input_map
        self.channels_ = tuple(data.channels)
        #IN_FIT
        return self

    def equations(self, precision: int = 4):
        return ["x"]

#SIMULATE
"""

_SIMULATE = """    def simulate(self, x0, xd0, t, u=None):
        from testbed.numerics.linear_response import simulate_linear
        return simulate_linear(self.M_, self.C_, self.K_, self.B_, x0, xd0, t, u)
"""


def plugins_cases(work: Path) -> list[tuple[str, object]]:
    """A user's plugin identifier (``--plugin``, a least-squares beam model) that breaks the
    contract at import or in its fit, or leaves ``simulate`` out: ``testbed run`` of the stiff
    beam.  Anything but a verdict (a failed fit naming the plugin) or one error line is a
    finding; a pass is a finding for every case but the first."""
    from testbed.pipeline.scenario import SCENARIO_DIR

    def case(k: int, label: str, at_import: str = "", in_fit: str = "", simulate: bool = True,
             may_pass: bool = False):
        def run():
            name = f"h19_bad{k}"
            plugin = work / f"{name}.py"
            plugin.write_text(_PLUGIN.replace("NAME", name).replace("#AT_IMPORT", at_import)
                              .replace("#IN_FIT", in_fit)
                              .replace("#SIMULATE", _SIMULATE if simulate else ""))
            scen = _write(work / f"{name}.toml",
                          f'[scenario]\nname = "{name}"\nextends = '
                          f'"{SCENARIO_DIR / "cantilever_stiff_impact_lsq.toml"}"\n'
                          f'[identify]\nmethod = "{name}"\n')
            status, out, err = cli_inprocess(["run", str(scen), "--plugin", str(plugin),
                                              "--no-figures", "-o", str(work / "runs"),
                                              "--cache", str(CACHE)])
            found = judged(status, out, err)
            if found:
                return found
            if status == 0 and not may_pass:
                return "passed"
            return None
        return run

    cases = [
        ("a plugin whose model's simulate is its own linear response (a verdict)", {}, True),
        ("simulate left out", {"simulate": False}, False),
        ("GeneratorExit at import", {"at_import": "raise GeneratorExit('x')"}, False),
        ("a BaseException subclass at import",
         {"at_import": "class Skipped(BaseException):\n    pass\nraise Skipped('no')"}, False),
        ("sys.exit(0) at import", {"at_import": "import sys\nsys.exit(0)"}, False),
        ("GeneratorExit in fit", {"in_fit": "raise GeneratorExit('x')"}, False),
        ("sys.exit(0) in fit", {"in_fit": "raise SystemExit(0)"}, False),
        ("RecursionError in fit", {"in_fit": "raise RecursionError('deep')"}, False),
        ("MemoryError in fit", {"in_fit": "raise MemoryError()"}, False),
        ("fit returns None (the model is fitted: a verdict)", {"in_fit": "return None"}, True),
        ("M_ NaN", {"in_fit": "self.M_ = self.M_ * np.nan"}, False),
        ("M_ of another size", {"in_fit": "self.M_ = np.eye(2)"}, False),
        ("K_ complex", {"in_fit": "self.K_ = self.K_.astype(complex)"}, False),
        ("K_ a nested list (real numbers: a verdict)", {"in_fit": "self.K_ = self.K_.tolist()"},
         True),
        ("M_ boolean", {"in_fit": "self.M_ = self.M_ > 0"}, False),
        ("K_ complex with an imaginary part", {"in_fit": "self.K_ = self.K_ + 1j * self.K_"}, False),
        ("M_ float16", {"in_fit": "self.M_ = self.M_.astype(np.float16)"}, False),
        ("M_ times 1e308", {"in_fit": "self.M_ = self.M_ * 1e308"}, False),
        ("M_ zero", {"in_fit": "self.M_ = np.zeros_like(self.M_)"}, False),
        ("M_ negative", {"in_fit": "self.M_ = -self.M_"}, False),
        ("K_ negative (unstable)", {"in_fit": "self.K_ = -self.K_"}, False),
        ("M_ text", {"in_fit": "self.M_ = 'x'"}, False),
        ("learned attributes deleted", {"in_fit": "del self.M_, self.K_, self.C_"}, False),
    ]
    def exits_the_interpreter():
        """``os._exit(0)`` in the plugin's fit, through a real command (it would end this
        process): status 0 without a verdict is a finding (open: no Python code runs after
        ``os._exit``; ``sweep --jobs 2`` names the plugin, `--jobs 1` and `run` cannot)."""
        name = "h19_exit"
        plugin = work / f"{name}.py"
        plugin.write_text(_PLUGIN.replace("NAME", name).replace("#AT_IMPORT", "")
                          .replace("#IN_FIT", "import os\n        os._exit(0)")
                          .replace("#SIMULATE", _SIMULATE))
        scen = _write(work / f"{name}.toml",
                      f'[scenario]\nname = "{name}"\nextends = '
                      f'"{SCENARIO_DIR / "cantilever_stiff_impact_lsq.toml"}"\n'
                      f'[identify]\nmethod = "{name}"\n')
        p = _hostile.testbed_cli(["run", str(scen), "--plugin", str(plugin), "--no-figures", "-o",
                                  str(work / "runs"), "--cache", str(CACHE)], work, TIMEOUT_S)
        found = _hostile.cli_finding(p)
        if found:
            return found
        if p.returncode == 0 and "run written to" not in p.stdout:
            return "status 0 without a verdict (the plugin ended the interpreter in its fit)"
        return None

    return [(f"plugins {label}", case(k, label, may_pass=may, **kw))
            for k, (label, kw, may) in enumerate(cases)] + [
        ("plugins os._exit(0) in fit (a real command)", exits_the_interpreter)]


# ------------------------------------------------------------------ main

FAMILIES = _hostile.families({
    "tomlform": tomlform_cases,
    "studyform": studyform_cases,
    "h5form": h5form_cases,
    "uffform": uffform_cases,
    "cliargs": cliargs_cases,
    "apiuse": apiuse_cases,
    "csvform": csvform_cases,
    "plugins": plugins_cases,
}, TIMEOUT_S)


def main(argv: list[str]) -> int:
    return _hostile.main(argv, FAMILIES, "hostile19-")


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
