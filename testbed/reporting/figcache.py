"""Run figures kept by content: a figure is drawn once per set of inputs, then copied.

A run figure is a pure function of what its builder reads from the saved run
(:func:`testbed.reporting.figures.run_figures`) and of the drawing code and libraries: the
same scenario run again with the same seed, code and data (a served ``testbed run`` repeated,
the server's warm-up run and the first command after it) gives the same arrays bit for bit,
and so the same PNG byte for byte.  :class:`FigureCache` keeps each PNG drawn under a key of
all of that, and a later run with the same key copies it instead of drawing it (about 0.9 s
of CPU per drawing process for ``cantilever_stiff_impact``).  A run with any other input (a
seed, a noise level, an identifier's change) has another key and is drawn.

The key (:func:`run_key`, :meth:`FigureCache.key`) is the SHA-256 of:

- :data:`KEY_VERSION` and the figure's stem;
- the drawing code: the bytes of :data:`DRAWING_SOURCES` (this package's modules that draw),
  the versions of matplotlib, numpy and Pillow, and matplotlib's settings in effect (a user's
  ``matplotlibrc`` included; the backend's name left out: reading it can import pyplot);
- the whole run as the builders see it: its kind, its scenario (JSON, sorted keys) and every
  entry of its ``details``, ``model``, ``history`` and ``truth`` (name, dtype, shape and bytes
  of each array; JSON of each list), more than any one figure reads.

Rules (so that the cache never changes a picture, and never fails a run):

- an entry is used only if it is a regular file that starts with the PNG signature and ends
  with the PNG end chunk (written whole, through :func:`testbed.core.atomic.atomic_write`);
  anything else there is drawn again and replaced;
- the cache keeps at most :data:`MAX_ENTRIES` figures (about 100 kB each); after a store, the
  least recently used beyond that are removed (a use refreshes an entry's time);
- every error of the cache (a folder not writable, a full disk, a race with another process)
  is ignored: the figure is then drawn as without a cache.

``testbed run`` keeps it in the dataset cache's folder (``<cache>/figures``); ``--no-cache``
keeps none; ``testbed cache clear`` empties it with the datasets.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

from testbed.core.atomic import atomic_write

__all__ = ["DRAWING_SOURCES", "KEY_VERSION", "MAX_ENTRIES", "FigureCache", "run_key"]

#: Changed when the key's make-up changes (old entries are then never found again).
KEY_VERSION = "testbed-run-figure-1"
#: Modules of this package whose code draws the run figures (their bytes are in the key).
DRAWING_SOURCES = ("figures.py", "frames.py", "mplconfig.py", "figcache.py")
#: Most figures kept (about 100 kB each: about 50 MB); least recently used removed first.
MAX_ENTRIES = 512
_PNG_HEAD = b"\x89PNG\r\n\x1a\n"
_PNG_TAIL = b"\x00\x00\x00\x00IEND\xaeB`\x82"
_CODE: list[bytes] = []  # the drawing code's digest, computed once per process


def _code_digest() -> bytes:
    """SHA-256 of the drawing sources and library versions (computed once per process)."""
    if not _CODE:
        import matplotlib
        import PIL

        h = hashlib.sha256()
        here = Path(__file__).resolve().parent
        for name in DRAWING_SOURCES:
            h.update(name.encode() + b"\0" + (here / name).read_bytes() + b"\0")
        for v in (matplotlib.__version__, np.__version__, PIL.__version__):
            h.update(str(v).encode() + b"\0")
        rc = matplotlib.rcParams
        h.update(repr(sorted((k, repr(rc[k])) for k in rc if k not in ("backend", "backend_fallback")))
                 .encode())
        _CODE.append(h.digest())
    return _CODE[0]


def _feed(h: Any, name: str, value: Any) -> None:
    """Hash ``value`` under ``name``: arrays by dtype, shape and bytes; dicts by sorted key;
    anything else by its JSON (``str`` for what JSON cannot write)."""
    h.update(b"\x01" + name.encode() + b"\0")
    if isinstance(value, dict):
        for k in sorted(value, key=str):
            _feed(h, f"{name}/{k}", value[k])
        return
    if isinstance(value, np.ndarray):
        a = np.ascontiguousarray(value)
        h.update(f"{a.dtype.str}{a.shape}".encode() + b"\0")
        h.update(a.tobytes() if a.dtype != object else json.dumps(a.tolist(), default=str).encode())
        return
    h.update(json.dumps(value, sort_keys=True, default=str).encode())


def run_key(run: Any) -> str:
    """Digest (hex) of everything a run figure of ``run`` (a
    :class:`~testbed.studies.runstore.SavedRun`) is drawn from, and of the drawing code."""
    h = hashlib.sha256(KEY_VERSION.encode() + b"\0" + _code_digest())
    _feed(h, "kind", run.kind)
    _feed(h, "scenario", run.scenario)
    for group in ("details", "model", "history", "truth"):
        _feed(h, group, dict(getattr(run, group) or {}))
    return h.hexdigest()


def _whole_png(path: Path) -> bool:
    """Whether ``path`` is a regular file holding a whole PNG (signature and end chunk)."""
    if not os.path.isfile(path):  # (never opened otherwise: a FIFO would block)
        return False
    with open(path, "rb") as fh:
        if fh.read(8) != _PNG_HEAD:
            return False
        fh.seek(-len(_PNG_TAIL), os.SEEK_END)
        return fh.read() == _PNG_TAIL


class FigureCache:
    """PNGs of run figures by key in ``directory`` (see the module docstring).

    Parameters
    ----------
    directory : path-like
        The cache's folder (created on the first store).
    max_entries : int
        Most PNGs kept (:data:`MAX_ENTRIES`).
    """

    def __init__(self, directory: str | os.PathLike, max_entries: int = MAX_ENTRIES) -> None:
        self.directory = Path(directory)
        self.max_entries = int(max_entries)

    def key(self, run_digest: str, stem: str) -> str:
        """The key of figure ``stem`` of a run whose :func:`run_key` is ``run_digest``."""
        return hashlib.sha256(f"{run_digest}\0{stem}".encode()).hexdigest()

    def holds(self, key: str) -> bool:
        """Whether a whole PNG is kept under ``key`` (never fails: False)."""
        try:
            return _whole_png(self.directory / f"{key}.png")
        except Exception:
            return False

    def fetch(self, key: str, dest: Path) -> bool:
        """Copy the PNG of ``key`` to ``dest`` (atomically); whether there was a whole one."""
        src = self.directory / f"{key}.png"
        try:
            if not _whole_png(src):
                return False
            atomic_write(dest, lambda tmp: shutil.copyfile(src, tmp))
            os.utime(src)  # recently used
            return True
        except Exception:  # (an InputError for dest: raised again when the figure is drawn)
            return False

    def store(self, key: str, png: Path) -> None:
        """Keep a copy of the PNG ``png`` under ``key``, then trim to ``max_entries``."""
        try:
            if not _whole_png(png):
                return
            atomic_write(self.directory / f"{key}.png", lambda tmp: shutil.copyfile(png, tmp))
            self._trim()
        except Exception:  # a cache that cannot be written is no cache
            return

    def clear(self) -> int:
        """Remove every figure kept (and temporary files of killed writes); how many figures
        were removed (0 without a folder; a file that cannot be removed is left)."""
        n = 0
        if not self.directory.is_dir():
            return 0
        for p in [*self._entries(), *self.directory.glob(".*.png.*.tmp")]:
            try:
                p.unlink()
                n += p.suffix == ".png"
            except OSError:
                continue
        return n

    def _trim(self) -> None:
        """Remove the least recently used PNGs beyond ``max_entries`` (ties: by name)."""
        entries = []
        for p in self._entries():
            try:
                entries.append((p.stat().st_mtime_ns, p.name, p))
            except OSError:
                continue
        entries.sort(reverse=True)
        for _, _, p in entries[self.max_entries:]:
            p.unlink(missing_ok=True)

    def _entries(self) -> Iterable[Path]:
        return (p for p in self.directory.glob("*.png") if len(p.stem) == 64)
