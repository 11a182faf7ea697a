"""Figure frames made ahead (``testbed.reporting.frames``): the same pictures, each frame used
once, a frame of another shape never used, and nothing that can fail a run."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/testbed: _synthetic_runs
import _synthetic_runs as synth

from testbed.reporting import drawer, figures, frames
from testbed.studies.runstore import load_run, save_new_run


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    return synth.saved_runs(tmp_path_factory.mktemp("runs"))


@pytest.fixture(autouse=True)
def _empty_pool():
    frames.clear()
    yield
    frames.clear()


def test_figures_on_frames_made_ahead_are_the_same_pictures(runs, tmp_path):
    """Every run figure of both kinds, byte for byte, drawn on a frame made ahead (with its
    ticks) and on one made on the spot; each frame made is taken, once."""
    for kind, run in runs.items():
        fresh = {s: figures.save_figure(f, tmp_path / f"fresh-{kind}-{s}.png")
                 for s, f in figures.run_figures(run).items()}
        made = figures.prepare_run_frames(run)
        # the joint-angle figure makes its own (no frame): every other figure has one
        assert made == len([s for s in fresh if s != "joint_angles"]) > 0, kind
        taken = {}
        for s, f in figures.run_figures(run).items():
            taken[s] = figures.save_figure(f, tmp_path / f"framed-{kind}-{s}.png")
        assert frames.pooled() == 0, f"{kind}: a frame made ahead was not used"
        assert list(taken) == list(fresh)
        for s in fresh:
            assert taken[s].read_bytes() == fresh[s].read_bytes(), f"{kind} {s}"


def test_recording_draws_nothing_and_names_each_frame(runs):
    run = runs["structural"]
    keys = frames.record(figures._run_builders(run, None).values())
    assert len(keys) == len(figures.run_figures_available(run))  # every structural figure is framed
    assert frames.pooled() == 0 and not frames.recording()
    # a key is the figure's size [in] and grid: the reconstruction's rows are the channels
    n = len(run.details["channels"])
    assert any(k[2] == (n, 2) for k, _ in keys)


def test_a_frame_of_another_shape_is_not_taken(runs):
    """Frames made for a run with one channel more: no figure of the run takes them."""
    run = runs["structural"]
    frames.prepare(frames.record(figures._run_builders(run, None).values()), figures._make_frame,
                   figures.STYLE)
    before = frames.pooled()
    n = len(run.details["channels"])
    d = run.details
    fig = figures.reconstruction(d["t"], d["reference_xdd"][:n - 1], d["simulated_xdd"][:n - 1],
                                 d["channels"][:n - 1])
    assert frames.pooled() == before  # made on the spot
    assert len(fig.axes) == 2 * (n - 1)


def test_a_key_already_pooled_is_not_made_again(runs):
    run = runs["structural"]
    first = figures.prepare_run_frames(run)
    assert first > 0 and figures.prepare_run_frames(run) == 0  # as a server's inherited frames
    assert frames.pooled() == first


def test_preparing_from_a_missing_or_damaged_folder_makes_nothing(tmp_path):
    assert drawer.prepare_frames(tmp_path / "nowhere") == 0
    bad = tmp_path / "bad"
    bad.mkdir()
    (bad / "run.json").write_text("{not json")
    assert drawer.prepare_frames(bad) == 0
    assert frames.pooled() == 0


def test_the_latest_run_of_the_scenario_is_what_is_prepared(tmp_path):
    """``RunFigures.prepare``: nothing asked of the drawing process before a scenario's first
    run, its folder of runs after (the drawing process resolves its latest run)."""
    sent = []

    class Worker:
        def prepare(self, folder):
            sent.append(Path(folder))

    figs = drawer.RunFigures(Worker())
    figs.prepare(tmp_path, "cantilever_synthetic")
    assert sent == []
    run_dir = save_new_run(synth.structural_result(n_samples=1000), tmp_path)
    figs.prepare(tmp_path, "cantilever_synthetic")
    assert sent == [tmp_path / "cantilever_synthetic"]
    assert drawer.prepare_frames(sent[0]) == len(figures.run_figures_available(load_run(run_dir)))
    drawer.RunFigures(None).prepare(tmp_path, "cantilever_synthetic")  # in-process: nothing to do
