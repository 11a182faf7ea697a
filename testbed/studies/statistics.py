"""Summary of sweep results: per identifier and noise level, median and IQR of each score.

The spread is the interquartile range (25th and 75th percentiles, numpy's
default linear interpolation), taken over the cells that finished ("ok"); with
fewer than 2 such cells it degenerates to the single value.  The pass rate is
over all cells of the group: a failed cell counts as not passed, since a method
that crashes or returns NaN did not meet the scenario's thresholds.
"""

from __future__ import annotations

import math
import os
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

from testbed.studies.results import read_results, score_columns

GROUP_KEYS = ("identifier", "noise")


def summarize(path: str | os.PathLike, rows: list[dict[str, Any]] | None = None) -> list[dict[str, Any]]:
    """Per (identifier, noise) statistics of a results file.

    Parameters
    ----------
    path : path
        Results file of :func:`testbed.studies.sweep.run_sweep` (its unconsolidated parts
        are read too; a damaged row file is named in a warning and left out).
    rows : list of dict, optional
        Its rows as :func:`~testbed.studies.results.read_results` gave them (not read again).

    Returns
    -------
    list of dict
        Sorted by identifier and noise.  Keys: ``identifier``, ``noise`` [%],
        ``scenarios`` (comma-separated names), ``cells``, ``ok``, ``failed``,
        ``pass_rate`` (passed / cells), and for every score ``<score>_median``,
        ``<score>_q25``, ``<score>_q75`` and ``<score>_n`` (finite values used);
        NaN where the group has no finite value of that score.
    """
    rows = read_results(path) if rows is None else rows
    scores = score_columns(rows)
    groups: dict[tuple, list[dict[str, Any]]] = defaultdict(list)
    for r in rows:
        groups[tuple(r[k] for k in GROUP_KEYS)].append(r)
    out = []
    for key in sorted(groups):
        g = groups[key]
        ok = [r for r in g if r["status"] == "ok"]
        s: dict[str, Any] = dict(zip(GROUP_KEYS, key, strict=True))
        s.update(scenarios=",".join(sorted({r["scenario"] for r in g})), cells=len(g), ok=len(ok),
                 failed=len(g) - len(ok), pass_rate=sum(bool(r["passed"]) for r in g) / len(g))
        for m in scores:
            vals = np.array([r[m] for r in ok if r.get(m) is not None], dtype=float)
            vals = vals[np.isfinite(vals)]
            if vals.size:
                q25, med, q75 = np.percentile(vals, [25, 50, 75])
            else:
                q25 = med = q75 = math.nan
            s.update({f"{m}_median": float(med), f"{m}_q25": float(q25), f"{m}_q75": float(q75),
                      f"{m}_n": int(vals.size)})
        out.append(s)
    return out


def _fmt(x: float) -> str:
    if not math.isfinite(x):
        return "-"
    return f"{x:.3g}"


def print_summary(path: str | os.PathLike, console: Any = None) -> list[dict[str, Any]]:
    """Print :func:`summarize` as rich tables and return its rows.

    One table per identifier: a column per noise level, a row per score the
    identifier reported (``median`` over ``[q25, q75]``), plus the cell count,
    failures and pass rate; then the first errors of failed cells.
    """
    from rich.console import Console
    from rich.table import Table

    console = console or Console()
    path = Path(path)
    rows = read_results(path)
    summary = summarize(path, rows)
    if not rows:
        console.print(f"{path}: no results")
        return summary
    study = rows[0].get("study", "")
    console.print(f"study {study}: {len(rows)} cells from {path}; scores as median over "
                  "[25th, 75th percentile] of the ok cells, pass rate over all cells",
                  highlight=False)
    by_ident: dict[str, list[dict[str, Any]]] = defaultdict(list)
    for s in summary:
        by_ident[s["identifier"]].append(s)
    metrics = score_columns(rows)
    for ident, group in by_ident.items():
        shown = [m for m in metrics if any(s[f"{m}_n"] for s in group)]
        t = Table(title=f"{ident}  ({group[0]['scenarios']})", title_justify="left")
        t.add_column("")
        for s in group:
            t.add_column(f"noise {s['noise']:g} %", justify="right")
        t.add_row("cells (failed)", *(f"{s['cells']} ({s['failed']})" for s in group))
        t.add_row("pass rate", *(f"{100 * s['pass_rate']:.0f} %" for s in group), end_section=True)
        for m in shown:
            t.add_row(m, *(f"{_fmt(s[m + '_median'])}\n[{_fmt(s[m + '_q25'])}, {_fmt(s[m + '_q75'])}]"
                           for s in group))
        console.print(t)
    failed = [r for r in rows if r["status"] != "ok"]
    if failed:
        console.print(f"{len(failed)} failed cell(s); first errors:", highlight=False)
        for r in failed[:5]:
            console.print(f"  {r['scenario']} noise={r['noise']:g} seed={r['seed']} "
                          f"{r['identifier']}: {r['error']}", markup=False, highlight=False,
                          soft_wrap=True)
    return summary
