"""Content-keyed dataset cache shared by ``testbed run``, ``testbed generate`` and ``testbed sweep``.

The cache holds each *clean* simulation once: one HDF5 file per rig configuration
(:func:`~testbed.pipeline.generate.noise_free_scenario` of a scenario: its data sections with
the noise level and seed set aside), named ``<rig>-<key>.h5``.  The key hashes that
configuration (:meth:`Scenario.data_hash`), the versions of the engines that simulate it
and this project's generating source (the rigs and the noise model).  A scenario's
dataset, noisy or not, is :func:`~testbed.pipeline.generate.derive` of the clean entry with the
scenario's noise spec and seed, made on load: bit-identical to a fresh
:func:`~testbed.pipeline.generate.generate`, and no noisy copy is stored.

Stored data defend themselves: every load recomputes the content hash and compares it
with the stored one; an unreadable (e.g. truncated) or altered entry is reported in one
warning line naming the file and simulated again.  Files are written atomically
(temporary file, then rename), so a killed process never leaves a half-written entry,
a reader never sees one, and two processes filling the same entry at once both finish
(the last rename wins; both wrote the same content).
"""

from __future__ import annotations

import contextlib
import errno
import functools
import hashlib
import json
import logging
import os
import re
import sys
from collections.abc import Callable, Iterator
from pathlib import Path

try:
    import fcntl
except ImportError:  # Windows: no folder lock (a `cache clear` during a write may fail it)
    fcntl = None  # type: ignore[assignment]

from testbed.core import arguments
from testbed.core.dataset import Dataset, DatasetError
from testbed.core.errors import InputError
from testbed.core.provenance import versions
from testbed.core.rate_attrs import fs_attribute_problem
from testbed.pipeline.generate import derive, noise_free_scenario, record_problem, simulate_clean
from testbed.pipeline.plugins import rig_class
from testbed.pipeline.scenario import Scenario

log = logging.getLogger(__name__)


@contextlib.contextmanager
def _folder_lock(directory: Path, exclusive: bool) -> Iterator[bool]:
    """Hold ``flock`` on the cache folder itself while the block runs: shared while an entry is
    written (:meth:`DatasetCache.clean`), exclusive while :meth:`DatasetCache.clear` removes.

    `cache clear` removed the temporary file of another process's entry being written, whose
    rename then failed after its simulation ("[Errno 2] No such file or directory:
    '.../.cantilever-<key>.h5.<random>.tmp'", round 11: 15 of 15 writes against a clear in a
    loop); now it waits for the writes under way, and a writer killed meanwhile (SIGKILL)
    releases its lock with its descriptor.  The folder's own descriptor is locked, not a file in
    it: HDF5 ``flock``-s the files it writes, and a read-only cache needs no lock file.  A
    folder that cannot be opened is not locked (nothing is written into or cleared from it).
    The block receives False when the folder does not exist (else True): a `cache clear` that
    found no folder must not go on unlocked, since a writer may create it and start an entry
    meanwhile (the clear then removed that entry's temporary file: CI, 2026-11-27, the first of
    20 writes against a clear in a loop).
    A file system without ``flock`` (ENOLCK, EOPNOTSUPP: NFS without its lock daemon, some
    FUSE and SMB mounts) is used unlocked, with one warning: the lock only orders a `cache
    clear` against writes, and it holds between processes of one host (``flock`` on NFS does
    not reach other hosts; clear a cache a Dask cluster shares while no sweep runs).
    """
    try:
        fd = os.open(directory, os.O_RDONLY | os.O_DIRECTORY)
    except FileNotFoundError:
        yield False
        return
    except (OSError, AttributeError):  # unreadable; O_DIRECTORY absent (Windows)
        yield True
        return
    try:
        if fcntl is not None:
            try:
                fcntl.flock(fd, fcntl.LOCK_EX if exclusive else fcntl.LOCK_SH)
            except OSError as e:
                _warn_unlocked(directory, e.strerror or str(e))
        yield True
    finally:
        os.close(fd)  # (releases the lock)


@functools.cache
def _warn_unlocked(directory: Path, reason: str) -> None:
    """One warning per folder and reason that the cache goes on without its lock."""
    log.warning("dataset cache %s: the file system refuses a lock (%s); going on without it "
                "(do not run `testbed cache clear` while a sweep writes here)", directory, reason)


