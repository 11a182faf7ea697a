"""Run and sweep figures in one matplotlib style, drawn without pyplot (Agg canvas, no global state).

Run figures follow the papers the testbed reproduces: reconstruction of each sensor,
truth vs identified with a zoom window (paper 000, Fig. 2a/3a); where the model deviates
(PSD of measured, simulated and residual acceleration per sensor, and the residual over
time); the MAC matrix with its values (Fig. 2b/3b); penalty weights per epoch (Fig. 4);
true vs identified frequencies (Table 2); identified vs true M, C, K (and K3) side by side
with their relative errors; joint angles truth vs identified (paper 001, Figs. 3-6) with
the angle errors and the recorded torques below; coefficients truth vs identified.

Sweep figures: per score, a panel per scenario (shared axes) with a line per identifier
(median over seeds, interquartile band) against noise, the unit from the metric catalogue
(:func:`metric_unit`), a log axis where the values span decades (:func:`wants_log`) and the
scenario's thresholds; fit time per identifier.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import os
import re
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from testbed.core.atomic import PNG_FILE, PNG_SOFTWARE, atomic_write, refuse_foreign
from testbed.core.dataset import Dataset
from testbed.core.truth import StructuralTruth, Truth, TruthError, truth_type
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.scenario import Scenario
from testbed.reporting import frames
from testbed.reporting.mplconfig import ensure_config_dir

if TYPE_CHECKING:
    from matplotlib.figure import Figure

# matplotlib is imported where a figure is drawn (about 0.35 s of import), not with this module:
# a run without figures, a report's text, a sweep's summary do not pay for it.
ensure_config_dir()  # before that import, and before the drawing processes are forked

STYLE: dict[str, Any] = {
    "font.size": 10, "axes.titlesize": 10, "axes.labelsize": 10, "legend.fontsize": 9,
    "xtick.labelsize": 9, "ytick.labelsize": 9, "axes.grid": True, "grid.alpha": 0.3,
    "axes.spines.top": False, "axes.spines.right": False, "lines.linewidth": 1.2,
    "figure.dpi": 100, "savefig.dpi": 110, "image.cmap": "viridis",
    # a title at a fixed height: matplotlib otherwise measures every axis's top tick labels to
    # lift the title over them (none of our axes has any)
    "axes.titley": 1.0,
    # glyphs drawn unhinted, as matplotlib draws them into PDF and SVG: hinting cost about a
    # tenth of the six figures of `testbed run cantilever_stiff_impact` (2.26 -> 2.06 s CPU,
    # minimum of 10 interleaved rounds, 2 cores under load 15) and is not visible at 110 dpi
    "text.hinting": "no_hinting",
}
# No "savefig.bbox": "tight" and no constrained layout for the run figures: both measure every
# text of the figure in extra draw passes (measured: 2 of the 5 s of a `testbed run` went to
# six savefig calls, more than half of it in constrained layout).  Run figures are laid out once
# from margins in inches (:func:`_fixed_layout`), sized from the tick labels' text.  The dpi
# stays at 110: rendering is not where the time goes, and the smallest figure (a 3-mode
# frequency table) needs it to stay >= 200 px.
#: zlib level of the PNGs: 1, zlib's fastest.  PNG is lossless, so the pixels are those of any
#: level; only the bytes and the size differ.  The six figures of a cantilever run encode in
#: 0.100 s of CPU at level 1, 0.151 s at 3 and 0.204 s at 6 (matplotlib's default), and take
#: 539, 525 and 523 kB (2026-11-27, best of 5).
PNG_COMPRESS_LEVEL = 1
#: Longest line drawn as is; longer ones are drawn as their min/max envelope over this many
#: bins (at 1000 px a bin is under one pixel wide, so the picture is the same).
MAX_POINTS = 4000
TRUTH, IDENT = "#222222", "#d62728"
WIDTH = 10.0  # [in] every figure is this wide, so all read alike at report size


def _styled(fn: Callable[..., Any]) -> Callable[..., Any]:
    """Run a figure builder inside the house style (every artist it makes takes STYLE)."""
    @functools.wraps(fn)
    def wrapper(*args: Any, **kw: Any) -> Any:
        import matplotlib as mpl

        with mpl.rc_context(STYLE):
            return fn(*args, **kw)
    return wrapper


def _fig(height: float, width: float = WIDTH, layout: str | None = None) -> Figure:
    """A figure of ``width`` x ``height`` [in]; ``layout="constrained"`` for the sweep figures
    (their legend sits outside the axes), none for the run figures (:func:`_fixed_layout`)."""
    import matplotlib as mpl
    from matplotlib.figure import Figure

    if frames.recording():  # a builder that makes its own figure has no frame to record
        raise frames.Recorded
    with mpl.rc_context(STYLE):
        return Figure(figsize=(width, height), layout=layout)


def _axes(fig: Figure, *args: Any, **kw: Any) -> Any:
    import matplotlib as mpl

    with mpl.rc_context(STYLE):
        return fig.subplots(*args, squeeze=False, **kw)


def _frame(height: float, width: float = WIDTH, *grid: int, ticks: tuple[int, int] = frames.TICKS,
           **kw: Any) -> tuple[Figure, Any]:
    """A run figure of ``width`` x ``height`` [in] and its axes ``_axes(fig, *grid, **kw)``
    (shape ``grid``), made ahead of time where :func:`prepare_run_frames` did (same frame);
    ``ticks``: the major ticks (x, y) its axes likely show (:func:`frames.take`)."""
    key = (float(height), float(width), tuple(int(g) for g in grid), tuple(sorted(kw.items())))
    return frames.take(key, lambda: _make_frame(key), ticks)


def _make_frame(key: tuple) -> tuple[Figure, Any]:
    """The figure and axes of a :func:`_frame` key."""
    height, width, grid, kw = key
    fig = _fig(height, width)
    return fig, _axes(fig, *grid, **dict(kw))


def prepare_run_frames(run: Any) -> int:
    """Make the frames of the figures of ``run`` (a :class:`~testbed.studies.runstore.SavedRun`)
    into the pool of :mod:`testbed.reporting.frames`: a later run of the same shape (same
    scenario, another seed or version of the model) takes them instead of making its own.
    Returns the number made (0 for a run without run figures)."""
    # recorded inputs are only read by the joint-angle figure, which makes its own figure
    # (no frame): a placeholder spares reading the dataset
    keys = frames.record(_run_builders(run, (np.zeros((0, 0)), [], "N m")).values())
    return frames.prepare(keys, _make_frame, STYLE)


def png_bytes(fig: Figure) -> bytes:
    """``fig`` encoded as PNG in the house style (zlib level :data:`PNG_COMPRESS_LEVEL`: the
    same pixels, a third less encoding time than the default), with the text chunk ``Software``
    = :data:`~testbed.core.atomic.PNG_SOFTWARE` by which a later report knows the file for its
    own (a user's own PNG of the name is refused, not replaced: review 28b M2)."""
    import io

    import matplotlib as mpl

    buf = io.BytesIO()
    with mpl.rc_context(STYLE):
        fig.savefig(buf, format="png", metadata={"Software": PNG_SOFTWARE},
                    pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL})
    return buf.getvalue()


