"""Pass rates of a family sweep on the study's bars and on issue #15's bars, and every failing cell.

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/tally.py out/heldout/families_heldout.parquet

Issue #15's bars (not the study file's): structural cells TRAC >= 0.95, MAC of modes 1-2 >= 0.95,
|frequency error| of modes 1-2 <= 1 %; five-bars joint-angle RMSE <= 1e-4 rad clean and
<= 0.0501 rad at 1 % noise.  A missing or NaN score fails (NaN never passes).  The study's bars
are the row's own ``passed`` (the sweep's verdict).
"""

from __future__ import annotations

import math
import sys
from collections import defaultdict

from testbed.studies.results import read_results

ISSUE_MIN = 0.95        # TRAC and MAC of modes 1-2 (issue #15)
ISSUE_FREQ = 0.01       # |relative frequency error| of modes 1-2 (issue #15)
ISSUE_ANGLE = {0.0: 1e-4, 1.0: 0.0501}   # rad, clean / 1 % (issue #15)


def _ok(value: float | None, bound: float, low: bool) -> bool:
    """``value`` meets ``bound`` (``low``: value >= bound, else value <= bound); NaN fails."""
    if value is None or not math.isfinite(value):
        return False
    return value >= bound if low else value <= bound


def issue_verdict(row: dict) -> tuple[bool, str]:
    """Issue #15's verdict of one row and the bars it misses (text)."""
    if row["status"] != "ok":
        return False, "failed: " + row["error"][:120]
    if row["rig"].startswith("fivebar"):
        bound = ISSUE_ANGLE[row["noise"]]
        v = row.get("angle_rmse")
        return _ok(v, bound, False), "" if _ok(v, bound, False) else f"angle_rmse {v:.3g}"
    misses = []
    if not _ok(row.get("trac"), ISSUE_MIN, True):
        misses.append(f"TRAC {row.get('trac'):.3f}")
    for k in (1, 2):
        mac = row.get(f"mac_mode{k}")
        if not _ok(mac, ISSUE_MIN, True):
            misses.append(f"MAC{k} {mac:.3f}")
        fe = row.get(f"freq_error_mode{k}")
        fe = abs(fe) if fe is not None and math.isfinite(fe) else float("nan")
        if not _ok(fe, ISSUE_FREQ, False):
            misses.append(f"f{k} {100 * fe:.2f} %")
    return not misses, ", ".join(misses)


def family(scenario: str) -> str:
    """The family of a member's scenario name ``<family>__kkk``."""
    return scenario.split("__")[0]


def main(path: str) -> None:
    rows = read_results(path)
    table: dict[tuple, list[int]] = defaultdict(lambda: [0, 0, 0])
    fails = []
    for r in rows:
        key = (r["identifier"], r["noise"], family(r["scenario"]))
        ok, why = issue_verdict(r)
        t = table[key]
        t[0] += bool(r["passed"])
        t[1] += ok
        t[2] += 1
        if not ok or not r["passed"]:
            fails.append((r["identifier"], r["noise"], r["scenario"], bool(r["passed"]), ok,
                          why, r["status"], r["error"][:160]))
    print("identifier | noise % | family | study's bars | issue's bars")
    for (ident, noise, fam), (p, q, n) in sorted(table.items()):
        print(f"{ident} | {noise:g} | {fam} | {p} / {n} | {q} / {n}")
    print("\nfailing cells (identifier, noise, member, study pass, issue pass, issue misses, "
          "status, error):")
    for f in sorted(fails):
        print(" | ".join(str(x) for x in f))


if __name__ == "__main__":
    main(sys.argv[1])