#: The name of a cache entry: ``<rig>-<cache key, 32 hex digits>.h5`` (:meth:`DatasetCache.path`).
ENTRY_NAME = re.compile(r"[^/]+-[0-9a-f]{32}\.h5")


def default_cache_dir() -> Path:
    """``$TESTBED_CACHE``, else ``.cache/datasets`` under the current directory."""
    return Path(os.environ.get("TESTBED_CACHE", Path.cwd() / ".cache" / "datasets"))


#: Source every rig's data depend on besides its own package: the rig contract, the noise model
#: and the dataset format with its typed truth.
SHARED_GENERATOR_SOURCES = ("models/__init__.py", "models/_base.py", "testbed/pipeline/generate.py",
                            "testbed/core/dataset.py", "testbed/core/truth.py")


def generator_sources(rig: str) -> list[Path]:
    """The source files a scenario of ``rig`` turns into data through: the rig's own package (a
    rig in ``models/<name>/``: every file there; a rig defined elsewhere, e.g. a plugin file:
    that module) and :data:`SHARED_GENERATOR_SOURCES`."""
    root = Path(__file__).resolve().parents[2]
    models_dir = (root / "models").resolve()
    module = Path(sys.modules[rig_class(rig).__module__].__file__).resolve()
    if module.parent != models_dir and module.is_relative_to(models_dir):
        own = sorted(module.parent.rglob("*.py"))
    else:
        own = [module]
    return [*own, *(root / n for n in SHARED_GENERATOR_SOURCES)]


@functools.cache
def generator_code_hash(rig: str) -> str:
    """SHA-256 of :func:`generator_sources` (paths and contents).

    Package versions alone miss a change to this project's own code (a developer's stale cache
    would survive it); the source hash does not.  Adding or editing one rig leaves the other
    rigs' cached datasets valid.
    """
    root = Path(__file__).resolve().parents[2]
    h = hashlib.sha256()
    for f in generator_sources(rig):
        # the path's bytes as the file system holds them: .encode() (UTF-8) failed on a plugin
        # at a non-ASCII path under a non-UTF-8 locale (an internal error), and would have
        # hashed the same file differently under another locale
        h.update(os.fsencode((f.relative_to(root) if f.is_relative_to(root) else f).as_posix()))
        h.update(f.read_bytes())
    return h.hexdigest()


def cache_key(scenario: Scenario) -> str:
    """Key of a scenario's dataset: its data sections and seed, package versions, generator code."""
    blob = json.dumps({"data": scenario.data_hash(), "versions": versions(),
                       "code": generator_code_hash(scenario.rig)}, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:32]


#: errno values of a cache folder that cannot be written: no permission, a read-only file system.
NOT_WRITABLE = (errno.EACCES, errno.EPERM, errno.EROFS)
#: Cache folders already reported as not writable by this process.
_UNWRITABLE_WARNED: set[str] = set()


def _load_entry(path: Path, scenario: Scenario) -> Dataset:
    """A cache entry, verified: its content hash (:meth:`Dataset.load`), its rate attributes
    (:func:`~testbed.core.rate_attrs.fs_attribute_problem`) and its rate and number of samples
    against the record its scenario asks for (:meth:`Rig.record`, where the rig declares one).
    An edit made with the content hash anew that keeps the rate and length (samples scaled, a
    channel renamed) is not seen: the hash guards against damage, not against a forger.

    :meth:`Dataset.load` reads ``fs`` with ``float()`` and no unit (round 17, open item 2 of
    round 18: the text ``"12800"``, ``True`` or ``fs_unit = "kHz"`` were read as rates); checking
    it there would change the file the cache key hashes (``testbed/core/dataset.py``), so the
    cache checks what it reads here.  An entry whose rate is not its scenario's (an edit made
    with its content hash anew) was served with that rate: the chain's filters and the scores'
    time axis then belong to another record.

    Raises
    ------
    DatasetError
        Naming the file and what is wrong (the caller simulates it again).
    """
    problem = fs_attribute_problem(path)
    if problem:
        raise DatasetError(path, problem)
    ds = Dataset.load(path)
    problem = record_problem(ds, scenario)
    if problem:
        # simulate_clean refuses a rig whose dataset is not its record (review 29a M1), so an
        # entry of another rate or length was edited after it was written: one cut and its
        # content hash made anew was served as its scenario's record (hostile round 29), its
        # windows, chain and time axis then belonging to a shorter record
        raise DatasetError(path, problem)
    return ds


