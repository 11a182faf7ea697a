"""Summary: median and interquartile range per identifier and noise level, pass rate, rich table."""

from __future__ import annotations

import io
import math

import numpy as np
from rich.console import Console

from testbed.core import errors
from testbed.studies.results import write_part, write_rows
from testbed.studies.statistics import (
    failed_cells_line,
    failure_kind,
    missed_bars_line,
    print_summary,
    scored,
    summarize,
)
from testbed.studies.sweep import _error_text, error_name

CHECKS = '[{"metric": "trac", "bound": "min", "threshold": 0.75}]'


def row(cell, identifier, noise, seed, status="ok", passed=True, scenario="s", checks=CHECKS,
        error="RuntimeError: diverged (x.py:1)", **scores):
    return {"study": "t", "cell": cell, "scenario": scenario, "rig": "r", "noise": noise,
            "seed": seed, "identifier": identifier, "params": "{}", "status": status,
            "error": "" if status == "ok" else error, "fit_time": 1.0,
            "data_time": 0.0, "cell_time": 1.0, "passed": passed,
            "checks": checks if "(x.py:1)" not in error or status == "ok" else "[]",  # a crash: none
            "versions": "{}",
            "commit": "x", "dataset_hash": "h", **scores}


def test_median_iqr_and_pass_rate(tmp_path):
    res = tmp_path / "r.parquet"
    trac = [0.9, 0.8, 0.95, 0.7]
    rows = [row(f"a{i}", "ls", 1.0, i, passed=v > 0.75, trac=v, mac=1.0) for i, v in enumerate(trac)]
    rows.append(row("a9", "ls", 1.0, 9, status="failed", passed=False, trac=float("nan"), mac=float("nan")))
    rows += [row("b0", "ls", 0.0, 0, trac=1.0, mac=1.0)]
    write_rows(res, rows)
    write_part(res, row("p0", "pi", 5.0, 0, angle_rmse=0.2))  # an unconsolidated row counts too
    s = {(x["identifier"], x["noise"]): x for x in summarize(res)}
    assert list(s) == [("ls", 0.0), ("ls", 1.0), ("pi", 5.0)]
    g = s[("ls", 1.0)]
    assert (g["cells"], g["ok"], g["failed"]) == (5, 4, 1)
    assert g["pass_rate"] == 3 / 5  # 0.9, 0.8 and 0.95 pass; the failed cell counts as not passed
    q25, med, q75 = np.percentile(trac, [25, 50, 75])  # over the ok cells only
    assert (g["trac_q25"], g["trac_median"], g["trac_q75"], g["trac_n"]) == (q25, med, q75, 4)
    assert math.isnan(s[("pi", 5.0)]["trac_median"]) and s[("pi", 5.0)]["trac_n"] == 0
    assert s[("pi", 5.0)]["angle_rmse_median"] == 0.2

    buf = io.StringIO()
    print_summary(res, console=Console(file=buf, width=100))
    out = buf.getvalue()
    assert "noise 1 %" in out and "60 %" in out and "5 (1)" in out
    assert f"{med:.3g}" in out and f"[{q25:.3g}, {q75:.3g}]" in out
    assert "RuntimeError: diverged" in out and "crash: RuntimeError: 1" in out
    pi_table = out[out.index("pi  (s)"):]
    # no trac row in pi's table (it has no trac score); its missed trac bar (NaN) is counted
    assert "angle_rmse" in pi_table and "│ trac " not in pi_table.split("failed cell")[0]
    assert "failed bar trac: 1" in pi_table


def test_no_results(tmp_path):
    buf = io.StringIO()
    assert print_summary(tmp_path / "none.parquet", console=Console(file=buf, width=400)) == []
    assert "no results" in buf.getvalue()