def save_figure(fig: Figure, path: str | os.PathLike) -> Path:
    """Write ``fig`` as PNG to ``path`` in the house style, atomically; return the path.

    A report written on a full disk left a PNG of 0 bytes and ended in an internal error
    (OSError 28, naming no file; round 12): the write is now :func:`atomic_write`'s, which
    leaves the old file or the new one and names ``path`` in one line for want of room.
    A file at ``path`` that is not a PNG of the testbed (the user's own) is refused, not replaced (round 27;
    :func:`~testbed.core.atomic.refuse_foreign`).  A report checks all its outputs before it
    writes any (:meth:`testbed.reporting.report.Page.write`, with :func:`png_bytes`).
    """
    refuse_foreign(path, PNG_FILE, expected="a folder without it, or remove the file")
    data = png_bytes(fig)
    return atomic_write(path, lambda tmp: Path(tmp).write_bytes(data))


#: Text heights [in] of the house style: a 9 pt tick label with its 3.5 pt tick and 3.5 pt pad,
#: a 10 pt axis label with its 4 pt pad, one 10 pt title line with its 6 pt pad.
_TICK_H, _LABEL_H, _TITLE_H = (9 * 1.2 + 7) / 72, (10 * 1.2 + 4) / 72, (10 * 1.2 + 6) / 72


def _text_width(text: str, size_pt: float) -> float:
    """Width [in] of ``text`` in DejaVu Sans at ``size_pt``, from per-character advances (an
    upper estimate: digits 0.64 em, minus signs and wide letters 0.84 em, points 0.32 em)."""
    em = sum(0.32 if c in ".,:;!|il'" else 0.84 if c in "\u2212-mwMW" else 0.64 for c in text)
    return em * size_pt / 72.0


def _ytick_width(ax: Any) -> float:
    """Widest y tick label of ``ax`` [in], estimated from its text (nothing is drawn)."""
    if not ax.axison or not ax.yaxis.get_tick_params().get("labelleft", True):
        return 0.0
    lo, hi = sorted(ax.get_ylim())
    tol = 1e-9 * abs(hi - lo)
    locs = [v for v in ax.yaxis.get_majorticklocs() if lo - tol <= v <= hi + tol]
    labels = ax.yaxis.get_major_formatter().format_ticks(locs) if locs else []
    return max((_text_width(str(t), 9) for t in labels), default=0.0)


#: Relative tolerance, in the axis's own scale, of a tick kept at the edge of the view by
#: :func:`_in_view_locator`: 1e4 times matplotlib's own (1e-10 of the view's span), so that it keeps
#: every tick matplotlib draws (and may keep one it does not: it is not drawn either).
IN_VIEW_RTOL = 1e-6


@functools.cache
def _in_view_class() -> type:
    """The locator class of :func:`_in_view_locator` (made once: matplotlib loads on first use)."""
    from matplotlib.ticker import Locator

    class InView(Locator):
        """The ticks of locator ``base`` that are inside the view (see :func:`_in_view_locator`)."""

        def __init__(self, base: Any) -> None:
            self.base = base

        def set_axis(self, axis: Any) -> None:
            self.axis = axis
            self.base.set_axis(axis)

        def __call__(self) -> Any:
            locs = np.asarray(self.base())
            if not locs.size:
                return locs
            scale = self.axis.get_transform()
            lo, hi = sorted(scale.transform(np.asarray(self.axis.get_view_interval(), dtype=float)))
            tol = IN_VIEW_RTOL * (hi - lo)
            with np.errstate(invalid="ignore", divide="ignore"):  # log of a tick <= 0: dropped
                at = scale.transform(locs.astype(float))
            return locs[(at >= lo - tol) & (at <= hi + tol)]

        def tick_values(self, vmin: float, vmax: float) -> Any:
            return self.base.tick_values(vmin, vmax)

        def nonsingular(self, v0: float, v1: float) -> Any:
            return self.base.nonsingular(v0, v1)

        def view_limits(self, vmin: float, vmax: float) -> Any:
            return self.base.view_limits(vmin, vmax)

    return InView


