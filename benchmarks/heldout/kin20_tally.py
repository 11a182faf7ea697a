"""Session 20's tally of kinetics and cart-pole sweeps by failure class (every failing cell listed).

Usage (sweep each study into one folder first, ``testbed sweep STUDY --jobs 1 --results DIR/NAME.parquet``)::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/kin20_tally.py DIR [DIR ...]

Kinetics classes from the row's own reason and support scores: "diverged" (the rollout's reason),
"not determined" (the scorer's determinacy reason: the terms, or the law's, not determined at the
record's noise), else "wrong: spurious term" / "missing term" / both (support precision / recall
below 1), else "wrong: coefficients".  Cart-poles: "diverged", "wrong equation (law_error)", else
the angle bar alone.
"""

from __future__ import annotations

import glob
import sys
from collections import Counter

from testbed.studies.results import read_results


def kinetics_class(r: dict) -> str:
    e = r["error"]
    if r["passed"]:
        return "pass"
    if "diverged" in e:
        return "diverged"
    if "not determined" in e:
        return "not determined"
    p, rc = r.get("support_precision"), r.get("support_recall")
    if p is not None and p < 1 and rc is not None and rc < 1:
        return "wrong: spurious + missing term"
    if p is not None and p < 1:
        return "wrong: spurious term"
    if rc is not None and rc < 1:
        return "wrong: missing term"
    return "wrong: coefficients"


def cartpole_class(r: dict) -> str:
    e = r["error"]
    if r["passed"]:
        return "pass"
    if "diverged" in e or "no assembly" in e:
        return "diverged"
    if "law_error" in e:
        return "wrong equation (law_error)"
    return e[:60] if e else "angle_rmse bar only"


def main(dirs: list[str]) -> None:
    rows = [r for d in dirs for f in sorted(glob.glob(f"{d}/*.parquet")) for r in read_results(f)]
    for rig, cls, score in (("michaelis_menten", kinetics_class, "state_rmse"),
                            ("cartpole", cartpole_class, "angle_rmse")):
        sub = [r for r in rows if r["rig"] == rig]
        if not sub:
            continue
        print(f"{rig}: {len(sub)} cells, {sum(r['passed'] for r in sub)} pass; "
              + ", ".join(f"{k} {n}" for k, n in Counter(cls(r) for r in sub).most_common()))
        for r in sorted(sub, key=lambda r: (cls(r), r["scenario"], r["noise"], r["seed"])):
            if r["passed"]:
                continue
            extra = (f"coef_error {r.get('coef_error') or float('nan'):.3g} F1 "
                     f"{r.get('support_f1') or float('nan'):.3g} " if rig == "michaelis_menten" else "")
            print(f"  {cls(r):30s} {r['scenario']:26s} {r['noise']:4.1f} % s{r['seed']:<4d} {extra}"
                  f"{score} {r.get(score) or float('nan'):.3g} | {r['error'][:110]}")


if __name__ == "__main__":
    main(sys.argv[1:])
