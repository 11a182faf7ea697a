"""API round (session 15, docs/history.md; ``benchmarks/hostile_api16.py``): a researcher's
mistake through the public Python API is one of the project's errors naming the argument, its
value and what is allowed, never a raw numpy / KeyError / AttributeError / TypeError from
inside, a silent acceptance, or a NaN that looks like a result."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from sklearn.base import clone

import testbed
from benchmarks import bench_sgd_sindy
from testbed.core.errors import (
    ArgumentError,
    HyperparameterError,
    IdentificationError,
    NotFittedError,
    RegistrationError,
    TestbedError,
    UnknownNameError,
    UnsupportedError,
)


@pytest.fixture(scope="module")
def data():
    """An exact 3-DOF record of 0.05 s (640 samples)."""
    return bench_sgd_sindy.chain_measurement(bench_sgd_sindy.chain_system(), duration=0.05)


def one_line(e: pytest.ExceptionInfo, *words: str) -> None:
    assert isinstance(e.value, TestbedError) and "\n" not in str(e.value), str(e.value)
    for w in words:
        assert w in str(e.value), (w, str(e.value))


# --- Measurement: checked where it is made ------------------------------------------------------

@pytest.mark.parametrize(("change", "words"), [
    # were: ValueError from np.concatenate deep in the library
    (lambda d: {"xd": d.xd[:, :-1]}, ("'xd'", "(3, 639)", "(3 x 640)")),
    (lambda d: {"xdd": d.xdd[:2]}, ("'xdd'",)),
    # was: IndexError
    (lambda d: {"x": d.x[0], "xd": d.xd[0], "xdd": d.xdd[0], "channels": ("s1",)}, ("'x'",)),
    # was: ZeroDivisionError
    (lambda d: {"x": d.x[:, :0], "xd": d.x[:, :0], "xdd": d.x[:, :0]}, ("at least one",)),
    # were accepted: a model fitted to the real part, to 0/1, to text converted
    (lambda d: {"x": d.x.astype(complex)}, ("complex128 refused",)),
    (lambda d: {"x": d.x > 0}, ("bool refused",)),
    (lambda d: {"x": d.x.astype(str)}, ("refused",)),
    # were: LinAlgError
    (lambda d: {"xdd": np.where(np.arange(640) == 5, np.nan, d.xdd)}, ("NaN or infinite",)),
    # were: ValueError from the band rule, TypeError, or accepted (True as 1 Hz)
    (lambda d: {"fs": 0.0}, ("'fs'", "> 0")),
    (lambda d: {"fs": float("nan")}, ("'fs'",)),
    (lambda d: {"fs": "12800"}, ("'fs'",)),
    (lambda d: {"fs": True}, ("'fs'",)),
    (lambda d: {"free_start": 1.5}, ("'free_start'", "integer")),
    (lambda d: {"free_start": -1}, ("'free_start'",)),
    # were accepted
    (lambda d: {"channels": "abc"}, ("'channels'",)),
    (lambda d: {"channels": ("a", "a", "b")}, ("distinct",)),
    (lambda d: {"channels": ("a", "b", "c", "d")}, ("3 distinct",)),
    (lambda d: {"integration": "euler"}, ("'integration'", "'trapezoid'")),
    (lambda d: {"input_hold": "hold"}, ("'input_hold'",)),
    (lambda d: {"input_map": np.ones((2, 2))}, ("'input_map'",)),
    (lambda d: {"u": np.ones((1, 640)), "inputs": ("f", "g")}, ("'inputs'", "1 distinct")),
    (lambda d: {"noise_std": -np.ones(3)}, ("'noise_std'", ">= 0")),
    (lambda d: {"prior": {"total_mass": float("nan")}}, ("total_mass", "finite")),
    # were: TypeError / ValueError from the band rule
    (lambda d: {"passband": 5.0}, ("'passband'",)),
    (lambda d: {"passband": (100.0, 10.0)}, ("passband[1]",)),
])
def test_a_malformed_measurement_is_refused_where_it_is_made(data, change, words):
    with pytest.raises(ArgumentError) as e:
        dataclasses.replace(data, **change(data))
    one_line(e, "Measurement: argument", *words)
    assert isinstance(e.value, ValueError)  # as numpy's and scikit-learn's


def test_inputs_may_be_left_unnamed(data):
    # a record built in code may give u without names (the identifiers' own tests do); given,
    # the names must match u's rows (above)
    m = dataclasses.replace(data, u=np.ones((1, data.n_samples)))
    assert m.inputs == () and m.u.shape == (1, data.n_samples)


def test_float32_integer_lists_and_strided_arrays_fit_as_float64(data):
    ref = testbed.IDENTIFIERS.get("ls_sindy")().fit(data)
    strided = np.zeros((3, 2 * data.n_samples))
    strided[:, ::2] = data.x
    for change in ({"x": data.x.astype(np.float32), "xd": data.xd.astype(np.float32),
                    "xdd": data.xdd.astype(np.float32)},
                   {"x": data.x.tolist()}, {"x": strided[:, ::2]}, {"fs": np.int64(12800)}):
        m = dataclasses.replace(data, **change)
        assert m.x.dtype == np.float64 and isinstance(m.fs, float)
        model = testbed.IDENTIFIERS.get("ls_sindy")().fit(m)
        # float32 keeps 7 digits: the stiffness agrees to 1e-3 (measured 1e-6)
        np.testing.assert_allclose(model.K_, ref.K_, rtol=1e-3)


# --- identifiers: the template's checks --------------------------------------------------------

@pytest.mark.parametrize("name", ["ls_sindy", "sindy_pi", "sindy_pi_dynamical", "pysindy"])
def test_fit_on_what_is_not_a_measurement_names_it(name):
    est = testbed.IDENTIFIERS.get(name)()
    for bad in (None, {"x": 1}, np.ones((3, 10)), "data.h5"):  # were AttributeError
        with pytest.raises(ArgumentError) as e:
            est.fit(bad)
        one_line(e, ".fit: argument 'data'", "expected a Measurement")


def test_unknown_hyperparameter_names_the_allowed_ones():
    cls = testbed.IDENTIFIERS.get("ls_sindy")
    with pytest.raises(HyperparameterError) as e:  # was TypeError, naming none
        cls(no_such=1)
    one_line(e, "'no_such'", "allowed: cubic, mass_prior")
    with pytest.raises(HyperparameterError, match="no hyperparameter 'nope'"):
        cls().set_params(nope=1)  # was a plain ValueError


def test_numpy_scalars_and_none_are_checked_not_skipped(data):
    sgd = testbed.IDENTIFIERS.get("sgd_sindy")
    # np.int64(-5) epochs skipped the declaration's check (not a Python int)
    with pytest.raises(HyperparameterError, match="epochs"):
        sgd(epochs=np.int64(-5)).fit(data)
    # None where the default is not None (a bool): skipped, then used as False
    with pytest.raises(HyperparameterError, match="eigen_hold"):
        testbed.IDENTIFIERS.get("ls_sindy")(eigen_hold=None).fit(data)
    # a grid of np.arange values is a grid of numbers: accepted and kept
    est = clone(testbed.IDENTIFIERS.get("ls_sindy")(rcond=np.float64(1e-10)))
    assert est.fit(data).is_fitted()


def test_a_hyperparameter_is_checked_against_the_data_at_fit(data):
    # fit_band_hz above the Nyquist frequency: was a ValueError from inside the band rule
    with pytest.raises(HyperparameterError) as e:
        testbed.IDENTIFIERS.get("ls_sindy")(fit_band_hz=1e9).fit(data)
    one_line(e, "fit_band_hz")


def test_results_before_fit_are_not_fitted_errors(data):
    for name in ("ls_sindy", "sindy_pi", "sindy_pi_linear", "sindy_pi_dynamical"):
        est = testbed.IDENTIFIERS.get(name)()
        # were RuntimeError, AttributeError ('coef_', '_lib') by identifier
        for call in (est.equations, lambda e=est: e.simulate(np.zeros(3), np.zeros(3),
                                                               np.arange(10) / 1e3)):
            with pytest.raises(NotFittedError) as e:
                call()
            one_line(e, "not fitted")
            assert isinstance(e.value, AttributeError) and isinstance(e.value, ValueError)
    with pytest.raises(NotFittedError):
        testbed.IDENTIFIERS.get("ls_sindy")().score(data)
    with pytest.raises(UnsupportedError, match="structural") as e:  # documented: still one
        testbed.IDENTIFIERS.get("sindy_pi")().predict_acceleration(data)
    assert isinstance(e.value, NotImplementedError)


def test_a_fitted_models_methods_check_their_arguments(data):
    model = testbed.IDENTIFIERS.get("ls_sindy")().fit(data)
    two = dataclasses.replace(data, x=data.x[:2], xd=data.xd[:2], xdd=data.xdd[:2],
                              channels=data.channels[:2], input_map=data.input_map[:2])
    with pytest.raises(ArgumentError, match="fitted channels"):  # was a matmul ValueError
        model.score(two)
    with pytest.raises(ArgumentError, match="'x0'"):  # was a reshape ValueError
        model.simulate(np.zeros(2), np.zeros(2), np.arange(10) / 1e3)
    with pytest.raises(ArgumentError, match="'t'"):
        model.simulate(np.zeros(3), np.zeros(3), -np.arange(10) / 1e3)
    for p in (-1, "x", 1.5):  # was "Format specifier missing precision"
        with pytest.raises(ArgumentError, match="precision"):
            model.equations(p)
    with pytest.raises(ArgumentError, match="y must be None"):
        model.score(data, y=np.ones(3))


def test_a_record_without_free_decay_is_refused_by_name(data):
    for start in (data.n_samples - 1, data.n_samples, 10**9):  # were ZeroDivisionError
        with pytest.raises(IdentificationError, match="need at least 4"):
            testbed.IDENTIFIERS.get("ls_sindy")().fit(dataclasses.replace(data, free_start=start))


def test_clone_round_trip_keeps_the_guards(data):
    est = testbed.IDENTIFIERS.get("sgd_sindy")(epochs=3)
    twin = clone(est)
    assert twin.get_params() == est.get_params()
    twin.set_params(epochs=np.int64(-1))
    with pytest.raises(HyperparameterError, match="epochs"):
        twin.fit(data)


# --- public functions: checked where a call enters ---------------------------------------------

@pytest.mark.parametrize(("call", "words"), [
    (lambda: testbed.load_scenario(3), ("load_scenario: argument 'name_or_path'",)),
    (lambda: testbed.run_scenario(None), ("run_scenario: argument 'scenario'",)),
    (lambda: testbed.run_scenario("michaelis_menten", seed=-1), ("'seed'",)),
    (lambda: testbed.run_scenario("michaelis_menten", seed=1.5), ("'seed'",)),
    (lambda: testbed.run_scenario("michaelis_menten", model="ls_sindy"), ("'model'",)),
    (lambda: testbed.run_scenario("michaelis_menten", model=testbed.IDENTIFIERS.get("ls_sindy")),
     ("an instance",)),
    (lambda: testbed.run_scenario("michaelis_menten", cache=3), ("'cache'",)),
    (lambda: testbed.run_scenario("michaelis_menten", progress=1), ("'progress'",)),
    (lambda: testbed.run_scenario("michaelis_menten", no_such=1), ("no_such",)),
    (lambda: testbed.generate("michaelis_menten"), ("generate: argument 'scenario'",)),
    (lambda: testbed.measure(None, {}, "structural"), ("'dataset'",)),
    (lambda: testbed.scenario_from_dict(None), ("'raw'",)),
    (lambda: testbed.split_measurement(None, 2), ("'data'",)),
    (lambda: testbed.model_summary(None), ("'model'",)),
    (lambda: testbed.read_measured(None), ("'path'",)),
    (lambda: testbed.run_sweep("smoke", jobs=0), ("'jobs'",)),
    (lambda: testbed.run_sweep("smoke", jobs="2"), ("'jobs'",)),
    (lambda: testbed.run_sweep("smoke", jobs=10**6), ("'jobs'",)),
    (lambda: testbed.run_sweep(None), ("'study'",)),
    (lambda: testbed.run_sweep("smoke", dask_address=3), ("'dask_address'",)),
    (lambda: testbed.read_results(None), ("'path'",)),
    (lambda: testbed.list_runs(None), ("'out_dir'",)),
    (lambda: testbed.resolve_run(3), ("'source'",)),
    (lambda: testbed.save_new_run("x", "out"), ("'result'",)),
    (lambda: testbed.load_plugins("mymodule"), ("'plugins'",)),
    (lambda: testbed.load_plugins([3]), ("'plugins'",)),
    (lambda: testbed.DatasetCache(3), ("'directory'",)),
    (lambda: testbed.TimeWindows(0), ("'n_splits'",)),
    (lambda: testbed.MeasurementSamples.of(None), ("'data'",)),
])
def test_public_functions_refuse_wrong_arguments_in_one_line(call, words):
    # each was a TypeError, AttributeError or a plain ValueError from inside (or, for a text
    # given to load_plugins, one plugin per letter)
    with pytest.raises(ArgumentError) as e:
        call()
    one_line(e, *words)


def test_numpy_integers_are_integers_at_the_api(data):
    assert len(testbed.split_measurement(data, np.int64(2))) == 2  # was refused


def test_registering_twice_or_wrong_is_a_registration_error():
    from testbed.core.truth import TRUTH_TYPES
    from testbed.pipeline.signal_chain import SIGNAL_CHAINS
    from testbed.scoring.scorers import SCORERS

    with pytest.raises(RegistrationError, match="registered already"):
        testbed.register_scorer("structural", lambda *a: None)
    chain = next(iter(SIGNAL_CHAINS.values()))
    with pytest.raises(RegistrationError, match="registered already"):
        testbed.register_signal_chain(dataclasses.replace(chain, measure=lambda *a: None))
    other = type("OtherTruth", (TRUTH_TYPES["structural"],), {"kind": "structural"})
    with pytest.raises(RegistrationError, match="registered already"):
        testbed.register_truth(other)
    with pytest.raises(RegistrationError, match="not a subclass"):  # was AttributeError
        testbed.register_truth(int)
    with pytest.raises(ArgumentError, match="'kind'"):
        testbed.register_scorer("nope", lambda *a: None)
    with pytest.raises(ArgumentError, match="'chain'"):  # was AttributeError
        testbed.register_signal_chain(None)
    assert "structural" in SCORERS and isinstance(RegistrationError("x"), ValueError)


def test_an_unknown_identifier_is_a_keyerror_and_ours():
    for name in ("nope", 3, ["a"]):  # ["a"]: was TypeError (unhashable)
        with pytest.raises(UnknownNameError) as e:
            testbed.IDENTIFIERS.get(name)
        one_line(e, "unknown identifier", "allowed: ls_sindy")
        assert isinstance(e.value, KeyError)


def test_the_checked_functions_keep_their_signature_and_doc():
    import inspect

    from testbed.scoring import evaluate

    assert inspect.signature(testbed.run_scenario) == inspect.signature(evaluate.run_scenario)
    assert testbed.run_scenario.__doc__ == evaluate.run_scenario.__doc__
