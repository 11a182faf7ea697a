"""Twenty-sixth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile26 [family ...]      # all families when none is named

Families (what rounds 1-25 did not try; their families are listed in ``hostile21.py`` to
``hostile25.py``):

``sigarrays``
    The Python API's :class:`~testbed.core.dataset.Signal` given samples of every array kind a
    caller may hold: masked (one sample masked, and none), complex (and complex with no
    imaginary part), boolean, object, text, datetime, structured, float16, big-endian, Fortran
    order, a strided view, read-only, 0-d, empty, 3-D, a list of lists; ``channels`` one text,
    ``unit`` a number or bytes, ``positions`` a text or complex (of another length or NaN:
    accepted, the readers that use positions name them), ``acts_on`` one text;
    then :func:`testbed.measure` of the Michaelis-Menten record built from it.  A raw exception,
    a value of the wrong kind taken in silence (a masked sample read as its value, an imaginary
    part dropped, a boolean read as 0 / 1), or an accepted layout whose measurement differs
    from the plain float64 record's, is a finding.
``measarrays``
    The API's :class:`~testbed.core.measurement.Measurement` (the Michaelis-Menten record, then
    the cart-pole's) with ``x`` / ``xd`` / ``u`` of the same kinds; every accepted layout fitted
    (``sindy_pi_dynamical``, ``sindy_pi``) must give the plain record's model; and the fit given
    read-only arrays, and the caller's arrays compared before and after the fit.  A raw
    exception, a model that differs for the same numbers, or a caller's array changed by a fit,
    is a finding.
``simargs``
    A fitted model's ``simulate`` (``sindy_pi_dynamical`` on the kinetics, ``sindy_pi`` on the
    cart-pole, ``ls_sindy`` on the stiff beam) given ``x0`` and ``t`` of those kinds, and ``t``
    reversed, with a repeated time, non-monotonic, 2-D, starting at -1 s (accepted), of
    integers (accepted).  A raw exception,
    a non-finite trajectory returned, or a time grid that is no grid taken, is a finding.
``tomlvals``
    Every scalar key of four shipped scenarios (one per rig) given each value of one table: a
    text, an empty text, Unicode, a boolean, NaN, +inf, -inf, 1e308, 5e-324, -1, 0, an empty
    array, a table: :func:`~testbed.pipeline.scenario.scenario_from_dict`.  A raw exception, a
    refusal in more than one line or not naming the key, or a value of the wrong type (a text,
    a boolean, an array or a table where a number is; NaN or inf anywhere) accepted, is a
    finding.
``studyvals``
    The same table for every key of a study file's ``[study]`` table and its identifier
    tables, and grids of 10**7 cells: :func:`~testbed.studies.study.study_from_dict`.  The same
    rule.
``textenc``
    The Michaelis-Menten record as CSV in encodings and text forms rounds 19-21 did not try:
    UTF-16 with its byte-order mark, UTF-32, old Mac line ends (CR only), a DOS end-of-file
    (Ctrl-Z), a form feed or a line separator (U+2028) inside a row, a Latin-1 unit, a unit
    nobody knows, numbers with digit underscores, in Arabic-Indic or full-width digits; the
    SEP-005 export as UTF-16, with CRLF and with a key in full-width letters; the stiff beam's
    UFF export rewritten in ASCII UFF58 with CRLF, CR, a BOM, a BOM and CRLF.  ``testbed
    identify``.  A traceback, anything but one refusal line, or a file read to another model
    than the clean one's (numbers of another script read as ours included), is a finding.

``dssave``
    :meth:`~testbed.core.dataset.Dataset.save` of a dataset built by hand (the Python API's way
    to store a record), then :meth:`~testbed.core.dataset.Dataset.load`: ``attrs`` holding a
    set, bytes, 10**400, a key of the file's own (``format``, ``fs``), a NUL; a prior of a text
    or a list; a truth of a text, a ragged list, complex numbers; a signal named ``a/b``, ``""``
    or ``.``; no measured signal; ``fs`` a text, NaN, 10**400; a channel or unit holding a NUL;
    a bare array for a Signal; and the accepted forms (NaN and None attributes, a float truth, a
    list of names) round-tripped.  A raw exception, or a file written that its own load refuses
    or reads back to another content hash, is a finding.

``samefile``
    Every command's output aimed at its own input: ``export`` / ``identify`` of a dataset, a
    SEP-005 file and a CSV written over that file, ``generate`` over its scenario file, ``sweep
    --results`` over its study file, ``family write -o`` at the study file, ``report -o`` at
    the results file, ``run --out`` at the scenario file; each path as given, through
    ``dir/../``, through a symbolic link and through a hard link.  A traceback, more than one
    error line, or an input file whose bytes changed, is a finding (a hard link's name
    replaced by the new file, its input's bytes kept, is not).

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import copy
import dataclasses
import json
import math
import os
import shutil
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
CARTPOLE = "cartpole"
LAB = "cantilever_stiff_impact_lab"
LSQ = "cantilever_stiff_impact_lsq"

cli_inprocess = _hostile.cli_inprocess
judged = _hostile.judged
_generated = hostile19._generated
_safe = hostile19._safe
_model = hostile24._model
_same = hostile24._same


def _one_line_refusal(e: BaseException) -> str | None:
    """None for a one-line :class:`TestbedError`, else the finding."""
    from testbed.core.errors import TestbedError

    if not isinstance(e, TestbedError):
        return f"{type(e).__name__}: {str(e)[:200]}"
    if "\n" in str(e):
        return f"two lines: {str(e)[:200]!r}"
    return None


# ------------------------------------------------------------------ array kinds

def _kinds(np):
    """``label -> (make(a) -> array-like, expect)``: ``expect`` "refuse" or "same" (the same
    float64 numbers as ``a``)."""
    def masked(a, n):
        out = np.ma.masked_array(a, mask=False)
        if n:
            out.mask[0, 3] = True
        return out

    def readonly(a):
        a = a.copy()
        a.flags.writeable = False
        return a

    def strided(a):
        wide = np.zeros((a.shape[0], 2 * a.shape[1]))
        wide[:, ::2] = a
        return wide[:, ::2]

    return {
        "masked with one sample masked": (lambda a: masked(a, 1), "refuse"),
        "masked with nothing masked": (lambda a: masked(a, 0), "same"),
        "complex": (lambda a: a + 1j, "refuse"),
        "complex with no imaginary part": (lambda a: a.astype(complex), "refuse"),
        "boolean": (lambda a: a > np.median(a), "refuse"),
        "object of floats": (lambda a: a.astype(object), "refuse"),
        "text": (lambda a: a.astype(str), "refuse"),
        "datetime64": (lambda a: (a * 1e3).astype("datetime64[ms]"), "refuse"),
        "structured": (lambda a: np.zeros(a.shape, dtype=[("v", "f8")]), "refuse"),
        "float16": (lambda a: a.astype(np.float16), "widened"),
        "big-endian float64": (lambda a: a.astype(">f8"), "same"),
        "Fortran order": (lambda a: np.asfortranarray(a), "same"),
        "a strided view": (strided, "same"),
        "read-only": (readonly, "same"),
        "a list of lists": (lambda a: a.tolist(), "same"),
        "0-d": (lambda a: np.array(1.0), "refuse"),
        "empty": (lambda a: np.zeros((a.shape[0], 0)), "refuse"),
        "3-D": (lambda a: a[None], "refuse"),
    }


def _mm_dataset(work: Path, state: dict):
    if "ds" not in state:
        from testbed.core.dataset import Dataset
        from testbed.pipeline.scenario import load_scenario

        state["ds"] = Dataset.load(_generated(work, MM))
        state["sc"] = load_scenario(MM)
    return state["ds"], state["sc"]


def sigarrays_cases(work: Path) -> list[tuple[str, object]]:
    import numpy as np

    state: dict = {}

    def base():
        import testbed

        ds, sc = _mm_dataset(work, state)
        if "m" not in state:
            state["m"] = testbed.measure(ds, sc.signal, sc.kind)
        return ds, sc, state["m"]

    def built(**sig_change):
        """A Dataset whose signal ``x`` is built with ``sig_change`` (``data`` a maker)."""
        from testbed.core.dataset import Dataset, Signal

        ds, _, _ = base()
        x = ds.measured["x"]
        kw = {"data": x.data, "channels": x.channels, "unit": x.unit, "positions": x.positions,
              "acts_on": x.acts_on}
        for k, v in sig_change.items():
            kw[k] = v(x.data) if k == "data" else v
        return Dataset(ds.fs, {**ds.measured, "x": Signal(**kw)}, prior=dict(ds.prior))

    def case(expect, **sig_change):
        def run():
            import testbed

            _, sc, clean = base()
            try:
                ds = built(**sig_change)
                m = testbed.measure(ds, sc.signal, sc.kind)
            except Exception as e:
                found = _one_line_refusal(e)
                if found:
                    return found
                return None if expect in ("refuse", "any") else f"refused: {str(e)[:200]!r}"
            if expect == "refuse":
                return f"accepted (x of dtype {ds.measured['x'].data.dtype})"
            if expect == "same" and not (np.array_equal(m.x, clean.x) and np.array_equal(m.xd, clean.xd)):
                return "measured to other numbers than the plain record"
            return None
        return run

    cases = [(f"sigarrays samples {label}", case(expect, data=make))
             for label, (make, expect) in _kinds(np).items()]
    cases += [
        ("sigarrays channels one text", case("refuse", channels="x")),
        ("sigarrays channels a list (accepted)", case("same", channels=["x"])),
        ("sigarrays channels a number", case("refuse", channels=5)),
        ("sigarrays channels None", case("refuse", channels=None)),
        ("sigarrays channels of an empty name", case("refuse", channels=("",))),
        ("sigarrays channels of a number", case("refuse", channels=(5,))),
        ("sigarrays channels two for one row", case("refuse", channels=("x", "y"))),
        ("sigarrays unit a number", case("refuse", unit=5)),
        ("sigarrays unit bytes", case("refuse", unit=b"mM")),
        ("sigarrays unit None", case("refuse", unit=None)),
        # (a count or NaN: the readers that use positions name them, round 8's words)
        ("sigarrays positions of two for one row", case("any", positions=np.zeros(2))),
        ("sigarrays positions NaN", case("any", positions=np.array([np.nan]))),
        ("sigarrays positions complex", case("refuse", positions=np.array([0.1j]))),
        ("sigarrays positions a text", case("refuse", positions="0.1")),
        ("sigarrays acts_on one text", case("refuse", acts_on="xy")),
    ]
    return cases


def measarrays_cases(work: Path) -> list[tuple[str, object]]:
    import numpy as np

    state: dict = {}

    def fitted(scenario: str):
        """(the clean Measurement, its identifier's class and params, the clean model's
        equations) of a shipped scenario, made once."""
        if scenario not in state:
            import testbed
            from testbed.core.dataset import Dataset
            from testbed.pipeline.plugins import identifier_class
            from testbed.pipeline.scenario import load_scenario

            sc = load_scenario(scenario)
            m = testbed.measure(Dataset.load(_generated(work, scenario)), sc.signal, sc.kind)
            cfg = dict(sc.identify)
            cls = identifier_class(cfg.pop("method"))
            state[scenario] = (m, cls, cfg, _equations(cls(**cfg).fit(m)))
        return state[scenario]

    def case(scenario: str, field: str, make, expect):
        def run():
            from testbed.core.measurement import Measurement

            m, cls, cfg, clean = fitted(scenario)
            a = getattr(m, field)
            try:
                data = dataclasses.replace(m, **{field: make(a)})
            except Exception as e:
                found = _one_line_refusal(e)
                if found:
                    return found
                return None if expect in ("refuse", "any") else f"refused: {str(e)[:200]!r}"
            assert isinstance(data, Measurement)
            if expect == "refuse":
                return f"accepted (as {getattr(data, field).dtype})"
            if expect == "same":
                if not np.array_equal(getattr(data, field), a):
                    return "read to other numbers"
                if field == "x" and _equations(cls(**cfg).fit(data)) != clean:
                    return "fitted to another model than the plain record's"
            return None
        return run

    cases = []
    for scenario, fields in ((MM, ("x", "xd")), (CARTPOLE, ("x", "u"))):
        for field in fields:
            cases += [(f"measarrays {scenario} {field} {label}", case(scenario, field, make, expect))
                      for label, (make, expect) in _kinds(np).items()]

    def frozen(scenario: str):
        def run():
            m, cls, cfg, clean = fitted(scenario)
            change = {}
            for f in ("x", "xd", "xdd", "u", "input_map", "drift_basis", "noise_std"):
                a = getattr(m, f)
                if isinstance(a, np.ndarray):
                    a = a.copy()
                    a.flags.writeable = False
                    change[f] = a
            try:
                model = cls(**cfg).fit(dataclasses.replace(m, **change))
            except Exception as e:
                return f"fit of read-only arrays: {type(e).__name__}: {str(e)[:200]}"
            return None if _equations(model) == clean else "read-only arrays fitted to another model"
        return run

    def untouched(scenario: str):
        def run():
            m, cls, cfg, _ = fitted(scenario)
            arrays = {f: getattr(m, f).copy() for f in ("x", "xd", "xdd", "u", "input_map")
                      if isinstance(getattr(m, f), np.ndarray)}
            prior = copy.deepcopy(m.prior)
            cls(**cfg).fit(m)
            changed = [f for f, a in arrays.items() if not np.array_equal(getattr(m, f), a)]
            if m.prior != prior:
                changed.append("prior")
            return f"the fit changed the caller's {changed}" if changed else None
        return run

    for scenario in (MM, CARTPOLE):
        cases += [(f"measarrays {scenario} fit of read-only arrays", frozen(scenario)),
                  (f"measarrays {scenario} the caller's arrays after a fit", untouched(scenario))]
    return cases


def _equations(model) -> str:
    """A fitted model's printed equations (its identity for 'the same model')."""
    eq = model.equations()
    return "\n".join(eq) if isinstance(eq, (list, tuple)) else str(eq)


