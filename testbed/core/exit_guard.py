"""A user's code calling ``os._exit`` inside the testbed's process: an exception, not the end.

``os._exit(0)`` in a plugin's ``fit`` (or at its import) ended ``testbed run`` and a sequential
sweep with status 0, no verdict and no line (hostile round 19's open item): no Python code runs
after it, so nothing can record the cell.  While :func:`no_process_exit` is entered, a call of
``os._exit`` (or ``posix._exit``) made

- by the thread that entered it, or by a thread started while a guard was entered (the user's
  code's own threads; a thread that ran before, e.g. a sweep worker's parent watchdog, is left
  alone),
- in this process (a child it forked, e.g. by ``multiprocessing``, exits as it means to), and
- from code outside the ``testbed`` package (the testbed's own ``os._exit``: a signal's exit, a
  forked drawer's end, is its own)

raises :class:`ProcessExitCalled` instead: the fit failed, naming the call, and the run or the
cell is scored as a failure.  Made in another thread, the call ends that thread (silently, as
``sys.exit`` there does) and the guarded block raises it when it ends.  Not covered, and cannot
be from inside the process: ``os.abort``, a signal the code sends itself, a crash in compiled
code (their status is not 0; a sweep with ``--jobs`` > 1 names the plugin: its worker died).
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
from collections.abc import Iterator

_LOCK = threading.Lock()
#: Threads (by ident) inside :func:`no_process_exit`, with their depth.
_GUARDED: dict[int, int] = {}
#: The pid the first guard was entered in, and the threads (by ident) running then.
_PID: list[int] = []
_BEFORE: set[int] = set()
#: ``os._exit`` as it was before the first guard was entered (restored when the last leaves).
_REAL: list = []
#: Codes of calls intercepted in threads other than a guarded one, not raised yet.
_PENDING: list = []


class ProcessExitCalled(SystemExit):
    """``os._exit(code)`` was called by a user's code inside :func:`no_process_exit`.

    A SystemExit: code catching ``Exception`` does not swallow it, and a thread it ends ends
    without a traceback."""

    def __init__(self, code: object) -> None:
        super().__init__(f"os._exit({code!r}) called, which would have ended the testbed's "
                         "process with no verdict; raise an exception instead")
        self.exit_code = code


def _posix() -> object | None:
    return sys.modules.get("posix") or sys.modules.get("nt")


def _guarded_exit(code: object = 0) -> None:
    real = _REAL[0] if _REAL else os._exit
    caller = sys._getframe(1).f_globals.get("__name__", "") or ""
    own = caller == "testbed" or caller.startswith("testbed.")
    me = threading.get_ident()
    ours = me in _GUARDED or me not in _BEFORE
    if own or not _PID or os.getpid() != _PID[0] or not ours:
        real(code)  # type: ignore[arg-type]
    if me not in _GUARDED:  # the guarded block raises it when it ends; this thread ends by
        with _LOCK:  # a plain SystemExit, which threading's hook passes over in silence (a
            _PENDING.append(code)  # subclass's traceback it prints)
        raise SystemExit(code)
    raise ProcessExitCalled(code)


@contextlib.contextmanager
def no_process_exit() -> Iterator[None]:
    """Within: a user's ``os._exit`` raises :class:`ProcessExitCalled` (see the module's text).
    Re-entrant and thread-safe: ``os._exit`` is put back when the last thread inside leaves."""
    me = threading.get_ident()
    posix = _posix()
    with _LOCK:
        if not _GUARDED:
            _REAL[:] = [os._exit]
            _PID[:] = [os.getpid()]
            _BEFORE.clear()
            _BEFORE.update(t.ident for t in threading.enumerate() if t.ident is not None)
            _PENDING.clear()
            os._exit = _guarded_exit
            if posix is not None:
                posix._exit = _guarded_exit  # type: ignore[attr-defined]
        _GUARDED[me] = _GUARDED.get(me, 0) + 1
    try:
        yield
    finally:
        with _LOCK:
            _GUARDED[me] -= 1
            if not _GUARDED[me]:
                del _GUARDED[me]
            pending = _PENDING[:1] if _GUARDED.get(me) is None else []
            del _PENDING[:len(pending)]
            if not _GUARDED:
                os._exit = _REAL[0]
                if posix is not None:
                    posix._exit = _REAL[0]  # type: ignore[attr-defined]
                _REAL.clear()
                _PID.clear()
                _BEFORE.clear()
    if pending and sys.exc_info()[0] is None:
        raise ProcessExitCalled(pending[0])
