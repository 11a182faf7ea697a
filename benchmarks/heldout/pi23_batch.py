"""Session 23: cells of studies run one by one in one process as ``testbed sweep`` runs them
(:func:`testbed.studies.sweep.expand`, the cached dataset, :func:`testbed.scoring.run.run_scenario`),
one JSON line per cell: verdict, failure, scores, checks, the identified equations and the
identifier's stated rules.  Cells already in OUT (same study and cell key) are skipped, so an
interrupted batch resumes.

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/pi23_batch.py OUT.jsonl [--rig cartpole]
        [--ident sindy_pi] [--only NAME,...] [--noise 1.0,2.0] [--seeds 126]
        [--set 'formulation="strong"'] STUDY.toml [...]

``--set key=value`` overrides an identify setting of every cell (value a Python literal).
Run with ``PYTHONPATH`` at another checkout for its code's figures (before / after).
Tally of session 23's runs: ``benchmarks/heldout/pi23_cartpoles.tsv``.
"""

from __future__ import annotations

import ast
import json
import math
import sys
import time
from pathlib import Path

from testbed.pipeline.cache import DatasetCache, default_cache_dir
from testbed.scoring.run import run_scenario
from testbed.studies.study import load_study
from testbed.studies.sweep import expand

RULES = ("noise_prune_rule_", "determinacy_", "refit_rule_", "formulation_rule_", "noise_rule_",
         "record_rule_", "determinacy_rule_")


def parse(argv: list[str]) -> tuple[Path, dict, list[str]]:
    """OUT, the filters and settings, the study files."""
    opts: dict = {"sets": {}}
    studies, i = [], 0
    while i < len(argv):
        a = argv[i]
        if a in ("--only", "--ident"):
            opts[a[2:]] = argv[i + 1].split(",")
        elif a == "--noise":
            opts["noise"] = [float(x) for x in argv[i + 1].split(",")]
        elif a == "--seeds":
            opts["seeds"] = [int(x) for x in argv[i + 1].split(",")]
        elif a == "--rig":
            opts["rig"] = argv[i + 1]
        elif a == "--set":
            k, v = argv[i + 1].split("=", 1)
            opts["sets"][k] = ast.literal_eval(v)
        else:
            studies.append(a)
            i += 1
            continue
        i += 2
    return Path(argv[0]), opts, studies[1:]


def wanted(cell, opts: dict) -> bool:
    """Whether the cell passes the filters."""
    sc = cell.scenario
    return ((not opts.get("rig") or sc.rig == opts["rig"])
            and (not opts.get("only") or any(o in sc.name for o in opts["only"]))
            and (opts.get("noise") is None or cell.noise in opts["noise"])
            and (opts.get("seeds") is None or cell.seed in opts["seeds"])
            and (not opts.get("ident") or cell.identifier in opts["ident"]))


def run(argv: list[str]) -> None:
    out, opts, studies = parse(argv)
    done = set()
    if out.exists():
        done = {(r["study"], r["cell"]) for r in map(json.loads, out.read_text().splitlines()) if r}
    cache = DatasetCache(default_cache_dir())
    for path in studies:
        study = load_study(path)
        for cell in expand(study):
            if (study.name, cell.key) in done or not wanted(cell, opts):
                continue
            sc = cell.scenario
            if opts["sets"]:
                sc = sc.replace(identify={**sc.identify, **opts["sets"]})
            t0 = time.process_time()
            row = {"study": study.name, "cell": cell.key, "scenario": sc.name,
                   "method": cell.identifier, "noise": cell.noise, "seed": cell.seed,
                   "passed": False, "error": ""}
            try:
                res = run_scenario(sc, dataset=cache.get(sc))
                row["scores"] = {k: float(v) for k, v in res.scores.values.items()}
                row["passed"] = bool(res.passed)
                row["error"] = res.failure or ""
                row["checks"] = [(c.metric, float(c.value), c.passed) for c in res.checks]
                m = res.model
                row["rules"] = {k: str(getattr(m, k)) for k in RULES if hasattr(m, k)}
                if hasattr(m, "determinacy_"):
                    row["determinacy"] = [float(v) for v in m.determinacy_]
                row["equations"] = m.equations() if hasattr(m, "coef_") else []
            except Exception as e:  # a crash is recorded as such, the batch goes on
                row["error"] = f"CRASH {type(e).__name__}: {e}"
            row["cpu_s"] = time.process_time() - t0
            with out.open("a") as f:
                f.write(json.dumps(row, default=str) + "\n")
            s = row.get("scores", {})
            key = next((k for k in ("angle_rmse", "state_rmse") if k in s), None)
            v = s[key] if key else math.nan
            print(f"{sc.name:34s} {cell.identifier:18s} {cell.noise:4.1f} s{cell.seed:<5d} "
                  f"{'PASS' if row['passed'] else 'fail'} {v:.4g} {row['error'][:100]}", flush=True)


if __name__ == "__main__":
    run(sys.argv[1:])
