"""Run figures drawn in a separate process that imports matplotlib while the run computes.

``testbed run`` spends about a second importing matplotlib and drawing six figures after the
fit (``benchmarks/bench_cli.py``), all of it after the fit.  :func:`figure_drawer` forks a
drawing process when the command starts: it imports matplotlib and draws one small figure (font
files, PNG encoder) while the parent loads its data and fits, then waits for a run folder.  A
run folder sent to it is drawn by it and by one more process forked from it at that moment
(matplotlib already imported), each drawing about half of the figures; the parent writes the
report from the PNGs.  While the parent fits, the drawing process also makes the figures'
frames (figure, axes, ticks: :mod:`testbed.reporting.frames`), about a third of their CPU, with
the shapes of the scenario's previous run when there is one (:meth:`RunFigures.prepare`).
The figures are the same as drawn in-process (:func:`testbed.reporting.figures.save_run_figures`):
the same builders on the same files.

Life cycle:

- the drawing processes ignore Ctrl-C (the parent handles it and ends them) and are killed by
  the kernel when their parent dies (``PR_SET_PDEATHSIG``), also when it is killed with
  ``SIGKILL``; they also end when the pipe to the parent closes;
- an exception while drawing is sent to the parent and raised there, as it would have been
  in-process (same type where it pickles; the drawing process's traceback as a note);
- a drawing process that dies is an error raised in the parent (its exit code named);
- where ``fork`` is not available (not Linux) the figures are drawn in-process.
"""

from __future__ import annotations

import contextlib
import gc
import math
import multiprocessing
import os
import pickle
import signal
import sys
import traceback
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from testbed.reporting import figures as figs
from testbed.reporting.report import save_run_figures_and_report
from testbed.studies.runstore import load_run, resolve_run, scenario_folder

__all__ = ["FigureWorker", "FigureWorkerError", "RunFigures", "figure_drawer", "prepare_frames",
           "split_figures"]

#: Relative drawing cost of each run figure, as drawn on a frame made ahead (CPU of the
#: cantilever run's figures, served, 7 runs at load 10: matrices 0.48 s, spectra 0.41,
#: reconstruction 0.36, penalty weights 0.17, mac 0.14, frequencies 0.11; in units of 0.12 s);
#: a stem not listed counts 1.
FIGURE_COST = {"matrices": 4.0, "spectra": 3.4, "reconstruction": 3.0, "joint_angles": 3.0,
               "penalty_weights": 1.4, "mac": 1.2, "frequencies": 0.9, "coefficients": 1.0}
#: Most figures split exactly (every split tried); more are split longest first.
EXACT_SPLIT = 12
#: Seconds the parent waits for a drawing process to end after asking it to stop.
STOP_TIMEOUT_S = 5.0
_PR_SET_PDEATHSIG = 1


class FigureWorkerError(RuntimeError):
    """A drawing process died or could not draw (its own exceptions are re-raised as they are)."""


def split_figures(stems: Sequence[str], parts: int = 2) -> list[list[str]]:
    """Stems split into ``parts`` groups of about equal drawing cost (:data:`FIGURE_COST`).

    Two groups of at most :data:`EXACT_SPLIT` stems: the split whose costlier group costs
    least (ties: the first found, stems in report order); else longest first onto the least
    loaded group (ties: the earlier group, the earlier stem).  The split is the same on every
    machine.  Empty groups are dropped; each group keeps the report order.
    """
    cost = [FIGURE_COST.get(s, 1.0) for s in stems]
    if parts == 2 and 0 < len(stems) <= EXACT_SPLIT:
        best, pick = math.inf, 0
        for mask in range(1 << (len(stems) - 1)):  # the last stem stays in the first group
            second = sum(c for i, c in enumerate(cost) if mask >> i & 1)
            worst = max(sum(cost) - second, second)
            if worst < best - 1e-9:
                best, pick = worst, mask
        groups = [[s for i, s in enumerate(stems) if not pick >> i & 1],
                  [s for i, s in enumerate(stems) if pick >> i & 1]]
        return [g for g in groups if g]
    load = [0.0] * parts
    groups = [[] for _ in range(parts)]
    for s in sorted(stems, key=lambda s: -FIGURE_COST.get(s, 1.0)):  # stable: report order in ties
        g = min(range(parts), key=lambda k: (load[k], k))
        groups[g].append(s)
        load[g] += FIGURE_COST.get(s, 1.0)
    return [g for g in groups if g]


