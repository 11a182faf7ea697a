"""Write the round-24 beam scenarios (benchmarks/unseen/round24/b24_*.toml): cantilevers nobody tuned,
default identifier settings, the families' bars. Run from the repository root:

    python benchmarks/unseen/round24/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments, 1 %
damping, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``, 1 s at 12.8 kHz) with the keys below
changed. Round 24 draws corners rounds 6-23 did not (they drew steel, aluminium, titanium, brass, glass-
epoxy, tungsten, magnesium, CFRP, nylon, copper, beryllium-like, lead-like and zinc, 0.15-1.2 m (round 10:
1.5 m and 2-3 m), 3-45 segments, 1-6 sensors (seven on 1.5 m titanium), the hammer at 0.1-0.9 L and the
tip, 1 N-1 kN, 0.05-8 % damping, records of 0.5-15 s at 1-25.6 kHz (8 and 16 kHz clamped only), soft bases
at 0.2-300 EI/L with cubic fractions 0.001-3): two materials no round drew, a tin-like one (E 50 GPa, 7300
kg/m^3, mode 1 near 42 Hz) and a nickel-like one (E 200 GPa, 8900 kg/m^3) read by five sensors; a 1.6 m
steel beam (mode 1 near 3.2 Hz) in 32 segments under the default 10 Hz high-pass and under the high-pass
'auto' (hammer at 0.5 s, 4.5 s); a 1.35 m beam on a 1.2 EI/L soft base (mode 1 near 2.9 Hz) under the high-
pass 'auto'; the families' section corners: a flat strip (50 x 5 mm, mode 1 near 40 Hz) clamped and on a
1.8 EI/L base with cubic fraction 0.35, brass 0.2 m x 15 mm, and aluminium 0.2 m x 15 mm read at 0.5 / 1 L
on a 1 EI/L base with cubic fraction 0.5; one sensor at mid-span only (the hammer on it); 0.02 % damping on
2 s; a 0.3 s record; seven sensors on 0.5 m titanium; the shipped soft base at 8 and 16 kHz, read by five
sensors hit at 0.2 L; soft bases at 0.6 EI/L (cubic fraction 0.05) under 2 kN, 2.7 (0.45) at 0.2 % damping,
1 (0.7, just outside the families' 0.6) at 3 % damping, 0.45 (just below the families' 0.5, cubic 0.6), 3.3
(just above the families' 3, 0.02). A second batch at the families' own corners, every edge at once:
titanium 0.5 m x 6 mm on 0.5 EI/L with cubic fraction 0.6 under 100 N (beams_soft's), brass 0.5 m x 20 x 6
mm read by six sensors at 3 % damping and steel 0.2 m x 50 x 15 mm read by two under 10 N (beams_stiff's),
glass-epoxy 0.25 m x 20 x 6 mm; the tin-like beam on a 1.2 EI/L base (0.4) on 2 s. A third batch: 0.8 EI/L
(0.5) under 5 N, 1.2 EI/L (0.4) hit at 0.6 L under 300 N, 2 EI/L (0.3) at 1.5 % damping read by two sensors,
steel 1.8 m in 36 segments read by five under the high-pass 'auto', the nickel-like beam at 16 kHz read by
five hit at 0.4 L, the tin-like beam 0.25 m at 0.1 % damping on 4 s. Noise 1 / 3 / 5 % and seeds 151-155
are the studies' (round24_beams*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 6, 13 and 14's beam writers
from round6 import b_make as _ROUND6  # noqa: E402
from round13.b_make import soft  # noqa: E402
from round14.b_make import sensors  # noqa: E402

SOFT, TI, BRASS, AL = _ROUND6.SOFT, _ROUND6.TI, _ROUND6.BRASS, _ROUND6.AL
#: materials no round drew: E [Pa], rho [kg/m^3]
SN = {"E": 50e9, "rho": 7300.0}
NI = {"E": 200e9, "rho": 8900.0}
_S5 = sensors((0.2, 0.4, 0.6, 0.8, 1.0))
_S_MID = sensors((0.5,))
_L16 = {"length": 1.6, "n_segments": 32, "sensors": sensors((1 / 3, 2 / 3, 1.0), 1.6)}
_L135 = {"length": 1.35, "n_segments": 27, "sensors": sensors((1 / 3, 2 / 3, 1.0), 1.35)}
_STRIP = {"width": 0.05, "thickness": 0.005}
_SHORT = {"length": 0.2, "thickness": 0.015, "n_segments": 8, "sensors": sensors((1 / 3, 2 / 3, 1.0), 0.2)}
_SHORT_S2 = {**_SHORT, "sensors": sensors((0.5, 1.0), 0.2)}
_TI05_S7 = {**TI, "length": 0.5, "n_segments": 20,
            "sensors": sensors((1 / 7, 2 / 7, 3 / 7, 4 / 7, 5 / 7, 6 / 7, 1.0), 0.5)}
_F2K = {"peak_force": 2000.0}
_F10, _F100 = {"peak_force": 10.0}, {"peak_force": 100.0}
_TI_CORNER = {**TI, "length": 0.5, "thickness": 0.006, "n_segments": 20}
_BR_CORNER = {**BRASS, "length": 0.5, "width": 0.02, "thickness": 0.006, "n_segments": 20,
              "damping_ratio": 0.03, "sensors": sensors((1 / 6, 2 / 6, 3 / 6, 4 / 6, 5 / 6, 1.0), 0.5)}
_ST_CORNER = {"length": 0.2, "width": 0.05, "thickness": 0.015, "n_segments": 8,
              "sensors": sensors((0.5, 1.0), 0.2)}
_GF_CORNER = {**_ROUND6.GFRP, "length": 0.25, "width": 0.02, "thickness": 0.006}
_HIT02 = {"location": _S5[0]}
_F5, _F300 = {"peak_force": 5.0}, {"peak_force": 300.0}
_S06 = sensors((0.3, 0.6, 1.0))
_HIT06 = {"location": _S06[1]}
_S2 = sensors((0.5, 1.0))
_L18 = {"length": 1.8, "n_segments": 36, "sensors": sensors((0.2, 0.4, 0.6, 0.8, 1.0), 1.8)}

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # materials
    "b24_sn": ("a tin-like beam (E 50 GPa, 7300 kg/m^3) in the shipped geometry (mode 1 near 42 Hz)",
               {**SN}, {}, {}, {}),
    "b24_ni_s5": ("a nickel-like beam (E 200 GPa, 8900 kg/m^3) read by five sensors 0.2-1 L",
                  {**NI, "sensors": _S5}, {}, {}, {}),
    # long beams, mode 1 under the chain's high-pass
    "b24_st_L1p6_n32": ("steel 1.6 m in 32 segments (mode 1 near 3.2 Hz, under the default 10 Hz high-pass), "
                        "2 s", {**_L16}, {"duration": 2.0}, {}, {}),
    "b24_st_L1p6_n32_hpauto": ("steel 1.6 m in 32 segments under the high-pass 'auto', the hammer at 0.5 s, "
                               "4.5 s", {**_L16}, {"duration": 4.5}, {"start": 0.5}, {"highpass_hz": "auto"}),
    "b24_soft_L1p35_hpauto": ("a 1.35 m beam in 27 segments on k1 = 1.2 EI/L, cubic fraction 0.3 (mode 1 "
                              "near 2.9 Hz), the high-pass 'auto', the hammer at 0.5 s, 4.5 s",
                              {**_L135, **soft(1.2, 0.3, _L135, {"start": 0.5})}, {"duration": 4.5},
                              {"start": 0.5}, {"highpass_hz": "auto"}),
    # the families' section corners
    "b24_st_strip": ("a flat steel strip 50 x 5 mm (mode 1 near 40 Hz)", {**_STRIP}, {}, {}, {}),
    "b24_soft_strip_r1p8_cf0p35": ("the 50 x 5 mm strip on k1 = 1.8 EI/L, cubic fraction 0.35",
                                   {**_STRIP, **soft(1.8, 0.35, _STRIP)}, {}, {}, {}),
    "b24_br_L0p2_t15": ("brass 0.2 m x 15 mm in 8 segments", {**BRASS, **_SHORT}, {}, {}, {}),
    # (aluminium 0.2 m x 15 mm read by three sensors is refused by the scenario in one line: the 'auto'
    # low-pass between modes 3 and 4, 7.5 kHz, above the Nyquist frequency)
    "b24_al_L0p2_t15_s2_soft_r1_cf0p5": ("aluminium 0.2 m x 15 mm in 8 segments read at 0.5 / 1 L on k1 = 1 "
                                         "EI/L, cubic fraction 0.5",
                                         {**AL, **_SHORT_S2, **soft(1.0, 0.5, {**AL, **_SHORT_S2})}, {}, {},
                                         {}),
    # sensors, records, damping
    "b24_st_s1mid": ("the shipped beam read by one sensor at mid-span, the hammer on it", {"sensors": _S_MID},
                     {}, {"location": _S_MID[0]}, {}),
    "b24_st_z0p02_2s": ("the shipped beam at 0.02 % damping, a 2 s record", {"damping_ratio": 0.0002},
                        {"duration": 2.0}, {}, {}),
    "b24_st_0p3s": ("the shipped beam on a 0.3 s record", {}, {"duration": 0.3}, {}, {}),
    "b24_ti_L0p5_s7": ("titanium 0.5 m in 20 segments read by seven sensors", {**_TI05_S7}, {}, {}, {}),
    # soft bases: rates, placements, and draws inside and just outside the families' range
    "b24_soft_fs8k": ("the shipped soft base at 8 kHz", {**SOFT}, {"sample_rate": 8000.0}, {}, {}),
    "b24_soft_fs16k": ("the shipped soft base at 16 kHz", {**SOFT}, {"sample_rate": 16000.0}, {}, {}),
    "b24_soft_s5_hit0p2": ("the shipped soft base read by five sensors 0.2-1 L, the hammer at 0.2 L",
                           {**SOFT, "sensors": _S5}, {}, {**_HIT02}, {}),
    "b24_soft_r0p6_cf0p05_f2k": ("the shipped beam on k1 = 0.6 EI/L, cubic fraction 0.05 at 2 kN, under 2 kN",
                                 {**soft(0.6, 0.05, {}, _F2K)}, {}, {**_F2K}, {}),
    "b24_soft_r2p7_cf0p45_z0p2": ("the shipped beam on k1 = 2.7 EI/L, cubic fraction 0.45, 0.2 % damping",
                                  {**soft(2.7, 0.45, {}), "damping_ratio": 0.002}, {}, {}, {}),
    "b24_soft_r1_cf0p7_z3": ("the shipped beam on k1 = 1 EI/L, cubic fraction 0.7 (just outside the "
                             "families' 0.6), 3 % damping", {**soft(1.0, 0.7, {}), "damping_ratio": 0.03},
                             {}, {}, {}),
    "b24_soft_r0p45_cf0p6": ("the shipped beam on k1 = 0.45 EI/L (just below the families' 0.5), cubic "
                             "fraction 0.6", {**soft(0.45, 0.6, {})}, {}, {}, {}),
    "b24_soft_r3p3_cf0p02": ("the shipped beam on k1 = 3.3 EI/L (just above the families' 3), cubic fraction "
                             "0.02", {**soft(3.3, 0.02, {})}, {}, {}, {}),
    # a second batch (round24_beams_extra.toml): the families' own corners, every edge at once
    "b24_ti_L0p5_t6_soft_r0p5_cf0p6_f100": ("titanium 0.5 m x 30 x 6 mm in 20 segments on k1 = 0.5 EI/L, "
                                            "cubic fraction 0.6 at 100 N, under 100 N (beams_soft's corner)",
                                            {**_TI_CORNER, **soft(0.5, 0.6, _TI_CORNER, _F100)}, {},
                                            {**_F100}, {}),
    "b24_br_L0p5_w20_t6_s6_z3": ("brass 0.5 m x 20 x 6 mm in 20 segments read by six sensors at 3 % damping "
                                 "(beams_stiff's corner)", {**_BR_CORNER}, {}, {}, {}),
    "b24_st_L0p2_w50_t15_s2_f10": ("steel 0.2 m x 50 x 15 mm in 8 segments read at 0.5 / 1 L under 10 N "
                                   "(beams_stiff's other corner)", {**_ST_CORNER}, {}, {**_F10}, {}),
    "b24_gf_L0p25_w20_t6": ("glass-epoxy 0.25 m x 20 x 6 mm in 10 segments", {**_GF_CORNER}, {}, {}, {}),
    "b24_sn_soft_r1p2_cf0p4_2s": ("the tin-like beam on k1 = 1.2 EI/L, cubic fraction 0.4, 2 s",
                                  {**SN, **soft(1.2, 0.4, SN)}, {"duration": 2.0}, {}, {}),
    # a third batch (round24_beams_more.toml): forces, hammer spots, damping, a longer beam, a rate
    "b24_soft_r0p8_cf0p5_f5": ("the shipped beam on k1 = 0.8 EI/L, cubic fraction 0.5 at 5 N, under 5 N",
                               {**soft(0.8, 0.5, {}, _F5)}, {}, {**_F5}, {}),
    "b24_soft_r1p2_cf0p4_hit0p6_f300": ("the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.4 at 300 N on "
                                        "0.6 L, sensors 0.3 / 0.6 / 1 L, a 300 N hit at 0.6 L",
                                        {**soft(1.2, 0.4, {}, {**_F300, **_HIT06}), "sensors": _S06},
                                        {}, {**_F300, **_HIT06}, {}),
    "b24_soft_r2_cf0p3_z1p5_s2": ("the shipped beam on k1 = 2 EI/L, cubic fraction 0.3, 1.5 % damping, two "
                                  "sensors 0.5 / 1 L", {**soft(2.0, 0.3, {}), "damping_ratio": 0.015,
                                                        "sensors": _S2}, {}, {}, {}),
    "b24_st_L1p8_s5_hpauto": ("steel 1.8 m in 36 segments (mode 1 near 2.5 Hz) read by five sensors under "
                              "the high-pass 'auto', the hammer at 0.5 s, 5.5 s", {**_L18}, {"duration": 5.5},
                              {"start": 0.5}, {"highpass_hz": "auto"}),
    "b24_ni_fs16k_s5_hit0p4": ("the nickel-like beam at 16 kHz read by five sensors 0.2-1 L, the hammer at "
                               "0.4 L", {**NI, "sensors": _S5}, {"sample_rate": 16000.0},
                               {"location": _S5[1]}, {}),
    "b24_sn_L0p25_z0p1_4s": ("the tin-like beam 0.25 m at 0.1 % damping, 4 s",
                             {**SN, "length": 0.25, "sensors": sensors((1 / 3, 2 / 3, 1.0), 0.25),
                              "damping_ratio": 0.001}, {"duration": 4.0}, {}, {}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 24)
