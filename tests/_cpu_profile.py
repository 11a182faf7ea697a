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

By kind: each row also holds ``kinds``, this process's CPU seconds inside a test split by what
ran (:data:`KINDS`): a rig's simulation (:func:`testbed.pipeline.generate.simulate_clean`), an
identifier's fit (its outermost guarded ``fit``), a numba compile (numba's ``numba:compile``
events, the outermost of a nest) and a figure saved (``Figure.savefig``); a kind timed inside
another takes its own share (a simulation inside a fit is simulation, a kernel compiled in a fit
is compile), so the kinds and the rest add up to ``cpu`` less the children's share.  And
``work``: one ``[kind, key, seconds]`` for each fit and simulation, its key the identifier's class,
hyperparameters and measured arrays (a hash), or the scenario's ``repr`` (a hash): a key seen
twice in a run is the same work done twice (:func:`repeated`).  Children (CLI processes, a
sweep's loky workers) are counted only in ``cpu``, when reaped.
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
#: The kinds of work timed inside a test (see the module's docstring).
KINDS = ("simulation", "fit", "compile", "savefig")
_stack: list[list] = []  # [kind, process CPU at its start, CPU of the kinds timed inside it]
_kinds: dict[str, float] = {}  # this test's CPU seconds by kind
_work: list[list] = []  # this test's [kind, key, seconds] of each fit and simulation


def _enter(kind: str) -> None:
    _stack.append([kind, time.process_time(), 0.0])


def _leave(key: str | None = None) -> None:
    """End the innermost timed kind: its own share to :data:`_kinds`, its whole time to the kind
    around it (which does not count it again); a keyed piece of work to :data:`_work`."""
    kind, start, inner = _stack.pop()
    total = time.process_time() - start
    _kinds[kind] = _kinds.get(kind, 0.0) + total - inner
    if _stack:
        _stack[-1][2] += total
    if key is not None:
        _work.append([kind, key, round(total, 4)])


def _timed(kind: str, f, key=None):
    """``f`` timed as ``kind`` (keyed by ``key(*args, **kwargs)`` where given)."""
    import functools

    @functools.wraps(f)
    def timed(*a, **kw):
        _enter(kind)
        try:
            return f(*a, **kw)
        finally:
            _leave(key(*a, **kw) if key is not None else None)
    return timed


def _digest(*parts) -> str:
    import hashlib

    import numpy as np

    h = hashlib.blake2b(digest_size=6)
    for part in parts:
        h.update(np.ascontiguousarray(part).tobytes() if isinstance(part, np.ndarray)
                 else repr(part).encode())
    return h.hexdigest()


def _fit_key(model, a) -> str:
    """The identifier's class, hyperparameters and measured arrays, hashed."""
    data = a[0] if a else None
    try:
        params = sorted(model.get_params().items())
    except Exception:  # a plugin's broken get_params is its test's to find
        params = None
    arrays = [getattr(data, n, None) for n in ("x", "xd", "xdd", "u")]
    return f"{type(model).__name__}:{_digest(params, *arrays)}"


def _install_kinds() -> None:
    """Time the kinds of :data:`KINDS` in this process (the plugin is imported before any test
    module, so before ``identify`` defines its identifiers: :func:`identify._base._guard_fit`
    wraps each one's ``fit`` when its class is made; those made already are wrapped again)."""
    import matplotlib.figure

    import identify._base as base
    import testbed.pipeline.cache as cache
    import testbed.pipeline.generate as generate

    guard = base._guard_fit

    def timed_guard(fit):
        guarded = guard(fit)

        def outermost_timed(self, *a, **kw):
            if any(entry[0] == "fit" for entry in _stack):
                return guarded(self, *a, **kw)
            _enter("fit")
            try:
                return guarded(self, *a, **kw)
            finally:
                _leave(_fit_key(self, a))
        outermost_timed.__wrapped__ = fit
        outermost_timed._api_guard = True
        return outermost_timed

    base._guard_fit = timed_guard
    made = [base.Identifier]
    while made:
        cls = made.pop()
        made += cls.__subclasses__()
        own = cls.__dict__.get("fit")
        if getattr(own, "_api_guard", False) and hasattr(own, "__wrapped__"):
            cls.fit = timed_guard(own.__wrapped__)
    simulate = _timed("simulation", generate.simulate_clean,
                      lambda sc, *a, **kw: f"{getattr(sc, 'name', '?')}:{_digest(sc)}")
    generate.simulate_clean = cache.simulate_clean = simulate  # cache.py imported it by name
    matplotlib.figure.Figure.savefig = _timed("savefig", matplotlib.figure.Figure.savefig)
    try:
        from numba.core import event
    except ImportError:
        return

    class Compiles(event.Listener):
        def on_start(self, ev):
            _enter("compile")

        def on_end(self, ev):
            _leave()

    event.register("numba:compile", Compiles())


if _FOLDER:
    _install_kinds()


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
    _kinds.clear()
    _work.clear()
    cpu0, sched0, t0 = _cpu_seconds(), _sched_seconds(), time.time()
    yield
    cpu1, sched1, t1 = _cpu_seconds(), _sched_seconds(), time.time()
    mark = item.get_closest_marker("xdist_group")
    row = {"id": item.nodeid, "group": mark.args[0] if mark and mark.args else None,
           "cpu": cpu1 - cpu0, "t0": t0, "t1": t1, "pid": os.getpid(),
           "kinds": {k: round(v, 4) for k, v in _kinds.items()}, "work": list(_work)}
    if sched0 is not None and sched1 is not None:
        row.update(run=sched1[0] - sched0[0], queued=sched1[1] - sched0[1])
    _out[0].write(json.dumps(row) + "\n")
    _out[0].flush()


def repeated(rows: list[dict]) -> list[tuple[float, str, str, int, list[str]]]:
    """Work done more than once in a run: ``(seconds of the repeats, kind, key, calls, test
    ids)`` for each fit or simulation key recorded by more than one call, most seconds first
    (the first call is the one needed)."""
    seen: dict[tuple[str, str], list[tuple[str, float]]] = collections.defaultdict(list)
    for r in rows:
        for kind, key, seconds in r.get("work", ()):
            seen[kind, key].append((r["id"].split("@")[0], seconds))
    out = [(sum(s for _, s in calls[1:]), kind, key, len(calls), sorted({i for i, _ in calls}))
           for (kind, key), calls in seen.items() if len(calls) > 1]
    return sorted(out, key=lambda x: -x[0])


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
    kinds = collections.Counter()
    for r in rows:
        kinds.update(r.get("kinds", {}))
    if kinds:
        lines.append("by kind: " + ", ".join(f"{k} {kinds[k]:.1f} s" for k in KINDS) +
                     f", the rest {sum(r['cpu'] for r in rows) - sum(kinds.values()):.1f} s "
                     "(children reaped, scoring, I/O, imports ...)")
    twice = repeated(rows)
    if twice:
        lines.append(f"--- work done more than once: {sum(t[0] for t in twice):.1f} s [CPU s]")
        lines += [f"{s:7.1f}  {kind} {key} x{calls}: {', '.join(ids[:3])}"
                  for s, kind, key, calls, ids in twice[:n]]
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
