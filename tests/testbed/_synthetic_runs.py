"""Synthetic RunResults (cantilever-like and five-bar-like) and sweep rows for the report tests.

They carry every field the real pipeline fills, with known numbers, so that the
run store, the figures and the report can be tested without the rigs and identifiers.
Test modules import it after putting this folder on ``sys.path`` (tests are not a package).
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.linalg import eigh

from testbed.core.dataset import Dataset, Signal
from testbed.core.measurement import Measurement
from testbed.pipeline.scenario import Scenario
from testbed.scoring.run import RunResult
from testbed.scoring.scorers import Scores, check_thresholds
from testbed.studies.runstore import load_run, save_run


class FakeIdentifier:
    """Stands for a fitted identifier: learned attributes end in ``_``."""

    kind = "structural"

    def __init__(self, learning_rate: float = 1e-3, epochs: int = 40) -> None:
        self.learning_rate = learning_rate
        self.epochs = epochs

    def get_params(self) -> dict[str, Any]:
        return {"learning_rate": self.learning_rate, "epochs": self.epochs}

    def equations(self, precision: int = 4) -> list[str]:
        if self.kind == "mechanical":  # as long as the five-bar's: one line must wrap on the page
            return [f"0 = +1*ddth{i + 1}" + "".join(f" +0.5455*cos(th{i + 1}-th2)*sin(th2-th3)*ddth{k}"
                                                    for k in range(20)) for i in range(2)]
        return [f"eq {i}: xdd{i} = ..." for i in range(2)]


def _structural_system(n: int = 3) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    M = np.diag(np.full(n, 0.2))
    K = 4e4 * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    K[-1, -1] = 4e4
    C = 1e-4 * K + 0.5 * M
    return M, C, K


def structural_result(n_samples: int = 4000, fs: float = 4000.0) -> RunResult:
    """A 3-sensor cantilever-like run with an SGD-SINDy-like history."""
    M, C, K = _structural_system()
    w2, phi = eigh(K, M)
    f = np.sqrt(w2) / (2 * np.pi)
    zeta = np.array([0.5 * (1e-4 * w + 0.5 / w) for w in np.sqrt(w2)])
    t = np.arange(n_samples) / fs
    q = np.array([np.exp(-z * 2 * np.pi * fi * t) * np.sin(2 * np.pi * fi * t) / (k + 1)
                  for k, (fi, z) in enumerate(zip(f, zeta, strict=True))])
    acc = phi @ q * 50.0
    rng = np.random.default_rng(0)
    scenario = Scenario(name="cantilever_synthetic", rig="cantilever", seed=1,
                        rig_params={"length": 0.5, "width": 0.02, "base": "stiff", "base_k1": 2000.0,
                                    "base_k3": 2.5e9, "sensors": []},
                        excitation={"type": "impact", "peak_force": 50.0, "location": 0.0},
                        noise={"rms_percent": 1.0, "signals": ["acceleration"]},
                        signal={"highpass_hz": 10.0, "lowpass_hz": 0.0},
                        identify={"method": "sgd_sindy", "learning_rate": 1e-3, "epochs": 40},
                        score={"trac": {"min": 0.9}, "freq_error": {"max": 0.01}})
    pos = np.array([0.1, 0.3, 0.5])
    ds = Dataset(fs, {"acceleration": Signal(acc + 0.01 * rng.standard_normal(acc.shape),
                                             ("acc1", "acc2", "acc3"), "m/s^2", pos),
                      "force": Signal(np.where(t < 1e-3, 10.0, 0.0), ("force",), "N", pos[-1:])},
                 {"acceleration": Signal(acc, ("acc1", "acc2", "acc3"), "m/s^2", pos)},
                 {"M": M, "C": C, "K": K, "modes": phi, "frequencies_hz": f, "eb_frequencies_hz": f * 1.01,
                  "damping_ratios": zeta, "sensor_modes": phi, "Mr": M, "Kr": K, "Cr": C, "k3": 1e9,
                  "cubic_map": np.array([1.0, 0, 0]), "cubic_direction": np.array([1.0, 0, 0])},
                 {"frequencies_hz": "Hz", "Mr": "kg", "Kr": "N/m", "Cr": "N s/m", "k3": "N/m^3"},
                 {"total_mass": 0.6}, {"rig": "cantilever", "seed": 1, "content_hash": "ab" * 32})
    model = FakeIdentifier()
    model.M_, model.C_, model.K_ = M * 1.02, C, K * 0.99
    model.K3_ = np.diag([9e8, 0, 0])
    model.natural_frequencies_ = f * 1.005
    epochs = 40
    model.history_ = {"alpha": {"freq": np.linspace(1, 5, epochs).tolist(),
                                "mass": np.geomspace(1, 0.1, epochs).tolist()},
                      "loss": np.geomspace(10, 0.5, epochs).tolist()}
    sim = acc * 0.98
    w2i, phii = eigh(model.K_, model.M_)
    mac = np.abs(phii.T @ phi) ** 2 / np.outer(np.sum(phii**2, 0), np.sum(phi**2, 0))
    pair = np.arange(3)
    f_id = np.sqrt(w2i) / (2 * np.pi)
    values = {"trac": 0.97, "mac": float(np.min(np.diag(mac)[:2])),
              "freq_error": float(np.max(np.abs(f_id[:2] / f[:2] - 1))), "damping_error": 0.2,
              "Mr_error": 0.02, "Kr_error": 0.01, "Cr_error": 0.0, "MinvK_error": 0.03,
              "K3_norm": 9e8, "K3_force_error": 0.1, "cross_orth": 0.02}
    details = {"trac": np.array([0.99, 0.98, 0.97]), "t": t, "simulated_xdd": sim, "reference_xdd": acc,
               "channels": ("acc1", "acc2", "acc3"), "mac": mac, "pair": pair, "f_id": f_id, "f_true": f,
               "z_id": zeta * 1.1, "z_true": zeta, "M_id": model.M_, "K_id": model.K_, "C_id": model.C_,
               "Mr": M, "Kr": K, "Cr": C, "cross_orth": np.eye(3)}
    data = Measurement(fs, acc, acc, acc, ("acc1", "acc2", "acc3"))
    scores = Scores(values, details)
    return RunResult(scenario, ds, data, model, scores, check_thresholds(values, scenario.score), 1.25)


def mechanical_result(n_samples: int = 2000, fs: float = 200.0) -> RunResult:
    """A five-bar-like run: four joint angles, two torques, implicit equations."""
    t = np.arange(n_samples) / fs
    th = np.array([0.5 * np.sin(2 * np.pi * (k + 1) * 0.2 * t) + k for k in range(4)])
    tau = np.array([np.sin(2 * np.pi * 0.5 * t), np.cos(2 * np.pi * 0.5 * t)])
    terms = ["ddth1", "ddth2", "cos(th1-th2)*ddth2", "u1", "dth1"]
    coef_true = np.array([[1.0, 0.0, 0.5, -1.0, 0.1], [0.0, 1.0, 0.5, 0.0, 0.1]])
    coef_id = coef_true * 1.03
    coef_id[0, 1] = 0.01
    scenario = Scenario(name="fivebar_synthetic", rig="fivebar", seed=0,
                        rig_params={"link_lengths": [1.0, 1.0, 1.0, 1.0], "link_mass": 1.0},
                        identify={"method": "sindy_pi", "threshold": 0.05},
                        score={"angle_rmse": {"max": 0.0501}, "support_f1": {"min": 0.9}})
    ds = Dataset(fs, {"angles": Signal(th, ("th1", "th2", "th3", "th4"), "rad"),
                      "torques": Signal(tau, ("tau1", "tau2"), "N m")},
                 {"angles": Signal(th, ("th1", "th2", "th3", "th4"), "rad")},
                 {"equation_terms": terms, "equation_coef": coef_true}, {"equation_coef": ""},
                 {}, {"rig": "fivebar", "seed": 0})
    model = FakeIdentifier()
    model.kind = "mechanical"
    model.coef_, model.feature_names_ = coef_id, terms
    sim = th + 0.02 * np.sin(7 * t)
    values = {"angle_rmse": 0.0141, "coef_error": 0.03, "support_precision": 0.86, "support_recall": 1.0,
              "support_f1": 0.92}
    details = {"angle_rmse": np.full(4, 0.0141), "t": t, "simulated_x": sim, "reference_x": th,
               "channels": ("th1", "th2", "th3", "th4"), "terms": terms, "coef_true": coef_true,
               "coef_id": coef_id, "coef_errors": np.array([0.03, 0.03])}
    data = Measurement(fs, th, th, th, ("th1", "th2", "th3", "th4"), tau, ("tau1", "tau2"))
    return RunResult(scenario, ds, data, model, Scores(values, details),
                     check_thresholds(values, scenario.score), 0.4)


def sweep_rows() -> list[dict[str, Any]]:
    """Results-schema rows (:mod:`testbed.studies.results`): 2 identifiers x 3 noise levels x 2 seeds."""
    rows = []
    for ident, base in (("sindy_ls", 0.9), ("sgd_sindy", 0.97)):
        for noise in (0.0, 1.0, 5.0):
            for seed in (0, 1):
                trac = base - 0.01 * noise - 0.005 * seed
                ok = ident != "sindy_ls" or noise < 5
                rows.append({"study": "noise_study", "cell": f"{ident}-{noise}-{seed}",
                             "scenario": "cantilever_synthetic", "rig": "cantilever", "noise": noise,
                             "seed": seed, "identifier": ident, "status": "ok" if ok else "error",
                             "error": "" if ok else "LinAlgError: singular matrix",
                             "fit_time": 0.1 + (2.0 if ident == "sgd_sindy" else 0.0) + 0.01 * seed,
                             "passed": trac >= 0.9 if ok else False, "trac": trac if ok else float("nan"),
                             "freq_error": 0.001 * (1 + noise) if ok else float("nan"),
                             "checks": '[{"metric": "trac", "bound": "min", "threshold": 0.9}]',
                             "versions": '{"numpy": "2"}', "commit": "abc123", "dataset_hash": "ff" * 8})
    return rows



def study_rows() -> list[dict[str, Any]]:
    """A richer study: two cantilever scenarios and a five-bar one, 3 noise levels x 3 seeds.

    ``ls_sindy`` and ``sgd_sindy`` on the cantilevers (TRAC falls with noise; ``ls_sindy``
    fails to run once, at 5 % noise, seed 2, on ``cantilever_b``), ``sindy_pi`` on the
    five-bar (angle RMSE from 1e-6 to 1e-2 rad: a log axis).  Thresholds: TRAC >= 0.9 on both
    cantilevers, angle RMSE <= 0.0501 rad on the five-bar.
    """
    rows = []
    cant = '[{"metric": "trac", "value": %r, "bound": "min", "threshold": 0.9, "passed": %s}]'
    five = '[{"metric": "angle_rmse", "value": %r, "bound": "max", "threshold": 0.0501, "passed": %s}]'
    for scenario, rig in (("cantilever_a", "cantilever"), ("cantilever_b", "cantilever"),
                          ("fivebar_x", "fivebar")):
        idents = ("sindy_pi",) if rig == "fivebar" else ("ls_sindy", "sgd_sindy")
        for ident in idents:
            for noise in (0.0, 1.0, 5.0):
                for seed in (0, 1, 2):
                    ok = not (scenario == "cantilever_b" and ident == "ls_sindy" and noise == 5.0
                              and seed == 2)
                    row: dict[str, Any] = {
                        "study": "method_comparison", "cell": f"{scenario}-{ident}-{noise}-{seed}",
                        "scenario": scenario, "rig": rig, "noise": noise, "seed": seed,
                        "identifier": ident, "params": "{}", "status": "ok" if ok else "failed",
                        "error": "" if ok else "LinAlgError: singular matrix (identify/ls.py:42)",
                        "fit_time": 0.05 + 0.01 * seed + (1.0 if ident == "sgd_sindy" else 0.0),
                        "data_time": 0.01, "cell_time": 0.2, "versions": "{}", "commit": "abc123",
                        "dataset_hash": "ff" * 8}
                    nan = float("nan")
                    if rig == "cantilever":
                        trac = (0.99 if ident == "sgd_sindy" else 0.97) - 0.02 * noise - 0.002 * seed
                        row.update(trac=trac if ok else nan, angle_rmse=nan,
                                   freq_error=(0.001 * (1 + noise) * (1 + seed)) if ok else nan,
                                   K3_norm=0.0 if ok else nan, passed=ok and trac >= 0.9,
                                   checks=cant % (trac, "true" if trac >= 0.9 else "false"))
                    else:
                        rmse = {0.0: 1e-6, 1.0: 1e-4, 5.0: 1e-2}[noise] * (1 + 0.5 * seed)
                        row.update(trac=nan, angle_rmse=rmse, freq_error=nan, K3_norm=nan,
                                   passed=rmse <= 0.0501,
                                   checks=five % (rmse, "true" if rmse <= 0.0501 else "false"))
                    rows.append(row)
    return rows


def saved_runs(folder) -> dict[str, Any]:
    """One small structural and one mechanical run, each saved under ``folder`` and read back
    (``load_run``): what the figure tests draw, shape for shape as a real run's."""
    return {k: load_run(save_run(f(), folder / k))
            for k, f in (("structural", lambda: structural_result(n_samples=1000)),
                         ("mechanical", lambda: mechanical_result(n_samples=400)))}
