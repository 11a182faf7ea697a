"""The ``cantilever`` rig: a steel beam as a MuJoCo hinge chain, struck by a hammer.

Measured: vertical accelerations at the sensors [m/s^2] and the hammer force [N].
Reference (no lab has them): sensor displacements [m] and velocities [m/s],
noise-free accelerations.  Truth: full joint-space M, C, K, modes, SEREP-reduced
Mr, Cr, Kr at the sensors, the soft base's cubic stiffness and its reduced form,
Euler-Bernoulli frequencies.  See :mod:`models.cantilever.beam` for the
discretisation and :mod:`models.cantilever.simulate` for the timestep.

Default soft-base cubic: the default impact (50 N, 0.3 ms at the tip) turns the
base by about 4e-4 rad at most (measured); ``k3 = 2.5e9 N m/rad^3`` makes the
cubic moment ``k3 q^3`` about 20 % of ``k1 q = 2000 q`` there
(``2.5e9 * (4e-4)^2 / 2000 = 0.2``): clearly measurable, yet a perturbation of
the linear beam (the tests check the measured ratio).

Small angles: the truth is the chain linearised at rest, so a run in which any segment turns
by more than :data:`SMALL_ANGLE_MAX_RAD` from the beam's axis is refused after the rollout
(:func:`check_small_angles`, naming ``excitation.peak_force``): beyond it the exact
kinematics MuJoCo integrates leave more of the record unexplained by the truth than the 1 %
noise the studies score at.

Slender beams only: the chain stands for an Euler-Bernoulli beam (no shear deformation, no
rotary inertia of the sections, one rigid cross-section per segment), so a beam deeper than
:data:`SLENDER_MAX_DEPTH` (0.113) or wider than :data:`SLENDER_MAX_WIDTH` (1) times its length
is refused at load (:func:`_check_slender`, naming the key and the bound).
"""

from __future__ import annotations

import logging
import math
import sys
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np

from models import RIGS
from models._base import MJ_MINVAL, ErrorFn, Rig, check_two_samples, furthest_from_default
from models.cantilever.beam import BeamParams
from models.cantilever.euler_bernoulli import auto_cutoff, clamped_estimates
from models.cantilever.model import (
    CantileverModel,
    beam_params,
    build_model,
    hit_position,
    sensor_positions,
)
from models.cantilever.simulate import (
    IMPLICIT_ACCURACY,
    MUJOCO_MAX_CONTROL,
    RK4_ACCURACY,
    half_sine,
    implicit_accurate,
    implicit_unfit,
    mode_errors,
    rollout_sensors,
    static_equilibrium,
    unstable_modes,
)
from testbed.core.budget import CPU_BUDGET_S, MEMORY_BUDGET_BYTES, SAMPLE_BUDGET, STEP_BUDGET, Cost
from testbed.core.dataset import Dataset, Signal
from testbed.core.errors import RigError
from testbed.core.measurement import nearest_within
from testbed.core.schema import Field

LOG = logging.getLogger(__name__)

#: An impact must land within 1 mm [m] of an accelerometer: the structural signal chain
#: (``testbed.pipeline.signal_chain.IMPACT_TOLERANCE_M``, the same 1 mm; a test keeps them equal) maps
#: the force onto the sensor it hits, because a model in sensor coordinates cannot place a
#: force between sensors.
HIT_SENSOR_TOLERANCE_M = 1e-3

#: Most accelerometers one rigid segment of the chain may carry: a rigid body moving in the
#: plane has two degrees of freedom (the translation and rotation of its hinge), so the
#: readings of a third sensor on it are a fixed combination of the other two, the sensor rows
#: of the mode shapes are dependent and the SEREP reduction at the sensors is singular
#: (measured: sensors 0.30, 0.31, 0.3175 m on the default beam's last segment gave a reduced
#: mass matrix with a zero eigenvalue and the scorer stopped with an internal error).
MAX_SENSORS_PER_SEGMENT = 2

#: A sensor within this fraction of a segment's length outboard of a hinge is counted on the
#: segment inboard of it (:func:`_check_sensors_per_segment`): its lever arm about that hinge is
#: too short for its reading to be told apart.  Measured (review, session 19; the stiff beam in
#: 3 segments, 0.106 m, sensors 0.1 m / hinge 1 + d / L): d = 1e-7 m (1e-6 of a segment) gave a
#: reduction at the sensors of condition 2e33 whose modes were 167 / 1082 / 1212 Hz against 82 /
#: 516 / 1426; d = 1e-6 m (1e-5 of a segment) condition 1.2e11 and its modes within 4.2e-6,
#: inside the scorer's REDUCED_TRUTH_GAP (1e-5).
HINGE_SNAP = 1e-5

#: Largest angle [rad] any segment may turn from the beam's axis (:func:`peak_segment_angle`).
#: The truth (M, C, K, modes, SEREP) is the chain linearised at rest, where ``sin phi = phi``
#: and ``cos phi = 1``; MuJoCo keeps the exact kinematics, whose departure grows as
#: ``phi^2``.  Measured 2026-11-26 (tip impacts 10 N-60 kN): MuJoCo's sensed accelerations
#: depart from the linear truth's response by 0.58-0.77 ``phi^2`` (relative RMS in the sensed
#: band) on four beams: the default one (0.89 % at 0.108 rad, 3.6 % at 0.22 rad, 7.9 % at
#: 0.32 rad, 30 % at 0.65 rad), a 2 mm deep one (0.44 % at 0.082 rad, 4.8 % at 0.27 rad), a
#: 2 m long one (3.7 % at 0.22 rad) and a linear soft base (1.3 % at 0.15 rad).  At 0.1 rad
#: that share is at most 0.77 %, below the 1 % noise the studies score at, and the modes 1-2
#: frequencies move by less than 0.02 %: beyond it the record holds a motion the truth does
#: not describe, so neither a pass nor a failure would be the identifier's.  (0.1 rad is also
#: the textbook small-angle bound: sin within 0.17 %, cos within 0.5 %.)
SMALL_ANGLE_MAX_RAD = 0.1

#: Memory per integration step [bytes]: the hammer force is built for every step before the
#: rollout (the step times, the phase, its clip and the force: about five float64 arrays).
BYTES_PER_STEP = 48
#: Memory per sample and sensor [bytes]: MuJoCo's 9 sensor readings per accelerometer (kept
#: at every sample), the dataset's measured and reference copies (4), the noisy copy, the
#: signal chain's filtered acceleration, velocity and displacement with their intermediates
#: (about 10) and an identifier's library (up to 6 columns per sensor): about 30 float64
#: values, doubled for temporaries.
BYTES_PER_SAMPLE_PER_SENSOR = 512
#: Memory per sample for the force channel and the time axis [bytes] (about 8 float64 arrays).
BYTES_PER_SAMPLE = 64

