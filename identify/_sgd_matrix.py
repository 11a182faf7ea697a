"""SGD-SINDy in its symmetric-matrix parametrisation (the default of :class:`SGDSINDy`).

Why not the paper's raw coefficients
------------------------------------
In the paper's coupled library row ``i`` regresses ``x''_i`` on the *other* channels'
accelerations, velocities and displacements.  Exact data satisfy the other rows' equations of
motion, and those involve only library columns of row ``i``: each row's regression therefore
has an ``n - 1`` dimensional null space, and the least-squares (or SGD) coefficients wander in
it.  On the cantilever data this gave a non-symmetric mass matrix with a negative eigenvalue
and a diverging fit.  The paper escapes through its symmetry penalty, whose annealed weight it
reports growing to ~1e4 "so that the resulting matrices all had symmetric values".  Here that
limit is built in: the parameters are a symmetric positive definite ``M = m0 L L^T``, symmetric
``C`` and ``K`` and a cubic ``K3``, and the paper's coefficients follow from them exactly
(``xi_a[i, j] = -M_ij / M_ii``, ``xi_v = -C_ij / M_ii``, ``xi_d = -K_ij / M_ii``).

Loss (the paper's terms, Eqs 2-18)
----------------------------------
- data: the paper's reconstruction error of row ``i``, ``x''_i - Theta xi_i``, is
  ``(M x'' + C x' + K x + K3 x^3 - B u)_i / M_ii``; it is standardised by the RMS of ``x''_i``;
- symmetry (Eq. 7): zero by construction (recorded in the history as such);
- total mass (Eqs 4-6): ``trace(M) = M_hat`` is enforced after every step by scaling all
  matrices together (Eq. 5 at its fixed point; a common scale leaves the free-vibration fit
  unchanged, the measured force, where present in the window, then sets nothing else);
- eigenvalues (Eqs 8-13): relative squared error of the lowest generalised eigenvalues of
  ``(K, M)`` against ``(2 pi f)^2`` of the measured spectral peaks, with the exact first-order
  sensitivity ``d lambda = u^T (dK - lambda dM) u`` (``u`` mass-normalised);
- L1 (Eqs 14-15) on the cubic block, applied as a proximal (soft-threshold) step of size
  ``learning_rate * alpha_l1`` after each Adam step: Adam normalises every gradient, so a
  sign gradient fed through it would shrink the cubic block as fast as the data can grow it
  (measured: K3 driven to ~0 on a Duffing chain);
- learning-rate annealing of the penalty weights (Eqs 17-18) once per epoch, capped at
  ``alpha_max``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy import linalg

from identify._sgd_penalties import Adam
from testbed.measurement import Measurement


def _sym(a: np.ndarray) -> np.ndarray:
    return 0.5 * (a + a.T)


def warm_start(xdd: np.ndarray, xd: np.ndarray, x: np.ndarray, x3: np.ndarray | None,
               m_hat: float) -> tuple[np.ndarray, ...]:
    """Symmetric (M, C, K, K3) from the unique least-squares fit of ``x''`` on [x', x, x^3].

    The uncoupled regression determines ``A = M^-1 K`` and ``B = M^-1 C`` uniquely.  With ``Phi``
    the eigenvectors of ``A``, ``M0 = Phi^-T Phi^-1`` (equal modal masses) makes ``M0 A``
    symmetric; scaled to ``trace = m_hat``.  Falls back to ``m_hat / n * I`` if ``A`` has complex
    eigenvalues.
    """
    n = xdd.shape[0]
    feats = [xd, x] + ([x3] if x3 is not None else [])
    theta = np.vstack(feats)
    scale = np.sqrt(np.mean(theta**2, axis=1))  # x^3 ~ 1e-13 m^3 beside x' ~ 1e-2 m/s: rcond would
    scale[scale == 0] = 1.0                      # cut the cubic columns without standardising
    coef = np.linalg.lstsq((theta / scale[:, None]).T, xdd.T, rcond=1e-10)[0].T / scale[None, :]
    Bv, A = -coef[:, :n], -coef[:, n:2 * n]
    A3 = -coef[:, 2 * n:] if x3 is not None else None
    lam, phi = np.linalg.eig(A)
    if np.all(np.abs(lam.imag) <= 1e-9 * np.abs(lam).max()) and np.all(lam.real > 0):
        phi_inv = np.linalg.inv(phi.real)
        M0 = phi_inv.T @ phi_inv
    else:
        M0 = np.eye(n)
    M0 *= m_hat / np.trace(M0)
    K0, C0 = _sym(M0 @ A), _sym(M0 @ Bv)
    K30 = M0 @ A3 if A3 is not None else None
    return M0, C0, K0, K30


def fit_matrix_sgd(data: Measurement, est: Any, m_hat: float, lam_hat: np.ndarray) -> dict[str, Any]:
    """Run the matrix-parametrised SGD; ``est`` supplies the hyperparameters.

    Returns a dict with M, C, K, K3, history, n_steps and alphas.
    """
    i0 = int(data.free_start)
    i1 = data.n_samples if not est.fit_duration else min(data.n_samples,
                                                          i0 + round(est.fit_duration * data.fs))
    xdd, xd, x = data.xdd[:, i0:i1], data.xd[:, i0:i1], data.x[:, i0:i1]
    n, N = x.shape
    x3 = x**3 if est.cubic else None
    if data.u is not None and data.input_map is not None:
        bu = np.asarray(data.input_map, dtype=float) @ data.u[:, i0:i1]
    else:
        bu = np.zeros_like(x)
    M0, C0, K0, K30 = warm_start(xdd, xd, x, x3, m_hat) if est.init == "lstsq" else (
        np.eye(n) * m_hat / n, np.zeros((n, n)), np.zeros((n, n)), np.zeros((n, n)) if est.cubic else None)
    # parameter scales (Adam steps are relative to these)
    m0 = m_hat / n
    k0 = max(np.abs(np.diag(K0)).max(), 1e-12) if est.init == "lstsq" else m0 * (2 * np.pi * 100.0) ** 2
    c0 = max(np.abs(np.diag(C0)).max(), 1e-12) if est.init == "lstsq" else m0 * 10.0
    L = np.linalg.cholesky(M0 / m0)
    P, Q = K0 / k0, C0 / c0
    k30 = 1.0
    R = None
    if est.cubic:
        k30 = max(np.abs(K30).max(), 1e-12) if K30 is not None and np.abs(K30).max() > 0 else 1.0
        R = K30 / k30 if K30 is not None else np.zeros((n, n))
    s_a = np.sqrt(np.mean(xdd**2, axis=1))
    s_a[s_a == 0] = 1.0
    tril = np.tril(np.ones((n, n)))

    def mats(L, P, Q, R):
        M = m0 * (L @ L.T)
        return M, c0 * _sym(Q), k0 * _sym(P), (k30 * R if R is not None else None)

    def data_loss_grad(L, P, Q, R, idx):
        M, C, K, K3 = mats(L, P, Q, R)
        a, v, d, f = xdd[:, idx], xd[:, idx], x[:, idx], bu[:, idx]
        res = M @ a + C @ v + K @ d - f
        if K3 is not None:
            c3 = x3[:, idx]
            res = res + K3 @ c3
        w = 1.0 / (np.diag(M) * s_a)  # row scale: the paper's per-row reconstruction, standardised
        E = w[:, None] * res
        b = idx.size if isinstance(idx, np.ndarray) else N
        loss = float(np.sum(E**2)) / (b * n)
        G = (2.0 / (b * n)) * w[:, None] * E
        gM = G @ a.T
        gM[np.diag_indices(n)] -= (2.0 / (b * n)) * np.sum(E**2, axis=1) / np.diag(M)
        gL = m0 * ((gM + gM.T) @ L) * tril
        gP = k0 * _sym(G @ d.T)
        gQ = c0 * _sym(G @ v.T)
        gR = k30 * (G @ x3[:, idx].T) if R is not None else None
        return loss, gL, gP, gQ, gR

    def eig_loss_grad(L, P):
        if lam_hat.size == 0:
            return 0.0, np.zeros_like(L), np.zeros_like(P)
        M, _, K, _ = mats(L, P, P, None)
        lam, U = linalg.eigh(K, M)
        k = lam_hat.size
        lam, U = lam[:k], U[:, :k]
        r = (lam_hat - lam) / lam_hat
        loss = float(np.sum(r**2))
        gK = np.einsum("k,ik,jk->ij", -2.0 * r / lam_hat, U, U)
        gM = np.einsum("k,ik,jk->ij", 2.0 * r * lam / lam_hat, U, U)
        return loss, m0 * ((gM + gM.T) @ L) * tril, k0 * _sym(gK)

    def project(L, P, Q, R):
        """Eq. 5 at its fixed point: trace(M) = m_hat, all matrices scaled together."""
        s = m_hat / (m0 * np.sum(L * L))
        return L * np.sqrt(s), P * s, Q * s, (R * s if R is not None else None)

    L, P, Q, R = project(L, P, Q, R)
    shapes = [L.shape, P.shape, Q.shape] + ([R.shape] if R is not None else [])
    opts = [Adam(s, float(est.learning_rate)) for s in shapes]
    alpha = {"sym": float(est.alpha_init), "eig": float(est.alpha_init), "l1": float(est.alpha_init)}
    use_eig, use_l1 = bool(est.eigen) and lam_hat.size > 0, R is not None and est.l1 != "none"
    hist: dict[str, list[float]] = {k: [] for k in (
        "epoch", "n_steps", "loss_data", "loss_sym", "loss_eig", "loss_l1", "mass_residual",
        "alpha_sym", "alpha_eig", "alpha_l1")}
    full = np.arange(N)

    def record(epoch, n_steps):
        loss, gL, gP, gQ, gR = data_loss_grad(L, P, Q, R, full)
        le, eL, eP = eig_loss_grad(L, P) if use_eig else (np.nan, None, None)
        M = mats(L, P, Q, R)[0]
        hist["epoch"].append(epoch)
        hist["n_steps"].append(n_steps)
        hist["loss_data"].append(loss)
        hist["loss_sym"].append(0.0)
        hist["loss_eig"].append(le)
        hist["loss_l1"].append(float(np.sum(np.abs(R))) if use_l1 else np.nan)
        hist["mass_residual"].append(float(np.trace(M)) / m_hat - 1.0)
        for k in alpha:
            hist[f"alpha_{k}"].append(alpha[k])
        g_data = np.concatenate([g.ravel() for g in (gL, gP, gQ, gR) if g is not None])
        return g_data, eL, eP

    rng = np.random.default_rng(est.random_state)
    bs = int(est.batch_size)
    spe = int(np.ceil(N / bs)) if est.steps_per_epoch is None else int(est.steps_per_epoch)
    record(0, 0)
    n_steps = 0
    for epoch in range(1, int(est.epochs) + 1):
        perm = rng.permutation(N)
        for s in range(spe):
            idx = perm[(s * bs) % N:(s * bs) % N + bs]
            if idx.size == 0:
                idx = perm[:bs]
            _, gL, gP, gQ, gR = data_loss_grad(L, P, Q, R, idx)
            if use_eig:
                _, eL, eP = eig_loss_grad(L, P)
                gL = gL + alpha["eig"] * float(est.epsilon) * eL
                gP = gP + alpha["eig"] * float(est.epsilon) * eP
            L = L + opts[0].step(gL)
            P = P + opts[1].step(gP)
            Q = Q + opts[2].step(gQ)
            if R is not None:
                R = R + opts[3].step(gR)
                if use_l1:  # Eqs 14-15 as a proximal step: Adam would normalise a sign gradient
                    R = np.sign(R) * np.maximum(np.abs(R) - float(est.learning_rate) * alpha["l1"], 0.0)
            L, P, Q, R = project(L, P, Q, R)
            n_steps += 1
        g_data, eL, eP = record(epoch, n_steps)
        if est.anneal:  # Eqs 17-18, capped
            gmax = float(np.max(np.abs(g_data)))
            if use_eig:
                ge = np.abs(float(est.epsilon) * np.concatenate([eL.ravel(), eP.ravel()]))
                if ge.mean() > 0:
                    hat = gmax / ge.mean()
                    alpha["eig"] = min((1 - est.beta) * alpha["eig"] + est.beta * hat, float(est.alpha_max))
            if use_l1:
                hat = gmax / 1.0  # |sign| has mean 1 on nonzero entries
                alpha["l1"] = min((1 - est.beta) * alpha["l1"] + est.beta * hat, float(est.alpha_max))
    M, C, K, K3 = mats(L, P, Q, R)
    return {"M": _sym(M), "C": C, "K": K, "K3": K3, "n_steps": n_steps, "alphas": alpha,
            "history": {k: np.asarray(v) for k, v in hist.items()}}
