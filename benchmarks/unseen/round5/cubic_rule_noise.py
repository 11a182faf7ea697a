"""Round 5 (beams): the cubic rule's statistic per scenario at 0 / 0.5 / 1 / 2 % noise.

Not a test: prints, per scenario file, the largest partial correlation of an x^3 column with
the linear model's residual (:func:`identify._cubic_rule.cubic_rule`, the value its rule string
states) on the scenario's own signal chain at each noise level (the scenario's seed), against
``CUBIC_SELECT_CORR``.  No identifier is fitted.

    PYTHONPATH=$PWD .venv/bin/python benchmarks/unseen/round5/cubic_rule_noise.py FILE.toml ...
"""

from __future__ import annotations

import re
import sys

from identify._cubic_rule import CUBIC_SELECT_CORR, cubic_rule
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure

NOISE_PERCENT = (0.0, 0.5, 1.0, 2.0)


def main(files: list[str]) -> None:
    cache = DatasetCache()
    print(f"noise % {NOISE_PERCENT}; cubic terms in above {CUBIC_SELECT_CORR:g}")
    for f in files:
        base = load_scenario(f)
        corr = []
        for n in NOISE_PERCENT:
            sc = base.with_noise(n)
            _, rule = cubic_rule(measure(cache.get(sc), sc.signal, sc.kind), None)
            corr.append(float(re.search(r"residual ([0-9.e+-]+)", rule)[1]))
        print(base.name, " ".join(f"{c:.3f}" for c in corr), flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
