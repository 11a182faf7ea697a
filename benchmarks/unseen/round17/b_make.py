"""Write the round-17 beam scenarios (benchmarks/unseen/round17/b17_*.toml): cantilevers nobody
tuned, default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round17/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments,
1 % damping, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``, 1 s at 12.8 kHz) with the
keys below changed.  Round 17 goes to corners rounds 3-16 did not draw: the hammer late in the
record (at 0.7-0.8 s of 1 s: 0.2-0.3 s of free decay) and at the record's first sample (start
0); a 1 kN hit and a 1 N one; 8 s records at the full 12.8 kHz (rounds drew 8-15 s at 6.4 kHz
only); 1.5 % damping at 11-12 segments; the hammer on a sensor at 0.75 L with sensors unevenly
spaced (0.15 / 0.75 / 1 L) and three sensors at 0.1 / 0.45 / 1 L; soft bases with the cubic 10x
round 13's rule (fraction 3: the cubic moment three times the linear one at the peak rotation),
at 1 N and at 300 N, and bases between the soft and the clamped regimes (k1 5, 30 and 100 EI/L at
round 13's rule: a stiff base with a small, hard cubic).  Noise 0 / 0.3 / 2 / 5 % and seeds
81-82 are the studies' (round17_beams*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 6, 13 and 14's beam writers
from round6 import b_make as _ROUND6  # noqa: E402
from round13.b_make import L, soft  # noqa: E402
from round14.b_make import sensors  # noqa: E402

BRASS = _ROUND6.BRASS
_UNEVEN = sensors((0.15, 0.75, 1.0))  # the hammer on the 0.75 L one
_HIT075 = {"location": round(0.75 * L, 4)}

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # clamped: the hammer's time and place
    "b17_st_late0p8": ("the shipped beam, the hammer at 0.8 s of the 1 s record (0.2 s of decay)",
                       {}, {}, {"start": 0.8}, {}),
    "b17_st_start0": ("the shipped beam, the hammer at the record's first sample (start 0)",
                      {}, {}, {"start": 0.0}, {}),
    "b17_st_uneven_hit0p75": (
        "the shipped beam, sensors at 0.15 / 0.75 / 1 L, the hammer on the 0.75 L one",
        {"sensors": _UNEVEN}, {}, _HIT075, {},
    ),
    "b17_st_s3_0p1_0p45": ("the shipped beam, sensors at 0.1 / 0.45 / 1 L",
                           {"sensors": sensors((0.1, 0.45, 1.0))}, {}, {}, {}),
    # clamped: forces, records, damping
    "b17_st_f1000": ("the shipped beam, a 1 kN hit", {}, {}, {"peak_force": 1000.0}, {}),
    "b17_st_f1": ("the shipped beam, a 1 N hit", {}, {}, {"peak_force": 1.0}, {}),
    "b17_st_8s_z0p3": ("the shipped beam, 0.3 % damping, 8 s at 12.8 kHz",
                       {"damping_ratio": 0.003}, {"duration": 8.0}, {}, {}),
    "b17_st_n12_z1p5": ("the shipped beam, 12 segments, 1.5 % damping",
                        {"n_segments": 12, "damping_ratio": 0.015}, {}, {}, {}),
    "b17_br_n11_z1p5": ("brass (E 100 GPa, rho 8500), 11 segments, 1.5 % damping",
                        {**BRASS, "n_segments": 11, "damping_ratio": 0.015}, {}, {}, {}),
    # soft bases: the cubic 10x round 13's rule
    "b17_soft_r1p2_cf3": ("the shipped beam on k1 = 1.2 EI/L, cubic fraction 3 (10x the rule)",
                          {**soft(1.2, 3.0, {})}, {}, {}, {}),
    "b17_soft_r1p2_cf3_f1": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 3 at 50 N, a 1 N hit (the cubic "
        "2500x weaker relative to the linear moment)",
        {**soft(1.2, 3.0, {})}, {}, {"peak_force": 1.0}, {},
    ),
    "b17_soft_r1p2_cf0p3_f300_uneven": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3 at 300 N, a 300 N hit on the "
        "0.75 L sensor of 0.15 / 0.75 / 1 L",
        {**soft(1.2, 0.3, {}, {"peak_force": 300.0, **_HIT075}), "sensors": _UNEVEN},
        {}, {"peak_force": 300.0, **_HIT075}, {},
    ),
    "b17_soft_r1p2_cf0p3_late0p7": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3, the hammer at 0.7 s of 1 s",
        {**soft(1.2, 0.3, {})}, {}, {"start": 0.7}, {},
    ),
    "b17_soft_r1p2_cf0p3_8s_z0p3": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3, 0.3 % damping, 8 s at 12.8 kHz",
        {**soft(1.2, 0.3, {}), "damping_ratio": 0.003}, {"duration": 8.0}, {}, {},
    ),
    "b17_soft_r1p2_cf0p3_z1p5_n12": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3, 1.5 % damping, 12 segments",
        {**soft(1.2, 0.3, {}), "damping_ratio": 0.015, "n_segments": 12}, {}, {}, {},
    ),
    # bases between the soft and the clamped regimes
    "b17_soft_r5_cf0p3": ("the shipped beam on k1 = 5 EI/L, cubic fraction 0.3",
                          {**soft(5.0, 0.3, {})}, {}, {}, {}),
    "b17_soft_r30_cf0p3": ("the shipped beam on k1 = 30 EI/L, cubic fraction 0.3",
                           {**soft(30.0, 0.3, {})}, {}, {}, {}),
    "b17_soft_r100_cf0p3": ("the shipped beam on k1 = 100 EI/L, cubic fraction 0.3",
                            {**soft(100.0, 0.3, {})}, {}, {}, {}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 17)
