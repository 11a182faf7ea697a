"""Figures: the right panels, labelled axes with units, readable size, PNGs that decode."""

from __future__ import annotations

import sys
from pathlib import Path

import matplotlib.image as mpimg
import numpy as np
import pytest
from matplotlib.figure import Figure

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/testbed: _synthetic_runs
import _synthetic_runs as synth

from testbed.core.truth import StructuralTruth
from testbed.reporting import figures
from testbed.studies.runstore import load_run, save_run


def labelled(fig: Figure) -> list[tuple[str, str]]:
    """(xlabel, ylabel) of every visible data axes (colour bars and tables excluded)."""
    return [(a.get_xlabel(), a.get_ylabel()) for a in fig.axes
            if a.axison and a.get_label() != "<colorbar>" and (a.lines or a.images or a.patches)]


def assert_units(fig: Figure) -> None:
    pairs = labelled(fig)
    assert pairs
    for _, y in pairs:
        assert y and "[" in y, f"y label without unit: {y!r}"
    assert any("[" in x for x, _ in pairs) or all(x for x, _ in pairs)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    return synth.saved_runs(tmp_path_factory.mktemp("runs"))


def test_reconstruction_has_zoom_and_units():
    t = np.linspace(0, 1, 500)
    ref = np.vstack([np.sin(20 * t), np.cos(20 * t)])
    fig = figures.reconstruction(t, ref, ref * 0.9, ["acc1", "acc2"], trac=[0.99, 0.98], zoom=(0.2, 0.3))
    assert len(fig.axes) == 4
    assert_units(fig)
    assert "m/s^2" in fig.axes[0].get_ylabel() and fig.axes[-1].get_xlabel() == "time [s]"
    zoom_line = fig.axes[1].lines[0].get_xdata()
    # the zoom window asked for, (0.2, 0.3) s: not a tolerance
    assert zoom_line.min() >= 0.2 and zoom_line.max() <= 0.3
    assert "TRAC 0.990" in fig.axes[0].get_title()


def test_mac_matrix_writes_values():
    mac = np.array([[0.98, 0.1], [0.05, 0.91]])
    fig = figures.mac_matrix(mac, pair=[0, 1])
    texts = {t.get_text() for t in fig.axes[0].texts}
    assert {"0.98", "0.10", "0.05", "0.91"} <= texts
    assert fig.axes[0].get_xlabel().startswith("true mode")


def test_penalty_weights_split_weights_and_losses():
    assert figures.penalty_weights({}) is None
    h = {"alpha": {"eig": [1, 2, 3], "mass": [3, 2, 1]}, "loss_total": [5, 4, 3],
         "alpha_vec": np.array([[1, 2], [2, 3], [3, 4]])}
    fig = figures.penalty_weights(h)
    left, right = fig.axes
    assert {ln.get_label() for ln in left.lines} == {"alpha/eig", "alpha/mass", "alpha_vec[0]",
                                                     "alpha_vec[1]"}
    assert [ln.get_label() for ln in right.lines] == ["loss_total"]
    assert left.get_xlabel() == "epoch" and left.get_yscale() == "log"


def test_frequency_rows_pair_and_error():
    rows = figures.frequency_rows(np.array([80.0, 500.0]), np.array([505.0, 79.0]), pair=[1, 0])
    assert rows[0]["f_id"] == 79.0 and rows[0]["error_pct"] == pytest.approx(-1.25)
    assert rows[1]["f_id"] == 505.0 and rows[1]["error_pct"] == pytest.approx(1.0)
    table = figures.frequency_table(rows).axes[0].tables[0]
    cells = [c.get_text().get_text() for c in table.get_celld().values()]
    assert "-1.25" in cells and "+1.00" in cells


def test_true_cubic_only_when_it_exists_in_the_basis():
    eye = np.eye(3)
    base = {"M": eye, "C": eye, "K": eye, "frequencies_hz": np.ones(3), "damping_ratios": np.ones(3),
            "modes": eye, "sensor_modes": eye, "Mr": eye, "Cr": eye, "Kr": eye}
    cubic = {"k3": 2.0, "cubic_map": np.array([0, 3.0, 0]), "cubic_direction": np.array([1.0, -1.0, 0])}
    tr = StructuralTruth.from_dict(base | cubic)
    K3 = figures.true_cubic(tr, 3)
    x = np.array([0.1, 0.2, 0.3])
    np.testing.assert_allclose(K3 @ x**3, cubic["cubic_direction"] * 2.0 * (3.0 * 0.2) ** 3)
    two = StructuralTruth.from_dict(base | cubic | {"cubic_map": np.array([1.0, -1.0, 0])})
    assert figures.true_cubic(two, 3) is None  # the cubic coordinate mixes two sensor DOFs
    assert figures.true_cubic(StructuralTruth.from_dict(base), 3) is None  # linear: no cubic truth
    assert figures.true_cubic(None, 3) is None


