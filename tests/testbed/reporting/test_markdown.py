"""Free text in the testbed's markdown (``testbed.reporting.markdown``): shown, never markup."""

from __future__ import annotations

import dataclasses
import re
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/testbed: _synthetic_runs
import _synthetic_runs as synth

from testbed.reporting.identified import render_identified
from testbed.reporting.markdown import md_code_block, md_text
from testbed.reporting.report import write_report
from testbed.studies.runstore import save_run

#: A "[" not escaped: a link or an image may open there.
OPEN_BRACKET = re.compile(r"(?<!\\)\[")
HOSTILE = "<img src=x onerror=alert(1)> ![t](https://evil.example/t.png) [a](javascript:x) `c` | d"


def test_md_text_leaves_no_html_link_image_or_line_end():
    text = md_text(HOSTILE + "\nline two & <b>")
    assert "<" not in text and ">" not in text and "\n" not in text
    assert not OPEN_BRACKET.search(text)
    assert "\\[" in text and "&lt;img" in text and "&amp; &lt;b&gt;" in text
    assert "\\`c\\`" in text and "\\|" in text


def test_a_code_block_is_fenced_past_any_backticks_inside():
    block = md_code_block(["x = 1", "````", "<img src=x>"])
    assert block[0] == block[-1] == "`````" and block[1:-1] == ["x = 1", "````", "<img src=x>"]
    assert md_code_block(["x"])[0] == "```"


def test_a_run_reports_markdown_shows_a_hostile_description_and_equation_as_text(tmp_path):
    # hostile round 19's open item: report.md carried a scenario description or a plugin's text
    # as written, raw HTML and a remote image to a markdown renderer (report.html escaped it)
    result = synth.structural_result(n_samples=400)
    result.scenario = dataclasses.replace(result.scenario, description=HOSTILE)
    result.model.equations = lambda precision=4: ["```", HOSTILE]
    run_dir = save_run(result, tmp_path / "run", figures=None)
    write_report(run_dir, tmp_path / "rep")
    md = (tmp_path / "rep" / "report.md").read_text()
    outside = md.split("````")  # the equations' fence is four backticks: it holds ```
    assert len(outside) == 3, "the equations' block must be fenced past its own ```"
    assert "&lt;img src=x onerror=alert(1)&gt;" in outside[0] + outside[2]  # the settings
    for part in outside[0::2]:
        assert "<img" not in part and not OPEN_BRACKET.search(part.split("## Figures")[0])
    assert "<img" in outside[1]  # inside the code block: shown as text by every renderer


def test_identifys_report_shows_the_users_names_as_text():
    summary = {"method": "m", "source": "/data/<img src=x>.csv", "kind": "structural",
               "channels": ["[a](javascript:x)", "b"], "n_samples": 10, "fs_hz": 100.0,
               "fit_time_s": 0.1, "r2": 0.9,
               "identifier": {"class": "C", "params": {"p": "<b>"}},
               "equations": ["```", "<img src=y>"]}
    text = render_identified(summary)
    head, block = text.split("## Equations")
    assert "<" not in head and not OPEN_BRACKET.search(head)
    assert block.strip().startswith("````") and block.strip().endswith("````")
