"""scikit-learn's model selection on an identifier: GridSearchCV over ls_sindy's hyperparameter on a
cantilever measurement, cut into time windows, scored by the truth-free R^2 of the accelerations."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from sklearn.base import clone
from sklearn.exceptions import FitFailedWarning
from sklearn.model_selection import GridSearchCV, KFold, TimeSeriesSplit, cross_val_score

import testbed
from testbed.core.measurement import Measurement


@pytest.fixture(scope="module")
def data(dataset_cache):
    """The stiff cantilever's measurement after the signal chain (1 s at 12.8 kHz, 2 sensors)."""
    sc = testbed.load_scenario("cantilever_stiff_impact_lsq")
    ds = dataset_cache.get(sc)
    return testbed.MeasurementSamples.of(testbed.measure(ds, sc.signal, sc.kind))


def test_windows_are_measurements_cut_in_time(data):
    w = data[np.arange(100, 300)]
    assert isinstance(w, Measurement) and w.n_samples == 200 and w.fs == data.fs
    np.testing.assert_array_equal(w.xdd, data.xdd[:, 100:300])
    np.testing.assert_array_equal(w.u, data.u[:, 100:300])
    assert w.drift_basis.shape == (data.drift_basis.shape[0], 200)
    assert w.free_start == max(data.free_start - 100, 0)
    assert data[np.arange(0, 50)].free_start == data.free_start  # 81: after the pulse
    # every other field is the record's: the pass band, the chain's integration, ...
    assert (w.passband, w.integration, w.channels) == (data.passband, "trapezoid", data.channels)
    parts = testbed.split_measurement(data, 4)
    assert sum(p.n_samples for p in parts) == data.n_samples
    np.testing.assert_array_equal(np.concatenate([p.x for p in parts], axis=1), data.x)
    with pytest.raises(ValueError, match="one contiguous run"):
        data[np.array([0, 1, 5])]
    with pytest.raises(ValueError, match="expected an integer >= 1"):
        testbed.split_measurement(data, 0)


def test_time_windows_chain_forward_from_the_start(data):
    splits = list(testbed.TimeWindows(3).split(data))
    assert len(splits) == 3
    for train, test in splits:
        assert train[0] == 0 and test[0] == train[-1] + 1  # fit from the impact, test right after
        assert np.all(np.diff(train) == 1) and np.all(np.diff(test) == 1)
        assert len(test) == data.n_samples // 4 or len(test) == data.n_samples // 4 + 1
    assert splits[-1][1][-1] == data.n_samples - 1
    with pytest.raises(ValueError, match="shorter than min_window"):
        list(testbed.TimeWindows(3, min_window=10**6).split(data))


def test_grid_search_over_rcond_picks_the_full_rank_solve(data):
    cls = testbed.IDENTIFIERS.get("ls_sindy")
    grid = [1e-10, 0.3]  # 0.3 cuts most singular values: an unstable, non-physical model
    search = GridSearchCV(cls(), {"rcond": grid}, cv=testbed.TimeWindows(3), error_score=np.nan)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", FitFailedWarning)  # the rcond=0.3 fits fail, scored NaN
        warnings.simplefilter("ignore", UserWarning)  # "non-finite test scores": the same NaNs
        search.fit(data)
    assert search.best_params_ == {"rcond": 1e-10}
    assert np.all(np.isnan(search.cv_results_["mean_test_score"][1:]))
    # the search's numbers are exactly the loop it stands for: fit on each train window,
    # score the truth-free R^2 on the test window after it
    by_hand = [clone(cls(rcond=1e-10)).fit(data[train]).score(data[test])
               for train, test in testbed.TimeWindows(3).split(data)]
    assert [search.cv_results_[f"split{k}_test_score"][0] for k in range(3)] == by_hand
    # measured: 0.9993 on the window after the first quarter, 0.964 on average
    assert by_hand[0] > 0.99 and search.best_score_ > 0.9
    # the refit is the fit on the whole record
    direct = cls(rcond=1e-10).fit(data)
    np.testing.assert_array_equal(search.best_estimator_.K_, direct.K_)
    assert search.score(data) == direct.score(data)


def test_other_splitters(data):
    cls = testbed.IDENTIFIERS.get("ls_sindy")
    scores = cross_val_score(cls(), data, cv=TimeSeriesSplit(2))
    # R^2 is at most 1 by definition (no tolerance: a larger value is a bug)
    assert scores.shape == (2,) and np.all(np.isfinite(scores)) and np.all(scores <= 1.0)
    # a shuffling splitter would fit on a record with holes: refused in one line
    with pytest.raises(ValueError, match="contiguous"):
        cross_val_score(cls(), data, cv=KFold(3, shuffle=True, random_state=0), error_score="raise")


def test_score_takes_no_targets(data):
    model = testbed.IDENTIFIERS.get("ls_sindy")().fit(data)
    with pytest.raises(ValueError, match="y must be None"):
        model.score(data, np.zeros(3))
