"""One conformance test of the estimator contract, parametrised over every registered identifier.

The contract (identify/_base.py): ``__init__`` only stores hyperparameters under their own names;
``fit(data)`` returns ``self``; learned attributes end in ``_`` and exist only after ``fit``;
fitting is deterministic; ``clone`` gives an unfitted twin; ``simulate`` returns a Trajectory of
the data's shape; ``equations`` returns text.  Structural identifiers expose ``M_``, ``C_``,
``K_``; mechanical and dynamical ones ``coef_`` and ``feature_names_``.  The contract is checked
on every registered identifier and on a plugin loaded from a file (the guide's example,
``docs/identifiers.md``), as a user adds one.
"""

import inspect
import re
from pathlib import Path

import numpy as np
import pytest
from sklearn.base import clone

from benchmarks import bench_sgd_sindy, sindy_pi_problems
from identify import IDENTIFIERS
from identify._base import Identifier
from testbed.core.measurement import Measurement, Trajectory
from testbed.pipeline.plugins import load_plugins

GUIDE = Path(__file__).resolve().parents[2] / "docs" / "identifiers.md"

# Small budgets so each identifier fits in seconds: the contract does not depend on them.
FAST = {"sgd_sindy": {"epochs": 2}, "pysindy_pi": {"stride": 4}}


@pytest.fixture(scope="module")
def structural_data():
    return bench_sgd_sindy.chain_measurement(bench_sgd_sindy.chain_system(), duration=0.1)


@pytest.fixture(scope="module")
def pendulum():
    return sindy_pi_problems.double_pendulum(duration=3.0, fs=1e3, amp=10.0)


@pytest.fixture(scope="module")
def logistic():
    """A first-order autonomous record in closed form: the logistic ``x = 1 / (1 + e^-t)``,
    ``dx = x (1 - x)``, 0..4 s at 100 Hz."""
    t = np.arange(400) / 100.0
    x = 1.0 / (1.0 + np.exp(-t))
    xd = x * (1.0 - x)
    return Measurement(fs=100.0, x=x[None], xd=xd[None], xdd=(xd * (1 - 2 * x))[None],
                       channels=("x",))


def _make(name, pendulum):
    cls = IDENTIFIERS.get(name)
    params = dict(FAST.get(name, {}))
    if cls.kind == "mechanical":
        params["library"] = list(pendulum.truth_terms)  # the problem's own terms: small and exact
    return cls(**params)


@pytest.fixture
def guide_plugin(tmp_path):
    """The guide's example identifier (``docs/identifiers.md``), saved as a file and loaded as a
    plugin (``--plugin``); its registration is forgotten after the test."""
    code = "\n\n".join(re.findall(r"^```python\n(.*?)^```", GUIDE.read_text(), flags=re.S | re.M))
    path = tmp_path / "my_method.py"
    path.write_text(code)
    snap = IDENTIFIERS.snapshot()
    try:
        (added,) = load_plugins([str(path)])
        yield added.removeprefix("identifier ")
    finally:
        IDENTIFIERS.restore(snap)


def check_contract(name, est, data):
    """Assert the estimator contract on ``est``, an unfitted ``IDENTIFIERS.get(name)``, fitted to
    ``data`` (a Measurement of its kind)."""
    cls = IDENTIFIERS.get(name)
    assert issubclass(cls, Identifier) and cls.name in ("", name) and cls.kind in (
        "structural", "mechanical", "dynamical")
    # __init__ stores every hyperparameter under its own name and nothing else (no learned,
    # cached or private attribute: clone and set_params would not reset it)
    init_names = [p for p in inspect.signature(cls.__init__).parameters if p != "self"]
    assert sorted(est.get_params()) == sorted(init_names)
    assert sorted(vars(est)) == sorted(init_names), (name, set(vars(est)) ^ set(init_names))
    assert est.fit(data) is est
    # what fit sets beside the hyperparameters is learned (public names end in _) or private
    added = set(vars(est)) - set(init_names)
    assert not [k for k in added if not k.endswith("_") and not k.startswith("_")], (name, added)
    learned = {k for k in vars(est) if k.endswith("_") and not k.startswith("_")}
    need = {"M_", "C_", "K_"} if cls.kind == "structural" else {"coef_", "feature_names_"}
    assert need <= learned, f"{name} lacks {need - learned}"
    # clone (ours and scikit-learn's): same hyperparameters, nothing learned; refitting gives
    # identical results
    for twin in (est.clone(), clone(est)):
        assert type(twin) is cls and twin.get_params() == est.get_params()
        assert sorted(vars(twin)) == sorted(init_names)
    twin = est.clone()
    # a fit learns afresh: a learned attribute an earlier fit left (here planted) does not
    # survive it (identify._base's fit wrapper; an earlier record_agreement_ decided a refit's
    # rule in SGDSINDy before)
    twin.stale_from_an_earlier_fit_ = 1.0
    twin.fit(data)
    assert not hasattr(twin, "stale_from_an_earlier_fit_"), name
    for k in need:
        a, b = getattr(est, k), getattr(twin, k)
        if isinstance(a, np.ndarray):
            np.testing.assert_array_equal(a, b)
        else:
            assert a == b
    # simulate from the data's initial state, with its inputs where it has some
    n = min(data.n_samples, 200)
    t = np.arange(n) / data.fs
    u = None if data.u is None else data.u[:, :n]
    traj = est.simulate(data.x[:, 0], data.xd[:, 0], t, u)
    assert isinstance(traj, Trajectory)
    for arr in traj:
        assert arr.shape == (data.n_channels, n)
    eqs = est.equations()
    assert isinstance(eqs, list) and eqs and all(isinstance(e, str) and e for e in eqs)


