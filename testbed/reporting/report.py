"""Reports people look at: one self-contained ``report.html`` and its markdown twin ``report.md``.

The HTML has its figures embedded as base64 data URIs, its CSS inline and a
Content-Security-Policy that forbids every network request, so it opens
anywhere, offline, as one file.  The markdown twin links the PNGs written beside it.

A report is written for a run folder (from :func:`testbed.studies.runstore.save_run`) or
for the results file of a sweep (rows of :func:`testbed.studies.results.read_results`).

A run report reads top-down as a person checks a run: the verdict and why it failed, the
scores with units and thresholds, frequencies, the identified equations (wrapped, one per
line), every setting of the scenario as tables (keys the chosen options make irrelevant left
out and named, the actual sensor positions), the truth, the figures and provenance.  A sweep
report is titled by its study and shows pass rates, a numeric summary per scenario
(median and interquartile range over seeds, pass rate, reasons of failures counted) and
one small-multiples figure per score (:func:`testbed.reporting.figures.score_panels`).
"""

from __future__ import annotations

import base64
import html
import json
import math
import os
import re
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from testbed.core.atomic import (
    HTML_FILE,
    HTML_REPORT_HEAD,
    PNG_FILE,
    REPORT_CSP,
    REPORT_MARKDOWN_FILE,
    REPORT_MARKDOWN_MARK,
    atomic_write,
    atomic_write_text,
    foreign_head,
    refuse_foreign,
)
from testbed.core.errors import InputError, terminal_safe
from testbed.core.kinds import METRICS
from testbed.numerics.quantiles import quartiles
from testbed.pipeline.plugins import RIGS
from testbed.pipeline.scenario import NOISE_SCHEMA
from testbed.pipeline.signal_chain import SIGNAL_SCHEMAS
from testbed.reporting import figures as figs
from testbed.reporting.markdown import md_code_block, md_text
from testbed.studies.results import ResultsError, parts_dir, read_results, score_columns, stored_checks
from testbed.studies.runstore import SavedRun, load_run, resolve_run
from testbed.studies.statistics import scored

