"""The truth's cross-to-self ratio of the soft base's cubic, member by member (diagnosis only).

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/soft21_cross_ratio.py STUDY.toml PREFIX

For a single cubic spring on the base rotation ``theta = c . x`` (SEREP: ``k3 c (c . x)^3`` in
the reduced coordinates, mass-normalised modes ``phi_k``, ``b_k = c . phi_k``) the first-order
shifts of mode 2 by mode 1's amplitude ``A_1`` (cross) and of mode 1 by its own (self) are
``d(w_2^2) = 3/2 k3 b_1^2 b_2^2 A_1^2`` and ``d(w_1^2) = 3/4 k3 b_1^4 A_1^2``, so
``(dw_2 / w_2) / (dw_1 / w_1) = 2 (b_2 / b_1)^2 (w_1 / w_2)^2 = 2 e_2 / e_1``, ``e_k`` the share of
mode ``k``'s strain energy in the base spring.  Printed per member: f1, f2, zeta1, zeta2 (truth),
that ratio, and how much of mode 1's squared amplitude is left when mode 2 has decayed to 1 %
(``100^(-2 sigma_1 / sigma_2)``): the span a fit of mode 2's frequency against mode 1's squared
envelope would extrapolate from.
"""

from __future__ import annotations

import sys

import numpy as np
import scipy.linalg as sla

from testbed.pipeline.cache import DatasetCache
from testbed.studies.study import load_study
from testbed.studies.sweep import expand


def main() -> None:
    study, prefix = sys.argv[1], sys.argv[2]
    cache = DatasetCache()
    seen = set()
    print("member\tf1\tf2\tzeta1\tzeta2\tf2/f1\tcross/self\tA1^2_left")
    for cell in expand(load_study(study)):
        sc = cell.scenario
        if not sc.name.startswith(prefix) or sc.name in seen:
            continue
        seen.add(sc.name)
        tr = cache.get(sc).typed_truth
        lam, phi = sla.eigh(tr.Kr, tr.Mr)
        b = np.asarray(tr.cubic_map, float) @ phi
        f = np.sqrt(lam) / (2 * np.pi)
        z = np.asarray(tr.damping_ratios, float)
        ratio = 2 * (b[1] / b[0]) ** 2 * lam[0] / lam[1]
        left = 100.0 ** (-2 * z[0] * f[0] / (z[1] * f[1]))
        print(f"{sc.name}\t{f[0]:.2f}\t{f[1]:.2f}\t{z[0]:.4f}\t{z[1]:.4f}\t{f[1] / f[0]:.3f}"
              f"\t{ratio:.3f}\t{left:.3f}", flush=True)


if __name__ == "__main__":
    main()
