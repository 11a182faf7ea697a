"""Eighteenth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile18 [family ...]      # all families when none is named

Families (what rounds 1-17 did not try):

``conflicts``
    A cantilever scenario with two settings each valid alone that contradict each other, and
    settings at the exact edge of what is allowed, run and scored with ``ls_sindy``: the hammer
    at the record's first sample, one sample in, at the chain's edge span and one past it; the
    low-pass ``"auto"`` at a sample rate where the rule's cut-off passes Nyquist; a low-pass one
    ulp below Nyquist; a high-pass one ulp below the low-pass; two sensors at one position or
    1 um apart; more sensors than segments (fewer modes than sensors); sensors unsorted; the
    hammer 1 mm and 1.000001 mm from its sensor; a pulse ending on the record's last sample or
    one before; ``free_margin_s`` one sample shorter than the record; a pulse exactly one
    sample period long; a record exactly as long as the low-pass needs, and one sample
    shorter.  A traceback, an internal error, a refusal in more than one line, a pass with
    NaN, or a record on which the truth's own reduced model scores TRAC below 0.90, is a
    finding.
``h5links``
    A dataset file (``testbed generate``) whose measured array is an HDF5 external link to
    another file (there, missing, or a link loop), a virtual dataset over another file, external
    raw storage, stored compressed by LZF, scale-offset, gzip with shuffle and fletcher32, or by
    a filter this installation has no plugin for (a shuffle filter's id patched to Blosc's), or
    its channel rows transposed (samples x channels): ``testbed identify`` and ``export``.  A
    traceback, an internal error, a refusal in more than one line or naming no filter, or a
    record whose data live in another file accepted, is a finding.
``studies``
    Study files whose cells collide on what they write: one scenario by name and by a copy
    under another folder with the same stem, two scenarios of one stem, two identifier tables
    differing only in case; a sweep resumed after its study file changed (a noise level added,
    an identifier's parameter changed, a scenario's file edited).  A traceback, rows of the old
    study kept as the new one's, or rows of two cells under one key, is a finding.
``store``
    ``testbed runs`` and ``report`` on run folders of older or unknown store formats: format
    missing, ``/0``, ``/3``, a number, a list; a ``/1`` run with extra keys, with its scores as
    text, a run folder holding a ``run.json`` that is a list: a traceback, an internal error or
    an edit shown as the run's own is a finding.
``api``
    The public Python API with keyword typos, paths as ``str``, ``Path`` and ``bytes``, seeds as
    numpy integers and floats, a noise level as a numpy scalar, tags as a list, an identifier
    given a measurement of another kind (a five-bar's to ``ls_sindy``, a beam's to
    ``sindy_pi_dynamical``), ``measure`` of a dataset with the kind of another rig.  A raw
    exception from inside, or a wrong kind fitted in silence, is a finding.

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import copy
import json
import math
import shutil
import sys
from pathlib import Path
from typing import Any

import numpy as np

try:
    from benchmarks import _hostile
except ImportError:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks import _hostile

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 180
#: The paper's TRAC bar: a linear beam hit at its tip sensor whose truth's own reduced model
#: scores below it on the chain's signals is a record the chain spoiled (round 17's hammer at
#: the first sample: 0.45).
TRUTH_TRAC_MIN = 0.90
#: The shipped dataset cache: most cases simulate nothing new.
CACHE = ROOT / ".cache" / "datasets"


#: ``testbed argv`` in this process: (status, stdout, stderr).
cli_inprocess = _hostile.cli_inprocess


judged = _hostile.judged


# ------------------------------------------------------------------ conflicts

def _beam(**changes: Any) -> dict:
    """The shipped stiff cantilever as a raw table, 0.25 s, ``ls_sindy``, no bars; ``changes``
    maps ``"table.key"`` to a value."""
    _, raw = _hostile.base_scenario({"structural": ("cantilever_stiff_impact", 0.25)}, "structural")
    raw = copy.deepcopy(raw)
    raw["identify"] = {"method": "ls_sindy"}
    raw["scenario"]["name"] = "h18_beam"
    for dotted, value in changes.items():
        table, key = dotted.split(".")
        raw.setdefault(table, {})[key] = value
    return raw


def _scored(raw: dict) -> str | None:
    from testbed.pipeline.scenario import scenario_from_dict
    from testbed.scoring.run import run_scenario

    sc = scenario_from_dict(raw, file="h18.toml", stem="h18_beam")
    result = run_scenario(sc)
    floor = result.scores.details.get("truth_trac")
    if floor is not None and np.nanmin(floor) < TRUTH_TRAC_MIN:
        # the record and its chain, not a model: the truth's own reduced model fails the bar
        return f"the truth's own reduced model scores TRAC {np.nanmin(floor):.3g} on this record"
    return _hostile.scored_finding(result)


def conflicts_cases(work: Path) -> list[tuple[str, object]]:
    fs = 12800.0
    dt = 1.0 / fs
    length = 0.3175
    third = length / 3
    cases: dict[str, dict] = {
        "hammer at sample 0": {"excitation.start": 0.0},
        "hammer at sample 1": {"excitation.start": dt},
        "hammer at the span (21 samples, no low-pass)": {"excitation.start": 21 * dt},
        "hammer one past the span": {"excitation.start": 22 * dt},
        "hammer at sample 0, 2 kHz low-pass": {"excitation.start": 0.0, "signal.lowpass_hz": 2000.0},
        "low-pass auto at 2 kHz": {"simulation.sample_rate": 2000.0, "signal.lowpass_hz": "auto"},
        "low-pass auto at 1.5 kHz": {"simulation.sample_rate": 1500.0, "signal.lowpass_hz": "auto"},
        "low-pass one ulp below Nyquist": {"signal.lowpass_hz": math.nextafter(fs / 2, 0.0)},
        "high-pass one ulp below the low-pass": {"signal.lowpass_hz": 2000.0,
                                                 "signal.highpass_hz": math.nextafter(2000.0, 0.0)},
        "two sensors at one position": {"rig.sensors": [third, third, length]},
        "two sensors 1 um apart": {"rig.sensors": [third, third + 1e-6, length]},
        "sensors unsorted": {"rig.sensors": [length, third, 2 * third]},
        "three sensors on two segments": {"rig.n_segments": 2},
        "four sensors on three segments": {"rig.n_segments": 3,
                                           "rig.sensors": [0.1, 0.15, 0.25, length]},
        "hammer 1 mm from its sensor": {"excitation.location": length - 1e-3},
        "hammer 1.000001 mm from its sensor": {"excitation.location": length - 1.000001e-3},
        "pulse ending on the last sample": {"excitation.start": 0.25 - 3e-4 - dt},
        "pulse ending one sample before the last": {"excitation.start": 0.25 - 3e-4 - 2 * dt},
        "free margin one sample short of the record": {"signal.free_margin_s": 0.25 - dt},
        "pulse one sample period long": {"excitation.pulse_duration": dt,
                                         "excitation.start": 64 * dt},
        "record as long as the low-pass needs": {"simulation.duration": 28 * dt,
                                                 "signal.lowpass_hz": 2000.0,
                                                 "excitation.start": 2 * dt},
        "record one sample shorter": {"simulation.duration": 27 * dt,
                                      "signal.lowpass_hz": 2000.0, "excitation.start": 2 * dt},
        "hammer on the first hinge": {"rig.sensors": [length / 30, 2 * third, length],
                                      "excitation.location": length / 30},
    }
    return [(f"conflicts {label}", lambda ch=ch: _scored(_beam(**ch))) for label, ch in cases.items()]


# ------------------------------------------------------------------ h5links

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


def _h5_link_edits(work: Path):
    """name -> (edit of an open h5py file given the signal's path, must be refused)."""
    import h5py

    def moved(f, name):
        """The signal's array and attributes; the array removed from the file."""
        d = f[name]
        attrs, data = dict(d.attrs), d[()]
        del f[name]
        return attrs, data

    def external(target: str | None, loop: bool = False):
        def edit(f, name):
            attrs, data = moved(f, name)
            other = work / f"other_{abs(hash((target, loop))) % 10**6}.h5"
            with h5py.File(other, "w") as g:
                if loop:
                    g[name] = h5py.ExternalLink(str(Path(f.filename).resolve()), name)
                else:
                    g.create_dataset(name, data=data)
                    for k, v in attrs.items():
                        g[name].attrs[k] = v
            f[name] = h5py.ExternalLink(str(other) if target is None else target, name)
        return edit

    def virtual(f, name):
        attrs, data = moved(f, name)
        other = work / "virtual_source.h5"
        with h5py.File(other, "w") as g:
            g.create_dataset("src", data=data)
        layout = h5py.VirtualLayout(shape=data.shape, dtype=data.dtype)
        layout[:] = h5py.VirtualSource(str(other), "src", shape=data.shape)
        v = f.create_virtual_dataset(name, layout)
        for k, val in attrs.items():
            v.attrs[k] = val

    def raw_external(f, name):
        attrs, data = moved(f, name)
        other = work / "raw_external.bin"
        other.write_bytes(np.ascontiguousarray(data, dtype="<f8").tobytes())
        d = f.create_dataset(name, shape=data.shape, dtype="<f8",
                             external=[(str(other), 0, data.size * 8)])
        for k, v in attrs.items():
            d.attrs[k] = v

    def stored(**kwargs):
        def edit(f, name):
            attrs, data = moved(f, name)
            d = f.create_dataset(name, data=data, **kwargs)
            for k, v in attrs.items():
                d.attrs[k] = v
        return edit

    def transposed(f, name):
        attrs, data = moved(f, name)
        d = f.create_dataset(name, data=data.T)
        for k, v in attrs.items():
            d.attrs[k] = v

    return {"external link to a copy": (external(None), True),
            "external link to a missing file": (external("/nonexistent/h18.h5"), True),
            "external link loop": (external(None, loop=True), True),
            "virtual dataset over another file": (virtual, True),
            "external raw storage in another file": (raw_external, True),
            "compressed by LZF": (stored(compression="lzf", chunks=True), False),
            "scale-offset filter": (stored(scaleoffset=10, chunks=True), False),
            "gzip and shuffle and fletcher32": (stored(compression="gzip", shuffle=True,
                                                       fletcher32=True, chunks=True), False),
            "rows transposed (samples x channels)": (transposed, True)}


def h5links_cases(work: Path) -> list[tuple[str, object]]:
    import h5py

    def case(scenario: str, signal: str, kind: str, method: str, label: str, edit, refuse: bool):
        def run() -> str | None:
            src = _generated(work, scenario)
            path = work / f"{scenario}_{label.replace(' ', '_')}.h5"
            shutil.copy(src, path)
            with h5py.File(path, "r+") as f:
                edit(f, f"measured/{signal}")
            _rehash(path)
            found = judged(*cli_inprocess(["identify", str(path), "--kind", kind, "--method",
                                           method, "-o", f"{path}.model.json"]), refuse=refuse)
            if found:
                return f"identify: {found}"
            found = judged(*cli_inprocess(["export", str(path), "--format", "sep005", "-o", f"{path}.json"]),
                           refuse=refuse)
            return f"export: {found}" if found else None
        return run

    def unknown_filter():
        """``measured/x`` shuffled, the filter's id patched to 32001 (Blosc, no plugin here)."""
        src = _generated(work, "michaelis_menten")
        path = work / "michaelis_menten_unknown_filter.h5"
        shutil.copy(src, path)
        with h5py.File(path, "r+", libver="earliest") as f:
            d = f["measured/x"]
            attrs, data = dict(d.attrs), d[()]
            del f["measured/x"]
            new = f.create_dataset("measured/x", data=data, chunks=True, shuffle=True)
            for k, v in attrs.items():
                new.attrs[k] = v
        raw = bytearray(path.read_bytes())
        at = raw.find(b"shuffle")
        raw[at - 8:at - 6] = (32001).to_bytes(2, "little")
        path.write_bytes(bytes(raw))
        status, out, err = cli_inprocess(["identify", str(path), "--kind", "dynamical", "--method",
                                          "sindy_pi_dynamical", "-o", f"{path}.model.json"])
        found = judged(status, out, err, refuse=True)
        if found is None and "32001" not in err:
            return f"refused without naming the filter: {err.strip()[:200]}"
        return found

    cases = [("h5links michaelis_menten compressed by a filter without a plugin", unknown_filter)]
    for label, (edit, refuse) in _h5_link_edits(work).items():
        cases.append((f"h5links michaelis_menten {label}",
                      case("michaelis_menten", "x", "dynamical", "sindy_pi_dynamical", label, edit,
                           refuse)))
    return cases


# ------------------------------------------------------------------ store

def store_cases(work: Path) -> list[tuple[str, object]]:
    def case(label: str, edit, must_refuse: bool):
        def run() -> str | None:
            from testbed.studies.runstore import list_runs, load_run, save_new_run

            sys.path.insert(0, str(ROOT / "tests" / "testbed"))
            import _synthetic_runs

            out = work / f"runs_{abs(hash(label)) % 10**8}"
            if out.exists():
                shutil.rmtree(out)
            saved = save_new_run(_synthetic_runs.structural_result(n_samples=200), out)
            path = saved / "run.json"
            meta = json.loads(path.read_text())
            new = edit(meta)
            path.write_text(new if isinstance(new, str) else json.dumps(new, indent=2))
            for argv in (["runs", "ls", "--out", str(out)], ["report", str(saved), "-o",
                                                        str(work / f"rep_{out.name}.html")]):
                found = judged(*cli_inprocess(argv))
                if found:
                    return f"{argv[0]}: {found}"
            try:
                listed = list_runs(out)
                load_run(saved)
                loaded = True
            except ValueError:
                loaded = False
            except Exception as e:
                return f"load_run: {type(e).__name__}: {str(e)[:160]}"
            if must_refuse and (listed or loaded):
                return "an edited or foreign run was listed or read as a run"
            return None
        return run

    def fmt(value):
        def f(meta):
            meta["format"] = value
            return meta
        return f

    def drop_format(meta):
        meta.pop("format")
        return meta

    def as_v1(change):
        def f(meta):
            meta["format"] = "sysid-testbed-run/1"
            meta.pop("sha256", None)
            meta.pop("npz_sha256", None)
            change(meta)
            return meta
        return f

    def scores_text(meta):
        meta["scores"] = {k: str(v) for k, v in meta["scores"].items()}

    def scores_list(meta):
        meta["scores"] = list(meta["scores"].values())

    def extra_key(meta):
        meta["sha512"] = "0" * 128

    def passed_text(meta):
        meta["passed"] = "yes"

    def thresholds_nan(meta):
        meta["thresholds"] = {"trac": {"min": "NaN"}}

    return [(f"store {label}", case(label, edit, refuse)) for label, edit, refuse in [
        ("format missing", drop_format, True),
        ("format /0", fmt("sysid-testbed-run/0"), True),
        ("format /3", fmt("sysid-testbed-run/3"), True),
        ("format a number", fmt(2), True),
        ("format a list", fmt(["sysid-testbed-run/2"]), True),
        ("format in upper case", fmt("SYSID-TESTBED-RUN/2"), True),
        ("run.json a list", lambda meta: json.dumps([meta]), True),
        ("/1 with scores as text", as_v1(scores_text), False),
        ("/1 with scores as a list", as_v1(scores_list), False),
        ("/1 with a sha512 key", as_v1(extra_key), False),
        ("/1 with passed as text", as_v1(passed_text), False),
        ("/1 with a threshold as text", as_v1(thresholds_nan), False),
    ]]


# ------------------------------------------------------------------ studies

def _write(path: Path, text: str) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def studies_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.scenario import SCENARIO_DIR

    mm = SCENARIO_DIR / "michaelis_menten.toml"

    def study(folder: Path, scenarios: list[str], noise="[0.0]", extra: str = "") -> Path:
        return _write(folder / "h18.toml",
                      "[study]\nname = \"h18\"\nscenarios = [" +
                      ", ".join(json.dumps(s) for s in scenarios) +
                      f"]\nnoise = {noise}\nseeds = [0]\nidentifiers = [\"sindy_pi_dynamical\"]\n"
                      + extra)

    def sweep(folder: Path, refuse: bool = False) -> str | None:
        status, out, err = cli_inprocess(["sweep", str(folder / "h18.toml"), "--results",
                                          str(folder / "results.parquet"), "--cache", str(CACHE)])
        found = judged(status, out, err, refuse=refuse)
        if found is None and status == 2 and not refuse:
            return f"a valid study refused: {err.strip()[:200]}"
        return found

    def rows(folder: Path) -> list[dict]:
        from testbed.studies.results import read_results

        return read_results(folder / "results.parquet")

    def same_stem():
        folder = work / "same_stem"
        shutil.rmtree(folder, ignore_errors=True)
        other = _write(folder / "other" / "michaelis_menten.toml",
                       mm.read_text().replace("[rig]", "[rig]\n# a copy\n", 1))
        study(folder, ["michaelis_menten", str(other)])
        found = sweep(folder, refuse=True)  # two cells would write under one name
        if found:
            return found
        cells = [r["cell"] for r in rows(folder)] if (folder / "results.parquet").exists() else []
        if len(cells) != len(set(cells)):
            return f"two cells under one key: {cells}"
        return None

    def two_copies_same_stem():
        folder = work / "two_copies"
        shutil.rmtree(folder, ignore_errors=True)
        a = _write(folder / "a" / "mm.toml", mm.read_text().replace(
            'name = "michaelis_menten"', 'name = "mm"'))
        b = _write(folder / "b" / "mm.toml", mm.read_text().replace(
            'name = "michaelis_menten"', 'name = "mm"').replace("Vmax = 1.5", "Vmax = 2.0", 1))
        study(folder, [str(a), str(b)])
        found = sweep(folder, refuse=True)  # two cells would write under one name
        if found:
            return found
        if (folder / "results.parquet").exists():
            cells = [r["cell"] for r in rows(folder)]
            if len(cells) != len(set(cells)):
                return f"two cells under one key: {cells}"
        return None

    def resumed(change):
        def run():
            folder = work / f"resume_{change}"
            shutil.rmtree(folder, ignore_errors=True)
            scen = _write(folder / "michaelis_menten.toml", mm.read_text())
            study(folder, [str(scen)])
            found = sweep(folder)
            if found:
                return f"first sweep: {found}"
            before = rows(folder)
            if change == "noise added":
                study(folder, [str(scen)], noise="[0.0, 1.0]")
            elif change == "parameter changed":
                study(folder, [str(scen)], extra="[identifiers.sindy_pi_dynamical]\ndegree = 2\n")
            elif change == "scenario edited":
                _edit_first_number(scen, "rig")
            found = sweep(folder)
            if found:
                return f"resumed sweep: {found}"
            after = rows(folder)
            if change == "scenario edited" and after and before and \
                    after[0].get("dataset_hash") == before[0].get("dataset_hash"):
                return "a row of the scenario before its edit kept as the edited one's"
            if change == "parameter changed" and after and before and \
                    after[0].get("params") == before[0].get("params"):
                return "a row of the old parameters kept as the new study's"
            return None
        return run

    return [("studies one scenario by name and by a copy of the same stem", same_stem),
            ("studies two scenarios of one stem and name", two_copies_same_stem),
            ("studies resumed after a noise level was added", resumed("noise added")),
            ("studies resumed after a parameter changed", resumed("parameter changed")),
            ("studies resumed after the scenario was edited", resumed("scenario edited"))]


def _edit_first_number(path: Path, table: str) -> None:
    """Multiply the first number of ``[table]`` in a TOML file by 1.1."""
    import re

    lines = path.read_text().splitlines()
    inside = False
    for i, ln in enumerate(lines):
        if ln.strip().startswith("["):
            inside = ln.strip() == f"[{table}]"
            continue
        m = re.match(r"^(\s*\w+\s*=\s*)([0-9.eE+-]+)(.*)$", ln)
        if inside and m:
            lines[i] = f"{m.group(1)}{float(m.group(2)) * 1.1!r}{m.group(3)}"
            break
    path.write_text("\n".join(lines) + "\n")


# ------------------------------------------------------------------ api

def api_cases(work: Path) -> list[tuple[str, object]]:
    import testbed
    from testbed.pipeline.cache import DatasetCache
    from testbed.pipeline.scenario import SCENARIO_DIR, load_scenario
    from testbed.pipeline.signal_chain import measure
    from testbed.scoring.run import run_scenario

    cache = DatasetCache(CACHE)

    def data_of(name: str):
        sc = load_scenario(name)
        return sc, cache.get(sc)

    def fit(method: str, scenario: str):
        def run():
            sc, ds = data_of(scenario)
            m = measure(ds, sc.signal, sc.kind)
            testbed.IDENTIFIERS.get(method)().fit(m)
            return f"{method} fitted a {sc.kind} record in silence"
        return run

    def measured_as(kind: str, scenario: str):
        def run():
            sc, ds = data_of(scenario)
            measure(ds, {}, kind)
            return f"a {sc.kind} dataset measured as {kind} in silence"
        return run

    def call(fn, check=lambda r: None):
        def run():
            try:
                return check(fn())
            except TypeError as e:  # the language's own one line at the call, naming the key
                if "unexpected keyword argument" in str(e):
                    return None
                raise
        return run

    def scored(r):
        return _hostile.scored_finding(r)

    mm = load_scenario("michaelis_menten")
    return [(f"api {label}", fn) for label, fn in [
        ("ls_sindy given a five-bar's measurement", fit("ls_sindy", "fivebar_multisine")),
        ("sindy_pi_dynamical given a beam's measurement",
         fit("sindy_pi_dynamical", "cantilever_stiff_impact")),
        ("sindy_pi given a kinetics measurement", fit("sindy_pi", "michaelis_menten")),
        ("a beam measured as mechanical", measured_as("mechanical", "cantilever_stiff_impact")),
        ("a kinetics record measured as structural", measured_as("structural", "michaelis_menten")),
        ("load_scenario of a Path", call(lambda: load_scenario(SCENARIO_DIR / "michaelis_menten.toml"))),
        ("load_scenario of bytes", call(lambda: load_scenario(b"michaelis_menten"))),
        ("run_scenario with a numpy seed", call(lambda: run_scenario(mm.replace(seed=np.int64(3)),
                                                                     cache=cache), scored)),
        ("run_scenario with a float seed", call(lambda: run_scenario(mm.replace(seed=3.0),
                                                                     cache=cache), scored)),
        ("run_scenario with a numpy noise", call(lambda: run_scenario(mm.with_noise(np.float32(0.01)),
                                                                      cache=cache), scored)),
        ("run_scenario with tags a list", call(lambda: run_scenario(mm.replace(tags=["a"]),
                                                                    cache=cache), scored)),
        ("run_scenario with a keyword typo", call(lambda: run_scenario(mm, cahce=cache))),
        ("run_scenario of a scenario name", call(lambda: run_scenario("michaelis_menten"))),
        ("run_scenario of a path", call(lambda: run_scenario(SCENARIO_DIR / "michaelis_menten.toml"))),
        ("run_scenario with a cache folder as str", call(lambda: run_scenario(mm, cache=str(CACHE)))),
        ("run_scenario with a cache folder as Path", call(lambda: run_scenario(mm, cache=CACHE))),
    ]]


# ------------------------------------------------------------------ importcombo

def _lab_channels(work: Path) -> tuple[list[dict], list[str]]:
    """The shipped lab beam (3 accelerations and the force, 12.8 kHz) as SEP-005 channels, and
    the ``--prior`` arguments its export names."""
    path = _generated(work, "cantilever_stiff_impact_lab")
    out = work / "lab.sep005.json"
    status, stdout, err = cli_inprocess(["export", str(path), "--format", "sep005", "-o", str(out)])
    if status != 0:
        raise RuntimeError(f"export: {err[-300:]}")
    prior = [a for a in (stdout + err).split() if "=" in a and not a.startswith("-")]
    return json.loads(out.read_text()), [x for p in prior for x in ("--prior", p)]


def importcombo_cases(work: Path) -> list[tuple[str, object]]:
    def record(label: str, edit) -> Path:
        chans, _ = _lab_channels(work)
        for c in chans:
            c.pop("content_hash", None)
        path = work / f"{''.join(c if c.isalnum() else '_' for c in label)}.json"
        path.write_text(json.dumps(edit(chans)))
        return path

    def decimated(q: int):
        def edit(chans):
            for c in chans:
                c["data"] = c["data"][::q]
                c["fs"] = c["fs"] / q
            return chans
        return edit

    def cut(first: int, last: int | None = None):
        def edit(chans):
            for c in chans:
                c["data"] = c["data"][first:last]
            return chans
        return edit

    def case(label: str, edit, extra: list[str], refuse: bool, with_prior: bool = True):
        def run():
            path = record(label, edit)
            prior = _lab_channels(work)[1] if with_prior else []
            argv = ["identify", str(path), "-o", f"{path}.model.json", *prior, *extra]
            return judged(*cli_inprocess(argv), refuse=refuse)
        return run

    start = 64  # the lab beam's hammer, 5 ms at 12.8 kHz
    same = lambda chans: chans  # noqa: E731
    lab = ["--scenario", "cantilever_stiff_impact_lab"]
    beam = ["--kind", "structural", "--method", "ls_sindy"]
    return [(f"importcombo {label}", case(label, edit, extra, refuse, *rest))
            for label, edit, extra, refuse, *rest in [
        ("lab chain on the record at 3.2 kHz (low-pass 2 kHz above Nyquist)", decimated(4), lab, True),
        ("lab chain on the record at 6.4 kHz", decimated(2), lab, False),
        ("the record cut to 30 samples (a verdict: unusable model)", cut(start, start + 30), beam,
         False),
        ("the hammer at the record's first sample", cut(start), beam, False),
        ("the hammer at the first sample, lab chain", cut(start), lab, False),
        ("the record starting inside the pulse", cut(start + 2), beam, False),
        ("the record ending inside the pulse", cut(0, start + 2), beam, True),
        ("--fs contradicting the file's rate", same, [*beam, "--fs", "10000"], True),
        ("--units g on a file that declares m/s^2", same, [*beam, "--units", "g"], True),
        ("--units g for one channel the file declares in m/s^2", same,
         [*beam, "--units", "acceleration/acc1=g"], True),
        ("--units m/s^2 for one channel, as the file says", same,
         [*beam, "--units", "acceleration/acc1=m/s^2"], False),
        ("--kind mechanical on a beam", same, ["--kind", "mechanical", "--method", "sindy_pi"],
         True, False),
        ("--scenario of a five-bar on a beam", same, ["--scenario", "fivebar_multisine"], True,
         False),
        ("--scenario and --kind disagreeing", same, [*lab, "--kind", "dynamical"], True),
        ("--method of another kind", same, ["--kind", "structural", "--method", "sindy_pi"], True),
    ]]


# ------------------------------------------------------------------ keycase

def keycase_cases(work: Path) -> list[tuple[str, object]]:
    """Scenario files whose keys or tables differ from the schema's only by case: each must be
    one refusal line naming the key (a key read case-blind would be a second value of one key;
    a key dropped in silence, a setting not applied)."""
    from testbed.pipeline.scenario import SCENARIO_DIR, load_scenario

    base = (SCENARIO_DIR / "michaelis_menten.toml").read_text()

    def case(label: str, edit):
        def run():
            folder = work / "".join(c if c.isalnum() else "_" for c in label)
            folder.mkdir(exist_ok=True)
            path = folder / "michaelis_menten.toml"
            path.write_text(edit(base))
            load_scenario(path, check_cost=False)
            return "loaded: a key differing only by case was accepted"
        return run

    return [(f"keycase {label}", case(label, edit)) for label, edit in [
        ("[Rig] beside [rig]", lambda t: t + "\n[Rig]\njx = 0.7\n"),
        ("[RIG] instead of [rig]", lambda t: t.replace("[rig]", "[RIG]", 1)),
        ("Seed beside seed", lambda t: t.replace("seed = 0", "seed = 0\nSeed = 1", 1)),
        ("Km beside km", lambda t: t.replace("\nKm = 0.3\n", "\nKm = 0.3\nkm = 0.4\n", 1)),
        ("VMAX instead of Vmax", lambda t: t.replace("\nVmax = 1.5\n", "\nVMAX = 1.5\n", 1)),
        ("[Signal] beside [signal]", lambda t: t + "\n[Signal]\nderivatives = \"estimated\"\n"),
        ("Method beside method", lambda t: t.replace('method = "sindy_pi_dynamical"',
                                                     'method = "sindy_pi_dynamical"\n'
                                                     'Method = "ls_sindy"', 1)),
        ("Degree beside degree", lambda t: t.replace("degree = 3", "degree = 3\nDegree = 2", 1)),
    ]]


# ------------------------------------------------------------------ main

FAMILIES = _hostile.families({
    "conflicts": conflicts_cases,
    "h5links": h5links_cases,
    "store": store_cases,
    "studies": studies_cases,
    "api": api_cases,
    "importcombo": importcombo_cases,
    "keycase": keycase_cases,
}, TIMEOUT_S)


def main(argv: list[str]) -> int:
    return _hostile.main(argv, FAMILIES, "hostile18-")


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
