"""Reports: self-contained HTML + markdown twin, checked as text and in real headless Chromium.

The browser tests open each report offline (no network, a fresh profile), keep a
full-page screenshot under ``out/test-artifacts/``, require that the page logs no
console message at all (a report has no scripts, so any message is an error or a
blocked request), and run a probe copy of the page whose inline script records,
after load, whether every image decoded (``naturalWidth > 0``).
"""

from __future__ import annotations

import json
import re
import subprocess
import sys
from pathlib import Path

import matplotlib.image as mpimg
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/testbed: _synthetic_runs
import _synthetic_runs as synth

from testbed.reporting.figures import save_run_figures
from testbed.reporting.report import CSP, sweep_report, write_report
from testbed.studies.runstore import save_run

ROOT = Path(__file__).resolve().parents[3]
ARTIFACTS = ROOT / "out" / "test-artifacts"
PROBE = """<script>window.addEventListener("load", () => {
  const imgs = [...document.images].map(i => ({ok: i.complete && i.naturalWidth > 0, w: i.naturalWidth}));
  const eqs = [...document.querySelectorAll("ol.eq")].map(e => ({scroll: e.scrollWidth, client: e.clientWidth,
                                                                 height: e.clientHeight}));
  const page = {height: document.documentElement.scrollHeight, width: document.documentElement.scrollWidth,
                view: window.innerWidth};
  document.body.setAttribute("data-probe", JSON.stringify({imgs, eqs, page}));
});</script>"""


@pytest.fixture(scope="module")
def reports(tmp_path_factory):
    """Synthetic cantilever and five-bar runs saved with figures, their reports, and a sweep report."""
    d = tmp_path_factory.mktemp("reports")
    out = {}
    for name, make in (("cantilever", lambda: synth.structural_result(n_samples=2000)),
                       ("fivebar", lambda: synth.mechanical_result(n_samples=600))):
        run_dir = save_run(make(), d / "runs" / name, figures=save_run_figures)
        out[name] = write_report(run_dir, d / "reports" / name)
    out["sweep"] = sweep_report(synth.sweep_rows(), d / "reports" / "sweep", "noise_study")
    out["study"] = sweep_report(synth.study_rows(), d / "reports" / "study", "results_file_name")
    return out


def images(html: str) -> list[str]:
    return re.findall(r'<img src="([^"]*)"', html)


FIGURES = [("cantilever", 6), ("fivebar", 2), ("sweep", 3), ("study", 4)]


@pytest.mark.parametrize(("name", "n_figures"), FIGURES)
def test_report_is_self_contained(reports, name, n_figures):
    html_path = reports[name]
    text = html_path.read_text()
    srcs = images(text)
    assert len(srcs) == n_figures
    assert all(s.startswith("data:image/png;base64,") for s in srcs)
    assert not re.search(r'(src|href)="(?!data:)', text), "no external resource"
    assert "<script" not in text and f'content="{CSP}"' in text
    md = (html_path.parent / "report.md").read_text()
    pngs = re.findall(r"!\[[^\]]*\]\(([^)]+)\)", md)
    assert len(pngs) == n_figures and all((html_path.parent / p).is_file() for p in pngs)


def test_run_report_content(reports):
    text = reports["cantilever"].read_text()
    assert '<span class="badge fail">FAIL</span>' in text
    assert re.search(r"<td>freq_error</td>.*?<td class=\"fail\">FAIL</td>", text)
    assert re.search(r"<td>trac</td>.*?<td class=\"pass\">pass</td>", text)
    assert re.search(r"<h3>Why it failed</h3>\s*<ul><li>freq_error = [0-9.e-]+, needs &lt;= 0.01</li>", text)
    assert "Euler-Bernoulli [Hz]" in text and "total_mass = 0.6" in text
    assert "eq 0: xdd0 = ..." in text and "abababab" in text  # equations, dataset hash
    md = (reports["cantilever"].parent / "report.md").read_text()
    assert "| freq_error |" in md and "FAIL" in md
    fb = reports["fivebar"].read_text()
    assert '<span class="badge pass">PASS</span>' in fb and "angle_rmse" in fb
    assert re.search(r"<td>angle_rmse</td><td>[^<]*</td><td class=\"num\">0.0141</td><td>rad</td>", fb)


def _table(text: str, heading: str) -> str:
    """The first table after ``<h3>heading</h3>``."""
    m = re.search(rf"<h3>{re.escape(heading)}</h3>\s*<table>(.*?)</table>", text)
    assert m, f"no table under {heading!r}"
    return m.group(1)


