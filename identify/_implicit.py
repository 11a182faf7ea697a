"""Shared machinery of the implicit (SINDy-PI) identifiers: the shared-Gram sequentially
thresholded least-squares sweep, held-out model selection, and equation selection.

All regressions run in *normalised* units: column c of the library is divided by its training
norm ``s_c``, so a coefficient is the share of a unit-norm column and one threshold means the
same for every term.  An implicit model for left-hand side j is a row ``W`` (n_terms,) with
``W[j] = 1`` and ``Theta_n @ W ~ 0``; its held-out error is the normalised residual
``||Theta_val,n W||^2 / ||Theta_val,n[:, j]||^2 = W^T G_v W / G_v[j, j]``, computed from the
validation Gram matrix ``G_v`` for every model at once.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from itertools import pairwise

import numpy as np

from testbed.core.errors import IdentificationError

DEFAULT_THRESHOLDS = np.r_[0.0, np.logspace(-6, -0.5, 12)]


class NoModelError(IdentificationError):
    """No model of the sweep is eligible as some input's equation (:func:`select_models`)."""


def split_index(n_samples: int, val_fraction: float) -> int:
    """Index of the first validation sample: the last ``val_fraction`` of the record in time."""
    if not 0.0 < val_fraction < 1.0:
        raise ValueError(f"val_fraction must lie in (0, 1), got {val_fraction}")
    n_tr = round(n_samples * (1.0 - val_fraction))
    if n_tr < 2 or n_samples - n_tr < 2:
        raise IdentificationError(f"{n_samples} samples are too few to split for validation")
    return n_tr


def grams(Theta: np.ndarray, n_train: int) -> tuple[np.ndarray, np.ndarray]:
    """Training and validation Gram matrices ``Theta^T Theta``, each (p, p).

    ``A.T @ A`` on row blocks of ``Theta``: numpy hands it to BLAS's symmetric rank-k update
    for either memory order, without the transposed copy a C-ordered ``Theta`` needed before
    (2-3x the products at 100k x 97, measured; the libraries build ``Theta`` F-ordered, where
    both cost the same, 24-30 ms on one core).
    """
    train, val = Theta[:n_train], Theta[n_train:]
    return train.T @ train, val.T @ val


@dataclass
class Sweep:
    """Every (threshold, candidate) model of a SINDy-PI sweep.

    Attributes
    ----------
    scale : ndarray, shape (p,)
        Training norm of each column (1 for all-zero columns).
    candidates : ndarray of int, shape (C,)
        Left-hand-side column of each model.
    thresholds : ndarray, shape (T,)
        Thresholds on normalised coefficients.
    W : ndarray, shape (T, C, p)
        Implicit coefficients in normalised units, ``W[t, c, candidates[c]] = 1``.
    val_error, train_error : ndarray, shape (T, C)
        Normalised squared residuals on the validation and training samples.
    nnz : ndarray of int, shape (T, C)
        Number of terms of each model (left-hand side included).
    """

    scale: np.ndarray
    candidates: np.ndarray
    thresholds: np.ndarray
    W: np.ndarray
    val_error: np.ndarray
    train_error: np.ndarray
    nnz: np.ndarray

    def coef(self, t: int, c: int) -> np.ndarray:
        """Model (t, c) in original units, scaled to max |coef| = 1, sign by :func:`canonical_scale`."""
        return canonical_scale(self.W[t, c] / self.scale)


#: Coefficients below this share of the largest one do not decide an equation's sign: they are
#: at most round-off residue of a threshold-0 fit (1e-6 is ten orders above float64's 1e-16).
SIGN_RTOL = 1e-6


def canonical_scale(w: np.ndarray) -> np.ndarray:
    """An implicit equation scaled by the declared convention: ``max |coef| = 1`` and the first
    term in library order whose ``|coef|`` exceeds ``SIGN_RTOL`` of the largest is positive.

    The magnitude is tie-proof; the sign is not taken from the largest entry, because by the
    rig's symmetry several entries can be exactly +-1 and which is "largest" is then decided by
    rounding (it differed between OpenBLAS kernels).
    """
    w = np.asarray(w, dtype=float)
    big = np.abs(w).max(initial=0.0)
    if not np.isfinite(big) or big == 0.0:
        return w.copy()
    w = w / big
    first = np.flatnonzero(np.abs(w) > SIGN_RTOL)[0]
    return w if w[first] > 0 else -w


def _errors(W: np.ndarray, G: np.ndarray, cand: np.ndarray) -> np.ndarray:
    num = np.einsum("tcp,tcp->tc", W @ G, W)
    den = G[cand, cand]
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den > 0, np.maximum(num, 0.0) / np.where(den > 0, den, 1.0), np.inf)


