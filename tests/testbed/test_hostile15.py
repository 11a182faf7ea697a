"""Fifteenth malformed-input round: the findings of ``benchmarks/hostile15.py`` (docs/history.md,
malformed-input audits), each fixed in the layer that owns it.
"""

from __future__ import annotations

import json
import re

import pytest

from benchmarks._hostile import results_row
from testbed.core.errors import InputError

# ------------------------------------------------------------------ results files


def _v1(path, rows):
    """A results file of format ``/1`` (no checksums: read as it was written) holding ``rows``."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    from testbed.studies.results import BASE_COLUMNS, DIGEST, TAIL_COLUMNS

    cols = {name: pa.array([r.get(name) for r in rows], getattr(pa, t)())
            for name, t in {**BASE_COLUMNS, **TAIL_COLUMNS}.items() if name != DIGEST}
    cols["coef_error"] = pa.array([r["coef_error"] for r in rows], pa.float64())
    table = pa.table(cols).replace_schema_metadata({"format": "sysid-testbed-results/1", "study": "s"})
    pq.write_table(table, path)
    return path


@pytest.mark.parametrize("checks", ["3", '{"metric": "coef_error"}', '"text"', "not json", "null"])
def test_report_and_summary_of_results_whose_checks_are_not_a_list_end_in_their_tables(tmp_path, checks):
    from testbed.reporting.report import write_report
    from testbed.studies.results import read_results, stored_checks
    from testbed.studies.statistics import summarize

    # `testbed report` of a /1 file whose checks were "3" was an internal error (TypeError
    # iterating an int): every reader parses the column through one function, and a value
    # that is not a JSON list holds no check (the row does not pass), as text not JSON did
    path = _v1(tmp_path / "r.parquet", [results_row(checks=checks)])
    (row,) = read_results(path)
    assert stored_checks(row) is None and row["passed"] is False
    (s,) = summarize(path)
    assert s["cells"] == 1 and s["judged"] == 0  # held to no bar: pass rate NaN, as "[]"
    write_report(path, tmp_path / "rep")
    assert (tmp_path / "rep" / "report.md").is_file()


def test_stored_checks_reads_what_the_sweep_writes():
    from testbed.studies.results import stored_checks

    good = [{"metric": "coef_error", "value": 0.01, "bound": "max", "threshold": 0.1, "passed": True}]
    assert stored_checks({"checks": json.dumps(good)}) == good
    assert stored_checks({"checks": ""}) == stored_checks({"checks": None}) == stored_checks({}) == []


# ------------------------------------------------------------------ scenario extends

_MM = "michaelis_menten.toml"


@pytest.mark.parametrize(("edit", "key"), [
    (("description = \"Michaelis", "description = \"a\\tb\" #"), "scenario.description"),
    (("x0 = 2.0", "x0 = \"two\""), "rig.x0"),
    (("degree = 3", "degree = \"three\""), "identify.degree"),
])
def test_a_parent_refused_on_its_own_is_refused_as_a_parent(tmp_path, edit, key):
    from pathlib import Path

    from testbed.core.errors import ScenarioError
    from testbed.pipeline.scenario import SCENARIO_DIR, load_scenario

    # the child overrides (or, [identify], replaces) the parent's malformed key: it loaded
    # while the parent, run alone, was refused
    text = (Path(SCENARIO_DIR) / _MM).read_text().replace('name = "michaelis_menten"', 'name = "p"')
    assert edit[0] in text
    (tmp_path / "p.toml").write_text(text.replace(edit[0], edit[1], 1))
    (tmp_path / "k.toml").write_text('[scenario]\nname = "k"\nextends = "p.toml"\ndescription = "d"\n'
                                     '[rig]\nx0 = 2.0\n[identify]\nmethod = "sindy_pi_dynamical"\n')
    with pytest.raises(ScenarioError, match=rf"p\.toml: key '{re.escape(key)}'.*\(extended by .*k\.toml\)"):
        load_scenario(tmp_path / "k.toml")


def test_a_parent_over_budget_that_its_child_shortens_still_loads(tmp_path):
    from pathlib import Path

    from testbed.core.errors import BudgetError
    from testbed.pipeline.scenario import SCENARIO_DIR, load_scenario

    text = (Path(SCENARIO_DIR) / _MM).read_text().replace('name = "michaelis_menten"', 'name = "p"')
    (tmp_path / "p.toml").write_text(text.replace("duration = 4.0", "duration = 1e6", 1))
    (tmp_path / "k.toml").write_text('[scenario]\nname = "k"\nextends = "p.toml"\n'
                                     '[simulation]\nduration = 4.0\n')
    with pytest.raises(BudgetError):
        load_scenario(tmp_path / "p.toml")
    assert load_scenario(tmp_path / "k.toml").simulation["duration"] == 4.0


# ------------------------------------------------------------------ sweep --dask


@pytest.mark.parametrize("address", ["tcp://[::1", "tcp://" + "a" * 64 + ":1", "tcp://a..b:1",
                                     "tcp://.:1", "tcp://\udcff:1"])
def test_a_dask_address_python_cannot_parse_or_encode_is_one_line(address):
    from testbed.cli import check_dask_address

    # urlsplit's ValueError (an unclosed IPv6 bracket) and the idna codec's UnicodeError (an
    # empty label, one of 64 characters, a lone surrogate) were internal errors of `sweep`
    with pytest.raises(InputError, match=r"^--dask .*expected a scheduler address tcp://host:port$") as e:
        check_dask_address(address)
    assert "\n" not in str(e.value)


# ------------------------------------------------------------------ report of no results


@pytest.mark.parametrize("source", ["rows", "parts"])
def test_report_of_results_without_a_row_is_one_line_and_writes_nothing(tmp_path, capsys, source):
    from testbed.cli import main
    from testbed.studies.results import parts_dir, write_rows

    # an empty results file, or the parts folder of a sweep killed before its first row, was
    # reported as "0 cells: ... noise levels  % of channel RMS" with status 0
    res = tmp_path / "r.parquet"
    if source == "rows":
        write_rows(res, [], study="s")
    else:
        parts_dir(res).mkdir(parents=True)
    assert main(["report", str(res), "-o", str(tmp_path / "rep")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "holds no results" in err, err
    assert not (tmp_path / "rep").exists()


# ------------------------------------------------------------------ identify --scenario --param


def test_a_param_over_a_scenarios_identify_table_is_named_as_the_command_lines(tmp_path):
    from testbed.core.errors import ScenarioError
    from testbed.pipeline.fit import identify_file

    # `identify --scenario S --param max_iter=1` was refused as "S: key 'identify.max_iter'
    # ...", naming a scenario file that holds no such key
    data = tmp_path / "d.csv"
    data.write_text("x [mM],dx [mM/s]\n" + "".join(f"{2 - 0.01 * k},{-0.7 + 0.001 * k}\n" for k in range(50)))
    with pytest.raises(ScenarioError, match=r"^<command line>: key 'identify\.max_iter'"):
        identify_file(data, scenario="cantilever_stiff_impact", params={"max_iter": 1}, fs=100.0)
    with pytest.raises(ScenarioError, match=r"^<command line>: key 'identify\.degree'"):
        identify_file(data, scenario="michaelis_menten", params={"degree": "x"}, fs=100.0)


# ------------------------------------------------------------------ modes of a tiny mass


@pytest.mark.parametrize("symmetric", [True, False])
def test_modes_of_a_mass_matrix_tiny_against_k_are_nan_when_not_strict(symmetric):
    import numpy as np

    from testbed.numerics.shapes import modal_from_matrices

    # `identify --prior total_mass=1e-320`: M^-1 K overflowed and scipy's eig raised
    # ValueError (an internal error) where strict=False promises NaN modes
    m = np.eye(2) * 1e-320
    k = np.array([[2.0, -1.0], [-1.0 if symmetric else -0.5, 1.0]]) * 1e4
    c = np.eye(2)
    f, zeta, modes = modal_from_matrices(m, c, k, strict=False)
    assert np.isnan(f).all() and np.isnan(zeta).all() and modes.shape == (2, 2)
    with pytest.raises(ValueError, match="overflows"):
        modal_from_matrices(m, c, k)


@pytest.mark.parametrize("mass", [1e-320, 5e-324])
def test_scoring_a_model_whose_mass_is_tiny_against_k_names_it(mass):
    import numpy as np

    from testbed.numerics.shapes import modal_from_matrices
    from testbed.scoring.scorers import physical_failures

    # an M positive definite to its relative bar but subnormal: M^-1 K overflowed and numpy's
    # eigvals raised LinAlgError inside the scorer (5e-324: scipy's eigh failed first), an
    # internal error; now a failure named "model"
    m, c, k = np.eye(3) * mass, np.eye(3) * 1e-3, np.eye(3) * 1e3
    failures = physical_failures(m, c, k)
    assert set(failures) == {"model"} and "not finite" in failures["model"]
    assert np.isnan(modal_from_matrices(m, c, k, strict=False)[0]).all()
    assert physical_failures(np.eye(3), c, k) == {}  # the same model at 1 kg is physical


@pytest.mark.parametrize("value", [1e-320, 5e-324, 1e308, 1e-101, 1.1e100])
def test_a_prior_beyond_float64s_working_range_is_one_line(value):
    from testbed.pipeline.importers import PRIOR_RANGE, MeasuredDataError, check_prior

    # `identify --prior total_mass=1e-320 / 5e-324 / 1e308`: three internal errors in the
    # identifier and the scorer; the prior is refused where it is read, with its range
    with pytest.raises(MeasuredDataError,
                       match=r"prior total_mass=.*expected a finite number from 1e-100 to 1e\+100"):
        check_prior("d.h5", "total_mass", value)
    for ok in (*PRIOR_RANGE, 0.7):
        check_prior("d.h5", "total_mass", ok)
