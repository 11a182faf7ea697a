"""SGD-SINDy in its symmetric-matrix parametrisation (``sgd_sindy``, :class:`identify.sgd_sindy.SGDSINDy`).

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
  ``(M x'' + C x' + K x + K3 x^3 - G u - D w)_i / M_ii``; it is standardised by the RMS of
  ``x''_i``.  The input gain ``G`` (free in every row, as ``ls_sindy``'s coupled input) and
  the coefficients ``D`` of the chain's drift waveforms ``w`` (``data.drift_basis``) are
  profiled out (:func:`project_out`) and recovered after the fit.  With the tilt
  (``fit_tilt``, ``ls_sindy``'s rule, :func:`identify.structural.tilt_rows`) every feature,
  target and nuisance column is differenced once before, for the warm start and the SGD
  alike, so the error is weighed by frequency squared (the force and drift coefficients are
  then fitted flat on the result's residual);
- symmetry (Eq. 7): zero by construction (recorded in the history as such);
- total mass (Eqs 4-6): ``trace(M) = M_hat`` is enforced after every step by scaling all
  matrices together (Eq. 5 at its fixed point; with the force's gain free, a common scale
  leaves the whole fit unchanged);
- eigenvalues (Eqs 8-13): relative squared error of the generalised eigenvalues of
  ``(K, M)`` paired with the measured spectral peaks (:func:`eigen_targets`) against
  ``(2 pi f)^2``, with the exact first-order sensitivity ``d lambda = u^T (dK - lambda dM) u``
  (``u`` mass-normalised); the result's paired eigenvalues are then held within one line of
  their peaks (:func:`hold_eigenvalues`); with the cubic library a hardening mode's peak is
  replaced by its backbone's linear frequency (:func:`backbone_targets`, ``eigen_backbone``);
- L1 (Eqs 14-15) on the cubic block, as a lasso on *standardised* cubic coefficients (see
  below), with a proximal step in Adam's metric, then a debiasing stage;
- learning-rate annealing of the eigenvalue weight (Eqs 17-18) once per epoch, capped at
  ``alpha_max``; the L1 weight is a declared selection threshold and is not annealed (below).

The L1 penalty: what it compares, and why it is not the paper's literal form
---------------------------------------------------------------------------
Eq. 14 adds ``alpha_l1 * sum |Xi|`` on raw coefficients.  A raw cubic coefficient
[N/m^3 / kg] says nothing about whether the term is needed: on the clamped beam the sensors
move ~3x less than on the soft base, so an irrelevant cubic term needs a ~30x *larger*
coefficient than a relevant one, and the paper's Eq. 21 contrast inverts (measured before
this design: clamped 2e14, soft 3e13 N/m^3).  What decides whether a nonlinear term belongs
in the model is how much of what the *linear* model leaves unexplained it explains.  So:

1. *Standardised coefficients.*  The cubic block is parametrised as
   ``K3_ij = R_ij * M0_ii * rms(x''_i) / rms(x_j^3)`` (``M0`` the warm start's masses), so
   ``R_ij`` is the coefficient of the unit-RMS column ``x_j^3`` in row ``i``'s standardised
   residual, the quantity the data loss sees.
2. *The threshold is a partial correlation.*  The L1 weight on ``|R_ij|`` is
   ``lam_ij = (2 / n) * l1_threshold * rho_i * sigma_j``, with ``rho_i`` the RMS residual of
   the least-squares linear model of row ``i`` (standardised) and ``sigma_j`` the RMS of
   ``x_j^3`` after removing its projection on the linear features (:func:`cubic_profile`).
   At ``R = 0`` with the linear terms at their optimum, ``dL/dR_ij = (2 / n) mean(E_i z_j)``,
   so the lasso leaves a term out exactly when its partial correlation with the linear
   model's residual is at most ``l1_threshold`` (the square of the partial correlation is the
   share of that residual's variance the term would explain).  Scale-free, and it works for a
   weak nonlinearity on exact data as well as for a strong one.  Measured largest partial
   correlations (noise-free, seed 0): clamped beam 0.066, soft base 0.99 (its weakest row
   0.74), synthetic linear chain 0.031, synthetic Duffing chain 1.00; the default 0.2 sits
   3x above the clamped beam, and at 0.5 the soft base loses terms it needs (TRAC 0.64).
   With 1 % noise the clamped beam's x^3 columns correlate up to 0.26 with the residual
   (integrated noise at the high-pass cut-off), so the selection is for clean data or
   thresholds above the noise's correlation.
3. *Where the selection happens.*  The warm start solves this lasso in closed form
   (:func:`warm_start`; scikit-learn's coordinate descent on the profiled problem), and the
   terms it rejects stay at zero in the SGD: the SGD's own residual, ~1e-3 of the response
   from its step noise, is not the data's, and a threshold scaled by the data's residual
   (1e-15 on exact linear data) cannot hold a zero against it.  With ``init="zeros"`` the SGD
   does the selection alone.
4. *A proximal step in Adam's metric.*  Adam divides each gradient by its running RMS, so a
   step is ~``learning_rate`` however small the gradient: a fixed shrink per step (or a sign
   gradient, Eq. 15) fights the data at a rate that has nothing to do with how much a term
   explains (measured before this design: no weight from 0.01 to 10 separated the clamped
   beam from the soft base).  Here the soft threshold is ``lam_ij`` times Adam's own
   per-entry step size ``learning_rate / (sqrt(v_hat) + eps)``, so an entry stays at zero
   exactly when ``|m_hat| <= lam_ij`` (its averaged data gradient lies in the lasso's
   subdifferential): the fixed points are the lasso's, whatever Adam's scaling.
5. *Annealing.*  Eq. 17 would set ``alpha_l1`` to the largest data-gradient entry; at a
   lasso fixed point that entry equals the weight itself on the active terms, so *every*
   weight is a fixed point and annealing cannot choose it.  The threshold is therefore
   declared; the history records the largest ``lam_ij`` as ``alpha_l1`` (0 once debiasing).
6. *Debiasing.*  The lasso shrinks the terms it keeps (measured with the former fixed L1:
   soft-base cubic restoring-force error 0.22, against 0.05 without L1).  After a fraction
   ``1 - l1_debias`` of the epochs the zero pattern is frozen and the remaining epochs run
   without L1 on the selected terms (the "relaxed lasso").

Speed
-----
The steps run in one compiled loop per epoch (:func:`identify._compiled.sgd_steps`): the
epoch's seeded permutation (the same sequence as ever for a ``random_state``) gathers the
samples once, each mini-batch's loss and gradient are sums over its rows, and the generalised
eigenproblem of the eigenvalue term is a 3 x 3 Cholesky + Jacobi solve.  Measured ~12 us per
step on one core (140-290 us in numpy): the paper's 1,000,000 steps in ~15-20 s.  The whole
window's loss and gradient (the history, and ``gradient="full"``) come from the features'
second-moment matrix in O(n^3), whatever the window's length.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from identify._modal_damping import modal_decay
from identify._unresolved import place_unresolved
from identify.structural import (
    FIT_BAND_ORDER,
    FIT_TILT_DIFFERENCES,
    MODE_SEPARATION,
    SHAPES_COND_MAX,
    check_physical,
    fit_band_cutoff,
    modal,
    symmetric_least_squares,
    tilt_rows,
)
from testbed.core.errors import IdentificationError
from testbed.core.lazy import lazy_module
from testbed.core.measurement import Measurement
from testbed.numerics.filters import elliptic_highpass
from testbed.numerics.linear_response import state_matrix

linalg = lazy_module("scipy.linalg")  # imported on first use: `testbed list` does not pay for it

#: Relative singular-value cut-off of the nuisance columns' basis (:func:`nuisance_basis`):
#: the drift rows and the force are independent waveforms, so only an exactly repeated column
#: (two inputs driven alike) falls below it; 1e-10 is the least-squares cut-off ls_sindy uses.
NUISANCE_RCOND = 1e-10


def _rms(a: np.ndarray, axis: int = 1) -> np.ndarray:
    """RMS along ``axis``, with 1 where it is zero (a safe divisor)."""
    r = np.sqrt(np.mean(a**2, axis=axis))
    r[r == 0] = 1.0
    return r


def _sym(a: np.ndarray) -> np.ndarray:
    return 0.5 * (a + a.T)


def _project_psd(A: np.ndarray) -> float:
    """Project the symmetric part of ``A`` onto the positive semi-definite cone, in place.

    Returns the most negative eigenvalue removed, relative to the largest absolute one
    (0 if none was negative).
    """
    w, V = np.linalg.eigh(_sym(A))
    if w[0] >= 0:
        return 0.0
    A[...] = (V * np.maximum(w, 0.0)) @ V.T
    return float(w[0] / max(np.abs(w).max(), 1e-300))


def cubic_profile(xdd: np.ndarray, xd: np.ndarray, x: np.ndarray, x3: np.ndarray) -> dict[str, Any]:
    """The standardised regression of ``x''`` with the linear terms profiled out.

    Returns ``s_a`` (n,) RMS of each ``x''_i``, ``s3`` (n,) RMS of each ``x_j^3``, ``F`` (N, 2n)
    the unit-RMS linear features [x', x], ``Q`` an orthonormal basis of their span, ``Z`` (N, n)
    the unit-RMS cubic columns, ``Zr`` those with the linear span removed, ``Er`` (N, n) the
    residual of the least-squares linear model of each ``x''_i / s_a_i``, and ``rho`` (n,),
    ``sigma`` (n,) the RMS of ``Er`` and ``Zr``: the partial correlation of cubic term ``j``
    with row ``i`` at the linear model is ``mean(Er_i Zr_j) / (rho_i sigma_j)``.
    """
    lin = np.vstack([xd, x])
    s_lin = _rms(lin)
    F = (lin / s_lin[:, None]).T  # x^3 ~ 1e-13 m^3 beside x' ~ 1e-2 m/s: rcond would cut
    Q = np.linalg.qr(F)[0]        # unstandardised cubic columns
    s_a, s3 = _rms(xdd), _rms(x3)
    Y, Z = (xdd / s_a[:, None]).T, (x3 / s3[:, None]).T
    Er, Zr = Y - Q @ (Q.T @ Y), Z - Q @ (Q.T @ Z)
    return {"s_lin": s_lin, "s_a": s_a, "s3": s3, "F": F, "Q": Q, "Y": Y, "Z": Z,
            "Er": Er, "Zr": Zr, "rho": _rms(Er, 0), "sigma": _rms(Zr, 0)}


def nuisance_basis(data: Measurement, i0: int, i1: int, inputs: np.ndarray | None = None
                   ) -> tuple[np.ndarray, np.ndarray]:
    """The columns every row of the model carries with a free coefficient, on samples ``[i0, i1)``.

    They are the measured inputs ``u`` (when nonzero in the window) and the rows of
    ``data.drift_basis`` (the chain's unknown integration constants), as in ``ls_sindy``
    (``build_library(..., drift=True, input_coupling=True)``): the force's coefficients are
    ``M B`` in full (they also absorb the residual flexibility of the unmodelled modes under
    the chain-filtered force tail), the drift's are the offsets, then dropped.

    ``inputs`` (optional) names the inputs to take instead of those nonzero on the samples.

    Returns
    -------
    W : ndarray, shape (N, p)
        The columns (inputs first), ``p = 0`` when there are none.
    inputs : ndarray of int
        Which inputs (rows of ``data.u``) are the first ``inputs.size`` columns.
    """
    cols: list[np.ndarray] = []
    if data.u is not None and data.input_map is not None:
        u = np.asarray(data.u, dtype=float)[:, i0:i1]
        if inputs is None:
            inputs = np.flatnonzero(np.any(u != 0.0, axis=1))
        cols.append(u[inputs])
    if data.drift_basis is not None:
        cols.append(np.asarray(data.drift_basis, dtype=float)[:, i0:i1])
    inputs = np.zeros(0, dtype=int) if inputs is None else np.asarray(inputs, dtype=int)
    if not cols:
        return np.zeros((i1 - i0, 0)), inputs
    return np.ascontiguousarray(np.vstack(cols).T), inputs


def project_out(W: np.ndarray, *signals: np.ndarray) -> list[np.ndarray]:
    """Each signal (n, N) minus its least-squares fit on the columns of ``W`` (N, p).

    Minimising a row's residual ``(M x'' + C x' + K x + K3 x^3)_i - g_i W^T`` over the free
    ``g_i`` is the same as fitting the model to the signals with the span of ``W`` removed
    (Frisch-Waugh-Lovell), so the SGD runs on these and never sees ``g``.
    """
    if W.shape[1] == 0:
        return list(signals)
    U, sv, _ = np.linalg.svd(W / _rms(W, 0)[None, :], full_matrices=False)
    Qw = U[:, sv > NUISANCE_RCOND * sv[0]]
    return [s - (s @ Qw) @ Qw.T for s in signals]


def cubic_direction(x: np.ndarray) -> np.ndarray:
    """The direction the cubic feature is taken along: the data's dominant displacement shape.

    The soft base's cubic moment acts on one coordinate, the base rotation, which at the
    sensors is one linear combination ``c . x`` of the displacements, and pushes back along
    one direction; ``n`` diagonal features ``x_j^3`` only approximate ``(c . x)^3`` and are
    nearly collinear (while one mode dominates, ``x_j^3 ~ phi_j^3 q^3`` for every ``j``), so
    the lasso and the SGD split one force among ``n^2`` coefficients by noise.  The rule:
    ``w`` is the first left singular vector of the fit window's displacements (the shape
    that carries most of their energy: the lowest mode's after an impact, which is also the
    mode that moves the soft base most), unit length, its largest entry positive.  It depends
    on the data only, and not on the displacements' scale (stiffness, amplitude).

    Parameters
    ----------
    x : ndarray, shape (n, N)
        Displacements [m] on the fit window.

    Returns
    -------
    ndarray, shape (n,)
        Unit vector ``w`` [-].
    """
    U = np.linalg.svd(np.asarray(x, dtype=float), full_matrices=False)[0]
    w = U[:, 0]
    return w if w[np.argmax(np.abs(w))] > 0 else -w


def cubic_feature(x: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The one cubic feature ``s = sum_j w_j^3 x_j^3`` [m^3], shape (N,), of ``x`` (n, N).

    ``s = (w^3) . x^3`` rather than ``(w . x)^3``: both equal a constant times ``q^3`` while
    the motion is along ``w`` (``x = w q``), and the first is exactly the structural model's
    ``K3 x^3`` with the rank-one ``K3 = b (w^3)^T`` that the simulation and the scorers take.
    """
    return (np.asarray(w, dtype=float) ** 3) @ (np.asarray(x, dtype=float) ** 3)


