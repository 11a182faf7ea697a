"""Write the session-20 check set of kinetics and cart-poles (benchmarks/heldout/kin20/*.toml):
new parameter draws within the ranges rounds 10-18 drew from, default identifier settings, the
rounds' bars.  Run from the repository root:

    python benchmarks/heldout/kin20_make.py

The draws are log-uniform (uniform for fractions) from ``numpy.random.default_rng(2020)``, in
the order written below; nothing was redrawn after a run.  Kinetics (``michaelis_menten_noise1``'s
weak setup, as rounds 10-18): Km 0.01-20 mM, Vmax 0.5-40 mM/s, the influx jx a fraction 0-0.95
of Vmax, x0 0.05-30 mM (a draw within 20 % of the steady state jx Km / (Vmax - jx) is moved to
3 x it, the rig's refusal of a start at rest), records of 4-40 s at 200-5000 Hz.  Cart-poles
(``cartpole_noise1``'s multisine and chain): cart 0.5-5 kg, pole 0.05-3 kg, pole length 0.3-3 m,
rail damping 0.01-5 N s/m, records of 3-30 s.  Noise levels 0 / 1 / 2 % and seeds 2001 / 2002 are
the studies' (kinetics_validation.toml, cartpole_validation.toml).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
OUT = HERE / "kin20"
N_KINETICS, N_CARTPOLES = 8, 6


def _log(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def _write(name: str, base: str, what: str, tables: dict[str, dict[str, float]], bar: str) -> None:
    lines = [f"# Session 20's check set: {what}; {base}'s setup", "", "[scenario]",
             f'extends = "../../../scenarios/{base}.toml"', f'name = "{name}"',
             f'description = "Session 20 check set: {what}"', 'tags = ["heldout", "kin20"]', ""]
    for table, keys in tables.items():
        lines.append(f"[{table}]")
        lines += [f"{k} = {v:.4g}" for k, v in keys.items()]
        lines.append("")
    lines += ["[score]", bar, ""]
    (OUT / f"{name}.toml").write_text("\n".join(lines))


def main() -> None:
    OUT.mkdir(exist_ok=True)
    rng = np.random.default_rng(2020)
    for i in range(N_KINETICS):
        km, vmax = _log(rng, 0.01, 20.0), _log(rng, 0.5, 40.0)
        jx = vmax * rng.uniform(0.0, 0.95)
        x0 = _log(rng, 0.05, 30.0)
        steady = jx * km / (vmax - jx)
        if abs(x0 - steady) <= 0.2 * steady:
            x0 = 3.0 * steady
        dur, fs = _log(rng, 4.0, 40.0), _log(rng, 200.0, 5000.0)
        what = (f"Km {km:.3g} mM, Vmax {vmax:.3g} mM/s, jx {jx:.3g} mM/s (x* {steady:.3g} mM), "
                f"x0 {x0:.3g} mM, {dur:.3g} s at {fs:.4g} Hz")
        _write(f"mmv_{i}", "michaelis_menten_noise1", what,
               {"rig": {"Km": km, "Vmax": vmax, "jx": jx, "x0": x0},
                "simulation": {"duration": dur, "sample_rate": fs}},
               "state_rmse_max = 0.01         # mM (rounds 2-18's bar); the rig's own equation "
               "bars apply too")
    for i in range(N_CARTPOLES):
        cart, pole = _log(rng, 0.5, 5.0), _log(rng, 0.05, 3.0)
        length, rail, dur = _log(rng, 0.3, 3.0), _log(rng, 0.01, 5.0), _log(rng, 3.0, 30.0)
        what = (f"a {cart:.3g} kg cart, a {pole:.3g} kg, {length:.3g} m pole, rail {rail:.3g} N s/m, "
                f"{dur:.3g} s")
        _write(f"cpv_{i}", "cartpole_noise1", what,
               {"rig": {"cart_mass": cart, "pole_mass": pole, "pole_length": length,
                        "cart_damping": rail}, "simulation": {"duration": dur}},
               "angle_rmse_max = 0.0501       # the paper's figure (rounds 2-18's bar for unseen "
               "cart-poles)")


if __name__ == "__main__":
    main()
