"""The cross-to-self ratio ``R`` from the record by a rank-one cubic ``b (a . x)^3`` (diagnosis).

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/soft21_ratio_rank_one.py STUDY.toml PREFIX \
        [NOISE] > out.tsv

A single cubic spring ``k3 c (c . x)^3`` (SEREP coordinates) gives mode 2 a first-order cross
shift by mode 1's amplitude ``R`` times mode 1's relative self shift, ``R = 2 (b_2 / b_1)^2
(w_1 / w_2)^2`` with ``b_k = c . phi_k`` on mass-normalised modes (``soft21_cross_ratio.py``).
In any scaling of the modes ``Phi`` (columns ``alpha_k phi_k``), the cubic's acceleration
direction ``beta = Mr^-1 c`` and its argument ``a = c`` (both up to scale) give
``(Phi^-1 beta)_k (a . Phi_k) = b_k^2`` up to one common factor, so
``R = 2 (w_1 / w_2)^2 [(Phi^-1 beta)_2 (a . Phi_2)] / [(Phi^-1 beta)_1 (a . Phi_1)]`` needs no
mass.  ``a`` and ``beta`` are fitted by variable projection
(:func:`identify._cubic_form.fit_rank_one`) jointly with a free linear part (``x, x'``, the
input and the chain's drift waveforms in every row, projected out), all columns through the
identifier's fit band (:func:`identify.structural.fit_band_cutoff`), on the record from the
free start; ``Phi``, ``w`` from ``ls_sindy``'s model.  Printed: the truth's ``R`` and the
estimate's ratio to it, and the angle [deg] of ``a`` from the truth's ``c``.
"""

from __future__ import annotations

import sys

import numpy as np
import scipy.linalg as sla

from identify._cubic_form import fit_rank_one
from identify.structural import fit_band_cutoff, modal, modal_peaks
from testbed.numerics.filters import elliptic_highpass
from testbed.pipeline import plugins
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.signal_chain import measure
from testbed.studies.study import load_study
from testbed.studies.sweep import expand


def ratio_rank_one(data, Phi: np.ndarray, w: np.ndarray, fc: float) -> tuple[float, np.ndarray]:
    """``R`` estimated from the record (module docstring) and the fitted direction ``a``."""
    s = int(data.free_start)
    x = np.asarray(data.x, float)
    lin = [x, np.asarray(data.xd, float)]
    if data.u is not None:
        lin.append(np.asarray(data.u, float))
    if getattr(data, "drift_basis", None) is not None:
        lin.append(np.asarray(data.drift_basis, float))
    L = np.vstack(lin)
    y = np.asarray(data.xdd, float)

    def tf(z):
        z = elliptic_highpass(np.atleast_2d(z), data.fs, fc, 5) if fc > 0 else np.atleast_2d(z)
        out = z[:, s:]
        return out[0] if np.ndim(z) and out.shape[0] == 1 and np.ndim(z) == 2 and z.shape[0] == 1 else out

    Lf, yf = tf(L), tf(y)
    Q = np.linalg.svd(Lf.T, full_matrices=False)[0]
    yq = yf - (yf @ Q) @ Q.T
    a, beta = fit_rank_one(x, yq, Q=Q, transform=lambda z: tf(z).ravel() if np.ndim(z) == 1 else tf(z))
    pb = np.linalg.solve(Phi, beta)
    pa = a @ Phi
    R = 2 * (w[0] / w[1]) ** 2 * (pb[1] * pa[1]) / (pb[0] * pa[0])
    return float(R), a


def main() -> None:
    study, prefix = sys.argv[1], sys.argv[2]
    noise = float(sys.argv[3]) if len(sys.argv) > 3 else 0.0
    cache = DatasetCache()
    print("member\tR_true\tR_est/R_true\tangle_a_deg")
    for cell in expand(load_study(study)):
        sc = cell.scenario
        if not sc.name.startswith(prefix) or cell.noise != noise or cell.identifier != "ls_sindy":
            continue
        ds = cache.get(sc)
        tr = ds.typed_truth
        data = measure(ds, sc.signal, sc.kind)
        lam, phi = sla.eigh(tr.Kr, tr.Mr)
        c = np.asarray(tr.cubic_map, float)
        b = c @ phi
        R = 2 * (b[1] / b[0]) ** 2 * lam[0] / lam[1]
        try:
            mod = plugins.make_identifier(sc.identify, sc.name).fit(data)
            fm, Phi = modal(mod.M_, mod.K_)
            fc = fit_band_cutoff(data, None, modal_peaks(data).peaks)[0]
            Re, a = ratio_rank_one(data, Phi, 2 * np.pi * fm, fc)
        except Exception as e:
            print(f"{sc.name}\t{R:.3f}\t{type(e).__name__}", flush=True)
            continue
        ang = np.degrees(np.arccos(min(1.0, abs(a @ c) / np.linalg.norm(c))))
        print(f"{sc.name}\t{R:.3f}\t{Re / R:.3f}\t{ang:.1f}", flush=True)


if __name__ == "__main__":
    main()
