"""Write the round-12 linkage and small-rig scenarios (benchmarks/unseen/round12/{fb,cp,mm}12_*.toml):
rigs nobody tuned, default identifier settings, the earlier rounds' bars.  Run from the repository
root:

    python benchmarks/unseen/round12/l_make.py

Five-bars: the paper's sine input (``fivebar_sine_replay_noise1``) on link-length ratios rounds
3-11 did not use: couplers 5x the cranks (0.3 / 1.5 m over a 0.8 m base; rounds went to 3x
under the sine, 3.6x under the multisine), cranks 2x the couplers (1.2 / 0.6 m over 0.5 m;
rounds went to 1.44x), a base 5x the cranks (0.4 m cranks, 1.2 m couplers, 2 m base; rounds
went to 2.2 m on 1.2 m cranks), and couplers of 0.5 / 1.5 m on equal cranks (3x; rounds went
to 1.75x on a linkage with equal cranks, 3.6x with cranks 4x apart).  The rig's validation
(``models/fivebar/rig.py`` ``check``: the loop closes, the start pose and the whole sine path
keep the transmission angle in range) admits each; where the paper's pose does not, the start
pose is the rig's own rule written out (round 11's ``fivebar_tables``).  Each case twice:
``fb12_<case>`` with the noise chain, ``fb12_<case>_rec`` clean with the recorded rates.
The multisine (``fivebar_multisine_noise1``) at 0.25, 0.5, 0.75, 1.25 and 1.5 N m (rounds used
1, 2, 3).
Cart-poles: ``cartpole_noise1``'s chain with friction-like damping on both joints (a rail of
2 and 15 N s/m with a damped hinge, a hinge of 0.5 N m s/rad on the base pole).
Kinetics: ``michaelis_menten_noise1``'s weak setup with other dosing: a 5 mM dose, a 1 mM dose
under a weak influx (0.3 mM/s), an influx near Vmax (1.4 of 1.5 mM/s, x* 4.2 mM) from 2 mM,
and a 0.5 mM dose decaying to x* 0.046 mM under 0.2 mM/s.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 10-11's linkage writers
from round10.l_make import path_transmission_deg  # noqa: E402
from round11.l_make import PAPER_AMP, PAPER_POSE, _value, fivebar_tables  # noqa: E402

#: name -> (description, {table: keys changed from the paper's sine scenario})
FIVEBARS: dict[str, tuple[str, dict[str, dict]]] = {
    "fb12_coupler_5x": ("couplers 5x the cranks: cranks 0.3 m, couplers 1.5 m, base 0.8 m",
                        {"rig": {"l1": 0.3, "l2": 1.5, "l3": 1.5, "l4": 0.3, "L0": 0.8}}),
    "fb12_crank_2x": ("cranks 2x the couplers: cranks 1.2 m, couplers 0.6 m, base 0.5 m",
                      {"rig": {"l1": 1.2, "l2": 0.6, "l3": 0.6, "l4": 1.2, "L0": 0.5}}),
    "fb12_base_5x": ("a base 5x the cranks: cranks 0.4 m, couplers 1.2 m, base 2 m",
                     {"rig": {"l1": 0.4, "l2": 1.2, "l3": 1.2, "l4": 0.4, "L0": 2.0}}),
    "fb12_couplers_3to1": ("couplers 0.5 / 1.5 m on 1 m cranks over a 1 m base",
                           {"rig": {"l2": 0.5, "l3": 1.5}}),
}

#: name -> (description, {table: keys changed from fivebar_multisine_noise1})
MULTISINES: dict[str, tuple[str, dict[str, dict]]] = {
    f"fb12_ms_amp{str(a).replace('.', 'p')}": (f"the multisine at {a} N m (the paper's linkage)",
                                                {"excitation": {"amplitude": a}})
    for a in (0.25, 0.5, 0.75, 1.25, 1.5)
}

#: name -> (description, {table: keys changed from cartpole_noise1})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp12_rail2_hinge0p05": ("rail damping 2 N s/m and hinge damping 0.05 N m s/rad (20x / 10x the "
                             "base rig's)", {"rig": {"cart_damping": 2.0, "pole_damping": 0.05}}),
    "cp12_rail15": ("rail damping 15 N s/m (150x the base rig's: the cart follows the force)",
                    {"rig": {"cart_damping": 15.0}}),
    "cp12_hinge0p5": ("hinge damping 0.5 N m s/rad on the 0.6 m pole (100x the base rig's)",
                      {"rig": {"pole_damping": 0.5}}),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1})
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm12_dose5": ("a 5 mM dose (x0 5 mM) decaying to x* 0.18 mM", {"rig": {"x0": 5.0}}),
    "mm12_jx0p3_dose1": ("a 1 mM dose under a weak influx 0.3 mM/s (x* 0.075 mM)",
                         {"rig": {"jx": 0.3, "x0": 1.0}}),
    "mm12_jx1p4": ("an influx near Vmax (1.4 of 1.5 mM/s, x* 4.2 mM) from 2 mM, 8 s",
                   {"rig": {"jx": 1.4}, "simulation": {"duration": 8.0}}),
    "mm12_dose0p5_jx0p2": ("a 0.5 mM dose under 0.2 mM/s (x* 0.046 mM)", {"rig": {"jx": 0.2, "x0": 0.5}}),
}


def _write(name: str, base: str, description: str, tables: dict[str, dict], score: str) -> None:
    """Write ``round12/<name>.toml``: ``base`` with ``tables``' keys and the ``[score]`` line."""
    lines = [f"# Rigs nobody tuned, round 12: {description}", "", "[scenario]",
             f'extends = "../../../scenarios/{base}.toml"', f'name = "{name}"',
             f'description = "Rigs nobody tuned, round 12: {description}"',
             'tags = ["unseen", "round12"]']
    for table in ("rig", "simulation", "excitation"):
        if tables.get(table):
            lines += ["", f"[{table}]"] + [f"{k} = {_value(v)}" for k, v in tables[table].items()]
    lines += ["", "[score]", score, ""]
    (HERE / f"{name}.toml").write_text("\n".join(lines))


