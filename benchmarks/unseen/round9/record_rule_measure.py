"""Member-by-member before / after of the record rule's rest baseline (round 9), as run on
2026-11-27: python benchmarks/unseen/round9/record_rule_measure.py OUT.tsv STUDY.toml ...
Columns: study, scenario, noise, seed, pairs the rest baseline excluded that the divergence test
kept ("fired"; 0: the same code path as before), before verdict, angle_rmse, after verdict,
angle_rmse, seconds, the failures before and after.  families_linkages: studies/families.toml's
30 five-bars with sindy_pi, clean and 1 %."""
import os
import sys
import time

import identify.sindy_pi as S
from testbed.scoring.run import run_scenario
from testbed.studies.study import load_study
from testbed.studies.sweep import expand

NEW = S._ImplicitMechanical._replay_status
FIRED = []

def old(self, model, data):
    a, _ = NEW(self, model, data)
    return a, a

def spy(self, model, data):
    a, b = NEW(self, model, data)
    if a and not b:
        FIRED.append(1)
    return a, b

def one(sc):
    try:
        r = run_scenario(sc)
        v = r.scores.values.get("angle_rmse", float("nan"))
        why = "; ".join(f"{k}: {w}" for k, w in (r.scores.failures or {}).items())[:90]
        return ("P" if r.passed else "F"), v, why
    except Exception as exc:
        return "E", float("nan"), f"{type(exc).__name__}: {str(exc)[:80]}"

done = set()
if os.path.exists(sys.argv[1]):
    for line in open(sys.argv[1]):
        f = line.split("\t")
        done.add((f[0], f[1], float(f[2]), int(f[3])))
out = open(sys.argv[1], "a")
for f in sys.argv[2:]:
    st = load_study(f)
    for c in expand(st):
        if c.identifier != "sindy_pi" or (st.name, c.scenario.name, float(c.noise), int(c.seed)) in done:
            continue
        FIRED.clear()
        S._ImplicitMechanical._replay_status = spy
        t0 = time.time()
        va, xa, wa = one(c.scenario)
        fired = len(FIRED)
        vb, xb, wb = va, xa, wa
        if fired:
            S._ImplicitMechanical._replay_status = old
            vb, xb, wb = one(c.scenario)
        out.write(f"{st.name}\t{c.scenario.name}\t{c.noise}\t{c.seed}\t{fired}\t{vb}\t{xb:.4g}\t{va}\t{xa:.4g}\t{time.time()-t0:.0f}\t{wb}\t{wa}\n")
        out.flush()
