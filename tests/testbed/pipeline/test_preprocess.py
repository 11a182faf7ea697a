"""The lab's signal chain from a Dataset to a Measurement, on data built here with exact answers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal as ss

from testbed.core.dataset import Dataset, Signal
from testbed.core.errors import ScenarioError
from testbed.numerics import filters as sig
from testbed.pipeline.signal_chain import SIGNAL_SCHEMAS, measure, pulse_end

FS = 2000.0  # [Hz]
# a 3-DOF chain fixed at one end: masses [kg], springs [N/m]; modes about 9, 25 and 36 Hz
M = np.diag([1.0, 1.0, 0.5])
K = 4e4 * np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]])
C = 2e-4 * K + 2.0 * M  # Rayleigh damping: zeta 2.3 % (mode 1) to 3.7 %
SENSORS = np.array([0.1, 0.2, 0.3])  # [m]
PULSE = (0.1, 0.005, 50.0)  # impact at 0.1 s, 5 ms half-sine, 50 N peak
CFG = {"highpass_hz": 2.0, "highpass_order": 5}


class Forbidden(dict):
    """A mapping that fails the test on any read."""

    def _boom(self, *args, **kwargs):
        raise AssertionError("the signal chain read truth or reference data")

    __getitem__ = get = items = keys = values = __iter__ = __contains__ = __len__ = _boom


def simulate(impact_at: float = 0.3, n: int = 8000):
    """Exact sampled response of the chain to a half-sine force at the DOF at ``impact_at``."""
    t = np.arange(n) / FS
    t0, width, peak = PULSE
    force = np.where((t >= t0) & (t <= t0 + width), peak * np.sin(np.pi * (t - t0) / width), 0.0)
    b = np.zeros((3, 1))
    b[int(np.argmin(np.abs(SENSORS - impact_at)))] = 1.0
    minv = np.linalg.inv(M)
    a = np.block([[np.zeros((3, 3)), np.eye(3)], [-minv @ K, -minv @ C]])
    system = ss.lti(a, np.vstack([np.zeros((3, 1)), minv @ b]), np.eye(6), np.zeros((6, 1)))
    _, _, state = ss.lsim(system, force, t)  # exact for the piecewise-linear force
    x, v = state[:, :3].T, state[:, 3:].T
    acc = minv @ (b @ force[None] - C @ v - K @ x)
    return t, force, x, v, acc, b


def structural_dataset(impact_at: float = 0.3, truth=None, reference=None, **kw) -> Dataset:
    _, force, x, _, acc, _ = simulate(impact_at, **kw)
    measured = {"acceleration": Signal(acc, ("s1", "s2", "s3"), "m/s^2", SENSORS),
                "force": Signal(force, ("F",), "N", np.array([impact_at]))}
    ref = {"displacement": Signal(x, ("s1", "s2", "s3"), "m", SENSORS)} if reference is None else reference
    tr = {"M": M, "K": K} if truth is None else truth
    return Dataset(FS, measured, ref, tr, {}, {"total_mass": 2.5}, {"rig": "test"})


def test_structural_chain_matches_filtered_exact_motion():
    _, force, x, v, acc, b = simulate()
    m = measure(structural_dataset(), CFG, "structural")
    assert m.x.shape == m.xd.shape == m.xdd.shape == (3, 8000)
    assert m.channels == ("s1", "s2", "s3") and m.inputs == ("F",) and m.fs == FS

    def h2(z):
        return sig.elliptic_highpass(sig.elliptic_highpass(z, FS, 2.0, 5), FS, 2.0, 5)

    # The record starts at rest and ends with the motion decayed (0.05 % left), so filtering and
    # integration commute up to the trapezoid bias 1 - x/tan x per integration at the highest
    # mode (36 Hz at 2 kHz: 0.11 %): 0.11 % for velocity, 0.22 % for displacement.  Allow 0.5 %
    # of the peak.  (A record cut mid-decay adds end transients of the order of the motion left.)
    def err(got, ref):
        return np.abs(got - ref).max() / np.abs(ref).max()

    # the chain's acceleration and force are H^2 of the record itself, as h2: equal to rounding
    assert err(m.xdd, h2(acc)) < 1e-12
    # the trapezoid bias (0.11 %, 0.22 %, above) with the 0.5 % of the peak allowed
    assert err(m.xd, h2(v)) < 5e-3
    assert err(m.x, h2(x)) < 5e-3
    np.testing.assert_allclose(m.u, h2(force[None]), atol=1e-12 * PULSE[2])
    np.testing.assert_array_equal(m.input_map, b)


def test_equation_of_motion_holds_for_filtered_signals():
    m = measure(structural_dataset(), CFG, "structural")
    residual = M @ m.xdd + C @ m.xd + K @ m.x - m.input_map @ m.u
    # every signal went through the same LTI filter, so M a + C v + K d = B f survives it; what is
    # left is the trapezoid bias of K x (0.22 % at 36 Hz) relative to the inertia term: 1 %
    assert np.abs(residual).max() < 1e-2 * np.abs(M @ m.xdd).max()
    # without filtering the force, the high-pass tail of the pulse is missing from the balance
    raw = measure(structural_dataset(), {**CFG, "filter_force": False}, "structural")
    np.testing.assert_array_equal(raw.u, structural_dataset().measured["force"].data)
    bad = M @ raw.xdd + C @ raw.xd + K @ raw.x - raw.input_map @ raw.u
    assert np.abs(bad[:, raw.free_start:]).max() > 3 * np.abs(residual[:, raw.free_start:]).max()


def test_free_start_after_pulse_plus_margin():
    t0, width, _ = PULSE
    m = measure(structural_dataset(), {**CFG, "free_margin_s": 0.01}, "structural")
    end = round((t0 + width) * FS)  # the half-sine's last sample, sin(pi), is already ~1e-16
    assert m.free_start == end + int(0.01 * FS)
    assert pulse_end(np.zeros((1, 50))) == 0


def test_pulse_end_with_noise():
    rng = np.random.default_rng(3)
    _, force, *_ = simulate()
    noisy = force + rng.normal(0.0, 0.05, force.size)  # 0.1 % of the 50 N peak
    end = pulse_end(noisy[None])
    clean_end = pulse_end(force[None])
    # the threshold rises to 5 sigma = 0.25 N, which the 10 Hz-wide half-sine (slope
    # pi * 50 N / 5 ms at its ends) crosses within a sample of its end
    assert clean_end - 2 <= end <= clean_end


def test_impact_must_be_at_a_sensor():
    with pytest.raises(ValueError, match="within 1 mm"):
        measure(structural_dataset(impact_at=0.305), CFG, "structural")
    m = measure(structural_dataset(impact_at=0.2005), CFG, "structural")  # 0.5 mm off: accepted
    np.testing.assert_array_equal(m.input_map[:, 0], [0.0, 1.0, 0.0])


def test_structural_never_reads_truth_or_reference():
    plain = measure(structural_dataset(), CFG, "structural")
    forbidden = measure(structural_dataset(truth=Forbidden(), reference=Forbidden()), CFG, "structural")
    garbage = measure(structural_dataset(truth={"M": np.full((3, 3), np.nan), "f": [1e9]},
                                         reference={"acceleration": Signal(np.ones((3, 8000)),
                                                                           ("a", "b", "c"), "m/s^2")}),
                      CFG, "structural")
    for other in (forbidden, garbage):
        for name in ("x", "xd", "xdd", "u", "input_map"):
            np.testing.assert_array_equal(getattr(other, name), getattr(plain, name))
        assert (other.free_start, other.prior, other.channels) == (plain.free_start, plain.prior,
                                                                   plain.channels)


def test_prior_is_a_copy_and_lowpass_applies():
    ds = structural_dataset()
    m = measure(ds, {**CFG, "lowpass_hz": 200.0}, "structural")
    assert m.prior == {"total_mass": 2.5}
    m.prior["total_mass"] = 0.0
    assert ds.prior["total_mass"] == 2.5
    # the low-pass is applied to force and acceleration alike, so the balance of the
    # equation-of-motion test still holds (same 1 % bound) ...
    residual = M @ m.xdd + C @ m.xd + K @ m.x - m.input_map @ m.u
    assert np.abs(residual).max() < 1e-2 * np.abs(M @ m.xdd).max()
    # ... and only the pulse's content above ~150 Hz is lost, which the displacement weights
    # by 1 / w^2: the 5 ms half-sine keeps under 1 % of its displacement effect up there
    plain = measure(ds, CFG, "structural")
    assert np.abs(m.x - plain.x).max() < 1e-2 * np.abs(plain.x).max()


def test_config_is_validated():
    with pytest.raises(ScenarioError, match="unknown key"):
        measure(structural_dataset(), {"highpas_hz": 2.0}, "structural")
    with pytest.raises(ScenarioError, match="highpass_hz"):
        measure(structural_dataset(), {"highpass_hz": -1.0}, "structural")
    with pytest.raises(ValueError, match="kind"):
        measure(structural_dataset(), {}, "optical")
    assert {"highpass_hz", "highpass_order", "ripple_db", "stop_db", "lowpass_hz",
            "lowpass_order"} <= set(SIGNAL_SCHEMAS["structural"])


# ------------------------------------------------------------------ mechanical
def mechanical_dataset(noise: float = 0.0, truth=None, reference=None) -> Dataset:
    fs, n = 1e4, 20000  # the five-bar's dt = 1e-4 s, 2 s
    t = np.arange(n) / fs
    phase = np.array([0.0, 0.4, 0.8, 1.2])[:, None]
    amp = 0.0698
    th = amp * np.sin(t + np.pi / 2 + phase)
    rng = np.random.default_rng(7)
    ch = ("th1", "th2", "th3", "th4")
    measured = {"theta": Signal(th + noise * rng.normal(size=th.shape), ch, "rad"),
                "dtheta": Signal(amp * np.cos(t + np.pi / 2 + phase), ch, "rad/s"),
                "ddtheta": Signal(-th, ch, "rad/s^2"),
                "torque": Signal(np.stack([np.sin(t), np.cos(t)]), ("u1", "u2"), "N m",
                                  acts_on=("th1", "th4"))}
    return Dataset(fs, measured, {} if reference is None else reference, {} if truth is None else truth,
                   {}, {}, {"rig": "five_bar"})


def test_mechanical_recorded():
    ds = mechanical_dataset()
    m = measure(ds, {}, "mechanical")
    np.testing.assert_array_equal(m.x, ds.measured["theta"].data)
    np.testing.assert_array_equal(m.xd, ds.measured["dtheta"].data)
    np.testing.assert_array_equal(m.xdd, ds.measured["ddtheta"].data)
    np.testing.assert_array_equal(m.u, ds.measured["torque"].data)
    assert m.channels == ("th1", "th2", "th3", "th4") and m.inputs == ("u1", "u2")
    np.testing.assert_array_equal(m.input_map, [[1, 0], [0, 0], [0, 0], [0, 1]])
    assert m.free_start == 0


def test_mechanical_estimated_derivatives():
    ds = mechanical_dataset(noise=1e-5)
    m = measure(ds, {"derivatives": "estimated", "window": 1001, "polyorder": 4}, "mechanical")
    mid = slice(1000, -1000)
    # the 0.1 s quartic window fits the 1 rad/s sine exactly (its Taylor remainder over 0.1 s
    # is 1e-9 rad); what is left is noise 1e-5 rad times the filter's gain: < 1e-5 rad, and for the
    # derivatives noise / (window time)^k times a factor ~10: 2e-3 rad/s, 0.5 rad/s^2 bounds
    assert np.abs(m.x - ds.measured["ddtheta"].data * -1)[:, mid].max() < 1e-5
    assert np.abs(m.xd - ds.measured["dtheta"].data)[:, mid].max() < 2e-3
    assert np.abs(m.xdd - ds.measured["ddtheta"].data)[:, mid].max() < 0.5


def test_mechanical_lowpass_derivatives():
    clean = mechanical_dataset()
    m = measure(clean, {"derivatives": "lowpass", "cutoff_hz": 10.0}, "mechanical")
    np.testing.assert_array_equal(m.u, clean.measured["torque"].data)
    # noise-free 1 rad/s motion, 10 Hz cut-off: flat pass band, and the end fits (0.1 s,
    # order 5) catch its value, rate and curvature to 1e-9, so the record is right up to its
    # ends: measured 2e-8 rad/s, 1.2e-6 rad/s^2; bounds 50x
    for got, name in ((m.x, "theta"), (m.xd, "dtheta"), (m.xdd, "ddtheta")):
        scale = {"theta": 1e-7, "dtheta": 1e-6, "ddtheta": 1e-4}[name]
        assert np.abs(got - clean.measured[name].data).max() < scale
    noisy = measure(mechanical_dataset(noise=1e-5), {"derivatives": "lowpass", "cutoff_hz": 10.0},
                    "mechanical")
    mid = slice(5000, -5000)
    # noise 1e-5 rad through the 10 Hz low-pass: sigma (2 pi)^k sqrt(fc^(2k+1) / ((2k+1) fs / 2))
    # = 1.6e-5 rad/s and 7.9e-4 rad/s^2 RMS; measured maxima 5e-5 rad/s, 2.3e-3 rad/s^2; bounds 4x
    assert np.abs(noisy.xd - clean.measured["dtheta"].data)[:, mid].max() < 2e-4
    assert np.abs(noisy.xdd - clean.measured["ddtheta"].data)[:, mid].max() < 1e-2


def test_mechanical_lowpass_settings_validated():
    from testbed.core.errors import ScenarioError
    with pytest.raises(ScenarioError):
        measure(mechanical_dataset(), {"derivatives": "lowpass", "cutoff_hz": -1.0}, "mechanical")
    with pytest.raises(ScenarioError):
        measure(mechanical_dataset(), {"derivatives": "spline"}, "mechanical")


def test_mechanical_never_reads_truth_or_reference():
    cfg = {"derivatives": "estimated", "window": 101}
    plain = measure(mechanical_dataset(), cfg, "mechanical")
    other = measure(mechanical_dataset(truth=Forbidden(), reference=Forbidden()), cfg, "mechanical")
    for name in ("x", "xd", "xdd", "u", "input_map"):
        np.testing.assert_array_equal(getattr(other, name), getattr(plain, name))


def test_mechanical_joints_and_inputs_come_from_the_data():
    """No five-bar facts in the chain: three joints, one torque on the second, named freely."""
    n = 100
    th = np.arange(3 * n, dtype=float).reshape(3, n)
    ds = Dataset(100.0, {"theta": Signal(th, ("a", "b", "c"), "rad"),
                         "dtheta": Signal(2 * th, ("da", "db", "dc"), "rad/s"),
                         "ddtheta": Signal(3 * th, ("dda", "ddb", "ddc"), "rad/s^2"),
                         "torque": Signal(np.ones((1, n)), ("motor",), "N m", acts_on=("b",))})
    m = measure(ds, {}, "mechanical")
    assert m.channels == ("a", "b", "c") and m.inputs == ("motor",)
    np.testing.assert_array_equal(m.input_map, [[0], [1], [0]])
    np.testing.assert_array_equal(m.xdd, 3 * th)
    ds.measured["ddtheta"] = Signal(np.zeros((2, n)), ("x", "y"), "rad/s^2")
    with pytest.raises(ValueError, match="expected 3"):
        measure(ds, {}, "mechanical")


def test_mechanical_inputs_must_declare_their_joints():
    ds = mechanical_dataset()
    ds.measured["theta"] = Signal(np.zeros((3, 100)), ("a", "b", "c"), "rad")
    with pytest.raises(ValueError, match="acts on 'th1', not a channel of 'theta'"):
        measure(ds, {}, "mechanical")
    ds = mechanical_dataset()
    tq = ds.measured["torque"]
    ds.measured["torque"] = Signal(tq.data, tq.channels, tq.unit)
    with pytest.raises(ValueError, match="does not declare the joints"):
        measure(ds, {}, "mechanical")
