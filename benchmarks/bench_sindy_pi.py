"""Our shared-Gram SINDy-PI vs pysindy 2.1.0's SINDyPI (plain and QR form) on identical
library matrices of ~20, 50 and 97 columns at 10k and 100k samples.

Problem: the forced damped double pendulum of ``benchmarks/sindy_pi_problems.py`` (exact
signals), libraries = the 12 true terms followed by the other columns of the 97-column
``generic_mechanical_library(2, 2)`` in library order.  Timed: from the library matrix to the
selected equations (ours: Gram matrices + sweep + selection; pysindy: its optimiser on the
training rows, or on their R factor, + the same selection); the library build is reported
apart.  BLAS pinned to one thread, medians over repeats, everything in one run.  pysindy cells
expected to exceed ~60 s are skipped and extrapolated (noted).  Peak memory: tracemalloc peak
of the timed call (numpy allocations; OSQP's C allocations are not traced).

Run: ``OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_sindy_pi.py``
"""

from __future__ import annotations

import os

for _v in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_v] = "1"

import importlib.util  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import tracemalloc  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from identify._implicit import DEFAULT_THRESHOLDS, grams, select_models, split_index, stlsq_sweep  # noqa: E402
from identify.library import Library, generic_mechanical_library  # noqa: E402
from identify.pysindy_pi import PySINDyPI  # noqa: E402
from testbed.core.errors import IdentificationError  # noqa: E402

_spec = importlib.util.spec_from_file_location("sindy_pi_problems", Path(__file__).with_name(
    "sindy_pi_problems.py"))
P = importlib.util.module_from_spec(_spec)
sys.modules["sindy_pi_problems"] = P
_spec.loader.exec_module(P)

SIZES = (20, 50, 97)
SAMPLES = (10_000, 100_000)
BUDGET_S = 60.0          # skip a pysindy cell predicted to take longer than this
TARGET_SPEEDUP = 300.0   # at ~50 columns, vs plain pysindy SINDyPI


def _library(truth: list[str], p: int) -> Library:
    full = generic_mechanical_library(2, 2).names
    return Library(truth + [n for n in full if n not in truth][:p - len(truth)], 2, 2)


def _ours(Theta: np.ndarray, lib: Library) -> np.ndarray:
    n_tr = split_index(Theta.shape[0], 0.2)
    G_tr, G_v = grams(Theta, n_tr)
    sw = stlsq_sweep(G_tr, G_v, np.arange(len(lib)), DEFAULT_THRESHOLDS)
    picks = select_models(sw, [lib.input_columns(k) for k in range(2)])
    return np.array([sw.coef(*p[0]) for p in picks])


def _theirs(Theta: np.ndarray, lib: Library, qr: bool, normalize: bool) -> np.ndarray:
    n_tr = split_index(Theta.shape[0], 0.2)
    G_tr, G_v = grams(Theta, n_tr)
    est = PySINDyPI(library=lib, qr=qr, normalize=normalize, prune_tol=None)
    sw = est._sweep(G_tr, G_v, np.arange(len(lib)), Theta[:n_tr])
    picks = select_models(sw, [lib.input_columns(k) for k in range(2)])
    return np.array([sw.coef(*p[0]) for p in picks])


def _timed(fn, repeats: int):
    times, out, peak = [], None, 0
    for _ in range(repeats):
        tracemalloc.start()
        t0 = time.perf_counter()
        try:
            out = fn()
        except IdentificationError as exc:  # reported, with the time it took to fail
            out = exc
        times.append(time.perf_counter() - t0)
        peak = max(peak, tracemalloc.get_traced_memory()[1])
        tracemalloc.stop()
    return float(np.median(times)), out, peak


def _row(name, value, unit, target=None, ok=None, note=""):
    return {"name": name, "value": value, "unit": unit, "target": target, "ok": ok, "note": note}


