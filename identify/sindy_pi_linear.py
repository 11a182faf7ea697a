"""SINDy-PI on a linear structural library: ``M a + C v + K x = B u`` from free vibration.

Implicit rows, one per channel
------------------------------
Row ``i`` has left-hand side ``a_i`` and is regressed, over the free-vibration part of the record
(from ``data.free_start``), on ``[x, v]`` only; the *other* channels' accelerations are not
candidates.  With them (the coupled library ``[x, v, a]`` of every channel) the regression is
ill-posed: the data satisfy all ``n`` equations of motion, so every row's solution set has an
``n - 1`` dimensional null space (the other rows' equations hold among its columns; see
:mod:`identify._sgd_matrix`), and on the cantilever, where the third sensor mode is barely
excited, the near-null space is larger still.  The coupled sweep then returned an arbitrary
member of it, thresholding pruned the small velocity (damping) terms of that member, and
``W_a^-1 W_v`` came out wrong (measured on ``cantilever_stiff_impact``: damping ratios
0.22 / 0.11 against 0.010 / 0.063, TRAC 0.26; with no thresholding M was indefinite).  Free
vibration identifies ``M^-1 K`` and ``M^-1 C`` and nothing else, and the decoupled rows
``a_i + (M^-1 K)_i x + (M^-1 C)_i v = 0`` determine them uniquely, so nothing identifiable is
lost.  **This makes the regression step least-squares SINDy (``ls_sindy``) written in implicit
form**; the shared-Gram thresholded sweep of :mod:`identify._implicit` with held-out selection
(last ``val_fraction`` of the window) is kept per row, and on the cantilever data it selects
the unthresholded model (threshold 0), so no velocity term is pruned there.  What this
identifier adds over ``ls_sindy`` is the physical normalisation below: a symmetric positive
definite M and symmetric K and C.

Normalisation (reported in ``normalisation_``)
----------------------------------------------
M is the symmetric matrix for which ``M (M^-1 K)`` and ``M (M^-1 C)`` are symmetric
(:func:`symmetric_mass`; unique up to scale for non-proportional damping), with the sign that
makes its trace positive.  If that solve is ill-posed (a family of solutions, condition number
above :data:`MAX_MASS_COND`, or an M that is not positive definite) the modal masses are taken
equal, ``M = Phi^-T Phi^-1`` with ``Phi`` the eigenvectors of ``M^-1 K`` (as SGD-SINDy's warm
start); on the cantilever data the solve gives an indefinite M and this fallback is used.
M is scaled so that ``trace(M) = data.prior[mass_prior]`` [kg].  Given M, the symmetric K and
C are refitted by least squares on the equation error ``M a + C v + K x`` over the
free-vibration window (:func:`symmetric_stiffness_damping`), rather than symmetrising
``M (M^-1 K)`` and ``M (M^-1 C)``: on exact data the two coincide; on the 1 %-noise cantilever
the symmetrised damping kept a strongly wrong mode-2 damping (TRAC 0.61) where the refit gives
TRAC 0.94.  C is then projected onto the positive semi-definite cone (a passive structure
dissipates).  Simulation: exact zero-order-hold discretisation (matrix exponential).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import ClassVar

import numpy as np

from identify import IDENTIFIERS
from identify._base import Identifier
from identify._implicit import DEFAULT_THRESHOLDS, grams, rank_models, split_index, stlsq_sweep
from identify.library import linear_structural_library
from identify.ls_sindy import MASS_PRIOR_FIELD
from identify.sindy_pi import (
    MAX_ITER_FIELD,
    SELECTION_ATOL_FIELD,
    SELECTION_RTOL_FIELD,
    THRESHOLDS_FIELD,
    VAL_FRACTION_FIELD,
    check_thresholds,
)
from identify.structural import (
    MASS_PRIORS,
    remove_drift,
    symmetric_basis,
    symmetric_least_squares,
    unwarp_rule,
)
from testbed.core.errors import ArgumentError, IdentificationError
from testbed.core.lazy import lazy_module
from testbed.core.measurement import Measurement, Trajectory
from testbed.core.schema import Field

linalg = lazy_module("scipy.linalg")  # imported on first use: `testbed list` does not pay for it


def symmetric_mass(AK: np.ndarray, AC: np.ndarray, guess: np.ndarray) -> tuple[np.ndarray, int]:
    """Symmetric M with ``M AK`` and ``M AC`` symmetric, closest to ``guess``; and the family size.

    ``M (M^-1 K)`` and ``M (M^-1 C)`` are symmetric for the true M; the symmetric solutions
    form a linear family, one-dimensional (M unique up to scale) for non-proportional damping
    and n-dimensional (modal masses free) for proportional damping.  Within the family, the
    member nearest (Frobenius) to ``guess`` is returned.
    """
    n = AK.shape[0]
    S = symmetric_basis(n)
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


def symmetric_stiffness_damping(M: np.ndarray, x: np.ndarray, v: np.ndarray,
                                a: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Symmetric K and C minimising ``||M a + C v + K x||`` over the samples, given M.

    Parameters
    ----------
    M : ndarray, shape (n, n)
        Mass matrix [kg].
    x, v, a : ndarray, shape (n, N)
        Displacements [m], velocities [m/s], accelerations [m/s^2].

    Returns
    -------
    K, C : ndarray, shape (n, n)
        Stiffness [N/m] and damping [N s/m], symmetric.
    """
    C, K = symmetric_least_squares([v, x], -(M @ a))
    return K, C


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
        Ridge on the normalised Gram matrix of row i's columns ``[x, v, a_i]``; 1e-10 because
        a weakly excited mode makes that matrix near-singular (the third sensor mode of the
        cantilever), and the damped first solution is the stable one.
    max_iter, val_fraction, selection_rtol, selection_atol
        As :class:`~identify.sindy_pi.SINDyPI`.
    mass_prior : str
        Key of ``data.prior`` holding the mass scale [kg]: ``"reduced_mass_trace"`` (trace of
        the sensor-coordinate mass matrix) or ``"total_mass"``.

    Attributes
    ----------
    drift_offsets_ : ndarray, shape (2, n) or None
        The chain's integration constants taken out before the fit
        (:func:`identify.structural.remove_drift`: velocity [m/s] and displacement [m] offsets).
    M_, C_, K_ : ndarray, shape (n, n)
        Mass [kg], damping [N s/m], stiffness [N/m] in sensor coordinates.
    K3_ : None
    coef_ : ndarray, shape (n, 3n)
        Selected implicit equations over ``feature_names_`` (x_i, v_i, a_i), max |coef| = 1;
        row i has zeros on every acceleration but ``a_i`` (see the module docstring).
    lhs_terms_ : list of str
        Left-hand side of each row (``a_i``).
    selected_thresholds_, validation_errors_ : ndarray, shape (n,)
        Threshold and normalised held-out error of each selected row.
    normalisation_ : str
        How M, K and C were fixed.
    """

    name = "sindy_pi_linear"
    deterministic = True  # no draws; refitted to the bit in test_conformance
    kind = "structural"
    prior_keys = MASS_PRIORS
    hyperparameters: ClassVar[dict[str, Field]] = {
        "thresholds": THRESHOLDS_FIELD,
        "ridge": Field(float, 1e-10, min=0.0, max=1.0,
                       doc="ridge on the unit-diagonal normalised Gram matrix of each row"),
        "max_iter": MAX_ITER_FIELD,
        "val_fraction": VAL_FRACTION_FIELD,
        "selection_rtol": SELECTION_RTOL_FIELD,
        "selection_atol": SELECTION_ATOL_FIELD,
        "mass_prior": MASS_PRIOR_FIELD,
    }

    @classmethod
    def check_hyperparameters(cls, params, error):
        """Thresholds ascending (see :func:`identify.sindy_pi.check_thresholds`)."""
        check_thresholds(params, error)

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
        self.check_params()
        n = data.n_channels
        if self.mass_prior not in data.prior:
            raise IdentificationError(f"data.prior has no {self.mass_prior!r} (has "
                                      f"{sorted(data.prior)}): free vibration fixes M^-1 K only")
        # the chain's integration constants out first: this library has no columns for them
        data, self.drift_offsets_ = remove_drift(data)
        lib = linear_structural_library(n)
        s0 = data.free_start
        Theta = lib.evaluate(data.x[:, s0:], data.xd[:, s0:], data.xdd[:, s0:])
        G_tr, G_v = grams(Theta, split_index(Theta.shape[0], self.val_fraction))
        thr = DEFAULT_THRESHOLDS if self.thresholds is None else np.asarray(self.thresholds)
        W = np.zeros((n, 3 * n))
        lhs, thr_sel, errs = [], [], []
        for i in range(n):
            cols = np.r_[np.arange(2 * n), 2 * n + i]
            sub = np.ix_(cols, cols)
            sw = stlsq_sweep(G_tr[sub], G_v[sub], [2 * n], thr, self.ridge, self.max_iter)
            order = rank_models(sw, np.ones(sw.val_error.shape, dtype=bool), self.selection_rtol,
                                self.selection_atol)
            if order.size == 0:
                raise IdentificationError(f"no finite implicit equation has left-hand side "
                                          f"{lib.names[2 * n + i]}")
            t, c = np.unravel_index(order[0], sw.val_error.shape)
            W[i, cols] = sw.coef(t, c)
            lhs.append(lib.names[2 * n + i])
            thr_sel.append(sw.thresholds[t])
            errs.append(sw.val_error[t, c])
        Wx, Wv, Wa = W[:, :n], W[:, n:2 * n], W[:, 2 * n:]
        AK, AC = np.linalg.solve(Wa, Wx), np.linalg.solve(Wa, Wv)
        M, family = symmetric_mass(AK, AC, np.eye(n))  # W_a is diagonal: rows normalised, I
        lam, phi = np.linalg.eig(AK)
        if np.trace(M) < 0:
            M = -M  # the symmetric solutions form a linear space: the sign is free
        ill = (family > 1 or np.linalg.cond(M) > MAX_MASS_COND
               or not np.all(np.linalg.eigvalsh(M) > 0))
        if ill and np.all(np.abs(lam.imag) <= 1e-9 * np.abs(lam).max()) and np.all(lam.real > 0):
            # The data leave the modal masses open (proportional damping, or damping too weakly
            # non-proportional to pin them): take them equal, as SGD-SINDy's warm start does and
            # as the SEREP truth's mass-normalised modes imply.  On the stiff cantilever the
            # symmetric solve gave an indefinite M (eigenvalues -0.0015 / 0.045 / 0.96 of trace).
            p_inv = np.linalg.inv(phi.real)
            M = p_inv.T @ p_inv
            how = "equal modal masses (the symmetric solve was ill-posed)"
        elif ill:
            raise IdentificationError("no positive definite mass matrix: the symmetric solve is "
                                      "ill-posed and M^-1 K has complex or non-positive eigenvalues")
        else:
            how = "unique up to scale"
        M = float(data.prior[self.mass_prior]) / np.trace(M) * M
        K, C = symmetric_stiffness_damping(M, data.x[:, s0:], data.xd[:, s0:], data.xdd[:, s0:])
        # A passive structure dissipates: C is symmetric positive semi-definite.  Free decay hardly
        # excites the sensors' third mode, whose identified damping came out negative on the
        # stiff cantilever, and the free simulation diverged (measured: accelerations ~1e75).
        w, V = np.linalg.eigh(C)
        C = (V * np.maximum(w, 0.0)) @ V.T
        M, C = 0.5 * (M + M.T), 0.5 * (C + C.T)  # exactly symmetric (round-off of the products)
        if not np.all(np.linalg.eigvalsh(0.5 * (K + K.T)) > 0):
            # a structure held at its base has a positive definite K; with M positive definite
            # and C positive semi-definite that is what makes the model stable
            raise IdentificationError("identified K is not positive definite (a static divergence "
                                      "mode): not returned")
        self.integration_rule_ = "signals are exact derivatives: no mapping"
        if data.integration == "trapezoid":
            # the structural identifiers' rule: poles on the map's cut kept as fitted, every
            # other pole mapped back (whatever round-off makes of a double real pole)
            mapped, self.integration_rule_ = unwarp_rule(M, C, K, float(data.fs))
            if mapped is not None:
                C, K = mapped
        self.M_, self.C_, self.K_, self.K3_ = M, C, K, None
        self.normalisation_ = (
            f"M symmetric with M (M^-1 K) and M (M^-1 C) symmetric ({family}-dimensional family; "
            f"{how}), K and C symmetric least squares given M, "
            f"trace(M) = prior[{self.mass_prior!r}] = {float(data.prior[self.mass_prior]):g} kg")
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
        if t.size < 2 or not np.allclose(np.diff(t), t[1] - t[0], rtol=1e-9, atol=0):
            # one sample was numpy's IndexError and a non-uniform grid a plain ValueError
            raise ArgumentError(f"{type(self).__name__}.simulate", "t", f"{t.size} time(s)",
                                "expected at least 2 uniformly spaced sample times [s] (the "
                                "zero-order-hold step is their spacing)", described=True)
        dt = t[1] - t[0]
        n = self.M_.shape[0]
        Minv = np.linalg.inv(self.M_)
        A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ self.K_, -Minv @ self.C_]])
        B = self.input_map_ if u is not None else np.zeros((n, 0))
        m = B.shape[1]
        Bz = np.vstack([np.zeros((n, m)), Minv @ B])
        E = linalg.expm(np.block([[A, Bz], [np.zeros((m, 2 * n + m))]]) * dt)
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
