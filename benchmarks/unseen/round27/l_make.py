"""Write the round-27 linkage and small-rig scenarios (benchmarks/unseen/round27/{fb,cp,mm}27_*.toml): rigs
nobody tuned, default identifier settings, the earlier rounds' bars. Run from the repository root:

    python benchmarks/unseen/round27/l_make.py

Five-bars under the paper's sine (``fivebar_sine_replay_noise1``, and clean with recorded rates), in corners
rounds 9-26 did not draw (they drew cranks of 0.1-0.25 / 0.3-2.2 m, couplers 0.1-2.65 m, grounds of 0.02-4 m,
link masses 0.01-50 kg with coupler pairs 0.5 / 0.6 / 0.7 / 0.8 / 1.2 / 1.5 / 1.8 / 2 kg, records of 1-40 s,
the down branch over the paper's, a 0.45 and a 0.6 m ground, the sine at the paper's amplitude and
frequency): cranks of 0.27 m, couplers of 0.85 m on a 0.7 m ground, a 1.25 m ground, couplers of 0.35 kg,
cranks of 0.7 kg under couplers of 1.6 kg, couplers with their own inertia (0.05 kg m^2, not a slender
rod's), a 3 s record; the paper's sine at the schema's edges: its amplitude at the bound (0.5 rad, 7.2 x the
paper's), at a fifth of the paper's (0.014 rad), and at 1.5 rad/s; the sine on the down branch over a
0.75 m ground (written in full, the rig's own start pose). The multisine (``fivebar_multisine_noise1``) at
0.3 N m on phase seed 5, at 1.3 N m on phase seed 17, and as a single tone (``n_tones = 1``, the schema's
edge) at 0.8 Hz; chirps of 0.6 N m 0.1-0.8 Hz over 10 s and 1.5 N m 0.3-2.5 Hz over 8 s with the
multisine's feedback (written in full). Cart-poles under ``cartpole_noise1``'s chain: a 0.8 m pole of
0.35 kg, a 0.4 m pole of 0.15 kg, a 0.7 kg cart, the multisine at 3 N, the pole released from 1.5 rad (near
the schema's pi/2 bound). Kinetics (``michaelis_menten_noise1``'s weak setup; Km 0.3, Vmax 1.5, influx 0.6
mM/s, x0 2 mM, 4 s at 1 kHz): Km 0.15 mM (x* 0.1 mM), Km 1 under Vmax 2.2 (x* 0.38 mM), an influx of 0.9
mM/s (x* 0.45 mM), a start from nothing (x0 = 0, the schema's edge) rising to x* 0.2 mM, a 4 mM
dose, a 3 s record at 200 Hz. Noise levels and seeds 181-189 are the studies' (round27_linkages_*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 12, 22 and 23's linkage writers
from round12 import l_make as _ROUND12  # noqa: E402
from round22 import l_make as _ROUND22  # noqa: E402
from round23 import l_make as _ROUND23  # noqa: E402

#: name -> (description, {table: keys changed from the paper's sine scenario})
FIVEBARS: dict[str, tuple[str, dict[str, dict]]] = {
    "fb27_paper": ("the paper's linkage and sine, unchanged (held out on new seeds)", {}),
    "fb27_cranks_0p27": ("cranks of 0.27 m (couplers and ground 1 m)", {"rig": {"l1": 0.27, "l4": 0.27}}),
    "fb27_couplers_0p85_ground_0p7": ("couplers of 0.85 m on a 0.7 m ground (cranks 1 m)",
                                      {"rig": {"l2": 0.85, "l3": 0.85, "L0": 0.7}}),
    "fb27_ground_1p25": ("a 1.25 m ground under four 1 m links", {"rig": {"L0": 1.25}}),
    "fb27_couplers_m0p35": ("couplers of 0.35 kg (cranks 1 kg)", {"rig": {"m2": 0.35, "m3": 0.35}}),
    "fb27_cranks_m0p7_couplers_m1p6": ("cranks of 0.7 kg under couplers of 1.6 kg",
                                       {"rig": {"m1": 0.7, "m4": 0.7, "m2": 1.6, "m3": 1.6}}),
    "fb27_couplers_I0p05": ("couplers with their own inertia, 0.05 kg m^2 about the centre of mass",
                            {"rig": {"I2": 0.05, "I3": 0.05}}),
    "fb27_3s": ("the paper's sine, a 3 s record", {"simulation": {"duration": 3.0}}),
    "fb27_sine_amp0p5": ("the paper's sine at the schema's bound amplitude, 0.5 rad (7.2 x the paper's)",
                         {"excitation": {"amplitude": 0.5}}),
    "fb27_sine_amp0p014": ("the paper's sine at a fifth of its amplitude, 0.014 rad",
                           {"excitation": {"amplitude": 0.014}}),
    "fb27_sine_1p5rads": ("the paper's sine at 1.5 rad/s (0.2387 Hz)", {"excitation": {"frequency": 0.2387}}),
}

#: name -> (description, {table: keys changed from fivebar_multisine_noise1})
MULTISINES: dict[str, tuple[str, dict[str, dict]]] = {
    "fb27_ms_amp0p3_ph5": ("the multisine at 0.3 N m on phase seed 5",
                           {"excitation": {"amplitude": 0.3, "phase_seed": 5}}),
    "fb27_ms_amp1p3_ph17": ("the multisine at 1.3 N m on phase seed 17",
                            {"excitation": {"amplitude": 1.3, "phase_seed": 17}}),
    "fb27_ms_1tone_0p8hz": ("the multisine as a single tone (n_tones 1, the schema's edge: the tone at "
                            "f_min, 0.8 Hz), 1 N m",
                            {"excitation": {"n_tones": 1, "f_min": 0.8}}),
}

_FB_BAR = "angle_rmse_max = 0.0501       # the paper's figure"
#: written in full by round 22's writer (the input replaced whole, the paper's up-branch pose kept)
CHIRPS: dict[str, tuple[str, str, dict, dict[str, dict], str]] = {
    "fb27_chirp_0p6nm_0p8hz": ("a 0.6 N m chirp 0.1-0.8 Hz over 10 s, the multisine's feedback",
                               "fivebar_multisine_noise1",
                               {"type": "chirp", "amplitude": 0.6, "kp": 10.0, "kd": 2.0, "f0": 0.1,
                                "f1": 0.8},
                               {}, _FB_BAR),
    "fb27_chirp_1p5nm_2p5hz": ("a 1.5 N m chirp 0.3-2.5 Hz over 8 s, the multisine's feedback",
                               "fivebar_multisine_noise1",
                               {"type": "chirp", "amplitude": 1.5, "kp": 10.0, "kd": 2.0, "f0": 0.3,
                                "f1": 2.5},
                               {"simulation": {"duration": 8.0}}, _FB_BAR),
}
#: written in full by round 23's writer (the start pose left to the rig)
DOWN: dict[str, tuple[str, str, dict[str, dict], str]] = {
    "fb27_sine_down_ground_0p75": ("the paper's sine on the down branch over a 0.75 m ground (the mirror "
                                   "assembly, the rig's own start pose)", "fivebar_sine_replay_noise1",
                                   {"rig": {"branch": "down", "L0": 0.75}}, _FB_BAR),
}

#: name -> (description, {table: keys changed from cartpole_noise1 (its multisine kept)})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp27_L0p8_m0p35": ("a 0.8 m pole of 0.35 kg on the 1 kg cart",
                        {"rig": {"pole_length": 0.8, "pole_mass": 0.35}}),
    "cp27_L0p4_m0p15": ("a 0.4 m pole of 0.15 kg on the 1 kg cart",
                        {"rig": {"pole_length": 0.4, "pole_mass": 0.15}}),
    "cp27_cart0p7": ("a 0.7 kg cart under the 0.5 kg pole", {"rig": {"cart_mass": 0.7}}),
    "cp27_amp3": ("the shipped cart-pole under the multisine at 3 N", {"excitation": {"amplitude": 3.0}}),
    "cp27_th0_1p5": ("the shipped cart-pole with the pole released from 1.5 rad (near the schema's pi/2 "
                     "bound)", {"rig": {"th0": 1.5}}),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1}); Km 0.3, Vmax 1.5,
#: influx 0.6 mM/s (x* 0.2 mM), x0 2 mM, 4 s at 1 kHz
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm27_km0p15": ("Km 0.15 mM (x* 0.1 mM)", {"rig": {"Km": 0.15}}),
    "mm27_km1_vmax2p2": ("Km 1 mM under Vmax 2.2 mM/s (x* 0.38 mM)", {"rig": {"Km": 1.0, "Vmax": 2.2}}),
    "mm27_jx0p9": ("an influx of 0.9 mM/s (x* 0.45 mM)", {"rig": {"jx": 0.9}}),
    "mm27_x0_0": ("a start from nothing (x0 = 0, the schema's edge) rising to x* 0.2 mM",
                  {"rig": {"x0": 0.0}}),
    "mm27_x4": ("a 4 mM dose", {"rig": {"x0": 4.0}}),
    "mm27_3s_fs200": ("a 3 s record at 200 Hz", {"simulation": {"duration": 3.0, "sample_rate": 200.0}}),
}


_write = _ROUND12.writer_for(HERE, 27)


def _retag(name: str, number: int) -> None:
    """Rewrite ``round27/<name>.toml``, written by round ``number``'s full writer, as round 27's."""
    path = HERE / f"{name}.toml"
    text = path.read_text().replace(f"round {number}", "round 27")
    path.write_text(text.replace(f"round{number}", "round27"))


def main() -> None:
    _ROUND12.write_sets(_write, FIVEBARS, CARTPOLES, KINETICS, "2-26", MULTISINES)
    _ROUND22.HERE = _ROUND23.HERE = HERE  # their full writers write into their module's HERE
    for name, (desc, base, excitation, tables, score) in CHIRPS.items():
        _ROUND22._write_full(name, desc, base, excitation, tables, score)
        _retag(name, 22)
    for name, (desc, base, tables, score) in DOWN.items():
        _ROUND23._write_full(name, desc, base, tables, score)
        _retag(name, 23)


if __name__ == "__main__":
    main()
