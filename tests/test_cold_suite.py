"""The cold-cache economies of the test run itself (tests/conftest.py) stay in effect."""

from pathlib import Path


def _test_recipe(*fragments: str) -> tuple[list[str], ...]:
    """The command lines of the Makefile's ``test`` recipe, and for each of ``fragments`` the
    indices of the lines holding it."""
    import re

    root = Path(__file__).resolve().parent.parent
    recipe = re.search(r"^test:.*\n((?:\t.*\n)+)", (root / "Makefile").read_text(), re.M)
    assert recipe, "Makefile has no test target"
    lines = recipe.group(1).splitlines()
    return (lines, *([i for i, line in enumerate(lines) if f in line] for f in fragments))


def test_contrast_and_scored_runs_share_one_group():
    """The Eq. 21 contrast reads the runs of two scored tests (conftest ``scenario_run``): they
    must be in one xdist group, or each worker fits them again."""
    import importlib.util
    from pathlib import Path

    here = Path(__file__).parent / "scenarios"
    mods = {}
    for name in ("test_scored", "test_cubic_contrast"):
        spec = importlib.util.spec_from_file_location(f"_cold_{name}", here / f"{name}.py")
        mods[name] = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mods[name])
    contrast, scored = mods["test_cubic_contrast"], mods["test_scored"]
    assert set(scored.SHARED) == {contrast.LINEAR, contrast.NONLINEAR}
    (mark,) = contrast.test_linear_beam_cubic_matrix_hundredfold_smaller.pytestmark
    assert mark.name == "xdist_group" and mark.args == ("eq21",)


def test_make_test_byte_compiles_every_package_before_pytest():
    """``make test`` compiles the project's sources before pytest starts (Makefile: with
    PYTHONDONTWRITEBYTECODE set, each of the suite's processes compiled what it imported again):
    every top-level package the wheel ships, and the benchmarks and tests the suite imports."""
    import tomllib

    lines, compile_at, pytest_at = _test_recipe("-m compileall", "-m pytest")
    assert compile_at and pytest_at and compile_at[0] < pytest_at[0], lines
    root = Path(__file__).resolve().parent.parent
    folders = set(lines[compile_at[0]].split())
    packages = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]
    tops = {p.split(".")[0] for p in packages}
    assert tops | {"benchmarks", "tests"} <= folders, sorted(tops - folders)


