"""Twenty-third malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile23 [family ...]      # all families when none is named

Families (what rounds 1-22 did not try; their families are listed in ``hostile21.py`` and
``hostile22.py``):

``sepmix``
    SEP-005 records whose channels are each valid but disagree with each other or with what
    they declare: a channel one sample shorter, a ``time`` vector out of order, with a stamp
    repeated, starting later than its neighbour's, ``fs`` and ``time`` disagreeing by 1e-12
    (accepted) or 1 %; a rate's unit a state's, a unit of the same quantity in other words
    (``mol/m^3`` for mM: accepted, the same model), a unit missing; ``null`` or ``NaN`` in the
    first sample only (the edge a chain trims), ``1e308``, an extra channel of ``inf`` the
    chain does not read; a rate channel all zero beside a moving state; the beam's sensors at
    one position, beyond its root (negative: read, see known-gaps), unsorted, the force all
    zero (a named failure), in kN and the accelerations in mm/s^2 (the same model, the scale
    read), an acceleration labelled ``quantity = "force"``, one sensor's direction ``-Z``
    beside ``+Z`` ones (its samples negated to the others' frame, as the code's meaning asks:
    the same model where the file's samples are the -Z sensor's, review 24a), every channel
    ``-Z`` (one frame: the same model).  ``testbed identify``.  A
    traceback, more than one error line, an inconsistent record fitted with status 0, or a
    consistent one read to another model, is a finding.
``h5consist``
    A dataset file (``testbed generate``) edited and rehashed where its arrays stay valid but
    its attributes disagree: the beam's sensor positions beyond the beam its own scenario
    declares, negative, repeated; ``free_start`` past the record or negative; ``fs`` 1 % off
    the scenario's ``sample_rate``; NaN only in the beam's first samples (before the impact,
    where the chain trims), inf in the force after the pulse; ``layout`` claiming samples x
    channels.  ``testbed identify`` and ``export``.  A traceback, more than one error line, or
    a self-contradicting file fitted with status 0, is a finding.  (An export converts the
    file as it is: sensor positions are the structural chain's to judge on ``identify``.)
``tomlnear``
    Scenario keys one slip from a known one (a letter changed, added or dropped, another
    case: ``vmax``, ``xo``, ``duraton``, ``samplerate``, ``Degree``), keys written in another
    table (``sample_rate`` under ``[rig]``, ``seed`` under ``[simulation]``, ``derivatives``
    under ``[noise]``), a key given twice in its table.  A refusal that names neither the key
    meant, nor the table the key belongs in, nor the key given twice, is a finding.
``crossparam``
    ``testbed identify --param`` with a hyperparameter that another registered identifier
    declares (three per identifier, each of another owner where possible): anything but one
    refusal line naming an identifier that has it is a finding.
``cachepath``
    ``--cache``, ``run --out``, ``generate -o`` and ``sweep --results`` ending in a line end, a
    blank, a tab, a carriage return or a no-break space, a name of a single blank, of 255
    bytes (accepted) and 256 bytes, a name with an inner blank (accepted): a new file or folder
    whose name ends in an invisible character, made in silence, is a finding.
``runrace``
    Two ``run`` (one runs folder, one fresh cache), ``generate -o``, ``export -o`` or ``identify
    -o`` commands on one target started together or 0.3 s apart (real processes), and ``cache
    clear`` 1-4 s into a ``run`` simulating the beam into that cache: a traceback, both
    refused, a run without its verdict, a temporary file left, a cache entry or output that
    does not verify, or a finished run the run index does not list, is a finding.
``sigwrite``
    SIGINT / SIGTERM 0.8, 2 and 4 s into ``generate`` (the beam simulated into a fresh cache)
    and ``sweep --jobs 1`` / ``--jobs 2`` (fresh cache and results), 1.5 and 3 s into ``identify
    -o`` (``sgd_sindy`` on the beam) and 0.8 and 1.5 s into ``report`` of a sweep's results,
    then the command again: a process left in its session, a traceback, more than one error
    line, a temporary file, a file torn (empty, a model that does not parse, a PNG or HTML
    page cut short), a dataset file that does not verify, or a resumed sweep whose summary is
    not its whole grid, is a finding.

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
BEAM = "cantilever_stiff_impact_lsq"

cli_inprocess = _hostile.cli_inprocess
judged = _hostile.judged
_generated = hostile19._generated
_rehash = hostile19._rehash


def _identify(path: Path, kind: str, method: str, *more: str) -> tuple[int, str, str]:
    return cli_inprocess(["identify", str(path), "--kind", kind, "--method", method,
                          "-o", f"{path}.{method}.model.json", *more])


def _model(path: Path, method: str) -> dict | None:
    """The equations / matrices of a written model (None if none was written)."""
    out = Path(f"{path}.{method}.model.json")
    if not out.exists():
        return None
    model = json.loads(out.read_text())
    return {k: v for k, v in model.items() if k not in ("source", "fit_time_s")}


def _exported(work: Path, scenario: str) -> tuple[Path, list[dict]]:
    """The shipped scenario's record as SEP-005 (once) and its channel dicts."""
    path = work / f"{scenario}.json"
    if not path.exists():
        status, _, err = cli_inprocess(["export", str(_generated(work, scenario)), "--format",
                                        "sep005", "-o", str(path)])
        if status != 0:
            raise RuntimeError(f"export {scenario}: {err[-300:]}")
    return path, json.loads(path.read_text())


