"""Sweeps: the same rows sequentially, with loky and on a Dask cluster; kill and resume; failures.

The cells run a toy rig and toy identifiers (registered by a plugin file the
study names, so worker processes and a ``testbed sweep`` subprocess know them
too), fast and deterministic, independent of the real rigs being written.
"""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from testbed.studies.results import parts_dir, read_results
from testbed.studies.statistics import failure_kind
from testbed.studies.study import load_study
from testbed.studies.sweep import (
    SweepStats,
    cell_key,
    expand,
    release_freed_memory,
    run_cell,
    run_sweep,
    sweep_provenance,
)

ROOT = Path(__file__).resolve().parents[3]

# A "mechanical" toy: four undamped oscillators th_i'' = -w_i^2 th_i (what measure_mechanical
# expects: theta, dtheta, ddtheta 4 x n, torque 2 x n).  The identifier fits k_i by least
# squares of ddth_i on th_i; noise on theta and ddtheta makes the scores depend on the seed.
TOYS = '''
import time
from pathlib import Path
import numpy as np
from identify import IDENTIFIERS
from identify._base import Identifier
from models import RIGS
from models._base import Rig
from testbed.core.dataset import Dataset, Signal
from testbed.core.measurement import Trajectory
from testbed.core.schema import Field

NAMES = ["th1", "ddth1", "th2", "ddth2", "th3", "ddth3", "th4", "ddth4"]


@RIGS.register("toy_osc")
class ToyOscillators(Rig):
    kind = "mechanical"
    rig_schema = {"omega": Field(float, 3.0, min=0.1)}
    simulation_schema = {"n_samples": Field(int, 400, min=10), "fs": Field(float, 100.0)}
    excitation_schemas = {"none": {}}
    default_excitation = "none"
    measured_signals = ("theta", "dtheta", "ddtheta", "torque")
    noisy_signals = ("theta", "ddtheta")

    def simulate(self, progress=None):
        sc = self.scenario
        n, fs = sc.simulation["n_samples"], sc.simulation["fs"]
        w = sc.rig_params["omega"] * np.arange(1, 5)[:, None]
        t = np.arange(n) / fs
        th = np.sin(w * t + 0.3)
        ch = ("th1", "th2", "th3", "th4")
        measured = {"theta": Signal(th, ch, "rad"), "dtheta": Signal(w * np.cos(w * t + 0.3), ch, "rad/s"),
                    "ddtheta": Signal(-w**2 * th, ch, "rad/s^2"),
                    "torque": Signal(np.zeros((2, n)), ("u1", "u2"), "N m",
                                          acts_on=("th1", "th4"))}
        coef = np.zeros((4, 8))
        for i in range(4):
            coef[i, 2 * i], coef[i, 2 * i + 1] = w[i, 0] ** 2, 1.0
        return Dataset(fs, measured, truth={"equation_terms": NAMES, "equation_coef": coef})


class ToyFit(Identifier):
    kind = "mechanical"
    fail = ""

    def __init__(self, delay: float = 0.0, scale: float = 1.0):
        self.delay, self.scale = delay, scale

    def fit(self, data):
        if not Path(__file__).with_name("no_delay").exists():  # (a test's marker: no sleep)
            time.sleep(self.delay)
        if self.fail == "raise":
            raise ValueError("toy identifier told to fail")
        x, xdd = data.x, data.xdd
        k = -np.sum(x * xdd, axis=1) / np.sum(x * x, axis=1) * self.scale
        if self.fail == "nan":
            k = k * np.nan
        self.k_ = k
        self.feature_names_ = NAMES
        coef = np.zeros((4, 8))
        for i in range(4):
            coef[i, 2 * i], coef[i, 2 * i + 1] = k[i], 1.0
        if self.fail == "noterm":  # equations without the truth's largest term: coef_error inf
            coef[:, ::2] = 0.0
        self.coef_ = coef
        return self

    def simulate(self, x0, xd0, t, u=None):
        w = np.sqrt(np.abs(self.k_))[:, None]
        x = x0[:, None] * np.cos(w * t) + (xd0[:, None] / w) * np.sin(w * t)
        xd = -x0[:, None] * w * np.sin(w * t) + xd0[:, None] * np.cos(w * t)
        return Trajectory(x, xd, -w**2 * x)

    def equations(self, precision=4):
        return [f"ddth{i + 1} = {-k:.{precision}g} th{i + 1}" for i, k in enumerate(self.k_)]


IDENTIFIERS.register("toy_fit")(ToyFit)


@IDENTIFIERS.register("toy_det")
class ToyDeterministic(ToyFit):
    """Declares its fit deterministic; counts its fits (in this process)."""
    deterministic = True
    fits = []

    def fit(self, data):
        type(self).fits.append(data.n_samples)
        return super().fit(data)


@IDENTIFIERS.register("toy_flaky")
class ToyFlaky(ToyDeterministic):
    """Deterministic, but its first fit in a process fails for a passing reason."""
    deterministic = True
    fits = []

    def fit(self, data):
        if not type(self).fits:
            type(self).fits.append(-1)
            raise MemoryError("a passing shortage")
        return super().fit(data)


@IDENTIFIERS.register("toy_inherits")
class ToyInherits(ToyDeterministic):
    """Derives from a deterministic identifier without declaring it itself."""
    fits = []


@IDENTIFIERS.register("toy_raise")
class ToyRaise(ToyFit):
    fail = "raise"


@IDENTIFIERS.register("toy_nan")
class ToyNaN(ToyFit):
    fail = "nan"


@IDENTIFIERS.register("toy_noterm")
class ToyNoTerm(ToyFit):
    fail = "noterm"
'''

