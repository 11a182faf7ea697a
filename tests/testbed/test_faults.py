"""Fault injection: damaged stored data, a killed sweep, concurrent runs, run names that escape.

Each test breaks something the way the world does (a file cut short, a flipped bit, a
``kill -9``, two users at once, a hostile file name) and asserts the testbed notices,
says which file, repairs what it can and never loses or mixes up finished work.
"""

from __future__ import annotations

import contextlib
import json
import logging
import math
import os
import re
import resource
import signal
import subprocess
import sys
import textwrap
import time
from dataclasses import replace
from pathlib import Path

import h5py
import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
import _synthetic_runs as synth

from testbed.core.dataset import Dataset, DatasetError
from testbed.core.errors import InputError
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.generate import generate
from testbed.pipeline.scenario import load_scenario
from testbed.studies.results import ResultsError, parts_dir, read_results, write_part
from testbed.studies.runstore import RunStoreError, load_run, run_folder, save_run
from testbed.studies.statistics import summarize
from testbed.studies.study import load_study
from testbed.studies.sweep import SweepStats, run_sweep

ROOT = Path(__file__).resolve().parents[2]
# Columns that legitimately differ between two runs of the same cell.
TIMING = ("fit_time", "data_time", "cell_time")


def _env(**extra: str) -> dict[str, str]:
    """The environment of a subprocess: this checkout first on the import path, one thread."""
    path = os.pathsep.join(p for p in (str(ROOT), os.environ.get("PYTHONPATH", "")) if p)
    return {**os.environ, "PYTHONPATH": path, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
            **extra}


def _short(noise: float = 2.0, seed: int = 7):
    """The stiff cantilever over 0.05 s (a fraction of a second to simulate)."""
    sc = load_scenario("cantilever_stiff_impact")
    return sc.replace(simulation={**sc.simulation, "duration": 0.05}).with_noise(noise).replace(seed=seed)


def _assert_same_data(a: Dataset, b: Dataset) -> None:
    assert a.content_hash() == b.content_hash()
    for group in ("measured", "reference"):
        ga, gb = getattr(a, group), getattr(b, group)
        assert ga.keys() == gb.keys()
        for name in ga:
            np.testing.assert_array_equal(ga[name].data, gb[name].data)


