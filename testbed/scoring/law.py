"""An open chain's identified law of motion against the true one, over the record's state box.

On an open chain (one implicit equation per coordinate: a cart-pole) the equations of motion
``A(q) ddq + b(q, dq, u) = 0`` give the accelerations at any state.  Any invertible combination
of the rows is the same law (the cart's equation plus a multiple of the passive pole's gives the
same accelerations), so the rows' coefficients (``coef_error``, ``support_*``) score such a mix
as wrong, while a law that fits the record's own states but not the states around them (a record
whose coordinates move together, as under two tones, lets a wrong law replay it) passes a
rollout.  The law is compared where it is a law: both sets of equations are solved for the
accelerations at states drawn independently, coordinate by coordinate, across the ranges the
noise-free record itself visited (its angles, rates and inputs: the record's state box), and
the accelerations compared.

The draw is fixed (:data:`BOX_SAMPLES` states from numpy's ``default_rng(BOX_SEED)``, uniform
per coordinate); only the scorer uses it (the identifier never sees truth or reference).  A
closed chain's states must satisfy its loop closure, so no box is drawn there: None.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

from testbed.scoring.equation_basis import evaluate_terms

#: States drawn in the record's box: the RMS error of 4096 draws has a sampling spread of about
#: 1 / sqrt(2 x 4096) = 1.1 % of itself, far below any bar set on it.
BOX_SAMPLES = 4096
#: Seed of the box's draw (fixed: the score is the same on every machine and run).
BOX_SEED = 0


def state_box(signals: Mapping[str, np.ndarray], samples: int = BOX_SAMPLES,
              seed: int = BOX_SEED) -> dict[str, np.ndarray]:
    """States drawn uniformly, each coordinate on its own, within the record's ranges.

    Parameters
    ----------
    signals : mapping
        Noise-free ``"th"``, ``"dth"`` (n, N) [m or rad, m/s or rad/s] and ``"u"`` (m, N) [N or
        N m] of the record.
    samples, seed : int
        Number of states and the seed of numpy's ``default_rng``.

    Returns
    -------
    dict
        ``"th"``, ``"dth"`` (n, samples) and ``"u"`` (m, samples).
    """
    rng = np.random.default_rng(seed)
    out = {}
    for key in ("th", "dth", "u"):
        x = np.atleast_2d(np.asarray(signals[key], dtype=float))
        lo, hi = x.min(axis=1), x.max(axis=1)
        out[key] = lo[:, None] + (hi - lo)[:, None] * rng.random((x.shape[0], samples))
    return out


def accelerations(names: Sequence[str], coef: np.ndarray, states: Mapping[str, np.ndarray]
                  ) -> np.ndarray:
    """Accelerations (n, N) solving ``coef @ Theta(q, dq, ddq, u) = 0`` at each state.

    Every term is at most linear in the accelerations (:mod:`testbed.core.terms`), so each
    equation reads ``A(q, dq) ddq + b(q, dq, u) = 0``: ``b`` is the equations at ``ddq = 0`` and
    column k of ``A`` their change at ``ddq = e_k``.  States where ``A`` is singular give
    non-finite accelerations (the law says nothing there).

    Parameters
    ----------
    names : sequence of str
        Terms, length p.
    coef : ndarray, shape (n, p)
        One equation per coordinate.
    states : mapping
        ``"th"``, ``"dth"`` (n, N), ``"u"`` (m, N).

    Returns
    -------
    ndarray, shape (n, N)
    """
    coef = np.atleast_2d(np.asarray(coef, dtype=float))
    n, N = np.shape(states["th"])

    def equations(ddq: np.ndarray) -> np.ndarray:  # (N, n_eq)
        sig = {**states, "ddth": ddq}
        return evaluate_terms(list(names), sig) @ coef.T

    b = equations(np.zeros((n, N)))
    A = np.empty((N, coef.shape[0], n))
    for k in range(n):
        unit = np.zeros((n, N))
        unit[k] = 1.0
        A[:, :, k] = equations(unit) - b
    with np.errstate(all="ignore"):
        det_ok = np.abs(np.linalg.det(A)) > 0
        out = np.full((N, n), np.nan)
        if np.any(det_ok):
            out[det_ok] = np.linalg.solve(A[det_ok], -b[det_ok][..., None])[..., 0]
    return out.T


def law_error(id_names: Sequence[str], id_coef: np.ndarray, true_names: Sequence[str],
              true_coef: np.ndarray, signals: Mapping[str, np.ndarray]) -> float | None:
    """The largest over the coordinates of :func:`law_errors` (None where that is None; NaN
    where any is NaN)."""
    err = law_errors(id_names, id_coef, true_names, true_coef, signals)
    if err is None:
        return None
    return float(np.max(err)) if np.all(np.isfinite(err)) else float("nan")


def law_errors(id_names: Sequence[str], id_coef: np.ndarray, true_names: Sequence[str],
               true_coef: np.ndarray, signals: Mapping[str, np.ndarray]) -> np.ndarray | None:
    """The identified law's acceleration error over the record's state box [-].

    Per coordinate, the RMS over the box (:func:`state_box`) of the identified minus the true
    accelerations, divided by the RMS of the true ones.  0 for
    the same law (in any combination of its rows); NaN where the identified law gives no finite
    acceleration somewhere in the box (a singular or non-finite law: never a pass).

    Parameters
    ----------
    id_names, id_coef : sequence of str, ndarray (n, p_id)
        The identified equations.
    true_names, true_coef : sequence of str, ndarray (n, p_true)
        The true equations.
    signals : mapping
        The noise-free record's ``"th"``, ``"dth"`` (n, N) and ``"u"`` (m, N).

    Returns
    -------
    ndarray, shape (n,), or None
        Per coordinate [-]; None where the chain is not open (fewer true equations than
        coordinates, or an identified set of another size): no box can be drawn off a loop
        closure.
    """
    n = np.shape(signals["th"])[0]
    id_coef, true_coef = np.atleast_2d(id_coef), np.atleast_2d(true_coef)
    if true_coef.shape[0] != n or id_coef.shape[0] != n:
        return None
    if not np.all(np.isfinite(id_coef)):
        return np.full(n, np.nan)
    box = state_box(signals)
    truth = accelerations(true_names, true_coef, box)
    ident = accelerations(id_names, id_coef, box)
    with np.errstate(all="ignore"):
        num = np.sqrt(np.mean((ident - truth) ** 2, axis=1))
        den = np.sqrt(np.mean(truth**2, axis=1))
        # a coordinate the true law never accelerates in the box (0 / 0 was NaN, read as a
        # singular law): 0 where the identified law agrees, inf where it accelerates it
        return np.where(den > 0, num / den, np.where(num == 0, 0.0, np.where(np.isnan(num), num, np.inf)))
