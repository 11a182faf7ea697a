"""Mode shapes and comparing shapes across channels: the modes of ``(M, C, K)`` and the modal and
time-response assurance criteria (one implementation each; TRAC here since ``sgd_sindy`` compares
its models with the record by it; the modes here since the scorer and ``testbed identify``'s
summary both report them)."""

from __future__ import annotations

import numpy as np

from testbed.core.lazy import lazy_module

# imported on first use: `testbed list` does not pay for them
linalg = lazy_module("scipy.linalg")
optimize = lazy_module("scipy.optimize")

__all__ = ["mac_matrix", "modal_from_matrices", "pole_pairs", "slowest_decay_rate", "trac"]


def slowest_decay_rate(w: np.ndarray, zeta: np.ndarray) -> np.ndarray:
    """The slower decay rate of each mode of natural frequency ``w`` and damping ratio ``zeta``.

    ``zeta w`` for an underdamped mode (``zeta < 1``: the envelope's rate); ``w (zeta -
    sqrt(zeta^2 - 1))`` for an overdamped one (its slower real pole, the one that is left).

    Parameters
    ----------
    w : ndarray, shape (n,)
        Natural frequencies [rad/s].
    zeta : ndarray, shape (n,)
        Damping ratios [-]; NaN gives NaN.

    Returns
    -------
    ndarray, shape (n,)
        Decay rates [1/s].
    """
    w, z = np.asarray(w, dtype=float), np.asarray(zeta, dtype=float)
    with np.errstate(invalid="ignore"):
        return np.where(z < 1.0, z * w, w * (z - np.sqrt(np.maximum(z * z - 1.0, 0.0))))


def mac_matrix(phi_a: np.ndarray, phi_b: np.ndarray) -> np.ndarray:
    """Modal assurance criterion between every pair of mode shapes.

    Parameters
    ----------
    phi_a : ndarray, shape (n_dof, n_a)
        Mode shapes, one per column (real or complex); 1-D is one mode.
    phi_b : ndarray, shape (n_dof, n_b)

    Returns
    -------
    ndarray, shape (n_a, n_b)
        ``MAC[i, j] = |a_i^H b_j|^2 / ((a_i^H a_i)(b_j^H b_j))`` in [0, 1]; NaN for a zero shape.
    """
    a, b = np.asarray(phi_a), np.asarray(phi_b)
    a = a[:, None] if a.ndim == 1 else a
    b = b[:, None] if b.ndim == 1 else b
    if a.shape[0] != b.shape[0]:
        raise ValueError(f"mode shapes have {a.shape[0]} and {b.shape[0]} DOFs")
    a, b = _power_of_two_scaled(a, 0), _power_of_two_scaled(b, 0)  # scale-free by definition
    num = np.abs(np.conj(a).T @ b) ** 2
    den = np.outer(np.sum(np.abs(a) ** 2, axis=0), np.sum(np.abs(b) ** 2, axis=0))
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.where(den > 0, num / np.where(den > 0, den, 1.0), np.nan)
    return np.minimum(out, 1.0)


def _power_of_two_scaled(z: np.ndarray, axis: int) -> np.ndarray:
    """``z`` with each slice along ``axis`` scaled by the power of two that brings its largest
    magnitude into [0.5, 1): exact (no rounding, for normal numbers), so a ratio of products
    keeps every bit it had, while signals of 1e-299 no longer underflow in their sums of squares
    (TRAC was NaN for a beam struck with 1e-300 N: 0 / 0) nor those of 1e200 overflow."""
    peak = np.max(np.abs(z), axis=axis, keepdims=True) if z.size else np.zeros(1)
    _, e = np.frexp(peak)  # peak = m 2**e, m in [0.5, 1); 0 for a zero slice: left as it is
    if np.iscomplexobj(z):
        return np.ldexp(z.real, -e) + 1j * np.ldexp(z.imag, -e)
    return np.ldexp(np.asarray(z, dtype=float), -e)


