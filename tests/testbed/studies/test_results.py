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


def test_a_newer_versions_results_file_says_it_is_newer(tmp_path):
    # a whole file of a later format is not damage: the message says which version reads it
    res = tmp_path / "r.parquet"
    write_rows(res, [row("c1", trac=0.1)])
    table = pq.read_table(res)
    newer = FORMAT.rpartition("/")[0] + "/" + str(int(FORMAT.rpartition("/")[2]) + 1)
    pq.write_table(table.replace_schema_metadata({**table.schema.metadata,
                                                  b"format": newer.encode()}), res)
    with pytest.raises(ValueError, match="written by a newer sysid-testbed"):
        read_results(res)


# ------------------------------------------------------------------ the row checksum

def test_a_row_edited_within_its_types_is_refused_in_a_part_and_in_the_parquet_file(tmp_path):
    # round 12's open finding: a score or passed edited by hand to another value of its type
    # was summarised as computed; now every row carries the checksum of its values
    from testbed.studies.results import DIGEST, ResultsError

    res = tmp_path / "r.parquet"
    part = write_part(res, row("c1", trac=0.5))
    doc = json.loads(part.read_text())
    assert len(doc[DIGEST]) == 64
    doc["trac"] = 0.95  # the same type, another value
    part.write_text(json.dumps(doc))
    assert read_results(res, set_aside=True) == []
    assert part.with_name(part.name + ".bad").is_file()  # kept as evidence, its cell reruns

    write_rows(res, [row("c1", trac=0.5), row("c2", seed=1, trac=0.2)], study="t")
    table = pq.read_table(res)
    rows = table.to_pylist()
    rows[1]["trac"] = 0.25
    pq.write_table(pa.Table.from_pylist(rows, schema=table.schema), res)
    with pytest.raises(ResultsError, match=r"row 1 \(cell 'c2'\): its values do not match the "
                                           r"checksum stored with it \(row_sha256\)"):
        read_results(res)


@pytest.mark.parametrize("edit", ["dropped", "null"])
def test_a_part_without_its_checksum_is_refused(tmp_path, edit):
    from testbed.studies.results import DIGEST

    res = tmp_path / "r.parquet"
    part = write_part(res, row("c1", trac=0.5))
    doc = json.loads(part.read_text())
    if edit == "dropped":
        del doc[DIGEST]
    else:
        doc[DIGEST] = None
    part.write_text(json.dumps(doc))
    assert read_results(res) == []


def test_the_checksum_is_the_same_for_a_row_its_part_and_its_parquet_row(tmp_path):
    # NaN and absent scores, an int in a float column: one value in the Parquet file, one checksum
    from testbed.studies.results import DIGEST, row_digest

    res = tmp_path / "r.parquet"
    r = row("c1", trac=0.5, mac=float("nan"), noise=1)  # noise 1 (int) is stored as 1.0
    r["passed"] = False  # (what the reader judges it from its empty checks: kept as written)
    digest = row_digest(r)
    write_part(res, r)
    consolidate(res, study="t")
    stored = pq.read_table(res).to_pylist()[0]
    assert stored[DIGEST] == digest and stored["noise"] == 1.0 and isinstance(stored["noise"], float)
    assert row_digest({**r, "mac": 0.9}) != digest and row_digest({**r, "trac": None}) != digest
    assert row_digest({**r, "passed": True}) != digest


def test_a_results_file_of_format_1_is_read_without_checksums(tmp_path):
    # files written before the checksum (format /1, no row_sha256 column) stay readable
    from testbed.studies.results import DIGEST, READ_FORMATS

    res = tmp_path / "r.parquet"
    write_rows(res, [row("c1", trac=0.5)], study="t")
    table = pq.read_table(res).drop_columns([DIGEST])
    meta = {**table.schema.metadata, b"format": READ_FORMATS[0].encode()}
    pq.write_table(table.replace_schema_metadata(meta), res)
    assert [r["trac"] for r in read_results(res)] == [0.5]
    meta[b"format"] = FORMAT.encode()  # claimed /2 without the column: refused
    pq.write_table(table.replace_schema_metadata(meta), res)
    with pytest.raises(ValueError, match="no column 'row_sha256'"):
        read_results(res)


def test_rows_of_numpy_values_are_written_with_the_checksum_their_reader_computes(tmp_path):
    # write_rows hashed the Python values given, not what Arrow stores: a numpy seed, score,
    # passed or noise, or a seed of 3.0, made a file its own reader called damaged (review)
    import numpy as np

    res = tmp_path / "r.parquet"
    r = row("c1", trac=np.float32(0.9), noise=np.float32(1.5))
    r.update(seed=np.int64(3), passed=np.bool_(False))
    write_rows(res, [r, row("c2", seed=3.0, trac=0.5)], study="t")
    got = {x["cell"]: x for x in read_results(res)}
    assert got["c1"]["seed"] == 3 and got["c1"]["trac"] == float(np.float32(0.9))
    assert got["c2"]["seed"] == 3
