"""A scored run on disk: ``run.json`` + ``run.npz`` (+ figures), enough to report without re-running.

Layout of a run folder::

    run.json     format, scenario (dict), kind, identifier {name, class, params}, equations,
                 scores, failures {aspect: reason}, checks, verdict ("pass", "FAIL" or
                 "no verdict"), passed, fit_time [s], dataset {fs, n_samples, signals,
                 prior, hash}, truth_units, rig_units, versions, commit, created, figures
                 (format ``/2`` on: sha256 of the rest of run.json, npz_sha256 of run.npz;
                 checked on read, so a flipped bit or an edited value is refused as damaged)
    run.npz      details/<name>  arrays behind the scores (TRAC, MAC, simulated signals ...)
                 model/<name>    identified arrays (M_, C_, K_, K3_, coef_, ...)
                 history/<name>  per-epoch training history (flattened with "/")
                 truth/<name>    the dataset's truth arrays
    *.png        the run figures (:mod:`testbed.reporting.figures`)

The folder is written beside its final place (a private temporary folder) and renamed
into it, so a reader sees the old run or the new one, never half of one; on Linux the old
and new folders are swapped in one atomic ``renameat2(RENAME_EXCHANGE)``.  Two processes
saving the same run at once both succeed, and the folder holds the last complete one.

A run never touches a folder other than its own: :func:`run_folder` accepts only a plain
name that stays strictly inside the output folder, and :func:`save_run` refuses a target
named ``.`` or ``..`` and refuses to replace an existing folder that is not a run folder
(no ``run.json``), e.g. the output folder itself with every other run in it.

Run history (``testbed run``, :func:`save_new_run`) keeps every run instead of replacing
one::

    out/runs/index.html                    every run, newest first (regenerated after each run)
    out/runs/<scenario>/latest.json        {"run": "<id>", "created": ..., "seed": ...}
    out/runs/<scenario>/<id>/run.json ...  one run folder as above

The identifier ``<id>`` is ``<YYYYmmddTHHMMSSZ>-s<seed>`` (UTC time of the run, noise seed),
with ``-2``, ``-3`` ... appended when another run of the same scenario and seed took that
name in the same second.  The folder is written under a temporary name in the scenario
folder and renamed to an unused identifier (a rename never replaces a non-empty folder), so
concurrent runs each get their own.  ``latest.json`` and the index are written atomically
(temporary file, rename) under one lock per output folder.  :func:`resolve_run` turns a run
folder, a scenario folder (its latest run) or a scenario name into a run folder;
:func:`list_runs` reads both layouts (run folders directly under the output folder, as
written before run history, and run folders inside scenario folders).
"""

from __future__ import annotations

import contextlib
import ctypes
import datetime as _dt
import errno
import hashlib
import json
import math
import os
import shutil
import sys
import tempfile
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

try:
    import fcntl
except ImportError:  # Windows
    fcntl = None  # type: ignore[assignment]

from testbed.core.atomic import (
    HTML_FILE,
    atomic_write_text,
    begin_in_flight,
    end_in_flight,
    no_room,
    refuse_foreign,
)
from testbed.core.errors import TestbedError, is_control
from testbed.core.provenance import git_commit, versions
from testbed.core.run_arrays import RUN_ARRAY_KINDS, check_run_npz
from testbed.pipeline.plugins import RIGS
from testbed.scoring.scorers import PASS, Check, verdict

FORMAT = "sysid-testbed-run/2"
#: Formats :func:`load_run` and :func:`list_runs` read: ``/1`` is ``/2`` without the checksums
#: (runs written before them are read as they were written).
READ_FORMATS = ("sysid-testbed-run/1", FORMAT)
#: Key of ``run.json`` holding the SHA-256 of its other keys (:func:`meta_digest`).
DIGEST = "sha256"
#: Key of ``run.json`` holding the SHA-256 of ``run.npz``'s bytes.
NPZ_DIGEST = "npz_sha256"
#: Truth arrays larger than this many elements are not copied into the run.
MAX_TRUTH_SIZE = 1_000_000


class RunStoreError(TestbedError, ValueError):
    """A run folder that would leave the output folder, or replace something that is not a run."""


def run_folder(out_dir: str | os.PathLike, name: str) -> Path:
    """The folder of run ``name`` in ``out_dir``, checked to be strictly inside it.

    Parameters
    ----------
    out_dir : path-like
        The output folder (e.g. ``out/runs``).
    name : str
        The run's name (the scenario name): one path component, not empty, not starting
        with ``.`` (``.`` and ``..`` would name the output folder or its parent; other dot
        names are kept for the temporary folders of :func:`save_run`).

    Returns
    -------
    Path
        ``out_dir / name``.

    Raises
    ------
    RunStoreError
        If ``name`` is not such a component, or ``out_dir / name`` resolves (e.g. through a
        symbolic link) to anything but a direct child of ``out_dir``.
    """
    if (not isinstance(name, str) or not name or name.startswith(".")
            or any(c in name for c in ("/", "\\", "\0"))):
        raise RunStoreError(f"run name {name!r}: expected a plain folder name (no path separator, "
                            "not starting with '.'), so that the run stays inside "
                            f"{os.fspath(out_dir)}")
    out = Path(out_dir)
    if (out / name).resolve().parent != out.resolve():
        raise RunStoreError(f"run folder {out / name} resolves to {(out / name).resolve()}, "
                            f"outside the output folder {out.resolve()}")
    return out / name


