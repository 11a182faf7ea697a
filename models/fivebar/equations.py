"""The true equations of motion in library terms (absolute angles, multipliers eliminated).

Each chain is an open two-link arm; in absolute angles its Lagrange equations are
(damping on the relative joint rates, gravity along -y when switched on)::

    R1 = a1 ddth1 + b1 cos(th1-th2) ddth2 + b1 sin(th1-th2) dth2^2
         + (cA + cC) dth1 - cC dth2 + g1 cos(th1)
    R2 = b1 cos(th1-th2) ddth1 + a2 ddth2 - b1 sin(th1-th2) dth1^2 + cC (dth2 - dth1) + g2 cos(th2)
    R4 = a4 ddth4 + b2 cos(th3-th4) ddth3 - b2 sin(th3-th4) dth3^2
         + (cB + cD) dth4 - cD dth3 + g4 cos(th4)
    R3 = b2 cos(th3-th4) ddth4 + a3 ddth3 + b2 sin(th3-th4) dth4^2 + cD (dth3 - dth4) + g3 cos(th3)

(lumped coefficients in :attr:`FiveBarParams.lumped`) and the closed loop obeys
``R = B u + J^T lambda`` with J the Jacobian of the paper's constraint (f1, f2).  The
passive rows give ``lambda = J_p^-T (R2, R3)`` with ``det J_p = L2 L3 sin(th2-th3)``;
substituting in the actuated rows and multiplying by the determinant::

    L2 L3 sin(th2-th3) (R1 - u1) - L1 L3 sin(th1-th3) R2 - L1 L2 sin(th1-th2) R3 = 0
    L2 L3 sin(th2-th3) (R4 - u2) - L3 L4 sin(th3-th4) R2 - L2 L4 sin(th2-th4) R3 = 0

Expanded, each is a linear combination of product terms (a trig factor times a chain
term) named by :func:`testbed.core.terms.canonical`.  The coefficients are checked against
Pinocchio's constrained dynamics in the tests, not taken from the paper.
"""

from __future__ import annotations

import re
from collections.abc import Mapping

import numpy as np

from models.fivebar.params import FiveBarParams
from testbed.core.terms import canonical

_TRIG = re.compile(r"^(sin|cos)\(th(\d+)(?:-th(\d+))?\)$")
_VAR = re.compile(r"^(ddth|dth|th|u)(\d+)$")


def chain_terms(p: FiveBarParams) -> dict[str, list[tuple[float, str]]]:
    """Lagrange expressions R1..R4 (generalised force on each absolute angle) as (coef, term)."""
    k = p.lumped
    cA, cC, cB, cD = p.damping
    return {
        "R1": [(k["a1"], "ddth1"), (k["b1"], "cos(th1-th2)*ddth2"), (k["b1"], "sin(th1-th2)*dth2^2"),
               (cA + cC, "dth1"), (-cC, "dth2"), (k["g1"], "cos(th1)")],
        "R2": [(k["b1"], "cos(th1-th2)*ddth1"), (k["a2"], "ddth2"), (-k["b1"], "sin(th1-th2)*dth1^2"),
               (cC, "dth2"), (-cC, "dth1"), (k["g2"], "cos(th2)")],
        "R3": [(k["b2"], "cos(th3-th4)*ddth4"), (k["a3"], "ddth3"), (k["b2"], "sin(th3-th4)*dth4^2"),
               (cD, "dth3"), (-cD, "dth4"), (k["g3"], "cos(th3)")],
        "R4": [(k["a4"], "ddth4"), (k["b2"], "cos(th3-th4)*ddth3"), (-k["b2"], "sin(th3-th4)*dth3^2"),
               (cB + cD, "dth4"), (-cD, "dth3"), (k["g4"], "cos(th4)")],
    }


def _expand(rows: list[tuple[float, str, list[tuple[float, str]]]]) -> dict[str, float]:
    """Sum of ``coef * factor * (expression)`` over rows, collected by canonical term name."""
    out: dict[str, float] = {}
    for coef, factor, expr in rows:
        for c, term in expr:
            name, sign = canonical(f"{factor}*{term}")
            out[name] = out.get(name, 0.0) + sign * coef * c
    return out