#: CPU time of one implicitfast step [s] ~ STEP_S_0 + STEP_S_3 * nv^3 (dense factorisation of
#: the nv x nv mass matrix): fitted to 95 us at nv = 100 and 3.8 ms at nv = 400 (measured on
#: the shared 2-core machine, 2026-11-23; 0.55 ms at 200 is predicted within 8 %).
STEP_S_0, STEP_S_3 = 36e-6, 5.9e-11
#: An RK4 step costs this many implicitfast steps (four model evaluations; measured 2.7-2.9).
RK4_STEP_FACTOR = 2.8


def step_seconds(nv: int, integrator: str) -> float:
    """Estimated CPU time [s] of one integration step of a beam with ``nv`` joints."""
    t = STEP_S_0 + STEP_S_3 * nv**3
    return t * RK4_STEP_FACTOR if integrator.upper() == "RK4" else t


def fewest_substeps(simulation: dict[str, Any], nv: int) -> tuple[int, float]:
    """The least work :func:`models.cantilever.simulate.choose_stepping` could choose, from the
    sample rate alone (no model): lower bounds of a run's steps and CPU time per sample.

    A requested ``timestep`` fixes the substeps; under ``auto`` it is integrated with RK4, or
    with implicitfast where RK4 is unstable there and implicitfast meets ``auto``'s rule
    (:func:`models.cantilever.simulate.implicit_unfit`), which from the sample rate alone is
    possible only where ``omega_Ny dt <= IMPLICIT_ACCURACY``: the time bound is then the
    cheaper of the two.  Otherwise each
    integrator needs at least its accuracy limit, ``ceil(pi / RK4_ACCURACY) = 7`` (RK4) or
    ``ceil(pi / IMPLICIT_ACCURACY) = 29`` (implicitfast) steps per sample; stability can only
    ask more.  ``auto`` may take either, so each bound is the smaller over both.

    Parameters
    ----------
    simulation : dict
        Validated ``[simulation]`` table.
    nv : int
        Joints of the chain (segments, plus the base hinge of a soft base).

    Returns
    -------
    (substeps, seconds)
        Fewest integration steps per sample, least CPU time per sample [s].
    """
    period = 1.0 / float(simulation["sample_rate"])
    integrator = simulation["integrator"]
    if simulation["timestep"] > 0:
        # capped before rounding: a subnormal timestep (5e-324 s) makes the ratio inf, which
        # round() cannot take; the budget then refuses the steps by simulation.timestep
        n = max(1, round(min(period / simulation["timestep"], 2**62)))
        integs = [integrator]
        if integrator == "auto":
            # the accuracy half of implicit_unfit (its stability half needs the model)
            fits = implicit_accurate(float(simulation["sample_rate"]), period / n)
            integs = ["RK4", "implicitfast"] if fits else ["RK4"]
        return n, min(n * step_seconds(nv, i) for i in integs)
    options = []
    if integrator in ("auto", "RK4"):
        options.append(("RK4", math.ceil(math.pi / RK4_ACCURACY)))
    if integrator in ("auto", "implicitfast"):
        options.append(("implicitfast", math.ceil(math.pi / IMPLICIT_ACCURACY)))
    return min(n for _, n in options), min(n * step_seconds(nv, i) for i, n in options)


RIG_SCHEMA = {
    "E": Field(float, 210e9, unit="Pa", min=0.0, min_inclusive=False, doc="Young's modulus"),
    "rho": Field(float, 7850.0, unit="kg/m^3", min=0.0, min_inclusive=False, doc="density"),
    "width": Field(float, 0.03, unit="m", min=0.0, min_inclusive=False,
                   doc="cross-section width (along the bending axis); at most the length (a "
                       "beam, not a plate: a wider one has a plate mode below mode 2 that the "
                       "chain cannot hold)"),
    "thickness": Field(float, 0.01, unit="m", min=0.0, min_inclusive=False,
                       doc="cross-section thickness (the bending depth); at most 0.113 x the "
                           "length (a slender beam: deeper, shear and rotary inertia, which the "
                           "Euler-Bernoulli chain neglects, lower mode 1 by over 1 %)"),
    "length": Field(float, 0.3175, unit="m", min=0.0, min_inclusive=False, doc="beam length"),
    # max 400: the finest chain whose 1 s record at the default 12.8 kHz (29 implicitfast
    # substeps of ~3.8 ms, step_seconds) fits the CPU budget with room (1,400 s of 3,600 s);
    # 600 segments would need 4,750 s for that second.  Longer records of a fine chain are
    # refused by the budget (rig.n_segments named) before the model is compiled.
    "n_segments": Field(int, 10, min=2, max=400, doc="rigid segments of the hinge chain"),
    "joint_offset": Field(float, 1.0 / 3.0, min=0.0, max=0.5,
                          doc="first hinge at joint_offset * L / n_segments (1/3 minimises the "
                              "discretisation error; 0 = hinge at the wall, needs a stiff base)"),
    "damping_ratio": Field(float, 0.01, min=0.0, max=1.0, max_inclusive=False,
                           doc="damping ratio of mode 1 (C = beta K, beta = 2 zeta_1 / omega_1)"),
    "damping_beta": Field(float, 0.0, unit="s", min=0.0,
                          doc="stiffness-proportional damping C = beta K; 0 = derive from "
                              "damping_ratio (set damping_ratio = 0 to give this)"),
    "base": Field(str, "stiff", choices=("stiff", "soft"),
                  doc="clamped base, or a base hinge on a nonlinear rotational spring"),
    "base_k1": Field(float, 2000.0, unit="N m/rad", min=0.0, min_inclusive=False,
                     doc="linear stiffness of the soft base spring"),
    "base_k3": Field(float, 2.5e9, unit="N m/rad^3", min=0.0,
                     doc="cubic stiffness of the soft base spring (moment k1 q + k3 q^3)"),
    "sensors": Field(list, [], unit="m", item_type=float, min=0.0, min_inclusive=False,
                     doc="accelerometer positions along the beam; empty = L/3, 2L/3, L"),
}

SIMULATION_SCHEMA = {
    "duration": Field(float, 1.0, unit="s", min=0.0, min_inclusive=False, doc="record length"),
    "sample_rate": Field(float, 12800.0, unit="Hz", min=0.0, min_inclusive=False,
                         doc="sample rate of every signal"),
    "integrator": Field(str, "auto", choices=("auto", "RK4", "implicitfast"),
                        doc="MuJoCo integrator; auto = RK4 while it costs at most twice "
                            "implicitfast, else implicitfast; at a given timestep RK4 where it "
                            "is stable, else implicitfast where stable and accurate "
                            "(models/cantilever/simulate.py)"),
    "timestep": Field(float, 0.0, unit="s", min=0.0,
                      doc="integration step, rounded to sample period / integer; 0 = chosen "
                          "from the model's fastest mode"),
    "gravity": Field(str, "off", choices=("off", "removed"),
                     doc="off = no gravity in the model; removed = gravity on, start at the sagged "
                         "rest pose, static accelerometer reading subtracted"),
}

