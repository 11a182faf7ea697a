"""Summary of sweep results: per identifier and noise level (and optionally per scenario or
family), median and IQR of each score, pass rate and failure reasons.

The spread is the interquartile range (25th and 75th percentiles, numpy's
default linear interpolation), taken over the cells the scorer scored (:func:`scored`: those
that finished "ok" and the scored failures, which keep their scores beside their reason; a
crash has none); with fewer than 2 such cells it degenerates to the single value.

The pass rate is over the *judged* cells of the group: those whose (scenario, identifier)
pair was held to at least one threshold (a non-empty ``checks`` list in some cell of that
pair; the study decides which bars each identifier meets, see
:mod:`testbed.studies.study`), and crashed cells of an identifier held to bars elsewhere.
A judged cell that failed counts as not passed, since a
method that crashes or returns NaN did not meet its thresholds.  A group with no judged cell
has no pass rate (NaN): an identifier is never measured against bars declared for another.

Failure reasons are counted per group (:func:`row_failure_kinds`): a scored failure's reason
("fit failed", "diverged", "response blew up", "non-physical", "unstable", "non-finite
scores"), the scorer's explanation of a failed bar ("floor", "unexcited", "out of band", ...), ``failed bar
<metric>`` for a bar a finished cell missed with no such explanation, or, for a cell that
raised, ``refused: <ExceptionType>`` (a scenario its rig or loader refused, one line naming the
keys) or ``crash: <ExceptionType>`` (anything else).
"""

from __future__ import annotations

import math
import os
import re
from collections import Counter, defaultdict
from pathlib import Path
from typing import Any

from testbed.core import errors
from testbed.core.terminal import make_console
from testbed.numerics.quantiles import quartiles
from testbed.scoring.scorers import Check, bar_text
from testbed.studies.family import family_of
from testbed.studies.results import judged_checks, read_results, score_columns, stored_checks

GROUP_KEYS = ("identifier", "noise")
#: Groupings of :func:`summarize`: the extra key before identifier and noise.
BY = {"identifier": (), "scenario": ("scenario",), "family": ("family",)}
#: An exception's text as the sweep records it (``Type: message (file.py:line)``): a crash, not a
#: scored failure.
CRASH_PATTERN = re.compile(
    r"^([A-Za-z_][A-Za-z0-9_.]*(?:Error|Exception|Exit|Interrupt)): .*\([^()]+\.py:\d+\)$", re.DOTALL)
#: Scored failure reasons (testbed.scoring.scorers, testbed.studies.sweep.run_cell), in the order
#: they are looked for in a reason text.
SCORED_REASONS = ("fit failed", "diverged", "response blew up", "simulation failed", "non-physical",
                  "unstable", "non-finite scores", "no scores")
#: The scorer's explanations of a failed bar (testbed.scoring.scorers: uninformative_failures,
#: out_of_band_failures, unexcited_failures, decayed_failures, floor_failures, sensor_failures,
#: equation_failures, step_failures, sensitivity_failures, clipping_failures,
#: linear_model_failures, linear_trac_failures, unscored_mode_failures, channel_failures,
#: drift_failures, held_failures), each the head of its reason (``<head>: ...``).  Matched only at a
#: reason's start (the text's or after ``"; "``, as ``Scores.failure`` joins them): their words
#: occur inside other reasons ("at the sensors").  Without them a floor or an unexcited mode
#: was counted as "other" (held-out families, 2026-11-28).
EXPLAINED_REASONS = ("uninformative", "out of band", "unexcited", "decayed", "floor", "sensors",
                     "wrong equation", "equation not determined",
                     "equation not shown determined", "rollout step",
                     "sensitive record", "clipped", "linear model", "unscored mode",
                     "TRAC by channel", "drift", "held free coordinate")
_EXPLAINED = re.compile(r"(?:^|; )(" + "|".join(map(re.escape, EXPLAINED_REASONS)) + r")\b")


#: The failure kinds of a cell that never got to scoring (:func:`failure_kind`): no scores.
UNSCORED = ("crash", "refused")


