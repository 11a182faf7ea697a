"""Content-keyed dataset cache shared by ``testbed run`` and ``testbed sweep``.

A dataset is determined by the scenario's data sections and seed
(:meth:`Scenario.data_hash`), by the versions of the engines that simulate it and
by this project's generating source (the rigs and the noise model); the cache key
hashes all three.  Files are written atomically, so a
killed process never leaves a half-written entry.
"""

from __future__ import annotations

import functools
import hashlib
import json
import os
from collections.abc import Callable
from pathlib import Path

from testbed.dataset import Dataset
from testbed.provenance import versions
from testbed.scenario import Scenario


def default_cache_dir() -> Path:
    """``$TESTBED_CACHE``, else ``.cache/datasets`` under the current directory."""
    return Path(os.environ.get("TESTBED_CACHE", Path.cwd() / ".cache" / "datasets"))


@functools.cache
def generator_code_hash() -> str:
    """SHA-256 of the source that turns a scenario into data: the rigs and the noise model.

    Package versions alone miss a change to this project's own code (a developer's stale cache
    would survive it); the source hash does not.
    """
    root = Path(__file__).resolve().parent.parent
    h = hashlib.sha256()
    files = sorted((root / "models").rglob("*.py")) + [root / "testbed" / n for n in
                                                       ("generate.py", "dataset.py")]
    for f in files:
        h.update(f.relative_to(root).as_posix().encode())
        h.update(f.read_bytes())
    return h.hexdigest()


def cache_key(scenario: Scenario) -> str:
    """Key of a scenario's dataset: its data sections and seed, package versions, generator code."""
    blob = json.dumps({"data": scenario.data_hash(), "versions": versions(),
                       "code": generator_code_hash()}, sort_keys=True)
    return hashlib.sha256(blob.encode()).hexdigest()[:32]


class DatasetCache:
    """Datasets on disk, one HDF5 file per key.

    Parameters
    ----------
    directory : path, optional
        Where the files live (default :func:`default_cache_dir`).
    """

    def __init__(self, directory: str | os.PathLike | None = None) -> None:
        self.directory = Path(directory) if directory is not None else default_cache_dir()

    def path(self, scenario: Scenario) -> Path:
        return self.directory / f"{scenario.rig}-{cache_key(scenario)}.h5"

    def get(self, scenario: Scenario, progress: Callable[[float], None] | None = None) -> Dataset:
        """The cached dataset of ``scenario``, generating and storing it if absent.

        A noisy scenario is derived from the cached noise-free simulation of the same rig and
        excitation, so noise levels and seeds of a study simulate each configuration once.
        """
        from testbed.generate import generate, noise_free_scenario

        p = self.path(scenario)
        if p.is_file():
            return Dataset.load(p)
        clean_sc = noise_free_scenario(scenario)
        if clean_sc.data_hash() != scenario.data_hash():  # noisy: simulate once, add noise
            ds = generate(scenario, clean=self.get(clean_sc, progress))
        else:
            ds = generate(scenario, progress=progress)
        ds.save(p)
        return ds

    def entries(self) -> list[tuple[Path, int]]:
        """(path, size in bytes) of every cached file, sorted by name."""
        if not self.directory.is_dir():
            return []
        return [(p, p.stat().st_size) for p in sorted(self.directory.glob("*.h5"))]

    def clear(self) -> int:
        """Delete every cached file; return how many were removed."""
        n = 0
        for p, _ in self.entries():
            p.unlink(missing_ok=True)
            n += 1
        return n
