"""Write the round-28 linkage and small-rig scenarios (benchmarks/unseen/round28/{fb,cp,mm}28_*.toml): rigs
nobody tuned, default identifier settings, the earlier rounds' bars. Run from the repository root:

    python benchmarks/unseen/round28/l_make.py

Five-bars under the paper's sine (``fivebar_sine_replay_noise1``, and clean with recorded rates), in corners
rounds 9-27 did not draw (they drew cranks of 0.1-0.27 / 0.3-2.2 m, couplers 0.1-2.65 m, grounds of 0.02-4 m,
link masses 0.01-50 kg, coupler inertia 0.05 kg m^2, records of 1-40 s, the down branch over the paper's, a
0.45, 0.6 and 0.75 m ground, the sine at 0.014-0.5 rad and at the paper's frequency or 1.5 rad/s): cranks of
0.32 m under couplers of 1.1 m, couplers of 1.15 m on a 1.1 m ground, a 0.85 m ground, cranks of 1.3 kg,
couplers of 0.9 kg, cranks with their own inertia (0.03 kg m^2), a 2.5 s record; the paper's sine at 0.2
rad, at 0.04 rad, at 0.5 Hz, and starting at its mean (phase 0); the sine on the down branch over a 0.9 m
ground (written in full, the rig's own start pose). The multisine (``fivebar_multisine_noise1``) at 0.6 N m
on phase seed 23, at 1.1 N m with three tones 0.2-1.2 Hz, at 0.8 N m with 20 tones 0.05-2 Hz; a chirp of
0.9 N m 0.05-1.2 Hz over 12 s and one of 0.4 N m 0.5-3 Hz over 6 s with the multisine's feedback; the PD
loop tracking a 0.3 rad sine at 0.3 Hz (written in full). Cart-poles under ``cartpole_noise1``'s chain: a
1 m pole of 0.6 kg, a 0.5 m pole of 0.25 kg, a 2.5 kg cart, the multisine at 0.7 N, the pole released
from -0.8 rad, a chirp of 2.5 N 0.2-1.8 Hz (written in full). Kinetics (``michaelis_menten_noise1``'s weak
setup; Km 0.3, Vmax 1.5, influx 0.6 mM/s, x0 2 mM, 4 s at 1 kHz): Km 0.5 (x* 0.5 mM), Km 2 under Vmax 3
(x* 0.5 mM), an influx of 0.3 mM/s (x* 0.075 mM), a 1 mM start, a 6 mM dose, a 6 s record at 500 Hz.
Noise levels and seeds 191-199 are the studies' (round28_linkages_*.toml).
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
    "fb28_paper": ("the paper's linkage and sine, unchanged (held out on new seeds)", {}),
    "fb28_cranks_0p32_couplers_1p1": ("cranks of 0.32 m under couplers of 1.1 m (ground 1 m)",
                                      {"rig": {"l1": 0.32, "l4": 0.32, "l2": 1.1, "l3": 1.1}}),
    "fb28_couplers_1p15_ground_1p1": ("couplers of 1.15 m on a 1.1 m ground (cranks 1 m)",
                                      {"rig": {"l2": 1.15, "l3": 1.15, "L0": 1.1}}),
    "fb28_ground_0p85": ("a 0.85 m ground under four 1 m links", {"rig": {"L0": 0.85}}),
    "fb28_cranks_m1p3": ("cranks of 1.3 kg (couplers 1 kg)", {"rig": {"m1": 1.3, "m4": 1.3}}),
    "fb28_couplers_m0p9": ("couplers of 0.9 kg (cranks 1 kg)", {"rig": {"m2": 0.9, "m3": 0.9}}),
    "fb28_cranks_I0p03": ("cranks with their own inertia, 0.03 kg m^2 about the centre of mass",
                          {"rig": {"I1": 0.03, "I4": 0.03}}),
    "fb28_2p5s": ("the paper's sine, a 2.5 s record", {"simulation": {"duration": 2.5}}),
    "fb28_sine_amp0p2": ("the paper's sine at 0.2 rad (2.9 x the paper's)",
                         {"excitation": {"amplitude": 0.2}}),
    "fb28_sine_amp0p04": ("the paper's sine at 0.04 rad", {"excitation": {"amplitude": 0.04}}),
    "fb28_sine_0p5hz": ("the paper's sine at 0.5 Hz (3.14 x the paper's frequency)",
                        {"excitation": {"frequency": 0.5}}),
    "fb28_sine_phase0": ("the paper's sine starting at its mean (phase 0: the joints start moving at "
                         "full rate)", {"excitation": {"phase": 0.0}}),
}

#: name -> (description, {table: keys changed from fivebar_multisine_noise1})
MULTISINES: dict[str, tuple[str, dict[str, dict]]] = {
    "fb28_ms_amp0p6_ph23": ("the multisine at 0.6 N m on phase seed 23",
                            {"excitation": {"amplitude": 0.6, "phase_seed": 23}}),
    "fb28_ms_3tones_1p1nm": ("the multisine at 1.1 N m with three tones 0.2-1.2 Hz",
                             {"excitation": {"amplitude": 1.1, "n_tones": 3, "f_min": 0.2, "f_max": 1.2}}),
    "fb28_ms_20tones_0p8nm": ("the multisine at 0.8 N m with 20 tones 0.05-2 Hz",
                              {"excitation": {"amplitude": 0.8, "n_tones": 20, "f_min": 0.05, "f_max": 2.0}}),
}

_FB_BAR = "angle_rmse_max = 0.0501       # the paper's figure"
_CP_BAR = "angle_rmse_max = 0.0501       # the paper's figure (rounds 2-27's bar for unseen cart-poles)"
#: written in full by round 22's writer (the input replaced whole, the paper's up-branch pose kept)
FULL: dict[str, tuple[str, str, dict, dict[str, dict], str]] = {
    "fb28_chirp_0p9nm_1p2hz": ("a 0.9 N m chirp 0.05-1.2 Hz over 12 s, the multisine's feedback",
                               "fivebar_multisine_noise1",
                               {"type": "chirp", "amplitude": 0.9, "kp": 10.0, "kd": 2.0, "f0": 0.05,
                                "f1": 1.2},
                               {"simulation": {"duration": 12.0}}, _FB_BAR),
    "fb28_chirp_0p4nm_3hz": ("a 0.4 N m chirp 0.5-3 Hz over 6 s, the multisine's feedback",
                             "fivebar_multisine_noise1",
                             {"type": "chirp", "amplitude": 0.4, "kp": 10.0, "kd": 2.0, "f0": 0.5, "f1": 3.0},
                             {"simulation": {"duration": 6.0}}, _FB_BAR),
    "fb28_pd_0p3rad_0p3hz": ("the PD loop tracking a 0.3 rad sine at 0.3 Hz about the start pose",
                             "fivebar_multisine_noise1",
                             {"type": "pd", "amplitude": 0.3, "frequency": 0.3},
                             {}, _FB_BAR),
    "cp28_chirp_2p5n_1p8hz": ("a 2.5 N chirp 0.2-1.8 Hz", "cartpole_noise1",
                              {"type": "chirp", "amplitude": 2.5, "f0": 0.2, "f1": 1.8}, {}, _CP_BAR),
}
#: written in full by round 23's writer (the start pose left to the rig)
DOWN: dict[str, tuple[str, str, dict[str, dict], str]] = {
    "fb28_sine_down_ground_0p9": ("the paper's sine on the down branch over a 0.9 m ground (the mirror "
                                  "assembly, the rig's own start pose)", "fivebar_sine_replay_noise1",
                                  {"rig": {"branch": "down", "L0": 0.9}}, _FB_BAR),
}

#: name -> (description, {table: keys changed from cartpole_noise1 (its multisine kept)})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp28_L1_m0p6": ("a 1 m pole of 0.6 kg on the 1 kg cart",
                     {"rig": {"pole_length": 1.0, "pole_mass": 0.6}}),
    "cp28_L0p5_m0p25": ("a 0.5 m pole of 0.25 kg on the 1 kg cart",
                        {"rig": {"pole_length": 0.5, "pole_mass": 0.25}}),
    "cp28_cart2p5": ("a 2.5 kg cart under the 0.5 kg pole", {"rig": {"cart_mass": 2.5}}),
    "cp28_amp0p7": ("the shipped cart-pole under the multisine at 0.7 N", {"excitation": {"amplitude": 0.7}}),
    "cp28_th0_m0p8": ("the shipped cart-pole with the pole released from -0.8 rad", {"rig": {"th0": -0.8}}),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1}); Km 0.3, Vmax 1.5,
#: influx 0.6 mM/s (x* 0.2 mM), x0 2 mM, 4 s at 1 kHz
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm28_km0p5": ("Km 0.5 mM (x* 0.33 mM)", {"rig": {"Km": 0.5}}),
    "mm28_km2_vmax3": ("Km 2 mM under Vmax 3 mM/s (x* 0.5 mM)", {"rig": {"Km": 2.0, "Vmax": 3.0}}),
    "mm28_jx0p3": ("an influx of 0.3 mM/s (x* 0.075 mM)", {"rig": {"jx": 0.3}}),
    "mm28_x1": ("a 1 mM start", {"rig": {"x0": 1.0}}),
    "mm28_x6": ("a 6 mM dose", {"rig": {"x0": 6.0}}),
    "mm28_6s_fs500": ("a 6 s record at 500 Hz", {"simulation": {"duration": 6.0, "sample_rate": 500.0}}),
}


_write = _ROUND12.writer_for(HERE, 28)


def _retag(name: str, number: int) -> None:
    """Rewrite ``round28/<name>.toml``, written by round ``number``'s full writer, as round 28's."""
    path = HERE / f"{name}.toml"
    text = path.read_text().replace(f"round {number}", "round 28")
    path.write_text(text.replace(f"round{number}", "round28"))


def main() -> None:
    _ROUND12.write_sets(_write, FIVEBARS, CARTPOLES, KINETICS, "2-27", MULTISINES)
    _ROUND22.HERE = _ROUND23.HERE = HERE  # their full writers write into their module's HERE
    for name, (desc, base, excitation, tables, score) in FULL.items():
        _ROUND22._write_full(name, desc, base, excitation, tables, score)
        _retag(name, 22)
    for name, (desc, base, tables, score) in DOWN.items():
        _ROUND23._write_full(name, desc, base, tables, score)
        _retag(name, 23)


if __name__ == "__main__":
    main()
