"""Ctrl-C, SIGTERM and SIGHUP outside a command's own handling: while ``testbed`` starts and
while it exits.

:func:`testbed.cli.main` turns an interrupt into one line (``error: interrupted``, status 130;
SIGTERM and SIGHUP 128 + their number).  Before it runs, the console program imports
``testbed.cli`` and its modules (0.05 s idle, 0.1-0.2 s on a loaded machine), and after it
returns the interpreter shuts down; a Ctrl-C then printed Python's traceback (ending the
process by SIGINT) or "Exception ignored in: <module 'threading'> ... KeyboardInterrupt" (the
command ended with status 0).  This module makes those
signals end the console program at once with the same line and status (:func:`exit_at_once`,
the handler :func:`testbed.cli.main` replaces with its own while the command runs and puts back
after): nothing is written yet
(or everything is, at exit), so there is nothing to keep or clean up.  The package's
``__init__`` imports this module first, before its own imports and those of ``testbed.cli``.

Only the console program is so armed (``testbed``, ``python -m testbed.cli``): a Python
session importing the library keeps Python's own handling, and so does a signal the caller
set to be ignored (``nohup``, a shell's background job).  What comes before the first line of
the testbed's code (the interpreter's start and its ``site`` import, 0.02-0.1 s) is Python's
own and stays so.

The module imports nothing but ``os``, ``sys`` and ``_signal`` (loaded with the interpreter)
before it arms: each further import is a window for a traceback.  ``_signal`` is the C module
under ``signal``, whose own import (an enum conversion of every signal) was such a window.
"""

from __future__ import annotations

import _signal as signal  # not `signal`: see above
import os
import sys

#: Signals so handled, each with its exit status: a shell's for Ctrl-C (130), 128 + the
#: signal's number for the two that end a program (``kill``, a closed terminal).
STATUS = {signal.SIGINT: 130, signal.SIGTERM: 128 + signal.SIGTERM, signal.SIGHUP: 128 + signal.SIGHUP}

NAMES = {signal.SIGINT: "SIGINT", signal.SIGTERM: "SIGTERM", signal.SIGHUP: "SIGHUP"}

#: True once :func:`arm` armed this process (the console program).
armed = False


#: The interpreter's long options that take the next word as their value
_VALUED_LONG_OPTIONS = ("--check-hash-based-pycs",)
#: The interpreter's one-letter options that take a value: the rest of their word, or else the
#: next word (``-Wdefault`` / ``-W default``; ``-m`` and ``-c`` end the options)
_VALUED_LETTERS = "WX"


def _run_as_module() -> str | None:
    """The module named by ``python -m NAME`` on the interpreter's own command line
    (``sys.orig_argv``), or None (a script, ``-c``, the console script).

    A word beginning with a single ``-`` is read as the interpreter does, a cluster of
    one-letter options (``-Im NAME``, ``-mNAME``, ``-Xdev``; reader 29: only ``-m NAME`` as its
    own word was read): ``m`` takes the rest of the word or else the next word as the module,
    ``c`` ends the options (no module), ``W`` / ``X`` take the rest or else the next word as
    their value; any other letter takes none."""
    words = list(getattr(sys, "orig_argv", ())[1:])
    while words:
        word = words.pop(0)
        if word in _VALUED_LONG_OPTIONS:
            words = words[1:]
            continue
        if word == "--" or word == "-" or not word.startswith("-"):
            return None  # (a script's own words are not the interpreter's)
        if word.startswith("--"):
            continue  # a long option without a value (--help, --version)
        for i, letter in enumerate(word[1:], start=2):
            rest = word[i:]
            if letter == "m":
                return rest or (words[0] if words else None)
            if letter == "c":
                return None  # (-c's own words are not the interpreter's)
            if letter in _VALUED_LETTERS:
                if not rest:
                    words = words[1:]
                break
    return None


def _console_program() -> bool:
    """Whether this process is the ``testbed`` command (its console script, or ``python -m``).

    Under ``python -m testbed.cli`` the package is imported before runpy makes the module
    ``__main__`` (whose ``__spec__`` names it only then, and ``sys.argv[0]`` is ``"-m"``
    meanwhile), so the interpreter's own command line is read (hostile round 29: such a
    command was never armed, and a Ctrl-C in its first 0.2 s or at its exit was Python's
    traceback, status -2)."""
    main = sys.modules.get("__main__")
    spec = getattr(main, "__spec__", None)
    if spec is not None:  # python -m NAME, once runpy has made it __main__
        return spec.name in ("testbed.cli", "testbed.__main__")
    if _run_as_module() in ("testbed.cli", "testbed"):
        return True
    return os.path.basename(sys.argv[0] if sys.argv else "").removesuffix(".exe") == "testbed"


