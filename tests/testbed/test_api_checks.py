"""``testbed._api_checks``: the public functions' arguments checked together where they must agree."""

from __future__ import annotations

import numpy as np
import pytest

import testbed
from testbed.core.errors import ArgumentError


def _fitted(dataset_cache, name: str):
    sc = testbed.load_scenario(name)
    ds = dataset_cache.get(sc)
    data = testbed.measure(ds, sc.signal, sc.kind)
    model = testbed.IDENTIFIERS.get("sindy_pi_dynamical")(degree=3).fit(data)
    return sc, ds, model


def test_score_refuses_a_dataset_of_another_scenarios_record(dataset_cache):
    # hostile round 19: the 1 kHz dataset of michaelis_menten_noise1 was scored with the 100 Hz
    # michaelis_menten scenario (its chain and its bars) in silence
    sc, _, model = _fitted(dataset_cache, "michaelis_menten")
    other = dataset_cache.get(testbed.load_scenario("michaelis_menten_noise1"))
    with pytest.raises(ArgumentError, match=r"^score: argument 'dataset': a dataset of scenario "
                                            r"'michaelis_menten_noise1': expected a dataset of "
                                            r"scenario 'michaelis_menten' \(its simulation differs"):
        testbed.score(model, other, sc)
    with pytest.raises(ArgumentError, match="its simulation differs"):
        testbed.score(model, other, "michaelis_menten")  # by name too


def test_score_takes_the_scenarios_own_record_at_any_noise(dataset_cache):
    sc, ds, model = _fitted(dataset_cache, "michaelis_menten")
    assert testbed.score(model, ds, sc).values["coef_error"] < 1e-6
    noisy = dataset_cache.get(sc.with_noise(1.0).replace(seed=3))  # a noisy copy is its record
    assert testbed.score(model, noisy, "michaelis_menten").values.keys() == \
        testbed.score(model, ds, sc).values.keys()


def test_the_api_computes_under_numpys_defaults_whatever_the_caller_set(dataset_cache):
    # hostile round 20: under the caller's np.seterr(all="raise"), run_scenario of the shipped
    # cantilever_stiff_impact_sindy_pi raised a raw FloatingPointError (underflow) where it passes
    sc = testbed.load_scenario("cantilever_stiff_impact_sindy_pi")
    old = np.seterr(all="raise")
    try:
        result = testbed.run_scenario(sc, cache=dataset_cache)
        assert np.geterr()["under"] == "raise"
    finally:
        np.seterr(**old)
    assert result.passed, result.scores.failures
