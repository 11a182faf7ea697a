"""pysindy's optimizers and weak form behind the structural contract (identify/pysindy_field.py):
they recover a known chain, they are deterministic and leave numpy's global generator alone, and
the declared limits (weak form: linear only) are refused when a scenario loads."""

import numpy as np
import pytest

from benchmarks import bench_sgd_sindy
from identify import IDENTIFIERS
from testbed.core.errors import ScenarioError

VARIANTS = ["pysindy", "pysindy_sr3", "pysindy_ensemble", "pysindy_weak"]


@pytest.fixture(scope="module")
def chain():
    system = bench_sgd_sindy.chain_system()
    return system, bench_sgd_sindy.chain_measurement(system, duration=0.5)


def _true_frequencies(system):
    M, K = (np.asarray(system[k], dtype=float) for k in ("M", "K"))
    return np.sort(np.sqrt(np.linalg.eigvals(np.linalg.solve(M, K)).real)) / (2 * np.pi)


@pytest.mark.parametrize("name", VARIANTS)
def test_variant_recovers_the_chain(name, chain):
    system, data = chain
    model = IDENTIFIERS.get(name)().fit(data)
    assert model.kind == "structural" and model.M_.shape == (data.n_channels,) * 2
    # M^-1 K and the natural frequencies are identifiable from this free decay
    f_true = _true_frequencies(system)
    np.testing.assert_allclose(np.sort(model.natural_frequencies_), f_true, rtol=2e-3)
    assert model.score(data) > 0.999  # truth-free R^2 of the accelerations
    assert np.trace(model.M_) == pytest.approx(data.prior["reduced_mass_trace"])


def test_ensemble_is_seeded_and_leaves_the_global_generator_alone(chain):
    _, data = chain
    np.random.seed(123)  # noqa: NPY002 (the global generator is what pysindy draws from)
    before = np.random.get_state()[1].copy()  # noqa: NPY002
    a = IDENTIFIERS.get("pysindy_ensemble")(seed=1).fit(data)
    np.testing.assert_array_equal(np.random.get_state()[1], before)  # noqa: NPY002
    b = IDENTIFIERS.get("pysindy_ensemble")(seed=1).fit(data)
    np.testing.assert_array_equal(a.coef_, b.coef_)


def test_threshold_prunes_on_the_standardised_scale(chain):
    _, data = chain
    dense = IDENTIFIERS.get("pysindy")(threshold=0.0).fit(data)
    sparse = IDENTIFIERS.get("pysindy")(threshold=0.5).fit(data)
    assert np.count_nonzero(sparse.coef_) < np.count_nonzero(dense.coef_)


def test_weak_form_is_linear_only_and_says_so():
    cls = IDENTIFIERS.get("pysindy_weak")
    with pytest.raises(ScenarioError, match="cubic"):
        cls.validate_hyperparameters({"cubic": True}, file="s.toml")
    with pytest.raises(ScenarioError, match="optimizer"):
        cls.validate_hyperparameters({"optimizer": "lasso"}, file="s.toml")
