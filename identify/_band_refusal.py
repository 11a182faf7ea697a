"""The fit band's refusal rule, shared by ``ls_sindy`` and ``sgd_sindy``.

The fit band (:func:`identify.structural.fit_band`) high-passes every feature and target at
:data:`identify.structural.FIT_BAND_FRACTION` x the lowest *accepted* spectral peak.  Where no
peak located mode 1 (a mode just above the chain's high-pass, or one whose peak the chain's
ringing hides), the band removes it, and the model's lowest mode is then fitted on what the band
removed.  A band chosen by rule is therefore refused, and the whole fit made again without a
band, when

1. the fit in the band is refused (an :class:`~testbed.core.errors.IdentificationError`, e.g.
   non-physical): a mode below the cut-off cannot be checked there; the band's refusal is
   raised if the fit without the band is refused too (so the rule acts only where the old
   code raised); or
2. the fitted model's lowest undamped frequency lies below the band's cut-off (fitted on what
   the band removed).

A user's cut-off, or no band, is never refused.  Measured (``ls_sindy``, docs/known-gaps.md):
round 8's soft beam (mode 1 at 1.06 x the high-pass: 16.9 % -> 0.02 %), round 6's
``b_soft_L0p6_n12`` (169 % -> 0.44 %), round 15's ``b15_soft_long_al_L0p8_cf0p3`` (refused ->
modes 1-2 1.8 / 0.25 %); ``sgd_sindy`` on the latter clean: mode 1 54 % -> 1.8 % (rule 2: its
flat fit in the band put mode 1 at 1.04 Hz under the 16.7 Hz cut-off).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from identify.structural import modal
from testbed.core.errors import IdentificationError


def lowest_mode_hz(M: np.ndarray, K: np.ndarray) -> float:
    """The lowest finite undamped frequency [Hz] of ``(M, K)`` (0 when none is finite).

    Parameters
    ----------
    M, K : ndarray, shape (n, n)
        Mass [kg] and (linear) stiffness [N/m].
    """
    f = modal(M, K)[0]
    f = f[np.isfinite(f)]
    return float(f.min()) if f.size else 0.0


def fit_with_band_refusal(fit: Callable[[float | None], None],
                          band: Callable[[], tuple[float, str]],
                          lowest_mode: Callable[[], float], by_rule: bool) -> str | None:
    """Run ``fit`` in its fit band, and again without one where the band is refused (module
    docstring, rules 1-2).

    Parameters
    ----------
    fit : callable
        ``fit(cutoff)``: the identifier's whole fit with the fit band's cut-off [Hz] (None: as
        the identifier chooses it, by rule or a user's; 0.0: no band), setting the model;
        raises :class:`~testbed.core.errors.IdentificationError` when the fit is refused.  The
        second call (0.0) must start from the state before the first.
    band : callable
        ``band()``: the cut-off [Hz] the last fit used (0 = none) and the rule that chose it.
    lowest_mode : callable
        ``lowest_mode()``: the fitted model's lowest undamped frequency [Hz] (0 = none).
    by_rule : bool
        Whether the band is chosen by rule (only such a band is refused).

    Returns
    -------
    str or None
        The fit band's rule with its refusal (for ``fit_band_rule_``) where the band was
        refused and the model fitted without one; None where the band was kept.
    """
    try:
        fit(None)
    except IdentificationError as e:
        cut, rule = band()
        if not (by_rule and cut > 0.0):
            raise
        refused = (f"{rule}; refused: its fit is non-physical ({e}), a mode below the cut-off "
                   "unseen: no band")
        try:
            fit(0.0)
        except IdentificationError:
            raise e from None
        return refused
    cut, rule = band()
    low = lowest_mode()
    if by_rule and 0.0 < low < cut:
        refused = (f"{rule}; refused: the fitted mode 1 ({low:.4g} Hz) lies below it, fitted on "
                   "what it removed: no band")
        fit(0.0)
        return refused
    return None
