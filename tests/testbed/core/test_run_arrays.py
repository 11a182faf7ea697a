"""The one list of what a run's ``run.npz`` holds (review 25a: the checker's kinds were a copy
of the writer's literal)."""

import io
import zipfile

import numpy as np
import pytest

from testbed.core.run_arrays import RUN_ARRAY_KINDS, ZIP_SIGNATURES
from testbed.studies.runstore import _as_array

SAMPLES = {"b": np.array([True]), "i": np.array([-1]), "u": np.array([1], np.uint8),
           "f": np.array([0.5]), "c": np.array([1j]), "U": np.array(["a"]), "S": np.array([b"a"]),
           "M": np.array(["2026-01-01"], "M8[D]"), "m": np.array([1], "m8[s]"),
           "O": np.array([None], object), "V": np.zeros(1, [("a", "f8")])}


@pytest.mark.parametrize("kind", sorted(SAMPLES))
def test_the_writer_stores_exactly_the_kinds_the_checker_allows(kind):
    """The run store keeps an array (not a repr) where, and only where, its kind is listed."""
    assert SAMPLES[kind].dtype.kind == kind
    assert (_as_array(SAMPLES[kind]) is not None) == (kind in RUN_ARRAY_KINDS)


def test_numpy_writes_and_reads_a_zip_by_these_first_bytes():
    buf = io.BytesIO()
    np.savez(buf, a=np.arange(3.0))
    empty = io.BytesIO()
    with zipfile.ZipFile(empty, "w"):
        pass
    assert buf.getvalue()[:4] == ZIP_SIGNATURES[0] and empty.getvalue()[:4] == ZIP_SIGNATURES[1]
    with np.load(io.BytesIO(empty.getvalue())) as z:  # numpy takes the empty archive as an npz
        assert z.files == []
