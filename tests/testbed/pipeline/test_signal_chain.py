"""``testbed.pipeline.signal_chain.measure``: the dataset's sample rate checked before any chain runs."""

from __future__ import annotations

import numpy as np
import pytest

from testbed.core.dataset import Dataset, Signal
from testbed.core.errors import ArgumentError
from testbed.pipeline.signal_chain import measure


def _kinetics(fs) -> Dataset:
    """A hand-made kinetics record of 400 samples at the rate ``fs``."""
    x = (2.0 * np.exp(-np.arange(400) / 100.0))[None, :]
    return Dataset(fs, {"x": Signal(x, ("x",), "mM"), "dx": Signal(-x, ("dx",), "mM/s")})


@pytest.mark.parametrize(("fs", "allowed"), [
    # hostile round 19: 0 was ZeroDivisionError, NaN / -100 a plain ValueError from the filters,
    # complex a TypeError, and True and "100" were measured as 1 Hz and 100 Hz in silence
    (0.0, "expected a finite number > 0"), (float("nan"), "expected a finite number > 0"),
    (-100.0, "expected a finite number > 0"), (float("inf"), "expected a finite number > 0"),
    (True, "expected a finite number > 0"), ("100", "expected a finite number > 0"),
    (100 + 0j, "expected a finite number > 0"), (1e-320, "the duration overflows"),
])
def test_a_dataset_rate_that_is_no_rate_is_refused_in_one_line(fs, allowed):
    with pytest.raises(ArgumentError, match=r"^measure: argument 'dataset\.fs': .*" + allowed) as e:
        measure(_kinetics(fs), {}, "dynamical")
    assert "\n" not in str(e.value)


@pytest.mark.parametrize("fs", [100.0, 100, np.float32(100.0), np.int64(100)])
def test_a_real_rate_of_any_numeric_type_is_measured(fs):
    assert measure(_kinetics(fs), {}, "dynamical").fs == 100.0


@pytest.mark.parametrize(("measured", "words"), [
    # hostile round 25 (the API): a bare array was AttributeError inside the chain; an empty
    # table and a signal named "x/y" a raw "dataset has no measured signal 'x'"
    (lambda x, dx: {"x": x.data, "dx": dx}, r"argument 'dataset\.measured\['x'\]': array of shape "
                                             r"\(1, 400\).*expected a Signal"),
    (lambda x, dx: {}, r"argument 'dataset\.measured': an empty table: expected the measured signals "
                       r"\(the dynamical chain reads x, "),
    (lambda x, dx: {"x/y": x, "dx": dx}, r"argument 'dataset\.measured': a signal named 'x/y': "
                                         r"expected signal names without '/'"),
    # the read of session 26: the table was read (for the record's length) before its check, so
    # a table that is no mapping, or a list for a Signal, was still an AttributeError
    (lambda x, dx: np.zeros((2, 400)), r"argument 'dataset\.measured': array of shape \(2, 400\)"),
    (lambda x, dx: {"x": [0.0, 1.0], "dx": dx}, r"argument 'dataset\.measured\['x'\]': a list: "
                                                r"expected a Signal"),
], ids=["bare-array", "empty-table", "x/y", "not-a-mapping", "list"])
def test_a_measured_table_no_chain_can_read_is_refused_in_one_line(measured, words):
    ds = _kinetics(100.0)
    bad = Dataset(ds.fs, measured(ds.measured["x"], ds.measured["dx"]))
    with pytest.raises(ArgumentError, match=r"^measure: " + words) as e:
        measure(bad, {}, "dynamical")
    assert "\n" not in str(e.value)