def _is_run_folder(p: Path) -> bool:
    """A folder :func:`save_run` may replace: a real (not linked) folder holding a ``run.json``."""
    return p.is_dir() and not p.is_symlink() and (p / "run.json").is_file()


def _check_target(run_dir: str | os.PathLike) -> Path:
    """``run_dir`` as a Path, refused if it names ``.``/``..`` or an existing non-run folder."""
    last = os.path.basename(os.fspath(run_dir).rstrip("/" + os.sep))
    if last in ("", ".", ".."):
        raise RunStoreError(f"{os.fspath(run_dir)}: a run folder cannot be named {last!r}")
    run_dir = Path(run_dir)
    if (run_dir.exists() or run_dir.is_symlink()) and not _is_run_folder(run_dir) \
            and not (run_dir.is_dir() and not run_dir.is_symlink() and not any(run_dir.iterdir())):
        raise RunStoreError(f"{run_dir}: exists and is not a run folder (no run.json); "
                            "refusing to replace it")
    return run_dir


@dataclass
class SavedRun:
    """A run read back from its folder (see the module docstring).

    Attributes
    ----------
    path : Path
    meta : dict
        The content of ``run.json``.
    details, model, history, truth : dict of str to ndarray or list of str
        The groups of ``run.npz``.
    """

    path: Path
    meta: dict[str, Any]
    details: dict[str, Any] = field(default_factory=dict)
    model: dict[str, Any] = field(default_factory=dict)
    history: dict[str, Any] = field(default_factory=dict)
    truth: dict[str, Any] = field(default_factory=dict)

    @property
    def name(self) -> str:
        return str(self.scenario.get("name", self.path.name))

    @property
    def scenario(self) -> dict[str, Any]:
        return self.meta["scenario"]

    @property
    def kind(self) -> str:
        return str(self.meta.get("kind", ""))

    @property
    def identifier(self) -> str:
        return str(self.meta["identifier"]["name"])

    @property
    def scores(self) -> dict[str, float]:
        return {k: _num(v) for k, v in self.meta["scores"].items()}

    @property
    def checks(self) -> list[Check]:
        return [_judged(c, self.meta["scores"]) for c in self.meta["checks"]]

    @property
    def failures(self) -> dict[str, str]:
        """Why the model failed whatever its scores (``Scores.failures``); empty if nothing did."""
        return {str(k): str(v) for k, v in self.meta.get("failures", {}).items()}

    @property
    def failure(self) -> str | None:
        return "; ".join(self.failures.values()) if self.failures else None

    @property
    def verdict(self) -> str:
        """``"pass"``, ``"FAIL"`` or ``"no verdict"`` (:func:`testbed.scoring.scorers.verdict`)."""
        return verdict(self.checks, self.failures)

    @property
    def passed(self) -> bool:
        return self.verdict == PASS

    @property
    def fit_time(self) -> float:
        return float(self.meta["fit_time"])

    @property
    def equations(self) -> list[str]:
        return list(self.meta.get("equations", []))

    @property
    def figures(self) -> list[Path]:
        # plain file names only: a /1 run.json (no checksum) listing "../../x.png" named a
        # file outside its folder (round 16)
        return [self.path / f for f in self.meta.get("figures", [])
                if isinstance(f, str) and f and f == Path(f).name and not f.startswith(".")
                and (self.path / f).is_file()]


def _num(v: Any) -> float:
    """A number from ``run.json`` (NaN was stored as null, infinities as strings)."""
    return float("nan") if v is None else float(v)


def _jsonable(v: Any) -> Any:
    """Plain JSON form of ``v`` (arrays to lists, numpy scalars to numbers, else ``repr``)."""
    if isinstance(v, dict):
        return {str(k): _jsonable(x) for k, x in v.items()}
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if isinstance(v, np.ndarray):
        return _jsonable(v.tolist())
    if isinstance(v, np.generic):
        return v.item()
    if isinstance(v, float) and not np.isfinite(v):
        return None if np.isnan(v) else ("inf" if v > 0 else "-inf")
    if v is None or isinstance(v, (bool, int, float, str)):
        return v
    return repr(v)


