"""Rigs nobody tuned, round 11 (linkages and small rigs; benchmarks/unseen/round11_linkages_*.toml):
the round's studies load with their cells, its writer reproduces its scenario files, and its
narrow-based five-bar starts inside the rig's transmission range."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
UNSEEN = ROOT / "benchmarks" / "unseen"


def _maker():
    spec = importlib.util.spec_from_file_location("l_make11", UNSEEN / "round11" / "l_make.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize(("name", "cells"), [("round11_linkages_geometry", 24),
                                             ("round11_linkages_clean", 8),
                                             ("round11_linkages_sine", 12),
                                             ("round11_linkages_multisine", 8),
                                             ("round11_linkages_cartpoles", 12),
                                             ("round11_linkages_kinetics", 12)])
def test_round11_linkage_studies_load(name, cells):
    from testbed.studies.study import load_study
    from testbed.studies.sweep import expand
    assert len(expand(load_study(UNSEEN / f"{name}.toml"))) == cells


def test_writer_reproduces_the_scenario_files(tmp_path, monkeypatch):
    mod = _maker()
    monkeypatch.setattr(mod, "HERE", tmp_path)
    mod.main()
    written = sorted(p.name for p in tmp_path.glob("*.toml"))
    assert len(written) == 24  # 8 five-bars twice, 4 cart-poles, 4 kinetics
    for name in written:
        assert (tmp_path / name).read_text() == (UNSEEN / "round11" / name).read_text(), name


def test_the_narrow_base_starts_inside_the_transmission_range():
    # fb11_base_0p15 at the paper's pose (1.78, 1.36 rad): 32.9 deg, inside the rig's 30-150 deg
    # (a cell, not a refusal at load), 2.9 deg from the limit; the sine moves both cranks alike,
    # so the angle stays put
    mod = _maker()
    lo, hi = mod.path_transmission_deg({"L0": 0.15, "th1_0": 1.78, "th4_0": 1.36}, mod.PAPER_AMP)
    assert 30.0 < lo <= hi < 34.0
