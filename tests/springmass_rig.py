"""A third rig from outside the project: a two-mass spring chain in MuJoCo (kind "structural").

::

    wall --[k1, c1]-- m1 --[k2, c2]-- m2 <-- F(t)   (impulse on mass 2)

Two bodies slide along the world x axis: body 1 on a slide joint ``q1`` (its displacement
from rest [m]), body 2 nested in body 1 on a slide joint ``q2`` (the spring 2 elongation
``x2 - x1`` [m]).  MuJoCo's joint stiffness and damping act on each joint coordinate, so
joint 1 is the spring and damper to the wall and joint 2 the pair between the masses.
Damping is stiffness-proportional, ``c_i = beta k_i``, so the modes are classical.

Measured (what a lab records): accelerometers on both masses (the x component of MuJoCo's
``accelerometer`` sensors) and the force on mass 2, with the masses' rest positions along x
so the structural signal chain can place the force at the sensor of mass 2.

Truth (:class:`testbed.core.truth.StructuralTruth`), from the engine: the joint-space mass
matrix ``mj_fullM``, the joints' ``jnt_stiffness`` and ``dof_damping`` and the sensor sites'
x Jacobians ``Js`` (mass displacements ``x = Js q``) give ``M, C, K`` in the mass
displacements, ``M_x = Js^-T M_q Js^-1`` (likewise C, K).  The sensors are the coordinates,
so the reduced matrices equal the full ones and ``T`` is the identity.  The test checks
them against the independent derivation ``diag(m1, m2)`` and the chain stiffness
``[[k1 + k2, -k2], [-k2, k2]]``.

Registered as ``springmass`` when imported: load it with
``testbed.pipeline.plugins.load_plugins(["tests.springmass_rig"])``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any, ClassVar

import mujoco
import numpy as np
import scipy.linalg as sla

from models import RIGS
from models._base import ErrorFn, Rig
from testbed.core.dataset import Dataset, Signal
from testbed.core.schema import Field
from testbed.core.truth import StructuralTruth

_POS = {"min": 0.0, "min_inclusive": False}
#: Rest positions of the masses along x [m] (where their accelerometers sit).
X_REST = (0.1, 0.2)
#: RK4 steps per output sample.  At the defaults the fastest mode (71 Hz) turns by
#: omega dt = 2 pi 71 / (8192 * 8) = 0.0068 rad per step: RK4's relative frequency error is
#: of order (omega dt)^4 / 120 ~ 2e-11, far below anything the test resolves.
SUBSTEPS = 8


def half_sine(peak: float, duration: float, start: float) -> Callable[[np.ndarray], np.ndarray]:
    """Force [N] of a half-sine pulse of ``peak`` [N] lasting ``duration`` [s] from ``start`` [s]."""

    def force(t: np.ndarray) -> np.ndarray:
        t = np.asarray(t, dtype=float)
        on = (t >= start) & (t <= start + duration)
        return np.where(on, peak * np.sin(np.pi * (t - start) / duration), 0.0)

    return force


def build_mjcf(rig: dict[str, Any], timestep: float) -> str:
    """MJCF of the chain (no gravity: the masses slide horizontally)."""
    c1, c2 = rig["beta"] * rig["k1"], rig["beta"] * rig["k2"]
    return f"""
<mujoco model="springmass">
  <option timestep="{timestep!r}" integrator="RK4" gravity="0 0 0"/>
  <worldbody>
    <body name="mass1" pos="{X_REST[0]} 0 0">
      <joint name="q1" type="slide" axis="1 0 0" stiffness="{rig['k1']!r}" damping="{c1!r}"/>
      <inertial pos="0 0 0" mass="{rig['m1']!r}" diaginertia="1e-4 1e-4 1e-4"/>
      <site name="s1"/>
      <body name="mass2" pos="{X_REST[1] - X_REST[0]} 0 0">
        <joint name="q2" type="slide" axis="1 0 0" stiffness="{rig['k2']!r}" damping="{c2!r}"/>
        <inertial pos="0 0 0" mass="{rig['m2']!r}" diaginertia="1e-4 1e-4 1e-4"/>
        <site name="s2"/>
      </body>
    </body>
  </worldbody>
  <sensor>
    <accelerometer name="acc1" site="s1"/>
    <accelerometer name="acc2" site="s2"/>
  </sensor>
