"""Write the round-9 beam scenarios (benchmarks/unseen/round9/b9_*.toml): cantilevers nobody tuned,
default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round9/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments,
1 % damping, 1 s at 12.8 kHz, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``) with
the keys below changed.  Round 9 visits corners rounds 3-8 did not: 5-7 sensors placed unevenly
on 0.3-2 m beams, thick short beams whose modes crowd the low-pass and the Nyquist frequency,
0.05 % damping and 3-5 % on longer beams, the hammer at a node of mode 2 (clamped and on a soft
base), soft bases k1 200-20,000 N m/rad with k3 from 0 to 3e11 N m/rad^3, brass / titanium /
glass-epoxy on them, 25.6 and 6.4 kHz on soft bases and long beams, two-sensor soft beams.

Where a case puts the hammer at a node of mode 2, the node is Euler-Bernoulli's, solved here
from the boundary determinant (clamped, or a root hinge on the base's linear spring), not from
the rig's truth.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: round 6's writer is round6/b_make.py
from round6 import b_make as _ROUND6  # noqa: E402

L, SOFT, AL, TI, BRASS, GFRP = (_ROUND6.L, _ROUND6.SOFT, _ROUND6.AL, _ROUND6.TI, _ROUND6.BRASS,
                                _ROUND6.GFRP)


def _boundary(bl: float, kappa: float) -> np.ndarray:
    """Boundary matrix of ``w = A cos + B sin + C cosh + D sinh`` (root spring ``kappa = k1 L / EI``
    or a clamp for ``inf``; free tip), rows scaled by ``cosh(bl)`` at the tip."""
    c, s, ch, sh = (np.cos(bl), np.sin(bl), np.cosh(bl), np.sinh(bl))
    root = [0.0, 1.0, 0.0, 1.0] if math.isinf(kappa) else [-bl, -kappa, bl, -kappa]
    return np.array([[1.0, 0.0, 1.0, 0.0], root, [-c / ch, -s / ch, 1.0, sh / ch],
                     [s / ch, -c / ch, sh / ch, 1.0]])


def mode2_node(length: float, ei: float, k1: float = math.inf) -> float:
    """Position [m] of mode 2's interior node of an Euler-Bernoulli cantilever (root spring k1)."""
    kappa = k1 * length / ei
    det = lambda x: float(np.linalg.det(_boundary(x, kappa)))  # noqa: E731
    grid = np.linspace(1e-3, 9.0, 9001)
    v = [det(x) for x in grid]
    roots = [brentq(det, grid[i], grid[i + 1]) for i in range(len(grid) - 1) if v[i] * v[i + 1] < 0]
    bl = roots[1]
    _, _, vt = np.linalg.svd(_boundary(bl, kappa))
    a, b, c, d = vt[-1]
    xs = np.linspace(0.02, 0.999, 20000) * bl
    w = a * np.cos(xs) + b * np.sin(xs) + c * np.cosh(xs) + d * np.sinh(xs)
    i = int(np.flatnonzero(np.sign(w[1:]) != np.sign(w[:-1]))[-1])
    f = lambda x: a * np.cos(x) + b * np.sin(x) + c * np.cosh(x) + d * np.sinh(x)  # noqa: E731
    return round(brentq(f, xs[i], xs[i + 1]) / bl * length, 4)


