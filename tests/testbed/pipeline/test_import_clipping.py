"""A clipped sensor in an imported record is said (a warning naming the file, the channel, the
share of samples and the level), stored with the model, and refuses nothing."""

from __future__ import annotations

import json
import warnings

import pytest

from testbed.pipeline.fit import identify_file
from testbed.pipeline.importers import ClippedSensorWarning, measurement_from_file
from testbed.pipeline.scenario import load_scenario
from testbed.reporting.identified import render_identified
from tests.testbed._saved_record import clipped_acc1


@pytest.fixture(scope="module")
def records(dataset_cache, tmp_path_factory):
    """The stiff beam's record and a copy with acc1 clipped at 10 % of its peak (files)."""
    folder = tmp_path_factory.mktemp("clip")
    ds = dataset_cache.get(load_scenario("cantilever_stiff_impact"))
    bad, lim = clipped_acc1(ds)
    return ds.save(folder / "beam.h5"), bad.save(folder / "clipped.h5"), lim


def test_warning_at_import(records):
    clean, bad, lim = records
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        measurement_from_file(bad, "structural")
        measurement_from_file(clean, "structural")
    lines = [str(w.message) for w in caught if issubclass(w.category, ClippedSensorWarning)]
    assert len(lines) == 2  # both rails, the clipped file only
    assert all(line.startswith(f"{bad}: sensor acc1 is clipped at ") for line in lines)
    assert f"{lim:.6g} m/s^2" in lines[0] and "of 12800 samples (" in lines[0]


def test_stored_with_the_model(records):
    clean, bad, lim = records
    summary = identify_file(bad, kind="structural", method="ls_sindy").summary()
    assert [c["channel"] for c in summary["clipped_sensors"]] == ["acc1", "acc1"]
    assert sorted(c["level"] for c in summary["clipped_sensors"]) == [-lim, lim]
    assert sum(c["n_held"] for c in summary["clipped_sensors"]) == 57
    clean_summary = identify_file(clean, kind="structural", method="ls_sindy").summary()
    assert "clipped_sensors" not in clean_summary
    # and in the identify command's markdown report
    text = render_identified(summary)
    assert "## Clipped sensors" in text and text.count("\n- acc1: ") == 2
    assert "Clipped" not in render_identified(clean_summary)


def test_identify_command_says_it(records, cli_in_process, tmp_path):
    _, bad, _ = records
    out = tmp_path / "m.json"
    p = cli_in_process("identify", str(bad), "--kind", "structural", "--method", "ls_sindy",
                       "-o", str(out), cwd=tmp_path)
    assert p.returncode in (0, 1) and out.is_file()  # the model is written: nothing refused
    warned = [ln for ln in p.stderr.splitlines() if ln.startswith(f"warning: {bad}: sensor acc1")]
    assert len(warned) == 2 and "samples (" in warned[0]
    assert len(json.loads(out.read_text())["clipped_sensors"]) == 2
