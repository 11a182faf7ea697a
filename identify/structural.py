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

from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from identify._base import Identifier
from identify._structural_sim import simulate_structural, state_matrix
from testbed.core.errors import IdentificationError
from testbed.core.lazy import lazy_module
from testbed.core.measurement import PRIOR_RANGE, Measurement, Trajectory, prior_number
from testbed.core.schema import ErrorFn, Field
from testbed.numerics.filters import cutoff_problem, elliptic_highpass
from testbed.numerics.shapes import mac_matrix
from testbed.numerics.spectral import (
    band_power_fall,
    harmonic_amplitude_law,
    harmonic_lock,
    noise_lock_bar,
    own_lock,
    peak_candidates,
)

# imported on first use: `testbed list` does not pay for them
sfft = lazy_module("scipy.fft")
linalg = lazy_module("scipy.linalg")

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
        ``x^3`` (n, only if ``cubic``), ``(B u)`` (n, only if the window holds a nonzero input),
        the drift rows (only with ``drift`` and a declared ``data.drift_basis``).
    target : ndarray, shape (n, n_samples)
        Accelerations ``xdd`` [m/s^2] to reconstruct, one row per channel.
    mask : ndarray of bool, shape (n, n_features)
        Which coefficient each row may use: the own acceleration is excluded (zero diagonal of
        ``xi_a``) and row i uses only its own forcing ``(B u)_i``.
    names : list of str
        Feature names (``a1`` = x''_1, ``v1`` = x'_1, ``x1``, ``x1^3``, ``f1`` = (B u)_1,
        ``drift1``, ...).
    blocks : dict of str to slice
        Rows of ``theta`` of each block: keys among ``"a"``, ``"v"``, ``"d"``, ``"c"``, ``"f"``.
    """

    theta: np.ndarray
    target: np.ndarray
    mask: np.ndarray
    names: list[str]
    blocks: dict[str, slice]


def build_library(data: Measurement, *, coupled_mass: bool, cubic: bool, start: int | None = None,
                  drift: bool = False, input_coupling: bool = False) -> Library:
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
    drift : bool
        Add the rows of ``data.drift_basis`` (if the chain declares one) as block ``"z"``,
        free in every equation: the chain's unknown integration constants, to be estimated
        with the model and then dropped (they are not dynamics; see
        :attr:`testbed.core.measurement.Measurement.drift_basis`).
    input_coupling : bool
        Let every equation use every input column (``M^-1 B`` in full) instead of only the
        channel the input acts on.  For a model whose accelerations are not coupled through
        its own mass block (diagonal ``M``), ``M^-1 B`` of the real, mass-coupled structure
        is full; and these coefficients also take up the quasi-static response of the
        unmodelled modes (residual flexibility) to the chain-filtered force's slow tail.

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
            add("f", f, "f", "", np.ones((n, n), dtype=bool) if input_coupling else np.eye(n, dtype=bool))
    if drift and data.drift_basis is not None:
        z = np.asarray(data.drift_basis, dtype=float)[:, s:]
        k0 = sum(r.shape[0] for r in rows)
        rows.append(z)
        names.extend(f"drift{k + 1}" for k in range(z.shape[0]))
        blocks["z"] = slice(k0, k0 + z.shape[0])
        mask_blocks.append(np.ones((n, z.shape[0]), dtype=bool))
    return Library(np.vstack(rows), xdd, np.hstack(mask_blocks), names, blocks)


#: The fit-band high-pass (:func:`fit_band`), as a fraction of the lowest measured natural
#: frequency.  Below mode 1 a structure's response has nothing to fit, while twice-integrated
#: sensor noise (and what is left of the chain's integration constants) piles up there in the
#: displacements and, as noise in a regressor, pulls every stiffness toward zero, the weakly
#: excited modes most.  Measured on the beams family at 1 % noise (ls_sindy, mode-2 frequency
#: error on four members): 0.32-0.84 with the chain's 10 Hz high-pass only, 0.07-0.24 at
#: 0.5 x f1, 0.04-0.12 at 0.7 x f1.  0.7 keeps mode 1 inside the pass band (its edge is the
#: cut-off) with a 1.4x margin for a mode whose peak moves with amplitude (the soft base's
#: hardening: 5 %).
FIT_BAND_FRACTION = 0.7
#: Order of the fit-band elliptic high-pass (the chain's design: 0.1 dB ripple, 30 dB stop band).
FIT_BAND_ORDER = 5
#: The structural identifiers' ``fit_band_hz`` hyperparameter (see :func:`fit_band`).
FIT_BAND_FIELD = Field(float, None, unit="Hz", min=0.0,
                       doc="high-pass applied to every feature and target of the fit; default "
                           "by rule: 0.7 x the lowest measured peak; 0 = none")



def check_fit_band(params: dict[str, Any], fs: float, error: ErrorFn) -> None:
    """A user's ``fit_band_hz`` a zero-phase high-pass at ``fs`` [Hz] can take
    (:func:`testbed.numerics.filters.cutoff_problem`; None = by rule, 0 = none): 7000 Hz at
    12.8 kHz and 5e-324 Hz were ValueErrors of the fit, 1e-15 Hz a "Singular matrix"."""
    cut = params.get("fit_band_hz")
    problem = cutoff_problem(cut, fs) if cut else None
    if problem:
        error("fit_band_hz", cut, problem)


#: The peak search's lower-mode rule (rule 5 of :func:`modal_peaks`, :data:`LOWER_MODE_MAC`),
#: declared alike by ``sgd_sindy`` and ``ls_sindy``.
LOWER_MODES_FIELD = Field(bool, True, doc="a weaker peak below every kept one, with a shape "
                                          "unlike each (MAC < 0.7) and ringing at its own "
                                          "frequency, displaces the highest kept peak (a lower "
                                          "mode); False: the n strongest peaks")

#: The decay hold's switch, declared alike by ``sgd_sindy`` and ``ls_sindy``
#: (:func:`identify._modal_damping.decay_hold`).
DECAY_HOLD_FIELD = Field(bool, True, doc="give each mode the damping (and, within one spectral "
                                         "line, the frequency) fitted to its measured free "
                                         "decay (identify._modal_damping)")
#: The decay hold with the cubic library, declared alike by ``sgd_sindy`` and ``ls_sindy``
#: (:func:`identify._modal_damping.decay_hold` with ``backbone``).
DECAY_BACKBONE_FIELD = Field(bool, True, doc="with the cubic library, run the decay hold with an "
                                             "amplitude-dependent frequency wd + c "
                                             "exp(-2 sigma t), taking its small-amplitude "
                                             "limit wd as the linear frequency where the "
                                             "model's own cubic gives half the measured c")


def fit_band(data: Measurement, build: Callable[[int], Library], cutoff_hz: float | None = None,
             peaks: np.ndarray | None = None) -> tuple[Library, float, str]:
    """A library restricted to the band of the modes: one zero-phase high-pass on every row.

    The filter acts on the library's features and targets (built over the whole record, then
    cut to the fit window), not on the signals: an equation ``x'' = sum_k xi_k theta_k`` that
    holds sample by sample still holds for the filtered rows (the filter is linear and
    time-invariant), whatever the features are (``x^3`` too, which a filter on ``x`` would
    break).

    Parameters
    ----------
    data : Measurement
    build : callable
        ``build(start)``: the identifier's library from sample ``start`` on
        (e.g. ``lambda s: build_library(data, ..., start=s)``).
    cutoff_hz : float, optional
        A user's cut-off [Hz] (0 = no filter).  Default: the rule,
        :data:`FIT_BAND_FRACTION` x the lowest peak of :func:`modal_peaks`; no filter when no
        peak is accepted, or when the cut-off would not be above the chain's own high-pass.
    peaks : ndarray, optional
        ``modal_peaks(data).peaks`` [Hz] if the caller has them already (not searched again).

    Returns
    -------
    lib : Library
        On the fit window ``data.free_start:``.
    cutoff_hz : float
        The cut-off used [Hz]; 0 for none.
    rule : str
        Which rule chose it, for the fitted model's ``fit_band_rule_``.
    """
    s = int(data.free_start)
    fc, rule = fit_band_cutoff(data, cutoff_hz, peaks)
    if fc <= 0:
        return build(s), 0.0, rule
    full = build(0)

    def hp(z: np.ndarray) -> np.ndarray:
        return elliptic_highpass(z, data.fs, fc, FIT_BAND_ORDER)[:, s:]

    return Library(hp(full.theta), hp(full.target), full.mask, full.names, full.blocks), fc, rule


#: The fit band's tilt (:func:`tilt_library`): first differences of every row, so that the
#: squared equation error is weighed by ``(2 sin(pi f / fs))^2 ~ (2 pi f / fs)^2``.  Why: the
#: displacement regressor's noise is the sensor noise integrated twice, ``1/f^2`` in amplitude,
#: and piles up at the fit band's low edge, while a mode's stiffness is read from its
#: displacement, whose share of the signal falls as ``1/f^2``.  As noise in a regressor it
#: pulls the stiffness of the upper modes down (errors in variables).  Measured with ls_sindy
#: at 1 % noise on clamped beams of studies/families.toml: mode 2 at -12 to -74 % with clean
#: target and velocity but noisy displacement, at -0.01 to -1.5 % with only the displacement
#: clean (members 003, 004, 008, 012, 021); with one difference -0.2 to -37 % (mode 1 +0.02 to
#: +4.3 %), with two -1 to +0.5 % on mode 2 but mode 1 up to +115 %.  One difference is the
#: compromise; the measured peaks and free decays then place each mode (ls_sindy's holds).
FIT_TILT_DIFFERENCES = 1


def tilt_library(lib: Library, k: int = FIT_TILT_DIFFERENCES) -> Library:
    """``lib`` with ``k`` first differences along time applied alike to every row.

    An equation that holds sample by sample (``target = coef @ theta``) still holds for the
    differenced rows (a linear time-invariant filter), so the fit's coefficients mean the same;
    only the weight of each frequency in the squared error changes, by
    ``(2 sin(pi f / fs))^(2k)`` (see :data:`FIT_TILT_DIFFERENCES` for why).

    Parameters
    ----------
    lib : Library
    k : int
        Number of differences (0 = ``lib`` itself).

    Returns
    -------
    Library
        ``k`` samples shorter.
    """
    if k <= 0:
        return lib
    theta, target = tilt_rows(lib.theta, lib.target, k=k)
    return Library(theta, target, lib.mask, lib.names, lib.blocks)


def tilt_rows(*rows: np.ndarray, k: int = FIT_TILT_DIFFERENCES) -> list[np.ndarray]:
    """Each array of ``rows`` with ``k`` first differences along its last axis (time).

    The tilt of :func:`tilt_library` on bare signals (``sgd_sindy``'s fit, which keeps its
    features and nuisance columns as arrays).

    Parameters
    ----------
    *rows : ndarray, shape (..., N)
        Signals sampled along the last axis.
    k : int
        Number of differences (0 = unchanged).

    Returns
    -------
    list of ndarray
        Each ``k`` samples shorter.
    """
    return [np.diff(r, k, axis=-1) if k > 0 else r for r in rows]


#: A pole whose real part exceeds this fraction of its modulus grows; below it, the real part
#: is rounding of an undamped pole (float64 eigenvalues of a 2n x 2n state matrix).
GROWTH_RTOL = 1e-9


def growing_poles(lam: np.ndarray) -> np.ndarray:
    """Which poles ``lam`` [1/s] (complex, any shape) grow: real part above :data:`GROWTH_RTOL`
    of the modulus (a boolean array of the same shape); the one test of a growing mode."""
    lam = np.asarray(lam)
    return lam.real > GROWTH_RTOL * np.abs(lam)


def check_physical(M: np.ndarray, C: np.ndarray, K: np.ndarray, what: str = "least squares") -> None:
    """Raise :class:`IdentificationError` for a linear model with a growing mode.

    A pole of ``[[0, I], [-M^-1 K, -M^-1 C]]`` that grows (:func:`growing_poles`: real part
    above ``1e-9`` of its modulus, below it rounding of an undamped pole) is a mode that grows
    (negative damping or negative stiffness): a passive structure has none.

    Parameters
    ----------
    M, C, K : ndarray, shape (n, n)
        Mass [kg], damping [N s/m] and stiffness [N/m].
    what : str
        The fit named in the message as not constraining it.
    """
    lam = np.linalg.eigvals(state_matrix(M, C, K))
    bad = growing_poles(lam)
    if np.any(bad):
        worst = lam[bad][np.argmax(lam[bad].real)]
        raise IdentificationError(
            f"non-physical model: a pole at {worst.real:+.4g} {worst.imag:+.4g}j 1/s grows "
            f"(negative damping or negative stiffness); {what} does not constrain it")


def fit_band_cutoff(data: Measurement, cutoff_hz: float | None = None,
                    peaks: np.ndarray | None = None) -> tuple[float, str]:
    """The cut-off [Hz] of :func:`fit_band`'s high-pass and the rule that chose it (0 = none).

    ``cutoff_hz`` (a user's setting) wins; otherwise :data:`FIT_BAND_FRACTION` x the lowest
    peak of :func:`modal_peaks`, none when no peak is accepted or when it would not be above
    the chain's own high-pass.  ``peaks``: ``modal_peaks(data).peaks`` [Hz] if the caller has
    them already (not searched again).
    """
    if cutoff_hz is not None:
        return float(cutoff_hz), f"fit_band_hz = {float(cutoff_hz):g} Hz (user setting)"
    if peaks is None:
        peaks = modal_peaks(data).peaks
    if peaks.size == 0:
        return 0.0, "no measured peak: the chain's band as it is"
    fc = FIT_BAND_FRACTION * float(peaks.min())
    rule = f"{FIT_BAND_FRACTION:g} x the lowest measured peak ({peaks.min():.4g} Hz)"
    chain_hp = 0.0 if data.passband is None else float(data.passband[0])
    if not fc > chain_hp:
        return 0.0, rule + f": not above the chain's high-pass ({chain_hp:g} Hz), none added"
    return fc, rule


#: Length of the free decay :func:`free_decay_fit` reads, in periods of the model's lowest mode:
#: the slowest mode completes five cycles, enough for the modes' amplitudes to separate in one
#: least-squares fit.  With the cubic force on the right-hand side the reading does not depend
#: on it (measured, branch ``mass28``: 1, 2 and 5 periods agree within 2 % on the shipped soft
#: base at 50 and 150 N; without the cubic force the hardening mode's amplitude fell with the
#: window, 0.81 -> 0.35 -> -0.16 of ``1 / mu`` at 150 N).  The trade-off (review 28e): a
#: shorter window separates the slowest mode from the others less well (under one period its
#: amplitude and phase trade against theirs) and leaves fewer samples per column; a longer one
#: lets the model's frequency and decay-rate errors drift the simulated modes out of phase
#: with the record and weights the lightly damped modes' late samples, where the model's
#: cubic errors accumulate.  A mode's reading depends on where the window *starts* (its
#: amplitude is carried from the pulse to ``free_start`` by ``exp(sigma t)``), not on its
#: length (branch ``mass29``: 0.25-5 periods within 6 % of the cubic force error, 1 / mu within
#: 3 %); five periods sit on that plateau, with margin from both ends.
FREE_GAIN_PERIODS = 5.0


def free_decay_fit(data: Measurement, M: np.ndarray, C: np.ndarray, K: np.ndarray,
                   K3: np.ndarray | None, j: int) -> tuple[np.ndarray, np.ndarray] | None:
    """The input gain ``g = M^-1 B[:, j]`` that best explains the free decay after the pulse,
    with its covariance.

    An impact's samples hold, besides the kept modes' response, the quasi-static response of
    the modes the model leaves out (it ends with the pulse); a gain fitted on them carries it
    and, read as modal mass (:func:`driving_point_scaling`), shares the mass wrongly.  After
    the pulse only the kept modes ring, each with the amplitude and phase its share of the
    impulse gave it.  The model's equation ``M x'' + C x' + K x = B u - K3 x^3``, its cubic
    force evaluated on the *measured* displacement (so that the hardening modes' shifting
    phase is the model's, not left to the gain), is linear in the gains: the response to
    each input ``u[m]`` with the gain ``e_i`` (``n`` columns per input, so that another
    input's ringing is not put down to ``u[j]``'s gain) plus the response to ``-K3 x^3`` (zero
    initial state at the record's start), fitted by least squares to the measured
    accelerations on the samples from ``data.free_start`` over :data:`FREE_GAIN_PERIODS`
    periods of the model's lowest mode; ``g`` is input ``j``'s row.

    Parameters
    ----------
    data : Measurement
        Displacements ``x`` [m] and accelerations ``xdd`` [m/s^2], (n, n_t); input ``u`` [N];
        ``free_start``.
    M, C, K : ndarray, shape (n, n)
        The fitted linear part [kg], [N s/m], [N/m].
    K3 : ndarray, shape (n, n) or None
        The fitted cubic stiffness [N/m^3] (None: a linear model).
    j : int
        The input (row of ``data.u``) at the driving point.

    Returns
    -------
    (g, cov) or None
        The gain [1/kg], shape (n,), and its least-squares covariance ``s^2 (A^T A)^-1``
        [1/kg^2], shape (n, n) (``s^2`` the residual variance over the free samples), times
        the residual's :func:`correlation_factor` (a correlated residual holds fewer
        independent samples than it has); None
        when ``data.free_start`` is 0 (a continuous input, or a window
        cut after the pulse: no free decay), the window is too short, the model has no
        oscillating mode or the fit is not finite.
    """
    n = M.shape[0]
    w2 = np.linalg.eigvals(np.linalg.solve(M, K)).real
    if not np.all(np.isfinite(w2)) or not np.any(w2 > 0) or data.u is None:
        return None
    period = 2 * np.pi / np.sqrt(w2[w2 > 0].min())
    i0 = int(data.free_start)
    if i0 <= 0:  # a continuous input or a window cut after the pulse: no free decay to read
        return None
    U = np.asarray(data.u, dtype=float)
    i1 = min(data.n_samples, i0 + round(FREE_GAIN_PERIODS * period * data.fs))
    if i1 - i0 < max(n, U.shape[0]):
        return None
    t = np.arange(i1) / data.fs
    z = np.zeros(n)
    target = np.asarray(data.xdd, dtype=float)[:, i0:i1]
    if K3 is not None and np.any(K3 != 0):
        cubic = -np.asarray(K3, dtype=float) @ np.asarray(data.x, dtype=float)[:, :i1] ** 3
        target = target - simulate_structural(M, C, K, None, np.eye(n), z, z, t, cubic).xdd[:, i0:]
    # every input's response has its n columns in the one least squares (each input's gain
    # M^-1 B[:, m] free): another hammer's ringing is not put down to input j's gain
    cols = [simulate_structural(M, C, K, None, M[:, [i]], z, z, t, U[m:m + 1, :i1]).xdd[:, i0:].ravel()
            for m in range(U.shape[0]) for i in range(n)]
    A, b = np.stack(cols, axis=1), target.ravel()
    G = np.linalg.lstsq(A, b, rcond=None)[0]
    g = G.reshape(U.shape[0], n)[j]
    if not np.all(np.isfinite(g)):
        return None
    # the least squares' covariance, s^2 (A^T A)^-1 (residual variance over the free samples),
    # times the residual's correlation factor (review 28e M2: a clean record's residual is
    # model error, correlated from sample to sample, not white)
    dof = max(b.size - A.shape[1], 1)
    r = b - A @ G
    s2 = float(np.sum(r**2)) / dof
    cov = s2 * np.linalg.pinv(A.T @ A) * correlation_factor(r.reshape(n, -1))
    rows = slice(j * n, (j + 1) * n)
    return g, cov[rows, rows]


def correlation_factor(r: np.ndarray) -> float:
    """How many times a least squares' white-noise variance understates its coefficients'
    variance when its residual ``r`` is correlated from sample to sample.

    Rule (the AR(1) effective sample size, Bartlett): ``rho`` the lag-1 autocorrelation of
    the residual pooled over its channels (``sum r_t r_{t+1} / sum r_t^2``), the factor
    ``(1 + rho) / (1 - rho)``, held between 1 (a residual no more correlated than white noise
    is not read as less uncertain) and the number of samples per channel (no fewer than one
    independent sample).  Continuous in ``rho``.  Why (review 28e M2): on a clean record the
    free decay's residual is the model's error, smooth at the sample rate (``rho`` 0.83-0.98 on
    the shipped soft scenarios and round 24's soft cells), so the white spread, 0.3-0.7 % of a
    mode's reading on the shipped soft base, underrated how loosely a heavily damped mode is
    held (:func:`held_share`).

    A conservative bound (review 29c M3): for a least-squares coefficient the AR(1) factor is
    about ``(1 + rho rho_x) / (1 - rho rho_x)`` with ``rho_x`` its regressor's lag-1
    autocorrelation (Bretherton et al. 1999), and the mean's factor used here, ``rho_x = 1``,
    is the largest.  Measured (branch sgd30, free decay of the kept model, clean): it
    overstates the per-column variance 1.2-1.7x on the shipped soft scenarios, 1.0-2.2x on
    16 of the 19 families' soft members read (clean), 4.5x on 013, 8.6x on 008 and 21x on 017
    (``rho`` 0.9996).  Scaled per column instead (``cov_ij sqrt(f_i f_j)``, ``f_i`` in
    ``[1, n_t]``), no verdict moved on the four shipped cubic scenarios and the 20 soft
    members (issue #15's bars and the scenarios' own) and the cubic force error moved by -0.011 to
    +0.0003 (000 0.063 -> 0.053, its Mr error 0.011 -> 0.014): not adopted, a change with
    losses and no verdict gained (docs/known-gaps.md, sgd30).

    Parameters
    ----------
    r : ndarray, shape (n_channels, n_t)
        The residual, each row one channel's samples in time order.

    Returns
    -------
    float
        The factor [-], in ``[1, n_t]``; 1 for a residual of fewer than 2 samples or zero.
    """
    r = np.asarray(r, dtype=float)
    if r.ndim != 2 or r.shape[1] < 2:
        return 1.0
    e = float(np.sum(r**2))
    if not e > 0.0:
        return 1.0
    rho = float(np.sum(r[:, 1:] * r[:, :-1])) / e
    if not rho < 1.0:
        return float(r.shape[1])
    return float(np.clip((1.0 + rho) / (1.0 - rho), 1.0, r.shape[1]))


def free_decay_gain(data: Measurement, M: np.ndarray, C: np.ndarray, K: np.ndarray,
                    K3: np.ndarray | None, j: int) -> np.ndarray | None:
    """The input gain ``g = M^-1 B[:, j]`` read from the free decay after the pulse
    (:func:`free_decay_fit` without its covariance); None where that gives none."""
    fit = free_decay_fit(data, M, C, K, K3, j)
    return None if fit is None else fit[0]


def modal_spread(phi: np.ndarray, cov: np.ndarray, col: np.ndarray) -> np.ndarray:
    """Standard error of each mode's ``1 / mu_r = (Phi^-1 g)_r / Phi[k, r]`` from ``g``'s
    covariance ``cov`` (shape (n, n), [1/kg^2]); ``phi`` (n, n) mass-normalised shapes,
    ``col`` = ``phi[k, :]``.  Returns shape (n,), dimensionless (modal masses relative to
    the fitted ``M``'s)."""
    P = np.linalg.inv(phi) / col[:, None]
    return np.sqrt(np.maximum(np.diag(P @ cov @ P.T), 0.0))


def held_share(inv_mu: np.ndarray, spread: np.ndarray) -> np.ndarray:
    """Each mode's read ``1 / mu`` weighted by how well the free decay holds it.

    A mode the free decay barely holds (heavily damped, gone within the window's first
    samples) has a reading whose standard error ``spread`` is of the order of the reading
    itself; taken as it is, its error is spread over the other modes by the trace
    normalisation (review 28e M2).  The rule, continuous: ``w = a^2 / (a^2 + s^2)`` (the
    reading's signal-to-error share), ``1 / mu = w a + (1 - w) * 1``, ``1`` being the fitted
    model's own modal mass (``Phi`` mass-normalised to it: the mass prior's sharing).

    Parameters
    ----------
    inv_mu : ndarray, shape (n,)
        The read ``1 / mu`` relative to the fitted model's modal masses.
    spread : ndarray, shape (n,)
        Their standard errors (:func:`modal_spread`).

    Returns
    -------
    ndarray, shape (n,)
    """
    a2 = inv_mu**2
    w = np.divide(a2, a2 + spread**2, out=np.zeros_like(a2), where=(a2 + spread**2) > 0)
    return w * inv_mu + (1.0 - w)


def driving_point_scaling(M: np.ndarray, C: np.ndarray, K: np.ndarray, K3: np.ndarray | None,
                          B: np.ndarray | None, declared: np.ndarray | None,
                          data: Measurement | None = None
                          ) -> tuple[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray | None,
                                           np.ndarray | None], str]:
    """Modal masses from the identified input gain at the driving point, as modal testing scales modes.

    Free vibration fixes ``M^-1 K`` and ``M^-1 C`` but not how the mass is shared among the
    modes.  A force measured at sensor ``k`` does: the identified gain ``g = M^-1 B[:, j]`` is
    column ``k`` of the true ``M^-1 = Phi diag(1 / mu) Phi^T`` (``Phi`` the mode shapes,
    ``mu`` the modal masses).  With ``Phi`` mass-normalised to the fitted ``M``, the modal
    masses are ``1 / mu_r = (Phi^-1 g)_r / Phi[k, r]``, scaled together so that
    ``trace(M')`` stays ``trace(M)`` (the mass prior, the paper's Eq. 4: the force gives how the
    mass is shared among the modes, the prior its total), and the model becomes
    ``M' = Phi^-T diag(mu) Phi^-1``, ``K' = Phi^-T diag(mu omega^2) Phi^-1``,
    ``C' = Phi^-T (mu^1/2 D mu^1/2) Phi^-1`` (``D = Phi^T C Phi``; exact for modal damping, the
    symmetric part otherwise), ``B' = M' M^-1 B``: the same ``M^-1 K``
    (frequencies and mode shapes), the same modal damping, the same ``M^-1 B`` (so the model
    simulates as before), the mass shared as the force says.  For a linear model ``M^-1 B``
    is the gain read, ``B' = M' g``; a cubic model's ``B'`` keeps its fitted gain, not the
    free decay's ``g`` (review 28e L3: the fitted map also carries the unmodelled modes'
    quasi-static response under the pulse, which the scored simulation needs, and the
    reading ``g`` only shares the mass).

    A cubic model reads ``g`` from the free decay after the pulse (:func:`free_decay_fit`),
    not from ``B``: an impact's samples hold the quasi-static response of the modes the model
    leaves out, which a gain fitted on them takes as the kept modes' and which the cubic force
    ``K3 x^3``, read in newtons, would carry (measured, issue #15 against the corrected cubic
    truth, branch ``mass28``: ``cantilever_soft_impact`` cubic force error 0.213 with the
    prior's scale, 0.075 with ``B``'s gain (the 150 N base then fails: 0.48), 0.088 with the free
    decay's (150 N 0.123 -> 0.121); figures in
    docs/known-gaps.md).  Each mode's reading is weighted by its standard error from that fit
    (:func:`held_share`; the least squares' spread times the residual's
    :func:`correlation_factor`, review 28e M2): a mode the free decay barely holds keeps
    the fitted model's own modal mass in proportion, rather than spreading its error over
    the others through the trace normalisation.  A linear model keeps ``B``'s gain, and so
    does a model whose ``K3`` is all zero (a cubic library whose every term was dropped: no
    cubic force to carry the pulse's quasi-static response, review 28e L6).

    Parameters
    ----------
    M, C, K : ndarray, shape (n, n)
        The fitted model [kg], [N s/m], [N/m]; ``M`` positive definite, ``K`` symmetric.
    K3 : ndarray, shape (n, n) or None
        Cubic stiffness [N/m^3].
    B : ndarray, shape (n, n_inputs) or None
        The identified input map (force per unit input on each coordinate).
    declared : ndarray, shape (n, n_inputs) or None
        The measurement's ``input_map``: a column with a single 1 is a force at that sensor.
    data : Measurement, optional
        The record; required for a cubic model, whose gain is read from the free decay after
        the pulse (:func:`free_decay_fit`) rather than taken from ``B``.

    Returns
    -------
    (M, C, K, K3, B)
        Rescaled (``K3' = M' M^-1 K3``: the cubic acceleration ``M^-1 K3`` kept, as ``M^-1 K``
        is); the inputs unchanged when no driving point is declared, a cubic model's record
        is not given or holds no free decay to read its gain from, a modal mass comes out
        non-positive or non-finite, or a mode has a node at the driving point (``|Phi[k, r]|``
        below 1e-6 of its largest entry: its modal mass is not seen from there).
    rule : str
        What was done, for ``mass_scaling_rule_``.
    """
    same = (M, C, K, K3, B)
    cubic = K3 is not None and bool(np.any(np.asarray(K3) != 0.0))
    if cubic and data is None:
        return same, "cubic model without its record: the mass prior's scale kept"
    if B is None or declared is None:
        return same, "no measured input: the mass prior's scale kept"
    D = np.asarray(declared, dtype=float)
    cols = [j for j in range(D.shape[1]) if np.count_nonzero(D[:, j]) == 1 and np.any(B[:, j] != 0)]
    if not cols:
        return same, "no input at a sensor in the fit window: the mass prior's scale kept"
    j = cols[0]
    k = int(np.flatnonzero(D[:, j])[0])
    lam, phi = linalg.eigh(K, M)  # phi^T M phi = I
    g = np.linalg.solve(M, B[:, j])
    cov = None
    if cubic:
        fit = free_decay_fit(data, M, C, K, K3, j)
        if fit is None:
            return same, "cubic model: no free decay to read the gain from, the prior's scale kept"
        g, cov = fit
    col = phi[k, :]
    if np.any(np.abs(col) < 1e-6 * np.abs(phi).max()):
        return same, f"a mode has a node at the driving point (sensor {k + 1}): the prior's scale kept"
    inv_mu = np.linalg.solve(phi, g) / col
    if not (np.all(np.isfinite(inv_mu)) and np.all(inv_mu > 0)):
        return same, f"driving point (sensor {k + 1}) gives a non-positive modal mass: the prior's scale kept"
    if cov is not None:
        # weighted after the refusal, not before: a reading no passive structure has is refused
        # whatever its spread (measured, branch mass29: weighting first turned four refusals
        # into acceptances, b25_br_soft_r1p6_cf0p65_fs10k cubic force 0.104 -> 0.583)
        inv_mu = held_share(inv_mu, modal_spread(phi, cov, col))
    pinv = np.linalg.inv(phi)
    # the sharing from the force, the total from the fit (its trace is the mass prior, the
    # paper's Eq. 4 constraint): M' is linear in mu, so one factor sets trace(M') = trace(M)
    mu = 1.0 / inv_mu
    mu *= np.trace(M) / np.trace(pinv.T @ np.diag(mu) @ pinv)
    Dm = phi.T @ C @ phi
    r = np.sqrt(mu)
    M2 = pinv.T @ np.diag(mu) @ pinv
    K2 = pinv.T @ np.diag(mu * lam) @ pinv
    C2 = pinv.T @ (r[:, None] * _sym(Dm) * r[None, :]) @ pinv
    B2 = M2 @ np.linalg.solve(M, B)
    if not cubic:
        return ((_sym(M2), _sym(C2), _sym(K2), None if K3 is None else np.zeros_like(K3), B2),
                f"modal masses from the input gain at the driving point (sensor {k + 1})")
    return ((_sym(M2), _sym(C2), _sym(K2), M2 @ np.linalg.solve(M, K3), B2),
            f"modal masses from the free decay's gain at the driving point (sensor {k + 1})")


def symmetric_basis(n: int) -> np.ndarray:
    """Basis of symmetric n x n matrices, shape (n(n+1)/2, n, n)."""
    out = []
    for i in range(n):
        for j in range(i, n):
            E = np.zeros((n, n))
            E[i, j] = E[j, i] = 1.0
            out.append(E)
    return np.array(out)


def symmetric_least_squares(signals: list[np.ndarray], rhs: np.ndarray) -> list[np.ndarray]:
    """Symmetric matrices ``S_k`` minimising ``||sum_k S_k signals[k] - rhs||`` over the samples.

    Parameters
    ----------
    signals : list of ndarray, each shape (n, N)
        The signals each unknown matrix multiplies (e.g. velocities [m/s], displacements [m]).
    rhs : ndarray, shape (n, N)
        What their sum should reproduce (e.g. ``-M x''`` [N]).

    Returns
    -------
    list of ndarray, each shape (n, n)
        One symmetric matrix per signal, in its units ([rhs] / [signal]).
    """
    n = rhs.shape[0]
    S = symmetric_basis(n)
    A = np.array([(E @ s).ravel() for s in signals for E in S]).T
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    # columns standardised: stiffness columns are ~1e3 x the damping ones on the cantilever
    c = np.linalg.lstsq(A / scale, rhs.ravel(), rcond=1e-12)[0] / scale
    m = len(S)
    return [np.einsum("k,kij->ij", c[k * m:(k + 1) * m], S) for k in range(len(signals))]


def _sym(a: np.ndarray) -> np.ndarray:
    return 0.5 * (a + a.T)


def solve_rows(lib: Library, rcond: float | None = None) -> np.ndarray:
    """Least squares of each channel's target on the features its mask allows.

    Parameters
    ----------
    lib : Library
    rcond : float, optional
        Relative singular-value cut-off of ``numpy.linalg.lstsq`` on the column-standardised
        features (unit RMS each; an all-zero feature keeps scale 1); None = numpy's default.

    Returns
    -------
    ndarray, shape (n, n_features)
        Coefficients in the features' own units (zero where the mask excludes a feature).
    """
    scale = np.sqrt(np.mean(lib.theta**2, axis=1))
    scale[scale == 0] = 1.0
    phi = (lib.theta / scale[:, None]).T
    n = lib.target.shape[0]
    coef = np.zeros((n, lib.theta.shape[0]))
    for i in range(n):
        cols = np.flatnonzero(lib.mask[i])
        sol, *_ = np.linalg.lstsq(phi[:, cols], lib.target[i], rcond=rcond)
        coef[i, cols] = sol / scale[cols]
    return coef


def remove_drift(data: Measurement) -> tuple[Measurement, np.ndarray | None]:
    """The measurement with the chain's integration constants estimated and taken out.

    For identifiers that do not carry :attr:`Measurement.drift_basis` in their own regression
    (the SGD fits, SINDy-PI's linear form).  The rows are ``w0 = H^2 s`` and ``w1 = H I H s``
    (:func:`testbed.pipeline.signal_chain.drift_basis`): a velocity offset ``e`` adds ``e w0``
    to ``xd`` and ``e w1`` to ``x``, a displacement offset ``c`` adds ``c w0`` to ``x``.  A
    least-squares fit of ``xdd = -A x - B xd (+ G f) + alpha w0 + beta w1`` per channel on the fit
    window (the linear model; it only has to place the offsets) gives ``beta = A e`` and
    ``alpha = B e + A c``, so ``e = A^-1 beta`` and ``c = A^-1 (alpha - B e)``.

    Parameters
    ----------
    data : Measurement

    Returns
    -------
    Measurement
        ``xd - e w0`` and ``x - e w1 - c w0``, ``drift_basis`` None; ``data`` itself when it
        declares no drift basis or the linear fit is singular.
    offsets : ndarray, shape (2, n) or None
        ``e`` [m/s] and ``c`` [m] per channel (None when nothing was removed).
    """
    if data.drift_basis is None or np.asarray(data.drift_basis).shape[0] != 2:
        return data, None
    lib = build_library(data, coupled_mass=False, cubic=False, drift=True)
    coef = solve_rows(lib)
    A, B = -coef[:, lib.blocks["d"]], -coef[:, lib.blocks["v"]]
    z = coef[:, lib.blocks["z"]]
    try:
        e = np.linalg.solve(A, z[:, 1])
        c = np.linalg.solve(A, z[:, 0] - B @ e)
    except np.linalg.LinAlgError:
        return data, None
    if not (np.all(np.isfinite(e)) and np.all(np.isfinite(c))):
        return data, None
    w0, w1 = (np.asarray(r, dtype=float)[None, :] for r in data.drift_basis)
    clean = replace(data, xd=data.xd - e[:, None] * w0, x=data.x - e[:, None] * w1 - c[:, None] * w0,
                    drift_basis=None)
    return clean, np.vstack([e, c])


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
    # a mass scale is one number: float([0.7]) was a TypeError inside the fit (fuzz26, round
    # 25); a Measurement refuses a list here too (prior_ok), a caller's own object may not
    val = prior_number(data.prior[key])
    if val is None:
        lo, hi = PRIOR_RANGE
        raise IdentificationError(f"prior {key!r} must be one number (a mass [kg]) from {lo:g} to "
                                  f"{hi:g}, got {data.prior[key]!r:.60}")
    return val


#: Peaks closer than this fraction of their frequency count as one mode.  A hardening base
#: spring sweeps the soft cantilever's mode 1 from 40.2 to 38.4 Hz as it decays (measured), so
#: its peak splits; distinct bending modes of a beam lie a factor of 2 or more apart.
MODE_SEPARATION = 0.15
#: Largest condition number of the mode shapes' matrix (:func:`modal`'s real parts) by which a
#: mode is placed or reshaped: past it two shapes are parallel to within rounding (a coalesced
#: or near-coalesced pair; float64's 1e-16 times 1e12 leaves 1e-4 of a shape's direction), and
#: a solve with them returns the rounding's choice.
SHAPES_COND_MAX = 1e12


#: Lower edge of the peak band, as a multiple of the chain's high-pass cut-off: the elliptic
#: high-pass (applied at every integration stage, each forward-backward) attenuates, rings and
#: leaves integrated drift up to its pass-band edge; 1.1 keeps 10 % clear of that edge (mode 1
#: of cantilever_long_aluminium, 12.8 Hz, sits at 1.28x the 10 Hz cut-off and stays in).
HIGHPASS_MARGIN = 1.1
#: Upper edge of the peak band, as a multiple of the chain's low-pass cut-off (the Butterworth
#: low-pass bends the spectrum from about 0.8 of its cut-off), or of the Nyquist frequency
#: without one (0.45 fs: the last lines of a sampled spectrum carry aliasing).
LOWPASS_MARGIN, NYQUIST_FRACTION = 0.8, 0.9
#: Lower edge of the peak band in lines of the window's transform (``fs / n_window`` [Hz]
#: each): a peak needs lines on both sides to be one, and the lowest lines of a short window
#: carry its mean and the chain's drift.  So a window of ``n`` samples has a band only where
#: ``PEAK_BAND_LINES fs / n`` lies below the band's top: the peak search, hence every structural
#: identifier that reads its modes from it, needs more than ``PEAK_BAND_LINES fs / f_top``
#: samples of free decay (12 without a declared pass band: ``f_top = 0.45 fs``).
PEAK_BAND_LINES = 5
#: A weaker peak within this relative distance of k times a stronger one (k = 2, 3) is a
#: harmonic *candidate*; a hardening mode's peak sits above its small-amplitude frequency and
#: its harmonic tracks it (measured: 139.7 / 45.4 Hz = 3.08 on the 150 N soft base).
HARMONIC_TOL = 0.08
#: Range of the log-log slope of the candidate's amplitude against the fundamental's over
#: short-time segments, as multiples of k, for a harmonic: a polynomial restoring force makes
#: the k-th harmonic scale as A^k (slope k).  Measured, 8 segments: the 150 N soft base's
#: 139.7 Hz peak 2.2 against 45.4 Hz (k = 3); independent modes near 3x spacing 0.87-0.99
#: (soft base 1210 / 391 Hz, aluminium beam 226 / 80 Hz).  A linear mode with
#: stiffness-proportional damping would give (f_c / f_p)^2 ~ k^2, above the range.
HARMONIC_SLOPE = (0.6, 1.6)
#: Smallest fall of the fundamental's frequency from the first to the last short-time segment
#: (and at least two spectral lines) for it to have harmonics: only an amplitude-dependent,
#: i.e. nonlinear, mode makes them.  Needed beside the slope: a linear mode at 3x spacing that
#: decays 9x faster (stiffness-proportional damping) falls into the spectral floor within the
#: record and showed a slope of 3.5 (synthetic, measured).  Measured drift of the 150 N soft
#: base's 45.4 Hz peak: 17.5 %; the 50 N soft base's mode 1 sweeps 40.2 -> 38.4 Hz (4.7 %).
HARMONIC_DRIFT = 0.02
#: Short-time segments of the harmonic test (each resolves 8 / T Hz: 4 Hz on a 2 s record).
HARMONIC_SEGMENTS = 8
#: Phase lock of a candidate at k x a stronger peak (within :data:`HARMONIC_TOL`) for it to be
#: that peak's harmonic (:func:`testbed.numerics.spectral.harmonic_lock`, the mean resultant
#: length of ``phi_c - k phi_p``): 2 / pi is a phase spread evenly over pi rad.  A harmonic is
#: driven by the fundamental's motion and keeps its phase; a mode rings at its own frequency.
#: Measured on the soft-base family (studies/families.toml, clean / 1 % noise): the third
#: harmonics of members 000, 001, 006, 008 0.82-0.99; member 017's 0.64 / 0.56 (then caught
#: as a side lobe, MAC 0.97, and its fundamental, 17.8 Hz, is below the ringing zone anyway).
#: A mode that decays within a few periods of its own stays locked too (member 005's mode 3
#: at 2.99 x mode 2: 0.94), hence the shape test beside it; distinct modes at 2-3x within
#: the tolerance on both families otherwise 0.13-0.63.
HARMONIC_LOCK = 2.0 / np.pi
#: ... and whose deflection shape has at least this MAC with the stronger peak's: a harmonic is
#: the structure's forced response at k f to the force the fundamental's motion makes, which
#: below the next mode is mostly the fundamental's own mode.  Measured (studies/families.toml,
#: clean and 1 % noise): the soft bases' harmonics 0.85-1.00; distinct modes at 2x or 3x
#: within the tolerance 0.01-0.35 on both families; 0.6 sits between the two groups.  The
#: rule does not need a record long enough to see the fundamental's frequency drift (a lightly
#: damped 30 Hz mode decays 2 dB in 0.5 s), which the amplitude-law test below needs.
HARMONIC_SHAPE_MAC = 0.6
#: A weaker candidate whose deflection shape (the complex spectra of the channels at its
#: frequency) has a MAC of at least this with a stronger accepted peak's is the same mode seen
#: again: a side lobe of a lightly damped mode that rings through the whole record, or
#: ringing of the chain's high-pass under it.  Measured on 2-sensor beams of the beams family
#: (studies/families.toml): side lobes 0.985-1.000 against their mode; distinct bending modes
#: 0.16-0.84 (the highest, 0.84, with both sensors on the outer half of the beam).
ODS_MAC = 0.95
#: ... but only within this many spectral lines (``fs / n`` of the unpadded window) of that peak:
#: the rectangular window's side lobes fall as ``1 / (pi k)`` at ``k`` lines, below the
#: candidates' 40 dB range beyond ``100 / pi`` = 32 lines.  Two sensors can give distinct modes
#: similar shapes (a soft-base member's modes 1 and 2, 30 and 316 Hz: MAC 0.978), and there
#: shape alone rejected a genuine mode 143 lines away.
SIDE_LOBE_LINES = 100.0 / np.pi
#: ... or below this multiple of the chain's high-pass cut-off, where the high-pass rings
#: under the displacement with its shape (the second reason for the rule).
HIGHPASS_RING_FACTOR = 2.0


#: A candidate beyond the ``n`` strongest (rule 5 of :func:`modal_peaks`) that lies below every
#: kept peak is a lower mode, not an artefact, when its deflection shape has a MAC below this
#: with every kept peak's: then it displaces the highest kept peak (the model's ``n`` modes are
#: the structure's lowest ``n``, as the truth's reduction onto the sensors; a stronger peak
#: above them is a higher mode ringing beyond the model's reach, which an unfiltered record of
#: a lightly damped beam holds: in acceleration each mode weighs ~ its frequency).  Measured
#: 2026-11-26: on ``benchmarks/unseen/round3/beam_zeta1em5.toml`` (0.001 % damping, no
#: low-pass, 3 sensors) mode 1 (82.8 Hz, 19 dB below the strongest peak) is the 4th strongest
#: of five ringing modes, MAC 0.24 / 0.24 / 0.57 with modes 2-4; every such candidate of the
#: beams families (studies/families.toml, clean and 1 % noise: high-pass ringing, its leakage
#: and noise, 12.8-73.9 Hz) has a MAC of 0.82-1.00 with some kept peak (they take the lowest
#: mode's shape, or noise's chance one on two sensors).  0.7 sits between; a genuine lower
#: mode with a shape closer than that to a kept one is missed as before.
LOWER_MODE_MAC = 0.7
#: ... and only when it rings at its own frequency: the mean resultant length of its
#: demodulated phase against ``2 pi f t`` (:func:`own_lock`) at least this (``2 / pi``: a phase
#: spread evenly over pi rad, :data:`HARMONIC_LOCK`'s bar).  Noise has a chance shape, unlike
#: any mode's: at 50 % noise (shipped soft bases) a 35.1 Hz noise peak passed the shape test
#: and displaced mode 3; its lock is 0.02-0.28 (white noise over a 0.5 s record at 60 Hz:
#: 0.10-0.46).  Measured 2026-11-26: beam_zeta1em5's mode 1 0.999 (clean and 1 %); family low
#: candidates (which the shape test already refuses) clamped 003's 24.9 Hz 0.12, 008's at 1 %
#: 0.32-0.89 (0.89: 15.0 Hz, in the high-pass's ringing zone), soft 005's 55.8 Hz at 1 % 0.04.
LOWER_MODE_LOCK = 2.0 / np.pi
#: Rule 4b in the chain's ringing zone (at or below :data:`HIGHPASS_RING_FACTOR` x the
#: high-pass cut-off): a candidate after the strongest whose largest lock within
#: :data:`MODE_SEPARATION` of it (:func:`_ringing_zone_lock`) stays below
#: :data:`LOWER_MODE_LOCK` and whose band power falls no more than noise's is noise, whatever
#: noise's own lock bar (which there, on a short window, lies above 2 / pi: the test has less
#: power, and a candidate noise locks by chance is kept, as before).  The lock is the largest
#: near the candidate because the high-pass bends a mode's peak near its cut-off away from the
#: mode's frequency: ``b22_cu_L0p65_t8_n15`` (round 22, mode 1 at 11.05 Hz) peaks at 12.58 Hz,
#: lock 0.24 there, 1.000 at 10.94 Hz.  Measured 2026-11-28 (703 ``ls_sindy`` beam cells, 56
#: with a kept ringing-zone peak): the 31 at a true mode (within 3 %) lock 0.987-1.000 there;
#: the chain's own ringing (12.2-12.7 Hz on 0.49 s windows) 0.985-1.000; the soft bases'
#: hardened mode 1 (4-8 % above its linear frequency) 0.998; noise 0.26-0.46 with a fall under
#: noise's bar (``b22_st_jo0`` 5 % s133: 12.42 Hz, 0.458 at 13.07 Hz, fall 0.71 under 3.4).
RING_ZONE_LOCK = LOWER_MODE_LOCK


@dataclass(frozen=True)
class PeakSearch:
    """The spectral peaks a structural identifier takes as measured natural frequencies.

    Attributes
    ----------
    band : (float, float)
        Search band [Hz] and the rule that set it (see :func:`modal_peaks`).
    band_rule : str
    peaks : ndarray, shape (k,)
        Accepted peak frequencies [Hz], ascending, ``k <= n_modes``.
    rejected : list of (float, str)
        Every other candidate in the band [Hz] with the reason it was not taken.
    nonlinear : bool
        A harmonic following the amplitude law was recognised: the structure's peak
        frequencies depend on amplitude (no peak is accepted).
    harmonics : list of (float, int, float)
        Candidates recognised as harmonics by their phase lock and shape: ``(f, k, f_fund)``
        [Hz, -, Hz]; rejected, the other peaks kept.
    harmonic_rule : str
        The rule that recognised them, with its tolerances, and what it found.
    count_rule : str
        Which ``n_modes`` peaks were kept (rule 5 of :func:`modal_peaks`) and what it did.
    """

    band: tuple[float, float]
    band_rule: str
    peaks: np.ndarray
    rejected: list[tuple[float, str]]
    nonlinear: bool
    harmonics: list[tuple[float, int, float]] = field(default_factory=list)
    harmonic_rule: str = ""
    count_rule: str = ""


def peak_band(data: Measurement, n_window: int, freq_range: tuple[float, float] | None = None
              ) -> tuple[tuple[float, float], str]:
    """The band [Hz] searched for natural frequencies, and the rule that set it.

    ``freq_range`` (a user's setting) wins.  Otherwise, from the chain's pass band
    ``data.passband = (hp, lp)``: ``[HIGHPASS_MARGIN hp, LOWPASS_MARGIN lp]`` (with
    ``NYQUIST_FRACTION fs / 2`` if ``lp`` is the Nyquist frequency), and never below
    :data:`PEAK_BAND_LINES` lines of the window's transform (``5 fs / n_window``).  Without a
    declared pass band: 5 lines to ``0.45 fs``.  The band may be empty (lower edge at or above
    the upper) on a short window: :func:`check_peak_band` names that.
    """
    nyq = data.fs / 2.0
    lines = PEAK_BAND_LINES * data.fs / max(int(n_window), 1)
    if freq_range is not None:
        return (float(freq_range[0]), float(freq_range[1])), "freq_range (user setting)"
    if data.passband is None:
        return (lines, NYQUIST_FRACTION * nyq), "no pass band declared: 5 lines to 0.45 fs"
    hp, lp = (float(v) for v in data.passband)
    lo = max(lines, HIGHPASS_MARGIN * hp)
    hi = NYQUIST_FRACTION * nyq if lp >= nyq else LOWPASS_MARGIN * lp
    return (lo, hi), (f"chain pass band [{hp:g}, {lp:g}] Hz: from {HIGHPASS_MARGIN:g} x the high-pass "
                      f"cut-off to {'0.45 fs' if lp >= nyq else f'{LOWPASS_MARGIN:g} x the low-pass'}")


def check_peak_band(data: Measurement, n_window: int, band: tuple[float, float], rule: str,
                    start: int) -> None:
    """Raise :class:`IdentificationError` where :func:`peak_band`'s band is empty.

    The band's lower edge is at least :data:`PEAK_BAND_LINES` lines (``5 fs / n`` [Hz]) of an
    ``n``-sample window, so the window must hold more than ``5 fs / f_top`` samples, ``f_top``
    the band's upper edge [Hz] (0.45 fs without a declared pass band, 0.8 x the chain's
    low-pass with one): the message names the window's length and that minimum.  A band the
    chain's high-pass closes (``1.1 hp >= f_top``) or a user's ``freq_range`` out of order is
    named as such (no window length opens it).

    Parameters
    ----------
    data : Measurement
    n_window : int
        Samples in the searched window.
    band : (float, float)
        :func:`peak_band`'s band [Hz] and its ``rule``.
    rule : str
    start : int
        The window's first sample (``free_start`` by default).
    """
    lo, hi = band
    if lo < hi:
        return
    lines = PEAK_BAND_LINES * data.fs / max(int(n_window), 1)
    if lines >= hi:  # the window's length closed it (whatever else may close it too)
        need = int(np.floor(PEAK_BAND_LINES * data.fs / hi)) + 1
        raise IdentificationError(
            f"the free decay from sample {start} holds {n_window} samples; the peak search that "
            f"reads the natural frequencies needs at least {need} at fs = {data.fs:g} Hz (its "
            f"band starts {PEAK_BAND_LINES} lines, {PEAK_BAND_LINES:g} fs / n Hz, above 0 Hz and "
            f"must stay below its top {hi:g} Hz, {rule}): record a longer free decay")
    raise IdentificationError(f"the peak search's band [{lo:g}, {hi:g}] Hz is empty ({rule}): "
                              f"no natural frequency can be read from this record")


def modal_peaks(data: Measurement, n_modes: int | None = None,
                freq_range: tuple[float, float] | None = None, start: int | None = None,
                stop: int | None = None, lower_modes: bool = True, ringing: bool = False
                ) -> PeakSearch:
    """Natural frequencies [Hz] from the spectral peaks of the measured accelerations, by rule.

    Rules, in order (every candidate not taken is returned with its reason):

    1. *Band*: :func:`peak_band` (the chain's pass band, or ``freq_range``).
    2. *Candidates*: peaks of the channel-summed power spectrum of ``data.xdd`` on the window
       (rectangular window: the impact response decays within the record and a Hann window
       would hide a fast-decaying mode; 8x zero padding; 6 dB prominence; within 40 dB of the
       strongest), peaks within :data:`MODE_SEPARATION` of a stronger one merged into it.
    3. *Same shape*: a weaker candidate whose deflection shape across the channels matches
       a stronger accepted one's (MAC >= :data:`ODS_MAC`) is that mode again (a side lobe),
       not a mode: n sensors tell distinct modes apart by their shapes.  Only where a side
       lobe can be: within :data:`SIDE_LOBE_LINES` lines of that peak, or below
       :data:`HIGHPASS_RING_FACTOR` x the high-pass cut-off.  Checked after the harmonic
       test, which it does not replace.
    4. *Harmonics*: a weaker candidate within :data:`HARMONIC_TOL` of k = 2 or 3 times a
       stronger one whose short-time amplitude follows the stronger one's k-th power
       (:func:`testbed.numerics.spectral.harmonic_amplitude_law`, slope within
       :data:`HARMONIC_SLOPE` x k), while the stronger one's frequency falls as it decays
       (:data:`HARMONIC_DRIFT`: the fundamental is nonlinear), is a harmonic, not a mode.
       If one is found the structure is amplitude-dependent and its record-long peaks are
       not its linear natural frequencies (the 150 N soft base: 45.4 and 406.5 Hz against
       39.6 and 386.6 Hz), so no peak is accepted (``nonlinear`` = True).
       Otherwise a weaker candidate within :data:`HARMONIC_TOL` of k = 2 or 3 times a
       stronger accepted one that is phase-locked to it
       (:func:`testbed.numerics.spectral.harmonic_lock` >= :data:`HARMONIC_LOCK`) and moves
       in its deflection shape (MAC >= :data:`HARMONIC_SHAPE_MAC`) is its harmonic: rejected
       and listed in ``harmonics``, the other peaks kept.  This needs no drift of the
       fundamental, which a short record of a lightly damped mode does not show.  A
       candidate with a harmonic's shape within side-lobe reach of it is its side lobe.
       Fundamentals below :data:`HIGHPASS_RING_FACTOR` x the high-pass cut-off are not
       tried: there the chain's filter rings, a linear response that makes no harmonics,
       dies within a few periods (so anything looks locked to it over its short life) and
       has the displacement's shape.
    4b. *Decaying* (``ringing``, ``ls_sindy``'s): an accepted candidate after the strongest,
       above :data:`HIGHPASS_RING_FACTOR` x the high-pass cut-off, that neither rings at its
       own frequency (:func:`own_lock`) nor loses more power from the window's first half to
       its second (:func:`testbed.numerics.spectral.band_power_fall`) than noise would (3
       standard deviations each) is a bump of noise, not a mode: rejected.  At or below
       that (the chain's ringing zone) the lock is the largest within
       :data:`MODE_SEPARATION` of the candidate and its bar :data:`RING_ZONE_LOCK`.
    5. *Sensors*: at most ``n_modes`` (default the number of channels: n sensors resolve at
       most n mode shapes), the strongest; with ``lower_modes`` (default) a candidate beyond
       them that lies below every kept peak and whose shape differs from each kept one's
       (MAC < :data:`LOWER_MODE_MAC`), above the high-pass's ringing zone, ringing at its own
       frequency (:func:`own_lock` >= :data:`LOWER_MODE_LOCK`: not noise), displaces the
       highest kept peak (strongest such candidate first, until none is left): the model's
       modes are the structure's lowest, and a higher mode may ring stronger in acceleration
       (``count_rule``).

    Parameters
    ----------
    data : Measurement
    n_modes : int, optional
        Most peaks taken; default ``data.n_channels``.
    freq_range : (float, float), optional
        Band [Hz] overriding rule 1.
    start, stop : int, optional
        Window ``[start, stop)``; default ``data.free_start`` to the end.
    lower_modes : bool
        Rule 5's lower-mode test (True, default); False keeps the ``n_modes`` strongest.
    ringing : bool
        Rule 4b (False, default: the other structural identifiers' search as it was).

    Returns
    -------
    PeakSearch

    Raises
    ------
    IdentificationError
        Where the window is too short for rule 1's band (:func:`check_peak_band`: more than
        ``5 fs / f_top`` samples are needed), naming its length and the minimum.
    """
    s = data.free_start if start is None else int(start)
    xdd = np.asarray(data.xdd, dtype=float)[:, s:stop]
    n_modes = data.n_channels if n_modes is None else int(n_modes)
    band, rule = peak_band(data, xdd.shape[1], freq_range)
    check_peak_band(data, xdd.shape[1], band, rule, s)
    freqs, _ = peak_candidates(xdd, data.fs, band[0], band[1], window="boxcar", pad=8,
                                 min_rel_separation=MODE_SEPARATION)
    rejected: list[tuple[float, str]] = []
    kept: list[int] = []
    harmonics: list[tuple[float, int, float]] = []
    lobed: list[int] = []  # stronger peaks whose side lobes are not modes: kept ones and harmonics
    nonlinear = False
    shapes = deflection_shapes(xdd, data.fs, freqs, pad=8)
    lobe_reach = SIDE_LOBE_LINES * data.fs / xdd.shape[1]
    ring_top = HIGHPASS_RING_FACTOR * float(data.passband[0]) if data.passband else 0.0
    for i in range(freqs.size):  # strongest first
        why = None
        for j in kept:
            for k in (2, 3):
                if abs(freqs[i] / (k * freqs[j]) - 1.0) <= HARMONIC_TOL:
                    slope, drift, line = harmonic_amplitude_law(xdd, data.fs, freqs[j], k,
                                                                HARMONIC_SEGMENTS)
                    if (HARMONIC_SLOPE[0] * k <= slope <= HARMONIC_SLOPE[1] * k
                            and drift > max(HARMONIC_DRIFT, 2.0 * line)):
                        why = (f"harmonic {k} of {freqs[j]:.4g} Hz (amplitude ~ A^{slope:.2f} of it; "
                               f"a harmonic of a polynomial force scales as A^{k}; the fundamental "
                               f"drifts {drift:.1%} as it decays)")
        if why is not None:
            rejected.append((float(freqs[i]), why))
            nonlinear = True
            continue
        locked = _locked_harmonic(xdd, data.fs, freqs, shapes, i,
                                  [j for j in kept if freqs[j] > ring_top])
        if locked is not None:
            k, j, lock, m = locked
            harmonics.append((float(freqs[i]), k, float(freqs[j])))
            lobed.append(i)
            rejected.append((float(freqs[i]), f"harmonic {k} of {freqs[j]:.4g} Hz (phase-locked to it: "
                                              f"{lock:.3f}; its shape: MAC {m:.3f}), not a mode"))
            continue
        macs = [(float(mac_matrix(shapes[i], shapes[j])[0, 0]), j) for j in lobed
                if abs(freqs[i] - freqs[j]) <= lobe_reach or freqs[i] <= ring_top]
        same = [(m, j) for m, j in macs if m >= ODS_MAC]
        if same:
            m, j = same[0]
            what = "that mode" if j in kept else "that harmonic"
            rejected.append((float(freqs[i]), f"same deflection shape as the {freqs[j]:.4g} Hz peak "
                                              f"(MAC {m:.3f}): a side lobe of {what}, not another mode"))
        else:
            kept.append(i)
            lobed.append(i)
    if ringing:
        kept = _decaying_only(data, s, freqs, shapes, kept, rejected, ring_top)
    if nonlinear:
        for i in kept:
            rejected.append((float(freqs[i]), "amplitude-dependent structure (a harmonic was found): "
                                              "a record-long peak is not a linear natural frequency"))
        kept = []
    kept, count_rule = _lower_modes_first(xdd, data.fs, freqs, shapes, kept, n_modes, ring_top,
                                          lower_modes)
    for i in kept[n_modes:]:
        rejected.append((float(freqs[i]), f"beyond the {n_modes} kept (n sensors resolve at most "
                                          f"n modes)"))
    kept = kept[:n_modes]
    found = "; ".join(f"{f:.4g} Hz = {k} x {f0:.4g} Hz" for f, k, f0 in harmonics) or "none found"
    return PeakSearch(band, rule, np.sort(freqs[kept]), rejected, nonlinear, harmonics,
                      f"{HARMONIC_RULE}: {found}", count_rule)


def _decaying_only(data: Measurement, s: int, freqs: np.ndarray, shapes: np.ndarray,
                   kept: list[int], rejected: list[tuple[float, str]], ring_top: float
                   ) -> list[int]:
    """Rule 4b of :func:`modal_peaks`: the accepted candidates ``kept`` (indices into ``freqs``
    [Hz], strongest first) without those, after the strongest (at or below ``ring_top`` [Hz]
    with the zone's lock, below), that neither ring at their own frequency (:func:`own_lock`
    below :data:`LOWER_MODE_LOCK` and below 3 x noise's lock,
    :func:`testbed.numerics.spectral.noise_lock_bar`) nor lose band power over the free window
    from sample ``s`` of ``data.xdd`` more than white noise would
    (:func:`testbed.numerics.spectral.band_power_fall`), shapes ``shapes`` of
    :func:`deflection_shapes`: a mode rings through the window (a lightly damped one, whose
    power barely falls over a short record: family clamped 005 clean, mode 1 52.2 Hz, fall 2.35
    under noise's 2.54, lock 0.99) or decays within it (a heavily damped one, whose lock the
    window's dropped ends hide: soft 014 clean, mode 2 208.7 Hz, lock 0.148, fall 98); a bump
    of noise on a stronger mode's leakage does neither.  Round 22's magnesium at 1.8 kHz, 5 %
    noise, seed 139 took a 171.1 Hz bump (-36 dB, 6 dB prominent; lock 0.141 under 0.289, power
    ratio 1.14 under 1.57) as mode 2 (508.7 Hz, 6.25 % damped): 66 % off.  At or below
    ``ring_top`` the chain's high-pass rings (locked, as a mode does) and bends a mode's peak
    near its cut-off: there the lock is the largest within :data:`MODE_SEPARATION` of the
    candidate (:func:`_ringing_zone_lock`) and its bar :data:`RING_ZONE_LOCK` (or noise's,
    where lower).  Each rejected one is appended to
    ``rejected``."""
    x = np.asarray(data.xdd, dtype=float)
    out = list(kept[:1])
    for i in kept[1:]:
        ratio, bar = band_power_fall(x, data.fs, float(freqs[i]), shapes[i], s)
        if np.isfinite(ratio) and np.isfinite(bar) and ratio >= bar:  # decays: kept, whatever
            out.append(i)                                               # its lock (no lock run)
            continue
        zone = freqs[i] <= ring_top
        if zone:  # the chain's ringing zone: the lock where it rings nearest (RING_ZONE_LOCK)
            lock, at = _ringing_zone_lock(x[:, s:], data.fs, float(freqs[i]))
        else:
            lock, at = own_lock(x[:, s:], data.fs, float(freqs[i]), shapes[i]), float(freqs[i])
        noise_bar = noise_lock_bar(float(freqs[i]), data.fs, x.shape[1] - s)
        # (capped by noise's own bar in the zone too: on a long window noise's bar falls
        # below 2 / pi, and a mode locked above it is no noise; review 24c)
        lock_bar = min(RING_ZONE_LOCK if zone else LOWER_MODE_LOCK, noise_bar)
        # a test that cannot decide keeps the candidate (review 23f): a window too short for
        # the frequency (lock or fall not finite), or, above the ringing zone, one where noise
        # alone may lock above LOWER_MODE_LOCK (3 x noise's lock capped: the lock test has no
        # power there); a clean 1 %-damped 30 Hz mode on a 0.2 s record had been rejected as
        # noise with lock NaN
        untestable = (not (np.isfinite(lock) and np.isfinite(ratio) and np.isfinite(bar))
                      or (noise_bar > LOWER_MODE_LOCK and not zone))
        if untestable or lock >= lock_bar:  # (a finite fall at its bar kept the candidate above)
            out.append(i)
        else:
            where = f" at {at:.4g} Hz, the most within {MODE_SEPARATION:.0%}" if zone else ""
            rejected.append((float(freqs[i]), f"neither rings at its own frequency (lock {lock:.3f}"
                                              f"{where} < {lock_bar:.3f}) nor decays (its band's "
                                              f"power, first half of the window / second, "
                                              f"{ratio:.3g} < {bar:.3g}; each 3 x noise's spread): "
                                              f"noise, not a mode"))
    return out


def _ringing_zone_lock(x: np.ndarray, fs: float, f: float) -> tuple[float, float]:
    """The largest :func:`own_lock` of the window ``x`` (shape (n_channels, N), sampled at
    ``fs`` [Hz]) over frequencies within :data:`MODE_SEPARATION` of the candidate ``f`` [Hz]
    (a grid of ``1 / (4 T)`` Hz steps, ``T`` the window [s]: a mode ringing between two steps
    keeps ``sinc(1/8)`` = 0.97 of its lock), each with its own deflection shape; returns
    ``(lock, frequency [Hz])``.  :data:`RING_ZONE_LOCK` says why.  The window is not reached
    down to the high-pass cut-off (review 24c asked, for a mode bent more than 15 %): there the
    chain's own ringing locks near 1, and round 22's ``b22_st_jo0`` at 5 % kept its 12.42 Hz
    noise candidate again (mode 3 98.7 % off)."""
    step = fs / (4.0 * x.shape[1])
    grid = np.arange(f / (1.0 + MODE_SEPARATION), f * (1.0 + MODE_SEPARATION), step)
    shapes = deflection_shapes(x, fs, grid, pad=8)
    locks = np.array([own_lock(x, fs, float(g), shapes[k]) for k, g in enumerate(grid)])
    if not np.any(np.isfinite(locks)):
        return float("nan"), f
    k = int(np.nanargmax(locks))
    return float(locks[k]), float(grid[k])


def _lower_modes_first(xdd: np.ndarray, fs: float, freqs: np.ndarray, shapes: np.ndarray,
                       kept: list[int], n_modes: int, ring_top: float, on: bool
                       ) -> tuple[list[int], str]:
    """Rule 5 of :func:`modal_peaks`: the accepted candidates ``kept`` (indices into ``freqs``
    [Hz], strongest first) reordered so that the first ``n_modes`` are the ones kept, and the
    rule's statement.  A candidate beyond the first ``n_modes`` (strongest first) that lies
    below each of them and above ``ring_top`` [Hz], with a deflection shape (``shapes``,
    :func:`deflection_shapes`) of MAC < :data:`LOWER_MODE_MAC` with each, and ringing at its
    own frequency in the window ``xdd`` sampled at ``fs`` [Hz] (:func:`own_lock` >=
    :data:`LOWER_MODE_LOCK`), takes the place of the highest of them; repeated until no
    candidate qualifies."""
    strongest = f"the {n_modes} strongest accepted peaks"
    if not on:
        return kept, f"{strongest} (lower_modes = False: user setting)"
    head, tail = list(kept[:n_modes]), list(kept[n_modes:])
    locks: dict[int, float] = {}  # a candidate's lock does not change as the kept set does
    moved: list[tuple[float, float]] = []
    changed = True
    while changed and head:
        changed = False
        for c in tail:
            if not ring_top < freqs[c] < min(freqs[j] for j in head):
                continue
            if max(float(mac_matrix(shapes[c], shapes[j])[0, 0]) for j in head) >= LOWER_MODE_MAC:
                continue
            if c not in locks:
                locks[c] = own_lock(xdd, fs, float(freqs[c]), shapes[c])
            if not locks[c] >= LOWER_MODE_LOCK:
                continue
            top = max(head, key=lambda j: freqs[j])
            head[head.index(top)] = c
            tail[tail.index(c)] = top
            moved.append((float(freqs[c]), float(freqs[top])))
            changed = True
            break
    did = ("; ".join(f"{a:.4g} Hz kept instead of {b:.4g} Hz" for a, b in moved)
           or "none displaced")
    return head + tail, (f"{strongest}, except that one beyond them below each kept peak, above "
                         f"{HIGHPASS_RING_FACTOR:g} x the high-pass cut-off, with a shape of MAC < "
                         f"{LOWER_MODE_MAC:g} against each and ringing at its own frequency (lock >= "
                         f"2/pi), displaces the highest (a lower mode: a higher one rings stronger "
                         f"in acceleration): {did}")


#: The phase-lock harmonic rule as stored with a fitted model (``harmonic_rule_``).
HARMONIC_RULE = (f"a weaker peak within {HARMONIC_TOL:g} of k = 2 or 3 x a stronger accepted one, "
                 f"phase-locked to it (mean resultant length of phi_c - k phi_p >= 2/pi) and moving "
                 f"in its shape (MAC >= {HARMONIC_SHAPE_MAC:g}), is its harmonic, not a mode "
                 f"(fundamentals above {HIGHPASS_RING_FACTOR:g} x the chain's high-pass cut-off)")


def _locked_harmonic(xdd: np.ndarray, fs: float, freqs: np.ndarray, shapes: np.ndarray, i: int,
                     kept: list[int]) -> tuple[int, int, float, float] | None:
    """The first accepted peak ``j`` (strongest first) whose ``k``-th harmonic candidate ``i`` is
    by the phase-lock rule (:data:`HARMONIC_LOCK`, :data:`HARMONIC_SHAPE_MAC`), as
    ``(k, j, lock, MAC)``; None if it is none's."""
    for j in kept:
        for k in (2, 3):
            if abs(freqs[i] / (k * freqs[j]) - 1.0) > HARMONIC_TOL:
                continue
            m = float(mac_matrix(shapes[i], shapes[j])[0, 0])
            if m < HARMONIC_SHAPE_MAC:
                continue
            lock = harmonic_lock(xdd, fs, float(freqs[j]), float(freqs[i]), k, shapes[j], shapes[i])
            if lock >= HARMONIC_LOCK:
                return k, j, lock, m
    return None


def harmonics_array(ps: PeakSearch) -> np.ndarray:
    """``ps.harmonics`` as an array, shape (h, 3): rows ``(f [Hz], k, f_fundamental [Hz])``."""
    return np.asarray(ps.harmonics, dtype=float).reshape(-1, 3)


def deflection_shapes(x: np.ndarray, fs: float, freqs: np.ndarray, pad: int = 8) -> np.ndarray:
    """Operating deflection shapes: each channel's complex spectrum at each frequency.

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        Signals (mean removed here; rectangular window, as the peak search).
    fs : float
        Sample rate [Hz].
    freqs : ndarray, shape (k,)
        Frequencies [Hz]; each takes the nearest line of the ``pad``-times zero-padded transform.
    pad : int

    Returns
    -------
    ndarray, shape (k, n_channels), complex
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    nfft = sfft.next_fast_len(int(pad) * x.shape[1], real=True)
    spec = sfft.rfft(x - x.mean(axis=1, keepdims=True), n=nfft, axis=1)
    lines = np.clip(np.rint(np.asarray(freqs, dtype=float) * nfft / fs).astype(int), 0, spec.shape[1] - 1)
    return spec[:, lines].T


def measured_frequencies(data: Measurement, n_modes: int, freq_range: tuple[float, float] | None = None,
                         start: int | None = None) -> np.ndarray:
    """Accepted peak frequencies [Hz] of :func:`modal_peaks` (ascending; may be empty)."""
    return modal_peaks(data, n_modes, freq_range, start).peaks


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


def warp_frequency(f_hz: np.ndarray, fs: float) -> np.ndarray:
    """Where a mode at ``f_hz`` appears to a fit on trapezoid-rule integrals.

    Parameters
    ----------
    f_hz : ndarray
        Frequencies [Hz] below the Nyquist frequency.
    fs : float
        Sample rate [Hz].

    Returns
    -------
    ndarray
        ``(fs / pi) tan(pi f / fs)`` [Hz]: the bilinear map of an undamped mode (see
        :func:`unwarp_trapezoid`), e.g. +0.77 % at 617 Hz for fs = 12.8 kHz.
    """
    f = np.asarray(f_hz, dtype=float)
    return fs / np.pi * np.tan(np.pi * f / fs)


#: Relative distance [-] from the real axis within which a pole ``q = p / (2 fs)`` with
#: ``|Re q| >= 1`` lies on the trapezoid map's cut (:func:`on_trapezoid_cut`).  A critically
#: damped mode is a double real pole, which round-off returns either as two real poles or as
#: a complex pair split off the axis by about ``sqrt(eps ||A|| / |p|)`` relative: 1.2e-8 on
#: the constructed 2-DOF model of ``tests/identify/test_trapezoid_unwarp.py``, 1.8e-7 on round
#: 16's ``b16_ti_n32_s5`` (its mode placed critically damped at q = -1.11, session 18); 1e-4
#: holds ``||A|| / |p|`` up to 4e7.  The image of a pole that near the cut would be a mode
#: within about 1e-4 / (|Re q| - 1) of the Nyquist frequency, which no record resolves.
TRAPEZOID_CUT_TOL = 1e-4


def on_trapezoid_cut(q: np.ndarray) -> np.ndarray:
    """Which poles lie on the cut of the trapezoid map (:func:`unwarp_trapezoid`).

    Parameters
    ----------
    q : ndarray, shape (m,)
        Poles divided by twice the sample rate, ``p / (2 fs)`` [-].

    Returns
    -------
    ndarray of bool, shape (m,)
        ``|Re q| >= 1`` and ``|Im q| <= TRAPEZOID_CUT_TOL |q|``: a real pole at ``|p| >= 2
        fs``, which no continuous pole maps to (``|tanh| < 1`` on the real axis), or one that
        round-off moved off the axis (:data:`TRAPEZOID_CUT_TOL`).
    """
    q = np.asarray(q, dtype=complex)
    return (np.abs(q.real) >= 1.0) & (np.abs(q.imag) <= TRAPEZOID_CUT_TOL * np.abs(q))


def _map_keeping_cut(A: np.ndarray, p: np.ndarray, V: np.ndarray, fs: float) -> np.ndarray | None:
    """:func:`unwarp_trapezoid`'s map with ``keep_cut``: from the companion matrix ``A``
    (shape (2n, 2n), [1/s]) with eigenvalues ``p`` and eigenvectors ``V`` (``linalg.eig``), the
    one whose poles off the cut are ``2 fs artanh(p / (2 fs))`` with their shapes kept and
    whose invariant subspace of the poles on the cut (:func:`on_trapezoid_cut`) is ``A``'s,
    restriction and all; None where the two sets of shapes do not span the state space.

    The poles on the cut are not diagonalised: a double real pole (a critically damped mode)
    is a defective eigenproblem whose eigenvectors round-off returns parallel or not (10 of
    753 constructed models gave a singular eigenvector matrix).  Their subspace comes from the
    ordered Schur form instead, ``[X; X T]`` as every invariant subspace of a companion matrix
    is, and the mapped modes' eigenvectors ``[psi; p psi]`` become ``[psi; s psi]``.
    Velocities are counted in units of ``2 fs`` (the test of the spanning is then not one of
    the state's units)."""
    n = A.shape[0] // 2
    cut = on_trapezoid_cut(p / (2.0 * fs))
    unit = 2.0 * fs
    T, Z, k = linalg.schur(A.astype(complex), output="complex",
                           sort=lambda z: bool(on_trapezoid_cut(np.array([z / unit]))[0]))
    if k != np.count_nonzero(cut):  # the two eigensolvers disagree on the cut: no map
        return None
    s = unit * np.arctanh(p[~cut] / unit)
    psi, X = V[:n, ~cut], Z[:n, :k]
    W = np.block([[psi, X], [psi * (s / unit), X @ T[:k, :k] / unit]])
    if np.linalg.cond(W) > 1e12:  # the shapes do not span the state space
        return None
    B = np.zeros((2 * n, 2 * n), dtype=complex)
    B[: s.size, : s.size] = np.diag(s / unit)
    B[s.size:, s.size:] = T[:k, :k] / unit
    A_s = unit * (W @ B @ np.linalg.inv(W))  # in [x; x' / unit] coordinates, then back
    A_s[n:, :n] *= unit
    A_s[:n, n:] /= unit
    return A_s


def unwarp_trapezoid(M: np.ndarray, C: np.ndarray, K: np.ndarray, fs: float,
                     keep_cut: bool = False) -> tuple[np.ndarray, np.ndarray] | None:
    """Damping and stiffness whose poles are those of a model fitted to trapezoid integrals, mapped back.

    Parameters
    ----------
    M, C, K : ndarray, shape (n, n)
        Mass [kg], damping [N s/m] and stiffness [N/m] identified by regressing ``xdd`` on
        trapezoid-rule integrals ``xd`` and ``x`` of it (``Measurement.integration ==
        "trapezoid"``).
    fs : float
        Sample rate [Hz].
    keep_cut : bool
        False: None when a pole lies on or beyond the map's range (a real pole at ``|p| >= 2
        fs``).  True: such poles, and those round-off moved off the real axis
        (:func:`on_trapezoid_cut`), are kept as fitted and every other pole is mapped back,
        so that whether the resolved modes are mapped does not depend on how round-off
        returns a double real pole (the structural identifiers' rule).

    Returns
    -------
    (C, K) : tuple of ndarray, shape (n, n), or None
        ``M`` is kept.  The second-order model whose 2n poles are ``2 fs artanh(p / (2 fs))``
        for the identified poles ``p`` (``p`` itself for a pole on the cut kept by
        ``keep_cut``) and whose mode shapes are the identified ones.  Symmetric
        when the given ``C`` and ``K`` are (the part of a non-proportional damping that
        would break the symmetry, second order in the correction, is dropped).  None when a
        pole lies on or beyond the map's range and ``keep_cut`` is False (a real pole at
        ``|p| >= 2 fs``: such a model has no continuous counterpart) or the modes do not span
        the state space.

    Notes
    -----
    The trapezoid rule turns a sampled ``z^k`` into ``z^k / s_T(z)`` with
    ``s_T(z) = 2 fs (z - 1) / (z + 1)``.  A free decay is a sum of sampled exponentials
    ``z = exp(s / fs)`` of the true poles ``s``, so a model fitted to acceleration and its
    trapezoid integrals satisfies its equation exactly at ``p = s_T(exp(s / fs)) = 2 fs
    tanh(s / (2 fs))``: every pole is warped, an undamped mode by ``tan(w T / 2) / (w T / 2)``
    (0.77 % at 617 Hz for fs = 12.8 kHz, 4.8 % at 1.5 kHz; measured 1.3-4.5 % on mode 2 of the
    short stiff beams of studies/families.toml).  The paper integrates this way and reports
    the warped values; we map back, exactly for any damping, which a correction filter on the
    signals cannot do (it acts on the unit circle only, and a damped mode's poles lie inside
    it).  The eigenvectors of the first-order form ``[psi; p psi]`` keep their shapes
    ``psi``, and ``A = V diag(s) V^-1`` with ``V = [Psi; Psi diag(s)]`` has the companion form
    ``[[0, I], [-M^-1 K, -M^-1 C]]``.
    """
    return _unwarp(M, C, K, fs, keep_cut)[0]


def _unwarp(M: np.ndarray, C: np.ndarray, K: np.ndarray, fs: float, keep_cut: bool
            ) -> tuple[tuple[np.ndarray, np.ndarray] | None, int]:
    """:func:`unwarp_trapezoid`'s result and the number of poles on the map's cut
    (:func:`on_trapezoid_cut`; 0 where the model has no finite state matrix), from one
    eigensolve."""
    n = M.shape[0]
    try:
        A = state_matrix(M, C, K)
    except np.linalg.LinAlgError:
        return None, 0
    if not np.all(np.isfinite(A)):
        return None, 0
    p, V = linalg.eig(A)
    q = p / (2.0 * fs)
    n_cut = int(np.count_nonzero(on_trapezoid_cut(q)))
    if keep_cut and n_cut:
        A_s = _map_keeping_cut(A, p, V, fs)
        if A_s is None:
            return None, n_cut
    else:  # no pole on the cut (keep_cut then maps as before, to the bit)
        if np.any((np.abs(q.imag) < 1e-12 * (1.0 + np.abs(q))) & (np.abs(q.real) >= 1.0)):
            return None, n_cut
        s = 2.0 * fs * np.arctanh(q.astype(complex))
        psi = V[:n]
        W = np.vstack([psi, psi * s])
        if np.linalg.cond(W) > 1e12:  # defective: the shapes do not span the state space
            return None, n_cut
        A_s = (W * s) @ np.linalg.inv(W)
        if np.abs(A_s.imag).max() > 1e-8 * np.abs(A_s).max():  # poles not in conjugate pairs
            return None, n_cut
    A_s = A_s.real
    C_new, K_new = -M @ A_s[n:, n:], -M @ A_s[n:, :n]
    if np.allclose(C, C.T, rtol=1e-12, atol=0.0) and np.allclose(K, K.T, rtol=1e-12, atol=0.0):
        C_new, K_new = _sym(C_new), _sym(K_new)
    return (C_new, K_new), n_cut


# --------------------------------------------------------------------------------------------
# Common identifier behaviour
# --------------------------------------------------------------------------------------------
def unwarp_rule(M: np.ndarray, C: np.ndarray, K: np.ndarray, fs: float
                ) -> tuple[tuple[np.ndarray, np.ndarray] | None, str]:
    """The structural identifiers' rule for a model fitted to trapezoid integrals, and its text.

    :func:`unwarp_trapezoid` with ``keep_cut=True``: every pole off the map's cut is mapped
    back, poles on it (:func:`on_trapezoid_cut`) are kept as fitted, so whether the resolved
    modes are mapped does not depend on how round-off returns a double real pole.

    Parameters
    ----------
    M, C, K : ndarray, shape (n, n)
        Mass [kg], damping [N s/m] and stiffness [N/m] fitted to trapezoid integrals.
    fs : float
        Sample rate [Hz].

    Returns
    -------
    mapped : (C, K) or None
        The mapped damping and stiffness; None where the model has no state matrix or its modes
        do not span the state space (poles left warped).
    rule : str
        What was done, for ``integration_rule_``.
    """
    out, n_cut = _unwarp(M, C, K, fs, keep_cut=True)  # one eigensolve: the count is the map's
    if out is None:
        return None, ("trapezoid integrals, poles left warped: no state matrix, or modes that "
                      "do not span the state space")
    rule = "trapezoid integrals: poles mapped back by s = 2 fs artanh(p / (2 fs))"
    if n_cut:
        rule += (f"; {n_cut} pole(s) on the map's cut (real, |p| >= 2 fs, or within "
                 f"{TRAPEZOID_CUT_TOL:g} of it by round-off) kept as fitted")
    return out, rule


def _fmt(v: float, precision: int) -> str:
    return f"{v:+.{precision}g}"


class StructuralIdentifier(Identifier):
    """Common part of the structural identifiers: modal results, simulation, equations text.

    Subclasses set in ``fit``: ``M_``, ``C_``, ``K_``, ``K3_``, ``coef_``, ``feature_names_``,
    ``channels_``, ``input_map_`` and call :meth:`_finish_fit`.
    """

    kind = "structural"
    prior_keys = MASS_PRIORS

    def _finish_fit(self, data: Measurement | None = None) -> None:
        """Map the poles back from trapezoid integrals (:func:`unwarp_trapezoid`) when ``data``
        says the chain integrated that way, and set ``natural_frequencies_``, ``modes_`` and
        ``integration_rule_``."""
        self.integration_rule_ = "signals are exact derivatives: no mapping"
        if data is not None and data.integration == "trapezoid":
            mapped, self.integration_rule_ = unwarp_rule(self.M_, self.C_, self.K_, float(data.fs))
            if mapped is not None:
                self.C_, self.K_ = mapped
        self.natural_frequencies_, self.modes_ = modal(self.M_, self.K_)

    def _check_fitted(self) -> None:
        if not hasattr(self, "M_"):
            raise RuntimeError(f"{type(self).__name__} is not fitted; call fit(data) first")

    def _set_stiffness(self, K: np.ndarray, m: np.ndarray, d_block: slice) -> None:
        """Replace ``K_`` by ``K`` [N/m], shape (n, n), and ``coef_``'s displacement block
        ``d_block`` with it (``m`` [kg], shape (n, 1): the diagonal masses ``coef_`` divides
        by); the rules that move a fitted stiffness (``ls_sindy``'s, ``sgd_sindy``'s) share it."""
        self.coef_[:, d_block] -= (K - self.K_) / m
        self.K_ = K

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
