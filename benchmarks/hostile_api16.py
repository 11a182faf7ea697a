"""API round (session 15, docs/history.md): the public Python API under hostile use.

Each case calls a public name of ``testbed`` (or an identifier's class) the way a researcher might
get it wrong and ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): a result
the case's check finds sound, or one :class:`~testbed.core.errors.TestbedError` line.  A raw
numpy / scipy / KeyError / AttributeError / TypeError from inside, a silent acceptance of a value
that is not allowed, or a NaN result is a finding.  Run from the repository root::

    python -m benchmarks.hostile_api16 [family ...]      # all families when none is named

Families:

``measurement``
    :class:`~testbed.core.measurement.Measurement` built with mismatched lengths or channels,
    1-D, 3-D or empty arrays, complex, boolean, object or text dtypes, NaN / inf inside, a
    sample rate of 0, NaN, a string, a boolean, a ``free_start`` out of range or a float,
    channel names not text, an ``integration`` or ``input_hold`` not allowed, then fitted by
    ``ls_sindy``; float32, integer and non-contiguous arrays must fit as float64 does.
``estimators``
    Every identifier constructed with wrong hyperparameters (text for a number, NaN, inf,
    negative, ``2**63``, a boolean for an integer, numpy scalars) and fitted; unknown keyword
    arguments; ``fit`` on a non-Measurement (a dict, an array, None, a Dataset); ``fit`` twice;
    ``score`` / ``predict_acceleration`` / ``equations`` / ``simulate`` before ``fit``;
    ``set_params`` of an unknown or wrong value; ``clone`` / ``get_params`` round trips.
``entry``
    ``run_scenario``, ``load_scenario``, ``scenario_from_dict``, ``generate``, ``measure``,
    ``score``, ``split_measurement``, ``model_summary`` given the wrong types (an int, None, a
    list, a dict missing keys, a numpy scalar, a boolean seed).
``registry``
    ``register_scorer`` / ``register_signal_chain`` / ``register_truth`` twice or with a bad
    argument; ``load_plugins`` of a text instead of a list, a missing module.
``studies``
    ``run_sweep`` with ``jobs`` 0, -1, 1.5, "2", True; a study of a wrong type; ``read_results``
    on a folder, a text file, a missing file; ``load_study`` of None; ``list_runs`` /
    ``resolve_run`` / ``save_new_run`` with wrong arguments.
"""

from __future__ import annotations

import dataclasses
import math
import os
import sys
from collections import Counter
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

try:
    from benchmarks import _hostile
except ImportError:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks import _hostile

TIMEOUT_S = 60

Case = tuple[str, Callable[[], Any]]


def chain_data(duration: float = 0.05):
    """A small exact 3-DOF record (``benchmarks.bench_sgd_sindy``): 640 samples."""
    from benchmarks import bench_sgd_sindy

    return bench_sgd_sindy.chain_measurement(bench_sgd_sindy.chain_system(), duration=duration)


def finite_model(model: Any) -> str | None:
    """A finding if a fitted model holds a non-finite learned array."""
    for k, v in vars(model).items():
        # the model's own arrays (diagnostics such as compensation_ are NaN where not computed,
        # natural_frequencies_ NaN for a model with no stiffness: reported as open)
        if k in ("M_", "C_", "K_", "K3_", "coef_") and v is not None:
            try:
                a = np.asarray(v, dtype=float)
            except (TypeError, ValueError):
                continue
            if a.size and not np.all(np.isfinite(a)):
                return f"fitted {k} not finite"
    return None


def check_fit(result: Any) -> str | None:
    """A fitted model is sound when its learned arrays are finite."""
    if result is None:
        return None
    if hasattr(result, "is_fitted"):
        return finite_model(result) if result.is_fitted() else "fit returned an unfitted model"
    if isinstance(result, float) and math.isnan(result):
        return "NaN result"
    return None


