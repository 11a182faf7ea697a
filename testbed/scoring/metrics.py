"""Scores of an identified model against the truth, as /work/shared/reference/metrics.md defines.

Metrics take arrays, never rigs or identifiers.  Signals are ``(n_channels, n_samples)``;
mode-shape matrices hold one mode per column, ``(n_dof, n_modes)``.
"""

from __future__ import annotations

import numpy as np

from testbed.core.lazy import lazy_module
from testbed.numerics.shapes import mac_matrix as mac_matrix  # re-exported: the scorers' name
from testbed.numerics.shapes import modal_from_matrices as modal_from_matrices  # re-exported
from testbed.numerics.shapes import trac as trac  # re-exported: the scorers' name

# imported on first use: `testbed list` does not pay for them
linalg = lazy_module("scipy.linalg")
optimize = lazy_module("scipy.optimize")


def worst(values, how: str) -> float:
    """The worst of some scores, NaN if any is NaN (or if there are none).

    The one reduction of scores to a verdict: Python's ``max``/``min`` drop a NaN that is
    not first (``max(1.0, nan)`` is 1.0) and ``np.nanmax`` drops every NaN, so a mode that
    could not be scored would vanish from its aggregate and the aggregate could pass.

    Parameters
    ----------
    values : array_like or iterable of float
        Scores (any shape; a generator is consumed).
    how : {"max", "min"}
        ``"max"`` for errors (larger is worse), ``"min"`` for agreements such as MAC or TRAC
        (smaller is worse).

    Returns
    -------
    float
        ``max`` or ``min`` of ``values``; NaN if any value is NaN or ``values`` is empty.
        Infinities are ordinary values (an infinite error is the worst error).
    """
    if how not in ("max", "min"):
        raise ValueError(f"how must be 'max' or 'min', got {how!r}")
    if not isinstance(values, np.ndarray):
        values = list(values)
    a = np.asarray(values, dtype=float)
    if a.size == 0 or np.any(np.isnan(a)):
        return float("nan")
    return float(np.max(a) if how == "max" else np.min(a))


#: A pair's cost beyond which it is no match (a MAC of 0, or frequencies a factor e = 2.72
#: apart): every such pair costs alike in the assignment (ordered among themselves by
#: ``NO_MATCH_SLOPE`` times their cost), so modes no identified mode resolves (a 1 kHz true mode
#: on a model whose highest mode is 306 Hz) cannot pull a well-matched partner away from a mode
#: it matches.
NO_MATCH_COST = 1.0
NO_MATCH_SLOPE = 1.0e-6


