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

import functools
from collections.abc import Mapping, Sequence

import numpy as np

from testbed.scoring.equation_basis import term_plan, term_program

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


@functools.lru_cache(maxsize=64)
def linear_split(names: tuple[str, ...]) -> tuple[tuple[str, ...], np.ndarray]:
    """Each term as its factors other than an acceleration, and the acceleration it multiplies.

    Every term is at most linear in the accelerations (:mod:`testbed.core.terms`): ``"cos(th2)*
    ddth1"`` is ``("cos(th2)", 0)``, ``"ddth2"`` is ``("1", 1)``, ``"sin(th2)"`` is ``("sin(th2)",
    -1)`` (no acceleration).

    Parameters
    ----------
    names : tuple of str
        Terms, length p.

    Returns
    -------
    rest : tuple of str, length p
        The terms without their acceleration factor (``"1"`` where nothing is left).
    which : ndarray of int, shape (p,)
        The 0-based coordinate of each term's acceleration, -1 for none.
    """
    rest, which = [], []
    for name in names:
        factors = name.split("*")
        acc = [f for f in factors if f.partition("^")[0].startswith("ddth")]
        if len(acc) > 1 or (acc and acc[0].partition("^")[2] not in ("", "1")):
            raise ValueError(f"term {name!r} is not linear in the accelerations")
        rest.append("*".join(f for f in factors if f not in acc) or "1")
        which.append(int(acc[0].partition("^")[0][4:]) - 1 if acc else -1)
    return tuple(rest), np.asarray(which, dtype=int)


def accelerations(names: Sequence[str], coef: np.ndarray, states: Mapping[str, np.ndarray]
                  ) -> np.ndarray:
    """Accelerations (n, N) solving ``coef @ Theta(q, dq, ddq, u) = 0`` at each state.

    Every term is at most linear in the accelerations (:func:`linear_split`), so each
    equation reads ``A(q, dq) ddq + b(q, dq, u) = 0``: ``b`` sums the terms without an
    acceleration, column k of ``A`` those multiplying ``ddq_k`` (without it).  States where ``A``
    is singular give non-finite accelerations (the law says nothing there).

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
    n = np.shape(states["th"])[0]
    return _solve_law(_law_parts(names, coef, n), states).T


def _law_parts(names: Sequence[str], coef: np.ndarray, n: int) -> tuple:
    """The law's terms without their accelerations (compiled once: :func:`term_program`), and
    the coefficients of ``b`` and of each column of ``A`` (:func:`accelerations`) with the terms
    they take, for ``n`` coordinates."""
    coef = np.atleast_2d(np.asarray(coef, dtype=float))
    rest, which = linear_split(tuple(names))
    cols = [np.flatnonzero(which == k) for k in range(-1, n)]  # b's, then A's columns
    return term_program(rest), [(c, coef[:, c].T) for c in cols]


def _solve_law(parts: tuple, states: Mapping[str, np.ndarray]) -> np.ndarray:
    """Accelerations (N, n) of the law ``parts`` (:func:`_law_parts`) at ``states``."""
    with np.errstate(all="ignore"):
        return _solve_law_quiet(parts, states)


def _solve_law_quiet(parts: tuple, states: Mapping[str, np.ndarray]) -> np.ndarray:
    """:func:`_solve_law` without setting numpy's error state (the caller ignores all)."""
    program, cols = parts
    G = program(states)  # (N, p)
    b = G[:, cols[0][0]] @ cols[0][1]  # (N, n_eq)
    A = np.empty((G.shape[0], b.shape[1], len(cols) - 1))  # (N, n_eq, n)
    for k, (c, w) in enumerate(cols[1:]):
        A[:, :, k] = G[:, c] @ w
    try:  # one solve where every state's A is regular (the rollout's many small calls)
        return np.linalg.solve(A, -b[..., None])[..., 0]
    except np.linalg.LinAlgError:  # some singular: those states say nothing (NaN)
        det_ok = np.abs(np.linalg.det(A)) > 0
        out = np.full((G.shape[0], A.shape[2]), np.nan)
        if np.any(det_ok):
            out[det_ok] = np.linalg.solve(A[det_ok], -b[det_ok][..., None])[..., 0]
        return out


