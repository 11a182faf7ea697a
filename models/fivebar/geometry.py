"""Loop-closure kinematics of the five-bar linkage in absolute angles (vectorised numpy).

All functions broadcast over leading axes: ``theta`` has shape ``(..., 4)`` with
columns ``th1..th4`` [rad].  See :mod:`models.fivebar.params` for the conventions.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from models.fivebar.params import FiveBarParams

#: Safe transmission-angle range [deg]: outside it the linkage is near a Type II
#: (force) singularity, links 2 and 3 collinear, and the actuated coordinates
#: stop being a good parametrisation (the usual 30-150 deg rule for linkages).
TRANSMISSION_RANGE_DEG = (30.0, 150.0)

#: Relative joint coordinates q = P theta (Pinocchio / MuJoCo tree order A, C, B, D).
P = np.array([[1.0, 0, 0, 0], [-1, 1, 0, 0], [0, 0, 0, 1], [0, 0, 1, -1]])
P_INV = np.linalg.inv(P)
#: Columns of the actuated (th1, th4) and passive (th2, th3) angles in ``theta``.
ACTUATED, PASSIVE = (0, 3), (1, 2)


def to_joint(theta: np.ndarray) -> np.ndarray:
    """Absolute angles ``(..., 4)`` [rad] -> relative joint coordinates ``q`` in tree order."""
    return np.asarray(theta) @ P.T


def to_absolute(q: np.ndarray) -> np.ndarray:
    """Relative joint coordinates ``(..., 4)`` (tree order A, C, B, D) -> absolute ``th1..th4``."""
    return np.asarray(q) @ P_INV.T


def elbows(th1: np.ndarray, th4: np.ndarray, p: FiveBarParams) -> tuple[np.ndarray, np.ndarray]:
    """Elbow points C (end of link 1) and D (end of link 4) [m], each shape ``(..., 2)``."""
    C = np.stack([p.l[0] * np.cos(th1), p.l[0] * np.sin(th1)], axis=-1)
    D = np.stack([p.L0 + p.l[3] * np.cos(th4), p.l[3] * np.sin(th4)], axis=-1)
    return C, D


def closure_margin(th1: np.ndarray, th4: np.ndarray, p: FiveBarParams) -> tuple[np.ndarray, float, float]:
    """Distance |CD| [m] and the open interval (|l2 - l3|, l2 + l3) where the loop closes."""
    C, D = elbows(th1, th4, p)
    return np.linalg.norm(D - C, axis=-1), abs(p.l[1] - p.l[2]), p.l[1] + p.l[2]


def passive_angles(th1: np.ndarray, th4: np.ndarray, p: FiveBarParams,
                   branch: str | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Passive absolute angles ``th2, th3`` [rad] from the actuated ones (circle intersection).

    Parameters
    ----------
    th1, th4 : array_like
        Actuated absolute angles [rad], broadcastable.
    p : FiveBarParams
    branch : {"up", "down"}, optional
        Assembly branch (default ``p.branch``): ``"up"`` puts E to the left of C->D.

    Returns
    -------
    th2, th3 : ndarray
        In (-pi, pi]; NaN where the loop cannot close.
    """
    branch = branch or p.branch
    C, D = elbows(th1, th4, p)
    CD = D - C
    d = np.linalg.norm(CD, axis=-1)
    l2, l3 = p.l[1], p.l[2]
    with np.errstate(invalid="ignore", divide="ignore"):
        a = (l2**2 - l3**2 + d**2) / (2 * d)
        h = np.sqrt(l2**2 - a**2)
        u = CD / d[..., None]
    n = np.stack([-u[..., 1], u[..., 0]], axis=-1) * (1.0 if branch == "up" else -1.0)
    E = C + a[..., None] * u + h[..., None] * n
    th2 = np.arctan2(E[..., 1] - C[..., 1], E[..., 0] - C[..., 0])
    th3 = np.arctan2(E[..., 1] - D[..., 1], E[..., 0] - D[..., 0])
    return th2, th3