</mujoco>"""


def engine_truth(model: mujoco.MjModel) -> StructuralTruth:
    """The chain's exact truth in mass displacements, from the compiled model at rest.

    Returns
    -------
    StructuralTruth
        ``M, C, K`` [kg, N s/m, N/m] (shape (2, 2)), the undamped frequencies [Hz], the
        damping ratios ``beta omega / 2`` of the classical damping ``C = beta K``, the
        mass-normalised modes [m / sqrt(kg)] (signed so each column's largest entry is
        positive), the same at the sensors, and the reduced matrices (= the full ones).
    """
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    Mq = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, data, Mq)
    Js = np.zeros((2, model.nv))
    jac = np.zeros((3, model.nv))
    for i, site in enumerate(("s1", "s2")):
        mujoco.mj_jacSite(model, data, jac, None, model.site(site).id)
        Js[i] = jac[0]
    Ji = np.linalg.inv(Js)  # q = Ji x
    sym = lambda a: 0.5 * (a + a.T)  # noqa: E731 - remove round-off asymmetry only
    M = sym(Ji.T @ Mq @ Ji)
    K = sym(Ji.T @ np.diag(model.jnt_stiffness) @ Ji)
    C = sym(Ji.T @ np.diag(model.dof_damping) @ Ji)
    lam, phi = sla.eigh(K, M)
    phi = phi * np.sign(phi[np.argmax(np.abs(phi), axis=0), np.arange(phi.shape[1])])
    omega = np.sqrt(lam)
    beta = model.dof_damping[0] / model.jnt_stiffness[0]
    return StructuralTruth(M=M, C=C, K=K, frequencies_hz=omega / (2 * np.pi),
                           damping_ratios=beta * omega / 2, modes=phi, sensor_modes=phi.copy(),
                           Mr=M.copy(), Cr=C.copy(), Kr=K.copy(), T=np.eye(2),
                           beta=np.float64(beta), sensor_positions=np.array(X_REST))


TRUTH_UNITS = {"M": "kg", "C": "N s/m", "K": "N/m", "frequencies_hz": "Hz", "damping_ratios": "",
               "modes": "m/sqrt(kg)", "sensor_modes": "m/sqrt(kg)", "Mr": "kg", "Cr": "N s/m",
               "Kr": "N/m", "T": "m/m", "beta": "s", "sensor_positions": "m"}


@RIGS.register("springmass", tags=("structural", "mujoco", "test"))
class SpringMassChain(Rig):
    """Two masses on springs and dampers in a chain, struck on mass 2 (see the module docs)."""

    name: ClassVar[str] = "springmass"
    kind: ClassVar[str] = "structural"
    rig_schema: ClassVar[dict[str, Field]] = {
        "m1": Field(float, 1.0, unit="kg", doc="mass 1 (next to the wall)", **_POS),
        "m2": Field(float, 0.5, unit="kg", doc="mass 2 (struck)", **_POS),
        "k1": Field(float, 1e5, unit="N/m", doc="spring wall - mass 1", **_POS),
        "k2": Field(float, 5e4, unit="N/m", doc="spring mass 1 - mass 2", **_POS),
        "beta": Field(float, 9e-5, unit="s", min=0.0,
                      doc="stiffness-proportional damping: c_i = beta k_i"),
    }
    simulation_schema: ClassVar[dict[str, Field]] = {
        "duration": Field(float, 1.0, unit="s", doc="record length", **_POS),
        "sample_rate": Field(float, 8192.0, unit="Hz", doc="output sample rate", **_POS),
    }
    excitation_schemas: ClassVar[dict[str, dict[str, Field]]] = {
        "impulse": {
            "peak_force": Field(float, 100.0, unit="N", doc="peak of the half-sine force on mass 2"),
            "pulse_duration": Field(float, 1e-3, unit="s", doc="length of the pulse", **_POS),
            "start": Field(float, 0.01, unit="s", min=0.0, doc="start of the pulse"),
        },
    }
    default_excitation: ClassVar[str] = "impulse"
    measured_signals: ClassVar[tuple[str, ...]] = ("acceleration", "force")
    noisy_signals: ClassVar[tuple[str, ...]] = ("acceleration",)

    @classmethod
    def check(cls, rig: dict[str, Any], simulation: dict[str, Any], excitation: dict[str, Any],
              error: ErrorFn) -> None:
        end = excitation["start"] + excitation["pulse_duration"]
        if not end < simulation["duration"]:
            error("excitation.start", excitation["start"],
                  f"the pulse must end within the record ({simulation['duration']:g} s)")

    @classmethod
    def measurement_shape(cls, rig: dict[str, Any]) -> tuple[int, int]:
        return 2, 1

    def simulate(self, progress: Callable[[float], None] | None = None) -> Dataset:
        sc = self.scenario
        fs = float(sc.simulation["sample_rate"])
        n = round(sc.simulation["duration"] * fs)
        dt = 1.0 / (fs * SUBSTEPS)
        model = mujoco.MjModel.from_xml_string(build_mjcf(sc.rig_params, dt))
        data = mujoco.MjData(model)
        exc = sc.excitation
        force = half_sine(exc["peak_force"], exc["pulse_duration"], exc["start"])
        body2 = model.body("mass2").id
        acc, pos, vel = (np.zeros((2, n)) for _ in range(3))
        x_rest = np.array(X_REST)
        for k in range(n):
            t = k / fs
            data.xfrc_applied[body2, 0] = force(t)
            mujoco.mj_forward(model, data)  # sensors at the sample's state and force
            acc[:, k] = data.sensordata[[0, 3]]
            pos[:, k] = data.site_xpos[[model.site("s1").id, model.site("s2").id], 0] - x_rest
            vel[:, k] = [data.qvel[0], data.qvel[0] + data.qvel[1]]
            for j in range(SUBSTEPS):  # the force held at each step's midpoint
                data.xfrc_applied[body2, 0] = force(t + (j + 0.5) * dt)
                mujoco.mj_step(model, data)
            if progress is not None and k % 512 == 0:
                progress(k / n)
        t = np.arange(n) / fs
        truth = engine_truth(model)
        return Dataset(
            fs=fs,
            measured={"acceleration": Signal(acc, ("acc1", "acc2"), "m/s^2", x_rest),
                      "force": Signal(force(t)[None, :], ("force",), "N", x_rest[1:])},
            reference={"displacement": Signal(pos, ("disp1", "disp2"), "m", x_rest),
                       "velocity": Signal(vel, ("vel1", "vel2"), "m/s", x_rest),
                       "acceleration": Signal(acc.copy(), ("acc1", "acc2"), "m/s^2", x_rest)},
            truth=truth.to_dict(), truth_units=dict(TRUTH_UNITS),
            prior={"total_mass": float(np.trace(truth.M)),
                   "reduced_mass_trace": float(np.trace(truth.Mr))},
            attrs={"integrator": "RK4", "timestep": dt, "substeps": SUBSTEPS})
