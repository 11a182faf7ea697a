"""Write the round-24 linkage and small-rig scenarios (benchmarks/unseen/round24/{fb,cp,mm}24_*.toml): rigs
nobody tuned, default identifier settings, the earlier rounds' bars. Run from the repository root:

    python benchmarks/unseen/round24/l_make.py

Five-bars under the paper's sine (``fivebar_sine_replay_noise1``, and clean with recorded rates), in
corners rounds 9-23 did not draw (they drew cranks of 0.1 / 0.3-2.2 m, couplers 0.1-2.65 m, grounds of
0.02-4 m, link masses 0.01-50 kg, records of 1-40 s): the paper's linkage held out on new seeds, short
cranks of 0.15 m (couplers and ground 1 m), cranks of 0.3 m on a 0.5 m ground, a 0.2 m ground under
four 1 m links, couplers of 0.7 and 1.5 kg (a mass pair no round drew), a 9 s record. The multisine
(``fivebar_multisine_noise1``) at 0.8 N m (between rounds 21-23's 0.5 / 0.7 and 1 / 1.2 N m) and at 0.8 N m
on phase seed 5. Cart-poles under ``cartpole_noise1``'s chain: a 1 kg pole (twice the shipped), a 1.5 kg
cart, the multisine at twice its amplitude (2 N) on the shipped cart-pole, a 0.7 m pole on the 1.5 kg cart.
Kinetics (``michaelis_menten_noise1``'s weak setup; Km 0.3, Vmax 1.5, influx 0.6 mM/s, x0 2 mM, 4 s at 1
kHz): Km 0.7 under Vmax 1.2 (x* 0.7 mM), Km 2 under Vmax 3 from a 4 mM dose (x* 0.5 mM), Km 0.5 under
Vmax 3 (x* 0.125 mM), an influx of 0.45 (x* 0.13 mM), a 1.5 mM dose, 400 Hz, a 3 s record. A second
batch: five-bars on a 0.5 m ground under 2 kg couplers and with 0.3 m cranks on 12 s, the multisine at 0.8
N m on 0.5 kg couplers, the 1 kg pole under the 2 N multisine, kinetics on 6 s, Km 2 from a 4 mM dose
(x* 1.33 mM), a 1 mM dose on 3 s.
Noise levels and seeds 151-159 are the studies' (round24_linkages_*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: round 12's linkage writer
from round12 import l_make as _ROUND12  # noqa: E402

#: name -> (description, {table: keys changed from the paper's sine scenario})
FIVEBARS: dict[str, tuple[str, dict[str, dict]]] = {
    "fb24_paper": ("the paper's linkage and sine, unchanged (held out on new seeds)", {}),
    "fb24_cranks_0p15": ("cranks of 0.15 m (couplers and ground 1 m)", {"rig": {"l1": 0.15, "l4": 0.15}}),
    "fb24_cranks_0p3_ground_0p5": ("cranks of 0.3 m on a 0.5 m ground (couplers 1 m)",
                                   {"rig": {"l1": 0.3, "l4": 0.3, "L0": 0.5}}),
    "fb24_ground_0p2": ("a 0.2 m ground under four 1 m links", {"rig": {"L0": 0.2}}),
    "fb24_couplers_m0p7_1p5": ("couplers of 0.7 and 1.5 kg (cranks 1 kg)", {"rig": {"m2": 0.7, "m3": 1.5}}),
    "fb24_9s": ("the paper's sine, a 9 s record", {"simulation": {"duration": 9.0}}),
    # a second batch (round24_linkages_more.toml)
    "fb24_ground_0p5_couplers_m2": ("a 0.5 m ground under couplers of 2 kg (cranks 1 kg, links 1 m)",
                                    {"rig": {"L0": 0.5, "m2": 2.0, "m3": 2.0}}),
    "fb24_cranks_0p3_12s": ("cranks of 0.3 m (couplers and ground 1 m), a 12 s record",
                            {"rig": {"l1": 0.3, "l4": 0.3}, "simulation": {"duration": 12.0}}),
}

#: name -> (description, {table: keys changed from fivebar_multisine_noise1})
MULTISINES: dict[str, tuple[str, dict[str, dict]]] = {
    "fb24_ms_amp0p8": ("the multisine at 0.8 N m", {"excitation": {"amplitude": 0.8}}),
    "fb24_ms_amp0p8_ph5": ("the multisine at 0.8 N m on phase seed 5",
                           {"excitation": {"amplitude": 0.8, "phase_seed": 5}}),
    "fb24_ms_amp0p8_couplers_m0p5": ("the multisine at 0.8 N m on couplers of 0.5 kg",
                                     {"rig": {"m2": 0.5, "m3": 0.5}, "excitation": {"amplitude": 0.8}}),
}

#: name -> (description, {table: keys changed from cartpole_noise1 (its multisine kept)})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp24_pole_m1": ("a 1 kg pole (0.6 m) on the 1 kg cart", {"rig": {"pole_mass": 1.0}}),
    "cp24_cart1p5": ("a 1.5 kg cart under the 0.5 kg pole", {"rig": {"cart_mass": 1.5}}),
    "cp24_amp2": ("the shipped cart-pole under the multisine at twice its amplitude (2 N)",
                  {"excitation": {"amplitude": 2.0}}),
    "cp24_L0p7_cart1p5": ("a 0.7 m pole (0.5 kg) on a 1.5 kg cart",
                          {"rig": {"pole_length": 0.7, "cart_mass": 1.5}}),
    "cp24_pole_m1_amp2": ("a 1 kg pole (0.6 m) on the 1 kg cart under the multisine at 2 N",
                          {"rig": {"pole_mass": 1.0}, "excitation": {"amplitude": 2.0}}),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1}); Km 0.3, Vmax 1.5,
#: influx 0.6 mM/s (x* 0.2 mM), x0 2 mM, 4 s at 1 kHz
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm24_km0p7_vmax1p2": ("Km 0.7 mM under Vmax 1.2 mM/s (x* 0.7 mM)", {"rig": {"Km": 0.7, "Vmax": 1.2}}),
    "mm24_km2_vmax3_x4": ("Km 2 mM under Vmax 3 mM/s from a 4 mM dose (x* 0.5 mM)",
                          {"rig": {"Km": 2.0, "Vmax": 3.0, "x0": 4.0}}),
    "mm24_km0p5_vmax3": ("Km 0.5 mM under Vmax 3 mM/s (x* 0.125 mM)", {"rig": {"Km": 0.5, "Vmax": 3.0}}),
    "mm24_jx0p45": ("an influx of 0.45 mM/s (x* 0.13 mM)", {"rig": {"jx": 0.45}}),
    "mm24_x1p5": ("a 1.5 mM dose (x* 0.2 mM)", {"rig": {"x0": 1.5}}),
    "mm24_fs400": ("the weak setup at 400 Hz", {"simulation": {"sample_rate": 400.0}}),
    "mm24_3s": ("the weak setup on a 3 s record", {"simulation": {"duration": 3.0}}),
    # a second batch (round24_linkages_more.toml)
    "mm24_6s": ("the weak setup on a 6 s record", {"simulation": {"duration": 6.0}}),
    "mm24_km2_x4": ("Km 2 mM from a 4 mM dose (x* 1.33 mM)", {"rig": {"Km": 2.0, "x0": 4.0}}),
    "mm24_x1_3s": ("a 1 mM dose on a 3 s record", {"rig": {"x0": 1.0}, "simulation": {"duration": 3.0}}),
}


_write = _ROUND12.writer_for(HERE, 24)


def main() -> None:
    _ROUND12.write_sets(_write, FIVEBARS, CARTPOLES, KINETICS, "2-23", MULTISINES)


if __name__ == "__main__":
    main()
