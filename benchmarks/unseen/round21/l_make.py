"""Write the round-21 linkage and small-rig scenarios (benchmarks/unseen/round21/{fb,cp,mm}21_*.toml):
rigs nobody tuned, default identifier settings, the earlier rounds' bars.  Run from the repository
root:

    python benchmarks/unseen/round21/l_make.py

Five-bars under the paper's sine (``fivebar_sine_replay_noise1``, and clean with recorded rates):
the paper's linkage held out at 1 and 2 % on new seeds (rounds 17-20 drew 0.5-4 % on seeds
81-119), a long ground (1.4 m under four 1 m links; round 17 drew 0.6 m), couplers of 0.7 and 1.3
m (rounds 19-20 changed the couplers together with the cranks), heavy couplers (3 kg each; the
heaviest drawn were 2 kg), and records of 2 s and 8 s (rounds drew 1, 3, 5, 10, 15 and 30 s).
The multisine (``fivebar_multisine_noise1``) at 0.5 and 1.5 N m (rounds drew 1 N m and a 2 N m
chirp), and a 0.5 N m chirp 0.2-1 Hz over 10 s with the multisine's feedback.  Cart-poles under
``cartpole_noise1``'s multisine and chain: a heavy long pole (2 kg, 1.2 m), a light cart (0.3 kg),
a rail of 1 N s/m (10x the base rig's), gravity 5 m/s^2, and a 1.5 N multisine.  Kinetics: Km 1
mM with Vmax 0.8 mM/s (x* 3 mM: a rise from the 2 mM dose), an influx near Vmax (1.4 of 1.5 mM/s,
x* 4.2 mM), Km 0.01 mM (x* 0.0067 mM), a 5 mM dose, and 100 Hz on an 8 s record.  Later
(round21_linkages_more.toml): the multisine on the 1.4 m ground and with 3 kg couplers, the heavy
long pole under a 2 N multisine, Km 0.01 mM from a 5 mM dose.  Noise levels and seeds 121-129 are
the studies' (round21_linkages_*.toml).
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: round 12's linkage writer
sys.path.insert(0, str(HERE.parents[2]))  # the repository root
from round12 import l_make as _ROUND12  # noqa: E402

from testbed.core.schema import validate_variant  # noqa: E402
from testbed.pipeline.plugins import rig_class  # noqa: E402
from testbed.pipeline.scenario import load_scenario  # noqa: E402
from testbed.studies.family import scenario_toml  # noqa: E402

#: name -> (description, {table: keys changed from the paper's sine scenario})
FIVEBARS: dict[str, tuple[str, dict[str, dict]]] = {
    "fb21_paper": ("the paper's linkage and sine, unchanged (held out on new seeds)", {}),
    "fb21_ground_1p4": ("a 1.4 m ground under four 1 m links", {"rig": {"L0": 1.4}}),
    "fb21_couplers_0p7_1p3": ("couplers of 0.7 and 1.3 m (cranks and ground 1 m)",
                              {"rig": {"l2": 0.7, "l3": 1.3}}),
    "fb21_heavy_couplers": ("couplers of 3 kg each (cranks 1 kg)", {"rig": {"m2": 3.0, "m3": 3.0}}),
    "fb21_2s": ("the paper's sine, a 2 s record", {"simulation": {"duration": 2.0}}),
    "fb21_8s": ("the paper's sine, an 8 s record", {"simulation": {"duration": 8.0}}),
}

#: name -> (description, {table: keys changed from fivebar_multisine_noise1})
MULTISINES: dict[str, tuple[str, dict[str, dict]]] = {
    "fb21_ms_amp0p5": ("the multisine at 0.5 N m", {"excitation": {"amplitude": 0.5}}),
    "fb21_ms_amp1p5": ("the multisine at 1.5 N m", {"excitation": {"amplitude": 1.5}}),
    # round21_linkages_more.toml
    "fb21_ms_ground_1p4": ("the multisine on a 1.4 m ground under four 1 m links", {"rig": {"L0": 1.4}}),
    "fb21_ms_heavy_couplers": ("the multisine with couplers of 3 kg each",
                               {"rig": {"m2": 3.0, "m3": 3.0}}),
}

#: name -> (description, the input replacing fivebar_multisine_noise1's whole, record [s])
CHIRPS: dict[str, tuple[str, dict, float]] = {
    "fb21_chirp_0p5nm": ("a 0.5 N m chirp 0.2-1 Hz over 10 s, the multisine's feedback",
                         {"type": "chirp", "amplitude": 0.5, "kp": 10.0, "kd": 2.0, "f0": 0.2,
                          "f1": 1.0}, 10.0),
}

#: name -> (description, {table: keys changed from cartpole_noise1 (its multisine kept)})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp21_pole2_L1p2": ("a heavy long pole (2 kg, 1.2 m) on the 1 kg cart",
                        {"rig": {"pole_mass": 2.0, "pole_length": 1.2}}),
    "cp21_cart0p3": ("a light cart (0.3 kg) under the 0.5 kg pole", {"rig": {"cart_mass": 0.3}}),
    "cp21_rail1": ("a rail of 1 N s/m (10x the base rig's)", {"rig": {"cart_damping": 1.0}}),
    "cp21_g5": ("gravity 5 m/s^2", {"rig": {"gravity": 5.0}}),
    "cp21_amp1p5": ("a 1.5 N multisine", {"excitation": {"amplitude": 1.5}}),
    # round21_linkages_more.toml
    "cp21_pole2_L1p2_amp2": ("a heavy long pole (2 kg, 1.2 m) under a 2 N multisine",
                             {"rig": {"pole_mass": 2.0, "pole_length": 1.2},
                              "excitation": {"amplitude": 2.0}}),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1}); Km 0.3, Vmax 1.5,
#: influx 0.6 mM/s (x* 0.2 mM), x0 2 mM, 4 s at 1 kHz
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm21_km1_vmax0p8": ("Km 1 mM with Vmax 0.8 mM/s (x* 3 mM: a rise from the 2 mM dose)",
                         {"rig": {"Km": 1.0, "Vmax": 0.8}}),
    "mm21_jx1p4": ("an influx of 1.4 mM/s near Vmax 1.5 (x* 4.2 mM)", {"rig": {"jx": 1.4}}),
    "mm21_km0p01": ("Km 0.01 mM (x* 0.0067 mM)", {"rig": {"Km": 0.01}}),
    "mm21_x0_5": ("a 5 mM dose", {"rig": {"x0": 5.0}}),
    "mm21_fs100_8s": ("the weak setup at 100 Hz on an 8 s record",
                      {"simulation": {"sample_rate": 100.0, "duration": 8.0}}),
    # round21_linkages_more.toml
    "mm21_km0p01_x0_5": ("Km 0.01 mM with a 5 mM dose (x* 0.0067 mM)", {"rig": {"Km": 0.01, "x0": 5.0}}),
}


_write = _ROUND12.writer_for(HERE, 21)


def _write_chirp(name: str, description: str, excitation: dict, duration: float) -> None:
    """Write ``round21/<name>.toml``: ``fivebar_multisine_noise1`` with its input replaced whole
    and its record ``duration`` [s], written out in full (as round 18's chirps), held to the
    paper's bar."""
    sc = load_scenario("fivebar_multisine_noise1")  # a bare name: the shipped scenario
    exc = validate_variant(
        excitation, rig_class("fivebar").excitation_schemas, file=name, section="excitation"
    )
    text = f"Rigs nobody tuned, round 21: {description}; fivebar_multisine_noise1's chain"
    sc = dataclasses.replace(
        sc, name=name, description=text, tags=("unseen", "round21"), excitation=exc, score={},
        simulation={**sc.simulation, "duration": duration},
    )
    body = scenario_toml(sc).split("\n", 1)[1]
    (HERE / f"{name}.toml").write_text(
        f"# {text}\n# Written in full by round21/l_make.py from scenarios/fivebar_multisine_noise1.toml."
        f"\n{body}\n[score]\nangle_rmse_max = 0.0501       # the paper's figure\n"
    )


def main() -> None:
    _ROUND12.write_sets(_write, FIVEBARS, CARTPOLES, KINETICS, "2-20", MULTISINES)
    for name, (desc, excitation, duration) in CHIRPS.items():
        _write_chirp(name, desc, excitation, duration)


if __name__ == "__main__":
    main()
