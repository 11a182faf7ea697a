"""The five-bar linkage rig: schemas, input checks, simulation to a Dataset with its truth.

Default geometry: four 1 kg, 1 m uniform rods (the paper) on a base L0 = 1 m.  The
paper's figure does not fix L0; 1 m keeps every length equal, and with it the start
pose th1_0 = 1.78 rad, th4_0 = 1.36 rad of the shipped scenarios (symmetric about
x = L0/2, |CD| = 1.417 m) gives a transmission angle of 90.2 deg, the best-conditioned
pose (force transmission through links 2-3 is perpendicular); L0 = 1 m at th1 = th4
would give only 60 deg.

Start pose: a scenario that leaves out ``th1_0`` and ``th4_0`` gets
:func:`models.fivebar.geometry.auto_start_pose`, the usable pose (loop closed,
transmission angle in 30-150 deg) farthest in the actuated angles from every
unusable one, so any geometry runs without a hand-found pose.  The chosen angles
and the rule are stored in the dataset attributes.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any, ClassVar

import numpy as np

from models import RIGS
from models._base import ErrorFn, Rig, check_sample_steps, furthest_from_default
from models.fivebar import geometry as geo
from models.fivebar.dynamics import FiveBarDynamics
from models.fivebar.equations import true_equations
from models.fivebar.excitation import EXCITATION_SCHEMAS, build_program, start_actuated
from models.fivebar.integrate import BlowUpError
from models.fivebar.integrate import simulate as simulate_pinocchio
from models.fivebar.params import FiveBarParams
from testbed.core.budget import Cost
from testbed.core.dataset import Dataset, Signal
from testbed.core.errors import RigError, show_value
from testbed.core.measurement import ZOH_DECLARATION
from testbed.core.schema import Field
from testbed.core.truth import MechanicalTruth

#: Memory per sample of a run [bytes]: the record's 19 float64 channels (angles, rates,
#: accelerations, torques, constraint force, end point, transmission angle, references:
#: 152 B; a 3600 s record measured 5 GB), the dataset's noisy copy and the signal chain's
#: estimates (about 30 values), and SINDy-PI's library matrix (32-60 columns) with its
#: reconciled copies: about 120 float64 values in all, rounded up for temporaries.
BYTES_PER_SAMPLE = 1024

_POS = {"min": 0.0, "min_inclusive": False}
RIG_SCHEMA: dict[str, Field] = {
    **{f"l{i}": Field(float, 1.0, unit="m", doc=f"length of link {i}", **_POS) for i in range(1, 5)},
    "L0": Field(float, 1.0, unit="m", doc="base length |AB| (B = (L0, 0))", **_POS),
    **{f"m{i}": Field(float, 1.0, unit="kg", doc=f"mass of link {i}", **_POS) for i in range(1, 5)},
    **{f"I{i}": Field(float, 0.0, unit="kg m^2", min=0.0,
                      doc=f"inertia of link {i} about its centre of mass; 0 = uniform rod m l^2/12")
       for i in range(1, 5)},
    "damping": Field(float, 1e-3, unit="N m s/rad", min=0.0,
                     doc="viscous damping of each modelled joint A, C, D, B (relative rates; E is "
                         "the frictionless loop closure)"),
    "gravity": Field(bool, False, doc="gravity along -y of the plane (false: horizontal plane)"),
    "branch": Field(str, "up", choices=("up", "down"),
                    doc="assembly branch: E left of (up) or right of (down) the direction C->D"),
    "th1_0": Field(float, None, unit="rad",
                   doc="start angle of link 1 at A (centre of sine_replay); left out with th4_0: the "
                       "most central usable pose (models/fivebar/geometry.py auto_start_pose)"),
    "th4_0": Field(float, None, unit="rad",
                   doc="start angle of link 4 at B (centre of sine_replay); left out with th1_0: "
                       "chosen automatically"),
    "dth1_0": Field(float, 0.0, unit="rad/s", doc="start rate of joint A (not with sine_replay)"),
    "dth4_0": Field(float, 0.0, unit="rad/s", doc="start rate of joint B (not with sine_replay)"),
}

SIMULATION_SCHEMA: dict[str, Field] = {
    "duration": Field(float, 10.0, unit="s", min=0.0, min_inclusive=False, max=3600.0,
                      doc="length of the record"),
    "dt": Field(float, 1e-4, unit="s", min=0.0, min_inclusive=False, max=1e-2,
                doc="RK4 integration step"),
    "sample_rate": Field(float, 10000.0, unit="Hz", min=0.0, min_inclusive=False,
                         doc="sample rate of records and of the zero-order-hold inputs; 1/(rate dt) "
                             "must be a whole number"),
    "engine": Field(str, "pinocchio", choices=("pinocchio", "mujoco"),
                    doc="data source: Pinocchio (hard loop constraint, the truth) or its MuJoCo twin"),
}


def _pose_problem(th1: np.ndarray, th4: np.ndarray, p: FiveBarParams) -> str | None:
    """Why the pose(s) cannot be used (the loop cannot close / near a singularity), or None."""
    d, lo, hi = geo.closure_margin(th1, th4, p)
    d = np.atleast_1d(d)
    if not ((d > lo) & (d < hi)).all():
        k = int(np.argmax(~((d > lo) & (d < hi))))
        return (f"the loop closes only for |l2 - l3| < |CD| < l2 + l3, i.e. {lo:g} < |CD| < {hi:g} m, "
                f"but |CD| = {d[k]:.4g} m at th1 = {np.atleast_1d(th1)[k]:.4g}, "
                f"th4 = {np.atleast_1d(th4)[k]:.4g} rad")
    mu = np.degrees(geo.transmission_angle(geo.assemble(th1, th4, p)))
    mu = np.atleast_1d(mu)
    lo_mu, hi_mu = geo.TRANSMISSION_RANGE_DEG
    if not ((mu >= lo_mu) & (mu <= hi_mu)).all():
        k = int(np.argmax(~((mu >= lo_mu) & (mu <= hi_mu))))
        return (f"transmission angle {mu[k]:.1f} deg at th1 = {np.atleast_1d(th1)[k]:.4g}, "
                f"th4 = {np.atleast_1d(th4)[k]:.4g} rad: near a Type II singularity (links 2 and 3 "
                f"collinear); allowed {lo_mu:g}-{hi_mu:g} deg")
    return None


#: Keys of each excitation that set how far the linkage is driven, named when a simulation
#: leaves the usable workspace or diverges (which only the simulation can tell: the motion
#: under torques is not known before it is integrated).
MOTION_KEYS: dict[str, tuple[str, ...]] = {
    "multisine": ("amplitude", "f_max", "kp", "kd"),
    "chirp": ("amplitude", "f1", "kp", "kd"),
    "pd": ("amplitude", "frequency", "kp", "kd"),
    "sine_replay": ("amplitude", "frequency"),
}


def motion_keys_message(rig: dict[str, Any], excitation: dict[str, Any], simulation: dict[str, Any],
                        why: str, blow_up: bool) -> str:
    """A generation failure of the linkage in the scenario's terms: the keys and values that
    drive the motion, what happened, what to change.

    Parameters
    ----------
    rig, excitation, simulation : dict
        Validated ``[rig]``, ``[excitation]`` and ``[simulation]`` tables (gravity, when on,
        drives the motion too and is named).
    why : str
        The integrator's one-line account (time, transmission angle or non-finite signal).
    blow_up : bool
        The simulation blew up (:class:`~models.fivebar.integrate.BlowUpError`), so
        ``simulation.dt`` is named too.

    Returns
    -------
    str
        ``key 'excitation.amplitude, ...': value [...]: <why>`` (one line; ``why`` ends with
        what to change; the command line prefixes the scenario file).
    """
    names = [f"excitation.{k}" for k in MOTION_KEYS.get(excitation["type"], ("amplitude",))
             if k in excitation]
    values = [excitation[k.split(".", 1)[1]] for k in names]
    if rig["gravity"]:
        names.append("rig.gravity")
        values.append(True)
    if blow_up:  # the step is a suspect too
        names.append("simulation.dt")
        values.append(simulation["dt"])
    return (f"key '{', '.join(names)}': value {show_value(values)}: the motion under excitation "
            f"{excitation['type']!r} is not usable (found only by simulating it): {why}")


def start_pose(rig: dict[str, Any], p: FiveBarParams) -> np.ndarray:
    """Actuated start (or sine_replay centre) pose ``(th1_0, th4_0)`` [rad], shape (2,).

    The scenario's angles, or, when it leaves both out, :func:`geometry.auto_start_pose`
    (NaN if the geometry has no usable pose).
    """
    if rig["th1_0"] is None or rig["th4_0"] is None:
        th1, th4, _ = geo.auto_start_pose(p)
        return np.array([th1, th4])
    return np.array([rig["th1_0"], rig["th4_0"]], dtype=float)


#: The smallest link length (mass) as a fraction of the largest: sqrt(float64 eps).  Below it a
#: link is lost to rounding in the loop's sums of lengths, and the open tree's mass matrix is
#: singular to working precision (condition above 1 / sqrt(eps): the accelerations keep fewer
#: than 8 digits); measured: l1 or m2 = 1e-300 diverged at t = 0, refused as if the multisine
#: excitation were at fault.
MIN_SCALE_RATIO = float(np.sqrt(np.finfo(float).eps))


def _check_scales(rig: dict[str, Any], error: ErrorFn) -> None:
    """Refuse link lengths or masses spread by more than ``1 / MIN_SCALE_RATIO``, naming the
    smallest or the largest, whichever lies further from its default (by ratio)."""
    for keys, what in ((("l1", "l2", "l3", "l4", "L0"), "lengths"),
                       (("m1", "m2", "m3", "m4"), "masses")):
        small, big = min(keys, key=lambda k: rig[k]), max(keys, key=lambda k: rig[k])
        if not rig[small] >= MIN_SCALE_RATIO * rig[big]:
            key = furthest_from_default(rig, (small, big), RIG_SCHEMA)
            error(f"rig.{key}", rig[key],
                  f"link {what} within a factor {1.0 / MIN_SCALE_RATIO:.3g} of each other (here "
                  f"{rig[small]:g} to {rig[big]:g}): a link below that share is lost to rounding "
                  f"in the loop's kinematics and its mass matrix (the {what} are rig."
                  f"{', rig.'.join(keys)})")


@RIGS.register("fivebar", tags=("mechanical", "pinocchio", "closed-loop"))
class FiveBarRig(Rig):
    """Planar five-bar linkage actuated at A and B (Yan et al., SINDy-PI on a 2-DOF linkage).

    Measured: ``theta``, ``dtheta``, ``ddtheta`` (4 x n; absolute angles th1..th4 [rad],
    [rad/s], [rad/s^2]) and ``torque`` (2 x n; u1 at A, u2 at B [N m], zero-order hold).
    Reference: ``constraint_force`` (Fx, Fy [N], on link 2 from link 3 at E), ``E`` (x, y
    [m]), ``transmission_angle`` [rad], and ``theta_prescribed`` / ``theta_reference``
    (th1, th4 [rad]) for sine_replay / pd.  Truth: the physical parameters,
    ``mass_matrix_q0`` (4 x 4, absolute angles), ``reduced_mass_matrix_q0`` (2 x 2, in
    th1, th4), ``theta0`` / ``dtheta0`` and the true library equations
    ``equation_terms`` / ``equation_coef`` / ``equation_scale``
    (see :mod:`models.fivebar.equations`).

    ``[simulation] engine = "mujoco"`` records the MuJoCo twin instead (same schema, same
    truth from Pinocchio): angles within ~1e-10 rad of Pinocchio's, accelerations with
    ~1e-3 rad/s^2 of soft-constraint ripple (see :mod:`models.fivebar.twin`).
    """

    name: ClassVar[str] = "fivebar"
    kind: ClassVar[str] = "mechanical"
    rig_schema = RIG_SCHEMA
    simulation_schema = SIMULATION_SCHEMA
    excitation_schemas = EXCITATION_SCHEMAS
    default_excitation = "sine_replay"
    measured_signals = ("theta", "dtheta", "ddtheta", "torque")
    noisy_signals = ("theta",)

    @classmethod
    def check(cls, rig: dict[str, Any], simulation: dict[str, Any], excitation: dict[str, Any],
              error: ErrorFn) -> None:
        """Geometry that cannot close, start poses near a singularity, inconsistent timing."""
        check_sample_steps(simulation, error)
        nyquist = simulation["sample_rate"] / 2.0
        at_rest = rig["dth1_0"] == 0.0 and rig["dth4_0"] == 0.0 and not rig["gravity"]
        if excitation.get("amplitude", 1.0) == 0.0 and (at_rest or excitation["type"] == "sine_replay"):
            error("excitation.amplitude", 0.0,
                  "expected > 0: with no input, no start rates and no gravity the linkage rests "
                  "and every record is zero (nothing to identify)")
        if excitation["type"] == "multisine":
            if not excitation["f_min"] < excitation["f_max"]:
                error("excitation.f_min", excitation["f_min"],
                      f"expected f_min < f_max ({excitation['f_max']:g} Hz)")
            if not excitation["f_max"] < nyquist:
                error("excitation.f_max", excitation["f_max"],
                      f"expected below the Nyquist frequency {nyquist:g} Hz")
        for key in ("frequency", "f0", "f1"):
            if key in excitation and not excitation[key] < nyquist:
                error(f"excitation.{key}", excitation[key],
                      f"expected below the Nyquist frequency {nyquist:g} Hz")
        _check_scales(rig, error)
        p = FiveBarParams.from_rig(rig)
        if p.L0 >= p.l.sum():
            error("rig.L0", p.L0, f"the loop cannot close for any pose: expected L0 < l1 + l2 + l3 + l4 = "
                                  f"{p.l.sum():g} m")
        kind = excitation["type"]
        if kind == "sine_replay" and (rig["dth1_0"] != 0.0 or rig["dth4_0"] != 0.0):
            error("rig.dth1_0, rig.dth4_0", [rig["dth1_0"], rig["dth4_0"]],
                  "expected 0 with excitation 'sine_replay' (the prescribed motion sets the start rates)")
        if (rig["th1_0"] is None) != (rig["th4_0"] is None):
            error("rig.th1_0, rig.th4_0", [rig["th1_0"], rig["th4_0"]],
                  "both angles, or neither (a start pose chosen automatically)")
        th0 = start_pose(rig, p)
        if not np.isfinite(th0).all():
            lo_mu, hi_mu = geo.TRANSMISSION_RANGE_DEG
            error("rig.th1_0, rig.th4_0", None,
                  f"a start pose, but this geometry has none: no pose closes the loop with a "
                  f"transmission angle in {lo_mu:g}-{hi_mu:g} deg; change the link lengths or L0")
        start, _ = start_actuated(excitation, th0, np.zeros(2))
        why = _pose_problem(start[0], start[1], p)
        if why:
            error("rig.th1_0, rig.th4_0", [rig["th1_0"], rig["th4_0"]], f"start pose unusable: {why}")
        if kind == "sine_replay":
            # Every pose of one period of th_0 + A sin(psi): the whole prescribed path.
            psi = np.linspace(0.0, 2 * math.pi, 361) if excitation["frequency"] > 0 \
                else np.array([excitation["phase"]])
            th = th0 + excitation["amplitude"] * np.sin(psi)[:, None]
            why = _pose_problem(th[:, 0], th[:, 1], p)
            if why:
                error("excitation.amplitude", excitation["amplitude"],
                      f"the prescribed motion leaves the usable workspace: {why}")

    @classmethod
    def measurement_shape(cls, rig: dict[str, Any]) -> tuple[int, int]:
        """Four absolute angles th1..th4, two actuator torques u1, u2."""
        return 4, 2

    @classmethod
    def cost(cls, rig: dict[str, Any], simulation: dict[str, Any],
             excitation: dict[str, Any]) -> Cost:
        """Memory and RK4 steps of a run: ``duration / dt`` steps, ``duration * sample_rate``
        samples of :data:`BYTES_PER_SAMPLE` each (the step is the scenario's ``dt``)."""
        fs = float(simulation["sample_rate"])
        samples = simulation["duration"] * fs
        steps = simulation["duration"] / simulation["dt"]
        key = "simulation.sample_rate" if fs > 10 * SIMULATION_SCHEMA["sample_rate"].default \
            else "simulation.duration"
        step_key = "simulation.dt" if simulation["dt"] < SIMULATION_SCHEMA["dt"].default / 10 \
            else "simulation.duration"
        return Cost(memory_bytes=samples * BYTES_PER_SAMPLE, steps=steps, samples=samples,
                    memory_key=key, steps_key=step_key, samples_key=key,
                    memory_value=simulation[key.split(".")[1]],
                    steps_value=simulation[step_key.split(".")[1]],
                    samples_value=simulation[key.split(".")[1]])

    def __init__(self, scenario) -> None:
        super().__init__(scenario)
        self.params = FiveBarParams.from_rig(scenario.rig_params)
        self.dynamics = FiveBarDynamics(self.params)

    def start_state(self) -> tuple[np.ndarray, np.ndarray]:
        """Consistent absolute start angles [rad] and rates [rad/s], shape (4,) each."""
        rig, p = self.scenario.rig_params, self.params
        th_a, dth_a = start_actuated(self.scenario.excitation, start_pose(rig, p),
                                     np.array([rig["dth1_0"], rig["dth4_0"]]))
        theta0 = geo.assemble(th_a[0], th_a[1], p)
        dtheta0, _ = geo.complete_rates(theta0, dth_a, None, p)
        return theta0, dtheta0

    def simulate(self, progress: Callable[[float], None] | None = None) -> Dataset:
        """Simulate the scenario (noise-free) and return the Dataset with its truth."""
        sc, p, dyn = self.scenario, self.params, self.dynamics
        sim, rig = sc.simulation, sc.rig_params
        fs, dt = sim["sample_rate"], sim["dt"]
        n = round(sim["duration"] * fs)
        t = np.arange(n) / fs
        theta0, dtheta0 = self.start_state()
        program, extra = build_program(sc.excitation, start_pose(rig, p), t, fs,
                                       inverse_dynamics=dyn.inverse_dynamics)
        try:
            if sim["engine"] == "mujoco":
                from models.fivebar.twin import MujocoTwin

                rec = MujocoTwin(p, dt).simulate(theta0, dtheta0, program, fs, n, progress)
            else:
                rec = simulate_pinocchio(dyn, theta0, dtheta0, program, dt, fs, n, progress)
        except RigError as e:
            raise RigError(motion_keys_message(rig, sc.excitation, sim, str(e),
                                               isinstance(e, BlowUpError))) from None
        return self._dataset(rec, extra, theta0, dtheta0, fs)

    def _dataset(self, rec: dict[str, np.ndarray], extra: dict[str, np.ndarray], theta0: np.ndarray,
                 dtheta0: np.ndarray, fs: float) -> Dataset:
        p, dyn = self.params, self.dynamics
        th = rec["theta"]
        measured = {
            "theta": Signal(th.T, ("th1", "th2", "th3", "th4"), "rad"),
            "dtheta": Signal(rec["dtheta"].T, ("dth1", "dth2", "dth3", "dth4"), "rad/s"),
            "ddtheta": Signal(rec["ddtheta"].T, ("ddth1", "ddth2", "ddth3", "ddth4"), "rad/s^2"),
            # u1 drives joint A (link 1's angle th1), u2 joint B (link 4's angle th4)
            "torque": Signal(rec["torque"].T, ("u1", "u2"), "N m", acts_on=("th1", "th4")),
        }
        reference = {
            "constraint_force": Signal(rec["constraint_force"].T, ("Fx", "Fy"), "N"),
            "E": Signal(geo.endpoint(th, p).T, ("Ex", "Ey"), "m"),
            "transmission_angle": Signal(geo.transmission_angle(th)[None], ("mu",), "rad"),
        }
        for name, data in extra.items():
            reference[name] = Signal(data.T, ("th1", "th4"), "rad")
        truth, units = p.truth()
        q0, v0 = geo.to_joint(theta0), geo.to_joint(dtheta0)
        Mr0, _ = dyn.reduced_dynamics(q0, v0)
        terms, coef, scale = true_equations(p)
        truth = MechanicalTruth(**truth, mass_matrix_q0=dyn.mass_matrix_absolute(theta0),
                                reduced_mass_matrix_q0=Mr0, theta0=theta0, dtheta0=dtheta0,
                                equation_terms=terms, equation_coef=coef,
                                equation_scale=scale).to_dict()
        units.update(mass_matrix_q0="kg m^2", reduced_mass_matrix_q0="kg m^2", theta0="rad",
                     dtheta0="rad/s", equation_terms="", equation_coef="1 (row max |coef| = 1)",
                     equation_scale="N m^3")
        prior = {f"l{i + 1}": float(p.l[i]) for i in range(4)} | {"L0": float(p.L0)}
        attrs = {"gravity": f"on: {p.g} m/s^2 along -y" if p.g else "off: horizontal plane",
                 "engine": self.scenario.simulation["engine"], "branch": p.branch,
                 "angles": "absolute th1..th4 from the world x axis, counter-clockwise",
                 "torque_hold": ZOH_DECLARATION}
        rig = self.scenario.rig_params
        th0 = start_pose(rig, p)
        attrs.update(th1_0=float(th0[0]), th4_0=float(th0[1]), start_pose="given" if rig["th1_0"] is not None
                     else "auto: the usable pose farthest from the closure and transmission-angle limits "
                          f"in (th1, th4) on a {geo.AUTO_POSE_STEP_DEG:g} deg grid "
                          f"(margin {geo.auto_start_pose(p)[2]:.3f} rad)")
        return Dataset(fs=fs, measured=measured, reference=reference, truth=truth, truth_units=units,
                       prior=prior, attrs=attrs)
