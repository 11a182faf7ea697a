"""SINDy-PI's replay rule on exact data (:meth:`identify.sindy_pi.SINDyPI._replay_check`): the
held-out choice must replay the record; where it does not (the record leaves the equations
non-unique), the equations are chosen again by rollout over the unpruned library.

The case: the paper's sine replay on an unseen five-bar (benchmarks/unseen/unseen_linkages.toml,
member fb_sine__004, 0.89 Hz, clean, recorded rates).  The equations the held-out error picks fit
the rates to round-off (held-out error 1e-15) and lose the loop closure at 1.3 s of the record;
the data came from the study's own member, so the test runs what the sweep runs."""

from pathlib import Path

import numpy as np
import pytest

from identify.sindy_pi import SINDyPI
from testbed.core.errors import DivergenceError
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure
from testbed.studies.study import load_study

UNSEEN = Path(__file__).resolve().parents[2] / "benchmarks" / "unseen" / "unseen_linkages.toml"


def _data(dataset_cache, scenario):
    ds = dataset_cache.get(scenario)
    return measure(ds, scenario.signal, "mechanical")


@pytest.fixture(scope="module")
def sine004(dataset_cache):
    member = {m.name: m for m in load_study(UNSEEN).scenarios}["fb_sine__004"]
    return member, _data(dataset_cache, member)


def _replay(model, data):
    """RMSE [rad] of the model's simulation of the whole record from its first state."""
    tr = model.simulate(data.x[:, 0], data.xd[:, 0], data.t, data.u)
    return float(np.sqrt(np.mean((tr.x - data.x) ** 2, axis=1)).max())


def test_rich_record_keeps_the_held_out_choice(dataset_cache):
    data = _data(dataset_cache, load_scenario("fivebar_multisine"))
    m = SINDyPI(input_hold="zoh").fit(data)
    assert m.selection_ == "holdout" and m.replay_rule_.endswith(": kept")
    # measured 6.1e-7 rad (the integration error); the check's bar is 1e-4
    assert m.replay_rmse_ < 1e-5
    assert len(m.pruned_terms_) == 2  # the two kinematic identities only


@pytest.mark.slow
def test_sine_replay_with_non_unique_equations_is_chosen_by_rollout(sine004):
    member, data = sine004
    hold = SINDyPI(input_hold="zoh", selection="holdout").fit(data)  # user setting: no rule
    assert hold.replay_rmse_ is None and hold.replay_rule_.startswith("no replay check")
    assert float(np.max(hold.validation_errors_)) < 1e-12  # exact in derivative space ...
    with pytest.raises(DivergenceError, match="loop closure"):  # ... yet loses the loop (1.3 s)
        _replay(hold, data)
    m = SINDyPI(input_hold="zoh").fit(data)
    assert m.selection_ == "rollout" and "chosen again by rollout" in m.replay_rule_
    assert m.pruned_terms_ == []  # the pool is the unpruned library
    # the attribute is the replay of the record from its first state (same simulation)
    assert m.replay_rmse_ == pytest.approx(_replay(m, data), rel=1e-9)
    # measured 1.04e-4 rad over the 8 s record: bar 1e-3, 10x that (a replay over 8 s of a model
    # exact only on the record amplifies round-off), 50x below the paper's 0.0501 rad
    assert m.replay_rmse_ < 1e-3