# ------------------------------------------------------------------ sepmix

BEAM_PRIORS = ("--prior", "reduced_mass_trace=0.5157578642106304", "--prior", "total_mass=0.7477125")


def _close(a: dict | None, b: dict | None, rtol: float) -> bool:
    """Two written models equal up to ``rtol`` in every number (the same record read)."""
    if a is None or b is None:
        return False
    fa = np.array([float(x) for x in _numbers(a)])
    fb = np.array([float(x) for x in _numbers(b)])
    return fa.shape == fb.shape and bool(np.all(np.abs(fa - fb) <= rtol * (np.abs(fb) + 1e-300)
                                                + 1e-12 * np.max(np.abs(fb), initial=0)))


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


def sepmix_cases(work: Path) -> list[tuple[str, object]]:
    def mm_edit(x: dict, dx: dict) -> None:
        pass

    def case(label: str, rig: str, edit, expect: str):
        """``expect``: "refuse" (status 2), "same" (the clean file's model), "verdict" (a model
        or a named failure, not judged further)."""
        def run():
            scenario, kind, method, more = {
                "mm": (MM, "dynamical", "sindy_pi_dynamical", ()),
                "beam": (BEAM, "structural", "ls_sindy", BEAM_PRIORS),
            }[rig]
            src, channels = _exported(work, scenario)
            clean = work / f"{rig}_clean.json"
            if not clean.exists():
                shutil.copy(src, clean)
                found = judged(*_identify(clean, kind, method, *more))
                if found:
                    return f"clean record: {found}"
            channels = json.loads(json.dumps(channels))
            byname = {c["name"].split("/")[-1]: c for c in channels}
            edit(channels, byname)
            path = work / f"{rig}_{hostile19._safe(label)}.json"
            # allow_nan: the NaN / Infinity literals json.loads reads
            path.write_text(json.dumps(channels, allow_nan=True))
            status, out, err = _identify(path, kind, method, *more)
            found = judged(status, out, err, refuse=expect == "refuse")
            if found:
                return found
            if expect == "same" and status == 0:
                if not _close(_model(path, method), _model(clean, method), 1e-6):
                    return "read to another model than the clean file's"
            elif expect == "same":
                return f"refused a consistent record: {err.strip()[:200]!r}"
            return None
        return run

    def setitem(name: str, key: str, value):
        def edit(ch, by):
            by[name][key] = value
        return edit

    def drop(name: str, key: str):
        def edit(ch, by):
            by[name].pop(key, None)
        return edit

    def data(name: str, fn):
        def edit(ch, by):
            by[name]["data"] = fn(list(by[name]["data"]))
        return edit

    def timed(name: str, fn, keep_fs: bool = False):
        def edit(ch, by):
            c = by[name]
            n = len(c["data"])
            t = [k / c["fs"] for k in range(n)]
            c["time"] = fn(t)
            if not keep_fs:
                c.pop("fs")
        return edit

    def both(*edits):
        def edit(ch, by):
            for e in edits:
                e(ch, by)
        return edit

    def extra(name: str, values_fn, unit: str = "mM"):
        def edit(ch, by):
            n = len(by["x"]["data"])
            ch.append({"name": name, "data": values_fn(n), "fs": by["x"]["fs"], "unit_str": unit,
                       "quantity": "general", "node": 1, "direction": "+Z", "group": "measured"})
        return edit

    def swap2(t):
        t[10], t[11] = t[11], t[10]
        return t

    def repeat(t):
        t[11] = t[10]
        return t

    def scaled(name: str, factor: float, unit: str):
        def edit(ch, by):
            by[name]["data"] = [v * factor for v in by[name]["data"]]
            by[name]["unit_str"] = unit
        return edit

    cases = [
        ("dx one sample shorter than x", "mm", data("dx", lambda d: d[:-1]), "refuse"),
        ("x's time with two stamps swapped", "mm", timed("x", swap2), "refuse"),
        ("x's time with a stamp repeated", "mm", timed("x", repeat), "refuse"),
        ("x's time starting 1 s later than dx's fs-only start", "mm",
         timed("x", lambda t: [v + 1.0 for v in t]), "refuse"),
        ("x's time and fs agreeing to 1e-12", "mm", timed("x", lambda t: [v * (1 + 1e-12) for v in t],
                                                            keep_fs=True), "same"),
        ("x's time and fs 1 % apart", "mm", timed("x", lambda t: [v * 1.01 for v in t], keep_fs=True),
         "refuse"),
        ("dx's unit a state's (mM)", "mm", setitem("dx", "unit_str", "mM"), "refuse"),
        ("dx's unit in seconds' inverse words (mmol/l/s)", "mm", setitem("dx", "unit_str", "mmol/l/s"),
         "verdict"),
        ("x in mol/m^3 (= mM), dx in mol/m^3/s", "mm",
         both(setitem("x", "unit_str", "mol/m^3"), setitem("dx", "unit_str", "mol/m^3/s")), "verdict"),
        ("x in uM (x1000), dx in uM/s (x1000)", "mm",
         both(scaled("x", 1000.0, "uM"), scaled("dx", 1000.0, "uM/s")), "verdict"),
        ("x in uM (x1000), dx left in mM/s", "mm", scaled("x", 1000.0, "uM"), "verdict"),
        ("dx's unit missing", "mm", drop("dx", "unit_str"), "verdict"),
        ("both units missing", "mm", both(drop("dx", "unit_str"), drop("x", "unit_str")), "verdict"),
        ("x's first sample null", "mm", data("x", lambda d: [None, *d[1:]]), "refuse"),
        ("x's first sample NaN", "mm", data("x", lambda d: [float("nan"), *d[1:]]), "refuse"),
        ("dx's last sample NaN", "mm", data("dx", lambda d: [*d[:-1], float("nan")]), "refuse"),
        ("x's first sample 1e308", "mm", data("x", lambda d: [1e+308, *d[1:]]), "refuse"),
        ("an extra channel of inf", "mm", extra("y", lambda n: [float("inf")] * n), "refuse"),
        ("an extra channel of zeros", "mm", extra("y", lambda n: [0.0] * n), "refuse"),
        ("dx all zero beside a moving x", "mm", data("dx", lambda d: [0.0] * len(d)), "refuse"),
        ("x constant beside a moving dx", "mm", data("x", lambda d: [d[0]] * len(d)), "refuse"),
        ("x and dx as integers (x1e6, in nM)", "mm",
         both(data("x", lambda d: [round(v * 1e6) for v in d]), setitem("x", "unit_str", "nM"),
              data("dx", lambda d: [round(v * 1e6) for v in d]), setitem("dx", "unit_str", "nM/s")),
         "verdict"),
        ("x's position_m 0.3 on a kinetics record", "mm", setitem("x", "position_m", 0.3), "verdict"),
        # the beam
        ("acc1 and acc2 at one position", "beam", setitem("acc1", "position_m", 0.21166666666666667),
         "refuse"),
        ("acc1 at a negative position", "beam", setitem("acc1", "position_m", -0.1), "verdict"),
        ("acc1 at the clamp (0 m)", "beam", setitem("acc1", "position_m", 0.0), "verdict"),
        ("sensors unsorted (acc1 <-> acc3 positions)", "beam",
         both(setitem("acc1", "position_m", 0.3175), setitem("acc3", "position_m", 0.10583333333333333)),
         "verdict"),
        ("the force all zero", "beam", data("force", lambda d: [0.0] * len(d)), "verdict"),
        ("the force in kN", "beam", scaled("force", 1e-3, "kN"), "same"),
        ("the accelerations in mm/s^2", "beam",
         both(*(scaled(a, 1e3, "mm/s^2") for a in ("acc1", "acc2", "acc3"))), "same"),
        ("acc2 labelled quantity 'force'", "beam", setitem("acc2", "quantity", "force"), "verdict"),
        ("acc2 direction -Z, its samples negated", "beam",
         both(setitem("acc2", "direction", "-Z"), data("acc2", lambda d: [-v for v in d])), "same"),
        ("acc2 direction -Z, its samples as they were", "beam", setitem("acc2", "direction", "-Z"),
         "verdict"),
        ("the force direction -Z, its samples negated", "beam",
         both(setitem("force", "direction", "-Z"), data("force", lambda d: [-v for v in d])), "same"),
        ("every channel -Z, its samples as they were", "beam",
         both(*(setitem(c, "direction", "-Z") for c in ("acc1", "acc2", "acc3", "force"))), "same"),
        ("the force's first sample NaN", "beam", data("force", lambda d: [float("nan"), *d[1:]]),
         "refuse"),
        ("acc3's last sample inf", "beam", data("acc3", lambda d: [*d[:-1], float("inf")]), "refuse"),
        ("the force 3 samples shorter", "beam", data("force", lambda d: d[:-3]), "refuse"),
    ]
    return [(f"sepmix {rig}: {label}", case(label, rig, edit, expect)) for label, rig, edit, expect in cases]


