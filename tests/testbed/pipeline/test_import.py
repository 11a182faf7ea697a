"""Importing measured data: round trips through the exports, CSV, and one-line errors for bad files."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import numpy as np
import pytest
import pyuff

from testbed.core.dataset import Dataset, Signal
from testbed.core.errors import TestbedError
from testbed.pipeline.importers import MeasuredDataError, from_sep005, measurement_from_file, read_measured
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure
from testbed.reporting.export import export_dataset, to_sep005

FS = 1000.0
N = 400


@pytest.fixture(scope="module")
def beam(dataset_cache, tmp_path_factory):
    """The cantilever_stiff_impact dataset saved as HDF5, and the dataset as loaded back."""
    path = dataset_cache.get(load_scenario("cantilever_stiff_impact")).save(
        tmp_path_factory.mktemp("beam") / "beam.h5")
    return path, Dataset.load(path)


def fivebar_dataset() -> Dataset:
    """The five-bar rig's measured signals (names, units, channels) on made-up motion."""
    t = np.arange(N) / FS
    w = 2 * np.pi * np.arange(1, 5)[:, None]
    th = 1.0 + 0.3 * np.sin(w * t)
    return Dataset(FS, {"theta": Signal(th, ("th1", "th2", "th3", "th4"), "rad"),
                        "dtheta": Signal(0.3 * w * np.cos(w * t), ("dth1", "dth2", "dth3", "dth4"), "rad/s"),
                        "ddtheta": Signal(-0.3 * w**2 * np.sin(w * t), ("ddth1", "ddth2", "ddth3", "ddth4"),
                                          "rad/s^2"),
                        "torque": Signal(np.array([np.cos(w[0] * t), 0.5 * np.sin(w[0] * t)]), ("u1", "u2"),
                                         "N m", acts_on=("th1", "th4"))},
                   truth={"equation_terms": ["ddth1", "u1"], "equation_coef": np.array([[1.0, -1.0]])},
                   prior={"L0": 0.2}, attrs={"rig": "fivebar", "seed": 0})


def assert_same_measured(imported, ds: Dataset) -> None:
    """Every measured channel of ``ds`` is in ``imported``, bit for bit, with its unit."""
    names = [f"{g}/{ch}" for g, s in ds.measured.items() for ch in s.channels]
    assert list(imported.signals) == names
    assert imported.fs == ds.fs
    for g, s in ds.measured.items():
        for i, ch in enumerate(s.channels):
            unit, x = imported.signals[f"{g}/{ch}"]
            assert unit == s.unit and x.shape == (ds.n_samples,)
            np.testing.assert_array_equal(x, s.data[i])


@pytest.mark.parametrize("fmt", ["uff", "sep005", "hdf5"])
def test_beam_round_trip_feeds_the_signal_chain(beam, fmt, tmp_path):
    path, ds = beam
    src = path if fmt == "hdf5" else export_dataset(path, fmt, tmp_path / f"beam.{fmt}")[0]
    data = read_measured(src, format=None if fmt == "hdf5" else fmt)
    assert data.format == fmt and data.source == src
    assert_same_measured(data, ds)  # binary doubles (UFF58) and JSON floats are exact
    sensors = ds.measured["acceleration"].positions
    for i in range(3):
        assert data.positions[f"acceleration/acc{i + 1}"] == sensors[i]
    assert data.positions["force/force"] == ds.measured["force"].positions[0]
    if fmt != "hdf5":
        assert [data.nodes[f"acceleration/acc{i + 1}"] for i in range(3)] == [1, 2, 3]
        assert data.nodes["force/force"] == 3, "the impact at the tip sensor's node"
    if fmt == "uff":
        assert set(data.directions.values()) == {3}
    # truth-free: nothing but measured signals, and the prior only from the project's own file
    imported = data.to_dataset()
    assert not imported.truth and not imported.reference
    assert imported.prior == (ds.prior if fmt == "hdf5" else {})
    a = measure(imported, {}, "structural")
    b = measure(ds, {}, "structural")
    for key in ("x", "xd", "xdd", "u", "input_map"):
        np.testing.assert_array_equal(getattr(a, key), getattr(b, key))
    assert (a.channels, a.inputs, a.free_start) == (b.channels, b.inputs, b.free_start)


