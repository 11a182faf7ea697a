"""The public Python API: every name of ``testbed.__all__`` resolves, identifiers are scikit-learn
estimators (``clone``, ``get_params``/``set_params`` as a grid search uses them), a fitted model
prints and scores itself (truth-free), and ``testbed.score`` equals what a run scores."""

from __future__ import annotations

import io
import itertools

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.exceptions import NotFittedError
from sklearn.utils.validation import check_is_fitted

import identify
import models
import testbed
from benchmarks import bench_sgd_sindy


def test_every_public_name_resolves_and_import_is_cheap():
    for name in testbed.__all__:
        assert getattr(testbed, name) is not None, name
    assert set(testbed.__all__) <= set(dir(testbed))
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        testbed.nope  # noqa: B018
    for name in identify.__all__:
        assert getattr(identify, name) is not None, name
    assert models.Rig is testbed.Rig
    assert issubclass(testbed.StructuralIdentifier, testbed.Identifier)


def test_a_plugin_rig_of_every_kind_finds_its_truth_type_public():
    """A rig builds its kind's truth dataclass (docs/rigs.md): each registered one is public."""
    from testbed.core.truth import TRUTH_TYPES

    for kind, cls in TRUTH_TYPES.items():
        assert getattr(testbed, cls.__name__, None) is cls and cls.__name__ in testbed.__all__, kind


@pytest.mark.parametrize("name", testbed.IDENTIFIERS.names())
def test_sklearn_clone_and_params(name):
    cls = testbed.IDENTIFIERS.get(name)
    est = cls()
    twin = clone(est)
    assert type(twin) is cls and twin is not est
    assert twin.get_params(deep=False) == est.get_params(deep=False)
    with pytest.raises(NotFittedError):
        check_is_fitted(est)
    # a grid search's loop: set each point's parameters on a clone, read them back
    numeric = [k for k, f in cls.declared_hyperparameters().items()
               if f.type in (int, float) and f.default is not None and not isinstance(f.default, bool)][:2]
    grid = {k: [cls.declared_hyperparameters()[k].default] * 2 for k in numeric}
    for values in itertools.product(*grid.values()):
        point = dict(zip(grid, values, strict=True))
        c = clone(est).set_params(**point)
        assert {k: c.get_params()[k] for k in point} == point
    with pytest.raises(ValueError, match="no hyperparameter 'no_such'"):
        est.set_params(no_such=1)
    # the API round (session 15): the template's checks hold for every identifier, and a clone
    # keeps them (tests/testbed/test_hostile_api16.py has the cases)
    from testbed.core import errors

    with pytest.raises(errors.HyperparameterError, match="no hyperparameter 'no_such'"):
        cls(no_such=1)
    with pytest.raises(errors.ArgumentError, match="expected a Measurement"):
        twin.fit(None)
    with pytest.raises(errors.NotFittedError):
        twin.equations()


@pytest.fixture(scope="module")
def chain_data():
    return bench_sgd_sindy.chain_measurement(bench_sgd_sindy.chain_system(), duration=0.3)


def test_print_and_truth_free_score(chain_data):
    model = testbed.IDENTIFIERS.get("ls_sindy")().fit(chain_data)
    check_is_fitted(model)
    out = io.StringIO()
    model.print(precision=3, file=out)
    lines = out.getvalue().splitlines()
    assert lines == model.equations(3) and len(lines) == chain_data.n_channels
    # exact chain data: measured R^2 1 - 4e-11
    assert model.score(chain_data) > 0.999
    # a wrong model scores worse: with the stiffness 20 % off, R^2 falls to about 0.96
    model.K_ = 1.2 * model.K_
    assert model.score(chain_data) < 0.98


def test_mechanical_models_have_no_explicit_acceleration():
    est = testbed.IDENTIFIERS.get("sindy_pi")()
    with pytest.raises(NotImplementedError, match="structural"):
        est.predict_acceleration(None)


def test_score_equals_the_runs_scores(dataset_cache):
    result = testbed.run_scenario("cantilever_stiff_impact_lsq", cache=dataset_cache)
    again = testbed.score(result.model, result.dataset, "cantilever_stiff_impact_lsq")
    assert again.values.keys() == result.scores.values.keys()
    for k, v in result.scores.values.items():
        assert (np.isnan(v) and np.isnan(again.values[k])) or v == pytest.approx(again.values[k]), k
    with pytest.raises(ValueError, match="not fitted"):
        testbed.score(testbed.IDENTIFIERS.get("ls_sindy")(), result.dataset, result.scenario)