# --------------------------------------------------------------------------- stored datasets
def test_truncated_cache_entry_is_simulated_again_with_a_warning(tmp_path, caplog):
    sc = _short()
    cache = DatasetCache(tmp_path)
    first = cache.get(sc)
    (path, size), = cache.entries()
    with open(path, "r+b") as f:  # a copy cut short, a full disk
        f.truncate(size // 2)
    with pytest.raises(DatasetError, match="unreadable dataset file") as e:
        Dataset.load(path)
    assert str(path) in str(e.value)
    with caplog.at_level(logging.WARNING, logger="testbed.pipeline.cache"):
        again = cache.get(sc)
    warnings = [r.getMessage() for r in caplog.records if r.name == "testbed.pipeline.cache"]
    assert len(warnings) == 1 and str(path) in warnings[0] and "\n" not in warnings[0]
    _assert_same_data(again, first)
    Dataset.load(path)  # repaired in place
    assert [p for p, _ in cache.entries()] == [path]


def test_flipped_bits_in_a_cached_array_are_caught_by_the_content_hash(tmp_path, caplog):
    sc = _short()
    cache = DatasetCache(tmp_path)
    first = cache.get(sc)
    path = cache.path(sc)
    with h5py.File(path, "r") as f:  # where the raw samples of one signal sit in the file
        offset = f["measured/acceleration"].id.get_offset()
    assert offset is not None
    with open(path, "r+b") as f:
        f.seek(offset + 8 * 10)  # the 11th sample, last byte of its mantissa's low end
        byte = f.read(1)
        f.seek(offset + 8 * 10)
        f.write(bytes([byte[0] ^ 0x01]))
    with pytest.raises(DatasetError, match="does not match its stored content hash"):
        Dataset.load(path)
    assert Dataset.load(path, verify=False).measured  # still readable: only the hash can tell
    with caplog.at_level(logging.WARNING, logger="testbed.pipeline.cache"):
        again = cache.get(sc)
    assert any(str(path) in r.getMessage() for r in caplog.records if r.name == "testbed.pipeline.cache")
    _assert_same_data(again, first)


def test_a_truth_array_rewritten_as_complex_is_caught(tmp_path, caplog):
    # the content hash and the typed truth both cast a truth array to real: an imaginary part
    # added to a cached entry's truth passed the verification (with three ComplexWarnings)
    sc = _short()
    cache = DatasetCache(tmp_path)
    first = cache.get(sc)
    path = cache.path(sc)
    with h5py.File(path, "r+") as f:
        old = f["truth/M"]
        value, unit = old[()], old.attrs["unit"]
        del f["truth/M"]
        f.create_dataset("truth/M", data=value + 1j).attrs["unit"] = unit
    with pytest.raises(DatasetError, match=r"truth/M: complex128 data; expected real numbers"):
        Dataset.load(path)
    with caplog.at_level(logging.WARNING, logger="testbed.pipeline.cache"):
        again = cache.get(sc)
    assert any(str(path) in r.getMessage() for r in caplog.records if r.name == "testbed.pipeline.cache")
    _assert_same_data(again, first)


def test_loading_a_file_that_is_not_a_dataset_names_it(tmp_path):
    junk = tmp_path / "notes.h5"
    junk.write_text("not HDF5 at all\n")
    with pytest.raises(DatasetError, match="unreadable dataset file") as e:
        Dataset.load(junk)
    assert str(junk) in str(e.value)
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as f:
        f.attrs["format"] = "something-else"
    with pytest.raises(DatasetError, match="not a sysid-testbed-dataset"):
        Dataset.load(other)
    with pytest.raises(DatasetError, match="no such file"):
        Dataset.load(tmp_path / "absent.h5")


def test_content_hash_names_the_data_not_the_identifier_or_thresholds(tmp_path):
    sc = _short()
    cache = DatasetCache(tmp_path)
    a = cache.get(sc)
    b = cache.get(sc.replace(name="renamed", description="x", identify={"method": "lsq_structural"},
                             score={"mac_min": 0.5}, signal={**sc.signal}))
    assert a.content_hash() == b.content_hash()
    assert a.attrs["scenario"] != b.attrs["scenario"]  # the provenance still tells them apart
    assert cache.get(sc.replace(seed=8)).content_hash() != a.content_hash()


def test_noisy_fivebar_from_the_cache_is_bit_identical_to_a_fresh_one(tmp_path):
    """The five-bar's rig returns transposed arrays; the noise's RMS must not depend on that."""
    sc = load_scenario("fivebar_multisine_noise1")
    sc = sc.replace(simulation={**sc.simulation, "duration": 0.5}, seed=3)
    cache = DatasetCache(tmp_path)
    cache.get(sc.with_noise(0.0))  # the clean entry, stored and then read back from HDF5
    derived = cache.get(sc)
    fresh = generate(sc)
    _assert_same_data(derived, fresh)
    assert derived.content_hash() == fresh.attrs["content_hash"]


def test_concurrent_writers_and_readers_of_one_cache_entry(tmp_path):
    """Processes filling one key at once all finish; a reader never meets a half-written file."""
    from concurrent.futures import ProcessPoolExecutor

    sc = _short()
    cache = DatasetCache(tmp_path)
    want = generate(sc)
    with ProcessPoolExecutor(3) as ex:  # three cold processes race for the same entry
        got = list(ex.map(_fill_and_read, [(str(tmp_path), sc)] * 3))
    assert got == [(want.content_hash(), 0)] * 3  # 0: no reader found a damaged entry
    assert [p for p, _ in cache.entries()] == [cache.path(sc)]
    assert [p.name for p in tmp_path.iterdir()] == [cache.path(sc).name], "no temporary file left"


def _fill_and_read(args) -> tuple[str, int]:
    """Fill the entry, then rewrite and read it back 5 times: (content hash, warnings logged)."""
    directory, sc = args
    warned: list[logging.LogRecord] = []
    handler = logging.Handler(logging.WARNING)
    handler.emit = warned.append
    logging.getLogger("testbed.pipeline.cache").addHandler(handler)
    cache = DatasetCache(directory)
    ds = cache.get(sc)
    for _ in range(5):
        cache.clean(sc).save(cache.path(sc))  # another writer's atomic replace, over and over
        assert cache.get(sc).content_hash() == ds.content_hash()
    return ds.content_hash(), len(warned)


def _variant(path, base: str, name: str, tables: str):
    """Write a scenario file at ``path`` extending the shipped ``base`` as ``name``, with the
    TOML ``tables`` (indented text) added; return ``path``."""
    path.write_text(textwrap.dedent(f"""
        [scenario]
        extends = "{ROOT / 'scenarios' / (base + '.toml')}"
        name = "{name}"
    """) + textwrap.dedent(tables))
    return path


def test_generate_to_a_file_fills_the_run_cache(tmp_path):
    from testbed.cli import main

    variant = _variant(tmp_path / "short.toml", "cantilever_stiff_impact", "short", """
        [simulation]
        duration = 0.05
        [noise]
        rms_percent = 1.0
    """)
    out, cache_dir = tmp_path / "d.h5", tmp_path / "cache"
    assert main(["generate", str(variant), "-o", str(out), "--cache", str(cache_dir)]) == 0
    cache = DatasetCache(cache_dir)
    assert len(cache.entries()) == 1
    sc = load_scenario(variant)
    _assert_same_data(Dataset.load(out), cache.get(sc))
    assert len(cache.entries()) == 1


def test_a_folder_in_place_of_a_cache_entry_is_named_before_simulating(tmp_path):
    # the atomic rename onto it failed after the simulation ("[Errno 21] Is a directory:
    # '.../.x.h5.tmp' -> ..."), and `testbed cache clear` failed on it
    from testbed.core.errors import InputError

    sc = load_scenario("michaelis_menten")
    cache = DatasetCache(tmp_path)
    cache.path(sc).mkdir()
    other = f"other-{'f' * 32}.h5"  # (named as an entry: the cache lists only its own names)
    (tmp_path / other).symlink_to(tmp_path / other)  # a link that loops: listed, cleared
    with pytest.raises(InputError, match=r"is a folder where a cached dataset belongs"):
        cache.clean(sc)
    assert [p.name for p, _ in cache.entries()] == [other]
    assert cache.clear() == 1 and cache.path(sc).is_dir()


# --------------------------------------------------------------------------- sweeps
# A "mechanical" toy, as in test_sweep.py but under names of its own (one registration per
# process): four undamped oscillators, an identifier fitting k_i by least squares.
# fault_slow sleeps $FAULT_SLOW_SECONDS per fit: long while a sweep is to be killed, zero
# when it resumes (the rows do not depend on it); with $FAULT_SLOW_MARKS (a folder) it first
# writes a file named by its process id there, so a test sees which processes are in the fit.
PLUGIN = '''
import os
import time
import numpy as np
from identify import IDENTIFIERS
from identify._base import Identifier
from models import RIGS
from models._base import Rig
from testbed.core.dataset import Dataset, Signal
from testbed.core.measurement import Trajectory
from testbed.core.schema import Field

NAMES = ["th1", "ddth1", "th2", "ddth2", "th3", "ddth3", "th4", "ddth4"]


@RIGS.register("fault_osc")
class FaultOscillators(Rig):
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


@IDENTIFIERS.register("fault_fit")
class FaultFit(Identifier):
    kind = "mechanical"

    def __init__(self, delay: float = 0.0):
        self.delay = delay

    def pause(self):
        time.sleep(self.delay)

    def fit(self, data):
        self.pause()
        x, xdd = data.x, data.xdd
        k = -np.sum(x * xdd, axis=1) / np.sum(x * x, axis=1)
        self.k_ = k
        self.feature_names_ = NAMES
        coef = np.zeros((4, 8))
        for i in range(4):
            coef[i, 2 * i], coef[i, 2 * i + 1] = k[i], 1.0
        self.coef_ = coef
        return self

    def simulate(self, x0, xd0, t, u=None):
        w = np.sqrt(np.abs(self.k_))[:, None]
        x = x0[:, None] * np.cos(w * t) + (xd0[:, None] / w) * np.sin(w * t)
        xd = -x0[:, None] * w * np.sin(w * t) + xd0[:, None] * np.cos(w * t)
        return Trajectory(x, xd, -w**2 * x)

    def equations(self, precision=4):
        return [f"ddth{i + 1} = {-k:.{precision}g} th{i + 1}" for i, k in enumerate(self.k_)]


@IDENTIFIERS.register("fault_abort")
class FaultAbort(FaultFit):
    def pause(self):
        if os.environ.get("FAULT_ABORT"):  # the interpreter ends (SIGABRT): no Python runs after
            os.abort()
        if os.environ.get("FAULT_INTERRUPT"):
            raise KeyboardInterrupt


@IDENTIFIERS.register("fault_slow")
class FaultSlow(FaultFit):
    def pause(self):
        if os.environ.get("FAULT_SLOW_MARKS"):  # a folder: each process marks its entering here
            open(os.path.join(os.environ["FAULT_SLOW_MARKS"], str(os.getpid())), "w").close()
        time.sleep(float(os.environ.get("FAULT_SLOW_SECONDS", "0")))
'''

SCENARIO = """
[scenario]
name = "fault_a"
rig = "fault_osc"
[simulation]
n_samples = 400
[score]
angle_rmse_max = 0.05
"""


@pytest.fixture(scope="module")
def fault_dir(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("faults")
    (d / "faults.py").write_text(PLUGIN)
    (d / "fault_a.toml").write_text(SCENARIO)
    return d


def _study(d: Path, name: str, identifiers: list[str], *, seeds=(0, 1), noise=(0.0, 2.0),
           delay: float = 0.0) -> Path:
    path = d / f"{name}.toml"
    path.write_text("\n".join([
        "[study]", f'name = "{name}"', 'scenarios = ["fault_a.toml"]', f"noise = {json.dumps(list(noise))}",
        f"seeds = {json.dumps(list(seeds))}", f"identifiers = {json.dumps(identifiers)}",
        'plugins = ["faults.py"]', "[identifiers.fault_fit]", f"delay = {delay}"]) + "\n")
    return path


def _comparable(rows: list[dict], leave_out: tuple[str, ...] = ()) -> list[dict]:
    """Rows without the timing columns (and ``leave_out``), NaN made comparable."""
    return sorted(({k: ("nan" if isinstance(v, float) and math.isnan(v) else v)
                    for k, v in r.items() if k not in TIMING + leave_out} for r in rows),
                  key=lambda r: r["cell"])


def _as_killed(results: Path) -> None:
    """Turn a finished results file back into what a killed sweep leaves: row files only."""
    for row in read_results(results):
        write_part(results, row)
    results.unlink()


def test_truncated_row_file_is_named_set_aside_and_its_cell_run_again(fault_dir, tmp_path, caplog):
    study = load_study(_study(fault_dir, "parts", ["fault_fit"]))
    res, cache = tmp_path / "r.parquet", tmp_path / "c"
    whole = read_results(run_sweep(study, results=res, cache_dir=cache, verbose=False))
    _as_killed(res)
    victim = sorted(parts_dir(res).glob("*.json"))[1]
    victim.write_bytes(victim.read_bytes()[:40])  # cut short mid-row

    # summary reads what it can, naming the file it skips, and changes nothing on disk
    with caplog.at_level(logging.WARNING, logger="testbed.studies.results"):
        summary = summarize(res)
    assert sum(s["cells"] for s in summary) == 3
    assert any(str(victim) in r.getMessage() for r in caplog.records)
    assert victim.is_file()

    caplog.clear()
    stats = SweepStats()
    with caplog.at_level(logging.WARNING, logger="testbed.studies.results"):
        rows = read_results(run_sweep(study, results=res, cache_dir=cache, verbose=False, stats=stats))
    named = [r.getMessage() for r in caplog.records if str(victim) in r.getMessage()]
    assert len(named) == 1 and "set aside" in named[0]
    assert (stats.skipped_done, stats.run) == (3, 1)
    assert _comparable(rows) == _comparable(whole)
    assert [p.name for p in parts_dir(res).iterdir()] == [victim.name + ".bad"]  # evidence kept


def test_damaged_results_file_is_named_by_summary_and_set_aside_by_sweep(fault_dir, tmp_path):
    from testbed.cli import main

    study = load_study(_study(fault_dir, "whole", ["fault_fit"], seeds=(0,)))
    res, cache = tmp_path / "r.parquet", tmp_path / "c"
    whole = read_results(run_sweep(study, results=res, cache_dir=cache, verbose=False))
    res.write_bytes(res.read_bytes()[:100])
    with pytest.raises(ResultsError, match="unreadable results file"):
        read_results(res)
    assert main(["summary", str(res)]) == 2  # one clear line naming the file, no traceback
    stats = SweepStats()
    rows = read_results(run_sweep(study, results=res, cache_dir=cache, verbose=False, stats=stats))
    assert stats.run == 2 and _comparable(rows) == _comparable(whole)
    assert res.with_name(res.name + ".bad").is_file()


def _results_row(cell: str, **over) -> dict:
    """A results row as a sweep writes it (one score, trac)."""
    row = {"study": "s", "cell": cell, "scenario": "sc", "rig": "cantilever", "noise": 1.0,
           "seed": 0, "identifier": "ls_sindy", "params": "{}", "status": "ok", "error": "",
           "fit_time": 0.1, "data_time": 0.1, "cell_time": 0.2, "passed": True, "trac": 0.99,
           "checks": json.dumps([{"metric": "trac", "value": 0.99, "bound": "min",
                                  "threshold": 0.9, "passed": True}]),
           "versions": "{}", "commit": "abc", "dataset_hash": "0" * 64}
    return {**row, **over}


def _retyped(table, name, values):
    import pyarrow as pa

    return table.set_column(table.schema.get_field_index(name), name, pa.array(values))


@pytest.mark.parametrize(("edit", "fragment"), [
    (lambda t: t.drop_columns(["noise"]), "no column 'noise'; expected the columns of a `testbed sweep`"),
    (lambda t: t.drop_columns(["identifier"]), "no column 'identifier'"),
    (lambda t: _retyped(t, "noise", ["1", "1"]), "column 'noise' holds string; expected double"),
    (lambda t: _retyped(t, "trac", ["0.99", "0.99"]), "score column 'trac' holds string; expected double"),
    (lambda t: _retyped(t, "passed", ["yes", "yes"]), "column 'passed' holds string; expected bool"),
    (lambda t: _retyped(t, "status", ["ok", "maybe"]), "row 1 (cell 'b'): status 'maybe'; expected 'ok' or"),
    (lambda t: _retyped(t, "noise", [math.nan, 1.0]), "row 0 (cell 'a'): noise nan; expected a finite level"),
    (lambda t: _retyped(t, "passed", [None, True]), "row 0 (cell 'a'): no passed;"),
    (lambda t: __import__("pyarrow").concat_tables([t, t]), "row 2 (cell 'a'): the cell appears twice"),
])
def test_a_results_file_with_a_column_missing_or_retyped_is_named(tmp_path, capsys, edit, fragment):
    # a consolidated file without its noise, scenario or identifier column, or with noise as
    # text or NaN, was an internal error of `testbed summary` and `testbed report` (KeyError,
    # ValueError, ZeroDivisionError); a score as text, a passed of null or a cell twice passed
    import pyarrow.parquet as pq

    from testbed.cli import main
    from testbed.studies.results import write_rows

    res = tmp_path / "r.parquet"
    write_rows(res, [_results_row("a"), _results_row("b")], study="s")
    table = pq.read_table(res)
    pq.write_table(edit(table).replace_schema_metadata(table.schema.metadata), res)
    with pytest.raises(ResultsError, match=re.escape(fragment)):
        read_results(res)
    for argv in (["summary", str(res)], ["report", str(res), "-o", str(tmp_path / "rep")]):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and err.startswith(f"error: {res}: ") and fragment in err, err


def test_results_file_of_another_study_is_refused_untouched(fault_dir, tmp_path):
    # --results naming another study's file: consolidating dropped every row of that study
    # ("dropped N row(s) of cells no longer in study ...") and wrote this one's in their place
    from testbed.cli import main
    from testbed.core.errors import InputError

    res, cache = tmp_path / "r.parquet", tmp_path / "c"
    run_sweep(load_study(_study(fault_dir, "first", ["fault_fit"], seeds=(0,))), results=res,
              cache_dir=cache, verbose=False)
    before = res.read_bytes()
    other = _study(fault_dir, "second", ["fault_fit"], seeds=(0,))
    with pytest.raises(InputError, match=r"holds rows of study 'first', not 'second'"):
        run_sweep(load_study(other), results=res, cache_dir=cache, verbose=False)
    assert main(["sweep", str(other), "--results", str(res), "--cache", str(cache)]) == 2
    assert res.read_bytes() == before and not parts_dir(res).exists()


def test_retry_failed_flag_reruns_failed_cells_and_exit_status(fault_dir, tmp_path, capsys):
    from testbed.cli import main

    study = _study(fault_dir, "retry", ["fault_fit"], seeds=(0,))
    res = tmp_path / "r.parquet"
    args = ["sweep", str(study), "--results", str(res), "--cache", str(tmp_path / "c")]
    assert main(args) == 0
    rows = read_results(res)
    # mark one cell failed, as a crash in an earlier run would have
    rows[0].update(status="failed", error="RuntimeError: earlier crash", passed=False)
    _as_killed(res)
    write_part(res, rows[0])
    assert main(args) == 1  # still failed: reported, not rerun
    assert "1 cell(s) failed" in capsys.readouterr().err
    assert main([*args, "--retry-failed"]) == 0
    assert all(r["status"] == "ok" for r in read_results(res))


def test_sweep_interrupted_by_an_error_keeps_the_rows_that_finished(fault_dir, tmp_path, monkeypatch):
    """A lost worker (here: an error after two rows) ends the sweep; the two rows are consolidated."""
    import testbed.studies.sweep as sw

    real = sw.parallel

    def lossy(fn, args, n_jobs):
        for i, out in enumerate(real(fn, args, n_jobs)):
            if fn is sw.run_cell and i == 2:
                raise RuntimeError("worker lost")
            yield out

    monkeypatch.setattr(sw, "parallel", lossy)
    study = load_study(_study(fault_dir, "lossy", ["fault_fit"]))
    res = tmp_path / "r.parquet"
    with pytest.raises(RuntimeError, match="worker lost"):
        run_sweep(study, results=res, cache_dir=tmp_path / "c", verbose=False)
    assert res.is_file() and not parts_dir(res).exists()
    assert len(read_results(res)) == 2
    monkeypatch.setattr(sw, "parallel", real)
    stats = SweepStats()
    assert len(read_results(run_sweep(study, results=res, cache_dir=tmp_path / "c", verbose=False,
                                      stats=stats))) == 4
    assert stats.run == 2


def _group_alive(pgid: int) -> list[int]:
    """Pids of live (not zombie) processes in process group ``pgid``."""
    try:
        import psutil
    except ImportError:
        psutil = None
    out = []
    if psutil is not None:
        for p in psutil.process_iter(["pid", "status"]):
            try:
                if os.getpgid(p.info["pid"]) == pgid and p.info["status"] != psutil.STATUS_ZOMBIE:
                    out.append(p.info["pid"])
            except (ProcessLookupError, psutil.Error):
                continue
        return out
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[2]) == pgid and fields[0] != "Z":  # fields: state, ppid, pgrp, ...
            out.append(int(d.name))
    return out


@pytest.mark.slow
def test_kill_9_of_a_two_worker_sweep_leaves_no_worker_and_resumes_exactly(fault_dir, tmp_path,
                                                                           monkeypatch):
    """SIGKILL `testbed sweep --jobs 2` while both workers are in a long fit; nothing survives."""
    # 4 quick cells (0.2 s fits) run first (grid order), then 4 cells whose fit sleeps 600 s: the
    # kill lands mid-fit, where a worker that does not watch its parent would sleep on for minutes
    study = _study(fault_dir, "kill2", ["fault_fit", "fault_slow"], delay=0.2)
    res, cache = tmp_path / "killed.parquet", tmp_path / "cache"
    cmd = [sys.executable, "-m", "testbed.cli", "sweep", str(study), "--jobs", "2", "--results", str(res),
           "--cache", str(cache)]
    marks = tmp_path / "in-slow-fit"
    marks.mkdir()
    proc = subprocess.Popen(cmd, cwd=ROOT, env=_env(FAULT_SLOW_SECONDS="600", FAULT_SLOW_MARKS=str(marks)),
                            start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    try:
        deadline = time.monotonic() + 90
        # both workers inside a 600 s fit (each marked its entering; a fixed 1 s sleep after the
        # 4 quick cells assumed it)
        while (len(list(parts_dir(res).glob("*.json"))) if parts_dir(res).is_dir() else 0) < 4 \
                or len(list(marks.iterdir())) < 2:
            assert proc.poll() is None and time.monotonic() < deadline, proc.stderr.read().decode()
            time.sleep(0.05)
        assert len(_group_alive(proc.pid)) >= 3, "expected the main process and two workers"
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=10)
        t_kill = time.monotonic()
        while _group_alive(proc.pid) and time.monotonic() < t_kill + 10:
            time.sleep(0.1)
        left = _group_alive(proc.pid)
        assert not left, f"processes still running 10 s after the kill: {left}"
    finally:
        with __import__("contextlib").suppress(ProcessLookupError):
            os.killpg(proc.pid, signal.SIGKILL)  # whatever the assertion found, stop it
        proc.stderr.close()

    n_before = len(read_results(res))
    assert n_before == 4 and not res.exists()
    out = subprocess.run(cmd, cwd=ROOT, env=_env(FAULT_SLOW_SECONDS="0"), capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert "4 already done, 4 to run" in out.stderr
    resumed = read_results(res)
    monkeypatch.setenv("FAULT_SLOW_SECONDS", "0")
    whole = read_results(run_sweep(load_study(study), results=tmp_path / "whole.parquet", cache_dir=cache,
                                   verbose=False))
    assert len(resumed) == 8 and all(r["status"] == "ok" for r in resumed)
    # `commit` left out: the killed and resumed sweeps are `testbed sweep` processes, `whole`
    # runs in this one, each recording the commit it saw (a commit made while the suite runs
    # changes it between them); within one sweep every row carries one commit
    assert _comparable(resumed, ("commit",)) == _comparable(whole, ("commit",))
    assert len({r["commit"] for r in whole}) == 1


def test_a_cell_whose_process_keeps_ending_is_recorded_failed_not_run_forever(fault_dir, tmp_path,
                                                                              monkeypatch):
    """`sweep --jobs 1` of a plugin whose fit calls os.abort(): status 134, no row (hostile round
    20); every resume ran the cell and died again.  A cell inside which two processes in a row
    ended is recorded failed, naming it; a Ctrl-C in a cell leaves no marker (so an interrupted
    sweep only ever resumes), and the cells that finished are kept."""
    from testbed.studies.statistics import failure_kind
    from testbed.studies.sweep import ENDS_BEFORE_FAILED, expand, inflight_path

    study = _study(fault_dir, "aborting", ["fault_fit", "fault_abort"], seeds=(0,), noise=(0.0,))
    (key,) = [c.key for c in expand(load_study(study)) if c.identifier == "fault_abort"]
    res, cache = tmp_path / "r.parquet", tmp_path / "cache"
    cmd = [sys.executable, "-c", "from testbed.studies.sweep import run_sweep; "
           f"run_sweep({str(study)!r}, results={str(res)!r}, cache_dir={str(cache)!r})"]
    for end in range(1, ENDS_BEFORE_FAILED + 1):
        out = subprocess.run(cmd, cwd=ROOT, env=_env(FAULT_ABORT="1"), capture_output=True,
                             text=True, timeout=120)
        assert out.returncode == -signal.SIGABRT, out.stderr
        rows = read_results(res, resuming=True)
        assert [r["identifier"] for r in rows] == ["fault_fit"]  # the finished cell is kept
        assert [p.name for p in parts_dir(res).glob("*.inflight")] == [f"{key}.inflight"]
        assert inflight_path(res, key).read_text() == str(end)
    cells = {r["identifier"]: r for r in read_results(run_sweep(
        load_study(study), results=res, cache_dir=cache, verbose=False))}
    assert cells["fault_fit"]["status"] == "ok"
    failed = cells["fault_abort"]
    assert failed["status"] == "failed" and failure_kind(failed["error"]) == ["crash: process ended"]
    assert f"ended {ENDS_BEFORE_FAILED} times in a row" in failed["error"] and "faults.py" in failed["error"]
    assert not parts_dir(res).exists()
    # --retry-failed runs it again; the second process ending in it records it again, and
    # that invocation runs the cells after it (it had died in the cell on every retry)
    retry = [*cmd[:-1], cmd[-1][:-1] + ", retry_failed=True)"]
    for _ in range(ENDS_BEFORE_FAILED):
        out = subprocess.run(retry, cwd=ROOT, env=_env(FAULT_ABORT="1"), capture_output=True,
                             text=True, timeout=120)
        assert out.returncode == -signal.SIGABRT, out.stderr
    again = {r["identifier"]: r for r in read_results(run_sweep(
        load_study(study), results=res, cache_dir=cache, verbose=False, retry_failed=True))}
    assert again["fault_abort"]["error"] == failed["error"] and again["fault_fit"]["status"] == "ok"
    # a Python-level end (Ctrl-C) in the cell leaves no marker: the next run runs it again
    res2 = tmp_path / "r2.parquet"
    monkeypatch.setenv("FAULT_INTERRUPT", "1")
    with pytest.raises(KeyboardInterrupt):
        run_sweep(load_study(study), results=res2, cache_dir=cache, verbose=False)
    assert not list(parts_dir(res2).glob("*.inflight"))


def test_a_cells_marker_is_removed_by_a_signals_exit_that_cannot_unwind(tmp_path, monkeypatch):
    """SIGTERM while a compiled kernel runs ends the process by `os._exit` after removing what
    is in flight (testbed.core.interrupts.exit_now -> atomic.remove_in_flight): the cell's
    marker is in flight while the cell runs, so a scheduler's kill is not counted as the cell's
    crash (review, session 21: two such kills recorded "process ended")."""
    from testbed.core import atomic
    from testbed.studies import sweep

    marker = tmp_path / "r.parquet.parts" / "k.inflight"
    seen = []

    def cell(*a):
        seen.append((marker.read_text(), os.fspath(marker) in atomic._IN_FLIGHT))
        atomic.remove_in_flight()  # what exit_now does before os._exit
        return {}

    monkeypatch.setattr(sweep, "_run_cell", cell)
    sweep.run_cell(None, "", (), inflight=marker)
    assert seen == [("1", True)] and not marker.exists()
    assert os.fspath(marker) not in atomic._IN_FLIGHT


# --------------------------------------------------------------------------- run folders
@pytest.fixture(scope="module")
def mechanical():
    return synth.mechanical_result(n_samples=400)


def test_a_fifo_in_place_of_latest_json_does_not_block_the_report(mechanical, tmp_path):
    # `testbed report <scenario>` read latest.json: a FIFO there blocked it forever
    from testbed.studies.runstore import LATEST, resolve_run, save_new_run

    run = save_new_run(mechanical, tmp_path / "runs")
    (run.parent / LATEST).unlink()
    os.mkfifo(run.parent / LATEST)
    previous = signal.signal(signal.SIGALRM, lambda *a: pytest.fail("resolve_run blocked on a FIFO"))
    signal.setitimer(signal.ITIMER_REAL, 10.0)
    try:
        assert resolve_run(run.parent) == run  # the newest run, as without a pointer
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def test_a_run_named_dot_or_dotdot_never_touches_the_output_folder(mechanical, tmp_path):
    out = tmp_path / "runs"
    save_run(mechanical, out / "other")
    (tmp_path / "keep.txt").write_text("not a run")
    for name in (".", "..", "", ".hidden", "a/b", "../escape"):
        with pytest.raises(RunStoreError):
            run_folder(out, name)
    # save_run called directly with such names: refused, nothing replaced or deleted
    for target in (out / ".", out / "..", f"{out}/.", f"{out}/..", tmp_path):
        with pytest.raises(RunStoreError):
            save_run(mechanical, target)
    assert sorted(p.name for p in out.iterdir()) == ["other"]
    assert load_run(out / "other").fit_time == mechanical.fit_time
    assert (tmp_path / "keep.txt").read_text() == "not a run"
    # a link inside the output folder that points out of it is not a way out either
    (tmp_path / "elsewhere").mkdir()
    (out / "sneaky").symlink_to(tmp_path / "elsewhere")
    with pytest.raises(RunStoreError, match="outside the output folder"):
        run_folder(out, "sneaky")
    assert run_folder(out, "fine_name") == out / "fine_name"


@contextlib.contextmanager
def _file_size_limit(nbytes: int):
    """The process's file-size limit (``ulimit -f``, RLIMIT_FSIZE) at ``nbytes`` in the block: a
    full disk as a write meets it (Python ignores SIGXFSZ, so the write fails with EFBIG)."""
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    resource.setrlimit(resource.RLIMIT_FSIZE, (nbytes, hard))
    try:
        yield
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))


