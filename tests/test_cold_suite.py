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
