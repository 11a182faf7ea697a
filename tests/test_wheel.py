"""A wheel that works anywhere: built from the checkout, installed (not editable) in a fresh
virtual environment outside it, and run from an empty folder.

The fresh environment gets this interpreter's installed dependencies through a ``.pth`` file
(``site.addsitedir``, minus the import hooks of an editable install of this project), so
nothing is downloaded except, when this interpreter's setuptools is
older than the build needs, the build backend itself (pip's isolated build; skipped if that
cannot be fetched).  The installed package must then find its shipped scenarios and studies
by name (package data), register its rigs and identifiers, and run a scenario end to end.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import sysconfig
import venv
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
#: Building and installing take about 10 s; the run simulates 1 s of the beam (about 10 s).
TIMEOUT_S = 600


def _clean_env() -> dict[str, str]:
    """This environment without what would point Python or the testbed at the checkout."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "TESTBED_SCENARIOS",
                                                             "TESTBED_STUDIES", "TESTBED_CACHE")}
    env.update(OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1", MPLBACKEND="Agg",
               PIP_DISABLE_PIP_VERSION_CHECK="1")
    return env


def _pip_installs_into_other_interpreters() -> bool:
    """Whether this interpreter's pip has ``--python`` (pip 22.3): it then installs the wheel into
    the fresh environment, which needs no pip of its own (``ensurepip`` costs about 7 s of CPU)."""
    from importlib.metadata import PackageNotFoundError, version  # (importing pip would warn)

    try:
        major, minor = [*version("pip").split("."), "0"][:2]
    except PackageNotFoundError:
        return False
    return major.isdigit() and minor.isdigit() and (int(major), int(minor)) >= (22, 3)


def _setuptools_new_enough() -> bool:
    try:
        import setuptools
    except ImportError:
        return False
    return int(setuptools.__version__.split(".")[0]) >= 77


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    # built from a copy: setuptools writes build/ and *.egg-info next to the sources
    src = tmp_path_factory.mktemp("src") / "sysid-testbed"
    shutil.copytree(ROOT, src, symlinks=True, ignore=shutil.ignore_patterns(
        ".git", ".venv", ".cache", "out", "build", "*.egg-info", "__pycache__", ".pytest_cache"))
    cmd = [sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(out), str(src)]
    if _setuptools_new_enough():
        cmd.insert(4, "--no-build-isolation")
    r = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT_S, env=_clean_env())
    if r.returncode != 0 and "--no-build-isolation" not in cmd and (
            "No matching distribution" in r.stderr or "Could not find a version" in r.stderr
            or "NewConnectionError" in r.stderr):
        pytest.skip("the build backend (setuptools>=77) cannot be fetched here: " + r.stderr[-300:])
    assert r.returncode == 0, r.stderr[-3000:]
    (whl,) = out.glob("sysid_testbed-*.whl")
    return whl


def test_wheel_holds_every_package_and_the_shipped_files(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    for top in ("testbed", "models", "identify"):
        for init in (ROOT / top).rglob("__init__.py"):
            rel = init.relative_to(ROOT).as_posix()
            assert rel in names, f"{rel} is not in the wheel: list its package in pyproject.toml"
    for folder in ("scenarios", "studies"):
        for f in (ROOT / folder).glob("*.toml"):
            assert f"testbed/data/{folder}/{f.name}" in names, f


@pytest.mark.slow
def test_installed_wheel_runs_from_anywhere(wheel, tmp_path):
    env_dir = tmp_path / "venv"
    own_pip = not _pip_installs_into_other_interpreters()
    venv.EnvBuilder(with_pip=own_pip).create(env_dir)
    py = env_dir / "bin" / "python"
    env = _clean_env()
    pip = [str(py), "-m", "pip"] if own_pip else [sys.executable, "-m", "pip", "--python", str(py)]
    r = subprocess.run([*pip, "install", "-q", "--no-deps", "--no-index", str(wheel)],
                       capture_output=True, text=True, timeout=TIMEOUT_S, env=env)
    assert r.returncode == 0, r.stderr[-3000:]  # before the .pth: pip must not see another copy
    # the dependencies of this interpreter, without copying or downloading them
    site_dir = subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_path('purelib'))"],
                              capture_output=True, text=True, check=True).stdout.strip()
    deps = sysconfig.get_path("purelib")
    # (an editable install of this project there, e.g. the development .venv's, must not shadow
    # the wheel: its import hooks are dropped)
    Path(site_dir, "_testbed_deps.pth").write_text(
        f"import site, sys; site.addsitedir({deps!r}); "
        "sys.meta_path[:] = [f for f in sys.meta_path if 'sysid_testbed' not in "
        "(getattr(f, '__module__', '') or '')]; "
        "sys.path_hooks[:] = [h for h in sys.path_hooks if 'sysid_testbed' not in "
        "(getattr(h, '__module__', '') or '')]\n")
    work = tmp_path / "elsewhere"
    work.mkdir()

    def run(*args: str) -> subprocess.CompletedProcess:
        return subprocess.run(args, cwd=work, env=env, capture_output=True, text=True, timeout=TIMEOUT_S)

    where = run(str(py), "-c", "import testbed, identify, models; "
                               "print(testbed.__file__); print(testbed.__version__)")
    assert where.returncode == 0, where.stderr[-2000:]
    assert where.stdout.splitlines()[0].startswith(str(env_dir)), where.stdout  # not the checkout
    testbed = str(env_dir / "bin" / "testbed")
    assert run(testbed, "--version").stdout.split()[-1] == where.stdout.splitlines()[1]
    listed = run(testbed, "list")
    assert listed.returncode == 0, listed.stderr[-2000:]
    for f in (ROOT / "scenarios").glob("*.toml"):
        assert f"\n{f.stem}\t" in listed.stdout, f.stem
    assert "\nls_sindy\tstructural\t" in listed.stdout and "\tbuiltin" in listed.stdout
    study = run(str(py), "-c", "import testbed; print(testbed.load_study('smoke').n_cells())")
    assert study.returncode == 0 and int(study.stdout) > 0, study.stderr[-2000:]
    ran = run(testbed, "run", "cantilever_stiff_impact_lsq", "--no-figures", "--cache", str(tmp_path / "c"),
              "-o", str(work / "runs"))
    assert ran.returncode == 0, ran.stdout[-2000:] + ran.stderr[-2000:]
    latest = json.loads((work / "runs" / "cantilever_stiff_impact_lsq" / "latest.json").read_text())
    assert (work / "runs" / "cantilever_stiff_impact_lsq" / latest["run"] / "run.json").is_file()
    assert not (work / "scenarios").exists()