# ------------------------------------------------------------------ h5consist


def h5consist_cases(work: Path) -> list[tuple[str, object]]:
    import h5py

    def case(label: str, scenario: str, edit, expect: str, command: str = "identify"):
        def run():
            src = _generated(work, scenario)
            path = work / f"{hostile19._safe(label)}_{command}.h5"
            shutil.copy(src, path)
            with h5py.File(path, "r+") as f:
                edit(f)
            _rehash(path)
            if command == "identify":
                kind, method, more = {
                    MM: ("dynamical", "sindy_pi_dynamical", ()),
                    BEAM: ("structural", "ls_sindy", ()),
                }[scenario]
                got = _identify(path, kind, method, *more)
            else:
                got = cli_inprocess(["export", str(path), "--format", "sep005",
                                     "-o", str(path.with_suffix(".json"))])
            return judged(*got, refuse=expect == "refuse")
        return run

    def attr(dataset: str, key: str, value):
        def edit(f):
            f[dataset].attrs[key] = value
        return edit

    def values(dataset: str, fn):
        def edit(f):
            d = f[dataset]
            d[...] = fn(d[()])
        return edit

    def nan_head(a):
        a[:, :5] = np.nan
        return a

    def inf_tail(a):
        a[:, -100] = np.inf
        return a

    def scenario_rate(factor: float):
        def edit(f):
            sc = json.loads(f.attrs["scenario"])
            sc["simulation"]["sample_rate"] *= factor
            f.attrs["scenario"] = json.dumps(sc)
        return edit

    def root(key: str, value):
        def edit(f):
            f.attrs[key] = value
        return edit

    acc = "measured/acceleration"
    cases = [
        ("beam sensors beyond the beam (0.5 m of 0.3175)", BEAM,
         attr(acc, "positions", np.array([0.10583333, 0.21166667, 0.5])), "refuse"),
        ("beam sensors negative", BEAM, attr(acc, "positions", np.array([-0.2, 0.21166667, 0.3175])),
         "verdict"),
        ("beam sensors repeated", BEAM, attr(acc, "positions", np.array([0.2, 0.2, 0.3175])), "refuse"),
        ("beam force beyond the beam", BEAM, attr("measured/force", "positions", np.array([0.6])),
         "refuse"),
        ("beam free_start past the record", BEAM, root("free_start", np.int64(10**9)), "verdict"),
        ("beam free_start negative", BEAM, root("free_start", np.int64(-5)), "verdict"),
        ("beam fs 1 % off its scenario's sample_rate", BEAM, scenario_rate(1.01), "refuse"),
        ("mm fs 1 % off its scenario's sample_rate", MM, scenario_rate(1.01), "refuse"),
        ("beam NaN in the first 5 samples only", BEAM, values(acc, nan_head), "refuse"),
        ("beam force NaN in the first 5 samples only", BEAM, values("measured/force", nan_head), "refuse"),
        ("beam inf in the force after the pulse", BEAM, values("measured/force", inf_tail), "refuse"),
        ("mm layout attribute 'samples x channels'", MM, attr("measured/x", "layout", "samples x channels"),
         "refuse"),
        ("mm x NaN in the reference group only", MM, values("reference/x", lambda a: a * np.nan), "verdict"),
    ]
    out = [(f"h5consist {label}", case(label, sc, edit, expect)) for label, sc, edit, expect in cases]
    # an export converts the file as it is: positions are the identifiers' chain's to judge
    out += [(f"h5consist export: {label}", case(label, sc, edit, "verdict" if "sensors" in label else expect,
                                                  command="export"))
            for label, sc, edit, expect in cases if "sensors" in label or "NaN" in label or "fs" in label]
    return out


