"""``testbed.core.process_state``: the testbed computes under numpy's own float error state."""

from __future__ import annotations

import ast
import os
import subprocess
import sys

import numpy as np
import pytest

from testbed.core.process_state import DEFAULTS, kept_process_state, numpy_defaults


def test_defaults_are_those_of_a_fresh_interpreter():
    out = subprocess.run([sys.executable, "-c", "import numpy; print(numpy.geterr())"],
                         capture_output=True, text=True, timeout=60, check=True).stdout
    assert ast.literal_eval(out.strip()) == DEFAULTS


def test_within_the_defaults_hold_and_the_callers_state_comes_back():
    old = np.seterr(all="raise")
    try:
        with numpy_defaults():
            assert np.geterr() == DEFAULTS
            assert np.exp(-1000.0) == 0.0  # an underflow: ignored, as numpy's default
            np.seterr(all="raise")  # what a plugin sets within is undone
        assert np.geterr() == {k: "raise" for k in DEFAULTS}
        with pytest.raises(FloatingPointError):
            np.exp(-1000.0)
    finally:
        np.seterr(**old)


def test_the_working_folder_comes_back(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with kept_process_state():
        os.chdir("/")
    assert os.getcwd() == str(tmp_path)


def test_kept_numpy_state_leaves_the_callers_state_within_and_restores_it_after():
    with np.errstate(over="ignore"):
        with kept_process_state(defaults=False):
            assert np.geterr()["over"] == "ignore"
            np.seterr(all="raise")
        assert np.geterr()["over"] == "ignore" and np.geterr()["under"] == "ignore"