def refusal(type_name: str) -> bool:
    """Whether an exception type the sweep recorded (by name) is a refusal of what the cell asks:
    a :class:`~testbed.core.errors.RigError` or :class:`~testbed.core.errors.ScenarioError`
    (and their subclasses, e.g. ``BudgetError``) of :mod:`testbed.core.errors` (the sweep
    records a plugin's own subclass by the nearest of those and another module's class of the
    same name by its qualified name: :func:`testbed.studies.sweep.error_name`), which a rig or
    the scenario's loader raises for a scenario it cannot build or simulate as asked, in one
    line naming the keys (round 21's ``fb21_ms_amp1p5``: "the motion under excitation
    'multisine' is not usable (found only by simulating it) ... transmission angle 150.00 deg"),
    not a bug."""
    cls = getattr(errors, type_name, None)
    return isinstance(cls, type) and issubclass(cls, (errors.RigError, errors.ScenarioError))


def failure_kind(error: str) -> list[str]:
    """The kinds of failure in a cell's ``error`` text (empty for a cell that finished).

    ``refused: <Type>`` for a scenario the rig or the loader refused (:func:`refusal`),
    ``crash: <Type>`` for any other exception the sweep caught (a bug or an unforeseen input), else
    every scored reason of :data:`SCORED_REASONS` found in the text and every explanation of
    :data:`EXPLAINED_REASONS` heading one of its reasons (a cell may fail for several, e.g.
    non-physical and diverged), or ``other`` if none matches.
    """
    if not error:
        return []
    if error.startswith("process ended: "):  # testbed.studies.sweep.ended_cell_row
        return ["crash: process ended"]
    m = CRASH_PATTERN.match(error.strip())
    if m:
        return [f"{'refused' if refusal(m.group(1)) else 'crash'}: {m.group(1)}"]
    found = [r for r in SCORED_REASONS if r in error]
    heads = {h.group(1) for h in _EXPLAINED.finditer(error)}
    found += [r for r in EXPLAINED_REASONS if r in heads]
    return found or ["other"]


#: The kind of a cell that finished and missed bars the scorer explains by none of its reasons
#: (:func:`failed_bars`): ``"failed bar <metric>"``, one per missed bar.
FAILED_BAR = "failed bar"


def failed_bars(row: dict[str, Any]) -> list[Check]:
    """The bars a results row missed, judged again from its stored checks as the pass rate
    judges them (:func:`~testbed.studies.results.judged_checks`: a check's ``value``, NaN where
    it differs from the row's score column; NaN never passes): empty for a row whose checks
    all hold or cannot be read (no bar to name).

    A cell that finished ("ok") and missed a bar the scorer explains by none of its reasons
    (an identified mode off its bar on a record that holds it) has an empty ``error``: its
    group showed a pass rate below 100 % beside "failure reasons -", and the failed cells'
    list left it out (round 23's ``b23_soft_s2neartip`` at 2 %, ``ls_sindy``: mode 2 10.9 %
    off the 2.6 % bar, named nowhere in ``testbed summary``).
    """
    return [c for c in judged_checks(row) or [] if not c.passed]


def row_failure_kinds(row: dict[str, Any], judged: bool) -> list[str]:
    """The failure kinds of a results row: :func:`failure_kind` of its ``error``, or, for a row
    held to bars (``judged``) that finished without passing and without a reason,
    ``"failed bar <metric>"`` per bar it missed (:func:`failed_bars`), or ``"failed bar
    (checks unreadable)"`` where no stored check names one (a hand-edited or older file whose
    checks cannot be judged: not passed, and counted)."""
    kinds = failure_kind(row.get("error") or "")
    if kinds or not judged or row.get("passed"):
        return kinds
    return ([f"{FAILED_BAR} {c.metric}" for c in failed_bars(row)]
            or [f"{FAILED_BAR} (checks unreadable)"])