CSS = """
body{font-family:system-ui,-apple-system,"Segoe UI",Roboto,sans-serif;max-width:1100px;margin:2em auto;
padding:0 1em;color:#222;line-height:1.45}
h1{border-bottom:2px solid #ddd;padding-bottom:.3em}h2{margin-top:1.6em;border-bottom:1px solid #eee}
table{border-collapse:collapse;margin:.6em 0 1.2em}th,td{border:1px solid #ccc;padding:.25em .6em;
text-align:left;font-variant-numeric:tabular-nums}th{background:#f3f3f3}
td.num{text-align:right;white-space:nowrap}.pass{color:#137333;font-weight:600}.fail{color:#c5221f;font-weight:600}
.badge{display:inline-block;padding:.1em .6em;border-radius:.3em;color:#fff;font-size:.8em;
vertical-align:middle}.badge.pass{background:#137333;color:#fff}.badge.fail{background:#c5221f;color:#fff}
.badge.none{background:#777;color:#fff}
figure{margin:1em 0}figure img{max-width:100%;height:auto;border:1px solid #eee}
figcaption{color:#555;font-size:.9em}pre{background:#f7f7f7;padding:.6em;overflow-x:auto}
.muted{color:#666;font-size:.9em}
ol.eq{background:#f7f7f7;padding:.6em .6em .6em 2.4em;font-family:ui-monospace,Menlo,Consolas,monospace;
font-size:.85em}ol.eq li{white-space:pre-wrap;overflow-wrap:anywhere;margin:.2em 0;padding-left:2em;
text-indent:-2em}
.grid{display:grid;grid-template-columns:repeat(auto-fill,minmax(480px,1fr));gap:.6em 1em}
.grid figure{margin:.3em 0}.grid figure.wide{grid-column:1/-1}
td.fails{font-size:.85em;color:#8a1c1c;max-width:28em}
"""
CSP = REPORT_CSP
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
                    "initial state under the recorded torques; below, the angle error of every joint "
                    "over time and the recorded torques (read from the dataset cache when it holds "
                    "the run's dataset).",
    "coefficients": "Coefficients of the library terms per equation: truth vs identified "
                    "(scaled so that the leading true term matches).",
    "spectra": "Where the model deviates: power spectral density of the noise-free measured "
               "acceleration, of the identified model's simulation and of their difference per "
               "sensor (true natural frequencies dotted), and the residual over time.",
}
#: Order of the run figures in a report.
ORDER = ("reconstruction", "spectra", "mac", "frequencies", "matrices", "penalty_weights",
         "joint_angles", "coefficients")


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
        # the mark first: a user's own "# Study notes" is not taken for a report (review 27e M2)
        self.md: list[str] = [REPORT_MARKDOWN_MARK, f"# {md_text(title)}", ""]
        #: the PNGs to write beside the report (file name -> bytes), in :meth:`write`
        self.pngs: dict[str, bytes] = {}

    def png(self, name: str, data: bytes) -> str:
        """Keep the PNG ``data`` to be written as ``name`` beside the report (by :meth:`write`,
        with the report's other files); return ``name``, a plain file name (not a path)."""
        if Path(name).name != name or name.startswith("."):
            raise ValueError(f"a figure's name must be a plain file name, not {name!r}")
        self.pngs[name] = data
        return name

    def heading(self, text: str, level: int = 2) -> None:
        """A heading of ``level`` (2: a section) in both texts."""
        self.html.append(f"<h{level}>{html.escape(text)}</h{level}>")
        self.md += ["#" * level + " " + md_text(text), ""]

    def para(self, text: str, raw_html: str | None = None) -> None:
        """A paragraph: ``text`` escaped, or ``raw_html`` (built by the caller from escaped parts)
        in the HTML; ``text`` in the markdown."""
        self.html.append(f"<p>{raw_html or html.escape(text)}</p>")
        self.md += [md_text(text), ""]

    def table(self, head: Sequence[str], rows: Sequence[Sequence[Any]],
              classes: Sequence[str | None] | None = None, digits: int = 4) -> None:
        """A table; cells are formatted with :func:`fmt` (``digits`` significant figures);
        ``classes`` styles the last cell of a row."""
        cells = [[fmt(c, digits) for c in r] for r in rows]
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
        esc = [[md_text(c) for c in r] for r in cells]
        self.md += ["| " + " | ".join(md_text(c) for c in head) + " |", "|" + "---|" * len(head)]
        self.md += ["| " + " | ".join(r) + " |" for r in esc] + [""]

    def figure_html(self, name: str, caption: str, cls: str = "") -> str:
        """``<figure>`` of the kept PNG ``name`` (:meth:`png`) embedded as base64."""
        data = base64.b64encode(self.pngs[name]).decode("ascii")
        alt = html.escape(caption, quote=True)
        attr = f' class="{cls}"' if cls else ""
        return (f'<figure{attr}><img src="data:image/png;base64,{data}" alt="{alt}">'
                f"<figcaption>{html.escape(caption)}</figcaption></figure>")

    @staticmethod
    def figure_md(name: str, caption: str) -> str:
        """Markdown of the PNG ``name`` (beside the markdown) with its caption in italics."""
        return f"![{md_text(Path(name).stem)}]({name})\n\n*{md_text(caption)}*"

    def figure(self, name: str, caption: str) -> None:
        """Embed the kept PNG ``name`` (base64) in the HTML; link it from the markdown."""
        self.html.append(self.figure_html(name, caption))
        self.md += [self.figure_md(name, caption), ""]

    def bullets(self, items: Sequence[str]) -> None:
        """A bulleted list of plain-text items."""
        self.html.append("<ul>" + "".join(f"<li>{html.escape(i)}</li>" for i in items) + "</ul>")
        self.md += [f"- {md_text(i)}" for i in items] + [""]

    def equations(self, lines: Sequence[str]) -> None:
        """Equations, one numbered item each, wrapping at any character with a hanging indent."""
        self.html.append('<ol class="eq">' + "".join(f"<li>{html.escape(e)}</li>" for e in lines)
                         + "</ol>")
        self.md += [*md_code_block(lines), ""]

    def raw(self, html_text: str, md_text: str = "") -> None:
        """Raw HTML (built by the caller from escaped parts) and its markdown."""
        self.html.append(html_text)
        if md_text:
            self.md += [md_text, ""]

    def pre(self, lines: Sequence[str]) -> None:
        """Preformatted lines (escaped in the HTML, a code block in the markdown)."""
        self.html.append("<pre>" + html.escape("\n".join(lines)) + "</pre>")
        self.md += [*md_code_block(lines), ""]

    def write(self) -> Path:
        """Write the kept PNGs (:meth:`png`), ``report.html`` (self-contained: CSS inline,
        figures embedded, a Content-Security-Policy forbidding network requests) and
        ``report.md`` into ``out_dir``, each atomically, after checking every one of them
        (:func:`~testbed.core.atomic.refuse_foreign`): a file there that is not the kind the
        report writes is refused in one line before any output is written.

        Returns
        -------
        Path
            The HTML file.
        """
        doc = (HTML_REPORT_HEAD + '<meta name="viewport" content="width=device-width, initial-scale=1">'
               f"<title>{html.escape(self.title)}</title><style>{CSS}</style></head>\n<body>\n"
               f"<h1>{html.escape(self.title)}</h1>\n" + "\n".join(self.html) + "\n</body></html>\n")
        out = self.out_dir / "report.html"
        pngs = {self.out_dir / name: data for name, data in self.pngs.items()}
        # every output checked before any is written: a foreign fit_time.png had been refused
        # after the score figures were replaced (review 27e M1)
        # a PNG the folder holds byte for byte is not written, so not checked: a run's own
        # figures, reported into its own folder (those of a run written before figures carried
        # the testbed's marker too)
        pngs = {p: data for p, data in pngs.items() if not _holds(p, data)}
        refuse_foreign_outputs(self.out_dir, pngs)
        for path, data in pngs.items():
            atomic_write(path, lambda tmp, data=data: Path(tmp).write_bytes(data))
        atomic_write_text(out, doc)
        atomic_write_text(self.out_dir / "report.md", "\n".join(self.md).rstrip() + "\n")
        return out


#: The outputs every report writes, by name, and their kinds (its figures vary with its source)
REPORT_FILES = (("report.html", HTML_FILE), ("report.md", REPORT_MARKDOWN_FILE))


