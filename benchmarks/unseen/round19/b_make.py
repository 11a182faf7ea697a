"""Write the round-19 beam scenarios (benchmarks/unseen/round19/b19_*.toml): cantilevers nobody
tuned, default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round19/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments, 1 %
damping, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``, 1 s at 12.8 kHz) with the keys
below changed.  Round 19 draws these corners (where an earlier round drew the same family, it is
named): longer beams whose mode 1 lies at the chain's default 10 Hz high-pass, under the default
chain (0.85 m: 11.6 Hz, 1.16x it; 0.95 m: 9.3 Hz, just under it; round 6 drew 1.2 m at 5.6 Hz with
and without the high-pass 'auto'), aluminium at 1.1 m with 0.05 % damping on an 8 s record, steel
at 1.2 m with 3 % damping and the high-pass 'auto' on 2 s, titanium at 0.9 m with five sensors,
brass at 0.8 m with 2 % damping and 150 N; soft bases at linear stiffness 0.5-40 EI/L with cubic
fractions 0.05-2 (the families draw 0.5-3 EI/L and 0-0.6; rounds 13 and 17 went to 0.2-100 EI/L
and 0.65-3) under 1.5-3x the shipped 50 N; the hammer at mid-span (0.5 L) on the clamped beam with
five sensors and with three at 4 % damping, and on a 15 EI/L soft base (round 13 drew mid-span
hammers on 5 s records at 6.4 kHz); the shipped beam at 0.05 % damping on 8 s (rounds 11 / 14
drew 0.05-0.1 % on 1-5 s), and the shipped soft base at 0.05 % damping on 8 s; a base of 50 EI/L
(cubic fraction 0.1, 100 N, 2 s).  Noise 0 / 1 / 2 % and seeds 101-102 are the studies'
(round19_beams*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 6, 13 and 14's beam writers
from round6 import b_make as _ROUND6  # noqa: E402
from round13.b_make import soft  # noqa: E402
from round14.b_make import sensors  # noqa: E402

AL, TI, BRASS = _ROUND6.AL, _ROUND6.TI, _ROUND6.BRASS
_L085 = {"length": 0.85, "n_segments": 14}
_L095 = {"length": 0.95, "n_segments": 16}
_AL11 = {**AL, "length": 1.1, "n_segments": 16}
_L12 = {"length": 1.2, "n_segments": 20}
_TI09 = {**TI, "length": 0.9, "n_segments": 18}
_BR08 = {**BRASS, "length": 0.8, "n_segments": 14}
_S5 = sensors((0.2, 0.4, 0.5, 0.8, 1.0))
_S3MID = sensors((0.3, 0.5, 1.0))
_S3MIDOUT = sensors((0.5, 0.75, 1.0))
_F = {"f100": {"peak_force": 100.0}, "f150": {"peak_force": 150.0}, "f75": {"peak_force": 75.0},
      "f120": {"peak_force": 120.0}}

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # longer beams: mode 1 at the default 10 Hz high-pass
    "b19_st_L0p85_n14_2s": ("steel 0.85 m, 14 segments, 2 s (mode 1 near 11.6 Hz)",
                            {**_L085}, {"duration": 2.0}, {}, {}),
    "b19_st_L0p95_n16_2s": ("steel 0.95 m, 16 segments, 2 s (mode 1 near 9.3 Hz)",
                            {**_L095}, {"duration": 2.0}, {}, {}),
    "b19_al_L1p1_n16_z0p05_8s": ("aluminium 1.1 m, 16 segments, 0.05 % damping, 8 s",
                                 {**_AL11, "damping_ratio": 0.0005}, {"duration": 8.0}, {}, {}),
    "b19_st_L1p2_n20_z3_hpauto": ("steel 1.2 m, 20 segments, 3 % damping, 2 s, high-pass 'auto'",
                                  {**_L12, "damping_ratio": 0.03}, {"duration": 2.0}, {},
                                  {"highpass_hz": "auto"}),
    "b19_ti_L0p9_n18_s5_2s": ("titanium 0.9 m, 18 segments, five sensors 0.2 / 0.4 / 0.5 / 0.8 / 1 L, 2 s",
                              {**_TI09, "sensors": sensors((0.2, 0.4, 0.5, 0.8, 1.0), 0.9)},
                              {"duration": 2.0}, {}, {}),
    "b19_br_L0p8_n14_z2_f150_2s": ("brass 0.8 m, 14 segments, 2 % damping, 150 N, 2 s",
                                   {**_BR08, "damping_ratio": 0.02}, {"duration": 2.0},
                                   {**_F["f150"]}, {}),
    # soft bases beyond the families' corners, harder hits
    "b19_soft_r0p7_cf1p5_f100": ("the shipped beam on k1 = 0.7 EI/L, cubic fraction 1.5, 100 N",
                                 {**soft(0.7, 1.5, {}, _F["f100"])}, {}, {**_F["f100"]}, {}),
    "b19_soft_r40_cf0p5_f150": ("the shipped beam on k1 = 40 EI/L, cubic fraction 0.5, 150 N",
                                {**soft(40.0, 0.5, {}, _F["f150"])}, {}, {**_F["f150"]}, {}),
    "b19_soft_r8_cf2_f75": ("the shipped beam on k1 = 8 EI/L, cubic fraction 2, 75 N",
                            {**soft(8.0, 2.0, {}, _F["f75"])}, {}, {**_F["f75"]}, {}),
    "b19_soft_r3_cf0p05_f120_s5": (
        "the shipped beam on k1 = 3 EI/L, cubic fraction 0.05, 120 N, five sensors",
        {**soft(3.0, 0.05, {}, _F["f120"]), "sensors": _S5}, {}, {**_F["f120"]}, {},
    ),
    "b19_soft_r0p5_cf0p8_z3": ("the shipped beam on k1 = 0.5 EI/L, cubic fraction 0.8, 3 % damping",
                               {**soft(0.5, 0.8, {}), "damping_ratio": 0.03}, {}, {}, {}),
    "b19_soft_r15_cf1_hitmid": (
        "the shipped beam on k1 = 15 EI/L, cubic fraction 1, sensors 0.5 / 0.75 / 1 L, the hammer "
        "at mid-span",
        {**soft(15.0, 1.0, {}, {"location": _S3MIDOUT[0]}), "sensors": _S3MIDOUT}, {},
        {"location": _S3MIDOUT[0]}, {},
    ),
    # the hammer at mid-span on the clamped beam, damping
    "b19_st_s5_hitmid": ("the shipped beam, five sensors 0.2 / 0.4 / 0.5 / 0.8 / 1 L, the hammer at "
                         "mid-span", {"sensors": _S5}, {}, {"location": _S5[2]}, {}),
    "b19_st_s3_hitmid_z4": ("the shipped beam, sensors 0.3 / 0.5 / 1 L, the hammer at mid-span, 4 % "
                            "damping", {"sensors": _S3MID, "damping_ratio": 0.04}, {},
                            {"location": _S3MID[1]}, {}),
    "b19_st_z0p05_8s": ("the shipped beam, 0.05 % damping, 8 s", {"damping_ratio": 0.0005},
                        {"duration": 8.0}, {}, {}),
    # a light damping on a soft base over a long record, the stiffest base (round19_beams_extra.toml)
    "b19_soft_r1p2_cf0p3_z0p05_8s": ("the shipped beam on k1 = 1.2 EI/L, cubic fraction 0.3, 0.05 % "
                                     "damping, 8 s", {**soft(1.2, 0.3, {}), "damping_ratio": 0.0005},
                                     {"duration": 8.0}, {}, {}),
    "b19_soft_r50_cf0p1_f100_2s": ("the shipped beam on k1 = 50 EI/L, cubic fraction 0.1, 100 N, 2 s",
                                   {**soft(50.0, 0.1, {}, _F["f100"])}, {"duration": 2.0},
                                   {**_F["f100"]}, {}),
    "b19_al_s3_hitmid_f150": ("aluminium, the shipped section, sensors 0.3 / 0.5 / 1 L, a 150 N hit "
                              "at mid-span", {**AL, "sensors": _S3MID}, {},
                              {"location": _S3MID[1], **_F["f150"]}, {}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 19)
