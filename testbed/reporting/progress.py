"""The one progress seam (rich): a bar for one piece of work, or the phases of a scenario run.

``with progress_bar(label) as bar: bar(0.5)`` draws one bar.  ``with run_progress(label) as
phase:`` gives the phases of a run, each ``with phase("fit") as update: update(0.3, "step")``:
a row per phase with a bar where the work reports its fraction done (the simulation does), a
spinner and the elapsed time where it does not (signal chain, scoring, figures; a fit unless
its identifier reports its steps through :meth:`identify.Identifier.report_progress`), and
the current step's name when one is given.  Finished phases stay on their row with their time
until the run is done; then the display is erased, so only the caller's own output remains.

Nothing is drawn when standard output is not a terminal (a pipe, a file, CI): the commands'
output there is exactly their tables and lines.  The display goes to standard output, so a
terminal user sees it where the tables appear.
"""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Callable, Iterator
from typing import Any

#: ``update(fraction=None, step=None)``: fraction done in [0, 1] (None: unknown), step name.
Update = Callable[..., None]


def _enabled(console: Any) -> bool:
    return console is not None or sys.stdout.isatty()


def _progress(console: Any, transient: bool = True) -> Any:
    from rich.progress import (
        BarColumn,
        Progress,
        SpinnerColumn,
        TaskProgressColumn,
        TextColumn,
        TimeElapsedColumn,
    )

    return Progress(SpinnerColumn(finished_text="✓"), TextColumn("{task.description}"), BarColumn(),
                    TaskProgressColumn(), TimeElapsedColumn(), TextColumn("{task.fields[step]}"),
                    console=console, transient=transient)


@contextlib.contextmanager
def progress_bar(label: str, console: Any = None) -> Iterator[Callable[[float], None]]:
    """Yield ``update(fraction)`` for one bar; draws only on a terminal, silent otherwise.

    Parameters
    ----------
    label : str
    console : rich.console.Console, optional
        Draw there (tests); default: standard output when it is a terminal, else nothing.
    """
    if not _enabled(console):
        yield lambda fraction: None
        return
    with _progress(console) as prog:
        task = prog.add_task(label, total=1.0, step="")
        yield lambda fraction: prog.update(task, completed=min(max(fraction, 0.0), 1.0))


class _Phases:
    """``phase(name)`` context managers on one live display (see the module docstring)."""

    def __init__(self, label: str, prog: Any) -> None:
        self.label, self.prog = label, prog

    @contextlib.contextmanager
    def __call__(self, name: str) -> Iterator[Update]:
        prog = self.prog
        task = prog.add_task(f"{self.label}: {name}", total=None, step="")

        def update(fraction: float | None = None, step: str | None = None) -> None:
            kw: dict[str, Any] = {}
            if fraction is not None and fraction == fraction:  # NaN: leave the bar as it is
                kw.update(total=1.0, completed=min(max(float(fraction), 0.0), 1.0))
            if step is not None:
                kw["step"] = str(step)
            prog.update(task, **kw)

        try:
            yield update
        finally:
            prog.update(task, total=1.0, completed=1.0, step="")
            prog.stop_task(task)


@contextlib.contextmanager
def _no_phase(name: str) -> Iterator[Update]:
    yield lambda fraction=None, step=None: None


@contextlib.contextmanager
def run_progress(label: str, console: Any = None) -> Iterator[Callable[[str], Any]]:
    """Yield ``phase(name)``, a context manager per phase yielding ``update(fraction, step)``.

    Parameters
    ----------
    label : str
        Prefix of every row (the scenario's name).
    console : rich.console.Console, optional
        Draw there (tests); default: standard output when it is a terminal, else nothing.

    Examples
    --------
    >>> with run_progress("demo") as phase:
    ...     with phase("fit") as update:
    ...         update(0.5, "epoch 50/100")
    """
    if not _enabled(console):
        yield _no_phase
        return
    with _progress(console) as prog:
        yield _Phases(label, prog)
