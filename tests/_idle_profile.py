"""When each pytest-xdist worker of a running test session left its core idle: a sampler.

Wall seconds on a shared machine swing with its load, and a worker that sleeps (a fixed sleep,
a timeout, a poll, a wait for a child that waits itself) is not told apart by CPU seconds from a
worker whose children run.  This script watches a pytest process from outside: every ``dt``
seconds it reads, for each worker (a child of the pytest process), the states of every thread of
the worker and of its descendants (``/proc/<pid>/task/<tid>/stat``, ``.../children``).  A
sample in which none of them is running or waiting to run (state ``R``) is *idle*: on a quiet
machine that worker's core had nothing to do then.  A fixed sleep counts the same at any load;
so does an I/O wait (state ``D``).  Idle samples are written as one JSON line per worker::

    {"pid": 1234, "dt": 0.05, "idle": [t, ...], "busy": n}

Usage (Linux; next to ``-p tests._cpu_profile``, whose per-test wall start and end say in
which test each idle sample fell)::

    python tests/_idle_profile.py PYTEST_PID OUT.jsonl [DT]

It ends when the pytest process ends.  Workers are named by process id (the rows of
``tests._cpu_profile`` carry their worker's ``pid``); a process whose parent died (re-parented
to init) is no longer seen.
"""

from __future__ import annotations

import json
import os
import sys
import time


def _children(pid: int) -> list[int]:
    out = []
    try:
        for tid in os.listdir(f"/proc/{pid}/task"):
            with open(f"/proc/{pid}/task/{tid}/children") as f:
                out += [int(c) for c in f.read().split()]
    except OSError:
        pass
    return out


def _any_running(pid: int) -> bool:
    """Whether a thread of ``pid`` or of a descendant is running or runnable."""
    stack = [pid]
    while stack:
        p = stack.pop()
        try:
            for tid in os.listdir(f"/proc/{p}/task"):
                with open(f"/proc/{p}/task/{tid}/stat") as f:
                    if f.read().rsplit(")", 1)[1].split()[0] == "R":
                        return True
        except (OSError, IndexError):
            continue
        stack += _children(p)
    return False


def watch(pytest_pid: int, out_path: str, dt: float = 0.05) -> None:
    """Sample until ``pytest_pid`` ends; write the idle sample times of each worker."""
    idle: dict[int, list[float]] = {}
    busy: dict[int, int] = {}
    while os.path.exists(f"/proc/{pytest_pid}"):
        now = time.time()
        for w in _children(pytest_pid):
            if w not in idle:
                idle[w], busy[w] = [], 0
            if _any_running(w):
                busy[w] += 1
            else:
                idle[w].append(round(now, 3))
        time.sleep(dt)
    with open(out_path, "w") as f:
        for w in idle:
            f.write(json.dumps({"pid": w, "dt": dt, "idle": idle[w], "busy": busy[w]}) + "\n")


if __name__ == "__main__":
    watch(int(sys.argv[1]), sys.argv[2], float(sys.argv[3]) if len(sys.argv) > 3 else 0.05)