def run(sizes=SIZES, samples=SAMPLES, budget_s: float = BUDGET_S) -> list[dict]:
    """All benchmark rows (name, value, unit, target, ok, note)."""
    rows: list[dict] = []
    plain: dict[tuple[int, int], float] = {}
    for N in samples:
        pr = P.double_pendulum(duration=N / 1e4 if N >= 100_000 else N / 1e3,
                               fs=1e4 if N >= 100_000 else 1e3, amp=10.0)
        d = pr.data
        for p in sizes:
            lib = _library(pr.truth_terms, p)
            t0 = time.perf_counter()
            Theta = lib.evaluate(d.x[:, :N], d.xd[:, :N], d.xdd[:, :N], d.u[:, :N])
            t_lib = time.perf_counter() - t0
            cell = f"{N // 1000}k x {p}"
            mb = Theta.nbytes / 2**20
            rows.append(_row(f"library build {cell}", t_lib, "s", note=f"matrix {mb:.0f} MiB"))
            t_o, c_o, m_o = _timed(lambda T=Theta, L=lib: _ours(T, L), 5)
            f1_o, e_o = P.aligned_errors(lib.names, c_o, pr.truth_terms, pr.truth_coef)
            rows.append(_row(f"ours {cell}", t_o, "s", note=f"F1 {f1_o:.3f}, coef err {e_o:.2e}, "
                             f"peak {m_o / 2**20:.0f} MiB"))
            variants = [("pysindy QR", True, True), ("pysindy plain", False, True),
                        ("pysindy QR raw", True, False)]
            if (N, p) == (samples[0], sizes[0]):
                variants.append(("pysindy plain raw", False, False))
            for tag, qr, norm in variants:
                pred = _predict(plain, N, p) if tag == "pysindy plain" else None
                if pred is not None and pred > budget_s:
                    rows.append(_row(f"{tag} {cell}", pred, "s", note=f"skipped: extrapolated "
                                     f"{pred:.0f} s > {budget_s:.0f} s budget; speedup ~{pred / t_o:.0f}x"))
                    continue
                t_t, c_t, m_t = _timed(lambda qr=qr, nm=norm, T=Theta, L=lib: _theirs(T, L, qr, nm),
                                       1 if tag.startswith("pysindy plain") else 3)
                if tag == "pysindy plain":
                    plain[(N, p)] = t_t
                speed = t_t / t_o
                target = TARGET_SPEEDUP if (tag == "pysindy plain" and p == 50) else None
                if isinstance(c_t, IdentificationError):
                    rows.append(_row(f"{tag} {cell}", t_t, "s", note=f"FAILED: {str(c_t)[:140]}"))
                    rows.append(_row(f"speedup vs {tag} {cell}", speed, "x", target,
                                     None if target is None else bool(speed >= target),
                                     "pysindy produced no model"))
                    continue
                f1_t, e_t = P.aligned_errors(lib.names, c_t, pr.truth_terms, pr.truth_coef)
                better = f1_o >= f1_t and e_o <= e_t
                rows.append(_row(f"{tag} {cell}", t_t, "s", note=(
                    f"F1 {f1_t:.3f}, coef err {e_t:.2e}, peak {m_t / 2**20:.0f} MiB; "
                    f"{'one run' if tag.startswith('pysindy plain') else 'median of 3'}")))
                rows.append(_row(f"speedup vs {tag} {cell}", speed, "x", target,
                                 None if target is None else bool(speed >= target and better),
                                 "ours equal or better F1 and coef error" if better
                                 else "ours WORSE on F1 or coefficient error"))
    return rows


def _predict(plain: dict[tuple[int, int], float], N: int, p: int) -> float | None:
    """Extrapolate a plain-pysindy time from measured cells: power law in p, linear in N."""
    same_n = sorted((q, t) for (n, q), t in plain.items() if n == N)
    if len(same_n) >= 2:
        (p1, t1), (p2, t2) = same_n[-2:]
        return t2 * (p / p2) ** (np.log(t2 / t1) / np.log(p2 / p1))
    small = [(n, t) for (n, q), t in plain.items() if q == p and n < N]
    if small:
        n0, t0 = max(small)
        return t0 * N / n0
    ref = [(n, q, t) for (n, q), t in plain.items() if q < p]
    if ref:
        n0, q0, t0 = max(ref)
        return t0 * (N / n0) * (p / q0) ** 2
    return None


if __name__ == "__main__":
    for r in run():
        flag = "" if r["ok"] is None else (" OK" if r["ok"] else " FAIL")
        tgt = "" if r["target"] is None else f" (target >= {r['target']:g})"
        print(f"{r['name']:<34} {r['value']:>11.4g} {r['unit']:<2}{tgt}{flag}  {r['note']}")
