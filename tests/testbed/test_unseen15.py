"""Round 15 of rigs nobody tuned (benchmarks/unseen/round15_*.toml): the studies load and the
writers reproduce the scenario files."""

from __future__ import annotations

import shutil
import subprocess
import sys
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


def test_the_writers_reproduce_round15s_files(tmp_path):
    """b_make.py and l_make.py, run on a copy of round 15's folder, write its files byte for byte."""
    src = UNSEEN / "round15"
    work = tmp_path / "unseen"
    shutil.copytree(UNSEEN, work, ignore=shutil.ignore_patterns("*.parquet", "__pycache__"))
    for f in (work / "round15").glob("*.toml"):
        f.unlink()
    for script in ("b_make.py", "l_make.py"):
        subprocess.run([sys.executable, str(work / "round15" / script)], cwd=ROOT, check=True,
                       capture_output=True, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    written = sorted(p.name for p in (work / "round15").glob("*.toml"))
    assert written == sorted(p.name for p in src.glob("*.toml"))
    for name in written:
        assert (work / "round15" / name).read_bytes() == (src / name).read_bytes(), name