def refuse_foreign_outputs(out_dir: str | os.PathLike, pngs: Iterable[Path] = (),
                           option: str = "") -> None:
    """Refuse, before any is written, a file in ``out_dir`` that a report would replace and
    that is not of the kind the report writes there (:data:`REPORT_FILES`, and the figures
    ``pngs``): :func:`~testbed.core.atomic.refuse_foreign` for each.  The one list of a
    report's outputs: ``testbed report`` checks it before the work (``option`` names the
    folder's option in its message), :meth:`Page.write` again with its figures before it
    writes (review 28b L1: two lists before)."""
    out_dir = Path(out_dir)
    expected = "another --output folder, or remove the file"

    def shown(path: Path) -> str | None:
        return f"{option} {terminal_safe(str(path))}" if option else None

    # each figure opened once, by the marker check; an earlier report's unmarked figure is
    # looked for (its bytes read and encoded) only where that check refuses, and the page is
    # read once, at the first such figure: not for every marked figure (review 29a L6)
    page: bytes | None = None
    for p in map(Path, pngs):
        try:
            refuse_foreign(p, PNG_FILE, shown(p), expected=expected)
        except InputError:
            if page is None:
                page = _earlier_page(out_dir)
            if not _earlier_figure(p, page):
                raise
    for name, kind in REPORT_FILES:
        refuse_foreign(out_dir / name, kind, shown(out_dir / name), expected=expected)


def _earlier_page(out_dir: Path) -> bytes:
    """The bytes of the folder's ``report.html`` if it is the testbed's
    (:data:`~testbed.core.atomic.HTML_FILE`), else ``b""`` (none, empty, foreign or
    unreadable): the page :func:`_earlier_figure` searches."""
    page = out_dir / "report.html"
    try:
        if not page.is_file() or foreign_head(page, HTML_FILE):  # a FIFO never read
            return b""
        return page.read_bytes()
    except OSError:
        return b""


def _earlier_figure(path: Path, page: bytes) -> bool:
    """True for a figure an earlier report wrote before figures carried the testbed's PNG
    marker (:data:`~testbed.core.atomic.PNG_SOFTWARE`, review 28b M2): a PNG whose bytes the
    folder's ``report.html`` of the testbed's (``page``, :func:`_earlier_page`) embeds, as
    every report page embeds its figures (base64 data URIs).  Such a folder is replaced as
    before the marker; a PNG of the user's, which no page of the testbed's embeds byte for
    byte, is still refused."""
    if not page:
        return False
    try:
        # the whole data URI, quotes included: a prefix of another figure's does not match
        uri = b'src="data:image/png;base64,' + base64.b64encode(path.read_bytes()) + b'"'
    except OSError:
        return False
    return uri in page


def _holds(path: Path, data: bytes) -> bool:
    """True if the file ``path`` holds exactly ``data`` (nothing to write)."""
    try:
        return path.stat().st_size == len(data) and path.read_bytes() == data
    except OSError:
        return False


# ----------------------------------------------------------------------------- run report
def _words(text: str) -> set[str]:
    return set(re.findall(r"[A-Za-z0-9_]+", text.lower()))


def irrelevant_keys(values: dict[str, Any], schema: dict[str, Any], chosen: Sequence[str] = ()) -> set[str]:
    """Keys of a settings table that the chosen options make irrelevant, read from the schema.

    Generic (no rig named), three conventions of the schemas' documentation: a key named
    after a choice key (``base_k1`` after ``base``) whose documentation names another choice
    and not the chosen one ("stiffness of the soft base spring" under ``base = "stiff"``); a
    key whose documentation says ``not with X`` for a chosen value X of any table (``dth1_0``,
    "not with sine_replay", under ``type = "sine_replay"``); and keys a choice key's
    documentation lists in parentheses after another option only ("'lowpass' by a ...
    filter (cutoff_hz, filter_order)" under ``derivatives = "recorded"``).

    Parameters
    ----------
    values : dict
        The table as validated (defaults filled in).
    schema : dict of str to Field
        Its schema (``unit``, ``doc``, ``choices``); keys without a field are kept.
    chosen : sequence of str
        Chosen option values of other tables (e.g. the excitation type).
    """
    picks = {k: str(values[k]) for k, f in schema.items()
             if getattr(f, "choices", None) and k in values}
    every_pick = {v.lower() for v in (*picks.values(), *chosen)}
    out = set()
    for k, f in schema.items():
        doc = str(getattr(f, "doc", "") or "")
        words = _words(doc)
        for c, v in picks.items():
            others = {str(o).lower() for o in schema[c].choices} - {v.lower()}
            if k.startswith(c + "_") and words & others and v.lower() not in words:
                out.add(k)
        if any(f"not with {p}" in doc.lower() for p in every_pick):
            out.add(k)
    for c, v in picks.items():  # "'lowpass' by a ... filter (cutoff_hz, filter_order)" in c's doc
        doc = str(getattr(schema[c], "doc", "") or "")
        listed = {o: set(re.findall(r"[A-Za-z0-9_]+", m.group(1)))
                  for o in schema[c].choices
                  if (m := re.search(rf"'{re.escape(str(o))}'[^(']*\(([^)]*)\)", doc))}
        keep = listed.get(v, set())
        for o, keys in listed.items():
            if o != v:
                out |= keys - keep
    return out & set(values)


def _schemas(run: SavedRun) -> dict[str, dict[str, Any]]:
    """Schemas of the scenario's tables by section (empty where the rig is unknown here)."""
    sc = run.scenario
    out: dict[str, dict[str, Any]] = {"noise": NOISE_SCHEMA,
                                      "signal": SIGNAL_SCHEMAS.get(run.kind, {})}
    try:
        rig = RIGS.get(sc["rig"])
    except Exception:  # a run made with a rig this installation lacks: tables without units
        return out
    out["rig"] = dict(rig.rig_schema)
    out["simulation"] = dict(rig.simulation_schema)
    out["excitation"] = dict(rig.excitation_schemas.get(sc.get("excitation", {}).get("type", ""), {}))
    return out