def eigen_targets(M: np.ndarray, K: np.ndarray, lam_hat: np.ndarray,
                  symmetric: bool | None = None) -> np.ndarray:
    """The measured eigenvalue each mode of ``(K, M)`` is held at, by rule.

    A mode and a measured eigenvalue pair only if their frequencies are within
    :data:`identify.structural.MODE_SEPARATION` (15 %) of each other, the distance within
    which the peak search itself calls two peaks one mode.  Pairs are taken closest first
    (``|log(f / f_hat)|``, ties to the lower mode), each mode and peak at most once and only
    in the same order as the modes (a pair that would cross an earlier one is skipped): a
    measured peak farther than that from every mode of the model is not a mode it sees (a
    spurious or mis-assigned peak), and a mode with no peak near it is left to the data.

    Parameters
    ----------
    M, K : ndarray, shape (n, n)
        Mass [kg] and stiffness [N/m] of the model.
    lam_hat : ndarray, shape (k,)
        Measured eigenvalues ``(2 pi f)^2`` [rad^2/s^2].
    symmetric : bool or None
        True: ``M`` and ``K`` are symmetric by construction (``sgd_sindy``'s ``m0 L L^T`` and
        ``k0 sym(P)``, once per epoch: the check cost 0.23 ms of a 3.7 ms epoch); None: checked
        to ``rtol`` 1e-12 (``ls_sindy``'s ``K`` is not symmetric).

    Returns
    -------
    ndarray, shape (n,)
        Target ``(2 pi f)^2`` [rad^2/s^2] of the k-th lowest mode; 0 = none.
    """
    n = M.shape[0]
    target = np.zeros(n)
    if lam_hat.size == 0:
        return target
    if symmetric or (symmetric is None and np.allclose(K, K.T, rtol=1e-12, atol=0.0)
                     and np.allclose(M, M.T, rtol=1e-12, atol=0.0)):
        lam = linalg.eigh(_sym(K), _sym(M), eigvals_only=True)
    else:  # a non-symmetric model (ls_sindy's K): the eigenvalues of M^-1 K, real parts
        lam = (2.0 * np.pi * np.nan_to_num(modal(M, K)[0])) ** 2
    hat = np.sort(lam_hat)
    with np.errstate(divide="ignore", invalid="ignore"):
        cost = 0.5 * np.abs(np.log(np.maximum(lam, 1e-300)[:, None] / hat[None, :]))
    order = np.lexsort((np.tile(np.arange(n)[:, None], (1, hat.size)).ravel(), cost.ravel()))
    pairs: list[tuple[int, int]] = []
    for flat in order:
        r, c = divmod(int(flat), hat.size)
        if not cost[r, c] <= np.log1p(MODE_SEPARATION):
            break
        if any(r == r2 or c == c2 or (r - r2) * (c - c2) < 0 for r2, c2 in pairs):
            continue
        pairs.append((r, c))
        target[r] = hat[c]
    return target


def cross_stiffening(data: Measurement, M: np.ndarray, K: np.ndarray, K3: np.ndarray,
                     window: tuple[int, int], located: np.ndarray | None = None) -> np.ndarray:
    """Each mode's eigenvalue shift [rad^2/s^2] by the cubic's stiffening from the *other*
    modes' motion over its own life, to first order.

    Why: a spectral peak (and the backbone decay fit's small-amplitude limit, which removes only
    the shift that decays with the mode's own amplitude) holds mode ``k`` at the frequency it
    rings at in the record, stiffened by the motion of the modes that outlive it.  With
    stiffness-proportional damping mode 1 outlives mode 2 several-fold (``zeta_2 / zeta_1 =
    f_2 / f_1``), so over mode 2's whole life mode 1 swings near its first amplitude and mode 2
    rings at a constant, hardened frequency: no chirp, and the hardening is not in the record
    as a decay.  A model that carries the cubic adds that stiffening itself when simulated, so
    its *linear* mode ``k`` must lie below the record's by it (round 14's
    ``b14_soft_r2p5_cf0p5_n40_s4_z0p1``: mode 2 rings at +2.65 % over its linear twin).

    The cubic force ``K3 x^3`` (``(K3 x^3)_i = sum_j K3_ij x_j^3``) has the tangent stiffness
    ``3 K3_ij x_j^2``; averaged over mode k's life with its energy as the weight
    (``q_k(t)^2``, ``q = Phi^-1 x``), and with ``x_j`` the other *located* modes' displacement
    (``sum_m phi_m q_m`` over the modes a spectral peak located, ``m != k``: the mode's own
    amplitude is the backbone's part, and a mode no peak located is not the record's motion:
    at 1 % noise soft member 014's warm start has a 38 Hz mode fitted to noise, whose share
    lowered mode 2's target 2.4 %), it is ``dK = 3 K3 diag(<x_j^2>)``, and the shift
    ``phi_k^T dK phi_k / phi_k^T M phi_k``.

    Parameters
    ----------
    data : Measurement
        Its displacements ``data.x`` [m] on ``window``.
    M, K : ndarray, shape (n, n)
        Mass [kg] and linear stiffness [N/m] (their modes).
    K3 : ndarray, shape (n, n)
        Cubic stiffness [N/m^3].
    window : (int, int)
        Samples ``[i0, i1)``.
    located : ndarray of bool, shape (n,), optional
        The modes a spectral peak located (default: every mode).

    Returns
    -------
    ndarray, shape (n,)
        Shift of each mode's eigenvalue (ascending modes of ``(M, K)``); 0 where its modal
        coordinate is zero over the window.
    """
    _, Phi = modal(M, K)
    i0, i1 = window
    x = np.asarray(data.x, dtype=float)[:, i0:i1]
    q = np.linalg.solve(Phi, x)
    on = np.ones(Phi.shape[1], bool) if located is None else np.asarray(located, bool)
    out = np.zeros(Phi.shape[1])
    for k in range(Phi.shape[1]):
        w = q[k] ** 2
        if not np.sum(w) > 0.0:
            continue
        others = on.copy()
        others[k] = False
        msq = ((Phi[:, others] @ q[others]) ** 2 @ w) / np.sum(w)
        out[k] = float(Phi[:, k] @ (3.0 * K3 * msq[None, :]) @ Phi[:, k]) / float(
            Phi[:, k] @ M @ Phi[:, k])
    return out


