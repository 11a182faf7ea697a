"""Write the round-18 linkage and small-rig scenarios (benchmarks/unseen/round18/{fb,cp,mm}18_*.toml):
rigs nobody tuned, default identifier settings, the earlier rounds' bars.  Run from the repository
root:

    python benchmarks/unseen/round18/l_make.py

Five-bars under the paper's sine (``fivebar_sine_replay_noise1``, and clean with recorded rates):
the paper's linkage held out at 2 and 4 % on new seeds (round 17 drew 1 / 3 %), a nearly-
parallelogram linkage (cranks 0.6 / 1 m, couplers 1 / 0.6 m: the left crank as long as the right
coupler and the left coupler as long as the right crank, ground pivots 0.05 m apart; rounds 4, 5, 11
and 14 drew ground links of 0.02-0.15 m on other link lengths), records of 1 s (a sixth of the
sine's period) and 30 s (rounds 3 and 6 drew them under their own inputs), and the sine at 0.5 Hz
(3.1x the paper's 1 rad/s; round 5 drew 0.02 and 2 Hz).  The multisine
(``fivebar_multisine_noise1``) on 1 s and 30 s records (round 16 drew 3 and 15 s).  Chirps (rounds
3-6 drew them at 1 %), ``fivebar_multisine_noise1``'s chain and feedback with the input replaced
whole and written in full: 1 N m 0.1-2 Hz over 10 s, and 1 N m 0.05-1 Hz over 30 s.  Cart-poles
under ``cartpole_noise1``'s multisine and chain: a light long pole (0.05 kg, 2 m; round 16 drew the
0.05 kg pole at 0.6 m), a 3 m pole, a 5 kg cart (round 9 drew one under a long pole), a rail of 5 N
s/m under the light 0.6 m pole (rounds 11-12 drew damped rails under the 0.5 kg pole), records of 2
s (round 3 drew one) and 30 s.  Kinetics: an influx near Vmax with a small Km (1.4 of 1.5 mM/s, Km
0.01: x* 0.14 mM), Km 0.01 mM (round 11 drew it), a dose under x* (0.05 mM rising to 0.2), a 50 Hz
record and a 30 s record.  Not written: the dose at the steady state (x0 = x* = 0.2 mM), which the
rig refuses in one line ("started there, x never moves"). Noise levels and seeds 91-95 are the
studies' (round18_linkages_*.toml).
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
    "fb18_paper": ("the paper's linkage and sine, unchanged (held out on new seeds)", {}),
    "fb18_near_parallelogram": (
        "a nearly-parallelogram linkage: cranks 0.6 / 1 m, couplers 1 / 0.6 m (l1 = l3, l2 = l4), "
        "ground pivots 0.05 m apart",
        {"rig": {"l1": 0.6, "l2": 1.0, "l3": 0.6, "l4": 1.0, "L0": 0.05}},
    ),
    "fb18_1s": ("the paper's sine, a 1 s record (a sixth of its period)",
                {"simulation": {"duration": 1.0}}),
    "fb18_30s": ("the paper's sine, a 30 s record", {"simulation": {"duration": 30.0}}),
    "fb18_f0p5": ("the paper's sine at 0.5 Hz (3.1x its 1 rad/s)",
                  {"excitation": {"frequency": 0.5}}),
}

#: name -> (description, {table: keys changed from fivebar_multisine_noise1})
MULTISINES: dict[str, tuple[str, dict[str, dict]]] = {
    "fb18_ms_1s": ("the multisine, a 1 s record", {"simulation": {"duration": 1.0}}),
    "fb18_ms_30s": ("the multisine, a 30 s record", {"simulation": {"duration": 30.0}}),
}

_CHIRP = {"type": "chirp", "amplitude": 1.0, "kp": 10.0, "kd": 2.0}
#: name -> (description, the input replacing fivebar_multisine_noise1's whole, record [s])
CHIRPS: dict[str, tuple[str, dict, float]] = {
    "fb18_chirp_0p1_2": ("a 1 N m chirp 0.1-2 Hz over 10 s, the multisine's feedback",
                         {**_CHIRP, "f0": 0.1, "f1": 2.0}, 10.0),
    "fb18_chirp_30s": ("a 1 N m chirp 0.05-1 Hz over 30 s, the multisine's feedback",
                       {**_CHIRP, "f0": 0.05, "f1": 1.0}, 30.0),
}

#: name -> (description, {table: keys changed from cartpole_noise1 (its multisine kept)})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp18_pole0p05_L2": ("a light long pole (0.05 kg, 2 m) on the 1 kg cart",
                         {"rig": {"pole_mass": 0.05, "pole_length": 2.0}}),
    "cp18_pole_L3": ("a 3 m pole (0.5 kg) on the 1 kg cart", {"rig": {"pole_length": 3.0}}),
    "cp18_cart5": ("a 5 kg cart under the 0.5 kg, 0.6 m pole", {"rig": {"cart_mass": 5.0}}),
    "cp18_rail5_pole0p05": ("a rail of 5 N s/m (50x the base rig's) under a 0.05 kg pole",
                            {"rig": {"cart_damping": 5.0, "pole_mass": 0.05}}),
    "cp18_2s": ("a 2 s record", {"simulation": {"duration": 2.0}}),
    "cp18_30s": ("a 30 s record", {"simulation": {"duration": 30.0}}),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1}); Km 0.3, Vmax 1.5,
#: influx 0.6 mM/s (x* 0.2 mM), x0 2 mM, 4 s at 1 kHz
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm18_jx1p4_km0p01": ("an influx near Vmax (1.4 of 1.5 mM/s) with Km 0.01 mM (x* 0.14 mM)",
                          {"rig": {"jx": 1.4, "Km": 0.01}}),
    "mm18_km0p01": ("Km 0.01 mM (x* 6.7e-3 mM)", {"rig": {"Km": 0.01}}),
    "mm18_x0_0p05_rise": ("a dose under the steady state (x0 0.05 mM rising to x* 0.2 mM)",
                          {"rig": {"x0": 0.05}}),
    "mm18_fs50": ("the weak setup recorded at 50 Hz", {"simulation": {"sample_rate": 50.0}}),
    "mm18_30s": ("the weak setup, a 30 s record", {"simulation": {"duration": 30.0}}),
}


_write = _ROUND12.writer_for(HERE, 18)


def _write_chirp(name: str, description: str, excitation: dict, duration: float) -> None:
    """Write ``round18/<name>.toml``: ``fivebar_multisine_noise1`` with its input replaced whole
    and its record ``duration`` [s], written out in full (an ``extends`` merges ``[excitation]``
    key by key, so the multisine's keys would stay beside a chirp's), held to the paper's bar."""
    sc = load_scenario("fivebar_multisine_noise1")  # a bare name: the shipped scenario
    exc = validate_variant(
        excitation, rig_class("fivebar").excitation_schemas, file=name, section="excitation"
    )
    text = f"Rigs nobody tuned, round 18: {description}; fivebar_multisine_noise1's chain"
    sc = dataclasses.replace(
        sc, name=name, description=text, tags=("unseen", "round18"), excitation=exc, score={},
        simulation={**sc.simulation, "duration": duration},
    )
    body = scenario_toml(sc).split("\n", 1)[1]
    (HERE / f"{name}.toml").write_text(
        f"# {text}\n# Written in full by round18/l_make.py from scenarios/fivebar_multisine_noise1.toml."
        f"\n{body}\n[score]\nangle_rmse_max = 0.0501       # the paper's figure\n"
    )


def main() -> None:
    _ROUND12.write_sets(_write, FIVEBARS, CARTPOLES, KINETICS, "2-17", MULTISINES)
    for name, (desc, excitation, duration) in CHIRPS.items():
        _write_chirp(name, desc, excitation, duration)


if __name__ == "__main__":
    main()