def _as_array(v: Any) -> np.ndarray | None:
    """``v`` as a numeric or string array storable without pickle, or None."""
    if isinstance(v, (list, tuple)) and v and all(isinstance(x, str) for x in v):
        return np.asarray(v, dtype=str)
    try:
        a = np.asarray(v)
    except (ValueError, TypeError):
        return None
    return a if a.dtype.kind in RUN_ARRAY_KINDS else None


def _flatten(d: dict[str, Any], prefix: str) -> dict[str, np.ndarray]:
    out: dict[str, np.ndarray] = {}
    for k, v in d.items():
        key = f"{prefix}/{k}"
        if isinstance(v, dict):
            out.update(_flatten(v, key))
        elif (a := _as_array(v)) is not None:
            out[key] = a
    return out


def _model_arrays(model: Any) -> tuple[dict[str, Any], dict[str, Any]]:
    """(learned arrays, learned string lists) of a fitted identifier: public attributes ending in _.

    A plain string (the rule that chose a setting from the data, e.g. ``noise_rule_``) is kept
    as a one-element list.
    """
    arrays, lists = {}, {}
    for k, v in vars(model).items():
        if not k.endswith("_") or k.startswith("_") or k == "history_" or v is None:
            continue
        if isinstance(v, str):  # e.g. a rule that chose a setting from the data (noise_rule_)
            lists[k] = [v]
        elif isinstance(v, (list, tuple)) and v and all(isinstance(x, str) for x in v):
            lists[k] = list(v)
        elif (a := _as_array(v)) is not None and a.dtype.kind != "U":
            arrays[k] = a
    return arrays, lists


def _identifier(result: Any) -> dict[str, Any]:
    model = result.model
    ident = result.scenario.identify or {}
    params = model.get_params() if hasattr(model, "get_params") else {}
    return {"name": ident.get("method", getattr(model, "name", "") or type(model).__name__),
            "class": f"{type(model).__module__}.{type(model).__qualname__}",
            "params": _jsonable(params)}


def _equations(model: Any) -> list[str]:
    try:
        return [str(e) for e in model.equations()]
    except Exception as e:  # an identifier without readable equations still gets a run folder
        return [f"(equations unavailable: {type(e).__name__}: {e})"]


def _rig_units(rig: str) -> dict[str, dict[str, str]]:
    """Unit and doc of every ``[rig]`` key from the rig's schema (empty if the rig is unknown)."""
    try:

        schema = RIGS.get(rig).rig_schema
    except Exception:
        return {}
    return {k: {"unit": f.unit, "doc": f.doc} for k, f in schema.items()}


def build_meta(result: Any) -> dict[str, Any]:
    """The ``run.json`` content of a :class:`~testbed.scoring.run.RunResult`."""

    ds = result.dataset
    signals = {f"{g}/{n}": {"unit": s.unit, "channels": list(s.channels),
                            "positions": None if s.positions is None else s.positions.tolist()}
               for g, group in (("measured", ds.measured), ("reference", ds.reference))
               for n, s in group.items()}
    _, model_lists = _model_arrays(result.model)
    return _jsonable({
        "format": FORMAT,
        "scenario": result.scenario.to_dict(),
        "kind": result.scenario.kind,
        "identifier": _identifier(result),
        "equations": _equations(result.model),
        "model_lists": model_lists,
        "scores": result.scores.values,
        "failures": result.scores.failures,
        "checks": [{"metric": c.metric, "value": c.value, "bound": c.bound, "threshold": c.threshold,
                    "passed": c.passed} for c in result.checks],
        "verdict": verdict(result.checks, result.scores.failures),
        "passed": verdict(result.checks, result.scores.failures) == PASS,
        "fit_time": float(result.fit_time),
        "dataset": {"fs": ds.fs, "n_samples": ds.n_samples, "signals": signals, "prior": ds.prior,
                    "hash": ds.attrs.get("content_hash") or ds.content_hash(),
                    "data_hash": ds.attrs.get("data_hash", ""),
                    "versions": ds.attrs.get("versions", {}), "commit": ds.attrs.get("git_commit", "")},
        "truth_units": ds.truth_units,
        "rig_units": _rig_units(result.scenario.rig),
        "versions": versions(),
        "commit": git_commit(),
        "created": _dt.datetime.now(_dt.UTC).isoformat(timespec="seconds"),
        "figures": [],
    })


def build_arrays(result: Any) -> dict[str, np.ndarray]:
    """The ``run.npz`` content of a :class:`~testbed.scoring.run.RunResult`."""
    arrays = _flatten(result.scores.details, "details")
    model_arrays, _ = _model_arrays(result.model)
    arrays.update(_flatten(model_arrays, "model"))
    arrays.update(_flatten(getattr(result.model, "history_", None) or {}, "history"))
    truth = {k: v for k, v in result.dataset.truth.items() if np.size(v) <= MAX_TRUTH_SIZE}
    arrays.update(_flatten(truth, "truth"))
    return arrays


