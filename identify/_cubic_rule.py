"""The structural identifiers' cubic rule: whether a model gets the cubic features ``x_j^3``.

Why the partial correlation moved with the sample rate
-----------------------------------------------------
The rule's first statistic, the largest partial correlation of an ``x_j^3`` column with a row's
linear-model residual, weighs every sample by its squared residual; on the soft base 98 % of that
weight lies in the first millisecond of the fit window, where what the linear model misses is
the heavily damped upper modes' and the low-pass's transient (1-10 kHz).  The window starts where
the chain's low-pass has settled (``free_start``), later at a low rate (its digital Butterworth
rings longer near Nyquist): round 7's b_soft_fs6400, a 12.8 kHz copy and b_soft_fs20000 (the
same rig, ``lowpass_hz`` 2036 Hz) start at 7.66 / 6.88 / 6.70 ms and the flat correlation was
0.303 / 0.705 / 0.798 (out / in / in); from a common 7.7 ms it is 0.303 / 0.383 / 0.420, so the
decision was made on one millisecond.  Tilted (the fits' own rows, differenced once) it is 0.833
/ 0.967 / 0.978.

The physical evidence, fitted in physical time
----------------------------------------------
A cubic restoring force makes a free decay's frequency move with its amplitude: a hardening
spring rings faster while the amplitude is large and tends to its linear frequency as it decays
(the first-order backbone ``w(A) = w_0 (1 + 3/8 k3 A^2 / k1)``).
:func:`identify._modal_damping.modal_decay` with ``backbone`` fits each mode's instantaneous
frequency ``wd + c exp(-2 sigma t)`` to the whole decay by variable projection, so the relative
chirp ``c / wd`` (:func:`lowest_mode_chirp`) does not depend on the sample rate: 0.0478 /
0.0480 / 0.0481 on the three records.  Alone, as the rule (measured 2026-11-27 on the 20 soft
family beams, clean and 1 %, both identifiers), it would put the cubic in on 15 more soft
members at 1 % noise, where it gained 6 cells on the issue's bars and lost 5 (ls_sindy 010,
011, 018; sgd_sindy 004: a diagonal cubic fitted on a noisy record moves mode 2, known gap
"Mode 2 stiffened by mode 1's amplitude"), so it is a witness here, not the rule.

The rule
--------
Cubic terms go in when (1) the flat partial correlation exceeds :data:`CUBIC_SELECT_CORR`
(unchanged), or (2) a cubic is seen by two statistics that do not weigh the record's first
millisecond alike: the tilted partial correlation exceeds :data:`CUBIC_SELECT_CORR` and the
lowest measured mode hardens with amplitude, its backbone chirp above :data:`CUBIC_CHIRP_MIN`.
(2) is what decides b_soft_fs6400 (0.303 flat, 0.833 tilted, chirp +0.048): in at 6.4, 12.8 and
20 kHz.  On a clamped (linear) beam (2) never fires: its mode 1 does not harden (chirps
+0.6 % at most on the 40 clamped family beams, clean and 1 %; +1e-4 or less on round 7's), so a
tilted correlation raised by unmodelled dynamics (clamped member 009: 0.654) does not let a
cubic in.

(3) Where the lowest mode's backbone decay fit is not taken (strong hardening: round 10's soft
base k1 = 3000, k3 = 5e10 under 50 N, or the shipped soft base under a 2 ms contact), the tilted
correlation above :data:`CUBIC_SELECT_CORR` takes as its second witness the peak search's own
amplitude law (:func:`identify.structural.modal_peaks`, rule 4: a harmonic whose short-time
amplitude follows the k-th power of a stronger peak whose frequency falls as it decays, so no
peak is accepted, ``PeakSearch.nonlinear``).  That is the hardening the chirp measures, seen
through a harmonic instead of a decay fit; it asks nothing of the record's first millisecond.
It is tried only when (2) has no chirp and no peak was accepted (``peaks`` empty), so it never
changes a decision (2) could make.

(4) Where (1)-(3) leave the cubic out and no backbone chirp says the lowest mode does not
harden, a third harmonic of the lowest accepted peak that the peak search recognised
(:func:`identify.structural.modal_peaks`, rule 4: a weaker peak within 8 % of 3 x it,
phase-locked to it and moving in its shape) puts it in: a symmetric restoring force (the base's
``k3 q^3``) makes odd harmonics of the motion, a linear chain none.  Measured 2026-11-27
(round 11, ``b11_soft_z0p1``: the shipped soft base at 0.1 % damping, 2 s): at 2 and 5 %
noise the flat correlation is 0.21, the tilted 0.44, mode 1 rings the whole record so its
decay hardly chirps, and both identifiers held mode 1 at the hardened peak, 3.1 % high; the
harmonic at 122.8 Hz = 3 x 40.77 Hz was recognised and left unused.
"""

from __future__ import annotations

import numpy as np

from identify._modal_damping import modal_decay
from identify._sgd_matrix import fit_window
from identify.structural import (
    Library,
    PeakSearch,
    build_library,
    fit_band,
    matrices_from_coef,
    modal,
    modal_peaks,
    solve_rows,
    tilt_library,
)
from testbed.core.measurement import Measurement

