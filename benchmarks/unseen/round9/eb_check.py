"""Round 9 (beams): each rig's chain truth against Euler-Bernoulli (the truth's own cross-check).

Not a test: prints, per scenario file, the chain's first three undamped frequencies (the truth
the scorer holds) against Euler-Bernoulli's, solved independently of the rig by
``round5/truth_floor.py`` (boundary determinant; clamped, or a root hinge on the base's linear
spring), and the truth's damping ratios of the sensed modes.  Uses the dataset cache (run the
sweep first, or it simulates).

    PYTHONPATH=$PWD .venv/bin/python benchmarks/unseen/round9/eb_check.py FILE.toml ...
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np

from testbed.core.truth import StructuralTruth
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.scenario import load_scenario

_SPEC = importlib.util.spec_from_file_location(
    "truth_floor", Path(__file__).resolve().parents[1] / "round5" / "truth_floor.py")
_FLOOR = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(_FLOOR)


def main(files: list[str]) -> None:
    cache = DatasetCache()
    for f in files:
        sc = load_scenario(f)
        tr = cache.get(sc).truth_as(StructuralTruth)
        r = sc.rig_params
        k1 = r["base_k1"] if r["base"] == "soft" else np.inf
        eb = _FLOOR.eb_frequencies(r["E"], r["width"] * r["thickness"] ** 3 / 12,
                                   r["rho"] * r["width"] * r["thickness"], r["length"], k1)
        dev = 100 * (np.asarray(tr.frequencies_hz[:3]) / eb - 1)
        n = len(r["sensors"]) or 3
        print(f"{sc.name}: EB {np.round(eb, 1)} Hz, chain off {np.round(dev, 3)} %, zeta of the "
              f"{n} sensed modes {np.round(np.asarray(tr.damping_ratios[:n]), 3)}", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
