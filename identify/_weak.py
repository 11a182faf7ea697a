"""Weak (integral) form of implicit library equations: rows are test-function integrals.

Every implicit equation ``Theta(q, dq, ddq, u) xi = 0`` holds at every instant, so it also
holds for the integrals ``int phi_k(t) Theta(t) dt xi = 0`` against any test functions
``phi_k``.  The weak-form matrix ``V[k, c] = int phi_k Theta_c dt`` replaces the sample rows of
the strong form (one row per test function instead of one per sample); the same sparse
regression then runs on ``V``.

Test functions: ``phi(t) = (1 - s^2)^p`` with ``s = 2 (t - t_k) / L`` on ``|s| <= 1`` (zero
outside; window length ``L`` [s], degree ``p >= 2``), centred on ``n_windows`` equally spaced
times; ``phi`` and ``phi'`` vanish at the window ends.

Integration by parts.  A column with an acceleration factor is ``g(q, dq, u) ddq_j``.  With
``phi`` compactly supported ``int phi g ddq_j dt = -int (phi' g + phi dg/dt) dq_j dt``, exact.
Where ``g`` depends on angles (and constants) only, ``dg/dt = sum_i dg/dq_i dq_i`` needs the
rates alone (the product rule on the trig factors), so the column needs no second derivative
of the noisy angles: this is the case for every acceleration term of the five-bar and double
pendulum libraries (``cos(th1-th2)*ddth2``, ``sin(th1-th3)*cos(th1-th2)*ddth2``, ...).  A
column whose ``g`` holds a rate or an input factor (``dth1*ddth2``, ``u1*ddth1``) would need
``ddq`` or ``du/dt`` again; it is integrated as it stands, with the measured (estimated)
accelerations, and listed in ``WeakForm.strong_columns``.  Columns without an acceleration
are integrated directly; they need the rates at most.  The rates come from the signal chain
(low-passed, first derivative only): far less noisy than its accelerations (white noise
enters ``dq`` as ``fc^3`` against ``fc^5`` for ``ddq``), and the test-function integral
averages what is left over the window.

Quadrature: the rectangle rule on the samples (the integrands are smooth, sampled far above
their band, and vanish with ``phi`` at the ends), computed for all windows at once as a
correlation by FFT.  A held input (``hold="zoh"``: ``u[k]`` over ``[t_k, t_k+1)``) is not
smooth: its integral against a smooth ``w = phi g`` is ``sum_k u[k] int_k w dt``, and the
trapezoid of each interval, ``dt (w[k] + w[k+1]) / 2``, summed by parts pairs ``w[k]`` with
``(u[k-1] + u[k]) / 2`` (:func:`held_midpoints`; exact for the held input, ``O(dt^2 w'')``
for ``w``).  The rectangle rule with ``u[k]`` puts the held signal half a sample early: on a
double integrator held per sample (1 kHz) the true equation's window residual was 8.9e-3 of
its scale against 7.9e-5 (review 23g).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from identify.library import Library
from testbed.core.errors import IdentificationError
from testbed.core.schema import ErrorFn

#: Fewest samples of a test function: ``(1 - s^2)^p`` is zero at both ends of its window, so it
#: needs a sample in between to weigh anything (:func:`window_function`).
MIN_WINDOW_SAMPLES = 3


def window_samples(window_s: float, fs: float) -> int:
    """Samples a test-function window of ``window_s`` [s] spans at ``fs`` [Hz], both ends in
    (a window too long for any record, ``1e308`` s, counts ``2**62`` samples: no overflow)."""
    steps = window_s * fs
    return round(steps) + 1 if steps < 2.0**62 else 2**62


def check_window(window_s: float, fs: float, n_samples: int, error: ErrorFn) -> None:
    """A ``weak_window_s`` within a record of ``n_samples`` at ``fs`` [Hz] and long enough for
    a test function (:data:`MIN_WINDOW_SAMPLES`); ``error(key, value, allowed)`` otherwise."""
    samples = window_samples(window_s, fs)
    if samples > n_samples:
        error("weak_window_s", window_s, f"expected shorter than the record ({n_samples / fs:g} s)")
    if samples < MIN_WINDOW_SAMPLES:
        error("weak_window_s", window_s,
              f"at least {MIN_WINDOW_SAMPLES - 1} sample steps ({(MIN_WINDOW_SAMPLES - 1) / fs:g} s "
              f"at {fs:g} Hz): a test function vanishing at both ends needs a sample between")


def window_function(n: int, degree: int) -> tuple[np.ndarray, np.ndarray]:
    """``phi`` and ``dphi/ds`` of ``(1 - s^2)^degree`` on ``n`` samples spanning ``s`` in [-1, 1].

    Parameters
    ----------
    n : int
        Samples per window (>= 3).
    degree : int
        Exponent ``p`` (>= 2: ``phi`` and ``phi'`` vanish at the ends).

    Returns
    -------
    phi, dphi_ds : ndarray, shape (n,)
        The test function and its derivative with respect to ``s`` (multiply by ``2 / L``
        for the time derivative).
    """
    if n < MIN_WINDOW_SAMPLES:
        raise ValueError(f"a test function needs at least {MIN_WINDOW_SAMPLES} samples, got {n}")
    if int(degree) < 2:
        raise ValueError(f"test-function degree must be >= 2, got {degree}")
    p = int(degree)
    s = np.linspace(-1.0, 1.0, n)
    b = 1.0 - s**2
    return b**p, -2.0 * p * s * b ** (p - 1)


@dataclass
class WeakForm:
    """The weak-form library matrix and its windows.

    Attributes
    ----------
    V : ndarray, shape (n_windows, n_terms)
        ``V[k, c] = int phi_k Theta_c dt`` [column unit times s].
    starts : ndarray of int, shape (n_windows,)
        First sample of each window (in the arrays passed to :func:`weak_matrix`).
    length : int
        Samples per window.
    strong_columns : list of str
        Acceleration columns integrated with the measured accelerations (no exact integration
        by parts from angles and rates).
    """

    V: np.ndarray
    starts: np.ndarray
    length: int
    strong_columns: list[str]


def held_midpoints(u: np.ndarray) -> np.ndarray:
    """A held input's value paired with each sample: ``(u[k-1] + u[k]) / 2``, ``u[0]`` at the
    first sample [the input's unit], shape as ``u`` (n_inputs, n_samples).

    A zero-order hold acts as ``u[k]`` over ``[t_k, t_k+1)``; a sample ``t_k`` borders the
    intervals of ``u[k-1]`` and ``u[k]``, so a smooth quantity evaluated there and integrated
    or differenced symmetrically about it (the trapezoid of the weak form's quadrature, the
    chain's central differences) meets the two half and half.
    """
    out = np.array(u, dtype=float)
    if out.shape[-1] >= 2:
        out[..., 1:] = 0.5 * (out[..., 1:] + out[..., :-1])
    return out


def _factor_rates(lib: Library, F: np.ndarray, xd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Time derivative of every factor row that depends on the angles only; mask of the rows
    whose derivative would need accelerations or input rates (rates, inputs)."""
    n, m = lib.n_coords, lib.n_inputs
    dF = np.zeros_like(F)
    unknown = np.zeros(F.shape[0], dtype=bool)
    dF[:n] = xd[:n]                      # d th / dt
    unknown[n:3 * n + m] = True          # d dth / dt, d ddth / dt, d u / dt
    if lib._trig:
        rate = lib._arg @ xd[:n]
        trig = slice(3 * n + m, lib._one)
        ang = lib._arg @ F[:n]
        dF[trig] = np.where(lib._is_sin[:, None], np.cos(ang), -np.sin(ang)) * rate
    return dF, unknown


def _correlate(A: np.ndarray, kernel: np.ndarray, starts: np.ndarray) -> np.ndarray:
    """``out[k, c] = sum_i kernel[i] A[starts[k] + i, c]`` for all windows (FFT)."""
    from scipy.signal import fftconvolve  # lazy: scipy.signal costs ~0.3 s of import

    full = fftconvolve(A, kernel[::-1, None], mode="valid", axes=0)
    return full[starts]


def weak_matrix(lib: Library, x: np.ndarray, xd: np.ndarray, xdd: np.ndarray | None,
                u: np.ndarray | None, fs: float, window_s: float, n_windows: int,
                degree: int = 4, hold: str = "linear") -> WeakForm:
    """Weak-form library matrix of a record (see the module docstring).

    Parameters
    ----------
    lib : Library
    x, xd : ndarray, shape (n_coords, n_samples)
        Angles [rad] (or displacements) and their rates.
    xdd : ndarray, shape (n_coords, n_samples), or None
        Accelerations; only used for columns that cannot be integrated by parts exactly
        (``WeakForm.strong_columns``); None raises if there are any.
    u : ndarray, shape (n_inputs, n_samples), optional
    fs : float
        Sample rate [Hz].
    window_s : float
        Support length ``L`` of each test function [s].
    n_windows : int
        Number of test functions, centred at equally spaced times from the first window
        that fits to the last.
    degree : int
        Exponent ``p`` of ``(1 - s^2)^p``.
    hold : {"linear", "zoh"}
        How ``u`` acts between samples: ``"zoh"`` held, integrated as held (each sample's input
        :func:`held_midpoints`: see the module docstring; the first sample takes ``u[0]``, where
        the first window's ``phi`` is zero anyway); ``"linear"`` the samples as given.

    Returns
    -------
    WeakForm
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    xd = np.atleast_2d(np.asarray(xd, dtype=float))
    N = x.shape[1]
    L = window_samples(window_s, fs)
    if L > N:
        raise IdentificationError(f"test-function window {window_s} s is longer than the record")
    if int(n_windows) < 2:
        raise ValueError(f"n_windows must be >= 2, got {n_windows}")
    starts = np.unique(np.round(np.linspace(0, N - L, int(n_windows))).astype(np.intp))
    phi, dphi_ds = window_function(L, degree)
    dt = 1.0 / fs
    dphi = dphi_ds * (2.0 / ((L - 1) * dt))

    if u is not None and hold == "zoh":
        u = held_midpoints(u)
    F = lib._factors(x, xd, None, u)
    rest = lib._products(F, lib._idx_noacc)             # (p, N): g of acceleration columns
    dF, unknown = _factor_rates(lib, F, xd)
    acc = lib.acc_index
    ibp = np.zeros(len(lib), dtype=bool)
    for c in np.flatnonzero(acc >= 0):
        ibp[c] = not unknown[lib._idx_noacc[c]].any()
    strong = [lib.names[c] for c in np.flatnonzero((acc >= 0) & ~ibp)]
    if strong and xdd is None:
        raise IdentificationError(f"columns {strong} need accelerations (no exact integration by parts)")

    # integrands: A0 against phi, A1 against phi'
    A0 = np.empty((N, len(lib)))
    A1 = np.zeros((N, len(lib)))
    plain = acc < 0
    A0[:, plain] = rest[plain].T
    if strong:
        cols = np.flatnonzero((acc >= 0) & ~ibp)
        A0[:, cols] = (rest[cols] * np.atleast_2d(xdd)[acc[cols]]).T
    for c in np.flatnonzero(ibp):
        idx = lib._idx_noacc[c]
        g_dot = np.zeros(N)
        for j in range(idx.size):
            if idx[j] == lib._one:
                continue
            others = np.delete(idx, j)
            g_dot += dF[idx[j]] * np.prod(F[others], axis=0)
        A0[:, c] = -g_dot * xd[acc[c]]
        A1[:, c] = -rest[c] * xd[acc[c]]
    V = _correlate(A0, phi * dt, starts)
    if ibp.any():
        V[:, ibp] += _correlate(A1[:, ibp], dphi * dt, starts)
    return WeakForm(V, starts, L, strong)