def test_fivebar_uff_round_trip_and_input_nodes(tmp_path):
    path = fivebar_dataset().save(tmp_path / "fb.h5")
    ds = Dataset.load(path)
    (out,) = export_dataset(path, "uff")
    data = read_measured(out)
    assert_same_measured(data, ds)
    assert (data.nodes["torque/u1"], data.nodes["torque/u2"]) == (1, 4)
    assert data.directions["theta/th2"] == 6 and not data.positions, "no geometry for a mechanism"
    m = measure(data.to_dataset(prior={"L0": 0.2}), {"derivatives": "recorded"}, "mechanical")
    ref = measure(ds, {"derivatives": "recorded"}, "mechanical")
    np.testing.assert_array_equal(m.x, ref.x)
    np.testing.assert_array_equal(m.u, ref.u)
    # the torques' joints come back from their UFF nodes (u2 sits at th4's node 4)
    np.testing.assert_array_equal(m.input_map, ref.input_map)
    np.testing.assert_array_equal(m.input_map, [[1, 0], [0, 0], [0, 0], [0, 1]])
    assert m.prior == {"L0": 0.2}


def test_hdf5_reads_measured_signals_only(tmp_path):
    ds = fivebar_dataset()
    ds.reference["E"] = Signal(np.zeros((2, N)), ("Ex", "Ey"), "m")
    data = read_measured(ds.save(tmp_path / "fb.hdf5"), channels=["torque/u2", "theta/th1"])
    assert list(data.signals) == ["torque/u2", "theta/th1"]
    assert data.prior == {"L0": 0.2}
    np.testing.assert_array_equal(data.signals["torque/u2"][1], ds.measured["torque"].data[1])


def test_sep005_generic_list_with_time_and_direction_text():
    t = np.arange(50) / 200.0
    chans = [{"name": "a", "data": np.sin(t), "unit_str": "g", "time": t, "direction": "-Y"},
             {"name": "f", "data": list(np.cos(t)), "unit_str": "kN", "time": t.tolist(), "node": 7}]
    data = from_sep005(chans)
    # the rate from the time column (t = k / 200 s): 200 Hz to rounding; g to m/s^2 is one
    # product per sample, exact to its rounding (1e-15)
    assert data.fs == pytest.approx(200.0, rel=1e-12)
    np.testing.assert_allclose(data.signals["a"][1], 9.80665 * np.sin(t), rtol=1e-15)
    assert data.signals["a"][0] == "m/s^2" and data.signals["f"][0] == "N"
    assert data.directions == {"a": -2} and data.nodes == {"f": 7}
    # the export's in-memory list is a SEP-005 list too
    ds = fivebar_dataset()
    assert_same_measured(from_sep005(to_sep005(ds)), ds)


def test_csv_with_time_column_and_header_units(tmp_path):
    t = np.arange(N) / FS
    acc, force = np.sin(40 * t), np.exp(-t)
    path = tmp_path / "rec.csv"
    rows = "\n".join(f"{a!r},{b!r},{c!r}"  # plain Python floats: repr() is exact
                     for a, b, c in zip(t.tolist(), acc.tolist(), force.tolist(), strict=True))
    path.write_text(f"# a comment\ntime [s],acc1 [m/s^2],hammer (N)\n{rows}\n")
    data = read_measured(path)
    assert data.fs == pytest.approx(FS, rel=1e-12) and list(data.signals) == ["acc1", "hammer"]
    np.testing.assert_array_equal(data.signals["acc1"][1], acc)
    assert data.signals["hammer"][0] == "N"
    np.testing.assert_array_equal(data.signals["hammer"][1], force)  # repr() of a float is exact
    assert read_measured(path, fs=FS).fs == FS  # a declared rate that agrees is used exactly
    ds = data.to_dataset({"acceleration": ["acc1"], "force": ["hammer"]})
    assert ds.measured["force"].channels == ("hammer",) and ds.measured["acceleration"].unit == "m/s^2"


def test_csv_declared_rate_and_units_blank_delimited(tmp_path):
    path = tmp_path / "rec.txt"
    path.write_text("th1 th4\n" + "\n".join(f"{k} {2 * k}" for k in range(10)))
    data = read_measured(path, fs=100.0, units={"th1": "deg", "th4": "rad"})
    np.testing.assert_allclose(data.signals["th1"][1], np.deg2rad(np.arange(10.0)))
    assert data.signals["th1"][0] == "rad" and data.fs == 100.0
    assert list(read_measured(path, fs=100.0, units="N m", channels=["th4"]).signals) == ["th4"]
    semi = tmp_path / "semi.csv"
    semi.write_text("t;x\n0;1\n0.5;2\n1.0;3\n")
    assert read_measured(semi, units="m").fs == 2.0