def test_demo_reads_the_runs_of_the_eq21_group():
    """The demo test answers ``run_demo``'s two fits with the runs of the scored tests and the
    Eq. 21 contrast (conftest ``scenario_run``): it must be in their xdist group, or it fits them
    again on its own worker."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).parent / "testbed" / "reporting" / "test_demo.py"
    spec = importlib.util.spec_from_file_location("_cold_test_demo", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    (mark,) = mod.test_demo_runs_scores_reports_and_states_the_contrast.pytestmark
    assert mark.name == "xdist_group" and mark.args == ("eq21",)
    from testbed.reporting.demo import EQ21_PAIR

    scored = importlib.util.spec_from_file_location("_cold_scored", Path(__file__).parent / "scenarios"
                                                    / "test_scored.py")
    smod = importlib.util.module_from_spec(scored)
    scored.loader.exec_module(smod)
    assert set(EQ21_PAIR) == set(smod.SHARED)


def test_make_test_writes_the_rewritten_test_modules_before_pytest():
    """``make test`` runs tests/_rewrite_ahead.py after compiling and before pytest (each worker
    rewrote every test module again: about half of its collection)."""
    lines, compile_at, ahead, pytest_at = _test_recipe("-m compileall", "tests/_rewrite_ahead.py",
                                                       "-m pytest")
    assert compile_at and ahead and compile_at[0] < ahead[0], lines
    assert ahead and pytest_at and ahead[0] < pytest_at[0], lines


def test_rewrite_ahead_writes_what_pytest_would_and_pytest_reads_it(request, tmp_path):
    """What tests/_rewrite_ahead.py writes is pytest's own rewrite of the module under this run's
    configuration (the same code object), pytest's reader accepts it, a module edited afterwards is
    stale again, and every module this run collected is among those it rewrites."""
    import importlib.util
    import shutil
    from pathlib import Path

    from _pytest.assertion import rewrite

    here = Path(__file__).resolve().parent
    spec = importlib.util.spec_from_file_location("_cold_rewrite_ahead", here / "_rewrite_ahead.py")
    ahead = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ahead)

    modules = set(ahead.rewritten_modules([here]))
    collected = {Path(str(item.path)).resolve() for item in request.session.items}
    assert collected <= modules, sorted(collected - modules)[:5]
    assert here / "conftest.py" in modules

    src = tmp_path / "test_copy.py"
    shutil.copy(Path(__file__), src)
    assert not ahead.up_to_date(src)
    assert ahead.rewrite_one(src)
    assert ahead.up_to_date(src)
    written = rewrite._read_pyc(src, ahead.cache_file(src))
    _, own = rewrite._rewrite_test(src, request.config)  # as pytest's import hook calls it
    # code objects compare by their instructions, constants (nested code included), names and
    # line tables; marshal's bytes are not compared, as they depend on reference counts
    assert written == own and written.co_filename == own.co_filename == str(src)
    src.write_text(src.read_text() + "\n# edited\n")
    assert not ahead.up_to_date(src)


def test_the_conformance_group_is_dealt_first_and_the_sgd_fits_after_the_wheel_and_server():
    """The first work units (conftest ``_DEALT_FIRST``): the conformance group, which compiles
    numba's SGD-SINDy kernels, then on the other worker the wheel and server groups, then the
    scored ``cantilever_soft_impact_150N`` (an ``sgd_sindy`` fit, dealt by its length alone next to
    the conformance group: both workers compiled the SGD kernels).  Each name is a real work unit
    of the suite, and the rest follow longest first."""
    import importlib.util
    import tomllib

    here = Path(__file__).resolve().parent
    spec = importlib.util.spec_from_file_location("_cold_conftest", here / "conftest.py")
    conf = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(conf)
    first = conf._DEALT_FIRST
    assert first == ("tests/identify/test_conformance.py", "tests/test_wheel.py", "server",
                     f"{conf._SCORED}cantilever_soft_impact_150N]")
    others = sorted(conf._COLD_SECONDS, key=lambda unit: -conf._COLD_SECONDS[unit])
    units = [u for u in others if u not in first] + list(reversed(first)) + ["tests/not_listed.py"]
    order = sorted(units, key=conf._deal_rank)
    assert order[:4] == list(first), order[:6]
    rest = [conf._COLD_SECONDS.get(u, 0.0) for u in order[4:]]
    assert rest == sorted(rest, reverse=True) and order[-1] == "tests/not_listed.py"
    # the names are the suite's work units: two modules, test_server's group, a scored scenario
    # that fits SGD-SINDy
    assert (here / "identify" / "test_conformance.py").is_file() and (here / "test_wheel.py").is_file()
    assert 'pytest.mark.xdist_group("server")' in (here / "testbed" / "test_server.py").read_text()
    scenario = tomllib.loads((here.parent / "scenarios" / "cantilever_soft_impact_150N.toml").read_text())
    assert scenario["identify"]["method"] == "sgd_sindy" and scenario.get("score")


def test_compile_venv_writes_what_compileall_writes(tmp_path):
    """tests/_compile_venv.py (the install's byte-compile, run as the Makefile runs it) writes the
    files ``compileall -qq -j 0 -x '/tests?/'`` writes, byte for byte: not a dependency's test
    folder, not ``__pycache__``, not through a symlinked folder, and a file that does not compile
    stops nothing."""
    import compileall
    import marshal
    import re
    import shutil
    import subprocess
    import sys

    files = {"pkg/__init__.py": "", "pkg/mod.py": "X = 1\n", "pkg/sub/deep.py": "def f():\n    return 2\n",
             "pkg/tests/test_x.py": "Y = 1\n", "pkg/test/t.py": "Y = 2\n", "broken.py": "def (\n",
             "notes.txt": "x\n", "pkg/__pycache__/stray.py": "Z = 3\n"}
    src = tmp_path / "a" / "lib"
    for rel, text in files.items():
        (src / rel).parent.mkdir(parents=True, exist_ok=True)
        (src / rel).write_text(text)
    (src / "linked").symlink_to(src / "pkg", target_is_directory=True)
    other = tmp_path / "b" / "lib"
    shutil.copytree(src, other, symlinks=True)  # copy2: the same mtimes, so the same .pyc bytes

    r = subprocess.run([sys.executable, str(Path(__file__).parent / "_compile_venv.py"), str(src)],
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 0 and not r.stdout and not r.stderr, r
    compileall.compile_dir(str(other), quiet=2, rx=re.compile(r"/tests?/"), workers=2)

    def written(root):
        # the header (magic, flags, source mtime and size) and the code object; code objects
        # compare without their file name, which names each copy's own folder
        return {str(p.relative_to(root)): (p.read_bytes()[:16], marshal.loads(p.read_bytes()[16:]))
                for p in root.rglob("*.pyc")}

    mine, theirs = written(src), written(other)
    assert mine == theirs and len(mine) == 3, sorted(mine)  # __init__, mod, deep


def test_the_install_puts_the_build_systems_requirements_in_the_venv():
    """The Makefile's install adds pyproject's ``[build-system] requires`` to the venv in both of
    its branches (uv, pip), so tests/test_wheel.py builds with ``--no-build-isolation`` instead
    of pip making an isolated build environment and fetching setuptools on each run; and the
    command that reads them names exactly those requirements."""
    import re
    import subprocess
    import sys
    import tomllib

    root = Path(__file__).resolve().parent.parent
    text = (root / "Makefile").read_text()
    define = re.search(r"^BUILD_REQUIRES := \$\(BIN\)/python ((?:[^\n]*\\\n)*[^\n]*)$", text, re.M)
    assert define, "Makefile defines no BUILD_REQUIRES"
    recipe = re.search(r"^\$\(STAMP\):.*\n((?:\t.*\n)+)", text, re.M)
    assert recipe, "Makefile has no install recipe"
    installs = [ln for ln in recipe.group(1).splitlines() if "install" in ln and '-e ".[dev]"' in ln]
    assert len(installs) == 2 and all("$$($(BUILD_REQUIRES))" in ln for ln in installs), installs
    # the variable's command as make hands it to the shell (a backslash-newline is one space)
    command = re.sub(r"\\\n\s*", " ", define.group(1)).strip()
    assert command.startswith("-c "), command
    code = command[3:].strip().strip('"')
    out = subprocess.run([sys.executable, "-c", code], cwd=root, capture_output=True, text=True,
                         check=True).stdout.split()
    want = tomllib.loads((root / "pyproject.toml").read_text())["build-system"]["requires"]
    assert out == want and out, out