class DatasetCache:
    """Datasets on disk, one HDF5 file per key.

    Parameters
    ----------
    directory : path, optional
        Where the files live (default :func:`default_cache_dir`).
    """

    def __init__(self, directory: str | os.PathLike | None = None) -> None:
        if directory is not None:
            arguments.path("DatasetCache", "directory", directory)
        self.directory = Path(directory) if directory is not None else default_cache_dir()

    def path(self, scenario: Scenario) -> Path:
        """The file of ``scenario``'s clean simulation (shared by all its noise levels and seeds)."""

        clean_sc = noise_free_scenario(scenario)
        return self.directory / f"{clean_sc.rig}-{cache_key(clean_sc)}.h5"

    def clean(self, scenario: Scenario, progress: Callable[[float], None] | None = None) -> Dataset:
        """The clean dataset of ``scenario``'s simulation, verified, simulated and stored if absent.

        An entry that cannot be read or whose content does not match its stored hash is
        reported (one warning line on the ``testbed.pipeline.cache`` logger, naming the file) and
        simulated again; the new file replaces it atomically.
        """

        p = self.path(scenario)
        if p.is_dir():  # the atomic rename onto it failed after simulating, naming a temporary file
            raise InputError(f"dataset cache {self.directory}: {p.name} is a folder where a cached "
                             "dataset belongs; remove it or use another cache folder (--cache)")
        if p.is_file():
            try:
                return _load_entry(p, scenario)
            except DatasetError as e:
                if p.is_file():  # else another process cleared it meanwhile: a plain miss
                    log.warning("dataset cache: %s; simulating it again", e)
        ds = simulate_clean(scenario, progress)
        try:
            self.directory.mkdir(parents=True, exist_ok=True)
            with _folder_lock(self.directory, exclusive=False):
                ds.save(p)
        except OSError as e:
            if e.errno not in NOT_WRITABLE:
                raise
            # a read-only cache (shared, pre-filled) still serves what it holds; what it lacks
            # is simulated and used uncached.  Was "error: [Errno 13] Permission denied:
            # '<cache>/.<entry>.h5.<random>.tmp'" after the simulation, the run lost.
            if str(self.directory) not in _UNWRITABLE_WARNED:  # once a folder: a sweep's cells
                _UNWRITABLE_WARNED.add(str(self.directory))
                log.warning("dataset cache %s: cannot be written (%s); datasets it lacks are "
                            "simulated and not cached (--cache names another folder)",
                            self.directory, e.strerror or type(e).__name__)
        return ds

    def get(self, scenario: Scenario, progress: Callable[[float], None] | None = None) -> Dataset:
        """The dataset of ``scenario``: its clean simulation (:meth:`clean`) with its noise added.

        Bit-identical to :func:`testbed.pipeline.generate.generate` of ``scenario``; noise levels and
        seeds of a study share one simulation per configuration.
        """

        return derive(self.clean(scenario, progress), scenario)

    def entries(self) -> list[tuple[Path, int]]:
        """(path, size in bytes) of every cached file, sorted by name."""
        if not self.directory.is_dir():
            return []
        # not a folder named *.h5 (`cache clear` failed on it, "Is a directory"); lstat: a link
        # that loops is listed (and cleared), not an OSError
        # only names this cache writes (<rig>-<32 hex digits>.h5, :meth:`path`): `cache clear`
        # deleted every *.h5 of the folder, a user's own datasets in a --cache folder included
        return [(p, p.lstat().st_size) for p in sorted(self.directory.glob("*.h5"))
                if ENTRY_NAME.fullmatch(p.name) and not p.is_dir()]

    def clear(self) -> int:
        """Delete every cached file and any temporary file a killed writer left; return how many
        cached files were removed."""
        n = 0
        with _folder_lock(self.directory, exclusive=True) as present:  # after the writes under way
            if not present:  # no folder, nothing to clear
                return 0
            for p, _ in self.entries():
                p.unlink(missing_ok=True)
                n += 1
            if self.directory.is_dir():
                for tmp in self.directory.glob(".*.h5.*.tmp"):  # testbed.core.atomic's temporary names
                    tmp.unlink(missing_ok=True)
        return n