def test_structural_run_figures(runs, tmp_path):
    figs = figures.run_figures(runs["structural"])
    assert list(figs) == ["reconstruction", "spectra", "mac", "frequencies", "matrices", "penalty_weights"]
    titles = [a.get_title() for a in figs["matrices"].axes if a.get_title()]
    # M, C and K side by side, then the cubic matrix: identified (top row) over true
    assert titles == ["M identified\nrel. error 2.00%", "C identified\nrel. error 0.00%",
                      "K identified\nrel. error 1.00%", "K3 identified\nrel. error 10.00%",
                      "M true", "C true", "K true", "K3 true"]
    for name in ("reconstruction", "penalty_weights", "spectra"):
        assert_units(figs[name])
    bars = [a.get_xlabel() for a in figs["matrices"].axes if a.get_label() == "<colorbar>"]
    assert bars == ["M [kg]", "C [N s/m]", "K [1e4 N/m]", "K3 [1e9 N/m^3]"]
    cells = {t.get_text() for a in figs["matrices"].axes for t in a.texts}
    assert "8" in cells and "0.9" in cells  # K[0, 0] = 8e4 N/m, K3[0, 0] = 9e8 N/m^3 in 1e4 / 1e9
    paths = figures.save_run_figures(runs["structural"], tmp_path)
    for p in paths:
        img = mpimg.imread(p)
        assert 350 <= img.shape[1] <= 1300 and img.shape[0] >= 200, f"{p.name}: {img.shape} px"
        assert img[..., :3].std() > 0.01, f"{p.name} is blank"


def test_only_the_ticks_in_view_are_made_and_the_picture_is_the_same(runs, monkeypatch, tmp_path):
    """Every run figure, byte for byte, with and without the in-view locators; with them no
    axis makes a tick outside its view, and some axis of these figures would have."""
    drawn = {}
    for mode in ("in view", "all"):
        if mode == "all":
            monkeypatch.setattr(figures, "_ticks_in_view", lambda fig: None)
        for kind, run in runs.items():
            for stem, fig in figures.run_figures(run).items():
                drawn[mode, kind, stem] = figures.save_figure(fig, tmp_path / f"{mode}-{kind}-{stem}.png")
                if mode == "in view":
                    for axis in (a for ax in fig.axes for a in (ax.xaxis, ax.yaxis)):
                        loc = axis.get_major_locator()
                        if hasattr(loc, "base"):
                            lo, hi = sorted(axis.get_view_interval())
                            span = hi - lo
                            assert all(lo - 1e-6 * span <= v <= hi + 1e-6 * span for v in loc()), stem
                            drawn["beyond", kind, stem, id(axis)] = len(loc.base()) > len(loc())
    assert any(v for k, v in drawn.items() if k[0] == "beyond")
    for (_, kind, stem), path in [(k, v) for k, v in drawn.items() if k[0] == "in view"]:
        assert path.read_bytes() == drawn["all", kind, stem].read_bytes(), f"{kind} {stem}"


def test_in_view_locator_keeps_the_edges_and_log_decades():
    fig = figures._fig(2.0, 4.0)
    ax = figures._axes(fig, 1, 3)[0]
    ax[0].set_xlim(0.0, 1.0)
    ax[1].set_yscale("log")
    ax[1].set_ylim(1e-3, 1e2)
    ax[2].set_xlim(0.1, 0.9)
    figures._ticks_in_view(fig)
    for axis, (lo, hi) in ((ax[0].xaxis, (0.0, 1.0)), (ax[1].yaxis, (1e-3, 1e2))):
        loc = axis.get_major_locator()
        np.testing.assert_array_equal(loc(), [v for v in loc.base() if lo <= v <= hi])
    assert ax[0].xaxis.get_major_locator()()[[0, -1]].tolist() == [0.0, 1.0]  # edges stay
    loc = ax[2].xaxis.get_major_locator()
    assert len(loc.base()) > len(loc()) > 0  # the locator alone gives ticks beyond the view
    assert all(0.1 <= v <= 0.9 for v in loc())
    loc = ax[0].xaxis.get_major_locator()
    figures._ticks_in_view(fig)  # wrapped once
    assert ax[0].xaxis.get_major_locator() is loc and not hasattr(loc.base, "base")


