"""A fourth rig kind from outside the project: a lumped thermal mass, kind "thermal".

::

    C T' = P(t) - (T - T_amb) / R        (heat capacity C [J/K], resistance R [K/W])

Everything a kind needs is declared here, through the public registries only: its typed truth
(``register_truth``), its score catalogue (``KIND_METRICS``), its signal chain
(``register_signal_chain``), its scorer (``register_scorer``), a rig (``RIGS``) and an
identifier (``IDENTIFIERS``).  The rig integrates the equation exactly (zero-order-hold
heating power: the exponential of the one-state system), so its truth ``R, C`` is exact.
Registered when imported: ``testbed.load_plugins(["tests.thermal_kind"])``.
"""

# ruff: noqa: RUF009  (truth_field returns a dataclasses.field with metadata, not a default value)
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from testbed import (
    IDENTIFIERS,
    KIND_METRICS,
    RIGS,
    Dataset,
    Field,
    Identifier,
    Measurement,
    Rig,
    Scores,
    Signal,
    SignalChain,
    Trajectory,
    Truth,
    register_scorer,
    register_signal_chain,
    register_truth,
    truth_field,
)

KIND = "thermal"


@register_truth
@dataclass(frozen=True)
class ThermalTruth(Truth):
    """Truth of a thermal rig: ``C T' = P - (T - T_amb) / R``."""

    kind: ClassVar[str] = KIND
    R: np.ndarray = truth_field((), "K/W", "thermal resistance to ambient")
    C: np.ndarray = truth_field((), "J/K", "heat capacity")
    T0: np.ndarray = truth_field((), "K", "initial temperature above ambient")


KIND_METRICS[KIND] = {
    "R_error": "relative error of the identified thermal resistance",
    "C_error": "relative error of the identified heat capacity",
    "temp_rmse": "RMSE [K] of the identified model simulated under the recorded power from the "
                 "true start, against the noise-free temperature",
}


def measure_thermal(dataset: Dataset, cfg: Any) -> Measurement:
    """The measured temperature above ambient [K] and heating power [W]; its rate by
    central differences."""
    x = np.asarray(dataset.measured["temperature"].data, dtype=float)
    u = np.asarray(dataset.measured["power"].data, dtype=float)
    xd = np.gradient(x, 1.0 / dataset.fs, axis=1)
    return Measurement(fs=dataset.fs, x=x, xd=xd, xdd=np.gradient(xd, 1.0 / dataset.fs, axis=1),
                       channels=("T",), u=u, inputs=("P",))


register_signal_chain(SignalChain(KIND, {}, measure_thermal))


def score_thermal(dataset: Dataset, data: Measurement, clean: Measurement, model: Any) -> Scores:
    """Parameter errors and the simulated temperature's RMSE against the noise-free record."""
    truth = dataset.truth_as(ThermalTruth)
    t = np.arange(data.n_samples) / data.fs
    sim = model.simulate(np.array([float(truth.T0)]), None, t, clean.u)
    v = {"R_error": abs(model.R_ - float(truth.R)) / float(truth.R),
         "C_error": abs(model.C_ - float(truth.C)) / float(truth.C),
         "temp_rmse": float(np.sqrt(np.mean((sim.x - clean.x) ** 2)))}
    # the keys a report draws a time response from (docs/rigs.md)
    return Scores(v, {"t": t, "reference_x": clean.x, "simulated_x": sim.x,
                      "channels": data.channels})


register_scorer(KIND, score_thermal)


def exact_response(R: float, C: float, T0: float, power: np.ndarray, fs: float) -> np.ndarray:
    """Temperature above ambient [K] at the samples, power [W] held over each interval."""
    a = np.exp(-1.0 / (fs * R * C))
    T = np.empty(power.size)
    T[0] = T0
    for k in range(1, power.size):
        T[k] = a * T[k - 1] + (1.0 - a) * R * power[k - 1]
    return T


@RIGS.register("thermal_mass", tags=(KIND, "test"))
class ThermalMass(Rig):
    """A lumped thermal mass heated by a square-wave power (see the module docs)."""

    name: ClassVar[str] = "thermal_mass"
    kind: ClassVar[str] = KIND
    rig_schema: ClassVar[dict[str, Field]] = {
        "R": Field(float, 2.0, unit="K/W", min=0.0, min_inclusive=False, doc="resistance"),
        "C": Field(float, 50.0, unit="J/K", min=0.0, min_inclusive=False, doc="heat capacity"),
        "T0": Field(float, 1.0, unit="K", doc="start temperature above ambient"),
    }
    simulation_schema: ClassVar[dict[str, Field]] = {
        "duration": Field(float, 600.0, unit="s", min=0.0, min_inclusive=False, doc="record"),
        "sample_rate": Field(float, 2.0, unit="Hz", min=0.0, min_inclusive=False, doc="rate"),
    }
    excitation_schemas: ClassVar[dict[str, dict[str, Field]]] = {
        "square": {"power": Field(float, 5.0, unit="W", doc="heating power when on"),
                   "period": Field(float, 200.0, unit="s", min=0.0, min_inclusive=False,
                                   doc="on-off period")},
    }
    default_excitation: ClassVar[str] = "square"
    measured_signals: ClassVar[tuple[str, ...]] = ("temperature", "power")
    noisy_signals: ClassVar[tuple[str, ...]] = ("temperature",)

    def simulate(self, progress: Any = None) -> Dataset:
        rig, sim, exc = self.scenario.rig_params, self.scenario.simulation, self.scenario.excitation
        fs = float(sim["sample_rate"])
        t = np.arange(round(sim["duration"] * fs)) / fs
        power = np.where((t % exc["period"]) < exc["period"] / 2, exc["power"], 0.0)
        T = exact_response(rig["R"], rig["C"], rig["T0"], power, fs)
        truth = ThermalTruth(R=np.float64(rig["R"]), C=np.float64(rig["C"]),
                             T0=np.float64(rig["T0"]))
        return Dataset(fs=fs,
                       measured={"temperature": Signal(T[None], ("T",), "K"),
                                 "power": Signal(power[None], ("P",), "W")},
                       truth=truth.to_dict(), truth_units=ThermalTruth.units())


@IDENTIFIERS.register("thermal_least_squares", tags=(KIND, "test"))
class ThermalLeastSquares(Identifier):
    """Least squares of ``T' = a T + b P``, so ``C = 1 / b`` and ``R = -b / a``."""

    name = "thermal_least_squares"
    kind = KIND
    hyperparameters: ClassVar[dict[str, Field]] = {}

    def fit(self, data: Measurement) -> ThermalLeastSquares:
        theta = np.vstack([data.x[0], data.u[0]]).T
        (a, b), *_ = np.linalg.lstsq(theta, data.xd[0], rcond=None)
        self.C_, self.R_ = 1.0 / b, -b / a
        return self

    def simulate(self, x0: np.ndarray, xd0: Any, t: np.ndarray, u: np.ndarray | None = None
                 ) -> Trajectory:
        fs = 1.0 / float(t[1] - t[0])
        x = exact_response(self.R_, self.C_, float(x0[0]), np.asarray(u)[0], fs)[None]
        xd = np.gradient(x, 1.0 / fs, axis=1)
        return Trajectory(x, xd, np.gradient(xd, 1.0 / fs, axis=1))

    def equations(self, precision: int = 4) -> list[str]:
        return [f"{self.C_:.{precision}g} dT = P - T / {self.R_:.{precision}g}"]