IMPACT_SCHEMA = {
    "peak_force": Field(float, 50.0, unit="N", min=0.0, min_inclusive=False,
                        doc="peak of the half-sine hammer force (world +z)"),
    "pulse_duration": Field(float, 3e-4, unit="s", min=0.0, min_inclusive=False,
                            doc="half-sine duration (0.3 ms: flat spectrum to ~2 kHz)"),
    "location": Field(float, 0.0, unit="m", min=0.0,
                      doc="impact position along the beam; 0 = the tip"),
    "start": Field(float, 0.005, unit="s", min=0.0, doc="time the pulse begins"),
}


#: The frequency bar [-] a slender beam's neglected physics must stay within on mode 1: the
#: tightest bar any shipped scenario scores a frequency at (``freq_error_mode1_max = 0.01``).
SLENDER_FREQ_BAR = 0.01
#: Deepest beam the Euler-Bernoulli chain stands for, ``thickness / length`` [-]
#: (:func:`_check_slender`).  The chain (and its Euler-Bernoulli truth) neglects shear
#: deformation and the sections' rotary inertia; a real beam of these dimensions (Timoshenko
#: beam, Poisson's ratio 0.3, shear coefficient 5/6 for a rectangle) has its mode 1 lower by
#: ``delta_1 ~ 0.783 (h / L)^2``, which reaches :data:`SLENDER_FREQ_BAR` at ``h / L = 0.113``.
#: Measured 2026-11-28 (a converged Timoshenko finite-element cantilever, 200-1600 elements,
#: checked in ``tests/models/test_cantilever_slender.py``): delta_1 = 0.79 % at h / L = 0.1,
#: 1.0 % at 0.113, 3.0 % at 0.2 (mode 2: 5.1 % at 0.1); the textbook estimate
#: ``(1/2)(1 + E / (kappa G)) (1.875 r / L)^2`` (r = h / sqrt 12) gives 0.60 (h / L)^2, 23 % low
#: for the clamped-free beam.  At Poisson's ratio 0.25 / 0.35 the bound is 0.115 / 0.111.
SLENDER_MAX_DEPTH = 0.113
#: Widest beam the chain stands for, ``width / length`` [-] (:func:`_check_slender`).  The chain
#: holds one rigid cross-section per segment: a section that bends across its width is beyond
#: it.  A cantilever plate's first such mode symmetric about the centre line (excited by the
#: hammer there and read by the sensors there) lies, as a free strip bending across the width,
#: at ``(4.730 / 1.875)^2 / sqrt(1 - nu^2) (L / b)^2 f_1 = 6.67 (L / b)^2 f_1`` (the clamp only
#: stiffens it), which reaches mode 2 (``6.27 f_1``, barred by every shipped scenario) at
#: ``b / L = 1.03``.  Torsion (antisymmetric: neither excited nor read on the centre line) and
#: the plate's Poisson stiffening of mode 1 are not what the bound is set by.  The latter
#: (Kirchhoff plate by Ritz, ``tests/models/test_cantilever_slender.py``) is +0.65 % on the
#: shipped beam (b / L 0.0945), +1.5 % at the families' widest member (0.24), +3.5 % at b = L:
#: a bound at the 1 % bar (b / L ~0.15) would refuse family members; docs/known-gaps.md
#: (2026-11-28) records it as open.
SLENDER_MAX_WIDTH = 1.0


def _round_sig(x: float, direction: Callable[[float], float], digits: int = 4) -> float:
    """``x`` to ``digits`` significant figures, rounded by ``direction`` (``math.floor`` for a
    largest allowed value, ``math.ceil`` for a smallest), so the value a refusal suggests is
    itself accepted (review 23d: "thickness at most 0.03588 m" refused 0.03588)."""
    scale = 10.0 ** (digits - 1 - math.floor(math.log10(abs(x))))
    return direction(x * scale) / scale


def _check_slender(rig: dict[str, Any], error: ErrorFn) -> None:
    """Refuse a beam the Euler-Bernoulli hinge chain does not stand for: deeper than
    :data:`SLENDER_MAX_DEPTH` or wider than :data:`SLENDER_MAX_WIDTH` times its length.

    The key named is the one of the pair (``thickness`` or ``width``, and ``length``) furthest
    from its default by ratio (:func:`models._base.furthest_from_default`).

    Parameters
    ----------
    rig : dict
        Validated ``[rig]`` table (``thickness``, ``width``, ``length`` [m]).
    error : callable
        The scenario's error reporter (key, value, what is allowed).
    """
    length = rig["length"]
    depth, width = rig["thickness"] / length, rig["width"] / length
    if depth > SLENDER_MAX_DEPTH:
        key = furthest_from_default(rig, ("thickness", "length"), RIG_SCHEMA)
        error(f"rig.{key}", rig[key],
              f"a slender beam: thickness / length at most {SLENDER_MAX_DEPTH:g}, here "
              f"{depth:.6g} ({rig['thickness']:g} / {length:g} m): beyond it shear deformation and "
              "rotary inertia, which the Euler-Bernoulli hinge chain neglects, lower a clamped "
              f"beam's mode 1 by more than {SLENDER_FREQ_BAR * 100:g} % (Timoshenko; the bound "
              "of every base, models/cantilever/rig.py SLENDER_MAX_DEPTH); allowed: thickness at "
              f"most {_round_sig(SLENDER_MAX_DEPTH * length, math.floor):g} m on this length, or "
              f"length at least {_round_sig(rig['thickness'] / SLENDER_MAX_DEPTH, math.ceil):g} m")
    elif width > SLENDER_MAX_WIDTH:
        key = furthest_from_default(rig, ("width", "length"), RIG_SCHEMA)
        error(f"rig.{key}", rig[key],
              f"a beam, not a plate: width / length at most {SLENDER_MAX_WIDTH:g}, here "
              f"{width:.6g} ({rig['width']:g} / {length:g} m): wider, the plate's first mode "
              "bending across the width (struck and read on the centre line) lies below mode 2, "
              "and the chain of rigid sections cannot hold it (models/cantilever/rig.py "
              f"SLENDER_MAX_WIDTH); allowed: width at most "
              f"{_round_sig(SLENDER_MAX_WIDTH * length, math.floor):g} m on this length, or length "
              f"at least {_round_sig(rig['width'] / SLENDER_MAX_WIDTH, math.ceil):g} m")


#: Least stiffness-proportional damping coefficient ``beta`` [s] a beam may have: float64's
#: smallest normal number (2.2e-308).  Below it ``C = beta K`` is subnormal or 0 -- the undamped
#: chain ``damping_ratio = 0`` is refused for -- and the truth's damping ratios and ``Cr`` lose
#: their digits (``damping_ratio = 5e-324`` gave beta = 0 and damping scores of inf).
MIN_NORMAL_BETA_S = sys.float_info.min


