"""Run and sweep figures in one matplotlib style, drawn without pyplot (Agg canvas, no global state).

Run figures follow the papers the testbed reproduces: reconstruction of each sensor,
truth vs identified with a zoom window (paper 000, Fig. 2a/3a); the MAC matrix with
its values (Fig. 2b/3b); penalty weights per epoch (Fig. 4); true vs identified
frequencies (Table 2); identified vs true matrices; joint angles truth vs identified
(paper 001, Figs. 3-6); coefficients truth vs identified.  Sweep figures: a score
against noise per identifier, and fit time per identifier.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib as mpl
import numpy as np
from matplotlib.figure import Figure
from matplotlib.patches import Rectangle

STYLE: dict[str, Any] = {
    "font.size": 10, "axes.titlesize": 10, "axes.labelsize": 10, "legend.fontsize": 9,
    "xtick.labelsize": 9, "ytick.labelsize": 9, "axes.grid": True, "grid.alpha": 0.3,
    "axes.spines.top": False, "axes.spines.right": False, "lines.linewidth": 1.2,
    "figure.dpi": 100, "savefig.dpi": 110, "image.cmap": "viridis",
}
# No "savefig.bbox": "tight": constrained layout already keeps every label inside the figure,
# and a tight bounding box costs a second full draw of each figure (measured: 2 of the 5 s of a
# `testbed run` went to five savefig calls).  The dpi stays at 110: rendering is not where
# the time goes, and the smallest figure (a 3-mode frequency table) needs it to stay >= 200 px.
#: Longest line drawn as is; longer ones are drawn as their min/max envelope over this many
#: bins (at 1000 px a bin is under one pixel wide, so the picture is the same).
MAX_POINTS = 4000
TRUTH, IDENT = "#222222", "#d62728"
WIDTH = 10.0  # [in] every figure is this wide, so all read alike at report size


def _fig(height: float, width: float = WIDTH) -> Figure:
    with mpl.rc_context(STYLE):
        return Figure(figsize=(width, height), layout="constrained")


def _axes(fig: Figure, *args: Any, **kw: Any) -> Any:
    with mpl.rc_context(STYLE):
        return fig.subplots(*args, squeeze=False, **kw)


def save_figure(fig: Figure, path: str | os.PathLike) -> Path:
    """Write ``fig`` as PNG to ``path`` in the house style; return the path."""
    path = Path(path)
    with mpl.rc_context(STYLE):
        fig.savefig(path, format="png")
    return path


def _envelope(t: np.ndarray, y: np.ndarray, n_bins: int = MAX_POINTS // 2
              ) -> tuple[np.ndarray, np.ndarray]:
    """``(t, y)`` or, if longer than ``MAX_POINTS``, the min and max of y in each of ``n_bins``
    equal bins (in time order within the bin): what a rasteriser would draw of the full line,
    at a fraction of the cost (100k-sample records)."""
    t, y = np.asarray(t), np.asarray(y)
    if y.size <= MAX_POINTS:
        return t, y
    b = -(-y.size // n_bins)                                  # samples per bin
    yp = np.concatenate([y, np.full(b * n_bins - y.size, y[-1])]).reshape(n_bins, -1)
    base = b * np.arange(n_bins)
    i_lo = np.minimum(base + yp.argmin(axis=1), y.size - 1)
    i_hi = np.minimum(base + yp.argmax(axis=1), y.size - 1)
    idx = np.sort(np.stack([i_lo, i_hi], axis=1), axis=1).ravel()  # time order within a bin
    return t[idx], y[idx]


def _label(quantity: str, unit: str) -> str:
    return f"{quantity} [{unit}]" if unit else quantity


def reconstruction(t: np.ndarray, reference: np.ndarray, simulated: np.ndarray, channels: Sequence[str],
                   unit: str = "m/s^2", quantity: str = "acceleration",
                   zoom: tuple[float, float] | None = None, trac: Sequence[float] | None = None) -> Figure:
    """Truth vs identified signal per channel: whole record (left) and a zoom window (right).

    Parameters
    ----------
    t : ndarray, shape (n_samples,)
        Time [s].
    reference, simulated : ndarray, shape (n_channels, n_samples)
    channels : sequence of str
    zoom : (float, float), optional
        Window [s]; default the first tenth of the record.
    trac : sequence of float, optional
        TRAC per channel, shown in the titles.
    """
    n = len(channels)
    zoom = zoom or (float(t[0]), float(t[0] + 0.1 * (t[-1] - t[0])))
    fig = _fig(1.9 * n + 0.6)
    ax = _axes(fig, n, 2, width_ratios=(2, 1))
    inside = (t >= zoom[0]) & (t <= zoom[1])
    for i, ch in enumerate(channels):
        for a, sel in ((ax[i, 0], slice(None)), (ax[i, 1], inside)):
            a.plot(*_envelope(t[sel], reference[i, sel]), color=TRUTH, label="truth (noise-free)")
            a.plot(*_envelope(t[sel], simulated[i, sel]), color=IDENT, ls="--", label="identified model")
            a.set_ylabel(_label(quantity, unit))
        ax[i, 0].axvspan(*zoom, color="0.85", zorder=0)
        extra = f", TRAC {trac[i]:.3f}" if trac is not None else ""
        ax[i, 0].set_title(f"{ch}{extra}")
        ax[i, 1].set_title(f"{ch}: zoom {zoom[0]:.3g}-{zoom[1]:.3g} s")
    for a in ax[-1]:
        a.set_xlabel("time [s]")
    ax[0, 0].legend(loc="upper right")
    return fig


def mac_matrix(mac: np.ndarray, pair: Sequence[int] | None = None) -> Figure:
    """Heat map of ``mac[identified, true]`` with each value written in its cell; pairs outlined."""
    mac = np.asarray(mac, dtype=float)
    fig = _fig(0.55 * mac.shape[0] + 1.6, min(WIDTH, 0.8 * mac.shape[1] + 3.0))
    ax = _axes(fig)[0, 0]
    im = ax.imshow(mac, vmin=0, vmax=1, cmap="Blues")
    ax.grid(False)
    for (i, j), v in np.ndenumerate(mac):
        ax.text(j, i, f"{v:.2f}", ha="center", va="center", color="white" if v > 0.6 else "black")
    for j, i in enumerate(pair if pair is not None else []):
        ax.add_patch(Rectangle((j - 0.5, i - 0.5), 1, 1, fill=False, ec=IDENT, lw=2))
    ax.set_xticks(range(mac.shape[1]), [f"{j + 1}" for j in range(mac.shape[1])])
    ax.set_yticks(range(mac.shape[0]), [f"{i + 1}" for i in range(mac.shape[0])])
    ax.set_xlabel("true mode (sensor DOFs)")
    ax.set_ylabel("identified mode")
    ax.set_title("MAC")
    fig.colorbar(im, ax=ax, label="MAC [-]")
    return fig


def _series(history: dict[str, Any], prefix: str = "") -> dict[str, np.ndarray]:
    """Per-epoch series of a (nested) history: scalars per epoch, or one series per column."""
    out: dict[str, np.ndarray] = {}
    for k, v in history.items():
        name = f"{prefix}{k}"
        if isinstance(v, dict):
            out.update(_series(v, f"{name}/"))
            continue
        a = np.asarray(v, dtype=float)
        if a.ndim == 1 and a.size > 1:
            out[name] = a
        elif a.ndim == 2 and a.shape[0] > 1:
            out.update({f"{name}[{j}]": a[:, j] for j in range(a.shape[1])})
    return out


def is_weight(name: str) -> bool:
    """Whether a history series is a penalty weight (alpha) rather than a loss term."""
    low = name.lower()
    return "alpha" in low or "weight" in low


def penalty_weights(history: dict[str, Any]) -> Figure | None:
    """Penalty weights vs epoch (left) and loss terms vs epoch (right); None without a history."""
    series = _series(history or {})
    # the x axis and step counts are no loss terms; the mass residual is enforced to round-off
    counters = {"epoch", "n_steps", "step", "steps", "mass_residual"}
    series = {k: v for k, v in series.items()
              if k.lower() not in counters and np.any(np.isfinite(v)) and np.any(v != 0)}
    groups = [(t, {k: v for k, v in series.items() if is_weight(k) == w})
              for t, w in (("penalty weights", True), ("loss terms", False))]
    groups = [(t, g) for t, g in groups if g]
    if not groups:
        return None
    fig = _fig(3.6)
    ax = _axes(fig, 1, len(groups))[0]
    for a, (title, g) in zip(ax, groups, strict=True):
        for k, v in g.items():
            a.plot(np.arange(1, v.size + 1), v, label=k)
        if all(np.all(v[np.isfinite(v)] > 0) for v in g.values()):
            a.set_yscale("log")
        a.set(xlabel="epoch", ylabel=f"{title[:-1]} [-]", title=f"{title} vs epoch")
        a.legend(fontsize=8)
    return fig


def frequency_rows(f_true: np.ndarray, f_id: np.ndarray, pair: Sequence[int] | None = None,
                   z_true: np.ndarray | None = None,
                   z_id: np.ndarray | None = None) -> list[dict[str, float]]:
    """Table rows per true mode: true and paired identified frequency [Hz], error [%], damping."""
    pair = list(pair) if pair is not None else list(range(min(len(f_true), len(f_id))))
    rows = []
    for j, i in enumerate(pair[: len(f_true)]):
        r = {"mode": j + 1, "f_true": float(f_true[j]), "f_id": float(f_id[i]),
             "error_pct": 100.0 * (float(f_id[i]) / float(f_true[j]) - 1.0)}
        if z_true is not None and z_id is not None:
            r.update(z_true=float(z_true[j]), z_id=float(z_id[i]))
        rows.append(r)
    return rows


def frequency_table(rows: list[dict[str, float]]) -> Figure:
    """Table 2 of paper 000 as a figure: mode, true Hz, identified Hz, error %, damping ratios."""
    damp = all("z_true" in r for r in rows)
    head = ["mode", "true [Hz]", "identified [Hz]", "error [%]"] + (["ζ true [-]", "ζ identified [-]"]
                                                                     if damp else [])
    cells = [[f"{r['mode']}", f"{r['f_true']:.2f}", f"{r['f_id']:.2f}", f"{r['error_pct']:+.2f}"]
             + ([f"{r['z_true']:.4f}", f"{r['z_id']:.4f}"] if damp else []) for r in rows]
    fig = _fig(0.35 * len(rows) + 0.9, 7.0)
    ax = _axes(fig)[0, 0]
    ax.axis("off")
    tab = ax.table(cellText=cells, colLabels=head, loc="center", cellLoc="center")
    tab.auto_set_font_size(False)
    tab.set_fontsize(10)
    tab.scale(1, 1.5)
    ax.set_title("natural frequencies: true vs identified")
    return fig


def true_cubic(truth: dict[str, Any], n: int) -> np.ndarray | None:
    """The true cubic matrix in the basis ``x**3`` when the cubic spring acts on one sensor DOF."""
    if "k3" not in truth or "cubic_map" not in truth or "cubic_direction" not in truth:
        return None
    cmap = np.atleast_2d(np.asarray(truth["cubic_map"], dtype=float))
    nz = np.flatnonzero(cmap[0])
    if cmap.shape != (1, n) or nz.size != 1:
        return None
    e = np.zeros(n)
    e[nz[0]] = cmap[0, nz[0]] ** 3
    return float(np.asarray(truth["k3"])) * np.outer(np.asarray(truth["cubic_direction"], dtype=float), e)


def matrices(panels: Sequence[tuple[str, np.ndarray, np.ndarray | None, str]]) -> Figure:
    """Identified (left) vs true (right) matrices as heat maps, one shared colour scale per row.

    Parameters
    ----------
    panels : sequence of (name, identified, true or None, unit)
    """
    fig = _fig(2.9 * len(panels) + 0.4, 8.0)
    ax = _axes(fig, len(panels), 2)
    for r, (name, ident, true, unit) in enumerate(panels):
        mats = [np.asarray(ident, dtype=float), None if true is None else np.asarray(true, dtype=float)]
        lim = max(float(np.max(np.abs(m))) for m in mats if m is not None) or 1.0
        for c, (m, who) in enumerate(zip(mats, ("identified", "true"), strict=True)):
            a = ax[r, c]
            a.grid(False)
            if m is None:
                a.axis("off")
                a.text(0.5, 0.5, f"no true {name}\nin this basis", ha="center", va="center",
                       transform=a.transAxes)
                continue
            im = a.imshow(m, cmap="RdBu_r", vmin=-lim, vmax=lim)
            if m.shape[0] <= 6:
                for (i, j), v in np.ndenumerate(m):
                    a.text(j, i, f"{v:.3g}", ha="center", va="center", fontsize=8,
                           color="white" if abs(v) > 0.6 * lim else "black")
            err = "" if c or mats[1] is None else \
                f" (rel. error {np.linalg.norm(m - mats[1]) / max(np.linalg.norm(mats[1]), 1e-300):.2%})"
            a.set_title(f"{name} {who}{err}")
            a.set_xticks(range(m.shape[1]), [str(j + 1) for j in range(m.shape[1])])
            a.set_yticks(range(m.shape[0]), [str(i + 1) for i in range(m.shape[0])])
            a.set(xlabel="sensor DOF (column)", ylabel="sensor DOF (row)")
        fig.colorbar(im, ax=ax[r, :], label=_label(name, unit), shrink=0.9)
    # fixed-aspect images beside a shared colour bar: constrained layout converges in its
    # second pass only, so run the first here (savefig runs one more)
    fig.draw_without_rendering()
    return fig


def joint_angles(t: np.ndarray, reference: np.ndarray, simulated: np.ndarray, channels: Sequence[str],
                 rmse: Sequence[float] | None = None, unit: str = "rad") -> Figure:
    """One panel per joint: noise-free truth vs the identified model simulated (paper 001, Figs 3-6)."""
    n = len(channels)
    cols = 2 if n > 1 else 1
    rows = math.ceil(n / cols)
    fig = _fig(2.6 * rows + 0.5)
    ax = _axes(fig, rows, cols, sharex=True).ravel()
    for i, ch in enumerate(channels):
        ax[i].plot(*_envelope(t, reference[i]), color=TRUTH, label="truth (noise-free)")
        ax[i].plot(*_envelope(t, simulated[i]), color=IDENT, ls="--", label="identified model")
        ax[i].set_ylabel(_label(f"joint angle {ch}", unit))
        ax[i].set_title(ch + (f": RMSE {rmse[i]:.4g} {unit}" if rmse is not None else ""))
    for a in ax[n:]:
        a.axis("off")
    for a in ax[max(0, n - cols):n]:
        a.set_xlabel("time [s]")
    ax[0].legend(loc="best")
    return fig


def coefficients(terms: Sequence[str], coef_true: np.ndarray, coef_id: np.ndarray,
                 errors: Sequence[float] | None = None) -> Figure:
    """Grouped bars per equation: true vs identified coefficient of every library term."""
    T, I = np.atleast_2d(coef_true), np.atleast_2d(coef_id)
    n = T.shape[0]
    fig = _fig(3.2 * n + 0.8)
    ax = _axes(fig, n, 1)[:, 0]
    x = np.arange(len(terms))
    for k in range(n):
        ax[k].bar(x - 0.2, T[k], 0.4, color=TRUTH, label="true")
        ax[k].bar(x + 0.2, I[k], 0.4, color=IDENT, label="identified")
        ax[k].axhline(0, color="0.5", lw=0.6)
        ax[k].set_xticks(x, list(terms), rotation=60, ha="right", fontsize=8)
        ax[k].set_ylabel("coefficient [-]")
        ax[k].set_title(f"equation {k + 1}" + (f": relative error {errors[k]:.3g}" if errors is not None
                                               else ""))
    ax[0].legend()
    return fig


def score_vs_noise(rows: Sequence[dict[str, Any]], metric: str) -> Figure:
    """Median (line) and min-max over seeds (band) of ``metric`` against noise, per identifier."""
    fig = _fig(3.8, 8.0)
    ax = _axes(fig)[0, 0]
    for ident in sorted({r["identifier"] for r in rows}):
        pts: dict[float, list[float]] = {}
        for r in rows:
            v = r.get(metric)
            if r["identifier"] == ident and v is not None and np.isfinite(float(v)):
                pts.setdefault(float(r["noise"]), []).append(float(v))
        if not pts:
            continue
        nz = sorted(pts)
        med = [float(np.median(pts[z])) for z in nz]
        line, = ax.plot(nz, med, marker="o", label=ident)
        ax.fill_between(nz, [min(pts[z]) for z in nz], [max(pts[z]) for z in nz],
                        color=line.get_color(), alpha=0.15)
    ax.set(xlabel="noise [% of channel RMS]", ylabel=f"{metric} [-]", title=f"{metric} vs noise")
    ax.legend(title="identifier")
    return fig


def fit_times(rows: Sequence[dict[str, Any]]) -> Figure:
    """Fit time [s] per identifier: one box per identifier over all its cells."""
    idents = sorted({r["identifier"] for r in rows})
    data = [[float(r["fit_time"]) for r in rows if r["identifier"] == i and r.get("fit_time") is not None
             and np.isfinite(float(r["fit_time"]))] for i in idents]
    fig = _fig(0.5 * len(idents) + 1.8, 8.0)
    ax = _axes(fig)[0, 0]
    boxes = [d or [np.nan] for d in data]
    try:
        ax.boxplot(boxes, orientation="horizontal")
    except TypeError:  # matplotlib < 3.10
        ax.boxplot(boxes, vert=False)
    ax.set_yticks(range(1, len(idents) + 1), idents)
    if all(d and min(d) > 0 for d in data):
        ax.set_xscale("log")
    ax.set(xlabel="fit time [s]", title="fit time per identifier")
    return fig


def run_figures(run: Any) -> dict[str, Figure]:
    """Every figure a saved run (:class:`~testbed.studies.runstore.SavedRun`) supports, by stem."""
    d, figs = run.details, {}
    if "simulated_xdd" in d:
        figs["reconstruction"] = reconstruction(d["t"], d["reference_xdd"], d["simulated_xdd"],
                                                d["channels"], trac=d.get("trac"))
    if "mac" in d:
        figs["mac"] = mac_matrix(d["mac"], d.get("pair"))
    if "f_id" in d:
        figs["frequencies"] = frequency_table(frequency_rows(d["f_true"], d["f_id"], d.get("pair"),
                                                             d.get("z_true"), d.get("z_id")))
    if "M_id" in d:
        panels = [("M", d["M_id"], d.get("Mr"), "kg"), ("K", d["K_id"], d.get("Kr"), "N/m")]
        if run.model.get("K3_") is not None:
            panels.append(("K3", run.model["K3_"], true_cubic(run.truth, len(d["channels"])), "N/m^3"))
        figs["matrices"] = matrices(panels)
    if (pw := penalty_weights(run.history)) is not None:
        figs["penalty_weights"] = pw
    if "simulated_x" in d:
        figs["joint_angles"] = joint_angles(d["t"], d["reference_x"], d["simulated_x"], d["channels"],
                                            d.get("angle_rmse"))
    if "coef_true" in d:
        figs["coefficients"] = coefficients(d["terms"], d["coef_true"], d["coef_id"], d.get("coef_errors"))
    return figs


def save_run_figures(run: Any, directory: str | os.PathLike) -> list[Path]:
    """Render :func:`run_figures` of ``run`` into ``directory`` as ``<stem>.png``."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    return [save_figure(f, directory / f"{stem}.png") for stem, f in run_figures(run).items()]
