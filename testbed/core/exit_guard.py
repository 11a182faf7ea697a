"""A user's code calling ``os._exit`` inside the testbed's process: an exception, not the end.

``os._exit(0)`` in a plugin's ``fit`` (or at its import) ended ``testbed run`` and a sequential
sweep with status 0, no verdict and no line (hostile round 19's open item): no Python code runs
after it, so nothing can record the cell.  While :func:`no_process_exit` is entered, a call of
``os._exit`` (or ``posix._exit``) made

- by any thread of this process while a guard is entered (the user's code's own threads, a
  thread pool it keeps across fits included: a thread that ran before the guard was entered was
  left alone until the review of session 21, which a pool started in the first fit bypassed),
- in this process (a child it forked, e.g. by ``multiprocessing``, exits as it means to; a
  child forked inside a guard starts with no guard of its own), and
- from code outside the ``testbed`` package (the testbed's own ``os._exit``: a signal's exit, a
  forked drawer's end, the sweep worker's parent watchdog, is its own)

raises :class:`ProcessExitCalled` instead: the fit failed, naming the call, and the run or the
cell is scored as a failure.  Made in a thread that entered no guard, the call ends that thread
(silently, as ``sys.exit`` there does) and every guard entered at that moment raises it when
it ends (which cell's thread started it is not known: each such cell fails, none passes).  Not
covered, and cannot be from inside the process: ``os.abort``, a signal the code sends itself, a
crash in compiled code (their status is not 0; a sweep names the cell).

A thread started inside a guard and still running when its guard ends (a plugin's thread or
pool worker left behind) keeps the interception in place while it lives: its ``os._exit`` made
after every guard has ended ends that thread alone (a plain SystemExit) and is kept for
:func:`late_exit_calls` (the command line says it in one warning line after its verdict).
Hostile round 21: such a call 0.3-1.5 s after the fit ended ``testbed run`` with status 0 (or
the thread's code) and no verdict, and a sequential sweep with status 0 and no results file.
Every other thread's ``os._exit`` outside a guard (an API user's own watchdog) ends the
process as it means to.
"""

from __future__ import annotations

import contextlib
import os
import sys
import threading
import weakref
from collections.abc import Iterator

_LOCK = threading.Lock()
#: Threads (by ident) inside :func:`no_process_exit`, with their depth.
_GUARDED: dict[int, int] = {}
#: The pid the first guard was entered in.
_PID: list[int] = []
#: ``os._exit`` as it was before the first guard was entered (restored when the last leaves).
_REAL: list = []
#: Per guarded thread (by ident), the code of a call intercepted in a thread that entered no
#: guard while it was inside one, not raised yet.
_PENDING: dict[int, object] = {}
#: Threads started inside a guard and alive when it ended (a plugin's thread left running):
#: while one lives, ``os._exit`` stays intercepted after the last guard has ended.
_LEFTOVER: weakref.WeakSet = weakref.WeakSet()
#: ``(thread name, code)`` of each ``os._exit`` a left-over thread made outside every guard
#: (that thread was ended instead), until :func:`late_exit_calls` takes them.
_LATE: list[tuple[str, object]] = []
#: Threads alive when the interception was put in place (the caller's own: their ``os._exit``
#: outside every guard ends the process).  A thread started later that calls it while no guard
#: is entered and the interception lingers for a left-over thread was started by a guarded
#: block's code or by a left-over thread (a pool's worker started lazily: session 22's review),
#: and ends itself as a left-over thread does.
_BEFORE: weakref.WeakSet = weakref.WeakSet()


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
    if own or not _PID or os.getpid() != _PID[0]:
        real(code)  # type: ignore[arg-type]
    if me in _GUARDED:
        raise ProcessExitCalled(code)
    with _LOCK:
        guarded = bool(_GUARDED)
        for ident in _GUARDED:  # every guard entered now raises it when it ends; this
            _PENDING.setdefault(ident, code)  # thread ends by a plain SystemExit, which
            # threading's hook passes over in silence (a subclass's traceback it prints)
        this = threading.current_thread()
        late = not guarded and (this in _LEFTOVER or (this not in _BEFORE
                                                      and this is not threading.main_thread()))
        if late:  # after every guard ended: a thread a guarded block left running
            _LATE.append((this.name, code))
    if guarded or late:
        raise SystemExit(code)
    real(code)  # type: ignore[arg-type]  # a thread of the caller's own (not left by a guard)


def late_exit_calls() -> list[tuple[str, object]]:
    """Take the ``os._exit`` calls that threads left running by a guarded block made after
    every guard had ended (each ended its thread instead of the process).

    Returns
    -------
    list of (str, object)
        ``(thread name, exit code)`` in the order made; the record is emptied.
    """
    with _LOCK:
        out, _LATE[:] = list(_LATE), []
    return out


def _restore() -> None:
    """Put the real ``os._exit`` back and forget the guards' state (under the lock)."""
    if _REAL:
        os._exit = _REAL[0]
        posix = _posix()
        if posix is not None:
            posix._exit = _REAL[0]  # type: ignore[attr-defined]
    _REAL.clear()
    _PID.clear()
    _PENDING.clear()
    _BEFORE.clear()


def _forget_parents_guards() -> None:
    """In a child forked inside a guard: the parent's guarded threads do not exist here; put
    ``os._exit`` back and start with no guard (called under the lock)."""
    if _PID and _PID[0] != os.getpid():
        _restore()
        _GUARDED.clear()
        _LEFTOVER.clear()
        _LATE.clear()


@contextlib.contextmanager
def no_process_exit() -> Iterator[None]:
    """Within: a user's ``os._exit`` raises :class:`ProcessExitCalled` (see the module's text).
    Re-entrant and thread-safe: ``os._exit`` is put back when the last thread inside leaves."""
    me = threading.get_ident()
    posix = _posix()
    with _LOCK:
        _forget_parents_guards()
        if not _GUARDED:
            if not _REAL:  # else still intercepted for a left-over thread: _REAL is the real one
                _REAL[:] = [os._exit]
                _PID[:] = [os.getpid()]
                _BEFORE.clear()
                _BEFORE.update(threading.enumerate())
            _PENDING.clear()
            os._exit = _guarded_exit
            if posix is not None:
                posix._exit = _guarded_exit  # type: ignore[attr-defined]
        outermost = me not in _GUARDED
        _GUARDED[me] = _GUARDED.get(me, 0) + 1
    before = set(threading.enumerate()) if outermost else set()
    raised = False
    try:
        yield
    except BaseException:
        raised = True  # the block's own exception goes on; a pending exit is not raised over it
        raise
    finally:
        left = ({t for t in threading.enumerate() if t not in before and t.is_alive()}
                if outermost else set())
        with _LOCK:
            _GUARDED[me] -= 1
            pending = None
            if not _GUARDED[me]:
                del _GUARDED[me]
                pending = _PENDING.pop(me, None)
            _LEFTOVER.update(t for t in left if t.ident not in _GUARDED)
            if not _GUARDED:
                _PENDING.clear()
                if not any(t.is_alive() for t in _LEFTOVER):
                    _LEFTOVER.clear()
                    _restore()
    if pending is not None and not raised:
        raise ProcessExitCalled(pending)
