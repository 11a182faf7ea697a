"""The idle sampler of a test run (tests/_idle_profile.py): a sleeping process tree is idle."""

import os
import subprocess
import sys
import time

import pytest

from tests import _idle_profile

pytestmark = pytest.mark.skipif(not os.path.exists("/proc/self/task"), reason="Linux /proc only")


def test_a_sleeping_tree_is_idle_and_a_running_one_is_not():
    # a shell waiting on its sleeping child: nothing of the tree runs
    p = subprocess.Popen(["sh", "-c", "sleep 30; true"])
    try:
        deadline = time.monotonic() + 10
        while not _idle_profile._children(p.pid) and time.monotonic() < deadline:
            time.sleep(0.01)
        assert _idle_profile._children(p.pid), "the shell's child was not seen"
        # (the shell may still run for an instant after its fork, before it waits)
        while _idle_profile._any_running(p.pid):
            assert time.monotonic() < deadline, "the sleeping tree was never idle"
            time.sleep(0.01)
    finally:
        p.kill()
        p.wait()
    # this process runs while it asks (its own thread is in state R)
    assert _idle_profile._any_running(os.getpid())


def test_the_samples_are_written_per_worker(tmp_path):
    # the watched process ends at once: one line per child seen (none here), and the file exists
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    out = tmp_path / "idle.jsonl"
    _idle_profile.watch(p.pid, str(out), 0.01)
    assert out.read_text() == ""