def simargs_cases(work: Path) -> list[tuple[str, object]]:
    import numpy as np

    state: dict = {}

    def fitted(scenario: str):
        if scenario not in state:
            import testbed
            from testbed.core.dataset import Dataset
            from testbed.pipeline.plugins import identifier_class
            from testbed.pipeline.scenario import load_scenario

            sc = load_scenario(scenario)
            m = testbed.measure(Dataset.load(_generated(work, scenario)), sc.signal, sc.kind)
            cfg = dict(sc.identify)
            state[scenario] = (identifier_class(cfg.pop("method"))(**cfg).fit(m), m)
        return state[scenario]

    def call(scenario: str, x0=None, t=None, expect="refuse"):
        def run():
            model, m = fitted(scenario)
            n = m.n_channels
            tt = np.arange(20) / m.fs if t is None else t(m)
            xx = m.x[:, 0].copy() if x0 is None else x0(m.x[:, 0].copy())
            nt = np.size(tt) if np.ndim(tt) == 1 else 20
            u = None if m.u is None else np.zeros((m.u.shape[0], nt))
            xd = None if scenario == MM else np.zeros(n)  # (a dynamical model has no rates)
            try:
                out = model.simulate(xx, xd, tt, u)
            except Exception as e:
                found = _one_line_refusal(e)
                if found:
                    return found
                return None if expect in ("refuse", "any") else f"refused: {str(e)[:200]!r}"
            if expect == "refuse":
                return "accepted"
            arrays = [np.asarray(a) for a in (out if isinstance(out, tuple) else (out,))]
            if not all(np.all(np.isfinite(a)) for a in arrays if a.dtype.kind in "fc"):
                return "a non-finite trajectory returned"
            return None
        return run

    cases = []
    for scenario in (MM, CARTPOLE, LSQ):
        x0s = {
            "x0 of integers (accepted)": (lambda x: np.round(x).astype(int), "any"),
            "x0 a list (accepted)": (lambda x: x.tolist(), "any"),
            "x0 read-only (accepted)": (lambda x: _ro(x), "any"),
            "x0 boolean": (lambda x: x > 0, "refuse"),
            "x0 complex": (lambda x: x + 1j, "refuse"),
            "x0 masked": (lambda x: np.ma.masked_array(x, mask=np.ones_like(x, bool)), "refuse"),
            "x0 0-d": (lambda x: np.array(x[0]) if x.size > 1 else np.array([[x[0]]]), "refuse"),
            "x0 a text": (lambda x: "0.1", "refuse"),
            "x0 NaN": (lambda x: np.full_like(x, np.nan), "refuse"),
        }
        ts = {
            "t reversed": (lambda m: np.arange(20)[::-1] / m.fs, "refuse"),
            "t with a repeated time": (lambda m: np.r_[0.0, 0.0, np.arange(1, 19) / m.fs], "refuse"),
            "t non-monotonic": (lambda m: np.r_[np.arange(10), np.arange(5, 15)] / m.fs, "refuse"),
            "t 2-D": (lambda m: (np.arange(20) / m.fs)[None], "refuse"),
            "t boolean": (lambda m: np.arange(20) % 2 == 0, "refuse"),
            "t complex": (lambda m: np.arange(20) / m.fs + 0j, "refuse"),
            "t NaN at the end": (lambda m: np.r_[np.arange(19) / m.fs, np.nan], "refuse"),
            "t masked": (lambda m: np.ma.masked_array(np.arange(20) / m.fs,
                                                      mask=np.arange(20) == 5), "refuse"),
            "t starting at -1 s (accepted)": (lambda m: -1 + np.arange(20) / m.fs, "any"),
            "t of integers (accepted)": (lambda m: np.arange(20), "any"),
            "t empty": (lambda m: np.zeros(0), "refuse"),
        }
        cases += [(f"simargs {scenario} {label}", call(scenario, x0=make, expect=expect))
                  for label, (make, expect) in x0s.items()]
        cases += [(f"simargs {scenario} {label}", call(scenario, t=make, expect=expect))
                  for label, (make, expect) in ts.items()]
    return cases