SCENARIO = """
[scenario]
name = "{name}"
rig = "toy_osc"
[simulation]
n_samples = 400
[score]
angle_rmse_max = 0.05
"""

# Columns that legitimately differ between two runs of the same cell.
TIMING = ("fit_time", "data_time", "cell_time")


@pytest.fixture(scope="module")
def toy_dir(tmp_path_factory) -> Path:
    """One folder (one plugin path, so one registration per process) for the module's studies."""
    d = tmp_path_factory.mktemp("toys")
    (d / "toys.py").write_text(TOYS)
    for name in ("toy_a", "toy_b"):
        (d / f"{name}.toml").write_text(SCENARIO.format(name=name))
    return d


def write_study(d: Path, name: str, identifiers: list[str], *, seeds=(0, 1), noise=(0.0, 2.0),
                scenarios=("toy_a.toml",), params: dict | None = None) -> Path:
    lines = ["[study]", f'name = "{name}"', f"scenarios = {json.dumps(list(scenarios))}",
             f"noise = {json.dumps(list(noise))}", f"seeds = {json.dumps(list(seeds))}",
             f"identifiers = {json.dumps(identifiers)}", 'plugins = ["toys.py"]']
    for ident, p in (params or {}).items():
        lines.append(f"[identifiers.{ident}]")
        lines += [f"{k} = {json.dumps(v)}" for k, v in p.items()]
    path = d / f"{name}.toml"
    path.write_text("\n".join(lines) + "\n")
    return path


def comparable(rows: list[dict], leave_out: tuple[str, ...] = ()) -> list[dict]:
    """Rows without the timing columns (and ``leave_out``), NaN made comparable."""
    out = []
    for r in rows:
        out.append({k: ("nan" if isinstance(v, float) and math.isnan(v) else v)
                    for k, v in r.items() if k not in TIMING + leave_out})
    return sorted(out, key=lambda r: r["cell"])


