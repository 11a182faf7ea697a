"""Comparing shapes across channels: the modal and time-response assurance criteria (one
implementation each; TRAC here since ``sgd_sindy`` compares its models with the record by it)."""

from __future__ import annotations

import numpy as np

__all__ = ["mac_matrix", "trac"]


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
    num = np.abs(np.conj(a).T @ b) ** 2
    den = np.outer(np.sum(np.abs(a) ** 2, axis=0), np.sum(np.abs(b) ** 2, axis=0))
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.where(den > 0, num / np.where(den > 0, den, 1.0), np.nan)
    return np.minimum(out, 1.0)


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
    num = np.abs(np.sum(np.conj(x) * y, axis=-1)) ** 2
    den = np.sum(np.abs(x) ** 2, axis=-1) * np.sum(np.abs(y) ** 2, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.where(den > 0, num / np.where(den > 0, den, 1.0), np.nan)
    return np.minimum(out, 1.0)  # rounding can push the ratio of equal numbers to 1 + 1e-16
