"""Run folders: everything a report needs survives save_run -> load_run, written atomically."""

from __future__ import annotations

import json
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
import _synthetic_runs as synth

from testbed.reporting.figures import save_run_figures
from testbed.studies.runstore import load_run, save_run


@pytest.fixture(scope="module")
def structural():
    return synth.structural_result(n_samples=800)


@pytest.fixture(scope="module")
def mechanical():
    return synth.mechanical_result(n_samples=400)


def test_structural_round_trip(structural, tmp_path):
    r = structural
    run = load_run(save_run(r, tmp_path / "run"))
    assert run.name == "cantilever_synthetic" and run.kind == "structural"
    assert run.scenario == r.scenario.to_dict()
    assert run.scores == pytest.approx(r.scores.values)
    assert [(c.metric, c.bound, c.threshold, c.passed) for c in run.checks] == \
        [(c.metric, c.bound, c.threshold, c.passed) for c in r.checks]
    assert run.passed == r.passed is False
    assert run.fit_time == r.fit_time
    assert run.identifier == "sgd_sindy"
    assert run.meta["identifier"]["params"] == {"learning_rate": 1e-3, "epochs": 40}
    assert run.equations == r.model.equations()
    assert run.meta["dataset"]["hash"] == r.dataset.attrs["content_hash"]
    assert run.meta["dataset"]["signals"]["measured/acceleration"]["unit"] == "m/s^2"
    assert run.meta["commit"] and "numpy" in run.meta["versions"]
    for k, v in r.scores.details.items():
        if k == "channels":
            assert run.details[k] == list(v)
        else:
            np.testing.assert_array_equal(run.details[k], v)
    for k in ("M_", "C_", "K_", "K3_", "natural_frequencies_"):
        np.testing.assert_array_equal(run.model[k], getattr(r.model, k))
    np.testing.assert_array_equal(run.history["alpha"]["freq"], r.model.history_["alpha"]["freq"])
    np.testing.assert_array_equal(run.history["loss"], r.model.history_["loss"])
    np.testing.assert_array_equal(run.truth["sensor_modes"], r.dataset.truth["sensor_modes"])
    assert run.figures == []


def test_mechanical_round_trip_with_figures(mechanical, tmp_path):
    run = load_run(save_run(mechanical, tmp_path / "fb", figures=save_run_figures))
    assert run.kind == "mechanical" and run.passed
    assert run.model["feature_names_"] == mechanical.model.feature_names_
    assert run.details["terms"] == mechanical.scores.details["terms"]
    np.testing.assert_array_equal(run.model["coef_"], mechanical.model.coef_)
    assert run.truth["equation_terms"] == mechanical.dataset.truth["equation_terms"]
    assert [p.name for p in run.figures] == ["joint_angles.png", "coefficients.png"]
    assert all(p.stat().st_size > 10_000 for p in run.figures)
    assert run.history == {}


def test_nonfinite_scores_survive(mechanical, tmp_path):
    scores = replace(mechanical.scores, values={**mechanical.scores.values, "coef_error": float("inf"),
                                                "angle_rmse": float("nan")})
    run = load_run(save_run(replace(mechanical, scores=scores), tmp_path / "r"))
    assert run.scores["coef_error"] == float("inf") and np.isnan(run.scores["angle_rmse"])
    json.loads((tmp_path / "r" / "run.json").read_text())  # still strict JSON


def test_rewrite_replaces_whole_folder(mechanical, tmp_path):
    d = tmp_path / "run"
    save_run(mechanical, d, figures=save_run_figures)
    save_run(replace(mechanical, fit_time=9.0), d)
    run = load_run(d)
    assert run.fit_time == 9.0
    assert not list(d.glob("*.png")), "old figures must not survive into the new run"
    assert [p.name for p in tmp_path.iterdir()] == ["run"], "no temporary folders left"


def test_failed_write_keeps_old_run(mechanical, tmp_path, monkeypatch):
    d = tmp_path / "run"
    save_run(mechanical, d)

    def boom(*a, **k):
        raise RuntimeError("disk full")

    with pytest.raises(RuntimeError, match="disk full"):
        save_run(replace(mechanical, fit_time=5.0), d, figures=boom)
    assert load_run(d).fit_time == mechanical.fit_time
    assert [p.name for p in tmp_path.iterdir()] == ["run"]


def test_load_rejects_other_folders(tmp_path):
    with pytest.raises(FileNotFoundError):
        load_run(tmp_path)
    (tmp_path / "run.json").write_text('{"format": "something-else"}')
    with pytest.raises(ValueError, match="not a sysid-testbed-run"):
        load_run(tmp_path)
