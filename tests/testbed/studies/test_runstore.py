"""Run folders: everything a report needs survives save_run -> load_run, written atomically;
the run history keeps every run (save_new_run), finds the latest, lists and indexes them."""

from __future__ import annotations

import json
import re
import shutil
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/testbed: _synthetic_runs
import _synthetic_runs as synth

from testbed.reporting.figures import save_run_figures
from testbed.reporting.report import runs_index_html
from testbed.studies import runstore
from testbed.studies.runstore import (
    DIGEST,
    LATEST,
    NPZ_DIGEST,
    READ_FORMATS,
    RunStoreError,
    list_runs,
    load_run,
    resolve_run,
    save_new_run,
    save_run,
    scenario_folder,
)


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


@pytest.mark.parametrize(("damage", "fragment"), [
    (lambda m: m.pop("scenario"), "key 'scenario' missing"),
    (lambda m: m.update(scores=[1, 2]), "key 'scores' missing or not a dict"),
    (lambda m: m.update(fit_time="fast"), "key 'fit_time'"),
    (lambda m: m["identifier"].pop("name"), "'identifier.name'"),
    (lambda m: m.update(checks=[{"metric": "trac"}]), "checks[0]"),
])
def test_load_refuses_a_damaged_run_json_naming_the_key(mechanical, tmp_path, damage, fragment):
    # `testbed report` on a run.json without "scenario" was an internal error (KeyError)
    run = save_run(mechanical, tmp_path / "r")
    meta = json.loads((run / "run.json").read_text())
    damage(meta)
    (run / "run.json").write_text(json.dumps(meta))
    with pytest.raises(ValueError, match=re.escape(fragment)):
        load_run(run)


# ----------------------------------------------------------------------------- run history

FIXED = "2026-01-02T03:04:05+00:00"


@pytest.fixture()
def same_second(monkeypatch):
    """Every run made "now" is made in the same second, FIXED."""
    build = runstore.build_meta

    def fixed(result):
        meta = build(result)
        meta["created"] = FIXED
        return meta

    monkeypatch.setattr(runstore, "build_meta", fixed)


def test_history_keeps_every_run_even_in_one_second(structural, tmp_path, same_second):
    out = tmp_path / "runs"
    paths = [save_new_run(replace(structural, fit_time=float(i)), out, index=runs_index_html)
             for i in range(3)]
    seed = structural.scenario.seed
    folder = out / structural.scenario.name
    assert [p.name for p in paths] == [f"20260102T030405Z-s{seed}", f"20260102T030405Z-s{seed}-2",
                                       f"20260102T030405Z-s{seed}-3"]
    assert [load_run(p).fit_time for p in paths] == [0.0, 1.0, 2.0], "no run replaced another"
    assert sorted(p.name for p in folder.iterdir()) == sorted([LATEST] + [p.name for p in paths]), \
        "no temporary folder left"
    assert json.loads((folder / LATEST).read_text())["run"] == paths[-1].name
    rows = list_runs(out)
    assert [r["path"] for r in rows] == paths and {r["seed"] for r in rows} == {seed}
    assert {r["id"] for r in rows} == {p.name for p in paths}


def test_the_tenth_run_of_one_second_is_the_latest(structural, tmp_path, same_second):
    # "-10" sorted before "-2" as text: the pointer kept "-9" and, without it, resolve_run
    # took "-9" for the newest of eleven runs of one seed in one second (review, round 13)
    out = tmp_path / "runs"
    paths = [save_new_run(replace(structural, fit_time=float(i)), out) for i in range(11)]
    folder = out / structural.scenario.name
    assert paths[-1].name.endswith("-11")
    assert json.loads((folder / LATEST).read_text())["run"] == paths[-1].name
    assert [r["path"] for r in list_runs(out)] == paths
    (folder / LATEST).unlink()
    assert resolve_run(folder) == paths[-1]


def test_a_later_seed_is_its_own_run_and_the_latest(structural, tmp_path):
    out = tmp_path / "runs"
    first = save_new_run(structural, out)
    other = replace(structural, scenario=structural.scenario.replace(seed=structural.scenario.seed + 5))
    second = save_new_run(other, out)
    assert second.name.split("-s")[1] == str(other.scenario.seed) and first != second
    assert resolve_run(out / structural.scenario.name) == second
    assert [r["seed"] for r in list_runs(out)] == [structural.scenario.seed, other.scenario.seed]


def test_resolve_run_accepts_what_a_user_means(structural, tmp_path, same_second):
    out = tmp_path / "runs"
    name = structural.scenario.name
    a = save_new_run(structural, out)
    b = save_new_run(structural, out)
    assert resolve_run(a) == a  # a run folder is itself
    assert resolve_run(out / name) == b  # a scenario folder is its latest run
    assert resolve_run(name, out) == b  # so is a bare scenario name
    # a pointer to a run that is gone: the newest run left (by time, then name)
    shutil.rmtree(b)
    assert resolve_run(out / name) == a
    (out / name / LATEST).write_text("{not json")
    assert resolve_run(out / name) == a
    # the layout before run history: a run folder directly in the output folder
    legacy = save_run(structural, out / "legacy_name")
    assert resolve_run(legacy) == legacy and resolve_run("legacy_name", out) == legacy
    assert {r["path"] for r in list_runs(out)} == {a, legacy}
    for bad in (tmp_path / "missing", "no_such_scenario", tmp_path):
        with pytest.raises(RunStoreError, match="not a run folder"):
            resolve_run(bad, out)


