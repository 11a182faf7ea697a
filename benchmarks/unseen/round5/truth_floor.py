"""Round 5 (beams): independent checks of a scenario's truth, and what the truth itself scores.

Not a test: a diagnostic printing, per scenario file, measurements no identifier sees:

- ``EB``: the chain's first three undamped frequencies against Euler-Bernoulli's, solved here
  from the 4x4 boundary determinant (``w = A cos + B sin + C cosh + D sinh``; clamped, or a
  root hinge on the base's linear spring ``EI w'' = k1 w'``; free tip), independently of
  :mod:`models.cantilever.euler_bernoulli`;
- ``truth TRAC``: the SEREP truth (``Mr``, ``Cr``, ``Kr``, ``force_map``; linear only) scored
  by the shipped structural scorer on the scenario's own signal chain, as if it were the
  identified model: the TRAC no model with one degree of freedom per sensor can be expected
  to beat on that record (modes beyond the n-th ring in it after the impact);
- ``base angle`` (soft base): SEREP's base rotation against MuJoCo's own base joint angle and
  their cubes (``tests/identify/soft_cubic_floor.base_angle_error``), and the cubic moment's
  share of the linear one at the largest base rotation.

    PYTHONPATH=$PWD .venv/bin/python benchmarks/unseen/round5/truth_floor.py FILE.toml ...
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from testbed.core.truth import StructuralTruth
from testbed.pipeline import plugins
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure
from testbed.scoring.scorers import score_structural

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "tests" / "identify"))
from soft_cubic_floor import base_angle_error


def eb_determinant(bl: float, kappa: float) -> float:
    """Boundary determinant of a beam on a root spring, free at the tip (scaled by cosh^2).

    Parameters
    ----------
    bl : float
        ``beta L`` [-], ``beta^4 = mu omega^2 / (E I)``.
    kappa : float
        Root spring ``k1 L / (E I)`` [-]; ``inf`` for a clamp.
    """
    c, s, ch, sh = np.cos(bl), np.sin(bl), np.cosh(bl), np.sinh(bl)
    root = [0.0, 1.0, 0.0, 1.0] if np.isinf(kappa) else [-bl, -kappa, bl, -kappa]
    m = np.array([[1.0, 0.0, 1.0, 0.0], root, [-c, -s, ch, sh], [s, -c, sh, ch]])
    return float(np.linalg.det(m) / ch**2)


def eb_frequencies(E: float, I: float, mu: float, length: float, k1: float = np.inf,
                   n: int = 3) -> np.ndarray:
    """First ``n`` Euler-Bernoulli frequencies [Hz] (E [Pa], I [m^4], mu [kg/m], L [m], k1 [N m/rad])."""
    kappa = k1 * length / (E * I)
    grid = np.linspace(1e-3, 14.0, 28001)
    v = [eb_determinant(x, kappa) for x in grid]
    roots = [brentq(eb_determinant, grid[i], grid[i + 1], args=(kappa,))
             for i in range(len(grid) - 1) if v[i] * v[i + 1] < 0][:n]
    return np.array([r**2 / (2 * np.pi) * np.sqrt(E * I / (mu * length**4)) for r in roots])


def truth_as_model_trac(sc, ds) -> np.ndarray:
    """Per-channel TRAC of the linear SEREP truth scored as the identified model."""
    tr = ds.truth_as(StructuralTruth)
    data = measure(ds, sc.signal, sc.kind)
    model = plugins.make_identifier({"method": "ls_sindy"}, sc.name)
    model.fit(data)  # a fitted structural model object; its matrices are replaced by the truth's
    n = tr.Mr.shape[0]
    model.M_, model.C_, model.K_ = tr.Mr, tr.Cr, tr.Kr
    model.K3_, model.input_map_ = np.zeros((n, n)), np.asarray(tr.force_map, float).reshape(n, 1)
    return np.asarray(score_structural(ds, data, data, model).details["trac"])


def main(files: list[str]) -> None:
    cache = DatasetCache()
    for f in files:
        sc = load_scenario(f)
        ds = cache.get(sc)
        tr = ds.truth_as(StructuralTruth)
        r = sc.rig_params
        k1 = r["base_k1"] if r["base"] == "soft" else np.inf
        eb = eb_frequencies(r["E"], r["width"] * r["thickness"]**3 / 12,
                            r["rho"] * r["width"] * r["thickness"], r["length"], k1)
        dev = 100 * (np.asarray(tr.frequencies_hz[:3]) / eb - 1)
        line = f"{sc.name}: EB {np.round(eb, 2)} Hz, chain off {np.round(dev, 3)} %"
        if float(tr.k3) == 0.0:
            line += f" | truth TRAC {np.round(truth_as_model_trac(sc, ds), 4)}"
        else:
            x = np.asarray(ds.reference["displacement"].data)
            e_q, e_q3 = base_angle_error(sc, tr, x, int(ds.attrs["free_start"]) + 200)
            q_pk = float(np.max(np.abs(tr.cubic_map @ x)))
            line += (f" | base angle SEREP vs MuJoCo {e_q:.4f}, cube {e_q3:.4f}; cubic / linear "
                     f"moment at the peak {float(tr.k3) * q_pk**2 / r['base_k1']:.3f}")
        print(line, flush=True)


if __name__ == "__main__":
    main(sys.argv[1:])
