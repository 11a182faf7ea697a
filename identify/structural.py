"""Shared machinery of the structural identifiers (``kind = "structural"``).

A structural model in sensor coordinates ``x`` (n channels, displacement [m]) is

    M x'' + C x' + K x + K3 x^3 = B u,

with ``M``, ``C``, ``K`` [kg, N s/m, N/m] (n x n), the cubic restoring force
``f_i = sum_j K3[i, j] x_j^3`` (``K3`` [N/m^3], n x n) and ``B`` (n x n_inputs) mapping
measured inputs ``u`` [N] to the coordinates.

The SINDy regression form (see ``/work/shared/reference/sgd-sindy-notes.md``) divides row i by
``M_ii``:

    x''_i = sum_{j != i} xi_a[i, j] x''_j + sum_j xi_v[i, j] x'_j + sum_j xi_d[i, j] x_j
            + sum_j xi_c[i, j] x_j^3 (+ g_i (B u)_i),

so ``xi_a[i, j] = -M_ij / M_ii``, ``xi_v = -diag(M)^-1 C``, ``xi_d = -diag(M)^-1 K``,
``xi_c = -diag(M)^-1 K3`` and ``g_i = 1 / M_ii``.  :func:`build_library` builds the features,
:func:`matrices_from_coef` maps coefficients and diagonal masses back to ``M, C, K, K3``,
:func:`simulate_structural` integrates a model and :class:`StructuralIdentifier` gives both
identifiers their common ``simulate``/``equations``/modal attributes.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import linalg

from identify._base import Identifier
from identify._structural_sim import simulate_structural
from testbed.core.errors import IdentificationError
from testbed.core.measurement import Measurement, Trajectory

#: Keys of ``Measurement.prior`` a structural identifier may take the mass scale from.
MASS_PRIORS = ("reduced_mass_trace", "total_mass")


# --------------------------------------------------------------------------------------------
# Library
# --------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Library:
    """Features of the structural regression on the fit window.

    Attributes
    ----------
    theta : ndarray, shape (n_features, n_samples)
        Feature rows, in this order: ``xdd`` (n, only if ``coupled_mass``), ``xd`` (n), ``x`` (n),
        ``x^3`` (n, only if ``cubic``), ``(B u)`` (n, only if the window holds a nonzero input).
    target : ndarray, shape (n, n_samples)
        Accelerations ``xdd`` [m/s^2] to reconstruct, one row per channel.
    mask : ndarray of bool, shape (n, n_features)
        Which coefficient each row may use: the own acceleration is excluded (zero diagonal of
        ``xi_a``) and row i uses only its own forcing ``(B u)_i``.
    names : list of str
        Feature names (``a1`` = x''_1, ``v1`` = x'_1, ``x1``, ``x1^3``, ``f1`` = (B u)_1).
    blocks : dict of str to slice
        Rows of ``theta`` of each block: keys among ``"a"``, ``"v"``, ``"d"``, ``"c"``, ``"f"``.
    """

    theta: np.ndarray
    target: np.ndarray
    mask: np.ndarray
    names: list[str]
    blocks: dict[str, slice]


def build_library(data: Measurement, *, coupled_mass: bool, cubic: bool, start: int | None = None) -> Library:
    """Build the structural SINDy library from a measurement's fit window.

    Parameters
    ----------
    data : Measurement
        Measured ``x`` [m], ``xd`` [m/s], ``xdd`` [m/s^2], each (n, n_samples).
    coupled_mass : bool
        Include the other channels' accelerations (the SGD-SINDy library).
    cubic : bool
        Include the cubic displacement features ``x_j^3`` [m^3].
    start : int, optional
        First sample of the fit window; default ``data.free_start``.

    Returns
    -------
    Library
        The input block ``(B u)`` [N] is included only when ``data.u`` and ``data.input_map``
        exist and the input is nonzero somewhere in the window (free decay after an impact
        gives no input block).
    """
    s = data.free_start if start is None else int(start)
    x, xd, xdd = (np.asarray(a, dtype=float)[:, s:] for a in (data.x, data.xd, data.xdd))
    n = x.shape[0]
    if x.shape[1] < 4:
        raise IdentificationError(f"fit window from sample {s} holds {x.shape[1]} samples; need more")
    rows, names, blocks = [], [], {}
    mask_blocks = []

    def add(key: str, arr: np.ndarray, prefix: str, suffix: str, allow: np.ndarray) -> None:
        k0 = sum(r.shape[0] for r in rows)
        rows.append(arr)
        names.extend(f"{prefix}{j + 1}{suffix}" for j in range(n))
        blocks[key] = slice(k0, k0 + n)
        mask_blocks.append(allow)

    full = np.ones((n, n), dtype=bool)
    if coupled_mass:
        add("a", xdd, "a", "", ~np.eye(n, dtype=bool))
    add("v", xd, "v", "", full)
    add("d", x, "x", "", full)
    if cubic:
        add("c", x**3, "x", "^3", full)
    if data.u is not None and data.input_map is not None:
        f = np.asarray(data.input_map, dtype=float) @ np.asarray(data.u, dtype=float)[:, s:]
        if np.any(f != 0.0):
            add("f", f, "f", "", np.eye(n, dtype=bool))
    return Library(np.vstack(rows), xdd, np.hstack(mask_blocks), names, blocks)


def matrices_from_coef(coef: np.ndarray, blocks: dict[str, slice], masses: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None]:
    """Physical matrices from regression coefficients and the diagonal masses.

    Parameters
    ----------
    coef : ndarray, shape (n, n_features)
        Regression coefficients ``Xi^T`` in SI units (row i predicts ``x''_i``).
    blocks : dict of str to slice
        As :attr:`Library.blocks`.
    masses : ndarray, shape (n,)
        Diagonal masses ``M_ii`` [kg].

    Returns
    -------
    M, C, K : ndarray, shape (n, n)
        ``M = diag(m) (I - xi_a)`` (``M = diag(m)`` without an acceleration block),
        ``C = -diag(m) xi_v``, ``K = -diag(m) xi_d``.
    K3 : ndarray, shape (n, n) or None
        ``-diag(m) xi_c`` [N/m^3] if the library is cubic.
    """
    m = np.asarray(masses, dtype=float)[:, None]
    n = m.shape[0]
    M = np.eye(n) * m
    if "a" in blocks:
        xa = coef[:, blocks["a"]].copy()
        np.fill_diagonal(xa, 0.0)
        M = m * (np.eye(n) - xa)
    C = -m * coef[:, blocks["v"]]
    K = -m * coef[:, blocks["d"]]
    K3 = -m * coef[:, blocks["c"]] if "c" in blocks else None
    return M, C, K, K3


def mass_prior_value(data: Measurement, key: str) -> float:
    """The mass scale [kg] an identifier is given: ``data.prior[key]``.

    Parameters
    ----------
    data : Measurement
    key : {"reduced_mass_trace", "total_mass"}
        ``"reduced_mass_trace"``: trace of the sensor-coordinate (e.g. SEREP-reduced) mass
        matrix, the quantity ``sum_i M_ii`` really equals; ``"total_mass"``: the structure's
        physical mass, which the paper's Eq. 4 equates with ``sum_i M_ii`` (only exact for a
        lumped-mass model whose coordinates carry all the mass).

    Returns
    -------
    float
        The prior [kg], > 0.
    """
    if key not in MASS_PRIORS:
        raise ValueError(f"mass_prior must be one of {MASS_PRIORS}, got {key!r}")
    if key not in data.prior:
        raise IdentificationError(f"Measurement.prior has no {key!r} (has: {sorted(data.prior)}); the mass "
                         f"scale cannot be identified from free vibration without it")
    val = float(data.prior[key])
    if not val > 0:
        raise IdentificationError(f"prior {key!r} must be > 0 kg, got {val}")
    return val


#: Peaks closer than this fraction of their frequency count as one mode.  A hardening base
#: spring sweeps the soft cantilever's mode 1 from 40.2 to 38.4 Hz as it decays (measured), so
#: its peak splits; distinct bending modes of a beam lie a factor of 2 or more apart.
MODE_SEPARATION = 0.15


def measured_frequencies(data: Measurement, n_modes: int, freq_range: tuple[float, float] | None = None,
                         start: int | None = None) -> np.ndarray:
    """Natural frequencies [Hz] read from the spectral peaks of the measured accelerations.

    Uses :func:`testbed.numerics.spectral.peak_frequencies` (rectangular window, 8x zero padding,
    parabolic refinement; a Hann window would suppress the fast-decaying second mode of an impact
    response, whose energy sits at the start of the window) on ``data.xdd`` from the fit window.
    If fewer than ``n_modes`` peaks stand out the clear ones are returned (at least one).

    Parameters
    ----------
    data : Measurement
    n_modes : int
        Frequencies wanted.
    freq_range : (float, float), optional
        Search band [Hz]; default from 5 frequency bins (``5 fs / n_samples``) to ``0.45 fs``.
    start : int, optional
        First sample; default ``data.free_start``.

    Returns
    -------
    ndarray, shape (k,), 1 <= k <= n_modes
        Ascending frequencies [Hz].
    """
    from testbed.numerics.spectral import peak_frequencies

    s = data.free_start if start is None else int(start)
    xdd = np.asarray(data.xdd, dtype=float)[:, s:]
    n = xdd.shape[1]
    fmin, fmax = freq_range if freq_range is not None else (5.0 * data.fs / n, 0.45 * data.fs)
    last: Exception | None = None
    for k in range(int(n_modes), 0, -1):
        try:
            return peak_frequencies(xdd, data.fs, k, fmin=fmin, fmax=fmax, window="boxcar", pad=8,
                                    min_rel_separation=MODE_SEPARATION)
        except ValueError as exc:  # fewer clear peaks than asked for
            last = exc
    raise IdentificationError(f"no spectral peak found in the measured accelerations: {last}")


# --------------------------------------------------------------------------------------------
# Modal analysis and simulation
# --------------------------------------------------------------------------------------------
def modal(M: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Undamped natural frequencies and mode shapes of ``K u = lambda M u``.

    Parameters
    ----------
    M, K : ndarray, shape (n, n)
        Mass [kg] and stiffness [N/m]; need not be symmetric.

    Returns
    -------
    freqs : ndarray, shape (n,)
        ``sqrt(Re lambda) / (2 pi)`` [Hz], ascending; NaN for a non-positive eigenvalue.
    modes : ndarray, shape (n, n)
        Real parts of the eigenvectors, one mode per column; mass-normalised
        (``u^T M u = 1``) where ``u^T M u > 0``, else unit length.
    """
    lam, vec = linalg.eig(K, M)
    lam, vec = lam.real, vec.real
    order = np.argsort(np.where(np.isfinite(lam), lam, np.inf))
    lam, vec = lam[order], vec[:, order]
    with np.errstate(invalid="ignore"):
        freqs = np.where(lam > 0, np.sqrt(np.abs(lam)), np.nan) / (2.0 * np.pi)
    for k in range(vec.shape[1]):
        mk = float(vec[:, k] @ M @ vec[:, k])
        nrm = np.sqrt(mk) if mk > 0 else np.linalg.norm(vec[:, k])
        vec[:, k] /= nrm if nrm > 0 else 1.0
        imax = np.argmax(np.abs(vec[:, k]))
        if vec[imax, k] < 0:
            vec[:, k] *= -1.0
    return freqs, vec


