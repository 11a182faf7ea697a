"""Linear dependence among library columns, read off their Gram matrix.

Shared by SINDy-PI's pruning of dependent columns (identify/sindy_pi.py) and the scoring's
canonical basis modulo kinematic identities (testbed/scoring/equation_basis.py).
"""

from __future__ import annotations

import numpy as np


def normalized_gram(G: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(Gn, s)``: the Gram matrix of unit-norm columns, ``Gn = G / outer(s, s)``, and the
    column norms ``s = sqrt(diag(G))`` (floored at 1e-150 so a zero column divides safely)."""
    s = np.sqrt(np.clip(np.diag(G), 1e-300, None))
    return G / np.outer(s, s), s


def ordered_independent(Gn: np.ndarray, candidates: np.ndarray,
                        tol: float) -> tuple[list[int], list[int], list[float]]:
    """Ordered pivoted Cholesky: which candidate columns are independent of the earlier kept ones.

    Parameters
    ----------
    Gn : ndarray, shape (p, p)
        Gram matrix of unit-norm columns (:func:`normalized_gram`).
    candidates : ndarray of int
        Columns to examine, in priority order.
    tol : float
        A column whose residual variance after projection on the kept earlier ones is at most
        ``tol`` is dependent.

    Returns
    -------
    kept, dependent : list of int
    residual : list of float
        Residual variance of each dependent column (clipped at 0).
    """
    kept: list[int] = []
    dep: list[int] = []
    res: list[float] = []
    L = np.zeros((0, 0))
    for c in candidates:
        g = Gn[kept, c]
        y = np.linalg.solve(L, g) if kept else g
        r = Gn[c, c] - y @ y
        if r > tol:
            kept.append(int(c))
            L = np.block([[L, np.zeros((L.shape[0], 1))], [y[None, :], np.array([[np.sqrt(r)]])]])
        else:
            dep.append(int(c))
            res.append(max(float(r), 0.0))
    return kept, dep, res