#: A cubic column ``x_j^3`` enters a least-squares model chosen by rule when its partial
#: correlation with some row's residual, every other column of that row profiled out, exceeds
#: this.  A correlation is scale-free, so the choice does not depend on the beam's stiffness or
#: the response's amplitude.  Measured on the clean family beams (studies/families.toml): the
#: clamped (linear) beams 0.006-0.52, where what the linear model misses is unmodelled
#: dynamics (heavily damped upper modes, integration remnants), not a cubic force; the soft
#: bases 0.77-0.97 except two nearly linear members (0.12, 0.18).  0.65 sits between the two
#: groups; SGD-SINDy's per-term lasso threshold (0.2) answers a different question (which
#: terms, once cubic terms are in).
CUBIC_SELECT_CORR = 0.65

#: The rule's second witness (module docstring, rule (2)): the lowest mode's measured backbone
#: chirp ``c / wd`` (:func:`lowest_mode_chirp`) above this [-].  Measured on the beams of
#: studies/families.toml (2026-11-27): the 40 clamped (linear) beams' mode 1 at most +0.58 %
#: clean (member 019; 032, two sensors, -2.6 %) and +0.13 % at 1 % noise; the 20 soft bases
#: (cubic hardening) +0.85 to +9.4 % clean except member 015 (+0.43 %, a nearly linear member:
#: ls_sindy and sgd_sindy pass it linear), the same at 1 % noise where a decay fit is taken.
#: 0.7 % sits between the two groups (their geometric middle; the clamped beams at 1 % noise
#: reach +0.60 %, member 019); a shift of 0.7 % of a mode's frequency is 4.4 rad of phase over
#: 100 periods.
CUBIC_CHIRP_MIN = 0.007
#: The words rule (4)'s reason (:func:`_third_harmonic_rule`) puts the cubic in with: a caller
#: that must know the cubic came in by the lowest peak's third harmonic, the witness that this
#: peak is an amplitude-hardened frequency (``sgd_sindy``'s ``hardened_peak_rule_``), reads them
#: in ``cubic_rule_``.
THIRD_HARMONIC_IN = "the peak search recognised a third harmonic of the lowest peak"


def cubic_partial_correlation(lib: Library) -> float:
    """Largest partial correlation of a cubic column with a row's residual [-].

    Parameters
    ----------
    lib : Library
        Built with ``cubic=True``.

    Returns
    -------
    float
        ``max_ij |corr(e_i, z_j)|`` with ``e_i`` the residual of target row ``i`` and ``z_j``
        cubic column ``j``, both after least squares on row ``i``'s other columns (its mask);
        0 without a cubic block.
    """
    if "c" not in lib.blocks:
        return 0.0
    cub = np.zeros(lib.theta.shape[0], dtype=bool)
    cub[lib.blocks["c"]] = True
    best = 0.0
    for i in range(lib.target.shape[0]):
        base = lib.theta[lib.mask[i] & ~cub].T
        scale = np.linalg.norm(base, axis=0)
        q = np.linalg.qr(base / np.where(scale > 0, scale, 1.0))[0]
        e = lib.target[i] - q @ (q.T @ lib.target[i])
        z = lib.theta[cub & lib.mask[i]].T
        z = z - q @ (q.T @ z)
        norms = np.linalg.norm(z, axis=0) * np.linalg.norm(e)
        ok = norms > 0
        if np.any(ok):
            best = max(best, float(np.max(np.abs(e @ z[:, ok]) / norms[ok])))
    return best


def lowest_mode_chirp(data: Measurement, fit_band_hz: float | None = None,
                      peaks: np.ndarray | None = None) -> tuple[float, float]:
    """The relative backbone chirp of the lowest measured mode of a linear fit.

    Parameters
    ----------
    data : Measurement
    fit_band_hz : float, optional
        The fit band's cut-off (:func:`identify.structural.fit_band`'s ``cutoff_hz``).
    peaks : ndarray, optional
        ``modal_peaks(data).peaks`` [Hz] if the caller has them already (not searched again).

    Returns
    -------
    chirp : float
        ``c / wd`` [-] of the mode's backbone decay fit (module docstring); NaN when the fit
        was not taken or the linear fit has a non-positive stiffness eigenvalue.
    f_hz : float
        That mode's linear damped frequency [Hz] (NaN when not taken).
    """
    lib, _, _ = fit_band(data, lambda s: build_library(data, coupled_mass=False, cubic=False,
                                                       start=s, drift=True, input_coupling=True),
                         fit_band_hz, peaks)
    n = lib.target.shape[0]
    window = fit_window(data, 0.0)
    for rows in (tilt_library(lib), lib):  # the fits' tilt rule; flat when tilted fails
        M, C, K, _ = matrices_from_coef(solve_rows(rows), rows.blocks, np.ones(n))
        freqs = modal(M, K)[0]
        if not np.all(np.isfinite(freqs)):  # a non-positive stiffness eigenvalue
            continue
        k = 0
        if peaks is not None and np.size(peaks):
            k = int(np.argmin(np.abs(np.log(freqs / float(np.min(peaks))))))
        dec = modal_decay(data, M, K, C, window, backbone=True)
        if dec.taken[k]:  # not taken: e.g. repeated modes (soft member 001 at 1 %, tilted)
            break
    else:
        return float("nan"), float("nan")
    return float(dec.chirp[k] / dec.omega_d[k]), float(dec.omega_d[k] / (2.0 * np.pi))


