"""Session 14 probe: every support of at least min_terms terms of the kinetics library on one cell, with its
noise-residual ratio (identify._determinacy.noise_residual_ratio: about 1 where the terms hold
an equation to within the record's noise) and its determinacy bound, plus the truth for
comparison (offline diagnosis only; the identifier never sees the truth).

Usage: PYTHONPATH=$PWD .venv/bin/python benchmarks/unseen/round14/kin14_probe.py \
    benchmarks/unseen/round14/mm14_km8_vmax12.toml 1.0 54 [min_terms=2]
"""

import dataclasses
import itertools
import sys

import numpy as np

import identify.sindy_pi_dynamical as spd
import testbed
from identify._determinacy import determinacy_bound, noise_residual_ratio
from testbed import load_scenario

store = {}
orig = spd.SINDyPIDynamical.fit


def fit(self, data):
    store["data"] = data
    return orig(self, data)


spd.SINDyPIDynamical.fit = fit
path, noise, seed = sys.argv[1], float(sys.argv[2]), int(sys.argv[3])
KMIN = int(sys.argv[4]) if len(sys.argv) > 4 else 2
sc = load_scenario(path)
sc = dataclasses.replace(sc, noise={**sc.noise, "rms_percent": noise}, seed=seed)
res = testbed.run_scenario(sc)
m = res.model
d = store["data"]
print(
    path.split("/")[-1],
    noise,
    seed,
    res.verdict,
    {
        k: round(float(v), 4)
        for k, v in res.scores.values.items()
        if k in ("support_f1", "coef_error", "state_rmse")
    },
)
lib = m._lib
x = np.asarray(d.x, float)
xd = np.asarray(d.xd, float)
sigma = m._noise_level(d, x)
print(
    "  selected",
    [lib.names[j] for j in np.flatnonzero(m.coef_[0])],
    "det",
    m.determinacy_,
    "prune",
    m.noise_prune_,
)
t = res.dataset.truth
print(
    "  truth",
    t["equation_terms"],
    np.round(np.asarray(t["equation_coef"]).ravel() / np.abs(np.asarray(t["equation_coef"])).max(), 4),
)
for k in range(KMIN, 6):
    for S in itertools.combinations(lib.names, k):
        if "dx" not in S and "x*dx" not in S:
            continue
        rows = m._rows_of(list(S), lib, xd, None, d.fs)
        r, w = noise_residual_ratio(rows, x, sigma)
        b = determinacy_bound(rows, x, sigma)
        print(f"  {S!s:40s} ratio {r:10.3g} det {b:10.3g}  w {np.round(w / np.abs(w).max(), 4)}")