def law_rollout(names: Sequence[str], coef: np.ndarray, x0: np.ndarray, xd0: np.ndarray,
                u: np.ndarray, dt: float, scales: Sequence[float], substeps: int = 1) -> np.ndarray:
    """The law's coordinates over a record, one rollout per scale of its accelerations.

    Classical RK4 in ``substeps`` equal steps per sample step ``dt``, the inputs held over each
    sample (as recorded);
    rollout ``j`` integrates ``scales[j]`` times the law's accelerations (:func:`accelerations`),
    so ``scales = (1, 1 + e)`` gives the law and a law off by exactly ``e`` in the relative
    acceleration error of :func:`law_errors`.  All rollouts advance together (one evaluation of
    the terms per stage); a non-finite state stays non-finite.

    Parameters
    ----------
    names, coef : sequence of str, ndarray (n, p)
        The law's terms and equations (one per coordinate).
    x0, xd0 : ndarray, shape (n,)
        Initial coordinates [rad or m] and rates [per s].
    u : ndarray, shape (m, N)
        Inputs at the record's samples [N or N m].
    dt : float
        The record's sample step [s].
    scales : sequence of float, length K
        Factors on the accelerations [-].
    substeps : int
        RK4 steps per sample step (each ``dt / substeps`` [s]).

    Returns
    -------
    ndarray, shape (K, n, N)
        Coordinates at the record's samples.
    """
    s = np.asarray(scales, dtype=float)
    K, N = s.size, np.shape(u)[1]
    q = np.repeat(np.asarray(x0, dtype=float)[:, None], K, axis=1)
    qd = np.repeat(np.asarray(xd0, dtype=float)[:, None], K, axis=1)
    out = np.full((K, q.shape[0], N), np.nan)
    out[:, :, 0] = q.T

    parts = _law_parts(names, coef, q.shape[0])
    # the inputs held over each sample step, one column per rollout: (N, m, K)
    U = np.repeat(np.asarray(u, dtype=float).T[:, :, None], K, axis=2)

    def acc(a: np.ndarray, b: np.ndarray, uk: np.ndarray) -> np.ndarray:
        return _solve_law_quiet(parts, {"th": a, "dth": b, "u": uk}).T * s

    h = dt / substeps if substeps > 1 else dt
    h2 = h / 2
    h6 = h / 6
    with np.errstate(all="ignore"):
        for k in range(N - 1):
            uk = U[k]
            for _ in range(substeps):
                a1 = acc(q, qd, uk)
                v2 = qd + h2 * a1
                a2 = acc(q + h2 * qd, v2, uk)
                v3 = qd + h2 * a2
                a3 = acc(q + h2 * v2, v3, uk)
                v4 = qd + h * a3
                a4 = acc(q + h * v3, v4, uk)
                q = q + h6 * (qd + 2 * v2 + 2 * v3 + qd + h * a3)
                qd = qd + h6 * (a1 + 2 * a2 + 2 * a3 + a4)
            out[:, :, k + 1] = q.T
            if not np.any(np.isfinite(q)):
                break
    return out


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
    acceleration somewhere in the box (a singular or non-finite law: never a pass), or uses a
    term not linear in the accelerations or an acceleration of a coordinate the record has not.

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
    # terms the identified law does not use are left out; one it uses that is not linear in the
    # accelerations, or names a coordinate the record has not, gives no accelerations to compare
    # (a plugin's ``ddth1*ddth2`` was a ValueError of the scoring, review of session 20): NaN
    used = np.any(id_coef != 0.0, axis=0)
    id_names = [name for name, u in zip(id_names, used, strict=False) if u]
    try:
        which = linear_split(tuple(id_names))[1]
    except ValueError:
        return np.full(n, np.nan)
    if np.any(which >= n):
        return np.full(n, np.nan)
    box = state_box(signals)
    truth = accelerations(true_names, true_coef, box)
    ident = accelerations(id_names, id_coef[:, used], box)
    with np.errstate(all="ignore"):
        num = np.sqrt(np.mean((ident - truth) ** 2, axis=1))
        den = np.sqrt(np.mean(truth**2, axis=1))
        # a coordinate the true law never accelerates in the box (0 / 0 was NaN, read as a
        # singular law): 0 where the identified law agrees, inf where it accelerates it
        return np.where(den > 0, num / den, np.where(num == 0, 0.0, np.where(np.isnan(num), num, np.inf)))


def free_coordinates(names: Sequence[str], coef: np.ndarray, n: int) -> list[int]:
    """The coordinates a law does not depend on, only on their rates and accelerations: no term
    it uses holds the coordinate itself (``thk``, or ``sin`` / ``cos`` of an angle holding it).

    Nothing restores such a coordinate (a cart on its rail): shifting it leaves every
    acceleration unchanged, so a rollout integrates any error of its acceleration twice, with
    nothing to pull it back (:func:`testbed.scoring.scorers.drift_failures`).

    Parameters
    ----------
    names, coef : sequence of str, ndarray (n_equations, p)
        The law's terms (:mod:`testbed.core.terms` syntax) and equations; a term with no
        nonzero coefficient is not used.
    n : int
        Number of coordinates.

    Returns
    -------
    list of int
        0-based, ascending.
    """
    used = np.any(np.atleast_2d(np.asarray(coef, dtype=float)) != 0.0, axis=0)
    held: set[int] = set()
    for coords, u in zip(_held_coordinates(names), used, strict=True):
        if u:
            held |= coords
    return [k for k in range(n) if k not in held]


def holding_terms(names: Sequence[str], coef: np.ndarray, coordinates: Sequence[int]) -> list[int]:
    """The terms a law uses that hold any of ``coordinates`` itself (:func:`free_coordinates`'
    sense: ``thk``, or ``sin`` / ``cos`` of an angle holding it), by column index, ascending.

    Parameters
    ----------
    names, coef : sequence of str, ndarray (n_equations, p)
        The law's terms and equations; a term with no nonzero coefficient is not used.
    coordinates : sequence of int
        0-based coordinates.
    """
    used = np.any(np.atleast_2d(np.asarray(coef, dtype=float)) != 0.0, axis=0)
    want = set(coordinates)
    return [j for j, (coords, u) in enumerate(zip(_held_coordinates(names), used, strict=True))
            if u and coords & want]


def _held_coordinates(names: Sequence[str]) -> list[set[int]]:
    """Per term, the coordinates it holds itself (not through their rates or accelerations)."""
    out = []
    for factors in term_plan(tuple(names)):
        held: set[int] = set()
        for spec, _ in factors:
            if spec[0] in ("sin", "cos"):
                held.update(i for i in spec[1:] if i is not None)
            elif spec[1] == "th":
                held.add(spec[2])
        out.append(held)
    return out