EI_SHIPPED = 210e9 * 0.03 * 0.01**3 / 12  # N m^2
EI_0P6 = 210e9 * 0.03 * 0.015**3 / 12
NODE_CLAMPED_0P6 = mode2_node(0.6, EI_0P6)
NODE_SOFT = mode2_node(L, EI_SHIPPED, 2000.0)

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # five to seven sensors placed unevenly on 0.3-2 m beams (light damping keeps the top sensed
    # mode under the families' 30 % cap: stiffness-proportional damping grows as f_k / f_1)
    "b9_L0p4_s5_uneven": ("steel 0.4 m x 10 mm, five sensors at 0.06/0.15/0.22/0.31/0.4 m, 16 segments, "
                          "0.3 % damping",
                          {"length": 0.4, "n_segments": 16, "damping_ratio": 0.003,
                           "sensors": [0.06, 0.15, 0.22, 0.31, 0.4]}, {}, {}, {}),
    "b9_L0p3_h5_s6_tip": ("steel 0.3 m x 5 mm (mode 1 at 47 Hz), six sensors crowding the tip, 16 "
                          "segments, 0.2 % damping",
                          {"length": 0.3, "thickness": 0.005, "n_segments": 16, "damping_ratio": 0.002,
                           "sensors": [0.05, 0.12, 0.18, 0.24, 0.27, 0.3]}, {}, {}, {}),
    "b9_L1_s6_uneven": ("steel 1 m x 30 mm (mode 1 at 25 Hz), six sensors at 0.1/0.25/0.45/0.6/0.8/1 m, "
                        "20 segments, 0.3 % damping, 2 s",
                        {"length": 1.0, "thickness": 0.03, "n_segments": 20, "damping_ratio": 0.003,
                         "sensors": [0.1, 0.25, 0.45, 0.6, 0.8, 1.0]}, {"duration": 2.0}, {}, {}),
    "b9_L1p5_ti_s7": ("titanium 1.5 m x 50 mm (mode 1 at 18 Hz), seven uneven sensors, 24 segments, "
                      "0.2 % damping, 3 s at 6.4 kHz",
                      {**TI, "length": 1.5, "thickness": 0.05, "n_segments": 24, "damping_ratio": 0.002,
                       "sensors": [0.15, 0.35, 0.6, 0.8, 1.05, 1.3, 1.5]},
                      {"duration": 3.0, "sample_rate": 6400.0}, {}, {}),
    "b9_L2_alu_s5": ("aluminium 2 m x 80 mm (mode 1 at 16 Hz), five uneven sensors, 24 segments, "
                     "0.5 % damping, 3 s",
                     {**AL, "length": 2.0, "thickness": 0.08, "n_segments": 24, "damping_ratio": 0.005,
                      "sensors": [0.3, 0.7, 1.2, 1.6, 2.0]}, {"duration": 3.0}, {}, {}),
    # thick short beams: modes crowd the low-pass and the Nyquist frequency
    "b9_thick_L0p2_h40_s2": ("steel 0.2 m x 40 mm (L/h 5; modes 1-3 at 0.83 / 5.2 / 14.6 kHz), sensors "
                             "at L/2 and L, 200 N / 0.1 ms hammer, 0.5 s at 25.6 kHz",
                             {"length": 0.2, "thickness": 0.04, "sensors": [0.1, 0.2]},
                             {"duration": 0.5, "sample_rate": 25600.0},
                             {"peak_force": 200.0, "pulse_duration": 1e-4}, {}),
    "b9_thick_L0p3_h40_s2": ("steel 0.3 m x 40 mm (modes 1-3 at 0.37 / 2.3 / 6.5 kHz: mode 3 above "
                             "the 6.4 kHz Nyquist frequency), sensors at L/2 and L, 200 N / 0.1 ms",
                             {"length": 0.3, "thickness": 0.04, "sensors": [0.15, 0.3]}, {},
                             {"peak_force": 200.0, "pulse_duration": 1e-4}, {}),
    "b9_thick_L0p25_h30_s3": ("steel 0.25 m x 30 mm (modes 1-4 at 0.40 / 2.5 / 7.0 / 13.8 kHz), three "
                              "sensors, 200 N / 0.1 ms, 0.5 s at 25.6 kHz",
                              {"length": 0.25, "thickness": 0.03, "sensors": [0.08, 0.17, 0.25]},
                              {"duration": 0.5, "sample_rate": 25600.0},
                              {"peak_force": 200.0, "pulse_duration": 1e-4}, {}),
    # very light and heavy damping
    "b9_z0p05": ("the shipped clamped beam, 0.05 % damping", {"damping_ratio": 0.0005}, {}, {}, {}),
    "b9_z0p05_L1_s4": ("steel 1 m x 30 mm, 0.05 % damping, four uneven sensors, 20 segments, 2 s",
                       {"length": 1.0, "thickness": 0.03, "n_segments": 20, "damping_ratio": 0.0005,
                        "sensors": [0.2, 0.5, 0.75, 1.0]}, {"duration": 2.0}, {}, {}),
    "b9_soft_z0p05": ("the shipped soft base, 0.05 % damping", {**SOFT, "damping_ratio": 0.0005}, {}, {}, {}),
    "b9_z3_L0p8_s2": ("steel 0.8 m x 25 mm, 3 % damping, sensors at L/2 and L, 16 segments",
                      {"length": 0.8, "thickness": 0.025, "n_segments": 16, "damping_ratio": 0.03,
                       "sensors": [0.4, 0.8]}, {}, {}, {}),
    "b9_z5_L0p6_s2": ("steel 0.6 m x 15 mm, 5 % damping, sensors at 0.3 and 0.6 m, 16 segments",
                      {"length": 0.6, "thickness": 0.015, "n_segments": 16, "damping_ratio": 0.05,
                       "sensors": [0.3, 0.6]}, {}, {}, {}),
    "b9_soft_z4_s2": ("the shipped soft base, 4 % damping, sensors at L/2 and L",
                      {**SOFT, "damping_ratio": 0.04, "sensors": [L / 2, L]}, {}, {}, {}),
    # the hammer at a node of mode 2 (Euler-Bernoulli's node; the hammer must land on a sensor)
    "b9_hit_node2_L0p6": (f"steel 0.6 m x 15 mm, sensors at 0.2 m, mode 2's node ({NODE_CLAMPED_0P6} m) "
                          "and 0.6 m, hammer at the node, 16 segments, 2 s",
                          {"length": 0.6, "thickness": 0.015, "n_segments": 16,
                           "sensors": [0.2, NODE_CLAMPED_0P6, 0.6]}, {"duration": 2.0},
                          {"location": NODE_CLAMPED_0P6}, {}),
    "b9_soft_hit_node2": (f"the shipped soft base, sensors at L/3, mode 2's node ({NODE_SOFT} m) and L, "
                          "hammer at the node",
                          {**SOFT, "sensors": [round(L / 3, 6), NODE_SOFT, L]}, {},
                          {"location": NODE_SOFT}, {}),
    # soft bases across k1 and k3
    "b9_soft_k1_200_hpauto": ("soft base k1 = 200, k3 = 1e8 (mode 1 near 14 Hz), high-pass 'auto', hammer "
                              "at 0.4 s, 2 s",
                              {**SOFT, "base_k1": 200.0, "base_k3": 1e8}, {"duration": 2.0},
                              {"start": 0.4}, {"highpass_hz": "auto"}),
    "b9_soft_k1_400_k3_0_s2": ("linear soft base k1 = 400, k3 = 0, sensors at L/2 and L, high-pass "
                               "'auto', hammer at 0.4 s, 2 s",
                               {**SOFT, "base_k1": 400.0, "base_k3": 0.0, "sensors": [L / 2, L]},
                               {"duration": 2.0}, {"start": 0.4}, {"highpass_hz": "auto"}),
    "b9_soft_k1_8000_k3_0": ("linear soft base k1 = 8000, k3 = 0",
                             {**SOFT, "base_k1": 8000.0, "base_k3": 0.0}, {}, {}, {}),
    "b9_soft_k1_2e4_k3_3e11": ("soft base k1 = 2e4, k3 = 3e11 (strongly hardening at the root)",
                               {**SOFT, "base_k1": 2e4, "base_k3": 3e11}, {}, {}, {}),
    "b9_soft_k1_1000_k3_3e9_s2": ("soft base k1 = 1000, k3 = 3e9, sensors at L/2 and L",
                                  {**SOFT, "base_k1": 1000.0, "base_k3": 3e9, "sensors": [L / 2, L]},
                                  {}, {}, {}),
    "b9_soft_k1_5000_k3_2e10_20N": ("soft base k1 = 5000, k3 = 2e10, 20 N hammer",
                                    {**SOFT, "base_k1": 5000.0, "base_k3": 2e10}, {},
                                    {"peak_force": 20.0}, {}),
    # materials on soft bases
    "b9_soft_brass": ("brass on a soft base k1 = 3000, k3 = 5e9", {**BRASS, **SOFT, "base_k1": 3000.0,
                                                                  "base_k3": 5e9}, {}, {}, {}),
    "b9_soft_brass_L0p4_s4": ("brass 0.4 m x 12 mm on a soft base k1 = 1e4, k3 = 1e10, four uneven sensors, "
                              "12 segments",
                              {**BRASS, **SOFT, "length": 0.4, "thickness": 0.012, "n_segments": 12,
                               "base_k1": 1e4, "base_k3": 1e10, "sensors": [0.1, 0.2, 0.3, 0.4]},
                              {}, {}, {}),
    "b9_soft_ti_L0p5_k3_2e10": ("titanium 0.5 m x 15 mm on a soft base k1 = 5000, k3 = 2e10, three sensors, "
                                "14 segments",
                                {**TI, **SOFT, "length": 0.5, "thickness": 0.015, "n_segments": 14,
                                 "base_k1": 5000.0, "base_k3": 2e10, "sensors": [0.17, 0.34, 0.5]},
                                {}, {}, {}),
    "b9_soft_gfrp_k1_600_s2": ("glass-epoxy on a linear soft base k1 = 600, sensors at L/2 and L, 2 s",
                               {**GFRP, **SOFT, "base_k1": 600.0, "base_k3": 0.0, "sensors": [L / 2, L]},
                               {"duration": 2.0}, {}, {}),
    # sample rates
    "b9_soft_fs25600": ("the shipped soft base at 25.6 kHz", {**SOFT}, {"sample_rate": 25600.0}, {}, {}),
    "b9_soft_fs6400_s2": ("the shipped soft base, sensors at L/2 and L, 6.4 kHz",
                          {**SOFT, "sensors": [L / 2, L]}, {"sample_rate": 6400.0}, {}, {}),
    "b9_L1_fs6400_s5": ("steel 1 m x 30 mm, five uneven sensors, 20 segments, 0.3 % damping, 2 s at 6.4 kHz",
                        {"length": 1.0, "thickness": 0.03, "n_segments": 20, "damping_ratio": 0.003,
                         "sensors": [0.15, 0.4, 0.6, 0.85, 1.0]}, {"duration": 2.0, "sample_rate": 6400.0},
                        {}, {}),
    "b9_fs25600_s4": ("the shipped clamped beam, four uneven sensors, 0.5 % damping, 25.6 kHz",
                      {"damping_ratio": 0.005, "sensors": [0.08, 0.16, 0.25, L]},
                      {"sample_rate": 25600.0}, {}, {}),
    # two-sensor soft beams and soft beams with more sensors
    "b9_soft_s2_root": ("soft base k1 = 5000, k3 = 5e9, sensors at 0.1 m and L",
                        {**SOFT, "base_k1": 5000.0, "base_k3": 5e9, "sensors": [0.1, L]}, {}, {}, {}),
    "b9_soft_s2_L0p8": ("steel 0.8 m x 25 mm on a soft base k1 = 8000, k3 = 1e10, sensors at L/2 and L, "
                        "16 segments, 2 s",
                        {**SOFT, "length": 0.8, "thickness": 0.025, "n_segments": 16, "base_k1": 8000.0,
                         "base_k3": 1e10, "sensors": [0.4, 0.8]}, {"duration": 2.0}, {}, {}),
    "b9_soft_s5_L0p5": ("steel 0.5 m x 15 mm on a soft base k1 = 3000, k3 = 5e9, five uneven sensors, "
                        "14 segments, 0.3 % damping",
                        {**SOFT, "length": 0.5, "thickness": 0.015, "n_segments": 14, "damping_ratio": 0.003,
                         "base_k1": 3000.0, "base_k3": 5e9, "sensors": [0.08, 0.2, 0.3, 0.42, 0.5]},
                        {}, {}, {}),
    "b9_soft_L1p2_k1_2e4": ("steel 1.2 m x 40 mm on a soft base k1 = 2e4, k3 = 1e10, three sensors, "
                            "24 segments, 3 s",
                            {**SOFT, "length": 1.2, "thickness": 0.04, "n_segments": 24, "base_k1": 2e4,
                             "base_k3": 1e10, "sensors": [0.4, 0.8, 1.2]}, {"duration": 3.0}, {}, {}),
    "b9_soft_thick_L0p25": ("steel 0.25 m x 25 mm on a soft base k1 = 2e4, k3 = 1e11, two sensors, "
                            "200 N / 0.1 ms, 0.5 s at 25.6 kHz",
                            {**SOFT, "length": 0.25, "thickness": 0.025, "base_k1": 2e4, "base_k3": 1e11,
                             "sensors": [0.125, 0.25]}, {"duration": 0.5, "sample_rate": 25600.0},
                            {"peak_force": 200.0, "pulse_duration": 1e-4}, {}),
    "b9_brass_L0p5_s5_z0p05": ("brass 0.5 m x 12 mm, 0.05 % damping, five uneven sensors, 14 segments, 2 s",
                               {**BRASS, "length": 0.5, "thickness": 0.012, "n_segments": 14,
                                "damping_ratio": 0.0005, "sensors": [0.1, 0.18, 0.3, 0.4, 0.5]},
                               {"duration": 2.0}, {}, {}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 9)