def meta_digest(meta: dict[str, Any]) -> str:
    """The SHA-256 (64 hex digits) of ``run.json``'s content but its :data:`DIGEST`, as canonical
    JSON (keys sorted, ASCII): what a run of format ``/2`` stores under :data:`DIGEST`."""
    canon = {k: v for k, v in meta.items() if k != DIGEST}
    text = json.dumps(canon, sort_keys=True, ensure_ascii=True, allow_nan=True, default=repr)
    return hashlib.sha256(text.encode("ascii")).hexdigest()


def _write_json(path: Path, obj: dict[str, Any]) -> None:
    """Write ``run.json``, sealed with its :data:`DIGEST` (``obj`` gains it)."""
    obj[DIGEST] = meta_digest(obj)
    path.write_text(json.dumps(obj, indent=2, sort_keys=False, allow_nan=False) + "\n")


def _verify_meta(run_dir: Path, meta: dict[str, Any]) -> None:
    """Raise ValueError if a run of :data:`FORMAT` lacks its checksum or its content does not
    match it (round 16: a flipped digit of a score, a threshold loosened to 1e9, a seed or a
    scenario name edited in ``run.json`` were listed and reported as the run's own)."""
    if meta.get("format") != FORMAT:
        # a /1 run has no checksums: read as it was written.  But /1 was never written with
        # them: a /2 run.json whose format was edited to /1 (one word) was read unchecked, its
        # other edits (a score, a verdict) listed and reported as the run's own (round 17)
        sealed = [k for k in (DIGEST, NPZ_DIGEST) if k in meta]
        if sealed:
            raise ValueError(f"{run_dir / 'run.json'}: format {meta.get('format')!r} with "
                             f"{', '.join(sealed)}, which only {FORMAT!r} writes: edited")
        return
    if meta.get(DIGEST) != meta_digest(meta):
        raise ValueError(f"{run_dir / 'run.json'}: its content does not match its checksum "
                         f"({DIGEST!r}): damaged or edited after the run wrote it")


def _file_digest(path: Path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def save_run(result: Any, run_dir: str | os.PathLike,
             figures: Callable[[SavedRun, Path], list[Path]] | None = None) -> Path:
    """Write a run folder atomically (see the module docstring).

    Parameters
    ----------
    result : RunResult
    run_dir : path
        The folder to (re)place; see :func:`run_folder` for one inside an output folder.
    figures : callable, optional
        A figure writer ``figures(run, folder) -> paths`` (the reporting layer's
        :func:`testbed.reporting.figures.save_run_figures`), called on the saved run in its
        temporary folder before the atomic swap, so a run folder never holds half its figures.
        None: no figures.  Passed in, not imported: the run store sits below reporting.

    Returns
    -------
    Path
        ``run_dir``.

    Raises
    ------
    RunStoreError
        If ``run_dir`` is named ``.`` or ``..``, or exists and is neither a run folder nor
        empty (it is then left untouched).
    """
    run_dir = _check_target(run_dir)
    run_dir.parent.mkdir(parents=True, exist_ok=True)
    tmp, _ = _write_temporary(result, run_dir.parent, run_dir.name, figures)
    try:
        _replace_dir(tmp, run_dir)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    finally:
        end_in_flight(tmp)
    return run_dir


def _write_temporary(result: Any, parent: Path, stem: str,
                     figures: Callable[[SavedRun, Path], list[Path]] | None
                     ) -> tuple[Path, dict[str, Any]]:
    """A complete run folder under a private temporary name in ``parent``, and its meta.

    The folder is marked as being written (:func:`testbed.core.atomic.begin_in_flight`) until
    the caller renames it into place or removes it (:func:`~testbed.core.atomic.end_in_flight`).
    """
    tmp = Path(tempfile.mkdtemp(prefix=f".{stem}.", suffix=".tmp", dir=parent))
    begin_in_flight(tmp)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o777 & ~umask)  # mkdtemp makes it private; a run folder is as readable as any
    try:
        meta = build_meta(result)
        _write_json(tmp / "run.json", meta)
        np.savez_compressed(tmp / "run.npz", **build_arrays(result))
        meta[NPZ_DIGEST] = _file_digest(tmp / "run.npz")
        _write_json(tmp / "run.json", meta)
        if figures is not None:
            paths = figures(load_run(tmp), tmp)
            meta["figures"] = [p.name for p in paths]
            _write_json(tmp / "run.json", meta)
    except BaseException as e:
        shutil.rmtree(tmp, ignore_errors=True)
        end_in_flight(tmp)
        full = no_room(e, f"a run folder in {parent}")
        if full is not None:
            raise full from None
        raise
    return tmp, meta


#: The pointer file of a scenario folder naming its latest run.
LATEST = "latest.json"
#: The index page of an output folder.
INDEX = "index.html"
#: Lock file (``flock``) serialising the pointer and index updates of one output folder.
LOCK = ".runs.lock"


