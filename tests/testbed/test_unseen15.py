"""Round 15 of rigs nobody tuned (benchmarks/unseen/round15_*.toml): the studies load and the
writers reproduce the scenario files (tests/testbed/test_unseen_writers.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
UNSEEN = ROOT / "benchmarks" / "unseen"


@pytest.mark.parametrize(("name", "cells"), [
    ("round15_beams", 38), ("round15_beams_noise", 76), ("round15_linkages_sine", 15),
    ("round15_linkages_sine_seeds", 15), ("round15_linkages_clean", 5),
    ("round15_linkages_cartpoles", 12), ("round15_linkages_cartpoles_seeds", 12),
    ("round15_linkages_cartpoles_s2", 12),
    ("round15_linkages_kinetics", 12), ("round15_linkages_kinetics_seeds", 8)])
def test_round15_studies_load(name, cells):
    from testbed.studies.study import load_study
    from testbed.studies.sweep import expand
    assert len(expand(load_study(UNSEEN / f"{name}.toml"))) == cells