# --------------------------------------------------------------------------------------------
# Common identifier behaviour
# --------------------------------------------------------------------------------------------
def _fmt(v: float, precision: int) -> str:
    return f"{v:+.{precision}g}"


class StructuralIdentifier(Identifier):
    """Common part of the structural identifiers: modal results, simulation, equations text.

    Subclasses set in ``fit``: ``M_``, ``C_``, ``K_``, ``K3_``, ``coef_``, ``feature_names_``,
    ``channels_``, ``input_map_`` and call :meth:`_finish_fit`.
    """

    kind = "structural"

    def _finish_fit(self) -> None:
        self.natural_frequencies_, self.modes_ = modal(self.M_, self.K_)

    def _check_fitted(self) -> None:
        if not hasattr(self, "M_"):
            raise RuntimeError(f"{type(self).__name__} is not fitted; call fit(data) first")

    def simulate(self, x0: np.ndarray, xd0: np.ndarray, t: np.ndarray,
                 u: np.ndarray | None = None) -> Trajectory:
        """Integrate the identified model (see :func:`simulate_structural`).

        Parameters
        ----------
        x0, xd0 : ndarray, shape (n,)
            Initial displacement [m] and velocity [m/s].
        t : ndarray, shape (n_t,)
            Equally spaced times [s].
        u : ndarray, shape (n_inputs, n_t), optional
            Input [N] applied through ``input_map_`` (zero-order hold).

        Returns
        -------
        Trajectory
            ``x``, ``xd``, ``xdd``, each (n, n_t).
        """
        self._check_fitted()
        return simulate_structural(self.M_, self.C_, self.K_, self.K3_, self.input_map_, x0, xd0, t, u)

    def equations(self, precision: int = 4) -> list[str]:
        """One line per channel: ``sum_j M_ij x''_j + C_ij x'_j + K_ij x_j (+ K3_ij x_j^3) = (B u)_i``.

        Coefficients in SI units ([kg], [N s/m], [N/m], [N/m^3]).
        """
        self._check_fitted()
        n = self.M_.shape[0]
        out = []
        for i in range(n):
            terms = []
            for mat, pre, suf in ((self.M_, "a", ""), (self.C_, "v", ""), (self.K_, "x", ""),
                                  (self.K3_, "x", "^3")):
                if mat is None:
                    continue
                terms += [f"{_fmt(mat[i, j], precision)} {pre}{j + 1}{suf}" for j in range(n)
                          if mat[i, j] != 0.0]
            rhs = "0"
            if self.input_map_ is not None:
                ins = [f"{_fmt(b, precision)} u{k + 1}" for k, b in enumerate(self.input_map_[i]) if b != 0]
                rhs = " ".join(ins) if ins else "0"
            name = self.channels_[i] if i < len(self.channels_) else f"x{i + 1}"
            out.append(f"[{name}] " + " ".join(terms) + f" = {rhs}")
        return out
