"""Console summaries: the truth rows come from the kind's typed truth."""

import numpy as np

from testbed.core.dataset import Dataset, Signal
from testbed.reporting.console import truth_rows


def _dataset(truth, kind):
    attrs = {"rig": "r"} if kind is None else {"rig": "r", "kind": kind}
    return Dataset(100.0, {"x": Signal(np.zeros((2, 4)), ("x1", "x2"), "m")}, truth=truth,
                   prior={"total_mass": 2.5}, attrs=attrs)


def test_structural_rows():
    eye3, eye2 = np.eye(3), np.eye(2)
    truth = {"M": eye3, "C": eye3, "K": eye3, "frequencies_hz": np.array([10.0, 20.0, 30.0]),
             "damping_ratios": np.array([0.01, 0.02, 0.03]), "modes": eye3, "sensor_modes": eye2,
             "Mr": eye2, "Cr": eye2, "Kr": eye2, "eb_frequencies_hz": np.array([10.1, 19.8])}
    rows = dict(truth_rows(_dataset(truth, "structural")))
    assert rows["mode 1"] == "    10.00 Hz   Euler-Bernoulli     10.10 Hz   (-0.990 %)"
    assert rows["mode 3"] == "    30.00 Hz"  # no Euler-Bernoulli frequency for it
    assert rows["damping ratios"] == "0.0100, 0.0200, 0.0300"
    assert rows["samples"] == "4 at 100 Hz" and rows["prior total_mass"] == "2.5"
    # without a recorded kind the truth is undeclared: no truth rows
    assert "mode 1" not in dict(truth_rows(_dataset(truth, None)))


def test_equation_rows():
    truth = {"equation_terms": ["ddth1", "u1", "th1"], "equation_coef": np.ones((1, 3))}
    assert dict(truth_rows(_dataset(truth, "mechanical")))["true equation terms"] == "3"