def writer_for(here: Path, number: int):
    """A later round's writer: :func:`_write` into ``here``, with round ``number``'s header and tag."""
    def write(name: str, base: str, description: str, tables: dict[str, dict], score: str) -> None:
        global HERE
        HERE = here  # _write writes into this module's HERE
        _write(name, base, description, tables, score)
        path = here / f"{name}.toml"
        path.write_text(path.read_text().replace("round 12", f"round {number}")
                        .replace('"round12"', f'"round{number}"'))
    return write


def write_sets(write, fivebars: dict, cartpoles: dict, kinetics: dict, bar_rounds: str,
               multisines: dict | None = None) -> None:
    """Write each set's scenario files with ``write(name, base, description, tables, score)``:
    five-bars under the paper's sine (noisy, and clean with recorded rates), multisines,
    cart-poles and kinetics, each held to the bar of rounds ``bar_rounds`` (rounds 12-13)."""
    for name, (desc, tables) in fivebars.items():
        t = fivebar_tables(tables)
        rig = {"th1_0": PAPER_POSE[0], "th4_0": PAPER_POSE[1], **t.get("rig", {})}
        lo, hi = path_transmission_deg(rig, PAPER_AMP)
        print(f"{name}: pose ({rig['th1_0']}, {rig['th4_0']}), transmission {lo:.1f}-{hi:.1f} deg")
        write(name, "fivebar_sine_replay_noise1", desc, t,
              "angle_rmse_max = 0.0501       # the paper's figure")
        write(name + "_rec", "fivebar_sine_replay", desc + ", recorded rates", t,
              "angle_rmse_max = 1e-4         # the issue's clean bar")
    for name, (desc, tables) in (multisines or {}).items():
        write(name, "fivebar_multisine_noise1", desc, tables,
              "angle_rmse_max = 0.0501       # the paper's figure")
    for name, (desc, tables) in cartpoles.items():
        write(name, "cartpole_noise1", desc + "; cartpole_noise1's chain", tables,
              "angle_rmse_max = 0.0501       # the paper's figure (rounds "
              f"{bar_rounds}'s bar for unseen cart-poles)")
    for name, (desc, tables) in kinetics.items():
        write(name, "michaelis_menten_noise1", desc + "; michaelis_menten_noise1's weak setup", tables,
              f"state_rmse_max = 0.01         # mM (rounds {bar_rounds}'s bar); "
              "the rig's own equation bars apply too")


def main() -> None:
    write_sets(_write, FIVEBARS, CARTPOLES, KINETICS, "2-11", MULTISINES)


if __name__ == "__main__":
    main()
