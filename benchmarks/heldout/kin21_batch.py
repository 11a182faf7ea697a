"""Session 21: every kinetics cell (``sindy_pi_dynamical`` on ``michaelis_menten``) of the given
studies, run in one process as ``testbed sweep`` runs it (:func:`testbed.studies.sweep.run_cell`'s
path: the cached dataset, :func:`testbed.scoring.run.run_scenario`), one JSON line per cell: the
verdict, the row's reason, the scores, the simulated state's smallest value and largest
magnitude over the reference's (``sim_min``, ``sim_max_over_ref``), and the identifier's stored
rules (``noise_prune_rule_``, ``determinacy_``, ...).  Other rigs' cells are skipped.

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/kin21_batch.py OUT.jsonl STUDY.toml [...]

Cells already in OUT (same study and cell key) are skipped, so an interrupted batch resumes.
Tally: ``benchmarks/heldout/kin21_tally.py OUT.jsonl``.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from testbed.pipeline.cache import DatasetCache, default_cache_dir
from testbed.scoring.run import run_scenario
from testbed.studies.study import load_study
from testbed.studies.sweep import expand

KEEP = ("state_rmse", "coef_error", "support_f1", "support_precision", "support_recall")


def run(out: Path, studies: list[str]) -> None:
    done = set()
    if out.exists():
        done = {(r["study"], r["cell"]) for r in map(json.loads, out.read_text().splitlines()) if r}
    cache = DatasetCache(default_cache_dir())
    for path in studies:
        study = load_study(path)
        for cell in expand(study):
            sc = cell.scenario
            if sc.rig != "michaelis_menten" or (study.name, cell.key) in done:
                continue
            t0 = time.process_time()
            row = {"study": study.name, "cell": cell.key, "scenario": sc.name,
                   "noise": cell.noise, "seed": cell.seed, "passed": False, "error": ""}
            try:
                res = run_scenario(sc, dataset=cache.get(sc))
                row.update({k: float(res.scores.values.get(k, math.nan)) for k in KEEP})
                row["passed"] = bool(res.passed)
                row["error"] = res.failure or ""
                sim = res.scores.details.get("simulated_x")
                if sim is not None and len(sim):  # item 3: a negative concentration, a runaway
                    row["sim_min"] = float(np.nanmin(sim))
                    row["sim_max_over_ref"] = float(
                        np.nanmax(np.abs(sim)) / np.max(np.abs(res.scores.details["reference_x"])))
                m = res.model
                row["equations"] = m.equations() if hasattr(m, "coef_") else []
                row["rules"] = {k: str(getattr(m, k)) for k in
                                ("noise_prune_rule_", "determinacy_", "noise_std_", "refit_rule_",
                                 "sim_dt_rule_", "exact_tie_rule_", "shape_rule_")
                                if hasattr(m, k)}
            except Exception as e:  # a crash is recorded as such, the batch goes on
                row["error"] = f"CRASH {type(e).__name__}: {e}"
            row["cpu_s"] = time.process_time() - t0
            with out.open("a") as f:
                f.write(json.dumps(row, default=str) + "\n")
            print(f"{sc.name:28s} {cell.noise:4.1f} s{cell.seed:<5d} "
                  f"{'PASS' if row['passed'] else 'fail'} {row['error'][:90]}", flush=True)


if __name__ == "__main__":
    run(Path(sys.argv[1]), sys.argv[2:])