def test_history_stays_inside_the_output_folder(structural, tmp_path):
    out = tmp_path / "runs"
    for bad in ("..", ".", "a/b", ".hidden"):
        with pytest.raises(RunStoreError):
            scenario_folder(out, bad)
    out.mkdir()
    (out / structural.scenario.name).write_text("a file, not a folder of runs")
    with pytest.raises(RunStoreError, match="not a folder of runs"):
        save_new_run(structural, out)
    assert (out / structural.scenario.name).read_text() == "a file, not a folder of runs"


def _save_one(args):
    result, out, i = args
    return save_new_run(replace(result, fit_time=float(i)), out, index=runs_index_html)


def test_concurrent_processes_each_keep_their_run(structural, tmp_path, same_second):
    """Four processes save a run of one scenario and seed in the same second: four folders."""
    import multiprocessing

    out = tmp_path / "runs"
    with multiprocessing.get_context("fork").Pool(4) as pool:  # fork: keeps the patched clock
        paths = pool.map(_save_one, [(structural, out, i) for i in range(4)])
    assert len(set(paths)) == 4
    assert sorted(load_run(p).fit_time for p in paths) == [0.0, 1.0, 2.0, 3.0]
    assert len(list_runs(out)) == 4
    index = (out / "index.html").read_text()
    assert index.count("<tr>") == 1 + 4, "the index written last lists every run"
    assert json.loads((out / structural.scenario.name / LATEST).read_text())["run"] in \
        {p.name for p in paths}
    assert not [p for p in (out / structural.scenario.name).iterdir() if p.name.startswith(".")]


def test_index_page_links_every_run_and_is_self_contained(structural, mechanical, tmp_path):
    out = tmp_path / "runs"
    save_new_run(structural, out, figures=save_run_figures)
    save_new_run(mechanical, out, index=runs_index_html)
    page = (out / "index.html").read_text()
    assert page.count("<tr>") == 1 + 2 and "default-src 'none'" in page
    assert "http://" not in page and "https://" not in page and "<script" not in page
    hrefs = [h for h in re.findall(r'href="([^"]+)"', page)]
    assert len(hrefs) == 2 and all((out / h).is_file() for h in hrefs), hrefs
    for r in list_runs(out):
        assert r["scenario"] in page and r["id"] in page and r["verdict"] in page
    # newest first
    first, second = (page.index(r["id"]) for r in list_runs(out))
    assert second < first


def test_index_says_why_a_run_failed(structural, tmp_path):
    from testbed.scoring.scorers import failed_scores

    failed = replace(structural, scores=failed_scores(structural.scenario.kind,
                                                      "fit failed: the Gram matrix is singular"))
    save_new_run(failed, tmp_path, index=runs_index_html)
    (row,) = list_runs(tmp_path)
    assert row["verdict"] == "FAIL" and row["failure"] == "fit failed: the Gram matrix is singular"
    page = (tmp_path / "index.html").read_text()
    assert "fit failed: the Gram matrix is singular" in page and "badge fail" in page


def test_a_run_json_edited_to_pass_over_a_nan_is_listed_as_failed(structural, tmp_path):
    # the listing (testbed runs, the index page) read the stored verdict: a run.json edited to
    # say "pass" over a NaN check value was listed PASS; it is judged again from the values
    path = save_new_run(structural, tmp_path)
    meta = json.loads((path / "run.json").read_text())
    # a run of format /1 (no checksums, read as written): a /2 run edited so is refused as
    # damaged (test_hostile16), the re-judging below still guards the /1 runs
    meta.update(format=READ_FORMATS[0])
    meta.pop(DIGEST), meta.pop(NPZ_DIGEST)
    check = {"metric": "trac", "value": 0.97, "bound": "min", "threshold": 0.9, "passed": True}
    for value, expected in ((0.97, "pass"), (None, "FAIL")):  # NaN is stored as null
        meta.update(checks=[{**check, "value": value}], verdict="pass", passed=True, failures={})
        (path / "run.json").write_text(json.dumps(meta))
        (row,) = list_runs(tmp_path)
        assert row["verdict"] == expected and row["checks"][0]["passed"] == (expected == "pass")
        assert load_run(path).passed == (expected == "pass")


def test_a_users_own_index_page_is_refused_before_any_run_is_written(structural, tmp_path):
    # review 28b: `testbed run --out D` replaced a user's own D/index.html with the runs index
    from testbed.core.errors import InputError

    (tmp_path / "index.html").write_text("<p>my own site</p>\n")
    with pytest.raises(InputError, match=r"index\.html: exists and is not an HTML report"):
        save_new_run(structural, tmp_path, index=runs_index_html)
    assert (tmp_path / "index.html").read_text() == "<p>my own site</p>\n"
    assert not (tmp_path / structural.scenario.name).exists()
    # its own earlier index is replaced as before
    (tmp_path / "index.html").unlink()
    save_new_run(structural, tmp_path, index=runs_index_html)
    save_new_run(structural, tmp_path, index=runs_index_html)
    assert len(list_runs(tmp_path)) == 2