# ------------------------------------------------------------------ tomlnear


def _scenario_file(work: Path, stem: str, text: str) -> Path:
    from testbed.pipeline.scenario import SCENARIO_DIR

    base = (SCENARIO_DIR / f"{text}.toml").read_text() if text in (MM, "cantilever_stiff_impact") else text
    return hostile19._write(work / f"{stem}.toml", base)


def tomlnear_cases(work: Path) -> list[tuple[str, object]]:
    """Scenario keys one slip from a known one, keys in another table, a key given twice:
    the refusal must name the key meant (or the table it belongs in)."""
    from testbed.core.errors import ScenarioError
    from testbed.pipeline.scenario import SCENARIO_DIR, load_scenario

    mm = (SCENARIO_DIR / f"{MM}.toml").read_text()
    beam = (SCENARIO_DIR / "cantilever_stiff_impact.toml").read_text()

    def case(label: str, base: str, old: str, new: str, named: str):
        def run():
            import re

            stem = f"n_{hostile19._safe(label)}"[:60]
            # the key's own line (not a comment's mention of it), then the scenario's name
            src, n = re.subn(rf"^{re.escape(old)}", lambda m: new, base, count=1, flags=re.M)
            if not n:
                return f"the base has no line starting {old!r}"
            src = re.sub(r'^name = "[^"]*"', f'name = "{stem}"', src, count=1, flags=re.M)
            path = hostile19._write(work / f"{stem}.toml", src)
            try:
                load_scenario(path)
            except ScenarioError as e:
                text = str(e)
                if "\n" in text:
                    return f"two lines: {text[:200]!r}"
                return None if named in text else f"refused without naming {named!r}: {text[:240]!r}"
            return "accepted"
        return run

    cases = [
        # misspelt, mis-cased
        ("Vmax as vmax", mm, "Vmax = 1.5", "vmax = 1.5", "'Vmax'"),
        ("Km as km", mm, "Km = 0.3", "km = 0.3", "'Km'"),
        ("x0 as xo", mm, "x0 = 2.0", "xo = 2.0", "'x0'"),
        ("duration as duraton", mm, "duration = 4.0", "duraton = 4.0", "'duration'"),
        ("sample_rate as sample_rte", mm, "sample_rate = 100.0", "sample_rte = 100.0", "'sample_rate'"),
        ("sample_rate as samplerate", mm, "sample_rate = 100.0", "samplerate = 100.0", "'sample_rate'"),
        ("rms_percent as rms_procent", mm, "rms_percent = 0.0", "rms_procent = 0.0", "'rms_percent'"),
        ("derivatives as derivative", mm, 'derivatives = "recorded"', 'derivative = "recorded"',
         "'derivatives'"),
        ("description as Description", mm, "description = ", "Description = ", "'description'"),
        ("tags as tag", mm, "tags = [", "tag = [", "'tags'"),
        ("identify degree as degre", mm, "degree = 3", "degre = 3", "'degree'"),
        ("identify degree as Degree", mm, "degree = 3", "Degree = 3", "'degree'"),
        ("beam n_segments as n_segment", beam, "n_segments", "n_segment", "'n_segments'"),
        ("beam thickness as thicknes", beam, "thickness", "thicknes", "'thickness'"),
        ("beam sensors as sensor", beam, "sensors", "sensor", "'sensors'"),
        # in another table
        ("sample_rate under [rig]", mm, "[rig]\n", "[rig]\nsample_rate = 100.0\n", "[simulation]"),
        ("seed under [simulation]", mm, "[simulation]\n", "[simulation]\nseed = 1\n", "[scenario]"),
        ("rms_percent under [simulation]", mm, "[simulation]\n", "[simulation]\nrms_percent = 1.0\n",
         "[noise]"),
        ("Km under [simulation]", mm, "[simulation]\n", "[simulation]\nKm = 0.3\n", "[rig]"),
        ("duration under [rig]", mm, "[rig]\n", "[rig]\nduration = 4.0\n", "[simulation]"),
        ("derivatives under [noise]", mm, "[noise]\n", '[noise]\nderivatives = "recorded"\n', "[signal]"),
        ("beam sample_rate under [rig]", beam, "[rig]\n", "[rig]\nsample_rate = 12800.0\n", "[simulation]"),
        # given twice
        ("Km twice", mm, "Km = 0.3\n", "Km = 0.3\nKm = 0.4\n", "'rig.Km'"),
        ("duration twice", mm, "duration = 4.0\n", "duration = 4.0\nduration = 4.0\n",
         "'simulation.duration'"),
        ("seed twice at the end", mm, "seed = 0\n", "seed = 0\nseed = 1\n", "'scenario.seed'"),
    ]
    return [(f"tomlnear {label}", case(label, base, old, new, named))
            for label, base, old, new, named in cases]