def run_id(created: str, seed: int) -> str:
    """The identifier of a run made at ISO 8601 time ``created`` with noise seed ``seed``.

    >>> run_id("2026-11-23T20:15:21+00:00", 7)
    '20261123T201521Z-s7'
    """
    when = _dt.datetime.fromisoformat(created).astimezone(_dt.UTC)
    return f"{when:%Y%m%dT%H%M%SZ}-s{int(seed)}"


def run_order(created: str, name: str) -> tuple[str, str, int]:
    """The order of runs: by ``created`` (ISO 8601 to the second), then by the folder ``name``
    with its counter as a number (``<id>-2`` before ``<id>-10``; :func:`save_new_run` adds
    ``-N`` to a run made in the same second as another of its seed).  As text, ``-10`` sorted
    before ``-2``: the newest of ten such runs was taken for an older one."""
    head, sep, tail = name.rpartition("-")
    if sep and tail.isdigit() and not tail.startswith("0") and not head.endswith("-s"):
        return created, head, int(tail)
    return created, name, 1


def scenario_folder(out_dir: str | os.PathLike, scenario: str) -> Path:
    """The history folder of ``scenario`` in ``out_dir`` (checked as :func:`run_folder`)."""
    folder = run_folder(out_dir, scenario)
    if folder.is_symlink() or (folder.exists() and not folder.is_dir()):
        raise RunStoreError(f"{folder}: exists and is not a folder of runs; refusing to write into it")
    return folder


@contextlib.contextmanager
def _locked(out_dir: Path) -> Iterator[None]:
    """Hold an exclusive ``flock`` on ``out_dir/.runs.lock`` (no lock where ``fcntl`` is missing)."""
    if fcntl is None:  # not POSIX: pointer and index are still written atomically
        yield
        return
    with open(out_dir / LOCK, "a") as fh:
        fcntl.flock(fh.fileno(), fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh.fileno(), fcntl.LOCK_UN)


def save_new_run(result: Any, out_dir: str | os.PathLike,
                 figures: Callable[[SavedRun, Path], list[Path]] | None = None,
                 index: Callable[[list[dict[str, Any]], Path], str] | None = None) -> Path:
    """Add a run to the history in ``out_dir`` (see the module docstring); never replaces one.

    Parameters
    ----------
    result : RunResult
    out_dir : path-like
        The output folder (``out/runs``); the run goes to ``out_dir/<scenario>/<id>``.
    figures : callable, optional
        As for :func:`save_run`.
    index : callable, optional
        ``index(runs, out_dir) -> html``: renders :func:`list_runs` of ``out_dir`` as the page
        written atomically to ``out_dir/index.html`` (the reporting layer's
        :func:`testbed.reporting.report.runs_index_html`).  None: no index page.

    Returns
    -------
    Path
        The new run folder.

    Raises
    ------
    RunStoreError
        If the scenario's name is not a plain folder name, or its folder is not a folder.
    InputError
        With ``index``: an ``index.html`` in ``out_dir`` that the testbed did not write.
    """
    out = Path(out_dir)
    if index is not None:  # a user's own page of that name was replaced (review 28b)
        refuse_foreign(out / INDEX, HTML_FILE, expected="another --out folder, or remove the file")
    folder = scenario_folder(out, result.scenario.name)
    folder.mkdir(parents=True, exist_ok=True)
    tmp, meta = _write_temporary(result, folder, "run", figures)
    base = run_id(meta["created"], result.scenario.seed)
    try:
        # a rename onto a non-empty folder fails (ENOTEMPTY/EEXIST), so each writer lands in
        # a folder of its own; 1000 runs of one scenario and seed in one second do not happen
        for n in range(1, 1001):
            target = folder / (base if n == 1 else f"{base}-{n}")
            try:
                os.rename(tmp, target)
                break
            except OSError as e:
                if e.errno not in (errno.ENOTEMPTY, errno.EEXIST, errno.ENOTDIR):
                    raise
        else:
            raise RunStoreError(f"{folder}: no free run name {base}-N (N <= 1000)")
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    finally:
        end_in_flight(tmp)
    with _locked(out):
        pointer = _read_latest(folder)
        if pointer is None or run_order(str(pointer.get("created", "")), str(pointer["run"])) \
                <= run_order(meta["created"], target.name):
            atomic_write_text(folder / LATEST, json.dumps(
                {"run": target.name, "created": meta["created"], "seed": result.scenario.seed}) + "\n")
        if index is not None:
            atomic_write_text(out / INDEX, index(list_runs(out), out))
    return target


