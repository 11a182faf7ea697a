"""Figures drawn in a forked process (``testbed run``): the same PNGs, errors raised in the
parent, no process left behind."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/testbed: _synthetic_runs
import _synthetic_runs as synth

from testbed.reporting import drawer, figures
from testbed.studies.runstore import load_run, save_new_run, save_run
from tests._processes import alive

ROOT = Path(__file__).resolve().parents[3]
needs_fork = pytest.mark.skipif(not drawer.fork_available(), reason="figures drawn in-process here")


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory):
    return save_run(synth.structural_result(n_samples=1000), tmp_path_factory.mktemp("runs") / "s")


def test_split_is_balanced_and_the_same_every_time():
    stems = ["reconstruction", "spectra", "mac", "frequencies", "matrices", "penalty_weights"]
    groups = drawer.split_figures(stems)
    assert groups == drawer.split_figures(stems)
    assert sorted(s for g in groups for s in g) == sorted(stems)
    cost = [sum(drawer.FIGURE_COST[s] for s in g) for g in groups]
    # the best split of these costs (longest first would give 7.3 | 6.6: matrices, penalty
    # weights and mac | spectra, reconstruction and frequencies); sums of one-decimal costs
    assert groups == [["spectra", "mac", "frequencies", "penalty_weights"], ["reconstruction", "matrices"]]
    assert cost == pytest.approx([6.9, 7.0], abs=1e-9)
    many = [f"f{i}" for i in range(drawer.EXACT_SPLIT + 3)]  # longest first beyond the exact split
    assert sorted(s for g in drawer.split_figures(many) for s in g) == sorted(many)
    assert drawer.split_figures(["mac"]) == [["mac"]]
    assert drawer.split_figures([]) == []


@needs_fork
def test_the_worker_draws_the_pngs_drawn_in_process(run_folder, tmp_path):
    """Byte for byte: the same builders on the same run folder, in another process."""
    here = tmp_path / "here"
    expected = [p.name for p in figures.save_run_figures(load_run(run_folder), here)]
    there = tmp_path / "there"
    there.mkdir()
    for f in ("run.json", "run.npz"):
        (there / f).write_bytes((run_folder / f).read_bytes())
    with drawer.figure_drawer() as draw:
        run = load_run(there)
        paths = draw(run, there)
    assert [p.name for p in paths] == expected  # report order
    assert run.meta["figures"] == expected and (there / "report.html").is_file()
    for name in expected:
        assert (there / name).read_bytes() == (here / name).read_bytes(), name


@needs_fork
def test_a_drawing_error_is_raised_in_the_parent_and_nothing_is_saved(monkeypatch, tmp_path):
    def broken(*a, **k):
        raise ValueError("no room for the colour bar")

    monkeypatch.setattr(figures, "matrices", broken)  # before the fork: the worker inherits it
    with pytest.raises(ValueError, match="no room for the colour bar") as info:
        with drawer.figure_drawer() as draw:
            save_new_run(synth.structural_result(n_samples=1000), tmp_path, figures=draw)
    assert any("figure-drawing process" in n for n in getattr(info.value, "__notes__", []))
    assert not list((tmp_path / "synthetic_structural").glob("*-s*"))  # no half-written run


@needs_fork
def test_a_worker_that_dies_is_an_error_not_a_hang(run_folder, tmp_path):
    worker = drawer.FigureWorker()
    try:
        os.kill(worker._proc.pid, signal.SIGKILL)
        worker._proc.join(10)
        with pytest.raises(drawer.FigureWorkerError, match="died"):
            worker.draw(load_run(run_folder), tmp_path)
    finally:
        worker.close(kill=True)


@needs_fork
def test_a_killed_run_leaves_no_drawing_process(tmp_path):
    """SIGKILL of the command (no clean-up runs in it): the kernel ends its drawing process."""
    code = textwrap.dedent("""
        import sys, time
        from testbed.reporting import drawer
        with drawer.figure_drawer() as draw:
            w = draw  # the worker is running
            import multiprocessing
            print(*[p.pid for p in multiprocessing.active_children()], flush=True)
            time.sleep(60)
    """)
    env = dict(os.environ, PYTHONPATH=str(ROOT), MPLBACKEND="Agg")
    p = subprocess.Popen([sys.executable, "-c", code], cwd=ROOT, env=env, stdout=subprocess.PIPE, text=True)
    try:
        pids = [int(x) for x in p.stdout.readline().split()]
        assert pids and all(alive(q) for q in pids)
        p.kill()
        p.wait(10)
        deadline = time.monotonic() + 10
        while any(alive(q) for q in pids) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not any(alive(q) for q in pids), "a drawing process outlived the killed command"
    finally:
        p.kill()
        p.wait()


def test_without_figures_nothing_is_forked():
    import multiprocessing

    before = multiprocessing.active_children()
    with drawer.figure_drawer(enabled=False) as draw:
        assert draw is None
        assert multiprocessing.active_children() == before


def test_in_process_writer_where_fork_is_missing(monkeypatch):
    monkeypatch.setattr(drawer, "fork_available", lambda: False)
    import multiprocessing

    before = multiprocessing.active_children()
    with drawer.figure_drawer() as draw:
        assert isinstance(draw, drawer.RunFigures) and draw.worker is None  # draws in this process
        assert multiprocessing.active_children() == before
