"""Excitations of the five-bar linkage: schemas and the sampled torque programs they make.

Every excitation becomes a :class:`TorqueProgram`: a feed-forward torque plus optional
PD feedback on the actuated angles, evaluated at the sample instants and held
(zero-order hold) until the next sample.  The recorded torque is always the total
torque the actuators applied, so the equations of motion hold for it exactly.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from testbed.core.schema import Field

_FEEDBACK = {
    "kp": Field(float, 0.0, unit="N m/rad", min=0.0,
                doc="centring stiffness of a PD loop holding the actuated joints near the start "
                    "pose (keeps open-loop torques from drifting; included in the recorded torque)"),
    "kd": Field(float, 0.0, unit="N m s/rad", min=0.0, doc="damping gain of the same PD loop"),
}

EXCITATION_SCHEMAS: dict[str, dict[str, Field]] = {
    "sine_replay": {
        "amplitude": Field(float, 0.0698, unit="rad", min=0.0, max=0.5,
                           doc="amplitude A of the prescribed motion th = th_0 + A sin(2 pi f t + phase) "
                               "of both actuated joints (the paper: 0.0698 rad = 4 deg)"),
        "frequency": Field(float, 1.0 / (2.0 * math.pi), unit="Hz", min=0.0, min_inclusive=False,
                           max=20.0,
                           doc="frequency f of the prescribed motion (the paper: 1 rad/s); > 0: at "
                               "0 Hz both joints rest at th_0 + A sin(phase), nothing to identify"),
        "phase": Field(float, math.pi / 2.0, unit="rad",
                       doc="phase of the prescribed motion (the paper: pi/2, so it starts at "
                           "th_0 + A at rest)"),
    },
    "multisine": {
        "amplitude": Field(float, 1.0, unit="N m", min=0.0, doc="amplitude of every tone"),
        "f_min": Field(float, 0.1, unit="Hz", min=0.0, min_inclusive=False, doc="lowest tone"),
        "f_max": Field(float, 1.5, unit="Hz", min=0.0, min_inclusive=False, doc="highest tone"),
        "n_tones": Field(int, 8, min=1, max=1000, doc="tones per joint, evenly spaced in [f_min, f_max]"),
        "phase_seed": Field(int, 0, min=0, doc="seed of the random tone phases (uniform in [0, 2 pi))"),
        **_FEEDBACK,
    },
    "chirp": {
        "amplitude": Field(float, 0.5, unit="N m", min=0.0, doc="torque amplitude at both joints"),
        "f0": Field(float, 0.05, unit="Hz", min=0.0, doc="start frequency"),
        "f1": Field(float, 2.0, unit="Hz", min=0.0, doc="end frequency (linear sweep over the run)"),
        "phase_offset": Field(float, math.pi / 2.0, unit="rad",
                              doc="phase of the joint-B chirp relative to joint A"),
        **_FEEDBACK,
    },
    "pd": {
        "amplitude": Field(float, 0.2, unit="rad", min=0.0, max=1.0,
                           doc="amplitude of the sine reference about the start pose"),
        "frequency": Field(float, 0.5, unit="Hz", min=0.0, doc="frequency of the reference"),
        "phase_offset": Field(float, math.pi / 2.0, unit="rad",
                              doc="phase of the joint-B reference relative to joint A"),
        "kp": Field(float, 20.0, unit="N m/rad", min=0.0, doc="proportional gain"),
        "kd": Field(float, 2.0, unit="N m s/rad", min=0.0, doc="derivative gain"),
    },
}


@dataclass
class TorqueProgram:
    """Zero-order-hold actuator torques ``u_k = ff_k + kp (ref_k - th_a) + kd (dref_k - dth_a)``.

    Attributes
    ----------
    ff : ndarray, shape (n, 2)
        Feed-forward torque per sample [N m] (joints A, B).
    ref, dref : ndarray, shape (n, 2)
        Reference actuated angles [rad] and rates [rad/s] of the feedback.
    kp, kd : float
        Feedback gains [N m/rad], [N m s/rad] (0: open loop).
    """

    ff: np.ndarray
    ref: np.ndarray
    dref: np.ndarray
    kp: float = 0.0
    kd: float = 0.0

    @property
    def feedback(self) -> bool:
        return self.kp != 0.0 or self.kd != 0.0

    def torque(self, k: int, th_act: np.ndarray, dth_act: np.ndarray) -> np.ndarray:
        """Torque (2,) [N m] held over sample interval ``k`` given the actuated state then."""
        if not self.feedback:
            return self.ff[k]
        return self.ff[k] + self.kp * (self.ref[k] - th_act) + self.kd * (self.dref[k] - dth_act)

    @classmethod
    def open_loop(cls, u: np.ndarray) -> TorqueProgram:
        """Replay of recorded torques ``u`` (n, 2) [N m]."""
        z = np.zeros_like(u)
        return cls(np.asarray(u, float), z, z)


@dataclass
class Prescribed:
    """A prescribed actuated motion th_a(t) = th_0 + A sin(2 pi f t + phase) (both joints)."""

    th0: np.ndarray
    amplitude: float
    frequency: float
    phase: float

    def __call__(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Angles, rates and accelerations, each shape (len(t), 2), at times ``t`` [s]."""
        w = 2.0 * math.pi * self.frequency
        arg = w * np.asarray(t, float)[:, None] + self.phase
        A = self.amplitude
        return (self.th0 + A * np.sin(arg), A * w * np.cos(arg) * np.ones(2),
                -A * w * w * np.sin(arg) * np.ones(2))


