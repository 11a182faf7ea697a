"""Write the round-11 linkage and small-rig scenarios (benchmarks/unseen/round11/{fb,cp,mm}11_*.toml):
rigs nobody tuned, default identifier settings, the earlier rounds' bars.  Run from the repository
root:

    python benchmarks/unseen/round11/l_make.py

Five-bars: the paper's sine input (``fivebar_sine_replay_noise1``: both actuated joints
th_0 + A sin(t + pi/2), rates by the chain's automatic low-pass) where rounds 3-10 did not go:
asymmetric cranks (left and right of different lengths and masses, or of different inertias,
as a motor's rotor on one side would make them), a base wider (2.2 m) and narrower (0.15 m) than
any round's working linkage, the joints' viscous damping at 0 and 20x the paper's, cranks carrying
a rotor's inertia (0.8 kg m^2 each, 4.8x a rod's), and an asymmetric linkage in a vertical plane
(gravity on).  Where the paper's pose (1.78, 1.36 rad) does not assemble or leaves the transmission
range, the start pose is the rig's own rule (``models.fivebar.geometry.auto_start_pose``),
written out.  Each case is written twice: ``fb11_<case>`` with the noise chain and
``fb11_<case>_rec`` clean with the recorded rates (``fivebar_sine_replay``), scored on the issue's
clean bar (1e-4 rad).
Cart-poles: ``cartpole_noise1``'s chain with a heavily damped rail (5 N s/m), a 2.5 m pole, a
0.2 N forcing that keeps the pole near its hanging rest, and a damped hinge on a 1.5 m pole.
Kinetics: ``michaelis_menten_noise1``'s weak setup with Km far below x (0.01 mM: zero-order),
far above it (20 mM: first-order), no influx (a pure decay: the law has no constant term) and a
rise from 0.05 mM to x* = 0.6 mM over 6 s.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from models.fivebar import geometry

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: round 10's linkage writer
from round10.l_make import _params, path_transmission_deg  # noqa: E402

PAPER_POSE = (1.78, 1.36)
PAPER_AMP = 0.0698   # rad, the paper's 4 deg

#: name -> (description, {table: keys changed from the paper's sine scenario})
FIVEBARS: dict[str, tuple[str, dict[str, dict]]] = {
    "fb11_asym_cranks": ("asymmetric cranks: left 0.8 m 0.8 kg, right 1.2 m 1.4 kg",
                         {"rig": {"l1": 0.8, "m1": 0.8, "l4": 1.2, "m4": 1.4}}),
    "fb11_asym_rotor": ("cranks of one length, left 0.4 kg with 0.01 kg m^2, right 2 kg with 0.4 kg m^2",
                        {"rig": {"m1": 0.4, "I1": 0.01, "m4": 2.0, "I4": 0.4}}),
    "fb11_base_2p2": ("base 2.2 m, links 1.2 m (wider than any working round's base)",
                      {"rig": {"l1": 1.2, "l2": 1.2, "l3": 1.2, "l4": 1.2, "L0": 2.2}}),
    "fb11_base_0p15": ("base 0.15 m, links 1 m (narrower than any working round's base)",
                       {"rig": {"L0": 0.15}}),
    "fb11_damping_20x": ("the joints' viscous damping 0.02 N m s/rad (20x the paper's)",
                         {"rig": {"damping": 0.02}}),
    "fb11_damping_0": ("no joint damping (the equations' damping terms are absent)",
                       {"rig": {"damping": 0.0}}),
    "fb11_rotor_both": ("cranks carrying a rotor's inertia, 0.8 kg m^2 each (4.8x a rod's 0.167)",
                        {"rig": {"I1": 0.8, "I4": 0.8}}),
    "fb11_gravity_asym": ("a vertical plane (gravity on), cranks 0.9 / 1.1 m",
                          {"rig": {"gravity": True, "l1": 0.9, "l4": 1.1}}),
}

#: name -> (description, {table: keys changed from cartpole_noise1})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp11_cart_damped": ("rail damping 5 N s/m (50x the base rig's)", {"rig": {"cart_damping": 5.0}}),
    "cp11_pole_2p5m": ("a 0.5 kg, 2.5 m pole on the 1 kg cart", {"rig": {"pole_length": 2.5}}),
    "cp11_near_rest": ("the base rig forced with 0.2 N tones: the pole stays near its hanging rest",
                       {"excitation": {"amplitude": 0.2}}),
    "cp11_hinge_damped_long": ("a 1.5 m pole with hinge damping 0.2 N m s/rad",
                               {"rig": {"pole_length": 1.5, "pole_damping": 0.2}}),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1})
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm11_km0p01": ("Km 0.01 mM far below x (x* 0.012 mM, x0 2 mM): zero-order for most of the record",
                    {"rig": {"Km": 0.01}}),
    "mm11_km20_vmax30": ("Km 20 mM far above x, Vmax 30 mM/s (x* 0.41 mM, x0 2 mM): first-order",
                         {"rig": {"Km": 20.0, "Vmax": 30.0}}),
    "mm11_jx0_decay": ("no influx, Km 0.5 mM, x0 3 mM: a pure decay towards 0 (no constant term)",
                       {"rig": {"jx": 0.0, "Km": 0.5, "x0": 3.0}}),
    "mm11_rise_x0_0p05": ("influx 1 mM/s (x* 0.6 mM), x0 0.05 mM rising, 6 s",
                          {"rig": {"jx": 1.0, "x0": 0.05}, "simulation": {"duration": 6.0}}),
}


def _value(v: object) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    return repr(v) if isinstance(v, float) else str(v)


def _write(name: str, base: str, description: str, tables: dict[str, dict], score: str) -> None:
    """Write ``round11/<name>.toml``: ``base`` with ``tables``' keys and the ``[score]`` line."""
    lines = [f"# Rigs nobody tuned, round 11: {description}", "", "[scenario]",
             f'extends = "../../../scenarios/{base}.toml"', f'name = "{name}"',
             f'description = "Rigs nobody tuned, round 11: {description}"',
             'tags = ["unseen", "round11"]']
    for table in ("rig", "simulation", "excitation"):
        if tables.get(table):
            lines += ["", f"[{table}]"] + [f"{k} = {_value(v)}" for k, v in tables[table].items()]
    lines += ["", "[score]", score, ""]
    (HERE / f"{name}.toml").write_text("\n".join(lines))


