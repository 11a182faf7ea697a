"""Issue #15 pass counts of two ``soft_batch.py`` outputs, per family and identifier, and every
cell whose verdict or modes 1-2 moved.

Usage::

    python benchmarks/heldout/soft_compare.py BEFORE.jsonl AFTER.jsonl
"""

from __future__ import annotations

import json
import sys
from collections import defaultdict


def load(path: str) -> dict[str, dict]:
    with open(path) as f:
        return {r["key"]: r for r in map(json.loads, filter(None, f.read().splitlines()))}


def main() -> None:
    a, b = load(sys.argv[1]), load(sys.argv[2])
    keys = sorted(set(a) & set(b))
    tally: dict[tuple, list[int]] = defaultdict(lambda: [0, 0, 0])
    for k in keys:
        fam = a[k]["scenario"].split("__")[0]
        t = tally[(fam, a[k]["identifier"], a[k]["noise"])]
        t[0] += a[k]["issue"]
        t[1] += b[k]["issue"]
        t[2] += 1
    for (fam, ident, noise), (x, y, n) in sorted(tally.items()):
        print(f"{fam:12s} {ident:10s} {noise:4.1f} %: {x:2d} -> {y:2d} / {n}")
    for k in keys:
        ra, rb = a[k], b[k]
        moved = any(abs(ra.get(m, 0) - rb.get(m, 0)) > 1e-6 for m in
                    ("freq_error_mode1", "freq_error_mode2", "trac")
                    if isinstance(ra.get(m), float) and isinstance(rb.get(m), float))
        if ra["issue"] != rb["issue"] or moved:
            tag = ("GAIN" if rb["issue"] and not ra["issue"]
                   else "LOSS" if ra["issue"] and not rb["issue"] else "move")
            print(f"  {tag} {k}: [{ra['misses'] or 'pass'}] -> [{rb['misses'] or 'pass'}]"
                  f"  f1 {100 * ra.get('freq_error_mode1', float('nan')):.2f} -> "
                  f"{100 * rb.get('freq_error_mode1', float('nan')):.2f}, f2 "
                  f"{100 * ra.get('freq_error_mode2', float('nan')):.2f} -> "
                  f"{100 * rb.get('freq_error_mode2', float('nan')):.2f}, TRAC "
                  f"{ra.get('trac', float('nan')):.3f} -> {rb.get('trac', float('nan')):.3f}")


if __name__ == "__main__":
    main()
