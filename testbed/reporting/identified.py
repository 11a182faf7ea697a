"""The short report of a model identified from measured data (``testbed identify``): plain text
that reads the same on a terminal and as a markdown file."""

from __future__ import annotations

import math
from typing import Any

from testbed.reporting.markdown import md_code_block, md_text


def _num(v: Any) -> str:
    return "-" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{v:.5g}"


def render_identified(summary: dict[str, Any]) -> str:
    """Markdown text of a :meth:`testbed.pipeline.fit.FitResult.summary` dict: source, method,
    fit time, truth-free R^2, modal parameters (frequency [Hz], damping ratio), matrices and the
    equations."""
    ident = summary["identifier"]
    params = ", ".join(f"{k}={v!r}" for k, v in ident["params"].items())
    # the source's path, the channels' names, the parameters and the equations are the user's
    # text: shown as written, never as markup (hostile round 20)
    lines = [f"# Identified model: {md_text(summary['method'])}", "",
             f"- data: {md_text(summary['source'])} ({summary['kind']}; "
             f"{len(summary['channels'])} channels {md_text(', '.join(summary['channels']))}; "
             f"{summary['n_samples']} samples at {summary['fs_hz']:g} Hz)",
             f"- identifier: {md_text(ident['class'])}({md_text(params)})",
             f"- fit time: {summary['fit_time_s']:.3g} s",
             "- R^2 of the predicted accelerations (truth-free): "
             + (_num(summary["r2"]) if summary.get("r2") is not None
                else "not defined (implicit equations: no explicit acceleration)"), ""]
    clipped = summary.get("clipped_sensors") or []
    if clipped:  # (testbed.numerics.clipping; FitResult.summary) said, nothing refused
        lines += ["## Clipped sensors", "",
                  "The record holds a clip level (a saturated sensor): a model of it may be "
                  "wrong there.", ""]
        lines += [f"- {md_text(c['channel'])}: {c['level']:+.6g} {md_text(c['unit'])}, "
                  f"{c['n_held']} of {c['n_samples']} samples ({100 * c['share']:.3g} %) in "
                  f"{c['runs']} run(s)" for c in clipped]
        lines.append("")
    modal = summary.get("modal")
    if modal:
        lines += ["## Modes", "", "| mode | frequency [Hz] | damping ratio |", "|---|---|---|"]
        lines += [f"| {k + 1} | {_num(f)} | {_num(z)} |"
                  for k, (f, z) in enumerate(zip(modal["frequency_hz"], modal["damping_ratio"], strict=True))]
        lines.append("")
    mats = summary.get("matrices")
    if mats:
        lines += ["## Matrices (sensor coordinates)", ""]
        for key in ("M", "C", "K", "K3"):
            if mats.get(key) is None:
                continue
            lines += [f"{key} [{mats['units'][key]}]:", "```"]
            lines += ["  ".join(f"{v:+.5e}" for v in row) for row in mats[key]]
            lines += ["```", ""]
    lines += ["## Equations", "", *md_code_block(summary["equations"])]
    return "\n".join(lines) + "\n"
