"""The cubic restoring force's form: ``K3 (A x)^3``, diagonal (``A = I``) or rank one.

A structural model's cubic force in sensor coordinates ``x`` (n,) [m] is

    f = K3 (A x)^3,

with ``A`` (p x n) the cubic coordinates' map and ``K3`` (n x p) [N/m^3 when ``A`` is unitless]
how each pushes back.  ``A = None`` stands for the identity (``p = n``): the *diagonal* library
of the features ``x_j^3`` every structural identifier fits by default.  The *rank-one* form
(``p = 1``) is one nonlinear spring acting on one coordinate ``a . x``: the physics of a
localised nonlinearity (a joint, a support), e.g. the soft base's ``k3 d (c . x)^3`` of the
SEREP truth, whose cross terms ``x_i^2 x_j`` the diagonal features cannot represent.

:func:`fit_rank_one` fits ``b (a . x)^3`` to a target by variable projection.  Used, for now,
by the diagnosis scripts ``tests/identify/soft_cubic_rank_one_floor.py`` and
``soft_cubic_rank_one_ls.py`` only: no identifier fits the rank-one form, and the consumers of
``K3_`` (simulation, residuals, scores, figures) still take the diagonal ``K3_ @ x**3`` (the
form was measured not to be the soft base's floor: ``docs/known-gaps.md``).  Should a model
carry ``A``, every such consumer is to compute its cubic with :func:`cubic_force`.

:func:`one_mode_cubic` is a rank-one ``K3`` on the diagonal features (a cubic acting on one
mode's equation alone, a Duffing along that mode's motion), which every consumer reads as it
is: ``ls_sindy``'s steps 4c and 4d and ``sgd_sindy``'s backbone step
(:mod:`identify._structural_backbone`) size it by output error.
"""

from __future__ import annotations

import numpy as np


def cubic_features(x: np.ndarray, A: np.ndarray | None = None) -> np.ndarray:
    """The cubic features ``(A x)^3`` (``x^3`` when ``A`` is None).

    Parameters
    ----------
    x : ndarray, shape (n,) or (n, N)
        Displacements [m].
    A : ndarray, shape (p, n), optional
        The cubic coordinates' map; None is the identity (the diagonal library).

    Returns
    -------
    ndarray, shape (p,) or (p, N)
    """
    x = np.asarray(x, dtype=float)
    if A is None:
        return x**3
    return (np.asarray(A, dtype=float) @ x) ** 3


def cubic_force(K3: np.ndarray, x: np.ndarray, A: np.ndarray | None = None) -> np.ndarray:
    """The cubic restoring force ``K3 (A x)^3`` [N], shape (n,) or (n, N) like ``x``."""
    return np.asarray(K3, dtype=float) @ cubic_features(x, A)


def cubic_jacobian(K3: np.ndarray, x: np.ndarray, A: np.ndarray | None = None) -> np.ndarray:
    """``d f / d x = K3 diag(3 (A x)^2) A`` at one state ``x`` (n,), shape (n, n) [N/m]."""
    x = np.asarray(x, dtype=float)
    if A is None:
        return np.asarray(K3, dtype=float) * (3.0 * x**2)[None, :]
    A = np.asarray(A, dtype=float)
    return (np.asarray(K3, dtype=float) * (3.0 * (A @ x) ** 2)[None, :]) @ A