def test_spectra_show_where_the_model_deviates(runs):
    d = runs["structural"].details
    fig = figures.spectra(d["t"], d["reference_xdd"], d["simulated_xdd"], d["channels"],
                          frequencies=d["f_true"])
    psd_axes = [a for a in fig.axes if a.get_xlabel() == "frequency [Hz]" or "PSD" in a.get_ylabel()]
    assert len(psd_axes) == 3 and all(a.get_yscale() == "log" for a in psd_axes)
    assert psd_axes[0].get_ylabel() == "PSD [(m/s^2)^2/Hz]"
    assert [ln.get_label() for ln in psd_axes[0].lines[:3]] == ["measured (noise-free)", "identified model",
                                                                "residual"]
    marks = [ln.get_xdata()[0] for ln in psd_axes[0].lines[3:]]  # the true frequencies, dotted
    np.testing.assert_allclose(marks, d["f_true"][d["f_true"] <= 1.5 * d["f_true"].max()])
    res = [a for a in fig.axes if a.get_ylabel() == "residual [m/s^2]"]
    assert len(res) == 3 and "RMS 2.00% of signal" in res[0].get_title()  # simulated = 0.98 x truth


def test_psd_peak_and_parseval():
    fs, f0 = 1000.0, 125.0
    t = np.arange(20000) / fs
    y = np.sqrt(2) * np.sin(2 * np.pi * f0 * t)  # variance 1
    f, p = figures.psd(y, fs, 256)
    assert f[np.argmax(p[0])] == pytest.approx(f0, abs=fs / 256)
    assert np.sum(p[0]) * (f[1] - f[0]) == pytest.approx(1.0, rel=0.02)


def test_mechanical_run_figures(runs):
    figs = figures.run_figures(runs["mechanical"])
    assert list(figs) == ["joint_angles", "coefficients"]
    ja = figs["joint_angles"]
    panels = [a for a in ja.axes if a.lines]
    # four joints, then the angle errors (no dataset in the cache for a synthetic run: no torques)
    assert len(panels) == 5 and all("[rad]" in a.get_ylabel() for a in panels)
    assert "RMSE 0.0141 rad" in panels[0].get_title()
    assert panels[-1].get_ylabel() == "angle error [rad]" and panels[-1].get_xlabel() == "time [s]"
    co = figs["coefficients"].axes
    assert len(co) == 2
    assert [t.get_text() for t in co[0].get_xticklabels()] == runs["mechanical"].details["terms"]
    heights = [p.get_height() for p in co[0].patches]
    np.testing.assert_allclose(heights[:5], runs["mechanical"].details["coef_true"][0])


def test_joint_angles_with_errors_and_torques(runs):
    d = runs["mechanical"].details
    tau = np.vstack([np.sin(d["t"]), np.cos(d["t"])])
    fig = figures.joint_angles(d["t"], d["reference_x"], d["simulated_x"], d["channels"], inputs=tau,
                               input_channels=["u1", "u2"], input_unit="N m")
    *joints, err, torque = [a for a in fig.axes if a.lines]
    assert len(joints) == 4
    assert err.get_ylabel() == "angle error [rad]" and torque.get_ylabel() == "torque [N m]"
    assert [ln.get_label() for ln in err.lines[:4]] == list(d["channels"])
    np.testing.assert_allclose(err.lines[0].get_ydata(), d["simulated_x"][0] - d["reference_x"][0])
    np.testing.assert_allclose(torque.lines[1].get_ydata(), tau[1])
    assert torque.get_xlabel() == "time [s]" and err.get_xlabel() == ""  # one time axis, at the bottom
    assert torque.get_shared_x_axes().joined(torque, joints[0])


def test_metric_units_and_log_rule():
    assert figures.metric_unit("angle_rmse") == "rad"
    assert figures.metric_unit("K3_norm") == "N/m^3"
    assert figures.metric_unit("trac", "smallest TRAC over sensors") == "-"
    assert figures.metric_unit("new_score", "peak torque error [N m] over the record") == "N m"
    assert figures.wants_log([1e-6, 1e-4, 1e-2])
    assert not figures.wants_log([0.9, 0.95, 0.99])
    assert not figures.wants_log([0.0, 1e-6, 1e-2])  # a zero has no place on a log axis
    assert not figures.wants_log([1e-3, 5e-2])  # under 2 decades


