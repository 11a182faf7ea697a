"""Round 14 of rigs nobody tuned (benchmarks/unseen/round14_*.toml): the studies load, the
writers reproduce the scenario files (tests/testbed/test_unseen_writers.py), and the cart-pole's
law bar on a round-6 rig."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
UNSEEN = ROOT / "benchmarks" / "unseen"


@pytest.mark.parametrize(("name", "cells"), [
    ("round14_beams", 40), ("round14_beams_noise", 80), ("round14_linkages_sine", 18),
    ("round14_linkages_clean", 6), ("round14_linkages_multisine", 9),
    ("round14_linkages_cartpoles", 12), ("round14_linkages_kinetics", 12),
    ("round14_beams_noise_s52", 40), ("round14_linkages_sine_seeds", 18),
    ("round14_linkages_cartpoles_seeds", 12)])
def test_round14_studies_load(name, cells):
    from testbed.studies.study import load_study
    from testbed.studies.sweep import expand
    assert len(expand(load_study(UNSEEN / f"{name}.toml"))) == cells


def test_round6s_heavy_cart_gets_the_law_its_rollout_passed_with():
    """cp_heavy_cart_10 (a 10 kg cart under a 0.05 kg pole) at 1 %: the rollout met the bar
    (0.029 < 0.0501) while the identified law was 62 % off over the record's state box (a
    scored failure naming the law since the rig's law bar; the naming itself:
    tests/testbed/scoring/test_law.py).  The pole's selected row was the identity of nearly
    equal columns ``ddth2 - cos(th2)*ddth2`` (the light pole swings little), ranked first per
    unit of its left-hand side; tested per unit of the part holding ddth2
    (identify._implicit.select_passive_models, session 23) it is refuted and the pole's own
    equation taken: law_error 0.015, angle_rmse 0.0026, the cell passes."""
    import testbed
    from testbed import load_scenario

    sc = load_scenario(UNSEEN / "round6" / "cp_heavy_cart_10.toml")
    res = testbed.run_scenario(dataclasses.replace(sc, noise={**sc.noise, "rms_percent": 1.0}))
    assert res.scores.values["angle_rmse"] < 0.0501
    assert res.scores.values["law_error"] < 0.25  # the rig's law bar (was 0.62)
    assert res.passed, res.scores.failures