def _least_damping_ratio(rig: dict[str, Any]) -> float:
    """The least ``damping_ratio`` whose ``beta = 2 zeta_1 / omega_1`` [s] reaches
    :data:`MIN_NORMAL_BETA_S`: ``MIN_NORMAL_BETA_S pi f_1``.

    ``f_1`` is the clamped Euler-Bernoulli estimate of mode 1 (:func:`clamped_estimates`); the
    model's exact mode 1, which :func:`build_model` uses, lies within a few per cent of it for a
    clamped base and below it for a soft one, so the bound is never above the true one by more
    than that.  0 when the estimate leaves float64 (other checks name such a beam).
    """
    try:
        f1 = float(clamped_estimates(rig, 1)[0])
    except (OverflowError, ZeroDivisionError, ValueError):
        return 0.0
    return MIN_NORMAL_BETA_S * math.pi * f1 if math.isfinite(f1) and f1 > 0 else 0.0


#: The hinge chain's mode 1 is at least ``1 - CHAIN_MODE1_DEFICIT / n_segments^2`` of the clamped
#: Euler-Bernoulli estimate (:func:`clamped_estimates`): measured 2026-11-27 on the clamped
#: default beam over joint_offset 0-0.5 (the least ratio at 0, the hinge at the wall), 0.898 at
#: 2 segments (bound 0.875), 0.952 at 3 (0.944), 0.972 at 4 (0.969), 0.982 at 5 (0.980), 0.9954
#: at 10 (0.995), 0.9995 at 30 (0.99944), 1.000 at 100.  A clamped beam whose estimate times
#: this bound is above the Nyquist frequency has its chain's mode 1 above it too.
CHAIN_MODE1_DEFICIT = 0.5


def chain_mode1_ratio(n_segments: int) -> float:
    """Least ratio of the chain's mode 1 to the clamped Euler-Bernoulli estimate
    (:data:`CHAIN_MODE1_DEFICIT`)."""
    return 1.0 - CHAIN_MODE1_DEFICIT / n_segments**2


#: The keys a clamped beam's mode 1 comes from: ``sqrt(E / rho) thickness / length^2`` (the
#: width cancels); a beam whose mode 1 is above the Nyquist frequency names the one furthest
#: from its default, or ``simulation.sample_rate`` when that is further still.
_MODE1_KEYS = ("E", "rho", "thickness", "length")


def _check_mode1_sampled(rig: dict[str, Any], simulation: dict[str, Any], error: ErrorFn) -> None:
    """Refuse a clamped beam whose mode 1 lies above the Nyquist frequency ``sample_rate / 2``.

    The ideal sampler has no anti-aliasing filter: such a record holds none of the beam's modes,
    only their aliases, and every identifier is scored against modes no record shows (round 10
    left open ``rig.E = 2**63``: mode 1 at 549 kHz against 6.4 kHz, accepted within the step
    budget on a 0.05 s record, minutes of MuJoCo steps for a failure that says nothing of the
    identifier).  The rule: ``r f_1 > sample_rate / 2`` with ``f_1`` the clamped
    Euler-Bernoulli estimate and ``r`` the chain's least ratio to it
    (:func:`chain_mode1_ratio`); a soft base is not checked (its mode 1, the beam turning on
    the spring, may lie far below the clamped estimate).  The key named is the one of
    :data:`_MODE1_KEYS` or ``simulation.sample_rate`` furthest from its default by ratio.
    """
    if rig["base"] != "stiff":
        return
    try:
        f1 = float(clamped_estimates(rig, 1)[0])
    except (OverflowError, ZeroDivisionError, ValueError):
        return  # a section that leaves float64 is refused by _check_segment_inertia
    fs = float(simulation["sample_rate"])
    nyquist = fs / 2.0
    ratio = chain_mode1_ratio(rig["n_segments"])
    if not (math.isfinite(f1) and ratio * f1 > nyquist):
        return
    key = furthest_from_default(rig, _MODE1_KEYS, RIG_SCHEMA)

    def distance(value: float, default: float) -> float:
        r = value / default
        return abs(math.log(r)) if 0.0 < r < math.inf else math.inf

    rate_default = SIMULATION_SCHEMA["sample_rate"].default
    if distance(fs, rate_default) > distance(rig[key], RIG_SCHEMA[key].default):
        name, value = "simulation.sample_rate", fs
    else:
        name, value = f"rig.{key}", rig[key]
    # mode 1 scales as sqrt(E): the largest E whose chain mode 1 is surely below Nyquist
    e_max = rig["E"] * (nyquist / (ratio * f1)) ** 2
    error(name, value,
          f"expected a clamped beam whose mode 1 lies below the Nyquist frequency {nyquist:.6g} Hz "
          f"(sample_rate / 2): its Euler-Bernoulli estimate is {f1:.4g} Hz here (the chain's "
          f"at least {ratio:.4g} of it with {rig['n_segments']} segments), so the record, "
          "sampled without an anti-aliasing filter, holds none of the beam's modes, only their "
          f"aliases; allowed: rig.E below about {e_max:.3g} Pa on this beam (mode 1 scales as sqrt(E / rho) "
          f"thickness / length^2), or simulation.sample_rate above "
          f"{2 * ratio * f1:.4g} Hz")


def _pulse_recorded(excitation: dict[str, Any], fs: float) -> bool:
    """Whether some sample instant ``k / fs`` falls strictly inside the hammer's pulse.

    The force channel holds the half-sine sampled at ``k / fs`` (:meth:`CantileverRig.simulate`),
    zero at the pulse's ends: a pulse between two sample instants is recorded as no force at
    all (round 10: 0.3 ms at 3.2 kHz starting on a sample, 0.96 sample periods), and then the
    scorer simulates every model, the truth too, unforced (the truth's TRAC 0.11-0.24).  Any
    open interval longer than the sample period holds a sample instant, so only pulses of at
    most two periods are looked at, on the same instants the simulation records.

    Parameters
    ----------
    excitation : dict
        Validated impact ``[excitation]`` table (``start``, ``pulse_duration`` [s]).
    fs : float
        Sample rate [Hz].
    """
    start, width = excitation["start"], excitation["pulse_duration"]
    if not width * fs <= 2.0:  # (NaN-safe) longer than a period: a sample instant lies inside
        return True
    hi = (start + width) * fs
    if not hi < 2.0**53:  # a record of over 2^53 samples (or inf): the budget refuses it
        return True
    k = np.arange(math.floor(start * fs), math.ceil(hi) + 1)
    force = half_sine(1.0, width, start)(k / fs)
    return bool(np.any(force > 0.0))


def _root_hinge(rig: dict[str, Any]) -> float:
    """Position [m] of the first moving hinge (0 for a soft base)."""
    if rig["base"] == "soft":
        return 0.0
    return rig["joint_offset"] * rig["length"] / rig["n_segments"]