def test_expand_cells_and_keys(toy_dir):
    study = load_study(write_study(toy_dir, "grid", ["toy_fit", "toy_nan"], scenarios=("toy_a.toml",
                                                                                       "toy_b.toml")))
    cells = expand(study)
    assert len(cells) == study.n_cells() == 2 * 2 * 2 * 2
    assert len({c.key for c in cells}) == len(cells)
    c = cells[0]
    assert c.scenario.identify == {"method": c.identifier, **c.params}
    assert c.scenario.noise["rms_percent"] == c.noise and c.scenario.seed == c.seed
    # stable: the same cell of a reloaded study has the same key; hyperparameters change it
    assert cell_key(expand(load_study(study.path))[0].scenario) == c.key
    other = c.scenario.replace(identify={"method": "toy_fit", "delay": 0.0, "scale": 2.0})
    assert cell_key(other) != c.key


@pytest.mark.slow
def test_sequential_loky_dask_give_identical_rows(toy_dir, tmp_path):
    from distributed import LocalCluster

    study = load_study(write_study(toy_dir, "same", ["toy_fit"], seeds=(0, 1, 2)))
    cache = tmp_path / "cache"
    seq = read_results(run_sweep(study, jobs=1, results=tmp_path / "seq.parquet", cache_dir=cache,
                                 verbose=False))
    loky = read_results(run_sweep(study, jobs=2, results=tmp_path / "loky.parquet", cache_dir=cache,
                                  verbose=False))
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None) as cl:
        dask = read_results(run_sweep(study, dask_address=cl.scheduler_address,
                                      results=tmp_path / "dask.parquet", cache_dir=cache, verbose=False))
    assert len(seq) == study.n_cells() == 6
    assert all(r["status"] == "ok" for r in seq), [r["error"] for r in seq]
    assert comparable(seq) == comparable(loky) == comparable(dask)
    # noise and seed reach the data: three seeds give three errors at 2 % noise, one at 0 %
    # (angle_rmse: the toy's k fitted on noisy data drives its simulation off the clean angles)
    assert len({r["angle_rmse"] for r in seq if r["noise"] == 2.0}) == 3
    assert len({r["angle_rmse"] for r in seq if r["noise"] == 0.0}) == 1
    assert {r["passed"] for r in seq if r["noise"] == 0.0} == {True}


@pytest.mark.parametrize("path", ["loky", "dask"])
def test_every_row_of_a_sweep_records_the_main_process_commit(toy_dir, tmp_path, monkeypatch, path):
    # Each process caches the commit git gave it the first time it asked: a loky worker started
    # after a commit (or after the tree turned dirty, or whose `git status` ran past its 5 s
    # timeout under load) wrote another `commit` into its rows than the cells run in the main
    # process, so the sequential, loky and Dask rows of one cell differed (the full suite's
    # flaky failure of test_sequential_loky_dask_give_identical_rows whenever a commit landed
    # while it ran).  The sweep's main process decides the provenance once; here it sees a
    # commit and versions no worker process could find by itself.
    from distributed import LocalCluster

    import testbed.studies.sweep as sw

    monkeypatch.setattr(sw, "git_commit", lambda: "commit-of-the-sweep's-main-process")
    monkeypatch.setattr(sw, "versions", lambda: {"numpy": "as-the-main-process-sees-it"})
    study = load_study(write_study(toy_dir, f"stamp_{path}", ["toy_fit"], seeds=(0, 1), noise=(0.0,)))
    kw = dict(results=tmp_path / "r.parquet", cache_dir=tmp_path / "c", verbose=False)
    if path == "loky":
        rows = read_results(run_sweep(study, jobs=2, **kw))
    else:
        with LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                          dashboard_address=None) as cl:
            rows = read_results(run_sweep(study, dask_address=cl.scheduler_address, **kw))
    assert len(rows) == 2 and all(r["status"] == "ok" for r in rows)
    assert {r["commit"] for r in rows} == {"commit-of-the-sweep's-main-process"}
    assert {r["versions"] for r in rows} == {'{"numpy": "as-the-main-process-sees-it"}'}