def scored(row: dict[str, Any]) -> bool:
    """Whether a results row holds the scorer's scores: a cell that finished ("ok"), or a
    scored failure (a diverged, non-physical or refused model, a failed bar the scorer
    explains: "wrong equation", "floor", "out of band", ...), which keeps its scores beside its
    reason; not a crash (:func:`failure_kind` ``crash: <Type>``: the cell never got to scoring).

    The medians stand on these rows.  Over the "ok" rows alone they described the passing
    cells: round 20's kinetics at 1.5 % showed coef_error 0.0232 [0.0232, 0.0232], the one cell
    that passed, where the five cells scored 0.0232, 0.0519, 4.07, 5.89 and 88.1 (four "wrong
    equation" failures with finite scores): median 4.07.  A score that is NaN for a failure
    (a model that was never simulated) is left out and counted (``<score>_n``), an infinite
    one counted as the worst value it is (:func:`~testbed.numerics.quantiles.quartiles`).
    """
    if row.get("status") == "ok":
        return True
    return not any(k.startswith(UNSCORED) for k in failure_kind(row.get("error") or ""))


def failed_cells_line(rows: list[dict[str, Any]]) -> str | None:
    """One line on the failed rows of a sweep: how many crashed and how many are scored failures.

    A scored failure (a diverged or non-physical model, a floor, ...) is the cell's verdict with
    its reason and a rerun of the same code gives it again; a crash is an exception the sweep
    caught.  ``None`` when no row failed.
    """
    kinds = [failure_kind(r.get("error") or "") for r in rows if r.get("status") != "ok"]
    if not kinds:
        return None
    crashed = sum(any(k.startswith("crash") for k in ks) for ks in kinds)
    refused = sum(any(k.startswith("refused") for k in ks) for ks in kinds)
    other = sum(ks == ["other"] for ks in kinds)
    scored = len(kinds) - crashed - refused - other
    parts = [f"{n} {what}" for n, what in ((crashed, "crashed"),
                                            (refused, "refused by the rig or the scenario"),
                                            (scored, "scored failure(s) with their reason"),
                                            (other, "with another error")) if n]
    again = ("; `testbed sweep --retry-failed` runs them again" if refused < len(kinds) else "")
    if refused and again:
        again += " (a refused cell is refused again until its scenario changes)"
    return (f"{len(kinds)} cell(s) failed ({', '.join(parts)}; `testbed summary` counts the "
            f"reasons){again}")


def missed_bars_line(rows: list[dict[str, Any]]) -> str | None:
    """One line on the cells of a sweep that finished and missed bars the scorer gives no reason
    for (:func:`failed_bars`), which :func:`failed_cells_line` does not count (their status is
    "ok"): ``None`` when there are none.  Round 23's ``round23_beams_noise`` ended with its
    results line alone where ``ls_sindy`` missed mode 2's bar on one cell."""
    n = len(_missed_bar_rows(rows))
    if not n:
        return None
    return (f"{n} finished cell(s) missed bars the scorer gives no reason for (the identified "
            "model's scores; `testbed summary` names the bars)")


