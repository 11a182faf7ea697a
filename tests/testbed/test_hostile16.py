"""Sixteenth malformed-input round: the findings of ``benchmarks/hostile16.py`` (docs/history.md,
malformed-input audits), each fixed in the layer that owns it.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest


def _synthetic():
    """tests/testbed/_synthetic_runs.py (imported as test_runstore and test_faults do)."""
    if str(Path(__file__).parent) not in sys.path:
        sys.path.insert(0, str(Path(__file__).parent))
    import _synthetic_runs

    return _synthetic_runs


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """One run in a run history (its folder), written by save_new_run."""
    from testbed.studies.runstore import save_new_run

    out = tmp_path_factory.mktemp("runs")
    return save_new_run(_synthetic().structural_result(n_samples=200), out)


def _copy(saved: Path, tmp_path: Path) -> tuple[Path, Path]:
    import shutil

    out = tmp_path / "runs"
    shutil.copytree(saved.parent.parent, out)
    return out, out / saved.parent.name / saved.name


def _edit_json(run: Path, edit) -> None:
    meta = json.loads((run / "run.json").read_text())
    edit(meta)
    (run / "run.json").write_text(json.dumps(meta, indent=2))


# ------------------------------------------------------------------ run folders

@pytest.mark.parametrize("edit", [
    # a flipped digit of a score, a loosened bar, another seed or scenario: each was listed and
    # reported as the run's own (run.json carried no checksum)
    lambda m: m["scores"].__setitem__(next(iter(m["scores"])), 123.0),
    lambda m: [c.__setitem__("threshold", 1e9) for c in m["checks"]],
    lambda m: m["scenario"].__setitem__("seed", 7),
    lambda m: m["scenario"].__setitem__("name", "cartpole"),
    lambda m: m.__setitem__("fit_time", -1.0),
    lambda m: m.__setitem__("figures", ["../../../x.png"]),
], ids=["score", "threshold", "seed", "scenario", "fit_time", "figures"])
def test_an_edited_run_json_is_refused_as_damaged(saved, tmp_path, edit):
    from testbed.studies.runstore import list_runs, load_run

    out, run = _copy(saved, tmp_path)
    assert len(list_runs(out)) == 1 and load_run(run).meta["format"].endswith("/2")
    _edit_json(run, edit)
    damaged: list = []
    assert list_runs(out, damaged=damaged) == [] and damaged == [run]
    with pytest.raises(ValueError, match="does not match its checksum"):
        load_run(run)


@pytest.mark.parametrize("damage", ["flip", "cut", "remove"])
def test_a_damaged_or_missing_run_npz_is_refused(saved, tmp_path, damage):
    from testbed.studies.runstore import list_runs, load_run

    out, run = _copy(saved, tmp_path)
    npz = run / "run.npz"
    data = bytearray(npz.read_bytes())
    if damage == "remove":
        # `testbed report` of a run without its arrays wrote a report without them, status 0
        npz.unlink()
        damaged: list = []
        assert list_runs(out, damaged=damaged) == [] and damaged == [run]
    else:
        # a byte flipped inside a stored member's data may pass zip's own checks
        if damage == "flip":
            data[len(data) // 3] ^= 0x01
        else:
            data = data[: len(data) - 7]
        npz.write_bytes(bytes(data))
    with pytest.raises(ValueError, match="run.npz"):
        load_run(run)


def test_a_run_folder_without_its_run_json_is_named_not_dropped(saved, tmp_path):
    from testbed.studies.runstore import list_runs

    # run.json deleted (or a folder in its place): the folder was left out of the listing in
    # silence, its run.npz and figures still there
    out, run = _copy(saved, tmp_path)
    (run / "run.json").unlink()
    damaged: list = []
    assert list_runs(out, damaged=damaged) == [] and damaged == [run]
    (run / "run.json").mkdir()
    damaged = []
    assert list_runs(out, damaged=damaged) == [] and damaged == [run]


def test_a_v1_run_is_read_as_written(saved, tmp_path):
    from testbed.studies.runstore import DIGEST, NPZ_DIGEST, READ_FORMATS, list_runs, load_run

    # runs written before the checksums (format /1) are still listed and reported
    out, run = _copy(saved, tmp_path)
    _edit_json(run, lambda m: (m.update(format=READ_FORMATS[0]), m.pop(DIGEST), m.pop(NPZ_DIGEST)))
    assert len(list_runs(out)) == 1 and load_run(run).identifier
    # ... but a /2 run whose checksum was removed is not one of them
    _edit_json(run, lambda m: m.update(format=READ_FORMATS[1]))
    with pytest.raises(ValueError, match="checksum"):
        load_run(run)


def test_a_v1_runs_figures_name_files_inside_its_folder_only(saved, tmp_path):
    from testbed.studies.runstore import DIGEST, NPZ_DIGEST, READ_FORMATS, load_run

    out, run = _copy(saved, tmp_path)
    (tmp_path / "x.png").write_bytes(b"\x89PNG")
    (run / "f.png").write_bytes(b"\x89PNG")
    _edit_json(run, lambda m: (m.update(format=READ_FORMATS[0], figures=["../../../x.png", "f.png", 3]),
                               m.pop(DIGEST), m.pop(NPZ_DIGEST)))
    assert load_run(run).figures == [run / "f.png"]
