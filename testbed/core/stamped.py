"""A value computed from files, kept on disk with the files' stamps and reused while they hold.

``testbed list`` imports every rig and identifier module (their registrations run on import)
and validates every scenario file: 0.3-0.4 s of a 0.5 s start-up, most of it numpy and the
modules themselves, to print a few dozen names.  What it prints depends only on files, so
:func:`stamped_value` keeps it in an *index* (one JSON file) together with the *stamp* of every
file and folder the computation depended on, and a later call returns the kept value only if
every stamp still holds; otherwise it computes the value again, as if there were no index, and
rewrites the index.

The rule (stated here, applied by :func:`_current`):

- a **file** holds if it has the recorded size [bytes], modification time [ns] (Python's own
  rule for its bytecode cache, at a finer time), status-change time [ns] and inode, or is still
  absent if it was absent: a file replaced by one of the same size and modification time
  (``cp -p``, ``rsync -t``, ``touch -r``) has another status-change time, which no user sets;
- a **folder** holds if it has the recorded modification time [ns], status-change time and
  inode: a file created, removed or renamed in it changes it (a new identifier module in
  ``identify/``, a new scenario file);
- a folder **on** ``sys.path`` holds if it holds the same distributions and path files (the
  names of its ``*.dist-info``, ``*.egg-info``, ``*.egg-link`` and ``*.pth``): what can add an
  entry point or a path.  Not its modification time: the project's own folder is on the path,
  and a file a run writes there (``out/``, a log) would make every listing afresh (and the
  command line's test flaky, as other tests write there while it runs);
- the recorded files are those the caller names (the scenario files read) **plus the file of
  every module loaded in the process** when the value was computed (the project's modules, a
  plugin package's, numpy's ...); the folders are those the caller names (the registries'
  packages, the scenario folder) **plus every folder on** ``sys.path`` (by the rule above);
  and every installed distribution's ``entry_points.txt`` is recorded as a file (present or
  absent), so an entry point added, removed or edited shows at once; a module loaded from no
  file of its own (a zip archive) cannot be stamped, and no index is written;
- an index is **keyed** by the interpreter (``sys.executable``, its version), ``sys.path``
  (``""`` as the working folder it stands for), the working folder (a relative
  ``TESTBED_SCENARIOS`` names another folder in another one) and the ``TESTBED_*`` variables:
  another interpreter, path, working or scenario folder has its own index;
- **racy stamps** are not trusted: a value is written to the index only if every stamp is
  more than :data:`RACY_S` older than the import of this module (before the modules of the
  value were read; those read before it, the command line's own, were read at the command's
  start, a fraction of a second earlier), since a file changed again within the file
  system's time resolution keeps its time (git's "racy clean" rule), and only within
  :data:`WRITE_WITHIN_S` of that import (the command line imports this module as a listing
  starts, in a fresh process; a long-lived one may hold modules read long before).  The next
  call computes the value again;
- an index that cannot be read, parsed or written, whose content is not the one its
  ``sha256`` was computed from (a bit flipped, a value edited: an edited listing of no
  sections printed nothing, status 0), is not a regular file (a FIFO, a device)
  or is larger than :data:`MAX_INDEX_BYTES`, holds no stamps, or whose value the caller's
  ``valid`` refuses, is as good as none: the value is computed (the index only ever saves time;
  it never fails a command).

Indexes live in ``$TESTBED_INDEX`` (a folder; the empty string turns them off), else
``$XDG_CACHE_HOME/sysid-testbed/index`` (``~/.cache/...``).
"""

from __future__ import annotations

import hashlib
import json
import os
import stat
import sys
import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from testbed.core.atomic import atomic_write_text
from testbed.core.errors import TestbedError

#: Format of an index file; another version is ignored (recomputed and rewritten).  3: the
#: index carries the SHA-256 of its content (``sha256``), checked on read (round 14).
FORMAT = 3
#: Names in a folder on ``sys.path`` that are its stamp (see the module docs).
PATH_ENTRY_SUFFIXES = (".dist-info", ".egg-info", ".egg-link", ".pth")
#: A stamp less than this old [s] at the import of this module is not trusted (see the module
#: docs): 2 s is FAT's time resolution, the coarsest in common use (ext4's is 1-10 ms).
RACY_S = 2.0
#: A process writes an index only this soon [s] after it imported this module (see the
#: module docs): a command alone takes 0.5-5 s.
WRITE_WITHIN_S = 30.0
#: When this module was imported [s since the epoch] (see the module docs).
_IMPORTED_AT = time.time()
#: Largest index file read [bytes]: the listing's index, with the stamps of some 2,000 loaded
#: modules, is about 0.3 MB; a larger file is not one this module wrote, and is not read.
MAX_INDEX_BYTES = 16 << 20
#: Environment variable naming the index folder ("" turns indexes off).
INDEX_VARIABLE = "TESTBED_INDEX"
#: Variables that change how a command reaches a server, not what it computes: not keyed.
_UNKEYED = ("TESTBED_SERVER_SOCKET", "TESTBED_NO_SERVER", INDEX_VARIABLE)

