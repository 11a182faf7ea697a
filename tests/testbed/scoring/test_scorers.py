"""The dynamical scorer names a rollout below a state's declared lower bound (a concentration
below 0) as non-physical, its scores kept; a rig that declares nothing is scored as before."""

from dataclasses import replace

import numpy as np
import pytest

from testbed.core.measurement import Trajectory
from testbed.pipeline.generate import generate
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure
from testbed.scoring.run import noise_free
from testbed.scoring.scorers import (
    BOUND_RTOL,
    FAIL,
    STABLE_BLOWUP,
    bound_failures,
    physical_failures,
    score_dynamical,
    score_structural,
    stable_blowup,
    verdict,
)
from testbed.studies.statistics import failure_kind

_CONC = {"x": (0.0, "a concentration")}


def test_a_rollout_below_the_bound_by_more_than_the_tolerance_is_non_physical():
    ref = np.linspace(20.0, 0.0, 101)[None, :]  # a decay to 0: range 20 mM
    sim = ref.copy()
    sim[0, -1] = -3.83
    why = bound_failures(sim, ref, ["x"], ["mM"], _CONC)
    assert why == {"bounds": "non-physical: the simulated x reaches -3.83 mM, below 0 mM "
                             "(x is a concentration)"}
    # within the tolerance (a tenth of it: round-off of a rollout that keeps x >= 0) nothing;
    # ten times it, named
    sim[0, -1] = -0.1 * BOUND_RTOL * 20.0
    assert bound_failures(sim, ref, ["x"], ["mM"], _CONC) == {}
    sim[0, -1] = -10.0 * BOUND_RTOL * 20.0
    assert set(bound_failures(sim, ref, ["x"], ["mM"], _CONC)) == {"bounds"}


def test_only_declared_states_and_simulated_samples_count():
    ref = np.linspace(2.0, 0.1, 50)[None, :]
    sim = ref - 1.0  # reaches -0.9
    assert bound_failures(sim, ref, ["x"], ["mM"], {}) == {}  # nothing declared
    assert bound_failures(sim, ref, ["x"], ["mM"], {"y": (0.0, "a mass")}) == {}
    nan = np.full_like(ref, np.nan)  # a model never simulated: its failure says why
    assert bound_failures(nan, ref, ["x"], ["mM"], _CONC) == {}
    cut = ref.copy()
    cut[0, 10:] = np.nan  # diverged at sample 10: the samples before it count
    cut[0, 5] = -0.5
    assert "reaches -0.5 mM" in bound_failures(cut, ref, ["x"], ["mM"], _CONC)["bounds"]


class _Fixed:
    """A fitted model whose rollout is given (the true law's terms and coefficients, so only
    the rollout can fail)."""

    def __init__(self, coef, x):
        self.feature_names_ = ["dx", "x*dx", "1", "x"]
        self.coef_, self._x = np.atleast_2d(coef), np.atleast_2d(x)

    def simulate(self, x0, xd0, t, u):
        return Trajectory(self._x, np.gradient(self._x, t, axis=1), np.zeros_like(self._x))


@pytest.fixture(scope="module")
def record():
    sc = load_scenario("michaelis_menten")
    ds = generate(sc)
    data = measure(ds, sc.signal, "dynamical")
    return ds, data, measure(noise_free(ds), sc.signal, "dynamical")


def test_score_dynamical_names_a_negative_concentration_and_keeps_the_scores(record):
    ds, data, clean = record
    ref = ds.reference["x"].data
    coef = ds.truth["equation_coef"]
    went_negative = ref.copy()
    went_negative[0, -50:] = -3.83  # kin21: round 16's mm16_jx0_x0_20_20s rollout at 1 %
    sc = score_dynamical(ds, data, clean, _Fixed(coef, went_negative))
    assert sc.failures.get("bounds") == ("non-physical: the simulated x reaches -3.83 mM, below "
                                         "0 mM (x is a concentration)")
    assert np.isfinite(sc.values["state_rmse"]) and sc.values["state_rmse"] > 1.0  # kept
    assert sc.values["coef_error"] < 1e-12  # the equation's scores too
    assert verdict([], sc.failures) == FAIL
    # the reference's own rollout stays within the bound: nothing named
    assert score_dynamical(ds, data, clean, _Fixed(coef, ref.copy())).failures == {}
    # a rig that declares nothing (data of a rig not registered here) is scored as before
    other = replace(ds, attrs={**ds.attrs, "rig": "not_a_registered_rig"})
    assert "bounds" not in score_dynamical(other, data, clean, _Fixed(coef, went_negative)).failures


# ------------------------------------------- a stable model's blow-up is not a divergence
_BLOWUP = "diverged: blew up (beyond 1000 x the reference's largest value) simulation (at t = 7.813e-05 s)"


