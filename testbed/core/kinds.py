"""The kinds of rig and the scores each kind reports (names and meanings, no code).

A rig declares its ``kind``; every rig of a kind is measured, identified and scored alike.
The catalogue lives in the core because scenario files are validated against it (a
``[score]`` table may threshold ``<name>_min`` / ``<name>_max``) below the scoring layer that
computes the scores (:mod:`testbed.scoring.scorers`).
"""

from __future__ import annotations

import math
import re

METRICS: dict[str, dict[str, str]] = {
    "structural": {
        "trac": "smallest TRAC over sensors: simulated identified model vs noise-free "
                "measured accelerations",
        "mac": "smallest MAC over the scored modes (identified vs true sensor mode shapes, "
               "paired); the scored modes are as many as sensors",
        "freq_error": "largest relative natural-frequency error over the scored modes (as many "
                      "as sensors)",
        "damping_error": "largest relative damping-ratio error over the scored modes (as many as "
                         "sensors)",
        "Mr_error": "relative Frobenius error of the identified mass matrix vs SEREP Mr",
        "Kr_error": "relative Frobenius error of the identified stiffness matrix vs SEREP Kr",
        "Cr_error": "relative Frobenius error of the identified damping matrix vs SEREP Cr",
        "MinvK_error": "relative Frobenius error of M^-1 K (scale-free, identifiable from data)",
        "MinvC_error": "relative Frobenius error of M^-1 C (scale-free, identifiable from data)",
        "K3_force_error": "relative RMS error of the identified cubic restoring force along the "
                          "measured motion (soft base)",
        "K3_accel_error": "relative RMS error of the acceleration the identified cubic force "
                          "causes, M^-1 K3 x^3 against Mr^-1 times the truth's, along the "
                          "measured motion (soft base; free of the modal-mass sharing, which "
                          "free vibration does not determine)",
        "K3_norm": "Frobenius norm of the identified cubic matrix [N/m^3]",
        "K3_force_ratio": "RMS of the identified cubic restoring force over that of the identified "
                          "linear one, along the measured motion (scale-free size of K3)",
        "cross_orth": "largest off-diagonal of Phi_id^T Mr Phi_true (mass-normalised modes)",
    },
    "mechanical": {
        "angle_rmse": "largest joint-angle RMSE [rad] of the identified model simulated from the "
                      "true initial state under the recorded torques",
        "coef_error": "largest relative error of the true terms' coefficients",
        "support_precision": "precision of the identified nonzero pattern",
        "support_recall": "recall of the identified nonzero pattern",
        "support_f1": "F1 of the identified nonzero pattern",
        **{f"{score}_{lib}": f"{score} when the fitted library is {what} (absent otherwise), so "
                             "two fits of one study sit side by side"
           for lib, what in (("true_library", "the true-terms 'fivebar' library"),
                             ("full_library", "the full 'fivebar_full' library"))
           for score in ("coef_error", "support_f1")},
    },
    "dynamical": {
        "state_rmse": "largest state RMSE [unit of the state] of the identified model simulated "
                      "from the true initial state, against the noise-free states",
        "coef_error": "largest relative error of the true terms' coefficients (equations "
                      "compared up to scale: both divided by their coefficient on the true "
                      "equation's largest term)",
        "support_precision": "precision of the identified nonzero pattern (terms matched by name)",
        "support_recall": "recall of the identified nonzero pattern",
        "support_f1": "F1 of the identified nonzero pattern",
    },
}

#: Per-mode structural scores ``<score>_mode<k>`` for k = 1 .. MAX_MODE_SCORES: a scenario may
#: hold single modes to their own bars (e.g. modes 1-2 to the paper's).  Eight covers every
#: shipped scenario and family member (at most six sensors); a model with more sensors still
#: reports every mode in its details.
MAX_MODE_SCORES = 8
_PER_MODE = {"mac": "MAC", "freq_error": "relative natural-frequency error",
             "damping_error": "relative damping-ratio error"}
METRICS["structural"].update({
    f"{score}_mode{k}": f"{what} of true mode {k} against its paired identified mode (present "
                        f"when mode {k} is scored, i.e. with at least {k} sensors)"
    for score, what in _PER_MODE.items() for k in range(1, MAX_MODE_SCORES + 1)})


def metric_names(kind: str) -> set[str]:
    """Score names a rig of ``kind`` reports."""
    return set(METRICS[kind])


#: Scores that are fractions in [0, 1] by construction (TRAC and MAC are squared cosines,
#: support precision / recall / F1 are ratios of counts); every other score is an error, a
#: norm, an RMSE or a ratio of RMS values, in [0, inf).
_UNIT_INTERVAL = re.compile(r"(trac|mac(_mode\d+)?|support_(precision|recall|f1)(_\w+)?)")


def metric_range(name: str) -> tuple[float, float]:
    """The values score ``name`` can take, ``(low, high)``: (0, 1) or (0, inf).

    A threshold outside this range is either unpassable (``_max`` below 0, ``_min`` above 1)
    or never binding (``_min`` below 0, ``_max`` above 1): scenario validation refuses both.
    """
    return (0.0, 1.0) if _UNIT_INTERVAL.fullmatch(name) else (0.0, math.inf)
