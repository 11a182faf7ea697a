"""The guides in docs/ cannot rot: examples run, the scenario guide matches the schemas."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"


def python_blocks(path: Path) -> list[str]:
    """The fenced ```python blocks of a markdown file."""
    return re.findall(r"^```python\n(.*?)^```", path.read_text(), flags=re.S | re.M)


@pytest.mark.parametrize("guide", ["identifiers.md", "rigs.md"])
def test_guide_example_runs(guide, tmp_path):
    blocks = python_blocks(DOCS / guide)
    assert blocks, f"{guide} has no python example"
    script = tmp_path / "example.py"
    script.write_text("\n\n".join(blocks))
    # a fresh interpreter: the example's registration must not leak into other tests' registries
    env = {**os.environ, "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg",
           "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    r = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True, text=True,
                       timeout=120, env=env)
    assert r.returncode == 0, f"{guide} example failed:\n{r.stdout}\n{r.stderr[-3000:]}"
    assert r.stdout.strip()


def test_scenario_guide_is_up_to_date():
    from testbed.reporting.guide import render

    committed = (DOCS / "scenarios.md").read_text()
    assert committed == render(), ("docs/scenarios.md is out of date with the schemas; regenerate it: "
                                   "python -m testbed.reporting.guide > docs/scenarios.md")


def test_scenario_guide_lists_every_key():
    from models import RIGS
    from testbed.pipeline.scenario import HEADER_SCHEMA, NOISE_SCHEMA
    from testbed.pipeline.signal_chain import SIGNAL_SCHEMAS

    text = (DOCS / "scenarios.md").read_text()
    schemas = [HEADER_SCHEMA, NOISE_SCHEMA, *SIGNAL_SCHEMAS.values()]
    for name in RIGS.names():
        cls = RIGS.get(name)
        schemas += [cls.rig_schema, cls.simulation_schema, *cls.excitation_schemas.values()]
    for schema in schemas:
        for key, f in schema.items():
            rows = [ln for ln in text.splitlines() if ln.startswith(f"| `{key}` |")]
            assert rows, key
            if f.unit:
                assert any(f"| {f.unit} |" in r for r in rows), (key, f.unit)
