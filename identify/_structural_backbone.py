"""A linear model of a hardening record: its lowest mode at the backbone decay's linear limit,
the hardening carried by a cubic on that mode alone whose strength is fitted to the record by
simulation (output error): ``ls_sindy``'s step 4c and ``sgd_sindy``'s backbone step
(:func:`backbone_cubic`), and ``ls_sindy``'s step 4d (:func:`mode_cubic`, a fitted cubic
replaced by one on that mode alone); a structural identifier with ``M_``, ``C_``, ``K_``,
``input_map_`` and ``simulate`` may call them the same way.
"""

from __future__ import annotations

import copy

import numpy as np

from identify._cubic_form import duffing_by_balance, one_mode_cubic
from identify._cubic_rule import CUBIC_CHIRP_MIN
from identify._modal_damping import BACKBONE_MIN_FALL, limit_reached, modal_decay, set_eigenvalues
from identify._record import (
    AGREEMENT_RATIO,
    AGREEMENT_TIE,
    best_scale,
    clearly_more,
    record_agreement,
)
from identify._sgd_matrix import eigen_targets, fit_window
from identify.structural import (
    MODE_SEPARATION,
    SHAPES_COND_MAX,
    StructuralIdentifier,
    check_physical,
    modal,
)
from testbed.core.errors import IdentificationError
from testbed.core.measurement import Measurement