def test_run_report_settings_tables(reports):
    text = reports["cantilever"].read_text()
    rig = _table(text, "Rig")
    assert "<td>base</td><td>stiff</td>" in rig
    assert "base_k1" not in rig and "base_k3" not in rig  # soft-base keys under a clamped base
    assert "Not shown, irrelevant to the options chosen here: base_k1, base_k3." in text
    # the default empty list shown as the actual positions of the dataset
    assert re.search(r"<td>sensors</td><td>0.1, 0.3, 0.5</td><td>m</td><td>actual positions", rig)
    assert "<td>peak_force</td><td class=\"num\">50</td><td>N</td>" in _table(text, "Excitation")
    assert "<td>rms_percent</td><td class=\"num\">1</td><td>% of channel RMS</td>" in _table(text, "Noise")
    assert "<td>highpass_hz</td><td class=\"num\">10</td><td>Hz</td>" in _table(text, "Signal chain")
    ident = _table(text, "Identifier sgd_sindy")
    assert "<td>learning_rate</td><td class=\"num\">0.001</td><td>scenario</td>" in ident
    assert "<td>epochs</td><td class=\"num\">40</td><td>scenario</td>" in ident
    # equations: one list item each, wrapping anywhere with a hanging indent
    assert '<ol class="eq"><li>eq 0: xdd0 = ...</li>' in text
    assert "white-space:pre-wrap;overflow-wrap:anywhere" in text


def test_irrelevant_keys_follow_the_options():
    from testbed.pipeline.plugins import RIGS
    from testbed.pipeline.signal_chain import SIGNAL_SCHEMAS
    from testbed.reporting.report import irrelevant_keys

    cant = RIGS.get("cantilever").rig_schema
    values = {k: f.default for k, f in cant.items()}
    assert irrelevant_keys(values | {"base": "stiff"}, cant) == {"base_k1", "base_k3"}
    assert irrelevant_keys(values | {"base": "soft"}, cant) == set()
    five = RIGS.get("fivebar").rig_schema
    values = {k: f.default for k, f in five.items()}
    assert irrelevant_keys(values, five, ("sine_replay",)) == {"dth1_0", "dth4_0"}
    assert irrelevant_keys(values, five, ("multisine",)) == set()
    sig = SIGNAL_SCHEMAS["mechanical"]
    values = {k: f.default for k, f in sig.items()}
    assert {"window", "polyorder", "cutoff_hz"} <= irrelevant_keys(values | {"derivatives": "recorded"}, sig)
    low = irrelevant_keys(values | {"derivatives": "lowpass"}, sig)
    assert "cutoff_hz" not in low and {"window", "polyorder"} <= low


def test_sweep_report_content(reports):
    text = reports["sweep"].read_text()
    assert "2/2 (100 %)" in text and "0/2 (0 %)" in text  # sindy_ls fails to run at 5 % noise
    assert "LinAlgError: singular matrix" in text
    assert "12 cells: 1 scenario(s), 2 identifier(s)" in text
    assert "<title>Study noise_study</title>" in text  # the study's name, not the file's


def test_study_report_content(reports):
    text = reports["study"].read_text()
    assert "<title>Study method_comparison</title>" in text and "results_file_name" not in text
    for sc in ("cantilever_a", "cantilever_b", "fivebar_x"):
        assert re.search(rf"<h3>Scenario {sc}</h3>\s*<table>", text)
    five = _table(text, "Scenario fivebar_x")
    assert "<th>angle_rmse [rad] (≤ 0.0501)</th>" in five
    assert "<td>1.5e-06 [1.25e-06, 1.75e-06]</td>" in five  # median [IQR] over 3 seeds at noise 0
    cant = _table(text, "Scenario cantilever_b")
    assert "<th>trac [-] (≥ 0.9)</th>" in cant
    # ls_sindy at 5 %: one cell failed to run, two ran and missed the TRAC threshold
    assert "1× failed: LinAlgError: singular matrix" in cant and "2× trac &lt; 0.9" in cant
    assert "(identify/ls.py:42)" not in cant  # the reason without its source location
    assert '<div class="grid">' in text and text.count('<figure class="wide">') == 2  # trac, freq_error
    assert "Exactly 0 in every cell that ran (not drawn): K3_norm." in text
    # thresholded scores first, structural before mechanical, then the rest
    order = re.findall(r'<img src="[^"]*" alt="([a-zA-Z0-9_]+):', text)
    assert order == ["trac", "angle_rmse", "freq_error"]


# ------------------------------------------------------------------ real headless Chromium
def run_chromium(exe: str, url: str, tmp: Path, *extra: str) -> subprocess.CompletedProcess:
    args = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
            "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-extensions",
            "--disable-default-apps", f"--user-data-dir={tmp / 'profile'}", "--enable-logging=stderr",
            "--v=0", "--virtual-time-budget=5000", *extra, url]
    return subprocess.run(args, capture_output=True, text=True, timeout=120, cwd=tmp)


