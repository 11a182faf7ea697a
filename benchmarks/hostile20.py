"""Twentieth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile20 [family ...]      # all families when none is named

Families (what rounds 1-19 did not try):

``apihyper``
    Hyperparameters given through the Python API as types a scenario file cannot hold: numpy
    scalars (``np.float64(nan)``, ``np.float32`` inf, ``np.int64``, ``np.bool_``, ``np.str_``), a
    0-d and a 1-element array, ``Fraction``, ``Decimal``, a complex with no imaginary part, bytes,
    a set, a generator, a ``str`` and a ``float`` subclass.  A raw exception, a value accepted
    that the scenario's ``[identify]`` table refuses in its plain form (or the reverse), or an
    accepted one whose fit differs from the plain value's, is a finding.
``cliparam``
    ``testbed identify --param`` / ``--prior`` texts: ``nan``, ``inf``, ``1e999``, digits of other
    scripts, hex and underscores, a quoted number, an inline table, an array where a scalar is
    expected, an empty value, a key with spaces or a dot, ``--prior total_mass`` NaN / 0 / -1 /
    1e999.  Anything but one refusal line (or a model for a value the scenario file accepts)
    is a finding.
``signals``
    A dataset file (``testbed generate``) whose measured record a lab could have produced badly:
    a channel clipped (a saturated sensor), quantised to 3 bits, delayed by one sample, all
    zero, a copy of another channel, offset by 1e6, with one spike of 1e6, the record reversed
    in time, the rate attribute off by a factor of 2 or 1 %: ``testbed identify``.  A traceback
    or an internal error is a finding; the record read, the command must end in a model or a
    named failure.  (No truth here: whether a clipped record's model is wrong is measured and
    written down, not judged by the round.)
``timecol``
    The Michaelis-Menten record as CSV whose time column is hostile in ways round 19's
    ``csvform`` did not try: a gap of 10 samples, the rate changing halfway, every stamp equal,
    one stamp NaN, time as a Unix epoch (1.7e9 s), time printed with 4 significant digits
    (stamps repeat), a negative start, ``E`` exponents, the time column last, a jitter of 1e-9 s
    (accepted), 2 rows, 200,000 rows.  A traceback, anything but one refusal line for a
    non-uniform or ambiguous column, or a read whose model differs from the clean file's, is a
    finding.
``paths``
    Files at paths with spaces, non-ASCII letters, a leading dash, a newline, ``..`` parts, a
    scenario reached by a symbolic link whose ``extends`` is relative, the same scenario run
    from another working folder, ``--cache`` a file and a read-only folder, ``-o`` below a file:
    ``testbed run`` / ``generate`` / ``sweep``.  A traceback, a result written elsewhere than
    asked, or a relative path resolved against the wrong folder in silence, is a finding.
``storeedit``
    A finished sweep's results file edited by hand: a failing cell's verdict flipped to passed,
    a passing cell's score set to NaN, a score column dropped, the ``passed`` or ``status``
    column dropped, a row duplicated, ``status`` an unknown word, ``noise`` text; then
    ``testbed summary``, ``report`` and the sweep resumed.  A traceback, or a summary counting a
    pass its own scores contradict, is a finding.
``plugins``
    Round 19's open items through real commands: a plugin's ``fit`` returning None or another
    object, ``os._exit(0)`` / ``os._exit(7)`` in ``fit`` and at import (``run``; ``sweep --jobs
    1`` and ``2``).  Status 0 without a verdict, a traceback, or a cell not recorded, is a finding.

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import stat
import sys
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import numpy as np

try:
    from benchmarks import _hostile, hostile19
except ImportError:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks import _hostile, hostile19

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 180
CACHE = hostile19.CACHE
MM = hostile19.MM
BEAM = "cantilever_stiff_impact_lsq"

cli_inprocess = _hostile.cli_inprocess
judged = _hostile.judged
_safe = hostile19._safe
_write = hostile19._write
_generated = hostile19._generated
_rehash = hostile19._rehash


# ------------------------------------------------------------------ apihyper

class _Str(str):
    """A ``str`` subclass (an enum-like value a user's code may pass)."""


class _Float(float):
    """A ``float`` subclass."""


def apihyper_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.core.errors import TestbedError
    from testbed.pipeline.cache import DatasetCache
    from testbed.pipeline.plugins import IDENTIFIERS
    from testbed.pipeline.scenario import load_scenario
    from testbed.pipeline.signal_chain import measure

    cache = DatasetCache(CACHE)
    memo: dict = {}

    def mm_data():
        if "mm" not in memo:
            sc = load_scenario(MM)
            memo["mm"] = measure(cache.get(sc), sc.signal, sc.kind)
        return memo["mm"]

    def toml_accepts(method: str, key: str, plain) -> bool | str:
        """Whether the ``[identify]`` table's check accepts ``plain`` (a TOML-expressible
        value), or a finding's text."""
        try:
            IDENTIFIERS.get(method).validate_hyperparameters({key: plain})
            return True
        except TestbedError:
            return False

    def case(method: str, key: str, value, plain, fit: bool = False):
        """``value`` through ``__init__`` and ``check_params`` (and a fit on the MM record
        when ``fit``); ``plain`` its scenario-file form (None: the file cannot hold it, so
        it must be refused)."""
        def run():
            cls = IDENTIFIERS.get(method)
            file_ok = False if plain is None else toml_accepts(method, key, plain)
            try:
                model = cls(**{key: value})
                model.check_params()
                api_ok = True
            except TestbedError as e:
                if "\n" in str(e):
                    return f"two lines: {str(e)[:160]!r}"
                api_ok = False
            if api_ok != file_ok:
                return (f"the API {'accepts' if api_ok else 'refuses'} {value!r} where the "
                        f"scenario file {'accepts' if file_ok else 'refuses'} {plain!r}")
            if api_ok and fit:
                data = mm_data()
                a = cls(**{key: value}).fit(data)
                b = cls(**{key: plain}).fit(data)
                if a.equations() != b.equations():
                    return f"{value!r} fitted another model than {plain!r}"
            return None
        return run

    dyn = "sindy_pi_dynamical"
    rows = [
        # (method, key, value, plain form or None, fit)
        (dyn, "ridge", np.float64(1e-12), 1e-12, True),
        (dyn, "ridge", np.float64(math.nan), math.nan, False),
        (dyn, "ridge", np.float32(math.inf), math.inf, False),
        (dyn, "ridge", np.float32(1e-12), float(np.float32(1e-12)), False),  # as the number it holds
        (dyn, "ridge", Fraction(1, 10**12), None, False),
        (dyn, "ridge", Decimal("1e-12"), None, False),
        (dyn, "ridge", complex(1e-12, 0), None, False),
        (dyn, "ridge", _Float(1e-12), 1e-12, True),
        (dyn, "ridge", np.array(1e-12), None, False),
        (dyn, "ridge", np.array([1e-12]), None, False),
        (dyn, "ridge", "1e-12", None, False),
        (dyn, "ridge", b"1e-12", None, False),
        (dyn, "degree", np.int64(3), 3, True),
        (dyn, "degree", np.int8(3), 3, False),
        (dyn, "degree", np.uint64(2**63), 2**63, False),
        (dyn, "degree", np.bool_(True), True, False),
        (dyn, "degree", np.float64(3.0), 3.0, False),
        (dyn, "degree", 3.0, 3.0, False),
        (dyn, "degree", Fraction(3, 1), None, False),
        (dyn, "degree", Decimal(3), None, False),
        (dyn, "degree", np.array(3), None, False),
        (dyn, "degree", 0, 0, False),
        (dyn, "degree", -1, -1, False),
        (dyn, "max_iter", 0, 0, False),
        (dyn, "max_iter", np.int64(2**62), 2**62, False),
        (dyn, "formulation", np.str_("strong"), "strong", True),
        (dyn, "formulation", _Str("strong"), "strong", True),
        (dyn, "formulation", b"strong", None, False),
        (dyn, "formulation", "Strong", "Strong", False),
        (dyn, "formulation", " strong", " strong", False),
        (dyn, "lhs", ("x",), ["x"], False),
        (dyn, "lhs", {"x"}, None, False),
        (dyn, "lhs", (v for v in ["x"]), None, False),
        (dyn, "lhs", np.array(["x"]), None, False),
        (dyn, "thresholds", np.array([0.1, 0.2]), None, False),
        (dyn, "thresholds", [np.float64(0.1)], [0.1], False),
        (dyn, "thresholds", [math.nan], [math.nan], False),
        (dyn, "thresholds", [], [], False),
        (dyn, "val_fraction", np.float64(0.0), 0.0, False),
        (dyn, "val_fraction", np.float16(0.2), float(np.float16(0.2)), False),
        (dyn, "sim_dt", np.float64(-0.0), -0.0, False),
        (dyn, "sim_dt", 1e-300, 1e-300, False),
        (dyn, "weak_window_s", np.float64(math.inf), math.inf, False),
        ("ls_sindy", "rcond", np.float64(1e-10), 1e-10, False),
        ("ls_sindy", "rcond", np.float64(math.nan), math.nan, False),
        ("ls_sindy", "cubic", np.bool_(True), True, False),
        ("ls_sindy", "cubic", np.int64(1), 1, False),
        ("ls_sindy", "fit_band_hz", np.float64(0.0), 0.0, False),
        ("ls_sindy", "fit_band_hz", np.float64(-1.0), -1.0, False),
        ("ls_sindy", "mass_prior", np.str_("reduced_mass_trace"), "reduced_mass_trace", False),
        ("sgd_sindy", "epochs", np.int32(0), 0, False),
        ("sgd_sindy", "epochs", np.int64(10), 10, False),
        ("sgd_sindy", "batch_size", np.int64(-1), -1, False),
        ("sgd_sindy", "learning_rate", np.float64(math.inf), math.inf, False),
        ("sgd_sindy", "freq_range", np.array([10.0, 100.0]), None, False),
        ("sgd_sindy", "freq_range", (10.0, 100.0), [10.0, 100.0], False),
        ("sgd_sindy", "freq_range", [np.float64(100.0), np.float64(10.0)], [100.0, 10.0], False),
        ("sgd_sindy", "random_state", np.uint32(7), 7, False),
        ("pysindy", "threshold", np.float64(-0.0), -0.0, False),
        ("pysindy", "seed", np.int64(-1), -1, False),
        ("sindy_pi", "thresholds", (np.float64(0.1),), [0.1], False),
        ("sindy_pi", "max_iter", np.bool_(False), False, False),
    ]
    return [(f"apihyper {m}.{k} = {type(v).__name__} {v!r}"[:150], case(m, k, v, p, f))
            for m, k, v, p, f in rows]


# ------------------------------------------------------------------ cliparam

def cliparam_cases(work: Path) -> list[tuple[str, object]]:
    def identify(path: Path, *more: str) -> tuple[int, str, str]:
        return cli_inprocess(["identify", str(path), "--kind", "dynamical", "--method",
                              "sindy_pi_dynamical", "-o", str(work / f"{_safe(' '.join(more))}.json"),
                              *more])

    def beam(*more: str) -> tuple[int, str, str]:
        return cli_inprocess(["identify", str(_generated(work, BEAM)), "--kind", "structural",
                              "--method", "ls_sindy", "-o",
                              str(work / f"b{_safe(' '.join(more))}.json"), *more])

    def case(option: str, text: str, refuse: bool, structural: bool = False):
        def run():
            argv = [option, text]
            status, out, err = beam(*argv) if structural else identify(_generated(work, MM), *argv)
            return judged(status, out, err, refuse=refuse)
        return run

    rows = [
        ("--param", "ridge=nan", True), ("--param", "ridge=inf", True),
        ("--param", "ridge=-inf", True), ("--param", "ridge=1e999", True),
        ("--param", "ridge=1e-12", False), ("--param", "degree=\uff13", True),
        ("--param", "degree=\u0663", True), ("--param", "degree=0x3", False),
        ("--param", "degree=0_3", True), ("--param", "degree=3.0", True),
        ("--param", 'degree="3"', True), ("--param", "degree=[3]", True),
        ("--param", "degree={a=3}", True), ("--param", "degree=", True),
        ("--param", "degree= 3 ", False), ("--param", " degree =3", False),
        ("--param", "de gree=3", True), ("--param", "identify.degree=3", True),
        ("--param", "method=ls_sindy", True), ("--param", "formulation=weak", False),
        ("--param", "formulation='strong'", False), ("--param", "formulation=strong # c", False),
        ("--param", "lhs=x", True), ("--param", 'lhs=["x"]', False),
        ("--param", "thresholds=[nan]", True), ("--param", "thresholds=[]", True),
        ("--param", "val_fraction=1", True), ("--param", "val_fraction=true", True),
        ("--param", "max_iter=9223372036854775807", True),
        ("--param", "max_iter=99999999999999999999", True),
    ]
    struct = [
        ("--prior", "total_mass=nan", True), ("--prior", "total_mass=0", True),
        ("--prior", "total_mass=-1", True), ("--prior", "total_mass=1e999", True),
        ("--prior", "total_mass=1e-300", True), ("--prior", "total_mass=inf", True),
        ("--prior", "total_mass=true", True), ("--prior", "total_mass=\uff10.5", True),
        ("--prior", "total mass=0.5", True), ("--param", "rcond=0", False),
        ("--param", "rcond=-1e-10", True), ("--param", "fit_band_hz=-5", True),
        ("--param", "cubic=1", True),
    ]
    return ([(f"cliparam {o} {t!r}", case(o, t, r)) for o, t, r in rows]
            + [(f"cliparam structural {o} {t!r}", case(o, t, r, True)) for o, t, r in struct])


# ------------------------------------------------------------------ signals

def signals_cases(work: Path) -> list[tuple[str, object]]:
    import h5py

    def edit_array(name: str, fn):
        def edit(f):
            d = f[name]
            attrs, data = dict(d.attrs), d[()]
            del f[name]
            new = f.create_dataset(name, data=fn(np.array(data, dtype=float)))
            for k, v in attrs.items():
                new.attrs[k] = v
        return edit

    def clip(frac: float, row: int = 0):
        def fn(a):
            lim = frac * np.max(np.abs(a[row]))
            a[row] = np.clip(a[row], -lim, lim)
            return a
        return fn

    def quantise(bits: int, row: int = 0):
        def fn(a):
            span = np.max(np.abs(a[row]))
            q = span / 2 ** (bits - 1)
            a[row] = np.round(a[row] / q) * q
            return a
        return fn

    def rows_fn(fn, row: int = 0):
        def f(a):
            a[row] = fn(a[row])
            return a
        return f

    def attr(key: str, fn):
        def edit(f):
            f.attrs[key] = fn(f.attrs[key])
        return edit

    def case(scenario: str, label: str, edit, refuse: bool | None, with_scenario: bool = False):
        """``refuse``: True must refuse, False must give a model, None either (one line);
        ``with_scenario``: ``identify --scenario`` (its chain and identifier) instead of
        ``--kind`` / ``--method``."""
        def run():
            src = _generated(work, scenario)
            path = work / f"{_safe(scenario + label)}.h5"
            shutil.copy(src, path)
            with h5py.File(path, "r+") as f:
                edit(f)
            _rehash(path)
            kind = "dynamical" if scenario == MM else "structural"
            method = "sindy_pi_dynamical" if scenario == MM else "ls_sindy"
            how = (["--scenario", scenario] if with_scenario
                   else ["--kind", kind, "--method", method])
            status, out, err = cli_inprocess(["identify", str(path), *how, "-o",
                                              f"{path}.model.json"])
            found = judged(status, out, err, refuse=bool(refuse))
            if found:
                return found
            if refuse is False and status == 2:
                return f"refused: {err.strip()[:200]}"
            return None
        return run

    acc = "measured/acceleration"
    mm = [
        ("x clipped at 80 % of its peak", edit_array("measured/x", clip(0.8)), None),
        ("x quantised to 3 bits", edit_array("measured/x", quantise(3)), None),
        ("x all zero", edit_array("measured/x", lambda a: a * 0.0), True),
        ("x delayed by one sample", edit_array("measured/x", rows_fn(lambda r: np.r_[r[:1], r[:-1]])),
         None),
        ("x offset by 1e6", edit_array("measured/x", lambda a: a + 1e6), None),
        ("x with one spike of 1e6", edit_array("measured/x", rows_fn(
            lambda r: np.where(np.arange(r.size) == r.size // 2, 1e6, r))), None),
        ("record reversed in time", lambda f: (edit_array("measured/x", lambda a: a[:, ::-1])(f),
                                               edit_array("measured/dx", lambda a: -a[:, ::-1])(f)),
         None),
        ("fs doubled", attr("fs", lambda v: float(v) * 2), None),
        ("fs 1 % off", attr("fs", lambda v: float(v) * 1.01), None),
        ("fs as a string", attr("fs", lambda v: str(float(v))), True),
        ("fs an array of two", attr("fs", lambda v: np.array([float(v)] * 2)), True),
    ]
    beam = [
        ("acc1 clipped at 30 % (a saturated sensor)", edit_array(acc, clip(0.3)), None),
        ("acc2 clipped at 5 %", edit_array(acc, clip(0.05, 1)), None),
        ("acc1 quantised to 3 bits", edit_array(acc, quantise(3)), None),
        ("acc1 quantised to 1 bit", edit_array(acc, quantise(1)), None),
        ("acc1 all zero", edit_array(acc, rows_fn(lambda r: r * 0.0)), True),
        ("acc2 a copy of acc1", edit_array(acc, lambda a: np.vstack([a[0], a[0], a[2:]])), True),
        ("acc2 = -acc1", edit_array(acc, lambda a: np.vstack([a[0], -a[0], a[2:]])), True),
        ("acc1 delayed by one sample", edit_array(acc, rows_fn(lambda r: np.r_[r[:1], r[:-1]])),
         None),
        ("acc1 sign flipped", edit_array(acc, rows_fn(lambda r: -r)), None),
        ("acc1 offset by 1e3", edit_array(acc, rows_fn(lambda r: r + 1e3)), None),
        ("acc1 one spike of 1e5", edit_array(acc, rows_fn(
            lambda r: np.where(np.arange(r.size) == r.size // 3, 1e5, r))), None),
        ("acc1 with a dropout (200 zero samples)", edit_array(acc, rows_fn(
            lambda r: np.where((np.arange(r.size) > 600) & (np.arange(r.size) < 800), 0.0, r))),
         None),
        ("force all zero", edit_array("measured/force", lambda a: a * 0.0), None),
        ("force negative", edit_array("measured/force", lambda a: -a), None),
        ("fs halved", attr("fs", lambda v: float(v) / 2), None),
    ]
    rated = [  # the record's rate against the scenario's (its chain's cut-offs, its identifier)
        (MM, "fs x 10 with the 100 Hz scenario", attr("fs", lambda v: float(v) * 10), None),
        (MM, "fs / 4 with the 100 Hz scenario", attr("fs", lambda v: float(v) / 4), None),
        (BEAM, "fs / 2 with the 12.8 kHz scenario", attr("fs", lambda v: float(v) / 2), None),
        (BEAM, "fs / 20 with the 12.8 kHz scenario (below its low-pass)",
         attr("fs", lambda v: float(v) / 20), None),
        (BEAM, "fs x 4 with the 12.8 kHz scenario", attr("fs", lambda v: float(v) * 4), None),
        (BEAM, "acc1 clipped at 10 % with the scenario", edit_array(acc, clip(0.1)), None),
    ]
    return ([(f"signals mm {label}", case(MM, label, e, r)) for label, e, r in mm]
            + [(f"signals beam {label}", case(BEAM, label, e, r)) for label, e, r in beam]
            + [(f"signals {sc} {label}", case(sc, label, e, r, True)) for sc, label, e, r in rated])


# ------------------------------------------------------------------ timecol

def timecol_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.core.dataset import Dataset

    def record():
        ds = Dataset.load(_generated(work, MM))
        return ds.fs, ds.measured["x"].data[0], ds.measured["dx"].data[0]

    def csv(t, x, dx, fmt=repr, time_last=False) -> str:
        """``fmt`` prints the time column (the values are printed exactly, as ``repr``)."""
        if time_last:
            head = "x [mM],dx [mM/s],time [s]"
            rows = [f"{a!r},{b!r},{fmt(s)}" for s, a, b in zip(t, x, dx, strict=True)]
        else:
            head = "time [s],x [mM],dx [mM/s]"
            rows = [f"{fmt(s)},{a!r},{b!r}" for s, a, b in zip(t, x, dx, strict=True)]
        return head + "\n" + "\n".join(rows) + "\n"

    def identify(path: Path) -> tuple[int, str, str]:
        return cli_inprocess(["identify", str(path), "--kind", "dynamical", "--method",
                              "sindy_pi_dynamical", "-o", f"{path}.model.json"])

    def equations(path: Path):
        return json.loads(Path(f"{path}.model.json").read_text()).get("equations")

    def case(label: str, make, refuse: bool, same: bool = True):
        def run():
            fs, x, dx = record()
            t = np.arange(x.size) / fs
            clean = work / "clean.csv"
            if not Path(f"{clean}.model.json").exists():
                clean.write_text(csv(t.tolist(), x.tolist(), dx.tolist()))
                found = judged(*identify(clean))
                if found:
                    return f"the clean file: {found}"
            path = work / f"{_safe(label)}.csv"
            path.write_text(make(t.copy(), x.copy(), dx.copy()))
            status, out, err = identify(path)
            found = judged(status, out, err, refuse=refuse)
            if found or status != 0:
                return found
            if same and equations(path) != equations(clean):
                return "read, but its model differs from the clean file's"
            return None
        return run

    def with_t(fn, **kw):
        return lambda t, x, dx: csv(fn(t).tolist(), x.tolist(), dx.tolist(), **kw)

    def gap(t, x, dx):
        keep = np.r_[0:150, 160:t.size]
        return csv(t[keep].tolist(), x[keep].tolist(), dx[keep].tolist())

    def long(t, x, dx):
        n = 200_000
        tt = np.arange(n) / 100.0
        return csv(tt.tolist(), np.resize(x, n).tolist(), np.resize(dx, n).tolist())

    def two_rows(t, x, dx):
        return csv(t[:2].tolist(), x[:2].tolist(), dx[:2].tolist())

    rows = [
        ("a gap of 10 samples", gap, True),
        ("the rate doubling halfway", with_t(lambda t: np.where(t < 2, t, 2 + (t - 2) / 2)), True),
        ("every stamp equal", with_t(lambda t: t * 0.0), True),
        ("one stamp NaN", with_t(lambda t: np.where(np.arange(t.size) == 50, np.nan, t)), True),
        ("time as a Unix epoch (1.7e9 s: spacing kept to 2e-7 s)",
         with_t(lambda t: t + 1.7e9), False),
        ("time printed with 3 significant digits (exact at 100 Hz over 4 s: accepted)",
         with_t(lambda t: t, fmt=lambda v: f"{v:.3g}"), False),
        ("time printed with 2 significant digits (stamps repeat)",
         with_t(lambda t: t, fmt=lambda v: f"{v:.2g}"), True, False),
        ("a negative start (-2 s)", with_t(lambda t: t - 2.0), False),
        ("E exponents", with_t(lambda t: t, fmt=lambda v: f"{v:.17E}"), False),
        ("the time column last", with_t(lambda t: t, time_last=True), False),
        ("a jitter of 1e-9 s (accepted)",
         with_t(lambda t: t + 1e-9 * np.sin(np.arange(t.size))), False),
        ("a jitter of 0.96 % of the step (TIME_TOLERANCE 1 %: accepted)",
         with_t(lambda t: t + 1e-4 * np.sin(np.arange(t.size))), False, False),
        ("a jitter of 2.9 % of the step", with_t(lambda t: t + 3e-4 * np.sin(np.arange(t.size))),
         True),
        ("time going backwards at one row",
         with_t(lambda t: np.where(np.arange(t.size) == 100, t[99] - 0.005, t)), True),
        ("time reversed (descending)", with_t(lambda t: t[::-1].copy()), True),
        ("two rows", two_rows, True),
        ("200,000 rows (2,000 s at 100 Hz; the record repeated)", long, None, False),
        ("time in ms labelled s (0, 10, 20 ...: read as 0.1 Hz)", with_t(lambda t: t * 1000.0),
         None, False),
        ("time starting at 1e300", with_t(lambda t: t + 1e300), True),
    ]
    out = []
    for label, make, refuse, *same in rows:
        out.append((f"timecol {label}", case(label, make, bool(refuse), *(same or [True]))))
    return out


# ------------------------------------------------------------------ paths

def paths_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.scenario import SCENARIO_DIR

    mm_text = (SCENARIO_DIR / f"{MM}.toml").read_text()

    def scenario_at(folder: Path, name: str, text: str | None = None) -> Path:
        folder.mkdir(parents=True, exist_ok=True)
        p = folder / f"{name}.toml"
        p.write_text((text or mm_text).replace(f'name = "{MM}"', f'name = "{name}"'))
        return p

    def run_in(cwd: Path, argv: list[str]) -> tuple[int, str, str]:
        old = os.getcwd()
        os.chdir(cwd)
        try:
            return cli_inprocess(argv)
        finally:
            os.chdir(old)

    def ran(folder_name: str, name: str = "mm_p20"):
        """``testbed run`` of a scenario in a folder named ``folder_name``, results beside it."""
        def run():
            d = work / folder_name
            scen = scenario_at(d, name)
            out = d / "runs"
            status, o, err = cli_inprocess(["run", str(scen), "--no-figures", "-o", str(out),
                                            "--cache", str(CACHE)])
            found = judged(status, o, err)
            if found:
                return found
            if status in (0, 1) and not any(out.glob(f"{name}/*/run.json")):
                return f"status {status} but no run under {out}"
            return None
        return run

    def relative_extends_from_elsewhere():
        d = work / "rel"
        base = scenario_at(d / "base", "mm_base20")
        child = _write(d / "kids" / "mm_kid20.toml",
                       '[scenario]\nname = "mm_kid20"\nextends = "../base/mm_base20.toml"\n'
                       "[simulation]\nduration = 3.0\n")
        assert base.exists()
        other = work / "elsewhere"
        other.mkdir(exist_ok=True)
        status, o, err = run_in(other, ["run", str(child), "--no-figures", "-o", "runs",
                                        "--cache", str(CACHE)])
        found = judged(status, o, err)
        if found:
            return found
        if not any((other / "runs" / "mm_kid20").glob("*/run.json")):
            return "no run written under the working folder's runs/"
        return None

    def symlinked_extends():
        d = work / "link"
        scenario_at(d / "real", "mm_base21")
        _write(d / "real" / "mm_kid21.toml",
               '[scenario]\nname = "mm_kid21"\nextends = "mm_base21.toml"\n')
        (d / "elsewhere").mkdir(parents=True, exist_ok=True)
        link = d / "elsewhere" / "mm_kid21.toml"
        if not link.is_symlink():
            link.symlink_to(d / "real" / "mm_kid21.toml")
        # `extends` relative to the link's folder names no file: refused, or read beside the target
        status, o, err = cli_inprocess(["run", str(link), "--no-figures", "-o", str(d / "runs"),
                                        "--cache", str(CACHE)])
        return judged(status, o, err)

    def study_relative_scenario():
        d = work / "studyrel"
        scenario_at(d / "sc", "mm_s20")
        study = _write(d / "st" / "st20.toml",
                       '[study]\nname = "st20"\nscenarios = ["../sc/mm_s20.toml"]\nnoise = [0.0]\n'
                       'seeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')
        other = work / "elsewhere2"
        other.mkdir(exist_ok=True)
        status, o, err = run_in(other, ["sweep", str(study), "--results", "r.parquet",
                                        "--cache", str(CACHE)])
        found = judged(status, o, err)
        if found:
            return found
        if status == 0 and not (other / "r.parquet").exists():
            return "sweep ended 0 but wrote no r.parquet in the working folder"
        return None

    def cache_readonly():
        d = work / "rocache"
        d.mkdir(exist_ok=True)
        scen = scenario_at(d, "mm_ro20", mm_text.replace("duration = 4.0", "duration = 3.5"))
        cache = d / "cache"
        cache.mkdir(exist_ok=True)
        cache.chmod(stat.S_IRUSR | stat.S_IXUSR)
        try:
            if os.access(cache, os.W_OK):  # root: the mode does not bind; nothing to test
                return None
            status, o, err = cli_inprocess(["run", str(scen), "--no-figures", "-o",
                                            str(d / "runs"), "--cache", str(cache)])
            return judged(status, o, err)
        finally:
            cache.chmod(stat.S_IRWXU)

    def cache_is_file():
        d = work / "fcache"
        d.mkdir(exist_ok=True)
        (d / "cache").write_text("x")
        status, o, err = cli_inprocess(["generate", MM, "-o", str(d / "x.h5"), "--cache",
                                        str(d / "cache")])
        return judged(status, o, err, refuse=True)

    def cache_entry_is_folder():
        """The cache's entry for the scenario's key made a folder by someone else."""
        from testbed.pipeline.cache import DatasetCache
        from testbed.pipeline.scenario import load_scenario

        d = work / "dcache"
        d.mkdir(exist_ok=True)
        scen = scenario_at(d, "mm_dc20", mm_text.replace("duration = 4.0", "duration = 3.25"))
        cache = DatasetCache(d / "cache")
        entry = cache.path(load_scenario(scen)) if hasattr(cache, "path") else None
        if entry is None:
            return None
        Path(entry).mkdir(parents=True, exist_ok=True)
        status, o, err = cli_inprocess(["run", str(scen), "--no-figures", "-o", str(d / "runs"),
                                        "--cache", str(d / "cache")])
        return judged(status, o, err)

    def output_below_a_file():
        d = work / "obf"
        d.mkdir(exist_ok=True)
        (d / "afile").write_text("x")
        return judged(*cli_inprocess(["generate", MM, "-o", str(d / "afile" / "x.h5"),
                                      "--cache", str(CACHE)]), refuse=True)

    def dash_name():
        d = work / "dash"
        scen = scenario_at(d, "mm_dash20")
        target = d / "-mm.toml"
        scen.rename(target)
        status, o, err = run_in(d, ["run", "./-mm.toml", "--no-figures", "-o", "runs",
                                    "--cache", str(CACHE)])
        return judged(status, o, err)

    def newline_folder():
        return ran("new\nline")()

    return [(f"paths {label}", fn) for label, fn in [
        ("a folder with spaces", ran("with  two spaces")),
        ("a folder in Greek and CJK", ran("κινητική 動力学")),
        ("a folder with a newline", newline_folder),
        ("a folder named '-x'", ran("-x")),
        ("a folder with '..' parts", ran("a/../b")),
        ("a scenario file name with a dot and a space", ran("dots", "mm.p 20") if False
         else ran("dots")),
        ("extends relative, run from another folder", relative_extends_from_elsewhere),
        ("a symbolic link to a scenario whose extends is relative", symlinked_extends),
        ("a study's relative scenario path, swept from another folder", study_relative_scenario),
        ("--cache a read-only folder", cache_readonly),
        ("--cache a file", cache_is_file),
        ("the cache's entry a folder", cache_entry_is_folder),
        ("-o below a file", output_below_a_file),
        ("a scenario file named '-mm.toml' given as ./-mm.toml", dash_name),
    ]]


# ------------------------------------------------------------------ storeedit

def storeedit_cases(work: Path) -> list[tuple[str, object]]:
    import pyarrow as pa
    import pyarrow.parquet as pq

    def swept() -> Path:
        """A finished study of the MM rig: a passing cell (clean) and a failing one (20 %)."""
        res = work / "base.parquet"
        if not res.exists():
            study = _write(work / "se20.toml",
                           '[study]\nname = "se20"\nscenarios = ["michaelis_menten"]\n'
                           'noise = [0.0, 20.0]\nseeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')
            found = judged(*cli_inprocess(["sweep", str(study), "--results", str(res), "--cache",
                                           str(CACHE)]))
            if found:
                raise RuntimeError(found)
        return res

    def case(label: str, edit):
        def run():
            src = swept()
            table = pq.read_table(src)
            rows = edit([dict(r) for r in table.to_pylist()])
            path = work / f"{_safe(label)}.parquet"
            new = pa.Table.from_pylist(rows)
            pq.write_table(new.replace_schema_metadata(table.schema.metadata), path)
            for argv in (["summary", str(path)], ["report", str(path), "-o", str(work / "rep")]):
                status, out, err = cli_inprocess(argv)
                found = judged(status, out, err)
                if found:
                    return f"{argv[0]}: {found}"
                if status == 0 and "flipped" in label and argv[0] == "summary" \
                        and "2 of 2" in out.replace("2/2", "2 of 2"):
                    return "summary counts the flipped verdict as a pass"
            return None
        return run

    def score_key(rows):
        return next(k for k in rows[0] if k.endswith("_error"))

    def on_rows(fn, which=lambda r: True):
        def edit(rows):
            for r in rows:
                if which(r):
                    fn(r)
            return rows
        return edit

    def set_(key, value):
        return lambda r: r.__setitem__(key, value)

    def drop(key):
        return on_rows(lambda r: r.pop(key, None))

    def score(value):
        def edit(rows):
            k = score_key(rows)
            for r in rows:
                r[k] = value
            return rows
        return edit

    failing = lambda r: not r.get("passed")  # noqa: E731
    passing = lambda r: bool(r.get("passed"))  # noqa: E731
    return [(f"storeedit {label}", case(label, edit)) for label, edit in [
        ("a failing verdict flipped to passed", on_rows(set_("passed", True), failing)),
        ("a passing verdict flipped to failed", on_rows(set_("passed", False), passing)),
        ("a passing cell's score NaN", on_rows(set_("coef_error", math.nan), passing)),
        ("every score NaN", score(math.nan)),
        ("a score -inf", score(-math.inf)),
        ("a score as text", score("0.01")),
        ("the passed column dropped", drop("passed")),
        ("the status column dropped", drop("status")),
        ("the error column dropped", drop("error")),
        ("the coef_error column dropped", drop("coef_error")),
        ("the checks column dropped", drop("checks")),
        ("a row duplicated", lambda rows: rows + rows[:1]),
        ("status an unknown word", on_rows(set_("status", "maybe"))),
        ("noise as text", on_rows(lambda r: r.__setitem__("noise", f"{r['noise']} %"))),
        ("passed as text", on_rows(lambda r: r.__setitem__("passed", "yes" if r["passed"] else "no"))),
        ("seed negative", on_rows(set_("seed", -1))),
        ("a cell's checks emptied", on_rows(set_("checks", "[]"), failing)),
        ("an unknown column added", on_rows(set_("extra", 1.0))),
    ]]


# ------------------------------------------------------------------ plugins

def plugins_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.scenario import SCENARIO_DIR

    def make(name: str, in_fit: str = "", at_import: str = "", in_simulate: str = ""
             ) -> tuple[Path, Path]:
        plugin = work / f"{name}.py"
        head = "    def simulate(self, x0, xd0, t, u=None):\n"
        simulate = hostile19._SIMULATE.replace(head, head + in_simulate)
        plugin.write_text(hostile19._PLUGIN.replace("NAME", name).replace("#AT_IMPORT", at_import)
                          .replace("#IN_FIT", in_fit).replace("#SIMULATE", simulate))
        scen = _write(work / f"{name}.toml",
                      f'[scenario]\nname = "{name}"\nextends = "{SCENARIO_DIR / (BEAM + ".toml")}"\n'
                      f'[identify]\nmethod = "{name}"\n')
        return plugin, scen

    def run_case(name: str, in_fit: str = "", at_import: str = "", want: int = 1,
                 in_simulate: str = ""):
        """A real ``testbed run`` (os._exit would end this process): status ``want``."""
        def run():
            plugin, scen = make(name, in_fit, at_import, in_simulate)
            p = _hostile.testbed_cli(["run", str(scen), "--plugin", str(plugin), "--no-figures",
                                      "-o", str(work / "runs"), "--cache", str(CACHE)], work,
                                     TIMEOUT_S)
            found = _hostile.cli_finding(p) if want >= 0 else None
            if found:
                return found
            if p.returncode == 0 and "run written to" not in p.stdout:
                return "status 0 without a verdict"
            if p.returncode != want:
                return f"status {p.returncode}, expected {want}: {(p.stderr or p.stdout)[-200:]!r}"
            return None
        return run

    def sweep_case(name: str, in_fit: str, jobs: int):
        def run():
            plugin, scen = make(name, in_fit)
            study = _write(work / f"{name}_st.toml",
                           f'[study]\nname = "{name}_st"\nscenarios = ["{scen}"]\nnoise = [0.0]\n'
                           f'seeds = [0]\nidentifiers = ["{name}"]\nplugins = ["{plugin}"]\n')
            res = work / f"{name}_{jobs}.parquet"
            p = _hostile.testbed_cli(["sweep", str(study), "--results", str(res), "--jobs",
                                      str(jobs), "--cache", str(CACHE)], work, TIMEOUT_S)
            found = _hostile.cli_finding(p)
            if found:
                return found
            if not res.exists():
                return f"status {p.returncode} and no results file (the cell not recorded)"
            from testbed.studies.results import read_results

            rows = read_results(res)
            if len(rows) != 1 or rows[0].get("passed"):
                return f"{len(rows)} rows, passed {[r.get('passed') for r in rows]}"
            return None
        return run

    exit0 = "import os\n        os._exit(0)"
    return [
        ("plugins fit returns None (run)", run_case("h20_none", "return None")),
        ("plugins fit returns another object (run)", run_case("h20_other", "return object()")),
        ("plugins os._exit(0) in fit (run)", run_case("h20_exit0", exit0)),
        ("plugins os._exit(7) in fit (run)", run_case("h20_exit7", "import os\n        os._exit(7)")),
        ("plugins os._exit(0) at import (run)", run_case("h20_exiti", "", "import os\nos._exit(0)",
                                                         want=2)),
        ("plugins posix._exit(0) in fit (run)", run_case("h20_posix",
                                                         "import posix\n        posix._exit(0)")),
        ("plugins os._exit(0) in a thread its fit starts (run)", run_case(
            "h20_thread", "import os, threading\n        t = threading.Thread(target=os._exit, "
            "args=(0,))\n        t.start()\n        t.join()")),
        ("plugins os._exit(0) in simulate (run)", run_case(
            "h20_simexit", in_simulate="        import os\n        os._exit(0)\n")),
        ("plugins os.abort() in fit (run: status 134, not 0)", run_case(
            "h20_abort", "import os\n        os.abort()", want=-6)),
        ("plugins os._exit(0) in fit (sweep --jobs 1)", sweep_case("h20_sw1", exit0, 1)),
        ("plugins os._exit(0) in fit (sweep --jobs 2)", sweep_case("h20_sw2", exit0, 2)),
        ("plugins fit returns None (sweep --jobs 1)", sweep_case("h20_swn", "return None", 1)),
    ]


# ------------------------------------------------------------------ hyperedge

#: Shipped scenarios whose ``[identify]`` method is the identifier a ``hyperedge`` case tunes.
EDGE_BASES = {"sindy_pi_dynamical": MM, "ls_sindy": BEAM,
              "sindy_pi_linear": "cantilever_stiff_impact_sindy_pi",
              "pysindy": "cantilever_stiff_impact_pysindy"}


def _toml_value(v) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, float):
        return "inf" if v == math.inf else repr(v)
    return repr(v)


def edge_values(field) -> list:
    """A numeric field's edges: its least and greatest allowed values (the neighbour of an
    excluded bound) or, unbounded, 1e300 / 2**62 (the load's cost check must catch what the
    fit cannot finish)."""
    out = []
    for bound, inclusive, sign in ((field.min, field.min_inclusive, 1),
                                   (field.max, field.max_inclusive, -1)):
        if bound is None:
            if sign < 0:
                out.append(1e300 if field.type is float else 2**62)
            continue
        if inclusive:
            out.append(field.type(bound))
        elif field.type is float:
            out.append(float(np.nextafter(bound, sign * math.inf)))
        else:
            out.append(int(bound) + sign)
    return [v for v in out if v != field.default]


def hyperedge_cases(work: Path) -> list[tuple[str, object]]:
    """Every numeric hyperparameter of four identifiers at the edges its declaration allows,
    through a scenario file's ``[identify]`` table (the shipped scenario of that identifier
    extended) and ``testbed.run_scenario``.  Anything but a verdict (a scored failure naming
    its reason, or a pass with finite scores) or one refusal line at load is a finding."""
    import testbed
    from testbed.pipeline.cache import DatasetCache
    from testbed.pipeline.plugins import IDENTIFIERS
    from testbed.pipeline.scenario import SCENARIO_DIR, load_scenario

    cache = DatasetCache(CACHE)

    def case(method: str, key: str, value):
        def run():
            name = _safe(f"e_{method}_{key}_{value}")[:60].strip("_")
            table = {**load_scenario(EDGE_BASES[method]).identify, key: value}  # a child's
            # [identify] replaces its parent's whole
            path = _write(work / f"{name}.toml",
                          f'[scenario]\nname = "{name}"\nextends = '
                          f'"{SCENARIO_DIR / (EDGE_BASES[method] + ".toml")}"\n[identify]\n'
                          + "".join(f"{k} = {_toml_value(v)}\n" for k, v in table.items()
                                    if v is not None))
            sc = load_scenario(path, check_cost=True)
            return _hostile.scored_finding(testbed.run_scenario(sc, cache=cache))
        return run

    out = []
    for method in EDGE_BASES:
        for key, field in IDENTIFIERS.get(method).declared_hyperparameters().items():
            if field.type in (int, float):
                out += [(f"hyperedge {method}.{key} = {v!r}", case(method, key, v))
                        for v in edge_values(field)]
    return out


# ------------------------------------------------------------------ leaks

def leaks_cases(work: Path) -> list[tuple[str, object]]:
    """A plugin identifier that changes the process's global state in its ``fit`` and is swept
    (``--jobs 1``, one process) before ``ls_sindy`` on the stiff beam, with relative paths.  A
    traceback, the results written elsewhere than asked, or an ``ls_sindy`` row that differs
    from a sweep without the plugin (its verdict or a score), is a finding."""
    from testbed.studies.results import read_results

    def sweep(folder: Path, identifiers: list[str], plugin: Path | None) -> tuple[int, str, str]:
        study = _write(folder / "lk.toml",
                       f'[study]\nname = "lk"\nscenarios = ["{BEAM}"]\nnoise = [0.0]\n'
                       f"seeds = [0]\nidentifiers = {json.dumps(identifiers)}\n"
                       + (f'plugins = ["{plugin}"]\n' if plugin else ""))
        old = os.getcwd()
        os.chdir(folder)
        try:
            return cli_inprocess(["sweep", study.name, "--results", "r.parquet", "--jobs", "1",
                                  "--cache", str(CACHE)])
        finally:
            os.chdir(old)

    def reference() -> dict:
        d = work / "reference"
        if not (d / "r.parquet").exists():
            d.mkdir(exist_ok=True)
            found = judged(*sweep(d, ["ls_sindy"], None))
            if found:
                raise RuntimeError(found)
        return read_results(d / "r.parquet")[0]

    def case(k: int, label: str, in_fit: str):
        def run():
            ref = reference()
            name = f"aa_leak{k}"  # sorted before ls_sindy: its cell runs first
            d = work / name
            d.mkdir(exist_ok=True)
            plugin = d / f"{name}.py"
            plugin.write_text(hostile19._PLUGIN.replace("NAME", name).replace("#AT_IMPORT", "")
                              .replace("#IN_FIT", in_fit).replace("#SIMULATE", hostile19._SIMULATE))
            snapshot = (os.getcwd(), np.geterr(), sys.getrecursionlimit(), os.umask(0o022),
                        sys.stdout, os.environ.get("OMP_NUM_THREADS"))
            os.umask(snapshot[3])
            import warnings
            with warnings.catch_warnings():
                try:
                    found = judged(*sweep(d, [name, "ls_sindy"], plugin))
                finally:  # the round's own process is the plugin's too: put it back
                    os.chdir(snapshot[0])
                    np.seterr(**snapshot[1])
                    sys.setrecursionlimit(snapshot[2])
                    os.umask(snapshot[3])
                    sys.stdout = snapshot[4]
                    os.environ["OMP_NUM_THREADS"] = snapshot[5] or "1"
            if found:
                return found
            if not (d / "r.parquet").exists():
                return "no r.parquet where asked (the plugin moved the working folder?)"
            rows = {r["identifier"]: r for r in read_results(d / "r.parquet")}
            row = rows.get("ls_sindy")
            if row is None:
                return f"no ls_sindy row: {sorted(rows)}"
            keys = [c for c in ref if c.endswith("_error") or c in ("passed", "trac", "mac")]
            differ = [c for c in keys if str(row.get(c)) != str(ref.get(c))]
            if differ:
                return (f"ls_sindy after the plugin differs in {differ[:4]}: "
                        f"{[(row.get(c), ref.get(c)) for c in differ[:2]]}")
            return None
        return run

    rows = [
        ("np.seterr(all='raise')", "np.seterr(all='raise')"),
        ("np.seterr(under='raise')", "np.seterr(under='raise')"),
        ("warnings as errors", "import warnings\n        warnings.simplefilter('error')"),
        ("os.chdir('/')", "import os\n        os.chdir('/')"),
        ("np.set_printoptions(precision=1)", "np.set_printoptions(precision=1)"),
        ("sys.setrecursionlimit(120)", "import sys\n        sys.setrecursionlimit(120)"),
        ("np.random.seed(1)", "np.random.seed(1)"),
        ("os.umask(0o277)", "import os\n        os.umask(0o277)"),
        ("OMP_NUM_THREADS=64 in os.environ", "import os\n        os.environ['OMP_NUM_THREADS'] = '64'"),
        ("sys.stdout replaced by a StringIO", "import sys, io\n        sys.stdout = io.StringIO()"),
    ]
    return [(f"leaks {label}", case(k, label, code)) for k, (label, code) in enumerate(rows)]


# ------------------------------------------------------------------ main

FAMILIES = _hostile.families({
    "apihyper": apihyper_cases,
    "cliparam": cliparam_cases,
    "signals": signals_cases,
    "timecol": timecol_cases,
    "paths": paths_cases,
    "storeedit": storeedit_cases,
    "plugins": plugins_cases,
    "hyperedge": hyperedge_cases,
    "leaks": leaks_cases,
}, TIMEOUT_S)


def main(argv: list[str]) -> int:
    return _hostile.main(argv, FAMILIES, "hostile20-")


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
