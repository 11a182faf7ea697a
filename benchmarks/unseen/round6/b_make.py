"""Write the round-6 beam scenarios (benchmarks/unseen/round6/b_*.toml): cantilevers nobody tuned,
default identifier settings, the families' bars.  Run from the repository root:

    python benchmarks/unseen/round6/b_make.py

Each case is the shipped steel beam (0.3175 m x 30 mm x 10 mm, 10 segments, 1 % damping, 1 s at
12.8 kHz, 50 N / 0.3 ms hammer at the tip) with the keys below changed.  The shipped soft base is
k1 = 2000 N m/rad, k3 = 2.5e9 N m/rad^3.  ``lowpass_hz = "auto"`` (the families' low-pass between
the last sensed mode and the next) unless a case says otherwise.
"""

from __future__ import annotations

from pathlib import Path

HERE = Path(__file__).resolve().parent
L = 0.3175
SOFT = {"base": "soft", "base_k1": 2000.0, "base_k3": 2.5e9}
#: materials the later rounds put on the same base beam (E [Pa], rho [kg/m^3])
AL = {"E": 69e9, "rho": 2700.0}
TI = {"E": 116e9, "rho": 4500.0}
BRASS = {"E": 100e9, "rho": 8500.0}
GFRP = {"E": 20e9, "rho": 1900.0}
EI = 210e9 * 0.03 * 0.01**3 / 12  # N m^2 of the shipped section

#: name -> (description, rig, simulation, excitation, signal)
CASES: dict[str, tuple[str, dict, dict, dict, dict]] = {
    # combinations
    "b_soft_L0p6_n12": ("0.6 m on a soft base (k1 = 1.2 EI/L, the shipped ratio), 12 segments",
                        {"length": 0.6, "n_segments": 12, **SOFT, "base_k1": 1.2 * EI / 0.6}, {}, {}, {}),
    "b_soft_L1_n16_s4": ("1 m on a soft base (k1 = 1.2 EI/L), 16 segments, 4 sensors, 3 s",
                         {"length": 1.0, "n_segments": 16, **SOFT, "base_k1": 1.2 * EI / 1.0,
                          "sensors": [0.25, 0.5, 0.75, 1.0]}, {"duration": 3.0}, {}, {}),
    "b_soft_s2": ("shipped soft base, two sensors (L/2, L)",
                  {**SOFT, "sensors": [L / 2, L]}, {}, {}, {}),
    "b_soft_s2_nolp": ("shipped soft base, two sensors (L/2, L), no low-pass (the default)",
                       {**SOFT, "sensors": [L / 2, L]}, {}, {}, {"lowpass_hz": 0.0}),
    "b_stiff_s2_nolp": ("clamped, two sensors (L/2, L), no low-pass (the default)",
                        {"sensors": [L / 2, L]}, {}, {}, {"lowpass_hz": 0.0}),
    "b_stiff_s2": ("clamped, two sensors (L/2, L)", {"sensors": [L / 2, L]}, {}, {}, {}),
    # sensor placements
    "b_tip_cluster": ("clamped, sensors at 0.8, 0.9, 1.0 L", {"sensors": [0.254, 0.28575, L]}, {}, {}, {}),
    "b_root_cluster": ("clamped, sensors at 0.1, 0.2, 0.3 L, hammer on the outer one",
                       {"sensors": [0.03175, 0.0635, 0.09525]}, {}, {"location": 0.09525}, {}),
    "b_soft_tip_cluster": ("soft base, sensors at 0.8, 0.9, 1.0 L",
                           {**SOFT, "sensors": [0.254, 0.28575, L]}, {}, {}, {}),
    "b_soft_root_cluster": ("soft base, sensors at 0.1, 0.2, 0.3 L, hammer on the outer one",
                            {**SOFT, "sensors": [0.03175, 0.0635, 0.09525]}, {}, {"location": 0.09525}, {}),
    # hammer on soft bases
    "b_soft_hit_L3": ("soft base, hammer at sensor 1 (L/3)", {**SOFT}, {}, {"location": L / 3}, {}),
    "b_soft_hit_root": ("soft base, sensors 0.05 m, L/2, L, hammer at 0.05 m",
                        {**SOFT, "sensors": [0.05, L / 2, L]}, {}, {"location": 0.05}, {}),
    # damping with soft bases
    "b_soft_z0p3": ("soft base, 0.3 % damping", {**SOFT, "damping_ratio": 0.003}, {}, {}, {}),
    "b_soft_z2": ("soft base, 2 % damping", {**SOFT, "damping_ratio": 0.02}, {}, {}, {}),
    "b_soft_z3": ("soft base, 3 % damping", {**SOFT, "damping_ratio": 0.03}, {}, {}, {}),
    "b_soft_z5": ("soft base, 5 % damping", {**SOFT, "damping_ratio": 0.05}, {}, {}, {}),
    # stiff soft bases: the clamped limit
    "b_soft_k1_2e4": ("soft base k1 = 2e4 N m/rad (30 EI/L)", {**SOFT, "base_k1": 2e4}, {}, {}, {}),
    "b_soft_k1_2e5": ("soft base k1 = 2e5 N m/rad", {**SOFT, "base_k1": 2e5}, {}, {}, {}),
    "b_soft_k1_2e6": ("soft base k1 = 2e6 N m/rad", {**SOFT, "base_k1": 2e6}, {}, {}, {}),
    "b_soft_k1_2e7": ("soft base k1 = 2e7 N m/rad", {**SOFT, "base_k1": 2e7}, {}, {}, {}),
    "b_soft_k1_2e8": ("soft base k1 = 2e8 N m/rad (3e5 EI/L)", {**SOFT, "base_k1": 2e8}, {}, {}, {}),
    "b_stiff_ref": ("clamped reference for the stiff-base limit", {}, {}, {}, {}),
    # odd segment counts
    **{f"b_n{n}": (f"clamped, {n} segments", {"n_segments": n}, {}, {}, {}) for n in (5, 7, 9, 11, 13)},
    # sample rates
    **{f"b_fs{fs}": (f"clamped, {fs} Hz", {}, {"sample_rate": float(fs)}, {}, {})
       for fs in (5000, 8000, 10240, 16000, 25600)},
    # high-pass 'auto' where the 10 Hz default cuts into mode 1 (rounds 4-5 open cases)
    "b_soft_alu_k1_300_s2_hpauto": ("aluminium 0.5 m, 12 segments, soft base k1 = 300, k3 = 1e8, two "
                                    "sensors, 0.3 % damping, 2 s, high-pass 'auto'",
                                    {"E": 69e9, "rho": 2700.0, "length": 0.5, "n_segments": 12,
                                     "damping_ratio": 0.003, "base": "soft", "base_k1": 300.0,
                                     "base_k3": 1e8, "sensors": [0.25, 0.5]}, {"duration": 2.0}, {},
                                    {"highpass_hz": "auto"}),
    "b_soft_alu_k1_300_s2": ("as b_soft_alu_k1_300_s2_hpauto with the default 10 Hz high-pass",
                             {"E": 69e9, "rho": 2700.0, "length": 0.5, "n_segments": 12,
                              "damping_ratio": 0.003, "base": "soft", "base_k1": 300.0,
                              "base_k3": 1e8, "sensors": [0.25, 0.5]}, {"duration": 2.0}, {}, {}),
    "b_L1p2_hpauto": ("clamped 1.2 m x 10 mm (mode 1 at 5.6 Hz), 16 segments, 5 s, high-pass 'auto'",
                      {"length": 1.2, "n_segments": 16}, {"duration": 5.0}, {}, {"highpass_hz": "auto"}),
    "b_L1p2_hpauto_start0p5": ("as b_L1p2_hpauto with the hammer at 0.5 s (the zero-phase 2.9 Hz "
                               "high-pass spreads the pulse ~0.3 s back in time)",
                               {"length": 1.2, "n_segments": 16}, {"duration": 5.5},
                               {"start": 0.5}, {"highpass_hz": "auto"}),
    "b_soft_L0p6_n12_hpauto": ("as b_soft_L0p6_n12 (mode 1 at 1.07x the 10 Hz high-pass) with the "
                               "high-pass 'auto' and 2 s",
                               {"length": 0.6, "n_segments": 12, **SOFT, "base_k1": 1.2 * EI / 0.6},
                               {"duration": 2.0}, {}, {"highpass_hz": "auto"}),
    "b_soft_L1_n16_s4_hpauto": ("as b_soft_L1_n16_s4 (mode 1 at 4 Hz) with the high-pass 'auto' and 5 s",
                                {"length": 1.0, "n_segments": 16, **SOFT, "base_k1": 1.2 * EI / 1.0,
                                 "sensors": [0.25, 0.5, 0.75, 1.0]}, {"duration": 5.0}, {},
                                {"highpass_hz": "auto"}),
    "b_L1p2": ("as b_L1p2_hpauto with the default 10 Hz high-pass",
               {"length": 1.2, "n_segments": 16}, {"duration": 5.0}, {}, {}),
}

