"""The CPU profile of a test run (tests/_cpu_profile.py): it sums what the workers recorded."""

import json

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