def trac(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Time response assurance criterion per channel.

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        Reference signal (truth or measurement), real or complex; 1-D is one channel.
    y : ndarray, shape (n_channels, n_samples)
        The identified model's counterpart.  Over frequency lines of FRFs this is FRAC.

    Returns
    -------
    ndarray, shape (n_channels,)
        ``|x_j^H y_j|^2 / ((x_j^H x_j)(y_j^H y_j))`` in [0, 1]; 1 for proportional signals
        (any nonzero scale), 0 for orthogonal ones.  NaN where either channel is all zero
        (undefined), so a threshold on it fails rather than passes.
    """
    x, y = np.atleast_2d(np.asarray(x)), np.atleast_2d(np.asarray(y))
    if x.shape != y.shape:
        raise ValueError(f"shapes differ: {x.shape} vs {y.shape}")
    x, y = _power_of_two_scaled(x, -1), _power_of_two_scaled(y, -1)  # scale-free by definition
    num = np.abs(np.sum(np.conj(x) * y, axis=-1)) ** 2
    den = np.sum(np.abs(x) ** 2, axis=-1) * np.sum(np.abs(y) ** 2, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.where(den > 0, num / np.where(den > 0, den, 1.0), np.nan)
    return np.minimum(out, 1.0)  # rounding can push the ratio of equal numbers to 1 + 1e-16


def modal_from_matrices(m: np.ndarray, c: np.ndarray | None, k: np.ndarray, *, strict: bool = True
                        ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Natural frequencies, damping ratios and mass-normalised modes of ``M x'' + C x' + K x = 0``.

    Parameters
    ----------
    m : ndarray, shape (n, n)
        Mass matrix [kg]; must be symmetric positive definite.
    c : ndarray, shape (n, n), or None
        Damping matrix [N s/m]; None means undamped.
    k : ndarray, shape (n, n)
        Stiffness matrix [N/m]; symmetric.
    strict : bool
        If True (default) a mass matrix that is not symmetric positive definite, or a negative
        stiffness eigenvalue, raises ValueError.  If False, the same cases return all-NaN
        arrays (non-PD M, or one so small against K or C that ``M^-1 K`` or ``M^-1 C``
        overflows) or NaN frequencies for the unstable modes, so a scorer can record a failed
        identification without a try block.

    Returns
    -------
    freqs_hz : ndarray, shape (n,)
        Undamped natural frequencies ``w_n / 2 pi`` [Hz], ascending.
    damping_ratios : ndarray, shape (n,)
        Damping ratios [-] (zeros when ``c`` is None); above 1 for an overdamped mode.
    modes : ndarray, shape (n, n)
        Real mode shapes of ``(K, M)``, one per column, ``modes^T M modes = I``, largest
        component of each positive.

    Notes
    -----
    Modes come from the generalised symmetric eigenproblem ``K phi = w^2 M phi``.  With
    damping, the 2n eigenvalues ``lambda`` of the first-order system
    ``[[0, I], [-M^-1 K, -M^-1 C]]`` are assigned two per real mode (:func:`pole_pairs`), and
    each pair gives ``w_n^2 = lambda_1 lambda_2`` and ``2 zeta w_n = -(lambda_1 + lambda_2)``:
    for an underdamped mode ``lambda_2 = conj(lambda_1)``, so ``w_n = |lambda|`` and
    ``zeta = -Re(lambda) / |lambda|``; an overdamped mode's two real eigenvalues give
    ``zeta > 1``.  Exact for proportional damping; for non-proportional damping the
    frequencies are the complex modes' and the shapes stay the undamped ones.
    """
    m, k = np.asarray(m, dtype=float), np.asarray(k, dtype=float)
    n = m.shape[0]
    if m.shape != (n, n) or k.shape != (n, n):
        raise ValueError(f"M and K must be square and alike, got {m.shape} and {k.shape}")
    nan = (np.full(n, np.nan), np.full(n, np.nan), np.full((n, n), np.nan))
    if not (np.all(np.isfinite(m)) and np.all(np.isfinite(k))
            and (c is None or np.all(np.isfinite(c)))):
        if strict:
            raise ValueError("M, C or K holds non-finite entries")
        return nan
    if not np.allclose(m, m.T, rtol=1e-10, atol=1e-14 * np.abs(m).max()):
        if strict:
            raise ValueError("mass matrix is not symmetric")
        return nan
    try:
        linalg.cholesky(m, lower=True)
    except linalg.LinAlgError:
        if strict:
            raise ValueError("mass matrix is not positive definite") from None
        return nan
    if np.allclose(k, k.T, rtol=1e-10, atol=1e-14 * max(np.abs(k).max(), 1e-300)):
        try:
            lam, modes = linalg.eigh(0.5 * (k + k.T), m)
        except linalg.LinAlgError:
            # M positive definite yet tiny against K (1e-320 kg: the reduction by its Cholesky
            # factor overflows and LAPACK's solver fails); named as the overflow below is
            if strict:
                raise ValueError("M^-1 K overflows (the mass matrix is too small against K)") from None
            return nan
    else:
        # An identified K need not be symmetric (e.g. least-squares SINDy with a diagonal M):
        # the shapes the model actually vibrates in are the right eigenvectors of M^-1 K.
        # Symmetrising K first would score modes the model does not have.
        mk = linalg.solve(m, k)
        if not np.all(np.isfinite(mk)):
            # a mass matrix tiny against K (a declared total mass of 1e-320 kg): M^-1 K
            # overflows and scipy's eig refused it, a ValueError even when not strict (round 15)
            if strict:
                raise ValueError("M^-1 K overflows (the mass matrix is too small against K)")
            return nan
        lam_c, vec = linalg.eig(mk)
        order = np.argsort(lam_c.real)
        lam_c, vec = lam_c[order], vec[:, order]
        # rotate each (possibly complex) vector so its largest component is real, keep the real part
        big = np.argmax(np.abs(vec), axis=0)
        vec = vec * np.exp(-1j * np.angle(vec[big, np.arange(n)]))
        lam, modes = lam_c.real, vec.real
        modes = modes / np.sqrt(np.einsum("ij,ik,kj->j", modes, 0.5 * (m + m.T), modes))
    if np.any(lam < -1e-12 * max(1.0, np.abs(lam).max())):
        if strict:
            raise ValueError(f"stiffness has negative eigenvalues {lam[lam < 0]} (unstable model)")
    big = np.argmax(np.abs(modes), axis=0)
    modes = modes * np.sign(modes[big, np.arange(n)])
    with np.errstate(invalid="ignore"):
        omega = np.where(lam >= 0, np.sqrt(np.abs(lam)), np.nan)
    zeta = np.zeros(n)
    if c is not None:
        c = np.asarray(c, dtype=float)
        if c.shape != (n, n):
            raise ValueError(f"C must be {(n, n)}, got {c.shape}")
        minv = linalg.solve(m, np.eye(n), assume_a="pos")
        with np.errstate(over="ignore", invalid="ignore"):
            a = np.block([[np.zeros((n, n)), np.eye(n)], [-minv @ k, -minv @ c]])
        if not np.all(np.isfinite(a)):  # as M^-1 K above, with M^-1 C
            if strict:
                raise ValueError("M^-1 K or M^-1 C overflows (the mass matrix is too small)")
            return nan
        ev, vec = linalg.eig(a)
        lam_pair = pole_pairs(ev, vec[:n], modes, m)
        w2 = np.real(lam_pair[:, 0] * lam_pair[:, 1])
        with np.errstate(invalid="ignore", divide="ignore"):
            omega = np.where(w2 >= 0, np.sqrt(np.abs(w2)), np.nan)
            zeta = -np.real(lam_pair.sum(axis=1)) / (2.0 * omega)
    order = np.argsort(omega)  # NaN (unstable) modes last
    return omega[order] / (2.0 * np.pi), zeta[order], modes[:, order]


def pole_pairs(ev: np.ndarray, shapes: np.ndarray, modes: np.ndarray, m: np.ndarray) -> np.ndarray:
    """The 2n poles of a damped n-DOF model, two per real mode.

    Each pole's displacement shape is compared with every real mode by mass-weighted MAC
    (``|phi_k^T M v|^2`` over its sum across the modes).  The rule:

    1. an underdamped pole and its conjugate form one pair, and the pairs claim their modes
       first, each the mode it matches best (an assignment maximising the summed MAC): a
       complex pole is never split from its conjugate;
    2. the real poles fill the modes left, two per mode, by maximum summed MAC (an overdamped
       mode's two decay rates).

    Assigning the 2n poles to 2n slots by MAC alone (the rule until 2026-11-27) could put one
    pole of a conjugate pair with a real pole of another mode when shapes look alike on few
    sensors, and the pair's product was then no frequency at all: round 8's soft beam with
    three sensors at 3 % noise (``ls_sindy``: poles at 17.56 Hz, zeta 0.012, and 227.6 Hz,
    and one overdamped mode) was scored with mode 1 at 2.89 Hz, zeta 6.6 (83 % off), and
    round 7's ``b_soft_s4`` with mode 1 at 4.9 Hz, zeta 4.  For a model with no real pole
    whose pairs the MAC assignment kept together, the result is the same, to the bit.

    Parameters
    ----------
    ev : ndarray of complex, shape (2n,)
        Eigenvalues of the real first-order system [1/s]; a complex one's conjugate is also
        among them.
    shapes : ndarray of complex, shape (n, 2n)
        Their eigenvectors' displacement parts, one per column.
    modes : ndarray, shape (n, n)
        Real mode shapes, one per column.
    m : ndarray, shape (n, n)
        Mass matrix [kg].

    Returns
    -------
    ndarray of complex, shape (n, 2)
        Row ``k``: mode ``k``'s two poles (the upper-half-plane pole first for a conjugate
        pair).
    """
    n = modes.shape[1]
    proj = np.abs(np.conj(modes).T @ m @ shapes) ** 2
    with np.errstate(invalid="ignore", divide="ignore"):
        mac = np.nan_to_num(proj / proj.sum(axis=0, keepdims=True))  # (modes, poles)
    upper = np.flatnonzero(ev.imag > 0.0)
    real = np.flatnonzero(ev.imag == 0.0)
    lam_pair = np.empty((n, 2), dtype=complex)
    free = np.ones(n, dtype=bool)
    if upper.size:
        rows, cols = optimize.linear_sum_assignment(mac[:, upper], maximize=True)
        lam_pair[rows, 0] = ev[upper[cols]]
        lam_pair[rows, 1] = np.conj(ev[upper[cols]])
        free[rows] = False
    left = np.flatnonzero(free)
    if left.size:  # the real poles, two slots per mode left
        slot, which = optimize.linear_sum_assignment(np.repeat(mac[left][:, real], 2, axis=0),
                                                     maximize=True)
        lam_pair[left[slot // 2], slot % 2] = ev[real[which]]
    return lam_pair
