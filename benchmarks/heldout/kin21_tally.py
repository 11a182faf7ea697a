"""Session 21's tally of kinetics cells (``kin21_batch.py``'s JSON lines) by failure class.

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/kin21_tally.py OUT.jsonl [BEFORE.jsonl]

Classes as ``kin20_tally.py`` draws them from the row's reason and support scores ("diverged",
"not determined", "wrong: spurious / missing term", "wrong: coefficients"), the undetermined
ones split by what the only-removal rule found (``noise_prune_rule_``: how many of the
equation's term removals hold within the noise).  With BEFORE, each study's passes before ->
after and every cell whose verdict or class changed.
"""

from __future__ import annotations

import json
import re
import sys
from collections import Counter, defaultdict


def rows_of(path: str) -> dict[tuple[str, str], dict]:
    out = {}
    for line in open(path):
        if line.strip():
            r = json.loads(line)
            out[(r["study"], r["cell"])] = r
    return out


def klass(r: dict) -> str:
    e = r["error"]
    if r["passed"]:
        return "pass"
    if e.startswith("CRASH"):
        return "CRASH"
    if "diverged" in e or "non-physical" in e:
        return "diverged / non-physical"
    if "not determined" in e:
        m = re.search(r"(\d+) removal\(s\) within", r.get("rules", {}).get("noise_prune_rule_", ""))
        return f"not determined ({m.group(1) if m else '?'} removals within)"
    p, rc = r.get("support_precision"), r.get("support_recall")
    if p is not None and p < 1 and rc is not None and rc < 1:
        return "wrong: spurious + missing term"
    if p is not None and p < 1:
        return "wrong: spurious term"
    if rc is not None and rc < 1:
        return "wrong: missing term"
    return "wrong: coefficients"


def main(after: str, before: str | None = None) -> None:
    rows = rows_of(after)
    print(f"{len(rows)} cells, {sum(r['passed'] for r in rows.values())} pass; "
          + ", ".join(f"{k} {n}" for k, n in Counter(map(klass, rows.values())).most_common()))
    per = defaultdict(lambda: [0, 0, 0])
    old = rows_of(before) if before else {}
    for key, r in rows.items():
        per[r["study"]][0] += 1
        per[r["study"]][1] += r["passed"]
        per[r["study"]][2] += old.get(key, {}).get("passed", False)
    for s, (n, p, p0) in per.items():
        print(f"  {s:40s} {(str(p0) + ' -> ') if old else ''}{p} / {n}")
    for key, r in sorted(rows.items(), key=lambda kv: (klass(kv[1]), kv[1]["scenario"],
                                                      kv[1]["noise"], kv[1]["seed"])):
        o = old.get(key)
        changed = o is not None and (o["passed"] != r["passed"] or klass(o) != klass(r)
                                     or o.get("coef_error") != r.get("coef_error"))
        if r["passed"] and not changed:
            continue
        mark = "*" if changed else " "
        was = (f"  [was {klass(o)}, coef_error {o.get('coef_error', float('nan')):.3g}, "
               f"state_rmse {o.get('state_rmse', float('nan')):.3g}]") if changed else ""
        print(f" {mark}{klass(r):36s} {r['scenario']:26s} {r['noise']:4.1f} % s{r['seed']:<5d} "
              f"coef_error {r.get('coef_error', float('nan')):.3g} F1 "
              f"{r.get('support_f1', float('nan')):.3g} state_rmse "
              f"{r.get('state_rmse', float('nan')):.3g}{was}")


if __name__ == "__main__":
    main(*sys.argv[1:3])
