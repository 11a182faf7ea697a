"""Probe (round 14, not a scorer): replay the identified cart-pole in the experiment's own loop,
u = ff - kp x - kd xd held per sample (RK4, 4 steps per sample), instead of open-loop under the
recorded u, and compare with the noise-free record.  Usage (from the repository root):

    python benchmarks/unseen/round14/closed_loop_probe.py benchmarks/unseen/round14/cp14_chirp.toml:2:53

Each argument is scenario:noise_percent:seed (a path, relative to the repository root)."""

import dataclasses
import sys

import numpy as np

import testbed
from testbed import load_scenario

for arg in sys.argv[1:]:
    f, noise, seed = arg.split(":")
    sc = load_scenario(f)
    sc = dataclasses.replace(sc, seed=int(seed), noise={**sc.noise, "rms_percent": float(noise)})
    res = testbed.run_scenario(sc)
    m = res.model.model_
    ds = res.dataset
    ff = ds.reference["feedforward"].data[0]
    th = np.asarray(ds.reference.get("theta", ds.measured["theta"]).data)
    kp, kd = sc.excitation["kp"], sc.excitation["kd"]
    fs = ds.fs
    n = th.shape[1]
    sub = 4
    h = 1.0 / (fs * sub)
    q = np.array(ds.truth["theta0"], float)
    v = np.array(ds.truth["dtheta0"], float)
    out = np.empty((2, n))
    def acc(q, v, u, m=m):
        return m.accelerations(q[:, None], v[:, None], np.array([[u]]))[:, 0]

    ok = True
    for k in range(n):
        out[:, k] = q
        u = ff[k] - kp * q[0] - kd * v[0]
        for _ in range(sub):
            a1 = acc(q, v, u)
            a2 = acc(q + h / 2 * v, v + h / 2 * a1, u)
            a3 = acc(q + h / 2 * (v + h / 2 * a1), v + h / 2 * a2, u)
            a4 = acc(q + h * (v + h / 2 * a2), v + h * a3, u)
            q = q + h * v + h * h / 6 * (a1 + a2 + a3)
            v = v + h / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
        if not np.all(np.isfinite(q)):
            ok = False
            break
    rm = np.sqrt(np.mean((out - th) ** 2, axis=1)) if ok else [np.nan, np.nan]
    print(
        arg.split("/")[-1],
        "open-loop",
        res.scores.details.get("angle_rmse"),
        "closed-loop",
        rm,
        "law",
        res.scores.details.get("law_errors"),
        flush=True,
    )