def _in_view_locator(base: Any) -> Any:
    """``base`` (a matplotlib locator) giving only the ticks inside the view.

    matplotlib makes a tick object (three lines, two texts) and a label for every location its
    locator gives, and draws only those inside the view: the default locators give one or two
    beyond each end (measured: 62 of the 328 tick objects made for the six figures of ``testbed
    run cantilever_stiff_impact``, which draw 198; 8 % of the figures' CPU, per-round ratio
    median 0.92 over 16 interleaved rounds).  The picture is the same (tested,
    byte for byte): the ticks drawn are the same, the scalar formatter takes its offset and
    exponent from the ticks in view and its number of decimals from their common spacing.
    Limits (``nonsingular``, ``view_limits``) are ``base``'s.
    """
    return _in_view_class()(base)


def _ticks_in_view(fig: Figure) -> None:
    """Every axis of ``fig`` (colour bars included) makes only the ticks it draws
    (:func:`_in_view_locator`); fixed and empty locators are left as they are."""
    from matplotlib.ticker import FixedLocator, NullLocator

    skip = (FixedLocator, NullLocator, _in_view_class())
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            loc = axis.get_major_locator()  # (shared axes share it: wrapped once)
            if not isinstance(loc, skip):
                axis.set_major_locator(_in_view_locator(loc))


def _fixed_layout(fig: Figure, grid: Any, *, right: float = 0.2, top_extra: float = 0.0,
                  bottom_extra: float = 0.0, row_extra: float = 0.0) -> None:
    """Margins and gaps [in] of a grid of axes from its texts, set once (no layout engine);
    then only the ticks in view are made (:func:`_ticks_in_view`).

    Each column's left room is its widest y tick label plus the y label; each row's top room
    its title lines, its bottom room the x tick labels and x label, as far as shown.

    Parameters
    ----------
    fig : Figure
    grid : array of Axes, shape (rows, cols)
        The axes of one GridSpec without parameters of its own (it takes the figure's subplot
        parameters, set here), as :func:`_axes` returns them (spanning axes: repeat them).
    right : float
        Right margin [in] (a colour bar's room).
    top_extra, bottom_extra, row_extra : float
        More room [in] above the grid, below it, between rows.
    """
    grid = np.asarray(grid, dtype=object)
    rows, cols = grid.shape
    W, H = fig.get_size_inches()
    left = np.zeros(cols)
    title, below = np.zeros(rows), np.zeros(rows)
    for (r, c), ax in np.ndenumerate(grid):
        if ax is None or not ax.axison:
            continue
        left[c] = max(left[c], _ytick_width(ax) + 0.1 + (_LABEL_H if ax.get_ylabel() else 0.0))
        if ax.get_title():
            title[r] = max(title[r], _TITLE_H * (ax.get_title().count("\n") + 1))
        shown = ax.xaxis.get_tick_params().get("labelbottom", True)
        below[r] = max(below[r], (_TICK_H if shown else 0.05) + (_LABEL_H if ax.get_xlabel() else 0.0))
    l_in = left[0] + 0.1
    t_in = title[0] + 0.1 + top_extra
    b_in = below[-1] + 0.1 + bottom_extra
    gap_w = (left[1:].max() + 0.25) if cols > 1 else 0.0
    gap_h = (max(below[r] + title[r + 1] for r in range(rows - 1)) + 0.1 + row_extra) if rows > 1 else 0.0
    aw = (W - l_in - right - (cols - 1) * gap_w) / cols   # mean axes width [in]
    ah = (H - t_in - b_in - (rows - 1) * gap_h) / rows    # mean axes height [in]
    params = {"left": l_in / W, "right": 1.0 - right / W, "bottom": b_in / H, "top": 1.0 - t_in / H,
              "wspace": gap_w / max(aw, 0.1), "hspace": gap_h / max(ah, 0.1)}
    fig.subplots_adjust(**params)
    _ticks_in_view(fig)


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


