"""Round 5 (beams): the cubic rule's statistic per scenario at 0 / 0.5 / 1 / 2 % noise.

Not a test: prints, per scenario file, the cubic rule's statistic (the lowest measured mode's
backbone chirp ``c / wd``, :func:`identify._cubic_rule.cubic_rule`, the value its rule string
states; NaN where no decay fit was taken) on the scenario's own signal chain at each noise level
(the scenario's seed), against ``CUBIC_CHIRP_MIN``.  No identifier is fitted.  (Until
2026-11-27 the rule's statistic was a partial correlation against 0.65; see
identify/_cubic_rule.py.)

    PYTHONPATH=$PWD .venv/bin/python benchmarks/unseen/round5/cubic_rule_noise.py FILE.toml ...
"""

from __future__ import annotations

import re
import sys

from identify._cubic_rule import CUBIC_CHIRP_MIN, cubic_rule
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure

NOISE_PERCENT = (0.0, 0.5, 1.0, 2.0)


def main(files: list[str]) -> None:
    cache = DatasetCache()
    print(f"noise % {NOISE_PERCENT}; cubic terms in above {CUBIC_CHIRP_MIN:g}")
    for f in files:
        base = load_scenario(f)
        corr = []
        for n in NOISE_PERCENT:
            sc = base.with_noise(n)
            _, rule = cubic_rule(measure(cache.get(sc), sc.signal, sc.kind), None)
            found = re.search(r"c / wd ([0-9.e+-]+)", rule)
            corr.append(float(found[1]) if found else float("nan"))
        print(base.name, " ".join(f"{c:+.4f}" for c in corr), flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
