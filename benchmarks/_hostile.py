"""The malformed-input drivers' one harness (``benchmarks/hostile7.py``, ``hostile8.py``,
``hostile9.py``): each case runs in-process under a time limit and ends ``ok`` or as a finding.

``ok`` is a result the driver's ``check`` finds nothing wrong in, or a
:class:`~testbed.core.errors.TestbedError` in one line (the user's mistake, refused); a hang, a
two-line or overlong error and every other exception are findings.
"""

from __future__ import annotations

import contextlib
import io
import os
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
#: The environment of the commands the rounds start: one BLAS thread, no server, no screen.
ENV = {**os.environ, "PYTHONPATH": os.environ.get("PYTHONPATH") or str(ROOT), "OMP_NUM_THREADS": "1",
       "OPENBLAS_NUM_THREADS": "1", "TESTBED_NO_SERVER": "1", "MPLBACKEND": "Agg"}


def results_row(**change: Any) -> dict:
    """One results row of a finished ``michaelis_menten`` cell (the hostile rounds' and their
    tests' fixture), with ``change`` applied."""
    row = {"study": "s", "cell": "c1", "scenario": "michaelis_menten", "rig": "michaelis_menten",
           "noise": 0.0, "seed": 0, "identifier": "sindy_pi_dynamical", "params": "{}",
           "status": "ok", "error": "", "fit_time": 0.1, "data_time": 0.1, "cell_time": 0.2,
           "passed": True, "coef_error": 0.01, "checks": "[]", "versions": "{}", "commit": "x",
           "dataset_hash": "h"}
    row.update(change)
    return row


def testbed_cli(argv: list[str], cwd: Path, timeout: float) -> subprocess.CompletedProcess:
    """``python -m testbed.cli argv`` in ``cwd`` with :data:`ENV`, its output captured."""
    return subprocess.run([sys.executable, "-m", "testbed.cli", *argv], cwd=cwd, env=ENV,
                          capture_output=True, text=True, timeout=timeout)


def cli_finding(p: subprocess.CompletedProcess) -> str | None:
    """An internal error, a traceback, or a refusal in more than one error line of a finished
    command (rounds 12 on), else None."""
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    if "Traceback" in p.stderr or "internal error" in p.stderr or p.returncode not in (0, 1, 2):
        return f"status {p.returncode}: {lines[-1][:200] if lines else ''}"
    if p.returncode == 2 and len([ln for ln in lines if ln.startswith("error")]) != 1:
        return f"refused in {len(lines)} lines: {p.stderr[:200]!r}"
    return None

#: A refusal longer than this many characters is a finding: a user reads one line.
MAX_LINE_CHARS = 6000
#: A case slower than this [s] is printed to stderr (not a finding: the time limit is).
SLOW_S = 20.0


class Hang(Exception):
    """A case ran past its time limit."""


def _alarm(signum: int, frame: Any) -> None:
    raise Hang


def classify(fn: Callable[[], Any], timeout_s: int,
             check: Callable[[Any], str | None] = lambda result: None) -> str:
    """``"ok"`` or a finding's description for the case ``fn`` (its result given to ``check``,
    which returns a finding or None)."""
    from testbed.core.errors import TestbedError

    signal.signal(signal.SIGALRM, _alarm)
    signal.alarm(timeout_s)
    t0 = time.perf_counter()
    try:
        return check(fn()) or "ok"
    except Hang:
        return f"hang > {timeout_s} s"
    except TestbedError as e:
        text = str(e)
        if "\n" in text:
            return f"two lines: {text[:200]!r}"
        if len(text) > MAX_LINE_CHARS:
            return f"line of {len(text)} chars"
        return "ok"
    except BaseException as e:  # every other exception is a finding (GeneratorExit from a
        # plugin too: round 19's old code let it end the round), but the user's Ctrl-C
        if isinstance(e, KeyboardInterrupt):
            raise
        return f"{type(e).__name__}: {str(e)[:200]}"
    finally:
        signal.alarm(0)
        dt = time.perf_counter() - t0
        if dt > SLOW_S:
            print(f"  (slow case: {dt:.1f} s)", file=sys.stderr)


def scored_finding(result: Any) -> str | None:
    """What is wrong with a scenario run's verdict, or None: a pass with a NaN score or a
    failure, or NaN scores without a failure naming why (NaN only: an infinite error, a true
    coefficient of 1e-300 missed, fails every bar on it)."""
    import math

    nan = sorted(k for k, v in result.scores.values.items() if isinstance(v, float) and math.isnan(v))
    failures = result.scores.failures
    if result.passed and (nan or failures):
        return f"passed with NaN scores {nan} or failures {sorted(failures)}"
    if nan and not failures:
        return f"NaN scores without a failure naming why: {nan[:4]}"
    return None