def _log_y(ax: Any) -> None:
    """Logarithmic y axis with plain ``1e-3`` tick labels: mathtext labels (``10^{-3}``) cost
    most of a small figure's layout time (measured: 1.6 of 2.4 s of a 3-row spectrum figure)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter, NullLocator

    ax.set_yscale("log")
    ax.yaxis.set_major_locator(LogLocator(numticks=5))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:.0e}".replace("e-0", "e-")
                                               .replace("e+0", "e").replace("e+", "e")))
    ax.yaxis.set_minor_formatter(NullFormatter())
    # no minor tick marks: unlabelled, they cost as much to make as labelled ones (58 of the 372
    # ticks of a `testbed run` figure set were minor ticks of one penalty-weight panel)
    ax.yaxis.set_minor_locator(NullLocator())


def _label(quantity: str, unit: str) -> str:
    return f"{quantity} [{unit}]" if unit else quantity


@_styled
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
    # one time axis per column, labelled under the last row only (the rows above repeat it)
    fig, ax = _frame(1.9 * n + 0.6, WIDTH, n, 2, width_ratios=(2, 1), sharex="col")
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
    _fixed_layout(fig, ax)
    return fig


@_styled
def mac_matrix(mac: np.ndarray, pair: Sequence[int] | None = None) -> Figure:
    """Heat map of ``mac[identified, true]`` with each value written in its cell; pairs outlined."""
    from matplotlib.patches import Rectangle

    mac = np.asarray(mac, dtype=float)
    fig, grid = _frame(0.55 * mac.shape[0] + 1.6, min(WIDTH, 0.8 * mac.shape[1] + 3.0),
                       ticks=(mac.shape[1], mac.shape[0]))
    ax = grid[0, 0]
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
    _fixed_layout(fig, grid, right=0.15)  # the colour bar sits inside the axes' cell
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


@_styled
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
    fig, ax = _frame(3.6, WIDTH, 1, len(groups))
    ax = ax[0]
    for a, (title, g) in zip(ax, groups, strict=True):
        for k, v in g.items():
            a.plot(np.arange(1, v.size + 1), v, label=k)
        if all(np.all(v[np.isfinite(v)] > 0) for v in g.values()):
            _log_y(a)
        a.set(xlabel="epoch", ylabel=f"{title[:-1]} [-]", title=f"{title} vs epoch")
        a.legend(fontsize=8)
    _fixed_layout(fig, ax[None, :])
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


@_styled
def frequency_table(rows: list[dict[str, float]]) -> Figure:
    """Table 2 of paper 000 as a figure: mode, true Hz, identified Hz, error %, damping ratios."""
    damp = all("z_true" in r for r in rows)
    head = ["mode", "true [Hz]", "identified [Hz]", "error [%]"] + (["ζ true [-]", "ζ identified [-]"]
                                                                     if damp else [])
    cells = [[f"{r['mode']}", f"{r['f_true']:.2f}", f"{r['f_id']:.2f}", f"{r['error_pct']:+.2f}"]
             + ([f"{r['z_true']:.4f}", f"{r['z_id']:.4f}"] if damp else []) for r in rows]
    fig, ax = _frame(0.35 * len(rows) + 0.9, 7.0, ticks=(0, 0))  # no axis shown
    ax = ax[0, 0]
    ax.axis("off")
    tab = ax.table(cellText=cells, colLabels=head, loc="center", cellLoc="center")
    tab.auto_set_font_size(False)
    tab.set_fontsize(10)
    tab.scale(1, 1.5)
    ax.set_title("natural frequencies: true vs identified")
    h = fig.get_size_inches()[1]
    fig.subplots_adjust(left=0.02, right=0.98, bottom=0.1 / h, top=1.0 - (_TITLE_H + 0.1) / h)
    return fig


def typed_truth(run: Any) -> Truth | None:
    """The truth of a saved run as its kind's dataclass (:mod:`testbed.core.truth`), or None if
    the run's kind has none or its stored truth does not validate (a figure then leaves the true
    panel out rather than failing)."""
    try:
        return truth_type(run.kind).from_dict(run.truth)
    except TruthError:
        return None


def true_cubic(truth: Truth | None, n: int) -> np.ndarray | None:
    """The true cubic matrix in the basis ``x**3`` when the cubic spring acts on one sensor DOF.

    Parameters
    ----------
    truth : StructuralTruth or None
        Its ``k3`` [N/m^3], ``cubic_map`` and ``cubic_direction`` (m,) are read.
    n : int
        Sensor DOFs of the identified model.
    """
    if not isinstance(truth, StructuralTruth) or truth.k3 is None or truth.cubic_map is None \
            or truth.cubic_direction is None:
        return None
    cmap = np.atleast_2d(truth.cubic_map)
    nz = np.flatnonzero(cmap[0])
    if cmap.shape != (1, n) or nz.size != 1:
        return None
    e = np.zeros(n)
    e[nz[0]] = cmap[0, nz[0]] ** 3
    return float(truth.k3) * np.outer(truth.cubic_direction, e)


def relative_error(ident: np.ndarray, true: np.ndarray) -> float:
    """Relative Frobenius error ``||ident - true|| / ||true||`` (NaN without a finite truth)."""
    ident, true = np.asarray(ident, dtype=float), np.asarray(true, dtype=float)
    den = float(np.linalg.norm(true))
    if ident.shape != true.shape or not np.isfinite(den) or den == 0.0:
        return float("nan")
    return float(np.linalg.norm(ident - true)) / den


@_styled
def matrices(panels: Sequence[tuple[str, np.ndarray, np.ndarray | None, str]]) -> Figure:
    """Identified (top row) vs true (bottom row) matrices as heat maps, one column per matrix.

    Each column shares one colour scale (its own colour bar, with the matrix's unit); the
    identified panel's title gives its relative Frobenius error against the truth.

    Parameters
    ----------
    panels : sequence of (name, identified, true or None, unit)
        E.g. ``[("M", M_id, Mr, "kg"), ("C", C_id, Cr, "N s/m"), ("K", K_id, Kr, "N/m")]``.
    """
    n = len(panels)
    size = max(np.asarray(p[1]).shape[0] for p in panels)
    fig, ax = _frame(5.6 if size <= 6 else 6.4, min(WIDTH, 3.4 * n + 0.4), 3, n,
                     height_ratios=(1.0, 1.0, 0.07), ticks=(size, size))  # last row: colour bars
    for c, (name, ident, true, unit) in enumerate(panels):
        mats = [np.asarray(ident, dtype=float), None if true is None else np.asarray(true, dtype=float)]
        lim = max(float(np.nanmax(np.abs(m))) for m in mats if m is not None) or 1.0
        # values such as 9.57e+06 do not fit a cell: show them in units of 10^k
        k = int(np.floor(np.log10(lim))) if np.isfinite(lim) else 0
        scale = 10.0**k if abs(k) >= 3 else 1.0
        mats = [None if m is None else m / scale for m in mats]
        lim /= scale
        shown_unit = f"1e{k} {unit}" if scale != 1.0 else unit
        im = None
        for r, (m, who) in enumerate(zip(mats, ("identified", "true"), strict=True)):
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
                    a.text(j, i, f"{v:.3g}", ha="center", va="center", fontsize=7,
                           color="white" if abs(v) > 0.6 * lim else "black")
            err = "" if r or mats[1] is None else f"\nrel. error {relative_error(m, mats[1]):.2%}"
            a.set_title(f"{name} {who}{err}")
            a.set_xticks(range(m.shape[1]), [str(j + 1) for j in range(m.shape[1])])
            a.set_yticks(range(m.shape[0]), [str(i + 1) for i in range(m.shape[0])])
            a.set(xlabel="sensor DOF", ylabel="sensor DOF" if c == 0 else "")
        cax = ax[2, c]
        if im is not None:
            cax.set_label("<colorbar>")
            fig.colorbar(im, cax=cax, orientation="horizontal", label=_label(name, shown_unit))
        else:
            cax.axis("off")
    _fixed_layout(fig, ax, right=0.3)
    return fig


def psd(y: np.ndarray, fs: float, nperseg: int = 1024) -> tuple[np.ndarray, np.ndarray]:
    """One-sided power spectral density of each row of ``y`` (Welch: Hann, 50 % overlap).

    Written with numpy alone (no ``scipy.signal`` import for a figure).

    Parameters
    ----------
    y : ndarray, shape (n_channels, n_samples) or (n_samples,)
    fs : float
        Sample rate [Hz].
    nperseg : int
        Segment length (shortened to the record if longer).

    Returns
    -------
    f : ndarray, shape (nperseg // 2 + 1,)
        Frequencies [Hz].
    p : ndarray, shape (n_channels, nperseg // 2 + 1)
        PSD [unit^2/Hz].
    """
    y = np.atleast_2d(np.asarray(y, dtype=float))
    n = int(min(nperseg, y.shape[1]))
    w = np.hanning(n)
    step = max(1, n // 2)
    segs = np.lib.stride_tricks.sliding_window_view(y, n, axis=1)[:, ::step]
    segs = segs - segs.mean(axis=2, keepdims=True)
    spec = np.abs(np.fft.rfft(segs * w, axis=2)) ** 2
    p = spec.mean(axis=1) / (fs * np.sum(w**2))
    p[:, 1:-1 if n % 2 == 0 else None] *= 2.0
    return np.fft.rfftfreq(n, 1.0 / fs), p


@_styled
def spectra(t: np.ndarray, reference: np.ndarray, simulated: np.ndarray, channels: Sequence[str],
            unit: str = "m/s^2", frequencies: Sequence[float] | None = None,
            f_max: float | None = None) -> Figure:
    """Where the model deviates: PSD of measured vs simulated signal and of their difference
    (left), and the time residual measured - simulated (right), one row per channel.

    Parameters
    ----------
    t : ndarray, shape (n_samples,)
        Time [s] (uniform).
    reference, simulated : ndarray, shape (n_channels, n_samples)
        Noise-free measured signal and the identified model's simulation of it.
    channels : sequence of str
    unit : str
        Unit of the signals.
    frequencies : sequence of float, optional
        True natural frequencies [Hz], marked as dotted vertical lines.
    f_max : float, optional
        Upper frequency limit [Hz]; default 1.5x the highest marked frequency (or Nyquist).
    """
    t = np.asarray(t, dtype=float)
    ref, sim = np.atleast_2d(reference), np.atleast_2d(simulated)
    fs = 1.0 / float(t[1] - t[0])
    ok = np.all(np.isfinite(sim))
    n = len(channels)
    fig, ax = _frame(2.0 * n + 0.7, WIDTH, n, 2, width_ratios=(1, 1.2), sharex="col")
    nper = int(2 ** np.clip(np.round(np.log2(ref.shape[1] / 8)), 6, 13))
    f, p_ref = psd(ref, fs, nper)
    _, p_sim = psd(np.nan_to_num(sim), fs, nper)
    _, p_res = psd(np.nan_to_num(ref - sim), fs, nper)
    freqs = [float(x) for x in (frequencies if frequencies is not None else []) if np.isfinite(x)]
    top = f_max or (1.5 * max(freqs) if freqs else fs / 2)
    band = (f > 0) & (f <= top)
    for i, ch in enumerate(channels):
        a = ax[i, 0]
        a.plot(f[band], p_ref[i, band], color=TRUTH, label="measured (noise-free)")
        if ok:
            a.plot(f[band], p_sim[i, band], color=IDENT, ls="--", label="identified model")
            a.plot(f[band], p_res[i, band], color="#1f77b4", lw=0.9, label="residual")
        _log_y(a)
        for fr in freqs:
            if fr <= top:
                a.axvline(fr, color="0.5", ls=":", lw=0.8)
        a.set_ylabel(f"PSD [({unit})^2/Hz]")
        a.set_title(f"{ch}: spectrum")
        b = ax[i, 1]
        b.plot(*_envelope(t, ref[i] - sim[i]), color="#1f77b4", lw=0.8)
        b.set_ylabel(_label("residual", unit))
        rel = float(np.sqrt(np.mean((ref[i] - sim[i]) ** 2)) / max(np.sqrt(np.mean(ref[i] ** 2)), 1e-300))
        b.set_title(f"{ch}: measured - simulated (RMS {rel:.2%} of signal)" if ok
                    else f"{ch}: no simulation (failed)")
    ax[-1, 0].set_xlabel("frequency [Hz]")
    ax[-1, 1].set_xlabel("time [s]")
    ax[0, 0].legend(loc="upper right", fontsize=8)
    _fixed_layout(fig, ax)
    return fig


@_styled
def joint_angles(t: np.ndarray, reference: np.ndarray, simulated: np.ndarray, channels: Sequence[str],
                 rmse: Sequence[float] | None = None, unit: str = "rad", errors: bool = True,
                 inputs: np.ndarray | None = None, input_channels: Sequence[str] = (),
                 input_unit: str = "N m") -> Figure:
    """One panel per joint: noise-free truth vs the identified model simulated (paper 001,
    Figs 3-6); below them, on the same time axis, the angle error of every joint and the
    recorded inputs (torques) that drove the simulation.

    Parameters
    ----------
    t : ndarray, shape (n_samples,)
    reference, simulated : ndarray, shape (n_channels, n_samples)
        Noise-free recorded angles and the identified model's simulation.
    channels : sequence of str
    rmse : sequence of float, optional
        RMSE per joint, shown in the titles.
    unit : str
        Angle unit.
    errors : bool
        Add the panel of angle errors (simulated - truth) over time.
    inputs : ndarray, shape (n_inputs, n_samples), optional
        Recorded inputs (:func:`recorded_inputs`); without them no input panel.
    input_channels : sequence of str
    input_unit : str
    """
    n = len(channels)
    cols = 2 if n > 1 else 1
    rows = math.ceil(n / cols)
    has_u = inputs is not None and np.size(inputs) > 0
    extra = int(errors) + int(has_u)
    fig = _fig(2.4 * rows + 2.3 * extra + 0.5)
    gs = fig.add_gridspec(rows + extra, cols)
    first = fig.add_subplot(gs[0, 0])
    ax = [first] + [fig.add_subplot(gs[i // cols, i % cols], sharex=first) for i in range(1, rows * cols)]
    wide = [fig.add_subplot(gs[rows + k, :], sharex=first) for k in range(extra)]
    for i, ch in enumerate(channels):
        ax[i].plot(*_envelope(t, reference[i]), color=TRUTH, label="truth (noise-free)")
        ax[i].plot(*_envelope(t, simulated[i]), color=IDENT, ls="--", label="identified model")
        ax[i].set_ylabel(_label(f"joint angle {ch}", unit))
        ax[i].set_title(ch + (f": RMSE {rmse[i]:.4g} {unit}" if rmse is not None else ""))
    for a in ax[n:]:
        a.axis("off")
    ax[0].legend(loc="best")
    if errors:
        e = wide[0]
        err = np.asarray(simulated, dtype=float) - np.asarray(reference, dtype=float)
        for i, ch in enumerate(channels):
            e.plot(*_envelope(t, err[i]), lw=0.9, label=ch)
        e.axhline(0, color="0.5", lw=0.6)
        e.set_ylabel(_label("angle error", unit))
        e.set_title("angle error: identified model - truth, per joint")
        e.legend(loc="upper left", ncols=min(4, n), fontsize=8)
    if has_u:
        b = wide[-1]
        u = np.atleast_2d(np.asarray(inputs, dtype=float))
        names = list(input_channels) or [f"u{j + 1}" for j in range(u.shape[0])]
        tu = t if u.shape[1] == t.size else np.arange(u.shape[1]) * (t[1] - t[0])
        for j, name in enumerate(names):
            b.plot(*_envelope(tu, u[j]), lw=0.9, label=name)
        what = "torque" if input_unit.replace("*", " ") in ("N m", "Nm") else "force"
        b.set_ylabel(_label(what, input_unit))
        b.set_title(f"recorded inputs ({what}s)")
        b.legend(loc="upper left", ncols=len(names), fontsize=8)
    bottom = [wide[-1]] if wide else ax[max(0, n - cols):n]
    for a in ax + wide:
        if a not in bottom:
            a.tick_params(labelbottom=False)
    for a in bottom:
        a.set_xlabel("time [s]")
    grid = [ax[r * cols:(r + 1) * cols] for r in range(rows)] + [[w] * cols for w in wide]
    _fixed_layout(fig, grid)
    return fig


@_styled
def coefficients(terms: Sequence[str], coef_true: np.ndarray, coef_id: np.ndarray,
                 errors: Sequence[float] | None = None) -> Figure:
    """Grouped bars per equation: true vs identified coefficient of every library term."""
    T, I = np.atleast_2d(coef_true), np.atleast_2d(coef_id)
    n = T.shape[0]
    fig, ax = _frame(3.2 * n + 0.8, WIDTH, n, 1)
    ax = ax[:, 0]
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
    # the term names stand at 60 degrees below each panel: room for the longest one
    slant = max((_text_width(str(x), 8) for x in terms), default=0.0) * math.sin(math.radians(60))
    _fixed_layout(fig, ax[:, None], bottom_extra=slant, row_extra=slant)
    return fig


#: Units of scores whose unit the catalogue (:data:`testbed.core.kinds.METRICS`) does not write
#: as ``[unit]`` in its text; relative errors, ratios, TRAC, MAC and F1 are dimensionless ("-").
#: Kept here rather than in the catalogue: only figures and tables need them.
UNITS: dict[str, str] = {"angle_rmse": "rad", "K3_norm": "N/m^3", "fit_time": "s"}
#: Positive values spanning more than this many decades get a logarithmic axis.
LOG_DECADES = 2.0


def metric_unit(name: str, doc: str = "") -> str:
    """Unit of score ``name``: :data:`UNITS`, else the first ``[unit]`` in its catalogue text
    ``doc``, else ``"-"`` (dimensionless)."""
    if name in UNITS:
        return UNITS[name]
    m = re.search(r"\[([^\]]+)\]", doc or "")
    return m.group(1) if m else "-"


def wants_log(values: Sequence[float], decades: float = LOG_DECADES) -> bool:
    """Whether ``values`` belong on a log axis: all finite ones positive and spanning more
    than ``decades`` decades."""
    v = np.asarray([x for x in values if x is not None], dtype=float)
    v = v[np.isfinite(v)]
    return bool(v.size >= 2 and np.all(v > 0) and np.log10(v.max() / v.min()) > decades)


def _quartiles(vals: Sequence[float]) -> tuple[float, float, float]:
    q25, med, q75 = np.percentile(np.asarray(vals, dtype=float), [25, 50, 75])
    return float(q25), float(med), float(q75)


@_styled
def score_panels(rows: Sequence[dict[str, Any]], metric: str, unit: str = "-",
                 thresholds: dict[str, list[tuple[str, float]]] | None = None,
                 max_cols: int = 3) -> Figure | None:
    """One metric against noise: a panel per scenario (shared axes), a line per identifier
    (median over seeds) with its interquartile band, and the scenario's thresholds.

    Parameters
    ----------
    rows : sequence of dict
        Result rows of cells that ran (``scenario``, ``identifier``, ``noise`` and the metric).
    metric : str
    unit : str
        Unit for the y label (``"-"``: dimensionless).
    thresholds : dict of str to list of (bound, threshold), optional
        Per scenario, ``("min"|"max", value)`` of ``metric`` (dashed horizontal lines).
    max_cols : int
        Panels per figure row.

    Returns
    -------
    Figure or None
        None if no row has a finite value of ``metric``.
    """
    pts: dict[str, dict[str, dict[float, list[float]]]] = {}
    for r in rows:
        v = r.get(metric)
        if v is None or isinstance(v, str) or not np.isfinite(float(v)):
            continue
        pts.setdefault(str(r["scenario"]), {}).setdefault(str(r["identifier"]), {}) \
            .setdefault(float(r["noise"]), []).append(float(v))
    if not pts:
        return None
    scenarios = sorted(pts)
    idents = sorted({i for s in pts.values() for i in s})
    thresholds = thresholds or {}
    n = len(scenarios)
    cols = min(n, max_cols)
    nrows = math.ceil(n / cols)
    fig = _fig(2.5 * nrows + 0.6, min(WIDTH, 3.3 * cols + 1.2), layout="constrained")
    ax = _axes(fig, nrows, cols, sharex=True, sharey=True).ravel()
    colours = {i: f"C{k % 10}" for k, i in enumerate(idents)}
    every = [v for s in pts.values() for d in s.values() for vs in d.values() for v in vs]
    every += [thr for s in scenarios for _, thr in thresholds.get(s, [])]
    noises = sorted({z for s in pts.values() for d in s.values() for z in d})
    for a, sc in zip(ax, scenarios, strict=False):
        for ident, by_noise in sorted(pts[sc].items()):
            nz = sorted(by_noise)
            q = np.array([_quartiles(by_noise[z]) for z in nz])
            k = idents.index(ident)  # distinct markers and widths: equal medians stay visible
            a.plot(nz, q[:, 1], marker="os^Dv<>"[k % 7], ms=4.5 - 0.5 * (k % 3), lw=2.0 - 0.4 * (k % 3),
                   color=colours[ident], label=ident)
            a.fill_between(nz, q[:, 0], q[:, 2], color=colours[ident], alpha=0.18, lw=0)
        for bound, thr in thresholds.get(sc, []):
            a.axhline(thr, color="#c5221f", ls="--", lw=1.0, label="threshold")
            a.annotate(f"{'≥' if bound == 'min' else '≤'} {thr:.3g}", (1.0, thr),
                       xycoords=("axes fraction", "data"), ha="right", va="bottom", fontsize=8,
                       color="#c5221f")
        a.set_title(sc, fontsize=9)
    for a in ax[n:]:
        a.axis("off")
    if wants_log(every):
        _log_y(ax[0])
    ax[0].set_xticks(noises)
    for k in range(n):
        if k % cols == 0:
            ax[k].set_ylabel(_label(metric, unit))
        if k >= n - cols:
            ax[k].set_xlabel("noise [% of RMS]")
    handles: dict[str, Any] = {}
    for a in ax[:n]:
        for h, lab in zip(*a.get_legend_handles_labels(), strict=True):
            handles.setdefault(lab, h)
    fig.legend(handles.values(), handles.keys(), loc="outside upper center", ncols=min(5, len(handles)),
               fontsize=8, frameon=False)
    return fig


@_styled
def fit_times(rows: Sequence[dict[str, Any]]) -> Figure:
    """Fit time [s] per identifier: one box per identifier over all its cells."""
    idents = sorted({r["identifier"] for r in rows})
    data = [[float(r["fit_time"]) for r in rows if r["identifier"] == i and r.get("fit_time") is not None
             and np.isfinite(float(r["fit_time"]))] for i in idents]
    fig = _fig(0.5 * len(idents) + 1.8, 8.0, layout="constrained")
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


#: Largest cached dataset [bytes] read for its inputs: a figure does not wait for a long record
#: (a 10 s five-bar record is about 20 MB; an hour, 5 GB).
MAX_INPUT_FILE_BYTES = 200 * 2**20
#: Units of measured signals that are inputs (forces and torques) rather than responses.
INPUT_UNITS = ("N", "N m", "N*m", "Nm")


def recorded_inputs(run: Any, cache: Any = None) -> tuple[np.ndarray, list[str], str] | None:
    """The recorded inputs (force or torque signals) of a saved run, from the dataset cache.

    A run folder keeps what scoring needs, not the raw record; the run's clean simulation is
    still in the dataset cache (:class:`testbed.pipeline.cache.DatasetCache`) when the run was
    made here, and is read from there (never simulated).

    Parameters
    ----------
    run : SavedRun
    cache : DatasetCache, optional
        Default: the default cache folder.

    Returns
    -------
    (ndarray, list of str, str) or None
        Inputs (n_inputs, n_samples), channel names, unit; None if the dataset is not cached,
        is larger than :data:`MAX_INPUT_FILE_BYTES`, cannot be read, or has no measured signal
        in a force or torque unit.
    """
    try:
        sc = dict(run.scenario)
        names = {f.name for f in dataclasses.fields(Scenario)}
        fields = {k: v for k, v in sc.items() if k in names}
        scenario = Scenario(**fields | {"tags": tuple(sc.get("tags", ()))})
        path = (cache or DatasetCache()).path(scenario)
        if not path.is_file() or path.stat().st_size > MAX_INPUT_FILE_BYTES:
            return None
        ds = Dataset.load(path)
    except Exception:  # a report never fails for want of an optional panel
        return None
    for sig in ds.measured.values():
        if sig.unit in INPUT_UNITS:
            return sig.data, list(sig.channels), sig.unit
    return None


def _run_builders(run: Any, inputs: tuple[np.ndarray, list[str], str] | None
                  ) -> dict[str, Callable[[], Figure | None]]:
    """Stem -> builder of every figure ``run`` supports, in report order (nothing drawn yet)."""
    d, b = run.details, {}
    if "simulated_xdd" in d:
        b["reconstruction"] = lambda: reconstruction(d["t"], d["reference_xdd"], d["simulated_xdd"],
                                                     d["channels"], trac=d.get("trac"))
        b["spectra"] = lambda: spectra(d["t"], d["reference_xdd"], d["simulated_xdd"], d["channels"],
                                       frequencies=np.asarray(d.get("f_true", []), dtype=float))
    if "mac" in d:
        b["mac"] = lambda: mac_matrix(d["mac"], d.get("pair"))
    if "f_id" in d:
        b["frequencies"] = lambda: frequency_table(frequency_rows(d["f_true"], d["f_id"], d.get("pair"),
                                                                  d.get("z_true"), d.get("z_id")))
    if "M_id" in d:
        def _matrices() -> Figure:
            panels = [("M", d["M_id"], d.get("Mr"), "kg")]
            if "C_id" in d:
                panels.append(("C", d["C_id"], d.get("Cr"), "N s/m"))
            panels.append(("K", d["K_id"], d.get("Kr"), "N/m"))
            K3 = run.model.get("K3_")
            if K3 is not None and np.any(np.asarray(K3) != 0):
                panels.append(("K3", K3, true_cubic(typed_truth(run), len(d["channels"])), "N/m^3"))
            return matrices(panels)
        b["matrices"] = _matrices
    if _series(run.history or {}):
        b["penalty_weights"] = lambda: penalty_weights(run.history)
    if "simulated_x" in d:
        def _angles() -> Figure:
            u = inputs if inputs is not None else recorded_inputs(run)
            return joint_angles(d["t"], d["reference_x"], d["simulated_x"], d["channels"],
                                d.get("angle_rmse"), inputs=None if u is None else u[0],
                                input_channels=() if u is None else u[1],
                                input_unit="N m" if u is None else u[2])
        b["joint_angles"] = _angles
    if "coef_true" in d:
        b["coefficients"] = lambda: coefficients(d["terms"], d["coef_true"], d["coef_id"],
                                                 d.get("coef_errors"))
    return b


def run_figures_available(run: Any) -> list[str]:
    """Stems of the figures :func:`run_figures` would draw for ``run`` (cheap: nothing drawn)."""
    return list(_run_builders(run, None))


def run_figures(run: Any, inputs: tuple[np.ndarray, list[str], str] | None = None,
                only: Sequence[str] | None = None) -> dict[str, Figure]:
    """Every figure a saved run (:class:`~testbed.studies.runstore.SavedRun`) supports, by stem.

    Parameters
    ----------
    run : SavedRun
    inputs : (ndarray, list of str, str), optional
        Recorded inputs for the five-bar's error figure; default :func:`recorded_inputs`.
    only : sequence of str, optional
        Draw just these stems.
    """
    out = {}
    for stem, build in _run_builders(run, inputs).items():
        if only is None or stem in only:
            if (f := build()) is not None:
                out[stem] = f
    return out


def save_run_figures(run: Any, directory: str | os.PathLike) -> list[Path]:
    """Render :func:`run_figures` of ``run`` into ``directory`` as ``<stem>.png``."""
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    return [save_figure(f, directory / f"{stem}.png") for stem, f in run_figures(run).items()]