# ------------------------------------------------------------------ crossparam


def crossparam_cases(work: Path) -> list[tuple[str, object]]:
    """``testbed identify --param`` with a hyperparameter another identifier declares: one
    refusal line naming that identifier (and the key meant where one is spelt alike)."""
    from testbed.pipeline.plugins import IDENTIFIERS

    records = {"dynamical": MM, "structural": BEAM, "mechanical": "fivebar_multisine"}
    names = IDENTIFIERS.names()
    declared = {n: set(IDENTIFIERS.get(n).declared_hyperparameters()) for n in names}
    out = []
    for method in names:
        kind = IDENTIFIERS.get(method).kind
        foreign = sorted({k for n in names if n != method for k in declared[n]} - declared[method])
        # three foreign keys an identifier (each a different owner where possible)
        picked: list[str] = []
        owners: set[str] = set()
        for key in foreign:
            owner = next(n for n in names if key in declared[n] and n != method)
            if owner not in owners:
                picked.append(key)
                owners.add(owner)
            if len(picked) == 3:
                break

        def case(method=method, kind=kind, key=None):
            def run():
                path = _generated(work, records[kind])
                status, out_, err = _identify(path, kind, method, "--param", f"{key}=1")
                found = judged(status, out_, err, refuse=True)
                if found:
                    return found
                homes = [n for n in names if n != method and key in declared[n]]
                return None if any(h in err for h in homes) else \
                    f"refused without naming {homes}: {err.strip()[:200]!r}"
            return run

        out += [(f"crossparam {method} --param {key}=1", case(key=key)) for key in picked]
    return out