def _die_with_parent(parent: int) -> None:
    """Be killed when ``parent`` dies (Linux ``prctl``); exit now if it already has."""
    if sys.platform.startswith("linux"):
        with contextlib.suppress(Exception):
            import ctypes

            ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL))
    if os.getppid() != parent:  # died between the fork and the prctl
        os._exit(0)


def _warm_up() -> None:
    """Import what drawing needs and draw one small figure (fonts, text layout, PNG encoder)."""
    fig = figs._fig(1.0, 2.0)
    ax = figs._axes(fig)[0, 0]
    ax.plot([0.0, 1.0], [0.0, 1.0])
    ax.set(title="warm-up", xlabel="x [-]")
    # into memory: saved to os.devnull through the atomic write, the PNG replaced /dev/null
    # itself with a regular file when run as root (round 13)
    figs.png_bytes(fig)


def prepare_frames(folder: str | os.PathLike) -> int:
    """Make the frames of the figures of the run saved in ``folder`` (a run folder, or a
    scenario's folder of runs: its latest run), so that a run of the same shape takes them
    (:func:`testbed.reporting.figures.prepare_run_frames`); the number made.

    Never fails: a folder that is missing, damaged or of another layout makes none.
    """
    try:
        return figs.prepare_run_frames(load_run(resolve_run(Path(folder))))
    except Exception:
        return 0


def _draw(run: Any, folder: str, stems: Sequence[str]) -> list[str]:
    """Draw ``stems`` of ``run`` (read from ``folder``) into ``folder``; the PNG paths written."""
    drawn = figs.run_figures(run, only=stems)
    return [str(figs.save_figure(f, Path(folder) / f"{stem}.png")) for stem, f in drawn.items()]


def _error(e: BaseException) -> tuple[str, bytes | None, str, str]:
    """An exception as it crosses the pipe: (``"error"``, pickled or None, one line, traceback)."""
    try:
        blob: bytes | None = pickle.dumps(e)
        pickle.loads(blob)
    except Exception:
        blob = None
    return ("error", blob, f"{type(e).__name__}: {e}", traceback.format_exc())


def _raise(msg: tuple) -> None:
    """Raise the exception a drawing process sent (as it was, where it pickled)."""
    _, blob, line, tb = msg
    e = pickle.loads(blob) if blob is not None else FigureWorkerError(f"drawing failed: {line}")
    e.add_note(f"raised in the figure-drawing process:\n{tb.rstrip()}")
    raise e


def _draw_split(folder: str) -> list[str]:
    """Draw every figure of the run in ``folder``: a forked helper draws half of them."""
    run = load_run(Path(folder))  # read once: the forked helper inherits it
    groups = split_figures(figs.run_figures_available(run))
    if len(groups) < 2:
        return _draw(run, folder, groups[0] if groups else [])
    recv, send = multiprocessing.Pipe(duplex=False)
    me = os.getpid()
    gc.freeze()  # see FigureWorker: no copy on write of the shared objects by the collector
    pid = os.fork()
    if pid == 0:  # the helper: draw the second group, report, exit (never return)
        code = 1
        try:
            recv.close()
            _die_with_parent(me)
            try:
                send.send(("ok", _draw(run, folder, groups[1])))
            except BaseException as e:
                send.send(_error(e))
            code = 0
        finally:
            os._exit(code)
    send.close()
    try:
        mine = _draw(run, folder, groups[0])
    finally:
        try:
            theirs = recv.recv()
        except EOFError:
            theirs = None
        recv.close()
        _, status = os.waitpid(pid, 0)
    if theirs is None:
        raise FigureWorkerError(f"the second drawing process died (wait status {status})")
    if theirs[0] == "error":
        _raise(theirs)
    return mine + theirs[1]


def _serve(conn: Any, parent_end: Any, parent: int) -> None:
    """The drawing process: warm up, then draw each run folder sent until ``None`` or EOF."""
    parent_end.close()
    _die_with_parent(parent)
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    try:
        _warm_up()
        broken = None
    except BaseException as e:  # reported with the first run sent, where the parent waits
        broken = _error(e)
    while True:
        try:
            folder = conn.recv()
        except (EOFError, OSError):
            return
        if folder is None:
            return
        if isinstance(folder, tuple):  # ("prepare", previous run folder): no answer
            if broken is None:
                prepare_frames(folder[1])
            continue
        if broken is not None:
            conn.send(broken)
            continue
        try:
            conn.send(("ok", _draw_split(folder)))
        except BaseException as e:
            conn.send(_error(e))


