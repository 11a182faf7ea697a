"""Probe (session 19, not a scorer): sindy_pi on every five-bar cell of the studies or
scenarios given, with the inertia rule (identify/sindy_pi.py ``_inertia_rule``) on, and, where
it acted (excluded a pair in some fit), off too, in one process; the cells where it did not
act are identical by construction.  Usage (from the repository root, PYTHONPATH=.):

    python benchmarks/unseen/round17/inertia_rule_probe.py OUT.tsv STUDY_OR_SCENARIO.toml ...

One row per cell and variant (new / old; "rig": the rig refused the scenario): passed,
angle_rmse, failures, CPU seconds, the rule's statement per fit.  Session 19's table:
inertia_rule_members.tsv (rounds 14-17's five-bar studies, round 15's clean one, the shipped
five-bar scenarios, studies/families.toml)."""
import math
import sys
import time

import identify.sindy_pi as sp
from testbed.pipeline.cache import DatasetCache, default_cache_dir
from testbed.pipeline.scenario import load_scenario
from testbed.scoring.run import run_scenario
from testbed.studies.study import load_study
from testbed.studies.sweep import expand

ORIG = sp._ImplicitMechanical._inertia_rule
LOG = []
def wrapped(self, combos, models, data, wider, make):
    try:
        out = ORIG(self, combos, models, data, wider, make)
    finally:
        LOG.append(self.inertia_rule_)
    return out
sp._ImplicitMechanical._inertia_rule = wrapped

out, files = sys.argv[1], sys.argv[2:]
cells = []
for f in files:
    if "benchmarks" not in f and f.startswith("scenarios/"):
        cells.append((f, load_scenario(f)))
    else:
        st = load_study(f)
        cells += [(st.name, c.scenario) for c in expand(st) if c.identifier == "sindy_pi"
                  and c.scenario.rig == "fivebar"]
cache = DatasetCache(default_cache_dir())

def one(sc, ds):
    t0 = time.process_time()
    try:
        r = run_scenario(sc, dataset=ds)
        v = r.scores.values
        row = [r.passed, v.get("angle_rmse", math.nan),
               "; ".join(f"{k}: {w}" for k, w in r.scores.failures.items())[:200]]
    except Exception as e:
        row = [False, math.nan, f"raised {e!r}"[:200]]
    return [*row, f"{time.process_time() - t0:.1f}"]

with open(out, "w") as fh:
    fh.write("study\tscenario\tnoise\tseed\tvariant\tpassed\tangle_rmse\tfailures\tcpu\tinertia\n")
    for study, sc in cells:
        try:
            ds = cache.get(sc)
        except Exception as e:  # a rig refusing its own scenario: no cell
            fh.write("\t".join(map(str, [study, sc.name, sc.noise.get("rms_percent", 0.0), sc.seed,
                                         "rig", False, math.nan, repr(e)[:120], 0, ""])) + "\n")
            continue
        LOG.clear()
        sp._ImplicitMechanical._inertia_rule_on = False
        sp.SINDyPI._inertia_rule_on = True
        row = one(sc, ds)
        acted = [s for s in LOG if "none excluded" not in s and not s.startswith("not applied")]
        key = [study, sc.name, sc.noise.get("rms_percent", 0.0), sc.seed]
        fh.write("\t".join(map(str, [*key, "new", *row, " | ".join(LOG)[:400]])) + "\n")
        fh.flush()
        if acted:
            sp.SINDyPI._inertia_rule_on = False
            row = one(sc, ds)
            sp.SINDyPI._inertia_rule_on = True
            fh.write("\t".join(map(str, [*key, "old", *row, ""])) + "\n")
            fh.flush()