def backbone_targets(data: Measurement, M: np.ndarray, C: np.ndarray, K: np.ndarray,
                     window: tuple[int, int], lam_hat: np.ndarray, K3: np.ndarray | None = None,
                     cross_out: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, str]:
    """The eigenvalue penalty's targets with each hardening mode's peak replaced by its
    backbone's linear frequency (``sgd_sindy``'s ``eigen_backbone``, cubic library).

    A hardening mode's spectral peak sits at the record's amplitude-shifted frequency, above
    the linear one.  Each mode of the model ``(M, C, K)`` (the warm start) paired with a peak
    (:func:`eigen_targets`) whose backbone decay fit
    (:func:`identify._modal_damping.modal_decay` with ``backbone=True``) is taken and hardens
    (``c > 0``) has that peak replaced by the fit's linear eigenvalue (``lam_model``), so that
    the penalty pulls the linear part to the linear frequency and the cubic term has to carry
    the shift.  With the warm start's cubic ``K3``, every paired target the backbone left
    within one line (``fs / N``) of its peak (a mode whose decay shows no chirp of its own), and
    every one it lowered whose mode the other located modes outlive (each of their measured
    decay rates below its own: their stiffening is near-constant over its life, no part of its
    chirp), is then lowered by the stiffening the other located modes' motion adds over that
    mode's life (:func:`cross_stiffening`), which the model's own cubic adds back when
    simulated (where the target stays positive).

    Parameters
    ----------
    data : Measurement
    M, C, K : ndarray, shape (n, n)
        The warm start's mass [kg], damping [N s/m] and stiffness [N/m] (its modes).
    window : (int, int)
        Samples ``[i0, i1)`` of the fit window.
    lam_hat : ndarray, shape (k,)
        Measured eigenvalues ``(2 pi f)^2`` [rad^2/s^2] of the spectral peaks.
    K3 : ndarray, shape (n, n), optional
        The warm start's cubic stiffness [N/m^3] (None: no cross stiffening subtracted).
    cross_out : ndarray, shape (k,), optional
        Filled in place, for the decay hold (``MatrixSGDResult.eigen_cross``), with the cross
        stiffening [rad^2/s^2] subtracted from each entry of ``lam`` whose mode the other
        located modes outlive (0 elsewhere): only such a mode's measured decay rings stiffened
        by their motion over its whole life; a mode that outlives them is read by its decay
        where they have died (soft member 005: mode 1, the slowest, lowered 0.36 Hz there
        went 0.18 -> 0.70 % off).

    Returns
    -------
    lam : ndarray, shape (k,)
        ``lam_hat`` sorted, the replaced entries the backbone fits' linear eigenvalues (less
        the cross stiffening).
    moved : ndarray of bool, shape (k,)
        The replaced entries.
    rule : str
        What was replaced.
    """
    peaks = np.sort(np.asarray(lam_hat, dtype=float))
    lam = peaks.copy()
    moved = np.zeros(lam.size, bool)
    target = eigen_targets(M, K, lam)
    dec = modal_decay(data, M, K, C, window, backbone=True)
    modes = []
    slot = {}  # mode -> its entry of lam (eigen_targets returns peaks' own values)
    for k in np.flatnonzero(target > 0):
        slot[int(k)] = int(np.flatnonzero((peaks == target[k]) & ~np.isin(
            np.arange(lam.size), list(slot.values())))[0])
    for k in np.flatnonzero(dec.taken & (target > 0) & (np.nan_to_num(dec.chirp) > 0)):
        j = slot[int(k)]
        lam[j], moved[j] = dec.lam_model[k], True
        modes.append(int(k) + 1)
    cross = ""
    if K3 is not None and np.any(K3 != 0.0) and slot:
        shift = cross_stiffening(data, M, K, K3, window, target > 0)
        # only a mode whose decay shows no chirp of its own beyond one line of the window's
        # transform (the backbone left its target within a line of the peak): its frequency
        # stood still over its life, the stiffening the others' motion gives it; where its own
        # decay chirps, the backbone's measured limit stands (soft member 014 at 1 % noise:
        # the backbone moved mode 2 by +4.1 Hz, two lines, to within 0.4 % of its linear
        # frequency, and lowering it 3.1 Hz more put the model's mode 2 2.4 % low)
        line = float(data.fs) / max(window[1] - window[0], 1)
        still = {k for k, j in slot.items()
                 if abs(np.sqrt(lam[j]) - np.sqrt(peaks[j])) / (2.0 * np.pi) <= line}
        # A mode the other located modes outlive (every one's measured decay rate below its
        # own) is stiffened by their motion at a near-constant level over its whole life: its
        # own chirp, which the backbone reads, does not hold that part, and the backbone's
        # linear limit still carries it.  Its target, where the backbone lowered it (a
        # hardening decay), is lowered by the cross stiffening too.  Round 19's
        # b19_soft_r8_cf2_f75 (cubic fraction 2): mode 2 peak 466.2 Hz, backbone 462.8 Hz,
        # linear truth 446.9 Hz; measured decay rates 4.34 (mode 1) and 199.4 1/s: the model's
        # mode 2 2.90 % -> 0.11 % off (clean), 2.91 -> 0.91 % (1 %), 2.93 -> 1.84 % (2 %).
        sigma = np.asarray(dec.sigma, dtype=float)
        outlived = {k for k, j in slot.items()
                    if len(slot) > 1 and lam[j] <= peaks[j] and np.isfinite(sigma[k])
                    and all(np.isfinite(sigma[m]) and sigma[m] < sigma[k] for m in slot if m != k)}
        lowered = [k for k, j in slot.items()
                   if (k in still or k in outlived) and 0.0 < shift[k] < lam[j]]
        hz = []
        for k in lowered:
            j = slot[k]
            hz.append((np.sqrt(lam[j]) - np.sqrt(lam[j] - shift[k])) / (2.0 * np.pi))
            lam[j] -= shift[k]
            moved[j] = True
            if cross_out is not None and k in outlived:
                cross_out[j] = shift[k]
        if lowered:
            cross = (f"; less the cubic's stiffening by the other modes' motion over each mode's "
                     f"life: modes {[k + 1 for k in lowered]} by "
                     + ", ".join(f"{h:.3g}" for h in hz) + " Hz")
            modes = sorted(set(modes) | {k + 1 for k in lowered})
    if not modes:
        return lam, moved, "no paired mode's backbone decay fit hardens: the peaks"
    f0 = np.sqrt(peaks[moved]) / (2.0 * np.pi)
    f1 = np.sqrt(lam[moved]) / (2.0 * np.pi)
    return lam, moved, (f"modes {modes}: peak -> backbone linear frequency "
                        + ", ".join(f"{a:.4g} -> {b:.4g} Hz" for a, b in zip(f0, f1, strict=True))
                        + cross)


def hold_eigenvalues(L: np.ndarray, P: np.ndarray, m0: float, k0: float, target: np.ndarray,
                     band: float = 0.0, upper_only: np.ndarray | None = None) -> float:
    """Move each targeted eigenvalue of ``(K, M)`` into its target's band, in place on ``P``.

    The band of a target ``lam_hat = (2 pi f_hat)^2`` is ``[(2 pi (f_hat - band))^2,
    (2 pi (f_hat + band))^2]`` (``band`` [Hz]); an eigenvalue outside it is moved onto the
    nearer edge, one inside is left alone (``band = 0``: onto the target).  With ``U`` the
    mass-normalised modes (``U^T M U = I``, ascending eigenvalues ``lam``),
    ``K + (M U) diag(lam_new - lam) (M U)^T`` has the same modes and exactly the eigenvalues
    ``lam_new``: the smallest change of K in the modal metric that meets the constraints, the
    limit of the eigenvalue penalty (Eqs 8-13) at infinite weight outside the band.  K stays
    symmetric, and positive semi-definite when it was (the bands are positive).
    ``upper_only`` (bool, shape of ``target``): those targets bound their eigenvalues from
    above only (the band's lower edge is 0: an eigenvalue below the band is left alone).

    Returns
    -------
    float
        The largest relative frequency change ``|sqrt(lam_new / lam) - 1|`` made.
    """
    if not np.any(target > 0):
        return 0.0
    M, K = m0 * (L @ L.T), k0 * _sym(P)
    lam, U = linalg.eigh(K, _sym(M))
    on = target > 0
    f_hat = np.sqrt(np.where(on, target, 0.0)) / (2.0 * np.pi)
    lo = (2.0 * np.pi * np.maximum(f_hat - band, 0.5 * f_hat)) ** 2
    hi = (2.0 * np.pi * (f_hat + band)) ** 2
    if upper_only is not None:
        lo = np.where(upper_only, 0.0, lo)
    new = np.where(on, np.clip(lam, lo, hi), lam)
    if np.all(new == lam):
        return 0.0
    MU = M @ U
    P[...] = _sym(K + (MU * (new - lam)) @ MU.T) / k0
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.abs(np.sqrt(new[on] / np.maximum(lam[on], 1e-300)) - 1.0)
    return float(rel.max())


def symmetric_damping(M: np.ndarray, K: np.ndarray, xdd: np.ndarray, xd: np.ndarray,
                      x: np.ndarray, x3: np.ndarray | None = None, K3: np.ndarray | None = None
                      ) -> np.ndarray:
    """The symmetric ``C`` minimising ``||M x'' + C x' + K x (+ K3 x^3)||`` given the rest.

    Parameters
    ----------
    M, K : ndarray, shape (n, n)
        Mass [kg] and stiffness [N/m].
    xdd, xd, x : ndarray, shape (n, N)
        Accelerations [m/s^2], velocities [m/s], displacements [m].
    x3, K3 : ndarray, optional
        Cubic features ``x^3`` [m^3], shape (n, N), and their coefficients [N/m^3], (n, n).

    Returns
    -------
    ndarray, shape (n, n)
        Damping [N s/m], symmetric.

    Notes
    -----
    Why not the symmetric part of ``M (M^-1 C)``: the unconstrained regression's ``M^-1 C``
    carries large non-symmetric couplings to a poorly determined heavily damped top mode, and
    halving them moves the lightly damped mode 1's damping by 10-300x (measured on family beams
    with 4 sensors).  The least-squares symmetric ``C`` is the best the data allow in that form.
    """
    r = -(M @ xdd + K @ x)
    if K3 is not None and x3 is not None:
        r = r - K3 @ x3
    return symmetric_least_squares([xd], r)[0]


def _uncoupled_coef(xdd: np.ndarray, xd: np.ndarray, x: np.ndarray,
                    x3: np.ndarray | None = None) -> np.ndarray:
    """The uncoupled least squares of ``x''`` on ``[x', x (, x^3)]``, columns scaled to unit RMS
    (cut-off 1e-10, ``ls_sindy``'s): coefficients, shape (n, 2 n) or (n, 3 n), so that
    ``x'' = coef @ [x'; x (; x^3)]`` (``-M^-1 C``, ``-M^-1 K`` (, ``-M^-1 K3``))."""
    theta = np.vstack([xd, x] + ([x3] if x3 is not None else []))
    scale = _rms(theta)
    return np.linalg.lstsq((theta / scale[:, None]).T, xdd.T, rcond=1e-10)[0].T / scale[None, :]


def equal_modal_mass(A: np.ndarray, m_hat: float) -> tuple[np.ndarray, np.ndarray | None]:
    """The warm start's mass for ``A = M^-1 K``: ``M0 = Phi^-T Phi^-1`` (equal modal masses of
    the unit-norm eigenvectors ``Phi`` of ``A``), which makes ``M0 A`` symmetric, scaled to
    ``trace = m_hat`` [kg].  ``m_hat / n * I`` (and ``Phi`` None) when ``A`` has a complex or
    non-positive eigenvalue or dependent eigenvectors (e.g. a 60-sample free decay through 5
    sensors defines no mass: the identity instead of inverting a singular matrix).

    Returns
    -------
    M0 : ndarray, shape (n, n)
        Mass [kg].
    Phi : ndarray, shape (n, n) or None
        The eigenvectors (columns, unit norm) ``M0`` was formed from.
    """
    n = A.shape[0]
    lam, phi = np.linalg.eig(A)
    if (np.all(np.abs(lam.imag) <= 1e-9 * np.abs(lam).max()) and np.all(lam.real > 0)
            and np.linalg.cond(phi.real) < 1e12):
        phi = phi.real
        phi_inv = np.linalg.inv(phi)
        M0 = phi_inv.T @ phi_inv
    else:
        phi, M0 = None, np.eye(n)
    return M0 * (m_hat / np.trace(M0)), phi


