"""Run figures kept by content (:mod:`testbed.reporting.figcache`): a figure of the same inputs
is copied byte for byte instead of drawn; any other input is drawn; a damaged entry, a cache
that cannot be written, a full cache never change a picture or fail a run."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/testbed: _synthetic_runs
import _synthetic_runs as synth

from testbed.reporting import drawer, figcache, figures
from testbed.studies.runstore import load_run, save_run

needs_fork = pytest.mark.skipif(not drawer.fork_available(), reason="figures drawn in-process here")


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory):
    return save_run(synth.structural_result(n_samples=1000), tmp_path_factory.mktemp("runs") / "s")


@pytest.fixture(scope="module")
def drawn(run_folder, tmp_path_factory):
    """The run's figures drawn without any cache: name -> bytes."""
    out = tmp_path_factory.mktemp("plain")
    return {p.name: p.read_bytes() for p in figures.save_run_figures(load_run(run_folder), out)}


def _no_drawing(monkeypatch):
    def refuse(run, inputs=None, only=None):
        if only is None or list(only):
            raise AssertionError(f"drew {only} although the cache holds them")
        return {}
    monkeypatch.setattr(figures, "run_figures", refuse)


def test_a_kept_figure_is_the_drawn_one_byte_for_byte(run_folder, drawn, tmp_path, monkeypatch):
    cache = figcache.FigureCache(tmp_path / "cache")
    first = drawer.draw_run_figures(load_run(run_folder), tmp_path / "a", cache)
    assert [p.name for p in first] == list(drawn)  # report order
    assert len(list((tmp_path / "cache").glob("*.png"))) == len(drawn)
    _no_drawing(monkeypatch)
    second = drawer.draw_run_figures(load_run(run_folder), tmp_path / "b", cache)
    assert [p.name for p in second] == list(drawn)
    for p in [*first, *second]:
        assert p.read_bytes() == drawn[p.name], p


def test_the_key_is_the_inputs_and_the_code(run_folder):
    run = load_run(run_folder)
    key = figcache.run_key(run)
    assert figcache.run_key(load_run(run_folder)) == key  # read again: the same
    other = load_run(run_folder)
    x = other.details["simulated_xdd"]
    x[0, 0] = np.nextafter(x[0, 0], np.inf)  # one ulp of one sample
    assert figcache.run_key(other) != key
    other = load_run(run_folder)
    other.history[next(iter(other.history))] = np.zeros(3)
    assert figcache.run_key(other) != key
    other = load_run(run_folder)
    other.meta["scenario"] = {**other.meta["scenario"], "seed": 12345}
    assert figcache.run_key(other) != key
    cache = figcache.FigureCache("unused")
    assert cache.key(key, "mac") != cache.key(key, "matrices")
    assert "figures.py" in figcache.DRAWING_SOURCES and "frames.py" in figcache.DRAWING_SOURCES


def test_a_damaged_entry_is_drawn_again_and_replaced(run_folder, drawn, tmp_path):
    cache = figcache.FigureCache(tmp_path / "cache")
    run = load_run(run_folder)
    drawer.draw_run_figures(run, tmp_path / "a", cache)
    key = cache.key(figcache.run_key(run), "mac")
    entry = tmp_path / "cache" / f"{key}.png"
    entry.write_bytes(drawn["mac.png"][:-100])  # cut short: no end chunk
    out = drawer.draw_run_figures(run, tmp_path / "b", cache)
    assert (tmp_path / "b" / "mac.png").read_bytes() == drawn["mac.png"]
    assert entry.read_bytes() == drawn["mac.png"] and len(out) == len(drawn)


def test_a_cache_that_cannot_be_written_draws_as_without_one(run_folder, drawn, tmp_path):
    (tmp_path / "file").write_text("not a folder")
    cache = figcache.FigureCache(tmp_path / "file" / "figures")
    out = drawer.draw_run_figures(load_run(run_folder), tmp_path / "a", cache)
    assert {p.name: p.read_bytes() for p in out} == drawn