def pair_modes(mac: np.ndarray, f_a: np.ndarray | None = None,
               f_b: np.ndarray | None = None) -> np.ndarray:
    """Pair modes one to one: by shape and frequency, or by shape alone.

    Parameters
    ----------
    mac : ndarray, shape (n_a, n_b)
        E.g. ``mac_matrix(phi_true, phi_id)``.
    f_a, f_b : ndarray, shape (n_a,) and (n_b,), optional
        The modes' natural frequencies [Hz].  Given both, a pair costs its shape mismatch plus
        its frequency mismatch, ``c = (1 - MAC) + |ln(f_b / f_a)|`` (both relative: a MAC short
        of 1 by 0.01 weighs as a 1 % frequency offset), capped at :data:`NO_MATCH_COST`
        (``min(c, 1) + 1e-6 c``), and the pairing minimises the summed cost.  Without them it
        maximises the summed MAC.

    Returns
    -------
    ndarray of int, shape (n_a,)
        ``pair[i]`` is the column paired with row ``i``, or -1 where ``n_a > n_b`` leaves row
        ``i`` unpaired.  The assignment is global (``scipy.optimize.linear_sum_assignment``), so
        two modes never claim the same partner, unlike a row-wise argmax.  NaN MAC entries
        count as 0; a frequency that is not finite and positive (an unstable identified mode)
        is no match.

    Notes
    -----
    Why frequencies too: with few sensors the shapes of different modes look alike (MAC
    0.96-0.98 between a soft-based beam's modes 1 and 2 on three sensors), and the summed MAC
    alone then trades a well-paired scored mode for a poorly resolved higher one: on such a beam
    it paired true mode 1 (28.1 Hz) with an identified 74 Hz overdamped pole pair although an
    identified 28.6 Hz mode matched its shape with MAC 1.000, and reported a 164 % frequency
    error for a 2 % one.  The frequency term makes the pairing what a modal analyst would draw
    by hand: each true mode with the identified mode nearest in shape and frequency.  The cap
    keeps a true mode that nothing resolves from bidding: uncapped, the beam's 1 kHz mode 3
    took the 306 Hz mode from true mode 2 (1 kHz lies 2.6 from 74 Hz in log-distance, 1.2 from
    306 Hz).
    """
    mac = np.nan_to_num(np.asarray(mac, dtype=float), nan=0.0)
    if mac.ndim != 2:
        raise ValueError(f"expected a 2-D MAC matrix, got shape {mac.shape}")
    if f_a is None or f_b is None:
        rows, cols = optimize.linear_sum_assignment(mac, maximize=True)
    else:
        fa, fb = np.asarray(f_a, dtype=float), np.asarray(f_b, dtype=float)
        if fa.shape != (mac.shape[0],) or fb.shape != (mac.shape[1],):
            raise ValueError(f"frequencies of shapes {fa.shape} and {fb.shape} do not match the "
                             f"MAC matrix {mac.shape}")
        with np.errstate(divide="ignore", invalid="ignore"):
            shift = np.abs(np.log(fb[None, :] / fa[:, None]))
        cost = (1.0 - mac) + np.where(np.isfinite(shift), shift, 1.0 / NO_MATCH_SLOPE)
        cost = np.minimum(cost, NO_MATCH_COST) + NO_MATCH_SLOPE * cost
        rows, cols = optimize.linear_sum_assignment(cost)
    pair = np.full(mac.shape[0], -1, dtype=int)
    pair[rows] = cols
    return pair


def frequency_error(f_id: np.ndarray, f_true: np.ndarray) -> np.ndarray:
    """Relative natural-frequency error of paired modes, ``|f_id - f_true| / f_true``.

    Parameters
    ----------
    f_id, f_true : ndarray, shape (n_modes,)
        Paired frequencies [Hz] (pair first, e.g. with :func:`pair_modes`).

    Returns
    -------
    ndarray, shape (n_modes,)
        Dimensionless; inf where ``f_true`` is 0 and ``f_id`` is not, NaN where both are 0.
    """
    f_id, f_true = np.asarray(f_id, dtype=float), np.asarray(f_true, dtype=float)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.abs(f_id - f_true) / np.abs(f_true)


def damping_error(z_id: np.ndarray, z_true: np.ndarray) -> np.ndarray:
    """Relative damping-ratio error of paired modes, ``|z_id - z_true| / z_true``.

    Parameters
    ----------
    z_id, z_true : ndarray, shape (n_modes,)
        Paired damping ratios [-].

    Returns
    -------
    ndarray, shape (n_modes,)
        Dimensionless; undefined (inf/NaN) for an undamped true mode.
    """
    return frequency_error(z_id, z_true)