def test_pass_rate_only_against_own_bars_and_failure_reasons_by_family(tmp_path):
    res = tmp_path / "r.parquet"
    rows = [
        # identifier "a" has bars on the members of family f: judged
        row("a0", "a", 0.0, 0, scenario="f__000", passed=True, trac=0.95),
        row("a1", "a", 0.0, 0, scenario="f__001", status="failed", passed=False,
            error="unstable: pole with real part +3 1/s; diverged: blew up", trac=float("nan")),
        row("a2", "a", 0.0, 0, scenario="f__002", passed=False, trac=0.5),
        # identifier "b" was held to nothing: no pass rate, never a's bars
        row("b0", "b", 0.0, 0, scenario="f__000", passed=False, checks="[]", trac=0.2),
        row("b1", "b", 0.0, 0, scenario="f__001", status="failed", passed=False,
            error="fit failed: singular", checks="[]", trac=float("nan")),
        row("c0", "a", 0.0, 0, scenario="hand", passed=True, trac=0.99),
        # a crash has no checks; it counts (as not passed) where its identifier is held to bars
        row("a3", "a", 0.0, 0, scenario="f__003", status="failed", passed=False, trac=float("nan")),
    ]
    write_rows(res, rows)
    s = {(x["identifier"], x["noise"]): x for x in summarize(res)}
    assert s[("a", 0.0)]["judged"] == 5 and s[("a", 0.0)]["pass_rate"] == 2 / 5
    assert s[("b", 0.0)]["judged"] == 0 and math.isnan(s[("b", 0.0)]["pass_rate"])
    # (a2 finished and missed its trac bar with no reason: counted by the bar it missed)
    assert s[("a", 0.0)]["failures"] == {"crash: RuntimeError": 1, "diverged": 1, "unstable": 1,
                                         "failed bar trac": 1}
    assert s[("b", 0.0)]["failures"] == {"fit failed": 1}
    fam = {(x["family"], x["identifier"]): x for x in summarize(res, by="family")}
    assert set(fam) == {("f", "a"), ("f", "b"), ("hand", "a")}
    assert fam[("f", "a")]["pass_rate"] == 1 / 4 and fam[("hand", "a")]["pass_rate"] == 1.0
    per = {(x["scenario"], x["identifier"]) for x in summarize(res, by="scenario")}
    assert ("f__001", "b") in per and len(per) == 7

    buf = io.StringIO()
    print_summary(res, console=Console(file=buf, width=120), by="family")
    out = buf.getvalue()
    assert "no bars" in out and "fit failed: 1" in out and "25 % of 4" in out


def test_medians_stand_on_every_scored_cell_not_the_passing_ones_alone(tmp_path):
    # round 20's kinetics at 1.5 % (seed 114): one cell passed at coef_error 0.0232, four failed
    # "wrong equation" with their scores (0.0519, 4.07, 5.89, 88.1); the summary showed 0.0232
    # [0.0232, 0.0232], the passing cell alone
    res = tmp_path / "r.parquet"
    checks = '[{"metric": "coef_error", "bound": "max", "threshold": 0.05}]'
    why = "wrong equation: coef_error {} above 0.05"
    rows = [row("k0", "dyn", 1.5, 0, checks=checks, coef_error=0.0232)]
    rows += [row(f"k{i}", "dyn", 1.5, i, status="failed", passed=False, checks=checks,
                 error=why.format(v), coef_error=v)
             for i, v in enumerate([0.0519, 4.07, 5.89, 88.1], start=1)]
    # a model never simulated keeps its reason and no score; a crash is no scored cell (its
    # value here stands for anything a crash might have left in the row)
    rows.append(row("k5", "dyn", 1.5, 5, status="failed", passed=False, checks=checks,
                    error="fit failed: non-physical model", coef_error=float("nan")))
    rows.append(row("k6", "dyn", 1.5, 6, status="failed", passed=False, coef_error=1e9))
    write_rows(res, rows)
    (s,) = summarize(res)
    assert (s["cells"], s["ok"], s["failed"], s["scored"]) == (7, 1, 6, 6)
    assert (s["coef_error_q25"], s["coef_error_median"], s["coef_error_q75"], s["coef_error_n"]) \
        == (*np.percentile([0.0232, 0.0519, 4.07, 5.89, 88.1], [25, 50, 75]), 5)
    assert s["pass_rate"] == 1 / 7
    buf = io.StringIO()
    print_summary(res, console=Console(file=buf, width=120))
    out = buf.getvalue()
    assert "4.07" in out and "5 of 6 cells" in out and "of the scored cells" in out