def _ro(a):
    a = a.copy()
    a.flags.writeable = False
    return a


# ------------------------------------------------------------------ tomlvals / studyvals

#: The value table: label -> (value, whether a number key may take it, a text key, a boolean).
def _values() -> dict[str, object]:
    return {"a text": "abc", "an empty text": "", "unicode": "\u00fc\u2713\u540d", "true": True,
            "NaN": math.nan, "+inf": math.inf, "-inf": -math.inf, "1e308": 1e308,
            "5e-324": 5e-324, "-1": -1, "0": 0, "an empty array": [], "a table": {}}


def _scalar_keys(raw: dict, prefix: tuple = ()) -> list[tuple[tuple, object]]:
    out = []
    for k, v in raw.items():
        if isinstance(v, dict):
            out += _scalar_keys(v, (*prefix, k))
        elif not isinstance(v, list):
            out.append(((*prefix, k), v))
    return out


def _wrong_kind(old, new) -> bool:
    """Whether ``new`` is of a kind a key holding ``old`` must refuse: NaN / inf anywhere, a
    boolean where no boolean was, a text where a number was (or the reverse), an array or a
    table where a scalar was."""
    if isinstance(new, float) and not math.isfinite(new):
        return True
    if isinstance(new, (list, dict)):
        return True
    if isinstance(new, bool) != isinstance(old, bool):
        return True
    num = (int, float)
    if isinstance(old, num) and not isinstance(old, bool):
        return isinstance(new, str)
    if isinstance(old, str):
        return isinstance(new, num) and not isinstance(new, bool)
    return False


