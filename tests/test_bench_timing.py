"""The benchmarks' timing helper (benchmarks/_timing.py): interleaved rounds, one BLAS thread
inside the timed calls, medians of per-round ratios, memory outside the timed region."""

import numpy as np
from threadpoolctl import threadpool_info

from benchmarks import _timing


def test_interleaved_rounds_and_one_blas_thread():
    calls, threads = [], []

    def a():
        calls.append("a")
        threads.append(max((i["num_threads"] for i in threadpool_info()), default=1))

    def b():
        calls.append("b")

    t = _timing.interleaved({"a": a, "b": b}, 3)
    assert calls == ["a", "b"] * 4  # one warm-up round, then a b a b a b
    assert set(t) == {"a", "b"} and all(v.shape == (3,) and np.all(v >= 0) for v in t.values())
    assert set(threads) == {1}


def test_ratio_and_spread():
    r, note = _timing.ratio_spread(np.array([2.0, 4.0, 9.0]), np.array([1.0, 1.0, 3.0]))
    assert r == 3.0 and "min 2" in note and "max 4" in note
    assert _timing.spread(np.array([1.0, 3.0, 2.0])).startswith("median 2")


def test_peak_memory_is_measured_apart():
    assert _timing.peak_memory(lambda: np.ones(1_000_000)) >= 8_000_000
    assert "load average" in _timing.machine()