# ------------------------------------------------------------------ cachepath


def cachepath_cases(work: Path) -> list[tuple[str, object]]:
    """``--cache`` / ``--out`` / ``-o`` paths with a trailing line end or blank, a name of 255
    and 256 bytes, a blank name: a new folder named with an invisible end is a finding."""
    import os

    cache = hostile19.CACHE

    def case(option: str, name: str, expect: str):
        def run():
            d = work / f"c{abs(hash((option, name))) % 10**8}"
            d.mkdir(exist_ok=True)
            before = set(os.listdir(d))
            if option == "--cache":
                argv = ["generate", MM, "-o", str(d / "o.h5"), "--cache", str(d / name)]
            elif option == "run --out":
                argv = ["run", MM, "--no-figures", "--cache", str(cache), "-o", str(d / name)]
            elif option == "generate -o":
                argv = ["generate", MM, "--cache", str(cache), "-o", str(d / name)]
            else:
                argv = ["sweep", str(_mini_study(work)), "--cache", str(cache), "--results",
                        str(d / name)]
            status, out_, err = cli_inprocess(argv)
            found = judged(status, out_, err, refuse=expect == "refuse")
            if found:
                return found
            made = sorted(set(os.listdir(d)) - before - {"o.h5"})
            if expect == "refuse" and made:
                return f"made {made}"
            return None
        return run

    names = [("c\n", "refuse"), ("c ", "refuse"), ("c\t", "refuse"), (" ", "refuse"),
             ("c\r", "refuse"), ("a" * 255, "ok"), ("b" * 256, "refuse"), ("c\u00a0", "refuse"),
             ("c d", "ok")]
    out = [(f"cachepath --cache {n!r:.40}", case("--cache", n, e)) for n, e in names]
    out += [(f"cachepath run --out {n!r:.40}", case("run --out", n, e)) for n, e in names[:5]]
    out += [(f"cachepath generate -o {n!r:.40}", case("generate -o", n + ".h5" if e == "ok" else n, e))
            for n, e in names[:5]]
    out += [(f"cachepath sweep --results {n!r:.40}", case("sweep", n, e)) for n, e in names[:2]]
    return out


def _mini_study(work: Path) -> Path:
    """A study of the kinetics scenario: 1 noise level x 2 seeds x 1 identifier."""
    path = work / "h23mini.toml"
    if not path.exists():
        path.write_text('[study]\nname = "h23mini"\nscenarios = ["michaelis_menten"]\nnoise = [1.0]\n'
                        'seeds = [0, 1]\nidentifiers = ["sindy_pi_dynamical"]\n')
    return path


# ------------------------------------------------------------------ runrace


def _left_in_session(sid: int) -> list[str]:
    """Processes of the session ``sid`` still there within 5 s, but zombies whose parent is
    init (round 21's rule: init reaps them)."""
    import subprocess
    import time

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


def _temporaries(folder: Path) -> list[str]:
    return [str(p.relative_to(folder)) for p in folder.rglob("*")
            if p.is_file() and (".tmp" in p.name or p.name.startswith((".", "tmp")))
            and p.name not in (".lock", ".runs.lock")]  # the stores' flock files, kept by design


def _start(argv: list[str], cwd: Path):
    import subprocess

    return subprocess.Popen([sys.executable, "-m", "testbed.cli", *argv], cwd=cwd, env=_hostile.ENV,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)


