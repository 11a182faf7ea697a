"""HDF5 round trip, plain-h5py readability with units, atomic writes, content hash."""

import h5py
import numpy as np
import pytest

from testbed.core.dataset import Dataset, Signal
from testbed.core.errors import ArgumentError


def _dataset(seed=0):
    rng = np.random.default_rng(seed)
    acc = Signal(rng.standard_normal((3, 100)), ("acc1", "acc2", "acc3"), "m/s^2",
                 np.array([0.1, 0.2, 0.3]))
    force = Signal(rng.standard_normal(100), ("force",), "N", np.array([0.3]))
    return Dataset(
        fs=12800.0, measured={"acceleration": acc, "force": force},
        reference={"displacement": Signal(rng.standard_normal((3, 100)), acc.channels, "m")},
        truth={"M": np.eye(3), "frequencies_hz": np.array([82.9, 519.5]), "terms": ["a*b", "c"],
               "k3": np.float64(0.0)},
        truth_units={"M": "kg", "frequencies_hz": "Hz", "terms": "", "k3": "N m/rad^3"},
        prior={"total_mass": 0.75},
        attrs={"rig": "toy", "seed": 3, "scenario": {"name": "x", "rig": "toy"}, "gravity": "off"})


def test_truth_and_prior_keys_come_in_one_order_whichever_path_made_them(tmp_path):
    """A rig writes its truth in its own order, HDF5 gives it back sorted: a run's npz and its
    report tables differed between a fresh simulation and the cache (same arrays)."""
    from testbed.pipeline.generate import simulate_clean
    from testbed.pipeline.scenario import load_scenario

    sc = load_scenario("cartpole")
    fresh = simulate_clean(sc.replace(simulation={**sc.simulation, "duration": 0.5}))
    back = Dataset.load(fresh.save(tmp_path / "d.h5"))
    for name in ("truth", "truth_units", "prior"):
        assert list(getattr(back, name)) == list(getattr(fresh, name)), name
        assert list(getattr(fresh, name)) == sorted(getattr(fresh, name)), name


def test_round_trip_gives_back_the_same_object(tmp_path):
    ds = _dataset()
    p = ds.save(tmp_path / "d.h5")
    back = Dataset.load(p)
    assert back.fs == ds.fs
    for g in ("measured", "reference"):
        a, b = getattr(ds, g), getattr(back, g)
        assert a.keys() == b.keys()
        for k in a:
            np.testing.assert_array_equal(a[k].data, b[k].data)
            assert a[k].channels == b[k].channels and a[k].unit == b[k].unit
            if a[k].positions is not None:
                np.testing.assert_array_equal(a[k].positions, b[k].positions)
    for k in ds.truth:
        if isinstance(ds.truth[k], list):
            assert back.truth[k] == ds.truth[k]
        else:
            np.testing.assert_array_equal(back.truth[k], ds.truth[k])
    assert back.truth_units == ds.truth_units
    assert back.prior == ds.prior
    assert back.attrs["scenario"] == ds.attrs["scenario"]
    assert back.attrs["seed"] == 3
    assert back.content_hash() == ds.content_hash() == back.attrs["content_hash"]


def test_plain_h5py_reads_units_and_layout(tmp_path):
    p = _dataset().save(tmp_path / "d.h5")
    with h5py.File(p, "r") as f:
        assert f.attrs["fs"] == 12800.0 and f.attrs["fs_unit"] == "Hz"
        d = f["measured/acceleration"]
        assert d.shape == (3, 100)
        assert d.attrs["unit"] == "m/s^2"
        assert list(d.attrs["channels"]) == ["acc1", "acc2", "acc3"]
        assert d.attrs["positions_unit"] == "m"
        assert f["truth/M"].attrs["unit"] == "kg"
        assert f["prior"].attrs["total_mass"] == 0.75


def test_content_hash_changes_with_any_data():
    a, b = _dataset(), _dataset()
    assert a.content_hash() == b.content_hash()
    b.measured["force"].data[0, 5] += 1e-12
    assert a.content_hash() != b.content_hash()