def run_inprocess(cases: Iterable[tuple[str, Callable[[], Any]]], timeout_s: int,
                  check: Callable[[Any], str | None] = lambda result: None) -> Counter:
    """Classify every ``(name, fn)`` case; print each finding; count cases and findings."""
    counts: Counter = Counter()
    for name, fn in cases:
        verdict = classify(fn, timeout_s, check)
        counts["cases"] += 1
        if verdict != "ok":
            counts["findings"] += 1
            print(f"FINDING {name}: {verdict}", flush=True)
    return counts


def subfolder(work: Path, sub: str) -> Path:
    """``work / sub``, made if missing: a family's own scratch folder."""
    d = work / sub
    d.mkdir(exist_ok=True)
    return d


def families(makers: dict[str, Callable[[Path], Iterable[tuple[str, Callable[[], Any]]]]],
             timeout_s: int) -> dict[str, Callable[[Path], Counter]]:
    """A round's families for :func:`main`: each maker given its own :func:`subfolder` of the
    work folder (named as the family) and its cases run by :func:`run_inprocess`, each case
    returning a finding's description or None (a verdict, or refused in one line)."""
    def family(name: str, make: Callable[[Path], Any]) -> Callable[[Path], Counter]:
        return lambda work: run_inprocess(make(subfolder(work, name)), timeout_s, lambda f: f)
    return {name: family(name, make) for name, make in makers.items()}


def main(argv: list[str], families: dict[str, Callable[[Path], Counter]], prefix: str) -> int:
    """Run the named families (all when ``argv`` is empty) in one temporary folder; print each
    family's count and the total; status 1 when anything was found."""
    total: Counter = Counter()
    with tempfile.TemporaryDirectory(prefix=prefix) as tmp:
        for fam in argv or list(families):
            if fam not in families:
                raise SystemExit(f"unknown family {fam!r}; known: {', '.join(families)}")
            t0 = time.perf_counter()
            c = families[fam](Path(tmp))
            print(f"{fam}: {c['cases']} cases, {c['findings']} findings "
                  f"({time.perf_counter() - t0:.0f} s)", flush=True)
            total += c
    print(f"total: {total['cases']} cases, {total['findings']} findings")
    return 1 if total["findings"] else 0


def base_scenario(bases: dict[str, tuple[str, float]], kind: str) -> tuple[str, dict]:
    """The shipped scenario a round starts a rig ``kind``'s cases from (``bases[kind]``: its
    name and the record's duration [s]), as a raw table: no ``extends``, no ``[score]`` (the
    bars were set for the base's identifier)."""
    from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml

    base, cut = bases[kind]
    raw = _read_toml(SCENARIO_DIR / f"{base}.toml")
    raw["scenario"].pop("extends", None)
    raw["simulation"]["duration"] = cut
    raw.pop("score", None)
    return base, raw


def cli_inprocess(argv: list[str]) -> tuple[int, str, str]:
    """``testbed argv`` in this process: (status, stdout, stderr)."""
    from testbed import cli

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = cli.main(argv)
        except SystemExit as e:  # argparse's own refusal
            status = e.code if isinstance(e.code, int) else 2
    return status, out.getvalue(), err.getvalue()


def judged(status: int, out: str, err: str, refuse: bool = False,
           warnings: bool = False) -> str | None:
    """A finding of a finished in-process command (:func:`cli_inprocess`), or None.

    A status other than 0 / 1 / 2, a traceback or an internal error; a refusal (status 2) in
    more than one line; with ``refuse``, anything but a refusal (the input is the user's
    mistake); with ``warnings``, a warning printed beside a result (round 17's rule)."""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    if status not in (0, 1, 2) or "Traceback" in err or "internal error" in err:
        return f"status {status}: {(lines or [''])[-1][:200]}"
    if status == 2 and len(lines) != 1:
        return f"refused in {len(lines)} lines: {err[:200]!r}"
    if warnings and status != 2 and lines and any("Warning" in ln for ln in lines):
        return f"status {status} with a warning: {lines[0][:200]!r}"
    if refuse and status != 2:
        return f"accepted with status {status}: {(out.strip().splitlines() or [''])[-1][:160]!r}"
    return None
