"""Twenty-fourth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile24 [family ...]      # all families when none is named

Families (what rounds 1-23 did not try; their families are listed in ``hostile21.py``,
``hostile22.py`` and ``hostile23.py``):

``uffmix``
    UFF files whose records are each valid but of mixed types that disagree with each other:
    a node given two positions (twice in one UFF2411 record, in two 2411 records, by a 2411
    and a UFF15 record), the same position twice (accepted), a node's coordinate NaN, a
    sensor's node missing from the geometry; two UFF164 records (both SI: accepted; the second
    in mm), a non-SI 164 after the 58 records; a UFF151 header, a UFF2412 element record, the
    truth's UFF55 records dropped, the records in another order (each accepted: the clean
    model); a UFF58 frequency response or complex record among the time responses; a record
    stored with an explicit abscissa (spacing 0) that is uniform (accepted), has a gap, is
    logarithmic, runs 1 % fast; a channel given twice (same name, or another name at the same
    node and direction); a sensor pointing along ``+Y`` beside ``+Z`` ones.  ``testbed
    identify``.  A traceback, anything but one refusal line for a file that contradicts
    itself, or an accepted equivalent file read to another model, is a finding.
``kindswap``
    A record of one rig kind fed as another: each of the four rigs' dataset files (``.h5``) and
    their SEP-005 exports (``.json``) through ``testbed identify --kind K`` for every other
    kind K (with K's default identifier), with ``--method`` of another kind than ``--kind``,
    and with ``--scenario`` of another rig.  Anything but one refusal line is a finding.
``h5meta``
    A dataset file whose groups or declarative attributes say something the reader does not
    read (content hash made anew): an attribute on the ``/measured``, ``/truth`` or
    ``/reference`` group itself, ``positions_unit`` of ``"mm"`` / ``"in"`` / a number / an
    array, ``positions`` in millimetres declared as such, ``layout`` as a one-item list
    (accepted), a ``unit`` as bytes (accepted) or a two-item array, ``acts_on`` an integer;
    and a cached dataset whose truth was edited without its hash, then ``testbed run``.  An
    attribute that changes the meaning of the numbers read in silence, or anything but one
    refusal line, is a finding.
``famdraw``
    ``testbed family write`` of a study whose family draws are hostile in ways round 12's
    ``family`` and round 15's ``studies`` did not try: a uniform range spanning +-1.7e308 (its
    width overflows to inf), a log range of 300 decades, ``choices`` of tables, of booleans, of
    mixed types, of one NaN-free number (accepted), a draw of the rig's text key
    (``excitation.type``), a range for a key the rig has not, every draw refused by the rig
    (a cart of negative mass), members 10**9, ``integers`` over [2**62, 2**63 - 1].  A hang, a
    traceback, anything but one refusal line, or a member written that its own scenario
    loader refuses, is a finding.
``npzform``
    A run folder's ``run.npz`` replaced by a crafted one and the run sealed anew (both
    checksums): an object member holding a pickle (whose code would make a marker folder),
    the whole file a pickle, a zip of a ``.pkl`` member, a lone ``.npy``, a text file; a
    member of a structured dtype, datetimes, fixed-length bytes; big-endian, float16, text or
    complex members and an empty zip (read: kinds a run writes).  ``testbed report`` and
    ``runs ls``.  A pickle loaded, a traceback, an internal error, or anything but one refusal
    line where one is due, is a finding.
``rigedge``
    Scenarios whose numbers lie within their bounds at edges rounds 14 and 22 did not try: no
    excitation, one tone, no damping, no gravity, no centring, Vmax = 0, Km = 1e12, a beam of
    2 segments, joint offsets 0 and 0.5, damping 0 and 0.999 of critical, a soft base of
    k3 = 0 or 1e-6 of its stiffness, one sensor: run and scored (``run_scenario``).
``cliunits``
    ``testbed identify --units`` given twice for a channel, for all beside one channel, with
    no channel or no unit, with blanks, without the signal's name, of another quantity, of
    the same quantity against the file's, in Unicode or upper case; the kinetics CSV without
    units, with one for both channels, per channel (the clean model), per minute, and the
    time column given a unit.
``sweepresume``
    ``testbed sweep --jobs 1 / 2`` sent SIGINT / SIGTERM 1.5-6 s in, then resumed: every row
    must equal the uninterrupted sweep's bit for bit (but times and provenance); ``summary``
    and ``report`` of the results while the sweep writes them.
``repro``
    Same scenario + seed = one content hash: two fresh caches, no cache, a cache it filled,
    ``--seed`` equal to the scenario's own, and a scenario file spelled another way (integers
    for floats, exponents, comments, keys reordered, another name); two noise seeds, two.
``envrun``
    ``TESTBED_CACHE`` / ``TESTBED_SCENARIOS`` / ``TESTBED_STUDIES`` a file, a FIFO, a path
    under a file, ``/proc/self``, ``/sys`` or ``/dev/full`` for ``run``, ``sweep``, ``cache
    ls`` and ``runs ls`` (round 14's ``envvars`` ran ``list`` and ``generate``).

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import json
import shutil
import sys
from pathlib import Path

import numpy as np

try:
    from benchmarks import _hostile, hostile19
except ImportError:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks import _hostile, hostile19

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 240
MM = hostile19.MM
LAB = "cantilever_stiff_impact_lab"

cli_inprocess = _hostile.cli_inprocess
judged = _hostile.judged
_generated = hostile19._generated
_rehash = hostile19._rehash
_safe = hostile19._safe


def _numbers(obj) -> list[float]:
    if isinstance(obj, bool):
        return []
    if isinstance(obj, (int, float)):
        return [obj]
    if isinstance(obj, dict):
        return [x for k in sorted(obj) for x in _numbers(obj[k])]
    if isinstance(obj, list):
        return [x for v in obj for x in _numbers(v)]
    return []


def _model(out: Path) -> dict | None:
    """The equations / matrices of a written model (None if none was written)."""
    if not out.exists():
        return None
    model = json.loads(out.read_text())
    return {k: v for k, v in model.items() if k not in ("source", "fit_time_s")}


def _same(a: dict | None, b: dict | None, rtol: float, reordered: bool = False) -> bool:
    """Two written models equal up to ``rtol`` in every number (the same record read); with
    ``reordered``, their numbers as sorted multisets (the channels read in another order
    permute the matrices' rows and columns)."""
    if a is None or b is None:
        return False
    fa, fb = np.array(_numbers(a), dtype=float), np.array(_numbers(b), dtype=float)
    if reordered:
        fa, fb = np.sort(fa), np.sort(fb)
    return fa.shape == fb.shape and bool(np.all(np.abs(fa - fb) <= rtol * np.abs(fb)
                                                + 1e-12 * np.max(np.abs(fb), initial=0)))


# ------------------------------------------------------------------ uffmix

def uffmix_cases(work: Path) -> list[tuple[str, object]]:
    import pyuff

    beam = ["--kind", "structural", "--method", "ls_sindy"]

    def exported() -> tuple[Path, list[str]]:
        src = _generated(work, LAB)
        out = work / "lab.uff"
        prior_file = work / "lab.prior"
        if not out.exists():
            status, stdout, err = cli_inprocess(["export", str(src), "--format", "uff", "-o", str(out)])
            if status != 0:
                raise RuntimeError(f"export: {err[-300:]}")
            prior_file.write_text(json.dumps([a for a in (stdout + err).split()
                                              if "=" in a and not a.startswith("-")]))
        return out, [x for p in json.loads(prior_file.read_text()) for x in ("--prior", p)]

    def identify(path: Path, prior: list[str]) -> tuple[int, str, str]:
        return cli_inprocess(["identify", str(path), "-o", f"{path}.model.json", *prior, *beam])

    def clean_model() -> dict | None:
        src, prior = exported()
        clean = work / "clean.uff"
        if not clean.exists():
            shutil.copy(src, clean)
            found = judged(*identify(clean, prior))
            if found:
                raise RuntimeError(f"clean file: {found}")
        return _model(Path(f"{clean}.model.json"))

    def case(label: str, edit, expect: str):
        """``expect``: "refuse", "same" (the clean file's model), "permuted" (the clean file's
        model, channels in another order) or "verdict"."""
        def run():
            src, prior = exported()
            sets = pyuff.UFF(str(src)).read_sets()
            sets = sets if isinstance(sets, list) else [sets]
            edit(sets)
            path = work / f"{_safe(label)}.uff"
            path.unlink(missing_ok=True)
            pyuff.UFF(str(path)).write_sets(sets, mode="add")
            status, out, err = identify(path, prior)
            found = judged(status, out, err, refuse=expect == "refuse")
            if found:
                return found
            if expect in ("same", "permuted"):
                if status == 2:
                    return f"refused an equivalent file: {err.strip()[:200]!r}"
                if not _same(_model(Path(f"{path}.model.json")), clean_model(), 1e-9,
                             reordered=expect == "permuted"):
                    return "read to another model than the clean file's"
            return None
        return run

    def of_type(sets, t):
        return [s for s in sets if s["type"] == t]

    def origin_noise(sets):
        """The clamp's node (one past the sensors', no record's) added at the origin, and a
        UFF2411 twin of the geometry placing it at z = -1.2e-16 m."""
        [g] = [s for s in sets if s["type"] in (15, 2411)][:1]
        clamp = int(np.max(g["node_nums"])) + 1
        for k in ("node_nums", "def_cs", "disp_cs", "color", "x", "y", "z"):
            g[k] = np.append(g[k], clamp if k == "node_nums" else 0.0 if k in "xyz" else g[k][0])
        twin = {k: (np.array(v, copy=True) if isinstance(v, np.ndarray) else v) for k, v in g.items()}
        twin["type"], twin["z"][-1] = 2411, -1.2e-16
        sets.insert(sets.index(g) + 1, twin)

    def geometry(sets):
        return of_type(sets, 2411)[0]

    def node_twice_in_one(sets):
        g = geometry(sets)
        for k in ("node_nums", "def_cs", "disp_cs", "color", "x", "y", "z"):
            g[k] = np.append(g[k], g[k][1])
        g["x"][-1] = g["x"][1] + 0.05

    def second_geometry(dx: float):
        def edit(sets):
            g = json.loads(json.dumps({k: (v.tolist() if hasattr(v, "tolist") else v)
                                       for k, v in geometry(sets).items()}))
            g = {k: (np.array(v) if isinstance(v, list) else v) for k, v in g.items()}
            g["x"] = g["x"] + dx
            sets.insert(2, g)
        return edit

    def uff15(dx: float):
        def edit(sets):
            g = geometry(sets)
            sets.insert(2, {"type": 15, "node_nums": g["node_nums"].copy(), "def_cs": g["def_cs"].copy(),
                            "disp_cs": g["disp_cs"].copy(), "color": g["color"].copy(),
                            "x": g["x"] + dx, "y": g["y"].copy(), "z": g["z"].copy()})
        return edit

    def nan_coordinate(sets):
        geometry(sets)["x"][1] = np.nan

    def drop_node(k: int):
        def edit(sets):
            g = geometry(sets)
            for key in ("node_nums", "def_cs", "disp_cs", "color", "x", "y", "z"):
                g[key] = np.delete(g[key], k)
        return edit

    def units(length: float, where: str = "after"):
        def edit(sets):
            u = dict(of_type(sets, 164)[0])
            u.update(length=length, units_code=1 if length == 1 else 5,
                     units_description="SI" if length == 1 else "mm")
            if where == "after":
                sets.append(u)
            else:
                sets.insert(1, u)
        return edit

    def header(sets):
        sets.insert(0, {"type": 151, "model_name": "beam", "description": "lab", "db_app": "x",
                        "date_db_created": "", "time_db_created": "", "version_db1": 0,
                        "version_db2": 0, "file_type": 0, "date_db_saved": "",
                        "time_db_saved": "", "program": "sysid", "date_file_written": "",
                        "time_file_written": ""})

    def elements(sets):
        sets.insert(2, {"type": 2412, "element_nums": np.array([1, 2]),
                        "fe_descriptor": np.array([21, 21]), "phys_table": np.array([1, 1]),
                        "mat_table": np.array([1, 1]), "color": np.array([1, 1]),
                        "num_nodes": np.array([2, 2]), "nodes_nums": np.array([[1, 2], [2, 3]])})

    def drop_truth(sets):
        sets[:] = [s for s in sets if s["type"] != 55]

    def reorder(sets):
        recs = of_type(sets, 58)
        rest = [s for s in sets if s["type"] != 58]
        sets[:] = rest[:2] + recs[::-1] + rest[2:]

    def extra58(change: dict, data=None):
        def edit(sets):
            s = dict(of_type(sets, 58)[1])
            s.update(change)
            if data is not None:
                s["data"] = data(s["data"])
            sets.append(s)
        return edit

    def explicit_x(which, make_x):
        def edit(sets):
            for k, s in enumerate(of_type(sets, 58)):
                if which is None or k == which:
                    n = len(s["data"])
                    s["abscissa_spacing"] = 0
                    s["x"] = make_x(n, s["abscissa_inc"])
                    s["id5"] = "sysid-testbed"  # the rate read from the abscissa
        return edit

    def uniform(n, inc):
        return np.arange(n) * inc

    def gap(n, inc):
        x = np.arange(n) * inc
        x[n // 2:] += 10 * inc
        return x

    def logarithmic(n, inc):
        return np.geomspace(inc, n * inc, n)

    def fast(n, inc):
        return np.arange(n) * inc * 0.99

    def binary(flag: int):
        def edit(sets):
            for s in of_type(sets, 58):
                s["binary"] = flag
        return edit

    def direction(k: int, d: int):
        def edit(sets):
            of_type(sets, 58)[k]["rsp_dir"] = d
        return edit

    cases = [
        ("a node twice in one UFF2411 record, 5 cm apart", node_twice_in_one, "refuse"),
        ("two UFF2411 records placing the sensors 5 cm apart", second_geometry(0.05), "refuse"),
        ("two UFF2411 records of the same positions", second_geometry(0.0), "same"),
        ("a UFF15 record disagreeing with the UFF2411 one by 5 cm", uff15(0.05), "refuse"),
        ("a UFF15 record agreeing with the UFF2411 one", uff15(0.0), "same"),
        ("a node's x coordinate NaN", nan_coordinate, "refuse"),
        ("the first sensor's node missing from the geometry", drop_node(0), "refuse"),
        ("two UFF164 records, both SI", units(1.0, "before"), "same"),
        ("a second UFF164 record in mm after the responses", units(1000.0), "refuse"),
        ("a second UFF164 record in mm before the responses", units(1000.0, "before"), "refuse"),
        ("a UFF151 header", header, "same"),
        ("a UFF2412 element record", elements, "same"),
        ("the truth's UFF55 records dropped", drop_truth, "same"),
        ("the UFF58 records in reverse order", reorder, "permuted"),
        ("a UFF58 frequency response among the time responses",
         extra58({"func_type": 4, "id1": "frf/acc2"}), "refuse"),
        ("a UFF58 complex record among the time responses",
         extra58({"ord_data_type": 6, "id1": "acceleration/acc2c"}, lambda d: d + 0j), "refuse"),
        ("every record with an explicit uniform abscissa", explicit_x(None, uniform), "same"),
        ("one record with an explicit uniform abscissa", explicit_x(1, uniform), "same"),
        ("one record's explicit abscissa with a gap of 10 samples", explicit_x(1, gap), "refuse"),
        ("one record's explicit abscissa logarithmic", explicit_x(1, logarithmic), "refuse"),
        ("one record's explicit abscissa 1 % fast", explicit_x(1, fast), "refuse"),
        ("every record in ASCII (binary 0)", binary(0), "verdict"),
        ("a channel given twice under its name", extra58({}), "refuse"),
        ("a second channel at one node and direction, another name",
         extra58({"id1": "acceleration/acc2b", "rsp_ent_name": "acc2b"}, lambda d: d * 1.01), "refuse"),
        ("a sensor along +Y beside +Z ones", direction(1, 2), "refuse"),
        ("every sensor and the force along +Y (one frame)",
         lambda sets: [s.__setitem__("rsp_dir", 2) for s in of_type(sets, 58)], "same"),
        ("every record starting 0.5 s later (one clock)",
         lambda sets: [s.__setitem__("abscissa_min", 0.5) for s in of_type(sets, 58)], "same"),
        ("ordinates in single precision",
         lambda sets: [s.update(ord_data_type=2, data=s["data"].astype(np.float32))
                       for s in of_type(sets, 58)], "verdict"),
        ("every ID line 1 empty (channels named by node)",
         lambda sets: [s.__setitem__("id1", "") for s in of_type(sets, 58)], "verdict"),
        # review 25a: a node at the origin written 0 and -1.2e-16 (L cos(pi/2)) is one place
        ("a UFF2411 twin with float noise at the origin node", origin_noise, "same"),
        ("one sensor without a direction beside +Z ones", direction(1, 0), "verdict"),
        ("one sensor's node 0 (no node)", lambda sets: of_type(sets, 58)[1].__setitem__("rsp_node", 0),
         "refuse"),
        ("the force's node absent from the geometry",
         lambda sets: of_type(sets, 58)[3].__setitem__("rsp_node", 9), "refuse"),
    ]
    return [(f"uffmix {label}", case(label, edit, expect)) for label, edit, expect in cases]


# ------------------------------------------------------------------ kindswap

RECORDS = {"structural": LAB, "mechanical": "fivebar_multisine", "cartpole": "cartpole", "dynamical": MM}
KIND_OF = {"structural": "structural", "mechanical": "mechanical", "cartpole": "mechanical",
           "dynamical": "dynamical"}
METHOD_OF = {"structural": "ls_sindy", "mechanical": "sindy_pi", "dynamical": "sindy_pi_dynamical"}


def kindswap_cases(work: Path) -> list[tuple[str, object]]:
    def record(rig: str, form: str) -> Path:
        h5 = _generated(work, RECORDS[rig])
        if form == "h5":
            return h5
        out = work / f"{RECORDS[rig]}.json"
        if not out.exists():
            status, _, err = cli_inprocess(["export", str(h5), "--format", "sep005", "-o", str(out)])
            if status != 0:
                raise RuntimeError(f"export {rig}: {err[-300:]}")
        return out

    def case(rig: str, form: str, args: list[str]):
        def run():
            path = record(rig, form)
            out = work / f"{_safe(rig + form + ' '.join(args))}.model.json"
            return judged(*cli_inprocess(["identify", str(path), *args, "-o", str(out)]), refuse=True)
        return run

    cases = []
    for rig in RECORDS:
        own = KIND_OF[rig]
        for form in ("h5", "json"):
            for kind in ("structural", "mechanical", "dynamical"):
                if kind != own:
                    cases.append((f"kindswap {RECORDS[rig]}.{form} as {kind}",
                                  case(rig, form, ["--kind", kind, "--method", METHOD_OF[kind]])))
        other = next(k for k in ("dynamical", "structural", "mechanical") if k != own)
        cases.append((f"kindswap {RECORDS[rig]}.h5 --kind {own} --method {METHOD_OF[other]}",
                      case(rig, "h5", ["--kind", own, "--method", METHOD_OF[other]])))
        foreign = next(RECORDS[r] for r in RECORDS if KIND_OF[r] != own)
        cases.append((f"kindswap {RECORDS[rig]}.h5 --scenario {foreign}",
                      case(rig, "h5", ["--scenario", foreign])))

    def same_kind(rig: str, form: str, scenario: str):
        """A record under a scenario of another rig of its own kind: a model or a named
        failure, not judged further (a lab's own record is read by any scenario of its kind)."""
        def run():
            path = record(rig, form)
            out = work / f"{_safe(rig + form + scenario)}.model.json"
            return judged(*cli_inprocess(["identify", str(path), "--scenario", scenario, "-o", str(out)]))
        return run

    cases += [(f"kindswap {RECORDS[r]}.{f} --scenario {sc} (same kind)", same_kind(r, f, sc))
              for r, f, sc in (("cartpole", "h5", "fivebar_multisine"),
                               ("mechanical", "h5", "cartpole"),
                               ("cartpole", "json", "fivebar_multisine"),
                               ("structural", "h5", "cantilever_soft_impact"))]
    return cases


# ------------------------------------------------------------------ h5meta

def h5meta_cases(work: Path) -> list[tuple[str, object]]:
    import h5py

    def case(label: str, scenario: str, edit, expect: str, command: str = "identify"):
        def run():
            src = _generated(work, scenario)
            path = work / f"{_safe(label)}_{command}.h5"
            shutil.copy(src, path)
            with h5py.File(path, "r+") as f:
                edit(f)
            _rehash(path)
            if command == "identify":
                kind, method = {MM: ("dynamical", "sindy_pi_dynamical"),
                                LAB: ("structural", "ls_sindy"),
                                "cartpole": ("mechanical", "sindy_pi")}[scenario]
                got = cli_inprocess(["identify", str(path), "--kind", kind, "--method", method,
                                     "-o", f"{path}.model.json"])
            else:
                got = cli_inprocess(["export", str(path), "--format", "sep005",
                                     "-o", str(path.with_suffix(".json"))])
            found = judged(*got, refuse=expect == "refuse")
            if found or expect not in ("metres", "read"):
                return found
            # review 25a: a valid spelling is read (positions declared in mm in metres)
            if got[0] == 2:
                return f"refused a valid declaration: {got[2].strip()[:200]!r}"
            if command == "export":
                with h5py.File(src, "r") as f:
                    want = np.asarray(f["measured/acceleration"].attrs["positions"], float)
                read = [c["position_m"] for c in json.loads(path.with_suffix(".json").read_text())
                        if c["name"].startswith("acceleration/")]
                # x 1000 then x 1e-3: a rounding of each (2 ulp)
                if not np.allclose(read, want, rtol=4e-16, atol=0):
                    return f"exported positions {read} m, the source's {want.tolist()} m"
            return None
        return run

    def attr(where: str, key: str, value):
        def edit(f):
            f[where].attrs[key] = value
        return edit

    def mm_positions(f):
        d = f["measured/acceleration"]
        d.attrs["positions"] = np.asarray(d.attrs["positions"]) * 1000
        d.attrs["positions_unit"] = "mm"

    def mm_positions_bytes(f):
        mm_positions(f)
        f["measured/acceleration"].attrs["positions_unit"] = np.bytes_(b"mm")

    acc = "measured/acceleration"
    text = h5py.string_dtype()
    cases = []
    for cmd in ("identify", "export"):
        cases += [
            (f"an attribute fs on the /measured group ({cmd})", MM, attr("measured", "fs", 1.0),
             "refuse", cmd),
            (f"an attribute unit on the /truth group ({cmd})", MM, attr("truth", "unit", "mM"),
             "refuse", cmd),
            (f"an attribute on the /reference group ({cmd})", MM, attr("reference", "scale", 2.0),
             "refuse", cmd),
            # review 25a: a length unit is read as it says (positions 1000 x closer: a verdict)
            (f"positions_unit 'mm', positions unchanged ({cmd})", LAB, attr(acc, "positions_unit", "mm"),
             "verdict", cmd),
            (f"positions_unit 'in' ({cmd})", LAB, attr(acc, "positions_unit", "in"), "refuse", cmd),
            (f"positions_unit a number ({cmd})", LAB, attr(acc, "positions_unit", 1.0), "refuse", cmd),
            (f"positions_unit an array ({cmd})", LAB,
             attr(acc, "positions_unit", np.array(["m", "m"], dtype=text)), "refuse", cmd),
            (f"positions in mm declared 'mm' ({cmd})", LAB, mm_positions, "metres", cmd),
            (f"positions in mm declared 'mm' as fixed-length bytes ({cmd})", LAB,
             mm_positions_bytes, "metres", cmd),
            (f"positions_unit 'm' on a signal without positions ({cmd})", MM,
             attr("measured/x", "positions_unit", "m"), "verdict", cmd),
            (f"a channel name as fixed-length bytes ({cmd})", MM,
             attr("measured/x", "channels", np.array([b"x"], dtype="S1")), "refuse", cmd),
            (f"unit a two-item array ({cmd})", MM,
             attr("measured/x", "unit", np.array(["mM", "s"], dtype=text)), "refuse", cmd),
        ]
    cases += [
        ("layout a one-item list (identify)", MM,
         attr("measured/x", "layout", np.array(["channels x samples"], dtype=text)), "verdict"),
        # review 25a: valid spellings of a text, decoded
        ("unit as fixed-length bytes (identify)", MM, attr("measured/x", "unit", np.bytes_(b"mM")),
         "read"),
        ("unit a one-item text array (identify)", MM,
         attr("measured/x", "unit", np.array(["mM"], dtype=text)), "read"),
        ("unit not UTF-8 bytes (identify)", MM, attr("measured/x", "unit", np.bytes_(b"\xff")), "refuse"),
        ("acts_on an integer (identify)", "cartpole", attr("measured/torque", "acts_on", 3), "refuse"),
    ]
    out = [(f"h5meta {label}", case(label, sc, edit, expect, command))
           for label, sc, edit, expect, *more in cases for command in [more[0] if more else "identify"]]

    def cached_truth_edited():
        """A cached dataset's truth edited in place (its hash not made anew), then ``run``:
        the cache verifies on read, so the run regenerates or refuses; never scores against
        the edited truth."""
        from testbed.pipeline.cache import DatasetCache
        from testbed.pipeline.scenario import load_scenario

        cache = work / "cache"
        status, _, err = cli_inprocess(["generate", MM, "--cache", str(cache), "-o", str(work / "mm_c.h5")])
        if status != 0:
            return f"generate: {err.strip()[-200:]}"
        sc = load_scenario(MM)
        entry = DatasetCache(cache).path_for(sc, sc.seed) if hasattr(DatasetCache, "path_for") else None
        files = [entry] if entry else sorted(cache.rglob("*.h5"))
        if not files:
            return "no cache entry written"
        with h5py.File(files[0], "r+") as f:
            name = next(iter(f["truth"]))
            d = f["truth"][name]
            if d.dtype.kind == "f":
                d[...] = d[()] * 2.0
        status, out_, err = cli_inprocess(["run", MM, "--cache", str(cache), "-o", str(work / "runs"),
                                           "--no-figures"])
        found = judged(status, out_, err)
        if found:
            return found
        from testbed.core.dataset import Dataset
        try:
            Dataset.load(files[0])
        except Exception as e:
            return f"the cache entry left unverifiable after run: {e}"
        return None

    out.append(("h5meta a cached dataset's truth edited in place, then run", cached_truth_edited))
    return out


# ------------------------------------------------------------------ famdraw

FAMILY_STUDY = """
[study]
name = "fd"
description = "hostile family draws"
noise = [0.0]
seeds = [0]
identifiers = ["sindy_pi"]

[families.f]
base = "cartpole"
members = {members}
seed = 0
description = "drawn"

[families.f.{table}]
{key} = {spec}
"""


def famdraw_cases(work: Path) -> list[tuple[str, object]]:
    def case(label: str, table: str, key: str, spec: str, expect: str, members: str = "2"):
        def run():
            folder = work / _safe(label)
            folder.mkdir(exist_ok=True)
            study = folder / "fd.toml"
            study.write_text(FAMILY_STUDY.format(members=members, table=table, key=key, spec=spec))
            out = folder / "members"
            status, stdout, err = cli_inprocess(["family", "write", str(study), "-o", str(out)])
            found = judged(status, stdout, err, refuse=expect == "refuse")
            if found:
                return found
            if status == 0:
                from testbed.pipeline.scenario import load_scenario

                written = sorted(out.glob("*.toml"))
                if not written:
                    return "status 0 and no member written"
                for p in written:
                    try:
                        load_scenario(p)
                    except Exception as e:
                        return f"wrote {p.name}, which its loader refuses: {str(e)[:160]}"
                if expect == "refuse":
                    return f"wrote {len(written)} members"
            return None
        return run

    cases = [
        ("a uniform range over +-1.7e308 (its width overflows)", "rig", "x0",
         "{uniform = [-1.7e308, 1.7e308]}", "refuse"),
        ("a uniform range [0, 1.7e308]", "rig", "cart_mass", "{uniform = [0.0, 1.7e308]}", "verdict"),
        ("a log range of 300 decades", "rig", "cart_mass", "{log_uniform = [1e-150, 1e150]}", "verdict"),
        ("choices of inline tables", "rig", "cart_mass", "{choices = [{a = 1}, {b = 2}]}", "refuse"),
        ("choices of booleans", "rig", "cart_mass", "{choices = [true, false]}", "refuse"),
        ("choices of a number and a text", "rig", "cart_mass", "{choices = [1.0, \"heavy\"]}", "refuse"),
        ("choices of one number (accepted)", "rig", "cart_mass", "{choices = [2.0]}", "verdict"),
        ("choices of nested lists", "rig", "cart_mass", "{choices = [[1.0, 2.0]]}", "refuse"),
        ("a draw of the excitation's type", "excitation", "type",
         "{choices = [\"multisine\", \"impact\"]}", "verdict"),
        ("a range for a key the rig has not", "rig", "spring_rate", "{uniform = [1.0, 2.0]}", "refuse"),
        ("every draw refused by the rig (negative mass)", "rig", "cart_mass",
         "{uniform = [-2.0, -1.0]}", "refuse"),
        ("members 10**9", "rig", "cart_mass", "{uniform = [1.0, 2.0]}", "refuse", "1000000000"),
        ("integers over [2**62, 2**63 - 1] for a float key (a heavy cart: no bound)", "rig",
         "cart_mass", "{integers = [4611686018427387904, 9223372036854775807]}", "verdict"),
        ("log_integers over [1, 2**62] for the phase seed", "excitation", "phase_seed",
         "{log_integers = [1, 4611686018427387904]}", "verdict"),
        ("uniform of integers for an integer key", "excitation", "n_tones",
         "{uniform = [2, 9]}", "refuse"),
        ("integers for a float key (accepted)", "rig", "cart_mass", "{integers = [1, 3]}", "verdict"),
        ("a range as a text", "rig", "cart_mass", "{uniform = \"1, 2\"}", "refuse"),
        ("a range of three numbers", "rig", "cart_mass", "{uniform = [1.0, 2.0, 3.0]}", "refuse"),
        ("a NaN bound", "rig", "cart_mass", "{uniform = [1.0, nan]}", "refuse"),
        ("subnormal log bounds", "rig", "cart_mass", "{log_uniform = [5e-324, 1e-323]}", "refuse"),
    ]
    return [(f"famdraw {c[0]}", case(*c)) for c in cases]


# ------------------------------------------------------------------ npzform

class _Marker:
    """Unpickled, makes the folder ``path``: a pickle that ran leaves its trace."""

    def __init__(self, path: str) -> None:
        self.path = path

    def __reduce__(self):
        import os

        return (os.mkdir, (self.path,))


def npzform_cases(work: Path) -> list[tuple[str, object]]:
    """A run folder's ``run.npz`` replaced by a crafted one and the run sealed anew (its npz
    checksum and ``run.json``'s own), then ``testbed report`` of the run and ``testbed runs
    ls``: one refusal line (or the same report for the same numbers), and never a pickle
    loaded."""
    import io
    import pickle
    import zipfile

    from testbed.studies import runstore

    def base_run() -> Path:
        runs = work / "runs"
        done = sorted(runs.glob(f"{MM}/*/run.json"))
        if not done:
            status, _, err = cli_inprocess(["run", MM, "-o", str(runs), "--no-figures",
                                            "--cache", str(work / "cache")])
            if status not in (0, 1):
                raise RuntimeError(f"run: {err[-300:]}")
            done = sorted(runs.glob(f"{MM}/*/run.json"))
        return done[0].parent

    def reseal(run: Path) -> None:
        meta = json.loads((run / "run.json").read_text())
        meta[runstore.NPZ_DIGEST] = runstore._file_digest(run / "run.npz")
        meta[runstore.DIGEST] = runstore.meta_digest(meta)
        (run / "run.json").write_text(json.dumps(meta))

    def arrays(run: Path) -> dict[str, np.ndarray]:
        with np.load(run / "run.npz", allow_pickle=False) as z:
            return {k: z[k] for k in z.files}

    def case(label: str, make, expect: str, said: str = ""):
        """``make(arrays, marker) -> bytes`` of the new run.npz; ``expect`` "refuse" or "same";
        ``said``: text the refusal must hold."""
        def run():
            src = base_run()
            folder = work / "cases" / _safe(label)
            shutil.rmtree(folder, ignore_errors=True)
            target = folder / MM / src.name
            shutil.copytree(src, target)
            marker = folder / "PICKLE_RAN"
            (target / "run.npz").write_bytes(make(arrays(src), str(marker)))
            reseal(target)
            status, out, err = cli_inprocess(["report", str(target), "-o", str(folder / "report")])
            if marker.exists():
                return "a pickle in run.npz was loaded (its code ran)"
            found = judged(status, out, err, refuse=expect == "refuse")
            if found:
                return f"report: {found}"
            if said and said not in err:
                return f"report refused without naming {said!r}: {err.strip()[-200:]!r}"
            if expect == "same" and status != 0:
                return f"report refused an equivalent run.npz: {err.strip()[:200]!r}"
            status, out, err = cli_inprocess(["runs", "ls", "-o", str(folder), "--plain"])
            found = judged(status, out, err)
            if found:
                return f"runs ls: {found}"
            return None
        return run

    def saved(a: dict[str, np.ndarray]) -> bytes:
        buf = io.BytesIO()
        np.savez(buf, **a)
        return buf.getvalue()

    def with_member(fn):
        def make(a, marker):
            b = dict(a)
            fn(b, marker)
            return saved(b)
        return make

    def first_float(a: dict[str, np.ndarray]) -> str:
        return next(k for k, v in a.items() if v.dtype.kind == "f" and v.ndim >= 1 and v.size > 1)

    def object_member(b, marker):
        b[first_float(b)] = np.array([_Marker(marker), 1.0], dtype=object)

    def object_extra(b, marker):
        b["details/evil"] = np.array([_Marker(marker)], dtype=object)

    def whole_pickle(a, marker):
        return pickle.dumps({"model/x": _Marker(marker)})

    def pickle_in_zip(a, marker):
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w") as z:
            z.writestr("model/x.pkl", pickle.dumps(_Marker(marker)))
        return buf.getvalue()

    def big_endian(b, marker):
        k = first_float(b)
        b[k] = b[k].astype(">f8")

    def structured(b, marker):
        k = first_float(b)
        b[k] = np.zeros(b[k].shape, dtype=[("a", "f8"), ("b", "i4")])

    def text_member(b, marker):
        k = first_float(b)
        b[k] = np.array(["1.0"] * b[k].size)

    def complex_member(b, marker):
        k = first_float(b)
        b[k] = b[k] + 1j

    def float16(b, marker):
        k = first_float(b)
        b[k] = b[k].astype(np.float16)

    def empty_zip(a, marker):
        buf = io.BytesIO()
        with zipfile.ZipFile(buf, "w"):
            pass
        return buf.getvalue()

    def npy_not_npz(a, marker):
        buf = io.BytesIO()
        np.save(buf, np.arange(3.0))
        return buf.getvalue()

    cases = [
        ("a float member replaced by an object array holding a pickle", with_member(object_member), "refuse"),
        ("an extra object member holding a pickle", with_member(object_extra), "refuse"),
        ("the whole run.npz a pickle", whole_pickle, "refuse"),
        ("a zip holding a .pkl member", pickle_in_zip, "refuse"),
        ("a float member big-endian (the same numbers)", with_member(big_endian), "same"),
        ("a float member of a structured dtype", with_member(structured), "refuse"),
        # (text and complex are kinds a run.npz holds: which member holds which is the
        # run's, not read from a schema; not judged further)
        ("a float member as text", with_member(text_member), "verdict"),
        ("a float member complex", with_member(complex_member), "verdict"),
        ("a float member float16", with_member(float16), "verdict"),
        ("an empty zip (no member: a run without arrays)", empty_zip, "verdict"),
        ("a member of datetimes", with_member(lambda b, m: b.__setitem__(
            first_float(b), np.zeros(b[first_float(b)].size, dtype="M8[s]"))), "refuse"),
        ("a member of fixed-length bytes", with_member(lambda b, m: b.__setitem__(
            "details/extra", np.array([b"x"]))), "refuse"),
        ("run.npz a text file", lambda a, m: b"not a zip\n", "refuse"),
        ("a .npy file under the name run.npz", npy_not_npz, "refuse"),
        # review 25a: zipfile finds a zip by its end, numpy.load by its first bytes
        # (before: "not a run folder written by `testbed run` (TypeError)", naming nothing)
        ("a .npy with the run's zip appended", lambda a, m: npy_not_npz(a, m) + saved(a), "refuse",
         "run.npz: starts with the bytes"),
        ("a pickle with the run's zip appended", lambda a, m: whole_pickle(a, m) + saved(a), "refuse",
         "run.npz: starts with the bytes"),
    ]
    return [(f"npzform {label}", case(label, *how)) for label, *how in cases]


# ------------------------------------------------------------------ rigedge

#: The shipped scenario each rig's cases start from: (name, duration [s]).
EDGE_BASES = {
    "stiff": ("cantilever_stiff_impact_lsq", 0.3),
    "soft": ("cantilever_soft_impact_lsq", 0.3),
    "fivebar": ("fivebar_multisine", 2.0),
    "cartpole": ("cartpole", 4.0),
    "kinetics": (MM, 4.0),
}


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {_toml_value(x)}" for k, x in v.items()) + "}"
    return repr(v)


def _toml(raw: dict) -> str:
    return "".join(f"[{section}]\n" + "".join(f"{k} = {_toml_value(v)}\n" for k, v in table.items())
                   for section, table in raw.items())


def rigedge_cases(work: Path) -> list[tuple[str, object]]:
    """Scenarios each of whose numbers lies within its bounds, at an edge rounds 14 (``bounds``)
    and 22 (``physcombo``) did not try: no excitation (a torque or force amplitude of 0), a
    beam of 2 segments (its fewest), a joint offset of 0 and 0.5, damping at 0 and 0.999 of
    critical, a soft base of k3 = 0 (a linear base declared soft), a soft base 1e-6 as stiff
    as the beam, kinetics with Vmax = 0 (no reaction) or Km = 1e12 (linear), a cart-pole
    without gravity (no restoring force on the pole), a five-bar without damping: run and
    scored (``run_scenario``).  A traceback, anything but one refusal line, a pass with NaN
    scores, or NaN scores without a failure naming why, is a finding."""
    from testbed.pipeline.cache import DatasetCache
    from testbed.pipeline.scenario import load_scenario
    from testbed.scoring.run import run_scenario

    def case(label: str, base: str, edits: dict):
        def run():
            _, raw = _hostile.base_scenario(EDGE_BASES, base)
            for section, table in edits.items():
                raw.setdefault(section, {}).update(table)
            raw["scenario"]["name"] = f"h24_{_safe(label)}"[:100]
            path = work / f"{raw['scenario']['name']}.toml"
            path.write_text(_toml(raw))
            result = run_scenario(load_scenario(path), cache=DatasetCache(work / "cache"))
            return _hostile.scored_finding(result)
        return run

    rows = [
        ("five-bar torque amplitude 0 (no excitation)", "fivebar", {"excitation": {"amplitude": 0.0}}),
        ("five-bar 1e-9 N m of torque", "fivebar", {"excitation": {"amplitude": 1e-9}}),
        ("five-bar without damping", "fivebar", {"rig": {"damping": 0.0}}),
        ("five-bar one tone", "fivebar", {"excitation": {"n_tones": 1}}),
        ("cart-pole force amplitude 0 (no excitation)", "cartpole", {"excitation": {"amplitude": 0.0}}),
        ("cart-pole without gravity", "cartpole", {"rig": {"gravity": 0.0}}),
        ("cart-pole without damping", "cartpole", {"rig": {"cart_damping": 0.0, "pole_damping": 0.0}}),
        ("cart-pole one tone", "cartpole", {"excitation": {"n_tones": 1}}),
        ("cart-pole no centring (kp = kd = 0)", "cartpole", {"excitation": {"kp": 0.0, "kd": 0.0}}),
        ("kinetics Vmax = 0 (no reaction)", "kinetics", {"rig": {"Vmax": 0.0}}),
        ("kinetics Km = 1e12 (linear kinetics)", "kinetics", {"rig": {"Km": 1e12}}),
        ("kinetics no influx, started empty", "kinetics", {"rig": {"jx": 0.0, "x0": 0.0}}),
        ("beam of 2 segments", "stiff", {"rig": {"n_segments": 2, "sensors": [0.3175]}}),
        ("beam joint offset 0", "stiff", {"rig": {"joint_offset": 0.0}}),
        ("beam joint offset 0.5", "stiff", {"rig": {"joint_offset": 0.5}}),
        ("beam undamped", "stiff", {"rig": {"damping_ratio": 0.0}}),
        ("beam damped 0.999 of critical", "stiff", {"rig": {"damping_ratio": 0.999}}),
        ("soft base of k3 = 0 (linear, declared soft)", "soft", {"rig": {"base_k3": 0.0}}),
        ("soft base 1e-6 as stiff as declared", "soft", {"rig": {"base_k1": 2e-3}}),
        ("beam one sensor at the tip", "stiff", {"rig": {"sensors": [0.3175]}}),
        ("beam sensors at the first joint only", "stiff", {"rig": {"sensors": [0.03175]}}),
    ]
    return [(f"rigedge {label}", case(label, base, edits)) for label, base, edits in rows]


# ------------------------------------------------------------------ cliunits

def cliunits_cases(work: Path) -> list[tuple[str, object]]:
    """``testbed identify --units`` given in ways round 18's three cases did not try: one
    channel twice (the same unit, another), a unit for all beside one for a channel, an empty
    channel or unit, blanks around ``=``, a channel without its signal's name, a unit of
    another quantity for the force, a unit of the same quantity contradicting the file's,
    Unicode and upper-case spellings, on the beam's SEP-005 record (units declared); and on
    the kinetics record as CSV without units (``x`` and ``dx``): a rate given the state's unit,
    each unit given per channel (accepted: the clean model), a rate per minute.  A refusal in
    more than one line, a contradiction accepted, or an accepted equivalent read to another
    model, is a finding."""
    from testbed.core.dataset import Dataset

    def beam() -> Path:
        out = work / "beam.json"
        if not out.exists():
            status, _, err = cli_inprocess(["export", str(_generated(work, LAB)), "--format",
                                            "sep005", "-o", str(out)])
            if status != 0:
                raise RuntimeError(f"export: {err[-300:]}")
        return out

    def kinetics_csv() -> Path:
        out = work / "mm.csv"
        if not out.exists():
            ds = Dataset.load(_generated(work, MM))
            x, dx = ds.measured["x"].data[0], ds.measured["dx"].data[0]
            rows = [f"{k / ds.fs!r},{a!r},{b!r}" for k, (a, b) in
                    enumerate(zip(x.tolist(), dx.tolist(), strict=True))]
            out.write_text("time [s],x,dx\n" + "\n".join(rows) + "\n")
        return out

    def identify(path: Path, tag: str, args: list[str]) -> tuple[int, str, str]:
        kind = (["--kind", "structural", "--method", "ls_sindy", "--prior", "total_mass=0.7477125",
                 "--prior", "reduced_mass_trace=0.5157578642106304"] if path.suffix == ".json"
                else ["--kind", "dynamical", "--method", "sindy_pi_dynamical"])
        return cli_inprocess(["identify", str(path), *kind, *args, "-o", str(work / f"{tag}.model.json")])

    def case(label: str, record, args: list[str], expect: str, said: str = ""):
        """``said``: text the refusal must hold (the option at fault, not another)."""
        def run():
            path = record()
            tag = "clean_" + path.stem
            if expect == "same" and not (work / f"{tag}.model.json").exists():
                base = ["--units", "x=mM", "--units", "dx=mM/s"] if path.suffix == ".csv" else []
                found = judged(*identify(path, tag, base))
                if found:
                    return f"clean: {found}"
            status, out, err = identify(path, _safe(label), args)
            found = judged(status, out, err, refuse=expect == "refuse")
            if found:
                return found
            if said and said not in err:
                return f"refused without naming {said!r}: {err.strip()[:200]!r}"
            if expect == "same":
                if status == 2:
                    return f"refused an equivalent reading: {err.strip()[:200]!r}"
                if not _same(_model(work / f"{_safe(label)}.model.json"), _model(work / f"{tag}.model.json"),
                             1e-9):
                    return "read to another model than the clean reading's"
            return None
        return run

    a1 = "acceleration/acc1"
    rows = [
        ("a channel twice, two units", beam, ["--units", f"{a1}=g", "--units", f"{a1}=m/s^2"], "refuse"),
        ("a channel twice, one unit (the file's)", beam,
         ["--units", f"{a1}=m/s^2", "--units", f"{a1}=m/s^2"], "verdict"),
        ("a unit for all beside one for a channel", beam, ["--units", "m/s^2", "--units", f"{a1}=g"],
         "refuse"),
        ("an empty channel", beam, ["--units", "=m/s^2"], "refuse"),
        ("an empty unit", beam, ["--units", f"{a1}="], "refuse", "--units"),
        ("an empty unit for every channel", beam, ["--units", ""], "refuse", "--units"),
        # review 25a: blank after TOML parsing
        ("an empty quoted unit", beam, ["--units", f'{a1}=""'], "refuse", "--units"),
        ("a blank quoted unit", beam, ["--units", f"{a1}=' '"], "refuse", "--units"),
        ("blanks around =", beam, ["--units", f"{a1} = m/s^2"], "verdict"),
        ("a channel without its signal's name", beam, ["--units", "acc1=m/s^2"], "refuse"),
        ("the force in m/s^2", beam, ["--units", "force/force=m/s^2"], "refuse"),
        ("the force in kN on a file declaring N", beam, ["--units", "force/force=kN"], "refuse"),
        ("an acceleration in g on a file declaring m/s^2", beam, ["--units", f"{a1}=g"], "refuse"),
        ("m/s with a superscript two", beam, ["--units", f"{a1}=m/s\u00b2"], "refuse"),
        ("upper-case G", beam, ["--units", f"{a1}=G"], "refuse"),
        ("an unknown channel", beam, ["--units", "acceleration/acc9=m/s^2"], "refuse"),
        ("kinetics without units", kinetics_csv, [], "refuse"),
        ("kinetics one unit for both (the rate in mM)", kinetics_csv, ["--units", "mM"], "refuse"),
        ("kinetics each unit per channel", kinetics_csv, ["--units", "x=mM", "--units", "dx=mM/s"], "same"),
        ("kinetics the rate per minute", kinetics_csv, ["--units", "x=mM", "--units", "dx=mM/min"], "refuse"),
        ("kinetics the state in m (a length)", kinetics_csv, ["--units", "x=m", "--units", "dx=m/s"],
         "verdict"),
        ("kinetics the time column given a unit", kinetics_csv,
         ["--units", "x=mM", "--units", "dx=mM/s", "--units", "time=s"], "verdict"),
        ("kinetics the time column in ms", kinetics_csv,
         ["--units", "x=mM", "--units", "dx=mM/s", "--units", "time=ms"], "refuse"),
    ]
    return [(f"cliunits {label}", case(label, *how)) for label, *how in rows]


# ------------------------------------------------------------------ sweepresume

#: Columns of a results row that name when, where or how long, not what was found.
NOT_FOUND = ("fit_time", "data_time", "cell_time", "commit", "versions")


def _sweep_study(work: Path) -> Path:
    """A kinetics study: 3 noise levels x 3 seeds x 1 identifier (9 cells)."""
    path = work / "h24resume.toml"
    if not path.exists():
        path.write_text('[study]\nname = "h24resume"\nscenarios = ["michaelis_menten"]\n'
                        'noise = [0.0, 1.0, 5.0]\nseeds = [0, 1, 2]\n'
                        'identifiers = ["sindy_pi_dynamical"]\n')
    return path


def _found(path: Path) -> dict[str, dict]:
    """A results file's rows by cell, less :data:`NOT_FOUND` (NaN as the text 'nan')."""
    from testbed.studies.results import read_results

    def plain(v):
        return "nan" if isinstance(v, float) and v != v else v

    return {str(r["cell"]): {k: plain(v) for k, v in r.items() if k not in NOT_FOUND}
            for r in read_results(path)}


def sweepresume_cases(work: Path) -> list[tuple[str, object]]:
    """``testbed sweep`` (``--jobs 1`` and ``2``: loky workers) sent SIGINT or SIGTERM 1.5-6 s
    after its start, then resumed: round 23's ``sigwrite`` asked the resumed sweep for its
    whole grid; here each row must equal, bit for bit but for times and provenance, the row of
    the same cell in an uninterrupted sweep (reproducible: same scenario + seed = same data,
    the same fit).  And ``testbed summary`` / ``report`` of the results file while the sweep
    writes it: a table of the rows so far, or one refusal line.  A process left in the sweep's
    session, a traceback, a row that differs from the uninterrupted one, or a reader's
    traceback, is a finding."""
    import contextlib
    import os
    import signal
    import subprocess
    import time

    from benchmarks import hostile23

    def reference() -> dict[str, dict]:
        ref = work / "reference.parquet"
        if not ref.exists():
            status, _, err = cli_inprocess(["sweep", str(_sweep_study(work)), "--jobs", "2", "--cache",
                                            str(work / "cache"), "--results", str(ref)])
            if status not in (0, 1):
                raise RuntimeError(f"reference sweep: {err[-300:]}")
        return _found(ref)

    def stop(p, sig: int) -> str | None:
        p.send_signal(sig)
        try:
            _, err = p.communicate(timeout=90)
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.communicate()
            return f"still running 90 s after {signal.Signals(sig).name}"
        left = hostile23._left_in_session(p.pid)
        if left:
            for ln in left:
                with contextlib.suppress(ProcessLookupError):
                    os.kill(int(ln.split()[0]), signal.SIGKILL)
            return f"processes left in its session: {left[:3]}"
        lines = [ln for ln in err.splitlines() if ln.strip()]
        if "Traceback" in err or "internal error" in err or p.returncode not in (0, 1, 2, 130, 143, -sig):
            return f"status {p.returncode}: {(lines or [''])[-1][:200]}"
        return None

    def case(jobs: str, sig: int, delay: float):
        def run():
            want = reference()
            d = work / f"j{jobs}_{signal.Signals(sig).name}_{delay}"
            shutil.rmtree(d, ignore_errors=True)
            d.mkdir()
            argv = ["sweep", str(_sweep_study(work)), "--jobs", jobs, "--cache", str(work / "cache"),
                    "--results", str(d / "res.parquet")]
            p = hostile23._start(argv, d)
            time.sleep(delay)
            found = stop(p, sig)
            if found:
                return found
            again = _hostile.testbed_cli(argv, d, TIMEOUT_S)
            found = _hostile.cli_finding(again)
            if found or again.returncode not in (0, 1):
                return f"resumed: {found or again.returncode}"
            got = _found(d / "res.parquet")
            if sorted(got) != sorted(want):
                return f"resumed sweep holds cells {sorted(got)}, the grid {sorted(want)}"
            for cell, row in want.items():
                diff = sorted(k for k in set(row) | set(got[cell]) if row.get(k) != got[cell].get(k))
                if diff:
                    return (f"cell {cell}: {diff[:4]} differ from the uninterrupted sweep's "
                            f"({[row.get(k) for k in diff[:2]]} -> {[got[cell].get(k) for k in diff[:2]]})")
            return None
        return run

    def reading(what: str, delay: float):
        def run():
            reference()  # the cache filled: the sweep fits, it does not simulate
            d = work / f"read_{what}_{delay}"
            shutil.rmtree(d, ignore_errors=True)
            d.mkdir()
            res = d / "res.parquet"
            p = hostile23._start(["sweep", str(_sweep_study(work)), "--jobs", "2", "--cache",
                                  str(work / "cache"), "--results", str(res)], d)
            try:
                time.sleep(delay)
                argv = (["summary", str(res)] if what == "summary"
                        else ["report", str(res), "-o", str(d / "rep")])
                status, out, err = cli_inprocess(argv)
                found = judged(status, out, err)
            finally:
                try:
                    p.communicate(timeout=TIMEOUT_S)
                except subprocess.TimeoutExpired:
                    os.killpg(p.pid, signal.SIGKILL)
                    p.communicate()
            if found:
                return f"{what} while the sweep writes: {found}"
            if p.returncode not in (0, 1):
                return f"the sweep read while it wrote ended with status {p.returncode}"
            return None
        return run

    cases = [(f"sweepresume --jobs {jobs} {signal.Signals(sig).name} at {delay} s", case(jobs, sig, delay))
             for jobs in ("1", "2") for sig in (signal.SIGINT, signal.SIGTERM) for delay in (1.5, 3.0, 6.0)]
    cases += [(f"sweepresume {what} while the sweep writes, at {delay} s", reading(what, delay))
              for what in ("summary", "report") for delay in (1.0, 3.0, 5.0)]
    return cases


# ------------------------------------------------------------------ repro

def repro_cases(work: Path) -> list[tuple[str, object]]:
    """Reproducible data (the project's standard: same scenario + seed = bit-identical data):
    ``testbed generate`` twice into fresh caches, without a cache, from a cache it filled,
    with ``--seed`` equal to the scenario's own; and a scenario file written another way that
    TOML reads to the same numbers (integers for floats, exponents, keys reordered, comments,
    another name and description).  Each pair must give one content hash; two noise seeds,
    two.  A pair of one content that differs, or a pair of different contents that agrees,
    is a finding."""
    import re

    from testbed.pipeline.scenario import SCENARIO_DIR

    def generate(tag: str, scenario: str, *more: str) -> str:
        out = work / f"{tag}.h5"
        out.unlink(missing_ok=True)
        status, stdout, err = cli_inprocess(["generate", scenario, "-o", str(out), *more])
        if status != 0:
            raise RuntimeError(f"generate {tag}: {err.strip()[-300:]}")
        m = re.search(r"content hash ([0-9a-f]+)", stdout + err)
        if not m:
            raise RuntimeError(f"generate {tag}: no content hash printed")
        return m.group(1)

    def written(name: str, edit) -> str:
        text = (SCENARIO_DIR / f"{name}.toml").read_text()
        new = edit(text)
        if new == text:
            raise RuntimeError(f"the edit changed nothing in {name}.toml")
        stem = re.search(r'^name = "([^"]+)"', new, re.M).group(1)  # a file is named as its scenario
        path = work / f"v{len(list(work.glob('v*')))}" / f"{stem}.toml"
        path.parent.mkdir()
        path.write_text(new)
        return str(path)

    def pair(label: str, a, b, same: bool = True):
        def run():
            ha, hb = a(), b()
            if (ha == hb) != same:
                return f"content hashes {ha} and {hb}: expected {'one' if same else 'two'}"
            return None
        return run

    NOISY = "cantilever_stiff_impact_noise1"
    n = 0

    def gen(scenario_fn, *more: str, cache: str | None = "fresh"):
        def make() -> str:
            nonlocal n
            n += 1
            scenario = scenario_fn() if callable(scenario_fn) else scenario_fn
            args = list(more)
            if cache == "fresh":
                args += ["--cache", str(work / f"cache{n}")]
            elif cache is None:
                args += ["--no-cache"]
            else:
                args += ["--cache", str(work / cache)]
            return generate(f"g{n}", scenario, *args)
        return make

    def mm_edit(fn):
        return lambda: written(MM, fn)

    cases = [
        ("kinetics into two fresh caches", gen(MM), gen(MM), True),
        ("kinetics without a cache and with one", gen(MM, cache=None), gen(MM), True),
        ("kinetics into a cache, then from it", gen(MM, cache="shared"), gen(MM, cache="shared"), True),
        ("kinetics --seed 0 and its own seed 0", gen(MM, "--seed", "0"), gen(MM), True),
        ("the noisy beam seed 3 twice", gen(NOISY, "--seed", "3"), gen(NOISY, "--seed", "3"), True),
        ("the noisy beam seed 3 from its cache", gen(NOISY, "--seed", "3", cache="beam"),
         gen(NOISY, "--seed", "3", cache="beam"), True),
        ("the noisy beam seeds 3 and 4", gen(NOISY, "--seed", "3"), gen(NOISY, "--seed", "4"), False),
        ("kinetics with another name and description",
         gen(mm_edit(lambda t: t.replace('name = "michaelis_menten"', 'name = "mm_copy"')
                     .replace("description = ", 'description = "another" # ', 1))), gen(MM), True),
        ("kinetics duration 4 (an integer) for 4.0",
         gen(mm_edit(lambda t: re.sub(r"duration = [0-9.]+", "duration = 4", t, count=1))), gen(MM), True),
        ("kinetics sample rate 1e2 for 100.0",
         gen(mm_edit(lambda t: re.sub(r"sample_rate = [0-9.]+", "sample_rate = 1e2", t, count=1))),
         gen(MM), True),
        ("kinetics with comments and blank lines added",
         gen(mm_edit(lambda t: t.replace("[rig]\n", "# a comment\n\n[rig]   # the rig\n", 1))), gen(MM),
         True),
        ("kinetics with [rig] keys reordered",
         gen(mm_edit(lambda t: re.sub(r"(\[rig\]\n)((?:[^\[\n][^\n]*\n)+)",
                                      lambda m: m.group(1) + "".join(reversed(m.group(2).splitlines(True))),
                                      t, count=1))), gen(MM), True),
    ]
    return [(f"repro {label}", pair(label, a, b, same)) for label, a, b, same in cases]


# ------------------------------------------------------------------ envrun

def envrun_cases(work: Path) -> list[tuple[str, object]]:
    """``TESTBED_CACHE`` / ``TESTBED_SCENARIOS`` / ``TESTBED_STUDIES`` naming a file, a FIFO, a
    path under a file, ``/proc/self``, ``/sys`` (a read-only file system: root writes
    anywhere else) or ``/dev/full`` for the commands round 14's ``envvars`` did not run:
    ``run``, ``sweep``, ``cache ls`` and ``runs ls`` (real processes).  A traceback, a status
    other than 0 / 1 / 2, more than one error line, or a run / sweep that ends without its
    verdict line and reports no reason, is a finding."""
    import os
    import subprocess

    (work / "afile").write_text("x")
    if not (work / "fifo").exists():
        os.mkfifo(work / "fifo")
    study = work / "h24env.toml"
    study.write_text('[study]\nname = "h24env"\nscenarios = ["michaelis_menten"]\nnoise = [0.0]\n'
                     'seeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')
    values = {"a file": str(work / "afile"), "a FIFO": str(work / "fifo"),
              "a path under a file": str(work / "afile" / "x"), "/proc/self": "/proc/self",
              "/sys (read-only)": "/sys/h24", "/dev/full": "/dev/full"}
    commands = {
        "run": ["run", MM, "--no-figures", "-o", "runs"],
        "sweep": ["sweep", str(study), "--results", "res.parquet"],
        "cache ls": ["cache", "ls"],
        "runs ls": ["runs", "ls", "-o", "runs", "--plain"],
    }

    def case(var: str, label: str, value: str, cmd: str):
        def run():
            d = work / _safe(f"{var}_{label}_{cmd}")
            shutil.rmtree(d, ignore_errors=True)
            d.mkdir()
            env = {**_hostile.ENV, var: value}
            try:
                p = subprocess.run([sys.executable, "-m", "testbed.cli", *commands[cmd]], cwd=d, env=env,
                                   capture_output=True, text=True, timeout=180, stdin=subprocess.DEVNULL)
            except subprocess.TimeoutExpired:
                return "hang > 180 s"
            found = _hostile.cli_finding(p)
            if found:
                return found
            if cmd in ("run", "sweep") and p.returncode in (0, 1) and not p.stdout.strip():
                return f"status {p.returncode} and nothing on stdout: {p.stderr.strip()[-200:]!r}"
            return None
        return run

    cases = [(f"envrun TESTBED_CACHE {label}: {cmd}", case("TESTBED_CACHE", label, value, cmd))
             for label, value in values.items() for cmd in ("run", "sweep", "cache ls")]
    cases += [(f"envrun TESTBED_SCENARIOS {label}: run", case("TESTBED_SCENARIOS", label, value, "run"))
              for label, value in list(values.items())[:3]]
    cases += [(f"envrun TESTBED_STUDIES {label}: sweep", case("TESTBED_STUDIES", label, value, "sweep"))
              for label, value in list(values.items())[:3]]
    cases += [(f"envrun TESTBED_CACHE {label}: runs ls", case("TESTBED_CACHE", label, value, "runs ls"))
              for label, value in list(values.items())[:2]]
    return cases


# ------------------------------------------------------------------ main

FAMILIES = _hostile.families(
    {
        "uffmix": uffmix_cases,
        "kindswap": kindswap_cases,
        "h5meta": h5meta_cases,
        "famdraw": famdraw_cases,
        "npzform": npzform_cases,
        "rigedge": rigedge_cases,
        "cliunits": cliunits_cases,
        "sweepresume": sweepresume_cases,
        "repro": repro_cases,
        "envrun": envrun_cases,
    },
    TIMEOUT_S,
)


def main(argv: list[str]) -> int:
    return _hostile.main(argv, FAMILIES, "hostile24-")


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