def test_a_full_disk_while_caching_a_dataset_is_one_error_naming_the_file(tmp_path):
    # was an internal error, or HDF5's finalizers printing tracebacks and a crash (SIGBUS)
    sc = _short()
    cache = DatasetCache(tmp_path)
    with _file_size_limit(20_000), pytest.raises(InputError) as e:  # the entry takes 93 kB
        cache.get(sc)
    msg = str(e.value)
    assert msg.startswith(f"{cache.path(sc)}: cannot be written: File too large (") and "\n" not in msg
    assert list(tmp_path.iterdir()) == []  # nothing half-written: no entry, no temporary file
    _assert_same_data(cache.get(sc), generate(sc))  # room again: simulated and stored whole


def test_a_full_disk_while_saving_a_run_is_one_error_naming_its_folder(mechanical, tmp_path):
    from testbed.studies.runstore import save_new_run

    out = tmp_path / "runs"
    save_run(mechanical, out / "other")
    with _file_size_limit(2_000), pytest.raises(InputError) as e:  # run.json takes 6 kB, run.npz 24 kB
        save_new_run(mechanical, out)
    assert str(e.value).startswith(f"a run folder in {out / mechanical.scenario.name}: cannot be "
                                   "written: File too large")
    assert not (out / mechanical.scenario.name).exists() or not any(
        (out / mechanical.scenario.name).iterdir())  # no half-written run
    assert load_run(out / "other").fit_time == mechanical.fit_time