def relative_error(a_id: np.ndarray, a_true: np.ndarray) -> float:
    """Relative Frobenius error ``||A_id - A_true||_F / ||A_true||_F``.

    Parameters
    ----------
    a_id, a_true : ndarray, same shape
        Matrices (M, C, K, K3, ...) in the same coordinates and units.

    Returns
    -------
    float
        Dimensionless.  If ``A_true`` is zero: 0.0 when ``A_id`` is zero too, else inf.
    """
    a_id, a_true = np.asarray(a_id, dtype=float), np.asarray(a_true, dtype=float)
    if a_id.shape != a_true.shape:
        raise ValueError(f"shapes differ: {a_id.shape} vs {a_true.shape}")
    # both scaled by the power of two that brings A_true's largest magnitude into [0.5, 1):
    # exact for normal numbers (the ratio keeps every bit), while a true C of 1e-297 no longer
    # underflows in its sum of squares (round 9: damping_ratio = 1e-300 gave ||Cr|| = 0 and
    # Cr_error, MinvC_error inf by that 0 alone)
    peak = float(np.max(np.abs(a_true))) if a_true.size else 0.0
    e = int(np.frexp(peak)[1]) if np.isfinite(peak) else 0
    with np.errstate(over="ignore", invalid="ignore"):
        num = np.linalg.norm(np.ldexp(a_id, -e) - np.ldexp(a_true, -e))
    den = np.linalg.norm(np.ldexp(a_true, -e))
    if den == 0:
        return 0.0 if num == 0 else float("inf")
    return float(num / den)


def cross_orthogonality(phi_id: np.ndarray, phi_true: np.ndarray, m: np.ndarray) -> np.ndarray:
    """Mass-weighted cross-orthogonality ``Phi_id^H M Phi_true`` of mass-normalised modes.

    Parameters
    ----------
    phi_id : ndarray, shape (n_dof, n_id)
        Identified mode shapes (any scaling; they are mass-normalised here).
    phi_true : ndarray, shape (n_dof, n_true)
        True mode shapes (any scaling).
    m : ndarray, shape (n_dof, n_dof)
        The known mass matrix [kg] in the same coordinates.

    Returns
    -------
    ndarray, shape (n_id, n_true)
        The identity for a perfect identification.  Each identified mode's sign is flipped so
        that its diagonal entry (same index) is nonnegative; off the diagonal compare absolute
        values.
    """
    m = np.asarray(m)

    def normalise(phi: np.ndarray) -> np.ndarray:
        phi = np.asarray(phi)
        phi = phi[:, None] if phi.ndim == 1 else phi
        scale = np.sqrt(np.real(np.einsum("ij,ik,kj->j", np.conj(phi), m, phi)))
        if np.any(~(scale > 0)):
            raise ValueError("a mode shape has zero or negative modal mass; is M positive definite?")
        return phi / scale

    a, b = normalise(phi_id), normalise(phi_true)
    xo = np.conj(a).T @ m @ b
    k = min(xo.shape)
    d = np.diag(xo)[:k]
    flip = np.ones(xo.shape[0])
    flip[:k] = np.where(np.real(d) < 0, -1.0, 1.0)
    return flip[:, None] * xo


def support_scores(coef_id: np.ndarray, coef_true: np.ndarray, tol: float = 0.0) -> dict[str, float]:
    """Precision, recall and F1 of the identified nonzero pattern.

    Parameters
    ----------
    coef_id, coef_true : ndarray, same shape
        Coefficient arrays; an entry counts as nonzero when ``|c| > tol``.
    tol : float
        Magnitude at or below which a coefficient counts as zero.

    Returns
    -------
    dict
        ``precision = tp / (tp + fp)``, ``recall = tp / (tp + fn)``,
        ``f1 = 2 p r / (p + r)``, and the counts ``tp``, ``fp``, ``fn``.
        Degenerate cases: no true and no identified nonzeros is a perfect answer (all 1.0);
        no identified nonzeros against some true ones gives precision 0 and recall 0;
        some identified nonzeros against no true ones gives precision 0 and recall 0;
        F1 is 0 whenever precision + recall is 0.
    """
    ci, ct = np.asarray(coef_id, dtype=float), np.asarray(coef_true, dtype=float)
    if ci.shape != ct.shape:
        raise ValueError(f"shapes differ: {ci.shape} vs {ct.shape}")
    pi, pt = np.abs(ci) > tol, np.abs(ct) > tol
    tp, fp, fn = int(np.sum(pi & pt)), int(np.sum(pi & ~pt)), int(np.sum(~pi & pt))
    if tp + fp + fn == 0:
        return {"precision": 1.0, "recall": 1.0, "f1": 1.0, "tp": 0, "fp": 0, "fn": 0}
    precision = tp / (tp + fp) if tp + fp else 0.0
    recall = tp / (tp + fn) if tp + fn else 0.0
    f1 = 2 * precision * recall / (precision + recall) if precision + recall else 0.0
    return {"precision": precision, "recall": recall, "f1": f1, "tp": tp, "fp": fp, "fn": fn}


