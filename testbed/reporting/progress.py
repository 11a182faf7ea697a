"""One progress bar for long work (rich), usable as ``with progress_bar(label) as bar: bar(0.5)``."""

from __future__ import annotations

import contextlib
import sys
from collections.abc import Callable, Iterator


@contextlib.contextmanager
def progress_bar(label: str) -> Iterator[Callable[[float], None]]:
    """Yield ``update(fraction)``; draws only on a terminal, silent otherwise (CI, pipes)."""
    if not sys.stderr.isatty():
        yield lambda fraction: None
        return
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

    with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.percentage:>3.0f}%"),
                  TimeElapsedColumn(), transient=True) as prog:
        task = prog.add_task(label, total=1.0)
        yield lambda fraction: prog.update(task, completed=min(max(fraction, 0.0), 1.0))
