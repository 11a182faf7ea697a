"""Write the round-15 beam scenarios (benchmarks/unseen/round15/b15_*.toml): cantilevers nobody
tuned, default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round15/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments,
1 % damping, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``, 1 s at 12.8 kHz) with the
keys below changed.  Round 15 goes to corners rounds 3-14 did not draw: sample rates of 3.2 kHz and
25.6 kHz; records of 0.3 s and 4 s; very stiff short beams (mode 1 at 210-820 Hz) and very flexible
long ones (mode 1 at 2.4-2.6 Hz clamped); the hammer at 0.3 L (on a sensor there); two sensors only,
both in the outer half; soft bases (round 13's ``soft``: the cubic fraction at the families'
estimated peak base rotation) at the rule's middle (0.3) and at its extremes (0.02 and 1.0)
with 3-5 % damping.  Not written, the rig refuses them when the study loads (one line each):
the hammer inside a sensor's segment but 6 mm off the sensor (sensors 0.3 / 0.7 / 1.0 L, the
hit at 0.32 L: "a model in sensor coordinates cannot place a force between sensors"); the
0.3 ms pulse at 3.2 kHz (no sample inside it); three sensors at 3.2 kHz on the shipped beam
and steel 0.2 m (the 'auto' low-pass above Nyquist); three sensors on aluminium 0.1 m at
25.6 kHz (mode 3 at 14.3 kHz above the 12.8 kHz Nyquist).  Noise 0 / 1 / 2 % and seeds 61-62
are the studies' (round15_beams*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 6, 13 and 14's beam writers
from round6 import b_make as _ROUND6  # noqa: E402
from round13.b_make import L, soft  # noqa: E402
from round14.b_make import sensors  # noqa: E402

AL = _ROUND6.AL
#: polyamide (nylon): E [Pa], rho [kg/m^3] (round 13's)
PA = {"E": 2.7e9, "rho": 1140.0}
FS_LOW, FS_HIGH = {"sample_rate": 3200.0}, {"sample_rate": 25600.0}
#: at 3.2 kHz the families' 0.3 ms pulse falls between two samples and the rig refuses it
#: (the force channel records point samples): a 0.8 ms pulse (a softer tip; the half-sine's
#: first spectral zero at 1.9 kHz, above the 1.6 kHz Nyquist) [s]
LOW_PULSE = {"pulse_duration": 8e-4}
#: at 3.2 kHz three sensors put the 'auto' low-pass (between modes 3 and 4) above the Nyquist
#: frequency and the rig refuses it (the shipped beam: sqrt(1454 x 2850) = 2036 Hz against
#: 1600 Hz): two sensors, 0.5 / 1.0 L (the low-pass between modes 2 and 3, 867 Hz)
S2 = sensors((0.5, 1.0))
SHORT, LONG = {"duration": 0.3}, {"duration": 4.0}

_ST02 = {"length": 0.2}  # mode 1 about 209 Hz
_AL01 = {**AL, "length": 0.1}  # mode 1 about 817 Hz
_AL1 = {**AL, "length": 1.0, "thickness": 0.003}  # mode 1 about 2.45 Hz
_PA07 = {**PA, "length": 0.7, "thickness": 0.005}  # mode 1 about 2.5 Hz
_AL08 = {**AL, "length": 0.8, "thickness": 0.004}  # mode 1 about 5.1 Hz clamped
_HP = {"highpass_hz": "auto"}  # the default 10 Hz high-pass would cut a 2.5 Hz mode 1 (round 6)

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # clamped
    "b15_st_fs3k2": (
        "the shipped beam, sensors 0.5 / 1.0 L, at 3.2 kHz",
        {"sensors": S2},
        FS_LOW,
        LOW_PULSE,
        {},
    ),
    "b15_st_fs25k6_0p3s_n16": (
        "the shipped beam, 16 segments, 0.3 s at 25.6 kHz",
        {"n_segments": 16},
        {**FS_HIGH, **SHORT},
        {},
        {},
    ),
    "b15_st_4s_fs3k2_z0p3": (
        "the shipped beam at 0.3 % damping, sensors 0.5 / 1.0 L, 4 s at 3.2 kHz",
        {"damping_ratio": 0.003, "sensors": S2},
        {**FS_LOW, **LONG},
        LOW_PULSE,
        {},
    ),
    "b15_st_h0p3_0p3s": (
        "the shipped beam, sensors 0.3 / 0.7 / 1.0 L, the hammer on the 0.3 L one, 0.3 s",
        {"sensors": sensors((0.3, 0.7, 1.0))},
        SHORT,
        {"location": round(0.3 * L, 4)},
        {},
    ),
    "b15_st_s2_outer": (
        "the shipped beam, two sensors 0.6 / 1.0 L",
        {"sensors": sensors((0.6, 1.0))},
        {},
        {},
        {},
    ),
    "b15_st_s2_outer_h0p8": (
        "the shipped beam, two sensors 0.55 / 0.8 L (none at the tip), the hammer on the 0.8 L one",
        {"sensors": sensors((0.55, 0.8))},
        {},
        {"location": round(0.8 * L, 4)},
        {},
    ),
    "b15_short_st_L0p2_4s": ("steel 0.2 m (mode 1 209 Hz, mode 2 1.31 kHz), 4 s", _ST02, LONG, {}, {}),
    "b15_short_al_L0p1_fs25k6_0p3s": (
        "aluminium 0.1 m (mode 1 817 Hz, mode 2 5.1 kHz), sensors 0.5 / 1.0 L "
        "(with three, mode 3 at 14.3 kHz lies above the 12.8 kHz Nyquist "
        "and the rig refuses the 'auto' low-pass), 0.3 s at 25.6 kHz",
        {**_AL01, "sensors": sensors((0.5, 1.0), 0.1)},
        {**FS_HIGH, **SHORT},
        {},
        {},
    ),
    "b15_long_al_L1_t3_4s": (
        "aluminium 1 m x 30 x 3 mm (mode 1 2.45 Hz), 16 segments, a 0.5 N hit, "
        "4 s at 3.2 kHz, high-pass 'auto'",
        {**_AL1, "n_segments": 16},
        {**FS_LOW, **LONG},
        {"peak_force": 0.5, **LOW_PULSE},
        _HP,
    ),
    "b15_long_pa_L0p7_t5_4s": (
        "polyamide 0.7 m x 30 x 5 mm (mode 1 2.5 Hz), 14 segments, a 0.5 N hit, "
        "sensors 0.6 / 1.0 L, 4 s at 3.2 kHz, high-pass 'auto'",
        {**_PA07, "n_segments": 14, "sensors": sensors((0.6, 1.0), 0.7)},
        {**FS_LOW, **LONG},
        {"peak_force": 0.5, **LOW_PULSE},
        _HP,
    ),
    # soft bases
    "b15_soft_r1p2_cf0p3_fs3k2": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3, sensors 0.5 / 1.0 L, 2 s at 3.2 kHz",
        {**soft(1.2, 0.3, {}, LOW_PULSE), "sensors": S2},
        {**FS_LOW, "duration": 2.0},
        LOW_PULSE,
        {},
    ),
    "b15_soft_r1p2_cf0p02_z4": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.02, 4 % damping",
        {**soft(1.2, 0.02, {}), "damping_ratio": 0.04},
        {},
        {},
        {},
    ),
    "b15_soft_r1p2_cf1_z4": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 1.0, 4 % damping",
        {**soft(1.2, 1.0, {}), "damping_ratio": 0.04},
        {},
        {},
        {},
    ),
    "b15_soft_r0p5_cf1_z3_4s": (
        "the shipped beam on k1 = 0.5 EI/L, cubic fraction 1.0, 3 % damping, "
        "sensors 0.5 / 1.0 L, 4 s at 3.2 kHz",
        {**soft(0.5, 1.0, {}, LOW_PULSE), "damping_ratio": 0.03, "sensors": S2},
        {**FS_LOW, **LONG},
        LOW_PULSE,
        {},
    ),
    "b15_soft_r2_cf0p02_z5_0p3s": (
        "the shipped beam on k1 = 2 EI/L, cubic fraction 0.02, 5 % damping, 0.3 s at 25.6 kHz",
        {**soft(2.0, 0.02, {}), "damping_ratio": 0.05},
        {**FS_HIGH, **SHORT},
        {},
        {},
    ),
    "b15_soft_r1_cf0p3_s2_outer": (
        "the shipped beam on k1 = 1 EI/L, cubic fraction 0.3, two sensors 0.6 / 1.0 L",
        {**soft(1.0, 0.3, {}), "sensors": sensors((0.6, 1.0))},
        {},
        {},
        {},
    ),
    "b15_soft_r1p5_cf0p3_h0p3": (
        "the shipped beam on k1 = 1.5 EI/L, cubic fraction 0.3, sensors 0.3 / "
        "0.7 / 1.0 L, the hammer on the 0.3 L one",
        {**soft(1.5, 0.3, {}, {"location": round(0.3 * L, 4)}), "sensors": sensors((0.3, 0.7, 1.0))},
        {},
        {"location": round(0.3 * L, 4)},
        {},
    ),
    "b15_soft_short_st_L0p2_cf0p3": (
        "steel 0.2 m on k1 = 1.2 EI/L, cubic fraction 0.3 (mode 1 under the clamped 209 Hz)",
        {**_ST02, **soft(1.2, 0.3, _ST02)},
        {},
        {},
        {},
    ),
    "b15_soft_long_al_L0p8_cf0p3": (
        "aluminium 0.8 m x 30 x 4 mm on k1 = 1 EI/L, cubic fraction 0.3, "
        "14 segments, a 2 N hit, 4 s at 3.2 kHz, high-pass 'auto'",
        {**_AL08, "n_segments": 14, **soft(1.0, 0.3, _AL08, {"peak_force": 2.0, **LOW_PULSE})},
        {**FS_LOW, **LONG},
        {"peak_force": 2.0, **LOW_PULSE},
        _HP,
    ),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 15)