def test_cli_run_of_a_scenario_named_dot_leaves_every_other_run(mechanical, tmp_path, capsys):
    """`testbed run ..toml` (name ".") once replaced the whole output folder; now it is refused."""
    from testbed.cli import main

    out = tmp_path / "runs"
    save_run(mechanical, out / "other")
    dot = tmp_path / "..toml"
    dot.write_text(f'[scenario]\nextends = "{ROOT / "scenarios" / "cantilever_stiff_impact_lsq.toml"}"\n'
                   'name = "."\n')
    assert main(["run", str(dot), "--no-figures", "--no-cache", "-o", str(out)]) == 2
    assert "error:" in capsys.readouterr().err
    assert [p.name for p in out.iterdir()] == ["other"] and load_run(out / "other")


def test_concurrent_writers_of_one_run_folder_leave_one_complete_run(mechanical, tmp_path):
    """Eight threads save the same run at once (distinct fit times): each succeeds, one wins whole."""
    from concurrent.futures import ThreadPoolExecutor

    d = tmp_path / "runs" / "same"
    save_run(mechanical, d)
    with ThreadPoolExecutor(8) as ex:
        done = list(ex.map(lambda i: save_run(replace(mechanical, fit_time=100.0 + i), d),
                           range(8)))
    assert done == [d] * 8
    run = load_run(d)
    assert run.fit_time in {100.0 + i for i in range(8)}
    assert sorted(p.name for p in d.iterdir()) == ["run.json", "run.npz"]
    assert [p.name for p in d.parent.iterdir()] == ["same"], "no temporary folders left"


