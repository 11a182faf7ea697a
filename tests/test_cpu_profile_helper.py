"""The CPU profile of a test run (tests/_cpu_profile.py): it sums what the workers recorded."""

import json

import pytest

from tests import _cpu_profile


def test_summary_sums_workers_modules_and_tests(tmp_path):
    rows = {"gw0": [("tests/a.py::t1", 2.0, 0.0, 5.0), ("tests/a.py::t2", 1.0, 5.0, 6.0)],
            "gw1": [("tests/b.py::t3@g", 4.0, 1.0, 9.0)]}
    for worker, tests in rows.items():
        (tmp_path / f"{worker}.jsonl").write_text("".join(
            json.dumps({"id": i, "group": None, "cpu": c, "t0": t0, "t1": t1}) + "\n"
            for i, c, t0, t1 in tests))
    text = _cpu_profile.summary(tmp_path, 2).splitlines()
    assert text[0] == "3 tests, 7.0 s of CPU in the tests"
    assert text[1] == "gw0: 3.0 s of CPU, span 6.0 s wall" and text[2] == "gw1: 4.0 s of CPU, span 8.0 s wall"
    assert text[4:6] == ["    4.0  tests/b.py", "    3.0  tests/a.py"]
    assert text[7] == "    4.0  gw1  tests/b.py::t3"  # the load group's suffix dropped


def test_summary_of_an_empty_folder_says_so(tmp_path):
    assert _cpu_profile.summary(tmp_path) == f"no records in {tmp_path}"


def test_summary_splits_the_kinds_and_names_work_done_twice(tmp_path):
    rows = [{"id": "tests/a.py::t1", "cpu": 3.0, "t0": 0.0, "t1": 3.0,
             "kinds": {"simulation": 1.0, "fit": 1.5},
             "work": [["simulation", "beam:ab", 1.0], ["fit", "LS:cd", 1.5]]},
            {"id": "tests/b.py::t2@g", "cpu": 2.0, "t0": 0.0, "t1": 2.0, "kinds": {"fit": 1.25},
             "work": [["fit", "LS:cd", 1.25], ["fit", "LS:ef", 0.5]]}]
    (tmp_path / "gw0.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    text = _cpu_profile.summary(tmp_path, 5).splitlines()
    assert text[2] == ("by kind: simulation 1.0 s, fit 2.8 s, compile 0.0 s, savefig 0.0 s, the rest "
                       "1.2 s (children reaped, scoring, I/O, imports ...)")
    # the fit keyed LS:cd ran in both tests: its second call is the repeat; LS:ef once is none
    assert _cpu_profile.repeated(rows) == [(1.25, "fit", "LS:cd", 2, ["tests/a.py::t1", "tests/b.py::t2"])]
    assert text[3:5] == ["--- work done more than once: 1.2 s [CPU s]",
                         "    1.2  fit LS:cd x2: tests/a.py::t1, tests/b.py::t2"]


def test_the_kinds_are_timed_innermost_first_and_fits_keyed_by_their_data(tmp_path, monkeypatch):
    """The plugin's own timers, in this process: a simulation inside a fit is the simulation's,
    the fit keeps the rest; the same fit on the same arrays has the same key, other data another."""
    import numpy as np

    monkeypatch.setattr(_cpu_profile, "_kinds", {})
    monkeypatch.setattr(_cpu_profile, "_work", [])

    def burn(seconds):
        t = __import__("time").process_time()
        while __import__("time").process_time() - t < seconds:
            pass

    sim = _cpu_profile._timed("simulation", lambda: burn(0.05), key=lambda: "rig:1")
    _cpu_profile._enter("fit")
    burn(0.05)
    sim()
    _cpu_profile._leave("model:1")
    kinds, work = _cpu_profile._kinds, _cpu_profile._work
    assert kinds["simulation"] >= 0.05 and kinds["fit"] >= 0.05
    assert work[0][:2] == ["simulation", "rig:1"] and work[1][:2] == ["fit", "model:1"]
    # the fit's whole time (recorded to 1e-4 s)
    assert work[1][2] == pytest.approx(kinds["fit"] + kinds["simulation"], abs=1e-4)
    assert not _cpu_profile._stack

    class Data:
        x = np.arange(3.0)

    class Other:
        x = np.arange(4.0)

    class Model:
        def get_params(self):
            return {"rcond": 1e-10}

    assert _cpu_profile._fit_key(Model(), (Data(),)) == _cpu_profile._fit_key(Model(), (Data(),))
    assert _cpu_profile._fit_key(Model(), (Data(),)) != _cpu_profile._fit_key(Model(), (Other(),))
    assert _cpu_profile._fit_key(Model(), (Data(),)).startswith("Model:")
