"""Tenth malformed-input round: the two findings left open by the ninth, and those of
``benchmarks/hostile10.py`` (docs/history.md, malformed-input audits), each refused in one line
by the layer that owns the check.
"""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from testbed.core.dataset import Dataset, DatasetError, Signal
from testbed.pipeline.importers import MeasuredDataError, read_measured
from testbed.reporting.export import export_dataset

FS = 1000.0  # Hz; 400 samples of a 7 Hz sine: any rate and length the readers accept


def _saved(tmp_path) -> object:
    """A hand-made record (no kind: no truth to validate), saved with its content hash."""
    t = np.arange(400) / FS
    acc = np.vstack([np.sin(2 * np.pi * 7 * t) * (k + 1) for k in range(2)])
    ds = Dataset(FS, {"acceleration": Signal(acc, ("acc1", "acc2"), "m/s^2", np.array([0.1, 0.2])),
                      "force": Signal(np.exp(-t / 0.01)[None, :], ("force",), "N", np.array([0.2]))})
    return ds.save(tmp_path / "d.h5")


# ------------------------------------------------------------------ left open by round 9

def _add_root_group(f):
    f.create_group("notes").attrs["who"] = "me"


def _add_root_dataset(f):
    f["extra"] = np.arange(3.0)


def _add_measured_dataset(f):
    f["measured/extra"] = np.ones((1, 400))


def _add_signal_attr(f):
    f["measured/force"].attrs["gain"] = 2.0


def _add_group_under_measured(f):
    f["measured"].create_group("sub")


def _soft_link(f):
    f["measured/copy"] = h5py.SoftLink("/measured/force")


def _delete_prior(f):
    del f["prior"]


def _dataset_under_prior(f):
    f["prior/total_mass"] = 0.7


@pytest.mark.parametrize("edit, fragment", [
    # read without a word: outside the content hash
    (_add_root_group, "/notes: not part of a dataset file (its root holds the groups measured, "
                      "reference, truth, prior"),
    (_add_root_dataset, "/extra: not part of a dataset file"),
    (_add_signal_attr, "/measured/force: unknown attribute 'gain' (allowed: unit, channels"),
    (_soft_link, "/measured/copy: a SoftLink (to '/measured/force')"),
    (_dataset_under_prior, "/prior/total_mass: the prior is held in the group's attributes"),
    # "unreadable dataset file (KeyError: ... 'channels')"
    (_add_measured_dataset, "/measured/extra: no attribute 'unit' (a member of /measured carries "
                            "unit, channels)"),
    (_add_group_under_measured, "/measured/sub: a group; /measured holds datasets only"),
    (_delete_prior, "/prior: missing (a dataset file's root holds the groups"),
])
def test_a_dataset_file_with_members_outside_its_layout_is_refused_naming_them(tmp_path, edit, fragment):
    p = _saved(tmp_path)
    assert read_measured(p).signals  # the file as written is read
    with h5py.File(p, "a") as f:
        edit(f)
    for read in (Dataset.load, read_measured):
        with pytest.raises((DatasetError, MeasuredDataError)) as e:
            read(p)
        assert fragment in str(e.value) and "\n" not in str(e.value), str(e.value)


def _uff(tmp_path) -> bytes:
    (out,) = export_dataset(_saved(tmp_path), "uff", tmp_path / "d.uff")
    return out.read_bytes()


@pytest.mark.parametrize("where, fragment", [
    ("between", "line 7 ('junk 1 2 3') lies outside every UFF block"),
    ("first", "line 1 ('junk 1 2 3') lies outside every UFF block"),
    ("last", "('junk 1 2 3') lies outside every UFF block"),
])
def test_a_line_of_junk_outside_the_uff_blocks_is_refused_naming_it(tmp_path, where, fragment):
    # pyuff reads only what lies between a block's start and end '    -1' and skipped the rest
    data = _uff(tmp_path)
    assert data.startswith(b"    -1\n") and data.count(b"    -1\n    -1\n") >= 1
    i = {"between": data.find(b"    -1\n    -1\n") + 7, "first": 0, "last": len(data)}[where]
    p = tmp_path / "junk.uff"
    p.write_bytes(data[:i] + b"junk 1 2 3\n" + data[i:])
    if where == "last":  # the tail check ("does not end with a block end") would catch it first
        p.write_bytes(data[:i] + b"junk 1 2 3\n    -1\n")
        fragment = "unpaired UFF block delimiter"
    with pytest.raises(MeasuredDataError) as e:
        read_measured(p)
    assert fragment in str(e.value) and "\n" not in str(e.value), str(e.value)


def test_blank_lines_between_uff_blocks_are_read(tmp_path):
    data = _uff(tmp_path)
    i = data.find(b"    -1\n    -1\n") + 7
    p = tmp_path / "blank.uff"
    p.write_bytes(data[:i] + b"\n   \n" + data[i:])
    assert read_measured(p).signals.keys() == read_measured(tmp_path / "d.uff").signals.keys()
