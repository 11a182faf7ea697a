"""Write the round-19 linkage and small-rig scenarios (benchmarks/unseen/round19/{fb,cp,mm}19_*.toml):
rigs nobody tuned, default identifier settings, the earlier rounds' bars.  Run from the repository
root:

    python benchmarks/unseen/round19/l_make.py

Five-bars under the paper's sine (``fivebar_sine_replay_noise1``, and clean with recorded rates):
the paper's linkage held out at 1, 2 and 3 % on new seeds (rounds 17-18 drew 1-4 % on seeds
81-94), asymmetric cranks (0.7 / 1.3 m: round 11 drew 0.8 / 1.2 m cranks with other couplers), all
four links at the families' heaviest 2 kg (rounds 11-13 drew single heavy links), heavy cranks
under light couplers (2 / 0.5 kg), a new geometry inside the families' 0.6-1.4 m (cranks 1.3 / 0.9
m, couplers 0.7 / 1.2 m, ground 0.8 m), and records of 5 s and 15 s (rounds 3 and 6 drew them
under their own inputs, round 18 1 s and 30 s).  Cart-poles under ``cartpole_noise1``'s multisine
and chain: a heavy short pole (1.2 kg, 0.45 m), a light cart (0.7 kg), hinge damping 0.02 N m s/rad
(rounds 11-12 drew 0.05-0.5), Mars gravity (3.71 m/s^2; round 14 drew the Moon's), a 1.5 N m
multisine on 5 s, a 6 N multisine (the pole turns over the top), and towards that onset 3 N, 4 N on
a 0.3 m pole and 2.5 N on 20 s.  Kinetics: Vmax 4 with Km 0.7 and a 6 mM dose (x* 0.24 mM),
a weak influx with a small Km (0.1 mM/s, Km 0.15: x* 0.011 mM), an influx near a slow Vmax (0.75
of 0.9 mM/s: x* 1.5 mM, 8 s), a 12 s record at 500 Hz, and Km 0.7 mM rising from a 0.1 mM dose.
Noise levels and seeds 101-105 are the studies' (round19_linkages_*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: round 12's linkage writer
from round12 import l_make as _ROUND12  # noqa: E402

#: name -> (description, {table: keys changed from the paper's sine scenario})
FIVEBARS: dict[str, tuple[str, dict[str, dict]]] = {
    "fb19_paper": ("the paper's linkage and sine, unchanged (held out on new seeds)", {}),
    "fb19_asym_cranks": ("asymmetric cranks 0.7 / 1.3 m (couplers and ground 1 m)",
                         {"rig": {"l1": 0.7, "l4": 1.3}}),
    "fb19_heavy": ("all four links at 2 kg (the families' heaviest)",
                   {"rig": {"m1": 2.0, "m2": 2.0, "m3": 2.0, "m4": 2.0}}),
    "fb19_heavy_cranks": ("cranks of 2 kg under couplers of 0.5 kg",
                          {"rig": {"m1": 2.0, "m2": 0.5, "m3": 0.5, "m4": 2.0}}),
    "fb19_geom_a": ("cranks 1.3 / 0.9 m, couplers 0.7 / 1.2 m, ground 0.8 m",
                    {"rig": {"l1": 1.3, "l2": 0.7, "l3": 1.2, "l4": 0.9, "L0": 0.8}}),
    "fb19_5s": ("the paper's sine, a 5 s record", {"simulation": {"duration": 5.0}}),
    "fb19_15s": ("the paper's sine, a 15 s record", {"simulation": {"duration": 15.0}}),
}

#: name -> (description, {table: keys changed from cartpole_noise1 (its multisine kept)})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp19_pole1p2_L0p45": ("a heavy short pole (1.2 kg, 0.45 m) on the 1 kg cart",
                           {"rig": {"pole_mass": 1.2, "pole_length": 0.45}}),
    "cp19_cart0p7": ("a 0.7 kg cart under the 0.5 kg, 0.6 m pole", {"rig": {"cart_mass": 0.7}}),
    "cp19_hinge0p02": ("hinge damping 0.02 N m s/rad (4x the base rig's)",
                       {"rig": {"pole_damping": 0.02}}),
    "cp19_mars": ("Mars gravity (3.71 m/s^2)", {"rig": {"gravity": 3.71}}),
    "cp19_amp1p5_5s": ("a 1.5 N multisine on a 5 s record",
                       {"simulation": {"duration": 5.0}, "excitation": {"amplitude": 1.5}}),
    "cp19_amp6": ("a 6 N multisine", {"excitation": {"amplitude": 6.0}}),
    # towards the pole's turning over (round19_linkages_cartpoles_onset.toml)
    "cp19_amp3": ("a 3 N multisine", {"excitation": {"amplitude": 3.0}}),
    "cp19_amp4_L0p3": ("a 4 N multisine on a 0.3 m pole",
                       {"rig": {"pole_length": 0.3}, "excitation": {"amplitude": 4.0}}),
    "cp19_amp2p5_20s": ("a 2.5 N multisine on a 20 s record",
                        {"simulation": {"duration": 20.0}, "excitation": {"amplitude": 2.5}}),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1}); Km 0.3, Vmax 1.5,
#: influx 0.6 mM/s (x* 0.2 mM), x0 2 mM, 4 s at 1 kHz
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm19_vmax4_km0p7_x0_6": ("Vmax 4 mM/s, Km 0.7 mM, a 6 mM dose (x* 0.24 mM)",
                              {"rig": {"Vmax": 4.0, "Km": 0.7, "x0": 6.0}}),
    "mm19_jx0p1_km0p15": ("a weak influx 0.1 mM/s with Km 0.15 mM (x* 0.011 mM)",
                          {"rig": {"jx": 0.1, "Km": 0.15}}),
    "mm19_vmax0p9_jx0p75_8s": ("an influx near a slow Vmax (0.75 of 0.9 mM/s, x* 1.5 mM), 8 s",
                               {"rig": {"Vmax": 0.9, "jx": 0.75}, "simulation": {"duration": 8.0}}),
    "mm19_fs500_12s": ("the weak setup at 500 Hz on a 12 s record",
                       {"simulation": {"sample_rate": 500.0, "duration": 12.0}}),
    "mm19_km0p7_x0_0p1": ("Km 0.7 mM, a 0.1 mM dose rising to x* 0.47 mM",
                          {"rig": {"Km": 0.7, "x0": 0.1}}),
}


_write = _ROUND12.writer_for(HERE, 19)


def main() -> None:
    _ROUND12.write_sets(_write, FIVEBARS, CARTPOLES, KINETICS, "2-18")


if __name__ == "__main__":
    main()
