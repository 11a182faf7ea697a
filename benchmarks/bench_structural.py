"""Simulating an identified cubic structural model: the compiled RK4 against a numpy loop.

The scorer simulates every identified cubic model over its record
(``M x'' + C x' + K x + K3 x^3 = B u``, :func:`identify._structural_sim.simulate_structural`,
classical RK4 at sub-steps of the sample interval, compiled with numba).  The peer is the same
RK4 written as a numpy loop here (the form it replaced: one vectorised right-hand side per
stage), run over the same model, start, force, step and sub-steps, so both do the same
arithmetic; their states must agree to round-off.

The model is the one ``sgd_sindy`` identifies on ``cantilever_soft_impact`` (its cubic terms
kept), simulated from the measured start of the scored window, as the scorer does, over its
first ``WINDOW`` samples (the numpy loop takes about 25 s for the whole window; the ratio is per
step, so a shorter window measures the same).

All timings: BLAS pinned to one thread, contenders interleaved, medians with spread
(:mod:`benchmarks._timing`).

Run: ``.venv/bin/python -m benchmarks bench_structural``.
"""

from __future__ import annotations

import numpy as np

from benchmarks._timing import interleaved, machine, ratio_spread, spread

REPEATS = 5
WINDOW = 4000  # samples (0.31 s at 12.8 kHz)


def numpy_rk4(A: np.ndarray, MK3: np.ndarray, MF: np.ndarray, z0: np.ndarray, h: float,
               sub: int, n_t: int) -> np.ndarray:
    """The peer: classical RK4 of ``z' = A z + [0; MF[:, k-1] - MK3 x^3]``, a numpy call per
    stage (the Python loop the compiled one replaced; ``tests/identify/test_structural_sim.py``
    checks the compiled loop against it); returns Z, shape (2n, n_t)."""
    n = MK3.shape[0]

    def rhs(z: np.ndarray, f: np.ndarray) -> np.ndarray:
        d = A @ z
        d[n:] += f - MK3 @ z[:n] ** 3
        return d

    Z = np.empty((2 * n, n_t))
    z = z0.copy()
    Z[:, 0] = z
    for k in range(1, n_t):
        f = MF[:, k - 1]
        for _ in range(sub):
            k1 = rhs(z, f)
            k2 = rhs(z + 0.5 * h * k1, f)
            k3 = rhs(z + 0.5 * h * k2, f)
            k4 = rhs(z + h * k3, f)
            z = z + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        Z[:, k] = z
    return Z


def run() -> list[dict]:
    from identify import _compiled as cc
    from identify._structural_sim import pole_radius, state_matrix
    from testbed.pipeline.cache import DatasetCache
    from testbed.pipeline.scenario import load_scenario
    from testbed.pipeline.signal_chain import measure
    from testbed.scoring.run import make_identifier

    sc = load_scenario("cantilever_soft_impact")
    data = measure(DatasetCache().get(sc), sc.signal, "structural")
    est = make_identifier(sc).fit(data)
    if est.K3_ is None or not np.any(est.K3_ != 0.0):
        raise RuntimeError("bench_structural: sgd_sindy kept no cubic term on "
                           "cantilever_soft_impact; nothing cubic to simulate")
    M, C, K, K3, B = est.M_, est.C_, est.K_, est.K3_, est.input_map_
    i0 = int(data.free_start)
    n_t = min(data.n_samples - i0, WINDOW)
    dt = 1.0 / data.fs
    Minv = np.linalg.inv(M)
    A = np.ascontiguousarray(state_matrix(M, C, K))
    MK3 = np.ascontiguousarray(Minv @ K3)
    f = B @ data.u[:, i0:i0 + n_t] if B is not None and data.u is not None else np.zeros((M.shape[0], n_t))
    MF = np.ascontiguousarray(Minv @ f)
    z0 = np.concatenate([data.x[:, i0], data.xd[:, i0]])
    sub = max(1, int(np.ceil(pole_radius(A) * dt / 0.1)))  # simulate_structural's max_omega_h
    h = dt / sub
    Z = np.empty((A.shape[0], n_t))

    def ours() -> None:
        bad = cc.rk4_cubic(A, MK3, MF, z0, h, sub, Z)
        assert bad < 0

    peer: list[np.ndarray] = []

    def theirs() -> None:
        peer[:] = [numpy_rk4(A, MK3, MF, z0, h, sub, n_t)]

    t = interleaved({"ours": ours, "numpy": theirs}, REPEATS)
    gap = float(np.max(np.abs(Z - peer[0])) / np.max(np.abs(peer[0])))
    steps = (n_t - 1) * sub
    speed, rs = ratio_spread(t["numpy"], t["ours"])
    # Same operations in another order (numba's loops vs BLAS's gemv): agreement to a few
    # hundred ulps over the record, growing with the number of steps.
    agree = gap < 1e-10
    return [{"name": "cubic structural model simulation, compiled RK4 / numpy RK4 loop",
             "value": speed, "unit": "x faster", "target": "report", "ok": None if agree else False,
             "note": f"identified sgd_sindy model of cantilever_soft_impact ({M.shape[0]} DOF), "
                     f"{steps} RK4 steps ({sub} per sample over {n_t} samples); ours "
                     f"{spread(t['ours'] * 1e3)} ms, numpy {spread(t['numpy'] * 1e3)} ms; {rs} "
                     f"(numpy / ours); states agree to {gap:.1e} of their largest value; "
                     f"{machine()}"}]


if __name__ == "__main__":
    for r in run():
        print(r)
