"""Seventeenth malformed-input round: the findings of ``benchmarks/hostile17.py`` (docs/history.md,
malformed-input audits), each fixed in the layer that owns it.
"""

from __future__ import annotations

import json
import os
import re
import shutil
import sys
import warnings
from pathlib import Path

import h5py
import numpy as np
import pytest

from testbed import cli
from testbed.core.atomic import atomic_write_text
from testbed.core.dataset import Dataset, Signal
from testbed.core.errors import ArgumentError, InputError
from testbed.pipeline.importers import (
    MeasuredDataError,
    from_sep005,
    measurement_from_file,
    rate_misfit,
    read_measured,
)
from testbed.reporting.export import export_dataset
from testbed.studies.runstore import list_runs, load_run, save_new_run
from tests.testbed._saved_record import FS, saved_record


def _mm_record(path: Path, fs: float, rate_scale: float = 1.0) -> Path:
    """A Michaelis-Menten-like SEP-005 record (x = 2 exp(-t) mM and its rate, 400 samples at
    100 Hz) relabelled to the sample rate ``fs`` [Hz], its rate multiplied by ``rate_scale``."""
    t = np.arange(400) / 100.0
    x = 2.0 * np.exp(-t)
    path.write_text(json.dumps([
        {"name": "x/x", "data": x.tolist(), "unit_str": "mM", "fs": fs},
        {"name": "dx/dx", "data": (-x * rate_scale).tolist(), "unit_str": "mM/s", "fs": fs}]))
    return path


# ------------------------------------------------------------------ extreme sample rates

@pytest.mark.parametrize("fs", [1e160, 1e200, 1e300])
def test_rate_check_at_a_huge_sample_rate_is_finite(fs):
    # the rate check's time axis [s] squared underflowed to 0 at fs > ~1e154 Hz: a
    # ZeroDivisionError, an internal error of `testbed identify` (round 17).  The rate here is
    # per 100 Hz (values of a record: within the importer's 1e50), so at fs it is far too slow
    a = 2.0 * np.exp(-np.arange(400) / 100.0)[None, :]
    misfit, bias = rate_misfit(a, -a, fs)
    assert np.all(np.isfinite(misfit)) and np.all(np.isfinite(bias))
    assert misfit[0] > 1.0 or bias[0] > 1.0  # a slow rate is no rate of this signal


@pytest.mark.parametrize("fs", [1e200, 1e300])
def test_identify_of_a_record_relabelled_to_a_huge_rate_is_refused_in_one_line(tmp_path, capsys, fs):
    rec = _mm_record(tmp_path / "r.json", fs)  # the rate left per 100 Hz: not the signal's rate
    status = cli.main(["identify", str(rec), "--kind", "dynamical", "--method", "sindy_pi_dynamical",
                       "-o", str(tmp_path / "m.json")])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "is not the rate of" in err[0], err


# ------------------------------------------------------------------ a dataset file's rate attributes



def _rehashed(path: Path, key: str, value) -> Path:
    """``path`` with its root attribute ``key`` set to ``value`` and its content hash made anew
    (as a user's edit would): only the readers' own checks stand between it and a fit."""
    with h5py.File(path, "r+") as f:
        f.attrs[key] = value
    with warnings.catch_warnings():  # a complex fs cast to real: the edit's, not the reader's
        warnings.simplefilter("ignore", np.exceptions.ComplexWarning)
        ds = Dataset.load(path, verify=False)
    with h5py.File(path, "r+") as f:
        f.attrs["content_hash"] = ds.content_hash()
    return path


@pytest.mark.parametrize(("key", "value", "said"), [
    # each was read as a rate with status 0 (round 17): text by float(), True as 1 Hz, a complex
    # rate with its imaginary part dropped (a ComplexWarning over two lines), and fs_unit never
    # read (the content hash leaves it out: no rehash needed), so 1000 "kHz" fitted as 1000 Hz
    ("fs", "1000", "fs='1000'"),
    ("fs", np.bool_(True), "fs=True"),
    ("fs", np.complex128(1000 + 1j), "fs=(1000+1j)"),
    ("fs_unit", "kHz", "fs_unit='kHz'"),
    ("fs_unit", np.bytes_(b"s"), "fs_unit='s'"),
], ids=["text", "bool", "complex", "kHz", "bytes_s"])
def test_a_dataset_files_rate_must_be_one_real_number_in_hz(tmp_path, capsys, key, value, said):
    path = _rehashed(saved_record(tmp_path), key, value)
    with pytest.raises(MeasuredDataError, match=rf"attribute {re.escape(said)}.*expected"):
        read_measured(path)
    with pytest.raises(MeasuredDataError, match=re.escape(said)):
        export_dataset(path, "sep005", tmp_path / "d.json")
    status = cli.main(["identify", str(path), "--kind", "structural", "--method", "ls_sindy",
                       "-o", str(tmp_path / "m.json")])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and said in err[0], err