def backbone_cubic(model: StructuralIdentifier, data: Measurement, peaks: np.ndarray,
                   ratio: float = AGREEMENT_RATIO
                   ) -> tuple[np.ndarray | None, np.ndarray | None, str, float]:
    """A fitted linear model's lowest mode moved to its backbone limit, with a cubic on that
    mode alone sized by output error, where the record calls for it.

    Mode ``k`` is the model's lowest mode that a measured peak locates, by the eigenvalue
    hold's pairing (:func:`identify._sgd_matrix.eigen_targets`: within
    :data:`identify.structural.MODE_SEPARATION`, closest first, in order); a mode no peak
    locates is the fit's, not the record's (review 28c; before, the mode nearest the lowest
    peak was taken at any distance).  A lowest peak no mode takes (a spurious peak under mode
    1: ``soft_v21__008`` at 1 %, 18.2 Hz under 41.9; ``b26_fe_soft_r0p45_cf0p2`` at 2 %, 13.4
    under 20.1) does not stop it: requiring it to locate ``k`` lost the latter's mode-1 gain
    (2.34 % -> within) for the former's study bar (docs/known-gaps.md, beam34).  The shapes'
    cubes must be resolved (``cond(Phi**3)`` under :data:`identify.structural.SHAPES_COND_MAX`,
    else no cubic acts on one mode alone) and the moved stiffness physical
    (:func:`identify.structural.check_physical`, checked before any simulation).  Its backbone
    decay fit
    (:func:`identify._modal_damping.modal_decay`, ``backbone=True``, on the model as it stands)
    must be taken, chirp up by more than :data:`identify._cubic_rule.CUBIC_CHIRP_MIN` of its
    frequency (the record hardens), have its limit read
    (:func:`identify._modal_damping.limit_reached`: the squared amplitude falls to
    :data:`identify._modal_damping.BACKBONE_MIN_FALL` or less over the fit window, the decay
    hold's own condition; held-out soft 013 clean / 1 %, a fall to 0.60, had its limit 1.8 %
    under the truth and lost mode 1's bar when moved) and put the linear limit
    ``sqrt(lam_model) / (2 pi)`` under the model's frequency (the linear model heard the
    amplitude-averaged, hardened frequency; no line's tolerance: the decay fit resolves finer
    than the window's line, 2 Hz on the soft family's 0.5 s against mode 1's 25-45 Hz, and the
    move is as large as the gap).  Then the mode's eigenvalue is set to that limit (shapes
    kept, :func:`identify._modal_damping.set_eigenvalues`) and the model gets the cubic
    :func:`identify._cubic_form.one_mode_cubic` on mode ``k`` alone, ``g = s g_hb``: ``g_hb``
    (:func:`identify._cubic_form.duffing_by_balance`) is the Duffing whose first harmonic
    balance at the record's modal amplitude (``sqrt 2`` x the RMS of mode ``k``'s modal
    displacement over the fit window) rings at the linear model's eigenvalue, and ``s``
    maximises the model's record agreement (:func:`identify._record.best_scale` of
    :func:`identify._record.record_agreement`: the model's own simulation from the record's
    start against the measured accelerations).  The result is refused where the linear model
    explains clearly more of the record (it leaves under 1 / ``ratio`` of what the new model
    leaves unexplained, :func:`identify._record.clearly_more`) or where no scale simulated.
    ``s = 0``, the bare move of the frequency without a cubic (the record's hardening then
    carried by nothing), is kept only where it explains clearly more than
    the linear model (the same margin, the other way; round 24's ``b24_ti_..._f100`` clean:
    0.8847 -> 0.8726, refused).  Only the record enters.

    Why: where the cubic library's own fit is refused (non-physical, diverging) or not kept, a
    linear model holds the lowest mode at the amplitude-averaged frequency (soft members 001 /
    004 / 006 clean: +3.7 / +1.5 / +5.2 %), and the equation error sizes no usable cubic; a
    cubic sized from the chirp alone collapsed TRAC (docs/known-gaps.md, fam11), a modal
    Duffing sized by harmonic balance explained less than the linear model (beam30).  The
    output error sizes it on the response itself.

    Parameters
    ----------
    model : StructuralIdentifier
        A fitted linear model (``M_``, ``C_``, ``K_``, ``input_map_``; ``K3_`` None).
    data : Measurement
        The record it was fitted on.
    peaks : ndarray, shape (p,)
        Accepted spectral peaks [Hz], in the fit's domain (warped as the eigenvalue hold warps
        them for a trapezoid-integrated record).
    ratio : float
        The margin of :func:`identify._record.clearly_more`.

    Returns
    -------
    K : ndarray, shape (n, n) or None
        The moved stiffness [N/m]; None where nothing moves.
    K3 : ndarray, shape (n, n) or None
        The cubic [N/m^3] (None: none, also where ``s = 0``).
    rule : str
        What was done, with both record agreements and the scale, or why not.
    agreement : float
        The moved model's record agreement [-] (:func:`identify._record.record_agreement`, at
        the chosen scale; the caller need not simulate it again); NaN where nothing moves.
    """
    if np.size(peaks) == 0:
        return None, None, "not tried (no measured peak)", float("nan")
    freqs, Phi = modal(model.M_, model.K_)
    if not np.all(np.isfinite(freqs)) or not np.linalg.cond(Phi) < SHAPES_COND_MAX:
        return None, None, "not tried (the model's modes not resolved)", float("nan")
    if not np.linalg.cond(Phi**3) < SHAPES_COND_MAX:
        return None, None, ("not tried (the cubes of the model's mode shapes are not resolved: "
                            "no cubic acts on one mode alone)"), float("nan")
    targets = eigen_targets(model.M_, model.K_, (2.0 * np.pi * np.asarray(peaks, dtype=float)) ** 2)
    if not np.any(targets > 0):
        return None, None, (f"not tried (no mode of the model within {MODE_SEPARATION:.0%} of "
                            "a measured peak)"), float("nan")
    k = int(np.flatnonzero(targets > 0)[0])
    peak = float(np.sqrt(targets[k]) / (2.0 * np.pi))
    i0, i1 = fit_window(data, 0.0)
    dec = modal_decay(data, model.M_, model.K_, model.C_, (i0, i1), backbone=True)
    chirp = float(dec.chirp[k] / dec.omega_d[k]) if dec.taken[k] else float("nan")
    f_lim = float(np.sqrt(dec.lam_model[k]) / (2.0 * np.pi)) if dec.taken[k] else float("nan")
    duration = (i1 - i0) / float(data.fs)
    head = (f"mode {k + 1} ({freqs[k]:.4g} Hz, paired with the peak at {peak:.4g} Hz): "
            f"backbone chirp c / wd {chirp:+.3g}, linear limit {f_lim:.4g} Hz, decay rate "
            f"{float(dec.sigma[k]):.3g} 1/s over the {duration:.3g} s window")
    if not (chirp > CUBIC_CHIRP_MIN and freqs[k] > f_lim
            and limit_reached(dec.sigma[k], duration)):
        return None, None, (f"{head}: not moved (it needs a chirp above {CUBIC_CHIRP_MIN:g}, "
                            "the limit under the model's frequency and read, the squared "
                            f"amplitude falling to {BACKBONE_MIN_FALL:g} or less)"), float("nan")
    lam = np.full(freqs.size, np.nan)
    lam[k] = float(dec.lam_model[k])
    K_b = set_eigenvalues(model.M_, model.K_, lam)
    try:
        check_physical(model.M_, model.C_, K_b)
    except IdentificationError as e:
        return None, None, f"{head}: not moved ({e})", float("nan")
    # K_b keeps the model's shapes (set_eigenvalues), so Phi holds them in the same order;
    # the moved model's own modal() re-sorts them where the limit falls below a lower
    # (unlocated) mode, and its column k would be that mode (read 28a)
    q = np.linalg.solve(Phi, np.asarray(data.x, dtype=float)[:, i0:i1])[k]
    g_hb = duffing_by_balance((2.0 * np.pi * freqs[k]) ** 2, lam[k],
                              float(np.sqrt(2.0 * np.mean(q**2))))

    def cubic(s: float) -> np.ndarray | None:
        return one_mode_cubic(model.M_, Phi, k, s * g_hb) if s > 0 else None

    def candidate(s: float) -> StructuralIdentifier:
        new = copy.copy(model)
        new.K_, new.K3_ = K_b, cubic(s)
        return new

    s, a_new = best_scale(lambda s: record_agreement(candidate(s), data)[0])
    a_lin = record_agreement(model, data)[0]
    figures = (f"record agreement (TRAC) linear {a_lin:.6g}, moved with the cubic x {s:.3g} "
               f"of the harmonic balance's {a_new:.6g}")
    why = ""
    if not np.isfinite(a_new):
        why = "its simulation failed at every scale"
    elif clearly_more(a_lin, a_new, ratio):
        why = f"the linear model leaves under 1 / {ratio:g} of what it leaves unexplained"
    elif not s > 0 and not clearly_more(a_new, a_lin, ratio):
        why = (f"no cubic (scale 0): a bare move of the frequency is kept only where it leaves "
               f"under 1 / {ratio:g} of what the linear model leaves unexplained")
    if why:
        return None, None, f"{head}: not moved ({why}; {figures})", float("nan")
    K3 = cubic(s)
    return K_b, K3, (f"{head}: moved to its limit, "
                     + ("with a cubic on that mode alone sized by output error"
                        if K3 is not None else "no cubic (output error chose scale 0)")
                     + f" ({figures})"), float(a_new)