def write(tmp_path, name: str, text: str):
    p = tmp_path / name
    p.write_text(text)
    return p


def frf_uff(path):
    s = pyuff.prepare_58(binary=0, func_type=4, rsp_node=1, rsp_dir=3, ref_node=1, ref_dir=3,
                         data=np.ones(8, dtype=complex), x=np.arange(8.0), id1="frf", rsp_ent_name="a",
                         ref_ent_name="a", abscissa_spacing=1, abscissa_spec_data_type=18,
                         ordinate_spec_data_type=12, orddenom_spec_data_type=13)
    pyuff.UFF(str(path)).write_sets([s], mode="add")
    return path


def units_only_uff(path):
    pyuff.UFF(str(path)).write_sets([pyuff.prepare_164(units_code=1, units_description="SI", temp_mode=1,
                                                       length=1.0, force=1.0, temp=1.0, temp_offset=0.0)],
                                    mode="add")
    return path


MALFORMED = [
    ("missing file", lambda d: d / "nope.csv", {}, "no such file"),
    ("unknown suffix", lambda d: write(d, "x.dat", "a\n1\n"), {}, "suffix"),
    ("unknown format", lambda d: write(d, "x.csv", "a\n1\n"), {"format": "mat"}, "unknown format"),
    ("non-uniform time", lambda d: write(d, "x.csv", "t,a\n0,1\n0.1,2\n0.3,3\n0.4,4\n"),
     {"units": "m"}, "not uniform"),
    ("ragged row", lambda d: write(d, "x.csv", "t,a,b\n0,1,2\n0.1,2\n"), {"units": "m"},
     "line 3 has 2 fields"),
    ("text in data", lambda d: write(d, "x.csv", "t,a\n0,1\n0.1,oops\n"), {"units": "m"}, "'oops'"),
    ("NaN", lambda d: write(d, "x.csv", "t,a\n0,1\n0.1,nan\n0.2,1\n"), {"units": "m"}, "NaN"),
    ("unknown unit", lambda d: write(d, "x.csv", "t,a [furlong]\n0,1\n0.1,2\n"), {},
     "unknown unit 'furlong'"),
    ("no unit", lambda d: write(d, "x.csv", "t,a\n0,1\n0.1,2\n"), {}, "no unit"),
    ("no rate", lambda d: write(d, "x.csv", "a,b\n0,1\n0.1,2\n"), {"units": "m"}, "pass fs="),
    ("rate contradicted", lambda d: write(d, "x.csv", "t,a\n0,1\n0.1,2\n"), {"units": "m", "fs": 50.0},
     "declared fs=50"),
    ("unknown channel", lambda d: write(d, "x.csv", "t,a\n0,1\n0.1,2\n"), {"units": "m", "channels": ["b"]},
     "no channel 'b'"),
    ("JSON not a list", lambda d: write(d, "x.json", '"hello"'), {}, "list of channel dicts"),
    ("JSON broken", lambda d: write(d, "x.json", "[{"), {}, "not a SEP-005 JSON file"),
    ("SEP-005 lengths", lambda d: write(d, "x.json", json.dumps(
        [{"name": "a", "data": [1, 2, 3], "unit_str": "m", "fs": 10},
         {"name": "b", "data": [1, 2], "unit_str": "m", "fs": 10}])), {}, "different lengths"),
    ("SEP-005 rates", lambda d: write(d, "x.json", json.dumps(
        [{"name": "a", "data": [1, 2], "unit_str": "m", "fs": 10},
         {"name": "b", "data": [1, 2], "unit_str": "m", "fs": 20}])), {}, "different sample rates"),
    ("SEP-005 no rate", lambda d: write(d, "x.json", json.dumps([{"name": "a", "data": [1, 2]}])), {},
     "neither fs nor time"),
    ("SEP-005 null", lambda d: write(d, "x.json", json.dumps(
        [{"name": "a", "data": [1, None], "unit_str": "m", "fs": 10}])), {}, "NaN"),
    # were internal errors: ValueError converting the time, RecursionError in json
    ("SEP-005 time text", lambda d: write(d, "x.json", json.dumps(
        [{"name": "a", "data": [1, 2], "unit_str": "m", "time": "ab"}])), {}, "time values are not numbers"),
    ("JSON nested deep", lambda d: write(d, "x.json", "[" * 100000 + "]" * 100000), {},
     "nested too deeply"),
    ("SEP-005 time shape", lambda d: write(d, "x.json", json.dumps(
        [{"name": "a", "data": [1, 2], "unit_str": "m", "time": [[0], [1]]}])), {},
     "time of shape (2, 1) for data of shape (2,)"),
    ("garbage UFF", lambda d: write(d, "x.uff", "    -1\n    58\nnot a record\n    -1\n"), {}, "UFF"),
    ("not UFF", lambda d: write(d, "x.uff", "hello\n"), {}, "not a complete UFF file"),
    ("UFF without 58", lambda d: units_only_uff(d / "u.uff"), {}, "no UFF58"),
    ("UFF frequency response", lambda d: frf_uff(d / "frf.uff"), {}, "not a time response"),
    ("not HDF5", lambda d: write(d, "x.h5", "plain text"), {}, "unreadable dataset file"),
]


