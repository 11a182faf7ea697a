"""The guides in docs/ and the README cannot rot: examples run and use only public names, the
scenario guide matches the schemas."""

from __future__ import annotations

import ast
import os
import re
import runpy
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
DOCS = ROOT / "docs"
#: Every markdown file with a ```python example (a test below checks that none is left out).
GUIDES = {"identifiers.md": DOCS / "identifiers.md", "rigs.md": DOCS / "rigs.md",
          "python-api.md": DOCS / "python-api.md", "README.md": ROOT / "README.md"}
#: The guides whose example registers an identifier or a rig (run in a fresh interpreter).
REGISTERING = ("identifiers.md", "rigs.md")


def python_blocks(path: Path) -> list[str]:
    """The fenced ```python blocks of a markdown file."""
    return re.findall(r"^```python\n(.*?)^```", path.read_text(), flags=re.S | re.M)


def test_every_python_example_is_run():
    with_examples = {p for p in [ROOT / "README.md", *DOCS.glob("*.md")] if python_blocks(p)}
    assert with_examples == set(GUIDES.values())


@pytest.mark.parametrize("guide", list(GUIDES))
def test_guide_example_runs(guide, tmp_path, monkeypatch, capsys, cli_in_process, dataset_cache):
    blocks = python_blocks(GUIDES[guide])
    assert blocks, f"{guide} has no python example"
    if guide in ("python-api.md", "README.md"):
        # both run cantilever_stiff_impact_lsq: on a cold cache its record is simulated once, by
        # the test process holding the cache's lock, not by both examples at once
        from testbed.pipeline.scenario import load_scenario

        dataset_cache.clean(load_scenario("cantilever_stiff_impact_lsq"))
    script = tmp_path / "example.py"
    script.write_text("\n\n".join(blocks))
    # the shared test cache: a dataset the examples need is simulated once per machine
    env = {**os.environ, "OMP_NUM_THREADS": "1", "MPLBACKEND": "Agg",
           "TESTBED_CACHE": os.environ.get("TESTBED_TEST_CACHE", str(ROOT / ".cache" / "test-datasets")),
           "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    if guide in REGISTERING:
        # a fresh interpreter: the example's registration must not leak into other tests'
        # registries
        r = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True,
                           text=True, timeout=120, env=env)
        assert r.returncode == 0, f"{guide} example failed:\n{r.stdout}\n{r.stderr[-3000:]}"
        out = r.stdout
    else:
        # registers nothing: run in this process, as a script in its own folder (the interpreter's
        # start and imports were 2-3 s of CPU of each of these two examples on a cold run)
        monkeypatch.chdir(tmp_path)
        monkeypatch.setenv("TESTBED_CACHE", env["TESTBED_CACHE"])
        from testbed.pipeline.plugins import IDENTIFIERS, RIGS

        before = [r.snapshot() for r in (IDENTIFIERS, RIGS)]
        capsys.readouterr()
        runpy.run_path(str(script), run_name="__main__")
        out = capsys.readouterr().out
        assert [r.snapshot() for r in (IDENTIFIERS, RIGS)] == before, (
            f"{guide}'s example registers: list it in REGISTERING")
    assert out.strip()
    if guide in ("identifiers.md", "rigs.md"):
        # the example, saved as a file outside the repository, is a plugin of the command line
        # (`testbed list --plugin` in this process: what it registers is forgotten after it)
        monkeypatch.setenv("TESTBED_CACHE", env["TESTBED_CACHE"])
        r = cli_in_process("list", "--plugin", str(script), cwd=tmp_path)
        assert r.returncode == 0, r.stderr[-3000:]
        name = "example_least_squares" if guide == "identifiers.md" else "example_two_mass"
        (row,) = [ln for ln in r.stdout.splitlines() if ln.startswith(name + "\t")]
        assert row.endswith(f"\tfile {script}")


@pytest.mark.parametrize("guide", list(GUIDES))
def test_guides_import_only_public_names(guide):
    """Imports come from the packages themselves (``from testbed import X``, never a module of
    theirs), and every name imported or reached as ``testbed.X`` is in the package's ``__all__``."""
    import identify
    import models
    import testbed

    packages = {"testbed": testbed, "identify": identify, "models": models}
    code = "\n".join(python_blocks(GUIDES[guide]))
    private = []
    for node in ast.walk(ast.parse(code)):
        if isinstance(node, ast.Import):
            private += [a.name for a in node.names
                        if a.name.split(".")[0] in packages and a.name not in packages]
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] in packages:
            if node.module not in packages:
                private.append(node.module)
            else:
                private += [f"{node.module}.{a.name}" for a in node.names
                            if a.name not in packages[node.module].__all__]
        elif isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) \
                and node.value.id in packages and node.attr not in packages[node.value.id].__all__:
            private.append(f"{node.value.id}.{node.attr}")
    assert not private, f"{guide} uses {private}: use the public names of testbed.__all__"


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


def test_citation_file_is_valid_and_current():
    yaml = pytest.importorskip("yaml")

    import testbed

    cff = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert cff["cff-version"] == "1.2.0" and cff["type"] == "software"
    assert str(cff["version"]) == testbed.__version__
    titles = [r["title"] for r in cff["references"]]
    assert any("Stochastic Gradient SINDy" in t for t in titles)
    assert any("Parallel implicit sparse identification" in t for t in titles)
    for ref in cff["references"]:
        assert ref["authors"] and all(a.get("family-names") for a in ref["authors"])
