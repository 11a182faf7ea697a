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

from collections.abc import Callable

import numpy as np

#: Noise draws of the parametric bootstrap: the mean of 32 ``D^T D`` has a relative standard
#: error of about ``sqrt(2 / 32) = 0.25`` on its largest eigenvalue, enough to tell a bound
#: of 1e-3 from one of 1 (the measured populations are three decades apart).
DRAWS = 32
#: Seed of the draws (fixed: the bound is a property of the record, not of a random stream).
SEED = 0


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
    theta = np.asarray(rows(x), dtype=float)
    if theta.shape[1] < 2 or not np.all(np.isfinite(theta)):
        return float("nan")
    norms = np.linalg.norm(theta, axis=0)
    if np.any(norms == 0.0):
        return float("inf")
    base = theta / norms
    gap = float(np.linalg.eigvalsh(base.T @ base)[1])
    sigma = np.asarray(sigma, dtype=float).reshape(-1, 1)
    if not np.any(sigma > 0.0):
        return 0.0
    rng = np.random.default_rng(SEED)
    dG = np.zeros((theta.shape[1], theta.shape[1]))
    for _ in range(DRAWS):
        d = np.asarray(rows(x + sigma * rng.standard_normal(x.shape)), dtype=float) / norms - base
        dG += d.T @ d
    if not np.all(np.isfinite(dG)):  # a perturbed record overflowed the terms: no bound
        return float("nan")
    noise = float(np.linalg.eigvalsh(dG / DRAWS)[-1])
    return noise / gap if gap > 0.0 else float("inf")