@pytest.mark.parametrize(("make", "kwargs", "words"), [m[1:] for m in MALFORMED],
                         ids=[m[0] for m in MALFORMED])
def test_malformed_files_raise_one_line_naming_the_file(tmp_path, make, kwargs, words):
    path = make(tmp_path)
    with pytest.raises(MeasuredDataError) as err:
        read_measured(path, **kwargs)
    msg = str(err.value)
    assert isinstance(err.value, TestbedError)
    assert msg.startswith(f"{path}: ") and "\n" not in msg
    assert words in msg, msg
    # no h5py / pyuff / json traceback chained to it
    assert err.value.__cause__ is None and (err.value.__context__ is None or err.value.__suppress_context__)


@pytest.mark.parametrize(("name", "simulation"), [
    ("cartpole", {"duration": 0.5}), ("michaelis_menten", {"duration": 0.5})])
def test_the_testbeds_own_datasets_of_every_rig_read_back(tmp_path, name, simulation):
    # `testbed identify` refused them: the cart-pole's coordinates state one unit each
    # ("m, rad": was "unknown unit"), the kinetics rig's concentrations have no SI form ("mM")
    from testbed.pipeline.generate import simulate_clean
    from testbed.pipeline.plugins import rig_kind

    sc = load_scenario(name)
    sc = sc.replace(simulation={**sc.simulation, **simulation})
    ds = simulate_clean(sc)
    kind = rig_kind(sc.rig)
    path = ds.save(tmp_path / f"{name}.h5")
    imported = read_measured(path).to_dataset()
    for g, sig in ds.measured.items():
        assert imported.measured[g].unit == sig.unit, g
        np.testing.assert_array_equal(imported.measured[g].data, sig.data)
    m = measurement_from_file(path, kind, dict(sc.signal))
    ref = measure(ds, dict(sc.signal), kind)
    np.testing.assert_array_equal(m.x, ref.x)


def test_a_group_mixes_one_quantity_on_both_kinds_of_coordinate_never_two_quantities():
    data = from_sep005([{"name": "x", "data": [1.0, 2.0], "unit_str": "mm", "fs": 1.0},
                        {"name": "th", "data": [1.0, 2.0], "unit_str": "rad", "fs": 1.0},
                        {"name": "a", "data": [1.0, 2.0], "unit_str": "m/s^2", "fs": 1.0}])
    sig = data.to_dataset({"theta": ["x", "th"]}).measured["theta"]
    assert sig.unit == "m, rad" and sig.data[0, 0] == 1e-3
    with pytest.raises(MeasuredDataError, match="mixes units m, m/s\\^2"):
        data.to_dataset({"theta": ["x", "a"]})
    with pytest.raises(MeasuredDataError, match="unknown unit 'mM'"):  # only a dynamical rig's own file
        from_sep005([{"name": "c", "data": [1.0, 2.0], "unit_str": "mM", "fs": 1.0}])


def test_to_dataset_group_errors():
    data = from_sep005([{"name": "a", "data": [1.0, 2.0], "unit_str": "m", "fs": 1.0},
                        {"name": "f", "data": [1.0, 2.0], "unit_str": "N", "fs": 1.0}])
    with pytest.raises(MeasuredDataError, match="mixes units"):
        data.to_dataset({"x": ["a", "f"]})
    with pytest.raises(MeasuredDataError, match="unknown channel"):
        data.to_dataset({"x": ["b"]})