#: Supports are solved in batches of equal padded size: sizes rounded up to this multiple (the
#: padding is an identity block with a zero right-hand side, so the solution is unchanged).
#: Fewer, larger LAPACK calls: the per-call overhead, not the flops, dominated at p ~ 100.
_SIZE_STEP = 8


def _solve_masked(Gn: np.ndarray, cand: np.ndarray, mask: np.ndarray, ridge: float) -> np.ndarray:
    """Least squares of column cand[k] on the columns mask[k], for every k.

    Each model is solved on its support only, ``(Gn[S, S] + ridge I) xi_S = Gn[c, S]`` (the
    other coefficients are zero), with one factorisation per distinct support, shared by every
    model on it (on exact data many left-hand sides share one support).  Supports are batched
    by size (padded to a multiple of ``_SIZE_STEP``) into one LAPACK call each.  An exactly
    singular support gets the minimum-norm solution instead.
    """
    p = Gn.shape[0]
    out = np.zeros(mask.shape)
    groups: dict[bytes, list[int]] = {}
    for k in range(mask.shape[0]):
        groups.setdefault(np.packbits(mask[k]).tobytes(), []).append(k)
    sups = [ks for ks in groups.values() if mask[ks[0]].any()]
    if not sups:
        return out
    sizes = np.array([np.count_nonzero(mask[ks[0]]) for ks in sups])
    padded = -(-sizes // _SIZE_STEP) * _SIZE_STEP
    Gx = np.zeros((p + 1, p + 1))  # Gn with a zero row and column p for the padding
    Gx[:p, :p] = Gn
    for size in np.unique(padded):
        js = np.flatnonzero(padded == size)
        Sidx = np.full((js.size, size), p)                          # p: padding
        for r, j in enumerate(js):
            Sidx[r, :sizes[j]] = np.flatnonzero(mask[sups[j][0]])
        jj = np.concatenate([np.full(len(sups[j]), r) for r, j in enumerate(js)])  # its support
        ll = np.concatenate([np.arange(len(sups[j])) for j in js])              # its rhs slot
        kk = np.concatenate([sups[j] for j in js])
        A = Gx[Sidx[:, :, None], Sidx[:, None, :]]
        d = np.arange(size)
        A[:, d, d] += np.where(Sidx < p, ridge, 1.0)
        R = np.zeros((js.size, size, int(ll.max()) + 1))
        R[jj, :, ll] = Gx[cand[kk][:, None], Sidx[jj]]
        try:
            sol = np.linalg.solve(A, R)
        except np.linalg.LinAlgError:  # some support exactly singular: one at a time
            sol = np.empty_like(R)
            for r in range(js.size):
                try:
                    sol[r] = np.linalg.solve(A[r], R[r])
                except np.linalg.LinAlgError:
                    sol[r] = np.linalg.pinv(A[r], hermitian=True) @ R[r]
        valid = Sidx[jj] < p
        rows = np.broadcast_to(kk[:, None], valid.shape)
        out[rows[valid], Sidx[jj][valid]] = sol[jj, :, ll][valid]
    return out


def _stlsq_rounds(Gn: np.ndarray, cand: np.ndarray, base: np.ndarray, xi: np.ndarray,
                  thr: np.ndarray, ridge: float, max_iter: int) -> np.ndarray:
    """The thresholding rounds of :func:`stlsq_sweep` batched across candidates, each round's
    refits by :func:`_solve_masked` (LAPACK, minimum norm on exactly singular supports).

    The path for candidates the compiled kernel flags as exactly singular; models of shape
    (T, C, p).
    """
    xi = xi.copy()
    mask = base.copy()
    models = np.empty((thr.size, cand.size, Gn.shape[0]))
    for t, lam in enumerate(thr):
        for _ in range(max_iter):
            new = base & (np.abs(xi) >= lam)
            changed = np.flatnonzero((new != mask).any(axis=1))
            if changed.size == 0:
                break
            mask[changed] = new[changed]
            xi[changed] = _solve_masked(Gn, cand[changed], mask[changed], ridge)
        models[t] = xi
    return models


def stlsq_sweep(G_train: np.ndarray, G_val: np.ndarray, candidates: Sequence[int],
                thresholds: Sequence[float], ridge: float = 1e-14, max_iter: int = 20) -> Sweep:
    """SINDy-PI by sequentially thresholded least squares, all candidates on one Gram matrix.

    For left-hand side j the regression ``Theta_j ~ Theta_{-j} xi`` has normal equations
    ``G_{-j,-j} xi = G_{-j,j}``.  The first (unthresholded) solutions of all candidates come
    from one inverse, ``B = (G + ridge I)^-1``: ``xi = -B[:, j] / B[j, j]`` (the Schur
    complement identity).  Then, threshold by threshold (ascending, warm-started from the
    previous threshold's models), coefficients with ``|xi| < threshold`` are zeroed and the
    models whose support changed are refitted on their support, until no support changes (at
    most ``max_iter`` rounds).  The refits run in one compiled loop
    (:func:`identify._pi_kernels.stlsq_chains_downdate`): supports only shrink along a
    candidate's path, so each refit deletes columns from one shared Cholesky factor of
    ``G + ridge I`` by Givens rotations instead of factorising anew (at 100k x 97: ~1,280
    refits, 87 ms as batched LAPACK solves, ~8 ms compiled).  If that factor does not exist
    (not numerically positive definite) each refit gets a fresh Cholesky, else LU
    (:func:`identify._pi_kernels.stlsq_chains`); an exactly singular support sends its
    candidate to the round-batched LAPACK path with minimum-norm solutions
    (:func:`_stlsq_rounds`).  All paths solve the same normal equations and agree to
    round-off times the support's condition number (``tests/identify/test_sindy_pi_kernels.py``
    states the comparison rule); on exact data, where supports along the path are
    rank-deficient, round-off decides intermediate supports and so the threshold index at
    which a selected equation is first reached (its support and coefficients are unchanged).

    Parameters
    ----------
    G_train, G_val : ndarray, shape (p, p)
        Gram matrices of the training and validation samples.
    candidates : sequence of int
        Left-hand-side columns.
    thresholds : sequence of float
        Thresholds on normalised coefficients, ascending.
    ridge : float
        Added to the unit diagonal of the normalised Gram matrix.  The default 1e-14 is a
        numerical safeguard at the level of the Gram matrix's own round-off (it biases a
        coefficient by about ridge / smallest eigenvalue); raise it for ridge regression.
    max_iter : int
        Thresholding rounds per threshold.

    Returns
    -------
    Sweep
    """
    p = G_train.shape[0]
    s = np.sqrt(np.clip(np.diag(G_train), 0.0, None))
    dead = s <= 1e-300 + 1e-150 * s.max(initial=0.0)
    s = np.where(dead, 1.0, s)
    Gn = G_train / np.outer(s, s)
    Gv = G_val / np.outer(s, s)
    cand = np.asarray(candidates, dtype=np.intp)
    cand = cand[~dead[cand]]
    if cand.size == 0:
        raise IdentificationError("every candidate left-hand-side column is zero on the data")
    thr = np.asarray(thresholds, dtype=float)
    if np.any(np.diff(thr) < 0):
        raise ValueError("thresholds must be ascending")
    n_c, idx = cand.size, np.arange(cand.size)
    A = Gn + ridge * np.eye(p)
    A[dead, dead] = 1.0
    B = np.linalg.inv(A)
    xi = -(B[:, cand] / B[cand, cand]).T
    base = ~dead[None, :].repeat(n_c, axis=0)
    base[idx, cand] = False
    xi[~base] = 0.0
    from identify._pi_kernels import stlsq_chains, stlsq_chains_downdate  # lazy: numba ~0.4 s

    args = (thr, float(ridge), int(max_iter))
    models, status, _ = stlsq_chains_downdate(Gn, cand, ~dead, base, xi, *args)
    if np.all(status == 2):  # Gn + ridge I not numerically positive definite: fresh refits
        models, status, _ = stlsq_chains(Gn, cand, base, xi, *args)
    bad = np.flatnonzero(status == 2)  # a support exactly singular: minimum-norm refits
    if bad.size:
        models[:, bad] = _stlsq_rounds(Gn, cand[bad], base[bad], xi[bad], thr, ridge, max_iter)
    if not np.all(np.isfinite(models)):
        raise IdentificationError("the thresholded least-squares sweep produced non-finite "
                                  "coefficients (library columns exactly dependent?)")
    W = np.negative(models, out=models)  # in place: one (T, C, p) array less
    W[:, idx, cand] = 1.0
    return Sweep(scale=s, candidates=cand, thresholds=thr, W=W, val_error=_errors(W, Gv, cand),
                 train_error=_errors(W, Gn, cand), nnz=np.count_nonzero(W, axis=2))


def merge_sweeps(full: Sweep, part: Sweep, cols: np.ndarray) -> Sweep:
    """One sweep holding the models of ``full`` and then those of ``part``.

    ``part`` was run on the columns ``cols`` (indices into ``full``'s columns) of the same
    Gram matrices with the same thresholds (e.g. the input-free columns, for the equations of
    passive coordinates); its models are embedded with zeros on the other columns, its
    candidates renumbered to ``full``'s columns.
    """
    if not np.array_equal(full.thresholds, part.thresholds):
        raise ValueError("sweeps with different thresholds cannot be merged")
    cols = np.asarray(cols, dtype=np.intp)
    W = np.zeros(part.W.shape[:2] + full.W.shape[2:])
    W[..., cols] = part.W
    cat = lambda a, b: np.concatenate([a, b], axis=1)  # noqa: E731 - along the candidates
    return Sweep(scale=full.scale, candidates=np.concatenate([full.candidates, cols[part.candidates]]),
                 thresholds=full.thresholds, W=np.concatenate([full.W, W], axis=1),
                 val_error=cat(full.val_error, part.val_error),
                 train_error=cat(full.train_error, part.train_error), nnz=cat(full.nnz, part.nnz))

def input_shares(W: np.ndarray, input_cols: Sequence[np.ndarray]) -> np.ndarray:
    """Largest |normalised coefficient| of each input's terms, shape (n_inputs,) + W.shape[:-1]."""
    return np.stack([np.abs(W[..., c]).max(axis=-1) if c.size else np.zeros(W.shape[:-1])
                     for c in input_cols])


def rank_models(sw: Sweep, elig: np.ndarray, rtol: float, atol: float) -> np.ndarray:
    """Flat (threshold, candidate) indices of the eligible models, best first.

    A model whose held-out error is within ``best * (1 + rtol) + atol`` counts as equally good
    as the best; those come first, ordered by the declared rule:

    1. fewest terms;
    2. smaller held-out error, where errors at or below ``atol`` count as exactly equal (they
       are all "exact to the digits the Gram-based residual has", and ordering them would
       let rounding, i.e. the CPU's BLAS kernel, decide);
    3. the support in library order (lexicographically smallest set of column indices);
    4. the left-hand-side column in library order, then the threshold index.

    On exact data many candidates share one support (the same equation normalised on different
    left-hand sides); rules 3-4 pick the same representative on every machine.  The others
    follow by held-out error.  Ineligible models are left out.
    """
    err = np.where(elig & np.isfinite(sw.val_error), sw.val_error, np.inf)
    if not np.isfinite(err).any():
        return np.zeros(0, dtype=np.intp)
    good = (err <= err.min() * (1.0 + rtol) + atol).ravel()
    flat_err = err.ravel()
    n_t, n_c = err.shape
    support = (sw.W != 0).reshape(n_t * n_c, -1)
    # rank of each good model's support among the good ones in lexicographic library order
    # (rule 3): the support read as a bit string, first library column most significant
    # (a dense rank: equal supports share one)
    sup_rank = np.zeros(n_t * n_c, dtype=np.int64)
    gi = np.flatnonzero(good)
    rows = ~support[gi]
    order_s = np.lexsort(rows[:, ::-1].T)
    new_row = np.r_[True, np.any(rows[order_s[1:]] != rows[order_s[:-1]], axis=1)]
    sup_rank[gi[order_s]] = np.cumsum(new_row) - 1
    cand = np.tile(sw.candidates, n_t)
    thr = np.repeat(np.arange(n_t), n_c)
    tied_err = np.where(flat_err <= atol, 0.0, flat_err)
    big = np.iinfo(np.int64).max
    order = np.lexsort((thr, cand, np.where(good, sup_rank, big),
                        np.where(good, tied_err, flat_err),
                        np.where(good, sw.nnz.ravel(), big), ~good))
    return order[np.isfinite(flat_err[order])]


def no_model_reason(sw: Sweep, shares: np.ndarray, k: int) -> str:
    """Why no model of the sweep is eligible for input ``k`` (0-based), for the error.

    Three cases, told apart: no model carries the input's terms at all (the library lacks them,
    or the input is zero); some do, but another input's terms outweigh them in every one (the
    record does not separate the inputs: too short, or too little excited); or every model
    carrying it has a non-finite held-out error.

    Parameters
    ----------
    sw : Sweep
    shares : ndarray, shape (n_inputs, T, C)
        :func:`input_shares` of ``sw.W``.
    k : int
        The input.

    Returns
    -------
    str
    """
    head = f"no implicit model contains input {k + 1} as its dominant input"
    has = shares[k] > 0
    n_has = int(np.count_nonzero(has))
    if n_has == 0:
        return f"{head}: no model carries its terms (the library lacks them, or the input is zero)"
    others = np.delete(shares, k, axis=0)
    dominant = has & (shares[k] > (others.max(axis=0) if others.size else 0.0))
    if not dominant.any():
        share_k, share_o = shares[k][has], others.max(axis=0)[has]
        j = int(np.argmax(np.bincount(np.argmax(others[:, has], axis=0), minlength=len(others))))
        j += j >= k  # index among all inputs
        return (f"{head}: {n_has} of {has.size} models carry its terms, but another input's "
                f"outweigh them in every one (largest share of input {k + 1} / of the others: "
                f"{np.max(share_k / np.maximum(share_o, 1e-300)):.3g}; most often input {j + 1}): "
                "the record does not separate the inputs (too short, or too little excited)")
    return (f"{head}: the {int(np.count_nonzero(dominant))} models where it dominates have no "
            "finite held-out error")


def input_errors(sw: Sweep, G_val: np.ndarray, cols: np.ndarray, n_val: int = 0) -> np.ndarray:
    """Held-out residual of every model per unit of its input part, shape (T, C).

    ``W^T G W / (W_u^T G W_u)`` with ``G`` the validation Gram in normalised units (``G_val``,
    shape (p, p), over ``sw.scale``) and ``W_u`` the model restricted to the input's columns
    ``cols``: the residual relative to the force the equation attributes to its input.
    Adding an input-free equation that holds (a passive coordinate's) leaves it nearly
    unchanged, where the left-hand-side normalisation of ``sw.val_error`` falls with the
    input's share: on an open chain a passive equation plus a small admixture ``eps`` of the
    input's (round 16's ``cp16_3s`` clean: the pole's equation taken as the cart's, input
    share 0.029, law_error 0.855) has a residual per unit of left-hand side ``eps^2`` times the
    input equation's.  ``inf`` where the input part is zero.

    With ``n_val`` (the validation rows behind ``G_val``) the residual is floored at its
    round-off bound, ``n_val eps (sum_i |w_i| sqrt(G_ii))^2`` (each Gram entry a sum of
    ``n_val`` products; as :mod:`identify.sindy_pi_dynamical`'s exact tie): below it the
    residual's value and sign are round-off's, and clipping it at 0 let the CPU decide the
    ranking (session 18's portability runs: a pole equation plus a 1e-6 input admixture,
    input part 2.7e-17 under a bound 2.6x larger, ranked first on AVX-512 at residual
    -3.2e-17 and not under Haswell at +1.0e-17).

    Returns
    -------
    ndarray, shape (T, C)
        Dimensionless ratio of squared norms.
    """
    Gn = G_val / np.outer(sw.scale, sw.scale)
    Wu = np.zeros_like(sw.W)
    Wu[..., cols] = sw.W[..., cols]
    num = np.einsum("tcp,tcp->tc", sw.W @ Gn, sw.W)
    den = np.einsum("tcp,tcp->tc", Wu @ Gn, Wu)
    if n_val > 0:
        norm = np.sqrt(np.clip(np.diag(Gn), 0.0, None))
        num = np.maximum(num, n_val * np.finfo(float).eps * (np.abs(sw.W) @ norm) ** 2)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(den > 0, np.maximum(num, 0.0) / np.where(den > 0, den, 1.0), np.inf)


def select_models(sw: Sweep, input_cols: Sequence[np.ndarray], rtol: float = 0.1,
                  atol: float = 1e-12, top: int = 1, G_val: np.ndarray | None = None,
                  n_val: int = 0) -> list[list[tuple[int, int]]]:
    """Pick the implicit equation of each input by held-out error, then parsimony.

    Models eligible for input k are those whose input-k terms carry a larger normalised
    coefficient than every other input's terms (so a sparse model contains u_k and no other
    input), or one within the tie ``rtol`` of theirs (``share_k (1 + rtol) > share_other``):
    a dense equation that mixes the inputs' equations about equally counts for each of them,
    since its shares are round-off's where the record leaves directions of the Gram matrix
    undetermined (session 29, pi34: round 20's ``fb20_ms_short_cranks`` clean, the 26-term
    equation on input 2's term carried input 1's at 0.967 of input 2's share under OpenBLAS's
    Haswell kernel and 1.059 under SkylakeX: eligible on one machine only, 1.8e-6 against
    1.2e-4 rad).  The first pick of an earlier input is not offered again (the same equation up
    to scale, ``PARALLEL_RTOL``), so the inputs' first picks stay distinct (an equation
    further down one input's list may still stand in another's).
    They are ranked by
    :func:`rank_models`, by their held-out error (``sw.val_error``, per unit of the left-hand
    side) or, where ``G_val`` is given, per unit of the input's part (:func:`input_errors`;
    what ``sindy_pi`` passes for open chains, docs/known-gaps.md "SINDy-PI: the cart-pole's
    input equation (session 18)").

    Parameters
    ----------
    sw : Sweep
    input_cols : sequence of ndarray of int
        Library columns carrying each input.
    rtol : float
        Relative tolerance on the held-out error; 0.1 because the held-out residual of models
        differing by noise-level terms varies by about that much between validation windows.
        Also the tie of two inputs' shares in one equation (above).
    atol : float
        Absolute floor of the normalised squared residual: 1e-12 (a relative residual norm
        of 1e-6) is where the Gram-based residual of an exact model loses its digits.
    top : int
        Number of models returned per input (distinct supports, best first).
    G_val : ndarray, shape (p, p), optional
        Validation Gram matrix in original units: rank by :func:`input_errors`.
    n_val : int
        The validation rows behind ``G_val`` (0: no round-off floor; :func:`input_errors`).

    Returns
    -------
    list (one per input) of list of (threshold index, candidate index)
    """
    shares = input_shares(sw.W, input_cols)
    out = []
    for k in range(len(input_cols)):
        others = np.delete(shares, k, axis=0)
        other = others.max(axis=0) if others.size else np.zeros_like(shares[k])
        ranked = sw if G_val is None else replace(sw, val_error=input_errors(
            sw, G_val, input_cols[k], n_val))
        dominant = (shares[k] > 0) & (shares[k] * (1.0 + rtol) > other)
        elig = dominant.copy()
        for p in out:  # an earlier input's first pick, up to scale, is not offered again
            elig &= ~_parallel(sw.W, sw.W[p[0]])
        order = rank_models(ranked, elig, rtol, atol)
        if order.size == 0:
            if rank_models(ranked, dominant, rtol, atol).size == 0:
                raise NoModelError(no_model_reason(sw, shares, k))
            raise NoModelError(f"no implicit model contains input {k + 1} as its dominant input "
                               "other than the equation picked for an earlier input")
        picked: list[tuple[int, int]] = []
        seen: set[bytes] = set()
        for flat in order:
            t, c = np.unravel_index(flat, sw.val_error.shape)
            key = np.flatnonzero(sw.W[t, c]).tobytes()
            if key not in seen:
                seen.add(key)
                picked.append((int(t), int(c)))
            if len(picked) == top:
                break
        out.append(picked)
    return out


#: Two implicit equations are one up to scale where their normalised coefficient vectors'
#: cosine is within this of 1 [-]: 1e-9, an angle of 4.5e-5 rad, far above the round-off of a
#: unit vector's products (1e-16); two equations closer than that, taken for two inputs, leave
#: the input gain as near singular as that angle.
PARALLEL_RTOL = 1e-9


def _parallel(W: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Whether each model of ``W`` (T, C, p) is ``w`` (p,) up to scale, shape (T, C)."""
    nw = np.linalg.norm(W, axis=-1) * np.linalg.norm(w)
    with np.errstate(invalid="ignore", divide="ignore"):
        cos = np.abs(np.einsum("tcp,p->tc", W, w)) / np.where(nw > 0, nw, 1.0)
    return (nw > 0) & (cos >= 1.0 - PARALLEL_RTOL)


def select_passive_models(sw: Sweep, input_cols: Sequence[np.ndarray],
                          acc_cols: Sequence[np.ndarray], rtol: float = 0.1, atol: float = 1e-12,
                          top: int = 1, labels: Sequence[str] | None = None,
                          G_val: np.ndarray | None = None, n_val: int = 0
                          ) -> list[list[tuple[int, int]]]:
    """Pick the implicit equation of each passive coordinate of an open (underactuated) chain.

    A passive coordinate is driven by no input, so its equation of motion holds without any
    input term.  Models eligible for passive coordinate p carry no input term at all and a
    nonzero coefficient on a term with p's acceleration (``acc_cols[p]``), so the equation can
    be solved for it; they are ranked by :func:`rank_models` (held-out error, then
    parsimony) by their held-out error per unit of the left-hand side (``sw.val_error``).
    Where ``G_val`` is given, that ranking stands unless the record refutes its first pick per
    unit of the part holding p's acceleration (:func:`input_errors` over ``acc_cols[p]``): where
    that pick's error so is beyond the tie (``rtol``, ``atol``) of the best eligible model's,
    the models are ranked per unit of that part instead.  The first choice of an earlier
    passive coordinate is not offered again (two copies of one equation would leave the
    accelerations undetermined).

    Why per unit of the acceleration's part: a record on which two columns nearly coincide (a
    pole swinging +-0.25 rad: ``X`` and ``cos(th2)*X`` differ by at most 3 %) holds near-exact
    input-free identities such as ``ddth1 - cos(th2)*ddth1 = 0``; one written on its own
    left-hand side has a residual per unit of that side far below the passive equation's (the
    identity's own residual, not the noise's), so the identity plus a small admixture of the
    passive equation ranked first.  Per unit of the part that holds p's acceleration, adding
    an identity without that acceleration only adds its residual, and one whose terms cancel
    on it (``ddth2 - cos(th2)*ddth2``) shrinks the part: the equation of the coordinate's own
    motion ranks first, as the input's equation does per unit of its input's part (the same
    argument, :func:`input_errors`).  Only where the first pick is refuted so: ranking every
    record per unit of that part moved the long simulations of cells whose first pick was as
    good there (within the tie) both ways, by the luck of near-equal models (146 cart-pole
    cells: 119 -> 121 passed, 7 gained, 5 lost; refuted picks only: 119 -> 124, 6 gained, 1
    lost on a record the scorer names sensitive).  Measured: docs/known-gaps.md "SINDy-PI: the
    passive equation per unit of its acceleration (session 23)".

    Parameters
    ----------
    sw : Sweep
    input_cols : sequence of ndarray of int
        Library columns carrying each input.
    acc_cols : sequence of ndarray of int
        Per passive coordinate, the library columns holding its acceleration.
    rtol, atol : float
        As in :func:`select_models`.
    top : int
        Number of models returned per passive coordinate (distinct supports, best first).
    labels : sequence of str, optional
        Names of the passive coordinates for messages (default their positions, from 1).
    G_val : ndarray, shape (p, p), optional
        Validation Gram matrix in original units: test the first pick by :func:`input_errors`
        over each passive coordinate's acceleration columns (and rank by it where refuted).
    n_val : int
        The validation rows behind ``G_val`` (its round-off floor, :func:`input_errors`).

    Returns
    -------
    list (one per passive coordinate) of list of (threshold index, candidate index)

    Raises
    ------
    IdentificationError
        No eligible model for a passive coordinate.
    """
    free = np.ones(sw.W.shape[:-1], dtype=bool)
    if len(input_cols):
        free = ~(input_shares(sw.W, input_cols) > 0).any(axis=0)
    taken: set[bytes] = set()
    out = []
    for p, cols in enumerate(acc_cols):
        has_acc = (sw.W[..., cols] != 0).any(axis=-1) if cols.size else np.zeros_like(free)
        order = rank_models(sw, free & has_acc, rtol, atol)
        if G_val is not None and cols.size and order.size:
            # the held-out ranking stands unless the record refutes its first pick per unit
            # of p's acceleration part: beyond the tie of the best there
            # (the first pick is the first entry whose support no earlier coordinate took, as
            # the loop below picks it; models of a taken support are not offered as the best)
            acc_err = input_errors(sw, G_val, cols, n_val)
            offered = np.ones_like(free)
            if taken:
                supp = (sw.W != 0).reshape(-1, sw.W.shape[-1])
                offered = np.array([np.flatnonzero(r).tobytes() not in taken for r in supp]
                                   ).reshape(free.shape)
            ok = free & has_acc & np.isfinite(sw.val_error)
            elig = ok & offered & np.isfinite(acc_err)
            best = acc_err[elig].min() if elig.any() else np.inf
            first = next((f for f in order if offered.ravel()[f]), None)
            if first is not None and not acc_err.ravel()[first] <= best * (1.0 + rtol) + atol:
                order = rank_models(replace(sw, val_error=acc_err), ok, rtol, atol)
        picked: list[tuple[int, int]] = []
        seen: set[bytes] = set()
        for flat in order:
            t, c = np.unravel_index(flat, sw.val_error.shape)
            key = np.flatnonzero(sw.W[t, c]).tobytes()
            if key in seen or (not picked and key in taken):
                continue
            seen.add(key)
            picked.append((int(t), int(c)))
            if len(picked) == top:
                break
        if not picked:
            name = labels[p] if labels is not None else str(p + 1)
            raise IdentificationError(
                f"no input-free implicit model contains the acceleration of passive coordinate "
                f"{name} of the open chain: the library (or lhs) lacks its equation's terms")
        taken.add(np.flatnonzero(sw.W[picked[0]]).tobytes())
        out.append(picked)
    return out

@dataclass
class Ensemble:
    """Bagged refits of selected implicit models (E-SINDy's bagging and bragging).

    Attributes
    ----------
    coef : ndarray, shape (n_models, p)
        Median over the bags of each term's coefficient (original units, the left-hand-side
        term's coefficient 1), zeroed where the inclusion probability is below the cut.
    std : ndarray, shape (n_models, p)
        Standard deviation over the bags, same units.
    inclusion : ndarray, shape (n_models, p)
        Share of bags in which each term is non-zero.
    """

    coef: np.ndarray
    std: np.ndarray
    inclusion: np.ndarray


def block_grams(Theta_train: np.ndarray, n_blocks: int) -> np.ndarray:
    """Gram matrices of ``n_blocks`` contiguous row blocks, shape (n_blocks, p, p)."""
    n = Theta_train.shape[0]
    if n < n_blocks:
        raise IdentificationError(f"{n} training rows are too few for {n_blocks} ensemble blocks")
    edges = np.linspace(0, n, n_blocks + 1).round().astype(np.intp)
    return np.stack([Theta_train[a:b].T @ Theta_train[a:b] for a, b in pairwise(edges)])


def bagged_models(blocks: np.ndarray, G_val: np.ndarray, picks: Sequence[tuple[int, int]],
                  sw: Sweep, n_bags: int, ridge: float, max_iter: int,
                  rng: np.random.Generator, inclusion_min: float = 0.5,
                  aggregate: str = "median") -> Ensemble:
    """Refit each picked model on ``n_bags`` block bootstraps of the training rows.

    Every bag draws as many blocks as there are, with replacement (a moving-block bootstrap:
    blocks keep the rows' time correlation), sums their Gram matrices and reruns the
    thresholded least squares of the picked left-hand side over the thresholds up to the
    picked one (:func:`stlsq_sweep`, so the path is the full fit's).  Coefficients are
    compared in original units with the left-hand side's coefficient 1.

    Parameters
    ----------
    blocks : ndarray, shape (n_blocks, p, p)
        :func:`block_grams` of the training rows (kept columns).
    G_val : ndarray, shape (p, p)
    picks : sequence of (threshold index, candidate index)
        The selected models of ``sw``.
    sw : Sweep
        The full fit's sweep (its candidates and thresholds).
    n_bags : int
    ridge : float
    max_iter : int
    rng : numpy Generator
    inclusion_min : float
        Terms in fewer than this share of the bags are zeroed in the aggregate model (E-SINDy's
        inclusion cut; 0.5: in the majority of bags).
    aggregate : {"median", "mean", "refit"}
        Per-term median (E-SINDy's bragging) or mean (bagging) over the bags, or a least-
        squares refit on all training rows of the terms kept by the inclusion cut (one
        consistent equation instead of per-term aggregates).

    Returns
    -------
    Ensemble
    """
    nb = blocks.shape[0]
    p = blocks.shape[1]
    draws = np.zeros((len(picks), n_bags, p))
    for b in range(n_bags):
        G = blocks[rng.integers(0, nb, nb)].sum(axis=0)
        for r, (t, c) in enumerate(picks):
            j = int(sw.candidates[c])
            try:
                bag = stlsq_sweep(G, G_val, [j], sw.thresholds[:t + 1], ridge, max_iter)
            except IdentificationError:
                draws[r, b] = np.nan
                continue
            w = bag.W[-1, 0] / bag.scale
            draws[r, b] = w / w[j]
    ok = np.all(np.isfinite(draws), axis=2)
    if not ok.any(axis=1).all():
        raise IdentificationError("no ensemble bag could be fitted")
    coef = np.zeros((len(picks), p))
    std = np.zeros((len(picks), p))
    inc = np.zeros((len(picks), p))
    for r in range(len(picks)):
        d = draws[r, ok[r]]
        inc[r] = np.mean(d != 0, axis=0)
        std[r] = d.std(axis=0)
        keep = inc[r] >= inclusion_min
        if aggregate == "median":
            coef[r] = np.where(keep, np.median(d, axis=0), 0.0)
        elif aggregate == "mean":
            coef[r] = np.where(keep, d.mean(axis=0), 0.0)
        elif aggregate == "refit":
            coef[r] = _refit(blocks.sum(axis=0), int(sw.candidates[picks[r][1]]), keep, ridge)
        else:
            raise ValueError(f"aggregate must be 'median', 'mean' or 'refit', got {aggregate!r}")
    return Ensemble(coef, std, inc)


def _refit(G: np.ndarray, j: int, keep: np.ndarray, ridge: float) -> np.ndarray:
    """Least squares of column ``j`` on the columns ``keep`` (``j`` excluded) on Gram matrix
    ``G``; the implicit row in original units with coefficient 1 on ``j``."""
    s = np.sqrt(np.clip(np.diag(G), 0.0, None))
    s = np.where(s > 0, s, 1.0)
    mask = keep.copy()
    mask[j] = False
    w = np.zeros(G.shape[0])
    if mask.any():
        w = -_solve_masked(G / np.outer(s, s), np.array([j]), mask[None, :], ridge)[0]
    w[j] = 1.0
    return w / s * s[j]
