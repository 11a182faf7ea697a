"""A fourth rig kind added from outside the project runs end to end, touching nothing generic.

The kind ("thermal": a lumped thermal mass, ``tests/thermal_kind.py``) declares its typed
truth, score catalogue, signal chain, scorer, a rig and an identifier through the public names
of ``testbed`` only.  Its scenario, a dict built here, is validated, generated, measured,
identified, scored, saved and read back, and a study sweeps it; the generic code reaches the
kind only through its registries.
"""

import sys

import pytest

import testbed
from testbed.core import kinds, truth
from testbed.pipeline import signal_chain
from testbed.scoring import scorers

PLUGIN = "tests.thermal_kind"


@pytest.fixture(scope="module", autouse=True)
def plugin():
    """The kind joins the registries for this module's tests only (others list every kind)."""
    rigs, idents = testbed.RIGS.snapshot(), testbed.IDENTIFIERS.snapshot()
    testbed.load_plugins([PLUGIN])
    yield
    testbed.RIGS.restore(rigs)
    testbed.IDENTIFIERS.restore(idents)
    for reg in (truth.TRUTH_TYPES, kinds.METRICS, signal_chain.SIGNAL_CHAINS,
                signal_chain.SIGNAL_SCHEMAS, scorers.SCORERS):
        reg.pop("thermal", None)
    sys.modules.pop(PLUGIN, None)


def scenario(noise=0.0, **score):
    return testbed.scenario_from_dict({
        "scenario": {"name": "thermal_square", "rig": "thermal_mass"},
        "rig": {"R": 2.0, "C": 50.0, "T0": 1.0},
        "simulation": {"duration": 600.0, "sample_rate": 2.0},
        "excitation": {"type": "square", "power": 5.0, "period": 200.0},
        "noise": {"rms_percent": noise}, "identify": {"method": "thermal_least_squares"},
        "score": score})


def test_a_fourth_kind_runs_end_to_end(tmp_path):
    # On clean data the only error is the chain's rate: central differences straddle each step
    # of the heating power, where T' jumps by P / C = 0.1 K/s, and average its two sides on the
    # two samples around each of the 6 steps (12 of 1200 samples).  Measured: C 0.62 %, R
    # 0.24 %, simulated temperature 0.014 K RMS (of a 9 K swing).  Bars at about 3x those; a
    # wrong sign, unit, start or swapped R and C misses them by decades.
    res = testbed.run_scenario(scenario(R_error_max=0.01, C_error_max=0.02, temp_rmse_max=0.05),
                               cache=str(tmp_path / "cache"))
    assert res.passed, res.checks
    assert set(res.scores.values) == set(testbed.KIND_METRICS["thermal"])
    run = testbed.save_new_run(res, tmp_path / "runs")
    assert testbed.resolve_run(str(run), tmp_path / "runs") is not None


def test_a_fourth_kind_refuses_a_misspelt_score_and_a_foreign_identifier():
    with pytest.raises(testbed.TestbedError, match="R_eror_max"):
        scenario(R_eror_max=0.1)
    with pytest.raises(testbed.TestbedError, match="thermal"):
        testbed.scenario_from_dict({
            "scenario": {"name": "thermal_ls", "rig": "thermal_mass"},
            "identify": {"method": "ls_sindy"}})


SCENARIO_TOML = """
[scenario]
name = "thermal_square"
rig = "thermal_mass"
[identify]
method = "thermal_least_squares"
"""


def test_a_fourth_kind_sweeps_and_reports(tmp_path):
    (tmp_path / "thermal_square.toml").write_text(SCENARIO_TOML)
    (tmp_path / "thermal_study.toml").write_text(
        '[study]\nname = "thermal_study"\nscenarios = ["thermal_square.toml"]\n'
        'noise = [0.0, 1.0]\nseeds = [0]\nidentifiers = ["thermal_least_squares"]\n'
        '[thresholds.thermal_least_squares]\nR_error_max = 0.01\n')
    out = testbed.run_sweep(tmp_path / "thermal_study.toml", results=tmp_path / "r.parquet",
                            cache_dir=tmp_path / "cache", verbose=False)
    rows = testbed.read_results(out)
    got = sorted((r["identifier"], r["noise"], r["status"]) for r in rows)
    assert got == [("thermal_least_squares", 0.0, "ok"), ("thermal_least_squares", 1.0, "ok")]
    res = testbed.run_scenario(tmp_path / "thermal_square.toml", cache=str(tmp_path / "cache"))
    run = testbed.save_new_run(res, tmp_path / "runs")
    from testbed.reporting.report import write_report

    page = write_report(run, tmp_path / "report")
    assert "R_error" in page.read_text()