# No xdist group of its own: the module's group (conftest) runs these where ``reports`` was built
# (with a "chromium" group of their own, both workers drew the reports' figures: measured on a
# cold cache, about 5 s of CPU twice).
@pytest.mark.parametrize(("name", "n_figures"), FIGURES)
def test_report_in_headless_chromium(chromium, reports, name, n_figures, tmp_path):
    html_path = reports[name]
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    shot = ARTIFACTS / f"report-{name}.png"
    shot.unlink(missing_ok=True)
    r = run_chromium(chromium, html_path.resolve().as_uri(), tmp_path, f"--screenshot={shot}",
                     "--window-size=1280,4000")
    assert r.returncode == 0, r.stderr[-2000:]
    console = [ln for ln in r.stderr.splitlines() if ":CONSOLE" in ln]
    assert not console, "console messages:\n" + "\n".join(console)
    img = mpimg.imread(shot)
    assert img.shape[:2] == (4000, 1280)
    assert img[:1500, :, :3].std() > 0.05, "the top of the page rendered blank"

    probe = tmp_path / "probe.html"
    text = html_path.read_text().replace(CSP, CSP + "; script-src 'unsafe-inline'")
    probe.write_text(text.replace("</body>", PROBE + "</body>"))
    r = run_chromium(chromium, probe.resolve().as_uri(), tmp_path, "--dump-dom")
    assert r.returncode == 0, r.stderr[-2000:]
    m = re.search(r'data-probe="([^"]*)"', r.stdout)
    assert m, "the probe did not run: " + r.stdout[:500]
    probe = json.loads(m.group(1).replace("&quot;", '"'))
    imgs, page = probe["imgs"], probe["page"]
    assert len(imgs) == n_figures
    assert all(i["ok"] and i["w"] > 300 for i in imgs), imgs
    assert page["width"] <= page["view"], f"the page scrolls sideways: {page}"
    for eq in probe["eqs"]:  # equations wrap inside their block
        assert eq["scroll"] <= eq["client"], eq
    if name == "fivebar":
        assert probe["eqs"] and probe["eqs"][0]["height"] > 60, "the long equations did not wrap"
    if name == "study":  # 4 figures, 3 summary tables: a page, not a scroll of 10,000 px
        assert page["height"] < 5000, page
    console = [ln for ln in r.stderr.splitlines() if ":CONSOLE" in ln]
    assert not console, "console messages:\n" + "\n".join(console)


def test_sweep_report_scores_are_not_wall_times():
    """Timing and bookkeeping columns of a results row are never plotted as scores."""
    from testbed.reporting.report import score_names
    from testbed.studies.results import BASE_COLUMNS, TAIL_COLUMNS

    row = {k: 1.0 for k in (*BASE_COLUMNS, *TAIL_COLUMNS)} | {"trac": 0.9, "mac": 0.99}
    assert score_names([row]) == ["mac", "trac"]


def test_the_sweep_reports_summary_shows_a_scored_failures_scores(tmp_path):
    """A cell that failed its bar with a reason keeps its scores, and the summary's medians stand
    on them (as `testbed summary`'s, `testbed.studies.statistics.scored`); a crash's are left
    out.  Round 20: `mm20_x0_20` at 0.5 % showed state_rmse "–" with "wrong equation" while the
    cell's state_rmse was 0.885 mM against the bar 0.01: the failed bar was shown nowhere."""
    checks = '[{"metric": "state_rmse", "bound": "max", "threshold": 0.01}]'
    base = {"study": "s", "scenario": "mm20_x0_20", "rig": "michaelis_menten", "noise": 0.5,
            "identifier": "sindy_pi_dynamical", "fit_time": 0.1, "checks": checks,
            "versions": '{"numpy": "2"}', "commit": "abc123", "dataset_hash": "ff" * 8}
    rows = [{**base, "cell": "c0", "seed": 0, "status": "failed", "passed": False,
             "error": "wrong equation: state_rmse 0.885 above 0.01", "state_rmse": 0.885},
            {**base, "cell": "c1", "seed": 1, "status": "failed", "passed": False,
             "error": "RuntimeError: boom (fit.py:12)", "state_rmse": 1e9}]  # a crash: not scored
    html = sweep_report(rows, tmp_path / "r", "s").read_text()
    summary = _table(html, "Scenario mm20_x0_20")
    assert re.search(r">0\.885</td>", summary) and "1e+09" not in summary


def _png(text: bytes) -> bytes:
    """A PNG's signature and one tEXt chunk (enough for the marker check: it stops at IDAT)."""
    import zlib

    chunk = b"tEXt" + text
    return (b"\x89PNG\r\n\x1a\n" + len(text).to_bytes(4, "big") + chunk
            + zlib.crc32(chunk).to_bytes(4, "big") + b"\0\0\0\0IEND\xaeB`\x82")


def test_a_marked_figure_is_not_searched_for_in_the_earlier_page(tmp_path, monkeypatch):
    # review 29a L6: every figure was read, base64-encoded and searched for in report.html,
    # marked ones too; only a figure the marker check would refuse is now
    from testbed.core.atomic import PNG_SOFTWARE
    from testbed.core.errors import InputError
    from testbed.reporting import report

    searched = []
    monkeypatch.setattr(report, "_earlier_figure", lambda p, page: searched.append(p.name) or False)
    ours, theirs = tmp_path / "fit.png", tmp_path / "photo.png"
    ours.write_bytes(_png(b"Software\0" + PNG_SOFTWARE.encode()))
    theirs.write_bytes(_png(b"Software\0my camera"))
    report.refuse_foreign_outputs(tmp_path, [ours])
    assert searched == []
    with pytest.raises(InputError, match=r"photo\.png"):
        report.refuse_foreign_outputs(tmp_path, [ours, theirs])
    assert searched == ["photo.png"]
