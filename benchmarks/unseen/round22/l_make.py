"""Write the round-22 linkage and small-rig scenarios (benchmarks/unseen/round22/{fb,cp,mm}22_*.toml):
rigs nobody tuned, default identifier settings, the earlier rounds' bars.  Run from the repository
root:

    python benchmarks/unseen/round22/l_make.py

Five-bars under the paper's sine (``fivebar_sine_replay_noise1``, and clean with recorded rates),
in corners rounds 9-21 did not draw (they drew grounds of 0.05-2.2 m, crank masses 0.4-3 kg,
couplers 0.5-1.5 m, records of 1-40 s, the ``up`` branch only): the paper's linkage held out at 1
and 3 % on new seeds, a short ground (0.3 m under four 1 m links), light cranks (0.3 kg each),
unequal couplers 0.8 / 1.2 m, records of 4 s and 12 s, and the ``down`` branch (the mirror
assembly, from the rig's own start pose).  The multisine (``fivebar_multisine_noise1``) at 0.7 N m,
and a 1 N m chirp 0.2-1 Hz over 10 s with the multisine's feedback (round 21 drew 0.5 N m,
round 18 2 N m).  Cart-poles under ``cartpole_noise1``'s chain: a short light pole (0.2 kg, 0.3
m), a heavy cart (3 kg), gravity 15 m/s^2, the pole started 0.4 rad from rest (``th0``), and
1 N steps held 0.5 s on a new level seed (written in full: round 14 drew 2 N steps on seed 0).
Kinetics (``michaelis_menten_noise1``'s weak setup; Km 0.3, Vmax 1.5, influx 0.6 mM/s, x0 2 mM,
4 s at 1 kHz): Km 0.1 and 10 mM, Vmax 5 mM/s, Vmax 0.3 mM/s under an influx of 0.2 (x* 0.6 mM)
and under the base influx 0.6 (above Vmax: no steady state, x grows without bound), 200 Hz, 2 s
and 20 s records.  Noise levels and seeds 131-139 are the studies' (round22_linkages_*.toml).
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
    "fb22_paper": ("the paper's linkage and sine, unchanged (held out on new seeds)", {}),
    "fb22_ground_0p3": ("a 0.3 m ground under four 1 m links", {"rig": {"L0": 0.3}}),
    "fb22_light_cranks": ("light cranks (0.3 kg each, couplers 1 kg)", {"rig": {"m1": 0.3, "m4": 0.3}}),
    "fb22_couplers_0p8_1p2": ("couplers of 0.8 and 1.2 m (cranks and ground 1 m)",
                              {"rig": {"l2": 0.8, "l3": 1.2}}),
    "fb22_4s": ("the paper's sine, a 4 s record", {"simulation": {"duration": 4.0}}),
    "fb22_12s": ("the paper's sine, a 12 s record", {"simulation": {"duration": 12.0}}),
}

#: name -> (description, {table: keys changed from fivebar_multisine_noise1})
MULTISINES: dict[str, tuple[str, dict[str, dict]]] = {
    "fb22_ms_amp0p7": ("the multisine at 0.7 N m", {"excitation": {"amplitude": 0.7}}),
}

#: name -> (description, base scenario, the input replacing its whole (None: kept), {table: keys
#: changed}, score); written in full (round 12's writer writes a string key unquoted)
_FB_BAR = "angle_rmse_max = 0.0501       # the paper's figure"
_CP_BAR = "angle_rmse_max = 0.0501       # the paper's figure (rounds 2-21's bar for unseen cart-poles)"
_STEPS = {"type": "steps", "amplitude": 1.0, "hold": 0.5, "level_seed": 131, "kp": 5.0, "kd": 2.0}
FULL: dict[str, tuple[str, str, dict | None, dict[str, dict], str]] = {
    "fb22_ms_down": ("the multisine on the down branch (the mirror assembly, the rig's own start pose)",
                     "fivebar_multisine_noise1", None, {"rig": {"branch": "down"}}, _FB_BAR),
    "fb22_chirp_1nm": ("a 1 N m chirp 0.2-1 Hz over 10 s, the multisine's feedback",
                       "fivebar_multisine_noise1",
                       {"type": "chirp", "amplitude": 1.0, "kp": 10.0, "kd": 2.0, "f0": 0.2, "f1": 1.0},
                       {"simulation": {"duration": 10.0}}, _FB_BAR),
    "cp22_steps_1n_0p5s": ("1 N steps held 0.5 s (levels uniform in +-1 N, level seed 131)",
                           "cartpole_noise1", _STEPS, {}, _CP_BAR),
}

#: name -> (description, {table: keys changed from cartpole_noise1 (its multisine kept)})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp22_pole0p2_L0p3": ("a short light pole (0.2 kg, 0.3 m) on the 1 kg cart",
                          {"rig": {"pole_mass": 0.2, "pole_length": 0.3}}),
    "cp22_cart3": ("a heavy cart (3 kg) under the 0.5 kg pole", {"rig": {"cart_mass": 3.0}}),
    "cp22_g15": ("gravity 15 m/s^2", {"rig": {"gravity": 15.0}}),
    "cp22_th0p4": ("the pole started 0.4 rad from its rest", {"rig": {"th0": 0.4}}),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1}); Km 0.3, Vmax 1.5,
#: influx 0.6 mM/s (x* 0.2 mM), x0 2 mM, 4 s at 1 kHz
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm22_km0p1": ("Km 0.1 mM (x* 0.067 mM)", {"rig": {"Km": 0.1}}),
    "mm22_km10": ("Km 10 mM (x* 6.7 mM: a rise from the 2 mM dose, far below saturation)",
                  {"rig": {"Km": 10.0}}),
    "mm22_vmax5": ("Vmax 5 mM/s (x* 0.041 mM)", {"rig": {"Vmax": 5.0}}),
    "mm22_vmax0p3_jx0p2": ("Vmax 0.3 mM/s under an influx of 0.2 (x* 0.6 mM)",
                           {"rig": {"Vmax": 0.3, "jx": 0.2}}),
    "mm22_vmax0p3": ("Vmax 0.3 mM/s under the base influx 0.6 (above Vmax: no steady state)",
                     {"rig": {"Vmax": 0.3}}),
    "mm22_fs200": ("the weak setup at 200 Hz", {"simulation": {"sample_rate": 200.0}}),
    "mm22_2s": ("the weak setup on a 2 s record", {"simulation": {"duration": 2.0}}),
    "mm22_20s": ("the weak setup on a 20 s record", {"simulation": {"duration": 20.0}}),
}


_write = _ROUND12.writer_for(HERE, 22)


def _write_full(name: str, description: str, base: str, excitation: dict | None, tables: dict[str, dict],
                score: str) -> None:
    """Write ``round22/<name>.toml``: the shipped scenario ``base`` with its input replaced whole
    and ``tables``' keys changed, written out in full (an ``extends`` merges ``[excitation]`` key
    by key: the multisine's keys would stay beside a chirp's), with the ``[score]`` line."""
    sc = load_scenario(base)  # a bare name: the shipped scenario
    exc = sc.excitation if excitation is None else validate_variant(
        excitation, rig_class(sc.rig).excitation_schemas, file=name, section="excitation"
    )
    text = f"Rigs nobody tuned, round 22: {description}; {base}'s chain"
    sc = dataclasses.replace(
        sc, name=name, description=text, tags=("unseen", "round22"), excitation=exc, score={},
        rig_params={**sc.rig_params, **tables.get("rig", {})},
        simulation={**sc.simulation, **tables.get("simulation", {})},
    )
    body = scenario_toml(sc).split("\n", 1)[1]
    (HERE / f"{name}.toml").write_text(
        f"# {text}\n# Written in full by round22/l_make.py from scenarios/{base}.toml.\n{body}\n"
        f"[score]\n{score}\n"
    )


def main() -> None:
    _ROUND12.write_sets(_write, FIVEBARS, CARTPOLES, KINETICS, "2-21", MULTISINES)
    for name, (desc, base, excitation, tables, score) in FULL.items():
        _write_full(name, desc, base, excitation, tables, score)


if __name__ == "__main__":
    main()