def cubic_rule(data: Measurement, user: bool | None, fit_band_hz: float | None = None,
               peaks: np.ndarray | None = None, search: PeakSearch | None = None
               ) -> tuple[bool, str]:
    """Whether a structural model gets the cubic features ``x_j^3``, and why.

    Parameters
    ----------
    data : Measurement
    user : bool or None
        The user's ``cubic`` setting; None = by rule.
    fit_band_hz, peaks
        As :func:`lowest_mode_chirp`, which this calls with them.
    search : PeakSearch, optional
        The caller's default peak search, ``modal_peaks(data)`` (every argument at its
        default), if it has it: rules (3) and (4) read it instead of searching again (the same
        call, so the same result; about 0.03 s a fit).

    Returns
    -------
    (bool, str)
        The rule (module docstring): in when :func:`cubic_partial_correlation` of the
        least-squares library (fit band, drift and input columns as ``ls_sindy`` builds it)
        exceeds :data:`CUBIC_SELECT_CORR`, or when that of its tilted rows does and the lowest
        measured mode's backbone chirp (:func:`lowest_mode_chirp`) exceeds
        :data:`CUBIC_CHIRP_MIN`, or (no chirp fit taken and ``peaks`` empty) the peak search
        (:func:`identify.structural.modal_peaks` on ``data``, its default band) finds the
        record amplitude-dependent (``nonlinear``; module docstring, rule (3)), or, where
        those leave it out and no chirp says the lowest mode does not harden, when that peak
        search recognised a third harmonic of the lowest of ``peaks`` (rule (4)).
    """
    if user is not None:
        return bool(user), "user setting"
    lib, _, _ = fit_band(data, lambda s: build_library(data, coupled_mass=False, cubic=True, start=s,
                                                       drift=True, input_coupling=True), fit_band_hz,
                         peaks)
    corr = cubic_partial_correlation(lib)
    head = (f"largest partial correlation of an x^3 column with the linear model's residual "
            f"{corr:.3g}")
    if corr > CUBIC_SELECT_CORR:
        return True, f"{head} > {CUBIC_SELECT_CORR:g}: cubic terms in"
    tilted = cubic_partial_correlation(tilt_library(lib))
    head += f" <= {CUBIC_SELECT_CORR:g}, tilted {tilted:.3g}"
    if not tilted > CUBIC_SELECT_CORR:
        head += f" <= {CUBIC_SELECT_CORR:g}"
        return _third_harmonic_rule(data, peaks, head, search)
    chirp, f = lowest_mode_chirp(data, fit_band_hz, peaks)
    if not np.isfinite(chirp):
        head += ", no backbone decay fit of the lowest mode taken"
        if peaks is not None and np.size(peaks) == 0 and (
                search if search is not None else modal_peaks(data)).nonlinear:
            return True, (f"{head}, and the peak search found a harmonic following a hardening "
                          "fundamental's amplitude law (no peak accepted): cubic terms in")
        return _third_harmonic_rule(data, peaks, head, search)
    on = chirp > CUBIC_CHIRP_MIN
    return on, (f"{head} and the lowest mode's ({f:.4g} Hz) backbone chirp c / wd {chirp:+.3g} "
                f"{'>' if on else '<='} {CUBIC_CHIRP_MIN:g} (it "
                f"{'hardens' if on else 'does not harden'} with amplitude): cubic terms "
                f"{'in' if on else 'out'}")


def _third_harmonic_rule(data: Measurement, peaks: np.ndarray | None, head: str,
                         search: PeakSearch | None = None) -> tuple[bool, str]:
    """Rule (4) of the module docstring, where (1)-(3) leave the cubic out: in when the peak
    search (:func:`identify.structural.modal_peaks` on ``data``, its default band; ``search``
    if the caller made it) recognised a third harmonic (``k = 3``) of the lowest accepted
    peak; ``head`` is the reason so far."""
    if peaks is None or np.size(peaks) == 0:
        return False, f"{head}: cubic terms out"
    low = float(np.min(peaks))
    # the fundamental is one of the search's own accepted peaks, the same number when the caller's
    # peaks come from the same search: 1e-9 only absorbs a round trip through float formatting
    third = [(fh, ff) for fh, k, ff in (search if search is not None else modal_peaks(data)).harmonics
             if k == 3 and abs(ff - low) <= 1e-9 * max(low, 1.0)]
    if not third:
        return False, f"{head}, no third harmonic of the lowest peak recognised: cubic terms out"
    fh, ff = third[0]
    return True, (f"{head}, but {THIRD_HARMONIC_IN} "
                  f"({fh:.4g} Hz = 3 x {ff:.4g} Hz, phase-locked, in its shape): an odd "
                  "restoring force: cubic terms in")