def _value(v: Any) -> Any:
    if isinstance(v, (list, tuple)):
        return ", ".join(fmt(x, 6) for x in v) if v else "(empty)"
    if isinstance(v, dict):
        return json.dumps(v, sort_keys=True)
    return v


def _settings_table(page: Page, title: str, values: dict[str, Any], schema: dict[str, Any],
                    chosen: Sequence[str] = (), override: dict[str, tuple[Any, str]] | None = None) -> None:
    """One settings table (key, value, unit, meaning), keys the options make irrelevant left out
    and named below it; ``override`` replaces a value and its meaning (e.g. actual positions)."""
    if not values:
        return
    hidden = irrelevant_keys(values, schema, chosen)
    override = override or {}
    rows = []
    for k, v in values.items():
        if k in hidden:
            continue
        f = schema.get(k)
        unit, doc = getattr(f, "unit", "") or "", getattr(f, "doc", "") or ""
        if k in override:
            v, doc = override[k]
        rows.append([k, _value(v), unit, doc])
    page.heading(title, 3)
    page.table(["key", "value", "unit", "meaning"], rows, digits=6)
    if hidden:
        page.para("Not shown, irrelevant to the options chosen here: " + ", ".join(sorted(hidden)) + ".",
                  '<span class="muted">Not shown, irrelevant to the options chosen here: '
                  + html.escape(", ".join(sorted(hidden))) + ".</span>")


def _positions(run: SavedRun) -> list[float] | None:
    """Actual sensor positions [m] of the run: the dataset's, else the truth's."""
    for name, sig in run.meta.get("dataset", {}).get("signals", {}).items():
        if name.startswith("measured/") and sig.get("positions") and sig.get("unit") not in figs.INPUT_UNITS:
            return [float(x) for x in sig["positions"]]
    pos = run.truth.get("sensor_positions")
    return None if pos is None else [float(x) for x in np.atleast_1d(pos)]


def _settings_section(page: Page, run: SavedRun) -> None:
    page.heading("Settings")
    sc, ds = run.scenario, run.meta.get("dataset", {})
    n, fs = ds.get("n_samples"), ds.get("fs")
    head = [["scenario", sc.get("name", run.name)], ["description", sc.get("description", "")],
            ["rig", f"{sc['rig']} ({run.kind})"], ["seed", str(sc.get("seed"))],
            ["tags", ", ".join(sc.get("tags", []))],
            ["record", f"{n} samples at {fmt(fs, 6)} Hz"
                       + (f" ({fmt(n / fs)} s)" if n and fs else "")]]
    page.table(["item", "value"], [r for r in head if r[1] not in ("", None)])
    schemas = _schemas(run)
    exc_type = str(sc.get("excitation", {}).get("type", ""))
    over = {}
    pos = _positions(run)
    rig = sc.get("rig_params", {})
    for k, f in schemas.get("rig", {}).items():  # list-valued keys in metres: the actual positions
        if k in rig and getattr(f, "type", None) is list and getattr(f, "unit", "") == "m" and pos:
            note = " (the default)" if not rig[k] else ""
            over[k] = (pos, f"actual positions from the dataset{note}; {getattr(f, 'doc', '')}")
    _settings_table(page, "Rig", rig, schemas.get("rig", {}), (exc_type,), over)
    for sec, title in (("simulation", "Simulation"), ("excitation", "Excitation"), ("noise", "Noise"),
                       ("signal", "Signal chain")):
        _settings_table(page, title, sc.get(sec, {}), schemas.get(sec, {}), (exc_type,))
    params = run.meta["identifier"].get("params", {})
    declared = {k for k in (sc.get("identify") or {}) if k != "method"}
    page.heading(f"Identifier {run.identifier}", 3)
    page.table(["hyperparameter", "value", "set by"],
               [[k, _value(v), "scenario" if k in declared else "default"] for k, v in params.items()]
               or [["(none)", "", ""]], digits=6)
    page.para(f"Class {run.meta['identifier'].get('class', '')}; fitted in {run.fit_time:.3g} s.")
    rules = {k: v[0] for k, v in run.meta.get("model_lists", {}).items()
             if k.endswith("rule_") and isinstance(v, list) and len(v) == 1}
    if rules:  # settings the identifier chose from the data, and the rule that chose each
        page.table(["chosen from the data", "rule"], [[k.removesuffix("rule_").rstrip("_") or k, v]
                                                      for k, v in sorted(rules.items())])
    if ds.get("prior"):
        page.para("Prior knowledge given to the identifier: "
                  + ", ".join(f"{k} = {fmt(v)}" for k, v in ds["prior"].items()) + ".")


def _truth_section(page: Page, run: SavedRun) -> None:
    tr = run.truth
    if "frequencies_hz" not in tr:
        return
    page.heading("Truth")
    f = np.asarray(tr["frequencies_hz"], dtype=float)
    eb = np.asarray(tr.get("eb_frequencies_hz", []), dtype=float)
    z = np.asarray(tr.get("damping_ratios", []), dtype=float)
    rows = [[i + 1, f[i], eb[i] if i < eb.size else None,
             100 * (f[i] / eb[i] - 1) if i < eb.size else None, z[i] if i < z.size else None]
            for i in range(min(len(f), 6))]
    page.table(["mode", "true [Hz]", "Euler-Bernoulli [Hz]", "true vs E-B [%]", "damping ratio [-]"],
               rows)


