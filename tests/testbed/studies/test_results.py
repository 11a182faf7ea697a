"""Results files: per-cell parts, consolidation into Parquet, one row per cell, atomic writes."""

from __future__ import annotations

import json
import math

import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from testbed.studies.results import FORMAT, consolidate, parts_dir, read_results, write_part, write_rows


def row(cell: str, *, scenario="s", noise=0.0, seed=0, identifier="m", status="ok", **scores) -> dict:
    return {"study": "t", "cell": cell, "scenario": scenario, "rig": "r", "noise": noise, "seed": seed,
            "identifier": identifier, "params": "{}", "status": status,
            "error": "" if status == "ok" else "ValueError: x", "fit_time": 0.5, "data_time": 0.1,
            "cell_time": 0.7, "passed": status == "ok", "checks": "[]", "versions": "{}",
            "commit": "abc", "dataset_hash": "h" + cell, **scores}


def test_parts_round_trip_and_consolidate(tmp_path):
    res = tmp_path / "r.parquet"
    write_part(res, row("c2", seed=1, trac=0.9, mac=float("nan")))
    write_part(res, row("c1", seed=0, trac=0.8, mac=0.99))
    write_part(res, row("c3", scenario="five", angle_rmse=0.01))  # another rig kind's score
    (parts_dir(res) / ".c4.json.x.tmp").write_text('{"cell": "half')  # a write that was killed
    rows = read_results(res)
    assert [r["cell"] for r in rows] == ["c3", "c1", "c2"]  # sorted by scenario, noise, seed
    by = {r["cell"]: r for r in rows}
    assert by["c1"]["trac"] == 0.8 and math.isnan(by["c2"]["mac"])
    assert math.isnan(by["c3"]["trac"]) and math.isnan(by["c1"]["angle_rmse"])

    n, dropped = consolidate(res, study="t")
    assert (n, dropped) == (3, 0) and not parts_dir(res).exists()
    table = pq.read_table(res)
    assert table.schema.metadata[b"format"].decode() == FORMAT
    assert table.schema.field("seed").type == pa.int64()
    assert table.schema.field("passed").type == pa.bool_()
    assert table.schema.field("angle_rmse").type == pa.float64()
    names = table.schema.names
    assert names.index("passed") < names.index("angle_rmse") < names.index("checks")
    again = read_results(res)
    assert json.dumps(again, sort_keys=True) == json.dumps(rows, sort_keys=True)  # NaN -> NaN


def test_a_part_replaces_the_consolidated_row_of_its_cell(tmp_path):
    res = tmp_path / "r.parquet"
    write_rows(res, [row("c1", trac=0.1), row("c2", seed=1, trac=0.2)], study="t")
    write_part(res, row("c1", trac=0.5))  # e.g. a failed cell retried
    rows = read_results(res)
    assert [(r["cell"], r["trac"]) for r in rows] == [("c1", 0.5), ("c2", 0.2)]
    n, dropped = consolidate(res, keep={"c1"})
    assert (n, dropped) == (1, 1)
    assert [(r["cell"], r["trac"]) for r in read_results(res)] == [("c1", 0.5)]


def test_write_rows_refuses_duplicates_and_never_leaves_half_a_file(tmp_path):
    res = tmp_path / "r.parquet"
    write_rows(res, [row("c1", trac=0.1)])
    with pytest.raises(ValueError, match="more than once"):
        write_rows(res, [row("c1"), row("c1")])
    with pytest.raises((pa.ArrowInvalid, pa.ArrowTypeError, TypeError)):
        write_rows(res, [row("c2", seed="not an int")])
    assert [r["cell"] for r in read_results(res)] == ["c1"]  # the old file, whole
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.parquet"]  # no temporary left


def test_empty_and_foreign_files(tmp_path):
    assert read_results(tmp_path / "none.parquet") == []
    other = tmp_path / "other.parquet"
    pq.write_table(pa.table({"a": [1]}), other)
    with pytest.raises(ValueError, match="not a sysid-testbed-results"):
        read_results(other)
