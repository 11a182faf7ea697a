"""Eighteenth malformed-input round: the findings of ``benchmarks/hostile18.py`` (docs/history.md,
malformed-input audits), each fixed in the layer that owns it.
"""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np
import pytest

from testbed import cli
from testbed.core.dataset import Dataset, Signal
from testbed.pipeline.importers import MeasuredDataError, measurement_from_file
from testbed.reporting.export import export_dataset

FS = 1000.0  # Hz; 400 samples of a 7 Hz sine: any rate and length the readers accept


def _saved(tmp_path: Path) -> Path:
    """A hand-made record (no kind: no truth to validate), saved with its content hash."""
    t = np.arange(400) / FS
    acc = np.vstack([np.sin(2 * np.pi * 7 * t) * (k + 1) for k in range(2)])
    ds = Dataset(FS, {"acceleration": Signal(acc, ("acc1", "acc2"), "m/s^2"),
                      "force": Signal(np.exp(-t / 0.01)[None, :], ("force",), "N")})
    return ds.save(tmp_path / "d.h5")


def _values_elsewhere(tmp_path: Path, how: str) -> Path:
    """The saved record with ``measured/acceleration`` keeping its values in another file
    (``how``: "virtual" or "external"), its content hash made anew (as a user's edit would):
    the hash is of the values read, so it matches."""
    path = _saved(tmp_path)
    name = "measured/acceleration"
    with h5py.File(path, "r+") as f:
        attrs, data = dict(f[name].attrs), f[name][()]
        del f[name]
        if how == "virtual":
            with h5py.File(tmp_path / "source.h5", "w") as g:
                g.create_dataset("src", data=data)
            layout = h5py.VirtualLayout(shape=data.shape, dtype=data.dtype)
            layout[:] = h5py.VirtualSource(str(tmp_path / "source.h5"), "src", shape=data.shape)
            d = f.create_virtual_dataset(name, layout)
        else:
            (tmp_path / "raw.bin").write_bytes(np.ascontiguousarray(data, "<f8").tobytes())
            d = f.create_dataset(name, shape=data.shape, dtype="<f8",
                                 external=[(str(tmp_path / "raw.bin"), 0, data.size * 8)])
        for k, v in attrs.items():
            d.attrs[k] = v
    ds = Dataset.load(path, verify=False)
    with h5py.File(path, "r+") as f:
        f.attrs["content_hash"] = ds.content_hash()
    Dataset.load(path)  # the edit passes the content hash: only the readers' checks remain
    return path


@pytest.mark.parametrize(("how", "said"), [("virtual", "a virtual dataset"),
                                           ("external", "stored in external file")])
def test_a_dataset_file_whose_values_live_in_another_file_is_refused(tmp_path, how, said):
    # round 18: fitted by `testbed identify` with status 0 and exported; the record was not the
    # file named, and its values change with a file the command line never names
    path = _values_elsewhere(tmp_path, how)
    with pytest.raises(MeasuredDataError, match=said):
        measurement_from_file(path, "structural", {"highpass_hz": 2.0})
    with pytest.raises(MeasuredDataError, match=said):
        export_dataset(path, "sep005", tmp_path / "out.json")


def test_identify_of_a_virtual_dataset_file_is_one_line(tmp_path, capsys):
    path = _values_elsewhere(tmp_path, "virtual")
    status = cli.main(["identify", str(path), "--kind", "structural", "--method", "ls_sindy",
                       "-o", str(tmp_path / "m.json")])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and "measured/acceleration" in err[0], err
    assert not (tmp_path / "m.json").exists()


def test_a_compressed_dataset_file_is_still_read(tmp_path):
    """Compression (gzip, shuffle, checksums) keeps the values in the file: read as before."""
    path = _saved(tmp_path)
    name = "measured/acceleration"
    with h5py.File(path, "r+") as f:
        attrs, data = dict(f[name].attrs), f[name][()]
        del f[name]
        d = f.create_dataset(name, data=data, compression="gzip", shuffle=True, fletcher32=True)
        for k, v in attrs.items():
            d.attrs[k] = v
    assert Dataset.load(path).measured["acceleration"].data.shape == (2, 400)
    export_dataset(path, "sep005", tmp_path / "out.json")
    assert (tmp_path / "out.json").is_file()
