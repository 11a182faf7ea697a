"""Reference for tests only: the Python RK4 of ``sindy_pi_dynamical``'s identified equations that
the compiled kernel (identify/_dynsim.py) replaced, kept as it was (one ``derivative`` call, numpy,
per RK4 stage) to check the kernel to round-off."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from testbed.core.measurement import Trajectory


def simulate_reference(model: Any, x0: np.ndarray, t: np.ndarray, u: np.ndarray | None,
                       dt: float) -> Trajectory:
    """RK4 of ``model.derivative`` from ``x0`` (n_states,) over the uniform times ``t``
    (n_samples,) [s] in steps of at most ``dt`` [s]; inputs ``u`` (n_inputs, n_samples)
    interpolated linearly; ``xdd`` central differences of ``xd``.  Raises what ``derivative``
    raises (:class:`testbed.core.errors.DivergenceError`)."""
    t = np.asarray(t, dtype=float)
    x = np.array(x0, dtype=float).ravel()
    uu = None if u is None or np.size(u) == 0 else np.atleast_2d(np.asarray(u, dtype=float))

    def u_at(s: float) -> np.ndarray | None:
        return None if uu is None else np.array([np.interp(s, t, r) for r in uu])

    def f(s: float, y: np.ndarray) -> np.ndarray:
        return model.derivative(y, u_at(s), s)

    X = np.empty((x.size, t.size))
    Xd = np.empty_like(X)
    X[:, 0] = x
    for k in range(t.size - 1):
        h_total = t[k + 1] - t[k]
        steps = max(1, math.ceil(h_total / dt - 1e-9))
        h = h_total / steps
        s = t[k]
        for _ in range(steps):
            k1 = f(s, x)
            k2 = f(s + h / 2, x + h / 2 * k1)
            k3 = f(s + h / 2, x + h / 2 * k2)
            k4 = f(s + h, x + h * k3)
            x = x + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
            s += h
        X[:, k + 1] = x
    for k in range(t.size):
        Xd[:, k] = f(t[k], X[:, k])
    Xdd = np.gradient(Xd, t, axis=1) if t.size > 1 else np.zeros_like(Xd)
    return Trajectory(X, Xd, Xdd)
