"""Run a study's grid of cells on one machine or a Dask cluster, resumably.

A *cell* is one (scenario, noise level, seed, identifier) of a
:class:`~testbed.studies.study.Study`.  :func:`run_sweep` sends every cell through one
joblib seam (:func:`parallel`): sequential for ``jobs=1``, loky processes for
``jobs>1``, and a ``distributed.Client`` with joblib's ``"dask"`` backend when a
scheduler address is given.  It first simulates the clean datasets the cells
need, one task per distinct rig configuration (cells that differ only in
identifier, noise level or seed share one simulation through the
:class:`~testbed.pipeline.cache.DatasetCache`, which derives each cell's noisy data on
load), then runs the cells, writing each row as it arrives (:mod:`testbed.studies.results`).
A rerun skips every cell already in the results; a killed sweep loses only the
cells in flight.

Faults: a damaged row file (e.g. truncated by a full disk) is named in a warning, set
aside as ``*.bad`` and its cell run again; ``retry_failed`` runs the cells recorded as
failed again.  Worker processes watch the sweep's main process and exit within
:data:`WATCHDOG_PERIOD` seconds of its death (a ``kill -9`` of the sweep included), so no
worker computes on as an orphan.

With a Dask cluster on several machines, the dataset cache folder must be one
all workers see (a shared file system); the results are written by the caller.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import math
import os
import re
import sys
import threading
import time
import traceback
from collections.abc import Callable, Iterable, Iterator
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

try:
    import fcntl
except ImportError:  # (not on Windows)
    fcntl = None  # type: ignore[assignment]

from joblib import Parallel, delayed, parallel_config

from testbed.core import errors
from testbed.core.atomic import (
    PARQUET_FILE,
    atomic_write_text,
    begin_in_flight,
    end_in_flight,
    not_regular,
    refuse_foreign,
)
from testbed.core.errors import IdentificationError, InputError, exception_text, show_value
from testbed.core.provenance import git_commit, versions
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.generate import noise_free_scenario
from testbed.pipeline.plugins import IDENTIFIERS, RIGS
from testbed.pipeline.scenario import Scenario
from testbed.scoring.run import run_scenario
from testbed.studies.results import ResultsError, consolidate, parts_dir, read_results, write_part
from testbed.studies.statistics import failed_cells_line, missed_bars_line
from testbed.studies.study import Study, import_plugins, load_study

DEFAULT_RESULTS_DIR = Path("out") / "studies"
#: How often a worker checks that the sweep's main process is alive [s]: an orphaned worker
#: stops within this time; a check is one getppid call, so polling costs nothing measurable.
WATCHDOG_PERIOD = 0.5

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Cell:
    """One run of a study: a scenario with its noise, seed and identifier filled in.

    Attributes
    ----------
    key : str
        :func:`cell_key` of ``scenario``.
    study : str
    scenario : Scenario
        ``with_noise(noise).replace(seed=seed, identify={"method": identifier, **params})``.
    noise : float
        [% of channel RMS]
    seed : int
    identifier : str
    params : dict
        The identifier's hyperparameters (without ``method``).
    """

    key: str
    study: str
    scenario: Scenario
    noise: float
    seed: int
    identifier: str
    params: dict[str, Any]


def cell_key(scenario: Scenario) -> str:
    """Stable key of a cell: a hash of everything that decides its row.

    The scenario's name, its data (:meth:`Scenario.data_hash`: rig, simulation,
    excitation, noise, seed), its signal chain, its ``[identify]`` table
    (identifier and hyperparameters) and its ``[score]`` thresholds.  Code
    versions are left out, so a rerun after a code change still resumes; each row
    records the versions and commit that computed it.
    """
    blob = json.dumps({"scenario": scenario.name, "data": scenario.data_hash(),
                       "signal": scenario.signal, "identify": scenario.identify,
                       "score": scenario.score}, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(blob.encode()).hexdigest()[:20]


#: Rough relative cost of one fit, for scheduling only (measured on the default study: pysindy's
#: convex solves take 10-20 s, SGD-SINDy 1-10 s, the least-squares fits well under a second).
_IDENTIFIER_COST = {"pysindy_pi": 100.0, "sgd_sindy": 10.0, "sindy_pi": 3.0}


def shared_computation(cell: Cell) -> str:
    """Key of the computation whose row ``cell`` reports: cells of one key give one row, but for
    their own cell key, seed, dataset hash and times.

    Parameters
    ----------
    cell : Cell

    Returns
    -------
    str
        ``"shared:"`` and the :func:`cell_key` of the cell with seed 0, for a cell at 0 % noise
        of an identifier that declares itself deterministic (:func:`declares_deterministic`);
        else the cell's own key.

    The seed draws only the measurement noise (:func:`testbed.pipeline.generate.derive`: at
    0 % noise it draws nothing and copies the clean arrays), and an identifier sees only the
    measurement and its hyperparameters.  So the cells of one scenario, identifier and
    hyperparameters at 0 % noise see bit-identical measurements, and an identifier that declares
    its fit :attr:`~identify._base.Identifier.deterministic` (every draw seeded by one of its
    hyperparameters; the conformance test refits each built-in one and compares to the bit)
    gives them bit-identical scores.  :func:`run_sweep` computes one of them and copies its row
    to the others, if that row passed through the fit (``ok``) and, a row of an earlier run, was
    computed by this sweep's commit and versions (else each is computed): the default study's
    0 % seeds repeated 32 of its 144 cells (88 s of its 380 s of CPU, two thirds of it
    pysindy's SINDyPI).  Every other cell is its own
    computation (its :func:`cell_key`): noisy cells, and the cells of an identifier that does
    not declare itself deterministic (a plugin's 0 % seeds then show its own spread).
    """
    sc = cell.scenario
    if float(sc.noise.get("rms_percent", 0.0)) == 0.0 and declares_deterministic(
            IDENTIFIERS.get(cell.identifier)):
        return "shared:" + cell_key(sc.replace(seed=0))
    return cell.key


def declares_deterministic(cls: type) -> bool:
    """Whether the identifier class itself declares ``deterministic = True``: a subclass (a
    plugin deriving from a built-in identifier and changing its fit) does not inherit it."""
    return vars(cls).get("deterministic", False) is True


def _expected_cost(cell: Cell) -> float:
    """Scheduling weight of a cell: identifier cost times the simulated duration."""
    return _IDENTIFIER_COST.get(cell.identifier, 1.0) * float(
        cell.scenario.simulation.get("duration", 1.0))


def expand(study: Study) -> list[Cell]:
    """Every runnable cell of ``study`` in grid order (scenario, identifier, noise, seed).

    Pairs whose identifier kind differs from the rig kind are left out (see
    :meth:`Study.skipped`).  An identifier that is the scenario's own ``[identify]`` method
    starts from that table's hyperparameters; the study's table for it overrides them.
    """
    cells = []
    for sc, method in study.combinations():
        # The scenario's own [identify] hyperparameters hold for its own method (they were chosen
        # for its data); the study's [identifiers.<name>] table overrides them.
        own = sc.identify if sc.identify and sc.identify.get("method") == method else {}
        params = {**{k: v for k, v in own.items() if k != "method"}, **study.params.get(method, {})}
        for noise in study.noise:
            for seed in study.seeds:
                csc = sc.with_noise(noise).replace(seed=seed, identify={"method": method, **params})
                cells.append(Cell(cell_key(csc), study.name, csc, float(noise), int(seed), method,
                                  dict(params)))
    return cells


# --------------------------------------------------------------------------- the joblib seam
@contextlib.contextmanager
def _backend(jobs: int, dask_address: str | None) -> Iterator[int]:
    """Configure joblib for the run; yield the ``n_jobs`` to give ``Parallel``."""
    if dask_address:
        from distributed import Client

        with Client(dask_address) as client, parallel_config(backend="dask"):
            client.wait_for_workers(1, timeout=60)
            yield -1
    elif jobs > 1:
        with parallel_config(backend="loky", inner_max_num_threads=1):
            yield jobs
    else:
        with parallel_config(backend="sequential"):
            yield 1


def parallel(fn: Callable[..., Any], args: Iterable[tuple], n_jobs: int) -> Iterator[Any]:
    """``fn(*a)`` for each ``a``, yielded as each finishes, under the active joblib backend.

    ``batch_size=1`` so that each result is handed back (and written) as soon as
    it exists rather than with a batch.
    """
    run = Parallel(n_jobs=n_jobs, return_as="generator_unordered", batch_size=1)
    yield from run(delayed(fn)(*a) for a in args)


# --------------------------------------------------------------------------- tasks (run in workers)
def error_name(e: BaseException) -> str:
    """The exception's name as a failed cell's row records it (read back by
    :func:`testbed.studies.statistics.failure_kind`): its class name, but a refusal
    (:class:`~testbed.core.errors.RigError`, :class:`~testbed.core.errors.ScenarioError`)
    whose class :mod:`testbed.core.errors` does not hold (a plugin's subclass) is named by the
    nearest class there, its own name after it, and another class that only shares a name
    with one there by its qualified name: the name decides refused or crashed (review 22b)."""
    cls = type(e)
    if isinstance(e, (errors.RigError, errors.ScenarioError)):
        if getattr(errors, cls.__name__, None) is cls:
            return cls.__name__
        base = next(c for c in cls.__mro__ if getattr(errors, c.__name__, None) is c)
        return f"{base.__name__}: {cls.__name__}"
    if hasattr(errors, cls.__name__) and getattr(errors, cls.__name__) is not cls:
        return f"{cls.__module__}.{cls.__name__}"
    return cls.__name__


def _error_text(e: BaseException) -> str:
    tb = traceback.extract_tb(e.__traceback__)
    where = f" ({Path(tb[-1].filename).name}:{tb[-1].lineno})" if tb else ""
    return f"{error_name(e)}: {exception_text(e)}{where}"


_WORKER_LOCK = threading.Lock()
_WATCHED: set[int] = set()


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # exists, owned by someone else (a recycled pid): not our sweep
        return False
    return True


def watch_parent(parent: int | None, period: float = WATCHDOG_PERIOD) -> None:
    """In a worker process: exit at once when the sweep's main process ``parent`` is gone.

    Starts one daemon thread per process (later calls do nothing).  A loky worker is a
    child of the main process, so its parent pid changes the moment the main process dies
    (the orphan is adopted by init or a subreaper), even while the dead main process is a
    zombie not yet reaped; a worker that is not a direct child polls ``parent`` itself.  The
    thread ends the process with ``os._exit``, in the middle of a fit if need be: its cell
    was not written and a rerun runs it.

    Parameters
    ----------
    parent : int or None
        Pid of the sweep's main process; None (a Dask worker, owned by its cluster) or this
        process's own pid (a sequential sweep) starts nothing.
    period : float
        Seconds between checks.
    """
    if parent is None or parent == os.getpid():
        return
    with _WORKER_LOCK:
        if _WATCHED:
            return
        _WATCHED.add(parent)
    ppid = os.getppid()
    direct = ppid == parent

    def watch() -> None:
        while (os.getppid() == ppid) if direct else _alive(parent):
            time.sleep(period)
        os._exit(3)  # 3: an exit status of its own, distinct from a failing cell's exception

    threading.Thread(target=watch, name="testbed-parent-watchdog", daemon=True).start()


def _prepare_worker(plugins: tuple[str, ...], parent: int | None = None) -> None:
    """Import the plugins and load both registries, once per process; watch ``parent``.

    The registries import their packages lazily on first lookup; a Dask worker
    runs tasks in several threads, so the first load is serialised here.
    See :func:`watch_parent` for ``parent``.
    """

    watch_parent(parent)
    with _WORKER_LOCK:
        import_plugins(plugins)
        RIGS.names()
        IDENTIFIERS.names()


def ensure_dataset(scenario: Scenario, cache_dir: str, plugins: tuple[str, ...],
                   parent: int | None = None) -> tuple[str, float, str]:
    """Simulate ``scenario``'s clean dataset into the cache unless present (and intact).

    ``parent``: the sweep's main process (see :func:`watch_parent`).

    Returns
    -------
    (data_hash, seconds, error)
        ``error`` is "" on success; a failure is left for the cells to record.
    """

    _prepare_worker(plugins, parent)
    t0 = time.perf_counter()
    try:
        DatasetCache(cache_dir).clean(scenario)
        err = ""
    except Exception as e:
        err = _error_text(e)
    return scenario.data_hash(), time.perf_counter() - t0, err


def sweep_provenance() -> dict[str, str]:
    """The ``versions`` and ``commit`` columns of a sweep's rows, as this process sees them.

    :func:`run_sweep` takes them once, in its main process, and hands them to every cell: each
    process caches its own answer from the first time it asks git (``git_commit``), so a loky
    worker started after a commit (or after the tree turned dirty, or whose ``git status`` ran
    past its timeout under load and gave "unknown") stamped its rows with another commit than
    the sequential and Dask cells of the same sweep, which run in the main process: the same
    cell gave another row depending on where it ran.
    """
    return {"versions": json.dumps(versions(), sort_keys=True), "commit": git_commit()}


#: Columns of a row that are its cell's own, not its computation's: a row copied from the cell
#: of the same :func:`shared_computation` keeps these (``dataset_hash`` and the times are its
#: own dataset's load) and takes every other column from its source.
OWN_COLUMNS = ("study", "cell", "scenario", "rig", "noise", "seed", "identifier", "params",
               "data_time", "cell_time", "dataset_hash")


#: A sweep run in this process (``jobs`` 1) whose process ended inside the same cell this many
#: times in a row, leaving no row (``os.abort``, a signal, a crash in compiled code, ``kill -9``:
#: nothing in the process can record it), records that cell as failed instead of running it
#: again; one such end is not enough, since a user's ``kill -9`` of a long cell is one too, and
#: a resumed sweep runs the cell again.  Hostile round 20: a plugin's ``os.abort()`` ended
#: ``sweep --jobs 1`` with status 134 and no row, and every resume ran the cell and died again.
ENDS_BEFORE_FAILED = 2
#: The error text of such a cell (:func:`testbed.studies.statistics.failure_kind`: a crash).
PROCESS_ENDED = "process ended"


def inflight_path(results: str | os.PathLike, key: str) -> Path:
    """The marker of a cell running in a sequential sweep: ``<results>.parts/<cell>.inflight``,
    holding how many processes in a row have ended while running it."""
    return parts_dir(results) / f"{key}.inflight"


def _inflight_count(marker: Path) -> int:
    """How many processes in a row ended inside the marker's cell (0 when there is no marker;
    an unreadable marker counts as one end, whatever else it holds)."""
    try:
        return max(1, int(marker.read_text(encoding="ascii").strip()))
    except FileNotFoundError:
        return 0
    except (OSError, ValueError, UnicodeDecodeError):
        return 1


def ended_cell_row(cell: Cell, ends: int, plugins: tuple[str, ...],
                   provenance: dict[str, str]) -> dict[str, Any]:
    """The failed row of a cell inside which :data:`ENDS_BEFORE_FAILED` processes in a row
    ended (see :func:`run_cell`'s ``inflight``)."""
    row = _base_row(cell)
    who = (f"code of plugin(s) {', '.join(plugins)} may abort the interpreter or crash it"
           if plugins else "the interpreter was aborted, crashed or killed")
    row["status"], row["error"] = "failed", (
        f"{PROCESS_ENDED}: the sweep's process ended {ends} times in a row while this cell ran, "
        f"with no verdict ({who}: os.abort, a signal, a crash in compiled code, kill -9); "
        "`--retry-failed` runs it again")
    row.update(provenance)
    row["cell_time"] = math.nan
    return row


def _base_row(cell: Cell) -> dict[str, Any]:
    """A cell's results row before it runs: its grid columns, status ok and no scores."""
    sc = cell.scenario
    return {
        "study": cell.study, "cell": cell.key, "scenario": sc.name, "rig": sc.rig,
        "noise": cell.noise, "seed": cell.seed, "identifier": cell.identifier,
        "params": json.dumps(cell.params, sort_keys=True), "status": "ok", "error": "",
        "fit_time": math.nan, "data_time": math.nan, "passed": False, "checks": "[]",
        "dataset_hash": "",
    }


def unexplained_nonfinite(values: dict[str, float], held: set[str],
                          failures: dict[str, str] | set[str]) -> list[str]:
    """The non-finite scores a cell's reason must name, sorted; [] where nothing is left to say.

    A failed fit or a failed simulation leaves the scores undefined by definition and its own
    reason says why: listing them again named some 40 scores after "fit failed" and counted the
    cell a second time ("non-finite scores") in the summary (round 24's
    ``b24_br_L0p5_w20_t6_s6_z3``, ``ls_sindy`` 1 %), and "diverged" with its NaN TRAC
    (``beams_stiff__019``, ``__025``).  A score no bar holds is not a reason when every held
    score is finite: the five-bar's ``coef_error`` is infinite by definition where the
    identified row lacks the truth's largest term; it failed a passing cell (marked failed and
    passed at once) and, after another failure such as "uninformative", counted it a second
    time (round 27's ``fb27_sine_amp0p014`` at 3 %).  Otherwise every non-finite score is
    named: a held score that is not finite (or missing) with no failure that explains it.

    Parameters
    ----------
    values : dict
        The cell's scores by name.
    held : set of str
        The metrics its checks hold.
    failures : dict or set
        The names of its scored failures (``Scores.failures``: ``"fit"``, ``"simulation"``, ...).

    Returns
    -------
    list of str
        The scores to name after "non-finite scores: ".
    """
    if "fit" in failures or "simulation" in failures:
        return []
    bad = sorted(k for k, v in values.items() if not math.isfinite(v))
    held_bad = any(not math.isfinite(values.get(m, math.nan)) for m in held)
    if held and not held_bad:
        return []
    return bad


def run_cell(cell: Cell, cache_dir: str, plugins: tuple[str, ...],
             parent: int | None = None, provenance: dict[str, str] | None = None,
             same_as: dict[str, Any] | None = None,
             inflight: Path | None = None) -> dict[str, Any]:
    """Run one cell (dataset from the cache, identify, score) and return its results row.

    Never raises for a failing cell: an exception, or a non-finite score, gives
    ``status = "failed"`` with the error text, so the sweep goes on.  ``parent``: the
    sweep's main process (see :func:`watch_parent`).  ``provenance``: the row's ``versions``
    and ``commit`` (:func:`sweep_provenance` of the sweep's main process); None takes this
    process's own.  ``same_as``: the finished row of a cell of the same
    :func:`shared_computation`; the cell's dataset is loaded (for its own ``dataset_hash``) and
    every other column but :data:`OWN_COLUMNS` is copied from it (its scores, verdict, fit time
    and the commit that computed them).  ``inflight``: the cell's marker
    (:func:`inflight_path`, a sweep run in this process), counted up before the cell runs and
    removed after, whatever Python code ends it (an exception, Ctrl-C, SIGTERM's clean exit):
    only a process that ended inside the cell leaves it.
    """
    if inflight is None:
        return _run_cell(cell, cache_dir, plugins, parent, provenance, same_as)
    atomic_write_text(inflight, str(_inflight_count(inflight) + 1))
    # a signal's exit that cannot unwind (testbed.core.interrupts.exit_now: SIGTERM while a
    # compiled kernel runs) removes it too, as it removes the temporary files being written: a
    # batch scheduler's wall-time kill twice in one slow cell is no crash of the cell
    begin_in_flight(inflight)
    try:
        return _run_cell(cell, cache_dir, plugins, parent, provenance, same_as)
    finally:
        inflight.unlink(missing_ok=True)
        end_in_flight(inflight)


def _run_cell(cell: Cell, cache_dir: str, plugins: tuple[str, ...], parent: int | None,
              provenance: dict[str, str] | None, same_as: dict[str, Any] | None) -> dict[str, Any]:
    """:func:`run_cell` without its marker."""

    t0 = time.perf_counter()
    sc = cell.scenario
    row = _base_row(cell)
    try:
        _prepare_worker(plugins, parent)

        dataset = DatasetCache(cache_dir).get(sc)
        row["data_time"] = time.perf_counter() - t0
        row["dataset_hash"] = str(dataset.attrs.get("content_hash", ""))
        if same_as is not None:
            row.update({k: v for k, v in same_as.items() if k not in OWN_COLUMNS})
            row["cell_time"] = time.perf_counter() - t0
            return row
        result = run_scenario(sc, dataset=dataset)
        row["fit_time"] = result.fit_time
        row.update({k: float(v) for k, v in result.scores.values.items()})
        row["checks"] = json.dumps([{**asdict(c), "passed": c.passed} for c in result.checks])
        bad = unexplained_nonfinite(result.scores.values, {c.metric for c in result.checks},
                                    result.scores.failures)
        reasons = [result.failure, bad and "non-finite scores: " + ", ".join(bad),
                   not result.scores.values and "no scores"]
        reason = "; ".join(r for r in reasons if r)
        if reason:
            row["status"], row["error"] = "failed", reason
        row["passed"] = result.passed
    except Exception as e:
        row["status"], row["error"] = "failed", _error_text(e)
    row.update(provenance if provenance is not None else sweep_provenance())
    row["cell_time"] = time.perf_counter() - t0
    release_freed_memory()
    return row


def release_freed_memory() -> bool:
    """Hand the C heap's free pages back to the system (glibc ``malloc_trim``); True if done.

    A cell's arrays, MuJoCo models and compiled kernels are freed when it ends, but glibc keeps
    the freed pages of its heap mapped, so a worker's resident size grew by 2-27 MB per beam
    member while its Python heap stayed flat (measured on the families study: +114 MB over 11
    members; after ``malloc_trim(0)`` flat).  loky counts that growth as a memory leak: past
    300 MB it stops the worker after its task and warns "A worker stopped while some jobs were
    given to the executor", and the next cell pays a fresh worker's imports.  No-op (False) on a
    C library without ``malloc_trim`` (macOS, musl).
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        import ctypes

        trim = ctypes.CDLL(None).malloc_trim
    except (OSError, AttributeError):
        return False
    trim(0)
    return True


# --------------------------------------------------------------------------- the sweep
def default_results_path(study: Study) -> Path:
    """``out/studies/<study>.parquet`` under the current directory."""
    return DEFAULT_RESULTS_DIR / f"{study.name}.parquet"


class _Progress:
    """Counters of a sweep, drawn as a rich progress bar only when stderr is a terminal."""

    def __init__(self, label: str, total: int) -> None:
        self.done = self.failed = 0
        self._prog = None
        if sys.stderr.isatty() and total:
            from rich.console import Console
            from rich.progress import (
                BarColumn,
                MofNCompleteColumn,
                Progress,
                TextColumn,
                TimeElapsedColumn,
                TimeRemainingColumn,
            )

            self._prog = Progress(TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(),
                                  TextColumn("{task.fields[failed]} failed"), TimeElapsedColumn(),
                                  TimeRemainingColumn(), console=Console(stderr=True), transient=True)
            self._prog.start()
            self._task = self._prog.add_task(label, total=total, failed=0)

    def advance(self, failed: bool = False) -> None:
        self.done += 1
        self.failed += bool(failed)
        if self._prog is not None:
            self._prog.update(self._task, advance=1, failed=self.failed)

    def close(self) -> None:
        if self._prog is not None:
            self._prog.stop()


@dataclass
class SweepStats:
    """What one :func:`run_sweep` call did (pass one as ``stats=`` to have it filled in).

    Attributes
    ----------
    cells, skipped_done, run, failed : int
        Cells in the grid, already in the results, run now, failed now.
    failed_total : int
        Cells recorded as failed in the results at the end (now or by an earlier run).
    copied : int
        Of ``run``, the cells whose row was copied from a cell of the same computation
        (:func:`shared_computation`) instead of computed.
    datasets : int
        Clean simulations run (absent from the cache); noisy datasets are derived, not counted.
    data_seconds, cells_seconds : float
        Wall time of the dataset phase and of the cell phase [s].
    """

    cells: int = 0
    skipped_done: int = 0
    run: int = 0
    failed: int = 0
    failed_total: int = 0
    copied: int = 0
    datasets: int = 0
    data_seconds: float = 0.0
    cells_seconds: float = 0.0


def _say(msg: str, verbose: bool) -> None:
    if verbose:
        print(msg, file=sys.stderr, flush=True)


def _check_rows_match_cells(rows: list[dict[str, Any]], cells: list[Cell], results: Path) -> None:
    """Refuse a finished row whose scenario, identifier, noise, seed or hyperparameters differ
    from those of the grid's cell its ``cell`` key names (round 9: a row's scenario edited by
    hand to another name was kept as that cell's result, under the other name, and its cell
    skipped).  Nothing is touched: the user fixes or removes the row, or gives a new path."""
    by_key = {c.key: c for c in cells}
    for r in rows:
        cell = by_key.get(r.get("cell"))
        if cell is None:
            continue  # a cell no longer in the grid: dropped at consolidation, as documented
        want = {"scenario": cell.scenario.name, "identifier": cell.identifier,
                "noise": cell.noise, "seed": cell.seed,
                "params": json.dumps(cell.params, sort_keys=True)}
        for col, value in want.items():
            if r.get(col) != value:
                raise InputError(f"results {results}: the row of cell {r['cell']} has {col} = "
                                 f"{show_value(r.get(col))}, where the study's cell has "
                                 f"{show_value(value)} (edited by hand?); correct or remove the "
                                 "row, or give a new path (the file is left as it is)")


def run_sweep(study: Study | str | os.PathLike, jobs: int = 1, dask_address: str | None = None,
              results: str | os.PathLike | None = None, cache_dir: str | os.PathLike | None = None,
              *, retry_failed: bool = False, verbose: bool = True,
              stats: SweepStats | None = None) -> Path:
    """Run every cell of ``study`` not yet in ``results``; return the results file.

    Parameters
    ----------
    study : Study or path
        A loaded study, or a study file / name to load.
    jobs : int
        Worker processes (joblib loky) when > 1; 1 runs in this process.
    dask_address : str, optional
        Scheduler address of a running ``dask.distributed`` cluster; the cells then
        run on its workers through joblib's dask backend (``jobs`` is ignored).
    results : path, optional
        Parquet results file (default ``out/studies/<study>.parquet``).  Rows already
        there (or in its ``.parts/`` folder from a killed run) are kept and their
        cells skipped.
    cache_dir : path, optional
        Dataset cache folder (default :func:`testbed.pipeline.cache.default_cache_dir`).
    retry_failed : bool
        Run the cells recorded as failed again.  (Cells whose row file is damaged run
        again anyway: the file is named in a warning and set aside as ``*.bad``.)
    verbose : bool
        One line on stderr about what is skipped and run.
    stats : SweepStats, optional
        Filled in with counts and phase wall times.

    Returns
    -------
    Path
        The consolidated results file: one row per cell of the study's grid (rows of
        cells no longer in the grid, e.g. after editing the study, are dropped).  Failed
        cells do not raise; see ``stats.failed_total``.  If the sweep itself is interrupted
        by an exception (e.g. a worker killed from outside), the rows that finished are
        consolidated before it propagates.

    Raises
    ------
    InputError
        If another sweep is writing ``results`` (:func:`results_lock`), or its rows are not
        this study's.
    """

    if not isinstance(study, Study):
        study = load_study(study)
    if jobs < 1:
        raise ValueError(f"jobs must be >= 1, got {jobs}")
    results = Path(results) if results is not None else default_results_path(study)
    not_regular(results)  # a device set aside as a damaged results file was renamed (round 13)
    with results_lock(results):
        return _run_locked(study, jobs, dask_address, results, cache_dir, retry_failed, verbose,
                           stats)


#: The lock file of results file ``R``: ``.<R's name>.lock`` beside it (:func:`results_lock`).
LOCK_SUFFIX = ".lock"


def lock_path(results: Path) -> Path:
    """The lock file :func:`results_lock` holds for ``results``."""
    return results.with_name(f".{results.name}{LOCK_SUFFIX}")


@contextlib.contextmanager
def results_lock(results: Path) -> Iterator[None]:
    """Hold an exclusive ``flock`` on :func:`lock_path` of ``results`` while one sweep writes it.

    Two sweeps on one results file at once lost rows in silence (round 13: a study of seeds
    0-5 and 12-19 and its edit to seeds 0-11 started 3 s later on one file ended with 8 rows,
    where the last sweep to finish had run 12 cells): each consolidation deletes every row
    file in ``<results>.parts/``, the other sweep's too, and drops the rows of cells not in
    its own grid.  A second sweep is therefore refused in one line naming the file and the
    process that holds it.  The lock goes with the sweep's process however it ends (SIGKILL
    included); the lock file is removed at the end while still locked, so a sweep that opened
    it meanwhile finds it gone once it holds it and opens the new one (only a killed sweep
    leaves it, unlocked).  A lock file another user made (0644: not writable here) is locked
    through a read-only descriptor (``flock`` needs none other): two users' sweeps on one shared
    file are the case the lock is for.  A folder where the lock file cannot be made is not
    locked (the results cannot be written there either: that write names the problem), nor a
    file system without ``flock`` (ENOLCK, EOPNOTSUPP); either way one warning says so.

    Raises
    ------
    InputError
        If another process holds the lock.
    """
    if fcntl is None:  # (no flock on this platform)
        yield
        return
    lock = lock_path(results)
    fd = -1

    def unlocked(what: str, e: OSError) -> None:
        log.warning("results %s: %s (%s); this sweep runs unlocked (do not start another on "
                    "the same file)", results, what, e.strerror or type(e).__name__)
    # each turn fails only if the holder removed the file between our open and our lock:
    # microseconds; a hundred in a row means something else is wrong (then unlocked)
    for _ in range(100):
        try:
            lock.parent.mkdir(parents=True, exist_ok=True)
            try:
                fd = os.open(lock, os.O_RDWR | os.O_CREAT, 0o666)
            except PermissionError:  # another user's lock file: flock needs no write access
                fd = os.open(lock, os.O_RDONLY)
        except OSError as e:
            unlocked("no lock file can be made", e)
            fd = -1
            break
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 64, 0).decode("ascii", "replace").strip() or "unknown"
            os.close(fd)
            raise InputError(f"results {results}: another sweep (process {holder}) is writing it; "
                             "wait for it to end or give another --results path (two sweeps "
                             "consolidating one file delete each other's rows)") from None
        except OSError as e:  # a file system without flock: unlocked, as before
            os.close(fd)
            unlocked("the file system refuses a lock", e)
            fd = -1
            break
        try:
            same = os.path.samestat(os.fstat(fd), os.stat(lock))
        except OSError:
            same = False
        if same:
            break
        os.close(fd)  # removed by the sweep that held it: lock the new file
        fd = -1
    if fd >= 0:
        with contextlib.suppress(OSError):
            os.ftruncate(fd, 0)
            os.pwrite(fd, str(os.getpid()).encode(), 0)
    try:
        yield
    finally:
        if fd >= 0:
            with contextlib.suppress(OSError):
                lock.unlink()
            os.close(fd)  # (releases the lock)


def _run_locked(study: Study, jobs: int, dask_address: str | None, results: Path,
                cache_dir: str | os.PathLike | None, retry_failed: bool, verbose: bool,
                stats: SweepStats | None) -> Path:
    """:func:`run_sweep` once it holds :func:`results_lock`."""
    cache = DatasetCache(cache_dir)
    cache_path = str(cache.directory.resolve())
    cells = expand(study)
    if parts_dir(results).is_dir():  # temporary files of a write that was killed
        for tmp in parts_dir(results).glob(".*.tmp"):
            tmp.unlink(missing_ok=True)
    try:
        previous, damaged = read_results(results, set_aside=True, resuming=True), None
    except ResultsError as e:  # a damaged consolidated file: keep it aside, rerun its cells
        previous, damaged = [], e
    if damaged is not None:
        # not Parquet at all (a dataset was renamed *.bad): not ours, refused, not set aside;
        # outside the handler, so the refusal is not chained to the ResultsError (review 28)
        refuse_foreign(results, PARQUET_FILE, f"results {results}",
                       f"a results file of study {study.name!r} or a new path")
        bad = results.with_name(results.name + ".bad")
        os.replace(results, bad)
        log.warning("%s; set aside as %s, its cells will run again", damaged, bad.name)
        previous = read_results(results, set_aside=True, resuming=True)
    others = sorted({str(r.get("study")) for r in previous if r.get("study") not in (None, "", study.name)})
    if others:  # consolidating would drop every row of the other study: refused, nothing touched
        raise InputError(f"results {results}: holds rows of study {', '.join(map(repr, others))}, "
                         f"not {study.name!r}; expected a results file of study {study.name!r} or "
                         "a new path (its rows would be dropped)")
    _check_rows_match_cells(previous, cells, results)
    provenance = sweep_provenance()  # one commit and set of versions for every row of this sweep
    # cells inside which processes kept ending (run_cell's inflight): recorded failed and not run
    # again by this invocation, whatever row they had (with --retry-failed a cell that aborts
    # had its "process ended" row and was run, and died, on every retry, the cells after it
    # never retried)
    ended: set[str] = set()
    for c in cells:
        marker = inflight_path(results, c.key)
        ends = _inflight_count(marker) if marker.exists() else 0
        if ends >= ENDS_BEFORE_FAILED and not any(r["cell"] == c.key and r["status"] == "ok"
                                                  for r in previous):
            row = ended_cell_row(c, ends, study.plugins, provenance)
            write_part(results, row)
            previous = [r for r in previous if r["cell"] != c.key] + [row]
            ended.add(c.key)
            marker.unlink(missing_ok=True)
    done = ended | {r["cell"] for r in previous if not (retry_failed and r["status"] == "failed")}
    todo = [c for c in cells if c.key not in done]
    skipped = study.skipped()
    _say(f"sweep {study.name}: {len(cells)} cells ({len(skipped) * len(study.noise) * len(study.seeds)} "
         f"skipped: identifier kind != rig kind), {len(cells) - len(todo)} already done, "
         f"{len(todo)} to run", verbose)

    stats = stats if stats is not None else SweepStats()
    stats.cells, stats.skipped_done, stats.run = len(cells), len(cells) - len(todo), len(todo)
    stats.failed = 0
    # Every dataset derives from its configuration's clean simulation, the one file the cache
    # holds for it (testbed.pipeline.cache): simulate each missing one once, in parallel, before the
    # cells, so that two workers never simulate the same configuration.
    missing: dict[Path, Scenario] = {}
    for c in todo:
        p = cache.path(c.scenario)
        if p not in missing and not p.is_file():
            missing[p] = noise_free_scenario(c.scenario)
    stats.datasets = len(missing)
    # One computation per shared_computation key: a cell whose key already has a finished row
    # (from an earlier run) or another cell to compute it is a copy of that row
    finished = {r["cell"]: r for r in previous if r["cell"] in done}
    # a source row must be what this sweep would compute: one that failed (perhaps for a
    # passing reason, a MemoryError) or that another commit or other versions computed is
    # not copied to cells it has not been run for
    same_code = {k: provenance[k] for k in ("commit", "versions")}
    sources = {k: r for k, r in finished.items() if r["status"] == "ok"
               and all(r.get(c) == v for c, v in same_code.items())}
    by_share: dict[str, list[Cell]] = {}
    for c in cells:
        by_share.setdefault(shared_computation(c), []).append(c)
    todo_keys = {c.key for c in todo}
    compute: list[Cell] = []
    copies: dict[str, list[Cell]] = {}  # source cell key -> the cells that copy its row
    for members in by_share.values():
        pending = [c for c in members if c.key in todo_keys]
        if not pending:
            continue
        source = next((c for c in members if c.key in sources), None)
        if source is None:
            source, pending = pending[0], pending[1:]
            compute.append(source)
        if pending:
            copies[source.key] = pending
    n_copies = stats.copied = sum(map(len, copies.values()))
    if n_copies:
        _say(f"{n_copies} of them repeat another cell's computation (0 % noise: the seed draws "
             "nothing) and copy its row", verbose)
    # Longest-processing-time-first: dispatch the cells expected to take longest first, so that
    # no worker is left with a long cell at the end.  The order changes no row.
    compute = sorted(compute, key=_expected_cost, reverse=True)
    # workers of a local pool watch this process; Dask workers belong to their cluster
    parent = os.getpid() if not dask_address and jobs > 1 else None
    try:
        with _backend(jobs, dask_address) as n_jobs:
            t0 = time.perf_counter()
            if missing:
                bar = _Progress("datasets", len(missing))
                try:
                    for _, _, err in parallel(ensure_dataset, [(s, cache_path, study.plugins, parent)
                                                               for s in missing.values()], n_jobs):
                        bar.advance(bool(err))
                finally:
                    bar.close()
            t1 = time.perf_counter()
            bar = _Progress(f"{study.name}", len(todo))

            def record(rows: Iterable[dict[str, Any]]) -> None:
                for row in rows:
                    write_part(results, row)
                    finished[row["cell"]] = row
                    stats.failed += row["status"] != "ok"
                    bar.advance(row["status"] != "ok")

            try:
                # in this process, each cell marked while it runs (run_cell's ``inflight``)
                marked = n_jobs == 1 and not dask_address

                def mark(c: Cell) -> Path | None:
                    return inflight_path(results, c.key) if marked else None

                record(parallel(run_cell, [(c, cache_path, study.plugins, parent, provenance,
                                            None, mark(c)) for c in compute], n_jobs))
                # the copies load their own datasets (their dataset_hash), nothing else; the
                # cells of a source that failed are computed after all
                second = [(c, cache_path, study.plugins, parent, provenance,
                           finished[src] if finished[src]["status"] == "ok" else None, mark(c))
                          for src, cs in copies.items() for c in cs]
                stats.copied = sum(a[5] is not None for a in second)  # (same_as)
                record(parallel(run_cell, second, n_jobs))
            except Exception as e:  # (loky's TerminatedWorkerError, not imported for this)
                if type(e).__name__ != "TerminatedWorkerError" or not study.plugins:
                    raise  # the testbed's own code crashed a worker: a bug
                # a plugin's os._exit or crash (a segmentation fault) killed a worker: an
                # internal error "please report it" before, naming no plugin
                codes = re.search(r"exit codes of the workers are (\{[^}]*\})", str(e))
                raise IdentificationError(
                    f"sweep {study.name}: a worker process died running cells (exit codes "
                    f"{codes.group(1) if codes else 'unknown'}): code of plugin(s) "
                    f"{', '.join(study.plugins)} may exit the interpreter (os._exit) or crash "
                    f"it; the finished rows are kept in {results}; `--jobs 1` runs the cells "
                    "in this process, one at a time") from None
            finally:
                bar.close()
            stats.data_seconds, stats.cells_seconds = t1 - t0, time.perf_counter() - t1
    except Exception:
        # keep what finished in the results file (atomically), then report the interruption
        with contextlib.suppress(Exception):
            consolidate(results, keep={c.key for c in cells}, study=study.name)
        raise
    _, dropped = consolidate(results, keep={c.key for c in cells}, study=study.name)
    if dropped:
        _say(f"dropped {dropped} row(s) of cells no longer in study {study.name}", verbose)
    final = read_results(results)
    stats.failed_total = sum(r["status"] != "ok" for r in final)
    for line in (failed_cells_line(final), missed_bars_line(final)):
        if line:
            _say(line, verbose)
    return results