def _verdict_section(page: Page, run: SavedRun) -> None:
    label = run.verdict.upper()  # PASS, FAIL or NO VERDICT
    status = {"PASS": "pass", "FAIL": "fail"}.get(label, "none")
    n_checks = len(run.checks)
    failed = [c for c in run.checks if not c.passed]
    body = (f"{n_checks - len(failed)} of {n_checks} threshold(s) met" if n_checks
            else "no thresholds declared in the scenario's [score] table (not a pass)")
    body += f"; identifier {run.identifier}, fit {run.fit_time:.3g} s."
    page.para(f"{label}: {body}", f'<span class="badge {status}">{label}</span> {html.escape(body)}')
    reasons = [f"{c.metric} = {fmt(c.value)}, needs {'>=' if c.bound == 'min' else '<='} "
               f"{fmt(c.threshold)}" for c in failed]
    reasons += [f"{k}: {why}" for k, why in run.failures.items()]
    if reasons:
        page.heading("Why it failed", 3)
        page.bullets(reasons)


def _scores_section(page: Page, run: SavedRun) -> None:
    page.heading("Scores")
    doc = METRICS.get(run.kind, {})
    rows, classes, checked = [], [], set()
    unit = {k: figs.metric_unit(k, doc.get(k, "")) for k in run.scores}
    for c in run.checks:
        checked.add(c.metric)
        op = ">=\u00a0" if c.bound == "min" else "<=\u00a0"  # no break inside a threshold
        rows.append([c.metric, doc.get(c.metric, ""), c.value, unit.get(c.metric, "-"),
                     op + fmt(c.threshold), "pass" if c.passed else "FAIL"])
        classes.append("pass" if c.passed else "fail")
    for k, v in sorted(run.scores.items()):
        if k not in checked:
            rows.append([k, doc.get(k, ""), v, unit.get(k, "-"), "–", "reported"])
            classes.append(None)
    for k, why in run.failures.items():  # a scored failure: diverged, fit failed, non-physical
        rows.append([f"failure: {k}", why, None, "", "–", "FAIL"])
        classes.append("fail")
    page.table(["metric", "meaning", "value", "unit", "threshold", "result"], rows, classes)


