"""Console summaries: the truth of a dataset and the score table of a run."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from rich.console import Console
from rich.table import Table

from testbed.core.terminal import make_console
from testbed.core.truth import DynamicalTruth, MechanicalTruth, StructuralTruth
from testbed.scoring.scorers import FAIL, PASS

if TYPE_CHECKING:
    from testbed.core.dataset import Dataset
    from testbed.scoring.run import RunResult


def truth_rows(ds: Dataset) -> list[tuple[str, str]]:
    """(label, value) pairs summarising a dataset's truth (its kind's typed truth; a dataset
    that records no kind has no declared truth, and only its rig, samples and prior show)."""
    rows = [("rig", str(ds.attrs.get("rig", "?"))), ("samples", f"{ds.n_samples} at {ds.fs:g} Hz")]
    tr = ds.typed_truth if ds.kind is not None else None
    if isinstance(tr, StructuralTruth):
        f = tr.frequencies_hz
        eb = tr.eb_frequencies_hz if tr.eb_frequencies_hz is not None else np.zeros(0)
        for i in range(min(4, len(f))):
            cell = f"{f[i]:9.2f} Hz"
            if i < len(eb):
                cell += f"   Euler-Bernoulli {eb[i]:9.2f} Hz   ({100 * (f[i] / eb[i] - 1):+.3f} %)"
            rows.append((f"mode {i + 1}", cell))
        rows.append(("damping ratios", ", ".join(f"{x:.4f}" for x in tr.damping_ratios[:3])))
    if isinstance(tr, (MechanicalTruth, DynamicalTruth)):
        rows.append(("true equation terms", str(len(tr.equation_terms))))
    for k, v in ds.prior.items():
        rows.append((f"prior {k}", f"{v}"))
    for key in ("stepping", "start_pose"):  # what the rig chose automatically, and why
        if key in ds.attrs:
            rows.append((key.replace("_", " "), str(ds.attrs[key])))
    return rows


def print_truth_summary(ds: Dataset, console: Console | None = None) -> None:
    """Print :func:`truth_rows` of ``ds`` as a two-column table titled "truth".

    Parameters
    ----------
    ds : Dataset
        A generated or loaded dataset.
    console : rich.console.Console, optional
        Where to print; default a new console on standard output.
    """
    t = Table(title="truth", show_header=False)
    t.add_column("")
    t.add_column("")
    for a, b in truth_rows(ds):
        t.add_row(a, b)
    (console or make_console()).print(t)


def verdict_line(verdict: str, failure: str | None, n_checks: int) -> str:
    """One line saying what a run's verdict is and why (console markup).

    Parameters
    ----------
    verdict : {"pass", "FAIL", "no verdict"}
        :func:`testbed.scoring.scorers.verdict` of the run.
    failure : str or None
        Its failure reasons (``Scores.failure``).
    n_checks : int
        Thresholds declared.
    """

    if verdict == PASS:
        return f"[green]PASS[/]: all {n_checks} threshold(s) met"
    if verdict == FAIL:
        return f"[red]FAIL[/]: {failure}" if failure else "[red]FAIL[/]: threshold(s) not met"
    # "\\[" keeps the literal "[score]" (rich would take it for a style tag and drop it)
    return ("[yellow]no verdict[/]: no thresholds declared in the scenario's \\[score] table "
            "(not a pass)")


def print_score_table(result: RunResult, console: Console | None = None) -> None:
    """Metric, value, threshold, pass — then every other score reported, each failure reason,
    and the verdict line (PASS, FAIL with its reason, or no verdict without thresholds)."""
    from rich.markup import escape

    t = Table(title=f"{result.scenario.name}: {(result.scenario.identify or {}).get('method', '?')} "
                    f"(fit {result.fit_time:.2f} s)",
              caption=verdict_line(result.verdict, result.failure and escape(result.failure),
                                   len(result.checks)))
    for c in ("metric", "value", "threshold", "pass"):
        t.add_column(c)
    checked = set()
    for c in result.checks:
        checked.add(c.metric)
        op = ">=" if c.bound == "min" else "<="
        t.add_row(c.metric, f"{c.value:.5g}", f"{op} {c.threshold:g}",
                  "[green]pass[/]" if c.passed else "[red]FAIL[/]")
    for k, v in sorted(result.scores.values.items()):
        if k not in checked:
            t.add_row(k, f"{v:.5g}", "-", "reported")
    for k, why in result.scores.failures.items():
        t.add_row(f"[red]failure: {k}[/]", escape(why), "-", "[red]FAIL[/]")
    if not result.checks:
        t.add_row("[yellow]thresholds[/]", "none declared", "-", "[yellow]no verdict[/]")
    (console or make_console()).print(t)
