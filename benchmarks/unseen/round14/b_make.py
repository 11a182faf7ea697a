"""Write the round-14 beam scenarios (benchmarks/unseen/round14/b14_*.toml): cantilevers nobody
tuned, default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round14/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 1 % damping,
50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``) recorded for 2-3 s at 6.4 kHz, with the
keys below changed.  Round 14 goes where the families (``studies/families.toml``) and rounds 3-13
did not draw together: 25-40 segments (the families: 8-30); 3-4 sensors, one of them near the
root (0.08-0.15 L) and one at the tip, where the hammer lands; hammer hits of 3 N and 300 N
(0.3x the families' lightest 10 N, 3x their heaviest 100 N); damping of 0.1 % and 5 % on mode 1
(the families: 0.2-3 %); clamped and soft bases.  A soft base's cubic is set as round 13's
(``round13/b_make.py`` ``soft``: a cubic fraction at the families' estimated peak base rotation)
for round 6's 50 N hammer, so a 300 N hit drives it about 36x further into the cubic (the
rotation 6x) and a 3 N hit leaves it practically linear.  Noise 0.5 / 2 / 3 % and seeds 51-54
are the studies' (round14_beams_noise*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 6 and 13's beam writers
from round6 import b_make as _ROUND6  # noqa: E402
from round13.b_make import L, soft  # noqa: E402

AL, TI, BRASS, GFRP = _ROUND6.AL, _ROUND6.TI, _ROUND6.BRASS, _ROUND6.GFRP
#: round 14's record: 2 s at 6.4 kHz
SIM = {"duration": 2.0, "sample_rate": 6400.0}
#: 0.3x the families' lightest hammer, 3x their heaviest [N]
LIGHT, HEAVY = {"peak_force": 3.0}, {"peak_force": 300.0}


def sensors(fractions: tuple[float, ...], length: float = L) -> list[float]:
    """Sensor positions [m] at ``fractions`` of ``length``, rounded to 0.1 mm."""
    return [round(f * length, 4) for f in fractions]


def sim(**kw) -> dict:
    """Round 14's record with ``kw`` changed."""
    return {**SIM, **kw}