def complex_stiffness_pair(A: np.ndarray) -> str:
    """Why an uncoupled regression's ``A = M^-1 K`` has no real mode shapes, or ``""``.

    Rule: the placement of an unresolved mode (:func:`~identify._unresolved.place_unresolved`)
    moves one eigenvalue of ``A`` along its shape and keeps the others' shapes; it needs
    ``n`` real shapes that span the space.  Where the fit gave ``A`` a complex eigenvalue
    pair (two modes coalesced: a "stiffness" that couples them with no real mode between
    them, which no passive structure has) the real parts of the pair's shapes are one vector
    and no mode can be placed by them: the placement does not act, stated here, and the
    fallback is the flat fit (round 20's ``b20_st_hit0p1`` at 3 %, seed 113: modes 2-3 fitted
    as 532.5 +- 11.7j Hz, the shapes' matrix singular and the fit ended in "numerical
    breakdown (LinAlgError: Singular matrix)"; flat, a scored model, TRAC 0.795, modes 1-2
    within 0.02 %).

    Decided on the shapes the placement itself uses (:func:`identify.structural.modal`'s
    real parts, the same solver): they span the space where their condition number is at
    most :data:`identify.structural.SHAPES_COND_MAX`, the placement's own bound.  A pair
    near coalescence splits into a real or a complex pair by rounding, differently in each
    eigensolver, but its shapes are near-parallel either way, so the statement does not
    depend on which (session 22's review: decided by a second solver, 9 of 300 near-defective
    ``A`` passed this check and the placement's solve met a singular matrix); a repeated
    eigenvalue with independent shapes is no coalescence and gives ``""``.  The statement
    names the pair as complex where LAPACK's eigenvalues have an imaginary part above
    ``1e-9`` of the largest modulus, else as near-parallel real shapes.

    Parameters
    ----------
    A : ndarray, shape (n, n)
        ``M^-1 K`` [1/s^2] of the uncoupled regression (:func:`_uncoupled_coef`).

    Returns
    -------
    str
        The statement (the pair in Hz), or ``""`` where the shapes span the space.
    """
    A = np.asarray(A, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        phi = modal(np.eye(A.shape[0]), A)[1]
        cond = np.linalg.cond(phi) if np.all(np.isfinite(phi)) else np.inf
    if cond <= SHAPES_COND_MAX:
        return ""
    lam = np.linalg.eigvals(A)
    pair = lam[lam.imag > 1e-9 * np.abs(lam).max()]
    if pair.size:
        f = np.sqrt(pair.astype(complex)) / (2.0 * np.pi)
        shown = ", ".join(f"{z.real:.4g} +- {abs(z.imag):.3g}j Hz" for z in f)
        return (f"none placed: the uncoupled regression's A = M^-1 K has a complex eigenvalue "
                f"pair ({shown}: two modes coalesced, no real mode shapes to place a mode by)")
    return (f"none placed: the uncoupled regression's A = M^-1 K has near-parallel real mode "
            f"shapes (condition number {cond:.3g} > {SHAPES_COND_MAX:g}: two modes near "
            "coalescence, no shapes to place a mode by)")


def unresolved_warm_start(xdd: np.ndarray, xd: np.ndarray, x: np.ndarray, m_hat: float,
                          top_hz: float, peaks: np.ndarray
                          ) -> tuple[np.ndarray, np.ndarray, np.ndarray, str] | None:
    """A linear warm start with the modes the record cannot resolve placed (``ls_sindy``'s step
    5, :func:`identify._unresolved.place_unresolved`, on the uncoupled regression).

    The uncoupled least squares (``A = M^-1 K``, ``B = M^-1 C``, :func:`_uncoupled_coef`) has
    its unresolved modes placed at the peak band's top, damped to 1/sqrt(2)
    (:func:`~identify._unresolved.place_unresolved` with ``M = I``); the mass is then
    :func:`equal_modal_mass` of the placed ``A`` and ``K0 = M0 A`` (symmetric).  The damping
    is each mode's own, ``C0 = M0 Phi diag(d) Phi^-1`` with ``d`` the diagonal of
    ``Phi^-1 B Phi`` (symmetric, positive semi-definite where every ``d_k >= 0``): the fitted
    couplings of ``B`` have no symmetric form with these masses (round 16's
    ``b16_ti_n32_s5``: ``|D - D^T| / |D|`` 1.0), and :func:`symmetric_damping`'s least
    squares gives the placed mode, which the record does not hold, a damping of its own
    choosing (measured there: poles at +3058 +3330j 1/s x 2 pi; the held warm start TRAC
    0.009, with the modal damping 0.985).

    Parameters
    ----------
    xdd, xd, x : ndarray, shape (n, N)
        The fit's (tilted, profiled) accelerations, velocities and displacements.
    m_hat : float
        Mass prior [kg], ``trace(M0)``.
    top_hz : float
        The peak search's band top [Hz].
    peaks : ndarray, shape (k,)
        Accepted spectral peaks [Hz].

    Returns
    -------
    (M0, C0, K0, rule) or str or None
        None where the rule does not act (:func:`~identify._unresolved.place_unresolved`) or
        the placed ``A`` defines no equal-modal-mass ``M0``; a statement of why, where ``A``
        has no real mode shapes to place a mode by (:func:`complex_stiffness_pair`).
    """
    n = xdd.shape[0]
    coef = _uncoupled_coef(xdd, xd, x)
    why = complex_stiffness_pair(-coef[:, n:])
    if why:
        return why
    placed = place_unresolved(np.eye(n), -coef[:, :n], -coef[:, n:], top_hz, peaks)
    if placed is None:
        return None
    B, A, rule = placed
    M0, phi = equal_modal_mass(A, m_hat)
    if phi is None:
        return None
    # in modal form, M0 = s Phi^-T Phi^-1: C0 = s Phi^-T diag(d) Phi^-1, K0 likewise with the
    # placed eigenvalues (not M0 @ A: with four root sensors M0's condition is 6e7)
    phi_inv = np.linalg.inv(phi)
    s = m_hat / float(np.sum(phi_inv * phi_inv))
    d = np.diag(phi_inv @ B @ phi)
    lam = np.diag(phi_inv @ A @ phi)
    return (M0, _sym(s * (phi_inv.T * d) @ phi_inv), _sym(s * (phi_inv.T * lam) @ phi_inv),
            rule)


def warm_start(xdd: np.ndarray, xd: np.ndarray, x: np.ndarray, x3: np.ndarray | None,
               m_hat: float, l1_threshold: float = 0.0,
               profile: dict[str, Any] | None = None) -> tuple[np.ndarray, ...]:
    """Symmetric (M, C, K, K3) from the uncoupled regression of ``x''`` on [x', x, x^3].

    The uncoupled regression determines ``A = M^-1 K`` and ``B = M^-1 C`` uniquely.  With ``Phi``
    the eigenvectors of ``A``, ``M0 = Phi^-T Phi^-1`` (equal modal masses) makes ``M0 A``
    symmetric; scaled to ``trace = m_hat``.  Falls back to ``m_hat / n * I`` if ``A`` has complex
    eigenvalues.  ``K0`` is the symmetric part of ``M0 A``; ``C0`` the least-squares symmetric
    damping given ``M0`` and ``K0`` (:func:`symmetric_damping`; family beams of
    studies/families.toml, clean: clamped 31/40 -> 34/40 within the issue's bars against the
    symmetric part of ``M0 B``).

    With ``l1_threshold > 0`` the cubic block is the lasso solution of the problem the SGD's L1
    then holds (module docstring, L1): per row, the linear terms are profiled out and
    scikit-learn's ``Lasso(alpha=l1_threshold)`` runs on the residual scaled to unit RMS
    against the residualised cubic columns scaled to unit RMS, so a term stays at zero
    exactly when its partial correlation is at most ``l1_threshold``.  The SGD thus starts on
    the selected support instead of walking a spurious term to zero.  ``profile`` is
    :func:`cubic_profile` of the same signals, if the caller already has it.
    """
    n = xdd.shape[0]
    if x3 is None or not l1_threshold > 0:
        coef = _uncoupled_coef(xdd, xd, x, x3)
    else:
        from sklearn.linear_model import Lasso

        pr = profile if profile is not None else cubic_profile(xdd, xd, x, x3)
        coef = np.zeros((n, 3 * n))
        for i in range(n):
            u = Lasso(alpha=float(l1_threshold), fit_intercept=False, tol=1e-12,
                      max_iter=100_000).fit(pr["Zr"] / pr["sigma"], pr["Er"][:, i] / pr["rho"][i]).coef_
            w = u * pr["rho"][i] / pr["sigma"]  # coefficients of the unit-RMS cubic columns
            a = np.linalg.lstsq(pr["F"], pr["Y"][:, i] - pr["Z"] @ w, rcond=1e-10)[0]
            coef[i] = pr["s_a"][i] * np.concatenate([a / pr["s_lin"], w / pr["s3"]])
    A = -coef[:, n:2 * n]
    A3 = -coef[:, 2 * n:] if x3 is not None else None
    M0 = equal_modal_mass(A, m_hat)[0]
    K0 = _sym(M0 @ A)
    C0 = symmetric_damping(M0, K0, xdd, xd, x, x3, M0 @ A3 if A3 is not None else None)
    K30 = M0 @ A3 if A3 is not None else None
    return M0, C0, K0, K30


@dataclass(frozen=True)
class MatrixSGDSettings:
    """The hyperparameters :func:`fit_matrix_sgd` runs with (those of
    :class:`identify.sgd_sindy.SGDSINDy`, where each is documented; built by its ``settings``).

    Attributes
    ----------
    epochs : int
        Number of epochs, >= 0.
    batch_size : int
        Samples per mini-batch, >= 1 (unused with ``gradient="full"``).
    learning_rate : float
        Adam step size [standardised units], > 0 (already resolved, never None).
    alpha_init : float
        Initial eigenvalue-penalty weight.
    epsilon : float
        Gain of the eigenvalue gradient (Eqs 12-13).
    beta : float
        Annealing stabilisation coefficient (Eq. 18).
    cubic : bool
        Cubic features ``x_j^3`` in the model.
    l1 : bool
        Lasso on the standardised cubic block (acts only with ``cubic``).
    l1_threshold : float
        Partial-correlation threshold of the lasso.
    l1_debias : float
        Fraction of the epochs, at the end, without L1 on the kept terms, in [0, 1).
    steps_per_epoch : int or None
        Gradient steps per epoch; None = a full pass (one step with ``gradient="full"``).
    init : {"lstsq", "zeros"}
        Warm start or zero start.
    anneal : bool
        Annealing of the eigenvalue weight (Eqs 17-18).
    alpha_max : float
        Upper bound of the annealed weight.
    random_state : int
        Seed of the mini-batch order.
    fit_duration : float
        Fit window after ``free_start`` [s]; 0 = to the end.
    gradient : {"minibatch", "full"}
        Mini-batch steps or the exact full-window gradient.
    iterate_average : float
        Fraction of the epochs, at the end, whose iterates are averaged, in [0, 1).
    eigen_hold : bool
        Move the result's paired eigenvalues into their peaks' bands, one line (fs / N) either
        side (:func:`hold_eigenvalues`); only with measured targets.
    fit_band_hz : float or None
        Cut-off [Hz] of the fit band's high-pass (:func:`identify.structural.fit_band_cutoff`):
        None = by rule, 0 = none.
    cubic_form : {"direction", "diagonal"}
        ``"direction"``: one cubic feature along the data's dominant displacement direction,
        ``K3 = b a^T`` (:func:`cubic_direction`); ``"diagonal"``: the n features ``x_j^3``, a
        full ``K3``.
    fit_tilt : bool or None
        Difference every row once (warm start and SGD): None = by rule (tilted, with the cubic
        library too; flat when the tilted warm start has a growing mode, and then, with the
        cubic library, tilted on the linear columns when the flat warm start kept no x^3 term;
        a linear tilted warm start whose growing pole its damping's projection onto the positive
        semi-definite cone removes stays tilted with that damping,
        :func:`psd_damping_warm_start`), True = tilted (a non-physical tilted warm start
        raises), False = flat.
    eigen_backbone : bool
        With the cubic library and a warm start that kept a cubic term, replace each hardening
        mode's peak by its backbone's linear frequency in the penalty and the hold
        (:func:`backbone_targets`); when the SGD then drops every cubic term, the hold puts
        those modes onto their peaks.
    lowest_peak_flat : bool
        Refuse a projected tilted warm start (then placed or flat as any growing tilted warm
        start); False: kept, and the doubt returned (``MatrixSGDResult.lowest_peak_unpaired``:
        :func:`lowest_peak_unpaired`'s statement, or :data:`PROJECTED_DOUBT` where the lowest
        peak is carried).  ``sgd_sindy`` sets it for its second fit only.
    """

    epochs: int
    batch_size: int
    learning_rate: float
    alpha_init: float
    epsilon: float
    beta: float
    cubic: bool
    l1: bool
    l1_threshold: float
    l1_debias: float
    steps_per_epoch: int | None
    init: Literal["lstsq", "zeros"]
    anneal: bool
    alpha_max: float
    random_state: int
    fit_duration: float
    gradient: Literal["minibatch", "full"]
    iterate_average: float
    eigen_hold: bool = True
    cubic_form: Literal["direction", "diagonal"] = "diagonal"
    fit_band_hz: float | None = 0.0
    fit_tilt: bool | None = False
    eigen_backbone: bool = False
    lowest_peak_flat: bool = False

    def __post_init__(self) -> None:
        for key, allowed in (("init", ("lstsq", "zeros")), ("gradient", ("minibatch", "full")),
                             ("cubic_form", ("direction", "diagonal"))):
            if getattr(self, key) not in allowed:
                raise ValueError(f"{key} must be one of {allowed}, got {getattr(self, key)!r}")
        if not (self.epochs >= 0 and self.batch_size >= 1 and self.learning_rate > 0):
            raise ValueError("need epochs >= 0, batch_size >= 1 and learning_rate > 0, got "
                             f"{self.epochs}, {self.batch_size}, {self.learning_rate}")
        for key in ("l1_debias", "iterate_average"):
            if not 0.0 <= getattr(self, key) < 1.0:
                raise ValueError(f"{key} must be in [0, 1), got {getattr(self, key)}")


@dataclass(frozen=True)
class MatrixSGDResult:
    """What :func:`fit_matrix_sgd` returns.

    Attributes
    ----------
    M, C, K : ndarray, shape (n, n)
        Symmetric [kg], [N s/m], [N/m]; ``M`` positive definite up to rounding, ``C`` and ``K``
        positive semi-definite, ``trace(M)`` the mass prior.
    K3 : ndarray, shape (n, n) or None
        Cubic stiffness [N/m^3] (None without the cubic library).
    n_steps : int
        Gradient steps taken.
    alphas : dict of str to float
        Final weights ``sym``, ``eig``, ``l1``.
    guard : dict of str to float
        Most negative eigenvalue (relative) removed from ``"C"`` / ``"K"`` by the projections
        onto the positive semi-definite cone; absent if none was needed.
    history : dict of str to ndarray
        Per-epoch records (:class:`identify.sgd_sindy.SGDSINDy`, ``history_``).
    input_map : ndarray, shape (n, n_inputs) or None
        Force per unit input on each coordinate [-]: identified (free in every row) for the
        inputs nonzero in the window (:func:`nuisance_basis`), ``data.input_map``'s column
        for the others; None without ``data.input_map``.
    drift_coef : ndarray, shape (n, n_drift)
        Coefficients [N / unit of the basis] of ``data.drift_basis``'s rows, dropped from the
        model.
    eigen_targets : ndarray, shape (n,) or (0,)
        Frequency [Hz] each mode (ascending) was held at (:func:`eigen_targets`); 0 = none.
    eigen_shift : float
        Largest relative frequency change a hold made (0 without holding).
    eigen_cross : ndarray, shape (n,) or (0,)
        The cross stiffening [rad^2/s^2] :func:`backbone_targets` subtracted from each mode's
        target (ascending modes; 0 = none): the decay hold subtracts it from that mode's
        measured decay frequency too (:meth:`identify.sgd_sindy.SGDSINDy._hold_decay`).
    fit_tilt : bool
        Whether the fit was tilted; ``fit_tilt_rule`` (str) says why.
    input_map_record : ndarray, shape (n, n_inputs) or None
        ``input_map`` fitted on the record from its start to the window's end (the impact
        pulse included) instead of the window alone, the same model and nuisance columns;
        None when no input is nonzero in the window or the window starts the record.
        :class:`identify.sgd_sindy.SGDSINDy` takes it when the window's gain is refused at
        the driving point (:func:`identify.structural.driving_point_scaling`).
    backbone_rule : str
        What ``eigen_backbone`` did (:func:`backbone_targets`).
    warm : MatrixSGDResult or None
        With ``with_warm``: the held warm start, the result ``epochs = 0`` gives (bit for bit;
        ``n_steps`` 0, ``history`` the first row); else None.
    stop_rule : str
        Why the epochs ended before ``epochs`` (:data:`BREAKDOWN_RULE`), or ``""`` when all
        ran; the history then ends at the last epoch that left a finite iterate.
    ceiling_held : bool
        Whether the hold bounded a mode from above only (``ceiling``): False when none was
        asked, the hold is off, or ``eigen_backbone`` replaced the peak.
    unresolved_rule : str
        What :func:`unresolved_warm_start` placed in the warm start (``fit_matrix_sgd``'s
        ``unresolved``), or ``""`` where it did not act.
    lowest_peak_unpaired : str
        Where the kept warm start is the tilted one with its damping projected, the doubt on
        it (:func:`lowest_peak_unpaired`'s statement where it has no mode near the lowest
        measured peak, else :data:`PROJECTED_DOUBT`; the caller fits flat too and compares),
        else ``""``.
    """

    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    K3: np.ndarray | None
    n_steps: int
    alphas: dict[str, float]
    guard: dict[str, float]
    history: dict[str, np.ndarray]
    input_map: np.ndarray | None
    drift_coef: np.ndarray
    eigen_targets: np.ndarray
    eigen_shift: float
    eigen_cross: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0))
    fit_tilt: bool = False
    fit_tilt_rule: str = ""
    input_map_record: np.ndarray | None = None
    backbone_rule: str = ""
    warm: MatrixSGDResult | None = None
    stop_rule: str = ""
    ceiling_held: bool = False
    unresolved_rule: str = ""
    lowest_peak_unpaired: str = ""