def _missed_bar_rows(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """The rows of cells that finished ("ok"), were held to bars and did not pass: each missed
    a bar (:func:`failed_bars`) or holds checks that cannot be judged (not a pass either)."""
    return [r for r, j in zip(rows, _judged(rows), strict=True)
            if r.get("status") == "ok" and j and not r.get("passed")]


def _judged(rows: list[dict[str, Any]]) -> list[bool]:
    """Whether each row was held to thresholds.

    A row is judged if its (scenario, identifier) pair has a non-empty ``checks`` list in some
    cell.  A cell that crashed has no checks (it never got to scoring); it is judged if its
    identifier is held to bars on any scenario of the results, so that a crash is never left
    out of a pass rate (it counts as not passed).
    """
    pairs, idents = set(), set()
    for r in rows:
        if stored_checks(r):  # (None, not a list of checks, holds no bar: round 15)
            pairs.add((r["scenario"], r["identifier"]))
            idents.add(r["identifier"])
    return [(r["scenario"], r["identifier"]) in pairs
            or (r["identifier"] in idents and any(k.startswith(UNSCORED)
                                                  for k in failure_kind(r.get("error") or "")))
            for r in rows]


def summarize(path: str | os.PathLike, rows: list[dict[str, Any]] | None = None,
              by: str = "identifier") -> list[dict[str, Any]]:
    """Per (identifier, noise) statistics of a results file (or per scenario or family too).

    Parameters
    ----------
    path : path
        Results file of :func:`testbed.studies.sweep.run_sweep` (its unconsolidated parts
        are read too; a damaged row file is named in a warning and left out).
    rows : list of dict, optional
        Its rows as :func:`~testbed.studies.results.read_results` gave them (not read again).
    by : {"identifier", "scenario", "family"}
        Group per identifier and noise, or per scenario (or family: the family of a member,
        the scenario itself otherwise) x identifier x noise.

    Returns
    -------
    list of dict
        Sorted by the group keys.  Keys: ``identifier``, ``noise`` [%] (and ``scenario`` or
        ``family``), ``scenarios`` (comma-separated names), ``cells``, ``ok``, ``failed``,
        ``scored`` (the cells with the scorer's scores, :func:`scored`), ``judged`` (cells held
        to thresholds), ``pass_rate`` (passed / judged; NaN if none is judged), ``failures``
        (dict: failure kind -> count, see :func:`failure_kind`), and for every score
        ``<score>_median``, ``<score>_q25``, ``<score>_q75`` over the scored cells and
        ``<score>_n``, the values they stand on (:func:`~testbed.numerics.quantiles.quartiles`:
        NaN left out, an infinite score counted as the worst value it is); NaN where the group
        has no value of that score.
    """
    if by not in BY:
        raise ValueError(f"by must be one of {', '.join(BY)}, not {by!r}")
    rows = read_results(path) if rows is None else rows
    scores = score_columns(rows)
    keys = BY[by] + GROUP_KEYS
    judged_flags = {id(r): j for r, j in zip(rows, _judged(rows), strict=True)}

    def value(r: dict[str, Any], k: str) -> Any:
        return family_of(r["scenario"]) if k == "family" else r[k]

    groups: dict[tuple, list[dict[str, Any]]] = defaultdict(list)
    for r in rows:
        groups[tuple(value(r, k) for k in keys)].append(r)
    out = []
    for key in sorted(groups):
        g = groups[key]
        ok = [r for r in g if r["status"] == "ok"]
        with_scores = [r for r in g if scored(r)]
        judged = [r for r in g if judged_flags[id(r)]]
        failures: dict[str, int] = defaultdict(int)
        for r in g:
            for kind in row_failure_kinds(r, judged_flags[id(r)]):
                failures[kind] += 1
        s: dict[str, Any] = dict(zip(keys, key, strict=True))
        s.update(scenarios=",".join(sorted({r["scenario"] for r in g})), cells=len(g), ok=len(ok),
                 failed=len(g) - len(ok), scored=len(with_scores), judged=len(judged),
                 pass_rate=(sum(bool(r["passed"]) for r in judged) / len(judged) if judged
                            else math.nan),
                 failures=dict(sorted(failures.items(), key=lambda kv: (-kv[1], kv[0]))))
        for m in scores:
            q25, med, q75, n = quartiles(r.get(m) for r in with_scores)
            s.update({f"{m}_median": med, f"{m}_q25": q25, f"{m}_q75": q75, f"{m}_n": n})
        out.append(s)
    return out


def _fmt(x: float) -> str:
    """A quartile for the table: "-" for NaN (no value), "inf" and "-inf" as they are."""
    if math.isnan(x):
        return "-"
    return f"{x:.3g}"


def _of(s: dict[str, Any], m: str) -> str:
    """``"\\n<n> of <scored> cells"`` where score ``m``'s quartiles stand on fewer than the
    group's scored cells (the others' ``m`` NaN: undefined for them, or a failure that was never
    simulated), else "": a median of 5 of 6 cells was shown as the median of the 6 (round 13)."""
    return f"\n{s[m + '_n']} of {s['scored']} cells" if s[m + "_n"] < s["scored"] else ""


def print_summary(path: str | os.PathLike, console: Any = None,
                  by: str = "identifier") -> list[dict[str, Any]]:
    """Print :func:`summarize` as rich tables and return its rows.

    One table per identifier (per scenario or family and identifier with ``by``): a column
    per noise level, a row per score the identifier reported (``median`` over
    ``[q25, q75]``), plus the cell count, failures, pass rate (over judged cells) and the
    failure reasons counted; then the first errors of failed cells.
    """
    from rich.table import Table


    console = console or make_console()
    path = Path(path)
    rows = read_results(path)
    summary = summarize(path, rows, by=by)
    if not rows:
        console.print(f"{path}: no results")
        return summary
    study = rows[0].get("study", "")
    console.print(f"study {study}: {len(rows)} cells from {path}; scores as median over "
                  "[25th, 75th percentile] of the scored cells (passed, or failed with the scorer's "
                  "reason; crashes left out), pass rate over the cells held to thresholds (that "
                  "identifier's own)",
                  highlight=False)
    codes = Counter((str(r.get("commit") or "?"), str(r.get("versions") or "?")) for r in rows)
    if len(codes) > 1:  # a sweep resumed after a change of code or libraries: said, not pooled in silence
        commits = Counter(c for c, _ in codes.elements())
        console.print(f"note: the cells were computed by {len(codes)} versions of the code or its "
                      "libraries (commits " + ", ".join(f"{c} x {n}" for c, n in sorted(commits.items()))
                      + "); the medians pool them", highlight=False)
    by_ident: dict[tuple, list[dict[str, Any]]] = defaultdict(list)
    for s in summary:
        by_ident[(*(s[k] for k in BY[by]), s["identifier"])].append(s)
    metrics = score_columns(rows)
    for ident, group in by_ident.items():
        shown = [m for m in metrics if any(s[f"{m}_n"] for s in group)]
        where = group[0]["scenarios"]
        if len(where) > 60:
            where = f"{len(where.split(','))} scenarios"
        t = Table(title=f"{'  '.join(ident)}  ({where})", title_justify="left")
        t.add_column("")
        for s in group:
            t.add_column(f"noise {s['noise']:g} %", justify="right")
        t.add_row("cells (failed)", *(f"{s['cells']} ({s['failed']})" for s in group))
        t.add_row("pass rate", *(f"{100 * s['pass_rate']:.0f} % of {s['judged']}"
                                 if math.isfinite(s["pass_rate"]) else "no bars" for s in group))
        t.add_row("failure reasons", *("\n".join(f"{k}: {n}" for k, n in s["failures"].items()) or "-"
                                       for s in group), end_section=True)
        for m in shown:
            t.add_row(m, *(f"{_fmt(s[m + '_median'])}\n[{_fmt(s[m + '_q25'])}, {_fmt(s[m + '_q75'])}]"
                           + _of(s, m) for s in group))
        console.print(t)
    failed = [r for r in rows if r["status"] != "ok"]
    if failed:
        console.print(f"{len(failed)} failed cell(s); first errors:", highlight=False)
        for r in failed[:5]:
            console.print(f"  {r['scenario']} noise={r['noise']:g} seed={r['seed']} "
                          f"{r['identifier']}: {r['error']}", markup=False, highlight=False,
                          soft_wrap=True)
    missed = [(r, failed_bars(r)) for r in _missed_bar_rows(rows)]
    if missed:
        console.print(f"{len(missed)} cell(s) missed bars the scorer gives no reason for (the "
                      "identified model's scores); first:", highlight=False)
        for r, bars in missed[:5]:
            console.print(f"  {r['scenario']} noise={r['noise']:g} seed={r['seed']} "
                          f"{r['identifier']}: "
                          f"{'; '.join(map(bar_text, bars)) or 'checks unreadable'}", markup=False,
                          highlight=False, soft_wrap=True)
    return summary