def test_a_dataset_files_integer_rate_in_hz_is_read(tmp_path):
    path = _rehashed(saved_record(tmp_path), "fs", np.int64(1000))  # an integer is a real number
    assert read_measured(path).fs == FS


# ------------------------------------------------------------------ channels of other start times

def _sep005_started(path: Path, lag_steps: float) -> Path:
    """Two channels of one 1000 Hz record, the second's time stamps ``lag_steps`` samples later."""
    t = np.arange(400) / FS
    path.write_text(json.dumps([
        {"name": "acc1", "data": np.sin(2 * np.pi * 7 * t).tolist(), "unit_str": "m/s^2",
         "time": t.tolist()},
        {"name": "force", "data": np.exp(-t / 0.01).tolist(), "unit_str": "N",
         "time": (t + lag_steps / FS).tolist()}]))
    return path


def test_sep005_channels_that_start_at_other_times_are_refused(tmp_path):
    # a force stamped 0.3 s after its response was lined up sample by sample with it and fitted
    # with status 0 (round 17)
    with pytest.raises(MeasuredDataError, match=r"channel 'force' starts at t = 0\.3 s.*300 samples"):
        read_measured(_sep005_started(tmp_path / "r.json", 300))
    # within half a step: a time stamp's rounding, the same instant
    assert read_measured(_sep005_started(tmp_path / "r.json", 0.4)).fs == pytest.approx(FS)


def test_uff_records_that_start_at_other_times_are_refused(tmp_path):
    import pyuff

    src = export_dataset(saved_record(tmp_path), "uff", tmp_path / "d.uff")[0]
    sets = pyuff.UFF(str(src)).read_sets()
    assert read_measured(src).fs == pytest.approx(FS)  # as exported: one start
    last = max(k for k, s in enumerate(sets) if s["type"] == 58)
    sets[last]["x"] = sets[last]["x"] + 0.3  # the force record's abscissa starts 0.3 s later
    late = tmp_path / "late.uff"
    pyuff.UFF(str(late)).write_sets(sets, mode="overwrite")
    with pytest.raises(MeasuredDataError, match=r"starts at t = 0\.3 s.*expected every channel"):
        read_measured(late)


# ------------------------------------------------------------------ a channel named twice

def test_a_dataset_signal_naming_a_channel_twice_is_refused(tmp_path):
    # channels ("acc1", "acc1"): the second replaced the first in the reader's channel table,
    # and a cantilever record of three accelerations was fitted on two (status 1, round 17)
    path = saved_record(tmp_path)
    with h5py.File(path, "r+") as f:
        f["measured/acceleration"].attrs["channels"] = np.array(["acc1", "acc1"],
                                                                dtype=h5py.string_dtype())
    _rehashed(path, "fs", FS)
    with pytest.raises(MeasuredDataError, match=r"measured/acceleration names channel 'acc1' twice"):
        read_measured(path)
    with pytest.raises(MeasuredDataError, match=r"names channel 'acc1' twice"):
        export_dataset(path, "sep005", tmp_path / "d.json")


# ------------------------------------------------------------------ a direction against its unit

@pytest.mark.parametrize(("direction", "unit", "said"), [
    ("+X rotation", "m/s^2", r"direction \+X rotation \(code 4\) is a rotation but its unit 'm/s\^2'"),
    ("-Z", "rad", r"direction -Z \(code -3\) is a translation but its unit 'rad'"),
    (5, "N", r"direction \+Y rotation \(code 5\) is a rotation"),
    (9, "m/s^2", r"direction code 9; expected -6 to 6"),  # read as a translation along X
    (-7, "m/s^2", r"direction code -7; expected -6 to 6"),
])
def test_a_channel_whose_direction_and_unit_disagree_is_refused(tmp_path, direction, unit, said):
    # an acceleration "about X" was read and fitted with status 0 (round 17)
    t = np.arange(400) / FS
    path = tmp_path / "r.json"
    path.write_text(json.dumps([{"name": "c", "data": np.sin(2 * np.pi * 7 * t).tolist(),
                                 "unit_str": unit, "fs": FS, "direction": direction}]))
    with pytest.raises(MeasuredDataError, match=said):
        read_measured(path)