def _keygrid(work: Path, tag: str, raw: dict, load, skip=()) -> list[tuple[str, object]]:
    def case(path: tuple, old, value):
        def run():
            doc = copy.deepcopy(raw)
            node = doc
            for k in path[:-1]:
                node = node[k]
            node[path[-1]] = copy.deepcopy(value)
            try:
                load(doc)
            except Exception as e:
                found = _one_line_refusal(e)
                if found:
                    return found
                if path[-1] not in str(e):
                    return f"refused without naming {path[-1]!r}: {str(e)[:200]!r}"
                return None
            if _wrong_kind(old, value):
                return f"accepted {value!r} (the key held {old!r})"
            return None
        return run

    cases = []
    for path, old in _scalar_keys(raw):
        if ".".join(path) in skip:
            continue
        for label, value in _values().items():
            cases.append((f"{tag} {'.'.join(path)} = {label}", case(path, old, value)))
    return cases


TOML_BASES = ("michaelis_menten", "cartpole", "cantilever_stiff_impact", "fivebar_multisine")


def tomlvals_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml, scenario_from_dict

    cases = []
    for name in TOML_BASES:
        raw = _read_toml(SCENARIO_DIR / f"{name}.toml")
        raw["scenario"].pop("extends", None)

        def load(doc, name=name):
            return scenario_from_dict(doc, file=f"{name}.toml", stem=name)

        cases += _keygrid(work, f"tomlvals {name}", raw, load)
    return cases


