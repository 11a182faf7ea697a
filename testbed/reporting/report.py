"""Reports people look at: one self-contained ``report.html`` and its markdown twin ``report.md``.

The HTML has its figures embedded as base64 data URIs, its CSS inline and a
Content-Security-Policy that forbids every network request, so it opens
anywhere, offline, as one file.  The markdown twin links the PNGs written beside it.

A report is written for a run folder (from :func:`testbed.studies.runstore.save_run`) or
for the results file of a sweep (rows of :func:`testbed.studies.results.read_results`).
"""

from __future__ import annotations

import base64
import html
import math
import os
import shutil
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from testbed.core.atomic import atomic_write_text
from testbed.core.kinds import METRICS
from testbed.reporting import figures as figs
from testbed.studies.results import read_results, score_columns
from testbed.studies.runstore import SavedRun, load_run

CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;max-width:1100px;margin:2em auto;
padding:0 1em;color:#222;line-height:1.45}
h1{border-bottom:2px solid #ddd;padding-bottom:.3em}h2{margin-top:1.6em;border-bottom:1px solid #eee}
table{border-collapse:collapse;margin:.6em 0 1.2em}th,td{border:1px solid #ccc;padding:.25em .6em;
text-align:left;font-variant-numeric:tabular-nums}th{background:#f3f3f3}
td.num{text-align:right}.pass{color:#137333;font-weight:600}.fail{color:#c5221f;font-weight:600}
.badge{display:inline-block;padding:.1em .6em;border-radius:.3em;color:#fff;font-size:.8em;
vertical-align:middle}.badge.pass{background:#137333;color:#fff}.badge.fail{background:#c5221f;color:#fff}
.badge.none{background:#777;color:#fff}
figure{margin:1em 0}figure img{max-width:100%;height:auto;border:1px solid #eee}
figcaption{color:#555;font-size:.9em}pre{background:#f7f7f7;padding:.6em;overflow-x:auto}
.muted{color:#666;font-size:.9em}
"""
CSP = "default-src 'none'; img-src data:; style-src 'unsafe-inline'"
#: Captions of the run figures, by file stem.
CAPTIONS = {
    "reconstruction": "Accelerations per sensor: noise-free truth vs the identified model simulated "
                      "under the measured force (whole record and a zoom window).",
    "mac": "MAC between identified and true mode shapes at the sensors; outlined: the pairing used "
           "for the scores.",
    "frequencies": "Natural frequencies: true vs identified (paired modes) and relative error.",
    "matrices": "Identified vs true matrices (true: SEREP reduction to the sensor DOFs).",
    "penalty_weights": "Penalty weights and loss terms per training epoch.",
    "joint_angles": "Joint angles: noise-free truth vs the identified model simulated from the true "
                    "initial state under the recorded torques.",
    "coefficients": "Coefficients of the library terms per equation: truth vs identified "
                    "(scaled so that the leading true term matches).",
}


def fmt(v: Any, digits: int = 4) -> str:
    """A number for a table: ``digits`` significant figures, a dash for missing/NaN."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "–"
    if isinstance(v, (bool, np.bool_)):
        return "yes" if v else "no"
    if isinstance(v, (int, float, np.integer, np.floating)):
        return f"{v:.{digits}g}"
    return str(v)


class Page:
    """An HTML body and a markdown text built side by side."""

    def __init__(self, title: str, out_dir: Path) -> None:
        self.title, self.out_dir = title, out_dir
        self.html: list[str] = []
        self.md: list[str] = [f"# {title}", ""]

    def heading(self, text: str, level: int = 2) -> None:
        self.html.append(f"<h{level}>{html.escape(text)}</h{level}>")
        self.md += ["#" * level + " " + text, ""]

    def para(self, text: str, raw_html: str | None = None) -> None:
        self.html.append(f"<p>{raw_html or html.escape(text)}</p>")
        self.md += [text, ""]

    def table(self, head: Sequence[str], rows: Sequence[Sequence[Any]],
              classes: Sequence[str | None] | None = None) -> None:
        """A table; cells are formatted with :func:`fmt`; ``classes`` styles the last cell of a row."""
        cells = [[fmt(c) for c in r] for r in rows]
        ths = "".join(f"<th>{html.escape(c)}</th>" for c in head)
        h = [f"<table><thead><tr>{ths}</tr></thead><tbody>"]
        for i, (raw, r) in enumerate(zip(rows, cells, strict=True)):
            tds = []
            for j, (x, c) in enumerate(zip(raw, r, strict=True)):
                cls = "num" if isinstance(x, (int, float, np.number)) and not isinstance(x, bool) else ""
                if classes is not None and classes[i] and j == len(r) - 1:
                    cls = classes[i]
                attr = f' class="{cls}"' if cls else ""
                tds.append(f"<td{attr}>{html.escape(c)}</td>")
            h.append("<tr>" + "".join(tds) + "</tr>")
        self.html.append("".join(h) + "</tbody></table>")
        esc = [[c.replace("|", "\\|") for c in r] for r in cells]
        self.md += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        self.md += ["| " + " | ".join(r) + " |" for r in esc] + [""]

    def figure(self, png: Path, caption: str) -> None:
        """Embed ``png`` (base64) in the HTML; copy it beside the markdown."""
        name = png.name
        if png.resolve() != (self.out_dir / name).resolve():
            shutil.copyfile(png, self.out_dir / name)
        data = base64.b64encode(png.read_bytes()).decode("ascii")
        alt = html.escape(caption, quote=True)
        self.html.append(f'<figure><img src="data:image/png;base64,{data}" alt="{alt}">'
                         f"<figcaption>{html.escape(caption)}</figcaption></figure>")
        self.md += [f"![{png.stem}]({name})", "", f"*{caption}*", ""]

    def pre(self, lines: Sequence[str]) -> None:
        self.html.append("<pre>" + html.escape("\n".join(lines)) + "</pre>")
        self.md += ["```", *lines, "```", ""]

    def write(self) -> Path:
        doc = ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
               f'<meta http-equiv="Content-Security-Policy" content="{CSP}">'
               '<meta name="viewport" content="width=device-width, initial-scale=1">'
               f"<title>{html.escape(self.title)}</title><style>{CSS}</style></head>\n<body>\n"
               f"<h1>{html.escape(self.title)}</h1>\n" + "\n".join(self.html) + "\n</body></html>\n")
        out = self.out_dir / "report.html"
        atomic_write_text(out, doc)
        atomic_write_text(self.out_dir / "report.md", "\n".join(self.md).rstrip() + "\n")
        return out


# ----------------------------------------------------------------------------- run report
def _truth_section(page: Page, run: SavedRun) -> None:
    page.heading("Truth")
    sc, units = run.scenario, run.meta.get("rig_units", {})
    ds = run.meta.get("dataset", {})
    noise = fmt(sc.get("noise", {}).get("rms_percent"))
    page.para(f"Rig {sc['rig']}, seed {sc.get('seed')}, noise {noise} % of channel RMS, "
              f"{ds.get('n_samples')} samples at {fmt(ds.get('fs'))} Hz.")
    params = sc.get("rig_params", {})
    if params:
        page.table(["rig parameter", "value", "unit", "meaning"],
                   [[k, v if isinstance(v, (int, float)) else str(v), units.get(k, {}).get("unit", ""),
                     units.get(k, {}).get("doc", "")] for k, v in params.items()])
    tr = run.truth
    if "frequencies_hz" in tr:
        f = np.asarray(tr["frequencies_hz"], dtype=float)
        eb = np.asarray(tr.get("eb_frequencies_hz", []), dtype=float)
        z = np.asarray(tr.get("damping_ratios", []), dtype=float)
        rows = [[i + 1, f[i], eb[i] if i < eb.size else None,
                 100 * (f[i] / eb[i] - 1) if i < eb.size else None, z[i] if i < z.size else None]
                for i in range(min(len(f), 6))]
        page.table(["mode", "true [Hz]", "Euler-Bernoulli [Hz]", "true vs E-B [%]", "damping ratio [-]"],
                   rows)
    if ds.get("prior"):
        prior = ", ".join(f"{k} = {fmt(v)}" for k, v in ds["prior"].items())
        page.para(f"Prior given to the identifier: {prior}")


def _scores_section(page: Page, run: SavedRun) -> None:
    page.heading("Scores")
    doc = METRICS.get(run.kind, {})
    rows, classes, checked = [], [], set()
    for c in run.checks:
        checked.add(c.metric)
        op = ">= " if c.bound == "min" else "<= "
        rows.append([c.metric, doc.get(c.metric, ""), c.value, op + fmt(c.threshold),
                     "pass" if c.passed else "FAIL"])
        classes.append("pass" if c.passed else "fail")
    for k, v in sorted(run.scores.items()):
        if k not in checked:
            rows.append([k, doc.get(k, ""), v, "–", "reported"])
            classes.append(None)
    for k, why in run.failures.items():  # a scored failure: diverged, fit failed, non-physical
        rows.append([f"failure: {k}", why, None, "–", "FAIL"])
        classes.append("fail")
    page.table(["metric", "meaning", "value", "threshold", "result"], rows, classes)
    if not run.checks:
        page.para("No thresholds declared in the scenario's [score] table: no verdict (not a pass).")


def run_report(run: SavedRun, out_dir: str | os.PathLike) -> Path:
    """Write the report of a saved run into ``out_dir``; return the HTML path."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    page = Page(f"Run {run.name}: {run.identifier}", out_dir)
    label = run.verdict.upper()  # PASS, FAIL or NO VERDICT
    status = {"PASS": "pass", "FAIL": "fail"}.get(label, "none")
    params = ", ".join(f"{k}={v}" for k, v in run.meta["identifier"].get("params", {}).items())
    body = f"identifier {run.identifier} ({params}) fitted in {run.fit_time:.3g} s."
    if run.failure:
        body += f" Failed: {run.failure}."
    page.para(f"{label}: {body}", f'<span class="badge {status}">{label}</span> {html.escape(body)}')
    _truth_section(page, run)
    _scores_section(page, run)
    d = run.details
    if "f_id" in d:
        page.heading("Natural frequencies")
        rows = figs.frequency_rows(d["f_true"], d["f_id"], d.get("pair"), d.get("z_true"), d.get("z_id"))
        page.table(["mode", "true [Hz]", "identified [Hz]", "error [%]", "ζ true [-]", "ζ identified [-]"],
                   [[r["mode"], r["f_true"], r["f_id"], r["error_pct"], r.get("z_true"), r.get("z_id")]
                    for r in rows])
    page.heading("Identified equations")
    page.pre(run.equations or ["(none)"])
    page.heading("Figures")
    pngs = {p.stem: p for p in run.figures}
    if not pngs:
        pngs = {p.stem: p for p in figs.save_run_figures(run, out_dir)}
    for stem, png in pngs.items():
        page.figure(png, CAPTIONS.get(stem, stem))
    page.heading("Provenance")
    ds = run.meta.get("dataset", {})
    prov = [["dataset content hash", ds.get("hash", "")], ["scenario data hash", ds.get("data_hash", "")],
            ["commit", run.meta.get("commit", "")], ["run written", run.meta.get("created", "")]]
    prov += [[f"version {k}", v] for k, v in run.meta.get("versions", {}).items()]
    page.table(["item", "value"], prov)
    return page.write()


# ----------------------------------------------------------------------------- sweep report
def score_names(rows: Sequence[dict[str, Any]]) -> list[str]:
    """Score columns of sweep rows (:func:`testbed.studies.results.score_columns`) holding numbers."""
    return [k for k in score_columns(rows)
            if any(isinstance(r.get(k), (int, float, np.number)) and not isinstance(r.get(k), bool)
                   for r in rows)]


def _ok(r: dict[str, Any]) -> bool:
    return str(r.get("status", "ok")) == "ok"


def sweep_report(rows: Sequence[dict[str, Any]], out_dir: str | os.PathLike, title: str = "Sweep") -> Path:
    """Write the report of sweep result rows into ``out_dir``; return the HTML path."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rows = list(rows)
    page = Page(f"Sweep {title}", out_dir)
    idents = sorted({str(r["identifier"]) for r in rows})
    noises = sorted({float(r["noise"]) for r in rows})
    errors = [r for r in rows if not _ok(r)]
    page.para(f"{len(rows)} cells: {len(idents)} identifier(s) ({', '.join(idents)}), noise levels "
              f"{', '.join(fmt(z) for z in noises)} % of channel RMS, "
              f"{len({r['seed'] for r in rows})} seed(s), {len(errors)} failed to run.")
    page.heading("Pass rate")
    page.para("Cells passing every threshold of their scenario, out of all cells (a cell that failed "
              "to run counts as not passed).")
    table = []
    for i in idents:
        line: list[Any] = [i]
        for z in noises:
            cell = [r for r in rows if r["identifier"] == i and float(r["noise"]) == z]
            n_pass = sum(bool(r.get("passed")) and _ok(r) for r in cell)
            line.append(f"{n_pass}/{len(cell)} ({100 * n_pass / len(cell):.0f} %)" if cell else "–")
        table.append(line)
    page.table(["identifier"] + [f"noise {fmt(z)} %" for z in noises], table)
    page.heading("Scores vs noise")
    for m in score_names(rows):
        ok = [r for r in rows if _ok(r)]
        if not any(r.get(m) is not None and np.isfinite(float(r[m])) for r in ok):
            continue
        png = figs.save_figure(figs.score_vs_noise(ok, m), out_dir / f"score_{m}.png")
        page.figure(png, f"{m} against noise per identifier: median over seeds (line), min-max (band).")
    page.heading("Fit time")
    page.table(["identifier", "cells", "median [s]", "max [s]"],
               [[i, len(t), float(np.median(t)) if t else None, float(np.max(t)) if t else None]
                for i in idents for t in [[float(r["fit_time"]) for r in rows if r["identifier"] == i
                                           and _ok(r) and r.get("fit_time") is not None]]])
    page.figure(figs.save_figure(figs.fit_times([r for r in rows if _ok(r)]), out_dir / "fit_time.png"),
                "Fit time per identifier over all cells that ran.")
    if errors:
        page.heading("Cells that failed to run")
        page.table(["cell", "identifier", "noise [%]", "seed", "error"],
                   [[r.get("cell", ""), r["identifier"], r["noise"], r["seed"], r.get("error", "")]
                    for r in errors])
    commits = sorted({str(r.get("commit", "")) for r in rows})
    page.para("Commit(s): " + ", ".join(commits) + ".")
    return page.write()


def write_report(source: str | os.PathLike, out_dir: str | os.PathLike) -> Path:
    """Write ``report.html`` and ``report.md`` of a run folder or a sweep results file.

    Parameters
    ----------
    source : path
        A run folder written by :func:`testbed.studies.runstore.save_run`, or a results
        file of a sweep (read with :func:`testbed.studies.results.read_results`).
    out_dir : path
        Report folder (created); the PNGs of the markdown twin go beside it.

    Returns
    -------
    Path
        The HTML report.
    """
    source = Path(source)
    if source.is_dir():
        return run_report(load_run(source), out_dir)
    if not source.is_file():
        raise FileNotFoundError(f"{source}: neither a run folder nor a results file")

    return sweep_report(read_results(source), out_dir, title=source.stem)
