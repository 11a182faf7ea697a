"""Write the round-16 linkage and small-rig scenarios (benchmarks/unseen/round16/{fb,cp,mm}16_*.toml):
rigs nobody tuned, default identifier settings, the earlier rounds' bars.  Run from the repository
root:

    python benchmarks/unseen/round16/l_make.py

Five-bars with long distal links (couplers l2 = l3 of 1.8 and 2.2 m on the 1 m cranks and base,
one coupler of 1.7 m: the transmission angle on the sine path drops toward the rig's 30 deg limit,
near the Type II singularity) and the paper's sine at other amplitudes (0.02 and 0.2 rad against
its 0.0698), under ``fivebar_sine_replay_noise1`` and clean with recorded rates; the multisine
(``fivebar_multisine_noise1``) with records of 3 and 15 s and on the 1.8 m couplers.  The rig's
ground link is horizontal by construction (B = (L0, 0)): with gravity off a tilted ground link is
the same rig rotated, and with gravity on it is not expressible (gravity is along -y only), so no
case is written for it.  Cart-poles with a light pole (0.05 kg on the 1 kg cart) and short records
(3-5 s) under ``cartpole_noise1``'s multisine and chain, and under round 14's chirp and steps
(written in full by round 14's writer).  Kinetics with the dose far above Km (x0 30 mM = 100 Km,
4 s and 40 s; 10 mM over Km 0.05) and with no influx (jx = 0: a pure decay, the law
``Km dx + x dx + Vmax x = 0``, three terms).  Noise levels and seeds 71-74 are the studies'
(round16_linkages_*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 12, 14 and 15's linkage writers
from round12 import l_make as _ROUND12  # noqa: E402
from round15 import l_make as _ROUND15  # noqa: E402

#: name -> (description, {table: keys changed from the paper's sine scenario})
FIVEBARS: dict[str, tuple[str, dict[str, dict]]] = {
    "fb16_couplers_1p8": ("couplers of 1.8 m on 1 m cranks and base", {"rig": {"l2": 1.8, "l3": 1.8}}),
    "fb16_couplers_2p2": ("couplers of 2.2 m on 1 m cranks and base", {"rig": {"l2": 2.2, "l3": 2.2}}),
    "fb16_coupler_r1p7": ("a right coupler (l3) of 1.7 m, the others 1 m", {"rig": {"l3": 1.7}}),
    "fb16_amp_0p02": ("the paper's sine at 0.02 rad (0.29x)", {"excitation": {"amplitude": 0.02}}),
    "fb16_amp_0p2": ("the paper's sine at 0.2 rad (2.9x)", {"excitation": {"amplitude": 0.2}}),
    "fb16_couplers_1p8_amp0p15_5s": (
        "couplers of 1.8 m, the sine at 0.15 rad, 5 s",
        {"rig": {"l2": 1.8, "l3": 1.8}, "excitation": {"amplitude": 0.15}, "simulation": {"duration": 5.0}},
    ),
}

#: name -> (description, {table: keys changed from fivebar_multisine_noise1})
MULTISINES: dict[str, tuple[str, dict[str, dict]]] = {
    "fb16_ms_3s": ("the multisine, 3 s", {"simulation": {"duration": 3.0}}),
    "fb16_ms_15s": ("the multisine, 15 s", {"simulation": {"duration": 15.0}}),
    "fb16_ms_couplers_1p8": ("the multisine on couplers of 1.8 m", {"rig": {"l2": 1.8, "l3": 1.8}}),
}

_LIGHT = {"pole_mass": 0.05}
#: name -> (description, {table: keys changed from cartpole_noise1 (its multisine kept)})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp16_light": ("a 0.05 kg pole on the 1 kg cart, 10 s", {"rig": _LIGHT}),
    "cp16_light_3s": ("a 0.05 kg pole on the 1 kg cart, 3 s",
                      {"rig": _LIGHT, "simulation": {"duration": 3.0}}),
    "cp16_3s": ("the shipped cart-pole, 3 s", {"simulation": {"duration": 3.0}}),
}

#: name -> (description, {"rig": keys changed, "simulation": ..., "excitation": the input, whole})
CARTPOLES_FULL: dict[str, tuple[str, dict[str, dict]]] = {
    "cp16_light_chirp_5s": (
        "a 0.05 kg pole, a 2 N chirp 0.1-2 Hz over 5 s",
        {"rig": _LIGHT, "simulation": {"duration": 5.0},
         "excitation": {"type": "chirp", "amplitude": 2.0, "kp": 5.0, "kd": 2.0, "f0": 0.1, "f1": 2.0}},
    ),
    "cp16_light_steps_3s": (
        "a 0.05 kg pole, 2 N steps held 0.5 s, 3 s",
        {"rig": _LIGHT, "simulation": {"duration": 3.0},
         "excitation": {"type": "steps", "amplitude": 2.0, "level_seed": 0, "kp": 5.0, "kd": 2.0,
                        "hold": 0.5}},
    ),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1}); Km 0.3, Vmax 1.5
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm16_x0_30": ("a 30 mM dose (100 Km): saturated over the 4 s record", {"rig": {"x0": 30.0}}),
    "mm16_x0_30_40s": ("a 30 mM dose (100 Km), 40 s: down to x* 0.2 mM at 33 s",
                       {"rig": {"x0": 30.0}, "simulation": {"duration": 40.0}}),
    "mm16_x0_10_km0p05": ("a 10 mM dose over Km 0.05 mM (200 Km), 12 s",
                          {"rig": {"x0": 10.0, "Km": 0.05}, "simulation": {"duration": 12.0}}),
    "mm16_jx0": ("no influx (jx = 0): a pure decay from 2 mM", {"rig": {"jx": 0.0}}),
    "mm16_jx0_x0_20_20s": ("no influx, a pure decay from 20 mM, 20 s",
                           {"rig": {"jx": 0.0, "x0": 20.0}, "simulation": {"duration": 20.0}}),
}


_write = _ROUND12.writer_for(HERE, 16)


def main() -> None:
    _ROUND12.write_sets(_write, FIVEBARS, CARTPOLES, KINETICS, "2-15", MULTISINES)
    _ROUND15.write_cartpoles(HERE, 16, CARTPOLES_FULL, ("rig", "simulation"))


if __name__ == "__main__":
    main()