_AL04 = {**AL, "length": 0.4}
_TI03 = {**TI, "length": 0.3, "width": 0.025}
_BR = {**BRASS, "length": 0.35, "thickness": 0.008}
_GF = {**GFRP, "length": 0.3, "width": 0.025, "thickness": 0.008}
_ST05 = {"length": 0.5}

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # clamped
    "b14_st_n30_f3": (
        "the shipped beam, 30 segments, sensors 0.1 / 0.5 / 1.0 L, a 3 N hit",
        {"n_segments": 30, "sensors": sensors((0.1, 0.5, 1.0))},
        sim(),
        LIGHT,
        {},
    ),
    "b14_st_n30_f300": (
        "the shipped beam, 30 segments, sensors 0.1 / 0.5 / 1.0 L, a 300 N hit",
        {"n_segments": 30, "sensors": sensors((0.1, 0.5, 1.0))},
        sim(),
        HEAVY,
        {},
    ),
    "b14_st_z0p1_n25_3s": (
        "the shipped beam at 0.1 % damping, 25 segments, sensors 0.12 / 0.55 / 1.0 L, 3 s",
        {"n_segments": 25, "damping_ratio": 0.001, "sensors": sensors((0.12, 0.55, 1.0))},
        sim(duration=3.0),
        {},
        {},
    ),
    "b14_st_z5_s4_n28": (
        "the shipped beam at 5 % damping, 28 segments, sensors 0.1 / 0.4 / 0.7 / 1.0 L, "
        "12.8 kHz (mode 4 at 2.9 kHz)",
        {"n_segments": 28, "damping_ratio": 0.05, "sensors": sensors((0.1, 0.4, 0.7, 1.0))},
        sim(sample_rate=12800.0),
        {},
        {},
    ),
    "b14_al_n40_s4": (
        "aluminium 0.4 m x 30 x 10 mm, 40 segments, sensors 0.08 / 0.4 / 0.7 / 1.0 L",
        {**_AL04, "n_segments": 40, "sensors": sensors((0.08, 0.4, 0.7, 1.0), 0.4)},
        sim(),
        {},
        {},
    ),
    "b14_ti_n25_z0p1_f300": (
        "titanium 0.3 m x 25 x 10 mm, 25 segments, 0.1 % damping, a 300 N hit, 3 s",
        {**_TI03, "n_segments": 25, "damping_ratio": 0.001, "sensors": sensors((0.15, 0.6, 1.0), 0.3)},
        sim(duration=3.0),
        HEAVY,
        {},
    ),
    "b14_brass_n32_s3": (
        "brass 0.35 m x 30 x 8 mm, 32 segments, sensors 0.1 / 0.5 / 1.0 L",
        {**_BR, "n_segments": 32, "sensors": sensors((0.1, 0.5, 1.0), 0.35)},
        sim(),
        {},
        {},
    ),
    "b14_gfrp_n28_z5_f3": (
        "glass-epoxy 0.3 m x 25 x 8 mm, 28 segments, 5 % damping, a 3 N hit",
        {**_GF, "n_segments": 28, "damping_ratio": 0.05, "sensors": sensors((0.12, 0.5, 1.0), 0.3)},
        sim(),
        LIGHT,
        {},
    ),
    "b14_st_L0p5_n36_s4": (
        "steel 0.5 m x 30 x 10 mm, 36 segments, sensors 0.1 / 0.35 / 0.65 / 1.0 L",
        {**_ST05, "n_segments": 36, "sensors": sensors((0.1, 0.35, 0.65, 1.0), 0.5)},
        sim(),
        {},
        {},
    ),
    "b14_al_z0p1_f3_3s": (
        "aluminium 0.4 m x 30 x 10 mm, 26 segments, 0.1 % damping, a 3 N hit, 3 s",
        {**_AL04, "n_segments": 26, "damping_ratio": 0.001, "sensors": sensors((0.1, 0.5, 1.0), 0.4)},
        sim(duration=3.0),
        LIGHT,
        {},
    ),
    # soft bases (cubic fraction at round 6's 50 N; the hit below scales it by (F / 50 N)^2)
    "b14_soft_r1p2_cf0p3_f3_n30": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3, 30 segments, "
        "sensors 0.1 / 0.5 / 1.0 L, a 3 N hit",
        {"n_segments": 30, **soft(1.2, 0.3, {}), "sensors": sensors((0.1, 0.5, 1.0))},
        sim(),
        LIGHT,
        {},
    ),
    "b14_soft_r1p2_cf0p03_f300": (
        "the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.03 (about 1.1 at "
        "the 300 N hit), 30 segments, sensors 0.1 / 0.5 / 1.0 L",
        {"n_segments": 30, **soft(1.2, 0.03, {}), "sensors": sensors((0.1, 0.5, 1.0))},
        sim(),
        HEAVY,
        {},
    ),
    "b14_soft_r2_cf0p3_z0p1_3s": (
        "the shipped beam on k1 = 2 EI/L, cubic fraction 0.3, 0.1 % damping, "
        "25 segments, sensors 0.12 / 0.6 / 1.0 L, 3 s",
        {
            "n_segments": 25,
            "damping_ratio": 0.001,
            **soft(2.0, 0.3, {}),
            "sensors": sensors((0.12, 0.6, 1.0)),
        },
        sim(duration=3.0),
        {},
        {},
    ),
    "b14_soft_r0p8_cf0p3_z5": (
        "the shipped beam on k1 = 0.8 EI/L, cubic fraction 0.3, 5 % damping, 26 "
        "segments, sensors 0.1 / 0.5 / 1.0 L",
        {"n_segments": 26, "damping_ratio": 0.05, **soft(0.8, 0.3, {}), "sensors": sensors((0.1, 0.5, 1.0))},
        sim(),
        {},
        {},
    ),
    "b14_soft_r1_cf0p02_f300_s4_n36": (
        "steel 0.5 m on k1 = 1 EI/L, cubic fraction 0.02 (about 0.7 at the "
        "300 N hit), 36 segments, sensors 0.1 / 0.4 / 0.7 / 1.0 L",
        {**_ST05, "n_segments": 36, **soft(1.0, 0.02, _ST05), "sensors": sensors((0.1, 0.4, 0.7, 1.0), 0.5)},
        sim(),
        HEAVY,
        {},
    ),
    "b14_soft_r2p5_cf0p5_n40_s4_z0p1": (
        "aluminium 0.4 m on k1 = 2.5 EI/L, cubic fraction 0.5, 40 segments, "
        "0.1 % damping, sensors 0.08 / 0.4 / 0.7 / 1.0 L",
        {
            **_AL04,
            "n_segments": 40,
            "damping_ratio": 0.001,
            **soft(2.5, 0.5, _AL04),
            "sensors": sensors((0.08, 0.4, 0.7, 1.0), 0.4),
        },
        sim(),
        {},
        {},
    ),
    "b14_soft_al_r1p5_cf0p2_f3_n25": (
        "aluminium 0.4 m on k1 = 1.5 EI/L, cubic fraction 0.2, 25 segments, a 3 N hit, 3 s",
        {**_AL04, "n_segments": 25, **soft(1.5, 0.2, _AL04), "sensors": sensors((0.15, 0.5, 1.0), 0.4)},
        sim(duration=3.0),
        LIGHT,
        {},
    ),
    "b14_soft_ti_r0p6_cf0p05_f300_z5": (
        "titanium 0.3 m x 25 x 10 mm on k1 = 0.6 EI/L, cubic fraction 0.05 "
        "(about 1.8 at the 300 N hit), 5 % damping, 28 segments",
        {
            **_TI03,
            "n_segments": 28,
            "damping_ratio": 0.05,
            **soft(0.6, 0.05, _TI03),
            "sensors": sensors((0.1, 0.5, 1.0), 0.3),
        },
        sim(),
        HEAVY,
        {},
    ),
    "b14_soft_gfrp_r2_cf0p4_n28": (
        "glass-epoxy 0.3 m x 25 x 8 mm on k1 = 2 EI/L, cubic fraction 0.4, 28 "
        "segments, sensors 0.12 / 0.5 / 1.0 L",
        {**_GF, "n_segments": 28, **soft(2.0, 0.4, _GF), "sensors": sensors((0.12, 0.5, 1.0), 0.3)},
        sim(),
        {},
        {},
    ),
    "b14_soft_brass_r1_cf0p6_z0p1_f3": (
        "brass 0.35 m x 30 x 8 mm on k1 = 1 EI/L, cubic fraction 0.6, 0.1 % "
        "damping, 32 segments, a 3 N hit, 3 s",
        {
            **_BR,
            "n_segments": 32,
            "damping_ratio": 0.001,
            **soft(1.0, 0.6, _BR),
            "sensors": sensors((0.1, 0.5, 1.0), 0.35),
        },
        sim(duration=3.0),
        LIGHT,
        {},
    ),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 14)
