"""Write the round-26 beam scenarios (benchmarks/unseen/round26/b26_*.toml): cantilevers nobody tuned,
default identifier settings, the families' bars. Run from the repository root:

    python benchmarks/unseen/round26/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments, 1 %
damping, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``, 1 s at 12.8 kHz) with the keys below
changed. Rounds 6-25 drew steel, aluminium, titanium, brass, glass-epoxy, tungsten, magnesium, CFRP, nylon,
copper, beryllium-, lead-, tin- and nickel-like beams and zinc of 0.15-1.8 m, 3-45 segments, 1-7 sensors,
the hammer at 0.1-0.9 L and the tip, 1 N-2 kN, 0.02-8 % damping, records of 0.3-15 s at 1-25.6 kHz, soft
bases at 0.2-300 EI/L with cubic fractions 0.001-3. Round 26 draws materials no round used (stainless
steel, phosphor bronze, grey cast iron, molybdenum) and copper / magnesium at lengths and sections not
drawn: a short thin copper strip (0.25 m x 6 mm at 25.6 kHz on 0.5 s), stainless 0.8 m under 'auto',
magnesium 2 m x 20 mm in 30 segments at 6.4 kHz under 'auto' (5 s, the hammer at 0.5 s), a thick bronze
bar (20 mm) at 25.6 kHz on 0.5 s, thin stainless (4 mm) read by two sensors on 2 s, molybdenum 0.45 m read
by five uneven sensors and hit at the one at 0.8 L; the clamped beam read by seven uneven sensors under 2 N
hit at the one at 0.6 L at 25.6 kHz, under 3 kN at 0.1 % damping hit at 0.5 L (read at 0.25 / 0.5 / 1 L),
at 3 % damping at 6.4 kHz on 0.25 s; soft bases
at 0.35 EI/L (cubic fraction 0.01, 0.3 % damping, 2 s), 0.75 (0.8, two sensors, hit at the inner one), 1.3
(0.25, five uneven sensors, hit at the one at 0.55 L), 3 (0.05 under 2 kN at 25.6 kHz on 0.5 s), 5 (0.5 under
5 N), 6 EI/L (0.3 at 6.4 kHz), copper 0.5 m on 2 EI/L (0.7), stainless on 1.2 EI/L (0.35) on a 0.25 s
record, cast iron on 0.45 EI/L (0.2). Noise 0-5 % and seeds 171-179 are the studies'
(round26_beams*.toml). A hammer between sensors (molybdenum at 0.68 L, 0.72 L on seven sensors,
0.45 L on five) is refused when loaded, one line and right: "key 'excitation.location': value 0.306: allowed:
0 (= tip) or a sensor position, within 1 mm (...; the impact at 0.306 m is 54 mm from the nearest): a model
in sensor coordinates cannot place a force between sensors". So are seven sensors at 12.8 kHz under the
low-pass 'auto' (its cut-off between modes 7 and 8, 11342 Hz, above Nyquist; the line names the 22684 Hz
rate that admits it).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 6, 13 and 14's beam writers
from round6 import b_make as _ROUND6  # noqa: E402
from round13.b_make import soft  # noqa: E402
from round14.b_make import sensors  # noqa: E402

#: materials no earlier round drew (E [Pa], rho [kg/m^3]), and copper / magnesium (rounds 10, 22)
SS = {"E": 193e9, "rho": 8000.0}
BRONZE = {"E": 110e9, "rho": 8800.0}
IRON = {"E": 110e9, "rho": 7200.0}
MO = {"E": 329e9, "rho": 10220.0}
CU = {"E": 117e9, "rho": 8960.0}
MG = {"E": 45e9, "rho": 1740.0}

_CU025 = {**CU, "length": 0.25, "thickness": 0.006, "n_segments": 10}
_SS08 = {**SS, "length": 0.8, "n_segments": 16, "sensors": sensors((1 / 3, 2 / 3, 1.0), 0.8)}
_MG2 = {**MG, "length": 2.0, "thickness": 0.02, "n_segments": 30, "sensors": sensors((0.3, 0.65, 1.0), 2.0)}
_BZ_THICK = {**BRONZE, "thickness": 0.02}
_S2_04 = sensors((0.4, 1.0))
_SS_THIN = {**SS, "thickness": 0.004, "sensors": _S2_04}
_MO045 = {**MO, "length": 0.45, "n_segments": 12,
          "sensors": sensors((0.15, 0.3, 0.55, 0.8, 1.0), 0.45)}
_HIT_MO = {"location": sensors((0.8,), 0.45)[0]}
_S3H = sensors((0.25, 0.5, 1.0))
_S7U = sensors((0.1, 0.2, 0.35, 0.5, 0.6, 0.85, 1.0))
_HIT06 = {"location": _S7U[4]}
_S5U = sensors((0.15, 0.3, 0.55, 0.8, 1.0))
_HIT055 = {"location": _S5U[2]}
_S2_05 = sensors((0.5, 1.0))
_HIT05 = {"location": _S2_05[0]}
_CU05 = {**CU, "length": 0.5, "n_segments": 14, "sensors": sensors((1 / 3, 2 / 3, 1.0), 0.5)}
_F2, _F5 = {"peak_force": 2.0}, {"peak_force": 5.0}
_F2K, _F3K = {"peak_force": 2000.0}, {"peak_force": 3000.0}
_FAST, _SLOW = {"sample_rate": 25600.0}, {"sample_rate": 6400.0}
_HP = {"highpass_hz": "auto"}

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # materials and sections no round drew
    "b26_cu_L0p25_t6_fs25k6": ("copper 0.25 m x 30 x 6 mm in 10 segments at 25.6 kHz on 0.5 s", {**_CU025},
                               {"duration": 0.5, **_FAST}, {}, {}),
    "b26_ss_L0p8_hpauto": ("stainless steel 0.8 m in 16 segments (mode 1 near 12 Hz) under the high-pass "
                           "'auto', the hammer at 0.5 s, 3 s", {**_SS08}, {"duration": 3.0}, {"start": 0.5},
                           {**_HP}),
    "b26_mg_L2_t20_fs6k4_hpauto": ("magnesium 2 m x 30 x 20 mm in 30 segments (mode 1 near 4 Hz), sensors "
                                   "0.3 / 0.65 / 1 L, at 6.4 kHz under the high-pass 'auto', the hammer at "
                                   "0.5 s, 5 s", {**_MG2}, {"duration": 5.0, **_SLOW}, {"start": 0.5},
                                   {**_HP}),
    "b26_bz_t20_fs25k6": ("phosphor bronze in the shipped length, 20 mm thick (mode 1 near 113 Hz), at 25.6 "
                          "kHz on 0.5 s", {**_BZ_THICK}, {"duration": 0.5, **_FAST}, {}, {}),
    "b26_ss_t4_s2_2s": ("stainless steel 4 mm thin (mode 1 near 32 Hz) read by two sensors at 0.4 / 1 L, 2 s",
                        {**_SS_THIN}, {"duration": 2.0}, {}, {}),
    "b26_mo_L0p45_s5u_hit0p8": ("molybdenum 0.45 m in 12 segments read by five sensors at 0.15 / 0.3 / 0.55 "
                                 "/ 0.8 / 1 L, hit at the sensor at 0.8 L", {**_MO045}, {}, {**_HIT_MO},
                                 {}),
    # the clamped beam: seven uneven sensors, a hard hit, heavy damping on a short record
    "b26_st_s7u_f2_hit0p6_fs25k6": ("the shipped beam read by seven sensors at 0.1 / 0.2 / 0.35 / 0.5 / "
                                    "0.6 / 0.85 / 1 L, a 2 N hit at the sensor at 0.6 L, at 25.6 kHz",
                                    {"sensors": _S7U}, {**_FAST},
                              {**_F2, **_HIT06}, {}),
    "b26_st_f3k_z0p1_hit0p5": ("the shipped beam at 0.1 % damping read at 0.25 / 0.5 / 1 L, a 3 kN hit at "
                               "0.5 L", {"damping_ratio": 0.001, "sensors": _S3H}, {},
                               {**_F3K, "location": _S3H[1]}, {}),
    "b26_st_z3_fs6k4_0p25s": ("the shipped beam at 3 % damping, at 6.4 kHz on 0.25 s",
                              {"damping_ratio": 0.03},
                              {"duration": 0.25, **_SLOW}, {}, {}),
    # soft bases between and beyond the drawn ones
    "b26_soft_r0p35_cf0p01_z0p3_2s": ("the shipped beam on k1 = 0.35 EI/L, cubic fraction 0.01, 0.3 % "
                                      "damping, 2 s", {**soft(0.35, 0.01, {}), "damping_ratio": 0.003},
                                      {"duration": 2.0}, {}, {}),
    "b26_soft_r0p75_cf0p8_s2_hit0p5": ("the shipped beam on k1 = 0.75 EI/L, cubic fraction 0.8 at the hit, "
                                       "two "
                                       "sensors at 0.5 / 1 L, hit at the inner one",
                                       {**soft(0.75, 0.8, {}, _HIT05), "sensors": _S2_05}, {}, {**_HIT05},
                                       {}),
    "b26_soft_r1p3_cf0p25_s5u_hit0p55": ("the shipped beam on k1 = 1.3 EI/L, cubic fraction 0.25 at the hit, "
                                         "five sensors at 0.15 / 0.3 / 0.55 / 0.8 / 1 L, hit at the sensor "
                                         "at "
                                         "0.55 L",
                                         {**soft(1.3, 0.25, {}, _HIT055), "sensors": _S5U}, {}, {**_HIT055},
                                         {}),
    "b26_soft_r3_cf0p05_f2k_fs25k6": ("the shipped beam on k1 = 3 EI/L, cubic fraction 0.05 at 2 kN, under "
                                      "2 kN at 25.6 kHz on 0.5 s", {**soft(3.0, 0.05, {}, _F2K)},
                                      {"duration": 0.5, **_FAST}, {**_F2K}, {}),
    "b26_soft_r5_cf0p5_f5": ("the shipped beam on k1 = 5 EI/L, cubic fraction 0.5 at 5 N, under 5 N",
                             {**soft(5.0, 0.5, {}, _F5)}, {}, {**_F5}, {}),
    "b26_soft_r6_cf0p3_fs6k4": ("the shipped beam on k1 = 6 EI/L, cubic fraction 0.3, at 6.4 kHz",
                                {**soft(6.0, 0.3, {})}, {**_SLOW}, {}, {}),
    "b26_cu_L0p5_soft_r2_cf0p7": ("copper 0.5 m in 14 segments on k1 = 2 EI/L, cubic fraction 0.7, 2 s",
                                  {**_CU05, **soft(2.0, 0.7, _CU05)}, {"duration": 2.0}, {}, {}),
    "b26_ss_soft_r1p2_cf0p35_0p25s": ("stainless steel in the shipped geometry on k1 = 1.2 EI/L, cubic "
                                      "fraction 0.35, on a 0.25 s record", {**SS, **soft(1.2, 0.35, SS)},
                                      {"duration": 0.25}, {}, {}),
    "b26_fe_soft_r0p45_cf0p2": ("grey cast iron in the shipped geometry on k1 = 0.45 EI/L, cubic fraction "
                                "0.2", {**IRON, **soft(0.45, 0.2, IRON)}, {}, {}, {}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 26)