def studyvals_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.studies.study import study_from_dict

    raw = {"study": {"name": "s", "description": "d", "scenarios": [MM], "noise": [0.0, 0.01],
                     "seeds": [0, 1], "identifiers": ["sindy_pi_dynamical"]},
           "identifiers": {"sindy_pi_dynamical": {"ridge": 1e-6}}}

    def load(doc):
        return study_from_dict(doc, file="s.toml", base=work)

    cases = _keygrid(work, "studyvals", raw, load)

    def grid(change, expect="refuse"):
        def run():
            doc = copy.deepcopy(raw)
            doc["study"].update(change)
            try:
                load(doc)
            except Exception as e:
                return _one_line_refusal(e)
            return f"accepted ({', '.join(change)})" if expect == "refuse" else None
        return run

    big = list(range(10 ** 7))
    cases += [
        ("studyvals seeds of 10**7 (a grid of 2e7 cells)", grid({"seeds": big})),
        ("studyvals noise of 10**6 levels", grid({"noise": [k * 1e-7 for k in range(10 ** 6)]})),
        ("studyvals seeds -1", grid({"seeds": [-1]})),
        ("studyvals seeds 2**64", grid({"seeds": [2 ** 64]})),
        ("studyvals seeds 1.5", grid({"seeds": [1.5]})),
        ("studyvals seeds true", grid({"seeds": [True]})),
        ("studyvals noise NaN", grid({"noise": [math.nan]})),
        ("studyvals noise -0.01", grid({"noise": [-0.01]})),
        ("studyvals noise 1e308", grid({"noise": [1e308]})),
        ("studyvals identifiers unknown", grid({"identifiers": ["nope"]})),
        ("studyvals identifiers empty", grid({"identifiers": []})),
        ("studyvals identifiers of another kind", grid({"identifiers": ["ls_sindy"]})),
        ("studyvals scenarios unknown", grid({"scenarios": ["nope"]})),
        ("studyvals scenarios empty", grid({"scenarios": []})),
    ]
    return cases


# ------------------------------------------------------------------ textenc

