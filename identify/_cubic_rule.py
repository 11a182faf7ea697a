"""The structural identifiers' cubic rule: whether a model gets the cubic features ``x_j^3``.

Why a backbone and not a correlation
------------------------------------
A cubic restoring force makes a free decay's frequency move with its amplitude: a hardening
spring rings faster while the amplitude is large and tends to its linear frequency as it
decays (the first-order backbone ``w(A) = w_0 (1 + 3/8 k3 A^2 / k1)``).  That chirp is the
physical evidence of a cubic in an impact record, and it is fitted in physical time to the
whole decay: :func:`identify._modal_damping.modal_decay` with ``backbone`` fits each mode's
instantaneous frequency ``wd + c exp(-2 sigma t)`` by variable projection, so the relative
chirp ``c / wd`` of a mode does not depend on the sample rate (nor on the response's scale).

The rule it replaces (the largest partial correlation of an ``x_j^3`` column with a row's
linear-model residual above 0.65) weighed every sample by its squared residual, and on the soft
base that puts 98 % of the weight in the first millisecond of the fit window, where what the
linear model misses is the heavily damped upper modes' and the low-pass's transient (1-10 kHz).
The window starts where the chain's low-pass has settled (``free_start``), later at a low rate
(its digital Butterworth rings longer near Nyquist): round 7's b_soft_fs6400, 12800 and 20000
(the same rig, ``lowpass_hz`` 2036 Hz) start at 7.66 / 6.88 / 6.70 ms, and the correlation
was 0.303 / 0.705 / 0.798 (out / in / in); from a common 7.7 ms it is 0.303 / 0.383 / 0.420.
The statistic of this rule is 0.0478 / 0.0480 / 0.0481 on the same three records (mode 1, within
0.6 %), and ls_sindy passes b_soft_fs6400 with the cubic in (mode 2 7.7 -> 0.22 %).

The rule
--------
The linear library (fit band, drift and input columns, as ``ls_sindy`` builds it) is fitted by
least squares with equal diagonal masses, tilted as the identifiers fit it (flat when the tilted
fit has a non-positive stiffness eigenvalue or no decay fit of the mode is taken on it); the
decay of its mode nearest the lowest measured peak (the lowest mode without a peak) is fitted
with the backbone.  Cubic terms go in when that
decay fit is taken and its relative chirp ``c / wd`` exceeds :data:`CUBIC_CHIRP_MIN`: the mode
hardens with amplitude.  The lowest mode: it carries the largest displacement, so a cubic
force's largest share, and a heavily damped upper mode's decay is too short to measure a chirp
on (on the clamped beams of the families, upper modes show apparent chirps of -6.5 to +1.6 %
at 1 % noise).
"""

from __future__ import annotations

import numpy as np

from identify._modal_damping import modal_decay
from identify._sgd_matrix import fit_window
from identify.structural import (
    build_library,
    fit_band,
    matrices_from_coef,
    modal,
    solve_rows,
    tilt_library,
)
from testbed.core.measurement import Measurement

#: Cubic terms enter a model chosen by rule when the lowest mode's measured backbone chirp
#: ``c / wd`` (:func:`lowest_mode_chirp`) exceeds this [-].  Measured on the beams of
#: studies/families.toml (2026-11-27): the 40 clamped (linear) beams' mode 1 at most +0.58 %
#: clean (member 019; 032, two sensors, -2.6 %) and +0.13 % at 1 % noise; the 20 soft bases
#: (cubic hardening) +0.85 to +9.4 % clean except member 015 (+0.43 %, a nearly linear member:
#: ls_sindy and sgd_sindy pass it linear), the same at 1 % noise where a decay fit is taken.
#: 0.7 % sits between the two groups (their geometric middle); a shift of 0.7 % of a mode's
#: frequency is 4.4 rad of phase over 100 periods.
CUBIC_CHIRP_MIN = 0.007


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
               peaks: np.ndarray | None = None) -> tuple[bool, str]:
    """Whether a structural model gets the cubic features ``x_j^3``, and why.

    Parameters
    ----------
    data : Measurement
    user : bool or None
        The user's ``cubic`` setting; None = by rule.
    fit_band_hz : float, optional
        The fit band's cut-off (:func:`identify.structural.fit_band`'s ``cutoff_hz``).
    peaks : ndarray, optional
        ``modal_peaks(data).peaks`` [Hz] if the caller has them already (not searched again).

    Returns
    -------
    (bool, str)
        The rule (module docstring): in when the lowest measured mode's backbone chirp
        (:func:`lowest_mode_chirp`) exceeds :data:`CUBIC_CHIRP_MIN`, a statistic fitted in
        physical time and so the same decision at any sample rate of the same record.
    """
    if user is not None:
        return bool(user), "user setting"
    chirp, f = lowest_mode_chirp(data, fit_band_hz, peaks)
    if not np.isfinite(chirp):
        return False, ("no backbone decay fit of the lowest mode taken (no amplitude-dependent "
                       "frequency measured): cubic terms out")
    on = chirp > CUBIC_CHIRP_MIN
    return on, (f"the lowest mode's ({f:.4g} Hz) backbone chirp c / wd {chirp:+.3g} "
                f"{'>' if on else '<='} {CUBIC_CHIRP_MIN:g} (it "
                f"{'hardens' if on else 'does not harden'} with amplitude): cubic terms "
                f"{'in' if on else 'out'}")