def mode_cubic(model: StructuralIdentifier, data: Measurement, peaks: np.ndarray,
               fitted_map: np.ndarray | None, a_old: float | None = None
               ) -> tuple[np.ndarray | None, np.ndarray | None, str]:
    """A fitted cubic model's cubic replaced by one on its lowest located mode alone, sized by
    output error, where that explains more of the record.

    Mode ``k`` is the model's lowest mode a measured peak locates, as :func:`backbone_cubic`
    takes it (the eigenvalue hold's pairing), its shapes' cubes resolved.  The candidate keeps
    the model's ``M_``, ``C_`` and ``K_`` (its frequencies and shapes, which the cubic library's
    linear part places) and takes the cubic :func:`identify._cubic_form.one_mode_cubic` on
    mode ``k`` with ``g = s |g_k|``: ``g_k = phi_k^T K3 phi_k^3`` (mass-normalised ``phi_k``) is
    the fitted cubic's own coefficient along that mode's motion, in size (a hardening cubic:
    the cubic library is chosen on a hardening record), and ``s`` maximises the record
    agreement (:func:`identify._record.best_scale` of :func:`identify._record.record_agreement`),
    once with the regression's fitted input map ``fitted_map`` and once with none (step 6
    judged that map beside the fitted cubic, not beside this one).  The candidate with the
    higher agreement (ties: no map) replaces the fitted cubic where it explains more of the
    record than the model as it stands (a plain "higher", within the tie band
    :data:`identify._record.AGREEMENT_TIE`: two estimates of one term, the
    equation error's and the output error's, the record choosing, as ``sgd_sindy`` chooses
    between its libraries where the decays contradict its cubic).  Not step 4c's convention
    (the new term kept unless the old explains clearly more, margin 2): measured, that
    replaced held-out soft 012 at 1 % within the margin (0.912 -> 0.828, 0.52 x) and lost its
    study bar.  Near ties (held-out 000 / 001 / 004 / 005 / 008 / 015 at 1 %: equal to 1e-4,
    cubics that barely act) are decided by the record beyond the tie band, not by a kernel's
    rounding; the verdicts and frequencies are the same either way (the linear part is not
    touched).  Scale 0 (no cubic) or nothing simulated: the model
    stands.  Only the record enters.

    Why: the equation error sizes the diagonal cubic ``x_j^3`` of a soft base from columns of
    ~1e-13 m^3, collinear with the linear ones; on a sensor beside the base it can soften the
    mode the record shows hardening (soft-base member 010 clean: ``g_1 = -1.6e14`` against a
    measured chirp of +1.06 Hz, TRAC 0.943 on that channel with the input map dropped, 0.870
    with it) where a hardening cubic on mode 1 alone, with the map, explains 0.963
    (docs/known-gaps.md, beam35).

    Parameters
    ----------
    model : StructuralIdentifier
        A fitted cubic model (``M_``, ``C_``, ``K_``, ``K3_``, ``input_map_``).
    data : Measurement
        The record it was fitted on.
    peaks : ndarray, shape (p,)
        Accepted spectral peaks [Hz] as the caller holds them (``ls_sindy`` passes its held
        peaks, on a trapezoid record 2e-5 relative off the measured ones, far inside the
        pairing's :data:`identify.structural.MODE_SEPARATION`).
    fitted_map : ndarray, shape (n, n_inputs), or None
        The regression's fitted input map before step 6 judged it; None where the regression
        fitted none (the model's own map, the data's or None, is then the only one tried).
    a_old : float, optional
        The model's own record agreement [-] where the caller has it (``ls_sindy``'s step 6
        computed it for the model as it stands: not simulated again); computed when None.

    Returns
    -------
    K3 : ndarray, shape (n, n) or None
        The new cubic [N/m^3]; None where the model stands.
    input_map : ndarray, shape (n, n_inputs) or None
        The input map that goes with it (the fitted one, zeros, or the model's own where
        ``fitted_map`` is None); None where the model stands.
    rule : str
        What was done with both record agreements and the scale, or why not.
    """
    if model.K3_ is None or np.size(peaks) == 0:
        return None, None, "not tried (a linear model, or no measured peak)"
    freqs, Phi = modal(model.M_, model.K_)
    if (not np.all(np.isfinite(freqs)) or not np.linalg.cond(Phi) < SHAPES_COND_MAX
            or not np.linalg.cond(Phi**3) < SHAPES_COND_MAX):
        return None, None, "not tried (the model's modes or their cubes not resolved)"
    targets = eigen_targets(model.M_, model.K_, (2.0 * np.pi * np.asarray(peaks, dtype=float)) ** 2)
    if not np.any(targets > 0):
        return None, None, (f"not tried (no mode of the model within {MODE_SEPARATION:.0%} of "
                            "a measured peak)")
    k = int(np.flatnonzero(targets > 0)[0])
    Phi = Phi / np.sqrt(np.einsum("ik,ij,jk->k", Phi, model.M_, Phi))  # mass-normalised
    g_k = float(Phi[:, k] @ np.asarray(model.K3_, dtype=float) @ Phi[:, k] ** 3)
    head = (f"mode {k + 1} ({freqs[k]:.4g} Hz): the fitted cubic's own coefficient along it "
            f"g_k {g_k:.4g}")
    if not (np.isfinite(g_k) and g_k != 0.0):
        return None, None, f"{head}: not tried (no cubic along that mode)"
    if fitted_map is None:  # no fitted map (none, or the data's own): the model's, as it is
        maps = [("its input map", model.input_map_)]
    else:
        own = np.asarray(fitted_map, dtype=float)
        maps = [("no input map", np.zeros_like(own)), ("the fitted input map", own)]

    def candidate(s: float, B: np.ndarray) -> StructuralIdentifier:
        new = copy.copy(model)
        new.K3_ = one_mode_cubic(model.M_, Phi, k, s * abs(g_k)) if s > 0 else None
        new.input_map_ = B
        return new

    a_old = record_agreement(model, data)[0] if a_old is None else a_old
    tried = [(name, B, *best_scale(lambda s, B=B: record_agreement(candidate(s, B), data)[0]))
             for name, B in maps]
    # the higher agreement (NaN lowest); within AGREEMENT_TIE, the first tried (no map)
    name, B, s, a_new = tried[0]
    for t in tried[1:]:
        if (np.isnan(a_new) and np.isfinite(t[3])) or clearly_more(t[3], a_new, AGREEMENT_TIE):
            name, B, s, a_new = t
    figures = (f"record agreement (TRAC) fitted cubic {a_old:.6g}, on mode {k + 1} alone x "
               f"{s:.3g} of |g_k| with {name} {a_new:.6g}")
    if not (s > 0 and clearly_more(a_new, a_old, AGREEMENT_TIE)):  # NaN or a tie: it stands
        return None, None, (f"{head}: kept, the cubic on that mode alone explains no more "
                            f"({figures})")
    return candidate(s, B).K3_, B, f"{head}: replaced by a cubic on that mode alone ({figures})"