#: The section and material keys a segment's mass and inertia come from (with ``length``).
_MASS_KEYS = ("thickness", "width", "rho", "length")
#: The keys the section's bending stiffness ``E width thickness^3 / 12`` comes from.
_SECTION_KEYS = ("E", "width", "thickness")
#: The physical keys a beam's model is built from; a build that fails names the one furthest
#: from its default (:func:`models._base.furthest_from_default`).
_BUILD_KEYS = ("E", "rho", "width", "thickness", "length", "base_k1", "base_k3")


def _check_segment_inertia(rig: dict[str, Any], error: ErrorFn) -> None:
    """Every segment's mass and principal inertias above MuJoCo's :data:`MJ_MINVAL`.

    A segment of length ``s`` has mass ``m = rho b h s``, ``I_yy = m s^2 / 12`` and ``I_xx = m
    b^2 / 12`` (:func:`models.cantilever.beam.build_mjcf`).  Below the bound MuJoCo refuses to
    compile the chain; the key named is the one of :data:`_MASS_KEYS` furthest below its
    default (by ratio), e.g. ``rig.thickness`` for a 1e-12 m deep beam.
    """
    with np.errstate(over="ignore", under="ignore"):  # Python's float ** raises on overflow
        ei = np.float64(rig["E"]) * np.float64(rig["width"]) * np.float64(rig["thickness"]) ** 3 / 12.0
    if not (np.isfinite(ei) and ei > 0.0):  # thickness = 1e300: the hinges' stiffness overflows
        key = furthest_from_default(rig, _SECTION_KEYS, RIG_SCHEMA)
        error(f"rig.{key}", rig[key],
              f"a section whose bending stiffness E width thickness^3 / 12 is finite and above "
              f"0 N m^2; it is {float(ei):g} here (the others are rig."
              f"{', rig.'.join(k for k in _SECTION_KEYS if k != key)})")
        return
    params = beam_params(rig)
    if not params.segment_length > 0.0:  # length / n_segments underflowed (5e-324 m): no segment
        error("rig.length", rig["length"],
              f"a segment length (rig.length / rig.n_segments) above 0 m; it underflows to "
              f"{params.segment_length:g} m here")
        return
    with np.errstate(over="ignore", invalid="ignore"):  # huge values: inf passes, refused elsewhere
        xs, _ = params.hinges()
        seg = np.append(xs[1:], params.length) - xs
        seg = seg[seg > 0]
        m = np.float64(params.mass_per_length) * seg
        b = np.float64(params.width)
        inertias = np.concatenate([m, m * seg**2 / 12.0, m * b**2 / 12.0])
        smallest = float(np.min(inertias))
    if not np.all(np.isfinite(inertias)):
        # length = 1e300: I_yy = m s^2 / 12 overflowed, and the build was refused naming the
        # table alone ("key 'rig': ... (34, 'Numerical result out of range')", round 9)
        key = furthest_from_default(rig, _MASS_KEYS, RIG_SCHEMA)
        error(f"rig.{key}", rig[key],
              f"a segment's mass and principal inertias must be finite (kg, kg m^2); they "
              f"overflow here (mass {float(np.max(m)):.3g} kg): a smaller {key} (the others "
              f"are rig.{', rig.'.join(k for k in _MASS_KEYS if k != key)})")
        return
    if not smallest > MJ_MINVAL:
        key = min(_MASS_KEYS, key=lambda k: rig[k] / RIG_SCHEMA[k].default)
        error(f"rig.{key}", rig[key],
              f"a segment's mass and principal inertias must exceed MuJoCo's mjMINVAL "
              f"{MJ_MINVAL:g} (kg, kg m^2); the smallest here is {smallest:.3g} (mass "
              f"{float(np.min(m)):.3g} kg): a larger {key} (the others are rig."
              f"{', rig.'.join(k for k in _MASS_KEYS if k != key)})")


def _check_sensors_per_segment(rig: dict[str, Any], sensors: list[float], x0: float,
                               error: ErrorFn) -> None:
    """Refuse sensors whose readings are linearly dependent through the chain's kinematics.

    Segment ``i`` (counted from the root, 1-based; a soft base's stub from 0 to the first
    hinge is segment 1) turns on the ``i`` hinges inboard of it, and a transverse
    accelerometer at ``s`` on it reads ``sum_j (s - x_j) ddot(theta_j)`` over those hinges.
    Two rules follow, both exact counts (no rank decided by round-off):

    * at most :data:`MAX_SENSORS_PER_SEGMENT` sensors on one segment (its rows lie in the
      span of two vectors, ``1`` and ``x``);
    * at most ``i`` sensors on segments ``1..i`` together, for every ``i`` (their rows have
      ``i`` entries).  Round 18: 0.05 / 0.1 / 0.15 L on the shipped clamped beam put two
      sensors on its first segment (one hinge); the build then failed with "Singular matrix"
      naming ``rig.E``, and 0.06 / 0.12 / 0.18 L was accepted with a reduction at the sensors
      whose modes were 92 / 109 / 733 Hz against the engine's 82.8 / 517 / 1447 Hz.

    A sensor at a hinge moves with the segment inboard of it (its offset on the outboard one
    is zero), so it is counted there, and so is one within :data:`HINGE_SNAP` of a segment
    outboard of it (a lever arm too short to tell its reading from the inboard segment's).

    Parameters
    ----------
    rig : dict
        Validated ``[rig]`` table.
    sensors : list of float
        The given sensor positions [m] (the default L/3, 2L/3, L lie on three segments).
    x0 : float
        Position of the root hinge [m]; sensors inboard of it are refused elsewhere.
    error : callable
        The scenario's error reporter (key, value, what is allowed).
    """
    on_beam = sorted(s for s in sensors if x0 < s <= rig["length"])
    if not on_beam:
        return
    params = beam_params(rig)
    xs, _ = params.hinges()
    # 0-based segment index; a sensor at hinge x_b, or within HINGE_SNAP of it outboard,
    # belongs to segment b - 1 (its lever arm about x_b is nil, or too short to tell)
    snap = HINGE_SNAP * params.segment_length
    segments = [int(np.searchsorted(xs + snap, s, side="left")) - 1 for s in on_beam]
    if segments[0] < 0:
        error("rig.sensors", sensors,
              f"allowed: positions more than {snap:.3g} m ({HINGE_SNAP:g} of a segment) outboard "
              f"of the root hinge at {xs[0]:.6g} m; {on_beam[0]:.9g} m reads no motion one can "
              "tell from zero")
        return

    def span(b: int) -> str:
        return f"{xs[b]:.6g}-{xs[b + 1] if b + 1 < len(xs) else rig['length']:.6g} m"

    for b in sorted(set(segments)):
        held = [s for s, i in zip(on_beam, segments, strict=True) if i == b]
        if len(held) > MAX_SENSORS_PER_SEGMENT:
            error("rig.sensors", sensors,
                  f"allowed: at most {MAX_SENSORS_PER_SEGMENT} sensors on one rigid segment; "
                  f"{', '.join(f'{s:.6g}' for s in held)} m all lie on segment {b + 1} "
                  f"({span(b)}), whose plane motion has 2 degrees of freedom: "
                  "their readings are linearly dependent and the reduction at the sensors "
                  "(SEREP) is singular")
            return
    for b in sorted(set(segments)):
        inboard = [s for s, i in zip(on_beam, segments, strict=True) if i <= b]
        if len(inboard) > b + 1:
            hinges = f"{b + 1} hinge" + ("s" if b else "")
            error("rig.sensors", sensors,
                  f"allowed: at most {b + 1} sensor{'s' if b else ''} on segment"
                  f"{'s 1-' if b else ' '}{b + 1} ({xs[0]:.6g}-{span(b).split('-')[1]}), which "
                  f"turn{'' if b else 's'} on {hinges}; {', '.join(f'{s:.6g}' for s in inboard)} m "
                  "lie there, so their readings are linearly dependent and the reduction at the "
                  "sensors (SEREP) is singular")
            return