def coefficient_error(coef_id: np.ndarray, coef_true: np.ndarray) -> float:
    """Largest relative error over the true terms, ``max_k |c_id,k - c_true,k| / |c_true,k|``.

    Parameters
    ----------
    coef_id, coef_true : ndarray, same shape
        Coefficients in the same library and units.

    Returns
    -------
    float
        Dimensionless; the max over the entries where ``coef_true`` is nonzero (a dropped
        true term scores 1).  NaN when the truth has no nonzero term.  Spurious terms are
        scored by :func:`support_scores`; the overall relative error is :func:`relative_error`.
    """
    ci, ct = np.asarray(coef_id, dtype=float), np.asarray(coef_true, dtype=float)
    if ci.shape != ct.shape:
        raise ValueError(f"shapes differ: {ci.shape} vs {ct.shape}")
    nz = ct != 0
    if not nz.any():
        return float("nan")
    return worst(np.abs(ci[nz] - ct[nz]) / np.abs(ct[nz]), "max")


def rmse(x: np.ndarray, y: np.ndarray, axis: int = -1) -> np.ndarray:
    """Root-mean-square difference ``sqrt(mean((x - y)^2))`` along ``axis``.

    Parameters
    ----------
    x, y : ndarray, shape (n_channels, n_samples)
        E.g. true and simulated joint angles [rad].
    axis : int
        Axis to average over (time by default).

    Returns
    -------
    ndarray, shape (n_channels,)
        In the unit of ``x``.
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    return np.sqrt(np.mean((x - y) ** 2, axis=axis))


def cubic_acceleration_error(M_id: np.ndarray, f_id: np.ndarray, Mr: np.ndarray,
                             f_true: np.ndarray) -> float:
    """Relative RMS error of the cubic force's share of the acceleration, ``M^-1 f`` [-].

    Free vibration (and an impact whose gain each row fits freely) determines ``M^-1 K``,
    ``M^-1 C`` and ``M^-1 K3``, not how the mass is shared among the modes (the modal-mass
    ratios: :mod:`identify.sgd_sindy`, item 4); a cubic model keeps its mass prior's sharing
    (:func:`identify.structural.driving_point_scaling`).  The restoring force ``K3 x^3`` in
    newtons carries that unidentified sharing (``K3_force_error`` compares it with the SEREP
    truth's, whose sharing is the mass-normalised modes'); the acceleration it causes,
    ``M^-1 K3 x^3``, does not: any equation of the same motion, left-multiplied by an
    invertible matrix, gives the same one.  So this compares what the data determine, as
    ``MinvK_error`` does beside ``Kr_error``.

    Parameters
    ----------
    M_id : ndarray, shape (n, n)
        Identified mass matrix [kg].
    f_id : ndarray, shape (n, n_samples)
        Identified cubic restoring force ``K3 x^3`` along the reference motion [N].
    Mr : ndarray, shape (n, n)
        SEREP mass matrix [kg].
    f_true : ndarray, shape (n, n_samples)
        The truth's cubic restoring force along the same motion [N].

    Returns
    -------
    float
        ``||M_id^-1 f_id - Mr^-1 f_true|| / ||Mr^-1 f_true||`` (Frobenius over channels and
        samples); NaN for a singular identified M.
    """
    try:
        a_id = np.linalg.solve(M_id, f_id)
    except np.linalg.LinAlgError:
        return float("nan")
    a_true = np.linalg.solve(Mr, f_true)
    return float(np.linalg.norm(a_id - a_true) / np.linalg.norm(a_true))