def exit_now(signum: int) -> None:
    """End the process at once with one line and the status of ``signum``, removing the
    temporary files and folders it was writing (:func:`testbed.core.atomic.remove_in_flight`).

    Written with ``os.write`` (no buffered stream: the signal may land inside a ``print``) and
    ended with ``os._exit`` (no Python code of a half-imported module, of the interpreter's
    shutdown or of a stuck main thread runs again)."""
    # not imported yet, or half imported (a signal during its import: its remove_in_flight not
    # defined yet was an AttributeError, status 1, hostile round 29): nothing is being written
    remove = getattr(sys.modules.get("testbed.core.atomic"), "remove_in_flight", None)
    if remove is not None:
        remove()
    line = "interrupted" if signum == signal.SIGINT else f"interrupted by {NAMES[signum]}"
    try:
        os.write(2, f"error: {line}\n".encode())
    except OSError:  # no standard error to write to: the status says it
        pass
    os._exit(STATUS[signum])


def exit_at_once(signum: int, frame: object) -> None:
    """The handler while armed: :func:`exit_now`, standard output flushed first (a finished
    command's table that sat in its buffer still reaches a pipe)."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, RuntimeError, AttributeError):  # closed, reentrant, None
            pass
    exit_now(signum)


def _python_default(signum: int) -> object:
    return signal.default_int_handler if signum == signal.SIGINT else signal.SIG_DFL


def arm() -> None:
    """In the console program, end at once on the signals of :data:`STATUS` whose handler is
    still Python's default (one a caller set, e.g. ignored, is kept); elsewhere do nothing."""
    global armed
    if not _console_program():
        return
    try:
        for s in STATUS:
            if signal.getsignal(s) == _python_default(s):
                signal.signal(s, exit_at_once)
    except ValueError:  # not the main thread: signals are not this thread's to set
        return
    armed = True


arm()  # on import: the package testbed imports this module before anything else



#: Seconds the main thread has to start handling a signal (its Python handler runs) before
#: the watchdog ends the process without it.  Python runs a handler between two bytecodes of
#: the main thread: in 26 SIGTERMs timed 0.5-11 s into runs of four shipped scenarios it ran
#: within 0.36 s but once, when the main thread was in one long call of compiled code that
#: does not check for signals (`sgd_sindy`'s numba ``nogil`` kernel: 30 s), which is what this
#: bounds; 2 s is over five times the longest orderly delay measured.
GRACE_S = 2.0


class _Watchdog:
    """A thread woken by every signal (``signal.set_wakeup_fd``: written by the C-level
    handler even while the main thread is in compiled code) that ends the process
    (:func:`exit_now`) if the signal's Python handler has not run :data:`GRACE_S` later."""

    def __init__(self, signums: tuple[int, ...]) -> None:
        import socket
        import threading

        self.signums = frozenset(int(s) for s in signums)
        self.handled = threading.Event()
        self._read, self._write = socket.socketpair()
        self._write.setblocking(False)  # set_wakeup_fd's requirement: a signal never blocks
        self.previous = signal.set_wakeup_fd(self._write.fileno(), warn_on_full_buffer=False)
        self._thread = threading.Thread(target=self._watch, name="testbed-signal-watchdog",
                                        daemon=True)
        self._thread.start()

    def _watch(self) -> None:
        while True:
            try:
                data = self._read.recv(64)
            except OSError:  # closed by stop()
                return
            if not data:
                return
            ours = [s for s in data if s in self.signums]
            if not ours:
                continue
            if self.handled.wait(GRACE_S):
                self.handled.clear()  # handled (before or after this thread woke): next one
                continue
            if self._read.fileno() == -1:  # stopped meanwhile: the command has returned
                return
            exit_now(ours[-1])

    def stop(self) -> None:
        import socket

        signal.set_wakeup_fd(self.previous)
        self._write.close()
        self._read.shutdown(socket.SHUT_RDWR)  # wakes the thread's recv
        self._read.close()


def watchdog(signums: tuple[int, ...]) -> object:
    """While the block runs, a :class:`_Watchdog` of ``signums``; yields the event their Python
    handlers must set when they run (None where there is no watchdog: not the main thread, or
    a caller's own wakeup fd, which stays).

    For the console program only: the watchdog ends the process, which in a caller's Python
    session would end that session.  (A context manager; its imports wait for its first use.)"""
    import contextlib
    import threading
    from collections.abc import Iterator

    @contextlib.contextmanager
    def run() -> Iterator[threading.Event | None]:
        if threading.current_thread() is not threading.main_thread():
            yield None
            return
        previous = signal.set_wakeup_fd(-1)
        if previous != -1:
            signal.set_wakeup_fd(previous)
            yield None
            return
        dog = _Watchdog(signums)
        try:
            yield dog.handled
        finally:
            dog.stop()

    return run()