def fivebar_tables(tables: dict[str, dict]) -> dict[str, dict]:
    """The tables with a start pose: the paper's where usable, else the rig's rule written out."""
    rig = dict(tables.get("rig", {}))
    if "th1_0" not in rig:
        if bool(geometry.usable(np.array(PAPER_POSE[0]), np.array(PAPER_POSE[1]), _params(rig))):
            return tables
        th1, th4, _ = geometry.auto_start_pose(_params(rig))
        rig.update(th1_0=round(th1, 4), th4_0=round(th4, 4))
    return {**tables, "rig": rig}


def main() -> None:
    for name, (desc, tables) in FIVEBARS.items():
        t = fivebar_tables(tables)
        rig = {"th1_0": PAPER_POSE[0], "th4_0": PAPER_POSE[1], **t.get("rig", {})}
        amp = t.get("excitation", {}).get("amplitude", PAPER_AMP)
        lo, hi = path_transmission_deg(rig, amp)
        print(f"{name}: pose ({rig['th1_0']}, {rig['th4_0']}), transmission {lo:.1f}-{hi:.1f} deg")
        _write(name, "fivebar_sine_replay_noise1", desc, t,
               "angle_rmse_max = 0.0501       # the paper's figure")
        _write(name + "_rec", "fivebar_sine_replay", desc + ", recorded rates", t,
               "angle_rmse_max = 1e-4         # the issue's clean bar")
    for name, (desc, tables) in CARTPOLES.items():
        _write(name, "cartpole_noise1", desc + "; cartpole_noise1's chain", tables,
               "angle_rmse_max = 0.0501       # the paper's figure (rounds 2-10's bar for unseen cart-poles)")
    for name, (desc, tables) in KINETICS.items():
        _write(name, "michaelis_menten_noise1", desc + "; michaelis_menten_noise1's weak setup", tables,
               "state_rmse_max = 0.01         # mM (rounds 2-10's bar); "
               "the rig's own equation bars apply too")


if __name__ == "__main__":
    main()
