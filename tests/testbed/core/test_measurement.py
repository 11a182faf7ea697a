"""testbed.core.measurement's shared rules."""

import numpy as np

from testbed.core.measurement import nearest_within


def test_an_impact_within_tolerance_is_one_rule_up_to_the_positions_round_off():
    # the rig's load check and the structural chain's force map share it (review, session 19:
    # the rig's slack scaled by the largest sensor position, the chain's by the pair, so a hit
    # 1e-16 past 1 mm of an inboard sensor was accepted at load and refused by the chain)
    assert nearest_within(0.3165, np.array([0.1, 0.2, 0.3175]), 1e-3) == (2, abs(0.3165 - 0.3175), True)
    # 9.8e-17 past 1 mm of the inboard sensor: beyond the pair's round-off (4 eps x 0.1 =
    # 8.9e-17), refused by both (the rig had allowed 4 eps x 0.3175 and accepted it)
    i, gap, ok = nearest_within(0.099 - 1e-16, np.array([0.1, 0.2, 0.3175]), 1e-3)
    assert i == 0 and gap > 1e-3 and not ok
    assert not nearest_within(0.0989, np.array([0.1, 0.2, 0.3175]), 1e-3)[2]
