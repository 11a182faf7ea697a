"""Write the round-20 beam scenarios (benchmarks/unseen/round20/b20_*.toml): cantilevers nobody
tuned, default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round20/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments, 1 %
damping, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``, 1 s at 12.8 kHz) with the keys
below changed.  Round 20 draws corners rounds 17-19 did not (the families draw 0.2-0.5 m, 8-30 segments, 2-6
sensors, 10-100 N, 0.2-3 % damping; rounds 17-19 drew 0.45-1.2 m at 8-40 segments, 8 s records, 1
N-1 kN, 0.05-4 % damping, soft bases at 0.5-100 EI/L with cubic fractions 0.001-3): few long
segments (0.6 m in 6 segments of 0.1 m) and many short ones (0.15 m in 30 segments of 5 mm, two
sensors), glass-epoxy at the families' softest material with four sensors clustered at the tip (0.7
/ 0.8 / 0.9 / 1 L), six sensors evenly on 12 segments (at 19.2 kHz), two sensors both at the tip
(0.9 / 1 L), the hammer near the root (on a sensor at 0.1 L) and near the tip (0.9 L), a 4 s record
at 0.2 % damping, 3.2 kHz (mode 3 at 0.9x the Nyquist frequency; two sensors, a 0.6 ms pulse), a
thick section (20 mm, outside the families' 6-15 mm); soft bases: the shipped base (k1 2000 N m/rad,
k3 2.5e9) under 0.3x and 3x the shipped 50 N (15 / 150 N), a tiny cubic fraction (0.01) on k1 2
EI/L, a base of 300 EI/L (near the clamped beam) with cubic fraction 0.3, and the hammer near the
root on a 5 EI/L base.  Later batches combine them (round20_beams_extra.toml), sample at 1 and
2.4 kHz with no low-pass so that a scored mode lies above the Nyquist frequency
(round20_beams_band.toml), and add an aluminium plate (80 x 3 mm), a 0.5 EI/L base at 0.1 %
damping on 3 s, a soft base read only at 0.1 / 0.2 L and three sensors near the root
(round20_beams_more.toml).  Noise 0 / 0.5 / 1 / 3 / 5 % and seeds 111-118 are the studies'
(round20_beams*.toml).

Refused at load in one line each, so written with the keys that make them valid (the refusals are
right: the chain cannot low-pass above the Nyquist frequency, and a force no sample sees cannot be
simulated against): 0.15 m with the default three sensors and six sensors at 12.8 kHz (the
``'auto'`` low-pass between the last sensed mode and the next at 9.1 / 8.3 kHz, above 6.4 kHz), and
the 0.3 ms pulse at 3.2 kHz (no sample inside it).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 6, 13 and 14's beam writers
from round6 import b_make as _ROUND6  # noqa: E402
from round13.b_make import soft  # noqa: E402
from round14.b_make import sensors  # noqa: E402

AL, GFRP, SOFT = _ROUND6.AL, _ROUND6.GFRP, _ROUND6.SOFT
_S4TIP = sensors((0.7, 0.8, 0.9, 1.0))
_S6 = sensors((1 / 6, 2 / 6, 3 / 6, 4 / 6, 5 / 6, 1.0))
_S2TIP = sensors((0.9, 1.0))
_SROOT = sensors((0.1, 0.5, 1.0))
_S09 = sensors((0.3, 0.9, 1.0))
_SROOT2 = sensors((0.2, 0.6, 1.0))
_F15, _F150 = {"peak_force": 15.0}, {"peak_force": 150.0}

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # segment counts and lengths
    "b20_st_L0p6_n6": ("steel 0.6 m in 6 segments of 0.1 m (mode 1 near 23 Hz)",
                       {"length": 0.6, "n_segments": 6}, {}, {}, {}),
    "b20_st_L0p15_n30_s2_0p5s": ("steel 0.15 m in 30 segments of 5 mm (mode 1 near 370 Hz), sensors "
                                 "0.5 / 1 L, 0.5 s", {"length": 0.15, "n_segments": 30,
                                                      "sensors": sensors((0.5, 1.0), 0.15)},
                                 {"duration": 0.5}, {}, {}),
    "b20_st_t20": ("the shipped beam 20 mm thick (mode 1 near 166 Hz)", {"thickness": 0.02}, {}, {},
                   {}),
    # sensors
    "b20_gf_s4tip": ("glass-epoxy, four sensors 0.7 / 0.8 / 0.9 / 1 L",
                     {**GFRP, "sensors": _S4TIP}, {}, {}, {}),
    "b20_st_n12_s6_fs19k2": ("the shipped beam in 12 segments, six sensors evenly 1/6 ... 1 L, 19.2 kHz",
                             {"n_segments": 12, "sensors": _S6}, {"sample_rate": 19200.0}, {}, {}),
    "b20_st_s2tip": ("the shipped beam, two sensors 0.9 / 1 L", {"sensors": _S2TIP}, {}, {}, {}),
    # the hammer near the root and near the tip
    "b20_st_hit0p1": ("the shipped beam, sensors 0.1 / 0.5 / 1 L, the hammer at 0.1 L",
                      {"sensors": _SROOT}, {}, {"location": _SROOT[0]}, {}),
    "b20_al_hit0p9": ("aluminium, sensors 0.3 / 0.9 / 1 L, the hammer at 0.9 L",
                      {**AL, "sensors": _S09}, {}, {"location": _S09[1]}, {}),
    # records
    "b20_st_4s_z0p2": ("the shipped beam, 0.2 % damping, 4 s", {"damping_ratio": 0.002},
                       {"duration": 4.0}, {}, {}),
    "b20_st_fs3k2_s2": ("the shipped beam at 3.2 kHz (mode 3 near 1.45 kHz, 0.9x the Nyquist "
                        "frequency), sensors 0.5 / 1 L, a 0.6 ms pulse",
                        {"sensors": sensors((0.5, 1.0))}, {"sample_rate": 3200.0},
                        {"pulse_duration": 6e-4}, {}),
    # soft bases
    "b20_soft_f15": ("the shipped soft base (k1 2000 N m/rad, k3 2.5e9) under 15 N (0.3x)",
                     {**SOFT}, {}, {**_F15}, {}),
    "b20_soft_f150": ("the shipped soft base (k1 2000 N m/rad, k3 2.5e9) under 150 N (3x)",
                      {**SOFT}, {}, {**_F150}, {}),
    "b20_soft_r2_cf0p01": ("the shipped beam on k1 = 2 EI/L, cubic fraction 0.01",
                           {**soft(2.0, 0.01, {})}, {}, {}, {}),
    "b20_soft_r300_cf0p3": ("the shipped beam on k1 = 300 EI/L, cubic fraction 0.3",
                            {**soft(300.0, 0.3, {})}, {}, {}, {}),
    "b20_soft_r5_hit0p2": (
        "the shipped beam on k1 = 5 EI/L, cubic fraction 0.3, sensors 0.2 / 0.6 / 1 L, the hammer at "
        "0.2 L", {**soft(5.0, 0.3, {}, {"location": _SROOT2[0]}), "sensors": _SROOT2}, {},
        {"location": _SROOT2[0]}, {},
    ),
    # a second batch (round20_beams_extra.toml): the corners above combined
    "b20_soft_r1p2_cf0p3_z0p5_4s": ("the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3, 0.5 % damping, "
                                    "4 s", {**soft(1.2, 0.3, {}), "damping_ratio": 0.005},
                                    {"duration": 4.0}, {}, {}),
    "b20_gf_soft_r1p2_cf0p3_s2tip": (
        "glass-epoxy on k1 = 1.2 EI/L, cubic fraction 0.3, two sensors 0.9 / 1 L",
        {**GFRP, **soft(1.2, 0.3, GFRP), "sensors": _S2TIP}, {}, {}, {},
    ),
    "b20_soft_r300_cf0p3_n12_s6_fs19k2": (
        "the shipped beam in 12 segments on k1 = 300 EI/L, cubic fraction 0.3, six sensors evenly, "
        "19.2 kHz", {"n_segments": 12, **soft(300.0, 0.3, {"n_segments": 12}), "sensors": _S6},
        {"sample_rate": 19200.0}, {}, {},
    ),
    "b20_soft_r0p5_cf0p01_f15": ("the shipped beam on k1 = 0.5 EI/L, cubic fraction 0.01, under 15 N",
                                 {**soft(0.5, 0.01, {}, _F15)}, {}, {**_F15}, {}),
    "b20_st_L0p6_n6_s4tip_4s": (
        "steel 0.6 m in 6 segments, four sensors 0.7 / 0.8 / 0.9 / 1 L, 4 s",
        {"length": 0.6, "n_segments": 6, "sensors": sensors((0.7, 0.8, 0.9, 1.0), 0.6)},
        {"duration": 4.0}, {}, {},
    ),
    "b20_al_L0p5_n8_hit0p1_f150": (
        "aluminium 0.5 m in 8 segments, sensors 0.1 / 0.5 / 1 L, a 150 N hit at 0.1 L",
        {**AL, "length": 0.5, "n_segments": 8, "sensors": sensors((0.1, 0.5, 1.0), 0.5)}, {},
        {"location": round(0.05, 4), **_F150}, {},
    ),
    "b20_st_s2_hit0p1_z3": ("the shipped beam, sensors 0.1 / 1 L, the hammer at 0.1 L, 3 % damping",
                            {"sensors": sensors((0.1, 1.0)), "damping_ratio": 0.03}, {},
                            {"location": _SROOT[0]}, {}),
    "b20_st_f15_fs6k4_4s": ("the shipped beam under 15 N at 6.4 kHz, 4 s", {},
                            {"sample_rate": 6400.0, "duration": 4.0}, {**_F15}, {}),
    # records whose chain leaves a scored mode out (round20_beams_band.toml): the scorer's reasons
    "b20_st_fs1k_s2_nolp": ("the shipped beam at 1 kHz with no low-pass (mode 2 near 517 Hz above the "
                            "500 Hz Nyquist frequency), sensors 0.5 / 1 L, a 2 ms pulse",
                            {"sensors": sensors((0.5, 1.0))}, {"sample_rate": 1000.0},
                            {"pulse_duration": 2e-3}, {"lowpass_hz": 0.0}),
    "b20_st_fs2k4_nolp": ("the shipped beam at 2.4 kHz with no low-pass (mode 3 near 1.45 kHz above the "
                          "1.2 kHz Nyquist frequency), a 0.6 ms pulse", {}, {"sample_rate": 2400.0},
                          {"pulse_duration": 6e-4}, {"lowpass_hz": 0.0}),
    # a third batch (round20_beams_more.toml)
    "b20_soft_r1p2_cf0p3_root2": ("the shipped soft base (rule), sensors 0.1 / 0.2 L only, the hammer at "
                                  "0.2 L",
                                  {**soft(1.2, 0.3, {}, {"location": sensors((0.2,))[0]}),
                                   "sensors": sensors((0.1, 0.2))}, {},
                                  {"location": sensors((0.2,))[0]}, {}),
    "b20_al_plate_80x3": ("aluminium plate 80 x 3 mm, 0.3175 m", {**AL, "width": 0.08, "thickness": 0.003},
                          {}, {"peak_force": 15.0}, {}),
    "b20_soft_r0p5_cf0p6_z0p1_3s": ("the shipped beam on k1 = 0.5 EI/L, cubic fraction 0.6, 0.1 % damping, "
                                    "3 s",
                                    {**soft(0.5, 0.6, {}), "damping_ratio": 0.001}, {"duration": 3.0},
                                    {}, {}),
    "b20_st_s4root_tip": ("the shipped beam, sensors 0.25 / 0.3 / 0.35 / 1 L (three near the root), "
                          "hammer at the tip", {"sensors": sensors((0.25, 0.3, 0.35, 1.0))}, {}, {}, {}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 20)
