"""The cross ratio ``R`` from three cubic coefficients of the modal equations (diagnosis).

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/soft21_ratio_modal.py STUDY.toml PREFIX \
        [NOISE] > out.tsv

In any scaling of the modes (``Phi`` columns ``alpha_k phi_k``) a single cubic spring's modal
equations carry ``s_1 q_1^3`` and ``h q_1^2 q_2`` in mode 1's and ``g q_1^3`` in mode 2's, with
``s_1 = k3 b_1^4 alpha_1^2``, ``h = 3 k3 b_1^3 b_2 alpha_1 alpha_2``, ``g = k3 b_1^3 b_2
alpha_1^3 / alpha_2``, so ``h g / s_1^2 = 3 (b_2 / b_1)^2`` whatever the scaling, and
``R = 2 (b_2/b_1)^2 (w_1/w_2)^2 = 2/3 h g / s_1^2 (w_1/w_2)^2``.  Each coefficient is regressed
over the whole record from the free start (mode ``k``'s row on ``q_1, q_1', q_2, q_2'``, the
cubic columns and the chain's drift waveforms, all through the identifier's fit band), with
the truth's modes (the regression's best case) and with ``ls_sindy``'s.  Printed: the truth's
``R`` and each estimate's ratio to it.
"""

from __future__ import annotations

import sys

import numpy as np
import scipy.linalg as sla

from identify.structural import fit_band_cutoff, modal, modal_peaks
from testbed.numerics.filters import elliptic_highpass
from testbed.pipeline import plugins
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.signal_chain import measure
from testbed.studies.study import load_study
from testbed.studies.sweep import expand


def ratio_modal(data, Phi: np.ndarray, w: np.ndarray, fc: float) -> float:
    """``R`` from ``h g / s_1^2`` (module docstring)."""
    s = int(data.free_start)
    q = np.linalg.solve(Phi, np.asarray(data.x, float))
    qd = np.linalg.solve(Phi, np.asarray(data.xd, float))
    qdd = np.linalg.solve(Phi, np.asarray(data.xdd, float))
    drift = [] if getattr(data, "drift_basis", None) is None else list(np.asarray(data.drift_basis, float))
    q1, q2 = q[0], q[1]
    cols = [q1, qd[0], q2, qd[1], q1 ** 3, q1 * q1 * q2, *drift]
    coef = []
    for k in (0, 1):
        A = np.vstack([*cols, qdd[k]])
        if fc > 0:
            A = elliptic_highpass(A, data.fs, fc, 5)
        A = A[:, s:]
        X, y = A[:-1].T, A[-1]
        sc = np.linalg.norm(X, axis=0)
        sc[sc == 0] = 1.0
        coef.append(np.linalg.lstsq(X / sc, -y, rcond=None)[0] / sc)
    s1, h, g = coef[0][4], coef[0][5], coef[1][4]
    return float(2.0 / 3.0 * h * g / s1 ** 2 * (w[0] / w[1]) ** 2)


def main() -> None:
    study, prefix = sys.argv[1], sys.argv[2]
    noise = float(sys.argv[3]) if len(sys.argv) > 3 else 0.0
    cache = DatasetCache()
    print("member\tR_true\ttruth_modes\tmodel_modes")
    for cell in expand(load_study(study)):
        sc = cell.scenario
        if not sc.name.startswith(prefix) or cell.noise != noise or cell.identifier != "ls_sindy":
            continue
        ds = cache.get(sc)
        tr = ds.typed_truth
        data = measure(ds, sc.signal, sc.kind)
        lam, phi = sla.eigh(tr.Kr, tr.Mr)
        b = np.asarray(tr.cubic_map, float) @ phi
        R = 2 * (b[1] / b[0]) ** 2 * lam[0] / lam[1]
        fc = fit_band_cutoff(data, None, modal_peaks(data).peaks)[0]
        rt = ratio_modal(data, phi, np.sqrt(lam), fc)
        try:
            mod = plugins.make_identifier(sc.identify, sc.name).fit(data)
            fm, Phi = modal(mod.M_, mod.K_)
            rm = ratio_modal(data, Phi, 2 * np.pi * fm, fc)
        except Exception:  # a refused fit or singular modes: no model estimate
            rm = float("nan")
        print(f"{sc.name}\t{R:.3f}\t{rt / R:.3f}\t{rm / R:.3f}", flush=True)


if __name__ == "__main__":
    main()