def start_actuated(excitation: dict[str, Any], th0: np.ndarray, dth0: np.ndarray
                   ) -> tuple[np.ndarray, np.ndarray]:
    """Actuated start state (angles [rad], rates [rad/s]), shape (2,) each.

    For ``sine_replay`` the prescribed motion at t = 0 (``th_0`` is the centre of the
    oscillation; the paper's phase pi/2 starts at ``th_0 + A`` at rest); otherwise the
    rig's start pose and rates.
    """
    if excitation["type"] == "sine_replay":
        pres = Prescribed(th0, excitation["amplitude"], excitation["frequency"], excitation["phase"])
        th, dth, _ = pres(np.zeros(1))
        return th[0], dth[0]
    return np.asarray(th0, float), np.asarray(dth0, float)


def build_program(excitation: dict[str, Any], th0: np.ndarray, t: np.ndarray, fs: float,
                  inverse_dynamics=None) -> tuple[TorqueProgram, dict[str, np.ndarray]]:
    """Sampled torque program of an ``[excitation]`` table.

    Parameters
    ----------
    excitation : dict
        Validated ``[excitation]`` table (with ``type``).
    th0 : ndarray, shape (2,)
        Rig start pose (th1_0, th4_0) [rad]; the centre of references and centring.
    t : ndarray, shape (n,)
        Sample times [s].
    fs : float
        Sample rate [Hz]: torques are held for 1/fs.
    inverse_dynamics : callable, optional
        ``(th_a, dth_a, ddth_a) -> (u, theta, lam)``, needed by ``sine_replay``.

    Returns
    -------
    program : TorqueProgram
    extra : dict of str to ndarray
        Reference signals to store, each shape (n, 2): ``theta_prescribed`` (sine_replay),
        ``theta_reference`` (pd).
    """
    kind = excitation["type"]
    n = len(t)
    zeros = np.zeros((n, 2))
    th0 = np.asarray(th0, float)
    if kind == "sine_replay":
        pres = Prescribed(th0, excitation["amplitude"], excitation["frequency"], excitation["phase"])
        # The held torque of interval k is the Simpson mean of the inverse-dynamics torque
        # over [t_k, t_k + 1/fs].  The mean makes the torque error zero-mean within each
        # interval, so the replayed motion follows the prescribed one to O(h^2) globally
        # (~1e-10 rad here) instead of drifting with the half-step delay of u(t_k) (~1e-4 rad).
        tt = np.arange(2 * n + 1) / (2.0 * fs)
        u, _, _ = inverse_dynamics(*pres(tt))
        ff = (u[0:-1:2] + 4.0 * u[1::2] + u[2::2]) / 6.0
        return TorqueProgram(ff, zeros, zeros), {"theta_prescribed": pres(t)[0]}
    if kind == "multisine":
        f = np.linspace(excitation["f_min"], excitation["f_max"], excitation["n_tones"])
        phases = np.random.default_rng(excitation["phase_seed"]).uniform(0.0, 2.0 * math.pi, (2, f.size))
        ff = np.stack([np.sin(2.0 * math.pi * np.outer(t, f) + phases[j]).sum(axis=1)
                       for j in range(2)], axis=1) * excitation["amplitude"]
        return TorqueProgram(ff, np.tile(th0, (n, 1)), zeros, excitation["kp"], excitation["kd"]), {}
    if kind == "chirp":
        T = max(float(t[-1]), 1.0 / fs)
        arg = 2.0 * math.pi * (excitation["f0"] * t + (excitation["f1"] - excitation["f0"]) * t**2 / (2 * T))
        ff = excitation["amplitude"] * np.stack([np.sin(arg), np.sin(arg + excitation["phase_offset"])], 1)
        return TorqueProgram(ff, np.tile(th0, (n, 1)), zeros, excitation["kp"], excitation["kd"]), {}
    if kind == "pd":
        w = 2.0 * math.pi * excitation["frequency"]
        ph = np.array([0.0, excitation["phase_offset"]])
        arg = w * t[:, None] + ph
        A = excitation["amplitude"]
        ref = th0 + A * (np.sin(arg) - np.sin(ph))  # starts at the start pose
        return (TorqueProgram(zeros, ref, A * w * np.cos(arg), excitation["kp"], excitation["kd"]),
                {"theta_reference": ref})
    raise ValueError(f"unknown excitation type {kind!r}")