def unnormalised_equations(p: FiveBarParams) -> list[dict[str, float]]:
    """The two actuated-joint equations as ``{term: coefficient}`` in physical units [N m^3].

    Equation k (k = 1 at A, 2 at B) is ``sum_i coef_i * term_i = 0`` with the terms above.
    """
    L1, L2, L3, L4 = p.l
    R = chain_terms(p)
    u1, u2 = [(1.0, "u1")], [(1.0, "u2")]
    eq1 = _expand([(L2 * L3, "sin(th2-th3)", R["R1"]), (-L2 * L3, "sin(th2-th3)", u1),
                   (-L1 * L3, "sin(th1-th3)", R["R2"]), (-L1 * L2, "sin(th1-th2)", R["R3"])])
    eq2 = _expand([(L2 * L3, "sin(th2-th3)", R["R4"]), (-L2 * L3, "sin(th2-th3)", u2),
                   (-L3 * L4, "sin(th3-th4)", R["R2"]), (-L2 * L4, "sin(th2-th4)", R["R3"])])
    return [eq1, eq2]


def true_equations(p: FiveBarParams) -> tuple[list[str], np.ndarray, np.ndarray]:
    """Term names, normalised coefficients and the normalising scales of the true equations.

    Terms whose coefficient is exactly zero (no gravity, no damping) are left out; the
    term list is the sorted union over both equations (zeros where a term is absent).
    **Normalisation:** each row is divided by its largest-magnitude coefficient, sign
    included, so that coefficient is exactly +1 (an implicit equation is defined only up
    to scale; scoring compares normalised rows).

    Returns
    -------
    terms : list of str
        Canonical term names.
    coef : ndarray, shape (2, n_terms)
        Normalised coefficients (dimensionless ratios).
    scale : ndarray, shape (2,)
        The divisor of each row [N m^3] (the units of :func:`unnormalised_equations`).
    """
    eqs = unnormalised_equations(p)
    terms = sorted({t for eq in eqs for t, c in eq.items() if c != 0.0})
    coef = np.array([[eq.get(t, 0.0) for t in terms] for eq in eqs])
    scale = coef[np.arange(2), np.argmax(np.abs(coef), axis=1)]
    return terms, coef / scale[:, None], scale


def _factor(f: str, v: Mapping[str, np.ndarray]) -> np.ndarray:
    m = _TRIG.match(f)
    if m:
        fn, i, j = m.groups()
        x = v["th"][int(i) - 1] - (v["th"][int(j) - 1] if j else 0.0)
        return np.sin(x) if fn == "sin" else np.cos(x)
    m = _VAR.match(f)
    if m:
        return v[m.group(1)][int(m.group(2)) - 1]
    if f == "1":
        return np.ones_like(v["th"][0])
    raise ValueError(f"cannot evaluate library factor {f!r}")


def evaluate_terms(terms: list[str], theta: np.ndarray, dtheta: np.ndarray, ddtheta: np.ndarray,
                   torque: np.ndarray) -> np.ndarray:
    """Library matrix: each term evaluated on the samples.

    Parameters
    ----------
    terms : list of str
        Term names (``testbed.core.terms`` syntax).
    theta, dtheta, ddtheta : ndarray, shape (4, n)
        Absolute angles [rad], rates [rad/s], accelerations [rad/s^2].
    torque : ndarray, shape (2, n)
        Actuator torques u1, u2 [N m].

    Returns
    -------
    ndarray, shape (n_terms, n)
    """
    v = {"th": theta, "dth": dtheta, "ddth": ddtheta, "u": torque}
    out = np.empty((len(terms), theta.shape[1]))
    for i, term in enumerate(terms):
        col = np.ones(theta.shape[1])
        for raw in term.split("*"):
            base, _, power = raw.partition("^")
            col = col * _factor(base, v) ** (int(power) if power else 1)
        out[i] = col
    return out


def true_library_residual(terms: list[str], coef: np.ndarray, theta: np.ndarray, dtheta: np.ndarray,
                          ddtheta: np.ndarray, torque: np.ndarray, relative: bool = True) -> np.ndarray:
    """Residual of the library equations ``coef @ Theta`` on samples.

    Parameters
    ----------
    terms, coef
        As returned by :func:`true_equations` (coef shape (n_eq, n_terms)).
    theta, dtheta, ddtheta, torque
        As in :func:`evaluate_terms`.
    relative : bool
        Divide each row's residual by ``sum_i |coef_i term_i|`` at the same sample (the
        size of the terms that cancel), so 0 means exact and 1 means no cancellation.

    Returns
    -------
    ndarray, shape (n_eq, n)
    """
    Theta = evaluate_terms(terms, theta, dtheta, ddtheta, torque)
    res = coef @ Theta
    if relative:
        res = res / np.maximum(np.abs(coef) @ np.abs(Theta), np.finfo(float).tiny)
    return res
