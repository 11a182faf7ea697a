"""Where SGD-SINDy's penalties earn their keep: the families' 60 beams under five settings.

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/sgd_penalty_ablation.py OUT.jsonl \
        [--noise 0,1,3] [--step 1] [--offset 0]
    PYTHONPATH=. .venv/bin/python benchmarks/heldout/sgd_penalty_ablation.py OUT.jsonl --table

Each beam member of ``studies/families.toml`` (seed 0 draws; clamped 40, soft 20) is run alone
through :func:`testbed.scoring.run.run_scenario` at each noise level (the study's noise seed)
with the member's own ``[identify]`` (the soft members' ``sgd_sindy`` is ``cubic = true``) and:

* ``default``: ``sgd_sindy`` as shipped (symmetric parametrisation: the symmetry penalty's
  limit; trace(M) = the mass prior: the mass penalty's fixed point; eigenvalue penalty with
  annealing; the holds);
* ``eigen_hold_false``: the eigenvalue penalty without the hold onto the measured peaks;
* ``eigen_false``: no eigenvalue information at all (no penalty, no hold, no backbone);
* ``epochs_0``: the SGD's least-squares warm start, held (no gradient step);
* ``ls_sindy``: the least-squares identifier's default.

Rows: the scores of issue #15's bars, the study's verdict (``passed``: the families' bars) and
issue #15's (:func:`tally.issue_verdict`).  ``--table`` prints the pass counts.  The scored
bars are scale-free (TRAC, MAC, frequencies), so the mass constraint is not measured by them.
"""

from __future__ import annotations

import argparse
import collections
import json
import math
import sys
import time
from pathlib import Path

from testbed.pipeline import plugins
from testbed.pipeline.cache import DatasetCache
from testbed.scoring.run import run_scenario
from testbed.studies.study import load_study
from testbed.studies.sweep import expand

sys.path.insert(0, str(Path(__file__).parent))
from tally import issue_verdict

VARIANTS = {"default": {"method": "sgd_sindy"},
            "eigen_hold_false": {"method": "sgd_sindy", "eigen_hold": False},
            "eigen_false": {"method": "sgd_sindy", "eigen": False},
            "epochs_0": {"method": "sgd_sindy", "epochs": 0},
            "ls_sindy": {"method": "ls_sindy"}}
KEEP = ("trac", "mac_mode1", "mac_mode2", "freq_error_mode1", "freq_error_mode2")


def table(path: Path) -> None:
    """Print the pass counts (families' bars / issue #15's) by variant, noise and family."""
    rows = [json.loads(line) for line in path.read_text().splitlines() if line]
    t: dict[tuple, list[int]] = collections.defaultdict(lambda: [0, 0, 0])
    for r in rows:
        for g in ("all", "soft" if "soft" in r["member"] else "clamped"):
            c = t[(r["variant"], r["noise"], g)]
            c[0] += bool(r.get("passed"))
            c[1] += bool(r.get("issue"))
            c[2] += 1
    noises = sorted({r["noise"] for r in rows})
    for g in ("all", "clamped", "soft"):
        print(g)
        for v in VARIANTS:
            print(f"  {v:18s}", "  ".join(
                f"{n:g} %: {t[(v, n, g)][0]} / {t[(v, n, g)][1]} of {t[(v, n, g)][2]}" for n in noises))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--noise", default="0,1,3")
    ap.add_argument("--step", type=int, default=1)
    ap.add_argument("--offset", type=int, default=0)
    ap.add_argument("--table", action="store_true")
    a = ap.parse_args()
    out = Path(a.out)
    if a.table:
        table(out)
        return
    done = set()
    if out.exists():
        done = {json.loads(line)["key"] for line in out.read_text().splitlines() if line}
    cache = DatasetCache(Path.cwd() / ".cache" / "datasets")
    cells: dict[str, dict] = {"sgd_sindy": {}, "ls_sindy": {}}
    for cell in expand(load_study("studies/families.toml")):
        if cell.scenario.rig == "cantilever" and cell.noise == 0 and cell.identifier in cells:
            cells[cell.identifier][cell.scenario.name] = cell.scenario
    members = sorted(cells["sgd_sindy"])[a.offset::a.step]
    for noise in (float(x) for x in a.noise.split(",")):
        for name in members:
            for var, ident0 in VARIANTS.items():
                key = f"{name}|{noise}|{var}"
                if key in done:
                    continue
                sc = cells[ident0["method"]][name].with_noise(noise)
                row = {"key": key, "member": name, "noise": noise, "variant": var, "status": "ok"}
                t0 = time.perf_counter()
                try:
                    model = plugins.make_identifier({**dict(sc.identify), **ident0}, sc.name)
                    res = run_scenario(sc, cache=cache, model=model)
                    row.update({k: float(res.scores.values.get(k, math.nan)) for k in KEEP})
                    row["passed"] = bool(res.passed)
                    row["failure"] = res.failure or ""
                except Exception as e:  # a crash is recorded, the batch goes on
                    row["status"], row["error"] = "failed", f"{type(e).__name__}: {e}"
                row["issue"], row["misses"] = issue_verdict({**row, "rig": "cantilever"})
                row["time"] = time.perf_counter() - t0
                with out.open("a") as f:
                    f.write(json.dumps(row) + "\n")
                print(f"{key:45s} {'pass' if row.get('passed') else 'fail'} "
                      f"{'issue' if row['issue'] else row['misses']}", flush=True)


if __name__ == "__main__":
    main()
