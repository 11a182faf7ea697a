"""Session 21's diagnosis, offline and with the truth beside (never an identifier's input): each
failing kinetics cell of a ``kin21_batch.py`` file run again with the identifier's library cut
to the true equation's terms (the rest of its setup as the cell's), so that the coefficient
bar alone says whether the record, fitted on the right terms, meets the rig's bars.  A cell
that fails so is out of reach of any term selection; one that passes so is lost by the
selection among terms.

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/kin21_oracle.py BATCH.jsonl OUT.jsonl \
        STUDY.toml [...]
"""

from __future__ import annotations

import json
import math
import sys

from testbed.pipeline.cache import DatasetCache, default_cache_dir
from testbed.scoring.run import run_scenario
from testbed.studies.study import load_study
from testbed.studies.sweep import expand


def main(batch: str, out_path: str, studies: list[str]) -> None:
    rows = [json.loads(line) for line in open(batch) if line.strip()]
    fail = {(r["study"], r["cell"]) for r in rows if not r["passed"]}
    cache = DatasetCache(default_cache_dir())
    with open(out_path, "a") as out:
        for path in studies:
            st = load_study(path)
            for c in expand(st):
                if (st.name, c.key) not in fail:
                    continue
                sc = c.scenario
                ds = cache.get(sc)
                terms = list(ds.truth["equation_terms"])
                res = run_scenario(sc.replace(identify={**sc.identify, "library": terms}),
                                   dataset=ds)
                v = {k: float(res.scores.values.get(k, math.nan))
                     for k in ("coef_error", "support_f1", "state_rmse")}
                rec = {"study": st.name, "cell": c.key, "scenario": sc.name, "noise": c.noise,
                       "seed": c.seed, "oracle": v, "passed": bool(res.passed),
                       "eq": res.model.equations() if hasattr(res.model, "coef_") else [],
                       "det": str(getattr(res.model, "determinacy_", ""))}
                out.write(json.dumps(rec) + "\n")
                out.flush()
                print(f"{sc.name:28s} {c.noise:4.1f} s{c.seed:<5d} true terms: coef_error "
                      f"{v['coef_error']:.3g} F1 {v['support_f1']:.3g} state_rmse "
                      f"{v['state_rmse']:.3g} pass {rec['passed']}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3:])
