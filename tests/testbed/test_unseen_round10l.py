"""Rigs nobody tuned, round 10 (linkages and small rigs; benchmarks/unseen/round10_linkages_*.toml):
the round's studies load with their cells, and its near-limit five-bar stays inside the rig's
transmission range."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
UNSEEN = ROOT / "benchmarks" / "unseen"


@pytest.mark.parametrize(("name", "cells"), [("round10_linkages_geometry", 24),
                                             ("round10_linkages_clean", 8),
                                             ("round10_linkages_inputs", 16),
                                             ("round10_linkages_cartpoles", 12),
                                             ("round10_linkages_kinetics", 12)])
def test_round10_linkage_studies_load(name, cells):
    from testbed.studies.study import load_study
    from testbed.studies.sweep import expand
    assert len(expand(load_study(UNSEEN / f"{name}.toml"))) == cells


def test_the_near_limit_path_stays_in_the_transmission_range():
    # fb10_near_limit: the sine path at 138-146 deg, inside the rig's 30-150 deg (so a cell, not
    # a refusal at load), 4 deg from the limit
    spec = importlib.util.spec_from_file_location("l_make", UNSEEN / "round10" / "l_make.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    lo, hi = mod.path_transmission_deg({"L0": 0.6, "th1_0": 1.6, "th4_0": 0.04}, mod.PAPER_AMP)
    assert 138.0 < lo < hi < 146.0 < 150.0