#: What a build returns: the value (JSON-able) and the files and folders it read beyond the
#: modules it imported.
Built = tuple[Any, Iterable[str | os.PathLike], Iterable[str | os.PathLike]]


def index_folder() -> Path | None:
    """Where indexes are kept: ``$TESTBED_INDEX``, else the user's cache; None if turned off or
    there is no absolute cache folder to use."""
    given = os.environ.get(INDEX_VARIABLE)
    if given is not None:
        return Path(given) if given else None
    base = os.environ.get("XDG_CACHE_HOME")
    if not base:
        home = os.path.expanduser("~")
        if not os.path.isabs(home):  # no home to find: not a folder named "~" in the working one
            return None
        base = os.path.join(home, ".cache")
    if not os.path.isabs(base):  # a relative $XDG_CACHE_HOME is invalid (the XDG spec): ignored
        return None
    return Path(base) / "sysid-testbed" / "index"


def _key(name: str) -> str:
    """The index file's name for ``name`` in this interpreter, path and environment."""
    try:
        cwd = os.getcwd()
    except OSError:  # the working folder was removed
        cwd = ""
    parts = [name, sys.executable, sys.version, cwd,
             *(p or cwd for p in sys.path),
             *(f"{k}={v}" for k, v in sorted(os.environ.items())
               if k.startswith("TESTBED_") and k not in _UNKEYED)]
    digest = hashlib.sha256("\0".join(parts).encode("utf-8", "surrogateescape")).hexdigest()
    return f"{name}-{digest[:32]}.json"


def _file_stamp(path: str) -> list[int] | None:
    """[size, mtime_ns, ctime_ns, inode] of a file, None if it is absent (or cannot be looked
    up)."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return [st.st_size, st.st_mtime_ns, st.st_ctime_ns, st.st_ino]


def _folder_stamp(path: str) -> list[int] | None:
    """[mtime_ns, ctime_ns, inode] of a folder, None if it is absent."""
    try:
        st = os.stat(path)
    except (OSError, ValueError):
        return None
    return [st.st_mtime_ns, st.st_ctime_ns, st.st_ino]


def _path_stamp(path: str) -> list[str] | None:
    """The sorted names of the distributions and path files in a folder on ``sys.path``
    (:data:`PATH_ENTRY_SUFFIXES`), None if it cannot be listed."""
    try:
        return sorted(n for n in os.listdir(path) if n.endswith(PATH_ENTRY_SUFFIXES))
    except (OSError, ValueError):
        return None


def _module_files() -> set[str]:
    """The file of every module loaded in this process (source or extension)."""
    out = set()
    for m in list(sys.modules.values()):
        f = getattr(m, "__file__", None)
        if isinstance(f, str):
            out.add(os.path.abspath(f))
    return out


def _entry_point_files() -> set[str]:
    """Every installed distribution's ``entry_points.txt`` (present or not) on ``sys.path``."""
    import importlib.metadata

    out = set()
    for dist in importlib.metadata.distributions():
        where = getattr(dist, "_path", None)  # a PathDistribution's folder
        if where is not None:
            out.add(os.path.abspath(os.path.join(str(where), "entry_points.txt")))
    return out


def _implicit() -> tuple[set[str], set[str]] | None:
    """The files and path folders recorded for every value: the loaded modules' files and the
    distributions' ``entry_points.txt``; the folders on ``sys.path`` (stamped by
    :func:`_path_stamp`).  None if a loaded module has no file of its own to stamp (imported
    from a zip archive): its changes could not be seen, so no index is written."""
    modules = _module_files()
    if any(_file_stamp(f) is None for f in modules):
        return None
    folders = {os.path.abspath(p or os.getcwd()) for p in sys.path if os.path.isdir(p or ".")}
    return modules | _entry_point_files(), folders


