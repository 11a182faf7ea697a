"""Run the soft-base (or any) family members of a study file cell by cell, in one process.

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/soft_batch.py STUDY.toml OUT.jsonl \
        [--family PREFIX] [--noise 0,1] [--ident ls_sindy,sgd_sindy]

Each cell is run as ``testbed sweep`` runs it (:func:`testbed.scoring.run.run_scenario` on the
cached dataset) and written as one JSON line: the scores of issue #15's bars, the issue's verdict
(:func:`tally.issue_verdict`), the study's verdict and the identifier's stored rules
(``cubic_rule_``, ``eigen_rule_``, ``decay_rule_``, ...).  Cells already in OUT are skipped.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

from testbed.pipeline.cache import DatasetCache
from testbed.scoring.run import run_scenario
from testbed.studies.study import load_study
from testbed.studies.sweep import expand

sys.path.insert(0, str(Path(__file__).parent))
from tally import issue_verdict

KEEP = ("trac", "mac_mode1", "mac_mode2", "freq_error_mode1", "freq_error_mode2",
        "K3_force_error", "K3_accel_error")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("study")
    ap.add_argument("out")
    ap.add_argument("--family", default="")
    ap.add_argument("--noise", default="0")
    ap.add_argument("--ident", default="ls_sindy,sgd_sindy")
    a = ap.parse_args()
    noises = {float(x) for x in a.noise.split(",")}
    idents = set(a.ident.split(","))
    out = Path(a.out)
    done = set()
    if out.exists():
        done = {json.loads(line)["key"] for line in out.read_text().splitlines() if line}
    cache = DatasetCache(Path.cwd() / ".cache" / "datasets")
    for cell in expand(load_study(a.study)):
        sc = cell.scenario
        if not sc.name.startswith(a.family) or cell.noise not in noises \
                or cell.identifier not in idents:
            continue
        key = f"{sc.name}|{cell.identifier}|{cell.noise}"
        if key in done:
            continue
        t0 = time.perf_counter()
        row = {"key": key, "scenario": sc.name, "identifier": cell.identifier,
               "noise": cell.noise, "status": "ok", "error": ""}
        try:
            res = run_scenario(sc, cache=cache)
            row.update({k: float(res.scores.values.get(k, math.nan)) for k in KEEP})
            row["passed"] = bool(res.passed)
            row["failure"] = res.failure or ""
            m = res.model
            row["rules"] = {k: str(getattr(m, k)) for k in dir(m)
                            if k.endswith("rule_") and not k.startswith("__")}
            row["cubic"] = bool(getattr(m, "cubic_", False))
        except Exception as e:  # a crash is recorded, the batch goes on
            row["status"], row["error"] = "failed", f"{type(e).__name__}: {e}"
        row["rig"] = "cantilever"
        ok, why = issue_verdict({**row, "rig": sc.rig})
        row["issue"], row["misses"] = ok, why
        row["time"] = time.perf_counter() - t0
        with out.open("a") as f:
            f.write(json.dumps(row) + "\n")
        print(f"{key:40s} {'PASS' if ok else 'fail'} {why}  ({row['time']:.1f} s)", flush=True)


if __name__ == "__main__":
    main()
