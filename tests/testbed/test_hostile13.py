"""Thirteenth malformed-input round: the findings of ``benchmarks/hostile13.py`` (docs/history.md,
malformed-input audits), each fixed in the layer that owns it.
"""

from __future__ import annotations

import functools
import io
import json
import math
import os

import numpy as np
import pytest

from benchmarks import _hostile
from testbed.core.errors import InputError

_row = functools.partial(_hostile.results_row, passed=False)


# ------------------------------------------------------------------ writes onto devices

def test_an_atomic_write_never_replaces_a_fifo_or_device(tmp_path):
    from testbed.core.atomic import atomic_write_text

    # os.replace onto a FIFO or device node replaced the node itself with a regular file
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match="fifo: exists and is not a regular file"):
        atomic_write_text(fifo, "x")
    assert fifo.is_fifo() and [p.name for p in tmp_path.iterdir()] == ["fifo"]


def test_the_drawing_warm_up_writes_no_file(monkeypatch):
    from testbed.reporting import drawer, figures

    # its figure went to os.devnull through the atomic write: as root, every drawing process
    # (`testbed run` with figures, the server) replaced /dev/null with a regular file
    def refuse(fig, path):
        raise AssertionError(f"the warm-up saved a file: {path}")

    monkeypatch.setattr(figures, "save_figure", refuse)
    drawer._warm_up()


def test_a_sweep_never_sets_a_device_aside_as_damaged_results(tmp_path):
    from testbed.studies.sweep import run_sweep

    # read as a damaged results file, the node was renamed `<name>.bad` (as root: /dev/null)
    fifo = tmp_path / "r.parquet"
    os.mkfifo(fifo)
    with pytest.raises(InputError, match=r"r\.parquet: exists and is not a regular file"):
        run_sweep("smoke", results=fifo, cache_dir=tmp_path / "c", verbose=False)
    assert fifo.is_fifo() and [p.name for p in tmp_path.iterdir()] == ["r.parquet"]


# ------------------------------------------------------------------ two sweeps, one file

def test_a_second_sweep_on_a_results_file_being_written_is_refused(tmp_path):
    from testbed.studies.sweep import lock_path, results_lock, run_sweep

    # two sweeps consolidating one file deleted each other's row files and dropped each other's
    # cells: a study of 14 cells and its edit to 12, 3 s apart, left 8 rows
    res = tmp_path / "r.parquet"
    with results_lock(res):
        assert lock_path(res).read_text() == str(os.getpid())
        with pytest.raises(InputError, match=rf"results {res}: another sweep \(process "
                                             rf"{os.getpid()}\) is writing it"):
            run_sweep("smoke", results=res, cache_dir=tmp_path / "c", verbose=False)
    assert not lock_path(res).exists()  # removed at the end: the folder is left as it was
    with results_lock(res), pytest.raises(InputError):  # and taken again
        with results_lock(res):
            pass


def test_another_users_lock_file_still_locks(tmp_path, monkeypatch):
    # the lock file of another user's sweep (0644) cannot be opened for writing: the sweep ran
    # unlocked in silence, beside the other user's (review); flock needs a read-only descriptor
    # only.  (Simulated: the suite runs as root, whom no mode refuses.)
    from testbed.studies import sweep as sweep_mod

    res = tmp_path / "r.parquet"
    sweep_mod.lock_path(res).write_text("4242")
    real_open = os.open

    def other_users(path, flags, *args):
        if os.fspath(path) == os.fspath(sweep_mod.lock_path(res)) and flags & os.O_RDWR:
            raise PermissionError(13, "Permission denied", os.fspath(path))
        return real_open(path, flags, *args)

    monkeypatch.setattr(sweep_mod.os, "open", other_users)
    with sweep_mod.results_lock(res):
        monkeypatch.setattr(sweep_mod.os, "open", real_open)
        with pytest.raises(InputError, match=r"another sweep \(process 4242\) is writing it"):
            with sweep_mod.results_lock(res):
                pass


# ------------------------------------------------------------------ medians of scores

def test_quartiles_count_infinite_scores_and_equal_numpy_on_finite_ones():
    from testbed.numerics.quantiles import quartiles

    # an infinite score (a true coefficient of 0 missed) was left out of the median
    assert quartiles([1.0, 2.0, 3.0, math.inf, math.nan]) == (1.75, 2.5, math.inf, 4)
    assert quartiles([math.inf, math.inf])[:3] == (math.inf, math.inf, math.inf)
    assert quartiles([-math.inf, 1.0, math.inf])[:3] == (-math.inf, 1.0, math.inf)
    assert quartiles([1.0, 2.0, 3.0, 4.0, math.inf])[:3] == (2.0, 3.0, 4.0)  # inf no neighbour
    assert quartiles([math.nan, None])[3] == 0 and all(map(math.isnan, quartiles([])[:3]))
    rng = np.random.default_rng(13)
    for _ in range(2000):  # bit-identical to numpy's linear rule on finite values
        v = rng.standard_normal(int(rng.integers(1, 30))) * 10.0 ** rng.integers(-5, 5)
        assert quartiles(v)[:3] == tuple(np.percentile(v, [25, 50, 75]))


def test_summary_and_report_count_an_infinite_score_and_say_how_many_cells_a_median_has(tmp_path):
    from rich.console import Console

    from testbed.reporting.report import sweep_report
    from testbed.studies.results import read_results, write_rows
    from testbed.studies.statistics import print_summary, summarize

    # the default study's sindy_pi at 5 %: coef_error 84.4 over 5 of its 6 ok cells, the sixth
    # inf, shown as the median of the group
    rows = [_row(cell=f"c{i}", seed=i, coef_error=v)
            for i, v in enumerate([1.0, 2.0, 3.0, math.inf, math.nan])]
    res = write_rows(tmp_path / "r.parquet", rows, study="s")
    (s,) = summarize(res)
    assert (s["coef_error_q25"], s["coef_error_median"], s["coef_error_q75"], s["coef_error_n"]) \
        == (1.75, 2.5, math.inf, 4)
    buf = io.StringIO()
    print_summary(res, console=Console(file=buf, width=100))
    out = buf.getvalue()
    assert "[1.75, inf]" in out and "4 of 5 cells" in out
    sweep_report(read_results(res), tmp_path / "rep")
    md = (tmp_path / "rep" / "report.md").read_text()
    assert "2.5 \\[1.75, inf] (4 of 5 cells)" in md  # "[" escaped: no link (hostile round 20)
    # every cell's score alike: no count said
    res2 = write_rows(tmp_path / "r2.parquet", [_row(cell="c1"), _row(cell="c2", seed=1)], study="s")
    buf = io.StringIO()
    print_summary(res2, console=Console(file=buf, width=100))
    assert " of 2 cells" not in buf.getvalue()
    json.dumps(summarize(res2))  # (plain values)


# ------------------------------------------------------------------ paths that name nothing

@pytest.mark.parametrize("argv", [["runs", "ls", "-o", "x" * 5000],
                                  ["report", "michaelis_menten", "--runs", "x" * 5000, "-o", "rep"],
                                  ["report", "x" * 5000, "-o", "rep"]])
def test_a_run_history_path_too_long_for_the_file_system_is_one_line(argv, tmp_path, monkeypatch,
                                                                     capsys):
    from testbed.cli import main

    # Path.exists / is_dir raised OSError 36 ("File name too long"): an internal error
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "a file name too long for the file system" in err
