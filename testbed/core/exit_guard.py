"""A user's code calling ``os._exit`` inside the testbed's process: an exception, not the end.

``os._exit(0)`` in a plugin's ``fit`` (or at its import) ended ``testbed run`` and a sequential
sweep with status 0, no verdict and no line (hostile round 19's open item): no Python code runs
after it, so nothing can record the cell.  While :func:`no_process_exit` is entered, a call of
``os._exit`` made

- by the thread that entered it (another thread's, e.g. a sweep worker's parent watchdog, is
  left alone),
- in this process (a child it forked, e.g. by ``multiprocessing``, exits as it means to), and
- from code outside the ``testbed`` package (the testbed's own ``os._exit``: a signal's exit, a
  forked drawer's end, is its own)

raises :class:`ProcessExitCalled` instead: the fit failed, naming the call, and the run or the
cell is scored as a failure.  Not covered, and cannot be from inside the process: ``posix._exit``
called directly, ``os.abort``, a signal the code sends itself, a crash in compiled code (a sweep
with ``--jobs`` > 1 names the plugin for those: its worker died).
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
from collections.abc import Iterator

_LOCK = threading.Lock()
#: Threads (by ident) inside :func:`no_process_exit`, with their depth, and the pid they were in.
_GUARDED: dict[int, int] = {}
_PID: list[int] = []
#: ``os._exit`` as it was before the first guard was entered (restored when the last leaves).
_REAL: list = []


class ProcessExitCalled(BaseException):
    """``os._exit(code)`` was called by a user's code inside :func:`no_process_exit`.

    A BaseException (as SystemExit): code catching ``Exception`` does not swallow it."""

    def __init__(self, code: object) -> None:
        super().__init__(f"os._exit({code!r}) called, which would have ended the testbed's "
                         "process with no verdict; raise an exception instead")
        self.code = code


def _guarded_exit(code: object = 0) -> None:
    real = _REAL[0] if _REAL else os._exit
    caller = sys._getframe(1).f_globals.get("__name__", "") or ""
    own = caller == "testbed" or caller.startswith("testbed.")
    if own or (_PID and os.getpid() != _PID[0]) or threading.get_ident() not in _GUARDED:
        real(code)  # type: ignore[arg-type]
    raise ProcessExitCalled(code)


@contextlib.contextmanager
def no_process_exit() -> Iterator[None]:
    """Within: this thread's ``os._exit`` from a user's code raises :class:`ProcessExitCalled`
    (see the module's text).  Re-entrant and thread-safe: ``os._exit`` is put back when the
    last thread inside leaves."""
    me = threading.get_ident()
    with _LOCK:
        if not _GUARDED:
            _REAL[:] = [os._exit]
            _PID[:] = [os.getpid()]
            os._exit = _guarded_exit
        _GUARDED[me] = _GUARDED.get(me, 0) + 1
    try:
        yield
    finally:
        with _LOCK:
            _GUARDED[me] -= 1
            if not _GUARDED[me]:
                del _GUARDED[me]
            if not _GUARDED:
                os._exit = _REAL[0]
                _REAL.clear()
                _PID.clear()
