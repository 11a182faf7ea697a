"""`make bench`: run every benchmarks/bench_*.py, print the results, write benchmarks/RESULTS.md.

Each benchmark module exposes ``run() -> list[dict]`` with keys name, value, unit,
target, ok, note.  Performance targets are ratios against a peer measured in the
same run, never absolute times.
"""

from __future__ import annotations

import importlib
import pkgutil
import platform
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main(argv: list[str]) -> int:
    only = set(argv)
    rows = []
    for info in sorted(pkgutil.iter_modules([str(HERE)]), key=lambda i: i.name):
        if not info.name.startswith("bench_") or (only and info.name not in only):
            continue
        mod = importlib.import_module(f"benchmarks.{info.name}")
        t0 = time.perf_counter()
        print(f"== {info.name}", flush=True)
        for r in mod.run():
            r = {"bench": info.name, **r}
            rows.append(r)
            mark = "ok" if r.get("ok") else ("-" if r.get("ok") is None else "MISSED")
            print(f"  {r['name']}: {r['value']:.4g} {r.get('unit', '')}  target {r.get('target', '-')}  "
                  f"[{mark}]  {r.get('note', '')}", flush=True)
        print(f"  ({time.perf_counter() - t0:.1f} s)")
    table = []
    for r in rows:
        met = {True: "yes", False: "**no**", None: "-"}[r.get("ok")]
        table.append(f"| {r['bench']} | {r['name']} | {r['value']:.4g} {r.get('unit', '')} | "
                     f"{r.get('target', '-')} | {met} | {r.get('note', '')} |")
    out = HERE / "RESULTS.md"
    if only and out.is_file():  # keep the other benchmarks' rows, replace these
        kept = [ln for ln in out.read_text().splitlines()
                if ln.startswith("| bench_") and ln.split("|")[1].strip() not in only]
        table = sorted(kept + table, key=lambda ln: ln.split("|")[1].strip())
    lines = ["# Benchmark results", "",
             f"Measured by `make bench` on {platform.machine()} / Python {platform.python_version()}, "
             f"{time.strftime('%Y-%m-%d')}; one BLAS thread; `python -m benchmarks NAME` re-measures "
             "one benchmark and keeps the others' rows.", "",
             "| benchmark | measure | value | target | met | note |", "|---|---|---|---|---|---|", *table]
    out.write_text("\n".join(lines) + "\n")
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