def runrace_cases(work: Path) -> list[tuple[str, object]]:
    """Two commands started together writing one place: ``run`` into one runs folder and one
    fresh cache, ``generate -o`` one file, ``export -o`` one file, ``identify -o`` one model.
    Each must end in its verdict (or one refusal line), the place whole: every run listed,
    the dataset verified, no temporary left."""
    import time

    def case(what: str, stagger: float):
        def run():
            d = work / f"{what}_{stagger}"
            shutil.rmtree(d, ignore_errors=True)
            d.mkdir()
            if what == "run":
                argv = ["run", MM, "--no-figures", "-o", str(d / "runs"), "--cache", str(d / "cache")]
            elif what == "generate":
                argv = ["generate", MM, "-o", str(d / "same.h5"), "--cache", str(d / "cache")]
            elif what == "export":
                argv = ["export", str(_generated(work, BEAM)), "--format", "uff", "-o", str(d / "same.uff")]
            else:
                argv = ["identify", str(_generated(work, MM)), "--kind", "dynamical", "--method",
                        "sindy_pi_dynamical", "-o", str(d / "same.model.json")]
            procs = []
            for _ in range(2):
                procs.append(_start(argv, d))
                time.sleep(stagger)
            errs = []
            for p in procs:
                try:
                    _, err = p.communicate(timeout=TIMEOUT_S)
                except Exception:
                    p.kill()
                    return "hang"
                errs.append((p.returncode, err))
            for code, err in errs:
                lines = [ln for ln in err.splitlines() if ln.strip()]
                if "Traceback" in err or "internal error" in err or code not in (0, 1, 2):
                    return f"status {code}: {(lines or [''])[-1][:200]}"
                if code == 2 and len(lines) != 1:
                    return f"refused in {len(lines)} lines: {err[:200]!r}"
            if all(code == 2 for code, _ in errs):
                return f"both refused: {errs[0][1][:160]!r}"
            temps = _temporaries(d)
            if temps:
                return f"temporary files left: {temps[:4]}"
            if what in ("run", "generate"):
                from testbed.core.dataset import Dataset

                for h5 in (d / "cache").glob("*.h5"):
                    Dataset.load(h5)  # verified: raises if torn
            if what == "generate":
                from testbed.core.dataset import Dataset

                Dataset.load(d / "same.h5")
            if what == "identify":
                json.loads((d / "same.model.json").read_text())
            if what == "run":
                status, out_, err = cli_inprocess(["runs", "ls", "--out", str(d / "runs")])
                ok = sum(code == 0 or code == 1 for code, _ in errs)
                listed = sum(1 for ln in out_.splitlines() if MM in ln)
                if status != 0 or listed < ok:
                    return f"runs ls lists {listed} run(s) of {ok} finished (status {status}: {err[:120]!r})"
            return None
        return run

    def clear_during_run(delay: float):
        """``cache clear`` while ``run`` simulates the beam into that cache: the run must end
        in its verdict, the cache hold only entries that verify, no temporary left."""
        def run():
            d = work / f"clear_{delay}"
            shutil.rmtree(d, ignore_errors=True)
            d.mkdir()
            p = _start(["run", BEAM, "--no-figures", "-o", str(d / "runs"), "--cache", str(d / "cache")], d)
            time.sleep(delay)
            status, _, err = cli_inprocess(["cache", "clear", "--cache", str(d / "cache")])
            found = judged(status, "", err)
            try:
                out_, err_ = p.communicate(timeout=TIMEOUT_S)
            except Exception:
                p.kill()
                return "hang"
            if found:
                return f"cache clear: {found}"
            if p.returncode not in (0, 1) or "run written to" not in out_:
                return f"run: status {p.returncode} without its verdict: {err_[-160:]!r}"
            temps = _temporaries(d)
            if temps:
                return f"temporary files left: {temps[:4]}"
            from testbed.core.dataset import Dataset

            for h5 in (d / "cache").glob("*.h5"):
                Dataset.load(h5)
            return None
        return run

    return [(f"runrace two {what} at once ({stagger} s apart)", case(what, stagger))
            for what in ("run", "generate", "export", "identify") for stagger in (0.0, 0.3)] + \
        [(f"runrace cache clear {delay} s into a simulating run", clear_during_run(delay))
         for delay in (1.0, 2.5, 4.0)]


# ------------------------------------------------------------------ sigwrite


