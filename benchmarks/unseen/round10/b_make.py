"""Write the round-10 beam scenarios (benchmarks/unseen/round10/b10_*.toml): cantilevers nobody
tuned, default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round10/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments,
1 % damping, 1 s at 12.8 kHz, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``) with
the keys below changed.  Round 10 visits corners rounds 3-9 did not: fine chains (30-60
segments) read by two to four sensors, sensors only on the beam's inner half (the hammer on the
outermost one, since it must land on a sensor), carbon fibre, tungsten, magnesium and PMMA,
long slender beams whose mode 1 sits at 1.1-2 x the default 10 Hz high-pass (or under it with
the high-pass "auto"), soft bases with a strong hardening cubic under 5-150 N (amplitude
scaling, the same rig), hammer contacts from 0.1 to 5 ms, 3.2 and 51.2 kHz.

The rig has no tip mass; heavy and light materials stand in for it.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: round 6's writer is round6/b_make.py
from round6 import b_make as _ROUND6  # noqa: E402

L, SOFT, AL, TI, BRASS, GFRP = (_ROUND6.L, _ROUND6.SOFT, _ROUND6.AL, _ROUND6.TI, _ROUND6.BRASS,
                                _ROUND6.GFRP)
#: materials no earlier round put on the beam (E [Pa], rho [kg/m^3]): unidirectional carbon
#: fibre / epoxy along the fibres, tungsten, magnesium alloy, PMMA
CFRP = {"E": 135e9, "rho": 1600.0}
W = {"E": 411e9, "rho": 19300.0}
MG = {"E": 45e9, "rho": 1740.0}
PMMA = {"E": 3.2e9, "rho": 1190.0}
#: a soft base with a strong hardening cubic (20 x the shipped k3 on 1.5 x its k1)
STRONG = {**SOFT, "base_k1": 3000.0, "base_k3": 5e10}

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # fine chains read by few sensors
    "b10_n40_s2": ("the shipped clamped beam in 40 segments, sensors at L/2 and L",
                   {"n_segments": 40, "sensors": [L / 2, L]}, {}, {}, {}),
    "b10_n60_s3": ("the shipped clamped beam in 60 segments, the default three sensors, 0.5 s",
                   {"n_segments": 60}, {"duration": 0.5}, {}, {}),
    "b10_n30_s4": ("the shipped clamped beam in 30 segments, four sensors at 0.1/0.17/0.24/0.3175 m",
                   {"n_segments": 30, "sensors": [0.1, 0.17, 0.24, L]}, {}, {}, {}),
    "b10_L1_n48_s2": ("steel 1 m x 30 mm in 48 segments, sensors at L/2 and L, 0.5 % damping, 2 s",
                      {"length": 1.0, "thickness": 0.03, "n_segments": 48, "damping_ratio": 0.005,
                       "sensors": [0.5, 1.0]}, {"duration": 2.0}, {}, {}),
    "b10_soft_n40_s2": ("the shipped soft base, 40 segments, sensors at L/2 and L",
                        {**SOFT, "n_segments": 40, "sensors": [L / 2, L]}, {}, {}, {}),
    "b10_z2_n40_s2": ("the shipped clamped beam in 40 segments, 2 % damping, sensors at L/2 and L",
                      {"n_segments": 40, "damping_ratio": 0.02, "sensors": [L / 2, L]}, {}, {}, {}),
    # sensors only on the inner half (the hammer on the outermost sensor)
    "b10_inner_s3": ("clamped, sensors at 0.05/0.1/0.15 m (inner half), hammer at 0.15 m, 20 segments",
                     {"n_segments": 20, "sensors": [0.05, 0.1, 0.15]}, {}, {"location": 0.15}, {}),
    "b10_inner_L1_s3": ("steel 1 m x 30 mm, sensors at 0.15/0.3/0.45 m, hammer at 0.45 m, 20 segments, "
                        "0.3 % damping, 2 s",
                        {"length": 1.0, "thickness": 0.03, "n_segments": 20, "damping_ratio": 0.003,
                         "sensors": [0.15, 0.3, 0.45]}, {"duration": 2.0}, {"location": 0.45}, {}),
    "b10_inner_s2_n30": ("clamped, 30 segments, sensors at 0.08 and 0.15 m, hammer at 0.15 m",
                         {"n_segments": 30, "sensors": [0.08, 0.15]}, {}, {"location": 0.15}, {}),
    "b10_soft_inner_s2": ("the shipped soft base, sensors at 0.08 and 0.15 m, hammer at 0.15 m",
                          {**SOFT, "sensors": [0.08, 0.15]}, {}, {"location": 0.15}, {}),
    "b10_soft_inner_s3": ("soft base k1 = 3000, k3 = 5e10, sensors at 0.05/0.1/0.15 m, hammer at "
                          "0.15 m, 20 segments",
                          {**STRONG, "n_segments": 20, "sensors": [0.05, 0.1, 0.15]}, {},
                          {"location": 0.15}, {}),
    # materials no round used
    "b10_cfrp_L0p6_s3": ("carbon fibre 0.6 m x 10 mm, 16 segments, 0.5 % damping, three sensors",
                         {**CFRP, "length": 0.6, "n_segments": 16, "damping_ratio": 0.005,
                          "sensors": [0.2, 0.4, 0.6]}, {}, {}, {}),
    "b10_cfrp_soft": ("carbon fibre on the shipped soft base",
                      {**CFRP, **SOFT}, {}, {}, {}),
    "b10_w_L0p5_h15": ("tungsten 0.5 m x 15 mm, 14 segments, 0.3 % damping",
                       {**W, "length": 0.5, "thickness": 0.015, "n_segments": 14,
                        "damping_ratio": 0.003}, {}, {}, {}),
    "b10_w_soft_k1_5e4": ("tungsten on a soft base k1 = 5e4, k3 = 1e11",
                          {**W, **SOFT, "base_k1": 5e4, "base_k3": 1e11}, {}, {}, {}),
    "b10_mg_L0p8_s3": ("magnesium 0.8 m x 20 mm, 16 segments, three sensors, 2 s",
                       {**MG, "length": 0.8, "thickness": 0.02, "n_segments": 16,
                        "sensors": [0.3, 0.55, 0.8]}, {"duration": 2.0}, {}, {}),
    "b10_pmma_L0p5_h8_s2": ("PMMA 0.5 m x 8 mm (mode 1 near 8.5 Hz), 16 segments, sensors at L/2 and L, "
                            "5 N hammer at 0.5 s, high-pass 'auto', 3 s",
                            {**PMMA, "length": 0.5, "thickness": 0.008, "n_segments": 16,
                             "sensors": [0.25, 0.5]}, {"duration": 3.0},
                            {"peak_force": 5.0, "start": 0.5}, {"highpass_hz": "auto"}),
    # long slender beams: mode 1 near the high-pass
    "b10_L1p5_h40_hp10": ("steel 1.5 m x 40 mm (mode 1 at 1.5 x the default 10 Hz high-pass), 20 "
                          "segments, three sensors, 0.5 % damping, 3 s",
                          {"length": 1.5, "thickness": 0.04, "n_segments": 20, "damping_ratio": 0.005,
                           "sensors": [0.5, 1.0, 1.5]}, {"duration": 3.0}, {}, {}),
    "b10_L1p5_h30_hp10": ("steel 1.5 m x 30 mm (mode 1 at 1.1 x the default 10 Hz high-pass), 20 "
                          "segments, three sensors, 0.5 % damping, 3 s",
                          {"length": 1.5, "thickness": 0.03, "n_segments": 20, "damping_ratio": 0.005,
                           "sensors": [0.5, 1.0, 1.5]}, {"duration": 3.0}, {}, {}),
    "b10_L2_h20_hpauto_s2": ("steel 2 m x 20 mm (mode 1 near 4.2 Hz), 30 segments, sensors at L/2 and "
                             "L, 0.5 % damping, high-pass 'auto', hammer at 0.5 s, 6 s at 3.2 kHz",
                             {"length": 2.0, "thickness": 0.02, "n_segments": 30, "damping_ratio": 0.005,
                              "sensors": [1.0, 2.0]}, {"duration": 6.0, "sample_rate": 3200.0},
                             {"start": 0.5}, {"highpass_hz": "auto"}),
    "b10_L3_h50_hpauto_s3": ("steel 3 m x 50 mm (mode 1 near 4.6 Hz), 30 segments, three sensors, "
                             "0.5 % damping, high-pass 'auto', hammer at 0.5 s, 6 s at 3.2 kHz",
                             {"length": 3.0, "thickness": 0.05, "n_segments": 30, "damping_ratio": 0.005,
                              "sensors": [1.0, 2.0, 3.0]}, {"duration": 6.0, "sample_rate": 3200.0},
                             {"start": 0.5}, {"highpass_hz": "auto"}),
    # a strong hardening cubic under 5-150 N (the same rig)
    **{f"b10_soft_strong_F{f}": (f"soft base k1 = 3000, k3 = 5e10, {f} N hammer",
                                 {**STRONG}, {}, {"peak_force": float(f)}, {})
       for f in (5, 20, 50, 150)},
    "b10_soft_strong_F50_s2": ("soft base k1 = 3000, k3 = 5e10, 50 N hammer, sensors at L/2 and L",
                               {**STRONG, "sensors": [L / 2, L]}, {}, {}, {}),
    "b10_soft_k1_800_k3_1e10_hpauto": ("soft base k1 = 800, k3 = 1e10, high-pass 'auto', hammer at "
                                       "0.4 s, 2 s",
                                       {**SOFT, "base_k1": 800.0, "base_k3": 1e10}, {"duration": 2.0},
                                       {"start": 0.4}, {"highpass_hz": "auto"}),
    # hammer contacts from 0.1 to 5 ms
    "b10_pulse_5ms": ("the shipped clamped beam, 5 ms contact (200 N)", {}, {},
                      {"pulse_duration": 5e-3, "peak_force": 200.0}, {}),
    "b10_pulse_1ms_L0p6": ("steel 0.6 m x 15 mm, 16 segments, 1 ms contact, 2 s",
                           {"length": 0.6, "thickness": 0.015, "n_segments": 16}, {"duration": 2.0},
                           {"pulse_duration": 1e-3}, {}),
    "b10_pulse_0p1ms_L1_s4": ("steel 1 m x 30 mm, 20 segments, four sensors, 0.1 ms contact (200 N), "
                              "0.3 % damping, 2 s",
                              {"length": 1.0, "thickness": 0.03, "n_segments": 20, "damping_ratio": 0.003,
                               "sensors": [0.25, 0.5, 0.75, 1.0]}, {"duration": 2.0},
                              {"pulse_duration": 1e-4, "peak_force": 200.0}, {}),
    "b10_soft_pulse_2ms": ("the shipped soft base, 2 ms contact", {**SOFT}, {}, {"pulse_duration": 2e-3}, {}),
    "b10_soft_strong_pulse_5ms": ("soft base k1 = 3000, k3 = 5e10, 5 ms contact (100 N)", {**STRONG}, {},
                                  {"pulse_duration": 5e-3, "peak_force": 100.0}, {}),
    # sample rates no round used
    "b10_fs51200_L0p15": ("steel 0.15 m x 10 mm (modes 1-3 at 0.37 / 2.3 / 6.5 kHz), 0.25 s at 51.2 kHz, "
                          "100 N / 0.1 ms",
                          {"length": 0.15}, {"duration": 0.25, "sample_rate": 51200.0},
                          {"pulse_duration": 1e-4, "peak_force": 100.0}, {}),
    "b10_soft_fs3200_s2": ("the shipped soft base, sensors at L/2 and L, 3.2 kHz",
                           {**SOFT, "sensors": [L / 2, L]}, {"sample_rate": 3200.0}, {}, {}),
    "b10_soft_L1_n40_s3": ("steel 1 m x 30 mm on a soft base k1 = 5e4, k3 = 1e11, 40 segments, three "
                           "sensors, 0.5 % damping, 2 s",
                           {**SOFT, "length": 1.0, "thickness": 0.03, "n_segments": 40,
                            "damping_ratio": 0.005, "base_k1": 5e4, "base_k3": 1e11,
                            "sensors": [0.35, 0.7, 1.0]}, {"duration": 2.0}, {}, {}),
    # the three 3.2 kHz rigs above are refused at load (their 0.3 ms pulse falls between two
    # sample instants: no force recorded); the same rigs with a 1 ms contact (3.2 periods)
    "b10_L2_h20_hpauto_s2_p1ms": ("as b10_L2_h20_hpauto_s2 with a 1 ms contact",
                                  {"length": 2.0, "thickness": 0.02, "n_segments": 30,
                                   "damping_ratio": 0.005, "sensors": [1.0, 2.0]},
                                  {"duration": 6.0, "sample_rate": 3200.0},
                                  {"start": 0.5, "pulse_duration": 1e-3}, {"highpass_hz": "auto"}),
    "b10_L3_h50_hpauto_s3_p1ms": ("as b10_L3_h50_hpauto_s3 with a 1 ms contact",
                                  {"length": 3.0, "thickness": 0.05, "n_segments": 30,
                                   "damping_ratio": 0.005, "sensors": [1.0, 2.0, 3.0]},
                                  {"duration": 6.0, "sample_rate": 3200.0},
                                  {"start": 0.5, "pulse_duration": 1e-3}, {"highpass_hz": "auto"}),
    "b10_soft_fs3200_s2_p1ms": ("as b10_soft_fs3200_s2 with a 1 ms contact",
                                {**SOFT, "sensors": [L / 2, L]}, {"sample_rate": 3200.0},
                                {"pulse_duration": 1e-3}, {}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 10)