def test_same_content_gives_identical_file_bytes(tmp_path):
    p1 = _dataset().save(tmp_path / "a.h5")
    p2 = _dataset().save(tmp_path / "b.h5")
    assert p1.read_bytes() == p2.read_bytes()


def test_failed_write_leaves_no_file(tmp_path, monkeypatch):
    ds = _dataset()
    target = tmp_path / "d.h5"

    def boom(self, f):
        f.create_group("half")
        raise RuntimeError("crash while writing")

    monkeypatch.setattr(Dataset, "_write", boom)
    with pytest.raises(RuntimeError):
        ds.save(target)
    assert not target.exists()
    assert list(tmp_path.iterdir()) == []


def test_failed_overwrite_keeps_the_old_file(tmp_path, monkeypatch):
    target = _dataset().save(tmp_path / "d.h5")
    before = target.read_bytes()
    monkeypatch.setattr(Dataset, "_write", lambda self, f: (_ for _ in ()).throw(OSError("disk")))
    with pytest.raises(OSError):
        _dataset(seed=1).save(target)
    assert target.read_bytes() == before


def test_format_1_file_still_loads_and_is_verified_with_its_own_hash(tmp_path):
    """A file written before the hash covered data only (format /1) is read, not called altered."""
    from testbed.core.dataset import DatasetError

    ds = _dataset()
    p = ds.save(tmp_path / "old.h5")
    legacy = ds._legacy_content_hash()
    assert legacy != ds.content_hash()  # the /1 hash also covered the scenario's name
    with h5py.File(p, "r+") as f:
        f.attrs["format"] = "sysid-testbed-dataset/1"
        f.attrs["content_hash"] = legacy
    back = Dataset.load(p)
    assert back.attrs["content_hash"] == ds.content_hash()
    with h5py.File(p, "r+") as f:
        f.attrs["content_hash"] = "0" * 64
    with pytest.raises(DatasetError, match="does not match its stored content hash"):
        Dataset.load(p)


@pytest.mark.parametrize("fields", [
    {"fs": 100},                                    # an int rate: hashed as the stored float
    {"fs": np.float32(100.0)},
    {"attrs": {"n": np.int64(3)}},                  # numpy scalars: hashed as load reads them
    {"attrs": {"g": np.float32(0.1)}},
    {"attrs": {"b": np.bool_(True)}},               # was a raw TypeError inside the write
    {"prior": {"total_mass": np.float32(0.7)}},
])
def test_a_dataset_saved_with_python_or_numpy_numbers_verifies_on_load(tmp_path, fields):
    """Review 27a: each of these saved a file whose own load refused it as "altered or damaged"
    (its hash taken over ``100`` / a numpy scalar's text, the load's over ``100.0`` / the number)."""
    kw = {"fs": 100.0, "measured": {"a": Signal(np.arange(10.0), ("x",), "m")}, **fields}
    path = Dataset(**kw).save(tmp_path / "d.h5")
    loaded = Dataset.load(path)
    assert loaded.fs == 100.0 and loaded.content_hash() == loaded.attrs["content_hash"]


@pytest.mark.parametrize(("fields", "label"), [
    ({"truth": {"a/b": [1.0]}}, "truth name"),      # saved; its load refused '/truth/a'
    ({"truth": {"": [1.0]}}, "truth name"),         # raw TypeError from h5py
    ({"truth": {5: [1.0]}}, "truth name"),
    ({"prior": {"a\x00b": 1.0}}, "prior name"),     # saved; failed its own hash check
    ({"truth": {"t": ["a\x00b"]}}, r"truth\['t'\]"),  # raw ValueError (VLEN NUL)
    ({"truth": {"t": [1.0]}, "truth_units": {"t": "m\x00"}}, r"truth_units\['t'\]"),
])
def test_save_refuses_truth_and_prior_names_hdf5_cannot_hold(tmp_path, fields, label):
    kw = {"fs": 100.0, "measured": {"a": Signal(np.arange(10.0), ("x",), "m")}, **fields}
    with pytest.raises(ArgumentError, match=label):
        Dataset(**kw).save(tmp_path / "d.h5")
    assert not (tmp_path / "d.h5").exists()
