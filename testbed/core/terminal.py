"""Tables drawn on a terminal: a rich Console that draws at any reported width."""

from __future__ import annotations

from typing import Any

#: Narrowest terminal a table is drawn for [columns]; a narrower reported width is taken for
#: rich's own default (80).  A terminal reporting 0 columns (``COLUMNS=0``, a pseudo-terminal
#: never given a size) made rich draw nothing: `testbed run` printed its run folder without
#: its score table or verdict.  No real terminal is narrower than the verdict line.
MIN_CONSOLE_WIDTH = 20


def make_console(**kwargs: Any) -> Any:
    """A ``rich.console.Console`` for tables (``kwargs`` as rich's), at least
    :data:`MIN_CONSOLE_WIDTH` columns wide.  rich is imported here, on first use."""
    from rich.console import Console

    console = Console(**kwargs)
    if console.width < MIN_CONSOLE_WIDTH:
        console = Console(**{**kwargs, "width": 80})
    return console
