"""Session 24 (pi25): the study cells whose automatic derivative cut-off the chain's noise-floor
rule changed, run one by one as ``testbed sweep`` runs them (``pi23_batch.py``'s runner and JSON
lines, restricted to a list of cells).

Usage::

    PYTHONPATH=CHECKOUT .venv/bin/python benchmarks/heldout/pi25_batch.py OUT.jsonl CELLS.tsv \
        STUDY.toml [...]

CELLS.tsv: tab-separated ``study, scenario, identifier, noise, seed`` (further columns ignored;
``benchmarks/heldout/pi25_cutoffs.tsv``, rows marked CHANGED).  Run with ``PYTHONPATH`` at
another checkout for its code's figures (before / after).
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import pi23_batch  # a script beside this one, not a package module


def main(argv: list[str]) -> None:
    out, cells_tsv, studies = argv[0], argv[1], argv[2:]
    keep = set()
    for line in Path(cells_tsv).read_text().splitlines():
        f = line.split("\t")
        if len(f) >= 5 and (len(f) < 8 or f[7] == "CHANGED"):
            keep.add((f[0], f[1], f[2], float(f[3]), int(f[4])))

    def wanted(cell, opts: dict) -> bool:
        return (cell.study, cell.scenario.name, cell.identifier, float(cell.noise),
                int(cell.seed)) in keep

    pi23_batch.wanted = wanted
    pi23_batch.run([out, *studies])


if __name__ == "__main__":
    main(sys.argv[1:])