def test_the_least_recently_used_beyond_the_limit_are_removed(run_folder, tmp_path):
    png = tmp_path / "x.png"
    png.write_bytes(figcache._PNG_HEAD + b"body" + figcache._PNG_TAIL)
    cache = figcache.FigureCache(tmp_path / "cache", max_entries=3)
    keys = [cache.key("run", f"f{i}") for i in range(5)]
    for i, k in enumerate(keys[:3]):
        cache.store(k, png)
        os.utime(tmp_path / "cache" / f"{k}.png", ns=(i * 10**9, i * 10**9))
    assert cache.fetch(keys[0], tmp_path / "used.png")  # the oldest, used now
    cache.store(keys[3], png)
    cache.store(keys[4], png)
    kept = {p.stem for p in (tmp_path / "cache").glob("*.png")}
    assert kept == {keys[0], keys[3], keys[4]}
    assert not cache.fetch(keys[1], tmp_path / "gone.png") and not (tmp_path / "gone.png").exists()


@needs_fork
def test_a_run_repeated_draws_nothing_in_the_drawing_processes(run_folder, drawn, tmp_path, monkeypatch):
    """``testbed run`` through the worker: the second run of the same inputs copies all."""
    folders = []
    for name in ("first", "second"):
        there = tmp_path / name
        there.mkdir()
        for f in ("run.json", "run.npz"):
            (there / f).write_bytes((run_folder / f).read_bytes())
        folders.append(there)
    with drawer.figure_drawer(cache=tmp_path / "cache") as draw:
        draw(load_run(folders[0]), folders[0])
    _no_drawing(monkeypatch)  # before the fork: the drawing processes inherit it
    with drawer.figure_drawer(cache=tmp_path / "cache") as draw:
        paths = draw(load_run(folders[1]), folders[1])
    assert [p.name for p in paths] == list(drawn)
    for p in paths:
        assert p.read_bytes() == drawn[p.name], p


def test_cache_clear_removes_the_kept_figures(tmp_path, capsys):
    from testbed.cli import main

    png = tmp_path / "x.png"
    png.write_bytes(figcache._PNG_HEAD + b"body" + figcache._PNG_TAIL)
    cache = figcache.FigureCache(tmp_path / "cache" / "figures")
    for i in range(3):
        cache.store(cache.key("run", f"f{i}"), png)
    (tmp_path / "cache" / "figures" / "notes.txt").write_text("not ours")
    assert main(["cache", "clear", "--cache", str(tmp_path / "cache")]) == 0
    out = capsys.readouterr().out
    assert "removed 0 dataset(s)" in out and "removed 3 run figure(s)" in out
    assert [p.name for p in (tmp_path / "cache" / "figures").iterdir()] == ["notes.txt"]
    assert cache.clear() == 0


def test_the_key_follows_matplotlibs_settings(run_folder, monkeypatch):
    """A user's matplotlibrc (another font size, say) draws other pictures: another key."""
    import matplotlib as mpl

    run = load_run(run_folder)
    monkeypatch.setattr(figcache, "_CODE", [])
    key = figcache.run_key(run)
    monkeypatch.setattr(figcache, "_CODE", [])
    with mpl.rc_context({"font.size": 13}):
        assert figcache.run_key(run) != key
    monkeypatch.setattr(figcache, "_CODE", [])
    assert figcache.run_key(run) == key


def test_a_drawing_process_forks_no_helper_when_every_figure_is_kept(run_folder, drawn, tmp_path,
                                                                     monkeypatch):
    cache = figcache.FigureCache(tmp_path / "cache")
    there = tmp_path / "there"
    there.mkdir()
    for f in ("run.json", "run.npz"):
        (there / f).write_bytes((run_folder / f).read_bytes())
    drawer.draw_run_figures(load_run(run_folder), tmp_path / "a", cache)  # fills the cache

    def no_fork():
        raise AssertionError("a helper was forked to copy files")

    monkeypatch.setattr(drawer.os, "fork", no_fork)
    paths = drawer._draw_split(str(there), cache)
    assert [Path(p).name for p in paths] == list(drawn)
    assert all(Path(p).read_bytes() == drawn[Path(p).name] for p in paths)
    (tmp_path / "cache" / f"{cache.key(figcache.run_key(load_run(there)), 'mac')}.png").unlink()
    with pytest.raises(AssertionError, match="forked"):  # one to draw: the split as before
        drawer._draw_split(str(there), cache)