def test_failing_cells_are_recorded_and_the_rest_goes_on(toy_dir, tmp_path):
    study = load_study(write_study(toy_dir, "fails", ["toy_fit", "toy_raise", "toy_nan"], seeds=(0,),
                                   noise=(1.0,)))
    rows = read_results(run_sweep(study, results=tmp_path / "r.parquet", cache_dir=tmp_path / "c",
                                  verbose=False))
    by = {r["identifier"]: r for r in rows}
    assert len(rows) == 3
    assert by["toy_fit"]["status"] == "ok" and by["toy_fit"]["error"] == ""
    assert by["toy_raise"]["status"] == "failed"
    # a plugin identifier raising in fit: the user's code failing on these data, a scored
    # failure naming the identifier and its file (testbed.pipeline.fit.fit_or_fail)
    assert by["toy_raise"]["error"].startswith("fit failed: identifier toy_raise (from file ")
    assert "toys.py) raised ValueError: toy identifier told to fail" in by["toy_raise"]["error"]
    assert by["toy_raise"]["fit_time"] >= 0.0 and by["toy_raise"]["dataset_hash"]
    # its scores are undefined because the fit failed, which its reason says: not listed again
    # as "non-finite scores" (round 24: some 40 names after "fit failed", and the summary
    # counted the cell under both kinds)
    assert "non-finite scores" not in by["toy_raise"]["error"]
    assert failure_kind(by["toy_raise"]["error"]) == ["fit failed"]
    assert by["toy_nan"]["status"] == "failed" and "non-finite scores" in by["toy_nan"]["error"]
    assert "angle_rmse" in by["toy_nan"]["error"]
    assert not by["toy_raise"]["passed"] and not by["toy_nan"]["passed"]
    # failed cells are finished: a rerun runs nothing (rows unchanged, timings included) ...
    stats = SweepStats()
    rerun = read_results(run_sweep(study, results=tmp_path / "r.parquet", cache_dir=tmp_path / "c",
                                   verbose=False, stats=stats))
    assert stats.run == 0 and [r["cell_time"] for r in rerun] == [r["cell_time"] for r in rows]
    # ... unless asked to retry them: the two failed cells run again, with the same outcome
    again = read_results(run_sweep(study, results=tmp_path / "r.parquet", cache_dir=tmp_path / "c",
                                   retry_failed=True, verbose=False, stats=stats))
    assert (stats.run, stats.failed) == (2, 2)
    assert comparable(again) == comparable(rows)


def test_an_infinite_reported_score_does_not_fail_a_cell_judged_on_finite_held_ones(toy_dir, tmp_path):
    # the five-bar's coef_error is infinite by definition when the identified row lacks the
    # truth's largest term; the cell was "failed" and passed at once, and its held scores were
    # left out of the summary's medians
    study = load_study(write_study(toy_dir, "noterm", ["toy_noterm", "toy_nan"], seeds=(0,),
                                   noise=(0.0,)))
    rows = read_results(run_sweep(study, results=tmp_path / "r.parquet", cache_dir=tmp_path / "c",
                                  verbose=False))
    by = {r["identifier"]: r for r in rows}
    assert by["toy_noterm"]["coef_error"] == math.inf and by["toy_noterm"]["passed"]
    assert by["toy_noterm"]["status"] == "ok" and by["toy_noterm"]["error"] == ""
    # a non-finite held score still fails the cell, and names itself
    assert by["toy_nan"]["status"] == "failed" and "angle_rmse" in by["toy_nan"]["error"]
    assert not by["toy_nan"]["passed"]


def _resident_bytes() -> int:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="glibc malloc_trim, /proc")
def test_a_worker_hands_freed_heap_back_so_loky_sees_no_leak():
    # 190 MB in 64 kB blocks (below glibc's 128 kB mmap threshold: heap, not mmap), one in 50
    # kept alive so the freed pages sit between live blocks and cannot be returned by shrinking
    # the heap's top.  Freed, they stay resident (what loky took for a leak in family sweeps)
    # until released: then at least 150 MB of the 186 MB freed must leave (pages holding a live
    # block or allocator metadata stay).
    blocks = [bytearray(64_000) for _ in range(3000)]
    keep = blocks[::50]
    del blocks
    before = _resident_bytes()
    if not release_freed_memory():
        pytest.skip("no malloc_trim in this C library")
    assert before - _resident_bytes() > 150e6
    assert len(keep) == 60


