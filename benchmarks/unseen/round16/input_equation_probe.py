"""Probe (session 18, not a scorer): sindy_pi on cart-pole cells member by member, the open
chain's input equation ranked per unit of its left-hand side ("old", as before session 18) and
per unit of its input's part ("new", identify._implicit.input_errors), in one process.  Usage
(from the repository root, PYTHONPATH=. so the working tree's identifiers are imported):

    python benchmarks/unseen/round16/input_equation_probe.py OUT.tsv STUDY_OR_SCENARIO.toml ...

Writes one row per cell and variant: passed, angle_rmse, law_error, the failures, lhs terms."""

import math
import sys

import identify._implicit as implicit
import identify.sindy_pi as sindy_pi
from testbed.pipeline.cache import DatasetCache, default_cache_dir
from testbed.pipeline.scenario import load_scenario
from testbed.scoring.run import run_scenario
from testbed.studies.study import load_study
from testbed.studies.sweep import expand

NEW = implicit.select_models


def old(sw, cols, rtol=0.1, atol=1e-12, top=1, G_val=None):
    return NEW(sw, cols, rtol, atol, top)


out, files = sys.argv[1], sys.argv[2:]
cells = []
for f in files:
    if "/scenarios/" in f"/{f}" and "benchmarks" not in f:
        cells.append((f, load_scenario(f)))
    else:
        st = load_study(f)
        cells += [(st.name, c.scenario) for c in expand(st) if c.identifier == "sindy_pi"]
cache = DatasetCache(default_cache_dir())
with open(out, "w") as fh:
    fh.write("study\tscenario\tnoise\tseed\tvariant\tpassed\tangle_rmse\tlaw_error\tfailures\tlhs\n")
    for study, sc in cells:
        ds = cache.get(sc)
        for name, rule in (("old", old), ("new", NEW)):
            sindy_pi.select_models = rule
            try:
                r = run_scenario(sc, dataset=ds)
                v = r.scores.values
                row = [r.passed, v.get("angle_rmse", math.nan), v.get("law_error", math.nan),
                       "; ".join(f"{k}: {w}" for k, w in r.scores.failures.items())[:160],
                       getattr(r.model, "lhs_terms_", None)]
            except Exception as e:  # a probe records every outcome
                row = [False, math.nan, math.nan, f"raised {e!r}"[:160], None]
            fh.write("\t".join(map(str, [study, sc.name, sc.noise.get("rms_percent", 0.0), sc.seed,
                                         name, *row])) + "\n")
            fh.flush()
