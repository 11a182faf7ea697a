"""Modes the record cannot resolve: placed at the top of what the chain passes, not refused.

A structural model has one mode per sensor. With many sensors at a modest sample rate the
highest of them may lie where the record holds nothing to fit it by: at or past the peak
search's band top (:func:`identify.structural.peak_band`, ``LOWPASS_MARGIN`` x the chain's low-
pass, or ``0.45 fs``), and, with the beam's stiffness-proportional damping, so heavily damped
that it dies within a sample or two (round 16's ``b16_ti_n32_s5``: five sensors at 12.8 kHz,
mode 5 at 4619 Hz with 57 % damping, the band's top 4522 Hz). Least squares then fits that mode
with a negative stiffness (a real pole pair, one growing at +1.8e5 1/s), and the whole model
was refused although modes 1-3 came out within 2 % of the truth.

The rule (:func:`place_unresolved`), from the data alone: a mode of the fitted model whose pole
reaches beyond the band's top (:func:`modal_pole_reach`: its frequency for an underdamped mode,
its larger real pole for a negative stiffness; 6275 Hz against the top's 4522 Hz on
``b16_ti_n32_s5``) is *unresolved* by the record. A negative stiffness whose poles lie inside
the band is not (round 15's ``b15_soft_long_al_L0p8_cf0p3``: mode 1 at 2.26 Hz, removed by the
fit band, fitted with poles at +6.4 and -22.8 Hz: placing it at the 100 Hz top put mode 1
4353 % off where the band's refusal gives 1.8 %). Where every accepted spectral peak is carried
by a resolved mode (within :data:`~identify.structural.MODE_SEPARATION`: the located modes are
all in the model, so the unresolved one is not a located mode gone wrong), the unresolved mode
is placed at the band's top (the lowest frequency at which the record could hide it; one mode
at most: two at the one top would be a repeated eigenvalue whose shapes round-off decides),
damped with no resonant peak (:data:`UNRESOLVED_ZETA`: no accepted peak shows it ringing) and uncoupled in
damping from the other modes, its shape kept. Its contribution in the band is then the
quasi-static one of a stiff, fast mode; the resolved modes keep what the fit gave them.

Inside the band (``band_low_hz`` given, ``ls_sindy``'s step 5 only; :func:`unlocated_growing`):
where no mode reaches beyond the top, a mode inside the peak band that no accepted peak locates
and whose own modal damping is negative is unresolved as well.  A mode with no damping of its
own rings through the whole free decay and would show a spectral peak; none lies near it, so the
record does not hold it where the fit put it (round 20, four sensors, three or two peaks: least
squares put the mode the record cannot resolve between the peaks of modes 1 and 2 with a growing
pole, while the truth's unlocated modes lie above the located ones, 17-34 % damped).  It is
placed as above.  Not below the band's lower edge: the chain's high-pass attenuates a mode
there, so no peak is no contradiction (round 19's ``b19_br_L0p8_n14_z2_f150_2s``: mode 1 at 8.65
Hz under a 10 Hz high-pass, fitted growing at 8.46 Hz; placing it at the top put mode 1 1870 %
off).
"""

from __future__ import annotations

import numpy as np

from identify._modal_damping import _is_symmetric, _modal_damping_matrix, hold_modal_damping
from identify.structural import MODE_SEPARATION, SHAPES_COND_MAX, modal

#: Damping ratio given to an unresolved mode [-]: 1/sqrt(2), the least damping whose response
#: has no resonant peak (the record shows no peak of it), and a complex pole pair.  Not
#: critical (1.0): a critically damped mode is a double real pole, a defective eigenproblem
#: whose eigenvalues round-off returns either as a complex pair or as two reals (5e-7 apart on
#: ``b16_ti_n32_s5``'s placed mode at q = p / 2 fs = -1.11, past the trapezoid map's range:
#: mapped back on one CPU, not on another, mode 3 0.2 % or 3.8 % off: session 18's portability
#: runs).  Measured on ``b16_ti_n32_s5`` clean, ``ls_sindy``: TRAC 0.998 with 1.0 and 0.9997
#: with 0.5, modes 1-3 unchanged (not tuned: the declared choice).
UNRESOLVED_ZETA = float(1.0 / np.sqrt(2.0))


