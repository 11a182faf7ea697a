"""Scores of an identified model against the truth, per rig kind.

``METRICS[kind]`` names every score a run of that kind reports (and that a
scenario's ``[score]`` table may threshold as ``<name>_min`` / ``<name>_max``).
"""

from __future__ import annotations

METRICS: dict[str, dict[str, str]] = {
    "structural": {
        "trac": "smallest TRAC over sensors: simulated identified model vs noise-free "
                "measured accelerations",
        "mac": "smallest MAC over the scored modes (identified vs true sensor mode shapes, paired)",
        "freq_error": "largest relative natural-frequency error over the scored modes",
        "damping_error": "largest relative damping-ratio error over the scored modes",
        "Mr_error": "relative Frobenius error of the identified mass matrix vs SEREP Mr",
        "Kr_error": "relative Frobenius error of the identified stiffness matrix vs SEREP Kr",
        "Cr_error": "relative Frobenius error of the identified damping matrix vs SEREP Cr",
        "MinvK_error": "relative Frobenius error of M^-1 K (scale-free, identifiable from data)",
        "K3_force_error": "relative RMS error of the identified cubic restoring force along the "
                          "measured motion (soft base)",
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
    },
}


def metric_names(kind: str) -> set[str]:
    """Score names a rig of ``kind`` reports."""
    return set(METRICS[kind])

# --------------------------------------------------------------------------- scoring
from dataclasses import dataclass, field  # noqa: E402
from typing import Any  # noqa: E402

import numpy as np  # noqa: E402

from testbed import metrics  # noqa: E402
from testbed.dataset import Dataset  # noqa: E402
from testbed.measurement import Measurement, Trajectory  # noqa: E402

#: Modes whose MAC, frequency and damping are scored (the paper scores modes 1-2;
#: mode 3 of a 3-sensor cantilever sits near 1.45 kHz and is barely excited by the impact).
SCORED_MODES = 2


@dataclass
class Check:
    """One threshold of a scenario's ``[score]`` table against a measured score."""

    metric: str
    value: float
    bound: str  # "min" or "max"
    threshold: float

    @property
    def passed(self) -> bool:
        if not np.isfinite(self.value):
            return False
        return self.value >= self.threshold if self.bound == "min" else self.value <= self.threshold


@dataclass
class Scores:
    """Scalar scores (names in :data:`METRICS`) plus the arrays behind them for figures."""

    values: dict[str, float]
    details: dict[str, Any] = field(default_factory=dict)


def check_thresholds(values: dict[str, float], thresholds: dict[str, dict[str, float]]) -> list[Check]:
    """Compare scores with ``{metric: {"min"|"max": threshold}}``; a missing score fails."""
    return [Check(m, float(values.get(m, np.nan)), b, t)
            for m, bounds in sorted(thresholds.items()) for b, t in sorted(bounds.items())]


def score(kind: str, dataset: Dataset, data: Measurement, clean: Measurement, model: Any) -> Scores:
    """Score a fitted identifier against the dataset's truth.

    Parameters
    ----------
    kind : {"structural", "mechanical"}
    dataset : Dataset
        Holds the truth.
    data : Measurement
        What the identifier was fitted on (its initial state starts simulations).
    clean : Measurement
        The same signal chain applied to the noise-free signals: the reference the
        simulated model is compared with.
    model : Identifier
        Fitted.
    """
    return (score_structural if kind == "structural" else score_mechanical)(dataset, data, clean, model)


def score_structural(dataset: Dataset, data: Measurement, clean: Measurement, model: Any) -> Scores:
    """TRAC, MAC, frequency, damping and matrix errors of a structural model.

    The identified model is simulated from the measured state at the end of the
    impact pulse (``data.free_start``) to the end of the record under the
    measured force, and its accelerations are compared with the noise-free
    accelerations passed through the same signal chain.
    """
    truth = dataset.truth
    i0 = data.free_start
    t = np.arange(data.n_samples - i0) / data.fs
    u = None if data.u is None else data.u[:, i0:]
    sim: Trajectory = model.simulate(data.x[:, i0], data.xd[:, i0], t, u)
    ref = clean.xdd[:, i0:]
    trac = metrics.trac(ref, sim.xdd)
    v: dict[str, float] = {"trac": float(np.min(trac))}
    d: dict[str, Any] = {"trac": trac, "t": t, "simulated_xdd": sim.xdd, "reference_xdd": ref,
                         "channels": data.channels}

    # strict=False: an identified M that is not positive definite scores NaN (a fail), not a crash.
    f_id, z_id, phi_id = metrics.modal_from_matrices(model.M_, model.C_, model.K_, strict=False)
    m = min(SCORED_MODES, len(truth["frequencies_hz"]), len(f_id))
    f_true = np.asarray(truth["frequencies_hz"])[: data.n_channels]
    z_true = np.asarray(truth["damping_ratios"])[: data.n_channels]
    phi_true = np.asarray(truth["sensor_modes"])[:, : data.n_channels]
    mac = metrics.mac_matrix(phi_id, phi_true)
    pair = metrics.pair_modes(mac.T)  # pair[j] = identified mode matched to true mode j
    paired = [j for j in range(m) if pair[j] >= 0]
    if len(paired) < m or not np.all(np.isfinite(mac)):  # a true mode without partner fails
        v["mac"] = v["freq_error"] = v["damping_error"] = float("nan")
    else:
        v["mac"] = float(min(mac[pair[j], j] for j in paired))
        v["freq_error"] = float(max(metrics.frequency_error(f_id[pair[j]], f_true[j]) for j in paired))
        v["damping_error"] = float(max(metrics.damping_error(z_id[pair[j]], z_true[j]) for j in paired))
    d.update(mac=mac, pair=pair, f_id=f_id, f_true=f_true, z_id=z_id, z_true=z_true)

    Mr, Kr, Cr = (np.asarray(truth[k]) for k in ("Mr", "Kr", "Cr"))
    v["Mr_error"] = metrics.relative_error(model.M_, Mr)
    v["Kr_error"] = metrics.relative_error(model.K_, Kr)
    v["Cr_error"] = metrics.relative_error(model.C_, Cr)
    v["MinvK_error"] = metrics.relative_error(np.linalg.solve(model.M_, model.K_), np.linalg.solve(Mr, Kr))
    if np.all(np.isfinite(phi_id)) and np.all(pair >= 0):  # identified modes in paired order
        xo = np.abs(metrics.cross_orthogonality(phi_id[:, pair], phi_true, Mr))
        v["cross_orth"] = float(np.max(xo - np.diag(np.diag(xo)))) if xo.shape[0] > 1 else 0.0
    else:  # identified M not positive definite: no modes to compare
        xo = np.full((data.n_channels, data.n_channels), np.nan)
        v["cross_orth"] = float("nan")
    d.update(M_id=model.M_, K_id=model.K_, C_id=model.C_, Mr=Mr, Kr=Kr, Cr=Cr, cross_orth=xo)

    K3 = getattr(model, "K3_", None)
    v["K3_norm"] = float(np.linalg.norm(K3)) if K3 is not None else 0.0
    if K3 is not None:
        x_ref = clean.x[:, i0:]
        lin = np.linalg.norm(model.K_ @ x_ref)
        v["K3_force_ratio"] = float(np.linalg.norm(K3 @ x_ref**3) / lin) if lin > 0 else float("nan")
    else:
        v["K3_force_ratio"] = 0.0
    k3 = float(np.asarray(truth.get("k3", 0.0)))
    if K3 is not None and k3 != 0.0:
        x_ref = clean.x[:, i0:]
        q0 = np.asarray(truth["cubic_map"]) @ x_ref
        f_true = np.outer(np.asarray(truth["cubic_direction"]), k3 * q0**3)
        f_id = K3 @ x_ref**3
        v["K3_force_error"] = float(np.linalg.norm(f_id - f_true) / np.linalg.norm(f_true))
        d.update(cubic_force_true=f_true, cubic_force_id=f_id)
    return Scores({k: float(x) for k, x in v.items()}, d)


