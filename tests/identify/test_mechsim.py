"""The compiled simulation of identified implicit models (identify/_compiled.py) against the
Python implementation it replaced (tests/identify/mechsim_reference.py): the same trajectory
to round-off, and failures raised as DivergenceError with their time."""

import numpy as np
import pytest

from benchmarks import sindy_pi_problems
from identify.sindy_pi import SINDyPI
from testbed.core.errors import ArgumentError, DivergenceError
from tests.identify import mechsim_reference as ref


@pytest.fixture(scope="module")
def fitted():
    fb = sindy_pi_problems.fivebar(duration=4.0, fs=1e3, amp=1.0)
    return fb.data, SINDyPI().fit(fb.data)


@pytest.fixture(scope="module")
def fivebar(fitted):
    d, est = fitted
    return d, est.model_


def _reference(model):
    cl = model.closure
    return ref.ImplicitModel(model.library, model.coef, model.actuated,
                             ref.LoopClosure(cl.a, cl.b, cl.passive, cl.source))


@pytest.mark.parametrize("hold", ["linear", "zoh"])
def test_same_trajectory_as_the_python_reference(fivebar, hold):
    d, model = fivebar
    n = 1001  # 1 s at RK4 steps of 1 ms
    args = (d.x[:, 0], d.xd[:, 0], d.t[:n], d.u[:, :n], 1e-3, hold)
    new, old = model.simulate(*args), _reference(model).simulate(*args)
    for k in ("x", "xd", "xdd"):
        a, b = getattr(new, k), getattr(old, k)
        # measured 1e-16..7e-16: only the order of a few sums differs
        assert np.abs(a - b).max() <= 1e-12 * np.abs(b).max(), k


def test_closure_methods_match_the_reference(fivebar):
    d, model = fivebar
    cl = model.closure
    rc = ref.LoopClosure(cl.a, cl.b, cl.passive, cl.source)
    q0 = d.x[:, :500] + 1e-3 * np.sin(np.arange(500))  # passive guesses off the manifold
    q, qr = cl.solve(q0), rc.solve(q0)
    np.testing.assert_allclose(q, qr, rtol=0, atol=1e-13)
    np.testing.assert_allclose(cl.velocity(q, d.xd[:, :500]), rc.velocity(q, d.xd[:, :500]),
                               rtol=1e-12, atol=1e-14)
    for a, b in zip(cl.acceleration_map(q, d.xd[:, :500]), rc.acceleration_map(q, d.xd[:, :500]),
                    strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-14)


def test_singular_model_raises_divergence_with_time(fivebar):
    d, model = fivebar
    cls = type(model)
    coef = model.coef.copy()
    coef[:, model.library.acc_index >= 0] = 0.0  # no acceleration left: singular at once
    bad = cls(model.library, coef, model.actuated, model.closure)
    with pytest.raises(DivergenceError, match="singular") as err:
        bad.simulate(d.x[:, 0], d.xd[:, 0], d.t[:101], d.u[:, :101], 1e-3)
    assert err.value.time == pytest.approx(0.0)


@pytest.mark.parametrize("t, words", [
    # hostile round 25: one sample was scipy's "`x` must be strictly increasing sequence" (the
    # output spline), [0, 1e308] an OverflowError converting the step count to an integer
    (np.array([0.0]), "at least 2 sample times"),
    (np.array([0.0, 1e308]), r"times spanning 1e\+308 s: expected a span of at most 1e\+07 RK4 steps"),
    # 1e7 steps of 1 ms and one more: the bound is the step count's, not the span's
    (np.array([0.0, 1.0001e4]), "at most 1e\\+07 RK4 steps"),
])
def test_simulate_refuses_times_it_cannot_step_in_one_line(fitted, t, words):
    d, est = fitted
    u = None if t.size < 2 else d.u[:, :2]
    for where, call in (("SINDyPI.simulate", lambda: est.simulate(d.x[:, 0], d.xd[:, 0], t, u)),
                        ("ImplicitModel.simulate",
                         lambda: est.model_.simulate(d.x[:, 0], d.xd[:, 0], t, u, 1e-3))):
        with pytest.raises(ArgumentError, match=rf"^{where}: argument 't': .*{words}") as e:
            call()
        assert "\n" not in str(e.value)


def test_simulate_of_two_samples_still_runs(fitted):
    d, est = fitted
    assert est.simulate(d.x[:, 0], d.xd[:, 0], d.t[:2], d.u[:, :2]).x.shape == (d.n_channels, 2)
