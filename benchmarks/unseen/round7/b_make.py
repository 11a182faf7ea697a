"""Write the round-7 beam scenarios (benchmarks/unseen/round7/b_*.toml): cantilevers nobody tuned,
default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round7/b_make.py

Each case is the shipped steel beam (0.3175 m x 30 mm x 10 mm, 10 segments, 1 % damping, 1 s at
12.8 kHz, 50 N / 0.3 ms hammer at the tip) with the keys below changed.  The shipped soft base is
k1 = 2000 N m/rad, k3 = 2.5e9 N m/rad^3.  ``lowpass_hz = "auto"`` (the families' low-pass between
the last sensed mode and the next) unless a case says otherwise.  Round 7 varies materials and
sections, 0.2-2 m, 2-8 sensors and their placement, hammer position and pulse width, clamped
damping 0.1-5 %, soft bases across k1 and k3 (k3 = 0 included), and sample rates.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: round 6's writer is round6/b_make.py
from round6 import b_make as _ROUND6  # noqa: E402

L, SOFT, AL, TI, BRASS, GFRP = (_ROUND6.L, _ROUND6.SOFT, _ROUND6.AL, _ROUND6.TI, _ROUND6.BRASS,
                                _ROUND6.GFRP)
HPA = {"highpass_hz": "auto"}


def even(n: int, length: float = L) -> list[float]:
    """n sensors evenly spaced to the tip [m]."""
    return [round(length * (k + 1) / n, 6) for k in range(n)]


#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # materials and sections (clamped)
    "b_alu_L0p5": ("aluminium 0.5 m, 14 segments, 2 s", {**AL, "length": 0.5, "n_segments": 14},
                   {"duration": 2.0}, {}, {}),
    "b_ti_L0p4": ("titanium 0.4 m, 12 segments", {**TI, "length": 0.4, "n_segments": 12}, {}, {}, {}),
    "b_brass": ("brass, shipped geometry", {**BRASS}, {}, {}, {}),
    "b_gfrp": ("glass-epoxy, shipped geometry", {**GFRP}, {}, {}, {}),
    "b_thin3mm": ("steel 3 mm deep (mode 1 at 25 Hz), 2 s", {"thickness": 0.003}, {"duration": 2.0}, {}, {}),
    "b_thick25mm": ("steel 25 mm deep (mode 1 at 207 Hz)", {"thickness": 0.025}, {}, {}, {}),
    "b_narrow": ("steel 10 mm wide", {"width": 0.01}, {}, {}, {}),
    "b_wide": ("steel 100 mm wide", {"width": 0.1}, {}, {}, {}),
    # length
    "b_short0p2": ("steel 0.2 m (mode 1 at 209 Hz)", {"length": 0.2}, {}, {}, {}),
    "b_short0p2_alu5mm": ("aluminium 0.2 m x 5 mm", {**AL, "length": 0.2, "thickness": 0.005}, {}, {}, {}),
    "b_L1p5_40mm": ("steel 1.5 m x 40 mm (mode 1 at 15 Hz), 20 segments, 3 s, 5 kHz",
                    {"length": 1.5, "thickness": 0.04, "n_segments": 20},
                    {"duration": 3.0, "sample_rate": 5000.0}, {}, {}),
    "b_L1p5_hpauto": ("steel 1.5 m x 10 mm (mode 1 at 3.7 Hz), 20 segments, 8 s at 5 kHz, high-pass "
                      "'auto', hammer at 0.5 s", {"length": 1.5, "n_segments": 20},
                      {"duration": 8.0, "sample_rate": 5000.0}, {"start": 0.5}, HPA),
    "b_L2_60mm": ("steel 2 m x 60 mm (mode 1 at 12.5 Hz), 20 segments, 3 s at 5 kHz",
                  {"length": 2.0, "thickness": 0.06, "n_segments": 20},
                  {"duration": 3.0, "sample_rate": 5000.0}, {}, {}),
    "b_L2_alu_hpauto": ("aluminium 2 m x 50 mm (mode 1 at 10.2 Hz), 20 segments, 4 s at 5 kHz, "
                        "high-pass 'auto', hammer at 0.5 s",
                        {**AL, "length": 2.0, "thickness": 0.05, "n_segments": 20},
                        {"duration": 4.0, "sample_rate": 5000.0}, {"start": 0.5}, HPA),
    # sensor counts and placements
    "b_s2_mid": ("two sensors at 0.3 L and 0.7 L, hammer at 0.7 L",
                 {"sensors": [0.3 * L, 0.7 * L]}, {}, {"location": 0.7 * L}, {}),
    "b_s4": ("four sensors evenly spaced, 12 segments", {"sensors": even(4), "n_segments": 12}, {}, {}, {}),
    "b_s6": ("0.6 m, six sensors evenly spaced, 18 segments, 2 s",
             {"length": 0.6, "sensors": even(6, 0.6), "n_segments": 18}, {"duration": 2.0}, {}, {}),
    "b_s8": ("1 m x 30 mm, eight sensors evenly spaced, 24 segments, 2 s",
             {"length": 1.0, "thickness": 0.03, "sensors": even(8, 1.0), "n_segments": 24},
             {"duration": 2.0}, {}, {}),
    "b_s8_z0p15": ("as b_s8 with 0.15 % damping (mode 8 damped 24 %, within the families' 30 %; "
                   "at 1 % it is overdamped, 1.6)",
                   {"length": 1.0, "thickness": 0.03, "sensors": even(8, 1.0), "n_segments": 24,
                    "damping_ratio": 0.0015}, {"duration": 2.0}, {}, {}),
    # not in the study: sensed modes above the Nyquist frequency (refused, naming the key)
    "b_s6_short": ("six sensors on the shipped 0.3175 m beam, 18 segments (mode 6 at 7 kHz)",
                   {"sensors": even(6), "n_segments": 18}, {}, {}, {}),
    "b_s3_irregular": ("sensors at 0.15, 0.55, 0.95 L, hammer at 0.95 L",
                       {"sensors": [0.15 * L, 0.55 * L, 0.95 * L]}, {}, {"location": 0.95 * L}, {}),
    "b_s2_tip": ("two sensors at 0.9 L and L", {"sensors": [0.9 * L, L]}, {}, {}, {}),
    "b_s5_alu_L0p6": ("aluminium 0.6 m, five sensors, 16 segments, 2 s",
                      {**AL, "length": 0.6, "n_segments": 16, "sensors": even(5, 0.6)},
                      {"duration": 2.0}, {}, {}),
    # hammer position and pulse width
    "b_hit_mid": ("sensors at L/4, L/2, L, hammer at L/2 (a hammer between sensors is refused, "
                  "naming excitation.location)", {"sensors": [L / 4, L / 2, L]}, {}, {"location": L / 2}, {}),
    "b_hit_2L3": ("hammer at sensor 2 (2L/3)", {}, {}, {"location": 2 * L / 3}, {}),
    "b_pulse0p1ms": ("a 0.1 ms pulse", {}, {}, {"pulse_duration": 1e-4}, {}),
    "b_pulse1ms": ("a 1 ms pulse", {}, {}, {"pulse_duration": 1e-3}, {}),
    "b_pulse2ms": ("a 2 ms pulse (spectrum's first zero near mode 2)", {}, {}, {"pulse_duration": 2e-3}, {}),
    "b_pulse1ms_200N": ("a 1 ms, 200 N pulse", {}, {}, {"pulse_duration": 1e-3, "peak_force": 200.0}, {}),
    # clamped damping
    "b_z0p1": ("0.1 % damping, 2 s", {"damping_ratio": 0.001}, {"duration": 2.0}, {}, {}),
    "b_z0p5": ("0.5 % damping", {"damping_ratio": 0.005}, {}, {}, {}),
    "b_z2": ("2 % damping", {"damping_ratio": 0.02}, {}, {}, {}),
    "b_z5": ("5 % damping", {"damping_ratio": 0.05}, {}, {}, {}),
    # soft bases across k1 and k3
    "b_soft_k1_500": ("soft base k1 = 500 N m/rad", {**SOFT, "base_k1": 500.0}, {}, {}, {}),
    "b_soft_k1_1000": ("soft base k1 = 1000 N m/rad", {**SOFT, "base_k1": 1000.0}, {}, {}, {}),
    "b_soft_k1_5000": ("soft base k1 = 5000 N m/rad", {**SOFT, "base_k1": 5000.0}, {}, {}, {}),
    "b_soft_k3_0": ("soft base with k3 = 0 (a linear spring)", {**SOFT, "base_k3": 0.0}, {}, {}, {}),
    "b_soft_k3_1e8": ("soft base k3 = 1e8 N m/rad^3", {**SOFT, "base_k3": 1e8}, {}, {}, {}),
    "b_soft_k3_1e10": ("soft base k3 = 1e10 N m/rad^3", {**SOFT, "base_k3": 1e10}, {}, {}, {}),
    "b_soft_k1_5000_k3_1e10": ("soft base k1 = 5000, k3 = 1e10", {**SOFT, "base_k1": 5000.0,
                                                                   "base_k3": 1e10}, {}, {}, {}),
    "b_soft_alu": ("aluminium on the shipped soft base", {**AL, **SOFT}, {}, {}, {}),
    "b_soft_s4": ("soft base, four sensors, 12 segments", {**SOFT, "sensors": even(4), "n_segments": 12},
                  {}, {}, {}),
    "b_soft_pulse1ms": ("soft base, a 1 ms pulse", {**SOFT}, {}, {"pulse_duration": 1e-3}, {}),
    "b_soft_z0p1": ("soft base, 0.1 % damping", {**SOFT, "damping_ratio": 0.001}, {}, {}, {}),
    # sample rates
    "b_fs6400": ("clamped, 6.4 kHz", {}, {"sample_rate": 6400.0}, {}, {}),
    "b_fs20000": ("clamped, 20 kHz", {}, {"sample_rate": 20000.0}, {}, {}),
    "b_soft_fs6400": ("soft base, 6.4 kHz", {**SOFT}, {"sample_rate": 6400.0}, {}, {}),
    "b_soft_fs20000": ("soft base, 20 kHz", {**SOFT}, {"sample_rate": 20000.0}, {}, {}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 7)