def _read_latest(folder: Path) -> dict[str, Any] | None:
    """The pointer of a scenario folder if it names an existing run folder in it, else None."""
    if not (folder / LATEST).is_file():  # a FIFO there blocked `testbed report <scenario>` forever
        return None
    try:
        pointer = json.loads((folder / LATEST).read_text())
        name = pointer["run"]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    if not isinstance(name, str) or "/" in name or "\\" in name or name.startswith(".") \
            or not _is_run_folder(folder / name):
        return None
    return pointer


def resolve_run(source: str | os.PathLike, out_dir: str | os.PathLike = "out/runs") -> Path:
    """The run folder a user means by ``source``.

    Parameters
    ----------
    source : path-like
        A run folder; a scenario folder of the history (the run its ``latest.json`` names,
        else its newest run); or a scenario name, read as ``out_dir/<name>``.
    out_dir : path-like
        Where a bare scenario name is looked up.

    Returns
    -------
    Path
        A folder holding a ``run.json``.

    Raises
    ------
    RunStoreError
        If ``source`` is none of these (the message names it and what was expected).
    """
    text = os.fspath(source)
    p = Path(source)
    if not p.exists() and not any(c in text for c in ("/", "\\")) and not text.startswith("."):
        p = Path(out_dir) / text
    if p.is_dir():
        if (pointer := _read_latest(p)) is not None:
            return p / pointer["run"]
        children = [r for r in _runs_in(p) if r["path"] != p]
        if children:
            return max(children, key=lambda r: run_order(r["created"], r["id"]))["path"]
        if _is_run_folder(p):
            return p
    raise RunStoreError(f"{text}: not a run folder, a scenario folder of runs or a scenario "
                        f"with runs in {os.fspath(out_dir)} (written by `testbed run`)")


#: renameat2 flag (linux/fs.h): swap the two paths atomically.
_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _exchange(a: Path, b: Path) -> bool:
    """Swap folders ``a`` and ``b`` in one atomic step (Linux); False where unsupported."""
    if not sys.platform.startswith("linux"):
        return False
    fn = getattr(ctypes.CDLL(None, use_errno=True), "renameat2", None)
    if fn is None:  # a C library older than glibc 2.28
        return False
    if fn(_AT_FDCWD, os.fsencode(a), _AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.EINVAL, errno.ENOSYS, errno.ENOENT, errno.EPERM):
        return False  # file system without exchange, or b gone meanwhile: rename instead
    raise OSError(err, os.strerror(err), str(b))


def _replace_dir(new: Path, target: Path) -> None:
    """Move folder ``new`` to ``target``, replacing an old run folder ``target``.

    Safe against a concurrent writer of the same ``target``: each attempt either renames
    ``new`` into an absent (or empty) ``target``, or swaps it atomically with the run there,
    or moves that run aside and tries again; the last complete run wins.  Only ``new`` and
    folders this call moved aside (all beside ``target``) are ever deleted.
    """
    # 100 attempts: each fails only if another writer renamed a run in between, which takes
    # microseconds; a hundred such collisions in a row means something else is wrong
    for _ in range(100):
        try:
            os.rename(new, target)  # POSIX: succeeds onto an absent or empty folder
            return
        except OSError as e:
            if e.errno not in (errno.ENOTEMPTY, errno.EEXIST, errno.ENOTDIR, errno.EISDIR):
                raise
        if not _is_run_folder(target):
            if not target.exists():
                continue  # removed meanwhile: try the rename again
            raise RunStoreError(f"{target}: exists and is not a run folder (no run.json); "
                                "refusing to replace it")
        if _exchange(new, target):  # new now holds the old run
            shutil.rmtree(new, ignore_errors=True)
            return
        old = Path(tempfile.mkdtemp(prefix=f".{target.name}.", suffix=".old", dir=target.parent))
        os.rmdir(old)
        try:
            os.rename(target, old)
        except FileNotFoundError:
            continue
        shutil.rmtree(old, ignore_errors=True)
    raise RunStoreError(f"{target}: could not be replaced (another process keeps writing it)")


def _unflatten(arrays: dict[str, np.ndarray], group: str) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, a in arrays.items():
        head, _, rest = key.partition("/")
        if head != group:
            continue
        node = out
        *parents, leaf = rest.split("/")
        for p in parents:
            node = node.setdefault(p, {})
        node[leaf] = a.tolist() if a.dtype.kind == "U" else a
    return out


#: What every run.json holds, and of which type: what :class:`SavedRun` reads without a
#: default (a damaged or hand-edited file is refused on read, not half-reported).
_META_TYPES = {"scenario": dict, "identifier": dict, "scores": dict, "checks": list,
               "fit_time": (int, float)}
_CHECK_KEYS = ("metric", "value", "bound", "threshold")
#: Keys a run.json may lack (read with a default) but, where present, are of this type: a
#: string for "dataset" was an internal error (AttributeError) of `testbed report`.
_OPTIONAL_META_TYPES = {"failures": dict, "dataset": dict, "truth_units": dict, "rig_units": dict,
                        "equations": list, "model_lists": dict, "figures": list, "versions": dict}


