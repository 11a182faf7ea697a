"""Chromium for the report tests, installed with apt-get (as root) while the rest of the suite runs.

On a machine without Chromium the install took 71 s of one worker's wall time in a cold
``make test`` (2026-11-28, the report test's setup; the other worker kept working, so about
half of it was added to the suite's wall time).  :func:`start_install` starts it in the
background when the selected tests hold one that needs it; :func:`wait_and_find` (the
``chromium`` fixture) waits for it, and installs itself where Chromium is still missing then
(no background install ran, or it failed: as each worker did before).

One install per test run: the process that starts it holds an exclusive ``flock`` on
``lock_path`` and hands the locked file to the install, so the lock is held exactly as long as
the install runs (released by the kernel when it ends, also if it is killed); a second process
(the other pytest-xdist worker) finds it locked and starts nothing; the fixture takes the lock,
blocking, before it looks for Chromium.  Without ``fcntl`` (Windows) there is no background
install.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

try:
    import fcntl
except ImportError:  # Windows
    fcntl = None

#: The install of a missing Chromium (Debian/Ubuntu); dpkg's lock waited for up to 10 min.
INSTALL = ("apt-get update && apt-get install -y -o DPkg::Lock::Timeout=600 "
           "chromium chromium-driver")
#: The install's own limit [s] (a download over a slow network).
INSTALL_TIMEOUT_S = 1800
_ENV = {"DEBIAN_FRONTEND": "noninteractive"}
_started: list[subprocess.Popen] = []


def find() -> str | None:
    """The Chromium executable on the PATH, or None."""
    for exe in ("chromium", "chromium-browser", "google-chrome"):
        if path := shutil.which(exe):
            return path
    return None


def installable() -> bool:
    """Whether :data:`INSTALL` can run here (apt-get present, running as root)."""
    return shutil.which("apt-get") is not None and hasattr(os, "geteuid") and os.geteuid() == 0


def start_install(lock_path: Path, log_path: Path) -> bool:
    """Start :data:`INSTALL` in the background unless Chromium is here, cannot be installed, or
    another process of this run holds ``lock_path`` (its install is under way).  Returns whether
    this call started it.  The output goes to ``log_path``."""
    if fcntl is None or find() is not None or not installable():
        return False
    lock_path.parent.mkdir(parents=True, exist_ok=True)
    with open(lock_path, "a") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            return False
        with open(log_path, "w") as log:
            # the child inherits the locked file: the lock lasts as long as the install
            _started.append(subprocess.Popen(
                ["timeout", str(INSTALL_TIMEOUT_S), "sh", "-c", INSTALL], stdin=subprocess.DEVNULL,
                stdout=log, stderr=subprocess.STDOUT, env={**os.environ, **_ENV},
                pass_fds=(lock.fileno(),)))
    return True  # closing our copy of the file leaves the lock with the child


def wait_started() -> None:
    """Wait for the installs this process started (pytest's end: no process outlives the run)."""
    while _started:
        _started.pop().wait()


def wait_and_find(lock_path: Path) -> tuple[str | None, str]:
    """Chromium's path once no install of this run is under way, installing it here when it is
    still missing and can be installed; else None, with the reason."""
    if fcntl is not None:
        lock_path.parent.mkdir(parents=True, exist_ok=True)
        with open(lock_path, "a") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)  # waits for a background install to end
            fcntl.flock(lock, fcntl.LOCK_UN)
    exe = find()
    if exe is not None:
        return exe, ""
    if not installable():
        return None, ("chromium missing and cannot be installed here (needs apt-get as root): "
                      "apt-get install chromium chromium-driver")
    r = subprocess.run(INSTALL, shell=True, capture_output=True, text=True,
                       timeout=INSTALL_TIMEOUT_S, env={**os.environ, **_ENV})
    exe = find()
    if exe is None:
        return None, f"apt-get could not install chromium (exit {r.returncode}): {r.stderr[-400:]}"
    return exe, ""
