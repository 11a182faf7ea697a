"""Write the round-12 beam scenarios (benchmarks/unseen/round12/b12_*.toml): cantilevers nobody
tuned, default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round12/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments,
1 % damping, 1 s at 12.8 kHz, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``) with
the keys below changed.  Round 12 combines corners rounds 3-11 visited one at a time: a soft
base read by two sensors (run at 2-3 % noise in ``round12_beams_noise.toml``); long flexible
beams on a soft base (mode 1 at 2.4-6.1 Hz, Euler-Bernoulli with the base's linear spring;
k3 / k1 the shipped 1.25e6 rad^-2) under the high-pass "auto"; sensors clustered near the tip
and near the clamp on 20-segment and 1 m chains, two or three of them; 1-2 ms hammer contacts
on short stiff beams whose mode 2 lies above 2 kHz (0.12-0.16 m at 12.8 kHz, two sensors: with
three, mode 3 is above Nyquist and the rig refuses the low-pass "auto"); sample rates
that put mode 3 at 0.32-0.33 fs (the clamped shipped beam at 4.5 kHz, the soft base at
3.7 kHz, aluminium 0.5 m at 1.8 kHz).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: round 6's writer is round6/b_make.py
from round6 import b_make as _ROUND6  # noqa: E402

L, SOFT, AL = _ROUND6.L, _ROUND6.SOFT, _ROUND6.AL
#: the shipped soft base's k3 / k1 [rad^-2], kept on the long soft beams
K3_PER_K1 = 2.5e9 / 2000.0


def ei(E: float, thickness: float, width: float = 0.03) -> float:
    """Bending stiffness [N m^2] of a ``width`` x ``thickness`` [m] section of modulus ``E`` [Pa]."""
    return E * width * thickness**3 / 12


def soft_base(k1: float) -> dict:
    """A soft base of linear stiffness ``k1`` [N m/rad] with the shipped k3 / k1."""
    return {**SOFT, "base_k1": round(k1, 1), "base_k3": float(f"{K3_PER_K1 * k1:.3g}")}


def at(x: float, length: float = L) -> float:
    """A position ``x * length`` [m] rounded to 0.1 mm (the scenario files' precision)."""
    return round(x * length, 4)


#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # a soft base read by two sensors (noise 2-3 % in round12_beams_noise.toml)
    "b12_soft_s2_n16": ("the shipped soft base, 16 segments, sensors at 0.4 L and L",
                        {**SOFT, "n_segments": 16, "sensors": [at(0.4), L]}, {}, {}, {}),
    "b12_soft_k1_3000_k3_1e10_s2": ("soft base k1 = 3000, k3 = 1e10, sensors at L/2 and L",
                                    {**SOFT, "base_k1": 3000.0, "base_k3": 1e10,
                                     "sensors": [at(0.5), L]}, {}, {}, {}),
    "b12_soft_tip_cluster_s2": ("the shipped soft base, sensors at 0.9 L and L",
                                {**SOFT, "sensors": [at(0.9), L]}, {}, {}, {}),
    "b12_soft_root_cluster_s3": ("the shipped soft base, 20 segments, sensors at 0.1 / 0.15 / 0.2 L, "
                                 "hammer on the outer one",
                                 {**SOFT, "n_segments": 20, "sensors": [at(0.1), at(0.15), at(0.2)]},
                                 {}, {"location": at(0.2)}, {}),
    # long flexible beams on a soft base (mode 1 at 2.4-6.1 Hz), high-pass "auto"
    "b12_soft_L1p2_h10": ("steel 1.2 m x 10 mm on a soft base k1 = 1.2 EI/L (mode 1 2.8 Hz), 20 "
                          "segments, three sensors, 0.5 % damping, hammer at 0.5 s, 6 s at 6.4 kHz, "
                          "high-pass 'auto'",
                          {"length": 1.2, "n_segments": 20, "damping_ratio": 0.005,
                           **soft_base(1.2 * ei(210e9, 0.01) / 1.2), "sensors": [0.4, 0.8, 1.2]},
                          {"duration": 6.0, "sample_rate": 6400.0}, {"start": 0.5},
                          {"highpass_hz": "auto"}),
    "b12_soft_L2_h20_s2": ("steel 2 m x 20 mm on a soft base k1 = 2 EI/L (mode 1 2.4 Hz), 30 segments, "
                           "sensors at L/2 and L, 0.5 % damping, 200 N / 1 ms hammer at 0.5 s, 8 s "
                           "at 3.2 kHz, high-pass 'auto'",
                           {"length": 2.0, "thickness": 0.02, "n_segments": 30, "damping_ratio": 0.005,
                            **soft_base(2 * ei(210e9, 0.02) / 2.0), "sensors": [1.0, 2.0]},
                           {"duration": 8.0, "sample_rate": 3200.0},
                           {"start": 0.5, "pulse_duration": 1e-3, "peak_force": 200.0},
                           {"highpass_hz": "auto"}),
    "b12_soft_al_L1_h10": ("aluminium 1 m x 10 mm on a soft base k1 = 5 EI/L (mode 1 6.1 Hz), 20 "
                           "segments, three sensors, 0.5 % damping, hammer at 0.5 s, 4 s at 6.4 kHz, "
                           "high-pass 'auto'",
                           {**AL, "length": 1.0, "n_segments": 20, "damping_ratio": 0.005,
                            **soft_base(5 * ei(69e9, 0.01) / 1.0), "sensors": [0.35, 0.7, 1.0]},
                           {"duration": 4.0, "sample_rate": 6400.0}, {"start": 0.5},
                           {"highpass_hz": "auto"}),
    # sensors clustered near the tip or near the clamp
    "b12_tip_cluster_s2_n20": ("clamped, 20 segments, sensors at 0.95 L and L",
                               {"n_segments": 20, "sensors": [at(0.95), L]}, {}, {}, {}),
    "b12_root_cluster_s2_n20": ("clamped, 20 segments, sensors at 0.1 L and 0.2 L, hammer on the outer one",
                                {"n_segments": 20, "sensors": [at(0.1), at(0.2)]}, {},
                                {"location": at(0.2)}, {}),
    "b12_tip_cluster_L1": ("steel 1 m x 30 mm, 20 segments, sensors at 0.85 / 0.925 / 1 m, 0.5 % "
                           "damping, 2 s",
                           {"length": 1.0, "thickness": 0.03, "n_segments": 20, "damping_ratio": 0.005,
                            "sensors": [0.85, 0.925, 1.0]}, {"duration": 2.0}, {}, {}),
    "b12_root_cluster_L1": ("steel 1 m x 30 mm, 20 segments, sensors at 0.1 / 0.2 / 0.3 m, hammer at "
                            "0.3 m, 0.5 % damping, 2 s",
                            {"length": 1.0, "thickness": 0.03, "n_segments": 20, "damping_ratio": 0.005,
                             "sensors": [0.1, 0.2, 0.3]}, {"duration": 2.0}, {"location": 0.3}, {}),
    # 1-2 ms contacts on short stiff beams (mode 2 above 2 kHz at 12.8 kHz)
    "b12_short0p15_p1ms": ("steel 0.15 m x 10 mm (modes 0.37 / 2.3 / 6.5 kHz), sensors at L/2 and L, 1 ms "
                           "contact, 200 N, 0.5 s",
                           {"length": 0.15, "sensors": [0.075, 0.15]}, {"duration": 0.5},
                           {"pulse_duration": 1e-3, "peak_force": 200.0}, {}),
    "b12_short0p15_p2ms": ("steel 0.15 m x 10 mm, sensors at L/2 and L, 2 ms contact, 200 N, 0.5 s",
                           {"length": 0.15, "sensors": [0.075, 0.15]}, {"duration": 0.5},
                           {"pulse_duration": 2e-3, "peak_force": 200.0}, {}),
    "b12_short0p12_p1ms_s2": ("steel 0.12 m x 10 mm (modes 0.58 / 3.6 kHz), sensors at L/2 and L, 1 ms "
                              "contact, 200 N, 0.5 s",
                              {"length": 0.12, "sensors": [0.06, 0.12]}, {"duration": 0.5},
                              {"pulse_duration": 1e-3, "peak_force": 200.0}, {}),
    "b12_short0p16_p1p5ms": ("steel 0.16 m x 10 mm (modes 0.33 / 2.0 / 5.7 kHz), sensors at L/2 and L, "
                             "1.5 ms contact, 200 N, 0.5 s",
                             {"length": 0.16, "sensors": [0.08, 0.16]}, {"duration": 0.5},
                             {"pulse_duration": 1.5e-3, "peak_force": 200.0}, {}),
    # mode 3 at 0.32-0.33 fs
    "b12_fs4500": ("the shipped clamped beam at 4.5 kHz (mode 3 at 0.323 fs)",
                   {}, {"sample_rate": 4500.0}, {}, {}),
    "b12_soft_fs3700": ("the shipped soft base at 3.7 kHz (mode 3 at 0.325 fs), low-pass 1.6 kHz (the "
                        "rig refuses 'auto' here: it resolves to 2036 Hz, above Nyquist)",
                        {**SOFT}, {"sample_rate": 3700.0}, {}, {"lowpass_hz": 1600.0}),
    "b12_al_L0p5_fs1800": ("aluminium 0.5 m x 10 mm, 12 segments, 1.8 kHz (mode 3 at 0.318 fs), 1 ms "
                           "contact, 2 s",
                           {**AL, "length": 0.5, "n_segments": 12}, {"duration": 2.0, "sample_rate": 1800.0},
                           {"pulse_duration": 1e-3}, {}),
    "b12_fs4500_s2_tip": ("the shipped clamped beam at 4.5 kHz, sensors at 0.9 L and L",
                          {"sensors": [at(0.9), L]}, {"sample_rate": 4500.0}, {}, {}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 12)