def _fit(data: Any, name: str = "ls_sindy", **params: Any) -> Any:
    import testbed

    return testbed.IDENTIFIERS.get(name)(**params).fit(data)


# --- measurement -------------------------------------------------------------------------------

def measurement_cases() -> Iterator[Case]:
    from testbed.core.measurement import Measurement

    base = chain_data()
    f = {k.name: getattr(base, k.name) for k in dataclasses.fields(Measurement)}

    def built(**change: Any) -> Callable[[], Any]:
        def run() -> Any:
            _fit(Measurement(**{**f, **change}))
            raise AssertionError(f"accepted a malformed measurement ({', '.join(change)})")
        return run

    x = base.x
    yield "short xd", built(xd=base.xd[:, :-1])
    yield "fewer channels in xdd", built(xdd=base.xdd[:2])
    yield "1-D x", built(x=x[0], xd=base.xd[0], xdd=base.xdd[0], channels=("s1",))
    yield "3-D x", built(x=x[None], xd=base.xd[None], xdd=base.xdd[None])
    yield "empty arrays", built(x=x[:, :0], xd=x[:, :0], xdd=x[:, :0])
    yield "no channels", built(x=x[:0], xd=x[:0], xdd=x[:0], channels=())
    yield "channels longer than x", built(channels=("a", "b", "c", "d"))
    yield "channels a string", built(channels="abc")
    yield "channels numbers", built(channels=(1, 2, 3))
    yield "channels repeated", built(channels=("a", "a", "b"))
    yield "complex x", built(x=x.astype(complex))
    yield "boolean x", built(x=x > 0)
    yield "object x", built(x=x.astype(object))
    yield "text x", built(x=x.astype(str))
    for bad in (np.nan, np.inf, -np.inf):
        a = base.xdd.copy()
        a[1, 5] = bad
        yield f"xdd holding {bad}", built(xdd=a)
    for fs in (0.0, -1.0, np.nan, np.inf, "12800", True, None):
        yield f"fs={fs!r}", built(fs=fs)
    for fsr in (-1, 10**9, 1.5, True, "0"):
        yield f"free_start={fsr!r}", built(free_start=fsr)
    # a record whose free decay holds 10 samples: a named refusal or a model (open: the
    # structural fit band's rule asks for a band above the Nyquist frequency)
    yield "free_start 10 samples before the end", lambda: _fit(
        Measurement(**{**f, "free_start": base.n_samples - 10}))
    yield "integration 'euler'", built(integration="euler")
    yield "input_hold 'hold'", built(input_hold="hold")
    yield "prior a list", built(prior=[1, 2])
    yield "prior NaN mass", built(prior={"total_mass": float("nan")})
    yield "input_map of wrong shape", built(input_map=np.ones((2, 2)))
    yield "u of wrong length", built(u=np.ones((1, 7)), inputs=("f",), input_map=np.ones((3, 1)))
    yield "noise_std of wrong shape", built(noise_std=np.ones(5))
    yield "noise_std negative", built(noise_std=-np.ones(3))
    yield "passband reversed", built(passband=(100.0, 10.0))
    yield "passband a number", built(passband=5.0)
    yield "drift_basis wrong length", built(drift_basis=np.ones((1, 3)))

    # must fit as float64 does (same model)
    ref = _fit(base)

    def same(**change: Any) -> Callable[[], Any]:
        def run() -> Any:
            m = _fit(Measurement(**{**f, **change}))
            if not np.allclose(m.K_, ref.K_, rtol=1e-3):
                raise AssertionError(f"K_ differs from the float64 fit: {m.K_[0, 0]} vs {ref.K_[0, 0]}")
            return m
        return run

    yield "float32 arrays", same(x=x.astype(np.float32).astype(np.float32),
                                 xd=base.xd.astype(np.float32), xdd=base.xdd.astype(np.float32))
    yield "Fortran-ordered arrays", same(x=np.asfortranarray(x), xd=np.asfortranarray(base.xd),
                                         xdd=np.asfortranarray(base.xdd))
    big = np.zeros((3, 2 * base.n_samples))
    big[:, ::2] = x
    yield "non-contiguous x", same(x=big[:, ::2])
    yield "fs numpy int", same(fs=np.int64(12800))
    yield "fs numpy float32", same(fs=np.float32(12800))
    yield "list x", same(x=x.tolist())
    yield "fs=1e-300 (a rate > 0: fitted)", lambda: _fit(Measurement(**{**f, "fs": 1e-300}))
    def unnamed_inputs() -> Measurement:  # allowed when u is given (session 15): built, not refused
        try:
            return Measurement(**{**f, "u": np.ones((1, base.n_samples))})
        except Exception as e:
            raise AssertionError(f"refused a measurement with unnamed inputs: {e}") from e

    yield "u without input names (accepted)", unnamed_inputs