def test_measurement_from_file_runs_the_kinds_chain(beam, tmp_path):
    path, ds = beam
    (out,) = export_dataset(path, "sep005", tmp_path / "beam.json")
    m = measurement_from_file(out, "structural", {"highpass_hz": 20.0}, prior={"total_mass": 0.7})
    ref = measure(ds, {"highpass_hz": 20.0}, "structural")
    np.testing.assert_array_equal(m.x, ref.x)
    assert m.prior == {"total_mass": 0.7}
    with pytest.raises(MeasuredDataError, match="cannot run the mechanical signal chain"):
        measurement_from_file(out, "mechanical")
    with pytest.raises(MeasuredDataError, match="unknown rig kind"):
        measurement_from_file(out, "optical")


def test_generic_ascii_uff58_units_from_data_types(tmp_path):
    """A time record from another tool: ASCII, no rate in ID line 5, no unit label, rotation."""
    path = tmp_path / "other.unv"
    x = np.sin(np.arange(64) / 5.0)
    sets = [pyuff.prepare_58(binary=0, func_type=1, rsp_node=12, rsp_dir=-6, ref_node=0, ref_dir=0,
                             id1="", data=x, x=np.arange(64) / 256.0, abscissa_spacing=1,
                             abscissa_spec_data_type=17, ordinate_spec_data_type=8,
                             ordinate_len_unit_exp=0, ordinate_force_unit_exp=0,
                             ordinate_axis_units_lab="", orddenom_spec_data_type=0, z_axis_spec_data_type=0,
                             z_axis_value=0.0, rsp_ent_name="a", ref_ent_name="NONE")]
    pyuff.UFF(str(path)).write_sets(sets, mode="add")
    data = read_measured(path)
    assert list(data.signals) == ["node12:-6"] and data.signals["node12:-6"][0] == "rad"
    # ASCII: the abscissa increment is printed E13.5 (6 digits), so the rate is known to 1e-5
    assert data.fs == pytest.approx(256.0, rel=1e-5) and data.directions == {"node12:-6": -6}
    np.testing.assert_allclose(data.signals["node12:-6"][1], x, rtol=1e-5)  # ASCII: E13.5