def test_exports_of_every_unit_keep_direction_and_unit_of_one_kind(tmp_path):
    # the exporter writes +Z for a translation's unit and +Z rotation for a rotation's: both
    # formats read back (a cart-pole's record holds both kinds of channel in one signal)
    t = np.arange(400) / FS
    ds = Dataset(FS, {"q": Signal(np.vstack([np.sin(2 * np.pi * 7 * t), np.cos(2 * np.pi * 7 * t)]),
                                  ("x", "th"), "m, rad"),
                      "u": Signal(np.sin(2 * np.pi * 3 * t)[None, :], ("f",), "N")})
    path = ds.save(tmp_path / "d.h5")
    for fmt in ("uff", "sep005"):
        out = export_dataset(path, fmt, tmp_path / f"d.{'uff' if fmt == 'uff' else 'json'}")[0]
        got = read_measured(out)
        assert sorted(got.signals) == ["q/th", "q/x", "u/f"], fmt


# ------------------------------------------------------------------ a run's format edited to /1

@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """One run in a run history (its folder), written by save_new_run."""
    if str(Path(__file__).parent) not in sys.path:
        sys.path.insert(0, str(Path(__file__).parent))
    import _synthetic_runs

    return save_new_run(_synthetic_runs.structural_result(n_samples=200),
                        tmp_path_factory.mktemp("runs"))


@pytest.mark.parametrize("keep", [("sha256", "npz_sha256"), ("sha256",), ("npz_sha256",)])
def test_a_run_whose_format_was_edited_to_1_is_refused(saved, tmp_path, keep):
    # format /1 has no checksums and is read unchecked: a /2 run.json edited to say /1 (and a
    # score edited with it) was listed and reported as the run's own (round 17)
    out = tmp_path / "runs"
    shutil.copytree(saved.parent.parent, out)
    run = out / saved.parent.name / saved.name
    meta = json.loads((run / "run.json").read_text())
    meta["format"] = "sysid-testbed-run/1"
    meta["scores"][next(iter(meta["scores"]))] = 123.0
    for k in {"sha256", "npz_sha256"} - set(keep):
        del meta[k]
    (run / "run.json").write_text(json.dumps(meta, indent=2))
    damaged: list = []
    assert list_runs(out, damaged=damaged) == [] and damaged == [run]
    with pytest.raises(ValueError, match=r"format 'sysid-testbed-run/1' with .*sha256.*edited"):
        load_run(run)


# ------------------------------------------------------------------ the import API's arguments

@pytest.mark.parametrize(("kwargs", "said"), [
    # each was an AttributeError, a ValueError of max() or a TypeError of pathlib (round 17)
    ({"units": 5}, "units=5: expected a unit"),
    ({"units": ["m/s^2"]}, r"units=\['m/s\^2'\]: expected"),
    ({"units": {"acc1": 5}}, r"units=\{'acc1': 5\}: expected"),
    ({"channels": []}, r"channels=\[\]: expected a non-empty list"),
    ({"channels": "acc1"}, "channels='acc1': expected"),
    ({"channels": [5]}, r"channels=\[5\]: expected"),
], ids=["units int", "units list", "units value int", "channels empty", "channels text", "channels int"])
def test_read_measured_refuses_arguments_of_the_wrong_type(tmp_path, kwargs, said):
    rec = _sep005_started(tmp_path / "r.json", 0)
    with pytest.raises(MeasuredDataError, match=said):
        read_measured(rec, **kwargs)
    chans = json.loads(rec.read_text())
    with pytest.raises(MeasuredDataError, match=said):
        from_sep005(chans, **kwargs)


def test_channels_and_groups_as_numpy_arrays_are_still_names(tmp_path):
    # review: the checks above refused np.array(["acc1"]) (worked before them)
    rec = _sep005_started(tmp_path / "r.json", 0)
    data = read_measured(rec, channels=np.array(["acc1", "force"]))
    assert list(data.signals) == ["acc1", "force"]
    data.to_dataset({"acceleration": np.array(["acc1"]), "force": np.array(["force"])})