def run_report(run: SavedRun, out_dir: str | os.PathLike) -> Path:
    """Write the report of a saved run into ``out_dir``; return the HTML path.

    Sections: verdict and its reasons, every setting of the scenario as tables (rig keys
    irrelevant to the chosen options left out, actual sensor positions), the truth, the
    scores, natural frequencies, the identified equations (wrapped), the figures
    (:func:`testbed.reporting.figures.run_figures`; the figures the run folder lacks are drawn
    here) and provenance.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    page = Page(f"Run {run.name}: {run.identifier}", out_dir)
    _verdict_section(page, run)
    _scores_section(page, run)
    d = run.details
    if "f_id" in d:
        page.heading("Natural frequencies")
        rows = figs.frequency_rows(d["f_true"], d["f_id"], d.get("pair"), d.get("z_true"), d.get("z_id"))
        page.table(["mode", "true [Hz]", "identified [Hz]", "error [%]", "ζ true [-]", "ζ identified [-]"],
                   [[r["mode"], r["f_true"], r["f_id"], r["error_pct"], r.get("z_true"), r.get("z_id")]
                    for r in rows])
    page.heading("Identified equations")
    page.equations(run.equations or ["(none)"])
    _settings_section(page, run)
    _truth_section(page, run)
    page.heading("Figures")
    # the run's own figures, copied beside the report with the report's other files (they had
    # been copied over a user's file of that name at once: hostile round 28)
    pngs = {p.stem: page.png(p.name, p.read_bytes()) for p in run.figures}
    wanted = list(figs.run_figures_available(run))
    missing = [s for s in wanted if s not in pngs]
    if missing:  # a run saved by an older version, or without figures: draw what it lacks
        drawn = figs.run_figures(run, only=missing)
        pngs.update({stem: page.png(f"{stem}.png", figs.png_bytes(f)) for stem, f in drawn.items()})
    for stem in [s for s in ORDER if s in pngs] + [s for s in pngs if s not in ORDER]:
        page.figure(pngs[stem], CAPTIONS.get(stem, stem))
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


def _number(v: Any) -> bool:
    """A score value: a number, not a bool (NaN and infinities included)."""
    return isinstance(v, (int, float, np.number)) and not isinstance(v, bool)


def _finite(v: Any) -> bool:
    return isinstance(v, (int, float, np.number)) and not isinstance(v, bool) and math.isfinite(float(v))


def _row_checks(r: dict[str, Any]) -> list[dict[str, Any]]:
    """The ``checks`` JSON of a results row as a list (empty if absent or unreadable)."""
    checks = stored_checks(r) or []  # (a JSON number there was a TypeError: round 15)
    return [c for c in checks if isinstance(c, dict) and {"metric", "bound", "threshold"} <= set(c)]


def thresholds(rows: Sequence[dict[str, Any]]) -> dict[str, dict[str, list[tuple[str, float]]]]:
    """Declared thresholds by scenario and metric: ``{scenario: {metric: [(bound, value)]}}``."""
    out: dict[str, dict[str, list[tuple[str, float]]]] = {}
    for r in rows:
        for c in _row_checks(r):
            lst = out.setdefault(str(r["scenario"]), {}).setdefault(str(c["metric"]), [])
            key = (str(c["bound"]), float(c["threshold"]))
            if key not in lst:
                lst.append(key)
    return out


def _short(error: str, n: int = 90) -> str:
    """An error message without its ``(file:line)`` tail, cut to ``n`` characters."""
    e = re.sub(r"\s*\([^()]*:\d+\)\s*$", "", str(error)).strip() or "unknown error"
    return e if len(e) <= n else e[: n - 1] + "…"


def failure_reasons(cells: Sequence[dict[str, Any]]) -> str:
    """Why cells did not pass, counted: errors of cells that failed to run (``error`` column),
    then thresholds missed by cells that ran (``checks`` column); "" if every cell passed."""
    counts: dict[str, int] = {}
    for r in cells:
        if not _ok(r):
            why = [f"failed: {_short(r.get('error', ''))}"]
        elif r.get("passed"):
            continue
        else:
            why = [f"{c['metric']} {'<' if c['bound'] == 'min' else '>'} {fmt(c['threshold'], 3)}"
                   for c in _row_checks(r) if not c.get("passed", True)] or ["not passed"]
        for w in why:
            counts[w] = counts.get(w, 0) + 1
    return "; ".join(f"{n}× {w}" for w, n in sorted(counts.items(), key=lambda x: (-x[1], x[0])))


def _rate(cell: Sequence[dict[str, Any]]) -> str:
    """``passed/cells (percent)`` of a group of cells; a cell that failed to run did not pass."""
    n_pass = sum(bool(r.get("passed")) and _ok(r) for r in cell)
    return f"{n_pass}/{len(cell)} ({100 * n_pass / len(cell):.0f} %)"


def _iqr(vals: Sequence[float], cells: int) -> str:
    """Median [25th, 75th percentile] of a score over ``cells`` cells that ran, ``vals`` their
    values (:func:`~testbed.numerics.quantiles.quartiles`: an infinite score counted, NaN left
    out and the count said: a median over 5 of 6 cells was shown as if over all, round 13)."""
    q25, med, q75, n = quartiles(vals)
    if n == 0:
        return "–"
    of = f" ({n} of {cells} cells)" if n < cells else ""
    if q25 == q75:  # one seed, or all alike: the value alone
        return fmt(med, 3) + of
    return f"{fmt(med, 3)} [{fmt(q25, 3)}, {fmt(q75, 3)}]" + of


def _doc(metric: str) -> str:
    for kind in METRICS.values():
        if metric in kind:
            return kind[metric]
    return ""


def _summary_tables(page: Page, rows: Sequence[dict[str, Any]],
                    thr: dict[str, dict[str, list[tuple[str, float]]]]) -> None:
    """Per scenario: a row per identifier x noise with cells, pass rate, median [IQR] of the
    scenario's thresholded scores (else its first scores) and the reasons cells did not pass."""
    metrics = score_names(rows)
    for sc in sorted({str(r["scenario"]) for r in rows}):
        srows = [r for r in rows if str(r["scenario"]) == sc]
        shown = [m for m in thr.get(sc, {}) if m in metrics]
        if not shown:  # nothing thresholded: the first few scores this scenario has
            shown = [m for m in metrics if any(_number(r.get(m)) and not math.isnan(float(r[m]))
                                               for r in srows)][:4]
        head = ["identifier", "noise [%]", "cells", "pass rate"]
        for m in shown:
            bounds = ", ".join(f"{'≥' if b == 'min' else '≤'} {fmt(t, 3)}"
                               for b, t in thr.get(sc, {}).get(m, []))
            u = figs.metric_unit(m, _doc(m))
            head.append(f"{m} [{u}]" + (f" ({bounds})" if bounds else ""))
        head.append("why cells did not pass")
        table, classes = [], []
        for ident in sorted({str(r["identifier"]) for r in srows}):
            for z in sorted({float(r["noise"]) for r in srows if str(r["identifier"]) == ident}):
                cell = [r for r in srows if str(r["identifier"]) == ident and float(r["noise"]) == z]
                n_pass = sum(bool(r.get("passed")) and _ok(r) for r in cell)
                line: list[Any] = [ident, z, len(cell), _rate(cell)]
                ran = [r for r in cell if scored(r)]  # a scored failure's scores too (its
                # bar failed is the row's point: over the "ok" rows a failed cell showed "–")
                line += [_iqr([float(r[m]) for r in ran if _number(r.get(m))], len(ran))
                         for m in shown]
                line.append(failure_reasons(cell) or "–")
                table.append(line)
                classes.append("fails" if n_pass < len(cell) else None)
        page.heading(f"Scenario {sc}", 3)
        page.table(head, table, classes)