def _current(index: dict) -> bool:
    """Whether every stamp of ``index`` holds (the module docs' rule); an index holding no
    file stamp is not (every value is computed by modules, whose files are stamped)."""
    if not index["files"]:
        return False
    for path, stamp in index["files"]:
        if _file_stamp(path) != stamp:
            return False
    for path, stamp in index["folders"]:
        if _folder_stamp(path) != stamp:
            return False
    for path, stamp in index["paths"]:
        if _path_stamp(path) != stamp:
            return False
    return True


def _read_regular(path: Path) -> bytes:
    """The bytes of the regular file ``path``; OSError if it is anything else or larger than
    :data:`MAX_INDEX_BYTES`.  Opened without blocking and checked on its descriptor: a FIFO at
    the index's path blocked `testbed list` for ever, a link to ``/dev/zero`` read until memory
    ran out (round 14)."""
    fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode) or st.st_size > MAX_INDEX_BYTES:
            raise OSError(f"{path}: not a regular file of at most {MAX_INDEX_BYTES} bytes")
        with os.fdopen(os.dup(fd), "rb") as fh:
            return fh.read(MAX_INDEX_BYTES + 1)
    finally:
        os.close(fd)


def _digest(index: dict) -> str:
    """SHA-256 of an index's content (every key but its own ``sha256``), in canonical JSON."""
    text = json.dumps(index, sort_keys=True, separators=(",", ":"), ensure_ascii=True)
    return hashlib.sha256(text.encode("ascii")).hexdigest()


def _read(path: Path, valid: Callable[[Any], bool]) -> dict | None:
    """The index in the file ``path`` if it is current and ``valid`` accepts its value (under
    ``"value"``), else None."""
    try:
        index = json.loads(_read_regular(path))
        if index.get("format") != FORMAT or "value" not in index \
                or index.pop("sha256", None) != _digest(index) or not _current(index):
            return None
        return index if valid(index["value"]) else None
    except (OSError, ValueError, TypeError, KeyError, AttributeError, IndexError):
        return None  # absent, unreadable or not an index of ours: compute


def stamped_value(name: str, build: Callable[[], Built],
                  valid: Callable[[Any], bool] = lambda value: True) -> Any:
    """``build()``'s value, from the index if it is current, else computed (and kept).

    Parameters
    ----------
    name : str
        What the value is (``"list"``): the index file's name starts with it.
    build : callable
        Computes the value; returns ``(value, files, folders)``: the value (JSON-able: dicts,
        lists, str, numbers; tuples come back as lists), the files it read and the folders it
        listed, beyond the modules it imported (which are recorded anyway).  An exception it
        raises propagates, and nothing is written.
    valid : callable, optional
        ``valid(value) -> bool`` of a kept value, before it is returned: a value of another
        shape (an index edited by hand, or written by another version under the same format)
        is computed again instead of failing the caller.

    Returns
    -------
    object
        The value (as JSON gives it back: lists for tuples).
    """
    folder = index_folder()
    path = None if folder is None else folder / _key(name)
    if path is not None:
        index = _read(path, valid)
        if index is not None:
            return index["value"]
    value, files, folders = build()
    value = json.loads(json.dumps(value))  # the value as the index will give it back
    if path is None:
        return value
    implicit = _implicit()
    if implicit is None:
        return value
    implicit_files, path_folders = implicit
    file_names = {os.path.abspath(os.fspath(f)) for f in files} | implicit_files
    folder_names = {os.path.abspath(os.fspath(f)) for f in folders}
    stamps_f = sorted([f, _file_stamp(f)] for f in file_names)
    stamps_d = sorted([d, _folder_stamp(d)] for d in folder_names)
    stamps_p = sorted([d, _path_stamp(d)] for d in path_folders)
    # (modification times: a status-change time is "now" after any chmod or utime)
    newest = max([s[1] for _, s in stamps_f if s is not None]
                 + [s[0] for _, s in stamps_d if s is not None], default=0)
    if newest / 1e9 > _IMPORTED_AT - RACY_S or time.time() - _IMPORTED_AT > WRITE_WITHIN_S:
        return value  # a stamp too young to trust, or modules read too long ago: not kept
    try:
        index = {"format": FORMAT, "name": name, "files": stamps_f, "folders": stamps_d,
                 "paths": stamps_p, "value": value}
        atomic_write_text(path, json.dumps({**index, "sha256": _digest(index)}))
    except (OSError, TestbedError):
        pass  # no room, a read-only cache: the index only ever saves time
    return value
