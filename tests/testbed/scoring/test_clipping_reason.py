"""A failed bar on a record with a clipped sensor names the clipping (clipping_failures);
a met bar, or a record with none, gets nothing: no verdict changes."""

from __future__ import annotations

import dataclasses

import numpy as np

from testbed.numerics.clipping import Clipping, clipping_table
from testbed.pipeline.scenario import load_scenario
from testbed.scoring.run import run_scenario
from testbed.scoring.scorers import Scores, bar_failures, clipping_failures
from tests.testbed._saved_record import clipped_acc1

BARS = {"mac": {"min": 0.95}}
TABLE = clipping_table([Clipping("acc1", 23.1, 26, 12800, 4, "m/s^2")])


def test_reason_only_on_a_failed_bar():
    failed = Scores({"mac": 0.136}, {"clipped_sensors": TABLE}, {})
    reason = clipping_failures(failed, BARS)["clipped"]
    assert reason.startswith("clipped: sensor acc1 is clipped at +23.1 m/s^2: 26 of 12800 samples")
    assert bar_failures(failed, BARS)["clipped"] == reason
    assert clipping_failures(Scores({"mac": 0.99}, {"clipped_sensors": TABLE}, {}), BARS) == {}
    assert clipping_failures(Scores({"mac": 0.136}, {}, {}), BARS) == {}


def test_stiff_beam_clipped_run_says_so(dataset_cache):
    """Hostile round 20: acc1 clipped at 10 % of its peak failed its bars with no reason naming
    the clipping; the clean record passes with no such reason."""
    sc = load_scenario("cantilever_stiff_impact")
    ds = dataset_cache.get(sc)
    clipped, _ = clipped_acc1(ds)
    r = run_scenario(sc, dataset=clipped)
    assert not r.passed and "sensor acc1 is clipped at" in r.scores.failures["clipped"]
    clean = run_scenario(sc, dataset=ds)
    assert clean.passed and "clipped" not in clean.scores.failures
    assert "clipped_sensors" not in clean.scores.details


def test_a_kinetics_record_clipped_from_its_start_says_so(dataset_cache):
    """Malformed-input round 21: a Michaelis-Menten record whose x is clipped from its first
    sample (a saturated probe, 30 % below the dose) failed its equation bars with no reason
    naming the clipping: the scorer judged clipping on structural records only and without
    the recorded rate (``dx`` says x moved while x is held).  The clean record passes with no
    such reason."""
    sc = load_scenario("michaelis_menten")
    ds = dataset_cache.get(sc)
    s = ds.measured["x"]
    x = s.data.copy()
    x[0] = np.minimum(x[0], 0.7 * float(np.max(x[0])))
    clipped = dataclasses.replace(ds, measured={**ds.measured, "x": dataclasses.replace(s, data=x)})
    r = run_scenario(sc, dataset=clipped)
    assert not r.passed and "sensor x is clipped at" in r.scores.failures["clipped"]
    clean = run_scenario(sc, dataset=ds)
    assert clean.passed and "clipped_sensors" not in clean.scores.details