def score_mechanical(dataset: Dataset, data: Measurement, clean: Measurement, model: Any) -> Scores:
    """Joint-angle RMSE of the free simulation, and coefficient and support scores modulo the
    kinematic identities of the loop.

    ``angle_rmse``: the identified model is simulated from the true initial state (the rig's
    ``theta0`` / ``dtheta0``) under the recorded torques for the whole record; the largest
    per-joint RMSE against the recorded noise-free angles (metrics.md).

    Coefficients (:func:`testbed.equation_basis.compare_equations`): on loop-closed data the
    true implicit equations are not unique (the loop constraint and its derivatives times trig
    factors are exact linear identities among the library columns), so the truth
    (``equation_terms`` / ``equation_coef``) and the identified equations are both put in the
    canonical basis of the identifier's library: its columns (plus any true term it lacks) are
    evaluated on the NOISE-FREE reference signals (the scorer's privilege; the identifier never
    sees them), input-free columns dependent on earlier ones (unit-norm residual variance
    <= ``DEPENDENCE_TOL``) are dropped in library order, and dropped columns are substituted by
    their unique expression in the kept ones.  The identifier is not told this basis: the
    scorer adapts the truth to the library.  Rows are paired, both divided by their coefficient
    on the true row's largest term; ``coef_error`` is the largest relative error over the true
    (canonical) terms, ``support_*`` compare the canonical nonzero patterns.  Equal canonical
    forms mean equal equations on the loop manifold; a wrong equation keeps a wrong form.
    """
    from testbed.equation_basis import compare_equations

    def ref(name: str) -> np.ndarray:  # noise-free raw signal (reference if noise was added)
        return np.asarray(dataset.reference.get(name, dataset.measured[name]).data, dtype=float)

    # The true initial state and angles, as recorded by the rig: not the signal chain's estimates,
    # whose end effects would otherwise count against the identifier.
    theta = ref("theta")
    x0 = np.asarray(dataset.truth.get("theta0", theta[:, 0]), dtype=float)
    xd0 = np.asarray(dataset.truth.get("dtheta0", ref("dtheta")[:, 0]), dtype=float)
    t = np.arange(data.n_samples) / data.fs
    sim: Trajectory = model.simulate(x0, xd0, t, data.u)
    rmse = metrics.rmse(theta, sim.x)
    v: dict[str, float] = {"angle_rmse": float(np.max(rmse))}
    d: dict[str, Any] = {"angle_rmse": rmse, "t": t, "simulated_x": sim.x, "reference_x": theta,
                         "channels": data.channels}

    signals = {"th": ref("theta"), "dth": ref("dtheta"), "ddth": ref("ddtheta"), "u": ref("torque")}
    cmp = compare_equations(list(model.feature_names_), np.asarray(model.coef_, dtype=float),
                            list(dataset.truth["equation_terms"]),
                            np.asarray(dataset.truth["equation_coef"], dtype=float), signals)
    v["coef_error"] = float(cmp["coef_error"])
    v["support_precision"], v["support_recall"], v["support_f1"] = (
        float(cmp["precision"]), float(cmp["recall"]), float(cmp["f1"]))
    d.update(terms=cmp["names"], coef_true=cmp["coef_true"], coef_id=cmp["coef_id"],
             coef_errors=cmp["coef_errors"], coef_error_norm=cmp["coef_error_norm"],
             dependent_terms=cmp["dependent"], truth_residual=cmp["truth_residual"])
    return Scores(v, d)