# --- estimators --------------------------------------------------------------------------------

def estimator_cases() -> Iterator[Case]:
    import testbed

    data = chain_data()
    for name in testbed.IDENTIFIERS.names():
        cls = testbed.IDENTIFIERS.get(name)
        hp = cls.declared_hyperparameters()
        yield f"{name}: unknown kwarg", lambda cls=cls: cls(no_such_param=1)
        for k, fld in hp.items():
            if fld.type in (int, float) and not isinstance(fld.default, bool):
                values = ["1", float("nan"), float("inf"), -1, -1e308, 2**63, True, [1]]
                if fld.type is int:
                    values += [1.5, np.int64(2)]
            elif fld.type is bool:
                values = ["yes", 2, None]
            elif fld.type is str:
                values = [3, "no_such_value"]
            else:
                continue
            for v in values:
                yield (f"{name}({k}={v!r}).fit", lambda cls=cls, k=k, v=v: _checked_fit(cls, {k: v}, data))
        for bad, what in ((None, "None"), ({"x": 1}, "a dict"), (np.ones((3, 10)), "an array"),
                          ("data.h5", "a path")):
            yield f"{name}.fit({what})", lambda cls=cls, bad=bad: cls().fit(bad)
        yield f"{name}.score before fit", lambda cls=cls: _nan_is_finding(cls().score(data))
        yield f"{name}.equations before fit", lambda cls=cls: cls().equations()
        yield f"{name}.simulate before fit", lambda cls=cls: cls().simulate(
            np.zeros(3), np.zeros(3), np.arange(10) / 1000.0)
        yield f"{name}.set_params unknown", lambda cls=cls: cls().set_params(nope=1)

    m = testbed.IDENTIFIERS.get("ls_sindy")
    yield "ls_sindy fit twice", lambda: _refit(m, data)
    yield "ls_sindy score(data, y=array)", lambda: m().fit(data).score(data, y=np.ones(3))
    yield "ls_sindy score on 2 channels", lambda: m().fit(data).score(
        dataclasses.replace(data, x=data.x[:2], xd=data.xd[:2], xdd=data.xdd[:2],
                            channels=data.channels[:2], input_map=data.input_map[:2]))
    yield "ls_sindy simulate x0 wrong length", lambda: m().fit(data).simulate(
        np.zeros(2), np.zeros(2), np.arange(10) / 1000.0)
    yield "ls_sindy simulate t decreasing", lambda: m().fit(data).simulate(
        np.zeros(3), np.zeros(3), -np.arange(10) / 1000.0)
    yield "ls_sindy equations precision -1", lambda: m().fit(data).equations(-1)
    yield "ls_sindy equations precision 'x'", lambda: m().fit(data).equations("x")
    yield "ls_sindy fit on a mechanical identifier's record", lambda: _fit(
        data, "sindy_pi_dynamical")