class FigureWorker:
    """A forked drawing process serving :meth:`draw` (see the module docstring).

    Use as a context manager (:func:`figure_drawer`): leaving it stops the process, and ends
    it at once when leaving on an exception (Ctrl-C included).
    """

    def __init__(self) -> None:
        ctx = multiprocessing.get_context("fork")
        self._conn, child = ctx.Pipe()
        self._proc = ctx.Process(target=_serve, args=(child, self._conn, os.getpid()),
                                 name="testbed-figures", daemon=True)
        # the objects made so far go to the collector's permanent generation, in this process
        # and so in the forked one: neither one's collections then write to (and so copy) the
        # memory pages the two still share.  Measured: 0.3-0.5 s less CPU of the whole
        # `testbed run cantilever_stiff_impact` in 2 of 3 interleaved pairs (2 cores, load 20);
        # what is frozen lives to the end of the process, as the modules it is mostly made of.
        gc.freeze()
        self._proc.start()
        child.close()

    def draw(self, run: Any, folder: Path) -> list[Path]:
        """Draw the figures of the run saved in ``folder`` there; their paths in report order.

        ``run`` is the :class:`~testbed.studies.runstore.SavedRun` read from ``folder`` (the
        drawing process reads the folder itself).

        Raises
        ------
        Exception
            What drawing raised (re-raised here); :class:`FigureWorkerError` if a drawing
            process died.
        """
        try:
            self._conn.send(str(folder))
            msg = self._conn.recv()
        except (EOFError, OSError, BrokenPipeError):
            self._proc.join(STOP_TIMEOUT_S)
            raise FigureWorkerError(f"the figure-drawing process died (exit code "
                                    f"{self._proc.exitcode})") from None
        if msg[0] == "error":
            _raise(msg)
        written = {Path(p).stem: Path(p) for p in msg[1]}
        return [written[s] for s in figs.run_figures_available(run) if s in written]

    def prepare(self, folder: Path) -> None:
        """Have the drawing process make the frames of the figures of the run saved in
        ``folder`` (:func:`prepare_frames`) while this process goes on (no answer awaited)."""
        with contextlib.suppress(OSError, ValueError):  # a dead process is found by draw()
            self._conn.send(("prepare", str(folder)))

    def close(self, *, kill: bool = False) -> None:
        """Stop the drawing process (``kill``: at once) and reap it."""
        if self._proc.is_alive() and not kill:
            with contextlib.suppress(OSError, ValueError):
                self._conn.send(None)
            self._proc.join(STOP_TIMEOUT_S)
        if self._proc.is_alive():
            self._proc.kill()
            self._proc.join()
        self._conn.close()


def fork_available() -> bool:
    """Whether figures can be drawn in a forked process here (Linux: ``fork`` is safe)."""
    return sys.platform.startswith("linux") and "fork" in multiprocessing.get_all_start_methods()


class RunFigures:
    """The figure writer of ``testbed run`` (:func:`figure_drawer`): ``figures(run, folder)``
    writes the figures and report of a saved run; ``figures.prepare(out, scenario)`` has the
    drawing process make the frames of the scenario's latest run in ``out`` ahead of its next.

    Parameters
    ----------
    worker : FigureWorker or None
        Where the figures are drawn; None: in this process, without frames made ahead.
    """

    def __init__(self, worker: FigureWorker | None = None) -> None:
        self.worker = worker

    def __call__(self, run: Any, folder: Path) -> list[Path]:
        draw = self.worker.draw if self.worker is not None else None
        return save_run_figures_and_report(run, folder, draw=draw)

    def prepare(self, out_dir: str | os.PathLike, scenario: str) -> None:
        """Before a run of ``scenario`` into ``out_dir``: the drawing process makes the frames
        of the figures of the scenario's latest run there, if any (never fails)."""
        if self.worker is None:
            return
        try:  # the drawing process finds the latest run (none: no frames are made ahead)
            folder = scenario_folder(out_dir, scenario)
        except Exception:
            return
        if folder.is_dir():
            self.worker.prepare(folder)


@contextlib.contextmanager
def figure_drawer(enabled: bool = True) -> Iterator[RunFigures | None]:
    """The figure writer of ``testbed run``: a :class:`RunFigures` to pass as ``figures`` to
    :func:`testbed.studies.runstore.save_new_run`, drawing in a :class:`FigureWorker`.

    Yields None when not ``enabled`` (``--no-figures``), one drawing in this process where
    ``fork`` is not available.  Start it before the work whose time it should overlap.
    """
    if not enabled:
        yield None
        return
    if not fork_available():
        yield RunFigures()
        return
    worker = FigureWorker()
    ok = False
    try:
        yield RunFigures(worker)
        ok = True
    finally:
        worker.close(kill=not ok)
