"""Write the round-23 beam scenarios (benchmarks/unseen/round23/b23_*.toml): cantilevers nobody tuned,
default identifier settings, the families' bars. Run from the repository root:

    python benchmarks/unseen/round23/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments, 1 %
damping, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``, 1 s at 12.8 kHz) with the keys below
changed. Round 23 draws corners rounds 6-22 did not (they drew steel, aluminium, titanium, brass, glass-
epoxy, tungsten, magnesium, CFRP, nylon and copper, 0.15-1.2 m, 3-45 segments, 1-6 sensors, the hammer
at 0.1-0.9 L and the tip, 1 N-1 kN, 0.05-8 % damping, records of 0.5-15 s at 1-25.6 kHz (the binary
rates, 1 / 1.8 / 2 / 5 kHz), soft bases at 0.2-300 EI/L with cubic fractions 0.001-3): two materials no
round drew, a stiff light one (beryllium-like: E 287 GPa, 1850 kg/m^3, mode 1 near 203 Hz, mode 3 near
3.5 kHz) and a soft dense one (lead-like: E 16 GPa, 11340 kg/m^3, mode 1 near 19 Hz on a 2 s record),
zinc (E 108 GPa, 7140 kg/m^3) in 9 segments; the shipped beam in 6 segments under 10 N, in 30 segments
read unevenly at 0.15 / 0.8 / 1 L on a 0.6 s record, at 10 kHz (a rate no round drew, not a power of two
times 100 Hz), hit at 0.7 L (sensors 0.35 / 0.7 / 1 L) under 120 N at 2.5 % damping, and a 0.05 ms pulse
at 25.6 kHz (two samples inside it); beryllium-like at 25.6 kHz; soft bases on new draws: 0.7 EI/L with
cubic fraction 0.55 in 6 segments, 1.5 EI/L with 0.6 (the families' edge) under 120 N, 3.5 EI/L with
0.65 (just outside) under 10 N, 0.4 EI/L with 0.25 (just below the families' 0.5) in 30 segments, the
shipped soft base read by two sensors near the tip (0.8 / 0.95 L, none at it, the hammer on the outer
one), on 0.6 s at 25.6 kHz, brass on 1 EI/L with 0.4 hit at 0.3 L, titanium 0.4 m clamped hit at 0.3 L.
Noise 0.7 / 2 / 4 % and seeds 141-146 are the studies' (round23_beams*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 6, 13 and 14's beam writers
from round6 import b_make as _ROUND6  # noqa: E402
from round13.b_make import soft  # noqa: E402
from round14.b_make import sensors  # noqa: E402

SOFT, TI, BRASS, GFRP = _ROUND6.SOFT, _ROUND6.TI, _ROUND6.BRASS, _ROUND6.GFRP
#: materials no round drew: E [Pa], rho [kg/m^3]
BE = {"E": 287e9, "rho": 1850.0}
PB = {"E": 16e9, "rho": 11340.0}
ZN = {"E": 108e9, "rho": 7140.0}
_S_UNEVEN = sensors((0.15, 0.8, 1.0))
_S07 = sensors((0.35, 0.7, 1.0))
_S_NEARTIP = sensors((0.8, 0.95))
_S03 = sensors((0.3, 0.65, 1.0))
_S_TIP2 = sensors((0.9, 0.95))
_S2 = sensors((0.5, 1.0))
_F10, _F40, _F120 = {"peak_force": 10.0}, {"peak_force": 40.0}, {"peak_force": 120.0}
_TI04 = {**TI, "length": 0.4, "n_segments": 14}

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # materials
    "b23_be": ("a beryllium-like beam (E 287 GPa, 1850 kg/m^3) in the shipped geometry (mode 1 near 203 Hz)",
               {**BE}, {}, {}, {}),
    "b23_be_fs25k6": ("the beryllium-like beam at 25.6 kHz", {**BE}, {"sample_rate": 25600.0}, {}, {}),
    "b23_pb_2s": ("a lead-like beam (E 16 GPa, 11340 kg/m^3) in the shipped geometry (mode 1 near 19 Hz), "
                  "2 s", {**PB}, {"duration": 2.0}, {}, {}),
    "b23_zn_n9": ("a zinc beam (E 108 GPa, 7140 kg/m^3) in 9 segments", {**ZN, "n_segments": 9}, {}, {}, {}),
    "b23_ti_L0p4_hit0p3": ("titanium 0.4 m in 14 segments, sensors 0.3 / 0.65 / 1 L, the hammer at 0.3 L",
                           {**_TI04, "sensors": sensors((0.3, 0.65, 1.0), 0.4)}, {},
                           {"location": sensors((0.3,), 0.4)[0]}, {}),
    # chains, sensors, records
    "b23_st_n6_f10": ("the shipped beam in 6 segments under 10 N", {"n_segments": 6}, {}, {**_F10}, {}),
    "b23_st_n30_uneven_0p6s": ("the shipped beam in 30 segments, sensors 0.15 / 0.8 / 1 L, a 0.6 s record",
                               {"n_segments": 30, "sensors": _S_UNEVEN}, {"duration": 0.6}, {}, {}),
    "b23_st_fs10k": ("the shipped beam at 10 kHz", {}, {"sample_rate": 10000.0}, {}, {}),
    "b23_st_z2p5_hit0p7_f120": ("the shipped beam at 2.5 % damping, sensors 0.35 / 0.7 / 1 L, a 120 N hit at "
                                "0.7 L", {"damping_ratio": 0.025, "sensors": _S07}, {},
                                {"location": _S07[1], **_F120}, {}),
    "b23_st_pulse0p05ms": ("the shipped beam at 25.6 kHz hit by a 0.05 ms pulse", {},
                           {"sample_rate": 25600.0}, {"pulse_duration": 5e-5}, {}),
    # soft bases, new draws of the families' range and just outside it
    "b23_soft_r0p7_cf0p55_n6": ("the shipped beam in 6 segments on k1 = 0.7 EI/L, cubic fraction 0.55",
                                {"n_segments": 6, **soft(0.7, 0.55, {})}, {}, {}, {}),
    "b23_soft_r1p5_cf0p6_f120": ("the shipped beam on k1 = 1.5 EI/L, cubic fraction 0.6 at 120 N, under "
                                 "120 N",
                                 {**soft(1.5, 0.6, {}, _F120)}, {}, {**_F120}, {}),
    "b23_soft_r3p5_cf0p65_f10": ("the shipped beam on k1 = 3.5 EI/L, cubic fraction 0.65 at 10 N, under 10 N",
                                 {**soft(3.5, 0.65, {}, _F10)}, {}, {**_F10}, {}),
    "b23_soft_r0p4_cf0p25_n30": ("the shipped beam in 30 segments on k1 = 0.4 EI/L, cubic fraction 0.25",
                                 {"n_segments": 30, **soft(0.4, 0.25, {})}, {}, {}, {}),
    # (the tip hammer with no sensor at the tip is refused by the scenario in one line: "allowed: 0 (= tip)
    # or a sensor position, within 1 mm")
    "b23_soft_s2neartip": ("the shipped soft base read by two sensors near the tip, 0.8 / 0.95 L, the hammer "
                           "at 0.95 L", {**SOFT, "sensors": _S_NEARTIP}, {}, {"location": _S_NEARTIP[1]}, {}),
    "b23_soft_fs25k6_0p6s": ("the shipped soft base at 25.6 kHz on a 0.6 s record", {**SOFT},
                             {"sample_rate": 25600.0, "duration": 0.6}, {}, {}),
    "b23_br_soft_r1_cf0p4_hit0p3": (
        "brass on k1 = 1 EI/L, cubic fraction 0.4 at 0.3 L, sensors 0.3 / 0.65 / 1 L, the hammer at 0.3 L",
        {**BRASS, **soft(1.0, 0.4, BRASS, {"location": _S03[0]}), "sensors": _S03}, {}, {"location": _S03[0]},
        {},
    ),
    # a second batch (round23_beams_extra.toml)
    # (with three sensors at 6.4 and 3.2 kHz the scenario refuses the 'auto' low-pass in one line: between
    # modes 3 and 4, 4.9 kHz, above the Nyquist frequency)
    "b23_be_fs6k4_s2": ("the beryllium-like beam at 6.4 kHz, two sensors 0.5 / 1 L (mode 3 near 3.5 kHz "
                        "above the Nyquist frequency, folded near 2.9 kHz above the 'auto' low-pass)",
                        {**BE, "sensors": _S2}, {"sample_rate": 6400.0}, {}, {}),
    "b23_be_fs3k2_s2_lp1k5": ("the beryllium-like beam at 3.2 kHz, two sensors 0.5 / 1 L, a 1.5 kHz "
                              "low-pass (mode 2 near 1.27 kHz, mode 3 folded near 360 Hz, between modes 1 "
                              "and 2), a 1 ms hammer", {**BE, "sensors": _S2}, {"sample_rate": 3200.0},
                              {"pulse_duration": 1e-3}, {"lowpass_hz": 1500.0}),
    "b23_st_s2_0p9_0p95": ("the shipped beam read by two sensors 16 mm apart near the tip, 0.9 / 0.95 L, the "
                           "hammer at 0.95 L", {"sensors": _S_TIP2}, {}, {"location": _S_TIP2[1]}, {}),
    "b23_st_3s_z0p3_f40": ("the shipped beam at 0.3 % damping under 40 N, a 3 s record",
                           {"damping_ratio": 0.003}, {"duration": 3.0}, {**_F40}, {}),
    "b23_soft_r2_cf0p3_fs6k4_0p6s": ("the shipped beam on k1 = 2 EI/L, cubic fraction 0.3 at 40 N, under "
                                     "40 N, 0.6 s at 6.4 kHz", {**soft(2.0, 0.3, {}, _F40)},
                                     {"sample_rate": 6400.0, "duration": 0.6}, {**_F40}, {}),
    "b23_gf_n9_s3uneven": ("glass-epoxy in 9 segments, sensors 0.15 / 0.8 / 1 L",
                           {**GFRP, "n_segments": 9, "sensors": _S_UNEVEN}, {}, {}, {}),
    # a third batch (round23_beams_more.toml)
    "b23_pb_soft_r3_cf0p3_2s": ("the lead-like beam on k1 = 3 EI/L, cubic fraction 0.3 (mode 1 near 12.6 Hz, "
                                "just above the 10 Hz high-pass), 2 s", {**PB, **soft(3.0, 0.3, PB)},
                                {"duration": 2.0}, {}, {}),
    "b23_pb_soft_r2_cf0p1_2s": ("the lead-like beam on k1 = 2 EI/L, cubic fraction 0.1 (mode 1 near the 10 "
                                "Hz high-pass), 2 s", {**PB, **soft(2.0, 0.1, PB)}, {"duration": 2.0}, {},
                                {}),
    "b23_soft_r0p7_z2p5_hit0p3": ("the shipped beam on k1 = 0.7 EI/L, cubic fraction 0.3 at 0.3 L, 2.5 % "
                                  "damping, sensors 0.3 / 0.65 / 1 L, the hammer at 0.3 L",
                                  {**soft(0.7, 0.3, {}, {"location": _S03[0]}), "damping_ratio": 0.025,
                                   "sensors": _S03}, {}, {"location": _S03[0]}, {}),
    "b23_st_n9_s4uneven": ("the shipped beam in 9 segments, four sensors 0.2 / 0.45 / 0.8 / 1 L",
                           {"n_segments": 9, "sensors": sensors((0.2, 0.45, 0.8, 1.0))}, {}, {}, {}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 23)