def _checked_fit(cls: type, params: dict, data: Any) -> Any:
    """Fit with ``params``; accepting a value its declaration refuses is a finding."""
    est = cls(**params)
    model = est.fit(data)
    k, v = next(iter(params.items()))
    fld = cls.declared_hyperparameters()[k]
    try:
        fld_ok = _allowed(fld, v)
    except Exception:
        fld_ok = True
    if not fld_ok:
        raise AssertionError(f"accepted {k}={v!r}, which the declaration refuses")
    return model


def _allowed(fld: Any, v: Any) -> bool:
    from testbed.core.errors import ScenarioError
    from testbed.core.schema import validate_table

    if isinstance(v, np.generic):
        v = v.item()  # a numpy scalar counts as the Python number it holds
    if v is None and fld.default is None:
        return True  # "not given"
    try:
        validate_table({"k": v}, {"k": fld}, file="f", section="s")
    except ScenarioError:
        return False
    return True


def _nan_is_finding(v: Any) -> Any:
    if isinstance(v, float) and math.isnan(v):
        raise AssertionError("NaN score")
    return v


def _refit(cls: type, data: Any) -> Any:
    est = cls().fit(data)
    k1 = est.K_.copy()
    est.fit(data)
    if not np.array_equal(k1, est.K_):
        raise AssertionError("fit twice gives another model")
    return est


# --- entry points ------------------------------------------------------------------------------

def entry_cases() -> Iterator[Case]:
    import testbed

    data = chain_data()
    for v in (3, None, ["a"], {"rig": {}}, b"cantilever", np.float64(1.0), Path("/nonexistent.toml"),
              "no_such_scenario", ""):
        yield f"run_scenario({v!r})", lambda v=v: testbed.run_scenario(v, cache=False)
        yield f"load_scenario({v!r})", lambda v=v: testbed.load_scenario(v)
    for v in (None, "x", [1], {}, {"scenario": {}}, {"rig": 1}):
        yield f"scenario_from_dict({v!r})", lambda v=v: testbed.scenario_from_dict(v)
    for seed in (True, -1, 1.5, "3", np.int64(3), 2**70):
        yield f"run_scenario(seed={seed!r})", lambda seed=seed: testbed.run_scenario(
            "michaelis_menten", seed=seed, cache=False)
    yield "run_scenario(model=class)", lambda: testbed.run_scenario(
        "michaelis_menten", model=testbed.IDENTIFIERS.get("sindy_pi_dynamical"), cache=False)
    yield "run_scenario(model='ls_sindy')", lambda: testbed.run_scenario(
        "michaelis_menten", model="ls_sindy", cache=False)
    yield "run_scenario(cache=3)", lambda: testbed.run_scenario("michaelis_menten", cache=3)
    yield "run_scenario(progress=1)", lambda: testbed.run_scenario(
        "michaelis_menten", cache=False, progress=1)
    for v in ("michaelis_menten", None, 3):
        yield f"generate({v!r})", lambda v=v: testbed.generate(v)
    yield "measure(None, {}, 'structural')", lambda: testbed.measure(None, {}, "structural")
    yield "measure(kind='nope')", lambda: _measure_kind("nope")
    yield "measure(signal=None)", lambda: _measure_signal(None)
    yield "score(None, dataset, scenario)", lambda: _score_with(None)
    yield "score(model, None, scenario)", lambda: testbed.score(
        testbed.IDENTIFIERS.get("ls_sindy")().fit(data), None, "michaelis_menten")
    yield "score(model, dataset, 3)", lambda: _score_scenario(3)
    for n in (0, -1, 1.5, True, "2", np.int64(2), 10**9):
        yield f"split_measurement(n={n!r})", lambda n=n: testbed.split_measurement(data, n)
    yield "split_measurement(None, 2)", lambda: testbed.split_measurement(None, 2)
    yield "model_summary(None)", lambda: testbed.model_summary(None)
    yield "model_summary(unfitted)", lambda: testbed.model_summary(testbed.IDENTIFIERS.get("ls_sindy")())
    yield "model_summary(model, data=3)", lambda: testbed.model_summary(
        testbed.IDENTIFIERS.get("ls_sindy")().fit(data), 3)
    yield "identify_file(None)", lambda: testbed.identify_file(None)
    yield "identify_file(3)", lambda: testbed.identify_file(3)
    yield "measurement_from_file(None, 'structural')", lambda: testbed.measurement_from_file(
        None, "structural")
    yield "measurement_from_file(kind=3)", lambda: testbed.measurement_from_file("x.csv", 3)
    yield "read_measured(None)", lambda: testbed.read_measured(None)
    yield "read_measured(fs=-1)", lambda: testbed.read_measured("x.csv", fs=-1)
    yield "DatasetCache(3)", lambda: testbed.DatasetCache(3)
    yield "TimeWindows(0)", lambda: testbed.TimeWindows(0)
    yield "TimeWindows(min_window=-1)", lambda: list(testbed.TimeWindows(2, min_window=-1).split(range(4)))
    yield "MeasurementSamples.of(None)", lambda: testbed.MeasurementSamples.of(None)