def textenc_cases(work: Path) -> list[tuple[str, object]]:
    import numpy as np

    from testbed.core.dataset import Dataset

    state: dict = {}

    def record():
        if "t" not in state:
            ds = Dataset.load(_generated(work, MM))
            x, dx = ds.measured["x"].data[0], ds.measured["dx"].data[0]
            state.update(t=np.arange(x.size) / ds.fs, x=x, dx=dx, xu=ds.measured["x"].unit,
                         du=ds.measured["dx"].unit)
        return state

    def num(v) -> str:
        return repr(float(v))

    def csv_text(fmt=num, xu=None, du=None, sep=",") -> list[str]:
        r = record()
        head = f"t [s]{sep}x [{xu or r['xu']}]{sep}dx [{du or r['du']}]"
        return [head] + [f"{fmt(a)}{sep}{fmt(b)}{sep}{fmt(c)}" for a, b, c in zip(r["t"], r["x"], r["dx"],
                                                                                  strict=True)]

    def identify(path: Path):
        return cli_inprocess(["identify", str(path), "--scenario", MM, "-o", f"{path}.model.json"])

    def clean(suffix: str):
        if suffix not in state:
            path = work / f"clean{suffix}"
            if suffix == ".csv":
                path.write_text("\n".join(csv_text()) + "\n")
            else:
                shutil.copy(sep_export(), path)
            found = judged(*identify(path))
            if found:
                raise RuntimeError(f"clean file: {found}")
            state[suffix] = _model(Path(f"{path}.model.json"))
        return state[suffix]

    def case(label: str, make_bytes, expect: str, suffix=".csv"):
        def run():
            path = work / f"{_safe(label)}{suffix}"
            path.write_bytes(make_bytes())
            status, out, err = identify(path)
            found = judged(status, out, err, refuse=expect == "refuse")
            if found:
                return found
            if expect == "same":
                if status == 2:
                    return f"refused an equivalent file: {err.strip()[:200]!r}"
                if not _same(_model(Path(f"{path}.model.json")), clean(suffix), 1e-9):
                    return "read to another model than the clean file's"
            return None
        return run

    def joined(lines, end="\n", enc="utf-8"):
        return lambda: (end.join(lines()) + end).encode(enc)

    arabic = str.maketrans("0123456789", "".join(chr(0x0660 + k) for k in range(10)))
    wide = str.maketrans("0123456789.-e", "".join(chr(0xFF10 + k) for k in range(10)) + "\uff0e\uff0d\uff45")

    def underscored(v):
        s = num(v)
        return s[:3] + "_" + s[3:] if len(s) > 4 and s[2].isdigit() and s[3].isdigit() else s

    table = [
        ("CSV UTF-16 with a BOM", joined(csv_text, enc="utf-16"), "any"),
        ("CSV UTF-16-LE without a BOM", joined(csv_text, enc="utf-16-le"), "refuse"),
        ("CSV UTF-32", joined(csv_text, enc="utf-32"), "any"),
        ("CSV UTF-8 BOM and CRLF (accepted)", lambda: b"\xef\xbb\xbf" + joined(csv_text, "\r\n")(),
         "same"),
        ("CSV CR line ends (accepted)", joined(csv_text, "\r"), "same"),
        ("CSV a DOS end-of-file Ctrl-Z", lambda: joined(csv_text)() + b"\x1a", "any"),
        ("CSV a form feed inside a row",
         lambda: joined(lambda: [*csv_text()[:5], csv_text()[5].replace(",", ",\x0c", 1),
                                 *csv_text()[6:]])(), "refuse"),
        ("CSV a line separator U+2028 inside a row",
         lambda: joined(lambda: [*csv_text()[:5], csv_text()[5].replace(",", "\u2028,", 1),
                                 *csv_text()[6:]])(), "refuse"),
        ("CSV a vertical tab inside a row",
         lambda: joined(lambda: [*csv_text()[:5], csv_text()[5].replace(",", "\x0b,", 1),
                                 *csv_text()[6:]])(), "refuse"),
        ("CSV a Latin-1 unit", lambda: joined(lambda: csv_text(xu="\u00b5M"), enc="latin-1")(),
         "refuse"),
        ("CSV a unit nobody knows", joined(lambda: csv_text(xu="furlong")), "refuse"),
        ("CSV units of another quantity", joined(lambda: csv_text(xu="m", du="m/s")), "any"),
        ("CSV numbers with digit underscores", joined(lambda: csv_text(fmt=underscored)), "refuse"),
        ("CSV numbers in Arabic-Indic digits",
         joined(lambda: [csv_text()[0]] + [ln.translate(arabic) for ln in csv_text()[1:]]), "refuse"),
        ("CSV numbers in full-width digits",
         joined(lambda: [csv_text()[0]] + [ln.translate(wide) for ln in csv_text()[1:]]), "refuse"),
        ("CSV one number in Arabic-Indic digits",
         joined(lambda: [*csv_text()[:7], csv_text()[7].translate(arabic), *csv_text()[8:]]),
         "refuse"),
        ("CSV a header only with CRLF", lambda: (csv_text()[0] + "\r\n").encode(), "refuse"),
        ("CSV a header and one row", joined(lambda: csv_text()[:2]), "refuse"),
        ("CSV semicolons and a BOM (accepted)",
         lambda: b"\xef\xbb\xbf" + joined(lambda: csv_text(sep=";"))(), "same"),
    ]
    cases = [(f"textenc {label}", case(label, make, expect)) for label, make, expect in table]

    def sep_export() -> Path:
        out = work / "mm.json"
        if not out.exists():
            status, _, err = cli_inprocess(["export", str(_generated(work, MM)), "--format",
                                            "sep005", "-o", str(out)])
            if status != 0:
                raise RuntimeError(f"export: {err[-300:]}")
        return out

    def uff_ascii() -> tuple[Path, list[str]]:
        """The stiff beam's lab record exported as UFF and rewritten with ASCII UFF58 records
        (the export writes binary 58b ones, whose data bytes a line-end edit would change), and
        the prior the export printed."""
        import pyuff

        out = work / "lab_ascii.uff"
        if "uff prior" not in state:
            src = work / "lab.uff"
            status, stdout, err = cli_inprocess(["export", str(_generated(work, LAB)), "--format",
                                                 "uff", "-o", str(src)])
            if status != 0:
                raise RuntimeError(f"export: {err[-300:]}")
            sets = pyuff.UFF(str(src)).read_sets()
            for r in sets if isinstance(sets, list) else [sets]:
                if r.get("type") == 58:
                    r["binary"] = 0
            out.unlink(missing_ok=True)
            pyuff.UFF(str(out)).write_sets(sets, mode="add")
            state["uff prior"] = [x for a in (stdout + err).split() if "=" in a and not a.startswith("-")
                                  for x in ("--prior", a)]
        return out, state["uff prior"]

    def uff_case(label: str, edit, expect: str):
        def run():
            src, prior = uff_ascii()
            beam = ["--kind", "structural", "--method", "ls_sindy", *prior]
            clean_out = Path(f"{src}.model.json")
            if not clean_out.exists():
                found = judged(*cli_inprocess(["identify", str(src), "-o", str(clean_out), *beam]))
                if found:
                    raise RuntimeError(f"clean UFF: {found}")
            path = work / f"{_safe(label)}.uff"
            path.write_bytes(edit(src.read_bytes()))
            status, out, err = cli_inprocess(["identify", str(path), "-o", f"{path}.model.json", *beam])
            found = judged(status, out, err)
            if found:
                return found
            if status == 0 and not _same(_model(Path(f"{path}.model.json")), _model(clean_out), 1e-9):
                return "read to another model than the clean file's"
            if expect == "same" and status == 2:
                return f"refused an equivalent file: {err.strip()[:200]!r}"
            return None
        return run

    bom = b"\xef\xbb\xbf"
    cases += [
        ("textenc UFF58 ASCII with CRLF (accepted)",
         uff_case("uff crlf", lambda d: d.replace(b"\n", b"\r\n"), "same")),
        ("textenc UFF58 ASCII with CR line ends (accepted)",
         uff_case("uff cr", lambda d: d.replace(b"\n", b"\r"), "same")),
        ("textenc UFF58 ASCII with a BOM", uff_case("uff bom", lambda d: bom + d, "any")),
        ("textenc UFF58 ASCII with a BOM and CRLF",
         uff_case("uff bom crlf", lambda d: bom + d.replace(b"\n", b"\r\n"), "any")),
    ]
    cases += [
        ("textenc SEP-005 as UTF-16", case("sep utf16",
                                           lambda: sep_export().read_text().encode("utf-16"),
                                           "any", ".json")),
        ("textenc SEP-005 with CRLF and indentation (accepted)",
         case("sep crlf", lambda: json.dumps(json.loads(sep_export().read_text()), indent=1)
              .replace("\n", "\r\n").encode(), "same", ".json")),
        ("textenc SEP-005 a key in full-width letters",
         case("sep wide", lambda: sep_export().read_text().replace('"fs"', '"\uff46\uff53"').encode(),
              "refuse", ".json")),
    ]
    return cases


