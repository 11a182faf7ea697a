"""Seventeenth malformed-input round: the findings of ``benchmarks/hostile17.py`` (docs/history.md,
malformed-input audits), each fixed in the layer that owns it.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from testbed import cli
from testbed.pipeline.importers import rate_misfit


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
