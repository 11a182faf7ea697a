"""Write the round-21 beam scenarios (benchmarks/unseen/round21/b21_*.toml): cantilevers nobody
tuned, default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round21/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments, 1 %
damping, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``, 1 s at 12.8 kHz) with the keys
below changed.  Round 21 draws corners rounds 17-20 did not (they drew 0.15-1.2 m at 6-40 segments,
2-6 sensors with clusters at the root on the clamped beam and at the tip, the hammer at 0.1 / 0.2 /
0.5 / 0.9 L and the tip, 1 N-1 kN, 0.05-4 % damping, records of 0.5-8 s, 1-19.2 kHz, soft bases at
0.5-300 EI/L with cubic fractions 0.001-3, steel, aluminium, titanium, brass, glass-epoxy and
tungsten): a soft base read by three sensors at 0.15 / 0.25 / 0.35 L (the hammer on the outer one),
long thin titanium (0.6 m x 6 mm in 20 segments, mode 1 near 13.6 Hz) and glass-epoxy (0.45 m x 8
mm in 25 segments) with three sensors, the shipped beam in 35 segments, 0.05 % damping on a 0.5 s
record, 8 % damping, the hammer at 0.3 L (steel) and 0.7 L (aluminium), each on a sensor, the
shipped soft base under 300 N and a base by the families' rule (1.2 EI/L, cubic fraction 0.3) under
5 N, a soft base on a 0.5 s record, a 6 s record at 6.4 kHz, 25.6 kHz, two sensors both near
mid-span (0.45 / 0.55 L) on the clamped beam and on a soft base, and glass-epoxy on a 0.8 EI/L base
with cubic fraction 1. A second batch combines them (round21_beams_extra.toml): the shipped soft
base under 5 N (cubic fraction near 0.002) and the rule base under 300 N, 40 segments at 0.05 %
damping, glass-epoxy hit at 0.3 L, 8 % damping read by two mid-span sensors, a soft base on 6 s at
6.4 kHz, aluminium at 25.6 kHz on 0.5 s, and the long titanium beam on a soft base. A third batch
(round21_beams_more.toml): brass 0.5 m hit at 0.3 L, the root-read soft base under 5 N, three
sensors clustered at mid-span (0.4 / 0.5 / 0.6 L, the hammer on the middle one), glass-epoxy at 0.05
% damping on 6 s, a 0.8 EI/L base with cubic fraction 1 under 5 N, and thin aluminium (0.45 m x 5
mm, 30 segments) with two tip sensors. Noise 0 / 0.5 / 1 / 2 / 3 / 4 % and seeds 121-129 are the
studies' (round21_beams*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 6, 13 and 14's beam writers
from round6 import b_make as _ROUND6  # noqa: E402
from round13.b_make import soft  # noqa: E402
from round14.b_make import sensors  # noqa: E402

AL, BRASS, GFRP, TI, SOFT = _ROUND6.AL, _ROUND6.BRASS, _ROUND6.GFRP, _ROUND6.TI, _ROUND6.SOFT
_SROOT3 = sensors((0.15, 0.25, 0.35))
_SMID2 = sensors((0.45, 0.55))
_SMID3 = sensors((0.4, 0.5, 0.6))
_S03 = sensors((0.3, 0.6, 1.0))
_S07 = sensors((0.4, 0.7, 1.0))
_F5, _F300 = {"peak_force": 5.0}, {"peak_force": 300.0}
_TI_LONG = {**TI, "length": 0.6, "thickness": 0.006, "n_segments": 20}
_GF_LONG = {**GFRP, "length": 0.45, "thickness": 0.008, "n_segments": 25}

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # materials and geometry
    "b21_ti_L0p6_t6_n20": ("titanium 0.6 m x 30 x 6 mm in 20 segments (mode 1 near 13.6 Hz)",
                           {**_TI_LONG, "sensors": sensors((0.3, 0.6, 1.0), 0.6)}, {}, {}, {}),
    "b21_gf_L0p45_t8_n25": ("glass-epoxy 0.45 m x 30 x 8 mm in 25 segments (mode 1 near 21 Hz)",
                            {**_GF_LONG, "sensors": sensors((0.3, 0.6, 1.0), 0.45)}, {}, {}, {}),
    "b21_st_n35": ("the shipped beam in 35 segments", {"n_segments": 35}, {}, {}, {}),
    # damping and records
    "b21_st_z0p05_0p5s": ("the shipped beam, 0.05 % damping, a 0.5 s record",
                          {"damping_ratio": 0.0005}, {"duration": 0.5}, {}, {}),
    "b21_st_z8": ("the shipped beam, 8 % damping", {"damping_ratio": 0.08}, {}, {}, {}),
    "b21_st_6s_fs6k4_z0p3": ("the shipped beam, 0.3 % damping, 6 s at 6.4 kHz",
                             {"damping_ratio": 0.003}, {"duration": 6.0, "sample_rate": 6400.0}, {},
                             {}),
    "b21_st_fs25k6": ("the shipped beam at 25.6 kHz", {}, {"sample_rate": 25600.0}, {}, {}),
    # the hammer at 0.3 L and 0.7 L, each on a sensor
    "b21_st_hit0p3": ("the shipped beam, sensors 0.3 / 0.6 / 1 L, the hammer at 0.3 L",
                      {"sensors": _S03}, {}, {"location": _S03[0]}, {}),
    "b21_al_hit0p7": ("aluminium, sensors 0.4 / 0.7 / 1 L, the hammer at 0.7 L",
                      {**AL, "sensors": _S07}, {}, {"location": _S07[1]}, {}),
    # two sensors near mid-span
    "b21_st_s2mid": ("the shipped beam, two sensors 0.45 / 0.55 L, the hammer at 0.55 L",
                     {"sensors": _SMID2}, {}, {"location": _SMID2[1]}, {}),
    # soft bases
    "b21_soft_root3": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3, sensors 0.15 / 0.25 / 0.35 L, the "
        "hammer at 0.35 L", {**soft(1.2, 0.3, {}, {"location": _SROOT3[2]}), "sensors": _SROOT3}, {},
        {"location": _SROOT3[2]}, {},
    ),
    "b21_soft_f300": ("the shipped soft base (k1 2000 N m/rad, k3 2.5e9) under 300 N (6x)",
                      {**SOFT}, {}, {**_F300}, {}),
    "b21_soft_rule_f5": ("the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3 at 5 N, under 5 N",
                         {**soft(1.2, 0.3, {}, _F5)}, {}, {**_F5}, {}),
    "b21_soft_r3_cf0p3_0p5s": ("the shipped beam on k1 = 3 EI/L, cubic fraction 0.3, a 0.5 s record",
                               {**soft(3.0, 0.3, {})}, {"duration": 0.5}, {}, {}),
    "b21_soft_s2mid": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3, two sensors 0.45 / 0.55 L, the hammer "
        "at 0.55 L", {**soft(1.2, 0.3, {}, {"location": _SMID2[1]}), "sensors": _SMID2}, {},
        {"location": _SMID2[1]}, {},
    ),
    "b21_gf_soft_r0p8_cf1": ("glass-epoxy on k1 = 0.8 EI/L, cubic fraction 1",
                             {**GFRP, **soft(0.8, 1.0, GFRP)}, {}, {}, {}),
    # a second batch (round21_beams_extra.toml): the corners above combined
    "b21_soft_f5": ("the shipped soft base (k1 2000 N m/rad, k3 2.5e9) under 5 N (cubic fraction near "
                    "0.002)", {**SOFT}, {}, {**_F5}, {}),
    "b21_soft_rule_f300": ("the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3 at 300 N, under 300 N",
                           {**soft(1.2, 0.3, {}, _F300)}, {}, {**_F300}, {}),
    "b21_st_n40_z0p05": ("the shipped beam in 40 segments, 0.05 % damping",
                         {"n_segments": 40, "damping_ratio": 0.0005}, {}, {}, {}),
    "b21_gf_hit0p3": ("glass-epoxy, sensors 0.3 / 0.6 / 1 L, the hammer at 0.3 L",
                      {**GFRP, "sensors": _S03}, {}, {"location": _S03[0]}, {}),
    "b21_st_z8_s2mid": ("the shipped beam, 8 % damping, two sensors 0.45 / 0.55 L, the hammer at 0.55 L",
                        {"damping_ratio": 0.08, "sensors": _SMID2}, {}, {"location": _SMID2[1]}, {}),
    "b21_soft_r2_cf0p5_6s": ("the shipped beam on k1 = 2 EI/L, cubic fraction 0.5, 0.3 % damping, 6 s at "
                             "6.4 kHz", {**soft(2.0, 0.5, {}), "damping_ratio": 0.003},
                             {"duration": 6.0, "sample_rate": 6400.0}, {}, {}),
    "b21_al_fs25k6_0p5s": ("aluminium at 25.6 kHz on a 0.5 s record", {**AL},
                           {"sample_rate": 25600.0, "duration": 0.5}, {}, {}),
    "b21_ti_soft_r1p2_cf0p3": (
        "titanium 0.6 m x 30 x 6 mm in 20 segments on k1 = 1.2 EI/L, cubic fraction 0.3, sensors 0.3 / 0.6 / "
        "1 L", {**_TI_LONG, **soft(1.2, 0.3, _TI_LONG), "sensors": sensors((0.3, 0.6, 1.0), 0.6)}, {}, {},
        {},
    ),
    # a third batch (round21_beams_more.toml)
    "b21_br_L0p5_n16_hit0p3": (
        "brass 0.5 m in 16 segments (mode 1 near 22 Hz), sensors 0.3 / 0.6 / 1 L, the hammer at 0.3 L",
        {**BRASS, "length": 0.5, "n_segments": 16, "sensors": sensors((0.3, 0.6, 1.0), 0.5)}, {},
        {"location": sensors((0.3,), 0.5)[0]}, {},
    ),
    "b21_soft_root3_f5": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3 at 50 N, sensors 0.15 / 0.25 / 0.35 L, a "
        "5 N hit at 0.35 L", {**soft(1.2, 0.3, {}, {"location": _SROOT3[2]}), "sensors": _SROOT3}, {},
        {"location": _SROOT3[2], **_F5}, {},
    ),
    "b21_st_s3mid_hit0p5": ("the shipped beam, sensors 0.4 / 0.5 / 0.6 L, the hammer at 0.5 L",
                            {"sensors": _SMID3}, {}, {"location": _SMID3[1]}, {}),
    "b21_gf_z0p05_6s": ("glass-epoxy, 0.05 % damping, 6 s at 6.4 kHz", {**GFRP, "damping_ratio": 0.0005},
                        {"duration": 6.0, "sample_rate": 6400.0}, {}, {}),
    "b21_soft_r0p8_cf1_f5": ("the shipped beam on k1 = 0.8 EI/L, cubic fraction 1 at 5 N, under 5 N",
                             {**soft(0.8, 1.0, {}, _F5)}, {}, {**_F5}, {}),
    "b21_al_L0p45_t5_n30_s2tip": (
        "aluminium 0.45 m x 30 x 5 mm in 30 segments, two sensors 0.9 / 1 L",
        {**AL, "length": 0.45, "thickness": 0.005, "n_segments": 30,
         "sensors": sensors((0.9, 1.0), 0.45)}, {}, {}, {},
    ),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 21)
