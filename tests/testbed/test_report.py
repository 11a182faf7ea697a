"""Reports: self-contained HTML + markdown twin, checked as text and in real headless Chromium.

The browser tests open each report offline (no network, a fresh profile), keep a
full-page screenshot under ``out/test-artifacts/``, require that the page logs no
console message at all (a report has no scripts, so any message is an error or a
blocked request), and run a probe copy of the page whose inline script records,
after load, whether every image decoded (``naturalWidth > 0``).
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import matplotlib.image as mpimg
import pytest

sys.path.insert(0, str(Path(__file__).parent))
import _synthetic_runs as synth

from testbed.reporting.figures import save_run_figures
from testbed.reporting.report import CSP, sweep_report, write_report
from testbed.studies.runstore import save_run

ROOT = Path(__file__).resolve().parents[2]
ARTIFACTS = ROOT / "out" / "test-artifacts"
PROBE = """<script>window.addEventListener("load", () => {
  const imgs = [...document.images].map(i => ({ok: i.complete && i.naturalWidth > 0, w: i.naturalWidth}));
  document.body.setAttribute("data-probe", JSON.stringify(imgs));
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
    return out


def images(html: str) -> list[str]:
    return re.findall(r'<img src="([^"]*)"', html)


@pytest.mark.parametrize(("name", "n_figures"), [("cantilever", 5), ("fivebar", 2), ("sweep", 3)])
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
    assert "Euler-Bernoulli [Hz]" in text and "total_mass = 0.6" in text
    assert "eq 0: xdd0 = ..." in text and "abababab" in text  # equations, dataset hash
    md = (reports["cantilever"].parent / "report.md").read_text()
    assert "| freq_error |" in md and "FAIL" in md
    fb = reports["fivebar"].read_text()
    assert '<span class="badge pass">PASS</span>' in fb and "angle_rmse" in fb


def test_sweep_report_content(reports):
    text = reports["sweep"].read_text()
    assert "2/2 (100 %)" in text and "0/2 (0 %)" in text  # sindy_ls fails to run at 5 % noise
    assert "LinAlgError: singular matrix" in text
    assert "12 cells: 2 identifier(s)" in text


# ------------------------------------------------------------------ real headless Chromium
def _find_chromium() -> str | None:
    for exe in ("chromium", "chromium-browser", "google-chrome"):
        if path := shutil.which(exe):
            return path
    return None


@pytest.fixture(scope="session")
def chromium() -> str:
    """Chromium, installed with apt-get when missing; skip only if it cannot be had."""
    exe = _find_chromium()
    if exe is None:
        if shutil.which("apt-get") is None or os.geteuid() != 0:
            pytest.skip("chromium missing and cannot be installed here (needs apt-get as root): "
                        "apt-get install chromium chromium-driver")
        cmd = ("apt-get update && apt-get install -y -o DPkg::Lock::Timeout=600 "
               "chromium chromium-driver")
        r = subprocess.run(cmd, shell=True, capture_output=True, text=True, timeout=1800,
                           env={**os.environ, "DEBIAN_FRONTEND": "noninteractive"})
        exe = _find_chromium()
        if exe is None:
            pytest.skip(f"apt-get could not install chromium (exit {r.returncode}): {r.stderr[-400:]}")
    return exe


def run_chromium(exe: str, url: str, tmp: Path, *extra: str) -> subprocess.CompletedProcess:
    args = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
            "--disable-component-update", "--disable-sync", "--no-first-run", "--disable-extensions",
            "--disable-default-apps", f"--user-data-dir={tmp / 'profile'}", "--enable-logging=stderr",
            "--v=0", "--virtual-time-budget=5000", *extra, url]
    return subprocess.run(args, capture_output=True, text=True, timeout=120, cwd=tmp)


@pytest.mark.xdist_group("chromium")
@pytest.mark.parametrize(("name", "n_figures"), [("cantilever", 5), ("fivebar", 2), ("sweep", 3)])
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
    imgs = json.loads(m.group(1).replace("&quot;", '"'))
    assert len(imgs) == n_figures
    assert all(i["ok"] and i["w"] > 300 for i in imgs), imgs
    console = [ln for ln in r.stderr.splitlines() if ":CONSOLE" in ln]
    assert not console, "console messages:\n" + "\n".join(console)


def test_sweep_report_scores_are_not_wall_times():
    """Timing and bookkeeping columns of a results row are never plotted as scores."""
    from testbed.reporting.report import score_names
    from testbed.studies.results import BASE_COLUMNS, TAIL_COLUMNS

    row = {k: 1.0 for k in (*BASE_COLUMNS, *TAIL_COLUMNS)} | {"trac": 0.9, "mac": 0.99}
    assert score_names([row]) == ["mac", "trac"]
