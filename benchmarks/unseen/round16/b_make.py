"""Write the round-16 beam scenarios (benchmarks/unseen/round16/b16_*.toml): cantilevers nobody
tuned, default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round16/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments,
1 % damping, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``, 1 s at 12.8 kHz) with the
keys below changed.  Round 16 goes to corners rounds 3-15 did not draw: 6-8 segments (the
coarsest chains yet drawn with three sensors) and 32-40 with five or six sensors; a polymer
(E 2.5 GPa, rho 1200) and titanium / aluminium at 6-8 segments; a thin wide strip (50 x 2 mm)
and a near-square section (15 x 14 mm); four sensors clustered within 0.2 L of the root (none
at the tip); 0.2 % and 8 % damping; hammer pulses of 0.1 ms and 2 ms; 5 N and 150 N on clamped
bases; soft bases (round 13's ``soft``) with k1 so low that the base mode lies under the
chain's default 10 Hz high-pass (0.03 EI/L: 6.8 Hz), with that high-pass and with ``'auto'``.
Noise 0 / 0.5 / 3 % and seeds 71-72 are the studies' (round16_beams*.toml).
Refused by the rig when written at first (one line, physically right): six sensors on the
near-square steel beam at 12.8 kHz (mode 6 at 9.9 kHz above the 6.4 kHz Nyquist); written at
25.6 kHz instead.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 6, 13 and 14's beam writers
from round6 import b_make as _ROUND6  # noqa: E402
from round13.b_make import L, soft  # noqa: E402
from round14.b_make import sensors  # noqa: E402

AL, TI = _ROUND6.AL, _ROUND6.TI
#: a polymer (an acetal / PMMA-like glassy polymer): E [Pa], rho [kg/m^3]
POLY = {"E": 2.5e9, "rho": 1200.0}
S3 = sensors((1 / 3, 2 / 3, 1.0))
_HP = {"highpass_hz": "auto"}  # mode 1 of 7-25 Hz: the default 10 Hz high-pass would cut it (round 6)
_STRIP = {**AL, "width": 0.05, "thickness": 0.002, "length": 0.3}  # mode 1 about 18 Hz
_SQUARE = {"width": 0.015, "thickness": 0.014}  # mode 1 about 116 Hz
_POLY = {**POLY, "length": 0.3}  # mode 1 about 26 Hz (10 mm thick)

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # clamped: materials, sections, segment counts
    "b16_ti_n7": ("titanium, 7 segments, sensors 1/3, 2/3, 1 L", {**TI, "n_segments": 7, "sensors": S3},
                  {}, {}, {}),
    "b16_poly_n8_2s": (
        "a polymer (E 2.5 GPa, rho 1200) 0.3 m, 8 segments (mode 1 about 26 Hz), 2 s, high-pass 'auto'",
        {**_POLY, "n_segments": 8, "sensors": sensors((1 / 3, 2 / 3, 1.0), 0.3)},
        {"duration": 2.0}, {"peak_force": 5.0}, _HP,
    ),
    "b16_al_strip_n6_2s": (
        "an aluminium strip 0.3 m x 50 x 2 mm (mode 1 about 18 Hz), 6 segments, a 2 N hit, 2 s, "
        "high-pass 'auto'",
        {**_STRIP, "n_segments": 6, "sensors": sensors((1 / 3, 2 / 3, 1.0), 0.3)},
        {"duration": 2.0}, {"peak_force": 2.0}, _HP,
    ),
    "b16_st_square_n40_s6": (
        "steel 15 x 14 mm (near-square), 40 segments, six sensors 1/6-1 L, at 25.6 kHz (at 12.8 kHz "
        "the 'auto' low-pass between modes 6 and 7, 11.6 kHz, lies above Nyquist and the rig "
        "refuses it)",
        {**_SQUARE, "n_segments": 40, "sensors": sensors((1 / 6, 2 / 6, 3 / 6, 4 / 6, 5 / 6, 1.0))},
        {"sample_rate": 25600.0}, {}, {},
    ),
    "b16_ti_n32_s5": (
        "titanium, 32 segments, five sensors 0.2-1 L",
        {**TI, "n_segments": 32, "sensors": sensors((0.2, 0.4, 0.6, 0.8, 1.0))},
        {}, {}, {},
    ),
    "b16_st_root4": (
        "the shipped beam, 20 segments, four sensors at 0.05 / 0.1 / 0.15 / 0.2 L (none at the "
        "tip), the hammer on the 0.2 L one",
        {"n_segments": 20, "sensors": sensors((0.05, 0.1, 0.15, 0.2))},
        {}, {"location": round(0.2 * L, 4)}, {},
    ),
    # clamped: damping, pulses, forces
    "b16_st_z0p2_n8": ("the shipped beam, 8 segments, 0.2 % damping",
                       {"n_segments": 8, "damping_ratio": 0.002}, {}, {}, {}),
    "b16_st_z8": ("the shipped beam, 8 % damping", {"damping_ratio": 0.08}, {}, {}, {}),
    "b16_st_p0p1ms": ("the shipped beam, a 0.1 ms pulse at 25.6 kHz", {}, {"sample_rate": 25600.0},
                      {"pulse_duration": 1e-4}, {}),
    "b16_st_p2ms": ("the shipped beam, a 2 ms pulse", {}, {}, {"pulse_duration": 2e-3}, {}),
    "b16_st_f5": ("the shipped beam, a 5 N hit", {}, {}, {"peak_force": 5.0}, {}),
    "b16_al_f150_n36_s5": (
        "aluminium, 36 segments, five sensors 0.2-1 L, a 150 N hit",
        {**AL, "n_segments": 36, "sensors": sensors((0.2, 0.4, 0.6, 0.8, 1.0))},
        {}, {"peak_force": 150.0}, {},
    ),
    # soft bases
    "b16_soft_r0p03_hp10_3s": (
        "the shipped beam on k1 = 0.03 EI/L (base mode about 6.8 Hz), cubic fraction 0.3, 3 s, the "
        "chain's default 10 Hz high-pass",
        {**soft(0.03, 0.3, {})}, {"duration": 3.0}, {}, {},
    ),
    "b16_soft_r0p03_hpauto_3s": (
        "the shipped beam on k1 = 0.03 EI/L (base mode about 6.8 Hz), cubic fraction 0.3, 3 s, "
        "high-pass 'auto'",
        {**soft(0.03, 0.3, {})}, {"duration": 3.0}, {}, _HP,
    ),
    "b16_soft_r0p06_hp10_3s": (
        "the shipped beam on k1 = 0.06 EI/L (base mode about 9.6 Hz), cubic fraction 0.3, 3 s, the "
        "chain's default 10 Hz high-pass",
        {**soft(0.06, 0.3, {})}, {"duration": 3.0}, {}, {},
    ),
    "b16_soft_al_r1_n7": (
        "aluminium on k1 = 1 EI/L, cubic fraction 0.3, 7 segments",
        {**AL, "n_segments": 7, **soft(1.0, 0.3, AL)}, {}, {}, {},
    ),
    "b16_soft_ti_r1_z0p2_n36_s5": (
        "titanium on k1 = 1 EI/L, cubic fraction 0.3, 0.2 % damping, 36 segments, five sensors",
        {**TI, "n_segments": 36, "damping_ratio": 0.002, **soft(1.0, 0.3, TI),
         "sensors": sensors((0.2, 0.4, 0.6, 0.8, 1.0))},
        {}, {}, {},
    ),
    "b16_soft_r1p2_z8": ("the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3, 8 % damping",
                         {**soft(1.2, 0.3, {}), "damping_ratio": 0.08}, {}, {}, {}),
    "b16_soft_r1p2_p2ms": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3 (at the 2 ms pulse), a 2 ms pulse",
        {**soft(1.2, 0.3, {}, {"pulse_duration": 2e-3})}, {}, {"pulse_duration": 2e-3}, {},
    ),
    "b16_soft_r1p2_f5_root4": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3 (at 5 N), a 5 N hit, 20 segments, "
        "four sensors at 0.05-0.2 L, the hammer on the 0.2 L one",
        {"n_segments": 20, **soft(1.2, 0.3, {}, {"peak_force": 5.0, "location": round(0.2 * L, 4)}),
         "sensors": sensors((0.05, 0.1, 0.15, 0.2))},
        {}, {"peak_force": 5.0, "location": round(0.2 * L, 4)}, {},
    ),
    "b16_soft_poly_r1_n8_2s": (
        "the polymer 0.3 m on k1 = 1 EI/L, cubic fraction 0.3, 8 segments, a 5 N hit, 2 s, "
        "high-pass 'auto'",
        {**_POLY, "n_segments": 8, **soft(1.0, 0.3, _POLY, {"peak_force": 5.0}),
         "sensors": sensors((1 / 3, 2 / 3, 1.0), 0.3)},
        {"duration": 2.0}, {"peak_force": 5.0}, _HP,
    ),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 16)
