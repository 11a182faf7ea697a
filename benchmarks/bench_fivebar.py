"""Five-bar rig: generating 10 s at dt = 1e-4 s against the bare constrained-dynamics loop.

The peer is the loop every generation must run anyway: RK4 with four
``pin.constraintDynamics`` calls per step, no recording, no torque program, no checks.
Target: a whole dataset (inverse dynamics for the replay, recording, transmission checks,
truth, noise, provenance) within 2x that loop, measured in the same run.

Run: ``OMP_NUM_THREADS=1 .venv/bin/python -m benchmarks.bench_fivebar``.
"""

from __future__ import annotations

import time

import numpy as np
import pinocchio as pin

from models.fivebar import geometry as geo
from models.fivebar.rig import FiveBarRig
from testbed.pipeline.generate import generate
from testbed.pipeline.scenario import load_scenario

TARGET_RATIO = 2.0


def bare_loop(rig: FiveBarRig, n_steps: int, dt: float) -> float:
    """Seconds for ``n_steps`` RK4 steps of ``pin.constraintDynamics`` only (constant torque)."""
    dyn = rig.dynamics
    m, d, cms, cds, prox = dyn.model, dyn.data, dyn.cmodels, dyn.cdatas, dyn.prox
    cd = pin.constraintDynamics
    theta0, dtheta0 = rig.start_state()
    q, v = geo.to_joint(theta0), geo.to_joint(dtheta0)
    tau = np.array([0.05, 0.0, 0.05, 0.0])
    h, h2, h6 = dt, dt / 2, dt / 6
    t0 = time.perf_counter()
    for _ in range(n_steps):
        a1 = cd(m, d, q, v, tau, cms, cds, prox).copy()
        v2, q2 = v + h2 * a1, q + h2 * v
        a2 = cd(m, d, q2, v2, tau, cms, cds, prox).copy()
        v3, q3 = v + h2 * a2, q + h2 * v2
        a3 = cd(m, d, q3, v3, tau, cms, cds, prox).copy()
        v4, q4 = v + h * a3, q + h * v3
        a4 = cd(m, d, q4, v4, tau, cms, cds, prox)
        q = q + h6 * (v + 2.0 * (v2 + v3) + v4)
        v = v + h6 * (a1 + 2.0 * (a2 + a3) + a4)
    return time.perf_counter() - t0


def run() -> list[dict]:
    rows = []
    for name in ("fivebar_sine_replay", "fivebar_multisine"):
        sc = load_scenario(name)
        dt, duration = sc.simulation["dt"], sc.simulation["duration"]
        n_steps = round(duration / dt)
        t_bare = bare_loop(FiveBarRig(sc), n_steps, dt)
        t0 = time.perf_counter()
        generate(sc)
        t_gen = time.perf_counter() - t0
        ratio = t_gen / t_bare
        rows.append({"name": f"{name}: generate / bare RK4 loop", "value": ratio, "unit": "x",
                     "target": f"<= {TARGET_RATIO:g}", "ok": ratio <= TARGET_RATIO,
                     "note": f"{duration:g} s at dt {dt:g} s: generate {t_gen:.2f} s, "
                             f"bare loop {t_bare:.2f} s"})
        rows.append({"name": f"{name}: steps per second (generate)", "value": n_steps / t_gen,
                     "unit": "steps/s", "target": "-", "ok": None,
                     "note": f"bare loop {n_steps / t_bare:.0f} steps/s"})
    return rows


if __name__ == "__main__":
    for r in run():
        mark = {True: "ok", False: "MISSED", None: "-"}[r["ok"]]
        print(f"{r['name']}: {r['value']:.4g} {r['unit']}  target {r['target']}  [{mark}]  {r['note']}")