def sweep_report(rows: Sequence[dict[str, Any]], out_dir: str | os.PathLike,
                 title: str | None = None) -> Path:
    """Write the report of sweep result rows into ``out_dir``; return the HTML path.

    Parameters
    ----------
    rows : sequence of dict
        Results rows (:func:`testbed.studies.results.read_results`).
    out_dir : path
        Report folder (created).
    title : str, optional
        Fallback title when the rows name no study (e.g. the results file's name).

    Notes
    -----
    The page: a pass-rate overview (scenario x identifier x noise), a numeric summary per
    scenario (median and interquartile range over seeds, pass rate, reasons of failures),
    then one figure per score: a panel per scenario, a line per identifier (median, IQR
    band) against noise, units from the metric catalogue, the scenario's thresholds as
    dashed lines, a log axis where the values span decades; then fit times and failed cells.
    """
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    rows = list(rows)
    studies = sorted({str(r.get("study") or "") for r in rows} - {""})
    name = ", ".join(studies) or title or "sweep"
    page = Page(f"Study {name}", out_dir)
    idents = sorted({str(r["identifier"]) for r in rows})
    scenarios = sorted({str(r["scenario"]) for r in rows})
    noises = sorted({float(r["noise"]) for r in rows})
    errors = [r for r in rows if not _ok(r)]
    page.para(f"{len(rows)} cells: {len(scenarios)} scenario(s), {len(idents)} identifier(s) "
              f"({', '.join(idents)}), noise levels {', '.join(fmt(z) for z in noises)} % of channel "
              f"RMS, {len({r['seed'] for r in rows})} seed(s); {len(errors)} failed to run.")
    thr = thresholds(rows)

    page.heading("Pass rate")
    page.para("Cells passing every threshold of their scenario, out of all cells (a cell that failed "
              "to run counts as not passed).")
    table = []
    for sc in scenarios:
        for i in idents:
            line: list[Any] = [sc, i]
            cells = [[r for r in rows if r["scenario"] == sc and r["identifier"] == i
                      and float(r["noise"]) == z] for z in noises]
            if not any(cells):
                continue
            line += [_rate(cell) if cell else "–" for cell in cells]
            table.append(line)
    page.table(["scenario", "identifier"] + [f"noise {fmt(z)} %" for z in noises], table)

    page.heading("Summary")
    page.para("Median [25th, 75th percentile] over seeds of the cells that were scored (passed, "
              "or failed with a reason; crashes left out); thresholds in the column heads; "
              "reasons counted over the cells of each row.")
    _summary_tables(page, rows, thr)

    page.heading("Scores vs noise")
    page.para("One figure per score, a panel per scenario (shared axes): median over seeds (line) "
              "and interquartile range (band) per identifier; dashed red: the scenario's threshold.")
    ok = [r for r in rows if scored(r)]  # as the summary: every cell scored, crashes left out
    names = score_names(rows)
    kinds = list(METRICS)

    def order(m: str) -> tuple[int, int, str]:  # thresholded first, then by rig kind, then name
        kind = next((k for k, v in enumerate(METRICS.values()) if m in v), len(kinds))
        return (0 if any(m in t for t in thr.values()) else 1, kind, m)

    thresholded = [m for m in names if any(m in t for t in thr.values())]
    figures_html, figures_md, zero = [], [], []
    for m in sorted(names, key=order):
        vals = [float(r[m]) for r in ok if _finite(r.get(m))]
        if vals and m not in thresholded and not any(vals):
            zero.append(m)  # e.g. a cubic norm of linear models: a flat line says nothing
            continue
        fig = figs.score_panels(ok, m, figs.metric_unit(m, _doc(m)),
                                {sc: t[m] for sc, t in thr.items() if m in t})
        if fig is None:
            continue
        wide = len({r["scenario"] for r in ok if _finite(r.get(m))}) > 1
        png = page.png(f"score_{m}.png", figs.png_bytes(fig))
        cap = f"{m}: {_doc(m) or 'score'}"
        figures_html.append(page.figure_html(png, cap, "wide" if wide else ""))
        figures_md.append(page.figure_md(png, cap))
    page.raw('<div class="grid">' + "".join(figures_html) + "</div>", "\n\n".join(figures_md))
    if zero:
        page.para(f"Exactly 0 in every cell that ran (not drawn): {', '.join(zero)}.")

    page.heading("Fit time")
    page.table(["identifier", "cells", "median [s]", "max [s]"],
               [[i, len(t), float(np.median(t)) if t else None, float(np.max(t)) if t else None]
                for i in idents for t in [[float(r["fit_time"]) for r in rows if r["identifier"] == i
                                           and _ok(r) and _finite(r.get("fit_time"))]]])
    page.figure(page.png("fit_time.png",  # as the table
                         figs.png_bytes(figs.fit_times([r for r in rows if _ok(r)]))),
                "Fit time per identifier over all cells that ran.")
    if errors:
        page.heading("Cells that failed to run")
        page.table(["scenario", "identifier", "noise [%]", "seed", "error"],
                   [[r["scenario"], r["identifier"], r["noise"], r["seed"], r.get("error", "")]
                    for r in errors])
    commits = sorted({str(r.get("commit", "")) for r in rows})
    page.para("Commit(s): " + ", ".join(commits) + ".")
    return page.write()


def write_report(source: str | os.PathLike, out_dir: str | os.PathLike) -> Path:
    """Write ``report.html`` and ``report.md`` of a run folder or a sweep results file.

    Parameters
    ----------
    source : path
        A run folder written by :func:`testbed.studies.runstore.save_run`, a scenario folder
        of the run history (its latest run, :func:`~testbed.studies.runstore.resolve_run`),
        or a results file of a sweep (read with :func:`testbed.studies.results.read_results`).
    out_dir : path
        Report folder (created); the PNGs of the markdown twin go beside it.

    Returns
    -------
    Path
        The HTML report.
    """
    source = Path(source)
    if source.is_dir():
        return run_report(load_run(resolve_run(source)), out_dir)
    if not source.is_file() and not parts_dir(source).is_dir():  # (parts: a sweep killed at once)
        raise FileNotFoundError(f"{source}: neither a run folder nor a results file")

    rows = read_results(source)
    if not rows:  # an empty results file, or the parts folder of a sweep killed before its
        # first row: the report of nothing, "0 cells ... noise levels  % ...", status 0 (round 15)
        raise ResultsError(f"{source}: holds no results (no cell has finished); nothing to "
                           "report: run or resume its sweep (`testbed sweep`)")
    return sweep_report(rows, out_dir, title=source.stem)


