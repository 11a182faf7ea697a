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


#: Dimensionless eigenvalues ``beta_k L`` of a clamped-free beam, modes 1-8 (roots of
#: ``cos(lambda) cosh(lambda) = -1`` to 4 decimals: the table the families were drawn with);
#: beyond mode 8 the asymptote ``(k - 1/2) pi``, within 1e-8 of the root there.
CLAMPED_BETA_L = (1.8751, 4.6941, 7.8548, 10.9955, 14.1372, 17.2788, 20.4204, 23.5619)


def _section(rig: dict) -> tuple[float, float]:
    """Bending stiffness ``E I`` [N m^2] and mass per length ``rho A`` [kg/m] of the rig's beam."""
    return (rig["E"] * rig["width"] * rig["thickness"] ** 3 / 12.0,
            rig["rho"] * rig["width"] * rig["thickness"])


def clamped_estimates(rig: dict, n: int) -> np.ndarray:
    """Euler-Bernoulli clamped-free frequencies of modes 1..n of the rig's nominal beam [Hz].

    Parameters
    ----------
    rig : dict
        A cantilever ``[rig]`` table (``E`` [Pa], ``rho`` [kg/m^3], ``width``, ``thickness``,
        ``length`` [m]); the base is ignored (clamped).
    n : int
        Number of modes (>= 1).

    Returns
    -------
    ndarray, shape (n,)
        ``(beta_k L)^2 / (2 pi L^2) sqrt(E I / (rho A))`` [Hz] with ``beta_k L`` from
        :data:`CLAMPED_BETA_L`.
    """
    ei, mu = _section(rig)
    k = np.arange(1, n + 1)
    table = np.asarray(CLAMPED_BETA_L)
    bl = np.where(k <= len(table), table[np.minimum(k, len(table)) - 1], (k - 0.5) * math.pi)
    return bl**2 / (2 * math.pi * rig["length"] ** 2) * math.sqrt(ei / mu)


def sensed_modes(rig: dict) -> int:
    """Modes a model in the rig's sensor coordinates holds: one per accelerometer (the default
    layout L/3, 2L/3, L has three)."""
    return len(rig["sensors"]) or 3


def auto_cutoff(rig: dict, key: str) -> tuple[float, str]:
    """The lab's filter cut-off ``signal.<key> = "auto"`` for a cantilever, from its nominal geometry.

    The experimenter's filter design, from the beam's nominal E, rho, width, thickness,
    length and base (never from the identified model or the chain's truth):

    * ``highpass_hz``: half the Euler-Bernoulli estimate of mode 1 on the rig's base (clamped:
      :func:`clamped_estimates`; soft: :func:`eb_frequencies` with ``k_r = base_k1``, since a
      soft base lowers mode 1 to 0.3-0.65 of the clamped estimate for ``k1 L / EI`` 0.5-3, where
      half the clamped one would cut into it); the noisy-record chain's 40 Hz for the shipped
      beam's 80 Hz.
    * ``lowpass_hz``: between the last sensed mode ``n`` (one per sensor) and mode ``n + 1``:
      ``sqrt(f_n f_(n+1))`` of the clamped estimates.  A soft base lowers every mode, yet its
      mode ``n + 1`` stays above this cut: it lies above the pinned-free root ``~(n + 1/4) pi``,
      whose square exceeds ``beta_n beta_(n+1) ~ (n^2 - 1/4) pi^2``.

    Both rounded to 0.1 Hz (the families' members carry these values).

    Parameters
    ----------
    rig : dict
        A validated cantilever ``[rig]`` table.
    key : {"highpass_hz", "lowpass_hz"}

    Returns
    -------
    value : float
        The cut-off [Hz].
    rule : str
        The rule with the estimates it used, for the run's record.

    Raises
    ------
    ValueError
        If the cut-off rounds to 0 Hz (mode 1 below 0.1 Hz) or is not finite; the message
        says why.
    """
    if key == "highpass_hz":
        if rig["base"] == "soft":
            ei, mu = _section(rig)
            f1 = float(eb_frequencies(ei, 1.0, mu, rig["length"], 1, k_r=rig["base_k1"])[0])
            where = f"on the soft base (k1 = {rig['base_k1']:g} N m/rad)"
        else:
            f1 = float(clamped_estimates(rig, 1)[0])
            where = "clamped"
        value = float(round(f1 / 2.0, 1))
        rule = (f"'auto': half the Euler-Bernoulli estimate of mode 1 {where}, "
                f"{f1:.4g} Hz / 2, to 0.1 Hz")
    elif key == "lowpass_hz":
        n = sensed_modes(rig)
        f = clamped_estimates(rig, n + 1)
        value = float(round(math.sqrt(f[-2] * f[-1]), 1))
        rule = (f"'auto': between mode {n} (one per sensor) and mode {n + 1}, sqrt(f{n} f{n + 1}) "
                f"of the clamped Euler-Bernoulli estimates {f[-2]:.4g} and {f[-1]:.4g} Hz, "
                "to 0.1 Hz")
    else:
        raise ValueError(f"no 'auto' rule for signal.{key}")
    if not (math.isfinite(value) and value > 0.0):
        raise ValueError(f"{rule} gives {value:g} Hz; give a cut-off > 0 Hz")
    return value, rule
