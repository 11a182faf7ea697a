"""Write pytest's rewritten test modules once, before ``make test`` starts its workers.

pytest rewrites the ``assert`` statements of every test module and ``conftest.py`` it imports
and caches the result as ``__pycache__/<name>.<tag>-pytest-<version>.pyc``, but only where
Python may write bytecode: with ``PYTHONDONTWRITEBYTECODE`` set (as on the machines the suite
is measured on) nothing is cached, and in a fresh clone nothing is cached yet, so each of the
two pytest-xdist workers parses and rewrites all of them (about half of a worker's collection:
measured with cProfile, ``pytest --collect-only`` 2026-11-27).  Here each module is rewritten
once, by pytest's own functions, on every core; a worker then reads the file (pytest reads a
cached rewritten module whether or not it may write one, checking the source's size and
mtime, so a stale file is rewritten as before).

The functions used are pytest internals (``_pytest.assertion.rewrite``): if an upgrade moves
them, or the project enables ``enable_assertion_pass_hook`` (the rewrite here is made without
pytest's configuration, so with that option off), nothing is written and pytest rewrites the
modules itself as it did before: the run is the same, only slower.  ``tests/test_cold_suite.py``
checks that what is written here is the code pytest's own rewrite makes.

Usage: ``python tests/_rewrite_ahead.py [folder ...]`` (default: this folder).
"""

from __future__ import annotations

import os
import sys
import tomllib
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

HERE = Path(__file__).resolve().parent


def rewritten_modules(folders: list[Path]) -> list[Path]:
    """The files pytest rewrites under ``folders``: its default ``python_files`` patterns
    (``test_*.py``, ``*_test.py``) and ``conftest.py``; pyproject sets no other."""
    return sorted({p for folder in folders for pattern in ("test_*.py", "*_test.py", "conftest.py")
                   for p in folder.rglob(pattern) if "__pycache__" not in p.parts})


def pass_hook_enabled(root: Path) -> bool:
    """Whether pyproject's pytest configuration enables the assertion pass hook (the rewrite
    made here would then differ from pytest's)."""
    try:
        ini = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["pytest"]["ini_options"]
    except (OSError, KeyError, tomllib.TOMLDecodeError):
        return True  # unknown configuration: leave the rewrite to pytest
    return bool(ini.get("enable_assertion_pass_hook", False))


def cache_file(path: Path) -> Path:
    """pytest's cache file of the rewritten module ``path``."""
    from _pytest.assertion import rewrite

    return rewrite.get_cache_dir(path) / (path.name[:-3] + rewrite.PYC_TAIL)


def up_to_date(path: Path) -> bool:
    """Whether pytest would read the cached rewritten module of ``path`` (it checks the
    source's size and mtime)."""
    from _pytest.assertion import rewrite

    return rewrite._read_pyc(path, cache_file(path)) is not None


def rewrite_one(path: Path) -> bool:
    """Rewrite ``path`` as pytest does and write pytest's cache file for it, atomically;
    False if nothing was written (writing failed, or the file does not compile)."""
    from _pytest.assertion import rewrite

    pyc = cache_file(path)
    try:
        pyc.parent.mkdir(exist_ok=True)
        stat, co = rewrite._rewrite_test(path, None)
    except (OSError, SyntaxError):  # a file that does not compile is pytest's to report
        return False

    class _State:  # what _write_pyc reads of pytest's AssertionState: its trace
        @staticmethod
        def trace(message: str) -> None:
            pass

    return rewrite._write_pyc(_State(), co, stat, pyc)


def main(argv: list[str]) -> int:
    folders = [Path(a).resolve() for a in argv] or [HERE]
    if pass_hook_enabled(HERE.parent):
        return 0
    try:
        from _pytest.assertion import rewrite

        for name in ("get_cache_dir", "PYC_TAIL", "_read_pyc", "_rewrite_test", "_write_pyc"):
            getattr(rewrite, name)
    except (ImportError, AttributeError):
        return 0  # another pytest: it rewrites the modules itself
    paths = [p for p in rewritten_modules(folders) if not up_to_date(p)]
    if not paths:
        return 0
    with ProcessPoolExecutor(max_workers=min(os.cpu_count() or 1, len(paths) or 1)) as pool:
        list(pool.map(rewrite_one, paths, chunksize=8))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