# ----------------------------------------------------------------------------- run history
def save_run_figures_and_report(run: SavedRun, folder: Path,
                                draw: Callable[[SavedRun, Path], list[Path]] | None = None
                                ) -> list[Path]:
    """The figure writer of ``testbed run``: the run figures, then ``report.html`` beside them.

    Passed as ``figures`` to :func:`testbed.studies.runstore.save_new_run`, so the report is
    written in the temporary folder and appears with the run, atomically.  ``draw(run,
    folder)`` writes the PNGs and returns their paths in report order (default
    :func:`testbed.reporting.figures.save_run_figures`; ``testbed run`` draws them in a
    separate process, :mod:`testbed.reporting.drawer`).  Returns the PNGs.
    """
    paths = (draw or figs.save_run_figures)(run, folder)
    run.meta["figures"] = [p.name for p in paths]
    run_report(run, folder)
    return paths


#: Scores shown per run in the index when the run declares no thresholds.
INDEX_SCORES = 3


def _key_scores(r: dict[str, Any]) -> tuple[str, str]:
    """(HTML, text) of a run's key scores: its checked metrics, else its first few scores."""
    if r["checks"]:
        items = [(f"{c['metric']} {fmt(c['value'])} {_BOUND.get(c['bound'], c['bound'])} "
                  f"{fmt(c['threshold'])}", "✓" if c["passed"] else "✗") for c in r["checks"]]
    else:
        items = [(f"{k} {fmt(v)}", "") for k, v in list(r["scores"].items())[:INDEX_SCORES]]
    h = "<br>".join('<span class="ks">'
                    + (f'<span class="{"pass" if c == "✓" else "fail"}">{c}</span> ' if c else "")
                    + html.escape(t) + "</span>" for t, c in items)
    if r.get("failure"):
        h = f'<span class="fail">{html.escape(_short(r["failure"]))}</span>' + ("<br>" + h if h else "")
    return h, "; ".join(f"{c} {t}".strip() for t, c in items)


#: How a threshold's bound reads in the index.
_BOUND = {"min": "≥", "max": "≤"}


def runs_index_html(runs: Sequence[dict[str, Any]], out_dir: str | os.PathLike) -> str:
    """The self-contained index page of a run history (no network, no script), newest first.

    Parameters
    ----------
    runs : sequence of dict
        Rows of :func:`testbed.studies.runstore.list_runs`.
    out_dir : path-like
        The folder the page is written to; links are relative to it.

    Returns
    -------
    str
        One row per run: time (UTC), scenario, seed, identifier, run (a link to the run's
        ``report.html``, or to its ``run.json`` when it has no report), verdict, key scores.
    """
    out = Path(out_dir).resolve()
    rows = []
    for r in sorted(runs, key=lambda r: (r["created"], r["scenario"], r["id"]), reverse=True):
        folder = Path(r["path"]).resolve()
        target = folder / "report.html" if (folder / "report.html").is_file() else folder / "run.json"
        try:
            href = target.relative_to(out).as_posix()
        except ValueError:
            href = target.as_uri()
        v = r["verdict"]
        badge = {"pass": "pass", "FAIL": "fail"}.get(v, "none")
        scores, _ = _key_scores(r)
        cells = [html.escape(r["created"].replace("+00:00", "Z").replace("T", " ")),
                 html.escape(r["scenario"]),
                 html.escape(str(r["seed"])), html.escape(r["identifier"]),
                 f'<a href="{html.escape(href, quote=True)}">{html.escape(r["id"])}</a>',
                 f'<span class="badge {badge}">{html.escape(v or "?")}</span>', scores]
        nowrap = ' class="nowrap"'  # the time and the run's name read best on one line
        rows.append("<tr>" + "".join(f"<td{nowrap if i in (0, 4) else ''}>{c}</td>"
                                     for i, c in enumerate(cells)) + "</tr>")
    head = "".join(f"<th>{h}</th>" for h in ("time (UTC)", "scenario", "seed", "identifier", "run",
                                             "verdict", "key scores"))
    body = (f"<table><thead><tr>{head}</tr></thead><tbody>{''.join(rows)}</tbody></table>" if rows
            else "<p>No runs yet: <code>testbed run SCENARIO</code> adds one.</p>")
    return (HTML_REPORT_HEAD + '<meta name="viewport" content="width=device-width, initial-scale=1">'
            f"<title>Runs</title><style>{CSS}td.nowrap,.ks{{white-space:nowrap}}.ks{{font-size:.85em}}"
            "body{max-width:1500px}"
            "</style></head>\n"
            "<body>\n<h1>Runs</h1>\n"
            f'<p class="muted">{len(runs)} run(s) in {html.escape(str(out_dir))}, newest first; '
            "each run links to its report.</p>\n" + body + "\n</body></html>\n")
