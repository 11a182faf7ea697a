"""The cold-cache economies of the test run itself (tests/conftest.py) stay in effect."""


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
    import re
    import tomllib
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    recipe = re.search(r"^test:.*\n((?:\t.*\n)+)", (root / "Makefile").read_text(), re.M)
    assert recipe, "Makefile has no test target"
    lines = recipe.group(1).splitlines()
    compile_at = [i for i, line in enumerate(lines) if "-m compileall" in line]
    pytest_at = [i for i, line in enumerate(lines) if "-m pytest" in line]
    assert compile_at and pytest_at and compile_at[0] < pytest_at[0], lines
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
