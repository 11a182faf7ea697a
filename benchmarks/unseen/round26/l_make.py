"""Write the round-26 linkage and small-rig scenarios (benchmarks/unseen/round26/{fb,cp,mm}26_*.toml): rigs
nobody tuned, default identifier settings, the earlier rounds' bars. Run from the repository root:

    python benchmarks/unseen/round26/l_make.py

Five-bars under the paper's sine (``fivebar_sine_replay_noise1``, and clean with recorded rates), in corners
rounds 9-25 did not draw (they drew cranks of 0.1-0.25 / 0.3-2.2 m, couplers 0.1-2.65 m, grounds of 0.02-4 m,
link masses 0.01-50 kg with coupler pairs 0.5 / 0.7 / 0.8 / 1.5 / 1.8 / 2 kg, records of 1-40 s, the down
branch over the paper's and a 0.45 m ground): cranks of 0.22 m, cranks of 0.3 m under 0.9 m couplers on a
0.5 m ground, a 0.55 m ground, couplers of 1.2 and 0.6 kg, cranks of 1.4 kg, 1.1 m couplers on a 0.8 m
ground, a 5 s record; the sine on the down branch over a 0.6 m ground (written in full, the rig's own start
pose). The multisine (``fivebar_multisine_noise1``) at 0.4 N m on phase seed 3 and at 0.9 N m on phase seed
11; chirps of 0.8 N m 0.2-1.2 Hz over 10 s and 1.2 N m 0.4-2 Hz over 8 s with the multisine's feedback
(written in full). Cart-poles under ``cartpole_noise1``'s chain: a 0.5 m pole of 0.25 kg, a 1 m pole of
0.6 kg, a 1.3 kg cart, the multisine at 0.6 N, the multisine on phase seed 4. Kinetics
(``michaelis_menten_noise1``'s weak setup; Km 0.3, Vmax 1.5, influx 0.6 mM/s, x0 2 mM, 4 s at 1 kHz): Km
0.6 mM (x* 0.4 mM), Km 2 under Vmax 3 (x* 0.5 mM), Vmax 1.1 (x* 0.36 mM), an influx of 0.4 mM/s (x* 0.11
mM), a 1.5 mM dose at 500 Hz, a 6 s record at 2 kHz.
Noise levels and seeds 171-179 are the studies' (round26_linkages_*.toml).
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
    "fb26_paper": ("the paper's linkage and sine, unchanged (held out on new seeds)", {}),
    "fb26_cranks_0p22": ("cranks of 0.22 m (couplers and ground 1 m)", {"rig": {"l1": 0.22, "l4": 0.22}}),
    "fb26_cranks_0p3_couplers_0p9_ground_0p5": ("cranks of 0.3 m under 0.9 m couplers on a 0.5 m ground",
                                                {"rig": {"l1": 0.3, "l4": 0.3, "l2": 0.9, "l3": 0.9,
                                                         "L0": 0.5}}),
    "fb26_ground_0p55": ("a 0.55 m ground under four 1 m links", {"rig": {"L0": 0.55}}),
    "fb26_couplers_m1p2_0p6": ("couplers of 1.2 and 0.6 kg (cranks 1 kg)", {"rig": {"m2": 1.2, "m3": 0.6}}),
    "fb26_cranks_m1p4": ("cranks of 1.4 kg (couplers 1 kg)", {"rig": {"m1": 1.4, "m4": 1.4}}),
    "fb26_couplers_1p1_ground_0p8": ("couplers of 1.1 m on a 0.8 m ground (cranks 1 m)",
                                     {"rig": {"l2": 1.1, "l3": 1.1, "L0": 0.8}}),
    "fb26_5s": ("the paper's sine, a 5 s record", {"simulation": {"duration": 5.0}}),
}

#: name -> (description, {table: keys changed from fivebar_multisine_noise1})
MULTISINES: dict[str, tuple[str, dict[str, dict]]] = {
    "fb26_ms_amp0p4_ph3": ("the multisine at 0.4 N m on phase seed 3",
                           {"excitation": {"amplitude": 0.4, "phase_seed": 3}}),
    "fb26_ms_amp0p9_ph11": ("the multisine at 0.9 N m on phase seed 11",
                            {"excitation": {"amplitude": 0.9, "phase_seed": 11}}),
}

_FB_BAR = "angle_rmse_max = 0.0501       # the paper's figure"
#: written in full by round 22's writer (the input replaced whole, the paper's up-branch pose kept)
CHIRPS: dict[str, tuple[str, str, dict, dict[str, dict], str]] = {
    "fb26_chirp_0p8nm_10s": ("a 0.8 N m chirp 0.2-1.2 Hz over 10 s, the multisine's feedback",
                             "fivebar_multisine_noise1",
                             {"type": "chirp", "amplitude": 0.8, "kp": 10.0, "kd": 2.0, "f0": 0.2, "f1": 1.2},
                             {}, _FB_BAR),
    "fb26_chirp_1p2nm_2hz": ("a 1.2 N m chirp 0.4-2 Hz over 8 s, the multisine's feedback",
                             "fivebar_multisine_noise1",
                             {"type": "chirp", "amplitude": 1.2, "kp": 10.0, "kd": 2.0, "f0": 0.4, "f1": 2.0},
                             {"simulation": {"duration": 8.0}}, _FB_BAR),
}
#: written in full by round 23's writer (the start pose left to the rig)
DOWN: dict[str, tuple[str, str, dict[str, dict], str]] = {
    "fb26_sine_down_ground_0p6": ("the paper's sine on the down branch over a 0.6 m ground (the mirror "
                                  "assembly, the rig's own start pose)", "fivebar_sine_replay_noise1",
                                  {"rig": {"branch": "down", "L0": 0.6}}, _FB_BAR),
}

#: name -> (description, {table: keys changed from cartpole_noise1 (its multisine kept)})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp26_L0p5_m0p25": ("a 0.5 m pole of 0.25 kg on the 1 kg cart",
                        {"rig": {"pole_length": 0.5, "pole_mass": 0.25}}),
    "cp26_L1_m0p6": ("a 1 m pole of 0.6 kg on the 1 kg cart",
                     {"rig": {"pole_length": 1.0, "pole_mass": 0.6}}),
    "cp26_cart1p3": ("a 1.3 kg cart under the 0.5 kg pole", {"rig": {"cart_mass": 1.3}}),
    "cp26_amp0p6": ("the shipped cart-pole under the multisine at 0.6 N", {"excitation": {"amplitude": 0.6}}),
    "cp26_ph4": ("the shipped cart-pole under the multisine on phase seed 4",
                 {"excitation": {"phase_seed": 4}}),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1}); Km 0.3, Vmax 1.5,
#: influx 0.6 mM/s (x* 0.2 mM), x0 2 mM, 4 s at 1 kHz
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm26_km0p6": ("Km 0.6 mM (x* 0.4 mM)", {"rig": {"Km": 0.6}}),
    "mm26_km2_vmax3": ("Km 2 mM under Vmax 3 mM/s (x* 0.5 mM)", {"rig": {"Km": 2.0, "Vmax": 3.0}}),
    "mm26_vmax1p1": ("Vmax 1.1 mM/s (x* 0.36 mM)", {"rig": {"Vmax": 1.1}}),
    "mm26_jx0p4": ("an influx of 0.4 mM/s (x* 0.11 mM)", {"rig": {"jx": 0.4}}),
    "mm26_x1p5_fs500": ("a 1.5 mM dose at 500 Hz",
                        {"rig": {"x0": 1.5}, "simulation": {"sample_rate": 500.0}}),
    "mm26_6s_fs2k": ("a 6 s record at 2 kHz", {"simulation": {"duration": 6.0, "sample_rate": 2000.0}}),
}


_write = _ROUND12.writer_for(HERE, 26)


def _retag(name: str, number: int) -> None:
    """Rewrite ``round26/<name>.toml``, written by round ``number``'s full writer, as round 26's."""
    path = HERE / f"{name}.toml"
    text = path.read_text().replace(f"round {number}", "round 26")
    path.write_text(text.replace(f"round{number}", "round26"))


def main() -> None:
    _ROUND12.write_sets(_write, FIVEBARS, CARTPOLES, KINETICS, "2-25", MULTISINES)
    _ROUND22.HERE = _ROUND23.HERE = HERE  # their full writers write into their module's HERE
    for name, (desc, base, excitation, tables, score) in CHIRPS.items():
        _ROUND22._write_full(name, desc, base, excitation, tables, score)
        _retag(name, 22)
    for name, (desc, base, tables, score) in DOWN.items():
        _ROUND23._write_full(name, desc, base, tables, score)
        _retag(name, 23)


if __name__ == "__main__":
    main()
