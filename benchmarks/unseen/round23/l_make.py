"""Write the round-23 linkage and small-rig scenarios (benchmarks/unseen/round23/{fb,cp,mm}23_*.toml): rigs
nobody tuned, default identifier settings, the earlier rounds' bars. Run from the repository root:

    python benchmarks/unseen/round23/l_make.py

Five-bars under the paper's sine (``fivebar_sine_replay_noise1``, and clean with recorded rates), in
corners rounds 9-22 did not draw (they drew grounds of 0.05-2.2 m, crank masses 0.3-3 kg, couplers
0.5-1.5 m, records of 1-40 s, the ``down`` branch under the multisine only): the paper's linkage held
out on new seeds, heavy cranks (2.5 kg each under 1 kg couplers), near-equal unequal couplers 0.9 / 1.1
m, a 0.6 m ground under four 1 m links, records of 6 s and 15 s, and the paper's sine on the ``down``
branch (the mirror assembly, from the rig's own start pose: no round drew the sine there). The multisine
(``fivebar_multisine_noise1``) at 0.5 N m on a new phase seed (3) and at 1.2 N m (between round 21's 0.5
and its 1.5, which the rig refused). Cart-poles under ``cartpole_noise1``'s chain: poles of 0.4 and 0.8
m, carts of 0.5 and 2 kg, the multisine on a new phase seed (3). Kinetics (``michaelis_menten_noise1``'s
weak setup; Km 0.3, Vmax 1.5, influx 0.6 mM/s, x0 2 mM, 4 s at 1 kHz): Km 3 mM from doses of 0.5 and 5
mM (x* 2 mM; from the base 2 mM dose, its steady state, the scenario refuses it in one line), Vmax 2
mM/s, Vmax 0.5 under an influx of 0.3 (x* 0.45 mM), an influx of 0.9 (x* 0.45 mM), a 0.5 mM dose (a
decay to x* 0.2 from close above it), 2 kHz, a 1.5 s record (1 s is refused: the weak window is 1 s).
Noise levels and seeds 141-149 are the studies' (round23_linkages_*.toml).
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: round 12's linkage writer
sys.path.insert(0, str(HERE.parents[2]))  # the repository root
from round12 import l_make as _ROUND12  # noqa: E402

from testbed.pipeline.scenario import load_scenario  # noqa: E402
from testbed.studies.family import scenario_toml  # noqa: E402

#: name -> (description, {table: keys changed from the paper's sine scenario})
FIVEBARS: dict[str, tuple[str, dict[str, dict]]] = {
    "fb23_paper": ("the paper's linkage and sine, unchanged (held out on new seeds)", {}),
    "fb23_heavy_cranks": ("heavy cranks (2.5 kg each, couplers 1 kg)", {"rig": {"m1": 2.5, "m4": 2.5}}),
    "fb23_couplers_0p9_1p1": ("couplers of 0.9 and 1.1 m (cranks and ground 1 m)",
                              {"rig": {"l2": 0.9, "l3": 1.1}}),
    "fb23_ground_0p6": ("a 0.6 m ground under four 1 m links", {"rig": {"L0": 0.6}}),
    "fb23_6s": ("the paper's sine, a 6 s record", {"simulation": {"duration": 6.0}}),
    "fb23_15s": ("the paper's sine, a 15 s record", {"simulation": {"duration": 15.0}}),
}

#: name -> (description, {table: keys changed from fivebar_multisine_noise1})
MULTISINES: dict[str, tuple[str, dict[str, dict]]] = {
    "fb23_ms_amp0p5_ph3": ("the multisine at 0.5 N m on phase seed 3",
                           {"excitation": {"amplitude": 0.5, "phase_seed": 3}}),
    "fb23_ms_amp1p2": ("the multisine at 1.2 N m", {"excitation": {"amplitude": 1.2}}),
}

#: name -> (description, base scenario, {table: keys changed}, score); written in full
_FB_BAR = "angle_rmse_max = 0.0501       # the paper's figure"
FULL: dict[str, tuple[str, str, dict[str, dict], str]] = {
    "fb23_sine_down": ("the paper's sine on the down branch (the mirror assembly, the rig's own start pose)",
                       "fivebar_sine_replay_noise1", {"rig": {"branch": "down"}}, _FB_BAR),
    # a second batch (round23_linkages_more.toml)
    "fb23_ms_down_0p5": ("the multisine at 0.5 N m on the down branch (the mirror assembly, the rig's own "
                         "start pose)", "fivebar_multisine_noise1",
                         {"rig": {"branch": "down"}, "excitation": {"amplitude": 0.5}}, _FB_BAR),
}

#: name -> (description, {table: keys changed from cartpole_noise1 (its multisine kept)})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp23_L0p4": ("a 0.4 m pole (0.5 kg) on the 1 kg cart", {"rig": {"pole_length": 0.4}}),
    "cp23_L0p8": ("a 0.8 m pole (0.5 kg) on the 1 kg cart", {"rig": {"pole_length": 0.8}}),
    "cp23_cart0p5": ("a 0.5 kg cart under the 0.5 kg pole", {"rig": {"cart_mass": 0.5}}),
    "cp23_cart2": ("a 2 kg cart under the 0.5 kg pole", {"rig": {"cart_mass": 2.0}}),
    "cp23_ph3": ("the shipped cart-pole under the multisine's phase seed 3",
                 {"excitation": {"phase_seed": 3}}),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1}); Km 0.3, Vmax 1.5,
#: influx 0.6 mM/s (x* 0.2 mM), x0 2 mM, 4 s at 1 kHz
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    # (Km 3 from the base 2 mM dose, its steady state, is refused by the scenario in one line: "rig.x0: value
    # 2.0: expected away from the steady state ... x never moves")
    "mm23_km3_x0p5": ("Km 3 mM from a 0.5 mM dose (a rise to x* 2 mM)", {"rig": {"Km": 3.0, "x0": 0.5}}),
    "mm23_km3_x5": ("Km 3 mM from a 5 mM dose (x* 2 mM)", {"rig": {"Km": 3.0, "x0": 5.0}}),
    "mm23_vmax2": ("Vmax 2 mM/s (x* 0.13 mM)", {"rig": {"Vmax": 2.0}}),
    "mm23_vmax0p5_jx0p3": ("Vmax 0.5 mM/s under an influx of 0.3 (x* 0.45 mM)",
                           {"rig": {"Vmax": 0.5, "jx": 0.3}}),
    "mm23_jx0p9": ("an influx of 0.9 mM/s (x* 0.45 mM)", {"rig": {"jx": 0.9}}),
    "mm23_x0p5": ("a 0.5 mM dose (x* 0.2 mM)", {"rig": {"x0": 0.5}}),
    "mm23_fs2k": ("the weak setup at 2 kHz", {"simulation": {"sample_rate": 2000.0}}),
    # (a 1 s record is refused by the scenario in one line: "identify.weak_window_s: value 1.0: shorter than
    # the record (1 s)")
    "mm23_1p5s": ("the weak setup on a 1.5 s record", {"simulation": {"duration": 1.5}}),
}


_write = _ROUND12.writer_for(HERE, 23)


def _write_full(name: str, description: str, base: str, tables: dict[str, dict], score: str) -> None:
    """Write ``round23/<name>.toml``: the shipped scenario ``base`` with ``tables``' keys changed (the
    input's keys over its own: the same input type) and
    the start pose left to the rig (``th1_0`` / ``th4_0`` dropped: the paper's pose is an up-branch
    assembly), written out in full, with the ``[score]`` line."""
    sc = load_scenario(base)  # a bare name: the shipped scenario
    text = f"Rigs nobody tuned, round 23: {description}; {base}'s chain"
    rig = {k: v for k, v in {**sc.rig_params, **tables.get("rig", {})}.items() if k not in ("th1_0", "th4_0")}
    sc = dataclasses.replace(
        sc, name=name, description=text, tags=("unseen", "round23"), score={}, rig_params=rig,
        excitation={**sc.excitation, **tables.get("excitation", {})},
        simulation={**sc.simulation, **tables.get("simulation", {})},
    )
    body = scenario_toml(sc).split("\n", 1)[1]
    (HERE / f"{name}.toml").write_text(
        f"# {text}\n# Written in full by round23/l_make.py from scenarios/{base}.toml.\n{body}\n"
        f"[score]\n{score}\n"
    )


def main() -> None:
    _ROUND12.write_sets(_write, FIVEBARS, CARTPOLES, KINETICS, "2-22", MULTISINES)
    for name, (desc, base, tables, score) in FULL.items():
        _write_full(name, desc, base, tables, score)


if __name__ == "__main__":
    main()