@pytest.mark.slow
def test_two_concurrent_testbed_runs_of_one_scenario(tmp_path):
    """Two `testbed run` processes of one scenario and cache: both give a verdict, both runs stay
    (each in its own folder of the run history), and the index lists both."""
    cache, out = tmp_path / "cache", tmp_path / "runs"
    # the shipped scenario over 0.1 s of its 1 s: what is checked is the run store and the cache
    # under two writers, not the identification (a failed verdict, exit 1, is accepted below)
    scenario = _variant(tmp_path / "cantilever_stiff_impact_lsq.toml", "cantilever_stiff_impact_lsq",
                        "cantilever_stiff_impact_lsq", """
        [simulation]
        duration = 0.1
    """)
    cmd = [sys.executable, "-m", "testbed.cli", "run", str(scenario), "--no-figures",
           "--cache", str(cache), "-o", str(out)]
    procs = [subprocess.Popen(cmd, cwd=ROOT, env=_env(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              text=True) for _ in range(2)]
    results = [p.communicate(timeout=300) for p in procs]
    for p, (stdout, stderr) in zip(procs, results, strict=True):
        assert p.returncode in (0, 1) and "Traceback" not in stderr, stderr
        assert "run written to" in stdout
    assert sorted(p.name for p in out.iterdir()) == [".runs.lock", "cantilever_stiff_impact_lsq",
                                                      "index.html"]
    folder = out / "cantilever_stiff_impact_lsq"
    runs = sorted(p for p in folder.iterdir() if p.is_dir())
    assert len(runs) == 2 and sorted(p.name for p in folder.iterdir() if not p.is_dir()) == ["latest.json"]
    for d in runs:
        run = load_run(d)
        assert sorted(p.name for p in run.path.iterdir()) == ["run.json", "run.npz"]
        assert run.scenario["name"] == "cantilever_stiff_impact_lsq"
    written = {line.removeprefix("run written to ").split(" ")[0] for stdout, _ in results
               for line in stdout.splitlines() if line.startswith("run written to ")}
    assert written == {str(d) for d in runs}
    assert (out / "index.html").read_text().count("<tr>") == 1 + 2
    assert [p.name for p in cache.iterdir()] == [DatasetCache(cache).path(
        load_scenario(scenario)).name], "one whole cache entry, no temporary file"


# --------------------------------------------------------------------------- paths that name no file
def _cli(argv: list[str], capsys) -> tuple[int, str]:
    from testbed.cli import main

    code = main(argv)
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.splitlines()) == 1, err
    return code, err


