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

A row file damaged all the same (a full disk, a copy cut short, an edit by hand) is
not trusted: :func:`read_results` names it in a warning and skips it, and with
``set_aside=True`` (what a sweep does) renames it ``<cell>.json.bad``, so its cell runs
again and the evidence stays; consolidation leaves ``*.bad`` files in place.  A damaged
``R`` raises :class:`ResultsError` naming the file.

Columns (:data:`BASE_COLUMNS`, then one float column per score name):

======================  =========  ===================================================
study, cell             str        study name; cell key (see ``testbed.studies.sweep.cell_key``)
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
row_sha256              str        the row's checksum (:func:`row_digest`)
======================  =========  ===================================================

Every row carries the SHA-256 of its own values (:func:`row_digest`), written with it by
:func:`write_part` and :func:`write_rows` and verified by every reader: a row edited by hand
within its column types (a score, ``passed``, a check's value) was summarised as if computed
(round 12's open finding).  Rows of a file written before the checksum (format
``sysid-testbed-results/1``) are read unverified, as they were written.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import math
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

from testbed.core.atomic import atomic_write, atomic_write_text
from testbed.core.errors import TestbedError
from testbed.core.lazy import lazy_module
from testbed.scoring.scorers import Check

# imported on first use: a run's report and `testbed list` do not pay for them (~0.05 s)
pa = lazy_module("pyarrow")
pq = lazy_module("pyarrow.parquet")

FORMAT = "sysid-testbed-results/2"
#: Formats :func:`read_results` reads: ``/1`` is ``/2`` without the ``row_sha256`` column.
READ_FORMATS = ("sysid-testbed-results/1", FORMAT)
#: The column of each row's checksum (:func:`row_digest`).
DIGEST = "row_sha256"

log = logging.getLogger(__name__)


class ResultsError(TestbedError, ValueError):
    """A results file cannot be read or is not a results file of :data:`FORMAT`; names the file."""

#: Column name -> its Arrow type, by the name of the ``pyarrow`` type factory.
BASE_COLUMNS: dict[str, str] = {
    "study": "string", "cell": "string", "scenario": "string", "rig": "string",
    "noise": "float64", "seed": "int64", "identifier": "string", "params": "string",
    "status": "string", "error": "string", "fit_time": "float64",
    "data_time": "float64", "cell_time": "float64", "passed": "bool_",
}
TAIL_COLUMNS: dict[str, str] = {
    "checks": "string", "versions": "string", "commit": "string", "dataset_hash": "string",
    DIGEST: "string",
}
SORT_KEYS = ("scenario", "noise", "seed", "identifier", "cell")
#: Text columns every row must hold as text (not null): the readers sort and group by them.
TEXT_KEYS = ("scenario", "identifier")


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


def row_digest(row: dict[str, Any]) -> str:
    """The SHA-256 (64 hex digits) of a row's values, the same for the row as the sweep made it,
    its row file and its Parquet row.

    The values hashed are every column but :data:`DIGEST`, as canonical JSON (keys sorted); a
    column whose value is null or a float NaN is left out, since the Parquet file stores a
    score a row lacks as NaN (a row's NaN score and its absence are one value there), and a
    float column's value is hashed as a float (a row file's ``1`` is the Parquet file's
    ``1.0``).  A score edited to NaN or from NaN still changes the set of columns hashed.
    """
    fixed = {**BASE_COLUMNS, **TAIL_COLUMNS}
    canon: dict[str, Any] = {}
    for name, value in row.items():
        if name == DIGEST or value is None:
            continue
        if (fixed.get(name, "float64") == "float64" and isinstance(value, (int, float))
                and not isinstance(value, bool)):
            value = float(value)
            if math.isnan(value):
                continue
        canon[name] = value
    # (default=repr: a value no column can hold still hashes, for the reader to refuse it)
    text = json.dumps(canon, sort_keys=True, ensure_ascii=True, allow_nan=True, default=repr)
    return hashlib.sha256(text.encode("ascii")).hexdigest()


def _digest_problem(row: dict[str, Any]) -> str:
    """"" if ``row`` holds its own checksum (:func:`row_digest`), else what is wrong."""
    stored = row.get(DIGEST)
    if not isinstance(stored, str):
        return (f"no checksum ({DIGEST}); every row this version writes has one (a row of an "
                "older version's interrupted sweep, or edited by hand)")
    if stored != row_digest(row):
        return (f"its values do not match the checksum stored with it ({DIGEST}): edited or "
                "damaged after the sweep wrote it")
    return ""


def write_part(path: str | os.PathLike, row: dict[str, Any]) -> Path:
    """Write one finished row atomically as ``<path>.parts/<cell>.json``, with its checksum
    (:func:`row_digest`); return the file."""
    out = parts_dir(path) / f"{row['cell']}.json"
    row = {k: v for k, v in row.items() if k != DIGEST}
    # the checksum of the values as the file holds them (JSON's, as its reader gets them back)
    text = json.dumps(row, sort_keys=True)  # NaN as the JSON extension NaN
    row[DIGEST] = row_digest(json.loads(text))
    atomic_write_text(out, json.dumps(row, sort_keys=True))
    return out


def _read_part(p: Path) -> dict[str, Any]:
    """One row file; ValueError if it is not a whole row written by :func:`write_part`."""
    try:
        row = json.loads(p.read_text(encoding="utf-8"))
    except UnicodeDecodeError as e:
        raise ValueError(f"not UTF-8 text: {e}") from None
    except json.JSONDecodeError as e:
        raise ValueError(f"not valid JSON ({e})") from None
    if not isinstance(row, dict) or not all(isinstance(row.get(k), str) for k in ("cell", "status")):
        raise ValueError("not a results row (no cell and status)")
    if row["cell"] != p.stem:
        raise ValueError(f"holds the row of cell {row['cell']!r}")
    why = (_part_value_problem(row) or _row_problem({**dict.fromkeys(BASE_COLUMNS), **row}, set())
           or _digest_problem(row))
    if why:
        raise ValueError(why)
    return row


#: The Python types a row file's JSON value may have for each Arrow column type (None, JSON's
#: null, is a missing value; NaN is a float).
_JSON_TYPES: dict[str, tuple[type, ...]] = {
    "string": (str,), "float64": (int, float), "int64": (int,), "bool_": (bool,),
}


def _part_value_problem(row: dict[str, Any]) -> str:
    """What in a row file's values the Parquet file could not hold or a reader could not use
    ("" if nothing): :data:`TEXT_KEYS` present as text, every other fixed column
    (:data:`BASE_COLUMNS`, :data:`TAIL_COLUMNS`) of its type or null, each other column a number
    or null, the seed within int64.

    The Parquet file's rows were checked on read, a row file's only for its cell and status
    (round 11): ``noise = "abc"`` in one made the resumed sweep an internal error (TypeError
    sorting the rows), ``noise = NaN`` `testbed report`'s ZeroDivisionError and `testbed
    summary` a table row of noise NaN.
    """
    fixed = {**BASE_COLUMNS, **TAIL_COLUMNS}
    for name in TEXT_KEYS:  # identifier missing: summary's KeyError; null: its TypeError sorting
        if not isinstance(row.get(name), str):
            return f"column {name!r} holds {row.get(name)!r:.40}; expected string"
    for name, value in row.items():
        if value is None:
            continue
        types = _JSON_TYPES[fixed[name]] if name in fixed else (int, float)
        if (isinstance(value, bool) and bool not in types) or not isinstance(value, types):
            want = fixed.get(name, "float64").rstrip("_")
            return f"column {name!r} holds {type(value).__name__} {value!r:.40}; expected {want}"
    if isinstance(row.get("seed"), int) and not -(2**63) <= row["seed"] < 2**63:
        return f"seed {row['seed']} beyond the 64-bit integers the results file stores"
    return ""


def _read_parts(path: str | os.PathLike, set_aside: bool = False) -> list[dict[str, Any]]:
    d = parts_dir(path)
    if not d.is_dir():
        return []
    rows = []
    for p in sorted(d.glob("*.json")):  # temporary files (.*.tmp) of a killed write are skipped
        try:
            rows.append(_read_part(p))
        except (OSError, ValueError) as e:
            if not set_aside:
                log.warning("results: %s is damaged (%s); skipped", p, e)
                continue
            bad = p.with_name(p.name + ".bad")
            try:
                os.replace(p, bad)
            except FileNotFoundError:  # set aside by another reader meanwhile
                continue
            log.warning("results: %s is damaged (%s); set aside as %s, its cell will run again",
                        p, e, bad.name)
    return rows


def _to_table(rows: list[dict[str, Any]], study: str | None) -> pa.Table:
    scores = score_columns(rows)
    schema = pa.schema([*(pa.field(k, getattr(pa, t)()) for k, t in BASE_COLUMNS.items()),
                        *(pa.field(k, pa.float64()) for k in scores),
                        *(pa.field(k, getattr(pa, t)()) for k, t in TAIL_COLUMNS.items())],
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
    the union over rows, NaN where a row has none.  Each row is written with its checksum
    (:func:`row_digest`), computed here from the values as the table holds them (a numpy
    scalar or an integral float is hashed as the Arrow value it becomes, as its reader gets it).
    """
    rows = sorted(({k: v for k, v in r.items() if k != DIGEST} for r in rows), key=_sort_key)
    keys = [r["cell"] for r in rows]
    if len(set(keys)) != len(keys):
        raise ValueError("write_rows: a cell appears more than once")
    table = _to_table(rows, study)
    digests = pa.array([row_digest(r) for r in table.to_pylist()], pa.string())
    table = table.set_column(table.schema.get_field_index(DIGEST), DIGEST, digests)
    path = Path(path)
    atomic_write(path, lambda tmp: pq.write_table(table, tmp))
    return path


def _read_parquet(path: Path) -> list[dict[str, Any]]:
    if not path.is_file():
        return []
    try:
        table = pq.read_table(path)
    except Exception as e:  # pyarrow raises ArrowInvalid, OSError ... for a damaged file
        raise ResultsError(f"{path}: unreadable results file ({type(e).__name__}: {e})") from None
    meta = table.schema.metadata or {}
    fmt = meta.get(b"format", b"").decode()
    if fmt not in READ_FORMATS:
        name, _, version = fmt.rpartition("/")
        ours, _, our_version = FORMAT.rpartition("/")
        if name == ours and version.isdigit() and int(version) > int(our_version):
            # say it is newer: "not a results file" read as damage, where a newer version's file
            # is whole and only this version cannot read it
            raise ResultsError(f"{path}: a {fmt} file, written by a newer sysid-testbed; this "
                               f"version reads {', '.join(READ_FORMATS)}")
        raise ResultsError(f"{path}: not a {FORMAT} file")
    verified = fmt == FORMAT  # a /1 file has no checksums: read as it was written
    _check_columns(path, table.schema, verified)
    rows = table.to_pylist()
    seen: set[str] = set()
    study = meta.get(b"study", b"").decode()
    for i, row in enumerate(rows):
        why = _row_problem(row, seen)
        # the sweep writes its name in both; a row without one is the sweep's own (as it reads it)
        if not why and study and row["study"] not in (None, "", study):
            why = f"study {row['study']!r}, the file's is {study!r}"
        if not why and verified:
            why = _digest_problem(row)
        if why:
            raise ResultsError(f"{path}: row {i} (cell {row['cell']!r}): {why}; the file was "
                               "altered or damaged")
    return rows


def _check_columns(path: Path, schema: pa.Schema, verified: bool = True) -> None:
    """Every fixed column (:data:`BASE_COLUMNS`, :data:`TAIL_COLUMNS`) with its type and every
    other column a float64 score, else ResultsError: a file without its ``noise`` or
    ``identifier`` column, or with ``noise`` as text, was an internal error of `testbed
    summary` and `testbed report` (KeyError, ValueError).  ``verified`` False: a file of
    format ``/1``, which has no :data:`DIGEST` column."""
    types = {f.name: f.type for f in schema}
    for name, t in {**BASE_COLUMNS, **TAIL_COLUMNS}.items():
        if name == DIGEST and not verified and name not in types:
            continue
        want = getattr(pa, t)()
        if name not in types:
            raise ResultsError(f"{path}: no column {name!r}; expected the columns of a "
                               f"`testbed sweep` results file ({FORMAT})")
        if types[name] != want:
            raise ResultsError(f"{path}: column {name!r} holds {types[name]}; expected {want}")
    for name, typ in types.items():
        if name in BASE_COLUMNS or name in TAIL_COLUMNS:
            continue
        if typ != pa.float64():
            raise ResultsError(f"{path}: score column {name!r} holds {typ}; expected double")
        if not name or name.startswith(".") or any(c in name for c in "/\\\0"):
            # a score names its figure (`report`'s score_<name>.png): "x/../../y" wrote outside
            # the -o folder (review 28b)
            raise ResultsError(f"{path}: score column {name!r}; expected a name without a path "
                               "separator or a leading '.'")


def _row_problem(row: dict[str, Any], seen: set[str]) -> str:
    """What is wrong with one row of a results file ("" if nothing); ``seen``: the cells of the
    rows before it (a cell twice is refused: :func:`write_rows` never writes one)."""
    if not row["cell"]:
        return "no cell key"
    if row["cell"] in seen:
        return "the cell appears twice"
    seen.add(row["cell"])
    text = next((k for k in TEXT_KEYS if not isinstance(row.get(k), str)), None)
    if text:  # null: `testbed summary` sorting the rows was a TypeError (round 11)
        return f"{text} {row.get(text)!r}; expected text"
    if row["status"] not in ("ok", "failed"):
        return f"status {row['status']!r}; expected 'ok' or 'failed'"
    if row["passed"] is None or row["seed"] is None:
        return "no " + ("passed" if row["passed"] is None else "seed")
    if row["noise"] is None or not (math.isfinite(row["noise"]) and row["noise"] >= 0):
        return f"noise {row['noise']!r}; expected a finite level >= 0 %"
    return ""


def _grid_problem(rows: list[dict[str, Any]]) -> str:
    """What makes ``rows`` (every row of a results file, parts included) more than one study's
    grid ("" if nothing): rows of two studies, or two cells of one scenario, noise level, seed
    and identifier.

    Each cell's key hashes its whole scenario (:func:`testbed.studies.sweep.cell_key`), so a
    row copied by hand under another key, or the rows of a study edited while its sweep ran
    (new bars: new keys; until the sweep consolidates, both versions' rows are in the file),
    were each counted: `testbed summary` reported 3 cells and a pass rate over 3 where the
    grid has 2, and merged rows of another study under the first row's name (round 12).
    """
    studies = sorted({str(r.get("study")) for r in rows if r.get("study") not in (None, "")})
    if len(studies) > 1:
        return (f"holds rows of studies {', '.join(map(repr, studies))}; expected one study's "
                "rows (a sweep writes one file per study)")
    seen: dict[tuple, str] = {}
    for r in rows:
        key = (r["scenario"], r["noise"], r["seed"], r["identifier"])
        if key in seen:
            return (f"cells {seen[key]!r} and {r['cell']!r} are both scenario {key[0]!r}, noise "
                    f"{key[1]:g} %, seed {key[2]}, identifier {key[3]!r}; expected one row per "
                    "cell (a row copied by hand, or a study edited while its sweep ran: "
                    "`testbed sweep` finishes it and keeps the current study's rows)")
        seen[key] = r["cell"]
    return ""


def read_results(path: str | os.PathLike, *, set_aside: bool = False,
                 resuming: bool = False) -> list[dict[str, Any]]:
    """Every row of a results file, including rows not yet consolidated.

    Parameters
    ----------
    path : path
        The results file; ``<path>.parts/`` is read too.
    set_aside : bool
        Rename a damaged row file ``<cell>.json.bad`` (else it is only skipped); either
        way a warning names it.
    resuming : bool
        For the sweep that owns the file: rows of another study or of cells no longer in its
        grid are the sweep's to refuse or drop (:func:`consolidate`); every other reader
        gets a ResultsError for them (:func:`_grid_problem`).

    Returns
    -------
    list of dict
        One row per cell (a row in both places counts once; the part wins, being
        the newer), sorted by scenario, noise, seed and identifier.  Every row has
        every score column found in any row (NaN where it has no such score); its
        checksum (:data:`DIGEST`), verified, is not among its columns.

    Raises
    ------
    ResultsError
        If ``path`` exists but is not a readable results file, or (unless ``resuming``)
        holds rows of two studies or two rows of one cell.
    """
    path = Path(path)
    by_cell: dict[str, dict[str, Any]] = {r["cell"]: r for r in _read_parquet(path)}
    for r in _read_parts(path, set_aside):
        by_cell[r["cell"]] = r
    rows = sorted(by_cell.values(), key=_sort_key)
    why = "" if resuming else _grid_problem(rows)
    if why:
        raise ResultsError(f"{path}: {why}")
    scores = score_columns(rows)
    for r in rows:
        r.pop(DIGEST, None)  # verified on read; a writer computes it anew from the values
        for k in scores:
            if r.get(k) is None:
                r[k] = math.nan
        r["passed"] = bool(r.get("passed")) and _checks_hold(r)
    return rows


def stored_checks(row: dict[str, Any]) -> list[Any] | None:
    """The checks stored in a results row's ``checks`` column: the JSON list the sweep writes
    (``[]`` for null or blank), or None when the text is not a JSON list (not JSON, a number,
    an object): the one parse every reader of the column goes through.

    A results file of format ``/1`` has no checksums, so its ``checks`` are read as they stand:
    ``"3"`` made `testbed report` an internal error (TypeError iterating an int, round 15),
    and `testbed summary` held the row to bars (a non-empty value) that no reader could list.
    Each reader judges a None as it judges text that is not JSON: no check holds.
    """
    text = row.get("checks")
    if text is None or text == "":
        return []
    try:
        checks = json.loads(text)
    except (TypeError, ValueError):
        return None
    return checks if isinstance(checks, list) else None


def judged_checks(row: dict[str, Any]) -> list[Check] | None:
    """The checks stored in ``row["checks"]``, judged again from their values and thresholds,
    a value that differs from the row's score column counting as NaN (never a pass: a row
    edited to ``passed`` over a NaN score counted in the pass rate); ``None`` where they
    cannot be read (not a list of checks).  A check without its value is judged from the
    score column alone."""
    checks = stored_checks(row)
    if checks is None:
        return None
    try:
        judged = []
        for c in checks:
            score = float(row.get(c["metric"], math.nan))
            value = float(c["value"]) if "value" in c else score
            same = value == score or (math.isnan(value) and math.isnan(score))
            judged.append(Check(str(c["metric"]), value if same else math.nan, str(c["bound"]),
                                float(c["threshold"])))
    except (TypeError, ValueError, KeyError):  # not a list of checks
        return None
    return judged


def _checks_hold(row: dict[str, Any]) -> bool:
    """Whether every check stored in ``row["checks"]`` passes (:func:`judged_checks`; none, or
    unreadable ones, hold nothing)."""
    checks = judged_checks(row)
    return bool(checks) and all(c.passed for c in checks)


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
    rows = read_results(path, resuming=True)  # the cells not kept are dropped below
    dropped = 0
    if keep is not None:
        kept = [r for r in rows if r["cell"] in keep]
        dropped = len(rows) - len(kept)
        rows = kept
    write_rows(path, rows, study=study)
    d = parts_dir(path)
    if d.is_dir():  # only after the Parquet file holds every row; set-aside *.bad files stay
        for p in d.iterdir():
            if not p.name.endswith(".bad"):
                p.unlink(missing_ok=True)
        with contextlib.suppress(OSError):  # not empty: it keeps the *.bad files
            d.rmdir()
    return len(rows), dropped