def test_rerun_after_editing_the_study_runs_only_new_cells(toy_dir, tmp_path):
    res, cache = tmp_path / "r.parquet", tmp_path / "c"
    first = read_results(run_sweep(load_study(write_study(toy_dir, "edit", ["toy_fit"], seeds=(0,))),
                                   results=res, cache_dir=cache, verbose=False))
    grown = load_study(write_study(toy_dir, "edit", ["toy_fit"], seeds=(0, 1)))
    second = read_results(run_sweep(grown, results=res, cache_dir=cache, verbose=False))
    assert len(first) == 2 and len(second) == 4
    kept = {r["cell"]: r for r in second}
    for r in first:  # the old rows are kept as they were, timings included (not rerun)
        assert kept[r["cell"]]["cell_time"] == r["cell_time"]
    shrunk = load_study(write_study(toy_dir, "edit", ["toy_fit"], seeds=(1,)))
    third = read_results(run_sweep(shrunk, results=res, cache_dir=cache, verbose=False))
    assert {r["seed"] for r in third} == {1} and len(third) == 2


def test_cells_at_zero_noise_of_a_deterministic_identifier_are_fitted_once(toy_dir, tmp_path):
    """The seed draws only the noise: at 0 % the seeds' cells are one computation, fitted once;
    each copy is the row fitting it gives (its own dataset hash included), on a resume too."""
    from identify import IDENTIFIERS

    res, cache = tmp_path / "r.parquet", tmp_path / "c"
    study = load_study(write_study(toy_dir, "det", ["toy_det", "toy_fit"], seeds=(0, 1, 2)))
    fits = IDENTIFIERS.get("toy_det").fits
    fits.clear()
    stats = SweepStats()
    rows = read_results(run_sweep(study, results=res, cache_dir=cache, verbose=False, stats=stats))
    assert len(rows) == 12 and stats.run == 12
    # toy_det: 1 fit at 0 % + 3 at 2 %; toy_fit (undeclared, a plugin's default) fits every cell
    assert stats.copied == 2 and len(fits) == 4
    # each row equals the row of the cell run alone
    cells = {c.key: c for c in expand(study)}
    alone = [run_cell(cells[r["cell"]], str(cache), study.plugins, provenance=sweep_provenance())
             for r in rows]
    assert comparable(rows) == comparable(alone)
    zero = [r for r in rows if r["identifier"] == "toy_det" and r["noise"] == 0.0]
    assert len({r["dataset_hash"] for r in zero}) == 3  # each seed's own dataset (its seed attr)
    # a resume after seeds were added copies the finished row: no new fit at 0 %
    fits.clear()
    grown = load_study(write_study(toy_dir, "det", ["toy_det", "toy_fit"], seeds=(0, 1, 2, 3)))
    again = read_results(run_sweep(grown, results=res, cache_dir=cache, verbose=False, stats=stats))
    assert len(again) == 16 and stats.run == 4 and stats.copied == 1 and len(fits) == 1


