"""Whether a record's noise leaves an identified implicit equation determined (one job).

An implicit equation ``Theta w = 0`` is the null direction of the regression matrix's Gram
``G = Theta_n^T Theta_n`` (columns of the selected terms, normalised to unit norm).  Noise on the
states adds, in expectation, ``dG = E[D^T D]`` to ``G`` (``D`` the rows' change): the
errors-in-variables term that biases the null direction.  ``G``'s second-smallest eigenvalue,
the gap, measures how far the nearest *other* combination of the same terms is from holding.
Where ``lambda_max(dG)`` reaches the gap, the noise alone adds as much to some combination's
residual as separates the second-best equation from the best (Weyl: the eigenvalues of
``G + dG`` move by up to ``lambda_max(dG)``), so which direction comes out smallest is the
noise's choice.  The ratio is the bias's scale; the random part of the fit scales as its square
root, so a ratio below 1 is necessary for a determined equation, not a guarantee of any
accuracy.  This module estimates that ratio from the data alone:

* the noise level is the record's own (``Measurement.noise_std``, as the signal chain estimated
  it from the raw states; else :func:`testbed.numerics.noise.noise_std` of ``x``);
* ``dG`` is the mean of ``D^T D`` over :data:`DRAWS` draws of white noise of that level added to
  the states, ``D`` the change it makes to the normalised rows (a parametric bootstrap, seeded
  with :data:`SEED` so a run is repeatable on any platform);
* the bound is ``lambda_max(dG) / lambda_2(G)`` (largest noise eigenvalue over the gap).

A ratio of 1 or more says the noise moves the regression as far as the gap to another equation
of the same terms: no estimator on these rows pins the equation, so a wrong one is the record's
answer, not the identifier's choice (measured on round 7's Michaelis-Menten records: 2.0-47 on
those whose true-support fit is itself 7-3900 % off, <= 4.2e-3 on every one within 5 %; see
docs/known-gaps.md).  Derivative columns the rows take from the signal chain (the strong form)
are not perturbed: the chain's derivative noise is left out, so the ratio is then a lower one.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator

import numpy as np

#: Noise draws of the parametric bootstrap: the mean of 32 ``D^T D`` has a relative standard
#: error of about ``sqrt(2 / 32) = 0.25`` on its largest eigenvalue, enough to tell a bound
#: of 1e-3 from one of 1 (the measured populations are three decades apart).
DRAWS = 32
#: Seed of the draws (fixed: the bound is a property of the record, not of a random stream).
SEED = 0


def _unit_rows(rows: Callable[[np.ndarray], np.ndarray], x: np.ndarray
               ) -> tuple[np.ndarray, np.ndarray, str]:
    """The terms' rows ``rows(x)`` (n_rows, q) with each column scaled to unit norm, the norms
    (q,), and what makes them unusable: ``"rows"`` (fewer than two terms, or a non-finite
    row), ``"zero"`` (an all-zero column), else ``""`` (then the first two are meaningful)."""
    theta = np.asarray(rows(x), dtype=float)
    if theta.shape[1] < 2 or not np.all(np.isfinite(theta)):
        return theta, np.ones(theta.shape[1]), "rows"
    norms = np.linalg.norm(theta, axis=0)
    if np.any(norms == 0.0):
        return theta, norms, "zero"
    return theta / norms, norms, ""


def determinacy_bound(rows: Callable[[np.ndarray], np.ndarray], x: np.ndarray,
                      sigma: np.ndarray) -> float:
    """The noise's Gram over the gap of an implicit equation's terms, at the record's noise
    level (module docstring).

    Parameters
    ----------
    rows : callable
        ``rows(x)`` -> regression rows of the equation's terms, shape (n_rows, q), from states
        ``x`` (n_states, n_samples) [unit of each state].
    x : ndarray, shape (n_states, n_samples)
        The states the equation was fitted on.
    sigma : ndarray, shape (n_states,)
        White-noise standard deviation of each state [unit of each state].

    Returns
    -------
    float
        ``lambda_max(dG) / lambda_2(G)`` [-]; 0 for noise-free states, ``inf`` when the terms
        hold two equations exactly (``lambda_2 = 0``), NaN for an equation of fewer than two
        terms or non-finite rows.
    """
    base, norms, fault = _unit_rows(rows, x)
    if fault:
        return float("inf") if fault == "zero" else float("nan")
    gap = float(np.linalg.eigvalsh(base.T @ base)[1])
    sigma = np.asarray(sigma, dtype=float).reshape(-1, 1)
    if not np.any(sigma > 0.0):
        return 0.0
    dG = _noise_gram(rows, x, sigma, base, norms)
    if not np.all(np.isfinite(dG)):  # a perturbed record overflowed the terms: no bound
        return float("nan")
    noise = float(np.linalg.eigvalsh(dG)[-1])
    return noise / gap if gap > 0.0 else float("inf")


def _noisy_rows(rows: Callable[[np.ndarray], np.ndarray], x: np.ndarray, sigma: np.ndarray,
                norms: np.ndarray) -> Iterator[np.ndarray]:
    """The rows, normalised by ``norms``, of ``x`` plus each of :data:`DRAWS` seeded draws of
    white noise of std ``sigma`` (n_states, 1): the one parametric bootstrap every estimate of
    this module draws (the same draws, in the same order, for each)."""
    rng = np.random.default_rng(SEED)
    for _ in range(DRAWS):
        yield np.asarray(rows(x + sigma * rng.standard_normal(x.shape)), dtype=float) / norms


def _noise_gram(rows: Callable[[np.ndarray], np.ndarray], x: np.ndarray, sigma: np.ndarray,
                base: np.ndarray, norms: np.ndarray, spread: bool = False
                ) -> np.ndarray | tuple[np.ndarray, float]:
    """Mean ``D^T D`` over the draws of :func:`_noisy_rows`, ``D`` the change of the rows from
    ``base``; with ``spread``, also the RMS distance from their mean of the draws' unit
    total-least-squares directions (signs aligned with ``base``'s; NaN if a draw's rows are
    not finite), from the same evaluation of the rows."""
    dG = np.zeros((base.shape[1], base.shape[1]))
    v0 = np.linalg.eigh(base.T @ base)[1][:, 0] if spread else None
    vs, finite = [], True
    for d in _noisy_rows(rows, x, sigma, norms):
        if spread:
            finite = finite and bool(np.all(np.isfinite(d)))
            if finite:
                v = np.linalg.eigh(d.T @ d)[1][:, 0]
                vs.append(v if v @ v0 >= 0.0 else -v)
        d = d - base
        dG += d.T @ d
    if not spread:
        return dG / DRAWS
    if not finite:
        return dG / DRAWS, float("nan")
    vs = np.array(vs)
    return dG / DRAWS, float(np.sqrt(np.mean(np.sum((vs - vs.mean(axis=0)) ** 2, axis=1))))


def noise_gram(rows: Callable[[np.ndarray], np.ndarray], x: np.ndarray,
               sigma: np.ndarray) -> np.ndarray:
    """Expected Gram the record's noise adds to an equation's normalised rows.

    Parameters
    ----------
    rows : callable
        ``rows(x)`` -> regression rows of the terms, shape (n_rows, q), from states ``x``.
    x : ndarray, shape (n_states, n_samples)
        The states [unit of each state].
    sigma : ndarray, shape (n_states,)
        White-noise standard deviation of each state [unit of each state].

    Returns
    -------
    ndarray, shape (q, q)
        Mean ``D^T D`` over :data:`DRAWS` seeded draws (``D`` the change of the rows, each
        column scaled by its noise-free norm) [-]: the term to take out of the normalised Gram
        for a bias-compensated fit; zeros for zero noise, NaN where the rows are unusable.
    """
    return _gram_of_record(rows, x, sigma, spread=False)


def direction_spread(rows: Callable[[np.ndarray], np.ndarray], x: np.ndarray,
                     sigma: np.ndarray) -> float:
    """Random spread of an equation's total-least-squares direction at the record's noise.

    The smallest eigenvector of the normalised Gram of the rows of ``x`` plus each of the
    :data:`DRAWS` seeded noise draws of :func:`noise_gram` (sign aligned with the record's own),
    and the root mean square distance of those unit vectors from their mean: how far another
    noise realisation of the record's level moves the fitted direction.

    Parameters
    ----------
    rows, x, sigma
        As in :func:`noise_gram`.

    Returns
    -------
    float
        The spread [-] (unit-norm directions; 0 for zero noise), NaN where the rows are unusable
        or a draw's rows are not finite.
    """
    return noise_gram_and_spread(rows, x, sigma)[1]


def noise_gram_and_spread(rows: Callable[[np.ndarray], np.ndarray], x: np.ndarray,
                          sigma: np.ndarray) -> tuple[np.ndarray, float]:
    """:func:`noise_gram` and :func:`direction_spread` from one evaluation of the draws' rows.

    Parameters
    ----------
    rows, x, sigma
        As in :func:`noise_gram`.

    Returns
    -------
    dG : ndarray, shape (q, q)
        As :func:`noise_gram` returns it [-].
    spread : float
        As :func:`direction_spread` returns it [-].
    """
    return _gram_of_record(rows, x, sigma, spread=True)


def _gram_of_record(rows: Callable[[np.ndarray], np.ndarray], x: np.ndarray, sigma: np.ndarray,
                    spread: bool) -> np.ndarray | tuple[np.ndarray, float]:
    """:func:`_noise_gram` of the record's normalised rows, with the unusable rows' NaN and the
    zero-noise zeros (and spread 0) handled once for :func:`noise_gram` and
    :func:`noise_gram_and_spread`."""
    base, norms, fault = _unit_rows(rows, x)
    q = base.shape[1]
    if fault:
        return (np.full((q, q), np.nan), float("nan")) if spread else np.full((q, q), np.nan)
    sigma = np.asarray(sigma, dtype=float).reshape(-1, 1)
    if not np.any(sigma > 0.0):
        return (np.zeros((q, q)), 0.0) if spread else np.zeros((q, q))
    return _noise_gram(rows, x, sigma, base, norms, spread=spread)


def noise_residual_ratio(rows: Callable[[np.ndarray], np.ndarray], x: np.ndarray,
                         sigma: np.ndarray) -> tuple[float, np.ndarray]:
    """How far the best equation of some terms is from holding, in units of what the record's
    noise alone leaves of it.

    The best equation of the terms is the eigenvector ``v`` of the smallest eigenvalue of their
    normalised Gram ``G`` (total least squares).  If the terms hold an equation of the noise-free
    states, noise of the record's level leaves it the residual ``v^T dG v`` in expectation
    (``dG`` as in :func:`determinacy_bound`, the same draws); an equation missing a needed term
    leaves in addition its own misfit.  The ratio ``lambda_min(G) / (v^T dG v)`` is therefore
    about 1 (below: the fit also absorbs part of the noise) for terms that hold an equation to
    within the noise, and grows with the misfit beyond it.

    Parameters
    ----------
    rows : callable
        ``rows(x)`` -> regression rows of the terms, shape (n_rows, q), from states ``x``.
    x : ndarray, shape (n_states, n_samples)
        The states [unit of each state].
    sigma : ndarray, shape (n_states,)
        White-noise standard deviation of each state [unit of each state].

    Returns
    -------
    ratio : float
        ``lambda_min(G) / (v^T dG v)`` [-]; ``inf`` for noise-free states or zero noise
        residual, NaN for fewer than two terms, an all-zero or non-finite column.
    w : ndarray, shape (q,)
        The equation ``v`` in the terms' original units (``v / norms``), or NaN.
    """
    base, norms, fault = _unit_rows(rows, x)
    nan = (float("nan"), np.full(base.shape[1], np.nan))
    if fault:
        return nan
    vals, vecs = np.linalg.eigh(base.T @ base)
    v = vecs[:, 0]
    sigma = np.asarray(sigma, dtype=float).reshape(-1, 1)
    if not np.any(sigma > 0.0):
        return float("inf"), v / norms
    dG = _noise_gram(rows, x, sigma, base, norms)
    if not np.all(np.isfinite(dG)):
        return nan
    noise = float(v @ dG @ v)
    return (max(float(vals[0]), 0.0) / noise if noise > 0.0 else float("inf")), v / norms