#: (argv, fragment): every path a command reads or writes is checked before any work.  A
#: FIFO or device as an output was replaced by the atomic rename (as root, `--results
#: /dev/full` replaced the device node with a parquet file); a symbolic-link loop and a name
#: too long for the file system were internal errors (RuntimeError, OSError) after the work.
BAD_PATHS = [
    (["generate", "michaelis_menten", "-o", "{tmp}/fifo"], "not a regular file (a FIFO"),
    (["sweep", "smoke", "--results", "{tmp}/fifo"], "not a regular file (a FIFO"),
    (["identify", "{tmp}/fifo", "--kind", "dynamical", "--method", "sindy_pi_dynamical"],
     "not a regular file (a FIFO"),
    (["run", "michaelis_menten", "--no-figures", "--out", "{tmp}/loop"], "a symbolic link that loops"),
    (["run", "michaelis_menten", "--no-figures", "--out", "{tmp}/loop/sub"],
     "a symbolic link that loops"),
    (["sweep", "smoke", "--results", "{tmp}/loop"], "a symbolic link that loops"),
    (["cache", "ls", "--cache", "{tmp}/loop"], "a symbolic link that loops"),
    (["run", "michaelis_menten", "--no-figures", "--out", "{tmp}/" + "y" * 300],
     "a file name too long"),
    (["sweep", "smoke", "--results", "{tmp}/" + "y" * 300 + ".parquet"], "a file name too long"),
    (["run", "michaelis_menten", "--no-figures", "--out", "{tmp}/a\x00b"], "a NUL byte"),
]


@pytest.mark.parametrize(("argv", "fragment"), BAD_PATHS, ids=[" ".join(a)[:50] for a, _ in BAD_PATHS])
def test_paths_that_name_no_usable_file_are_refused_and_kept(tmp_path, capsys, argv, fragment):
    import stat

    os.mkfifo(tmp_path / "fifo")
    (tmp_path / "loop").symlink_to(tmp_path / "loop2")
    (tmp_path / "loop2").symlink_to(tmp_path / "loop")
    code, err = _cli([a.replace("{tmp}", str(tmp_path)) for a in argv], capsys)
    assert code == 2 and fragment in err, err
    assert stat.S_ISFIFO((tmp_path / "fifo").stat().st_mode)  # never replaced
    assert (tmp_path / "loop").is_symlink()