def _check_meta(run_dir: Path, meta: dict[str, Any]) -> None:
    """Raise ValueError naming the first key of ``run.json`` missing or of the wrong type."""
    for key, typ in _META_TYPES.items():
        if not isinstance(meta.get(key), typ) or isinstance(meta.get(key), bool):
            raise ValueError(f"{run_dir / 'run.json'}: key {key!r} missing or not a "
                             f"{getattr(typ, '__name__', 'number')}")
    if not isinstance(meta["identifier"].get("name"), str):
        raise ValueError(f"{run_dir / 'run.json'}: key 'identifier.name' missing or not a str")
    # the fields a listing prints: a /1 run (no checksum) whose scenario name held a newline
    # split its `testbed runs --plain` row in two, a tab added a column, an ESC went to the
    # terminal and into the report (round 16)
    for key, value in (("scenario.name", meta["scenario"].get("name", "")),
                       ("identifier.name", meta["identifier"]["name"])):
        if not isinstance(value, str) or any(is_control(c) for c in value):
            raise ValueError(f"{run_dir / 'run.json'}: key {key!r} {value!r} is not one line of "
                             "text without control characters")
    seed = meta["scenario"].get("seed", 0)
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ValueError(f"{run_dir / 'run.json'}: key 'scenario.seed' {seed!r} is not an "
                         "integer >= 0")
    for key, typ in _OPTIONAL_META_TYPES.items():
        if key in meta and not isinstance(meta[key], typ):
            raise ValueError(f"{run_dir / 'run.json'}: key {key!r} not a {typ.__name__}")
    for i, c in enumerate(meta["checks"]):
        if not isinstance(c, dict) or any(k not in c for k in _CHECK_KEYS):
            raise ValueError(f"{run_dir / 'run.json'}: checks[{i}] is not a check with "
                             + ", ".join(_CHECK_KEYS))
    for k, v in meta["scores"].items():  # as _jsonable stores them: NaN null, infinities strings
        number = isinstance(v, (int, float)) and not isinstance(v, bool)
        if not (v is None or v in ("inf", "-inf") or number):
            raise ValueError(f"{run_dir / 'run.json'}: scores[{k!r}] {v!r} is not a number "
                             "(null for NaN, \"inf\" or \"-inf\")")


def _judged(c: dict[str, Any], scores: dict[str, Any]) -> Check:
    """A stored check judged again from its stored value and threshold, the value being NaN
    (never a pass) unless it equals its metric's stored score (NaN without one, as
    :func:`testbed.scoring.scorers.checks` makes it): a check holds a copy of its score, and a
    score edited to NaN under an unchanged check was listed and reported "pass"."""
    value, score = _num(c.get("value")), _num(scores.get(c.get("metric")))
    same = value == score or (math.isnan(value) and math.isnan(score))
    return Check(str(c.get("metric", "")), value if same else math.nan, str(c.get("bound", "")),
                 _num(c.get("threshold")))


def load_run(run_dir: str | os.PathLike) -> SavedRun:
    """Read a run folder written by :func:`save_run`.

    Raises
    ------
    FileNotFoundError
        If the folder has no ``run.json``.
    ValueError
        If ``run.json`` is not a run of a format it reads (:data:`READ_FORMATS`), lacks a key a
        run has, or (format ``/2``) does not match its checksum, or ``run.npz`` is missing or
        does not match its own.
    """
    run_dir = Path(run_dir)
    meta = json.loads((run_dir / "run.json").read_text())
    if not isinstance(meta, dict) or meta.get("format") not in READ_FORMATS:
        fmt = meta.get("format") if isinstance(meta, dict) else None
        raise ValueError(f"{run_dir}: not a {FORMAT} folder (format={fmt!r})")
    _check_meta(run_dir, meta)
    _verify_meta(run_dir, meta)
    arrays: dict[str, np.ndarray] = {}
    npz = run_dir / "run.npz"
    if meta["format"] == FORMAT:  # its arrays are part of the run: missing or changed, refused
        if not npz.is_file():
            raise ValueError(f"{npz}: missing (or not a file); the run wrote it")
        if _file_digest(npz) != meta.get(NPZ_DIGEST):
            raise ValueError(f"{npz}: its bytes do not match the checksum in run.json "
                             f"({NPZ_DIGEST!r}): damaged or replaced after the run wrote it")
    if npz.is_file():
        check_run_npz(run_dir)  # plain .npy members of numbers or text, judged by headers alone
        with np.load(npz, allow_pickle=False) as z:
            arrays = {k: z[k] for k in z.files}
    model = _unflatten(arrays, "model")
    model.update(meta.get("model_lists", {}))
    return SavedRun(run_dir, meta, _unflatten(arrays, "details"), model, _unflatten(arrays, "history"),
                    _unflatten(arrays, "truth"))