def canonical_sign(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``(a, b)`` with ``a`` unit length and its largest-magnitude entry positive.

    ``b (a . x)^3`` is unchanged by ``a -> s a``, ``b -> b / s^3``; the rule fixes ``s`` from
    ``a`` alone (ties in magnitude go to the first such entry), so the stored direction does
    not depend on the optimiser's path.  Where two entries are equal in magnitude to rounding
    (a symmetric direction), the kernel's last bits may pick either and flip both signs: the
    force ``b (a . x)^3`` is the same, so compare models by it, not by ``a``.

    Parameters
    ----------
    a : ndarray, shape (n,)
        Direction [-], nonzero.
    b : ndarray, shape (n,)
        Force coefficients [N per unit of ``(a . x)^3``].

    Returns
    -------
    (ndarray, ndarray)
        The same model with ``|a| = 1`` and its largest-magnitude entry positive.
    """
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    s = float(np.linalg.norm(a))
    a, b = a / s, b * s**3
    if a[int(np.argmax(np.abs(a)))] < 0.0:
        a, b = -a, -b
    return a, b


def _identity(z: np.ndarray) -> np.ndarray:
    return z


def _value_grad(a: np.ndarray, x: np.ndarray, y: np.ndarray, Q: np.ndarray | None,
                symmetric: bool = False, transform=_identity) -> tuple[float, np.ndarray]:
    """``-J(a)`` and its gradient, ``z = P (a . x)^3`` (``P``: off ``Q``): ``J = |y z^T|^2 / |z|^2``
    (free ``b``), or with ``b = g a`` (``symmetric``) ``J = (a . y z^T)^2 / |z|^2`` at unit ``a``."""
    if symmetric:
        r = float(np.linalg.norm(a))
        u = a / r
        J, dJ = _value_grad_symmetric(u, x, y, Q, transform)
        return J, (dJ - u * float(u @ dJ)) / r
    q = a @ x
    z = transform(q**3)
    G = transform(3.0 * q**2 * x)  # dz/da, (n, N')
    if Q is not None:
        z = z - (z @ Q) @ Q.T
        G = G - (G @ Q) @ Q.T
    s = float(z @ z)
    if s <= 0.0:
        return 0.0, np.zeros_like(a)
    v = y @ z  # (m,)
    dv = y @ G.T  # (m, n)
    J = float(v @ v) / s
    dJ = 2.0 * (v @ dv) / s - J * 2.0 * (G @ z) / s
    return -J, -dJ


def _value_grad_symmetric(u: np.ndarray, x: np.ndarray, y: np.ndarray, Q: np.ndarray | None,
                          transform=_identity) -> tuple[float, np.ndarray]:
    """``-(u . v)^2 / s`` with ``v = y z^T``, ``s = |z|^2``, and its gradient in ``u`` (not projected)."""
    q = u @ x
    z = transform(q**3)
    G = transform(3.0 * q**2 * x)
    if Q is not None:
        z = z - (z @ Q) @ Q.T
        G = G - (G @ Q) @ Q.T
    s = float(z @ z)
    if s <= 0.0:
        return 0.0, np.zeros_like(u)
    v = y @ z
    p = float(u @ v)
    dp = v + G @ (y.T @ u)
    J = p * p / s
    dJ = 2.0 * p * dp / s - J * 2.0 * (G @ z) / s
    return -J, -dJ


def rank_one_starts(x: np.ndarray) -> list[np.ndarray]:
    """The deterministic starts of :func:`fit_rank_one`: the first left singular vector of
    ``x`` (the dominant displacement shape), then each coordinate axis ``e_j`` in order."""
    n = x.shape[0]
    u = np.linalg.svd(x, full_matrices=False)[0][:, 0]
    return [u] + [np.eye(n)[j] for j in range(n)]


def fit_rank_one(x: np.ndarray, y: np.ndarray, Q: np.ndarray | None = None,
                 starts: list[np.ndarray] | None = None, symmetric: bool = False,
                 transform=None) -> tuple[np.ndarray, np.ndarray]:
    """Least-squares ``y ~ b (a . x)^3`` over a unit direction ``a`` and a vector ``b``.

    Variable projection: for a given ``a`` the best ``b`` is ``y z^T / (z z^T)`` with
    ``z = (a . x)^3`` (projected off the span of ``Q``'s columns when given: the other,
    linear, columns fitted jointly, Frisch-Waugh-Lovell), and the residual is
    ``|y|^2 - J(a)`` with ``J = |y z^T|^2 / |z|^2``, which is invariant to ``a``'s scale.
    ``J`` is maximised by BFGS (analytic gradient) from each of :func:`rank_one_starts`
    (or ``starts``); the best ``J`` wins, ties to the earlier start.  The result carries
    :func:`canonical_sign`'s sign rule.

    Parameters
    ----------
    x : ndarray, shape (n, N)
        Displacements [m] on the fit samples.
    y : ndarray, shape (m, N)
        The target each row's cubic term must match (already off ``Q``'s span when ``Q``
        is given).
    Q : ndarray, shape (N, r), optional
        Orthonormal columns projected out of the cubic feature.
    starts : list of ndarray, shape (n,), optional
        Starting directions.
    symmetric : bool
        ``b = g a`` (one scalar ``g``, ``y`` with ``m = n`` rows): the force of the potential
        ``g (a . x)^4 / 4``, a conservative spring on the coordinate ``a . x``.
    transform : callable, optional
        A linear, time-invariant operation on the samples (last axis) that the fit applies
        to every feature and the target alike (a band filter, the tilt's differences):
        the cubic feature is ``transform((a . x)^3)``; ``y`` and ``Q`` are already in its
        output's samples.

    Returns
    -------
    a : ndarray, shape (n,)
        Unit direction, largest-magnitude entry positive.
    b : ndarray, shape (m,)
        Coefficients in ``y``'s units per m^3.
    """
    from scipy.optimize import minimize

    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    # scale-free optimisation: x to unit RMS (the direction is mapped back below)
    sx = float(np.sqrt(np.mean(x**2))) or 1.0
    xs = x / sx
    tf = _identity if transform is None else transform
    best_J, best_a = -np.inf, None
    for a0 in (rank_one_starts(xs) if starts is None else starts):
        r = minimize(_value_grad, np.asarray(a0, dtype=float) / np.linalg.norm(a0),
                     args=(xs, y, Q, symmetric, tf), jac=True, method="BFGS",
                     options={"gtol": 1e-10, "maxiter": 500})
        J = -float(r.fun)
        if J > best_J * (1.0 + 1e-12) or best_a is None:
            best_J, best_a = J, np.asarray(r.x, dtype=float)
    a = best_a / np.linalg.norm(best_a)
    z = tf((a @ x) ** 3)
    if Q is not None:
        z = z - (z @ Q) @ Q.T
    b = (y @ z) / float(z @ z)
    if symmetric:
        b = a * float(a @ b)
    return canonical_sign(a, b)


def one_mode_cubic(M: np.ndarray, Phi: np.ndarray, k: int, g: float) -> np.ndarray:
    """The diagonal library's ``K3`` of a cubic spring acting on mode ``k``'s equation alone.

    ``K3 = g M phi_k u^T`` with ``u . phi_j^3 = delta_kj`` (``phi_j`` the columns of ``Phi``):
    in the modal coordinates ``q = Phi^-1 x`` only mode ``k``'s equation gets a cubic term,
    and along that mode's own motion (``x = phi_k q_k``) it is the Duffing ``q_k'' + lam_k q_k +
    g q_k^3 = 0``.  A rank-one ``K3`` on the features ``x_j^3``, so every consumer of ``K3_``
    reads it as it reads the fitted diagonal library.

    Parameters
    ----------
    M : ndarray, shape (n, n)
        Mass [kg].
    Phi : ndarray, shape (n, n)
        Mode shapes, one per column (:func:`identify.structural.modal`) [-].
    k : int
        The mode the cubic acts on.
    g : float
        Its modal cubic coefficient [1 / (s^2 (modal units)^2)].

    Returns
    -------
    ndarray, shape (n, n)
        ``K3`` [N/m^3].
    """
    Phi = np.asarray(Phi, dtype=float)
    u = np.linalg.solve((Phi**3).T, np.eye(Phi.shape[1])[k])
    return float(g) * np.outer(np.asarray(M, dtype=float) @ Phi[:, k], u)


def duffing_by_balance(lam_heard: float, lam_linear: float, amplitude: float) -> float:
    """The Duffing coefficient ``g`` whose first harmonic balance at ``amplitude`` rings at the
    eigenvalue ``lam_heard``: ``lam_heard = lam_linear + 3/4 g amplitude^2`` [1 / (s^2 units^2)].

    Parameters
    ----------
    lam_heard : float
        The squared frequency heard at that amplitude [rad^2/s^2].
    lam_linear : float
        The linear (small-amplitude) one [rad^2/s^2].
    amplitude : float
        The modal coordinate's amplitude [its units], positive.
    """
    return (float(lam_heard) - float(lam_linear)) / (0.75 * float(amplitude) ** 2)
