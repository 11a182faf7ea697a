"""Honest timing for the benchmarks: one BLAS thread, interleaved repeats, medians and spread.

- BLAS threads are pinned with ``threadpoolctl.threadpool_limits(1)`` around every timed call
  (environment variables only work if set before numpy is first imported, which a benchmark
  run through ``python -m benchmarks`` cannot guarantee).
- No tracer runs inside a timed region: memory is measured in a separate pass
  (:func:`peak_memory`); tracemalloc slows numpy-heavy code unevenly (measured: pysindy 3.2x,
  ours 1.4x), so a ratio timed under it is wrong.
- Contenders are timed interleaved (A B A B ...), so that load changes on a shared machine hit
  both alike; the median and the spread (min-max) of each are reported.
"""

from __future__ import annotations

import os
import platform
import time
import tracemalloc
from collections.abc import Callable

import numpy as np
from threadpoolctl import threadpool_limits


def interleaved(fns: dict[str, Callable[[], object]], repeats: int, warmup: bool = True
                ) -> dict[str, np.ndarray]:
    """Wall times [s] of each callable, ``repeats`` rounds, one call of each per round.

    Parameters
    ----------
    fns : dict of name -> callable
        The contenders (called without arguments).
    repeats : int
        Rounds.
    warmup : bool
        One untimed call of each first (compilation, caches, lazy imports).

    Returns
    -------
    dict of name -> ndarray, shape (repeats,)
    """
    out: dict[str, list[float]] = {k: [] for k in fns}
    with threadpool_limits(1):
        if warmup:
            for f in fns.values():
                f()
        for _ in range(repeats):
            for k, f in fns.items():
                t0 = time.perf_counter()
                f()
                out[k].append(time.perf_counter() - t0)
    return {k: np.asarray(v) for k, v in out.items()}


def timed_once(fn: Callable[[], object]) -> tuple[float, object]:
    """Wall time [s] and result of one call, BLAS pinned to one thread."""
    with threadpool_limits(1):
        t0 = time.perf_counter()
        out = fn()
        return time.perf_counter() - t0, out


def spread(t: np.ndarray, scale: float = 1.0, fmt: str = ".3g") -> str:
    """``median (min-max, n=k)`` of times scaled by ``scale``."""
    t = np.asarray(t) * scale
    return f"median {np.median(t):{fmt}} (min {t.min():{fmt}}, max {t.max():{fmt}}, n={t.size})"


def ratio_spread(a: np.ndarray, b: np.ndarray) -> tuple[float, str]:
    """Median of the per-round ratios a/b (interleaved rounds) and their range."""
    r = np.asarray(a) / np.asarray(b)
    return float(np.median(r)), (f"per-round ratio median {np.median(r):.3g} "
                                 f"(min {r.min():.3g}, max {r.max():.3g})")


def peak_memory(fn: Callable[[], object]) -> int:
    """tracemalloc peak [bytes] of one untimed call (numpy allocations; C libraries' own
    allocations are not traced)."""
    tracemalloc.start()
    try:
        fn()
        return int(tracemalloc.get_traced_memory()[1])
    finally:
        tracemalloc.stop()


def machine() -> str:
    """Machine, CPU count and load averages (1, 5, 15 min) now."""
    load = os.getloadavg()
    return (f"{platform.machine()}, {os.cpu_count()} CPUs, Python {platform.python_version()}, "
            f"load average {load[0]:.2f} / {load[1]:.2f} / {load[2]:.2f}")