@pytest.mark.parametrize("name", IDENTIFIERS.names())
def test_identifier_follows_the_estimator_contract(name, structural_data, pendulum, logistic):
    data = {"structural": structural_data, "dynamical": logistic}.get(IDENTIFIERS.get(name).kind,
                                                                      pendulum.data)
    check_contract(name, _make(name, pendulum), data)
    # every built-in identifier declares what check_contract's refit just showed (a study then
    # fits its 0 % cells once for all seeds: testbed.studies.sweep.shared_computation)
    assert vars(IDENTIFIERS.get(name)).get("deterministic") is True  # its own, not inherited


def test_a_plugin_identifier_follows_the_estimator_contract(guide_plugin, structural_data):
    assert IDENTIFIERS.origin(guide_plugin).startswith("file ")
    check_contract(guide_plugin, IDENTIFIERS.get(guide_plugin)(), structural_data)
    test_every_hyperparameter_is_declared_and_nothing_else(guide_plugin)
    # the guide's example declares the prior it reads, as the guide's contract asks (an
    # undeclared plugin, None, would let `testbed identify --prior` take any key)
    assert IDENTIFIERS.get(guide_plugin).prior_keys == ("total_mass",)


@pytest.mark.parametrize("name", IDENTIFIERS.names())
def test_every_hyperparameter_is_declared_and_nothing_else(name):
    """``hyperparameters`` (the declaration scenario files are checked against) equals
    ``__init__``: same names, same order, same defaults, each with a line of doc."""
    cls = IDENTIFIERS.get(name)
    assert "hyperparameters" in vars(cls) or any(
        "hyperparameters" in vars(b) for b in cls.__mro__[1:] if b is not Identifier), name
    params = {k: p for k, p in inspect.signature(cls.__init__).parameters.items() if k != "self"}
    declared = cls.hyperparameters
    assert list(declared) == list(params), (name, set(declared) ^ set(params))
    for k, p in params.items():
        f = declared[k]
        default = list(p.default) if isinstance(p.default, tuple) else p.default
        assert f.default == default and type(f.default) is type(default), (name, k, f.default)
        assert f.doc, (name, k)
    # the defaults themselves validate (a declaration that rejects its own default is wrong)
    assert cls.validate_hyperparameters({}) == {k: f.default for k, f in declared.items()}
    given = {k: f.default for k, f in declared.items() if f.default is not None}
    cls.validate_hyperparameters(given)


@pytest.mark.parametrize("name", IDENTIFIERS.names())
def test_every_identifier_declares_the_prior_keys_it_reads(name):
    """A declared tuple (``testbed identify --prior`` refuses other keys); a mass-scaled
    structural identifier reads the mass priors, SINDy-PI the loop's link lengths."""
    keys = IDENTIFIERS.get(name).prior_keys
    assert isinstance(keys, tuple) and all(isinstance(k, str) for k in keys), (name, keys)
    if IDENTIFIERS.get(name).kind == "structural":
        assert "total_mass" in keys and "reduced_mass_trace" in keys, name


def test_an_identifier_without_its_own_init_has_no_hyperparameters():
    # a plugin written without __init__ (nothing to set) inherited object's (*args, **kwargs)
    # as "hyperparameters": get_params raised AttributeError 'args' when its run was saved
    class Bare(Identifier):
        name = "bare"
        kind = "structural"

    class Varargs(Identifier):
        def __init__(self, alpha: float = 1.0, *args, **kwargs):
            self.alpha = alpha

    assert Bare().get_params() == {} and Bare().clone().get_params() == {}
    assert Varargs().get_params() == {"alpha": 1.0}
