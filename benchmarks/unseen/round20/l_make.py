"""Write the round-20 linkage and small-rig scenarios (benchmarks/unseen/round20/{fb,cp,mm}20_*.toml):
rigs nobody tuned, default identifier settings, the earlier rounds' bars.  Run from the repository
root:

    python benchmarks/unseen/round20/l_make.py

Five-bars under the paper's sine (``fivebar_sine_replay_noise1``, and clean with recorded rates):
the paper's linkage held out at 0.5, 1.5 and 2.5 % on new seeds (rounds 17-19 drew 1-4 % on seeds
81-105), the link-length ratio at the families' edges both ways (cranks 0.6 m under couplers 1.4 m,
and cranks 1.4 m under couplers 0.6 m on a 0.6 m ground: the families draw each link in 0.6-1.4 m,
rounds 11 and 19 drew cranks of 0.7-1.3 m with couplers near 1 m), all four links at the families'
lightest 0.5 kg (round 19 drew the heaviest), and a 3 s record (rounds drew 1, 5, 15 and 30 s).
The multisine (``fivebar_multisine_noise1``) on a 3 s record (rounds 16 and 18 drew 1-30 s), and a
chirp of 2 N m 0.2-1 Hz over 10 s with the multisine's feedback (round 18 drew 1 N m chirps).
Cart-poles under ``cartpole_noise1``'s multisine and chain: a light short pole (0.2 kg, 0.3 m), a 3
kg cart under a 1 kg pole, a nearly frictionless rail (0.01 N s/m, a tenth of the base rig's), a
stiff gravity (20 m/s^2; rounds 14 and 19 drew the Moon's and Mars'), and a weak 0.3 N multisine.
Kinetics: a fast enzyme (Vmax 10 mM/s, Km 2 mM: x* 0.13 mM), a nearly linear one (Km 5 mM, Vmax
3: x* 1.25 mM), a tiny influx (0.02 mM/s: x* 4e-3 mM), a 20 mM dose, and a 2 s record at 200 Hz.
Records that barely move, for the scorer's "uninformative" rule: the paper's sine at 0.001 rad, a
0.01 N multisine on the cart-pole, a dose of 0.205 mM (2.5 % above x*).  Large multisines on the
round's cart-poles (3 N at g 20, 2 N on the light short pole, 4 N on the heavy pole), the multisine
on the short cranks, and Km 0.05 mM from a 0.5 mM dose (x* 0.033 mM).  Noise levels and seeds
111-119 are the studies' (round20_linkages_*.toml).
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 12 and 18's linkage writers
sys.path.insert(0, str(HERE.parents[2]))  # the repository root
from round12 import l_make as _ROUND12  # noqa: E402

from testbed.core.schema import validate_variant  # noqa: E402
from testbed.pipeline.plugins import rig_class  # noqa: E402
from testbed.pipeline.scenario import load_scenario  # noqa: E402
from testbed.studies.family import scenario_toml  # noqa: E402

#: name -> (description, {table: keys changed from the paper's sine scenario})
FIVEBARS: dict[str, tuple[str, dict[str, dict]]] = {
    "fb20_paper": ("the paper's linkage and sine, unchanged (held out on new seeds)", {}),
    "fb20_short_cranks": ("cranks 0.6 m under couplers 1.4 m (ground 1 m)",
                          {"rig": {"l1": 0.6, "l2": 1.4, "l3": 1.4, "l4": 0.6}}),
    "fb20_long_cranks": ("cranks 1.4 m under couplers 0.6 m on a 0.6 m ground",
                         {"rig": {"l1": 1.4, "l2": 0.6, "l3": 0.6, "l4": 1.4, "L0": 0.6}}),
    "fb20_light": ("all four links at 0.5 kg (the families' lightest)",
                   {"rig": {"m1": 0.5, "m2": 0.5, "m3": 0.5, "m4": 0.5}}),
    "fb20_3s": ("the paper's sine, a 3 s record", {"simulation": {"duration": 3.0}}),
    # a record that barely moves (round20_linkages_small.toml)
    "fb20_amp0p001": ("the paper's sine at 0.001 rad (1/70 of its 0.0698 rad)",
                      {"excitation": {"amplitude": 0.001}}),
}

#: name -> (description, {table: keys changed from fivebar_multisine_noise1})
MULTISINES: dict[str, tuple[str, dict[str, dict]]] = {
    "fb20_ms_3s": ("the multisine, a 3 s record", {"simulation": {"duration": 3.0}}),
    # round20_linkages_more.toml
    "fb20_ms_short_cranks": ("the multisine on cranks 0.6 m under couplers 1.4 m (ground 1 m)",
                             {"rig": {"l1": 0.6, "l2": 1.4, "l3": 1.4, "l4": 0.6}}),
}

#: name -> (description, the input replacing fivebar_multisine_noise1's whole, record [s])
CHIRPS: dict[str, tuple[str, dict, float]] = {
    "fb20_chirp_2nm": ("a 2 N m chirp 0.2-1 Hz over 10 s, the multisine's feedback",
                       {"type": "chirp", "amplitude": 2.0, "kp": 10.0, "kd": 2.0, "f0": 0.2, "f1": 1.0},
                       10.0),
}

#: name -> (description, {table: keys changed from cartpole_noise1 (its multisine kept)})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp20_pole0p2_L0p3": ("a light short pole (0.2 kg, 0.3 m) on the 1 kg cart",
                          {"rig": {"pole_mass": 0.2, "pole_length": 0.3}}),
    "cp20_cart3_pole1": ("a 3 kg cart under a 1 kg, 0.6 m pole",
                         {"rig": {"cart_mass": 3.0, "pole_mass": 1.0}}),
    "cp20_rail0p01": ("a nearly frictionless rail (0.01 N s/m, a tenth of the base rig's)",
                      {"rig": {"cart_damping": 0.01}}),
    "cp20_g20": ("gravity 20 m/s^2", {"rig": {"gravity": 20.0}}),
    "cp20_amp0p3": ("a weak 0.3 N multisine", {"excitation": {"amplitude": 0.3}}),
    # a record that barely moves (round20_linkages_small.toml)
    "cp20_amp0p01": ("a 0.01 N multisine", {"excitation": {"amplitude": 0.01}}),
    # large swings on the round's rigs (round20_linkages_more.toml)
    "cp20_g20_amp3": ("gravity 20 m/s^2 under a 3 N multisine",
                      {"rig": {"gravity": 20.0}, "excitation": {"amplitude": 3.0}}),
    "cp20_pole0p2_L0p3_amp2": ("a light short pole (0.2 kg, 0.3 m) under a 2 N multisine",
                               {"rig": {"pole_mass": 0.2, "pole_length": 0.3},
                                "excitation": {"amplitude": 2.0}}),
    "cp20_cart3_pole1_amp4": ("a 3 kg cart under a 1 kg pole, a 4 N multisine",
                              {"rig": {"cart_mass": 3.0, "pole_mass": 1.0},
                               "excitation": {"amplitude": 4.0}}),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1}); Km 0.3, Vmax 1.5,
#: influx 0.6 mM/s (x* 0.2 mM), x0 2 mM, 4 s at 1 kHz
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm20_vmax10_km2": ("a fast enzyme, Vmax 10 mM/s with Km 2 mM (x* 0.13 mM)",
                        {"rig": {"Vmax": 10.0, "Km": 2.0}}),
    "mm20_km5_vmax3": ("a nearly linear enzyme, Km 5 mM with Vmax 3 mM/s (x* 1.25 mM)",
                       {"rig": {"Km": 5.0, "Vmax": 3.0}}),
    "mm20_jx0p02": ("a tiny influx 0.02 mM/s (x* 4.0e-3 mM)", {"rig": {"jx": 0.02}}),
    "mm20_x0_20": ("a 20 mM dose", {"rig": {"x0": 20.0}}),
    "mm20_fs200_2s": ("the weak setup at 200 Hz on a 2 s record",
                      {"simulation": {"sample_rate": 200.0, "duration": 2.0}}),
    # a record that barely moves (round20_linkages_small.toml)
    "mm20_x0_0p205": ("a dose of 0.205 mM, 2.5 % above x* 0.2 mM", {"rig": {"x0": 0.205}}),
    # round20_linkages_last.toml
    "mm20_km0p05_x0_0p5": ("Km 0.05 mM with a 0.5 mM dose (x* 0.033 mM)",
                           {"rig": {"Km": 0.05, "x0": 0.5}}),
}


_write = _ROUND12.writer_for(HERE, 20)


def _write_chirp(name: str, description: str, excitation: dict, duration: float) -> None:
    """Write ``round20/<name>.toml``: ``fivebar_multisine_noise1`` with its input replaced whole
    and its record ``duration`` [s], written out in full (as round 18's chirps), held to the
    paper's bar."""
    sc = load_scenario("fivebar_multisine_noise1")  # a bare name: the shipped scenario
    exc = validate_variant(
        excitation, rig_class("fivebar").excitation_schemas, file=name, section="excitation"
    )
    text = f"Rigs nobody tuned, round 20: {description}; fivebar_multisine_noise1's chain"
    sc = dataclasses.replace(
        sc, name=name, description=text, tags=("unseen", "round20"), excitation=exc, score={},
        simulation={**sc.simulation, "duration": duration},
    )
    body = scenario_toml(sc).split("\n", 1)[1]
    (HERE / f"{name}.toml").write_text(
        f"# {text}\n# Written in full by round20/l_make.py from scenarios/fivebar_multisine_noise1.toml."
        f"\n{body}\n[score]\nangle_rmse_max = 0.0501       # the paper's figure\n"
    )


def main() -> None:
    _ROUND12.write_sets(_write, FIVEBARS, CARTPOLES, KINETICS, "2-19", MULTISINES)
    for name, (desc, excitation, duration) in CHIRPS.items():
        _write_chirp(name, desc, excitation, duration)


if __name__ == "__main__":
    main()