def test_run_of_a_scenario_without_identify_is_refused_before_simulating(tmp_path, capsys):
    # was refused after simulating, naming the scenario instead of its file
    path = tmp_path / "bare.toml"
    parent = (ROOT / "scenarios" / "michaelis_menten.toml").read_text()
    path.write_text(parent.split("[identify]")[0].replace('name = "michaelis_menten"', 'name = "bare"'))
    code, err = _cli(["run", str(path), "--no-figures", "--out", str(tmp_path / "runs")], capsys)
    assert code == 2 and err.startswith(f"error: {path}: key 'identify': missing [identify]"), err
    assert not (tmp_path / "runs" / "bare").exists()


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGHUP])
def test_sigterm_ends_a_command_like_ctrl_c(monkeypatch, capsys, signum):
    # `kill`, `timeout` or a batch scheduler's SIGTERM ended a sweep by the default action:
    # exit status -15 and joblib's multi-line warning about its workers' shared memory, where
    # Ctrl-C stops the workers, keeps the finished rows and says "error: interrupted"
    # (measured with `testbed sweep --jobs 2` mid-cell, SIGTERM to the main process and to its
    # group, SIGHUP: now status 143 / 129, one line, no process left, resumed with no
    # duplicate row)
    from testbed import cli

    def killed(args):
        os.kill(os.getpid(), signum)
        time.sleep(5)  # the handler raises before this ends
        return 0

    monkeypatch.setattr(cli, "cmd_list", killed)
    previous = signal.signal(signum, signal.SIG_DFL)  # as in a command (a test runner may differ)
    try:
        assert cli.main(["list"]) == 128 + signum
        assert capsys.readouterr().err == f"error: interrupted by {signal.Signals(signum).name}\n"
        assert signal.getsignal(signum) is signal.SIG_DFL  # restored: main() is called from Python
    finally:
        signal.signal(signum, previous)


@pytest.mark.parametrize(("trac", "checks", "passed"), [
    (0.97, None, True),              # as the sweep wrote it
    (math.nan, None, False),         # the score edited to NaN under its passing check
    (0.5, None, False),              # ... or to a failing value
    (0.97, "[]", False),             # its checks removed
    (0.97, "not json", False),
    (0.97, '[{"metric": "trac"}]', False),
], ids=["kept", "nan", "worse", "no-checks", "not-json", "no-threshold"])
def test_a_results_row_edited_to_pass_is_judged_again_on_read(tmp_path, trac, checks, passed):
    # `summary` and the report counted a row's stored "passed": a results row edited over a
    # NaN score was a pass in the pass rate
    res = tmp_path / "r.parquet"
    check = [{"metric": "trac", "value": 0.97, "bound": "min", "threshold": 0.9, "passed": True}]
    write_part(res, {"cell": "c0", "study": "s", "scenario": "a", "noise": 0.0, "seed": 0,
                     "identifier": "m", "status": "ok", "error": "", "trac": trac, "passed": True,
                     "checks": json.dumps(check) if checks is None else checks})
    (row,) = read_results(res)
    assert row["passed"] is passed
    rate = summarize(res)[0]["pass_rate"]  # (a row without checks is held to no bar: NaN)
    assert rate == float(passed) or (checks in ("[]", "not json") and math.isnan(rate))


def test_cache_clear_deletes_only_the_caches_own_entries(tmp_path):
    # `testbed cache clear --cache <folder>` deleted every *.h5 of the folder: a user's own
    # datasets (`testbed generate -o <folder>/mine.h5`) with the cache's entries
    entry = tmp_path / f"michaelis_menten-{'0123456789abcdef' * 2}.h5"
    for p in (entry, tmp_path / "mine.h5", tmp_path / f"mine-{'0' * 31}.h5"):
        p.write_bytes(b"x")
    cache = DatasetCache(tmp_path)
    assert [p for p, _ in cache.entries()] == [entry]
    assert cache.clear() == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"mine-{'0' * 31}.h5", "mine.h5"]


def test_a_results_path_holding_another_format_is_refused_and_left_alone(fault_dir, tmp_path):
    # `sweep --results mine.h5` renamed the user's dataset mine.h5.bad as a damaged results file
    from testbed.core.errors import InputError

    study = load_study(_study(fault_dir, "other_format", ["fault_fit"], seeds=(0,), noise=(0.0,)))
    res = tmp_path / "mine.h5"
    res.write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 100)
    with pytest.raises(InputError, match=r"not a Parquet results file \(it begins with b'\\x89HDF"):
        run_sweep(study, results=res, cache_dir=tmp_path / "c", verbose=False)
    assert [p.name for p in tmp_path.iterdir()] == ["mine.h5"] and res.read_bytes()[:4] == b"\x89HDF"
    res.write_bytes(b"PAR1" + b"\0" * 100)  # a Parquet file cut short: set aside, its cells rerun
    assert len(read_results(run_sweep(study, results=res, cache_dir=tmp_path / "c", verbose=False))) == 1
    assert (tmp_path / "mine.h5.bad").read_bytes()[:4] == b"PAR1"


def test_a_worker_killed_by_a_plugin_is_one_line_naming_the_plugins(fault_dir, tmp_path, monkeypatch):
    # a plugin's os._exit(0) in fit killed its loky worker: "internal error (a bug, not your
    # input): TerminatedWorkerError ... please report it" (measured with --jobs 2; the worker's
    # death is mimicked here, as joblib reports it)
    from testbed.core.errors import IdentificationError
    from testbed.studies import sweep

    class TerminatedWorkerError(Exception):  # joblib.externals.loky's, by name
        pass

    real = sweep.parallel

    def dying(fn, args, n_jobs):
        if fn is not sweep.run_cell:
            yield from real(fn, args, n_jobs)
            return
        raise TerminatedWorkerError("... The exit codes of the workers are {EXIT(0), EXIT(0)} ...")

    monkeypatch.setattr(sweep, "parallel", dying)
    study = load_study(_study(fault_dir, "dying", ["fault_fit"], seeds=(0,), noise=(0.0,)))
    res = tmp_path / "r.parquet"
    with pytest.raises(IdentificationError, match=r"sweep dying: a worker process died running cells "
                                                  r"\(exit codes \{EXIT\(0\), EXIT\(0\)\}\): code of "
                                                  r"plugin\(s\) .*faults.py may exit"):
        run_sweep(study, results=res, cache_dir=tmp_path / "c", verbose=False)
    with pytest.raises(TerminatedWorkerError):  # without plugins: the testbed's own bug, raised
        run_sweep(replace(study, plugins=()), results=res, cache_dir=tmp_path / "c", verbose=False)