def assemble(th1: np.ndarray, th4: np.ndarray, p: FiveBarParams, branch: str | None = None) -> np.ndarray:
    """Full absolute pose ``(..., 4)`` [rad] from the actuated angles (see :func:`passive_angles`)."""
    th1, th4 = np.broadcast_arrays(np.asarray(th1, float), np.asarray(th4, float))
    th2, th3 = passive_angles(th1, th4, p, branch)
    return np.stack([th1, th2, th3, th4], axis=-1)


def endpoint(theta: np.ndarray, p: FiveBarParams) -> np.ndarray:
    """End point E = L1 e(th1) + L2 e(th2) [m], shape ``(..., 2)`` (the paper's Eq. 1)."""
    th1, th2 = theta[..., 0], theta[..., 1]
    return np.stack([p.l[0] * np.cos(th1) + p.l[1] * np.cos(th2),
                     p.l[0] * np.sin(th1) + p.l[1] * np.sin(th2)], axis=-1)


def closure_residual(theta: np.ndarray, p: FiveBarParams) -> np.ndarray:
    """Loop-closure residual (f1, f2) of the paper's Eqs. 2-3 [m], shape ``(..., 2)``."""
    l = p.l
    th1, th2, th3, th4 = (theta[..., i] for i in range(4))
    f1 = l[0] * np.cos(th1) + l[1] * np.cos(th2) - l[2] * np.cos(th3) - l[3] * np.cos(th4) - p.L0
    f2 = l[0] * np.sin(th1) + l[1] * np.sin(th2) - l[2] * np.sin(th3) - l[3] * np.sin(th4)
    return np.stack([f1, f2], axis=-1)


def transmission_angle(theta: np.ndarray) -> np.ndarray:
    """Angle at E between links 2 and 3 [rad], in [0, pi]: ``arccos(cos(th2 - th3))``.

    0 or pi is the Type II singularity (links 2 and 3 collinear).
    """
    return np.arccos(np.clip(np.cos(theta[..., 1] - theta[..., 2]), -1.0, 1.0))


def constraint_jacobian(theta: np.ndarray, p: FiveBarParams) -> np.ndarray:
    """Jacobian d(f1, f2)/d(th1..th4), shape ``(..., 2, 4)`` [m/rad].

    Columns: ``L1 e'(th1), L2 e'(th2), -L3 e'(th3), -L4 e'(th4)`` with ``e'(t) = (-sin t, cos t)``.
    Its passive block (columns 2, 3) has determinant ``L2 L3 sin(th2 - th3)``.
    """
    sgn = np.array([1.0, 1.0, -1.0, -1.0]) * p.l
    s, c = np.sin(theta), np.cos(theta)
    return np.stack([-s * sgn, c * sgn], axis=-2)


def constraint_bias(theta: np.ndarray, dtheta: np.ndarray, p: FiveBarParams) -> np.ndarray:
    """``Jdot(theta) dtheta`` [m/s^2], shape ``(..., 2)``: the velocity-product part of f''."""
    sgn = np.array([1.0, 1.0, -1.0, -1.0]) * p.l
    w2 = dtheta**2 * sgn
    return np.stack([-(np.cos(theta) * w2).sum(-1), -(np.sin(theta) * w2).sum(-1)], axis=-1)


def complete_rates(theta: np.ndarray, dth_act: np.ndarray, ddth_act: np.ndarray | None,
                   p: FiveBarParams) -> tuple[np.ndarray, np.ndarray | None]:
    """Full rates ``(..., 4)`` from the actuated ones ``(..., 2)`` by differentiating the closure.

    ``J_p dth_p = -J_a dth_a`` and ``J_p ddth_p = -(J_a ddth_a + Jdot dth)``.

    Returns
    -------
    dtheta : ndarray, shape (..., 4) [rad/s]
    ddtheta : ndarray, shape (..., 4) [rad/s^2], or None if ``ddth_act`` is None
    """
    J = constraint_jacobian(theta, p)
    Ja, Jp = J[..., list(ACTUATED)], J[..., list(PASSIVE)]
    dth_p = -np.linalg.solve(Jp, (Ja @ dth_act[..., None]))[..., 0]
    dtheta = np.empty(theta.shape)
    dtheta[..., list(ACTUATED)], dtheta[..., list(PASSIVE)] = dth_act, dth_p
    if ddth_act is None:
        return dtheta, None
    rhs = (Ja @ ddth_act[..., None])[..., 0] + constraint_bias(theta, dtheta, p)
    ddtheta = np.empty(theta.shape)
    ddtheta[..., list(ACTUATED)] = ddth_act
    ddtheta[..., list(PASSIVE)] = -np.linalg.solve(Jp, rhs[..., None])[..., 0]
    return dtheta, ddtheta