def test_a_cell_that_missed_a_bar_with_no_reason_is_counted_by_the_bar_it_missed(tmp_path):
    # round 23's b23_soft_s2neartip at 2 % (seed 142), ls_sindy: mode 2 10.9 % off the 2.6 % bar,
    # the scorer's reasons none (the record holds the mode: sgd_sindy meets it), the row "ok" with
    # an empty error; the summary showed "92 % of 12" beside "failure reasons -" and listed no cell
    res = tmp_path / "r.parquet"
    bars = ('[{"metric": "trac", "value": 0.996, "bound": "min", "threshold": 0.9}, '
            '{"metric": "freq_error_mode2", "value": 0.109, "bound": "max", "threshold": 0.026}]')
    rows = [row("m0", "ls", 2.0, 142, passed=False, checks=bars, trac=0.996, freq_error_mode2=0.109),
            row("m1", "ls", 2.0, 143, passed=True, checks=bars.replace("0.109", "0.001"), trac=0.996,
                freq_error_mode2=0.001),
            # a NaN score misses its bar too (never a pass); a cell held to nothing names none
            row("m2", "ls", 2.0, 144, passed=False, checks=CHECKS, trac=float("nan")),
            row("m3", "free", 2.0, 142, passed=False, checks="[]", trac=0.1)]
    write_rows(res, rows)
    s = {x["identifier"]: x for x in summarize(res)}
    assert s["ls"]["failures"] == {"failed bar freq_error_mode2": 1, "failed bar trac": 1}
    assert s["ls"]["pass_rate"] == 1 / 3 and s["free"]["failures"] == {}
    buf = io.StringIO()
    print_summary(res, console=Console(file=buf, width=200))
    out = buf.getvalue()
    assert "failed bar freq_error_mode2: 1" in out
    assert "2 cell(s) missed bars the scorer gives no reason for" in out
    assert "s noise=2 seed=142 ls: freq_error_mode2 0.109 above 0.026" in out
    assert "s noise=2 seed=144 ls: trac nan below 0.75" in out
    # and the sweep's last lines say so (the sweep said nothing: its results line alone)
    assert missed_bars_line(rows).startswith("2 finished cell(s) missed bars the scorer gives no reason")
    assert missed_bars_line(rows[1:2]) is None and failed_cells_line(rows) is None


def test_a_finished_cell_whose_checks_cannot_be_judged_is_still_counted(tmp_path):
    # review 24b: the pass rate judges a stored check whose value differs from the row's score
    # column as NaN (and an unreadable check as holding nothing), while the missed-bar count
    # trusted the stored value: such rows showed a pass rate under 100 % beside "failure
    # reasons -" and were named nowhere (older or hand-written results files)
    res = tmp_path / "r.parquet"
    edited = '[{"metric": "trac", "value": 0.95, "bound": "min", "threshold": 0.75}]'
    null = '[{"metric": "trac", "value": null, "bound": "min", "threshold": 0.75}]'
    upper = '[{"metric": "trac", "value": 0.9, "bound": "MAX", "threshold": 0.5}]'
    rows = [row("e0", "ls", 1.0, 1, passed=False, checks=edited, trac=0.5),
            row("e1", "ls", 1.0, 2, passed=False, checks=null, trac=0.5),
            row("e2", "ls", 1.0, 3, passed=False, checks=upper, trac=0.9),
            row("e3", "ls", 1.0, 4, passed=True, trac=0.9)]
    write_rows(res, rows)
    (s,) = summarize(res)
    assert s["pass_rate"] == 1 / 4
    assert s["failures"] == {"failed bar trac": 2, "failed bar (checks unreadable)": 1}
    assert missed_bars_line(rows).startswith("3 finished cell(s) missed bars")
    buf = io.StringIO()
    print_summary(res, console=Console(file=buf, width=200))
    out = buf.getvalue()
    assert "seed=1 ls: trac nan below 0.75" in out  # the edited value judged as NaN
    assert "seed=2 ls: checks unreadable" in out
    assert "seed=3 ls: trac 0.9 above 0.5" in out  # any bound but "min" is a maximum


