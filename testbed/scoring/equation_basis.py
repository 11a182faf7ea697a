"""Implicit equations compared modulo the identities of the data (canonical basis).

On a closed kinematic loop the library columns obey exact linear identities (the loop
constraint and its time derivatives times trig factors), so an implicit equation
``sum_c coef_c Theta_c = 0`` has many exactly equivalent forms: adding any identity changes the
coefficients, not the equation.  Scoring raw coefficients against one form of the truth would
penalise an exact identification.  This module puts every equation in one canonical form:

1. Evaluate the columns (the identifier's library, in its order, then any true term the
   library lacks) on the NOISE-FREE reference signals.  Only the scorer does this: it may
   use truth and reference, an identifier may not.
2. Walk the input-free columns in library order (ordered pivoted Cholesky of the unit-diagonal
   Gram matrix, the rule of ``SINDyPI(prune_tol=...)``): a column whose residual variance after
   projection on the earlier kept ones is at most :data:`DEPENDENCE_TOL` is *dependent* and
   dropped (later columns go, earlier ones stay).  Columns with an input are never dropped: the
   inputs are free signals, so no kinematic identity contains them.
3. Express each dropped column in the kept ones (unique: the kept columns are independent) and
   substitute it in an equation: ``c_K <- c_K + beta c_P``.  The result is the unique
   representative of the equation's class modulo the identities.

Two equations are equal on the loop manifold iff their canonical forms are equal, so a wrong
equation still scores badly; only the arbitrary choice among equivalent forms is removed.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from itertools import permutations

import numpy as np

from testbed.numerics.gram import normalized_gram, ordered_independent
from testbed.scoring import metrics

#: Residual variance (of a unit-norm column, after projection on the earlier kept columns)
#: at or below which a column counts as an exact combination of them.  Exact identities on the
#: five-bar records leave 1e-19..1e-15 (Gram round-off, ~p eps, and the RK4 error of the
#: record); the smallest genuine direction measured is 4.5e-6 (multisine, 32-term library).
#: 1e-10 sits four to five decades from both (the identifier's default prune_tol, 1e-9, lies
#: in the same gap, so both rules agree on noise-free data).
DEPENDENCE_TOL = 1e-10
#: A canonical coefficient below this fraction of its row's largest counts as zero: the
#: substitution (a least-squares solve on the columns) leaves ~1e-14 of round-off where
#: identities cancel exactly, while the
#: smallest physical coefficient of the five-bar (joint damping 1e-3 N m s/rad) is 5e-4.
ZERO_RTOL = 1e-8

_TRIG = re.compile(r"^(sin|cos)\(th(\d+)(?:-th(\d+))?\)$")
_VAR = re.compile(r"^(ddth|dth|th|u)(\d+)$")
_INPUT = re.compile(r"(^|\*)u\d+(\^\d+)?($|\*)")


def evaluate_terms(names: Sequence[str], signals: Mapping[str, np.ndarray]) -> np.ndarray:
    """Evaluate product terms (:mod:`testbed.core.terms` syntax) on samples.

    An implementation independent of the identifiers' library code, so that the scorer checks
    it rather than trusting it.  Each distinct factor (``sin`` / ``cos`` of an angle or a
    difference, or a signal, to its power) is evaluated once, and each term is the product of
    its factors in written order (:func:`term_program`).

    Parameters
    ----------
    names : sequence of str
        Terms such as ``"cos(th1-th2)*sin(th2-th3)*ddth2"``, ``"sin(th1-th2)*dth2^2"``, ``"u1"``.
    signals : mapping
        ``"th"``, ``"dth"``, ``"ddth"`` (n_coords, n) [rad, rad/s, rad/s^2], ``"u"`` (m, n).

    Returns
    -------
    ndarray, shape (n, len(names))
    """
    return term_program(tuple(names))(signals)


class TermProgram:
    """Product terms compiled once for repeated evaluation (a rollout's every stage).

    The distinct ``(factor, power)`` pairs of the terms are evaluated once a call, stacked
    under a row of ones, and each term is the product of its pairs' rows in written order,
    padded with the ones row: ``x * 1 == x`` exactly, so a term's value is the same
    floating-point product as factor by factor (``((f1 ** p1) * (f2 ** p2)) * ...``) and
    ``"1"`` is the ones row.

    Parameters
    ----------
    names : tuple of str
        Terms, length p (:func:`term_plan` syntax).
    """

    def __init__(self, names: tuple[str, ...]):
        pairs: list[tuple[tuple, int]] = []
        rows = []
        for factors in term_plan(names):
            row = []
            for pair in factors:
                if pair not in pairs:
                    pairs.append(pair)
                row.append(1 + pairs.index(pair))  # row 0: the ones
            rows.append(row)
        width = max([len(r) for r in rows] + [1])
        self.pairs = tuple(pairs)
        #: (width, p) rows of each term's factors, in written order, padded with 0 (the ones)
        self.index = np.array([r + [0] * (width - len(r)) for r in rows], dtype=np.intp
                              ).reshape(len(rows), width).T
        specs = list(dict.fromkeys(spec for spec, _ in pairs))
        #: per distinct factor: (kind, i, j) with kind "sin", "cos" or a signal's name
        self.specs = tuple((spec[0], spec[1], spec[2]) if spec[0] in ("sin", "cos")
                           else (spec[1], spec[2], None) for spec in specs)
        #: per pair: its factor's place in ``specs`` and its power
        self.powers = tuple((specs.index(spec), power) for spec, power in pairs)

    def __call__(self, signals: Mapping[str, np.ndarray]) -> np.ndarray:
        """The terms on ``signals`` (:func:`evaluate_terms`): ndarray (n, p)."""
        th = signals["th"]
        value = []
        for kind, i, j in self.specs:
            if kind == "sin" or kind == "cos":
                arg = th[i] - (th[j] if j is not None else 0.0)
                value.append(np.sin(arg) if kind == "sin" else np.cos(arg))
            else:
                value.append(np.asarray(signals[kind][i], dtype=float))
        rows = np.empty((1 + len(self.powers), np.shape(th)[1]))
        rows[0] = 1.0
        for r, (f, power) in enumerate(self.powers, start=1):
            rows[r] = value[f] if power == 1 else value[f] ** power  # x ** 1 == x exactly
        index = self.index
        out = rows[index[0]]  # (p, n)
        for k in range(1, index.shape[0]):
            out *= rows[index[k]]
        return out.T


@functools.lru_cache(maxsize=256)
def term_program(names: tuple[str, ...]) -> TermProgram:
    """:class:`TermProgram` of ``names``, compiled once per tuple of terms."""
    return TermProgram(names)


@functools.lru_cache(maxsize=256)
def term_plan(names: tuple[str, ...]) -> tuple[tuple[tuple[tuple, int], ...], ...]:
    """Product terms parsed once: per term, its factors as ``(spec, power)`` in written order.

    A spec is ``("sin" | "cos", i, j)`` (``j`` None without a difference) or ``("var", signal,
    i)``, 0-based; ``"1"`` has no factors.  Raises ValueError on a factor it cannot read.
    """
    plan = []
    for name in names:
        factors = []
        if name != "1":
            for raw in name.split("*"):
                base, _, power = raw.partition("^")
                mt, mv = _TRIG.match(base), _VAR.match(base)
                if mt:
                    fn, i, j = mt.groups()
                    spec: tuple = (fn, int(i) - 1, int(j) - 1 if j else None)
                elif mv:
                    spec = ("var", mv.group(1), int(mv.group(2)) - 1)
                else:
                    raise ValueError(f"cannot evaluate factor {base!r}")
                factors.append((spec, int(power) if power else 1))
        plan.append(tuple(factors))
    return tuple(plan)


def has_input(name: str) -> bool:
    """Whether a term has an input factor ``u<k>``."""
    return _INPUT.search(name) is not None


@dataclass
class CanonicalBasis:
    """Kept and dependent columns of a library on given data, and the substitution.

    Attributes
    ----------
    names : list of str
        All columns, in priority order.
    kept, dependent : ndarray of int
        Indices of the kept (independent) and the dropped (dependent) columns.
    beta : ndarray, shape (len(kept), len(dependent))
        ``Theta[:, dependent] = Theta[:, kept] @ beta`` on the data (original units).
    residual : ndarray, shape (len(dependent),)
        Residual variance of each dropped unit-norm column (<= tol): how exact the identity is.
    """

    names: list[str]
    kept: np.ndarray
    dependent: np.ndarray
    beta: np.ndarray
    residual: np.ndarray

    @classmethod
    def from_data(cls, names: Sequence[str], Theta: np.ndarray,
                  tol: float = DEPENDENCE_TOL, dynamics: np.ndarray | None = None) -> CanonicalBasis:
        """Find the identities of ``Theta`` (n_samples, p) and the canonical basis (see module).

        ``dynamics`` (k, p): the true input-free equations over ``names`` (a passive
        coordinate's equation of motion on an open chain).  They too are exact dependencies
        among the columns, but of the dynamics, not of the kinematics: a dependency that lies
        in their span is not an identity, and the column it would drop is kept (relative
        residual of the dependency against their span below :data:`DYNAMICS_RTOL`).
        """
        names = list(names)
        G = np.ascontiguousarray(Theta.T) @ Theta
        Gn, s = normalized_gram(G)
        protected = np.array([has_input(nm) for nm in names], dtype=bool)
        while True:
            kept_free, dep, res = ordered_independent(Gn, np.flatnonzero(~protected), tol)
            dyn = _dynamics_columns(Gn, s, kept_free, dep, dynamics)
            if not dyn:
                break
            protected[dyn] = True
        kept = np.sort(np.r_[np.flatnonzero(protected), kept_free].astype(np.intp))
        dependent = np.array(dep, dtype=np.intp)
        beta = np.zeros((kept.size, dependent.size))
        if dependent.size:
            kf = np.array(kept_free, dtype=np.intp)
            # least squares on the unit-norm columns themselves, not the normal equations: the
            # Gram solve squares the columns' condition (4-5e4 on held-out five-bar records, so
            # 2e9) and left 1e-8..6e-8 of the row's largest on kept terms whose true
            # coefficient is 0, above ZERO_RTOL: exact models scored coef_error 1 and 2e5
            # (benchmarks/heldout/README.md); this solve leaves ~1e-14 there.
            Bn, *_ = np.linalg.lstsq(Theta[:, kf] / s[kf], Theta[:, dependent] / s[dependent],
                                     rcond=None)
            beta[np.searchsorted(kept, kf)] = Bn * s[dependent][None, :] / s[kf][:, None]
        return cls(names, kept, dependent, beta, np.array(res))

    def reduce(self, coef: np.ndarray) -> np.ndarray:
        """Canonical form of equations ``coef`` (n_eq, p) over ``names``: (n_eq, len(kept))."""
        coef = np.atleast_2d(np.asarray(coef, dtype=float))
        return coef[:, self.kept] + coef[:, self.dependent] @ self.beta.T

    @property
    def kept_names(self) -> list[str]:
        return [self.names[i] for i in self.kept]

    @property
    def dependent_names(self) -> list[str]:
        return [self.names[i] for i in self.dependent]


#: A dependency among the columns whose (column-normalised) vector lies within this relative
#: distance of the span of the true input-free equations is that dynamics, not an identity.
#: The dependency's vector comes from a Gram solve accurate to ~1e-9 relative on the exact
#: reference signals (the five-bar's identities: 1e-19..1e-15 residual variance); a genuine
#: kinematic identity is at O(1) distance from an equation of motion.
DYNAMICS_RTOL = 1e-6


def _dynamics_columns(Gn: np.ndarray, s: np.ndarray, kept_free: Sequence[int], dep: Sequence[int],
                      dynamics: np.ndarray | None) -> list[int]:
    """The dependent columns whose dependency lies in the span of ``dynamics`` (see from_data)."""
    if dynamics is None or not len(dep) or not len(kept_free):
        return []
    E = np.atleast_2d(np.asarray(dynamics, dtype=float)) * s[None, :]  # to normalised columns
    E = E[np.any(E != 0, axis=1)]
    if not E.shape[0]:
        return []
    kf = np.asarray(kept_free, dtype=np.intp)
    out = []
    for d in dep:
        v = np.zeros(Gn.shape[0])
        v[d] = 1.0
        v[kf] = -np.linalg.solve(Gn[np.ix_(kf, kf)], Gn[kf, d])
        a, *_ = np.linalg.lstsq(E.T, v, rcond=None)
        if np.linalg.norm(v - E.T @ a) <= DYNAMICS_RTOL * np.linalg.norm(v):
            out.append(int(d))
    return out


def _on(names: Sequence[str], coef: np.ndarray, basis_names: Sequence[str]) -> np.ndarray:
    """Coefficient rows over ``names`` placed on the columns ``basis_names`` (by name)."""
    pos = {n: i for i, n in enumerate(basis_names)}
    coef = np.atleast_2d(np.asarray(coef, dtype=float))
    out = np.zeros((coef.shape[0], len(basis_names)))
    for j, n in enumerate(names):
        out[:, pos[n]] += coef[:, j]
    return out


def _zeroed(C: np.ndarray) -> np.ndarray:
    big = np.abs(C).max(axis=1, keepdims=True)
    return np.where(np.abs(C) > ZERO_RTOL * big, C, 0.0)


def compare_equations(id_names: Sequence[str], id_coef: np.ndarray, true_names: Sequence[str],
                      true_coef: np.ndarray, signals: Mapping[str, np.ndarray],
                      tol: float = DEPENDENCE_TOL) -> dict:
    """Support and coefficient scores of identified vs true implicit equations, modulo identities.

    Parameters
    ----------
    id_names, id_coef : sequence of str, ndarray (n_id, len(id_names))
        The identifier's library (in its priority order) and its equations.
    true_names, true_coef : sequence of str, ndarray (n_true, len(true_names))
        The true equations.
    signals : mapping
        Noise-free reference signals for :func:`evaluate_terms`.
    tol : float
        Dependence tolerance (:data:`DEPENDENCE_TOL`).

    Returns
    -------
    dict
        ``coef_error``: largest relative error ``|c_id - c_true| / |c_true|`` over the
        canonical true terms of every equation (``coef_errors`` per true row);
        ``coef_error_norm``: largest
        ``||c_id - c_true|| / ||c_true||`` over all canonical terms (extra terms included);
        ``precision``, ``recall``, ``f1`` of the canonical nonzero patterns (an entry is
        nonzero above ``ZERO_RTOL`` of its row's largest); ``names`` (canonical basis),
        ``coef_id``, ``coef_true`` (canonical rows, identified rows paired to the true rows
        and both divided by their coefficient on the true row's largest term), ``pairing``,
        ``dependent`` (dropped column names), ``truth_residual`` (relative residual of the
        canonical truth on the data: the substitution's accuracy).

    Notes
    -----
    Rows are paired by the permutation with the smallest total ``coef_error_norm``.  A row
    whose identified coefficient on the true lead term is zero has infinite error.
    """
    id_names = list(id_names)
    extra = [n for n in true_names if n not in set(id_names)]  # true terms the library lacks
    names = id_names + extra
    Theta = evaluate_terms(names, signals)
    true_rows = _on(true_names, true_coef, names)
    free = [i for i, row in enumerate(true_rows) if not any(has_input(names[j]) for j in np.flatnonzero(row))]
    basis = CanonicalBasis.from_data(names, Theta, tol, true_rows[free] if free else None)
    T = _zeroed(basis.reduce(true_rows))
    Id = _zeroed(basis.reduce(_on(id_names, id_coef, names)))
    Tk = Theta[:, basis.kept]
    tr_res = [float(np.abs(Tk @ row).max() / max(np.abs(Tk * row).sum(axis=1).max(), 1e-300))
              for row in T]

    def row_errors(i_row: np.ndarray, t_row: np.ndarray) -> tuple[float, float, np.ndarray]:
        lead = int(np.argmax(np.abs(t_row)))
        if i_row[lead] == 0:
            return np.inf, np.inf, np.full_like(i_row, np.nan)
        a, b = i_row / i_row[lead], t_row / t_row[lead]
        return metrics.coefficient_error(a, b), metrics.relative_error(a, b), a

    best = None
    for perm in permutations(range(Id.shape[0]), T.shape[0]):
        errs = [row_errors(Id[k], T[j]) for j, k in enumerate(perm)]
        # A NaN row error (non-finite identified coefficients) makes the pairing worst of all,
        # never unbeatable: ``total < nan`` is always False, so NaN is ranked as +inf here.
        total = float(np.sum([e[1] for e in errs]))
        total = np.inf if np.isnan(total) else total
        if best is None or total < best[0]:
            best = (total, perm, errs)
    if best is None:
        raise ValueError(f"{Id.shape[0]} identified equations for {T.shape[0]} true ones")
    _, perm, errs = best
    Ip = Id[list(perm)]
    sup = metrics.support_scores(Ip, T)
    lead = np.argmax(np.abs(T), axis=1)
    return {"coef_error": metrics.worst([e[0] for e in errs], "max"),
            "coef_error_norm": metrics.worst([e[1] for e in errs], "max"),
            "coef_errors": np.array([e[0] for e in errs]),
            "precision": float(sup["precision"]), "recall": float(sup["recall"]),
            "f1": float(sup["f1"]), "names": basis.kept_names,
            "coef_true": T / T[np.arange(T.shape[0]), lead][:, None],
            "coef_id": np.array([e[2] for e in errs]), "pairing": list(perm),
            "dependent": basis.dependent_names, "truth_residual": np.array(tr_res)}