#: The rule when an epoch's steps leave a non-finite iterate (round 12's
#: ``b12_tip_cluster_L1``: three sensors within 0.15 m of a 1 m beam's tip, the mass
#: matrix's Cholesky factor lost rank over 40 epochs, condition 1e16, then the next epoch's
#: steps turned every entry NaN and the K projection's eigensolver raised): an iterate that is
#: not a number is no result, so the epochs stop and the result is the last epoch's finite
#: iterate.  ``SGDSINDy``'s ``keep_sgd`` comparison with the held warm start then decides as
#: for every SGD result.  It fires only where the steps were about to fail the fit.
BREAKDOWN_RULE = ("the SGD's steps of epoch {epoch} left a non-finite iterate: the epochs "
                  "stopped there, the result is epoch {last}'s iterate")
#: The same when the breakdown comes inside the iterate averaging's epochs: the result is then
#: the average of the finite epochs it had taken, as it would have been of all of them.
BREAKDOWN_AVERAGED_RULE = ("the SGD's steps of epoch {epoch} left a non-finite iterate: the "
                           "epochs stopped there, the result is the average of epochs "
                           "{first}-{last}'s iterates")


#: The doubt on every projected tilted warm start (:func:`psd_damping_warm_start`) whose
#: lowest measured peak it carries (else :func:`lowest_peak_unpaired`'s statement): the
#: projection is a repair the record did not choose, so ``sgd_sindy`` fits flat too
#: (``MatrixSGDSettings.lowest_peak_flat``) and keeps the model that explains more of its
#: record (:func:`identify._record.record_agreement`) by a clear margin (``sgd_sindy``'s
#: ``SGD_AGREEMENT_RATIO``: a tie is no reason to drop the tilt).  Families' clamped member
#: 009 clean: the projected warm start (a pole at +1304 1/s) explains 0.815 of its record,
#: the SGD from it 0.847 (modes within 0.06 %); flat 0.937 (measured, session 24).  Where the
#: projection is right the comparison keeps it (round 7's ``b_s6`` at 0.5 %, s3: projected
#: TRAC 0.9999, flat 0.64).
PROJECTED_DOUBT = "the projection is a repair the record did not choose"
#: A cubic tilted warm start's growing pole is a damping the record does not resolve where it
#: grows by less than e over the fit window (``max Re(lambda) T < 1``, ``T`` the window's length
#: [s], the free decay's by default): a decay rate finer than ``1 / T`` is below what a record of
#: length ``T`` resolves, so its sign is the noise's and projecting the damping repairs nothing
#: measured.  Round 24's ``b24_soft_r2p7_cf0p45_z0p2`` at 1 % (0.2 % damping): +0.40 1/s over 0.99
#: s (0.40).  Faster growth is a fit the record contradicts; projected there, families' soft 014
#: clean (+5.4e4 1/s) kept a projected fit of 0.785 where the flat fit's refused cubic gave
#: 0.984, and soft 007 clean (+2.9 1/s, 1.45) and 019 clean lost issue #15's 1 % (measured):
#: those keep the flat fit.  A growing pole at a mode a measured peak locates is projected
#: whatever its growth (:func:`growing_mode_located`, session 27: soft 007 clean's is mode 1,
#: and the flat refit, which the projected fit must clearly better, stays kept there; 014's
#: and 019's are real poles).  A linear warm start's damping is projected whatever its growth
#: (round 7's ``b_s6``: +7122 1/s, an indefinite ``C`` on unexcited modes).
UNRESOLVED_GROWTH = 1.0


def growth_unresolved(M: np.ndarray, C: np.ndarray, K: np.ndarray, duration: float) -> bool:
    """Whether the fastest pole of ``M x'' + C x' + K x`` grows by less than e over
    ``duration`` [s] (:data:`UNRESOLVED_GROWTH`); False where the poles cannot be computed or
    are not finite (a singular or non-finite ``M``: review 26f)."""
    try:
        with np.errstate(all="ignore"):
            poles = np.linalg.eigvals(state_matrix(M, C, K))
    except (np.linalg.LinAlgError, ValueError):
        return False
    if not np.all(np.isfinite(poles)):
        return False
    return bool(np.max(poles.real) * duration < UNRESOLVED_GROWTH)


def growing_mode_located(M: np.ndarray, C: np.ndarray, K: np.ndarray, lam_hat: np.ndarray
                         ) -> bool:
    """Whether the fastest-growing pole of ``M x'' + C x' + K x`` is an oscillating mode that a
    measured peak locates: ``|lambda|`` within :data:`~identify.structural.MODE_SEPARATION` of
    one of ``sqrt(lam_hat)`` (the eigenvalue penalty's targets, warped as the fit's signals
    are); False where the poles cannot be computed, no pole grows, the fastest-growing pole is
    real or no peak was measured.

    Rule (with :func:`growth_unresolved`, for a cubic tilted warm start): the record holds that
    mode's ringing at the peak, so a growth there is the fit's damping contradicting a measured
    mode, not a mode the record does not hold, and the damping's projection
    (:func:`psd_damping_warm_start`) repairs the mode the record measures; ``sgd_sindy`` keeps
    the projected fit only where it explains clearly more of its record than the flat refit,
    the cubic warm start's fallback.  Round 24's ``b24_soft_r2p7_cf0p45_z0p2`` (0.2 % damping)
    at 3 %, s152: mode 1's pole +1.52 +328.5j 1/s (growth 1.5 over the window, not under
    :data:`UNRESOLVED_GROWTH`), fitted flat mode 3 72 % off (TRAC 0.493); projected, 0.993,
    the flat refit's 0.493 (measured, session 27).  A real growing pole (families' soft 014
    clean, +5.4e4 1/s; soft 019 clean, +326 1/s) or one at no peak is no located mode: flat as
    before.

    Parameters
    ----------
    M, C, K : ndarray, shape (n, n)
        The warm start's symmetric mass [kg], damping [N s/m] and stiffness [N/m].
    lam_hat : ndarray, shape (k,)
        Measured eigenvalues ``(2 pi f)^2`` [rad^2/s^2].

    Returns
    -------
    bool
    """
    lam_hat = np.asarray(lam_hat, dtype=float).ravel()
    lam_hat = lam_hat[np.isfinite(lam_hat) & (lam_hat > 0)]
    try:
        with np.errstate(all="ignore"):
            poles = np.linalg.eigvals(state_matrix(M, C, K))
    except (np.linalg.LinAlgError, ValueError):
        return False
    if not (lam_hat.size and np.all(np.isfinite(poles))):
        return False
    p = poles[np.argmax(poles.real)]
    if not (p.real > 0.0 and p.imag != 0.0):
        return False
    w, w_peak = abs(p), np.sqrt(lam_hat)
    return bool(np.any(np.abs(w - w_peak) <= MODE_SEPARATION * w_peak))


