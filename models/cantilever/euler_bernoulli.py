"""Euler-Bernoulli natural frequencies of a cantilever, clamped or on a rotational spring.

An independent derivation (continuous beam theory) against which the hinge
chain is checked.  With ``w(x) = A cos(bx) + B sin(bx) + C cosh(bx) + D sinh(bx)``
and ``omega = b^2 sqrt(EI / mu)``, the boundary conditions

* base: ``w(0) = 0`` and ``EI w''(0) = k_r w'(0)`` (``k_r -> inf``: clamped),
* free tip: ``w''(L) = 0`` and ``w'''(L) = 0``

give a 4 x 4 determinant in ``lambda = b L`` whose roots are found with
:func:`scipy.optimize.brentq` after a sign scan.  Clamped roots satisfy
``cos(lambda) cosh(lambda) = -1`` (1.8751, 4.6941, 7.8548, 10.9955).
"""

from __future__ import annotations

import math

import numpy as np


def _characteristic(lam: float, kappa: float) -> float:
    """Scaled boundary determinant for ``lambda = b L`` and ``kappa = k_r L / EI``.

    The clamped case (``kappa = inf``) uses ``1 + cos(lambda) cosh(lambda)``; the
    spring case divides the determinant by ``cosh(lambda)`` to keep it bounded.
    """
    c, s = math.cos(lam), math.sin(lam)
    if math.isinf(kappa):
        return 1.0 + c * math.cosh(lam)
    # Rows (scaled): w(0)=0; lambda (-A + C) - kappa (B + D) = 0 (EI w'' = k_r w' over b EI / L);
    # w''(L) = 0; w'''(L) = 0.  Hyperbolic columns divided by cosh(lambda).
    th = math.tanh(lam)
    e = 1.0 / math.cosh(lam)
    mat = np.array([
        [1.0, 0.0, e, 0.0],
        [-lam, -kappa, lam * e, -kappa * e],
        [-c, -s, 1.0, th],
        [s, -c, th, 1.0],
    ])
    return float(np.linalg.det(mat))


def eb_frequencies(E: float, I: float, mu: float, length: float, n: int = 4,
                   k_r: float = math.inf) -> np.ndarray:
    """First ``n`` bending frequencies of a uniform cantilever [Hz].

    Parameters
    ----------
    E : float
        Young's modulus [Pa].
    I : float
        Second moment of area about the bending axis [m^4].
    mu : float
        Mass per unit length [kg/m].
    length : float
        Beam length [m].
    n : int
        Number of frequencies.
    k_r : float
        Rotational stiffness of the base spring [N m/rad]; ``inf`` = clamped.

    Returns
    -------
    ndarray, shape (n,)
        Natural frequencies, ascending [Hz].
    """
    from scipy.optimize import brentq  # lazy: scipy.optimize costs ~0.3 s of import

    ei = E * I
    kappa = k_r * length / ei
    roots: list[float] = []
    grid = np.linspace(1e-3, (n + 2) * math.pi, 200 * (n + 2))
    vals = [_characteristic(x, kappa) for x in grid]
    for a, b, fa, fb in zip(grid[:-1], grid[1:], vals[:-1], vals[1:], strict=True):
        if fa == 0.0:
            roots.append(float(a))
        elif fa * fb < 0:
            roots.append(brentq(_characteristic, a, b, args=(kappa,), xtol=1e-14, rtol=1e-15))
        if len(roots) == n:
            break
    if len(roots) < n:
        raise RuntimeError(f"found only {len(roots)} Euler-Bernoulli roots")
    lam = np.array(roots)
    return lam**2 * math.sqrt(ei / mu) / length**2 / (2.0 * math.pi)