# ------------------------------------------------------------------ dssave

def dssave_cases(work: Path) -> list[tuple[str, object]]:
    import numpy as np

    from testbed.core.dataset import Dataset, Signal

    def sig(name="x", unit="m"):
        return Signal(np.arange(10.0), (name,), unit)

    def case(label: str, expect: str, **kw):
        def run():
            d = {"fs": 100.0, "measured": {"x": sig()}, **kw}
            ds = Dataset(**d)
            path = work / f"{_safe(label)}.h5"
            try:
                ds.save(path)
            except Exception as e:
                found = _one_line_refusal(e)
                if found:
                    return f"save: {found}"
                if path.exists():
                    return "refused, but a file was written"
                return None if expect in ("refuse", "any") else f"refused: {str(e)[:200]!r}"
            try:
                back = Dataset.load(path)
            except Exception as e:
                return f"saved, then its own load refused it: {str(e)[:200]!r}"
            if back.content_hash() != ds.content_hash():
                return "saved, then loaded to another content hash"
            return "saved (a refusal was due)" if expect == "refuse" else None
        return run

    table = [
        ("attrs a set", "refuse", {"attrs": {"s": {1, 2}}}),
        ("attrs bytes", "refuse", {"attrs": {"b": b"\x00\xff"}}),
        ("attrs 10**400", "refuse", {"attrs": {"h": 10 ** 400}}),
        ("attrs key format", "refuse", {"attrs": {"format": "x"}}),
        ("attrs key fs", "refuse", {"attrs": {"fs": 5}}),
        ("attrs a text with a NUL", "refuse", {"attrs": {"t": "a\x00b"}}),
        ("attrs NaN (accepted)", "any", {"attrs": {"n": math.nan}}),
        ("attrs None (accepted)", "any", {"attrs": {"z": None}}),
        ("attrs a nested table (accepted)", "any", {"attrs": {"j": {"a": [1, 2.5, "x"]}}}),
        ("prior a text", "refuse", {"prior": {"total_mass": "0.7"}}),
        ("prior a list", "refuse", {"prior": {"total_mass": [1, 2]}}),
        ("prior link_lengths (accepted)", "any", {"prior": {"link_lengths": [0.1, 0.2]}}),
        ("truth a text", "refuse", {"truth": {"M": "abc"}}),
        ("truth a ragged list", "refuse", {"truth": {"M": [[1, 2], [3]]}}),
        ("truth complex", "refuse", {"truth": {"M": np.array([1j])}}),
        ("truth a float (accepted)", "any", {"truth": {"g": 9.81}}),
        ("truth a list of names (accepted)", "any", {"truth": {"names": ["a", "b"]}}),
        ("a signal named a/b", "refuse", {"measured": {"a/b": sig()}}),
        ("a signal named empty", "refuse", {"measured": {"": sig()}}),
        ("a signal named .", "refuse", {"measured": {".": sig()}}),
        ("no measured signal", "refuse", {"measured": {}}),
        ("a bare array for a Signal", "refuse", {"measured": {"x": np.arange(3.0)}}),
        ("fs a text", "refuse", {"fs": "100"}),
        ("fs NaN", "refuse", {"fs": math.nan}),
        ("fs 10**400", "refuse", {"fs": 10 ** 400}),
        ("a channel with a NUL", "refuse", {"measured": {"x": sig(name="x\x00")}}),
        ("a unit with a NUL", "refuse", {"measured": {"x": sig(unit="m\x00")}}),
    ]
    return [(f"dssave {label}", case(label, expect, **kw)) for label, expect, kw in table]


