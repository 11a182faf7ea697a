"""Mode 1 of every soft member's cubic model against its backbone decay fit, with the truth.

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/soft_mode1_table.py STUDY.toml PREFIX [NOISE]

One row per member and identifier: the signed mode-1 error of the default fit, of the same fit
without the decay hold, of the backbone decay fit's ``wd``; ``exp(-2 sigma T)`` of that fit
(how much of the decay the window reads), ``c / wd``, and whether the model's cubic gives at
least half the measured chirp.  Diagnosis only (it reads the truth).
"""

from __future__ import annotations

import sys

import numpy as np

from identify._modal_damping import BACKBONE_SHARE, backbone_shift
from identify._sgd_matrix import fit_window
from identify.ls_sindy import LeastSquaresSINDy
from identify.sgd_sindy import SGDSINDy
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.signal_chain import measure
from testbed.studies.study import load_study
from testbed.studies.sweep import expand


def err(f: np.ndarray, ft: float) -> float:
    f = np.asarray(f, dtype=float)
    return float(100 * (f[np.argmin(np.abs(f - ft))] / ft - 1))


def main() -> None:
    study, prefix = sys.argv[1], sys.argv[2]
    noise = float(sys.argv[3]) if len(sys.argv) > 3 else 0.0
    cache = DatasetCache()
    print("member ident cubic | f1 default | no-hold | decay wd | exp(-2sT) | c/wd | explained")
    for cell in expand(load_study(study)):
        sc = cell.scenario
        if not sc.name.startswith(prefix) or cell.noise != noise or cell.identifier != "ls_sindy":
            continue
        ds = cache.get(sc)
        data = measure(ds, sc.signal, sc.kind)
        ft = np.asarray(ds.typed_truth.frequencies_hz)
        i0, i1 = fit_window(data, 0.0)
        T = (i1 - i0) / float(data.fs)
        for cls in (LeastSquaresSINDy, SGDSINDy):
            try:
                m = cls().fit(data)
                m0 = cls(decay_hold=False).fit(data)
            except Exception as e:
                print(sc.name, cls.name, "error", e)
                continue
            dec = getattr(m, "modal_decay_", None)
            if m.K3_ is None or dec is None or dec.chirp is None:
                print(f"{sc.name} {cls.name[:3]} lin   | {err(m.natural_frequencies_, ft[0]):+6.2f}")
                continue
            if not np.any(np.isfinite(dec.omega_d)):
                continue
            k = int(np.nanargmin(np.abs(dec.omega_d / 2 / np.pi - ft[0])))
            wd = dec.omega_d[k] / 2 / np.pi
            x_end = np.exp(-2 * dec.sigma[k] * T)
            expl = backbone_shift(m0.M_, m0.K_, m0.K3_, dec)[k] >= BACKBONE_SHARE * dec.chirp[k] \
                if m0.K3_ is not None else False
            print(f"{sc.name} {cls.name[:3]} cubic | {err(m.natural_frequencies_, ft[0]):+6.2f} |"
                  f" {err(m0.natural_frequencies_, ft[0]):+6.2f} | {100 * (wd / ft[0] - 1):+6.2f} |"
                  f" {x_end:5.2f} | {dec.chirp[k] / dec.omega_d[k]:+.4f} | {expl} taken {dec.taken[k]}",
                  flush=True)


if __name__ == "__main__":
    main()
