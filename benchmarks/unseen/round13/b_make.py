"""Write the round-13 beam scenarios (benchmarks/unseen/round13/b13_*.toml): cantilevers nobody
tuned, default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round13/b_make.py

Each case is round 6's base beam (the shipped steel beam, 0.3175 m x 30 mm x 10 mm, 10 segments,
1 % damping, 50 N / 0.3 ms hammer at the tip, ``lowpass_hz = "auto"``) recorded for 5 s at
6.4 kHz (the lab rate of round 13), with the keys below changed.  Round 13 goes where the
families (``studies/families.toml``) do not draw: soft bases with ``base_k1`` below and above
``beams_soft``'s 0.5-3 EI / L (0.2-0.4 and 4-10 EI / L) and cubic fractions (``k3 q_peak^2 /
k1``, the families' own ``peak_base_rotation`` estimate) beyond its 0-0.6 (0.65-1.0) or far
below it (0.05); a polyamide (nylon: E 2.7 GPa, 1140 kg/m^3) and a polymer beam of 5.7 Hz,
aluminium thin-and-wide (60 x 4 mm), a titanium square (15 x 15 mm), a tall steel section
(10 mm wide, 30 mm tall, mode 2 at 1.75 kHz); 9-24 segments; 2-6 sensors at positions the
families' Dirichlet draw does not put them (no tip sensor, clusters at 0.3-0.6 L, five
unevenly spaced); the hammer at mid-span and at 90 % of the length (it must land on a sensor);
5-15 s records.  Noise 1 / 2 % and seeds 41-44 are the studies' (round13_beams_noise*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: round 6's writer is round6/b_make.py
sys.path.insert(0, str(HERE.parents[2]))  # the repository root: the families' base-rotation rule
from round6 import b_make as _ROUND6  # noqa: E402

from testbed.studies.family import peak_base_rotation  # noqa: E402

L, AL, TI, GFRP = _ROUND6.L, _ROUND6.AL, _ROUND6.TI, _ROUND6.GFRP
#: polyamide 6 (nylon), dry: E [Pa], rho [kg/m^3] (no round used it)
PA = {"E": 2.7e9, "rho": 1140.0}
#: round 13's record: 5 s at 6.4 kHz
SIM = {"duration": 5.0, "sample_rate": 6400.0}
#: round 6's base beam (the shipped steel beam and hammer), for the soft-base rule below
BASE_RIG = {"E": 210e9, "rho": 7850.0, "width": 0.03, "thickness": 0.01, "length": L}
BASE_EXC = {"peak_force": 50.0, "pulse_duration": 3e-4, "location": 0.0}


def soft(ratio: float, fraction: float, rig: dict, exc: dict | None = None) -> dict:
    """A soft base of ``base_k1 = ratio * EI / L`` and ``base_k3`` putting the cubic moment at
    ``fraction`` of the linear one at the families' estimated peak base rotation (``beams_soft``'s
    ``base_k1_ratio`` and ``cubic_fraction`` rules, ``testbed/studies/family.py``), for the beam
    ``rig`` (keys over round 6's base beam) under ``exc``."""
    r = {**BASE_RIG, **rig}
    e = {**BASE_EXC, **(exc or {})}
    k1 = ratio * r["E"] * r["width"] * r["thickness"] ** 3 / 12.0 / r["length"]
    q = peak_base_rotation({**r, "base_k1": k1}, e)
    return {"base": "soft", "base_k1": float(f"{k1:.4g}"),
            "base_k3": float(f"{fraction * k1 / q**2:.3g}")}


def at(x: float, length: float = L) -> float:
    """A position ``x * length`` [m] rounded to 0.1 mm (the scenario files' precision)."""
    return round(x * length, 4)


def sim(**kw) -> dict:
    """Round 13's record with ``kw`` changed."""
    return {**SIM, **kw}


_TI_SQ = {**TI, "length": 0.3, "width": 0.025, "thickness": 0.012}
_AL_MID = {**AL, "width": 0.03, "thickness": 0.01}
_ST_06 = {"length": 0.6, "thickness": 0.01, "n_segments": 24, "damping_ratio": 0.005}

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # soft bases softer than beams_soft's 0.5 EI / L
    "b13_soft_r0p3_cf0p8": ("the shipped beam on a soft base k1 = 0.3 EI/L, cubic fraction 0.8, 0.5 % "
                            "damping, 10 s, high-pass 'auto'",
                            {"damping_ratio": 0.005, **soft(0.3, 0.8, {})}, sim(duration=10.0), {},
                            {"highpass_hz": "auto"}),
    "b13_soft_r0p4_cf0p05_ti_n12": ("titanium 0.3 m x 25 x 12 mm on k1 = 0.4 EI/L, cubic fraction "
                                    "0.05, 12 segments, sensors at 0.3 / 0.6 / 1.0 L",
                                    {**_TI_SQ, "n_segments": 12, **soft(0.4, 0.05, _TI_SQ),
                                     "sensors": [at(0.3, 0.3), at(0.6, 0.3), 0.3]}, sim(), {},
                                    {"highpass_hz": "auto"}),
    "b13_soft_r0p2_al_hmid_s2": ("aluminium 0.3175 m x 30 x 10 mm on k1 = 0.2 EI/L, cubic fraction 0.4, "
                                 "sensors at L/2 and L, hammer at mid-span, 10 s, high-pass 'auto'",
                                 {**_AL_MID, "damping_ratio": 0.005,
                                  **soft(0.2, 0.4, _AL_MID, {"location": at(0.5)}),
                                  "sensors": [at(0.5), L]}, sim(duration=10.0),
                                 {"location": at(0.5)}, {"highpass_hz": "auto"}),
    "b13_soft_r0p3_pa_L0p3": ("polyamide 0.3 m x 30 x 10 mm on k1 = 0.3 EI/L, cubic fraction 0.3, 3 % "
                              "damping, 12 s, hammer at 0.5 s, high-pass 'auto'",
                              {**PA, "length": 0.3, "damping_ratio": 0.03,
                               **soft(0.3, 0.3, {**PA, "length": 0.3}),
                               "sensors": [0.1, 0.2, 0.3]}, sim(duration=12.0),
                              {"start": 0.5}, {"highpass_hz": "auto"}),
    # soft bases stiffer than beams_soft's 3 EI / L
    "b13_soft_r4_cf0p7_al_s2": ("aluminium 0.3 m x 30 x 10 mm on k1 = 4 EI/L, cubic fraction 0.7, "
                                "sensors at 0.55 L and L",
                                {**AL, "length": 0.3, **soft(4.0, 0.7, {**AL, "length": 0.3}),
                                 "sensors": [at(0.55, 0.3), 0.3]}, sim(), {}, {}),
    "b13_soft_r8_cf0p3_s4_n14": ("steel 0.4 m x 30 x 8 mm on k1 = 8 EI/L, cubic fraction 0.3, 14 "
                                 "segments, sensors at 0.2 / 0.45 / 0.7 / 1.0 L",
                                 {"length": 0.4, "thickness": 0.008, "n_segments": 14,
                                  **soft(8.0, 0.3, {"length": 0.4, "thickness": 0.008}),
                                  "sensors": [0.08, 0.18, 0.28, 0.4]}, sim(), {}, {}),
    "b13_soft_r5_cf1_hmid": ("the shipped beam on k1 = 5 EI/L, cubic fraction 1.0, sensors at 0.5 / "
                             "0.75 / 1.0 L, hammer at mid-span",
                             {**soft(5.0, 1.0, {}, {"location": at(0.5)}),
                              "sensors": [at(0.5), at(0.75), L]}, sim(), {"location": at(0.5)}, {}),
    "b13_soft_r10_cf0p2_s6_n24": ("steel 0.6 m x 30 x 10 mm on k1 = 10 EI/L, cubic fraction 0.2, 24 "
                                  "segments, six sensors, 0.5 % damping",
                                  {**_ST_06, **soft(10.0, 0.2, _ST_06),
                                   "sensors": [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]}, sim(), {}, {}),
    "b13_soft_r3p5_cf0p65_ti_h0p9": ("titanium 0.3 m x 25 x 12 mm on k1 = 3.5 EI/L, cubic fraction 0.65, "
                                     "sensors at 0.3 L and 0.9 L, hammer at 0.9 L",
                                     {**_TI_SQ, **soft(3.5, 0.65, _TI_SQ, {"location": at(0.9, 0.3)}),
                                      "sensors": [at(0.3, 0.3), at(0.9, 0.3)]}, sim(),
                                     {"location": at(0.9, 0.3)}, {}),
    # a cubic fraction beyond beams_soft's 0.6 on a base inside its k1 range
    "b13_soft_r2_cf0p9_s5_n18": ("steel 0.5 m x 30 x 10 mm on k1 = 2 EI/L, cubic fraction 0.9, 18 "
                                 "segments, five sensors at 0.12 / 0.3 / 0.5 / 0.8 / 1.0 L",
                                 {"length": 0.5, "n_segments": 18,
                                  **soft(2.0, 0.9, {"length": 0.5}),
                                  "sensors": [0.06, 0.15, 0.25, 0.4, 0.5]}, sim(), {}, {}),
    # other materials and sections, clamped
    "b13_al_thin_wide": ("aluminium 0.3 m x 60 mm wide x 4 mm (mode 1 36 Hz), 0.5 % damping",
                         {**AL, "length": 0.3, "width": 0.06, "thickness": 0.004, "damping_ratio": 0.005,
                          "sensors": [0.1, 0.2, 0.3]}, sim(), {}, {}),
    "b13_ti_square_15": ("titanium 0.35 m x 15 x 15 mm (mode 1 100 Hz, mode 3 1.76 kHz), 12 segments",
                         {**TI, "length": 0.35, "width": 0.015, "thickness": 0.015, "n_segments": 12,
                          "sensors": [at(1 / 3, 0.35), at(2 / 3, 0.35), 0.35]}, sim(), {}, {}),
    "b13_st_tall_s2": ("steel 0.3 m, 10 mm wide x 30 mm tall (mode 1 278 Hz, mode 2 1.75 kHz), sensors at "
                       "L/2 and L, 200 N",
                       {"length": 0.3, "width": 0.01, "thickness": 0.03, "sensors": [0.15, 0.3]}, sim(),
                       {"peak_force": 200.0}, {}),
    "b13_pa_L0p25_z3": ("polyamide 0.25 m x 30 x 6 mm (mode 1 near 25 Hz), 3 % damping",
                        {**PA, "length": 0.25, "thickness": 0.006, "damping_ratio": 0.03,
                         "sensors": [0.08, 0.17, 0.25]}, sim(), {}, {}),
    "b13_pa_L0p65_s4_15s": ("polyamide 0.65 m x 40 x 10 mm (mode 1 5.7 Hz), 16 segments, four sensors, "
                            "2 % damping, hammer at 0.5 s, 15 s, high-pass 'auto'",
                            {**PA, "length": 0.65, "width": 0.04, "n_segments": 16, "damping_ratio": 0.02,
                             "sensors": [0.2, 0.35, 0.5, 0.65]}, sim(duration=15.0),
                            {"start": 0.5}, {"highpass_hz": "auto"}),
    "b13_al_n9_hmid": ("aluminium 0.3175 m x 30 x 10 mm, 9 segments, sensors at 0.5 / 0.75 / 1.0 L, "
                       "hammer at mid-span",
                       {**_AL_MID, "n_segments": 9, "sensors": [at(0.5), at(0.75), L]}, sim(),
                       {"location": at(0.5)}, {}),
    "b13_st_h0p9_notip": ("the shipped beam, sensors at 0.3 / 0.6 / 0.9 L (none at the tip), hammer at "
                          "0.9 L", {"sensors": [at(0.3), at(0.6), at(0.9)]}, sim(),
                          {"location": at(0.9)}, {}),
    "b13_ti_h0p9_s2_n16": ("titanium 0.4 m x 30 x 10 mm, 16 segments, sensors at 0.45 L and 0.9 L, hammer "
                           "at 0.9 L", {**TI, "length": 0.4, "n_segments": 16, "sensors": [0.18, 0.36]},
                           sim(), {"location": 0.36}, {}),
    "b13_st_s5_n15": ("steel 0.5 m x 30 x 10 mm (mode 5 at 1.9 kHz), 15 segments, five sensors at "
                      "0.24 / 0.54 / 0.66 / 0.82 / 1.0 L",
                      {"length": 0.5, "n_segments": 15, "sensors": [0.12, 0.27, 0.33, 0.41, 0.5]},
                      sim(), {}, {}),
    "b13_al_s2_mid": ("aluminium 0.4 m x 20 x 5 mm, sensors at 0.35 L and 0.65 L (none at the tip), "
                           "hammer on the outer one",
                           {**AL, "length": 0.4, "width": 0.02, "thickness": 0.005,
                            "sensors": [0.14, 0.26]}, sim(), {"location": 0.26}, {}),
    "b13_gfrp_s4_n20": ("glass-epoxy 0.3 m x 25 x 8 mm (mode 4 1.6 kHz), 20 segments, sensors at 0.2 / "
                        "0.45 / 0.7 / 1.0 L",
                        {**GFRP, "length": 0.3, "width": 0.025, "thickness": 0.008, "n_segments": 20,
                         "sensors": [0.06, 0.135, 0.21, 0.3]}, sim(), {}, {}),
    "b13_st_L0p8_z0p2_12s": ("steel 0.8 m x 30 x 10 mm (mode 1 13 Hz), 16 segments, 0.2 % damping, hammer "
                             "at 0.5 s, 12 s, high-pass 'auto'",
                             {"length": 0.8, "n_segments": 16, "damping_ratio": 0.002,
                              "sensors": [0.3, 0.55, 0.8]}, sim(duration=12.0), {"start": 0.5},
                             {"highpass_hz": "auto"}),
}


if __name__ == "__main__":
    _ROUND6.write_cases(CASES, HERE, 13)