#: Grid step [deg] of :func:`auto_start_pose` over the actuated angles.
AUTO_POSE_STEP_DEG = 1.0


def usable(th1: np.ndarray, th4: np.ndarray, p: FiveBarParams) -> np.ndarray:
    """Whether each pose (broadcast ``th1``, ``th4`` [rad]) closes on ``p.branch`` with the
    transmission angle in :data:`TRANSMISSION_RANGE_DEG`; boolean array of the broadcast shape."""
    with np.errstate(invalid="ignore"):
        mu = np.degrees(transmission_angle(assemble(th1, th4, p)))
        lo, hi = TRANSMISSION_RANGE_DEG
        return np.isfinite(mu) & (mu >= lo) & (mu <= hi)


@functools.lru_cache(maxsize=64)
def _auto_pose(l: tuple[float, ...], L0: float, branch: str, step_deg: float) -> tuple[float, float, float]:
    from scipy.ndimage import distance_transform_edt

    p = FiveBarParams(l=np.array(l), L0=L0, m=np.ones(4), inertia=np.ones(4), com=np.array(l) / 2,
                      damping=np.zeros(4), branch=branch)
    n = round(360.0 / step_deg)
    grid = np.arange(n) * (2.0 * np.pi / n)
    ok = usable(grid[:, None], grid[None, :], p)  # ok[i, j]: th1 = grid[i], th4 = grid[j]
    if not ok.any():
        return math.nan, math.nan, 0.0
    # Angles are periodic: the distance to the nearest unusable pose on a 3 x 3 tiling,
    # read on the centre tile (exact Euclidean distances in grid steps).
    dist = distance_transform_edt(np.tile(ok, (3, 3)))[n:2 * n, n:2 * n]
    i, j = np.unravel_index(int(np.argmax(dist)), dist.shape)  # first maximum in (th1, th4) order
    return float(grid[i]), float(grid[j]), float(dist[i, j] * 2.0 * np.pi / n)


def auto_start_pose(p: FiveBarParams, step_deg: float = AUTO_POSE_STEP_DEG) -> tuple[float, float, float]:
    """The start pose chosen when a scenario gives none: the most central usable pose.

    Rule: over a grid of actuated angles ``th1, th4`` in ``[0, 2 pi)`` with step
    ``step_deg``, mark the usable poses (the loop closes on ``p.branch`` and the
    transmission angle lies in :data:`TRANSMISSION_RANGE_DEG`), and take the usable
    pose farthest, in the ``(th1, th4)`` plane [rad] (periodic), from every unusable
    one: the pose with the most room to move before a closure failure or a Type II
    singularity.  Ties go to the smallest ``th1``, then the smallest ``th4``.  The
    distances are exact multiples of the grid step (a Euclidean distance transform),
    so the choice is deterministic.

    Parameters
    ----------
    p : FiveBarParams
    step_deg : float
        Grid step [deg]; the chosen pose is within half a step of the grid's best.

    Returns
    -------
    th1, th4 : float
        Actuated start angles [rad] in ``[0, 2 pi)``; NaN if no pose is usable.
    margin : float
        Distance [rad] in the ``(th1, th4)`` plane from the pose to the nearest unusable
        grid pose (0 if none is usable).
    """
    return _auto_pose(tuple(float(x) for x in p.l), float(p.L0), p.branch, float(step_deg))
