"""Penalty terms of SGD-SINDy and their exact gradients (Eqs 7-15 of the paper), plus Adam.

Everything here works on the regression coefficients in SI units, split into blocks
``xa`` (acceleration, zero diagonal), ``xv`` (velocity), ``xd`` (displacement), each (n, n),
and the diagonal masses ``m`` (n,) [kg]:

    M = diag(m) (I - xa),  C = -diag(m) xv,  K = -diag(m) xd.
"""

from __future__ import annotations

import numpy as np


def symmetry_penalty(xa: np.ndarray, xv: np.ndarray, xd: np.ndarray, m: np.ndarray, which: str = "MCK"
                     ) -> tuple[float, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Eq. 7 as a loss: ``S = sum_A ||A - A^T||_F^2 / ||A||_F^2`` over ``A`` in M, C, K.

    Parameters
    ----------
    xa, xv, xd : ndarray, shape (n, n)
        Coefficient blocks (SI units).
    m : ndarray, shape (n,)
        Diagonal masses [kg].
    which : str
        Letters of the matrices penalised (subset of ``"MCK"``).

    Returns
    -------
    S : float
        Dimensionless and invariant to the scale of each matrix.
    dS_dxa, dS_dxv, dS_dxd : ndarray, shape (n, n)
        Exact gradients (the diagonal of ``dS_dxa`` is zeroed: it is not a parameter).
    dS_dlogm : ndarray, shape (n,)
        Gradient with respect to ``log m``.
    """
    n = m.shape[0]
    eye = np.eye(n)
    total = 0.0
    grads = {}
    dlogm = np.zeros(n)
    for key, xt in (("M", eye - xa), ("C", -xv), ("K", -xd)):
        if key not in which:
            grads[key] = np.zeros((n, n))
            continue
        A = m[:, None] * xt
        nA2 = float(np.sum(A * A))
        if nA2 <= 0.0:
            grads[key] = np.zeros((n, n))
            continue
        D = A - A.T
        nD2 = float(np.sum(D * D))
        total += nD2 / nA2
        G = 4.0 * D / nA2 - 2.0 * nD2 * A / nA2**2  # dS_A / dA
        grads[key] = -(m[:, None] * G)  # dA/dx = -diag(m) for every block
        dlogm += m * np.sum(G * xt, axis=1)
    ga = grads["M"]
    np.fill_diagonal(ga, 0.0)
    return total, ga, grads["C"], grads["K"], dlogm


def eigen_penalty(xa: np.ndarray, xd: np.ndarray, lam_hat: np.ndarray
                  ) -> tuple[float, np.ndarray, np.ndarray, np.ndarray]:
    """Eigenvalue penalty (Eqs 8-13) with the exact first-order sensitivity.

    The undamped eigenvalues of the identified model are those of ``K u = lambda M u``; they
    do not depend on the masses ``m`` (row scaling), so they are computed from
    ``Kn = -xd``, ``Mn = I - xa``.  With right and left eigenvectors ``u``, ``v`` of the pencil
    (``v^T Mn u = 1``) the exact sensitivity is ``d lambda = v^T (dKn - lambda dMn) u`` (the
    non-symmetric form of ``u^T (dK - lambda dM) u``), so
    ``d lambda / d xd[i, j] = -v_i u_j`` and ``d lambda / d xa[i, j] = lambda v_i u_j``.

    Parameters
    ----------
    xa, xd : ndarray, shape (n, n)
        Acceleration and displacement coefficient blocks.
    lam_hat : ndarray, shape (k,)
        Measured eigenvalues ``(2 pi f)^2`` [rad^2/s^2], k <= n.

    Returns
    -------
    E : float
        ``mean_k ((Re lambda_p(k) - lam_hat_k) / lam_hat_k)^2``, the identified eigenvalue
        ``p(k)`` paired to measured ``k`` by minimum total ``|log|lambda| - log lam_hat|``.
    dE_dxa, dE_dxd : ndarray, shape (n, n)
        Gradients (diagonal of ``dE_dxa`` zeroed); zero if the pencil is singular.
    lam : ndarray, shape (n,)
        Real parts of the identified eigenvalues (unsorted).
    """
    from scipy.optimize import linear_sum_assignment  # lazy: scipy.optimize costs ~0.3 s of import

    n = xa.shape[0]
    Mn = np.eye(n) - xa
    zeros = np.zeros((n, n))
    try:
        Mn_inv = np.linalg.inv(Mn)
        lam_c, U = np.linalg.eig(Mn_inv @ (-xd))
        Wl = np.linalg.inv(U)  # rows: left eigenvectors of P = Mn^-1 Kn with w^T u = 1
    except np.linalg.LinAlgError:
        return float("nan"), zeros, zeros.copy(), np.full(n, np.nan)
    if not (np.all(np.isfinite(lam_c)) and np.all(np.isfinite(Wl))):
        return float("nan"), zeros, zeros.copy(), np.full(n, np.nan)
    V = Wl @ Mn_inv  # rows: left eigenvectors of the pencil, v^T Mn u = 1
    lam = lam_c.real
    cost = np.abs(np.log(np.abs(lam)[:, None] + 1e-300) - np.log(lam_hat)[None, :])
    rows, cols = linear_sum_assignment(cost)
    resid = (lam[rows] - lam_hat[cols]) / lam_hat[cols]
    E = float(np.mean(resid**2))
    w = 2.0 * resid / lam_hat[cols] / len(cols)  # dE / d lambda_p
    dxa = np.zeros((n, n))
    dxd = np.zeros((n, n))
    for p, wk in zip(rows, w, strict=True):
        outer = np.outer(V[p], U[:, p])
        dxd += wk * (-outer).real
        dxa += wk * (lam_c[p] * outer).real
    np.fill_diagonal(dxa, 0.0)
    return E, dxa, dxd, lam


def symmetric_mass_ratios(xa: np.ndarray, xv: np.ndarray, xd: np.ndarray, which: str = "MCK"
                          ) -> np.ndarray | None:
    """Diagonal masses (up to scale) that make ``diag(m) X`` most symmetric: generalised Eq. 6.

    Minimises ``sum_A sum_{i<j} (m_i At_ij - m_j At_ji)^2`` over unit ``m``, with
    ``At = X_A / ||X_A||`` for ``X_M = I - xa``, ``X_C = -xv``, ``X_K = -xd`` (each matrix
    weighted equally whatever its units): the right singular vector of the smallest singular
    value of the stacked pair equations.  Eq. 6 is the special case of M's adjacent pairs only.

    Returns
    -------
    ndarray, shape (n,) or None
        Positive masses with unit sum, or None when the minimiser has mixed signs (no
        physical solution at this iterate).
    """
    n = xa.shape[0]
    rows = []
    for key, xt in (("M", np.eye(n) - xa), ("C", -xv), ("K", -xd)):
        if key not in which:
            continue
        nrm = np.linalg.norm(xt)
        if nrm == 0:
            continue
        xt = xt / nrm
        for i in range(n):
            for j in range(i + 1, n):
                r = np.zeros(n)
                r[i], r[j] = xt[i, j], -xt[j, i]
                rows.append(r)
    if not rows:
        return None
    _, _, vt = np.linalg.svd(np.asarray(rows))
    m = vt[-1] * np.sign(vt[-1].sum())
    if not np.all(m > 0):
        return None
    return m / m.sum()


class Adam:
    """Adam (Kingma & Ba 2015) on one array; ``lr`` is the step size in parameter units."""

    def __init__(self, shape: tuple[int, ...], lr: float, beta1: float = 0.9, beta2: float = 0.999,
                 eps: float = 1e-12):
        self.lr, self.b1, self.b2, self.eps = lr, beta1, beta2, eps
        self.m = np.zeros(shape)
        self.v = np.zeros(shape)
        self.t = 0

    def step(self, g: np.ndarray) -> np.ndarray:
        """The update to *add* to the parameters for gradient ``g``."""
        self.t += 1
        self.m = self.b1 * self.m + (1.0 - self.b1) * g
        self.v = self.b2 * self.v + (1.0 - self.b2) * g * g
        mh = self.m / (1.0 - self.b1**self.t)
        vh = self.v / (1.0 - self.b2**self.t)
        #: per-entry step size of the last step (Adam's preconditioner): a proximal step in
        #: the same metric uses it as its threshold scale
        self.scale = self.lr / (np.sqrt(vh) + self.eps)
        return -self.scale * mh


class PlainSGD:
    """Eq. 3: ``Xi <- Xi - lr * grad``."""

    def __init__(self, shape: tuple[int, ...], lr: float):
        self.lr = lr

    def step(self, g: np.ndarray) -> np.ndarray:
        return -self.lr * g


def anneal(alpha: float, g_data_max: float, g_term: np.ndarray, beta: float) -> float:
    """Eqs 17-18: ``alpha <- (1 - beta) alpha + beta max|g_data| / mean|g_term|``.

    Parameters
    ----------
    alpha : float
        Current weight.
    g_data_max : float
        ``max |grad of the reconstruction loss|`` over the parameters.
    g_term : ndarray
        Gradient of the penalty over the parameters it acts on.
    beta : float
        Stabilisation coefficient (the paper: 0.1).

    Returns
    -------
    float
        The new weight; unchanged when the penalty's gradient is zero (already satisfied:
        Eq. 17 would divide by zero).
    """
    den = float(np.mean(np.abs(g_term))) if g_term.size else 0.0
    if not (den > 0.0 and np.isfinite(den) and np.isfinite(g_data_max)):
        return alpha
    return (1.0 - beta) * alpha + beta * g_data_max / den