def test_a_failed_row_or_another_commit_s_row_is_not_copied(toy_dir, tmp_path, monkeypatch):
    """Only a row that passed through the fit (``ok``), computed by this sweep's commit and
    versions, is copied; a subclass does not inherit ``deterministic``."""
    import testbed.studies.sweep as sw
    from identify import IDENTIFIERS

    stats = SweepStats()
    study = load_study(write_study(toy_dir, "flaky", ["toy_flaky"], seeds=(0, 1, 2), noise=(0.0,)))
    flaky = IDENTIFIERS.get("toy_flaky").fits  # (registered by the study's plugin)
    flaky.clear()
    rows = read_results(run_sweep(study, results=tmp_path / "f.parquet", cache_dir=tmp_path / "c",
                                  verbose=False, stats=stats))
    # the first fit failed (MemoryError); the other two seeds were fitted, not handed its failure
    assert sorted(r["status"] for r in rows) == ["failed", "ok", "ok"] and stats.copied == 0
    study = load_study(write_study(toy_dir, "inh", ["toy_inherits"], seeds=(0, 1), noise=(0.0,)))
    inherits = IDENTIFIERS.get("toy_inherits").fits
    inherits.clear()
    run_sweep(study, results=tmp_path / "i.parquet", cache_dir=tmp_path / "c", verbose=False,
              stats=stats)
    assert stats.copied == 0 and len(inherits) == 2
    # a resume by other code computes the added seed instead of copying the old code's row
    res = tmp_path / "d.parquet"
    monkeypatch.setattr(sw, "git_commit", lambda: "old-commit")
    run_sweep(load_study(write_study(toy_dir, "code", ["toy_det"], seeds=(0,), noise=(0.0,))),
              results=res, cache_dir=tmp_path / "c", verbose=False)
    det = IDENTIFIERS.get("toy_det").fits
    monkeypatch.setattr(sw, "git_commit", lambda: "new-commit")
    det.clear()
    rows = read_results(run_sweep(load_study(write_study(toy_dir, "code", ["toy_det"], seeds=(0, 1),
                                                         noise=(0.0,))),
                                  results=res, cache_dir=tmp_path / "c", verbose=False, stats=stats))
    assert stats.copied == 0 and len(det) == 1
    assert {r["seed"]: r["commit"] for r in rows} == {0: "old-commit", 1: "new-commit"}


def _finished_cells(results: Path) -> int:
    return len(list(parts_dir(results).glob("*.json"))) if parts_dir(results).is_dir() else 0


@pytest.mark.slow
def test_killed_sweep_resumes_without_losing_or_duplicating_cells(toy_dir, tmp_path):
    """SIGKILL a `testbed sweep` subprocess after some cells, rerun; compare with an unbroken run."""
    # 12 cells of 0.4 s each; the toy data take milliseconds, so the fit sleep dominates
    study_path = write_study(toy_dir, "killme", ["toy_fit"], seeds=(0, 1, 2), noise=(0.0, 1.0),
                             scenarios=("toy_a.toml", "toy_b.toml"), params={"toy_fit": {"delay": 0.4}})
    res, cache = tmp_path / "killed.parquet", tmp_path / "cache"
    cmd = [sys.executable, "-m", "testbed.cli", "sweep", str(study_path), "--results", str(res),
           "--cache", str(cache)]
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    proc = subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 60
    while _finished_cells(res) < 3 and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    proc.send_signal(signal.SIGKILL)
    proc.wait(timeout=30)
    n_before = _finished_cells(res)
    assert 3 <= n_before < 12, proc.stderr.read().decode()
    assert not res.exists()  # killed before consolidating
    partial = read_results(res)
    assert len(partial) == n_before

    # the delay is for the kill only: the resumed and the unbroken sweeps fit without it (9 and
    # 12 more sleeps of 0.4 s, 6 s of a test worker's wall time idle); a marker file next to the
    # plugin, not the study (the cells' keys) nor the environment (loky's reused workers)
    no_delay = toy_dir / "no_delay"
    no_delay.touch()
    try:
        out = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)
        whole = read_results(run_sweep(study_path, jobs=2, results=tmp_path / "whole.parquet",
                                       cache_dir=cache, verbose=False))
    finally:
        no_delay.unlink()
    assert out.returncode == 0, out.stderr
    assert f"{n_before} already done, {12 - n_before} to run" in out.stderr
    resumed = read_results(res)
    assert not parts_dir(res).exists()
    keys = [r["cell"] for r in resumed]
    assert len(keys) == len(set(keys)) == 12
    for r in partial:  # finished cells were not rerun
        assert next(x for x in resumed if x["cell"] == r["cell"])["cell_time"] == r["cell_time"]

    # `commit` left out: three sweeps in three processes (killed, resumed, this one), each
    # recording the commit it saw; a commit made while the suite runs changes it between them
    assert comparable(resumed, ("commit",)) == comparable(whole, ("commit",))
    assert len({r["commit"] for r in whole}) == 1  # within one sweep: one commit