def test_score_panels_small_multiples():
    rows = [r for r in synth.study_rows() if r["status"] == "ok"]
    thr = {"cantilever_a": [("min", 0.9)], "cantilever_b": [("min", 0.9)]}
    fig = figures.score_panels(rows, "trac", "-", thr)
    panels = [a for a in fig.axes if a.lines]
    assert [a.get_title() for a in panels] == ["cantilever_a", "cantilever_b"]  # no five-bar panel
    assert panels[0].get_yscale() == "linear" and panels[0].get_ylabel() == "trac [-]"
    assert panels[0].get_shared_y_axes().joined(panels[0], panels[1])
    lines = {ln.get_label(): ln for ln in panels[0].lines}
    assert {"ls_sindy", "sgd_sindy", "threshold"} <= set(lines)
    np.testing.assert_allclose(lines["sgd_sindy"].get_xdata(), [0, 1, 5])
    np.testing.assert_allclose(lines["sgd_sindy"].get_ydata(), [0.988, 0.968, 0.888])  # median seed
    np.testing.assert_allclose(lines["threshold"].get_ydata(), [0.9, 0.9])
    band = panels[0].collections[1].get_paths()[0].vertices[:, 1]  # sgd_sindy's IQR band
    assert band.min() == pytest.approx(0.887) and band.max() == pytest.approx(0.989)

    rmse = figures.score_panels(rows, "angle_rmse", "rad", {"fivebar_x": [("max", 0.0501)]})
    ax = next(a for a in rmse.axes if a.lines)
    assert ax.get_yscale() == "log" and ax.get_ylabel() == "angle_rmse [rad]"
    assert figures.score_panels(rows, "no_such_score") is None


def test_sweep_figures():
    rows = synth.sweep_rows()
    fig = figures.score_panels([r for r in rows if r["status"] == "ok"], "trac")
    ax = fig.axes[0]
    lines = {ln.get_label(): ln for ln in ax.lines}
    assert set(lines) == {"sindy_ls", "sgd_sindy"}
    np.testing.assert_allclose(lines["sgd_sindy"].get_xdata(), [0, 1, 5])
    np.testing.assert_allclose(lines["sgd_sindy"].get_ydata(), [0.9675, 0.9575, 0.9175])
    assert "noise [%" in ax.get_xlabel()
    ft = figures.fit_times(rows)
    assert ft.axes[0].get_xlabel() == "fit time [s]"
    assert [t.get_text() for t in ft.axes[0].get_yticklabels()] == ["sgd_sindy", "sindy_ls"]


def test_recorded_inputs_come_from_the_dataset_cache(tmp_path):
    from testbed.pipeline.cache import DatasetCache

    result = synth.mechanical_result(n_samples=400)
    run = load_run(save_run(result, tmp_path / "run"))
    cache = DatasetCache(tmp_path / "cache")
    assert figures.recorded_inputs(run, cache) is None  # not cached: no panel, no simulation
    path = cache.path(result.scenario)
    path.parent.mkdir(parents=True)
    result.dataset.save(path)
    data, names, unit = figures.recorded_inputs(run, cache)
    assert names == ["tau1", "tau2"] and unit == "N m"
    np.testing.assert_array_equal(data, result.dataset.measured["torques"].data)
    fig = figures.run_figures(run, inputs=(data, names, unit))["joint_angles"]
    assert [a.get_ylabel() for a in fig.axes if a.lines][-1] == "torque [N m]"


def _zlib_level(png: bytes) -> int:
    """FLEVEL of the zlib stream of a PNG's first IDAT chunk (0: the fastest, levels 0-1;
    1: levels 2-5; 2: level 6; 3: levels 7-9), from its header's FLG byte."""
    i = png.index(b"IDAT")
    return png[i + 5] >> 6


def test_pngs_are_encoded_fast_and_hold_the_same_pixels(runs, tmp_path):
    """The run figures' PNGs are written at zlib's fastest level, with every pixel equal to
    matplotlib's default encoding of the same figure (PNG is lossless: only the bytes differ).
    One run's figures: the encoder does not look at what is drawn."""
    import matplotlib as mpl
    from PIL import Image

    drawn = []
    for kind, run in list(runs.items())[:1]:
        for stem, fig in figures.run_figures(run, only=("reconstruction", "matrices")).items():
            ours = figures.save_figure(fig, tmp_path / f"{kind}-{stem}.png")
            ref = tmp_path / f"{kind}-{stem}-default.png"
            with mpl.rc_context(figures.STYLE):  # as save_figure draws (unhinted text)
                fig.savefig(ref, format="png")
            assert _zlib_level(ours.read_bytes()) == 0  # zlib's fastest class (levels 0-1)
            drawn.append(stem)
            with Image.open(ours) as a, Image.open(ref) as b:
                assert a.mode == b.mode and a.size == b.size, stem
                assert np.array_equal(np.asarray(a), np.asarray(b)), f"{kind} {stem}"
    assert drawn == ["reconstruction", "matrices"]
