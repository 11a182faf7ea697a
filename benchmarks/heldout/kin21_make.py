"""Write session 21's check set of kinetics (benchmarks/heldout/kin21/*.toml): new parameter
draws within the ranges rounds 10-19 drew from, default identifier settings, the rounds' bars.
Written, and its study file too, before any rule of session 21 was run on it.  Run from the
repository root::

    python benchmarks/heldout/kin21_make.py

The draws are log-uniform (uniform for the influx fraction) from
``numpy.random.default_rng(2121)``, in the order written below; nothing was redrawn after a run.
``michaelis_menten_noise1``'s weak setup (as rounds 10-19): Km 0.01-20 mM, Vmax 0.5-40 mM/s, the
influx jx a fraction 0-0.95 of Vmax, x0 0.05-30 mM (a draw within 20 % of the steady state
jx Km / (Vmax - jx) is moved to 3 x it, the rig's refusal of a start at rest), records of
4-40 s at 200-5000 Hz; kin20_make.py's ranges and rule, another stream.  Noise levels 0 / 1 / 2 %
and seed 2101 are the study's (kin21_kinetics.toml).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
OUT = HERE / "kin21"
N_KINETICS = 12


def _log(rng: np.random.Generator, lo: float, hi: float) -> float:
    return float(math.exp(rng.uniform(math.log(lo), math.log(hi))))


def main() -> None:
    OUT.mkdir(exist_ok=True)
    rng = np.random.default_rng(2121)
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
        name = f"mmw_{i}"
        lines = [f"# Session 21's check set: {what}; michaelis_menten_noise1's setup", "",
                 "[scenario]", 'extends = "../../../scenarios/michaelis_menten_noise1.toml"',
                 f'name = "{name}"', f'description = "Session 21 check set: {what}"',
                 'tags = ["heldout", "kin21"]', "", "[rig]",
                 f"Km = {km:.4g}", f"Vmax = {vmax:.4g}", f"jx = {jx:.4g}", f"x0 = {x0:.4g}", "",
                 "[simulation]", f"duration = {dur:.4g}", f"sample_rate = {fs:.4g}", "",
                 "[score]", "state_rmse_max = 0.01         # mM (rounds 2-19's bar); the rig's own "
                 "equation bars apply too", ""]
        (OUT / f"{name}.toml").write_text("\n".join(lines))


if __name__ == "__main__":
    main()
