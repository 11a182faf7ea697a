"""What mode 2's decay fit gives with the cross term held at the truth's ratio (diagnosis only).

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/soft21_cross_hold.py STUDY.toml PREFIX \
        [NOISE] > out.tsv

An upper bound, not a rule: it uses the truth's cross-to-self ratio ``R = 2 (b_2 / b_1)^2
(w_1 / w_2)^2`` (:mod:`soft21_cross_ratio`), which no identifier sees.  On the record (the
``ls_sindy`` model's modes ``Phi``, ``q'' = Phi^-1 x''`` from the free start): mode 1's backbone
decay (``sigma_1, wd_1, c_1``, :func:`identify._modal_damping._decay_fit`); mode 2's decay
over its life (to 1e-3 of its envelope), its instantaneous frequency
``wd_2 + c_2 exp(-2 sigma_2 t) + R (w_2 / w_1) c_1 exp(-2 sigma_1 t)``, the last term held (a
single cubic spring's first-order cross shift), ``sigma_2, wd_2, c_2`` fitted with the
amplitudes and the chain's transients profiled out.  Printed: signed errors [%] of the model's
f2, of mode 2's exponential and backbone fits, and of the held fit, against the truth's f2.
"""

from __future__ import annotations

import sys

import numpy as np
import scipy.linalg as sla
from scipy import optimize

from identify._modal_damping import _decay_fit, chain_transients
from identify.structural import modal
from testbed.pipeline import plugins
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.signal_chain import measure
from testbed.studies.study import load_study
from testbed.studies.sweep import expand


def held_fit(q: np.ndarray, t: np.ndarray, w: float, sigma0: float, extra: np.ndarray,
             nuisance: np.ndarray | None) -> tuple[float, float]:
    """``exp(-sigma t) (a cos ph + b sin ph)``, ``ph = wd t + c g(sigma, t) + extra``, least
    squares over ``(sigma, wd, c)`` with ``a, b`` and the nuisance amounts profiled out;
    returns ``(sigma, wd)`` [1/s, rad/s]."""
    U = None
    if nuisance is not None:
        U = np.linalg.svd(nuisance, full_matrices=False)[0]
        q = q - U @ (U.T @ q)

    def res(p):
        s, wd, c = p
        g = -np.expm1(-2 * max(s, 1e-12) * t) / (2 * max(s, 1e-12))
        ph = wd * t + c * g + extra
        E = np.exp(-s * t)
        A = np.column_stack([E * np.cos(ph), E * np.sin(ph)])
        if U is not None:
            A = A - U @ (U.T @ A)
        x = np.linalg.lstsq(A, q, rcond=None)[0]
        return A @ x - q

    s0 = min(max(sigma0, 1e-3 * w), 0.3 * w)
    best = min((optimize.least_squares(res, [s0, w, c0], x_scale=[1e-2 * w, 1e-3 * w, 1e-3 * w],
                                       bounds=([0, 0.5 * w, -0.5 * w], [0.7 * w, 1.5 * w, 0.5 * w]))
                for c0 in (0.0, 0.02 * w)), key=lambda r: r.cost)
    return float(best.x[0]), float(best.x[1])


def main() -> None:
    study, prefix = sys.argv[1], sys.argv[2]
    noise = float(sys.argv[3]) if len(sys.argv) > 3 else 0.0
    cache = DatasetCache()
    print("member\tzeta2\tR\tmodel\texp\tbackbone\theld\tc1/wd1")
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
        f2 = float(np.sqrt(lam[1]) / (2 * np.pi))
        z2 = float(np.asarray(tr.damping_ratios)[1])
        try:
            mod = plugins.make_identifier(sc.identify, sc.name).fit(data)
            fm, Phi = modal(mod.M_, mod.K_)
            s = int(data.free_start)
            qdd = np.linalg.solve(Phi, np.asarray(data.xdd, float)[:, s:])
        except Exception as e:
            print(f"{sc.name}\t{z2:.3f}\t{R:.3f}\t{type(e).__name__}", flush=True)
            continue
        t = np.arange(qdd.shape[1]) / data.fs
        nu = chain_transients(getattr(data, "chain_poles", None), t)
        d = np.einsum("ik,ij,jk->k", Phi, mod.C_, Phi)
        w = 2 * np.pi * fm
        s1, wd1, _, _ok1, c1, _ = _decay_fit(qdd[0], t, 0.5 * d[0], w[0], True, nu)
        se, wde, *_ = _decay_fit(qdd[1], t, 0.5 * d[1], w[1], False, nu)
        n2 = int(min(t.size, np.log(1e3) / max(se, 1e-9) * data.fs))
        t2, nu2 = t[:n2], (None if nu is None else nu[:n2])
        sb, wdb, *_ = _decay_fit(qdd[1, :n2], t2, se, w[1], True, nu2)
        extra = R * (w[1] / wd1) * c1 * (-np.expm1(-2 * s1 * t2)) / (2 * s1)
        sh, wdh = held_fit(qdd[1, :n2], t2, w[1], se, extra, nu2)

        def err(sig, wd, f2=f2):
            return 100 * (np.hypot(sig, wd) / (2 * np.pi) / f2 - 1)

        print(f"{sc.name}\t{z2:.3f}\t{R:.3f}\t{100 * (fm[1] / f2 - 1):+.2f}\t{err(se, wde):+.2f}"
              f"\t{err(sb, wdb):+.2f}\t{err(sh, wdh):+.2f}\t{c1 / wd1:+.4f}", flush=True)


if __name__ == "__main__":
    main()
