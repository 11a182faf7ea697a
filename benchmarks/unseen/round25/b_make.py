"""Write the round-25 beam scenarios (benchmarks/unseen/round25/b25_*.toml): cantilevers nobody tuned,
default identifier settings, the families' bars. Run from the repository root:

    python benchmarks/unseen/round25/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments, 1 %
damping, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``, 1 s at 12.8 kHz) with the keys below
changed. Rounds 6-24 drew steel, aluminium, titanium, brass, glass-epoxy, tungsten, magnesium, CFRP, nylon,
copper, beryllium-, lead-, tin- and nickel-like beams and zinc of 0.15-1.2 m (round 10: 1.5 m and 2-3 m
steel; round 24: steel 1.6 / 1.8 m, a 1.35 m soft beam, each under 'auto' or the 10 Hz high-pass), 3-45
segments, 1-7 sensors, the hammer at 0.1-0.9 L and the tip, 1 N-2 kN, 0.02-8 % damping, records of 0.3-15 s
at 1-25.6 kHz, soft bases at 0.2-300 EI/L with cubic fractions 0.001-3. Round 25 goes between and beside
them: long beams of other materials than steel, aluminium 1.1 m (mode 1 near 6.8 Hz) under the default 10 Hz
high-pass and aluminium 1.2 m under 'auto', brass 1.1 m read by four uneven sensors under 'auto', titanium
1.4 m at 10 kHz under 'auto' (the hammer at 0.5 s, 3 s records); soft bases between the drawn ones, 0.55
EI/L (cubic fraction 0.15) hit at 0.9 L, 0.9 (0.65) hit at 0.1 L under 200 N, 1.6 (0.05) at 20 kHz on 0.6 s,
2.3 (0.4) read by four uneven sensors on 1.5 s, 4 (0.15) under 1 kN, 0.55 (0.4) under 20 N, brass on 1.6
EI/L (0.65) at 10 kHz; the clamped beam read by three uneven sensors at 20 kHz on 0.6 s and hit at 0.1 L
under 1 kN. A second batch: aluminium 1.5 m (mode 1 near 3.6 Hz) under 'auto', brass 1.3 m on a 1 EI/L base
(0.3) under 'auto', 1.6 EI/L (0.15) under 500 N read by four uneven sensors, the clamped beam at 0.5 %
damping under 20 N on 3 s. Noise 0.5 / 2 / 4 % and seeds 161-169 are the studies' (round25_beams*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 6, 13 and 14's beam writers
from round6 import b_make as _ROUND6  # noqa: E402
from round13.b_make import soft  # noqa: E402
from round14.b_make import sensors  # noqa: E402

TI, BRASS, AL = _ROUND6.TI, _ROUND6.BRASS, _ROUND6.AL
_AL11 = {**AL, "length": 1.1, "n_segments": 22, "sensors": sensors((1 / 3, 2 / 3, 1.0), 1.1)}
_AL12 = {**AL, "length": 1.2, "n_segments": 24, "sensors": sensors((1 / 3, 2 / 3, 1.0), 1.2)}
_BR11 = {**BRASS, "length": 1.1, "n_segments": 22, "sensors": sensors((0.15, 0.45, 0.7, 1.0), 1.1)}
_TI14 = {**TI, "length": 1.4, "n_segments": 28, "sensors": sensors((1 / 3, 2 / 3, 1.0), 1.4)}
_LONG = ({"duration": 3.0}, {"start": 0.5}, {"highpass_hz": "auto"})
_S09 = sensors((0.3, 0.6, 0.9, 1.0))
_HIT09 = {"location": _S09[2]}
_S01 = sensors((0.1, 0.5, 1.0))
_HIT01 = {"location": _S01[0]}
_S4U = sensors((0.2, 0.35, 0.8, 1.0))
_S3U = sensors((0.25, 0.55, 0.9))
_F20, _F200, _F1K = {"peak_force": 20.0}, {"peak_force": 200.0}, {"peak_force": 1000.0}
_AL15 = {**AL, "length": 1.5, "n_segments": 30, "sensors": sensors((1 / 3, 2 / 3, 1.0), 1.5)}
_BR13 = {**BRASS, "length": 1.3, "n_segments": 26, "sensors": sensors((1 / 3, 2 / 3, 1.0), 1.3)}
_F500 = {"peak_force": 500.0}

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # long beams of other materials, mode 1 near or under the chain's high-pass
    "b25_al_L1p1": ("aluminium 1.1 m in 22 segments (mode 1 near 6.8 Hz, under the default 10 Hz high-pass), "
                    "2 s", {**_AL11}, {"duration": 2.0}, {}, {}),
    "b25_al_L1p2_hpauto": ("aluminium 1.2 m in 24 segments (mode 1 near 5.7 Hz) under the high-pass 'auto', "
                           "the hammer at 0.5 s, 3 s", {**_AL12}, *_LONG),
    "b25_br_L1p1_s4_hpauto": ("brass 1.1 m in 22 segments (mode 1 near 4.5 Hz) read by four sensors at "
                              "0.15 / 0.45 / 0.7 / 1 L under the high-pass 'auto', the hammer at 0.5 s, 3 s",
                              {**_BR11}, *_LONG),
    "b25_ti_L1p4_fs10k_hpauto": ("titanium 1.4 m in 28 segments (mode 1 near 4.1 Hz) at 10 kHz under the "
                                 "high-pass 'auto', the hammer at 0.5 s, 3 s", {**_TI14},
                                 {"duration": 3.0, "sample_rate": 10000.0}, {"start": 0.5},
                                 {"highpass_hz": "auto"}),
    # soft bases between and beside the drawn ones
    "b25_soft_r0p55_cf0p15_hit0p9": ("the shipped beam on k1 = 0.55 EI/L, cubic fraction 0.15 at the hit, "
                                     "sensors 0.3 / 0.6 / 0.9 / 1 L, the hammer at 0.9 L",
                                     {**soft(0.55, 0.15, {}, _HIT09), "sensors": _S09}, {}, {**_HIT09}, {}),
    "b25_soft_r0p9_cf0p65_hit0p1_f200": ("the shipped beam on k1 = 0.9 EI/L, cubic fraction 0.65 at 200 N on "
                                         "0.1 L, sensors 0.1 / 0.5 / 1 L, a 200 N hit at 0.1 L",
                                         {**soft(0.9, 0.65, {}, {**_F200, **_HIT01}), "sensors": _S01}, {},
                                         {**_F200, **_HIT01}, {}),
    "b25_soft_r1p6_cf0p05_fs20k_0p6s": ("the shipped beam on k1 = 1.6 EI/L, cubic fraction 0.05, at 20 kHz "
                                        "on 0.6 s", {**soft(1.6, 0.05, {})},
                                        {"duration": 0.6, "sample_rate": 20000.0}, {}, {}),
    "b25_soft_r2p3_cf0p4_s4u_1p5s": ("the shipped beam on k1 = 2.3 EI/L, cubic fraction 0.4, four sensors at "
                                     "0.2 / 0.35 / 0.8 / 1 L, 1.5 s", {**soft(2.3, 0.4, {}), "sensors": _S4U},
                                     {"duration": 1.5}, {}, {}),
    "b25_soft_r4_cf0p15_f1k": ("the shipped beam on k1 = 4 EI/L, cubic fraction 0.15 at 1 kN, under 1 kN",
                               {**soft(4.0, 0.15, {}, _F1K)}, {}, {**_F1K}, {}),
    "b25_soft_r0p55_cf0p4_f20": ("the shipped beam on k1 = 0.55 EI/L, cubic fraction 0.4 at 20 N, under 20 N",
                                 {**soft(0.55, 0.4, {}, _F20)}, {}, {**_F20}, {}),
    "b25_br_soft_r1p6_cf0p65_fs10k": ("brass in the shipped geometry on k1 = 1.6 EI/L, cubic fraction 0.65, "
                                      "at 10 kHz", {**BRASS, **soft(1.6, 0.65, BRASS)},
                                      {"sample_rate": 10000.0}, {}, {}),
    # the clamped beam: uneven sensors, a fast rate, a hit near the root
    "b25_st_s3u_fs20k_0p6s": ("the shipped beam read by three sensors at 0.25 / 0.55 / 0.9 L (none at the "
                              "tip, the hammer at 0.9 L), at 20 kHz on 0.6 s", {"sensors": _S3U},
                              {"duration": 0.6, "sample_rate": 20000.0}, {"location": _S3U[2]}, {}),
    "b25_st_hit0p1_f1k": ("the shipped beam read at 0.1 / 0.5 / 1 L, a 1 kN hit at 0.1 L", {"sensors": _S01},
                          {}, {**_F1K, **_HIT01}, {}),
    # a second batch (round25_beams_more.toml)
    "b25_al_L1p5_hpauto": ("aluminium 1.5 m in 30 segments (mode 1 near 3.6 Hz) under the high-pass 'auto', "
                           "the hammer at 0.5 s, 3 s", {**_AL15}, *_LONG),
    "b25_br_L1p3_soft_r1_cf0p3_hpauto": ("brass 1.3 m in 26 segments on k1 = 1 EI/L, cubic fraction 0.3, "
                                         "under the high-pass 'auto', the hammer at 0.5 s, 3 s",
                                         {**_BR13, **soft(1.0, 0.3, _BR13, {"start": 0.5})}, *_LONG),
    "b25_soft_r1p6_cf0p15_s4u_f500": ("the shipped beam on k1 = 1.6 EI/L, cubic fraction 0.15 at 500 N, four "
                                      "sensors at 0.2 / 0.35 / 0.8 / 1 L, under 500 N",
                                      {**soft(1.6, 0.15, {}, _F500), "sensors": _S4U}, {}, {**_F500}, {}),
    "b25_st_z0p5_f20_3s": ("the shipped beam at 0.5 % damping under 20 N, 3 s", {"damping_ratio": 0.005},
                           {"duration": 3.0}, {**_F20}, {}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 25)