def stiffness_eigenvalues(M: np.ndarray, K: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The eigenvalues ``lambda`` [rad^2/s^2] of ``M^-1 K`` in the order and with the shapes of
    :func:`identify.structural.modal` (non-positive ones kept, where ``modal`` gives NaN).

    Parameters
    ----------
    M, K : ndarray, shape (n, n)
        Mass [kg] and stiffness [N/m]; need not be symmetric.

    Returns
    -------
    lam : ndarray, shape (n,)
        Real parts [rad^2/s^2].
    modes : ndarray, shape (n, n)
        ``modal(M, K)[1]``.
    """
    _, Phi = modal(M, K)
    lam = np.diag(np.linalg.solve(Phi, np.linalg.solve(M, K @ Phi))).real
    return lam, Phi


def modal_pole_reach(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> np.ndarray:
    """Each mode's largest pole modulus [1/s]: the larger root of ``s^2 + d_k s + lambda_k``,
    ``lambda_k`` its stiffness eigenvalue (:func:`stiffness_eigenvalues`) and ``d_k`` its own
    modal damping (the diagonal of ``Phi^-1 M^-1 C Phi``), couplings left out.  For an
    underdamped mode it is ``sqrt(lambda_k)``; for a negative stiffness it is the growing or
    the faster decaying real pole.  Shape (n,), ``modal``'s order."""
    lam, Phi = stiffness_eigenvalues(M, K)
    d = np.diag(_modal_damping_matrix(M, C, Phi, _is_symmetric(M, C, K))).real
    disc = np.sqrt((0.25 * d * d - lam).astype(complex))
    return np.maximum(np.abs(-0.5 * d + disc), np.abs(-0.5 * d - disc))


def _one_resolvable(bad: np.ndarray, lam: np.ndarray) -> bool:
    """Whether exactly one mode is marked unresolved (``bad``) and every other has a positive
    stiffness eigenvalue ``lam`` [rad^2/s^2]: what :func:`place_unresolved` can place."""
    return not (np.count_nonzero(bad) != 1 or np.any(lam[~bad] <= 0.0))


def place_unresolved(M: np.ndarray, C: np.ndarray, K: np.ndarray, top_hz: float,
                     peaks: np.ndarray, band_low_hz: float | None = None
                     ) -> tuple[np.ndarray, np.ndarray, str] | None:
    """The model with its unresolved modes placed at the band's top (module docstring).

    Parameters
    ----------
    M, C, K : ndarray, shape (n, n)
        The fitted mass [kg], damping [N s/m] and stiffness [N/m] (need not be symmetric).
    top_hz : float
        The peak search's band top [Hz] (:func:`identify.structural.peak_band`).
    peaks : ndarray, shape (k,)
        Accepted spectral peaks [Hz].
    band_low_hz : float, optional
        The peak band's lower edge [Hz].  Given, where no mode reaches beyond the top, the
        modes of :func:`unlocated_growing` inside ``[band_low_hz, top_hz]`` are the unresolved
        ones (module docstring; ``ls_sindy``'s step 5).  None (``sgd_sindy``'s warm start):
        beyond the top only.  Given, where those rules place nothing, a fit with exactly one
        mode of non-positive stiffness eigenvalue has it placed (modes beyond the top left as
        fitted, named in the rule), on the direction the other modes' shapes leave (the unit
        vector orthogonal to their span), the accepted peaks still checked: a mode with no
        frequency shows no peak,
        and its fitted shape is what rounding left in directions the record does not excite
        (diag27: round 26's clean seven-sensor beam, modes 4-7 gone before the free window).

    Returns
    -------
    (C, K, rule) or None
        The new damping and stiffness and a statement of what was done; None where not exactly
        one mode is unresolved (:func:`modal_pole_reach` beyond ``2 pi top_hz``), a resolved
        mode has a stiffness eigenvalue <= 0, the shapes do not span the space, or an accepted peak
        has no resolved mode within :data:`~identify.structural.MODE_SEPARATION` of it.
    """
    if not (np.isfinite(top_hz) and top_hz > 0.0):
        return None
    # shapes that do not span the space (a complex eigenvalue pair of M^-1 K: modal keeps the
    # real parts, one vector for the pair) are refused before any solve with them, which
    # raised LinAlgError or returned rounding (round 20's b20_st_hit0p1 at 3 %, s111 / s113:
    # the tilted fit's modes 2-3 coalesced at 523.4 +- 19.1j / 532.5 +- 11.7j Hz)
    if not np.linalg.cond(modal(M, K)[1]) <= SHAPES_COND_MAX:
        return None
    lam, Phi = stiffness_eigenvalues(M, K)
    bad = modal_pole_reach(M, C, K) > 2.0 * np.pi * top_hz
    orth = False
    where = f"a pole beyond the peak band's top {top_hz:.4g} Hz) placed at that top"
    if band_low_hz is not None and not np.any(bad):
        bad = unlocated_growing(M, C, K, peaks, (float(band_low_hz), top_hz))
        where = ("negative own damping inside the band, where no accepted peak located it) "
                 f"placed at the peak band's top {top_hz:.4g} Hz")
    if band_low_hz is not None and not _one_resolvable(bad, lam):
        # a fit with no fit band (ls_sindy's step 5 only) whose one growing mode is a negative
        # stiffness: no accepted peak can locate a mode without a frequency, and the record's
        # free decay is carried by the other modes (the accepted peaks checked below), so the
        # record does not hold it (diag27: b26_st_s7u_f2_hit0p6_fs25k6 clean, seven sensors,
        # modes 4-7 34-116 % damped, gone before the free decay: least squares fits the
        # directions the record leaves unexcited with whatever rounding gives them)
        # (modes beyond the top stay as fitted: diag27's record has three, 2.9-39 kHz, as
        # unexcited as the placed one; the damping below goes to the placed mode: review 27f)
        neg = lam <= 0.0
        if np.count_nonzero(neg) == 1:
            bad, orth = neg, True
            where = ("no frequency for any peak to locate, in a fit with no fit band) placed at the "
                     f"peak band's top {top_hz:.4g} Hz on the direction the other modes' shapes leave")
    # one mode only: two or more placed at the one top would be a repeated eigenvalue whose
    # shapes round-off decides (on a non-symmetric warm start, 7 of 200 random 4-DOF models
    # with two modes above the top ended in a singular eigenvector matrix: session 18's review)
    if not _one_resolvable(bad, lam):  # (Phi's span checked above)
        return None
    f_ok = np.sqrt(lam[~bad]) / (2.0 * np.pi)
    for p in np.asarray(peaks, dtype=float):
        if not np.any(np.abs(f_ok / p - 1.0) <= MODE_SEPARATION):
            return None
    w2 = (2.0 * np.pi * top_hz) ** 2
    d = np.where(bad, w2 - lam, 0.0)
    if orth:
        # its shape is not the record's either: the direction the other modes' shapes leave
        # (least squares put it nearly parallel to mode 1's, cond(Phi) ~1e9)
        others = Phi[:, ~bad]
        q, _ = np.linalg.qr(np.hstack([others, np.eye(lam.size)]))
        Phi2 = Phi.copy()
        Phi2[:, bad] = q[:, others.shape[1]:others.shape[1] + 1]
        lam2 = np.where(bad, w2, lam)
        K2 = M @ Phi2 @ np.diag(lam2) @ np.linalg.inv(Phi2)
    else:
        K2 = K + (M @ Phi) @ np.linalg.solve(Phi.T, np.diag(d)).T
    if np.allclose(M, M.T) and np.allclose(K, K.T):
        K2 = 0.5 * (K2 + K2.T)
    # the placed modes are now the highest (every resolved one lies at or below the top), or,
    # placed on the free direction, the mode at the top's rank (modes beyond it left as fitted)
    n_bad = int(np.count_nonzero(bad))
    top = np.zeros(lam.size, dtype=bool)
    rank = int(np.count_nonzero(lam[~bad] < w2)) if orth else lam.size - n_bad
    top[rank:rank + n_bad] = True
    above = int(np.count_nonzero(lam[~bad] >= w2)) if orth else 0
    sigma = np.where(top, UNRESOLVED_ZETA * np.sqrt(w2), np.nan)
    try:
        C2 = hold_modal_damping(M, C, K2, sigma, uncouple=top)
    except np.linalg.LinAlgError:  # shapes that no longer span the space: the rule does not act
        return None
    what = ", ".join("a negative stiffness" if v <= 0 else f"{np.sqrt(v) / (2 * np.pi):.4g} Hz"
                     for v in lam[bad])
    rule = (f"{n_bad} mode(s) the record cannot resolve (fitted with {what}, {where}, "
            f"damping ratio "
            f"{UNRESOLVED_ZETA:g}, " + ("the other shapes kept" if orth else "shapes kept")
            + (f", {above} mode(s) beyond the top left as fitted" if above else "")
            + f"; the {lam.size - n_bad - above} modes below carry every accepted peak")
    return C2, K2, rule


def unlocated_growing(M: np.ndarray, C: np.ndarray, K: np.ndarray, peaks: np.ndarray,
                      band_hz: tuple[float, float]) -> np.ndarray:
    """Modes of the fit inside the peak band that no accepted peak located and whose own modal
    damping is negative.

    A mode inside the peak band with no damping of its own (``d_k < 0``, the diagonal of
    ``Phi^-1 M^-1 C Phi``) would ring through the whole free decay and show a spectral peak;
    where no accepted peak lies within :data:`~identify.structural.MODE_SEPARATION` of its
    frequency the record contradicts it: it is a mode the record does not resolve, fitted where
    least squares put it (measured, round 20: ``b20_gf_s4tip`` 0.5 % seed 111, the tilted fit's
    mode 2 at 265 Hz with a growing pole, between peaks at 51.9 and 323.5 Hz, while the
    truth's unlocated mode 4 lies at 1778 Hz, 34 % damped; ``b20_st_s4root_tip`` 1 % seed 118,
    mode 2 at 391 Hz between peaks 82.8 and 519.4 Hz, the truth's unlocated modes at 1447 and
    2835 Hz).

    Parameters
    ----------
    M, C, K : ndarray, shape (n, n)
        The fitted mass [kg], damping [N s/m] and stiffness [N/m] (need not be symmetric).
    peaks : ndarray, shape (k,)
        Accepted spectral peaks [Hz].
    band_hz : (float, float)
        The peak search's band [Hz] (:func:`identify.structural.peak_band`): a mode outside it
        shows no peak whatever its damping (below, the chain's high-pass attenuates it).

    Returns
    -------
    ndarray of bool, shape (n,)
        In :func:`identify.structural.modal`'s order; False for a non-positive stiffness
        eigenvalue (the band-top rule's case).
    """
    lam, Phi = stiffness_eigenvalues(M, K)
    d = np.diag(_modal_damping_matrix(M, C, Phi, _is_symmetric(M, C, K))).real
    f = np.sqrt(np.maximum(lam, 0.0)) / (2.0 * np.pi)
    p = np.asarray(peaks, dtype=float)
    located = np.array([p.size > 0 and bool(np.any(np.abs(fk / p - 1.0) <= MODE_SEPARATION))
                        for fk in f])
    inside = (f >= band_hz[0]) & (f <= band_hz[1])
    return (lam > 0.0) & inside & ~located & (d < 0.0)
