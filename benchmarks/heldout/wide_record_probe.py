"""Probe (session 20, not a scorer): sindy_pi on every five-bar cell of the studies or
scenarios given, with the record rule's wider search (identify/sindy_pi.py
``SINDyPI._wide_record``) on and, where the fit reached it (its ``record_rule_`` says "best per
input searched"), off too, in one process; the cells that do not reach it are identical by
construction.  Usage (from the repository root, PYTHONPATH=.):

    python benchmarks/heldout/wide_record_probe.py OUT.tsv STUDY_OR_SCENARIO.toml ...

One row per cell and variant (new / old; "rig": the rig refused the scenario): passed,
angle_rmse, failures, CPU seconds, the end of the record rule's statement; an existing OUT.tsv
is resumed.  Session 20's table: wide_record_members.tsv (rounds 14-18's five-bar sine,
sine-seed and multisine studies, round 18's seeds, the validation studies of this folder, the
shipped five-bar scenarios with estimated rates)."""
import math
import os
import sys
import time

import identify.sindy_pi as sp
from testbed.pipeline.cache import DatasetCache, default_cache_dir
from testbed.pipeline.scenario import load_scenario
from testbed.scoring.run import run_scenario
from testbed.studies.study import load_study
from testbed.studies.sweep import expand

out, files = sys.argv[1], sys.argv[2:]
cells = []
for f in files:
    if f.startswith("scenarios/"):
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
               "; ".join(f"{k}: {w}" for k, w in r.scores.failures.items())[:200],
               getattr(r.model, "record_rule_", "")]
    except Exception as e:
        row = [False, math.nan, f"raised {e!r}"[:200], ""]
    return [*row[:3], f"{time.process_time() - t0:.1f}", row[3][-300:]]

done = set()
if os.path.exists(out):
    done = {tuple(line.split("\t")[:4]) for line in open(out) if line.strip()}
with open(out, "a") as fh:
    if not done:
        fh.write("study\tscenario\tnoise\tseed\tvariant\tpassed\tangle_rmse\tfailures\tcpu\trecord_rule\n")
    for study, sc in cells:
        key = [study, sc.name, sc.noise.get("rms_percent", 0.0), sc.seed]
        if tuple(map(str, key)) in done:
            continue
        try:
            ds = cache.get(sc)
        except Exception as e:
            fh.write("\t".join(map(str, [*key, "rig", False, math.nan, repr(e)[:120], 0, ""])) + "\n")
            continue
        sp.SINDyPI._wide_record_on = True
        row = one(sc, ds)
        fh.write("\t".join(map(str, [*key, "new", *row])) + "\n")
        fh.flush()
        if "best per input searched" in row[-1]:
            sp.SINDyPI._wide_record_on = False
            row = one(sc, ds)
            sp.SINDyPI._wide_record_on = True
            fh.write("\t".join(map(str, [*key, "old", *row])) + "\n")
            fh.flush()