# ------------------------------------------------------------------ samefile

def samefile_cases(work: Path) -> list[tuple[str, object]]:
    import hashlib

    from testbed.pipeline.scenario import SCENARIO_DIR

    state: dict = {}

    def inputs() -> dict[str, Path]:
        """The inputs, made once: a dataset, its SEP-005 export, a CSV, a scenario file, a study
        file and a finished sweep's results."""
        if not state:
            data = _generated(work, MM)
            sep = work / "mm.json"
            cli_inprocess(["export", str(data), "--format", "sep005", "-o", str(sep)])
            csv = work / "mm.csv"
            ds = json.loads(sep.read_text())
            x = next(c for c in ds if c["name"] == "x/x")
            dx = next(c for c in ds if c["name"] == "dx/dx")
            rows = [f"{k / x['fs']!r},{a!r},{b!r}" for k, (a, b) in enumerate(zip(x["data"], dx["data"],
                                                                                 strict=True))]
            csv.write_text("t [s],x [mM],dx [mM/s]\n" + "\n".join(rows) + "\n")
            folder = work / "local"
            folder.mkdir(exist_ok=True)
            scen = folder / f"{MM}.toml"
            shutil.copy(SCENARIO_DIR / f"{MM}.toml", scen)
            study = folder / "st.toml"
            study.write_text(f'[study]\nname = "st"\nscenarios = ["{MM}"]\nnoise = [0.0]\n'
                             'seeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')
            results = work / "st.parquet"
            status, _, err = cli_inprocess(["sweep", str(study), "--results", str(results),
                                            "--jobs", "1"])
            if status not in (0, 1):
                raise RuntimeError(f"sweep: {err[-300:]}")
            state.update(data=data, sep=sep, csv=csv, scen=scen, study=study, results=results)
        return state

    def digest(p: Path) -> str:
        return hashlib.sha256(p.read_bytes()).hexdigest()

    def spelled(path: Path, how: str, label: str) -> str:
        if how == "as given":
            return str(path)
        if how == "through dir/../":
            sub = path.parent / "sub"
            sub.mkdir(exist_ok=True)
            return str(sub / ".." / path.name)
        link = work / f"{_safe(label)}{path.suffix}"
        if link.exists() or link.is_symlink():
            link.unlink()
        if how == "through a symbolic link":
            link.symlink_to(path)
        else:
            os.link(path, link)
        return str(link)

    commands = {
        "export a dataset over itself": ("data", lambda i, o: ["export", str(i["data"]), "--format",
                                                               "uff", "-o", o]),
        "identify a dataset over itself": ("data", lambda i, o: ["identify", str(i["data"]),
                                                                 "--scenario", MM, "-o", o]),
        "identify a SEP-005 file over itself": ("sep", lambda i, o: ["identify", str(i["sep"]),
                                                                     "--scenario", MM, "-o", o]),
        "identify a CSV file over itself": ("csv", lambda i, o: ["identify", str(i["csv"]),
                                                                 "--scenario", MM, "-o", o]),
        "generate over its scenario file": ("scen", lambda i, o: ["generate", str(i["scen"]),
                                                                  "-o", o]),
        "sweep --results over its study file": ("study", lambda i, o: ["sweep", str(i["study"]),
                                                                        "--results", o]),
        "family write -o at its study file": ("study", lambda i, o: ["family", "write",
                                                                     str(i["study"]), "-o", o]),
        "report -o at its results file": ("results", lambda i, o: ["report", str(i["results"]),
                                                                   "-o", o]),
        "run --out at its scenario file": ("scen", lambda i, o: ["run", str(i["scen"]), "--out", o,
                                                                 "--no-figures"]),
    }

    def case(label: str, key: str, argv, how: str):
        def run():
            i = inputs()
            before = {k: digest(p) for k, p in i.items()}
            target = spelled(i[key], how, label)
            status, out, err = cli_inprocess(argv(i, target))
            found = judged(status, out, err)
            if found:
                return found
            changed = [k for k, p in i.items() if digest(p) != before[k]]
            if changed:
                return f"status {status}: the input {changed} changed"
            if how != "through a hard link" and status == 0:
                return f"status 0 writing over the input: {out.strip()[-160:]!r}"
            return None
        return run

    hows = ("as given", "through dir/../", "through a symbolic link", "through a hard link")
    return [(f"samefile {label} {how}", case(f"{label} {how}", key, argv, how))
            for label, (key, argv) in commands.items() for how in hows]


# ------------------------------------------------------------------ main

FAMILIES = _hostile.families(
    {
        "sigarrays": sigarrays_cases,
        "measarrays": measarrays_cases,
        "simargs": simargs_cases,
        "tomlvals": tomlvals_cases,
        "studyvals": studyvals_cases,
        "textenc": textenc_cases,
        "dssave": dssave_cases,
        "samefile": samefile_cases,
    },
    TIMEOUT_S,
)


def main(argv: list[str]) -> int:
    os.environ.setdefault("TESTBED_NO_SERVER", "1")
    return _hostile.main(argv, FAMILIES, "hostile26-")


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
