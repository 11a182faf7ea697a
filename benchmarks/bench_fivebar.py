"""Five-bar rig: generating data, and simulating the identified model, against Pinocchio.

1. Generation of 10 s at dt = 1e-4 s against the bare constrained-dynamics loop (RK4 with four
   ``pin.constraintDynamics`` calls per step, no recording, no torque program, no checks).
   Target: a whole dataset within 2x that loop.
2. The identified five-bar model's right-hand side (SINDy-PI's equations with the loop closure:
   Newton solve of the passive angles, their rates, term evaluation, elimination of the passive
   accelerations, a 2 x 2 solve) per evaluation, inside the compiled RK4 loop of
   :meth:`identify._mechsim.ImplicitModel.simulate`, against one ``pin.constraintDynamics``
   call (full constrained dynamics of the same system, called from Python at the rig's start
   state).  Target: within 3x.
3. The ``fivebar_multisine`` scenario cell (warm dataset cache, no figures): measurement chain,
   SINDy-PI fit, and scoring, which simulates the identified model over the 10 s record.
   Target: under 2 s (an absolute time: the cell is what a user waits for).

All timings: BLAS pinned to one thread, contenders interleaved, medians with spread
(:mod:`benchmarks._timing`).

Run: ``.venv/bin/python -m benchmarks bench_fivebar``.
"""

from __future__ import annotations

import time

import numpy as np
import pinocchio as pin

from benchmarks._timing import interleaved, machine, ratio_spread, spread
from models.fivebar import geometry as geo
from models.fivebar.rig import FiveBarRig
from testbed.pipeline.generate import generate
from testbed.pipeline.scenario import load_scenario

TARGET_RATIO = 2.0       # generate / bare loop
TARGET_RHS_RATIO = 3.0   # identified RHS / pin.constraintDynamics
TARGET_CELL_S = 2.0      # fivebar_multisine cell, warm cache, no figures
REPEATS = 3


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


def _generation_rows() -> list[dict]:
    rows = []
    for name in ("fivebar_sine_replay", "fivebar_multisine"):
        sc = load_scenario(name)
        dt, duration = sc.simulation["dt"], sc.simulation["duration"]
        n_steps = round(duration / dt)
        rig = FiveBarRig(sc)
        bare: list[float] = []
        t = interleaved({"generate": lambda sc=sc: generate(sc),
                         "bare": lambda rig=rig, b=bare, k=n_steps, h=dt: b.append(bare_loop(rig, k, h))},
                        REPEATS)
        t_bare = np.asarray(bare[-REPEATS:])  # the loop's own clock, without the call around it
        ratio, rs = ratio_spread(t["generate"], t_bare)
        rows.append({"name": f"{name}: generate / bare RK4 loop", "value": ratio, "unit": "x",
                     "target": f"<= {TARGET_RATIO:g}", "ok": ratio <= TARGET_RATIO,
                     "note": f"{duration:g} s at dt {dt:g} s; generate {spread(t['generate'])} s, "
                             f"bare loop {spread(t_bare)} s; {rs}"})
        rows.append({"name": f"{name}: steps per second (generate)",
                     "value": n_steps / float(np.median(t["generate"])), "unit": "steps/s",
                     "target": "-", "ok": None,
                     "note": f"bare loop {n_steps / float(np.median(t_bare)):.0f} steps/s"})
    return rows


def _identified_rows() -> list[dict]:
    from identify.sindy_pi import SINDyPI
    from testbed.pipeline.cache import DatasetCache
    from testbed.pipeline.signal_chain import measure
    from testbed.scoring.run import make_identifier, run_scenario

    sc = load_scenario("fivebar_multisine")
    cache = DatasetCache()
    ds = cache.get(sc)
    data = measure(ds, sc.signal, "mechanical")
    est = make_identifier(sc)
    assert isinstance(est, SINDyPI)
    est.fit(data)
    model = est.model_
    from identify import _compiled as cc

    # the RK4 loop of ImplicitModel.simulate over the whole record, called directly so that
    # only right-hand sides are timed (no input interpolation or output spline)
    n_steps = round((data.t[-1] - data.t[0]) / est.sim_dt_)
    h = (data.t[-1] - data.t[0]) / n_steps
    tt = data.t[0] + 0.5 * h * np.arange(2 * n_steps + 1)
    uu = np.ascontiguousarray(np.stack([np.interp(tt, data.t, r) for r in data.u]))
    q0, dq0 = model.complete(data.x[:, :1].copy(), data.xd[:, :1].copy())
    n = q0.shape[0]
    bufs = [np.empty((n_steps + 1, n)) for _ in range(3)]

    def ours():
        st, _ = cc.rk4_implicit(q0[:, 0].copy(), dq0[:, 0].copy(), uu, h, n_steps,
                                *model._args(), *bufs)
        assert st == cc.OK

    rig = FiveBarRig(sc)
    dyn = rig.dynamics
    theta0, dtheta0 = rig.start_state()
    q, v = geo.to_joint(theta0), geo.to_joint(dtheta0)
    tau = np.array([0.05, 0.0, 0.05, 0.0])
    m, d, cms, cds, prox = dyn.model, dyn.data, dyn.cmodels, dyn.cdatas, dyn.prox
    cd = pin.constraintDynamics
    n_rhs = 4 * n_steps + 1

    def theirs():
        for _ in range(n_rhs):
            cd(m, d, q, v, tau, cms, cds, prox)

    t = interleaved({"ours": ours, "pinocchio": theirs}, 5)
    per_ours, per_pin = t["ours"] / n_rhs, t["pinocchio"] / n_rhs
    ratio, rs = ratio_spread(per_ours, per_pin)
    rows = [{"name": "identified five-bar RHS / pin.constraintDynamics", "value": ratio, "unit": "x",
             "target": f"<= {TARGET_RHS_RATIO:g}", "ok": ratio <= TARGET_RHS_RATIO,
             "note": f"per evaluation: ours {spread(per_ours, 1e6)} us inside the compiled RK4 "
                     f"loop ({n_rhs} evaluations over {data.t[-1] - data.t[0]:g} s at "
                     f"{est.sim_dt_:g} s), Pinocchio {spread(per_pin, 1e6)} us per call from "
                     f"Python (its call overhead included); {rs}; was 289 us per RHS in numpy"}]

    def cell():
        res = run_scenario(sc, cache=cache)
        assert res.passed, res.checks

    tc = interleaved({"cell": cell}, REPEATS)["cell"]
    rows.append({"name": "fivebar_multisine cell (warm cache, no figures)",
                 "value": float(np.median(tc)), "unit": "s", "target": f"< {TARGET_CELL_S:g}",
                 "ok": bool(np.median(tc) < TARGET_CELL_S),
                 "note": f"measurement chain + SINDy-PI fit + scoring (simulates 10 s); {spread(tc)} s; "
                         f"was 12-17 s; {machine()}"})
    return rows


def run() -> list[dict]:
    return _identified_rows() + _generation_rows()


if __name__ == "__main__":
    for r in run():
        mark = {True: "ok", False: "MISSED", None: "-"}[r["ok"]]
        print(f"{r['name']}: {r['value']:.4g} {r['unit']}  target {r['target']}  [{mark}]  {r['note']}")
