"""Sweep results: one row per cell, crash-safe while running, one Parquet file at the end.

Layout of a results file ``R`` (e.g. ``out/studies/default.parquet``)::

    R               Parquet (pyarrow), one row per cell, sorted by scenario, noise, seed,
                    identifier; schema metadata ``format`` = FORMAT and ``study``.
    R.parts/        while a sweep runs: ``<cell>.json``, one finished row per file, each
                    written atomically (temporary file + ``os.replace``).  Consolidation
                    merges them into ``R`` (again atomically) and then deletes them.

A sweep killed at any moment therefore leaves only whole rows (in ``R`` or in
``R.parts``) and loses just the cells in flight; :func:`read_results` reads both
places and keeps one row per cell, so a rerun skips every finished cell.

Columns (:data:`BASE_COLUMNS`, then one float column per score name):

======================  =========  ===================================================
study, cell             str        study name; cell key (see ``testbed.sweep.cell_key``)
scenario, rig           str        scenario name and its rig
noise                   float      sensor noise [% of channel RMS]
seed                    int        noise seed
identifier              str        identifier name
params                  str        its hyperparameters (JSON)
status                  str        "ok" or "failed"
error                   str        ``Type: message (file:line)``; "" if ok
fit_time                float      identifier fit wall time [s] (NaN if it never ran)
data_time, cell_time    float      dataset load-or-generate / whole cell wall time [s]
passed                  bool       every threshold of the scenario's [score] table met
<score>                 float      each score name (NaN if absent for this rig kind)
checks                  str        JSON list of {metric, value, bound, threshold, passed}
versions                str        JSON of package versions that computed the row
commit                  str        git commit of the code (``+dirty`` if modified)
dataset_hash            str        content hash of the dataset the cell used
======================  =========  ===================================================
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq

from testbed.atomic import atomic_write, atomic_write_text

FORMAT = "sysid-testbed-results/1"

BASE_COLUMNS: dict[str, pa.DataType] = {
    "study": pa.string(), "cell": pa.string(), "scenario": pa.string(), "rig": pa.string(),
    "noise": pa.float64(), "seed": pa.int64(), "identifier": pa.string(), "params": pa.string(),
    "status": pa.string(), "error": pa.string(), "fit_time": pa.float64(),
    "data_time": pa.float64(), "cell_time": pa.float64(), "passed": pa.bool_(),
}
TAIL_COLUMNS: dict[str, pa.DataType] = {
    "checks": pa.string(), "versions": pa.string(), "commit": pa.string(),
    "dataset_hash": pa.string(),
}
SORT_KEYS = ("scenario", "noise", "seed", "identifier", "cell")


def parts_dir(path: str | os.PathLike) -> Path:
    """The folder of per-cell row files belonging to results file ``path``."""
    p = Path(path)
    return p.with_name(p.name + ".parts")


def score_columns(rows: Iterable[dict[str, Any]]) -> list[str]:
    """Names of the score columns in ``rows`` (every key not a fixed column), sorted."""
    fixed = set(BASE_COLUMNS) | set(TAIL_COLUMNS)
    return sorted({k for r in rows for k in r if k not in fixed})


def _sort_key(row: dict[str, Any]) -> tuple:
    return tuple(row.get(k) if row.get(k) is not None else "" for k in SORT_KEYS)


def write_part(path: str | os.PathLike, row: dict[str, Any]) -> Path:
    """Write one finished row atomically as ``<path>.parts/<cell>.json``; return the file."""
    out = parts_dir(path) / f"{row['cell']}.json"
    atomic_write_text(out, json.dumps(row, sort_keys=True))  # NaN as the JSON extension NaN
    return out


def _read_parts(path: str | os.PathLike) -> list[dict[str, Any]]:
    d = parts_dir(path)
    if not d.is_dir():
        return []
    rows = []
    for p in sorted(d.glob("*.json")):  # temporary files (.*.tmp) of a killed write are skipped
        rows.append(json.loads(p.read_text()))
    return rows


def _to_table(rows: list[dict[str, Any]], study: str | None) -> pa.Table:
    scores = score_columns(rows)
    schema = pa.schema([*(pa.field(k, t) for k, t in BASE_COLUMNS.items()),
                        *(pa.field(k, pa.float64()) for k in scores),
                        *(pa.field(k, t) for k, t in TAIL_COLUMNS.items())],
                       metadata={"format": FORMAT, "study": study or ""})
    cols = {}
    for f in schema:
        if f.type == pa.float64():
            vals = [r.get(f.name) for r in rows]
            cols[f.name] = [math.nan if v is None else float(v) for v in vals]
        else:
            cols[f.name] = [r.get(f.name) for r in rows]
    return pa.table(cols, schema=schema)


def write_rows(path: str | os.PathLike, rows: Iterable[dict[str, Any]], *,
               study: str | None = None) -> Path:
    """Write ``rows`` (one per cell) as the Parquet file ``path``, atomically.

    Rows are sorted by scenario, noise, seed and identifier; score columns are
    the union over rows, NaN where a row has none.
    """
    rows = sorted(rows, key=_sort_key)
    keys = [r["cell"] for r in rows]
    if len(set(keys)) != len(keys):
        raise ValueError("write_rows: a cell appears more than once")
    table = _to_table(rows, study)
    path = Path(path)
    atomic_write(path, lambda tmp: pq.write_table(table, tmp))
    return path


def _read_parquet(path: Path) -> list[dict[str, Any]]:
    if not path.is_file():
        return []
    table = pq.read_table(path)
    meta = table.schema.metadata or {}
    if meta.get(b"format", b"").decode() != FORMAT:
        raise ValueError(f"{path}: not a {FORMAT} file")
    return table.to_pylist()


def read_results(path: str | os.PathLike) -> list[dict[str, Any]]:
    """Every row of a results file, including rows not yet consolidated.

    Parameters
    ----------
    path : path
        The results file; ``<path>.parts/`` is read too.

    Returns
    -------
    list of dict
        One row per cell (a row in both places counts once; the part wins, being
        the newer), sorted by scenario, noise, seed and identifier.  Every row has
        every score column found in any row (NaN where it has no such score).
    """
    path = Path(path)
    by_cell: dict[str, dict[str, Any]] = {r["cell"]: r for r in _read_parquet(path)}
    for r in _read_parts(path):
        by_cell[r["cell"]] = r
    rows = sorted(by_cell.values(), key=_sort_key)
    scores = score_columns(rows)
    for r in rows:
        for k in scores:
            if r.get(k) is None:
                r[k] = math.nan
    return rows


def consolidate(path: str | os.PathLike, *, keep: set[str] | None = None,
                study: str | None = None) -> tuple[int, int]:
    """Merge ``<path>.parts/`` into the Parquet file ``path`` and delete the parts.

    Parameters
    ----------
    keep : set of str, optional
        Cell keys to keep; rows of other cells (e.g. of an edited study) are dropped.
    study : str, optional
        Study name stored in the file's metadata.

    Returns
    -------
    (n_rows, n_dropped)
    """
    path = Path(path)
    rows = read_results(path)
    dropped = 0
    if keep is not None:
        kept = [r for r in rows if r["cell"] in keep]
        dropped = len(rows) - len(kept)
        rows = kept
    write_rows(path, rows, study=study)
    d = parts_dir(path)
    if d.is_dir():  # only after the Parquet file holds every row
        for p in d.iterdir():
            p.unlink(missing_ok=True)
        d.rmdir()
    return len(rows), dropped