def test_a_clipped_sensors_reason_is_a_named_kind():
    # session 21: a failed bar on a record with a clipped sensor reads "clipped: ..." (the
    # scorer's clipping_failures); counted as "other" it named nothing
    from testbed.studies.statistics import failure_kind

    assert failure_kind("clipped: sensor acc1 is clipped at +23.1 m/s^2: ...") == ["clipped"]


def test_a_trac_failure_named_by_channel_is_a_named_kind():
    # session 24 (score24): a failed TRAC bar with one channel at the record's floor and another
    # off it is named channel by channel; without its head it was counted as "other"
    from testbed.studies.statistics import failure_kind

    why = ("TRAC by channel against the bar 0.9: the identified model's own failure on acc2 0.541 "
           "(the truth's own 0.973)")
    assert failure_kind(why) == ["TRAC by channel"]


REFUSED = ("RigError: key 'excitation.amplitude, excitation.f_max, excitation.kp, excitation.kd': "
           "value [1.5, 1.5, 10.0, 2.0]: the motion under excitation 'multisine' is not usable "
           "(found only by simulating it): fivebar (pinocchio): at t = 6.6170 s the transmission "
           "angle (links 2-3 at E) is 150.00 deg; allowed 30-150 deg (rig.py:323)")


def test_a_scenario_the_rig_refuses_is_counted_refused_not_crashed(tmp_path):
    """Round 21's fb21_ms_amp1p5 (the multisine at 1.5 N m) at 1 / 2 %: the rig refuses the
    motion in one line naming the keys (a transmission angle of 150 deg at 6.6 s), and the
    sweep's last line said "2 crashed", the summary "crash: RigError": a refusal of what the
    cell asks, not a bug."""
    assert failure_kind(REFUSED) == ["refused: RigError"]
    assert failure_kind("BudgetError: scenario 'x': 3e9 steps (scenario.py:9)") == [
        "refused: BudgetError"]
    assert failure_kind("ValueError: boom (x.py:3)") == ["crash: ValueError"]
    assert failure_kind("TestbedError: what (x.py:3)") == ["crash: TestbedError"]  # not a refusal
    line = failed_cells_line([{"status": "failed", "error": REFUSED},
                              {"status": "failed", "error": "ValueError: boom (x.py:3)"}])
    assert line.startswith("2 cell(s) failed (1 crashed, 1 refused by the rig or the scenario;")
    res = tmp_path / "r.parquet"
    rows = [row("a0", "pi", 1.0, 0, trac=0.9),
            row("a1", "pi", 1.0, 1, status="failed", passed=False, error=REFUSED, checks="[]",
                trac=float("nan"))]
    write_rows(res, rows)
    (g,) = summarize(res)
    assert g["failures"] == {"refused: RigError": 1} and g["scored"] == 1
    assert g["judged"] == 2 and g["pass_rate"] == 0.5  # held to bars elsewhere: not passed
    assert not scored(rows[1])


def test_a_refusal_is_told_by_its_class_not_by_a_name_it_shares():
    """The sweep records a failed cell's exception by name, and the name decides refused or
    crashed (review 22b): a plugin's own subclass of RigError was counted a crash, and another
    module's class called RigError a refusal.  Now a subclass is recorded by the nearest class
    of testbed.core.errors, a namesake by its qualified name; a line of refusals alone does not
    offer --retry-failed, which would refuse them again."""
    class PluginRigError(errors.RigError):
        pass

    class RigError(Exception):  # a namesake, not ours
        pass

    for e, kind in ((PluginRigError("no"), "refused: RigError"), (errors.RigError("no"),
                    "refused: RigError"), (RigError("no"), None), (ValueError("no"),
                                                                    "crash: ValueError")):
        try:
            raise e
        except Exception as caught:
            text = _error_text(caught)
        got = failure_kind(text)
        assert got == [kind] if kind else got[0].startswith("crash: ") and "RigError" in got[0]
    assert error_name(PluginRigError("no")) == "RigError: PluginRigError"
    only = failed_cells_line([{"status": "failed", "error": REFUSED}])
    assert "--retry-failed" not in only
    both = failed_cells_line([{"status": "failed", "error": REFUSED},
                              {"status": "failed", "error": "ValueError: boom (x.py:3)"}])
    assert "--retry-failed` runs them again (a refused cell is refused again" in both
