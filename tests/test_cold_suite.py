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
