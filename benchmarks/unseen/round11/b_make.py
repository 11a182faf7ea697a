"""Write the round-11 beam scenarios (benchmarks/unseen/round11/b11_*.toml): cantilevers nobody
tuned, default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round11/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments,
1 % damping, 1 s at 12.8 kHz, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``) with
the keys below changed.  Round 11 visits corners rounds 3-10 did not: the hammer (which must
land on a sensor) on a node of the clamped beam's mode 2 or 3, so that mode is barely excited,
or next to the clamp; a sensor on mode 2's node; very light (0.05-0.2 %) and heavy (5-10 % on
mode 1; the rig's damping is stiffness-proportional, so mode 2 has 6.3 x that) damping with
other sensor sets and records; soft bases whose cubic is so weak the base is linear within the
noise (k3 q^3 / k1 q of 1e-4 to 3e-3 at the record's largest base angle: the cubic must not be
kept); finite stiff bases (k1 L / EI of 10-200) on other beams and materials; records of
0.1-0.25 s and of 4-8 s; 6.4 and 25.6 kHz on rigs those rates were not used with.

The rig refuses a softening base (``base_k3 >= 0``) and puts the hammer only at the tip or on a
sensor, so the softening corner is out and "a hammer at a node" is "a sensor at a node, struck".
Node positions are the clamped Euler-Bernoulli beam's (x / L = 0.7834 for mode 2, 0.5035 and
0.8677 for mode 3); the chain's nodes are within a few tenths of a percent of L of them.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: round 6's writer is round6/b_make.py
from round6 import b_make as _ROUND6  # noqa: E402

L, SOFT, AL, TI, BRASS, GFRP, EI = (_ROUND6.L, _ROUND6.SOFT, _ROUND6.AL, _ROUND6.TI, _ROUND6.BRASS,
                                    _ROUND6.GFRP, _ROUND6.EI)
#: the clamped Euler-Bernoulli beam's interior nodes (x / L) of modes 2 and 3
NODE2 = 0.7834
NODE3 = (0.5035, 0.8677)


def at(x: float, length: float = L) -> float:
    """A position ``x * length`` [m] rounded to 0.1 mm (the scenario files' precision)."""
    return round(x * length, 4)


#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # the hammer on a node of mode 2 or 3, or next to the clamp
    "b11_hit_node2": ("clamped, sensors at L/3, 0.783 L (mode 2's node), L, hammer on the node",
                      {"sensors": [at(1 / 3), at(NODE2), L]}, {}, {"location": at(NODE2)}, {}),
    "b11_hit_node2_n20": ("clamped, 20 segments, sensors at L/3, 0.783 L (mode 2's node), L, hammer "
                          "on the node",
                          {"n_segments": 20, "sensors": [at(1 / 3), at(NODE2), L]}, {},
                          {"location": at(NODE2)}, {}),
    "b11_hit_node2_s2": ("clamped, 20 segments, sensors at L/2 and 0.783 L (mode 2's node), hammer on "
                         "the node",
                         {"n_segments": 20, "sensors": [at(0.5), at(NODE2)]}, {},
                         {"location": at(NODE2)}, {}),
    "b11_hit_node3a": ("clamped, 20 segments, sensors at 0.25 L, 0.504 L (mode 3's inner node), L, "
                       "hammer on the node",
                       {"n_segments": 20, "sensors": [at(0.25), at(NODE3[0]), L]}, {},
                       {"location": at(NODE3[0])}, {}),
    "b11_hit_node3b": ("clamped, 20 segments, sensors at L/3, 0.868 L (mode 3's outer node), L, "
                       "hammer on the node",
                       {"n_segments": 20, "sensors": [at(1 / 3), at(NODE3[1]), L]}, {},
                       {"location": at(NODE3[1])}, {}),
    "b11_L1_hit_node2": ("steel 1 m x 30 mm, 20 segments, sensors at 0.5 / 0.783 / 1 m, hammer on "
                         "mode 2's node, 0.5 % damping, 2 s",
                         {"length": 1.0, "thickness": 0.03, "n_segments": 20, "damping_ratio": 0.005,
                          "sensors": [0.5, at(NODE2, 1.0), 1.0]}, {"duration": 2.0},
                         {"location": at(NODE2, 1.0)}, {}),
    "b11_hit_clamp": ("clamped, 20 segments, sensors at 0.02 m, L/2, L, hammer at 0.02 m (next to "
                      "the clamp), 200 N",
                      {"n_segments": 20, "sensors": [0.02, at(0.5), L]}, {},
                      {"location": 0.02, "peak_force": 200.0}, {}),
    "b11_sensor_node2_s2": ("clamped, sensors at 0.783 L (mode 2's node) and L, hammer at the tip",
                            {"sensors": [at(NODE2), L]}, {}, {}, {}),
    "b11_sensor_node2_s2_n20": ("clamped, 20 segments, sensors at 0.783 L (mode 2's node) and L",
                                {"n_segments": 20, "sensors": [at(NODE2), L]}, {}, {}, {}),
    # very light damping
    "b11_z0p05_2s": ("clamped, 0.05 % damping, 2 s", {"damping_ratio": 0.0005}, {"duration": 2.0},
                     {}, {}),
    "b11_z0p05_short": ("clamped, 0.05 % damping, 0.25 s (mode 1 decays 0.5 %)",
                        {"damping_ratio": 0.0005}, {"duration": 0.25}, {}, {}),
    "b11_z0p1_L1_4s": ("steel 1 m x 30 mm, 20 segments, 0.1 % damping, three sensors, 4 s",
                       {"length": 1.0, "thickness": 0.03, "n_segments": 20, "damping_ratio": 0.001,
                        "sensors": [0.35, 0.7, 1.0]}, {"duration": 4.0}, {}, {}),
    "b11_z0p2_fs6400_8s": ("clamped, 0.2 % damping, 8 s at 6.4 kHz",
                           {"damping_ratio": 0.002}, {"duration": 8.0, "sample_rate": 6400.0}, {}, {}),
    "b11_soft_z0p1": ("the shipped soft base, 0.1 % damping, 2 s",
                      {**SOFT, "damping_ratio": 0.001}, {"duration": 2.0}, {}, {}),
    # heavy damping
    "b11_z7": ("clamped, 7 % damping (mode 2 44 %)", {"damping_ratio": 0.07}, {}, {}, {}),
    "b11_z10_s2": ("clamped, 10 % damping, sensors at L/2 and L", {"damping_ratio": 0.1,
                                                                    "sensors": [at(0.5), L]}, {}, {}, {}),
    "b11_z5_n20_s4": ("clamped, 5 % damping, 20 segments, four sensors",
                      {"damping_ratio": 0.05, "n_segments": 20, "sensors": [0.08, 0.16, 0.24, L]},
                      {}, {}, {}),
    "b11_soft_z8": ("the shipped soft base, 8 % damping", {**SOFT, "damping_ratio": 0.08}, {}, {}, {}),
    "b11_z6_al_L0p6": ("aluminium 0.6 m x 10 mm, 12 segments, 6 % damping, 2 s",
                       {**AL, "length": 0.6, "n_segments": 12, "damping_ratio": 0.06},
                       {"duration": 2.0}, {}, {}),
    # weak cubics: the base is linear within the noise
    "b11_soft_k3_1e6": ("the shipped soft base with k3 = 1e6 (k3 q^2 / k1 ~ 1e-4)",
                        {**SOFT, "base_k3": 1e6}, {}, {}, {}),
    "b11_soft_k3_2p5e7": ("the shipped soft base with k3 = 2.5e7 (k3 q^2 / k1 ~ 2e-3)",
                          {**SOFT, "base_k3": 2.5e7}, {}, {}, {}),
    "b11_soft_k1_5000_k3_1e7_s2": ("soft base k1 = 5000, k3 = 1e7, sensors at L/2 and L",
                                   {**SOFT, "base_k1": 5000.0, "base_k3": 1e7, "sensors": [at(0.5), L]},
                                   {}, {}, {}),
    "b11_soft_al_k3_1e7": ("aluminium 0.5 m x 10 mm, 12 segments, soft base k1 = 2000, k3 = 1e7, 2 s",
                           {**AL, **SOFT, "length": 0.5, "n_segments": 12, "base_k3": 1e7},
                           {"duration": 2.0}, {}, {}),
    # finite stiff bases (k1 L / EI 10-200) on other beams
    "b11_al_L0p6_k1_kappa30": ("aluminium 0.6 m x 10 mm, 12 segments, base k1 = 30 EI/L, k3 = 0",
                               {**AL, **SOFT, "length": 0.6, "n_segments": 12,
                                "base_k1": 30 * 69e9 * 0.03 * 0.01**3 / 12 / 0.6, "base_k3": 0.0},
                               {}, {}, {}),
    "b11_ti_L0p5_k1_kappa200": ("titanium 0.5 m x 10 mm, 12 segments, base k1 = 200 EI/L, k3 = 1e9",
                                {**TI, **SOFT, "length": 0.5, "n_segments": 12,
                                 "base_k1": 200 * 116e9 * 0.03 * 0.01**3 / 12 / 0.5, "base_k3": 1e9},
                                {}, {}, {}),
    "b11_L1_k1_kappa10_s4": ("steel 1 m x 30 mm, 20 segments, base k1 = 10 EI/L, k3 = 0, four sensors, "
                             "0.5 % damping, 2 s",
                             {**SOFT, "length": 1.0, "thickness": 0.03, "n_segments": 20,
                              "damping_ratio": 0.005, "base_k1": 10 * 210e9 * 0.03 * 0.03**3 / 12,
                              "base_k3": 0.0, "sensors": [0.25, 0.5, 0.75, 1.0]},
                             {"duration": 2.0}, {}, {}),
    "b11_k1_kappa60_s2": ("the shipped beam on a base k1 = 60 EI/L, k3 = 0, sensors at L/2 and L",
                          {**SOFT, "base_k1": 60 * EI / L, "base_k3": 0.0, "sensors": [at(0.5), L]},
                          {}, {}, {}),
    # short records
    "b11_short0p1": ("clamped, 0.1 s", {}, {"duration": 0.1}, {}, {}),
    "b11_short0p15_s2": ("clamped, sensors at L/2 and L, 0.15 s", {"sensors": [at(0.5), L]},
                         {"duration": 0.15}, {}, {}),
    "b11_soft_short0p25": ("the shipped soft base, 0.25 s", {**SOFT}, {"duration": 0.25}, {}, {}),
    "b11_brass_short0p2": ("brass 0.4 m x 10 mm, 12 segments, 0.2 s", {**BRASS, "length": 0.4,
                                                                        "n_segments": 12},
                           {"duration": 0.2}, {}, {}),
    # long records and rates on new rigs
    "b11_soft_6s_fs6400": ("the shipped soft base, 0.3 % damping, 6 s at 6.4 kHz",
                           {**SOFT, "damping_ratio": 0.003}, {"duration": 6.0, "sample_rate": 6400.0},
                           {}, {}),
    "b11_fs25600_L0p2_s2": ("steel 0.2 m x 10 mm, 12 segments, sensors at L/2 and L, 0.5 s at 25.6 kHz",
                            {"length": 0.2, "n_segments": 12, "sensors": [0.1, 0.2]},
                            {"duration": 0.5, "sample_rate": 25600.0}, {}, {}),
    "b11_soft_fs25600": ("the shipped soft base at 25.6 kHz", {**SOFT}, {"sample_rate": 25600.0}, {}, {}),
    "b11_gfrp_L0p8_5s_fs6400": ("glass fibre 0.8 m x 20 mm, 16 segments, 0.5 % damping, 5 s at 6.4 kHz",
                                {**GFRP, "length": 0.8, "thickness": 0.02, "n_segments": 16,
                                 "damping_ratio": 0.005}, {"duration": 5.0, "sample_rate": 6400.0},
                                {}, {}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 11)
