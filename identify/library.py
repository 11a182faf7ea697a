"""Named candidate-term libraries for implicit (SINDy-PI) regression of mechanical systems.

A :class:`Library` is a list of product terms named as in :mod:`testbed.core.terms`
(``"sin(th2-th3)*ddth1"``, ``"sin(th1-th2)^2*dth2^2"``, ``"u1"``).  It evaluates them from
the measured signals into the library matrix ``Theta`` (n_samples x n_terms).  Evaluation is
vectorised: every distinct trigonometric factor is computed once, for all samples, as
``sin``/``cos`` of a row of ``C @ x`` (C a matrix of +1/-1 coefficients); a column is then a
product of gathered factor rows, done in chunks of samples to bound memory.

Variables: ``th{i}``/``x{i}`` are row i-1 of ``x`` (angle [rad] or displacement [m]),
``dth{i}``/``v{i}`` of ``xd``, ``ddth{i}``/``a{i}`` of ``xdd``, ``u{k}`` row k-1 of ``u``.
Every term must be linear in the accelerations (at most one acceleration factor, power 1):
implicit equations built from it can then be solved for the accelerations
(:meth:`Library.evaluate_parts`).

Linear dependence.  SINDy-PI needs a library without exact identities, or an implicit
equation has no unique sparse form.  The five-bar libraries are free of *functional*
identities: every column is ``sin(th_i-th_j)`` times a chain term, and a chain term carries at
most one cosine, that of its own chain (``cos(th1-th2)`` or ``cos(th3-th4)``); an identity such
as ``sin(a-c)cos(a-b) - sin(a-b)cos(a-c) = sin(b-c)`` needs two different cosines on the same
chain term, and the Fourier modes ``x +- y`` of ``sin(x)cos(y)`` only collide for ``x = -x'``
(the same column).  Single-angle products (``sin(th1)*cos(th2)``) are never generated: they
are exactly dependent on the difference terms.  Data on the five-bar's loop-closure manifold
add *kinematic* identities no builder can rule out (the loop constraint and its derivatives,
times trig factors): measured on 10 s loop-closed records (the rig's multisine, the synthetic
five-bar), 2 among the 30 input-free columns of the reduced library (eigenvalues ~1e-16 of the
unit-diagonal Gram matrix, the next one 2.6e-7..4.5e-6) and more than 20 in the full one.  They
contain no input, so
:func:`near_dependencies` on the input-free columns finds them, and
``SINDyPI(prune_tol=...)`` drops them in library order (``pruned_terms_``).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from itertools import combinations

import numpy as np

from testbed.core.errors import HyperparameterError
from testbed.core.terms import canonical

# indices from 1: 'th0' was read as index -1 (the constant row; 'u0' the last acceleration)
_TRIG = re.compile(r"^(sin|cos)\(th([1-9]\d*)(?:-th([1-9]\d*))?\)$")
_VAR = re.compile(r"^(ddth|dth|th|u|x|v|a)([1-9]\d*)$")
#: The structural library's names of displacement, velocity and acceleration (x1, v1, a1),
#: which a mechanical rig's truth and scoring do not use (they name th1, dth1, ddth1).
STRUCTURAL_FACTOR = re.compile(r"^[xva][1-9]\d*$")
_ROW = {"th": 0, "x": 0, "dth": 1, "v": 1, "ddth": 2, "a": 2, "u": 3}
#: Most factors a term may have (powers counted: ``dth1^3`` has 3).  Each is a row of the
#: gather that evaluates the library, terms x factors x :data:`_CHUNK` floats at once
#: (``th1^99999`` asked 24 GiB), and a product of more overflows float64 for any value beyond
#: 1e308 ** (1 / 64) = 6.6e4 in its unit.
MAX_TERM_FACTORS = 64
_CHUNK = 8192  # samples per gather-and-multiply block: bounds the temporary to p*k*8192 floats


class Library:
    """Product terms evaluated from (x, xd, xdd, u).

    Parameters
    ----------
    terms : sequence of str
        Term names; each is put in canonical form (:func:`testbed.core.terms.canonical`).  A sign
        picked up by canonicalisation is dropped: the column is the canonical term's value.
    n_coords : int, optional
        Number of coordinates (rows of x); default the largest index used.
    n_inputs : int, optional
        Number of inputs (rows of u); default the largest input index used.

    Attributes
    ----------
    names : list of str
        Canonical name of each column, in order.
    acc_index : ndarray of int, shape (n_terms,)
        Coordinate (0-based) whose acceleration multiplies the term, -1 if none.
    """

    def __init__(self, terms: Sequence[str], n_coords: int | None = None,
                 n_inputs: int | None = None):
        names = [canonical(t)[0] for t in terms]
        if len(set(names)) != len(names):
            dup = sorted({n for n in names if names.count(n) > 1})
            raise ValueError(f"duplicate library terms after canonicalisation: {dup}")
        self.names = names
        parsed = [self._parse(n) for n in names]
        max_c = max([i for p in parsed for kind, i in p[0] if kind != 3]
                    + [max(i, j) for p in parsed for _, i, j in p[1]] + [0]) + 1
        max_u = max([i for p in parsed for kind, i in p[0] if kind == 3] + [-1]) + 1
        self.n_coords = n_coords if n_coords is not None else max_c
        self.n_inputs = n_inputs if n_inputs is not None else max_u
        if max_c > self.n_coords or max_u > self.n_inputs:
            raise ValueError(f"terms use {max_c} coordinates and {max_u} inputs; library declared "
                             f"{self.n_coords} and {self.n_inputs}")
        n, m = self.n_coords, self.n_inputs
        self._trig = sorted({t for p in parsed for t in p[1]})
        self._arg = np.zeros((len(self._trig), n))
        for r, (_, i, j) in enumerate(self._trig):
            self._arg[r, i] = 1.0
            if j >= 0:
                self._arg[r, j] = -1.0
        self._is_sin = np.array([fn == "sin" for fn, _, _ in self._trig], dtype=bool)
        # factor rows: [x (n); xd (n); xdd (n); u (m); trig (n_trig); one]
        trig_pos = {t: 3 * n + m + r for r, t in enumerate(self._trig)}
        self._one = 3 * n + m + len(self._trig)
        kmax = max([len(p[0]) + len(p[1]) for p in parsed] + [1])
        self._idx = np.full((len(names), kmax), self._one, dtype=np.intp)
        self.acc_index = np.full(len(names), -1, dtype=np.intp)
        self._idx_noacc = self._idx.copy()
        for c, (vars_, trigs) in enumerate(parsed):
            rows = [(3 * n + i if kind == 3 else kind * n + i) for kind, i in vars_]
            rows += [trig_pos[t] for t in trigs]
            self._idx[c, :len(rows)] = rows
            accs = [r for r, (kind, _) in zip(rows, vars_, strict=False) if kind == 2]
            if len(accs) > 1:
                raise ValueError(f"term {names[c]!r} is not linear in the accelerations")
            self._idx_noacc[c, :len(rows)] = [self._one if r in accs else r for r in rows]
            if accs:
                self.acc_index[c] = accs[0] - 2 * n

    @staticmethod
    def _parse(name: str) -> tuple[list[tuple[int, int]], list[tuple[str, int, int]]]:
        """Split a canonical name into variable factors (kind, index) and trig factors."""
        if name == "1":
            return [], []
        vars_: list[tuple[int, int]] = []
        trigs: list[tuple[str, int, int]] = []
        for raw in name.split("*"):
            base, _, power = raw.partition("^")
            reps = int(power) if power else 1
            if len(vars_) + len(trigs) + reps > MAX_TERM_FACTORS:
                raise ValueError(f"term {name[:80]!r} has more than {MAX_TERM_FACTORS} factors "
                                 "(powers counted); expected at most that many")
            mt, mv = _TRIG.match(base), _VAR.match(base)
            if mt:
                fn, i, j = mt.groups()
                trigs += [(fn, int(i) - 1, int(j) - 1 if j else -1)] * reps
            elif mv:
                vars_ += [(_ROW[mv.group(1)], int(mv.group(2)) - 1)] * reps
            else:
                raise ValueError(f"unknown factor {base!r} in term {name!r}")
        return vars_, trigs

    def __len__(self) -> int:
        return len(self.names)

    def structural_terms(self) -> list[str]:
        """The terms with a factor of the structural names ``x``, ``v``, ``a``
        (:data:`STRUCTURAL_FACTOR`)."""
        return [n for n in self.names
                if any(STRUCTURAL_FACTOR.match(f.partition("^")[0]) for f in n.split("*"))]

    def __repr__(self) -> str:
        return f"Library({len(self)} terms, n_coords={self.n_coords}, n_inputs={self.n_inputs})"

    def _factors(self, x: np.ndarray, xd: np.ndarray, xdd: np.ndarray | None,
                 u: np.ndarray | None) -> np.ndarray:
        n, m = self.n_coords, self.n_inputs
        x = np.atleast_2d(np.asarray(x, dtype=float))
        ns = x.shape[1]
        if x.shape[0] < n:
            # a library written for other data (the five-bar's on a two-coordinate rig): the
            # user's choice of hyperparameter, never a bug; a ValueError still
            raise HyperparameterError(f"library: its terms use {n} coordinates (th1..th{n}), the "
                                      f"data have {x.shape[0]}; expected a library of the data's "
                                      "coordinates (a list of terms, or 'generic')")
        if m and (u is None or np.shape(u)[0] < m):
            got = 0 if u is None else np.shape(u)[0]
            raise HyperparameterError(f"library: its terms use {m} inputs (u1..u{m}), the data "
                                      f"have {got}; expected a library of the data's inputs")
        F = np.empty((self._one + 1, ns))
        F[:n] = x[:n]
        F[n:2 * n] = np.atleast_2d(xd)[:n]
        F[2 * n:3 * n] = 0.0 if xdd is None else np.atleast_2d(xdd)[:n]
        if m:
            F[3 * n:3 * n + m] = np.atleast_2d(u)[:m]
        if self._trig:
            ang = self._arg @ x[:n]
            F[3 * n + m:self._one][self._is_sin] = np.sin(ang[self._is_sin])
            F[3 * n + m:self._one][~self._is_sin] = np.cos(ang[~self._is_sin])
        F[self._one] = 1.0
        return F

    @staticmethod
    def _products(F: np.ndarray, idx: np.ndarray) -> np.ndarray:
        out = np.empty((idx.shape[0], F.shape[1]))
        for s in range(0, F.shape[1], _CHUNK):
            out[:, s:s + _CHUNK] = np.prod(F[:, s:s + _CHUNK][idx], axis=1)
        return out

    def evaluate(self, x: np.ndarray, xd: np.ndarray, xdd: np.ndarray,
                 u: np.ndarray | None = None) -> np.ndarray:
        """Library matrix.

        Parameters
        ----------
        x, xd, xdd : ndarray, shape (n_coords, n_samples)
            Coordinates [rad or m] and their first and second time derivatives.
        u : ndarray, shape (n_inputs, n_samples), optional
            Inputs [N m or N]; required if any term uses one.

        Returns
        -------
        ndarray, shape (n_samples, n_terms)
            ``Theta``; a transposed view of a C-ordered (n_terms, n_samples) array, so that
            ``Theta.T @ Theta`` runs on contiguous rows.
        """
        return self._products(self._factors(x, xd, xdd, u), self._idx).T

    def evaluate_parts(self, x: np.ndarray, xd: np.ndarray,
                       u: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """The library split into its acceleration-free part and acceleration coefficients.

        ``Theta = free + sum_k acc[k] * xdd[k][:, None]`` for any accelerations.

        Returns
        -------
        free : ndarray, shape (n_samples, n_terms)
            Terms without an acceleration factor (0 for the others).
        acc : ndarray, shape (n_coords, n_samples, n_terms)
            ``acc[k, s, c]`` = d Theta[s, c] / d xdd[k, s].
        """
        rest = self._products(self._factors(x, xd, None, u), self._idx_noacc)
        has = self.acc_index >= 0
        free = np.where(has[:, None], 0.0, rest).T
        acc = np.zeros((self.n_coords, rest.shape[1], len(self)))
        for k in range(self.n_coords):
            sel = self.acc_index == k
            acc[k][:, sel] = rest[sel].T
        return free, acc

    def subset(self, names: Sequence[str]) -> Library:
        """A library of the given terms with the same coordinate and input counts."""
        return Library(names, self.n_coords, self.n_inputs)

    def input_columns(self, k: int) -> np.ndarray:
        """Indices of the terms with a factor ``u{k+1}`` (k 0-based)."""
        pat = re.compile(rf"(^|\*)u{k + 1}(\^\d+)?($|\*)")
        return np.array([c for c, nm in enumerate(self.names) if pat.search(nm)], dtype=np.intp)


def near_dependencies(G: np.ndarray, names: Sequence[str], rtol: float = 1e-9,
                      weight: float = 0.05) -> list[list[str]]:
    """Groups of columns that are (nearly) linearly dependent on the data.

    Parameters
    ----------
    G : ndarray, shape (p, p)
        Gram matrix ``Theta^T Theta`` of the library on the data.
    names : sequence of str
        Column names.
    rtol : float
        An eigenvalue of the unit-diagonal (correlation) Gram matrix below ``rtol`` counts as a
        dependence: ``rtol = 1e-9`` means a combination of unit-norm columns whose residual norm
        is below 3e-5 of a column's, far below any term the regression should keep apart.
    weight : float
        A column belongs to a group if its share in the null vector is above ``weight`` times
        the largest share.

    Returns
    -------
    list of list of str
        One group per near-null direction (sorted by eigenvalue), empty if none.
    """
    d = np.sqrt(np.clip(np.diag(G), np.finfo(float).tiny, None))
    w, V = np.linalg.eigh(G / np.outer(d, d))
    groups = []
    for e in np.flatnonzero(w < rtol * w.max()):
        v = np.abs(V[:, e])
        groups.append([names[i] for i in np.flatnonzero(v > weight * v.max())])
    return groups


def _pairs(n: int) -> list[tuple[int, int]]:
    return list(combinations(range(1, n + 1), 2))


def _chain_terms(a: int, b: int) -> tuple[list[str], list[str]]:
    """Open-chain Lagrange terms of base joint a and distal joint b (1-based, absolute angles).

    Both expressions carry both rates: the elbow joint's damping acts on the RELATIVE rate
    ``dth_b - dth_a`` (a joint between two links), so in absolute angles R_a has ``(c_a + c_e)
    dth_a - c_e dth_b`` and R_b has ``c_e (dth_b - dth_a)``.  The own rate comes first.
    """
    lo, hi = min(a, b), max(a, b)
    cos_, sin_ = f"cos(th{lo}-th{hi})", f"sin(th{lo}-th{hi})"
    return ([f"ddth{a}", f"{cos_}*ddth{b}", f"{sin_}*dth{b}^2", f"dth{a}", f"dth{b}"],
            [f"ddth{b}", f"{cos_}*ddth{a}", f"{sin_}*dth{a}^2", f"dth{b}", f"dth{a}"])


def fivebar_library(kind: str = "reduced", chains: Sequence[tuple[int, int]] = ((1, 2), (4, 3)),
                    n_inputs: int = 2) -> Library:
    """Library of the five-bar's reduced implicit equations (see the module docstring).

    With R_i the open-chain Lagrange terms of joint i (chain (a, b), a at the base, b distal:
    R_a ~ ``ddth_a, cos(th_a-th_b)*ddth_b, sin(th_a-th_b)*dth_b^2, dth_a, dth_b``, R_b ~
    ``ddth_b, cos(th_a-th_b)*ddth_a, sin(th_a-th_b)*dth_a^2, dth_b, dth_a``: both rates, as the
    elbow joint damps the relative rate) and p, q the distal (passive)
    joints, eliminating the loop forces gives for actuated joint k
    ``a_p a_q sin(th_p-th_q) (R_k - u_k) = a_k a_q sin(th_k-th_q) R_p - a_k a_p sin(th_k-th_p) R_q``.

    Parameters
    ----------
    kind : {"reduced", "full"}
        ``"reduced"``: exactly those products for both actuated joints, with every input
        times ``sin(th_p-th_q)`` (32 columns for the default chains: exactly the terms of
        the rig's true equations without gravity).  ``"full"``: every
        ``sin(th_i-th_j)`` (six pairs) times every chain term (``ddth_a``, ``ddth_b``,
        ``cos*ddth_a``, ``cos*ddth_b``, ``sin*dth_a^2``, ``sin*dth_b^2`` per chain, ``dth_1..4``,
        ``u_1..m``): 108 columns, free of functional identities but with dozens of kinematic
        ones on loop-closed data.  Reduced-equation terms come first (pruning priority).
    chains : sequence of (int, int)
        The two open chains (base joint, distal joint), 1-based.
    n_inputs : int
        Number of inputs; input k acts on the base joint of chain k.

    Notes
    -----
    Even the reduced library has two kinematic identities on loop-closed data (the
    acceleration-level loop constraint times trig factors, measured: eigenvalues 1e-16 of
    the unit-diagonal Gram matrix of its 30 input-free columns on 10 s records), and they lie
    within the support of each reduced equation: the implicit equations are unique only up to
    them.  ``SINDyPI(prune_tol=...)`` removes them; score against a truth modulo them.
    """
    (a1, b1), (a2, b2) = chains
    R = {}
    for a, b in chains:
        R[a], R[b] = _chain_terms(a, b)
    terms: list[str] = []
    for k, (p, q) in ((a1, (b1, b2)), (a2, (b1, b2))):
        for fac, group in (((p, q), R[k]), ((k, q), R[p]), ((k, p), R[q])):
            terms += [f"sin(th{fac[0]}-th{fac[1]})*{t}" for t in group]
        terms += [f"sin(th{p}-th{q})*u{m}" for m in range(1, n_inputs + 1)]
    terms = list(dict.fromkeys(canonical(t)[0] for t in terms))
    if kind == "reduced":
        return Library(terms, 4, n_inputs)
    if kind != "full":
        raise ValueError(f"kind must be 'reduced' or 'full', got {kind!r}")
    chain_terms = []
    for a, b in chains:
        ra, rb = _chain_terms(a, b)
        chain_terms += ra[:3] + rb[:3]
    chain_terms += [f"dth{k}" for k in range(1, 5)] + [f"u{k}" for k in range(1, n_inputs + 1)]
    full = [canonical(f"sin(th{i}-th{j})*{c}")[0] for i, j in _pairs(4) for c in chain_terms]
    return Library(terms + [t for t in full if t not in set(terms)], 4, n_inputs)


def generic_mechanical_library(n_coords: int, n_inputs: int = 0, velocity_acceleration: bool = True,
                               ) -> Library:
    """A larger mechanical library, for stress tests and for open chains with gravity.

    Trig factors ``1, sin(th_i), cos(th_i), sin(th_i-th_j), cos(th_i-th_j)`` times chain
    terms ``ddth_k, dth_k, dth_i*dth_j (i <= j), u_k, 1`` and, if ``velocity_acceleration``,
    ``dth_i*ddth_j`` (no Lagrangian system has these: they are distractors).  Single-angle
    products such as ``sin(th1)*cos(th2)`` are left out because they are exactly dependent on
    the difference terms (``sin(th1-th2) = sin th1 cos th2 - cos th1 sin th2``).

    Returns
    -------
    Library
        98 columns for 2 coordinates and 2 inputs (7 x 14).
    """
    n = n_coords
    trig = ["1"] + [f"{f}(th{i})" for i in range(1, n + 1) for f in ("sin", "cos")]
    trig += [f"{f}(th{i}-th{j})" for i, j in _pairs(n) for f in ("sin", "cos")]
    chain = [f"ddth{k}" for k in range(1, n + 1)] + [f"dth{k}" for k in range(1, n + 1)]
    chain += [f"dth{i}*dth{j}" for i in range(1, n + 1) for j in range(i, n + 1)]
    if velocity_acceleration:
        chain += [f"dth{i}*ddth{j}" for i in range(1, n + 1) for j in range(1, n + 1)]
    chain += [f"u{k}" for k in range(1, n_inputs + 1)] + ["1"]
    terms = [c if t == "1" else (t if c == "1" else f"{t}*{c}") for t in trig for c in chain]
    return Library([t for t in terms if t != "1"], n, n_inputs)


def linear_structural_library(n_channels: int) -> Library:
    """``x_i``, ``v_i``, ``a_i`` per channel: displacement, velocity, acceleration (3n columns)."""
    return Library([f"{s}{i}" for s in ("x", "v", "a") for i in range(1, n_channels + 1)],
                   n_channels, 0)