@pytest.mark.parametrize("path", [5, None, b"r.json"])
def test_read_measured_refuses_a_path_that_is_not_one(path):
    with pytest.raises(MeasuredDataError, match=r"path=.*expected a file path"):
        read_measured(path)


@pytest.mark.parametrize("signal", [5, [], "recorded"])
def test_measurement_from_file_refuses_a_signal_table_that_is_not_one(tmp_path, signal):
    rec = _mm_record(tmp_path / "r.json", 100.0)
    with pytest.raises(MeasuredDataError, match=r"signal=.*expected a \[signal\] table"):
        measurement_from_file(rec, "dynamical", signal)


def test_a_masked_sample_is_not_read_as_a_value():
    # np.asarray dropped the mask: the masked first sample was read as the value under it
    data = np.ma.masked_array(np.sin(np.arange(400) / 10.0), mask=[True] + [False] * 399)
    chan = [{"name": "acc1", "data": data, "unit_str": "m/s^2", "fs": FS}]
    with pytest.raises(MeasuredDataError, match=r"masked array with 1 masked sample"):
        from_sep005(chan)
    chan[0]["data"] = np.ma.masked_array(data.data, mask=False)  # nothing masked: read
    assert from_sep005(chan).fs == FS


# ------------------------------------------------------------------ identify's output and its report