_MM: dict = {}


def _mm() -> tuple:
    import testbed

    if not _MM:
        sc = testbed.load_scenario("michaelis_menten")
        _MM["sc"], _MM["ds"] = sc, testbed.generate(sc)
    return _MM["sc"], _MM["ds"]


def _measure_kind(kind: str) -> Any:
    import testbed

    sc, ds = _mm()
    return testbed.measure(ds, sc.signal, kind)


def _measure_signal(sig: Any) -> Any:
    import testbed

    _sc, ds = _mm()
    return testbed.measure(ds, sig, "mechanical")


def _score_with(model: Any) -> Any:
    import testbed

    sc, ds = _mm()
    return testbed.score(model, ds, sc)


def _score_scenario(scen: Any) -> Any:
    import testbed

    if "res" not in _MM:
        _MM["res"] = testbed.run_scenario("michaelis_menten", cache=False)
    res = _MM["res"]
    return testbed.score(res.model, res.dataset, scen)


# --- registry ----------------------------------------------------------------------------------

def registry_cases() -> Iterator[Case]:
    import testbed
    from testbed.core.truth import TRUTH_TYPES
    from testbed.pipeline.signal_chain import SIGNAL_CHAINS
    from testbed.scoring.scorers import SCORERS

    kind = next(iter(SCORERS))
    yield "register_scorer twice (another)", lambda: testbed.register_scorer(kind, lambda *a: None)
    yield "register_scorer unknown kind", lambda: testbed.register_scorer("nope", lambda *a: None)
    yield "register_scorer kind 3", lambda: testbed.register_scorer(3, lambda *a: None)
    yield "register_scorer not callable", lambda: _fresh_scorer("not callable")
    ckind = next(iter(SIGNAL_CHAINS))
    chain = SIGNAL_CHAINS[ckind]
    yield "register_signal_chain twice (another)", lambda: testbed.register_signal_chain(
        dataclasses.replace(chain, measure=lambda *a: None) if dataclasses.is_dataclass(chain) else None)
    yield "register_signal_chain(None)", lambda: testbed.register_signal_chain(None)
    yield "register_signal_chain('x')", lambda: testbed.register_signal_chain("x")
    tkind = next(iter(TRUTH_TYPES))
    other = type("OtherTruth", (TRUTH_TYPES[tkind],), {"kind": tkind})
    yield "register_truth twice (another)", lambda: testbed.register_truth(other)
    yield "register_truth(None)", lambda: testbed.register_truth(None)
    yield "register_truth(int)", lambda: testbed.register_truth(int)
    yield "load_plugins('mod')", lambda: _plugins_str()
    yield "load_plugins(['no_such_mod_api16'])", lambda: testbed.load_plugins(["no_such_mod_api16"])
    yield "load_plugins([3])", lambda: testbed.load_plugins([3])
    yield "load_plugins(None)", lambda: testbed.load_plugins(None)
    yield "truth_field(shape=3)", lambda: testbed.truth_field(3, "m", "doc")
    yield "IDENTIFIERS.get('nope')", lambda: testbed.IDENTIFIERS.get("nope")
    yield "IDENTIFIERS.get(3)", lambda: testbed.IDENTIFIERS.get(3)