def _run_row(p: Path, meta: dict[str, Any]) -> dict[str, Any]:
    """A run's listing row.  Its verdict and each check's ``passed`` are judged again from the
    stored values, thresholds and failures (as :class:`SavedRun` does), not read: a run.json
    edited to say ``passed`` over a NaN score is listed as the FAIL it is."""
    sc = meta.get("scenario", {})
    checks = [_judged(c, meta.get("scores", {})) for c in meta.get("checks", [])]
    failures = meta.get("failures") or {}
    return {"path": p, "id": p.name, "scenario": str(sc.get("name", p.name)),
            "seed": sc.get("seed", ""), "identifier": str(meta.get("identifier", {}).get("name", "")),
            "verdict": verdict(checks, failures), "fit_time": _num(meta.get("fit_time")),
            "created": str(meta.get("created", "")),
            "failure": "; ".join(str(v) for v in failures.values()),
            "checks": [{"metric": c.metric, "value": c.value, "bound": c.bound,
                        "threshold": c.threshold, "passed": c.passed} for c in checks],
            "scores": {str(k): _num(v) for k, v in meta.get("scores", {}).items()
                       if v is None or isinstance(v, (int, float, str))}}


def _read_row(p: Path) -> dict[str, Any] | None:
    """The :func:`list_runs` row of run folder ``p``; None if it is not a readable run."""
    if not _is_run_folder(p):
        return None
    try:
        meta = json.loads((p / "run.json").read_text())
        if meta.get("format") not in READ_FORMATS:
            return None
        _check_meta(p, meta)  # as load_run: a damaged or edited file is named, not listed
        _verify_meta(p, meta)
        if meta["format"] == FORMAT and not (p / "run.npz").is_file():
            return None  # its arrays lost: `testbed report` could not read it
        return _run_row(p, meta)
    except (OSError, ValueError, TypeError, AttributeError):
        return None


def _lost_run_json(p: Path) -> bool:
    """A real folder holding a run's ``run.npz`` but no ``run.json`` file (deleted, or a folder
    in its place): a damaged run, which the listing left out in silence (round 16)."""
    return (p.is_dir() and not p.is_symlink() and (p / "run.npz").is_file()
            and not (p / "run.json").is_file())


def _runs_in(folder: Path, damaged: list[Path] | None = None) -> list[dict[str, Any]]:
    """Rows of ``folder`` itself if it is a run folder, and of the run folders in it; run
    folders whose ``run.json`` cannot be read are appended to ``damaged`` if given."""
    candidates = [folder]
    if folder.is_dir() and not folder.is_symlink():
        candidates += [c for c in sorted(folder.iterdir()) if not c.name.startswith(".")]
    rows = []
    for c in candidates:
        row = _read_row(c)
        if row is not None:
            rows.append(row)
        elif damaged is not None and (_is_run_folder(c) or _lost_run_json(c)):
            damaged.append(c)
    return rows


def list_runs(out_dir: str | os.PathLike, scenario: str | None = None, *,
              damaged: list[Path] | None = None) -> list[dict[str, Any]]:
    """The saved runs in ``out_dir`` (``testbed run``'s ``out/runs``), oldest first.

    Reads run folders directly under ``out_dir`` (written by :func:`save_run` into a
    :func:`run_folder`) and inside its scenario folders (:func:`save_new_run`).  Only
    ``run.json`` is read (not the arrays); a folder without a readable ``run.json`` of this
    format is left out (and named in ``damaged`` if it holds a damaged one).

    Parameters
    ----------
    out_dir : path-like
    scenario : str, optional
        Only the runs of this scenario.
    damaged : list of Path, optional
        If given, the run folders left out because their ``run.json`` cannot be read, is not
        JSON, is of another format, does not match its checksum or is missing beside a
        ``run.npz`` (damaged, truncated, edited or foreign), or whose ``run.npz`` is missing,
        are appended to it, in folder order, whatever their scenario.

    Returns
    -------
    list of dict
        ``path`` (Path), ``id`` (folder name), ``scenario``, ``seed``, ``identifier``,
        ``verdict``, ``fit_time`` [s], ``created`` (ISO 8601, UTC), ``failure`` (why the model
        failed whatever its scores, "" if nothing did), ``checks`` (metric, value, bound,
        threshold, passed) and ``scores`` (metric -> float); sorted by ``created``,
        then scenario and folder name.
    """
    out = Path(out_dir)
    if not out.is_dir():
        return []
    runs = [r for p in sorted(out.iterdir()) if not p.name.startswith(".")
            for r in _runs_in(p, damaged)]
    if scenario is not None:
        runs = [r for r in runs if r["scenario"] == scenario]
    return sorted(runs, key=lambda r: (r["created"], r["scenario"], run_order("", r["id"])[1:]))
