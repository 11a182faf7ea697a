"""Write the round-27 beam scenarios (benchmarks/unseen/round27/b27_*.toml): cantilevers nobody tuned,
default identifier settings, the families' bars. Run from the repository root:

    python benchmarks/unseen/round27/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments, 1 %
damping, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``, 1 s at 12.8 kHz) with the keys below
changed. Rounds 6-26 drew steel, stainless, aluminium, titanium, brass, phosphor bronze, cast iron,
molybdenum, glass-epoxy, tungsten, magnesium, CFRP, nylon, copper, beryllium-, lead-, tin- and nickel-like
beams and zinc of 0.15-2 m, 3-45 segments, 1-7 sensors, the hammer at 0.1-0.9 L and the tip, 1 N-3 kN,
0.02-8 % damping, records of 0.25-15 s at 1-25.6 kHz, soft bases at 0.2-300 EI/L with cubic fractions
0.001-3. Round 27 draws the longest beam yet (stainless 1.9 m x 25 mm in 38 segments, mode 1 near 5.5 Hz,
under 'auto' on 4 s), an invar-like beam (E 141 GPa, 8050 kg/m^3; no round drew it) 0.7 m read by five
uneven sensors and hit at the one at 0.4 L, copper 1.2 m x 12 mm on four uneven sensors under 'auto', thin
magnesium (3 mm) on 2 s, stainless at the slender bound (0.3 m x 33.9 mm: thickness 0.113 L, the schema's
edge) at 25.6 kHz on 0.5 s, brass 0.9 m at 2 % damping at 6.4 kHz, titanium 0.25 m x 4 mm at 19.2 kHz on
0.3 s; the clamped beam at 0.01 % damping on 5 s at 6.4 kHz, read by two sensors at 0.7 / 1 L under 2 N hit
at the inner one at 25.6 kHz; soft bases at EI/L ratios and cubic fractions between and beyond the drawn
ones: 0.3 (0.45), 0.65 (0.12, 3 % damping), 1.1 (0.02 under 2.5 kN), 1.4 (0.55, four uneven sensors hit at
the one at 0.45 L), 2.1 (0.75 under 3 N at 25.6 kHz on 0.5 s), 4.5 (0.25 at 6.4 kHz), 2.8 (0.18, magnesium
in the shipped geometry), copper 1 m on 0.85 EI/L (0.3) under 'auto', stainless 1.5 m on 1.7 EI/L (0.4)
under 'auto'. Noise 0-5 % and seeds 181-184 are the studies' (round27_beams*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 6, 13 and 14's beam writers
from round6 import b_make as _ROUND6  # noqa: E402
from round13.b_make import soft  # noqa: E402
from round14.b_make import sensors  # noqa: E402

#: materials (E [Pa], rho [kg/m^3]): invar no round drew; stainless, copper, magnesium, brass, titanium
INVAR = {"E": 141e9, "rho": 8050.0}
SS = {"E": 193e9, "rho": 8000.0}
CU = {"E": 117e9, "rho": 8960.0}
MG = {"E": 45e9, "rho": 1740.0}
BRASS = {"E": 100e9, "rho": 8500.0}
TI = {"E": 114e9, "rho": 4430.0}

_SS19 = {**SS, "length": 1.9, "thickness": 0.025, "n_segments": 38,
         "sensors": sensors((0.35, 0.7, 1.0), 1.9)}
_INV07 = {**INVAR, "length": 0.7, "n_segments": 16,
          "sensors": sensors((0.2, 0.4, 0.6, 0.75, 1.0), 0.7)}
_HIT_INV = {"location": sensors((0.4,), 0.7)[0]}
_CU12 = {**CU, "length": 1.2, "thickness": 0.012, "n_segments": 24,
         "sensors": sensors((0.25, 0.55, 0.8, 1.0), 1.2)}
_MG_THIN = {**MG, "thickness": 0.003}
_SS_EDGE = {**SS, "length": 0.3, "thickness": 0.0339}
_BR09 = {**BRASS, "length": 0.9, "n_segments": 18, "damping_ratio": 0.02,
         "sensors": sensors((1 / 3, 2 / 3, 1.0), 0.9)}
_TI025 = {**TI, "length": 0.25, "thickness": 0.004, "n_segments": 10}
_S2_07 = sensors((0.7, 1.0))
_S4U = sensors((0.2, 0.45, 0.7, 1.0))
_HIT045 = {"location": _S4U[1]}
_CU1 = {**CU, "length": 1.0, "n_segments": 20, "sensors": sensors((1 / 3, 2 / 3, 1.0), 1.0)}
_SS15 = {**SS, "length": 1.5, "thickness": 0.02, "n_segments": 30,
         "sensors": sensors((0.3, 0.65, 1.0), 1.5)}
_F2, _F3 = {"peak_force": 2.0}, {"peak_force": 3.0}
_F2K5 = {"peak_force": 2500.0}
_FAST, _SLOW = {"sample_rate": 25600.0}, {"sample_rate": 6400.0}
_HP = {"highpass_hz": "auto"}

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # lengths, materials and sections no round drew
    "b27_ss_L1p9_t25_hpauto": ("stainless steel 1.9 m x 30 x 25 mm in 38 segments (mode 1 near 5.5 Hz), "
                               "sensors 0.35 / 0.7 / 1 L, under the high-pass 'auto', the hammer at 0.5 s, "
                               "4 s",
                               {**_SS19}, {"duration": 4.0}, {"start": 0.5}, {**_HP}),
    "b27_inv_L0p7_s5u_hit0p4": ("an invar-like beam (E 141 GPa, 8050 kg/m^3) 0.7 m in 16 segments read by "
                                "five sensors at 0.2 / 0.4 / 0.6 / 0.75 / 1 L, hit at the sensor at 0.4 L, "
                                "2 s",
                                {**_INV07}, {"duration": 2.0}, {**_HIT_INV}, {}),
    "b27_cu_L1p2_t12_s4u_hpauto": ("copper 1.2 m x 30 x 12 mm in 24 segments (mode 1 near 6.6 Hz) read by "
                                   "four sensors at 0.25 / 0.55 / 0.8 / 1 L under the high-pass 'auto', the "
                                   "hammer at 0.5 s, 3 s", {**_CU12}, {"duration": 3.0}, {"start": 0.5},
                                   {**_HP}),
    "b27_mg_t3_2s": ("magnesium in the shipped length, 3 mm thin (mode 1 near 27 Hz), 2 s", {**_MG_THIN},
                     {"duration": 2.0}, {}, {}),
    "b27_ss_L0p3_t33p9_fs25k6": ("stainless steel 0.3 m x 30 x 33.9 mm, at the slender bound (thickness "
                                 "0.113 L; mode 1 near 300 Hz), at 25.6 kHz on 0.5 s", {**_SS_EDGE},
                                 {"duration": 0.5, **_FAST}, {}, {}),
    "b27_br_L0p9_z2_fs6k4_2s": ("brass 0.9 m in 18 segments at 2 % damping, at 6.4 kHz on 2 s", {**_BR09},
                                {"duration": 2.0, **_SLOW}, {}, {}),
    "b27_ti_L0p25_t4_fs19k2_0p3s": ("titanium 0.25 m x 30 x 4 mm at 19.2 kHz on 0.3 s", {**_TI025},
                                    {"duration": 0.3, "sample_rate": 19200.0}, {}, {}),
    # the clamped beam: the lightest damping on a long record, two sensors under a light hit
    "b27_st_z0p01_5s_fs6k4": ("the shipped beam at 0.01 % damping, at 6.4 kHz on 5 s",
                              {"damping_ratio": 0.0001}, {"duration": 5.0, **_SLOW}, {}, {}),
    "b27_st_s2_f2_hit0p7_fs25k6": ("the shipped beam read by two sensors at 0.7 / 1 L, a 2 N hit at the "
                                   "inner one, at 25.6 kHz", {"sensors": _S2_07}, {**_FAST},
                                   {**_F2, "location": _S2_07[0]}, {}),
    # soft bases between and beyond the drawn ones
    "b27_soft_r0p3_cf0p45": ("the shipped beam on k1 = 0.3 EI/L, cubic fraction 0.45",
                             {**soft(0.3, 0.45, {})}, {}, {}, {}),
    "b27_soft_r0p65_cf0p12_z3": ("the shipped beam on k1 = 0.65 EI/L, cubic fraction 0.12, 3 % damping",
                                 {**soft(0.65, 0.12, {}), "damping_ratio": 0.03}, {}, {}, {}),
    "b27_soft_r1p1_cf0p02_f2k5": ("the shipped beam on k1 = 1.1 EI/L, cubic fraction 0.02 at 2.5 kN, under "
                                  "2.5 kN", {**soft(1.1, 0.02, {}, _F2K5)}, {}, {**_F2K5}, {}),
    "b27_soft_r1p4_cf0p55_s4u_hit0p45": ("the shipped beam on k1 = 1.4 EI/L, cubic fraction 0.55 at the hit, "
                                         "four sensors at 0.2 / 0.45 / 0.7 / 1 L, hit at the sensor at "
                                         "0.45 L",
                                         {**soft(1.4, 0.55, {}, _HIT045), "sensors": _S4U}, {}, {**_HIT045},
                                         {}),
    "b27_soft_r2p1_cf0p75_f3_fs25k6": ("the shipped beam on k1 = 2.1 EI/L, cubic fraction 0.75 at 3 N, under "
                                       "3 N at 25.6 kHz on 0.5 s", {**soft(2.1, 0.75, {}, _F3)},
                                       {"duration": 0.5, **_FAST}, {**_F3}, {}),
    "b27_soft_r4p5_cf0p25_fs6k4": ("the shipped beam on k1 = 4.5 EI/L, cubic fraction 0.25, at 6.4 kHz",
                                   {**soft(4.5, 0.25, {})}, {**_SLOW}, {}, {}),
    "b27_mg_soft_r2p8_cf0p18": ("magnesium in the shipped geometry on k1 = 2.8 EI/L, cubic fraction 0.18",
                                {**MG, **soft(2.8, 0.18, MG)}, {}, {}, {}),
    "b27_cu_L1_soft_r0p85_cf0p3_hpauto": ("copper 1 m in 20 segments on k1 = 0.85 EI/L, cubic fraction 0.3, "
                                          "under the high-pass 'auto', the hammer at 0.5 s, 3 s",
                                          {**_CU1, **soft(0.85, 0.3, _CU1)}, {"duration": 3.0},
                                          {"start": 0.5}, {**_HP}),
    "b27_ss_L1p5_soft_r1p7_cf0p4_hpauto": ("stainless steel 1.5 m x 30 x 20 mm in 30 segments on k1 = 1.7 "
                                           "EI/L, cubic fraction 0.4, under the high-pass 'auto', the hammer "
                                           "at 0.5 s, 3 s", {**_SS15, **soft(1.7, 0.4, _SS15)},
                                           {"duration": 3.0}, {"start": 0.5}, {**_HP}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 27)
