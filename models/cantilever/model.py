"""A compiled cantilever: MuJoCo model, stepping choice and every truth array.

:func:`build_model` turns validated scenario tables into a :class:`CantileverModel`;
the rig simulates it, the tests and the benchmark reuse it.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from models.cantilever import truth as tr
from models.cantilever.beam import BeamParams, build_mjcf
from models.cantilever.euler_bernoulli import eb_frequencies
from models.cantilever.simulate import Stepping, choose_stepping
from testbed.core.errors import RigError
from testbed.core.lazy import lazy_module
from testbed.core.truth import StructuralTruth

mujoco = lazy_module("mujoco")  # imported on first use: `testbed list` does not pay for it

N_EB = 4  # Euler-Bernoulli frequencies reported


def sensor_positions(rig: dict[str, Any]) -> np.ndarray:
    """Sensor positions [m], shape (n_sensors,): the given list, or L/3, 2L/3, L."""
    if rig["sensors"]:
        return np.asarray(rig["sensors"], float)
    return rig["length"] * np.array([1.0, 2.0, 3.0]) / 3.0


def hit_position(rig: dict[str, Any], excitation: dict[str, Any]) -> float:
    """Impact position [m]: ``excitation.location``, or the tip when it is 0."""
    loc = float(excitation.get("location", 0.0))
    return float(rig["length"]) if loc == 0.0 else loc


def beam_params(rig: dict[str, Any], beta: float = 0.0) -> BeamParams:
    """:class:`BeamParams` from a validated ``[rig]`` table and a damping coefficient [s]."""
    return BeamParams(E=rig["E"], rho=rig["rho"], width=rig["width"], thickness=rig["thickness"],
                      length=rig["length"], n_segments=rig["n_segments"], base=rig["base"],
                      base_k1=rig["base_k1"], base_k3=rig["base_k3"] if rig["base"] == "soft" else 0.0,
                      beta=beta, joint_offset=rig["joint_offset"])


@dataclass
class CantileverModel:
    """The compiled model with its truth (all at the reference pose ``q = 0``).

    Attributes
    ----------
    params : BeamParams
    model : mujoco.MjModel
    xml : str
        The MJCF the model was compiled from.
    stepping : Stepping
    sensors : ndarray, shape (n_s,)
        Sensor positions [m].
    hit : float
        Impact position [m].
    M, C, K : ndarray, shape (n, n)
        Joint-space mass [kg m^2], damping [N m s/rad], stiffness [N m/rad].
    freqs, zetas : ndarray, shape (n,)
        Undamped frequencies [Hz] and damping ratios [-].
    modes : ndarray, shape (n, n)
        Mass-normalised modes (columns).
    Js : ndarray, shape (n_s, n)
        Vertical Jacobian rows of the sensors [m/rad].
    j_hit : ndarray, shape (n,)
        Vertical Jacobian row of the hit point [m/rad].
    red : truth.Serep
        SEREP reduction to the sensors.
    """

    params: BeamParams
    model: mujoco.MjModel
    xml: str
    stepping: Stepping
    sensors: np.ndarray
    hit: float
    M: np.ndarray
    C: np.ndarray
    K: np.ndarray
    freqs: np.ndarray
    zetas: np.ndarray
    modes: np.ndarray
    Js: np.ndarray
    j_hit: np.ndarray
    red: tr.Serep

    @property
    def force_map(self) -> np.ndarray:
        """How the hammer force enters the reduced equations, ``T^T j_hit^T``, shape (n_s,).

        SEREP's Galerkin projection, without the truncated modes' static response that
        :attr:`cubic_direction` adds: the pulse (0.3 ms by default) is not slow against the
        truncated modes, which it excites dynamically, and its quasi-static response
        ``Js R j_hit F(t)`` ends with it.  Written as a load (``+ Kr Js R j_hit``) it would drive
        the kept modes with a spurious impulse: the linear free decay after the pulse, exact
        with ``T^T j_hit`` (band error against MuJoCo 5e-5 on the default clamped beam),
        would be off by 0.8-2.3 % (soft base, ``k3 = 0``: 0.06-0.2 % -> 0.3-1.1 %).  On the
        exact signals of ``cantilever_soft_impact`` the residual within the pulse is 0.68 x
        the linear force with either map (0.69 with the correction): what the sensors read
        there is the truncated modes' dynamic response, which no static term describes.
        """
        return self.red.T.T @ self.j_hit

    @property
    def cubic_direction(self) -> np.ndarray:
        """How the base's cubic moment enters the reduced equations [rad/m], shape (n_s,).

        The full equations carry the base's moment ``k3 theta^3`` on the root joint
        (``theta = e0 . q``): ``M q'' + C q' + K q + e0 k3 theta^3 = j_hit F``.  In modal terms
        ``q = Phi_m eta + Phi_t eta_t``; the cubic moment varies at the kept modes'
        frequencies (and their sums), slowly against the truncated modes (and against the
        kept modes the added load mostly lands on: the highest, see
        :func:`~models.cantilever.truth.truncated_static_load`), so these follow it
        statically, ``Phi_t eta_t = -R e0 g`` with ``g = k3 theta^3`` and ``R`` the
        :func:`~models.cantilever.truth.residual_flexibility` beyond the ``m`` sensed modes.
        The sensors read ``u = Pa eta + s``, ``s = -Js R e0 g``.  The kept modes obey
        ``eta'' + Z eta' + Omega_m^2 eta = -Phi_m^T e0 g``; with ``eta = Pa^-1 (u - s)`` and
        ``Pa^-T`` applied, ``Mr u'' + Cr u' + Kr u + d g = Mr s'' + Cr s'`` with

        ``d = T^T e0 + Kr Js R e0``

        (:func:`~models.cantilever.truth.truncated_static_load`).  SEREP's ``T^T e0`` alone
        (the Galerkin projection) leaves the sensors' share of the truncated modes' static
        response out.  First order in the cubic: the argument is taken as ``c . u`` with
        ``c = T^T e0`` (:attr:`truth`'s ``cubic_map``), while ``theta = c . u - rho g``,
        ``rho = e0^T R e0 - c^T Js R e0`` (the base's own residual flexibility seen from the
        sensors; not a cubic of ``c . u``, so not the scorer's form).  Measured on the exact
        (MuJoCo) signals of ``cantilever_soft_impact`` from 200 samples after the pulse, as
        ``||Mr^-1 r|| / ||Mr^-1 d g||``: 0.296 with ``T^T e0``, 0.031 with ``d``; the
        neglected ``rho`` term takes it to 0.002, ``Mr s'' + Cr s'`` is 0.004 of the cubic
        force (docs/known-gaps.md, "The soft base's cubic truth, corrected").
        """
        e0 = np.zeros(self.K.shape[0])
        e0[0] = 1.0  # the root (base) joint
        R = tr.residual_flexibility(self.K, self.modes, len(self.sensors))
        return self.red.T.T @ e0 + tr.truncated_static_load(self.red.Kr, self.Js, R, e0)

    @property
    def k3(self) -> float:
        """Cubic base stiffness [N m/rad^3] (0 for a stiff base)."""
        return float(self.params.base_k3) if self.params.base == "soft" else 0.0

    def truth(self) -> tuple[dict[str, Any], dict[str, str]]:
        """Truth arrays and their units, as stored in ``Dataset.truth``: the fields of a
        :class:`~testbed.core.truth.StructuralTruth` (units in the hinge angles' terms)."""
        p, red = self.params, self.red
        e0_row = red.T[0]  # e0^T T: root (base) joint angle per unit sensor displacement
        eb_clamped = eb_frequencies(p.E, p.width * p.thickness**3 / 12, p.mass_per_length,
                                    p.length, N_EB)
        eb = eb_clamped if p.base == "stiff" else eb_frequencies(
            p.E, p.width * p.thickness**3 / 12, p.mass_per_length, p.length, N_EB, k_r=p.base_k1)
        joint_x, _ = p.hinges()
        t = StructuralTruth(**{
            "M": self.M, "C": self.C, "K": self.K,
            "frequencies_hz": self.freqs,
            "damped_frequencies_hz": tr.damped_frequencies(self.freqs, self.zetas),
            "damping_ratios": self.zetas,
            "modes": self.modes,
            "sensor_modes": red.Pa,
            "Mr": red.Mr, "Cr": red.Cr, "Kr": red.Kr, "T": red.T,
            "k3": np.float64(self.k3),
            "cubic_direction": self.cubic_direction,
            "cubic_map": e0_row.copy(),
            "force_map": self.force_map,
            "beta": np.float64(p.beta),
            "eb_frequencies_hz": eb,
            "eb_frequencies_clamped_hz": eb_clamped,
            "sensor_positions": self.sensors,
            "joint_positions": joint_x,
        }).to_dict()
        units = {
            "M": "kg m^2", "C": "N m s/rad", "K": "N m/rad", "frequencies_hz": "Hz",
            "damped_frequencies_hz": "Hz", "damping_ratios": "", "modes": "rad/sqrt(kg m^2)",
            "sensor_modes": "m/sqrt(kg m^2)", "Mr": "kg", "Cr": "N s/m", "Kr": "N/m", "T": "rad/m",
            "k3": "N m/rad^3", "cubic_direction": "rad/m", "cubic_map": "rad/m", "force_map": "",
            "beta": "s", "eb_frequencies_hz": "Hz", "eb_frequencies_clamped_hz": "Hz",
            "sensor_positions": "m", "joint_positions": "m",
        }
        return t, units


def _compile(params: BeamParams, sensors: np.ndarray, hit: float, stepping: Stepping,
             gravity: bool) -> tuple[mujoco.MjModel, str]:
    xml = build_mjcf(params, sensors, hit, timestep=stepping.timestep,
                     integrator=stepping.integrator, gravity=gravity)
    return mujoco.MjModel.from_xml_string(xml), xml


def check_mode_one_rings(f1: float, rig: dict[str, Any], simulation: dict[str, Any]) -> None:
    """Refuse a soft base whose mode 1 (the base's own) completes less than one period in the
    record.

    The damping is sized on mode 1 (``beta = 2 zeta_1 / omega_1``), and on a soft base
    ``base_k1`` alone sets it: ``base_k1 = 5e-324`` put mode 1 at 2e-162 Hz, ``beta`` at
    4.3e158 s and every other mode 1e161-1e162 times critically damped, simulated in silence
    with numpy's overflow warnings after its result (round 13).  An impact record shorter than
    mode 1's period cannot show that mode either.  A clamped beam's mode 1 is set by its
    geometry and material, whose own bounds hold it; its short records stay scored (round 3's
    0.01 s record, 0.83 periods of mode 1: a scored failure, mode 1 off 5.6 %).

    Parameters
    ----------
    f1 : float
        Mode 1's undamped frequency [Hz].
    rig, simulation : dict
        The validated tables.

    Raises
    ------
    RigError
        Naming ``rig.base_k1``.
    """
    duration = float(simulation["duration"])
    if rig["base"] != "soft" or (math.isfinite(f1) and f1 * duration >= 1.0):
        return
    raise RigError(f"cantilever: mode 1 at {f1:.3g} Hz (a soft base of base_k1 = "
                   f"{rig['base_k1']:g} N m/rad) completes less than one period in the "
                   f"{duration:g} s record; allowed: a base_k1 that puts mode 1 at or above "
                   f"1 / duration = {1.0 / duration:.3g} Hz",
                   key="rig.base_k1", value=rig["base_k1"])


def build_model(rig: dict[str, Any], simulation: dict[str, Any],
                excitation: dict[str, Any]) -> CantileverModel:
    """Compile the beam of validated scenario tables and compute its truth.

    The mass matrix does not depend on damping or timestep, so a first compile
    gives ``M``; from it the damping coefficient ``beta = 2 zeta_1 / omega_1``
    (unless ``damping_beta`` is given) and the stepping follow, and the final
    model is compiled with them.
    """
    sensors = sensor_positions(rig)
    hit = hit_position(rig, excitation)
    gravity = simulation["gravity"] == "removed"
    probe = Stepping("RK4", 1e-5, 1)
    params0 = beam_params(rig)
    model0, _ = _compile(params0, sensors, hit, probe, gravity)
    M = tr.mass_matrix(model0)
    K = np.diag(params0.hinges()[1])
    f0, _, _ = tr.modal(M, K, 0.0)
    check_mode_one_rings(float(f0[0]), rig, simulation)  # before beta = 2 zeta_1 / omega_1
    beta = rig["damping_beta"] or 2.0 * rig["damping_ratio"] / (2.0 * math.pi * f0[0])
    params = dataclasses.replace(params0, beta=float(beta))
    C = beta * K
    stepping = choose_stepping(M, C, K, simulation["sample_rate"], simulation["integrator"],
                               simulation["timestep"])
    model, xml = _compile(params, sensors, hit, stepping, gravity)
    freqs, zetas, modes = tr.modal(M, K, beta)
    names = [f"s{i + 1}" for i in range(len(sensors))]
    Js = tr.vertical_jacobian(model, names)
    j_hit = tr.vertical_jacobian(model, ["hit"])[0]
    red = tr.serep(M, C, K, Js, modes)
    return CantileverModel(params=params, model=model, xml=xml, stepping=stepping, sensors=sensors,
                           hit=hit, M=M, C=C, K=K, freqs=freqs, zetas=zetas, modes=modes, Js=Js,
                           j_hit=j_hit, red=red)