BARS = """# The families' bars.
[score]
trac_min = 0.90
mac_mode1_min = 0.90
mac_mode2_min = 0.90
freq_error_mode1_max = 0.026
freq_error_mode2_max = 0.026
"""


def value(v) -> str:
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, list):
        return "[" + ", ".join(value(x) for x in v) + "]"
    return repr(float(v)) if isinstance(v, float) else str(v)


def scenario_text(name: str, desc: str, rig: dict, sim: dict, exc: dict, sig: dict,
                  round_no: int = 6) -> str:
    base = rig.get("base", "stiff")
    tables = {
        "rig": {"E": 210e9, "rho": 7850.0, "width": 0.03, "thickness": 0.01, "length": L,
                "n_segments": 10, "damping_ratio": 0.01, "base": "stiff", **rig},
        "simulation": {"duration": 1.0, "sample_rate": 12800.0, **sim},
        "excitation": {"type": "impact", "peak_force": 50.0, "pulse_duration": 3e-4,
                       "location": 0.0, "start": 0.005, **exc},
        "noise": {"rms_percent": 0.0},
        "signal": {"lowpass_hz": "auto", **sig},
    }
    tags = ["structural", "cantilever", "impact"] + (["nonlinear", "cubic"] if base == "soft" else ["linear"])
    out = [f'[scenario]\nname = "{name}"\nrig = "cantilever"\nseed = 0\n'
           f'description = "Rigs nobody tuned, round {round_no}: {desc}"\n'
           f"tags = {value(tags)}\n"]
    for t, kv in tables.items():
        out.append(f"[{t}]\n" + "".join(f"{k} = {value(v)}\n" for k, v in kv.items()))
    out.append('[identify]\nmethod = "sgd_sindy"\n')
    out.append(BARS)
    return "\n".join(out)


def write_cases(cases: dict, here: Path, round_no: int) -> None:
    """Write each case as ``here/<name>.toml`` (a round's scenario files) and say how many."""
    for name, (desc, rig, sim, exc, sig) in cases.items():
        (here / f"{name}.toml").write_text(scenario_text(name, desc, rig, sim, exc, sig, round_no))
    print(f"{len(cases)} scenarios in {here}")


if __name__ == "__main__":
    write_cases(CASES, HERE, 6)
