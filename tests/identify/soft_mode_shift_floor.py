"""What frequencies does a soft base's impact record hold for modes 1-2?  Per family member.

Not a test (no ``test_`` prefix): a diagnosis script for issue #15's frequency bar on the
soft-base family (modes 1-2 within 1 % of the truth's ``frequencies_hz``, the linear ones about
rest).  A hardening base (moment ``k1 q + k3 q^3``) stiffens the beam while it swings, so the
record of one hammer blow shows each mode above its linear frequency while it is large.  This
script measures how far, from the engine alone (nothing an identifier sees):

- each member is simulated twice, as written and as its *linear twin* (``base_k3 = 0``, all
  else equal, so the same linear truth);
- the exact sensor displacements (the datasets' reference, no signal chain) are taken into the
  truth's sensor modal coordinates (``sensor_modes``) from the record's free start;
- mode 2 is fitted there with one damped sinusoid (plus a line for leakage) over its own life,
  ``ln(100) / (zeta_2 w_2)`` (its envelope falls to 1 %), and mode 1 over the first 0.1 s;
- ``hard`` is the member's fitted frequency over its twin's, minus 1 [%]: the hardening the
  record holds at that amplitude, the fits' own bias (damping, window) cancelled by the twin.

Mode 1 decays over the 0.5 s record toward rest, so its linear frequency is in the record (the
identifiers' backbone decay fit reaches it); mode 2 (4-32 % damped) dies within 7-100 ms, while
mode 1 still swings near its starting amplitude, so the record shows mode 2 only stiffened by
mode 1's amplitude, and its linear frequency only through a model whose cubic carries that
cross term.

    PYTHONPATH=$PWD .venv/bin/python tests/identify/soft_mode_shift_floor.py DIR [0,8]

``DIR`` holds the members written by ``testbed family write studies/families.toml -o DIR``;
datasets (the twins too) go through the ordinary cache.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares

from testbed.core.truth import StructuralTruth
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.scenario import load_scenario


def modal_coordinates(sc, cache: DatasetCache) -> tuple[np.ndarray, float, StructuralTruth]:
    """The exact modal coordinates ``q`` (m, n) from the free start, the sample rate [Hz] and
    the truth."""
    ds = cache.get(sc)
    tr = ds.truth_as(StructuralTruth)
    x = np.asarray(ds.reference["displacement"].data, float)
    start = int(ds.attrs["free_start"])
    q = np.linalg.lstsq(np.asarray(tr.sensor_modes, float), x[:, start:], rcond=None)[0]
    return q, float(ds.fs), tr


def damped_frequency(y: np.ndarray, fs: float, f0: float, zeta0: float) -> float:
    """Undamped frequency [Hz] of one damped sinusoid (plus an offset and a slope) fitted to
    ``y`` by least squares from ``f0`` [Hz], ``zeta0``."""
    t = np.arange(y.size) / fs
    scale = float(np.max(np.abs(y)))

    def resid(p: np.ndarray) -> np.ndarray:
        a, b, f, z, c0, c1 = p
        w = 2 * np.pi * f
        wd = w * np.sqrt(max(1 - z * z, 1e-9))
        return (np.exp(-z * w * t) * (a * np.cos(wd * t) + b * np.sin(wd * t)) + c0 + c1 * t - y) / scale

    inf = np.inf  # the frequency within +-50 % of the truth's, the damping below critical
    bounds = ([-inf, -inf, 0.5 * f0, 0.0, -inf, -inf], [inf, inf, 1.5 * f0, 0.99, inf, inf])
    return float(least_squares(resid, [y[0], 0.0, f0, zeta0, 0.0, 0.0], bounds=bounds,
                               x_scale="jac").x[2])


def hardening(path: Path, cache: DatasetCache) -> dict:
    """The member's mode-1 and mode-2 frequencies over its linear twin's (fractions)."""
    sc = load_scenario(path)
    twin = sc.replace(name=sc.name + "_linear_twin", rig_params={**sc.rig_params, "base_k3": 0.0})
    out = {"name": sc.name}
    fits = []
    for s in (sc, twin):
        q, fs, tr = modal_coordinates(s, cache)
        f, z = np.asarray(tr.frequencies_hz, float), np.asarray(tr.damping_ratios, float)
        n2 = int(np.log(100.0) / (z[1] * 2 * np.pi * f[1]) * fs)
        n1 = int(0.1 * fs)
        fits.append((damped_frequency(q[0, :n1], fs, f[0], z[0]),
                     damped_frequency(q[1, :n2], fs, f[1], z[1])))
        out.update(f_true=f[:2], zeta=z[:2], life2_ms=1e3 * n2 / fs)
    out["hard1"] = fits[0][0] / fits[1][0] - 1.0
    out["hard2"] = fits[0][1] / fits[1][1] - 1.0
    return out


def main(argv: list[str]) -> None:
    d = Path(argv[1])
    idx = [int(s) for s in argv[2].split(",")] if len(argv) > 2 else range(20)
    cache = DatasetCache()
    print("member  f1 [Hz]  f2 [Hz]  zeta2   mode 2 life [ms]   hard1 (0.1 s) %   hard2 (life) %")
    for i in idx:
        r = hardening(d / f"beams_soft__{i:03d}.toml", cache)
        print(f"{r['name'][-3:]}   {r['f_true'][0]:7.2f} {r['f_true'][1]:8.2f}  {r['zeta'][1]:.3f}"
              f"   {r['life2_ms']:8.1f}          {100 * r['hard1']:+6.2f}            "
              f"{100 * r['hard2']:+6.2f}", flush=True)


if __name__ == "__main__":
    main(sys.argv)
