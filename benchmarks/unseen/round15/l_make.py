"""Write the round-15 linkage and small-rig scenarios (benchmarks/unseen/round15/{fb,cp,mm}15_*.toml):
rigs nobody tuned, default identifier settings, the earlier rounds' bars.  Run from the repository
root:

    python benchmarks/unseen/round15/l_make.py

Five-bars whose actuated links (the cranks l1 and l4) differ, under the paper's sine
(``fivebar_sine_replay_noise1``) with records of 2-20 s (a third of the sine's 6.3 s period to
three periods); the transmission on the sine path is printed (the rig admits 30-150 deg).
Cart-poles with a heavy pole (3 kg on the 1 kg cart) or a long one (2 m), driven at the cart by
round 14's chirp (0.05-4 Hz) and held steps (0.5 s), ``cartpole_noise1``'s chain, written in full
by round 14's writer.  Kinetics at corners of Km and Vmax rounds 3-14 did not draw (Km 0.02 and
20 mM, Vmax 0.62-40 mM/s against the 0.6 mM/s influx).  Noise levels and seeds 61-64 are the
studies' (round15_linkages_*.toml).
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))  # benchmarks/unseen: rounds 12 and 14's linkage writers
from round12 import l_make as _ROUND12  # noqa: E402
from round14 import l_make as _ROUND14  # noqa: E402

#: name -> (description, {table: keys changed from the paper's sine scenario})
FIVEBARS: dict[str, tuple[str, dict[str, dict]]] = {
    "fb15_cranks_0p7_1p3": (
        "cranks of 0.7 m (left) and 1.3 m (right), 1 m couplers and base",
        {"rig": {"l1": 0.7, "l4": 1.3}},
    ),
    "fb15_cranks_1p3_0p7_20s": (
        "cranks of 1.3 m (left) and 0.7 m (right), 20 s",
        {"rig": {"l1": 1.3, "l4": 0.7}, "simulation": {"duration": 20.0}},
    ),
    "fb15_cranks_0p5_1_2s": (
        "cranks of 0.5 m (left) and 1 m (right), 2 s",
        {"rig": {"l1": 0.5, "l4": 1.0}, "simulation": {"duration": 2.0}},
    ),
    "fb15_cranks_1p6_1_5s": (
        "cranks of 1.6 m (left) and 1 m (right), 5 s",
        {"rig": {"l1": 1.6, "l4": 1.0}, "simulation": {"duration": 5.0}},
    ),
    "fb15_cranks_0p8_1p5_3s": (
        "cranks of 0.8 m (left) and 1.5 m (right), 1.2 m couplers, 3 s",
        {"rig": {"l1": 0.8, "l4": 1.5, "l2": 1.2, "l3": 1.2}, "simulation": {"duration": 3.0}},
    ),
}

_CHIRP = {"type": "chirp", "amplitude": 2.0, "kp": 5.0, "kd": 2.0, "f0": 0.05, "f1": 4.0}
_STEPS = {"type": "steps", "amplitude": 2.0, "level_seed": 0, "kp": 5.0, "kd": 2.0, "hold": 0.5}
_HEAVY, _LONG = {"pole_mass": 3.0}, {"pole_length": 2.0}
#: name -> (description, {"rig": keys changed, "excitation": the input replacing the multisine})
CARTPOLES: dict[str, tuple[str, dict[str, dict]]] = {
    "cp15_heavy_chirp": (
        "a 3 kg pole on the 1 kg cart, a 2 N chirp 0.05-4 Hz over 10 s",
        {"rig": _HEAVY, "excitation": _CHIRP},
    ),
    "cp15_long_chirp": (
        "a 2 m pole (0.44 Hz), a 2 N chirp 0.05-4 Hz over 10 s",
        {"rig": _LONG, "excitation": _CHIRP},
    ),
    "cp15_heavy_steps": (
        "a 3 kg pole on the 1 kg cart, 2 N steps held 0.5 s",
        {"rig": _HEAVY, "excitation": _STEPS},
    ),
    "cp15_heavy_long_steps": (
        "a 3 kg, 2 m pole on the 1 kg cart, 2 N steps held 0.5 s",
        {"rig": {**_HEAVY, **_LONG}, "excitation": _STEPS},
    ),
}

#: name -> (description, {table: keys changed from michaelis_menten_noise1}); influx 0.6 mM/s
KINETICS: dict[str, tuple[str, dict[str, dict]]] = {
    "mm15_km0p02_vmax3": (
        "Km 0.02 mM, Vmax 3 mM/s (x* 5e-3 mM: zero-order until the dose is gone)",
        {"rig": {"Km": 0.02, "Vmax": 3.0}},
    ),
    "mm15_km20_vmax40": (
        "Km 20 mM, Vmax 40 mM/s (x* 0.30 mM: first-order, x / Km under 0.1)",
        {"rig": {"Km": 20.0, "Vmax": 40.0}},
    ),
    "mm15_km0p5_vmax0p62_10s": (
        "Km 0.5 mM, Vmax 0.62 mM/s (x* 15 mM: saturated, a slow rise), 10 s",
        {"rig": {"Km": 0.5, "Vmax": 0.62}, "simulation": {"duration": 10.0}},
    ),
    "mm15_km3_vmax2": (
        "Km 3 mM, Vmax 2 mM/s (x* 1.29 mM, near Km over the record)",
        {"rig": {"Km": 3.0, "Vmax": 2.0}},
    ),
}


_write = _ROUND12.writer_for(HERE, 15)


def main() -> None:
    _ROUND12.write_sets(_write, FIVEBARS, {}, KINETICS, "2-14")
    write_cartpoles(HERE, 15, CARTPOLES, ("rig",))


def write_cartpoles(here: Path, number: int, cartpoles: dict, written: tuple[str, ...]) -> None:
    """Write each cart-pole ``name: (description, tables)`` into ``here`` by round 14's writer,
    with round ``number``'s header and tag, the keys of the ``written`` tables set in full."""
    for name, (desc, tables) in cartpoles.items():
        _ROUND14.HERE = here  # round 14's writer writes into its module's HERE
        _ROUND14._write_cartpole(name, desc, tables["excitation"])
        path = here / f"{name}.toml"
        text = path.read_text().replace("round 14", f"round {number}")
        text = text.replace('"round14"', f'"round{number}"')
        text = text.replace("round14/l_make.py", f"round{number}/l_make.py")
        for key, value in {k: v for t in written for k, v in tables[t].items()}.items():
            text, n = _re_sub(key, value, text)
            assert n == 1, (name, key)
        path.write_text(text)


def _re_sub(key: str, value: float, text: str) -> tuple[str, int]:
    """Set ``key = value`` in the written ``[rig]`` table (one line)."""
    import re

    return re.subn(rf"(?m)^{key} = .*$", f"{key} = {value!r}", text)


if __name__ == "__main__":
    main()
