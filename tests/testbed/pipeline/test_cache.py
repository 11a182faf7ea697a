"""The dataset cache: content-keyed, atomic, and noisy data derived from one clean simulation."""

import logging

import h5py
import numpy as np
import pytest

from testbed.core.dataset import Dataset
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.generate import generate
from testbed.pipeline.scenario import load_scenario


def _short():
    sc = load_scenario("cantilever_stiff_impact")
    return sc.replace(simulation={**sc.simulation, "duration": 0.05}).with_noise(2.0).replace(seed=7)


def test_noisy_dataset_from_cached_clean_simulation_is_bit_identical(tmp_path):
    sc = _short()
    cache = DatasetCache(tmp_path)
    derived = cache.get(sc)
    direct = generate(sc)
    assert derived.content_hash() == direct.content_hash()
    for name, s in direct.measured.items():
        np.testing.assert_array_equal(derived.measured[name].data, s.data)
    # the cache holds the clean simulation only; noisy copies are derived on load, so a second
    # noisy seed (or noise level) adds neither a file nor a simulation
    assert len(cache.entries()) == 1
    other = cache.get(sc.replace(seed=8))
    assert len(cache.entries()) == 1
    assert cache.get(sc.with_noise(0.0)).content_hash() == generate(sc.with_noise(0.0)).content_hash()
    assert len(cache.entries()) == 1
    assert not np.array_equal(other.measured["acceleration"].data, derived.measured["acceleration"].data)
    np.testing.assert_array_equal(other.reference["acceleration"].data,
                                  derived.reference["acceleration"].data)


def test_cache_hit_loads_and_clear_removes(tmp_path):
    sc = _short()
    cache = DatasetCache(tmp_path)
    first = cache.get(sc)
    again = cache.get(sc)
    assert again.content_hash() == first.content_hash()
    assert cache.clear() == 1 and cache.entries() == []


def test_a_rigs_cache_key_covers_its_own_source_and_the_shared_chain_only():
    """Editing or adding one rig does not invalidate another rig's cached datasets, while a
    change to the shared generation code (noise model, dataset format) does for every rig."""
    from testbed.pipeline.cache import SHARED_GENERATOR_SOURCES, generator_sources

    cant = {p.as_posix() for p in generator_sources("cantilever")}
    five = {p.as_posix() for p in generator_sources("fivebar")}
    assert any("/models/cantilever/" in p for p in cant) and not any("/models/fivebar/" in p for p in cant)
    assert any("/models/fivebar/" in p for p in five) and not any("/models/cantilever/" in p for p in five)
    for shared in SHARED_GENERATOR_SOURCES:
        assert any(p.endswith(shared) for p in cant) and any(p.endswith(shared) for p in five)


@pytest.mark.parametrize(("fs", "unit"), [("100", None), (True, None), (50.0, None),
                                          (100.0, "kHz")])
def test_a_cache_entry_whose_rate_was_edited_is_simulated_again(tmp_path, caplog, fs, unit):
    # round 18's open item (c): Dataset.load read `fs` with float() and no unit, so a cache
    # entry edited to fs "100" (text), True, another rate or fs_unit kHz, its content hash made
    # anew, was served with that rate (50 Hz: the chain's filters and the time axis of another
    # record); the cache now checks the rate it reads and simulates the entry again
    sc = load_scenario("michaelis_menten")
    cache = DatasetCache(tmp_path)
    clean = cache.get(sc)
    path = cache.path(sc)
    with h5py.File(path, "r+") as f:
        f.attrs["fs"] = fs
        if unit:
            f.attrs["fs_unit"] = unit
    ds = Dataset.load(path, verify=False)
    with h5py.File(path, "r+") as f:
        f.attrs["content_hash"] = ds.content_hash()
    Dataset.load(path)  # the edit passes the content hash: only the cache's checks remain
    with caplog.at_level(logging.WARNING, logger="testbed.pipeline.cache"):
        again = cache.get(sc)
    assert again.fs == 100.0 and again.content_hash() == clean.content_hash()
    assert any("fs" in r.getMessage() and "simulating it again" in r.getMessage()
               for r in caplog.records), caplog.text
    assert Dataset.load(path).fs == 100.0 and "kHz" not in str(h5py.File(path).attrs.get("fs_unit"))


@pytest.mark.parametrize("fs, n, said", [
    (100.0, 401, "simulated a dataset that holds 401 samples; its scenario records 400"),
    (100.0, 399, "holds 399 samples; its scenario records 400"),
    (50.0, 400, "has fs=50.0 Hz; its scenario records at 100.0 Hz"),
])
def test_a_rig_whose_dataset_is_not_its_record_is_refused_where_it_is_made(monkeypatch, fs, n,
                                                                          said):
    # review 29a M1: a (plugin) rig recording round(duration * fs) + 1 samples was accepted
    # when simulated, then its cache entry refused on every read (simulated again every run);
    # now simulate_clean refuses it once, naming the rig and both counts.  No simulation runs:
    # the rig's output is a hand-made dataset of michaelis_menten's rig (4 s at 100 Hz)
    from testbed.core.dataset import Signal
    from testbed.core.errors import RigError
    from testbed.pipeline import generate as gen

    made = Dataset(fs, {"conc": Signal(np.zeros((1, n)), ("s",), "mol/L")})
    monkeypatch.setattr(gen, "_simulate_rig", lambda sc, progress: made)
    with pytest.raises(RigError, match=rf"rig 'michaelis_menten' \(from builtin\) .*{said}"):
        gen.simulate_clean(load_scenario("michaelis_menten"))
    assert gen.record_problem(Dataset(100.0, {"conc": Signal(np.zeros((1, 400)), ("s",),
                                                             "mol/L")}),
                              load_scenario("michaelis_menten")) is None