@pytest.mark.parametrize("name", ["m.md", "m.MD"])
def test_identify_refuses_an_output_that_its_report_would_replace(tmp_path, capsys, name):
    # -o m.md: "model written to m.md (report m.md)", the model JSON overwritten by its report
    # (round 17)
    rec = _mm_record(tmp_path / "r.json", 100.0)
    status = cli.main(["identify", str(rec), "--kind", "dynamical", "--method", "sindy_pi_dynamical",
                       "-o", str(tmp_path / name)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "the report would replace the model" in err[0], err
    assert not (tmp_path / name).exists()


# ------------------------------------------------------------------ outputs over the given files

SCENARIOS = Path(__file__).resolve().parents[2] / "scenarios"
CACHE = Path(__file__).resolve().parents[2] / ".cache" / "datasets"


def test_generate_refuses_to_write_over_its_scenario_or_a_file_it_extends(tmp_path, capsys):
    # `generate s.toml -o s.toml` replaced the scenario file by the dataset, status 0 (round 17)
    parent = tmp_path / "michaelis_menten.toml"
    parent.write_text((SCENARIOS / "michaelis_menten.toml").read_text())
    child = tmp_path / "child.toml"
    child.write_text('[scenario]\nname = "child"\nextends = "michaelis_menten.toml"\n')
    before = {p: p.read_bytes() for p in (parent, child)}
    for out in (child, parent):
        status = cli.main(["generate", str(child), "-o", str(out), "--cache", str(CACHE)])
        err = capsys.readouterr().err.strip().splitlines()
        assert status == 2 and len(err) == 1 and "is the input file" in err[0], err
    assert {p: p.read_bytes() for p in before} == before


def test_identify_refuses_to_write_over_its_scenario(tmp_path, capsys):
    rec = _mm_record(tmp_path / "r.json", 100.0)
    scen = tmp_path / "michaelis_menten.toml"
    scen.write_text((SCENARIOS / "michaelis_menten.toml").read_text())
    # review: a file the scenario extends was not protected, nor a name in upper case
    child = tmp_path / "child.TOML"
    child.write_text('[scenario]\nname = "child"\nextends = "michaelis_menten.toml"\n')
    before = {p: p.read_bytes() for p in (scen, child)}
    for given, out in ((scen, scen), (child, scen), (child, child)):
        status = cli.main(["identify", str(rec), "--scenario", str(given), "--kind", "dynamical",
                           "-o", str(out)])
        err = capsys.readouterr().err.strip().splitlines()
        assert status == 2 and len(err) == 1 and "is the input file" in err[0], (given, out, err)
    assert {p: p.read_bytes() for p in before} == before


def test_generate_refuses_to_write_over_its_scenario_named_in_upper_case(tmp_path, capsys):
    # review: `generate s.TOML -o s.TOML` wrote HDF5 over the scenario, status 0
    scen = tmp_path / "michaelis_menten.TOML"
    scen.write_text((SCENARIOS / "michaelis_menten.toml").read_text())
    text = scen.read_text()
    status = cli.main(["generate", str(scen), "-o", str(scen), "--cache", str(CACHE)])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "is the input file" in err[0], err
    assert scen.read_text() == text


# ------------------------------------------------------------------ mechanical units, channel by channel

def _cart_pole_like(tmp_path: Path, theta_unit: str = "m, rad", torque_unit: str = "N",
                    acts_on: str = "x") -> Path:
    """A two-coordinate record (a cart's position [m] and a pole's angle [rad]) with exact
    rates, and a force on the cart: 2,000 samples at 200 Hz."""
    fs = 200.0
    t = np.arange(2000) / fs
    w = 2 * np.pi * np.array([[0.7], [1.3]])
    q = 0.2 * np.sin(w * t)
    ds = Dataset(fs, {"theta": Signal(q, ("x", "th"), theta_unit),
                      "dtheta": Signal(0.2 * w * np.cos(w * t), ("dx", "dth"), "m/s, rad/s"),
                      "ddtheta": Signal(-w**2 * q, ("ddx", "ddth"), "m/s^2, rad/s^2"),
                      "torque": Signal(np.sin(2 * np.pi * 0.5 * t)[None, :], ("u1",), torque_unit,
                                       acts_on=(acts_on,))})
    return ds.save(tmp_path / "cp.h5")


@pytest.mark.parametrize(("change", "said"), [
    # each was fitted with status 0 (round 17): every unit was checked alone
    ({"theta_unit": "rad, m"}, r"'dtheta' channel 'dx' is in m/s; expected rad/s, the rate of "
                               r"'theta' channel 'x' in rad"),
    ({"theta_unit": "m"}, r"'dtheta' channel 'dth' is in rad/s; expected m/s"),
    ({"torque_unit": "N m"}, r"'torque' channel 'u1' is in N m but acts on 'theta' channel 'x' "
                             r"in m; expected N"),
    ({"acts_on": "th"}, r"'u1' is in N but acts on 'theta' channel 'th' in rad; expected N m"),
], ids=["angle and position swapped", "one unit for both", "a moment on a cart", "a force on a pole"])
def test_a_mechanical_record_whose_units_disagree_channel_by_channel_is_refused(tmp_path, change, said):
    with pytest.raises(MeasuredDataError, match=said):
        measurement_from_file(_cart_pole_like(tmp_path, **change), "mechanical")


def test_a_mechanical_record_whose_units_agree_is_measured(tmp_path):
    m = measurement_from_file(_cart_pole_like(tmp_path), "mechanical")
    assert m.x.shape == (2, 2000)


# ------------------------------------------------------------------ to_dataset arguments

@pytest.mark.parametrize(("groups", "said"), [
    # an AttributeError, or a Dataset with a channel twice or a signal no file can name (round 17)
    (5, r"groups=5: expected a mapping"),
    ({"acceleration": ["acc1", "acc1"]}, r"channel 'acc1' is given twice"),
    ({"acceleration": ["acc1"], "force": ["acc1"]}, r"channel 'acc1' is given twice \(in group "
                                                    r"'acceleration' and 'force'\)"),
    ({"": ["acc1"]}, r"signal name ''"),
    ({"a/b": ["acc1"]}, r"signal name 'a/b'"),
    ({5: ["acc1"]}, r"signal name 5"),
    ({"acceleration": "acc1"}, r"group 'acceleration': 'acc1'; expected a list"),
], ids=["int", "twice in one", "in two", "empty name", "slash", "int name", "text"])
def test_to_dataset_refuses_groups_that_are_not_a_grouping(tmp_path, groups, said):
    data = read_measured(_sep005_started(tmp_path / "r.json", 0))
    with pytest.raises(MeasuredDataError, match=said):
        data.to_dataset(groups)


def test_to_dataset_refuses_two_channels_of_one_name_in_a_signal():
    t = np.arange(400) / FS
    data = from_sep005([{"name": f"{g}/x", "data": np.sin(2 * np.pi * 7 * t * k).tolist(),
                         "unit_str": "m/s^2", "fs": FS} for k, g in ((1, "a"), (2, "b"))])
    with pytest.raises(MeasuredDataError, match=r"two channels named 'x'"):
        data.to_dataset({"acceleration": ["a/x", "b/x"]})


@pytest.mark.parametrize(("prior", "said"), [
    (5, r"prior=5: expected a mapping"), ([], r"prior=\[\]: expected a mapping"),
    ({"total_mass": 10**400}, r"prior total_mass=1000.*expected a finite number"),
], ids=["int", "list", "10**400"])
def test_to_dataset_refuses_a_prior_that_is_not_one(tmp_path, prior, said):
    # a TypeError, an empty list taken as no prior, and math.isfinite's OverflowError
    data = read_measured(_sep005_started(tmp_path / "r.json", 0))
    with pytest.raises(MeasuredDataError, match=said):
        data.to_dataset(None, prior)


# ------------------------------------------------------------------ export_dataset's arguments

@pytest.mark.parametrize(("kwargs", "said"), [
    # a ValueError (after reading the file), TypeErrors, and an IsADirectoryError naming the
    # temporary file (round 17)
    ({"fmt": "UFF"}, r"'fmt': value 'UFF': unknown export format"),
    ({"fmt": None}, r"'fmt': value None: unknown export format"),
    ({"out": 5}, r"'out': value 5: of type int; expected a file path"),
    ({"out": b"x.uff"}, r"'out': value b'x.uff': of type bytes"),
    ({"path": None}, r"'path': value None: of type NoneType"),
], ids=["UFF", "None", "out int", "out bytes", "path None"])
def test_export_dataset_refuses_arguments_that_are_not_its_own(tmp_path, kwargs, said):
    args = {"path": saved_record(tmp_path), "fmt": "uff", "out": tmp_path / "d.uff", **kwargs}
    with pytest.raises(ArgumentError, match=said):
        export_dataset(args["path"], args["fmt"], args["out"])


def test_an_atomic_write_onto_a_folder_is_refused_naming_it(tmp_path):
    (tmp_path / "f").mkdir()
    with pytest.raises(InputError, match=r"/f: is a folder; expected a file path"):
        export_dataset(saved_record(tmp_path), "uff", tmp_path / "f")
    with pytest.raises(InputError, match=r"is a folder"):
        atomic_write_text(tmp_path / "f", "x")
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []  # no temporary left


# ------------------------------------------------------------------ out of file descriptors

@pytest.mark.slow  # a whole run in a subprocess (about 10 s)
def test_running_out_of_file_descriptors_is_one_line(tmp_path):
    # `ulimit -n 8; testbed run michaelis_menten` was an internal error, "OSError: [Errno 24] Too
    # many open files" (the drawing process's pipes), status 3 (round 17)
    import resource
    import subprocess
    import sys as _sys

    def limit():
        resource.setrlimit(resource.RLIMIT_NOFILE, (8, 8))

    env = {**os.environ, "TESTBED_NO_SERVER": "1", "MPLBACKEND": "Agg", "OMP_NUM_THREADS": "1",
           "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    p = subprocess.run([_sys.executable, "-m", "testbed.cli", "run", "michaelis_menten", "--cache",
                        str(CACHE), "--out", str(tmp_path / "runs")], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=300, preexec_fn=limit)
    err = p.stderr.strip().splitlines()
    assert p.returncode == 2 and len(err) == 1, p.stderr[-400:]
    assert "too many open files: this process may open 8 (`ulimit -n`)" in err[0]


def test_the_descriptor_limit_is_found_in_an_exception_chain():
    import errno

    try:
        try:
            raise OSError(errno.EMFILE, "Too many open files")
        except OSError as inner:
            raise RuntimeError("a drawing process failed") from inner
    except RuntimeError as outer:
        said = cli._descriptor_limit(outer)
    assert said is not None and said.startswith("too many open files: this process may open")
    assert cli._descriptor_limit(OSError(errno.ENFILE, "x")).startswith("too many open files in the system")
    assert cli._descriptor_limit(OSError(errno.ENOENT, "x")) is None


@pytest.mark.parametrize("ds", [5, None, {}], ids=["int", "None", "dict"])
def test_the_exporters_refuse_what_is_not_a_dataset(tmp_path, ds):
    from testbed.reporting.export import to_sep005, write_sep005, write_uff

    # AttributeError: 'int' object has no attribute 'measured' (round 17)
    for fn in (lambda: write_uff(ds, tmp_path / "d.uff"), lambda: write_sep005(ds, tmp_path / "d.json"),
               lambda: to_sep005(ds)):
        with pytest.raises(ArgumentError, match=r"argument 'ds'.*expected a Dataset"):
            fn()