def test_a_stable_models_blowup_names_its_fastest_pole_not_a_divergence():
    """Round 24's ``b24_br_L0p5_w20_t6_s6_z3`` (brass read by six sensors at 3 % damping),
    ``sgd_sindy`` clean, seed 154: every pole of the identified model stable (the fastest
    -8.0e10 1/s), its acceleration 3500 x the record's one sample after the start, was
    "diverged: blew up".  A 1-DOF model with the same kind of overdamped direction (poles
    -1e9 and -1e-9 1/s) stands for it; an unstable one keeps "diverged"."""
    dt = 1.0 / 12800.0
    why = stable_blowup(_BLOWUP, np.eye(1), np.array([[1e9]]), np.eye(1), dt, 1.0)
    assert why.startswith(f"{STABLE_BLOWUP}: no pole of the model grows over the record")
    assert "the fastest at -1e+09" in why
    assert "|lambda| dt = 7.81e+04 per sample: faster than the record's sample interval resolves" in why
    assert "beyond 1000 x the reference's largest value (at t = 7.813e-05 s): no divergence" in why
    assert failure_kind(why) == ["response blew up"]
    # a pole the record resolves is named without the clause
    slow = stable_blowup(_BLOWUP, np.eye(1), np.array([[100.0]]), np.eye(1), dt, 1.0)
    assert slow.startswith(STABLE_BLOWUP) and "resolves" not in slow
    # growth is a divergence; a non-finite state too, whatever the poles
    assert stable_blowup(_BLOWUP, np.eye(1), np.array([[-1.0]]), np.eye(1), dt, 1.0) == _BLOWUP
    nonfinite = "diverged: non-finite simulation (at t = 0.1 s)"
    assert stable_blowup(nonfinite, np.eye(1), np.array([[1e9]]), np.eye(1), dt, 1.0) == nonfinite


def test_a_blowup_with_a_growing_slow_pole_or_a_cubic_stays_a_divergence():
    """Review 25b: beside a -1e11 1/s pole, :func:`physical_failures`' relative bar (1e-9 x
    the fastest pole) passes a +10 1/s one, whose response grows as exp(10 t) and blows up
    within the second: still "diverged".  A cubic model's linear poles do not bound its
    response (a softening cubic escapes from a stable linear part): "diverged" too."""
    dt = 1.0 / 12800.0
    M, C, K = np.eye(2), np.diag([1e11, 0.0]), np.diag([1.0, -100.0])
    assert physical_failures(M, C, K) == {}  # the relative bar alone passes it
    assert stable_blowup(_BLOWUP, M, C, K, dt, 1.0) == _BLOWUP
    # a pole growing at 1e-3 1/s beside the same fast one: no growth over 0.5 s (5e-4 <= 1e-3),
    # growth over 10 s (1e-2); no record at all claims nothing
    slow_growth = np.diag([1.0, -1e-6])
    assert stable_blowup(_BLOWUP, M, C, slow_growth, dt, 0.5).startswith(STABLE_BLOWUP)
    assert stable_blowup(_BLOWUP, M, C, slow_growth, dt, 10.0) == _BLOWUP
    assert stable_blowup(_BLOWUP, np.eye(1), np.array([[1e9]]), np.eye(1), dt, 0.0) == _BLOWUP
    soft = stable_blowup(_BLOWUP, np.eye(1), np.array([[1e-3]]), np.eye(1), dt, 10.0, -np.eye(1))
    assert soft == _BLOWUP
    linear = stable_blowup(_BLOWUP, np.eye(1), np.array([[1e-3]]), np.eye(1), dt, 10.0, np.zeros((1, 1)))
    assert linear.startswith(STABLE_BLOWUP)


class _Huge:
    """A fitted structural model of given matrices whose response is a million times the
    record's: the blow-up the scorer sees (the matrices decide its name)."""

    def __init__(self, M, C, K, ref):
        self.M_, self.C_, self.K_, self._ref = M, C, K, ref

    def simulate(self, x0, xd0, t, u):
        y = 1e6 * self._ref[:, : t.size]
        return Trajectory(y, y, y)


@pytest.fixture(scope="module")
def beam_record():
    sc = load_scenario("cantilever_stiff_impact")
    sc = replace(sc, simulation={**sc.simulation, "duration": 0.1})
    ds = generate(sc)
    return ds, measure(ds, sc.signal, "structural"), measure(noise_free(ds), sc.signal, "structural")


def test_the_structural_scorer_names_a_stable_models_blowup(beam_record):
    ds, data, clean = beam_record
    n = data.n_channels
    ref = clean.xdd[:, data.free_start:]
    M, K = 0.05 * np.eye(n), 1e4 * np.eye(n)
    stable = score_structural(ds, data, clean, _Huge(M, 1e8 * np.eye(n), K, ref))
    assert stable.failures["simulation"].startswith(STABLE_BLOWUP)
    assert verdict([], stable.failures) == FAIL and np.isnan(stable.values["trac"])
    grows = score_structural(ds, data, clean, _Huge(M, -1.0 * np.eye(n), K, ref))
    assert grows.failures["simulation"].startswith("diverged: blew up")
