"""Penalties vs least squares on cantilever scenarios over noise: the table of the knobs report.

Not a test (no ``test_`` prefix): a script that prints one markdown row per (scenario, noise,
identifier) with the scorer's TRAC, MAC, frequency error, damping error and cubic force error,
default hyperparameters throughout.  ``sgd_sindy eigen=false`` removes the eigenvalue penalty;
symmetry and the mass constraint are built into SGD-SINDy's matrix parametrisation and cannot
be removed, so ``ls_sindy`` (no mass coupling, no symmetry) is the comparison for them.

    PYTHONPATH=$PWD .venv/bin/python tests/identify/structural_penalties_table.py \
        scenarios/cantilever_stiff_impact_noise1.toml 0,1,3,5

Each noise level is written as a small scenario extending the given one into a temporary
folder; datasets go through the ordinary cache.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from testbed.pipeline import plugins
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.scenario import load_scenario
from testbed.scoring.run import run_scenario


def rows(base: Path, noises: list[float], folder: Path) -> list[str]:
    out = []
    for nz in noises:
        name = f"pen_{base.stem}_{nz:g}".replace(".", "p")
        path = folder / f"{name}.toml"
        path.write_text(f'[scenario]\nname = "{name}"\nextends = "{base.resolve()}"\n\n'
                        f'[noise]\nrms_percent = {nz}\n')
        sc = load_scenario(path)
        cubic = bool(sc.identify.get("cubic", False))
        variants = [("ls_sindy", {"method": "ls_sindy", "cubic": cubic}),
                    ("sgd_sindy", {"method": "sgd_sindy", "cubic": cubic}),
                    ("sgd_sindy eigen=false", {"method": "sgd_sindy", "cubic": cubic, "eigen": False})]
        if not cubic:
            variants.append(("sindy_pi_linear", {"method": "sindy_pi_linear"}))
        for label, ident in variants:
            r = run_scenario(sc, cache=DatasetCache(), model=plugins.make_identifier(ident, sc.name))
            v = r.scores.values
            fails = ",".join(sorted(r.scores.failures)) or "-"
            out.append(f"| {base.stem} | {nz:g} % | {label} | {v.get('trac', np.nan):.3f} | "
                       f"{v.get('mac', np.nan):.3f} | {100 * v.get('freq_error', np.nan):.2f} % | "
                       f"{v.get('damping_error', np.nan):.3f} | {v.get('K3_force_error', np.nan):.3f} | "
                       f"{fails} |")
            print(out[-1], flush=True)
    return out


if __name__ == "__main__":
    print("| scenario | noise | identifier | TRAC | MAC | freq. error | damping error "
          "| cubic force error | failures |")
    print("|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        rows(Path(sys.argv[1]), [float(v) for v in sys.argv[2].split(",")], Path(tmp))
