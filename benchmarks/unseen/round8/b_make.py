"""Write the round-8 beam scenarios (benchmarks/unseen/round8/b_*.toml): cantilevers nobody tuned,
default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round8/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments,
1 % damping, 1 s at 12.8 kHz, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``) with
the keys below changed.  Round 8 varies what the round's brief names: longer beams (0.6-1.2 m,
sections chosen so mode 1 sits at 17-35 Hz, above the chain's 10 Hz high-pass) and other soft
bases (k1 800-10,000 N m/rad, k3 3e8-5e10 N m/rad^3, other materials and lengths on them).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: round 6's writer is round6/b_make.py
from round6 import b_make as _ROUND6  # noqa: E402

L, SOFT, AL, TI, BRASS, GFRP = (_ROUND6.L, _ROUND6.SOFT, _ROUND6.AL, _ROUND6.TI, _ROUND6.BRASS,
                                _ROUND6.GFRP)


def even(n: int, length: float) -> list[float]:
    """n sensors evenly spaced to the tip [m]."""
    return [round(length * (k + 1) / n, 6) for k in range(n)]


#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # longer clamped beams (mode 1 from Euler-Bernoulli, 1.875^2 / (2 pi L^2) sqrt(EI / rho A))
    "b8_L0p8_s3": ("steel 0.8 m x 25 mm (mode 1 at 33 Hz), three sensors, 16 segments, 2 s",
                   {"length": 0.8, "thickness": 0.025, "n_segments": 16, "sensors": even(3, 0.8)},
                   {"duration": 2.0}, {}, {}),
    "b8_L1_alu_s2": ("aluminium 1 m x 40 mm (mode 1 at 33 Hz), sensors at L/2 and L, 20 segments, 2 s",
                     {**AL, "length": 1.0, "thickness": 0.04, "n_segments": 20, "sensors": [0.5, 1.0]},
                     {"duration": 2.0}, {}, {}),
    "b8_L1p2_ti_s4": ("titanium 1.2 m x 40 mm (mode 1 at 23 Hz), four sensors, 24 segments, 3 s at 6.4 kHz",
                      {**TI, "length": 1.2, "thickness": 0.04, "n_segments": 24, "sensors": even(4, 1.2)},
                      {"duration": 3.0, "sample_rate": 6400.0}, {}, {}),
    "b8_L0p7_brass_s3": ("brass 0.7 m x 15 mm (mode 1 at 17 Hz, 1.7x the high-pass), three sensors, 3 s",
                         {**BRASS, "length": 0.7, "thickness": 0.015, "n_segments": 16,
                          "sensors": even(3, 0.7)}, {"duration": 3.0}, {}, {}),
    "b8_L1_gfrp_s3": ("glass-epoxy 1 m x 50 mm (mode 1 at 26 Hz), three sensors, 20 segments, 3 s",
                      {**GFRP, "length": 1.0, "thickness": 0.05, "n_segments": 20, "sensors": even(3, 1.0)},
                      {"duration": 3.0}, {}, {}),
    "b8_L0p9_hit_mid": ("steel 0.9 m x 20 mm (mode 1 at 21 Hz), sensors at 0.3/0.6/0.9 m, hammer at "
                        "0.6 m, 2 s",
                        {"length": 0.9, "thickness": 0.02, "n_segments": 18, "sensors": [0.3, 0.6, 0.9]},
                        {"duration": 2.0}, {"location": 0.6}, {}),
    "b8_L0p6_z0p3_s4": ("steel 0.6 m x 15 mm, 0.3 % damping, four sensors, 16 segments, 2 s",
                        {"length": 0.6, "thickness": 0.015, "n_segments": 16, "sensors": even(4, 0.6),
                         "damping_ratio": 0.003}, {"duration": 2.0}, {}, {}),
    # other soft bases
    "b8_soft_k1_3000_k3_5e9": ("soft base k1 = 3000, k3 = 5e9", {**SOFT, "base_k1": 3000.0, "base_k3": 5e9},
                               {}, {}, {}),
    "b8_soft_k1_1500_k3_1e9": ("soft base k1 = 1500, k3 = 1e9", {**SOFT, "base_k1": 1500.0, "base_k3": 1e9},
                               {}, {}, {}),
    "b8_soft_k1_1e4_k3_5e10": ("soft base k1 = 1e4, k3 = 5e10", {**SOFT, "base_k1": 1e4, "base_k3": 5e10},
                               {}, {}, {}),
    "b8_soft_alu_k1_800_k3_3e8": ("aluminium on a soft base k1 = 800, k3 = 3e8",
                                  {**AL, **SOFT, "base_k1": 800.0, "base_k3": 3e8}, {}, {}, {}),
    "b8_soft_L0p5_s3": ("steel 0.5 m x 15 mm on the shipped soft base, three sensors, 14 segments",
                        {**SOFT, "length": 0.5, "thickness": 0.015, "n_segments": 14,
                         "sensors": even(3, 0.5)}, {}, {}, {}),
    "b8_soft_L0p8_k1_5000": ("steel 0.8 m x 25 mm on a soft base k1 = 5000, k3 = 5e9, three sensors, 2 s",
                             {**SOFT, "length": 0.8, "thickness": 0.025, "n_segments": 16,
                              "sensors": even(3, 0.8), "base_k1": 5000.0, "base_k3": 5e9},
                             {"duration": 2.0}, {}, {}),
    "b8_soft_ti_s2": ("titanium on the shipped soft base, sensors at L/2 and L",
                      {**TI, **SOFT, "sensors": [0.15875, 0.3175]}, {}, {}, {}),
    "b8_soft_z0p5": ("the shipped soft base, 0.5 % damping", {**SOFT, "damping_ratio": 0.005}, {}, {}, {}),
    "b8_soft_gfrp": ("glass-epoxy on a soft base k1 = 1000, k3 = 1e9", {**GFRP, **SOFT, "base_k1": 1000.0,
                                                                          "base_k3": 1e9}, {}, {}, {}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 8)