def check_small_angles(peak: tuple[float, float, int], peak_force: float,
                       params: BeamParams) -> None:
    """Refuse a run whose beam turned beyond :data:`SMALL_ANGLE_MAX_RAD` (the linear truth's reach).

    Parameters
    ----------
    peak : (float, float, int)
        The largest segment angle [rad], its time [s] and segment (1-based), from
        :func:`models.cantilever.simulate.rollout_sensors`.
    peak_force : float
        The hammer's peak force [N]; the motion is close to proportional to it, so the
        message names the force that would stay within the bound.
    params : BeamParams
        The beam (its hinges locate the segment).

    Raises
    ------
    RigError
        Naming ``excitation.peak_force``, its value, the angle reached and the bound.
    """
    angle, t, seg = peak
    if angle <= SMALL_ANGLE_MAX_RAD:
        return
    hinge = params.hinges()[0][seg - 1]
    raise RigError(
        f"key 'excitation.peak_force': value {peak_force:g}: the beam turns by {angle:.3g} rad "
        f"(the segment outboard of the hinge at {hinge:.4g} m, t = {t:.4g} s), beyond the linear "
        f"truth's small-angle reach of {SMALL_ANGLE_MAX_RAD:g} rad (there the exact kinematics "
        "depart from the truth by up to 0.77 % of the record; models/cantilever/rig.py "
        f"SMALL_ANGLE_MAX_RAD); allowed: a peak force below about "
        f"{peak_force * SMALL_ANGLE_MAX_RAD / angle:.3g} N on this beam, or a stiffer beam")


