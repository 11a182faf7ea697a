"""Write the round-28 beam scenarios (benchmarks/unseen/round28/b28_*.toml): cantilevers nobody tuned,
default identifier settings, the families' bars. Run from the repository root:

    python benchmarks/unseen/round28/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments, 1 %
damping, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``, 1 s at 12.8 kHz) with the keys below
changed. Rounds 6-27 drew steel, stainless, aluminium, titanium, brass, phosphor bronze, cast iron,
molybdenum, glass-epoxy, tungsten, magnesium, CFRP, nylon, copper, invar-, beryllium-, lead-, tin- and
nickel-like beams and zinc of 0.15-2 m (1.9 m the longest under 'auto'), 3-45 segments, 1-7 sensors, the
hammer at 0.1-0.9 L and the tip, 1 N-3 kN, 0.01-8 % damping, records of 0.25-15 s at 1-25.6 kHz, soft bases
at 0.2-300 EI/L with cubic fractions 0.001-3. Round 28 draws a longer beam (stainless 2.2 m x 28 mm in 44
segments, mode 1 near 4.6 Hz, under 'auto' on 4 s at 5.12 kHz), materials no round drew: zirconium (E 88
GPa, 6520 kg/m^3) 0.6 m read by six uneven sensors and hit at the one at 0.3 L, silver (83 GPa, 10490
kg/m^3) 0.45 m x 6 mm (mode 1 near 13.5 Hz, just above the default 10 Hz high-pass), tantalum (186 GPa,
16650 kg/m^3) 0.35 m x 20 mm at 16 kHz on 0.6 s, an Inconel-like beam (205 GPa, 8440 kg/m^3) 1 m x 15 mm on
seven uneven sensors at 25.6 kHz under 'auto' on 2 s, PEEK (3.6 GPa, 1320 kg/m^3) 0.2 m x 5 mm at 3 %
damping; the clamped beam at 2.5 % damping under 1 kN, read at 0.25 / 0.6 / 1 L and hit at the one at 0.6 L
under 8 N at 9.6 kHz, read at 0.4 / 0.9 L and hit at the inner one under 4 N on 1.5 s at 10 kHz, at 0.05 %
damping on 3 s at 8 kHz; soft bases at EI/L ratios and cubic fractions between and beyond the drawn ones:
0.22 (0.9), 0.45 (0.35), 0.8 (0.05 under 1.2 kN), 1.25 (0.65, five uneven sensors hit at the one at
0.35 L), 1.9 (0.15 at 20 kHz), 3.3 (0.5 under 6 N at 9.6 kHz), 8 EI/L (0.08), 15 EI/L (1.2), zirconium in
the shipped geometry on 1.5 EI/L (0.28), stainless 1.2 m on 0.95 EI/L (0.22) under 'auto'. Noise 0-5 % and
seeds 191-194 are the studies' (round28_beams*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 6, 13 and 14's beam writers
from round6 import b_make as _ROUND6  # noqa: E402
from round13.b_make import soft  # noqa: E402
from round14.b_make import sensors  # noqa: E402

#: materials (E [Pa], rho [kg/m^3]): zirconium, silver, tantalum, Inconel and PEEK no round drew; stainless
ZR = {"E": 88e9, "rho": 6520.0}
AG = {"E": 83e9, "rho": 10490.0}
TA = {"E": 186e9, "rho": 16650.0}
INCONEL = {"E": 205e9, "rho": 8440.0}
PEEK = {"E": 3.6e9, "rho": 1320.0}
SS = {"E": 193e9, "rho": 8000.0}

_SS22 = {**SS, "length": 2.2, "thickness": 0.028, "n_segments": 44,
         "sensors": sensors((0.3, 0.65, 1.0), 2.2)}
_ZR06 = {**ZR, "length": 0.6, "n_segments": 14,
         "sensors": sensors((0.15, 0.3, 0.5, 0.62, 0.85, 1.0), 0.6)}
_HIT_ZR = {"location": sensors((0.3,), 0.6)[0]}
_AG045 = {**AG, "length": 0.45, "thickness": 0.006, "n_segments": 12}
_TA035 = {**TA, "length": 0.35, "thickness": 0.02, "n_segments": 10}
_INC1 = {**INCONEL, "length": 1.0, "thickness": 0.015, "n_segments": 20,
         "sensors": sensors((0.12, 0.3, 0.45, 0.6, 0.72, 0.88, 1.0), 1.0)}
_PEEK = {**PEEK, "length": 0.2, "thickness": 0.005, "n_segments": 10, "damping_ratio": 0.03}
_S3 = sensors((0.25, 0.6, 1.0))
_S2 = sensors((0.4, 0.9))
_S5U = sensors((0.15, 0.35, 0.55, 0.8, 1.0))
_HIT035 = {"location": _S5U[1]}
_ZR_SHIP = {**ZR}
_SS12 = {**SS, "length": 1.2, "thickness": 0.016, "n_segments": 24,
         "sensors": sensors((0.3, 0.7, 1.0), 1.2)}
_HP = {"highpass_hz": "auto"}

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # lengths, materials and sections no round drew
    "b28_ss_L2p2_t28_hpauto_fs5k12": ("stainless steel 2.2 m x 30 x 28 mm in 44 segments (mode 1 near "
                                      "4.6 Hz), sensors 0.3 / 0.65 / 1 L, under the high-pass 'auto', the "
                                      "hammer at 0.5 s, 4 s at 5.12 kHz",
                                      {**_SS22}, {"duration": 4.0, "sample_rate": 5120.0}, {"start": 0.5},
                                      {**_HP}),
    "b28_zr_L0p6_s6u_hit0p3": ("a zirconium beam (E 88 GPa, 6520 kg/m^3) 0.6 m in 14 segments read by six "
                               "sensors at 0.15 / 0.3 / 0.5 / 0.62 / 0.85 / 1 L, hit at the sensor at 0.3 L, "
                               "2 s", {**_ZR06}, {"duration": 2.0}, {**_HIT_ZR}, {}),
    "b28_ag_L0p45_t6_2s": ("silver (E 83 GPa, 10490 kg/m^3) 0.45 m x 30 x 6 mm in 12 segments (mode 1 near "
                           "13.5 Hz, above the default 10 Hz high-pass), 2 s", {**_AG045}, {"duration": 2.0},
                           {}, {}),
    "b28_ta_L0p35_t20_fs16k": ("tantalum (E 186 GPa, 16650 kg/m^3) 0.35 m x 30 x 20 mm at 16 kHz on 0.6 s",
                               {**_TA035}, {"duration": 0.6, "sample_rate": 16000.0}, {}, {}),
    "b28_inc_L1_t15_s7u_hpauto_fs25k6": ("an Inconel-like beam (E 205 GPa, 8440 kg/m^3) 1 m x 30 x 15 mm "
                                         "in 20 segments (mode 1 near 12 Hz) read by seven uneven sensors, "
                                         "under the high-pass 'auto', the hammer at 0.3 s, 2 s at 25.6 kHz",
                                         {**_INC1}, {"duration": 2.0, "sample_rate": 25600.0}, {"start": 0.3},
                                         {**_HP}),
    "b28_peek_L0p2_t5_z3": ("PEEK (E 3.6 GPa, 1320 kg/m^3) 0.2 m x 30 x 5 mm at 3 % damping (mode 1 near "
                            "33 Hz), 2 s", {**_PEEK}, {"duration": 2.0}, {}, {}),
    # the clamped beam: heavy damping under a heavy hit, light hits at inner sensors, light damping
    "b28_st_z2p5_f1k": ("the shipped beam at 2.5 % damping under a 1 kN hit",
                        {"damping_ratio": 0.025}, {}, {"peak_force": 1000.0}, {}),
    "b28_st_s3_hit0p6_f8_fs9k6": ("the shipped beam read by three sensors at 0.25 / 0.6 / 1 L, an 8 N hit at "
                                  "the one at 0.6 L, at 9.6 kHz", {"sensors": _S3}, {"sample_rate": 9600.0},
                                  {"peak_force": 8.0, "location": _S3[1]}, {}),
    "b28_st_s2_0p4_0p9_f4_fs10k": ("the shipped beam read by two sensors at 0.4 / 0.9 L, a 4 N hit at the "
                                   "inner one, on 1.5 s at 10 kHz", {"sensors": _S2},
                                   {"duration": 1.5, "sample_rate": 10000.0},
                                   {"peak_force": 4.0, "location": _S2[0]}, {}),
    "b28_st_z0p05_3s_fs8k": ("the shipped beam at 0.05 % damping, on 3 s at 8 kHz",
                             {"damping_ratio": 0.0005}, {"duration": 3.0, "sample_rate": 8000.0}, {}, {}),
    # soft bases between and beyond the drawn ones
    "b28_soft_r0p22_cf0p9": ("the shipped beam on k1 = 0.22 EI/L, cubic fraction 0.9",
                             {**soft(0.22, 0.9, {})}, {}, {}, {}),
    "b28_soft_r0p45_cf0p35": ("the shipped beam on k1 = 0.45 EI/L, cubic fraction 0.35",
                              {**soft(0.45, 0.35, {})}, {}, {}, {}),
    "b28_soft_r0p8_cf0p05_f1k2": ("the shipped beam on k1 = 0.8 EI/L, cubic fraction 0.05 at 1.2 kN, under "
                                  "1.2 kN", {**soft(0.8, 0.05, {}, {"peak_force": 1200.0})}, {},
                                  {"peak_force": 1200.0}, {}),
    "b28_soft_r1p25_cf0p65_s5u_hit0p35": ("the shipped beam on k1 = 1.25 EI/L, cubic fraction 0.65 at the "
                                          "hit, five sensors at 0.15 / 0.35 / 0.55 / 0.8 / 1 L, hit at the "
                                          "sensor at 0.35 L",
                                          {**soft(1.25, 0.65, {}, _HIT035), "sensors": _S5U}, {},
                                          {**_HIT035}, {}),
    "b28_soft_r1p9_cf0p15_fs20k": ("the shipped beam on k1 = 1.9 EI/L, cubic fraction 0.15, at 20 kHz",
                                   {**soft(1.9, 0.15, {})}, {"sample_rate": 20000.0}, {}, {}),
    "b28_soft_r3p3_cf0p5_f6_fs9k6": ("the shipped beam on k1 = 3.3 EI/L, cubic fraction 0.5 at 6 N, under "
                                     "6 N at 9.6 kHz", {**soft(3.3, 0.5, {}, {"peak_force": 6.0})},
                                     {"sample_rate": 9600.0}, {"peak_force": 6.0}, {}),
    "b28_soft_r8_cf0p08": ("the shipped beam on k1 = 8 EI/L, cubic fraction 0.08",
                           {**soft(8.0, 0.08, {})}, {}, {}, {}),
    "b28_soft_r15_cf1p2": ("the shipped beam on k1 = 15 EI/L, cubic fraction 1.2",
                           {**soft(15.0, 1.2, {})}, {}, {}, {}),
    "b28_zr_soft_r1p5_cf0p28": ("zirconium in the shipped geometry on k1 = 1.5 EI/L, cubic fraction 0.28",
                                {**_ZR_SHIP, **soft(1.5, 0.28, _ZR_SHIP)}, {}, {}, {}),
    "b28_ss_L1p2_soft_r0p95_cf0p22_hpauto": ("stainless steel 1.2 m x 30 x 16 mm in 24 segments on k1 = 0.95 "
                                             "EI/L, cubic fraction 0.22, under the high-pass 'auto', the "
                                             "hammer at 0.5 s, 3 s", {**_SS12, **soft(0.95, 0.22, _SS12)},
                                             {"duration": 3.0}, {"start": 0.5}, {**_HP}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 28)
