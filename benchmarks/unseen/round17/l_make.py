"""Write the round-17 linkage and small-rig scenarios (benchmarks/unseen/round17/{fb,cp,mm}17_*.toml):
rigs nobody tuned, default identifier settings, the earlier rounds' bars.  Run from the repository
root:

    python benchmarks/unseen/round17/l_make.py

Five-bars: the paper's linkage and sine unchanged (``fb17_paper``: held out on new seeds 81-84 at
1 and 3 %), a ground link shorter than the cranks (0.6 m under 1.2 m cranks), every link a
different length with the ground the shortest (0.9 / 1.3 / 0.8 / 1.1 over 0.7 m), the sine
started at phase 0 (the replay's motion starts at speed, not at rest) and the record at 2 kHz;
the multisine (``fivebar_multisine_noise1``) unchanged, with three tones, with tones up to 3 Hz
and with the centring gain kp 2 (rounds drew kp 10 only).  Cart-poles under
``cartpole_noise1``'s multisine and chain with the centring feedback changed (rounds 3-16 drew
kp 5, kd 2 only): kp 20 / kd 5, kp 1 / kd 1, kd 0, kp 0 (no centring: the cart is free), a
0.8 kg pole of 1.2 m, and tones up to 5 Hz.  Kinetics with the influx equal to Vmax (the
law's x term vanishes: three terms) and above it (2 of 1.5 mM/s: the substrate accumulates),
Km 1e-3 and 1e-4 mM (nearly zero-order: a sharp corner at x*), and a 5 kHz record.  Noise
levels and seeds 81-84 are the studies' (round17_linkages_*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: round 12's linkage writer
from round12 import l_make as _ROUND12  # noqa: E402

#: name -> (description, {table: keys changed from the paper's sine scenario})
FIVEBARS: dict[str, tuple[str, dict[str, dict]]] = {
    "fb17_paper": ("the paper's linkage and sine, unchanged (held out on new seeds)", {}),
    "fb17_ground_0p6": ("a ground link of 0.6 m under 1.2 m cranks, 1 m couplers",
                        {"rig": {"l1": 1.2, "l4": 1.2, "L0": 0.6}}),
    "fb17_all_diff_ground_short": (
        "every link a different length, the ground the shortest: 0.9 / 1.3 / 0.8 / 1.1 over 0.7 m",
        {"rig": {"l1": 0.9, "l2": 1.3, "l3": 0.8, "l4": 1.1, "L0": 0.7}},
    ),
    "fb17_phase0": ("the paper's sine started at phase 0 (the motion starts at speed)",
                    {"excitation": {"phase": 0.0}}),
    "fb17_fs2000": ("the paper's sine recorded at 2 kHz", {"simulation": {"sample_rate": 2000.0}}),
}

#: name -> (description, {table: keys changed from fivebar_multisine_noise1})
MULTISINES: dict[str, tuple[str, dict[str, dict]]] = {
    "fb17_ms_paper": ("the multisine, unchanged (held out at 5 and 8 %)", {}),
    "fb17_ms_tones3": ("the multisine with 3 tones", {"excitation": {"n_tones": 3}}),
    "fb17_ms_fmax3": ("the multisine with tones up to 3 Hz", {"excitation": {"f_max": 3.0}}),
    "fb17_ms_kp2": ("the multisine with the centring gain kp 2 N m/rad", {"excitation": {"kp": 2.0}}),
}

#: name -> (description, {table: keys changed from cartpole_noise1 (its multisine kept)})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp17_kp20_kd5": ("centring kp 20 N/m, kd 5 N s/m", {"excitation": {"kp": 20.0, "kd": 5.0}}),
    "cp17_kp1_kd1": ("centring kp 1 N/m, kd 1 N s/m", {"excitation": {"kp": 1.0, "kd": 1.0}}),
    "cp17_kd0": ("centring kp 5 N/m, no centring damping (kd 0)", {"excitation": {"kd": 0.0}}),
    "cp17_kp0": ("no centring stiffness (kp 0, kd 2): the cart's position is free",
                 {"excitation": {"kp": 0.0}}),
    "cp17_pole0p8_L1p2": ("a 0.8 kg pole of 1.2 m on the 1 kg cart",
                          {"rig": {"pole_mass": 0.8, "pole_length": 1.2}}),
    "cp17_fmax5": ("the multisine's tones up to 5 Hz", {"excitation": {"f_max": 5.0}}),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1}); Km 0.3, Vmax 1.5
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm17_jx_eq_vmax": ("the influx equal to Vmax (1.5 mM/s): the law's x term vanishes",
                        {"rig": {"jx": 1.5}}),
    "mm17_jx2_over_vmax": ("an influx of 2 mM/s over Vmax 1.5: the substrate accumulates",
                           {"rig": {"jx": 2.0}}),
    "mm17_km1em3": ("Km 1e-3 mM (nearly zero-order): x falls at 0.9 mM/s to x* 6.7e-4 mM at 2.2 s",
                    {"rig": {"Km": 0.001}}),
    "mm17_km1em4": ("Km 1e-4 mM: x falls at 0.9 mM/s to x* 6.7e-5 mM at 2.2 s",
                    {"rig": {"Km": 0.0001}}),
    "mm17_fs5000": ("the weak setup recorded at 5 kHz", {"simulation": {"sample_rate": 5000.0}}),
}


_write = _ROUND12.writer_for(HERE, 17)


def main() -> None:
    _ROUND12.write_sets(_write, FIVEBARS, CARTPOLES, KINETICS, "2-16", MULTISINES)


if __name__ == "__main__":
    main()
