"""Write the round-13 linkage and small-rig scenarios (benchmarks/unseen/round13/{fb,cp,mm}13_*.toml):
rigs nobody tuned, default identifier settings, the earlier rounds' bars.  Run from the repository
root:

    python benchmarks/unseen/round13/l_make.py

Five-bars: the paper's sine input (``fivebar_sine_replay_noise1``) on the paper's geometry with
link masses and inertias rounds 3-12 did not use: couplers of 0.3 and 2.5 kg (rounds varied the
cranks' masses only), coupler inertias far from a rod's (0.5 and 0.005 kg m^2 against 0.083),
a diagonal asymmetry (a 2.5 kg left crank and right coupler, the other two 0.5 kg), and four
different masses with four different inertias.  Each case twice: ``fb13_<case>`` with the noise
chain, ``fb13_<case>_rec`` clean with the recorded rates.  The paper's own input at 1 / 3 / 5 %
noise, seeds 41-44, is ``fivebar_sine_replay_noise1`` itself (round13_linkages_sine.toml).
Cart-poles: ``cartpole_noise1``'s chain under the Moon's gravity (1.62 m/s^2), from a 1.2 rad
start, and under two tones (rounds used 8 or more).
Kinetics: ``michaelis_menten_noise1``'s weak setup with a slow enzyme (Vmax 0.8 mM/s under 0.4
mM/s of influx), Km 3 mM with Vmax 6 mM/s (x* 0.33 mM, deep in the first-order range with a fast
enzyme), and the record sampled at 200 Hz (the setup's 1 kHz / 5).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 10-12's linkage writers
from round12 import l_make as _ROUND12  # noqa: E402

#: name -> (description, {table: keys changed from the paper's sine scenario})
FIVEBARS: dict[str, tuple[str, dict[str, dict]]] = {
    "fb13_couplers_0p3_2p5kg": ("couplers of 0.3 kg (left) and 2.5 kg (right), rod inertias",
                                {"rig": {"m2": 0.3, "m3": 2.5}}),
    "fb13_coupler_inertia": ("coupler inertias 0.5 kg m^2 (left) and 0.005 kg m^2 (right), a rod's 0.083",
                             {"rig": {"I2": 0.5, "I3": 0.005}}),
    "fb13_diagonal": ("a diagonal asymmetry: left crank and right coupler 2.5 kg, the other two 0.5 kg",
                      {"rig": {"m1": 2.5, "m2": 0.5, "m3": 2.5, "m4": 0.5}}),
    "fb13_all_different": ("masses 0.6 / 1.8 / 0.9 / 2.4 kg, inertias 0.02 / 0.3 / 0.05 / 0.4 kg m^2",
                           {"rig": {"m1": 0.6, "m2": 1.8, "m3": 0.9, "m4": 2.4,
                                    "I1": 0.02, "I2": 0.3, "I3": 0.05, "I4": 0.4}}),
}

#: name -> (description, {table: keys changed from cartpole_noise1})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp13_moon": ("the Moon's gravity, 1.62 m/s^2 (the pole's period 3.1 s)", {"rig": {"gravity": 1.62}}),
    "cp13_swing_th0_1p2": ("the pole released from 1.2 rad (69 deg)", {"rig": {"th0": 1.2}}),
    "cp13_two_tones": ("two tones (0.1 and 2 Hz) instead of eight", {"excitation": {"n_tones": 2}}),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1})
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm13_vmax0p8_jx0p4": ("a slow enzyme, Vmax 0.8 mM/s under 0.4 mM/s (x* 0.3 mM), 8 s",
                           {"rig": {"Vmax": 0.8, "jx": 0.4}, "simulation": {"duration": 8.0}}),
    "mm13_km3_vmax6": ("Km 3 mM with Vmax 6 mM/s (x* 0.33 mM)", {"rig": {"Km": 3.0, "Vmax": 6.0}}),
    "mm13_fs200": ("the record at 200 Hz", {"simulation": {"sample_rate": 200.0}}),
}


_write = _ROUND12.writer_for(HERE, 13)


def main() -> None:
    _ROUND12.write_sets(_write, FIVEBARS, CARTPOLES, KINETICS, "2-12")


if __name__ == "__main__":
    main()
