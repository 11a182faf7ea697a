"""SINDy-PI on an open underactuated chain (the cart-pole: force on the cart, pole passive):
one implicit equation per coordinate, the passive one without inputs, simulated by solving
the 2 x 2 system for both accelerations; no loop closure is invented."""

import dataclasses

import numpy as np
import pytest

from identify.sindy_pi import SINDyPI
from testbed.core.errors import IdentificationError
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure
from testbed.scoring.equation_basis import evaluate_terms


@pytest.fixture(scope="module")
def case(dataset_cache):
    sc = load_scenario("scenarios/cartpole.toml")
    ds = dataset_cache.get(sc)  # bit-identical to generate() (tests/testbed/pipeline/test_cache.py)
    return sc, ds, measure(ds, sc.signal, "mechanical")


@pytest.fixture(scope="module")
def fitted(case):
    sc, _, data = case
    return SINDyPI(library=sc.identify["library"], input_hold="zoh").fit(data)


def on_truth(model, truth):
    """The identified rows on the truth's terms (zeros where absent), and the truth's rows."""
    pos = {n: i for i, n in enumerate(model.feature_names_)}
    assert set(truth.equation_terms) <= set(pos)
    ident = model.coef_[:, [pos[t] for t in truth.equation_terms]]
    return ident, truth.equation_coef


def test_open_chain_one_equation_per_coordinate_exact(case, fitted):
    _, ds, _ = case
    assert fitted.closure_ is None and fitted.passive_.tolist() == [1]
    assert fitted.actuated_.tolist() == [0, 1]  # the cart's equation, then the pole's
    lib = fitted._library_
    inputs = lib.input_columns(0)
    assert np.any(fitted.coef_[0, inputs] != 0)      # the cart's equation holds the force
    assert np.all(fitted.coef_[1, inputs] == 0)      # the pole's has no input term
    ident, true = on_truth(fitted, ds.typed_truth)
    # support: exactly the true terms, nothing else of the 15-term library
    assert np.count_nonzero(fitted.coef_) == np.count_nonzero(true)
    for row_i, row_t in zip(ident, true, strict=True):
        k = np.argmax(np.abs(row_t))
        # measured 6e-15; 1e-8: least squares on exact data through a Gram matrix of condition
        # ~1e6 may lose that much on another BLAS, a wrong coefficient is off by >= 1e-3
        np.testing.assert_allclose(row_i / row_i[k], row_t, rtol=0, atol=1e-8)


def test_simulation_solves_both_accelerations(case, fitted):
    _, ds, data = case
    th0, dth0 = ds.typed_truth.theta0, ds.typed_truth.dtheta0
    tr = fitted.simulate(th0, dth0, data.t, data.u)
    # RK4 at 1 ms of exact equations over 10 s: measured 3e-11; 1e-8 is RK4's own order
    # for this ~1 Hz motion, a wrong sign of any term diverges by 1e-2 within seconds
    assert np.sqrt(np.mean((tr.x - data.x) ** 2, axis=1)).max() < 1e-8
    # the accelerations the model solves for satisfy the true equations
    sig = {"th": tr.x, "dth": tr.xd, "ddth": tr.xdd, "u": data.u}
    T = evaluate_terms(ds.typed_truth.equation_terms, sig)
    for row in ds.typed_truth.equation_coef:
        assert np.abs(T @ row).max() < 1e-7 * np.abs(T * row).max()


def test_deterministic(case, fitted):
    sc, _, data = case
    again = SINDyPI(library=sc.identify["library"], input_hold="zoh").fit(data)
    assert np.array_equal(again.coef_, fitted.coef_)


def test_passive_equation_missing_from_the_library_is_one_clear_error(case):
    sc, _, data = case
    lib = [t for t in sc.identify["library"] if "ddth2" not in t]
    with pytest.raises(IdentificationError, match="passive coordinate 2"):
        SINDyPI(library=lib).fit(data)
    with pytest.raises(IdentificationError, match="lhs holds no input-free term"):
        SINDyPI(library=sc.identify["library"], lhs=["u1"]).fit(data)
    with pytest.raises(IdentificationError, match="ensemble"):
        SINDyPI(library=sc.identify["library"], ensemble=5).fit(data)


def test_a_declared_closure_is_still_required_to_fit(case):
    """Link lengths in the prior declare a loop: the open-chain path is not taken silently."""
    sc, _, data = case
    d = dataclasses.replace(data, prior={"l1": 1.0, "l2": 1.0, "l3": 1.0, "l4": 1.0, "L0": 1.0})
    with pytest.raises(IdentificationError, match="planar single-loop closure"):
        SINDyPI(library=sc.identify["library"]).fit(d)