@RIGS.register("cantilever", tags=("structural", "mujoco", "beam"))
class CantileverRig(Rig):
    """Steel cantilever (hinge chain in MuJoCo) under a hammer impact.  See the module docs."""

    kind: ClassVar[str] = "structural"
    rig_schema: ClassVar[dict[str, Field]] = RIG_SCHEMA
    simulation_schema: ClassVar[dict[str, Field]] = SIMULATION_SCHEMA
    excitation_schemas: ClassVar[dict[str, dict[str, Field]]] = {"impact": IMPACT_SCHEMA}
    default_excitation: ClassVar[str] = "impact"
    measured_signals: ClassVar[tuple[str, ...]] = ("acceleration", "force")
    noisy_signals: ClassVar[tuple[str, ...]] = ("acceleration",)

    @classmethod
    def check(cls, rig: dict[str, Any], simulation: dict[str, Any], excitation: dict[str, Any],
              error: ErrorFn) -> None:
        """Cross-field checks (positions on the beam, damping, pulse, stepping, gravity, a
        slender beam)."""
        length = rig["length"]
        x0 = _root_hinge(rig)
        where = f"positions in ({x0:.6g}, length={length:.6g}] m" + (
            f" (points inboard of the root hinge at {x0:.6g} m do not move)" if x0 > 0 else "")
        sensors = rig["sensors"]
        for s in sensors:
            if not x0 < s <= length:
                error("rig.sensors", sensors, f"allowed: {where}")
        if len(set(sensors)) != len(sensors):
            error("rig.sensors", sensors, "allowed: distinct positions (one accelerometer each)")
        n_dof = rig["n_segments"] + (rig["base"] == "soft")
        _check_segment_inertia(rig, error)
        _check_mode1_sampled(rig, simulation, error)
        _check_sensors_per_segment(rig, sensors, x0, error)
        n_sensors = len(sensor_positions(rig))
        if n_sensors > n_dof and not sensors:  # the default stands for L/3, 2L/3, L
            need = n_sensors - (rig["base"] == "soft")
            error("rig.n_segments", rig["n_segments"],
                  f"allowed: at least {need} with the default sensors (L/3, 2L/3, L: the SEREP "
                  f"reduction needs a degree of freedom per sensor), or at most {n_dof} "
                  "positions in rig.sensors")
        elif n_sensors > n_dof:
            error("rig.sensors", sensors, f"allowed: at most {n_dof} sensors (the model's degrees "
                                          "of freedom, for the SEREP reduction)")
        if rig["damping_ratio"] == 0 and rig["damping_beta"] == 0:
            # the ideal sampler has no anti-aliasing filter: C = beta K damps every mode above
            # the Nyquist frequency within a fraction of a millisecond, unless beta = 0
            error("rig.damping_ratio", 0.0,
                  "expected > 0 (or rig.damping_beta > 0): an undamped chain's modes above the "
                  "Nyquist frequency ring for the whole record and fold into the band, where no "
                  "mode of the truth is (measured: the default beam's mode 8, 12456 Hz, at "
                  "344 Hz at 12.8 kHz, and ls_sindy's mode 1 off 3300 %)")
        # C = beta K with beta subnormal or 0 is the undamped chain refused above, in a number
        # that has lost its digits (round 8: damping_ratio = 5e-324 gave beta = 0, the truth's
        # damping ratios 0 and the damping scores inf, with no reason given)
        undamped = ("an undamped chain in all but name (C = beta K under float64's smallest "
                    f"normal number, {MIN_NORMAL_BETA_S:.4g} s)")
        if 0 < rig["damping_beta"] < MIN_NORMAL_BETA_S:
            error("rig.damping_beta", rig["damping_beta"],
                  f"expected 0 (derived from damping_ratio) or at least {MIN_NORMAL_BETA_S:.4g} "
                  f"s: below it {undamped}")
        zeta_min = _least_damping_ratio(rig)
        if rig["damping_beta"] == 0 and 0 < rig["damping_ratio"] < zeta_min:
            error("rig.damping_ratio", rig["damping_ratio"],
                  f"expected in [{zeta_min:.4g}, 1): below it beta = 2 zeta_1 / omega_1 (mode 1 "
                  f"about {zeta_min / MIN_NORMAL_BETA_S / math.pi:.4g} Hz by Euler-Bernoulli) is "
                  f"{undamped}")
        if rig["damping_ratio"] > 0 and rig["damping_beta"] > 0:
            error("rig.damping_beta", rig["damping_beta"],
                  "allowed: only one damping form; set rig.damping_ratio = 0 to give damping_beta")
        if rig["base"] == "stiff":
            # a clamped base has no spring: base_k1 = 5000 was accepted and ignored (round 9);
            # a value at its default is what a table written out whole lists
            for key in ("base_k1", "base_k3"):
                if rig[key] != RIG_SCHEMA[key].default:
                    error(f"rig.{key}", rig[key],
                          "read only with base = 'soft' (the clamped base has no spring): "
                          "remove it or set rig.base = 'soft'")
        if rig["base"] == "soft" and rig["joint_offset"] == 0:
            error("rig.joint_offset", rig["joint_offset"],
                  "allowed: > 0 with base = 'soft' (the base hinge needs a stub of beam to move)")
        if simulation["gravity"] == "removed" and rig["base"] == "soft" and rig["base_k3"] > 0:
            error("simulation.gravity", "removed",
                  "allowed: 'off' with a cubic soft base (the sag would add a quadratic term "
                  "the cubic truth does not describe)")
        period = 1.0 / simulation["sample_rate"]
        if simulation["timestep"] > period:
            error("simulation.timestep", simulation["timestep"],
                  f"allowed: at most the sample period {period:.6g} s")
        check_two_samples(simulation, error)
        if excitation["peak_force"] >= MUJOCO_MAX_CONTROL:
            error("excitation.peak_force", excitation["peak_force"],
                  f"expected below {MUJOCO_MAX_CONTROL:g} N: MuJoCo zeroes a larger control (the "
                  "hammer's force) as huge")
        loc = excitation["location"]
        if loc != 0.0 and not x0 < loc <= length:
            error("excitation.location", loc, f"allowed: 0 (= tip) or {where}")
        positions = sensor_positions(rig)
        hit = hit_position(rig, excitation)
        _, gap, within = nearest_within(hit, positions, HIT_SENSOR_TOLERANCE_M)
        if not within:
            error("excitation.location", loc,
                  f"allowed: 0 (= tip) or a sensor position, within {HIT_SENSOR_TOLERANCE_M * 1e3:g} "
                  f"mm (sensors at {', '.join(f'{x:.6g}' for x in positions)} m; the impact at "
                  f"{hit:.6g} m is {gap * 1e3:.6g} mm from the nearest): a model in sensor "
                  "coordinates cannot place a force between sensors")
        end = excitation["start"] + excitation["pulse_duration"]
        if end >= simulation["duration"]:
            # the key at fault: the start when the pulse begins after the record has ended
            key = "start" if excitation["start"] >= simulation["duration"] else "pulse_duration"
            error(f"excitation.{key}", excitation[key],
                  f"allowed: start + pulse_duration < duration ({simulation['duration']:g} s)")
        elif not _pulse_recorded(excitation, float(simulation["sample_rate"])):
            fs = float(simulation["sample_rate"])
            error("excitation.pulse_duration", excitation["pulse_duration"],
                  f"a pulse the force channel records: at {fs:g} Hz no sample instant falls "
                  f"inside the pulse ({excitation['start']:.6g}-{end:.6g} s), so the recorded "
                  "force is zero and no model can be simulated against the record; allowed: a "
                  f"pulse longer than the sample period {1.0 / fs:.4g} s (or a start that "
                  "puts a sample inside it)")
        # last: a beam refused above keeps its reason (e.g. a 1 mm beam's mode 1 above Nyquist)
        _check_slender(rig, error)

    #: ``[signal]`` keys that may say ``"auto"``: resolved from the nominal geometry when the
    #: scenario is loaded (:meth:`auto_signal`).
    auto_signal_keys: ClassVar[tuple[str, ...]] = ("highpass_hz", "lowpass_hz")

    @classmethod
    def auto_signal(cls, rig: dict[str, Any], key: str) -> tuple[float, str]:
        """Cut-off ``signal.<key> = "auto"`` [Hz] and its rule, from the rig's nominal geometry
        (:func:`~models.cantilever.euler_bernoulli.auto_cutoff`; ValueError if it cannot be
        resolved)."""
        return auto_cutoff(rig, key)

    @classmethod
    def clamped_estimates(cls, rig: dict[str, Any], n: int) -> np.ndarray:
        """Euler-Bernoulli clamped estimates of modes 1..n [Hz]
        (:func:`~models.cantilever.euler_bernoulli.clamped_estimates`)."""
        return clamped_estimates(rig, n)

    @classmethod
    def measurement_shape(cls, rig: dict[str, Any]) -> tuple[int, int]:
        """One channel per accelerometer, one input (the hammer force)."""
        return len(sensor_positions(rig)), 1

    @classmethod
    def cost(cls, rig: dict[str, Any], simulation: dict[str, Any],
             excitation: dict[str, Any]) -> Cost:
        """Memory and integration steps of a run, from the rig's own stepping rule.

        The record's size alone is checked first (every sample takes at least one step), then
        the least work any stepping could need (:func:`fewest_substeps`: steps and CPU time
        from the sample rate and the segment count); only if both fit is the model compiled to
        learn its step (:func:`models.cantilever.model.build_model`, about 20 ms for 10
        segments, 2.4 s for 400 on the idle machine), so an absurd ``duration``,
        ``sample_rate`` or ``n_segments`` is refused in microseconds.

        Raises
        ------
        RigError
            If the model cannot be compiled from these (valid but extreme) parameters.
        """
        fs = float(simulation["sample_rate"])
        samples = simulation["duration"] * fs
        n_sensors = len(sensor_positions(rig))
        per_sample = BYTES_PER_SAMPLE_PER_SENSOR * n_sensors + BYTES_PER_SAMPLE
        key = "simulation.sample_rate" if fs > 10 * SIMULATION_SCHEMA["sample_rate"].default \
            else "simulation.duration"
        value = simulation[key.split(".")[1]]

        def cost(substeps: float, step_key: str, step_value: Any, step_s: float | None = None) -> Cost:
            steps = samples * substeps
            nv = rig["n_segments"] + (rig["base"] == "soft")
            return Cost(memory_bytes=samples * per_sample + steps * BYTES_PER_STEP, steps=steps,
                        samples=samples, memory_key=key, steps_key=step_key, samples_key=key,
                        memory_value=value, steps_value=step_value, samples_value=value,
                        seconds=None if step_s is None else steps * step_s,
                        seconds_key="rig.n_segments" if nv > 60 else key,
                        seconds_value=rig["n_segments"] if nv > 60 else value)

        lower = cost(1.0, key, value)
        if (lower.samples > SAMPLE_BUDGET or lower.steps > STEP_BUDGET
                or lower.memory_bytes > MEMORY_BUDGET_BYTES):
            return lower
        # the fewest steps any stepping rule could take, from the sample rate alone: a fine beam
        # over the CPU budget is refused without compiling it (400 segments: 2.4 s idle, 39 s
        # on the loaded shared machine)
        substeps, per_sample_s = fewest_substeps(simulation, rig["n_segments"] + (rig["base"] == "soft"))
        step_key, step_value = (("simulation.timestep", simulation["timestep"])
                                if simulation["timestep"] > 0 else (key, value))
        lower = cost(substeps, step_key, step_value, per_sample_s / substeps)
        if (lower.steps > STEP_BUDGET or lower.memory_bytes > MEMORY_BUDGET_BYTES
                or lower.seconds > CPU_BUDGET_S):
            return lower
        try:
            built = build_model(rig, simulation, excitation)
        except (ValueError, ArithmeticError, np.linalg.LinAlgError) as e:
            # named: the key furthest from its default (round 9: length = 1e100 and a soft
            # base_k1 = 1e100 were refused naming the table 'rig' alone)
            keys = tuple(k for k in _BUILD_KEYS if rig[k] > 0)
            key = furthest_from_default(rig, keys, RIG_SCHEMA)
            raise RigError(f"the beam cannot be built from these parameters ({e}); rig.{key} "
                           f"lies furthest from its default {RIG_SCHEMA[key].default:g}",
                           key=f"rig.{key}", value=rig[key]) from None
        stepping = built.stepping
        if simulation["timestep"] > 0:
            step_key, step_value = "simulation.timestep", simulation["timestep"]
        # accuracy alone asks ceil(pi / 0.49) = 7 substeps (RK4) or ceil(pi / 0.109) = 29
        # (implicitfast) per sample; far more means stability, i.e. the stiffest mode of the
        # chain, sets the step
        elif stepping.substeps > 64:
            step_key, step_value = "rig.n_segments", rig["n_segments"]
        else:
            step_key, step_value = key, value
        return cost(float(stepping.substeps), step_key, step_value,
                    step_seconds(rig["n_segments"] + (rig["base"] == "soft"), stepping.integrator))

    def __init__(self, scenario: Any) -> None:
        super().__init__(scenario)
        self._built: CantileverModel | None = None

    @property
    def built(self) -> CantileverModel:
        """The compiled model and its truth (built once)."""
        if self._built is None:
            sc = self.scenario
            self._built = build_model(sc.rig_params, sc.simulation, sc.excitation)
        return self._built

    @property
    def params(self) -> BeamParams:
        return self.built.params

    def simulate(self, progress: Callable[[float], None] | None = None) -> Dataset:
        """Roll the model out under the impact; see :mod:`models.cantilever.simulate`."""
        sc, b = self.scenario, self.built
        fs = float(sc.simulation["sample_rate"])
        n = round(sc.simulation["duration"] * fs)
        st = b.stepping
        exc = sc.excitation
        force = half_sine(exc["peak_force"], exc["pulse_duration"], exc["start"])
        control = force((np.arange(n * st.substeps) + 0.5) * st.timestep)  # mid-step values
        q0 = static_equilibrium(b.model, b.K) if sc.simulation["gravity"] == "removed" \
            else np.zeros(b.model.nq)
        where = (f"with {st.integrator} at timestep {st.timestep:.4g} s "
                 f"({st.substeps} per sample)")
        if sc.simulation["timestep"] > 0:  # a requested step: refuse it if the linear model blows up
            why = unstable_modes(b.M, b.C, b.K, st.integrator, st.timestep)
            if why:
                other, name_it = "", False
                if sc.simulation["integrator"] == "auto":  # auto kept RK4: implicitfast did not fit
                    other = (f"; auto cannot take implicitfast instead: "
                             f"{implicit_unfit(b.M, b.C, b.K, fs, st.timestep)}")
                    # naming implicitfast helps only where it is stable at that step (review 23d:
                    # the advice was also given where implicitfast is unstable there)
                    name_it = unstable_modes(b.M, b.C, b.K, "implicitfast", st.timestep) is None
                raise RigError(f"cantilever: unstable {where}: {why}{other}; set simulation.timestep "
                               "= 0 (automatic) or a smaller one"
                               + (", or name simulation.integrator = \"implicitfast\" (stable "
                                  "there, less accurate than auto's bound)" if name_it else ""),
                               key="simulation.timestep", value=sc.simulation["timestep"])
        LOG.info("cantilever %s: %s", sc.name, st.rule)
        peak: list[tuple[float, float, int]] = []
        sens = rollout_sensors(b.model, q0, control, st.substeps, progress, peak_angle=peak)
        check_small_angles(peak[0], exc["peak_force"], b.params)
        rest = rollout_sensors(b.model, q0, np.zeros(st.substeps), st.substeps)[0]
        adr = b.model.sensor_adr  # per sensor i: acc (site frame), pos, vel (world); z = index 2
        ns = len(b.sensors)
        acc_z, pos_z, vel_z = (np.array([adr[3 * i + k] + 2 for i in range(ns)]) for k in range(3))
        acc = sens[:, acc_z].T - rest[acc_z][:, None]  # static reading: 0, or gravity's
        pos = sens[:, pos_z].T - rest[pos_z][:, None]  # displacement from the rest pose
        vel = sens[:, vel_z].T
        if exc["peak_force"] > 0 and not np.any(acc) and not np.any(pos):
            raise RigError(f"cantilever: the beam did not move under a {exc['peak_force']:g} N impact "
                           f"{where}: the data would be all zeros; check excitation.peak_force")
        labels = [str(i + 1) for i in range(ns)]
        t = np.arange(n) / fs
        ds = Dataset(
            fs=fs,
            measured={
                "acceleration": Signal(acc, tuple("acc" + s for s in labels), "m/s^2", b.sensors),
                "force": Signal(force(t)[None, :], ("force",), "N", np.array([b.hit])),
            },
            reference={
                "displacement": Signal(pos, tuple("disp" + s for s in labels), "m", b.sensors),
                "velocity": Signal(vel, tuple("vel" + s for s in labels), "m/s", b.sensors),
                "acceleration": Signal(acc.copy(), tuple("acc" + s for s in labels), "m/s^2",
                                       b.sensors),
            },
        )
        ds.truth, ds.truth_units = b.truth()
        # Prior knowledge an identifier may be given: the beam's weighed mass, and the
        # trace of the SEREP mass matrix, the scale an identifier of a sensor-coordinate
        # model (Mr, Cr, Kr) can normalise to (free vibration fixes only Mr^-1 Kr).
        ds.prior = {"total_mass": float(b.params.total_mass),
                    "reduced_mass_trace": float(np.trace(b.red.Mr))}
        ds.attrs.update(gravity=sc.simulation["gravity"], integrator=st.integrator,
                        timestep=float(st.timestep), substeps=int(st.substeps), stepping=st.rule,
                        integration_error=[float(e) for e in mode_errors(
                            b.M, b.C, b.K, st, len(b.sensors))],
                        n_dof=int(b.model.nv), free_start=int(np.ceil(
                            (exc["start"] + exc["pulse_duration"]) * fs)) + 1)
        return ds