def sigwrite_cases(work: Path) -> list[tuple[str, object]]:
    """SIGINT / SIGTERM into ``generate`` (simulating the beam into a fresh cache) and ``sweep``
    (--jobs 1 and 2, a fresh cache and results file) at 0.8-4 s, then the command again: a
    process left in its session, a traceback, more than one error line, a temporary file
    left, a partial output that does not verify, or a second command that does not finish
    the grid, is a finding."""
    import contextlib
    import os
    import signal
    import subprocess
    import time

    def case(what: str, sig: int, delay: float):
        def run():
            d = work / f"{what}_{signal.Signals(sig).name}_{delay}"
            shutil.rmtree(d, ignore_errors=True)
            d.mkdir()
            if what == "generate":
                argv = ["generate", BEAM, "-o", str(d / "beam.h5"), "--cache", str(d / "cache")]
            elif what == "identify":
                argv = ["identify", str(_generated(work, BEAM)), "--kind", "structural", "--method",
                        "sgd_sindy", "-o", str(d / "model.json")]
            elif what == "report":
                argv = ["report", str(_swept(work)), "-o", str(d / "rep")]
            else:
                jobs = what.split("-")[1]
                argv = ["sweep", str(_mini_study(work)), "--jobs", jobs, "--cache", str(d / "cache"),
                        "--results", str(d / "res.parquet")]
            p = _start(argv, d)
            time.sleep(delay)
            p.send_signal(sig)
            try:
                _, err = p.communicate(timeout=90)
            except subprocess.TimeoutExpired:
                os.killpg(p.pid, signal.SIGKILL)
                p.communicate()
                return f"still running 90 s after {signal.Signals(sig).name}"
            time.sleep(0.5)
            left = _left_in_session(p.pid)
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
            if len([ln for ln in lines if ln.startswith("error")]) > 1:
                return f"interrupted in {len(lines)} lines: {err[:200]!r}"
            temps = _temporaries(d)
            if temps:
                return f"temporary files left: {temps[:4]}"
            from testbed.core.dataset import Dataset

            for h5 in [*(d / "cache").glob("*.h5"), *d.glob("*.h5")]:
                try:
                    Dataset.load(h5)
                except Exception as e:
                    return f"a partial file left: {h5.name}: {str(e)[:120]}"
            torn = _torn_outputs(d)
            if torn:
                return f"partial outputs left: {torn[:4]}"
            again = _hostile.testbed_cli(argv, d, TIMEOUT_S)
            found = _hostile.cli_finding(again)
            if found:
                return f"again: {found}"
            if again.returncode not in (0, 1):
                return f"again: status {again.returncode}: {again.stderr[-160:]!r}"
            if what.startswith("sweep"):
                status, out_, err_ = cli_inprocess(["summary", str(d / "res.parquet")])
                if status != 0 or "2 cells from" not in out_:  # the grid: 1 noise x 2 seeds
                    return f"summary after the resumed sweep: status {status} {err_[:120]!r}"
            return None
        return run

    return [(f"sigwrite {what} {signal.Signals(sig).name} at {delay} s", case(what, sig, delay))
            for what, delays in (("generate", (0.8, 2.0, 4.0)), ("sweep-1", (0.8, 2.0, 4.0)),
                                 ("sweep-2", (0.8, 2.0, 4.0)), ("identify", (1.5, 3.0)),
                                 ("report", (0.8, 1.5)))
            for sig in (signal.SIGINT, signal.SIGTERM) for delay in delays]


def _swept(work: Path) -> Path:
    """The results file of :func:`_mini_study` (swept once, on the shared cache)."""
    path = work / "h23mini.parquet"
    if not path.exists():
        status, _, err = cli_inprocess(["sweep", str(_mini_study(work)), "--cache", str(hostile19.CACHE),
                                        "--results", str(path)])
        if status not in (0, 1):
            raise RuntimeError(f"sweep: {err[-300:]}")
    return path


def _torn_outputs(folder: Path) -> list[str]:
    """Files under ``folder`` a reader would take for whole that are not: empty files, a JSON
    model that does not parse, a PNG without its signature, an HTML page without its end."""
    torn = []
    for p in folder.rglob("*"):
        if not p.is_file() or p.name in (".lock", ".runs.lock"):
            continue
        data = p.read_bytes()
        if not data or (p.suffix == ".png" and not data.startswith(b"\x89PNG")) \
                or (p.suffix == ".html" and b"</html>" not in data[-200:]):
            torn.append(str(p.relative_to(folder)))
        elif p.suffix == ".json":
            try:
                json.loads(data)
            except ValueError:
                torn.append(str(p.relative_to(folder)))
    return torn


# ------------------------------------------------------------------ main

FAMILIES = _hostile.families(
    {
        "sepmix": sepmix_cases,
        "h5consist": h5consist_cases,
        "tomlnear": tomlnear_cases,
        "crossparam": crossparam_cases,
        "cachepath": cachepath_cases,
        "runrace": runrace_cases,
        "sigwrite": sigwrite_cases,
    },
    TIMEOUT_S,
)


def main(argv: list[str]) -> int:
    return _hostile.main(argv, FAMILIES, "hostile23-")


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