def test_cli_summary_of_a_sweep(toy_dir, tmp_path, capsys):
    from testbed.cli import main

    study = write_study(toy_dir, "cli", ["toy_fit", "toy_raise"], seeds=(0,), noise=(0.0,))
    res = tmp_path / "cli.parquet"
    # toy_raise fails its cell: the sweep writes every row, then exits with status 1
    assert main(["sweep", str(study), "--results", str(res), "--cache", str(tmp_path / "c")]) == 1
    assert len(read_results(res)) == 2
    assert main(["summary", str(res)]) == 0
    out = capsys.readouterr().out
    assert "toy_fit" in out and "toy_raise" in out and "told to fail" in out
    bad = toy_dir / "bad.toml"
    bad.write_text(textwrap.dedent("""
        [study]
        name = "bad"
        scenarios = ["toy_a.toml"]
        noise = [-1.0]
        seeds = [0]
        identifiers = ["toy_fit"]
        plugins = ["toys.py"]
    """))
    assert main(["sweep", str(bad)]) == 2
    err = capsys.readouterr().err
    assert "key 'study.noise[0]'" in err and "-1.0" in err


@pytest.mark.slow
def test_smoke_study_on_the_real_rigs(tmp_path, dataset_cache):
    """studies/smoke.toml end to end: one row per cell, each rig kind with its own scores."""
    from testbed.core.kinds import metric_names

    study = load_study("smoke")
    # The shared test cache: the smoke cells' clean records are those of the shipped scenarios
    # (cantilever_stiff_impact, fivebar_multisine) that test_scored and the rig tests use; a
    # private cache simulated both again on every run (11 s of CPU).  A sweep's simulation on a
    # cache miss is tested on the toy rigs above and in test_faults.
    rows = read_results(run_sweep(study, results=tmp_path / "smoke.parquet",
                                  cache_dir=dataset_cache.directory, verbose=False))
    assert sorted(r["cell"] for r in rows) == sorted(c.key for c in expand(study))
    for r in rows:
        assert r["status"] in ("ok", "failed") and (r["status"] == "ok") == (r["error"] == "")
        assert r["dataset_hash"] and json.loads(r["versions"])["numpy"] != "not installed"
        kind = "structural" if r["rig"] == "cantilever" else "mechanical"
        other = metric_names("mechanical" if kind == "structural" else "structural")
        assert all(math.isnan(r[m]) for m in other if m in r)  # no score of the other kind
        if r["status"] == "ok":
            # the cubic scores are NaN without a cubic truth (a stiff base)
            cubic = ("K3_force_error", "K3_accel_error")
            assert all(math.isfinite(r[m]) for m in metric_names(kind) if m in r and m not in cubic)


def test_a_copied_row_of_a_real_identifier_is_the_row_computing_it_gives(tmp_path, dataset_cache):
    """The 0 % seeds' rows of built-in identifiers on both real rigs: fitted once in a loky
    worker and copied, each equal, column for column, to its cell computed alone in this process
    (the conformance test compares only the fitted matrices or coefficients, in one process)."""
    path = tmp_path / "copied.toml"
    path.write_text('[study]\nname = "copied"\nscenarios = ["cantilever_stiff_impact", '
                    '"fivebar_multisine"]\nnoise = [0.0]\nseeds = [0, 1]\n'
                    'identifiers = ["ls_sindy", "sindy_pi"]\n')
    study = load_study(path)
    stats = SweepStats()
    rows = read_results(run_sweep(study, jobs=2, results=tmp_path / "r.parquet",
                                  cache_dir=dataset_cache.directory, verbose=False, stats=stats))
    assert stats.copied == 2 and all(r["status"] == "ok" for r in rows)
    cells = {c.key: c for c in expand(study)}
    copied = sorted((r for r in rows if r["seed"] == 1), key=lambda r: r["cell"])
    # alone under the sweep's own BLAS setting (its loky workers run one thread: with several,
    # the kernel's summation order moves the last bits of a fit, copied or not)
    from threadpoolctl import threadpool_limits

    with threadpool_limits(1):
        alone = [run_cell(cells[r["cell"]], str(dataset_cache.directory), study.plugins,
                          provenance=sweep_provenance()) for r in copied]
    # (the results file gives every row every score column, NaN where its kind has none)
    pairs = list(zip(copied, alone, strict=True))
    assert all(math.isnan(r[k]) for r, a in pairs for k in set(r) - set(a))
    assert comparable([{k: r[k] for k in a} for r, a in pairs]) == comparable(alone)