def test_a_signal_while_the_main_thread_is_in_compiled_code_ends_the_command_promptly(tmp_path):
    # a SIGTERM or Ctrl-C while an identifier's numba kernel (compiled, nogil) held the main
    # thread was acted on when the kernel returned: `testbed run` of a plugin whose fit is one
    # long kernel said "interrupted" 28 s after the SIGTERM (45 s with a hashlib loop, which
    # also releases the GIL and checks no signal): now within the watchdog's grace, one line, the
    # signal's status and no temporary file left.  The kernel's stand-in here (numba's compilation
    # would take seconds) is a second lock of a POSIX mutex the main thread holds, called
    # through ctypes: compiled code that releases the GIL, checks no signal and never returns,
    # as the hashlib loop was, without burning a core meanwhile (that loop spent 1 s + the grace,
    # 3 s of CPU, before the watchdog ended it).  Where the second lock returns (a mutex type that
    # checks for deadlock), the hashlib loop stands in as before.
    from testbed.core.interrupts import GRACE_S

    mark, tmp = tmp_path / "in-kernel", tmp_path / ".run.json.abc.tmp"
    # the mark is written by a thread 1 s after the kernel is entered (it releases the GIL):
    # written just before it, a SIGTERM sent at once could land while the main thread still ran
    # Python code, whose handler then raised outside any command's reporting (a traceback and
    # status 1 on a loaded machine: session 19's suite)
    code = textwrap.dedent(f"""
        import ctypes, hashlib, pathlib, threading, time
        from testbed import cli
        from testbed.core.atomic import begin_in_flight

        def mark():
            time.sleep(1.0)
            pathlib.Path({str(mark)!r}).write_text("")

        with cli._terminate_as_interrupt(console=True):
            pathlib.Path({str(tmp)!r}).write_text("half")
            begin_in_flight({str(tmp)!r})
            threading.Thread(target=mark, daemon=True).start()
            libc, mutex = ctypes.CDLL(None), ctypes.create_string_buffer(256)
            if libc.pthread_mutex_init(mutex, None) == 0 and libc.pthread_mutex_lock(mutex) == 0:
                libc.pthread_mutex_lock(mutex)  # blocks for good (a default mutex)
            hashlib.pbkdf2_hmac("sha256", b"k", b"s", 10**9)  # minutes
        print("the kernel returned")
    """)
    p = subprocess.Popen([sys.executable, "-c", code], env=_env(), cwd=tmp_path,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        deadline = time.monotonic() + 60
        while not mark.exists() and p.poll() is None and time.monotonic() < deadline:
            time.sleep(0.01)
        assert mark.exists(), p.communicate()[1]
        sent = time.monotonic()
        p.send_signal(signal.SIGTERM)
        out, err = p.communicate(timeout=GRACE_S + 30)
        took = time.monotonic() - sent
    finally:
        p.kill()
    assert (p.returncode, out, err) == (128 + signal.SIGTERM, "", "error: interrupted by SIGTERM\n")
    # the grace, and 1.5 s for the thread to wake and the process to end on a loaded machine
    # (0.06 s measured idle)
    assert GRACE_S <= took < GRACE_S + 1.5, took
    assert not tmp.exists()


def test_a_signal_handled_in_time_is_not_ended_by_the_watchdog(tmp_path):
    # the watchdog acts only when the main thread has not begun to handle the signal: a
    # command in Python code unwinds as before (its finally blocks run, its status is its own)
    from testbed.core.interrupts import GRACE_S

    code = textwrap.dedent(f"""
        import os, signal, time
        from testbed import cli
        try:
            with cli._terminate_as_interrupt(console=True):
                os.kill(os.getpid(), signal.SIGTERM)
                time.sleep(30)
        except cli.Terminated:
            time.sleep({GRACE_S} + 0.5)  # a slow but orderly clean-up, longer than the grace
            print("cleaned up")
    """)
    r = subprocess.run([sys.executable, "-c", code], env=_env(), cwd=tmp_path, capture_output=True,
                       text=True, timeout=60)
    assert (r.returncode, r.stdout, r.stderr) == (0, "cleaned up\n", "")


def test_a_run_under_a_folder_whose_name_is_not_utf8(fault_dir, tmp_path, monkeypatch, capsys):
    # a folder named in Latin-1 on a UTF-8 system, or any non-ASCII name under a locale that is
    # not UTF-8 (LC_ALL=C with Python's UTF-8 mode off): Python reads the name as lone
    # surrogates, which UTF-8 cannot write: the plugin rig's source hash (the cache key), the
    # run index and "run written to ..." on a strict UTF-8 standard output (a UTF-8 locale
    # other than C.UTF-8, PYTHONIOENCODING=utf-8) were internal errors ("surrogates not
    # allowed"), the run already saved.  The name is written as the file system's bytes.
    import io

    from testbed.cli import main
    from testbed.pipeline.plugins import IDENTIFIERS, RIGS

    folder = tmp_path / os.fsdecode(b"caf\xe9")
    folder.mkdir()
    # under names of its own: the module's plugin may be registered in this process already
    (folder / "faults.py").write_text(PLUGIN.replace('"fault_', '"latin1_'))
    (folder / "fault_a.toml").write_text(SCENARIO.replace('"fault_osc"', '"latin1_osc"')
                                         + '[identify]\nmethod = "latin1_fit"\n')
    out = folder / "runs"
    stdout = io.TextIOWrapper(io.BytesIO(), encoding="utf-8", errors="strict")
    monkeypatch.setattr(sys, "stdout", stdout)
    saved = IDENTIFIERS.snapshot(), RIGS.snapshot()  # the plugin registers its names here
    try:
        code = main(["run", str(folder / "fault_a.toml"), "--plugin", str(folder / "faults.py"),
                     "--no-figures", "--out", str(out), "--cache", str(folder / "cache")])
    finally:
        IDENTIFIERS.restore(saved[0])
        RIGS.restore(saved[1])
    assert code == 0, capsys.readouterr().err
    assert stdout.errors == "strict"  # the caller's handler is put back
    stdout.flush()
    assert b"run written to " + os.fsencode(str(out)) in stdout.buffer.getvalue()
    assert os.fsencode(str(out)) in (out / "index.html").read_bytes()
    assert len(list((folder / "cache").glob("latin1_osc-*.h5"))) == 1


def test_a_cache_folder_that_cannot_be_written_still_serves_and_the_run_goes_on(tmp_path, monkeypatch,
                                                                                caplog):
    # a read-only --cache (a shared, pre-filled one; or the default .cache under a read-only
    # current folder) ended a run after its simulation in "error: [Errno 13] Permission denied:
    # '<cache>/.<entry>.h5.<random>.tmp'"; the datasets it holds are read as before
    import errno as errno_

    from testbed.pipeline import cache as cache_mod

    sc = _short()
    filled = DatasetCache(tmp_path / "filled")
    held = filled.get(sc)

    def refused(self, path):
        raise PermissionError(errno_.EACCES, "Permission denied", str(path))

    monkeypatch.setattr(Dataset, "save", refused)
    monkeypatch.setattr(cache_mod, "_UNWRITABLE_WARNED", set())
    _assert_same_data(filled.get(sc), held)  # held: read, nothing written
    ro = DatasetCache(tmp_path / "ro")
    with caplog.at_level(logging.WARNING, logger="testbed.pipeline.cache"):
        _assert_same_data(ro.get(sc), held)
        _assert_same_data(ro.get(sc.with_noise(1.0)), filled.get(sc.with_noise(1.0)))
    assert [r.getMessage() for r in caplog.records] == [
        f"dataset cache {tmp_path / 'ro'}: cannot be written (Permission denied); datasets it "
        "lacks are simulated and not cached (--cache names another folder)"]  # once a folder