def psd_damping_warm_start(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> np.ndarray | None:
    """A linear warm start's damping projected onto the positive semi-definite cone, if that
    makes the model physical.

    The rule for a tilted warm start with a growing pole (``fit_tilt`` by rule; the linear
    library, and the cubic one where the growth is one the record does not resolve,
    :func:`growth_unresolved`: a cubic model's poles are its linear part's, which the
    projection acts on alike): the SGD's model has ``C`` positive semi-definite (``finish``
    projects it, :func:`_project_psd`), so the warm start is put in that set before the flat fallback is
    considered; kept tilted when then physical (:func:`identify.structural.check_physical`),
    which it is whenever its symmetric ``M`` and ``K`` are positive definite, and not when the
    growing pole is a negative stiffness (a mode the projection does not reach).  Why:
    ``symmetric_damping``'s least-squares ``C`` leaves the damping of spurious, unexcited modes
    free, and an indefinite ``C`` there grows although every measured mode's frequency and
    damping are sound; the flat fallback then put spurious modes between the peaks (round 7's
    ``b_s6`` at 0.5 % noise, seed 3: tilted warm start modes 23.19 / 145.3 Hz against 23.20 /
    145.24 true, a pole at +7122 1/s from an indefinite ``C``; flat TRAC 0.64; projected,
    TRAC 0.9999).  ``ls_sindy``'s eigenvalue and decay holds on the same warm start leave the
    pole (the spurious modes have no measured peak or taken decay, so their damping is the
    fit's).  The cubic library's tilted warm start was refused and fitted flat without it
    (and still is where it grows faster, :data:`UNRESOLVED_GROWTH`):
    round 24's ``b24_soft_r2p7_cf0p45_z0p2`` (0.2 % damping) at 1 % noise, seed 152, mode 1's
    pole at +0.40 +329j 1/s (damping -0.12 %), the flat fit put mode 3 20 % off its 1256 Hz
    peak (TRAC 0.779); projected and compared with the flat fit as every projected warm start
    is (``PROJECTED_DOUBT``), TRAC 0.994, mode 3 1.6 % off.

    Parameters
    ----------
    M, C, K : ndarray, shape (n, n)
        The warm start's symmetric mass [kg], damping [N s/m] and stiffness [N/m].

    Returns
    -------
    ndarray, shape (n, n), or None
        The projected damping [N s/m], or None when the model stays non-physical.
    """
    C = np.array(C, dtype=float)
    _project_psd(C)
    try:
        check_physical(M, C, K, "the warm start with its damping projected")
    except IdentificationError:
        return None
    return C


def lowest_peak_unpaired(M: np.ndarray, K: np.ndarray, lam_hat: np.ndarray) -> str:
    """Why a warm start does not carry the record's lowest measured peak, or ``""``.

    Rule: a tilted warm start that grew, made physical by projecting its damping
    (:func:`psd_damping_warm_start`), is kept only where the lowest measured peak (the least
    of the eigenvalue penalty's targets ``lam_hat``) has a mode of it within
    :data:`~identify.structural.MODE_SEPARATION` (:func:`eigen_targets`' pairing).  The
    projection answers a growing pole from indefinite damping of modes the record does not
    excite, while the measured modes stand where the peaks are (round 7's ``b_s6``: modes
    23.19 / 145.3 Hz against the peaks).  The tilt (one first difference) weighs the lowest
    mode least, and the flat fit weighs it most: where the lowest peak has no mode near it the
    tilted fit's stiffness may be wrong there, which no damping's projection mends.  The
    statement is a doubt, not a refusal: ``sgd_sindy`` then fits flat too
    (``MatrixSGDSettings.lowest_peak_flat``) and keeps the model that explains more of its
    record.  Round 20's ``b20_soft_r1p2_cf0p3_root2`` (two sensors at 0.1 / 0.2 L on a soft
    base) at 1 %, seed 118: peaks 39.8 / 389.5 Hz, the projected warm start's modes 81.8 /
    283.5 Hz (the SGD from it: mode 1 +213 %, TRAC 0.28); flat, TRAC 0.994, modes 1-2 within
    0.93 % (``ls_sindy``: 0.994).  Flat by this statement alone lost families' stiff 016
    clean (TRAC 0.996 -> 0.944) and ``b20_st_hit0p1`` 3 % s114 (0.857 -> 0.006).  Only the
    lowest: a heavily damped highest peak missed by the projected warm start (round 20 at 5 %,
    s112: ``b20_gf_s4tip``'s 904 Hz, ``b20_soft_r5_hit0p2``'s 1306 Hz) is one the SGD and the
    holds put right from it (flat there: TRAC 0.988 -> 0.702 and 0.990 -> 0.936, measured).
    With no measured peak there is nothing to contradict.

    Parameters
    ----------
    M, K : ndarray, shape (n, n)
        The warm start's mass [kg] and stiffness [N/m] (symmetric).
    lam_hat : ndarray, shape (k,)
        Measured eigenvalues ``(2 pi f)^2`` [rad^2/s^2] (warped as the fit's signals are).

    Returns
    -------
    str
        The statement (the lowest peak and the warm start's modes) or ``""``.
    """
    lam_hat = np.asarray(lam_hat, dtype=float)
    if lam_hat.size == 0:
        return ""
    low = float(np.min(lam_hat))
    if np.any(eigen_targets(M, K, lam_hat, symmetric=True) == low):
        return ""
    modes = modal(M, K)[0]
    return (f"the pairing (within {MODE_SEPARATION:.0%}, closest first) gives no mode of it the "
            f"lowest measured peak "
            f"{np.sqrt(low) / (2.0 * np.pi):.4g} Hz (its modes "
            + ", ".join(f"{f:.4g}" for f in modes) + " Hz): its stiffness, not its damping, "
            "is wrong")


def _physical_placed(sig: list[np.ndarray], m_hat: float, top_hz: float, peaks: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray, str] | str | None:
    """:func:`unresolved_warm_start` on the fit's signals ``sig`` (``[x'', x', x, ...]``),
    if it acts and the model it gives is physical (:func:`identify.structural.check_physical`),
    or is physical with its damping projected (:func:`psd_damping_warm_start`); its statement
    where it refuses to act (:func:`complex_stiffness_pair`); else None."""
    placed = unresolved_warm_start(*sig[:3], m_hat, top_hz, peaks)
    if placed is None or isinstance(placed, str):
        return placed
    try:
        check_physical(*placed[:3], "the warm start with its unresolved modes placed")
    except IdentificationError:
        # a resolved mode's own damping fitted negative (b19_st_s5_hitmid: the 2241 Hz mode,
        # a pole at +4096 +1.35e4j 1/s): the damping's projection, as for the tilted warm
        # start (psd_damping_warm_start), kept when the model is then physical
        C = psd_damping_warm_start(*placed[:3])
        if C is None:
            return None
        return (placed[0], C, placed[2],
                placed[3] + "; the damping then projected onto the positive semi-definite "
                "cone (a resolved mode's damping was fitted negative)")
    return placed


def kept_cubic(K3: np.ndarray | None) -> bool:
    """Whether a warm start's cubic stiffness [N/m^3] has a nonzero entry (its lasso kept an
    ``x^3`` term)."""
    return K3 is not None and bool(np.any(K3 != 0.0))


def fit_window(data: Measurement, fit_duration: float) -> tuple[int, int]:
    """Samples ``[i0, i1)`` of the fit window: from ``data.free_start``, ``fit_duration`` [s]
    long (0 = to the record's end), clipped to the record."""
    i0 = int(data.free_start)
    i1 = data.n_samples if not fit_duration else min(data.n_samples,
                                                     i0 + round(fit_duration * data.fs))
    return i0, i1


def fit_matrix_sgd(data: Measurement, est: MatrixSGDSettings, m_hat: float,
                   lam_hat: np.ndarray,
                   progress: Callable[[float | None, str | None], None] | None = None,
                   peaks: np.ndarray | None = None, with_warm: bool = False,
                   ceiling: np.ndarray | None = None,
                   unresolved: tuple[float, np.ndarray] | None = None) -> MatrixSGDResult:
    """Run the matrix-parametrised SGD.

    Parameters
    ----------
    data : Measurement
        Signals (n channels), sample rate, ``free_start`` and inputs.
    est : MatrixSGDSettings
        The hyperparameters.
    m_hat : float
        Mass prior [kg] that ``trace(M)`` equals.
    lam_hat : ndarray, shape (k,)
        Measured eigenvalues ``(2 pi f)^2`` [rad^2/s^2] the eigenvalue penalty targets; empty
        = no eigenvalue penalty.
    progress : callable, optional
        ``progress(fraction, step)`` after every epoch (e.g. ``Identifier.report_progress``).
    peaks : ndarray, optional
        ``modal_peaks(data).peaks`` [Hz] for the fit band's cut-off if the caller has them
        (:func:`identify.structural.fit_band_cutoff`; not searched again).
    with_warm : bool
        Also return the held warm start (``MatrixSGDResult.warm``): the state the epochs start
        from, finished (hold, projection, nuisance coefficients) exactly as with ``epochs = 0``,
        without fitting it again.  Only with ``init = "lstsq"`` and ``epochs > 0``.
    ceiling : ndarray of bool, shape (k,), optional
        The entries of ``lam_hat`` that bound their modes from above only: the hold
        (``eigen_hold``) moves a mode paired with one down into its band when it lies above,
        and leaves it where it lies below (``hold_eigenvalues``' ``upper_only``; ``sgd_sindy``'s
        ``hardened_peak_rule_``).  The eigenvalue penalty targets them as every peak.  An entry
        ``eigen_backbone`` replaces by its backbone's linear frequency is no longer a peak and
        is held from both sides (``MatrixSGDResult.ceiling_held`` says what was done).
    unresolved : (float, ndarray), optional
        The peak search's band top [Hz] and accepted peaks [Hz]: with ``fit_tilt`` by rule
        and the linear library, a tilted warm start that grows even with its damping projected
        (:func:`psd_damping_warm_start`) is replaced by :func:`unresolved_warm_start`'s, kept
        tilted when that is physical (``MatrixSGDResult.unresolved_rule`` says what was
        placed); None: the rule does not act (flat, as before).

    Returns
    -------
    MatrixSGDResult
    """
    i0, i1 = fit_window(data, est.fit_duration)
    full = [np.asarray(a, dtype=float) for a in (data.xdd, data.xd, data.x)]
    n, N = full[0].shape[0], i1 - i0
    cubic_dir = None
    if est.cubic and est.cubic_form == "direction":  # one cubic feature, K3 = b a^T (below)
        cubic_dir = cubic_direction(full[2][:, i0:i1])
        full.append(np.vstack([cubic_feature(full[2], cubic_dir)[None, :],
                               np.zeros((n - 1, full[2].shape[1]))]))
    elif est.cubic:
        full.append(full[2] ** 3)
    # the force (every row, M B in full) and the chain's integration constants enter with free
    # coefficients: profiled out of every feature (project_out), recovered after the fit
    inputs = nuisance_basis(data, i0, i1)[1]  # the inputs nonzero in the window
    W = nuisance_basis(data, 0, data.n_samples, inputs)[0]
    # the fit band (identify.structural.fit_band): one zero-phase high-pass on every feature,
    # target and nuisance column over the whole record, then the window
    fc = fit_band_cutoff(data, est.fit_band_hz, peaks)[0]
    if fc > 0:
        full = [elliptic_highpass(a, data.fs, fc, FIT_BAND_ORDER) for a in full]
        W = elliptic_highpass(W.T, data.fs, fc, FIT_BAND_ORDER).T if W.shape[1] else W
    raw = [a[:, i0:i1] for a in full]
    W_record = W[:i1]  # from the record's start (the impact pulse) to the window's end
    W = np.ascontiguousarray(W[i0:i1])
    n_u = inputs.size
    l1_on = est.cubic and est.l1

    def fit_signals(tilt: bool) -> list[np.ndarray]:
        """The window's features with the nuisance columns profiled out, tilted or flat."""
        rows = tilt_rows(*raw, W.T) if tilt else [*raw, W.T]
        return project_out(np.ascontiguousarray(rows[-1].T), *rows[:-1])

    def start(sig: list[np.ndarray]) -> tuple:
        """The warm start (or zero start) on ``sig``, and the cubic profile."""
        x3_ = sig[3] if est.cubic else None
        pr_ = cubic_profile(*sig[:3], x3_) if est.cubic else None
        if est.init != "lstsq":
            return (np.eye(n) * m_hat / n, np.zeros((n, n)), np.zeros((n, n)),
                    np.zeros((n, n)) if est.cubic else None), pr_
        return warm_start(*sig[:3], x3_, m_hat, float(est.l1_threshold) if l1_on else 0.0,
                          pr_), pr_

    # the fit band's tilt (identify.structural.FIT_TILT_DIFFERENCES, ls_sindy's rule, the
    # cubic library's too): every feature, target and nuisance column differenced once; flat
    # when the tilted warm start has a growing mode
    if est.fit_tilt is False:
        tilted = False
        tilt_rule = "fit_tilt = False (user setting)"
    else:
        tilted = True
        tilt_rule = (f"{FIT_TILT_DIFFERENCES} first difference of every row "
                     + ("(user setting)" if est.fit_tilt else "(rule)"))
    sig = fit_signals(tilted)
    (M0, C0, K0, K30), pr = start(sig)
    unresolved_rule = lowest_unpaired = ""
    if tilted and est.init == "lstsq":
        try:
            check_physical(M0, C0, K0, "the warm start's least squares")
        except IdentificationError as e:
            if est.fit_tilt:  # the user's choice: refused, not replaced
                raise
            # a cubic warm start's damping is projected only where its growth is one the
            # record does not resolve (UNRESOLVED_GROWTH); a linear one's whatever its growth
            # (over the fit window the warm start was fitted on: the whole free decay by
            # default, fit_duration's where set: review 26f)
            # (or where the growing pole is a mode a measured peak locates: the record holds
            # its ringing, growing_mode_located)
            C_psd = (psd_damping_warm_start(M0, C0, K0) if not est.cubic or growth_unresolved(
                M0, C0, K0, (i1 - i0) / float(data.fs))
                or growing_mode_located(M0, C0, K0, lam_hat) else None)
            unpaired = "" if C_psd is None else (lowest_peak_unpaired(M0, K0, lam_hat)
                                                 or PROJECTED_DOUBT)
            if unpaired and est.lowest_peak_flat:  # the caller's second fit: flat
                C_psd = None
            elif unpaired:  # kept; the caller fits flat too and compares (sgd_sindy.fit)
                lowest_unpaired = unpaired
            placed = (None if est.cubic or C_psd is not None or unresolved is None
                      else _physical_placed(sig, m_hat, *unresolved))
            if isinstance(placed, str):  # the placement's stated refusal
                unresolved_rule, placed = placed, None
            if C_psd is not None:
                C0 = C_psd
                tilt_rule = (f"rule: the tilted warm start had a growing pole ({e}); kept with "
                             "its damping projected onto the positive semi-definite cone "
                             "(physical then)")
            elif placed is not None:
                # ls_sindy's step 5 (identify._unresolved): a mode whose pole reaches past the
                # peak band's top is placed there (round 16's b16_ti_n32_s5, five sensors at
                # 12.8 kHz: mode 5 fitted with a negative stiffness; flat, the SGD diverged,
                # TRAC 4.6e-8; placed, 0.9946)
                M0, C0, K0, unresolved_rule = placed
                tilt_rule = (f"rule: the tilted warm start had a growing pole ({e})"
                             # (the caller's second fit: the projection did make it physical)
                             + (f"; with its damping projected it is physical, but {unpaired}: "
                                "refused" if unpaired else
                                ", not removed by projecting its damping")
                             + "; kept with its unresolved modes placed (physical then)")
            else:
                tilted = False
                tilt_rule = f"rule: the tilted warm start was refused ({e}); fitted flat"
                if unpaired:
                    tilt_rule += ("; with its damping projected it is physical, but "
                                  + unpaired)
                sig = fit_signals(False)
                (M0, C0, K0, K30), pr = start(sig)
    if (not tilted and est.cubic and est.fit_tilt is None and est.init == "lstsq"
            and not kept_cubic(K30)):
        # The tilted cubic warm start was refused.  A flat warm start whose lasso kept no x^3
        # term is a linear model: its linear columns are fitted again tilted (the linear rule;
        # the x^3 columns the lasso removed stay out, K3 = 0 and off the SGD's support), unless
        # that is non-physical.  Measured on soft-base member 015 (studies/families.toml,
        # clean, cubic = true), when the cubic library was fitted flat by rule: the flat fit
        # gave a 0 Hz and a 448 Hz (zeta 0.26) mode for 55.6 and 562.6 Hz true (TRAC 0.0003).
        sig_t = fit_signals(True)
        M1, C1, K1, _ = warm_start(*sig_t[:3], None, m_hat)
        try:
            check_physical(M1, C1, K1, "the warm start's least squares")
            why = None
        except IdentificationError as e:
            why = str(e)
        if why is None:
            tilted, sig = True, sig_t
            (M0, C0, K0, K30), pr = (M1, C1, K1, np.zeros((n, n))), cubic_profile(*sig_t[:4])
            tilt_rule += (f"; the flat warm start kept no x^3 term (a linear model): its linear "
                          f"columns fitted with {FIT_TILT_DIFFERENCES} first difference of every "
                          f"row")
        else:
            tilt_rule += f" (the flat warm start kept no x^3 term; tilted refused: {why})"
    xdd, xd, x = sig[:3]
    x3 = sig[3] if est.cubic else None
    bu = np.zeros_like(x)  # the force is in W
    # parameter scales (Adam steps are relative to these)
    m0 = m_hat / n
    if est.init == "lstsq":
        # K on the lowest mode's scale.  Adam moves every standardised entry by about
        # ``learning_rate`` per step whatever its gradient; with K scaled by its largest
        # diagonal entry (the highest mode's stiffness) a step moved the lowest eigenvalue by
        # up to ``learning_rate * lambda_max / lambda_min`` relatively (x 1100 on 4-sensor
        # beams), and 100 epochs walked 2-4-sensor beams of the beams family 10-60 % off
        # their modes (TRAC 0.97 -> 0.02-0.4, measured).  With the lowest mode's stiffness
        # ``m0 lambda_1`` as the scale a step moves every mode by at most about
        # ``learning_rate`` relatively.  C keeps its largest diagonal entry: scaled by the
        # lowest mode's damping the damping could not follow the data (3 % noise two-sensor
        # beam, damping error 0.68 against 0.35 with the largest entry; measured while the
        # frequencies were held every epoch).
        try:
            lam_min = float(linalg.eigh(_sym(K0), _sym(M0), eigvals_only=True)[0])
        except np.linalg.LinAlgError:  # M0 not positive definite to rounding (a 140-sample
            lam_min = 0.0  # free decay through 5 sensors): the stiffness diagonal's scale
        k0 = max(m0 * lam_min, 1e-12) if lam_min > 0 else max(np.abs(np.diag(K0)).max(), 1e-12)
        c0 = max(np.abs(np.diag(C0)).max(), 1e-12)
    else:  # the data's own scales, as standardised features have: K ~ M x''/x, C ~ M x''/x'
        k0 = m0 * float(np.max(_rms(xdd) / _rms(x)))
        c0 = m0 * float(np.max(_rms(xdd) / _rms(xd)))
    L = np.linalg.cholesky(M0 / m0)
    P, Q = K0 / k0, C0 / c0
    s_a = _rms(xdd)
    sc3, R, lam_l1 = 1.0, None, 0.0
    if pr is not None:  # standardised cubic coefficients (module docstring, L1 item 1)
        sc3 = (np.diag(M0) * s_a)[:, None] / pr["s3"][None, :]
        R = K30 / sc3 if K30 is not None else np.zeros((n, n))
        if l1_on:  # per-entry lasso weight: partial correlation above l1_threshold (L1 item 2)
            lam_l1 = (2.0 / n) * float(est.l1_threshold) * np.outer(pr["rho"], pr["sigma"])
    from identify import _compiled as cc  # lazy: numba's import costs ~0.4 s

    gradient = est.gradient
    # features z = [x'', x', x, x^3, -B u] per sample (N, 5n): the residual of row i is T_i z;
    # the whole window's loss and gradient follow from its second moments (cc.window_loss_grad)
    Z = np.ascontiguousarray(np.vstack([xdd, xd, x, x3 if x3 is not None else np.zeros_like(x), -bu]).T)
    nfa = int(np.flatnonzero(np.any(Z != 0.0, axis=0)).max(initial=-1)) + 1  # trailing zero columns
    S_full = Z.T @ Z
    Nz = Z.shape[0]  # the window's samples, one fewer per difference of the tilt
    L = np.ascontiguousarray(L)
    P, Q = np.ascontiguousarray(P), np.ascontiguousarray(Q)
    has_R = R is not None
    R = np.ascontiguousarray(R) if has_R else np.zeros((n, n))
    sc3 = np.broadcast_to(sc3, (n, n)).astype(float) if has_R else np.zeros((n, n))
    s_a = np.ascontiguousarray(s_a)
    cc.project(L, P, Q, R, m0, m_hat)
    # the target of each mode (ascending; 0 = none), paired on the current modes (eigen_targets)
    lam_meas = lam_peaks = np.asarray(lam_hat, dtype=float)
    moved = np.zeros(lam_meas.size, bool)
    cross_meas = np.zeros(lam_meas.size)  # the cross stiffening taken off each target
    ceiling = (np.zeros(lam_meas.size, bool) if ceiling is None
               else np.asarray(ceiling, dtype=bool).reshape(lam_meas.shape))
    backbone_rule = "eigen_backbone = False" if not est.eigen_backbone else (
        "no cubic library" if not est.cubic else "no measured peak")
    if est.cubic and est.eigen_backbone and lam_meas.size:
        if K30 is None or not np.any(K30 != 0.0):
            backbone_rule = "the warm start kept no cubic term: the peaks"
        else:
            lam_meas, moved, backbone_rule = backbone_targets(data, M0, C0, K0, (i0, i1),
                                                              lam_meas, K30, cross_meas)
            lam_peaks = np.sort(lam_peaks)
    target = eigen_targets(m0 * (L @ L.T), k0 * _sym(P), lam_meas, True)
    lam_hat = np.ascontiguousarray(target)
    hold = bool(est.eigen_hold) and bool(np.any(target > 0))
    # the peaks bounding from above only: those the backbone left peaks (matched by value below:
    # eigen_targets returns lam_meas's own entries, so the comparison is exact)
    ceiling_values = lam_meas[ceiling & ~moved]
    # A spectral peak of the window locates its mode to about one line of the window's
    # transform (fs / N): the leakage of the neighbouring modes and the damping move the peak
    # of a decaying response by a fraction of a line.  Within that band the data decide.
    band = float(data.fs) / N
    adam = (np.zeros((4, n, n)), np.zeros((4, n, n)), np.zeros((4, n, n)))  # m, v, step size
    use_eig, use_l1 = bool(np.any(target > 0)), has_R and l1_on
    lam_l1 = np.broadcast_to(lam_l1, (n, n)).astype(float)
    alpha = {"sym": float(est.alpha_init), "eig": float(est.alpha_init),
             "l1": float(np.max(lam_l1)) if use_l1 else 0.0}
    l1_epochs = int(np.ceil((1.0 - float(est.l1_debias)) * int(est.epochs))) if use_l1 else 0  # item 6
    # the cubic terms still in play: the warm start's lasso has already rejected the others
    # (L1 item 3); after the lasso epochs, the terms kept, frozen for the debiasing epochs
    support = (R != 0).astype(float) if use_l1 and est.init == "lstsq" else None
    hist: dict[str, list[float]] = {k: [] for k in (
        "epoch", "n_steps", "loss_data", "loss_sym", "loss_eig", "loss_l1", "mass_residual",
        "alpha_sym", "alpha_eig", "alpha_l1")}
    g = np.empty((4, n, n))
    T, TS, e2 = np.empty((n, 5 * n)), np.empty((n, 5 * n)), np.empty(n)
    eL, eP = np.empty((n, n)), np.empty((n, n))

    def record(epoch, n_steps):
        """History row; returns the full-window data gradient (for annealing)."""
        loss = cc.window_loss_grad(S_full, Nz, L, P, Q, R, m0, c0, k0, sc3, s_a, T, TS, e2, *g)
        le = cc.eig_loss_grad(L, P, m0, k0, lam_hat, eL, eP) if use_eig else np.nan
        hist["epoch"].append(epoch)
        hist["n_steps"].append(n_steps)
        hist["loss_data"].append(float(loss))
        hist["loss_sym"].append(0.0)
        hist["loss_eig"].append(float(le))
        hist["loss_l1"].append(float(np.sum(np.abs(R))) if use_l1 else np.nan)  # standardised
        hist["mass_residual"].append(m0 * float(np.sum(L * L)) / m_hat - 1.0)
        for k in alpha:
            hist[f"alpha_{k}"].append(alpha[k])
        return g if has_R else g[:3]

    rng = np.random.default_rng(est.random_state)
    bs = int(est.batch_size) if gradient == "minibatch" else 0
    spe = (int(est.steps_per_epoch) if est.steps_per_epoch is not None
           else (int(np.ceil(Nz / bs)) if bs else 1))
    eps_eig = float(est.epsilon)
    # A passive structure held at its base has C positive semi-definite (it dissipates) and K
    # positive semi-definite (no static divergence); with M = m0 L L^T positive definite the
    # linear model is then stable.  K is projected onto the cone after the warm start and after
    # every epoch (the steps themselves run compiled); C after the last epoch only: projecting
    # C every epoch redirected the path on the 5 %-noise stiff beam (MAC 0.98 -> 0.89,
    # measured) while the end state's C was already positive semi-definite there.  The most
    # negative eigenvalue removed, relative to the largest, is reported per matrix.
    guard: dict[str, float] = {}
    clipped = _project_psd(P)
    if clipped < 0:
        guard["K"] = clipped
    # The measured frequencies are held, not only pulled toward: the annealed penalty with its
    # weight capped at alpha_max let the data loss walk mode 2 10-60 % off a correctly
    # measured peak (2-sensor beams of the beams family) and 2 % off on the 3 %-noise
    # two-sensor beam (measured).  The penalty's targets are re-paired on the current modes
    # (eigen_targets) every epoch; the result's paired eigenvalues are then moved into their
    # peaks' bands (hold_eigenvalues).  Only the result: holding every epoch fought the data
    # loss along the flat modal-mass directions (stiff beam: Mr error 0.07 -> 0.32, measured).
    record(0, 0)
    n_steps = 0
    # the held warm start: the state the epochs start from, finished as epochs = 0 would
    # (copies: the steps, the hold and the projections work in place)
    warm = ((L.copy(), P.copy(), Q.copy(), R.copy(), target.copy()), dict(guard), dict(alpha)
            ) if with_warm and est.init == "lstsq" and int(est.epochs) > 0 else None
    no_support = np.zeros((n, n))
    # Iterate averaging (Polyak-Ruppert) over the last ``iterate_average`` of the epochs, and
    # never before the debiasing stage starts: Adam's steps leave the last iterate jittering
    # about the optimum by about the step size, and which side it ends on depends on the
    # mini-batch order (stiffer soft base: TRAC 0.80 / 0.96 for seeds 0 / 1, last iterate).
    # Averaging the epoch-end iterates (M as L L^T, whose mean stays positive definite with
    # trace m_hat) removed most of it (measured, seed 0: stiffer soft base TRAC 0.956, two
    # sensors at 3 % noise 0.80 -> 0.97, stiff beam 0.986 -> 0.995).  A quarter: averaging
    # half the epochs lagged the cubic block (soft base cubic force error 0.062 -> 0.099).
    frac = est.iterate_average
    avg_from = max(int(np.ceil(int(est.epochs) * (1.0 - frac))), l1_epochs) + 1 if frac > 0 else None
    acc = [np.zeros((n, n)) for _ in range(4)]
    n_acc = 0
    broke_at = 0  # the epoch whose steps left a non-finite iterate (BREAKDOWN_RULE), 0: none
    last = [a.copy() for a in (L, P, Q, R)]  # the last epoch's finite iterate (BREAKDOWN_RULE)
    for epoch in range(1, int(est.epochs) + 1):
        if progress is not None:
            progress((epoch - 1) / int(est.epochs), f"epoch {epoch}/{int(est.epochs)}")
        perm = rng.permutation(Nz) if bs else np.arange(0)
        cc.sgd_steps(Z, nfa, S_full, Nz, perm, bs, spe, (L, P, Q, R), adam, n_steps,
                     float(est.learning_rate), m0, c0, k0, sc3, s_a, lam_hat,
                     alpha["eig"] * eps_eig if use_eig else 0.0, has_R,
                     support if support is not None else no_support, support is not None,
                     lam_l1, use_l1 and epoch <= l1_epochs, float(m_hat))
        if not all(np.isfinite(a).all() for a in (L, P, Q, R)):
            for a, b in zip((L, P, Q, R), last, strict=True):
                a[...] = b
            broke_at = epoch
            break
        n_steps += spe
        clipped = _project_psd(P)  # K: positive semi-definite by construction, per epoch
        if clipped < 0:
            guard["K"] = min(guard.get("K", 0.0), clipped)
        if use_l1 and epoch == l1_epochs and epoch < int(est.epochs):  # L1 item 6: debias
            support = (R != 0).astype(float)
            alpha["l1"] = 0.0
        # history and annealing see the epoch's end before the hold (after it the eigenvalue
        # residual is 0 and Eq. 17 would have nothing to measure): loss_eig is how far the
        # epoch's steps moved the held frequencies
        g_data = record(epoch, n_steps)
        if est.anneal:  # Eqs 17-18, capped
            gmax = float(np.max(np.abs(g_data)))
            if use_eig:
                ge = np.abs(eps_eig * np.concatenate([eL.ravel(), eP.ravel()]))
                if ge.mean() > 0:
                    hat = gmax / ge.mean()
                    alpha["eig"] = min((1 - est.beta) * alpha["eig"] + est.beta * hat, float(est.alpha_max))
        if use_eig:  # re-paired on this epoch's modes; the compiled penalty reads lam_hat
            target = eigen_targets(m0 * (L @ L.T), k0 * _sym(P), lam_meas, True)
            lam_hat[:] = target
        if avg_from is not None and epoch >= avg_from:
            for a_, v_ in zip(acc, (L @ L.T, P, Q, R), strict=True):
                a_ += v_
            n_acc += 1
        for a, b in zip(last, (L, P, Q, R), strict=True):
            a[...] = b
    if n_acc:
        LLt, P, Q, R = (a_ / n_acc for a_ in acc)
        L = np.linalg.cholesky(_sym(LLt))
    stop_rule = ("" if not broke_at else
                 BREAKDOWN_AVERAGED_RULE.format(epoch=broke_at, first=avg_from, last=broke_at - 1)
                 if n_acc else BREAKDOWN_RULE.format(epoch=broke_at, last=broke_at - 1))

    def finish(L: np.ndarray, P: np.ndarray, Q: np.ndarray, R: np.ndarray, target: np.ndarray,
               guard: dict[str, float], n_steps: int, alpha: dict[str, float],
               hist: dict[str, np.ndarray]) -> MatrixSGDResult:
        """The result from the parameters ``L, P, Q, R`` (changed in place): the eigenvalue
        hold, the damping's projection, the physical matrices and the nuisance coefficients;
        ``target`` the modes' targets when nothing is held."""
        held, rule = 0.0, backbone_rule
        upper = np.zeros(0, bool)
        if hold:
            target = eigen_targets(m0 * (L @ L.T), k0 * _sym(P), lam_meas, True)
            upper = (target > 0) & np.isin(target, ceiling_values)
            held = hold_eigenvalues(L, P, m0, k0, target, band, upper)
        if hold and np.any(moved) and not np.any(R != 0.0):
            # the cubic was dropped: a linear model at the linear frequencies oscillates below
            # the record at its large amplitudes, so the moved modes go onto their peaks
            on = np.isin(eigen_targets(m0 * (L @ L.T), k0 * _sym(P), lam_meas, True),
                         lam_meas[moved])
            back = np.where(on, eigen_targets(m0 * (L @ L.T), k0 * _sym(P), lam_peaks, True),
                            0.0)
            held = max(held, hold_eigenvalues(L, P, m0, k0, back, 0.0))
            target = np.where(back > 0, back, target)
            rule += "; the SGD dropped every cubic term: those modes put onto their peaks"
        clipped = _project_psd(Q)  # C: projected once, at the end (see above)
        if clipped < 0:
            guard["C"] = min(guard.get("C", 0.0), clipped)
        M = m0 * (L @ L.T)
        C, K = c0 * _sym(Q), k0 * _sym(P)
        K3 = sc3 * R if has_R else None
        if K3 is not None and cubic_dir is not None:  # b (a . x^3): the column's coefficients
            K3 = np.outer(K3[:, 0], cubic_dir ** 3)
        # the free coefficients of the nuisance columns, from the unprojected residual
        K3f = None if K3 is None else (sc3 * R if cubic_dir is not None else K3)  # on features

        def nuisance_coef(sig: list[np.ndarray], Wn: np.ndarray) -> np.ndarray:
            """The nuisance columns' coefficients (n, p) fitting the model's residual on
            ``sig``."""
            if not Wn.shape[1]:
                return np.zeros((n, 0))
            res = (M @ sig[0] + C @ sig[1] + K @ sig[2]
                   + (K3f @ sig[3] if K3f is not None else 0.0))
            sw = _rms(Wn, 0)
            return (np.linalg.lstsq(Wn / sw[None, :], res.T, rcond=NUISANCE_RCOND)[0]
                    / sw[:, None]).T

        G = nuisance_coef(raw, W)
        input_map = None if data.input_map is None else np.array(data.input_map, dtype=float)
        input_map_record = None
        if input_map is not None:
            input_map[:, inputs] = G[:, :n_u]
            if n_u and i0 > 0:
                input_map_record = input_map.copy()
                input_map_record[:, inputs] = nuisance_coef([a[:, :i1] for a in full],
                                                            W_record)[:, :n_u]
        return MatrixSGDResult(M=_sym(M), C=C, K=K, K3=K3, n_steps=n_steps, alphas=alpha,
                               guard=guard, history=hist,
                               input_map=input_map, drift_coef=G[:, n_u:],
                               eigen_targets=np.sqrt(target) / (2.0 * np.pi), eigen_shift=held,
                               eigen_cross=np.array([cross_meas[lam_meas == t][0]
                                                     if t > 0 and np.any(lam_meas == t) else 0.0
                                                     for t in np.ravel(target)]),
                               fit_tilt=tilted, fit_tilt_rule=tilt_rule,
                               input_map_record=input_map_record, backbone_rule=rule,
                               ceiling_held=bool(np.any(upper)),
                               unresolved_rule=unresolved_rule,
                               lowest_peak_unpaired=lowest_unpaired)

    out = dataclasses.replace(finish(L, P, Q, R, target, guard, n_steps, alpha,
                                     {k: np.asarray(v) for k, v in hist.items()}),
                              stop_rule=stop_rule)
    if warm is None:
        return out
    (L0, P0, Q0, R0, target0), guard0, alpha0 = warm
    return dataclasses.replace(out, warm=finish(L0, P0, Q0, R0, target0, guard0, 0, alpha0,
                                                {k: v[:1] for k, v in out.history.items()}))
