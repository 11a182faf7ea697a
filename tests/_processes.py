"""The state of a process as Linux's ``/proc`` tells it, for the tests that check that no
process is left behind."""

from __future__ import annotations


def state(pid: int) -> str | None:
    """The process's one-letter state (``R``, ``S``, ``T``, ``Z`` ...), or None if it is gone.

    Read in one go: a process can end between a check that its file exists and the read
    (round 11's fresh-clone suite at load 10: FileNotFoundError in the killed-client test).
    The state follows the command name, which is in parentheses and may itself hold spaces
    or parentheses, so it is read after the last ``)``.
    """
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0]
    except (FileNotFoundError, ProcessLookupError):
        return None


def alive(pid: int) -> bool:
    """Whether the process exists and is not a zombie (one ended, waiting for its parent's
    ``wait``, is as good as gone)."""
    return state(pid) not in (None, "Z")