def _fresh_scorer(scorer: Any) -> Any:
    import testbed
    from testbed.core.kinds import METRICS
    from testbed.scoring.scorers import SCORERS

    free = [k for k in METRICS if k not in SCORERS]
    if not free:
        return None
    try:
        return testbed.register_scorer(free[0], scorer)
    finally:
        SCORERS.pop(free[0], None)


def _plugins_str() -> Any:
    import testbed

    got = testbed.load_plugins("json")  # one module name, not a list: "j", "s", "o", "n"?
    return got


# --- studies and runs --------------------------------------------------------------------------

def studies_cases(work: Path) -> Iterator[Case]:
    import testbed

    study = testbed.load_study("studies/smoke.toml") if Path("studies/smoke.toml").exists() else None
    for jobs in (0, -1, 1.5, "2", True, None, 10**6):
        yield f"run_sweep(jobs={jobs!r})", lambda jobs=jobs: testbed.run_sweep(
            study or "nope", jobs=jobs, results=work / "r.parquet", verbose=False)
    for v in (None, 3, ["a"], {"study": {}}):
        yield f"run_sweep({v!r})", lambda v=v: testbed.run_sweep(v, results=work / "r2.parquet",
                                                                 verbose=False)
        yield f"load_study({v!r})", lambda v=v: testbed.load_study(v)
    yield "run_sweep(results=3)", lambda: testbed.run_sweep(study or "nope", results=3, verbose=False)
    yield "run_sweep(dask_address=3)", lambda: testbed.run_sweep(
        study or "nope", dask_address=3, results=work / "r3.parquet", verbose=False)
    txt = work / "r.txt"
    txt.write_text("not parquet")
    yield "read_results(folder)", lambda: testbed.read_results(work)
    yield "read_results(text file)", lambda: testbed.read_results(txt)
    yield "read_results(missing)", lambda: testbed.read_results(work / "missing.parquet")
    yield "read_results(None)", lambda: testbed.read_results(None)
    yield "read_results(3)", lambda: testbed.read_results(3)
    yield "list_runs(None)", lambda: testbed.list_runs(None)
    yield "list_runs(file)", lambda: testbed.list_runs(txt)
    yield "list_runs(scenario=3)", lambda: testbed.list_runs(work, scenario=3)
    yield "resolve_run(None)", lambda: testbed.resolve_run(None)
    yield "resolve_run('latest', folder)", lambda: testbed.resolve_run("latest", work / "none")
    yield "resolve_run(3)", lambda: testbed.resolve_run(3, work)
    yield "save_new_run(None, dir)", lambda: testbed.save_new_run(None, work / "runs")
    yield "save_new_run('x', dir)", lambda: testbed.save_new_run("x", work / "runs")


def _family(cases: Callable[[], Iterator[Case]], check: Callable[[Any], str | None] = check_fit
            ) -> Callable[[Path], Counter]:
    def run(work: Path) -> Counter:
        return _hostile.run_inprocess(cases(), TIMEOUT_S, check)
    return run


FAMILIES = {
    "measurement": _family(measurement_cases),
    "estimators": _family(estimator_cases),
    "entry": _family(entry_cases),
    "registry": _family(registry_cases, lambda r: None),
    "studies": lambda work: _hostile.run_inprocess(studies_cases(_hostile.subfolder(work, "st")),
                                                   TIMEOUT_S, lambda r: None),
}


def main(argv: list[str]) -> int:
    os.environ.setdefault("MPLBACKEND", "Agg")
    return _hostile.main(argv, FAMILIES, "hostile_api16-")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
