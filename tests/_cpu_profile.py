"""CPU seconds of each test, per pytest-xdist worker: where a cold ``make test`` spends its time.

Wall seconds (``--durations``) on a shared machine swing with its load; CPU seconds do not.  Opt
in with ``-p tests._cpu_profile`` and a folder in ``TESTBED_CPU_PROFILE``::

    TESTBED_CPU_PROFILE=/tmp/prof .venv/bin/python -m pytest -n 2 --dist loadgroup -q \\
        -p tests._cpu_profile
    .venv/bin/python tests/_cpu_profile.py /tmp/prof [N]

Each worker (``gw0``, ``gw1``; ``main`` without xdist) appends one JSON line per test to
``<folder>/<worker>.jsonl``: its node id, xdist group, CPU seconds (user + system of the worker
and of the children it reaped: CLI subprocesses, a sweep's loky workers once shut down,
Chromium; a server still running is not counted) and wall start and end; where Linux's
``/proc/self/schedstat`` is readable, also the worker's own seconds on a CPU (``run``) and
waiting for one (``queued``, the machine's load).  ``wall - run - queued`` is then the time the
worker slept (on a child, a sleep, a lock, I/O): a core of the run left idle unless a child used
it, which the load does not inflate as it does wall seconds.  Setup, call and
teardown are counted together, so a module fixture falls in the first test that uses it.  The
summary prints each worker's CPU and span (their difference is the imbalance of ``--dist
loadgroup``), then the N largest modules and tests.  Without ``TESTBED_CPU_PROFILE`` the plugin
records nothing.
"""

from __future__ import annotations

import collections
import json
import os
import resource
import sys
import time
from pathlib import Path

import pytest

_FOLDER = os.environ.get("TESTBED_CPU_PROFILE")
_out = []  # the open file of this process, once a test ran


def _sched_seconds() -> tuple[float, float] | None:
    """Seconds this process ran on a CPU and waited to run (``/proc/self/schedstat``), or None."""
    try:
        with open("/proc/self/schedstat") as f:
            run_ns, queued_ns, _ = f.read().split()
    except (OSError, ValueError):
        return None
    return int(run_ns) / 1e9, int(queued_ns) / 1e9


def _cpu_seconds() -> float:
    """User + system CPU seconds of this process and of its reaped children."""
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    if not _FOLDER:
        yield
        return
    if not _out:
        Path(_FOLDER).mkdir(parents=True, exist_ok=True)
        worker = os.environ.get("PYTEST_XDIST_WORKER", "main")
        _out.append(open(Path(_FOLDER) / f"{worker}.jsonl", "a"))  # open for the whole run
    cpu0, sched0, t0 = _cpu_seconds(), _sched_seconds(), time.time()
    yield
    cpu1, sched1, t1 = _cpu_seconds(), _sched_seconds(), time.time()
    mark = item.get_closest_marker("xdist_group")
    row = {"id": item.nodeid, "group": mark.args[0] if mark and mark.args else None,
           "cpu": cpu1 - cpu0, "t0": t0, "t1": t1, "pid": os.getpid()}
    if sched0 is not None and sched1 is not None:
        row.update(run=sched1[0] - sched0[0], queued=sched1[1] - sched0[1])
    _out[0].write(json.dumps(row) + "\n")
    _out[0].flush()


def summary(folder: Path, n: int = 30) -> str:
    """The text summary of the records in ``folder`` (see the module's docstring)."""
    rows = []
    for f in sorted(folder.glob("*.jsonl")):
        rows += [{**json.loads(line), "worker": f.stem} for line in f.read_text().splitlines() if line]
    if not rows:
        return f"no records in {folder}"
    lines = [f"{len(rows)} tests, {sum(r['cpu'] for r in rows):.1f} s of CPU in the tests"]
    for worker in sorted({r["worker"] for r in rows}):
        mine = [r for r in rows if r["worker"] == worker]
        lines.append(f"{worker}: {sum(r['cpu'] for r in mine):.1f} s of CPU, span "
                     f"{max(r['t1'] for r in mine) - min(r['t0'] for r in mine):.1f} s wall")
    modules = collections.Counter()
    for r in rows:
        modules[r["id"].split("::")[0]] += r["cpu"]
    lines.append(f"--- the {n} largest modules [CPU s]")
    lines += [f"{cpu:7.1f}  {name}" for name, cpu in modules.most_common(n)]
    lines.append(f"--- the {n} largest tests [CPU s]")
    lines += [f"{r['cpu']:7.1f}  {r['worker']}  {r['id'].split('@')[0]}"
              for r in sorted(rows, key=lambda r: -r["cpu"])[:n]]
    return "\n".join(lines)


if __name__ == "__main__":
    print(summary(Path(sys.argv[1]), int(sys.argv[2]) if len(sys.argv) > 2 else 30))
