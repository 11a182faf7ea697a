"""SINDy-PI on a linear structural library: ``M a + C v + K x = B u`` from free vibration.

The shared-Gram sweep of :mod:`identify.sindy_pi` runs on the columns ``x_i, v_i, a_i`` of
the free-vibration part of the record (from ``data.free_start``), with the accelerations as
candidate left-hand sides.  One implicit equation is picked per channel (left-hand side
``a_i``; held-out error, then parsimony; an equation is skipped if it would make the stacked
acceleration block rank-deficient).  The stacked rows ``[W_x W_v W_a]`` are any invertible
row-combination ``T [K C M]`` of the truth; ``W_a^-1 W_x = M^-1 K`` and ``W_a^-1 W_v = M^-1 C``
are what free vibration identifies, and they are kept exactly.

Normalisation (reported in ``normalisation_``): M is the symmetric matrix for which
``M (M^-1 K)`` and ``M (M^-1 C)`` are symmetric (:func:`symmetric_mass`; unique up to scale
unless the damping is proportional, then the member nearest the row-normalised ``W_a``),
scaled so that ``trace(M) = data.prior[mass_prior]`` [kg]; ``K = M (M^-1 K)``,
``C = M (M^-1 C)``.  Simulation: exact zero-order-hold
discretisation (matrix exponential) of the identified linear model.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from scipy.linalg import expm

from identify import IDENTIFIERS
from identify._base import Identifier
from identify._implicit import DEFAULT_THRESHOLDS, grams, rank_models, split_index, stlsq_sweep
from identify.library import linear_structural_library
from testbed.errors import IdentificationError
from testbed.measurement import Measurement, Trajectory


def _sym_basis(n: int) -> np.ndarray:
    """Basis of symmetric n x n matrices, shape (n(n+1)/2, n, n)."""
    out = []
    for i in range(n):
        for j in range(i, n):
            E = np.zeros((n, n))
            E[i, j] = E[j, i] = 1.0
            out.append(E)
    return np.array(out)


def symmetric_mass(AK: np.ndarray, AC: np.ndarray, guess: np.ndarray) -> tuple[np.ndarray, int]:
    """Symmetric M with ``M AK`` and ``M AC`` symmetric, closest to ``guess``; and the family size.

    ``M (M^-1 K)`` and ``M (M^-1 C)`` are symmetric for the true M; the symmetric solutions
    form a linear family, one-dimensional (M unique up to scale) for non-proportional damping
    and n-dimensional (modal masses free) for proportional damping.  Within the family, the
    member nearest (Frobenius) to ``guess`` is returned.
    """
    n = AK.shape[0]
    S = _sym_basis(n)
    cols = [np.concatenate([(E @ A - A.T @ E)[np.triu_indices(n, 1)] / max(np.linalg.norm(A), 1e-300)
                            for A in (AK, AC)]) for E in S]
    L = np.array(cols).T
    _, sv, Vt = np.linalg.svd(L) if L.size else (None, np.zeros(0), np.eye(len(S)))
    # singular values below 1e-6 of the largest count as zero: identified M^-1 K carries
    # relative errors of ~1e-7 even on exact data; the smallest one always spans the family
    rank = min(int(np.sum(sv > 1e-6 * sv.max())), len(S) - 1) if sv.size else 0
    N = Vt[rank:]                                        # family coordinates (k, n(n+1)/2)
    F = np.einsum("ks,sij->kij", N, S)
    coef = np.linalg.lstsq(F.reshape(len(F), -1).T, guess.ravel(), rcond=None)[0]
    return np.einsum("k,kij->ij", coef, F), len(F)


#: Above this condition number the symmetric mass solve is taken as undetermined by the data.
MAX_MASS_COND = 1e3


@IDENTIFIERS.register("sindy_pi_linear", tags=("structural", "implicit", "sparse"))
class SINDyPILinear(Identifier):
    """SINDy-PI with the linear library, exposing M_, C_, K_ (K3_ is None).

    Parameters
    ----------
    thresholds : sequence of float, optional
        As :class:`~identify.sindy_pi.SINDyPI`.
    ridge : float
        Ridge on the normalised Gram matrix; 1e-10 because the linear library is rank-deficient
        by construction for a left-hand side a_i (any row combination eliminating a_i is also
        exact), and the minimum-norm first solution is the stable one.
    max_iter, val_fraction, selection_rtol, selection_atol
        As :class:`~identify.sindy_pi.SINDyPI`.
    mass_prior : str
        Key of ``data.prior`` holding the mass scale [kg]: ``"reduced_mass_trace"`` (trace of
        the sensor-coordinate mass matrix) or ``"total_mass"``.

    Attributes
    ----------
    M_, C_, K_ : ndarray, shape (n, n)
        Mass [kg], damping [N s/m], stiffness [N/m] in sensor coordinates.
    K3_ : None
    coef_ : ndarray, shape (n, 3n)
        Selected implicit equations over ``feature_names_`` (x_i, v_i, a_i), max |coef| = 1.
    """

    name = "sindy_pi_linear"
    kind = "structural"

    def __init__(self, thresholds: Sequence[float] | None = None, ridge: float = 1e-10,
                 max_iter: int = 20, val_fraction: float = 0.2, selection_rtol: float = 0.1,
                 selection_atol: float = 1e-12, mass_prior: str = "reduced_mass_trace"):
        self.thresholds = thresholds
        self.ridge = ridge
        self.max_iter = max_iter
        self.val_fraction = val_fraction
        self.selection_rtol = selection_rtol
        self.selection_atol = selection_atol
        self.mass_prior = mass_prior

    def fit(self, data: Measurement) -> SINDyPILinear:
        n = data.n_channels
        if self.mass_prior not in data.prior:
            raise IdentificationError(f"data.prior has no {self.mass_prior!r} (has "
                                      f"{sorted(data.prior)}): free vibration fixes M^-1 K only")
        lib = linear_structural_library(n)
        s0 = data.free_start
        Theta = lib.evaluate(data.x[:, s0:], data.xd[:, s0:], data.xdd[:, s0:])
        G_tr, G_v = grams(Theta, split_index(Theta.shape[0], self.val_fraction))
        thr = DEFAULT_THRESHOLDS if self.thresholds is None else np.asarray(self.thresholds)
        sw = stlsq_sweep(G_tr, G_v, np.arange(2 * n, 3 * n), thr, self.ridge, self.max_iter)
        rows, lhs, thr_sel, errs = [], [], [], []
        for i in range(n):
            elig = np.zeros(sw.val_error.shape, dtype=bool)
            elig[:, sw.candidates == 2 * n + i] = True
            for flat in rank_models(sw, elig, self.selection_rtol, self.selection_atol):
                t, c = np.unravel_index(flat, sw.val_error.shape)
                w = sw.coef(t, c)
                trial = np.array([*rows, w])[:, 2 * n:]
                if np.linalg.svd(trial / np.abs(trial).max(), compute_uv=False)[-1] > 1e-8:
                    rows.append(w)
                    lhs.append(lib.names[2 * n + i])
                    thr_sel.append(sw.thresholds[t])
                    errs.append(sw.val_error[t, c])
                    break
            else:
                raise IdentificationError(f"no implicit equation independent of the others has "
                                          f"left-hand side {lib.names[2 * n + i]}")
        W = np.array(rows)
        Wx, Wv, Wa = W[:, :n], W[:, n:2 * n], W[:, 2 * n:]
        AK, AC = np.linalg.solve(Wa, Wx), np.linalg.solve(Wa, Wv)
        guess = 0.5 * (Wa / np.diag(Wa)[:, None] + (Wa / np.diag(Wa)[:, None]).T)
        M, family = symmetric_mass(AK, AC, guess)
        lam, phi = np.linalg.eig(AK)
        ill = family > 1 or np.linalg.cond(M) > MAX_MASS_COND
        if ill and np.all(np.abs(lam.imag) <= 1e-9 * np.abs(lam).max()) and np.all(lam.real > 0):
            # The data leave the modal masses open (proportional damping, or damping too weakly
            # non-proportional to pin them): take them equal, as SGD-SINDy's warm start does and
            # as the SEREP truth's mass-normalised modes imply.  The symmetric solve was
            # near-singular on the cantilever (condition number 5e3), which wrecked M (M^-1 C).
            p_inv = np.linalg.inv(phi.real)
            M = p_inv.T @ p_inv
        scale = float(data.prior[self.mass_prior]) / np.trace(M)
        if not np.isfinite(scale) or scale <= 0:
            raise IdentificationError("identified mass matrix has a non-positive trace")
        M = scale * M
        # A passive structure dissipates: C is symmetric positive semi-definite.  Free decay hardly
        # excites the sensors' third mode, whose identified damping came out negative on the
        # stiff cantilever, and the free simulation diverged (measured: accelerations ~1e75).
        # Symmetrise K and C and project C onto the positive semi-definite cone.
        K = 0.5 * (M @ AK + (M @ AK).T)
        w, V = np.linalg.eigh(0.5 * (M @ AC + (M @ AC).T))
        C = (V * np.maximum(w, 0.0)) @ V.T
        self.M_, self.C_, self.K_, self.K3_ = M, C, K, None
        self.normalisation_ = (
            f"M symmetric with M (M^-1 K) and M (M^-1 C) symmetric ({family}-dimensional family; "
            f"{'unique up to scale' if family == 1 else 'equal modal masses'}"
            f"), trace(M) = prior[{self.mass_prior!r}] = {float(data.prior[self.mass_prior]):g} kg")
        self.coef_, self.feature_names_, self.lhs_terms_ = W, list(lib.names), lhs
        self.selected_thresholds_, self.validation_errors_ = np.array(thr_sel), np.array(errs)
        self.input_map_ = (np.zeros((n, 0)) if data.input_map is None
                           else np.asarray(data.input_map, dtype=float))
        return self

    def simulate(self, x0: np.ndarray, xd0: np.ndarray, t: np.ndarray,
                 u: np.ndarray | None = None) -> Trajectory:
        """ZOH simulation on the uniform time grid t [s]; u (n_inputs, len(t)) [N] or None."""
        if not hasattr(self, "M_"):
            raise IdentificationError("sindy_pi_linear: fit before simulate")
        t = np.asarray(t, dtype=float)
        dt = t[1] - t[0]
        if not np.allclose(np.diff(t), dt, rtol=1e-9, atol=0):
            raise ValueError("simulate needs a uniform time grid")
        n = self.M_.shape[0]
        Minv = np.linalg.inv(self.M_)
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ self.K_, -Minv @ self.C_]])
        B = self.input_map_ if u is not None else np.zeros((n, 0))
        m = B.shape[1]
        Bz = np.vstack([np.zeros((n, m)), Minv @ B])
        E = expm(np.block([[A, Bz], [np.zeros((m, 2 * n + m))]]) * dt)
        Ad, Bd = E[:2 * n, :2 * n], E[:2 * n, 2 * n:]
        uu = np.zeros((m, t.size)) if u is None else np.atleast_2d(np.asarray(u, dtype=float))
        Z = np.empty((2 * n, t.size))
        Z[:, 0] = np.r_[x0, xd0]
        for k in range(t.size - 1):
            Z[:, k + 1] = Ad @ Z[:, k] + Bd @ uu[:, k]
        x, xd = Z[:n], Z[n:]
        return Trajectory(x, xd, Minv @ (B @ uu - self.K_ @ x - self.C_ @ xd))

    def equations(self, precision: int = 4) -> list[str]:
        """``M a + C v + K x = B u`` row by row."""
        out = []
        n = self.M_.shape[0]
        for i in range(n):
            terms = [f"{c:+.{precision}g}*{s}{j + 1}" for s, Mx in (("a", self.M_), ("v", self.C_),
                                                                   ("x", self.K_))
                     for j, c in enumerate(Mx[i])]
            out.append(" ".join(terms) + f" = {'u' if self.input_map_[i].any() else '0'}")
        return out