@pytest.mark.parametrize("column, value", [("scenario", "ghost"), ("identifier", "toy_other"),
                                           ("noise", 7.0), ("seed", 5)])
@pytest.mark.parametrize("checksum", ["kept", "recomputed"])
def test_a_resumed_sweep_refuses_a_row_edited_to_another_cell(toy_dir, tmp_path, column, value,
                                                              checksum):
    # round 9: a row's scenario edited by hand was kept as its cell's result, under the other
    # name, and the cell skipped.  An edit under the row's checksum makes the file damaged: set
    # aside, its cells run again; an edit with the checksum made anew for it (a consistent row
    # of another cell) is refused by the cell check, the file untouched.
    import pyarrow as pa
    import pyarrow.parquet as pq

    from testbed.core.errors import InputError
    from testbed.studies.results import DIGEST, row_digest

    res, cache = tmp_path / "r.parquet", tmp_path / "c"
    study = load_study(write_study(toy_dir, "edited", ["toy_fit"], seeds=(0,), noise=(0.0,)))
    run_sweep(study, results=res, cache_dir=cache, verbose=False)
    table = pq.read_table(res)
    rows = table.to_pylist()
    rows[0][column] = value
    if checksum == "recomputed":
        rows[0][DIGEST] = row_digest(rows[0])
    pq.write_table(pa.Table.from_pylist(rows, schema=table.schema), res)
    before = res.read_bytes()
    if checksum == "recomputed":
        with pytest.raises(InputError, match=f"the row of cell {rows[0]['cell']} has {column} = "):
            run_sweep(study, results=res, cache_dir=cache, verbose=False)
        assert res.read_bytes() == before
        return
    stats = SweepStats()
    run_sweep(study, results=res, cache_dir=cache, verbose=False, stats=stats)
    assert stats.run == 1 and res.with_name(res.name + ".bad").read_bytes() == before
    assert [r[column] for r in read_results(res)] != [value]


def test_an_unheld_infinite_score_is_no_second_reason_after_a_failure():
    # round 27's fb27_sine_amp0p014 at 3 %: "uninformative; non-finite scores: coef_error, ..."
    # named scores no bar holds (coef_error is infinite by definition where the identified row
    # lacks the truth's largest term) after the cell's own reason
    from testbed.studies.sweep import unexplained_nonfinite

    values = {"angle_rmse": 0.2, "coef_error": float("inf"), "f1": float("nan")}
    assert unexplained_nonfinite(values, {"angle_rmse"}, {"uninformative"}) == []
    # a held score that is not finite is named ...
    nan_held = {**values, "angle_rmse": float("nan")}
    assert unexplained_nonfinite(nan_held, {"angle_rmse"}, set()) == ["angle_rmse", "coef_error", "f1"]
    # ... unless the fit or the simulation failed, whose reason says why the scores are
    # undefined (review 28a: "diverged; non-finite scores: trac" counted a cell twice)
    assert unexplained_nonfinite(nan_held, {"angle_rmse"}, {"fit"}) == []
    assert unexplained_nonfinite(nan_held, {"angle_rmse"}, {"simulation": "diverged"}) == []
    # a held metric with no score at all is not finite either
    assert unexplained_nonfinite({"coef_error": float("inf")}, {"angle_rmse"}, set()) == ["coef_error"]
    # with no checks at all, non-finite scores are the only thing to say
    assert unexplained_nonfinite(values, set(), set()) == ["coef_error", "f1"]