def test_truncated_uff_export(beam, tmp_path):
    path, _ = beam
    (out,) = export_dataset(path, "uff", tmp_path / "beam.uff")
    cut = tmp_path / "cut.uff"
    cut.write_bytes(out.read_bytes()[: out.stat().st_size // 2])
    with pytest.raises(MeasuredDataError, match=r"cut\.uff: not a complete UFF file"):
        read_measured(cut)


@pytest.mark.parametrize("value", [math.nan, math.inf, -1.0, 0.0])
def test_a_declared_prior_that_is_not_a_positive_size_is_refused(value):
    # `testbed identify --prior total_mass=nan` used to fit and write a model
    data = from_sep005([{"name": "a", "data": [1.0, 2.0], "unit_str": "m", "fs": 1.0}])
    with pytest.raises(MeasuredDataError,
                       match=r"prior total_mass=.*expected a finite number from 1e-100 to 1e\+100"):
        data.to_dataset(prior={"total_mass": value})
    assert data.to_dataset(prior={"total_mass": 0.7}).prior["total_mass"] == 0.7


def _beam_channels(acc, positions=(0.1, 0.2, 0.3)):
    """SEP-005 channels of a 3-sensor beam record (acc: (3, n) [m/s^2]) with a hammer at 0.3 m."""
    n = acc.shape[1]
    force = np.zeros(n)
    force[5:8] = 1.0
    return [{"name": f"acceleration/a{i}", "data": acc[i], "unit_str": "m/s^2", "fs": 1000.0,
             "position_m": p} for i, p in enumerate(positions)] + \
           [{"name": "force/hammer", "data": force, "unit_str": "N", "fs": 1000.0, "position_m": 0.3}]


@pytest.mark.parametrize(("acc", "positions", "words"), [
    # were fitted and written with exit 0 (zero stiffness, NaN damping ratios) or crashed
    # inside an identifier (ZeroDivisionError, LinAlgError)
    (np.zeros((3, 400)), (0.1, 0.2, 0.3), "do not move"),
    (np.ones((3, 400)), (0.1, 0.2, 0.3), "do not move"),
    (1e-300 * np.sin(np.arange(400.0))[None].repeat(3, 0), (0.1, 0.2, 0.3), "do not move"),
    (1e300 * np.sin(np.arange(400.0))[None].repeat(3, 0), (0.1, 0.2, 0.3), "expected at most 1e+50"),
    (np.sin(np.arange(400.0))[None].repeat(3, 0), (0.2, 0.2, 0.2), "share a position"),
])
def test_a_record_with_nothing_to_identify_is_refused(tmp_path, acc, positions, words):
    path = write(tmp_path, "x.json", json.dumps(_beam_channels(acc, positions), default=list))
    with pytest.raises(MeasuredDataError, match=re.escape(words)):
        measurement_from_file(path, "structural")


def _mixed_channels(t0: float) -> list[dict]:
    """Two channels at 100 Hz: ``a`` with a ``time`` from ``t0`` [s], ``b`` with ``fs`` alone."""
    n = 50
    return [{"name": "a", "data": list(np.sin(np.arange(n) / 5.0)), "unit_str": "m",
             "time": list(t0 + np.arange(n) / 100.0)},
            {"name": "b", "data": list(np.cos(np.arange(n) / 5.0)), "unit_str": "m", "fs": 100.0}]


def test_a_sep005_channel_with_fs_alone_beside_a_later_timed_one_is_refused():
    # round 18, open item (d): a channel with `fs` alone states no start; beside a channel
    # whose `time` starts 0.3 s (30 samples) later, the two were lined up sample by sample
    with pytest.raises(MeasuredDataError, match=r"channel 'b' gives fs alone .*t = 0 s\), channel "
                                                r"'a' starts at t = 0\.3 s: 30 samples apart"):
        from_sep005(_mixed_channels(0.3))


def test_a_sep005_channel_with_fs_alone_beside_a_timed_one_from_zero_is_read():
    data = from_sep005(_mixed_channels(0.0))
    assert data.fs == 100.0 and list(data.signals) == ["a", "b"]


def _hammer_record(tmp_path: Path, last: int | None) -> Path:
    """A beam-like SEP-005 record at 1 kHz: three decaying sines (their own frequencies) after
    a 5-sample half-sine hammer at samples 20-24, the hammer at the tip sensor, cut at
    ``last``."""
    fs, n = 1000.0, 600
    t = np.arange(n) / fs
    force = np.where((t >= 0.020) & (t < 0.025), np.sin(np.pi * (t - 0.020) / 0.005), 0.0)
    after = t >= 0.020
    chans = [{"name": f"acceleration/acc{k + 1}", "unit_str": "m/s^2", "fs": fs, "position_m": 0.1 * (k + 1),
              "data": list((after * np.exp(-3 * t) * np.sin(2 * np.pi * f * (t - 0.02)))[:last])}
             for k, f in enumerate((11.0, 47.0, 103.0))]
    chans.append({"name": "force/force", "unit_str": "N", "fs": fs, "position_m": 0.3,
                  "data": list(force[:last])})
    path = tmp_path / f"hammer_{last}.json"
    path.write_text(json.dumps(chans))
    return path


def test_a_beam_record_cut_inside_the_pulse_is_refused_for_that(tmp_path):
    # round 18, open item (b): cut two samples into the pulse it was refused as "'acc3' is a
    # linear combination of 'acc1', 'acc2'": one line, not the cause
    with pytest.raises(MeasuredDataError, match=r"force pulse \(from sample 2[01]\) has not ended "
                                                r"4 samples before the record's last.*cut inside"):
        measurement_from_file(_hammer_record(tmp_path, 23), "structural", {"highpass_hz": 2.0})
    m = measurement_from_file(_hammer_record(tmp_path, None), "structural", {"highpass_hz": 2.0})
    assert m.free_start < m.n_samples - 4


@pytest.mark.parametrize(("name", "empty"), [("acceleration/", "channel"), ("/acc1", "signal")])
def test_a_channel_name_with_an_empty_part_around_the_slash_is_refused(name, empty):
    # hostile round 19: "acceleration/" was read as a channel named "" and "/acc1" as a signal
    # named "" (a report's rows and a --units key could not name them)
    t = np.arange(100) / 1000.0
    chans = [{"name": name, "data": list(np.sin(40 * t)), "fs": 1000.0, "unit_str": "m/s^2"}]
    with pytest.raises(MeasuredDataError, match=f"channel name {name!r}: an empty {empty} name"):
        from_sep005(chans).to_dataset()


@pytest.mark.parametrize(("path", "shown"), [("r\nx.json", r"r\nx.json"), ("r.json\0", r"r.json\x00")])
def test_a_path_with_a_control_character_is_shown_escaped_in_one_line(path, shown):
    # a newline in the path made the one error line two (round 19); a NUL was printed raw
    # (round 17, open item 7)
    with pytest.raises(MeasuredDataError) as e:
        read_measured(path)
    assert "\n" not in str(e.value) and "\0" not in str(e.value)
    assert str(e.value).startswith(shown + ": "), str(e.value)
