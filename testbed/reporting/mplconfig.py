"""A writable configuration folder for matplotlib, chosen before matplotlib is imported.

matplotlib keeps its font list in a configuration and a cache folder (``$MPLCONFIGDIR``, else
``$XDG_CONFIG_HOME/matplotlib`` and ``$XDG_CACHE_HOME/matplotlib``, else under ``$HOME``).
Where that folder cannot be used, its import either failed (``HOME`` under an unreadable
folder: "error: [Errno 13] Permission denied: '/proc/1/root'", naming neither matplotlib nor
the variable) or printed two warning lines before the verdict and created a
``/tmp/matplotlib-*`` folder that it removes at exit, which the drawing processes
(:mod:`testbed.reporting.drawer`, ended by ``os._exit``) never reach: one folder left behind
per run.  :func:`ensure_config_dir` checks the folders as matplotlib would and, where one is
unusable, points ``MPLCONFIGDIR`` at a temporary folder of this process, removed when it
exits (also when it is ended at once by a signal: :func:`testbed.core.atomic.remove_in_flight`).
Forked drawing processes inherit the variable.  The font list is then rebuilt once per command
(about a second), the price of a home folder matplotlib cannot write.
"""

from __future__ import annotations

import atexit
import os
import shutil
import sys
import tempfile
from pathlib import Path

from testbed.core.atomic import begin_in_flight, end_in_flight
from testbed.core.errors import exception_text, show_value

__all__ = ["ensure_config_dir", "usable_folder"]

#: The temporary folder this process made, if any (one per process).
_made: str | None = None


def usable_folder(path: str | os.PathLike) -> bool:
    """Whether matplotlib can use ``path`` as its folder: an existing writable folder, or a
    path whose nearest existing ancestor is a writable folder (matplotlib runs ``mkdir -p``).

    Any error while looking (a folder on the way that cannot be searched, a loop of links, a
    name too long) counts as unusable.
    """
    try:
        p = Path(path).resolve()
        while not p.exists():
            if p.parent == p:
                return False
            p = p.parent
        return p.is_dir() and os.access(p, os.W_OK | os.X_OK)
    except (OSError, RuntimeError, ValueError):  # EACCES, ELOOP, ENAMETOOLONG, NUL in the path
        return False


def _default_folders() -> list[Path] | None:
    """The configuration and cache folders matplotlib would use; None if the home folder
    cannot be found (no ``HOME`` and no password entry)."""
    configured = os.environ.get("MPLCONFIGDIR")
    if configured:
        return [Path(configured)]
    try:
        config = os.environ.get("XDG_CONFIG_HOME") or str(Path.home() / ".config")
        cache = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    except (KeyError, RuntimeError, OSError):
        return None
    if not sys.platform.startswith(("linux", "freebsd")):
        return [Path.home() / ".matplotlib"]
    return [Path(config) / "matplotlib", Path(cache) / "matplotlib"]


def _remove(path: str, pid: int) -> None:
    if os.getpid() == pid:  # not in a forked child that exits normally
        shutil.rmtree(path, ignore_errors=True)
        end_in_flight(path)


def ensure_config_dir() -> str | None:
    """Point ``MPLCONFIGDIR`` at a temporary folder if matplotlib could not use its own.

    Does nothing once matplotlib is imported (it has read its folders), nor where its folders
    are usable.  If no temporary folder can be made either, matplotlib's own error (one line,
    naming ``MPLCONFIGDIR``) follows at its import.

    Returns
    -------
    str or None
        The temporary folder now in ``MPLCONFIGDIR``, or None if none was needed.
    """
    global _made
    if "matplotlib" in sys.modules:
        return None
    if _made is not None and os.environ.get("MPLCONFIGDIR") == _made:
        return _made
    folders = _default_folders()
    if folders is not None and all(usable_folder(f) for f in folders):
        return None
    try:
        made = tempfile.mkdtemp(prefix="testbed-matplotlib-")
    except OSError:
        return None
    begin_in_flight(made)  # removed by a process ended at once by a signal
    atexit.register(_remove, made, os.getpid())
    os.environ["MPLCONFIGDIR"] = _made = made
    return made


def backend_refusal(error: BaseException) -> str | None:
    """The one line for matplotlib refusing ``$MPLBACKEND`` at its import, if ``error`` is that.

    matplotlib validates the variable when first imported (``ValueError: Key backend: 'bogus'
    is not a valid value for backend; supported values are [...]``: an internal error, "please
    report it", in ``run`` and ``report``).  Which names it accepts is known only by importing
    it (its registry, entry points included), so the refusal is recognised where it surfaces,
    in the drawing process's error re-raised in the command or in the command itself.
    """
    backend = os.environ.get("MPLBACKEND")
    if (backend is None or not isinstance(error, ValueError)
            or "valid value for backend" not in exception_text(error)):
        return None
    return (f"$MPLBACKEND {show_value(backend)}: matplotlib refuses it as a backend; unset it (the "
            "testbed draws on Agg canvases, never in a window) or name one matplotlib has "
            "(agg, pdf, svg, ...)")
