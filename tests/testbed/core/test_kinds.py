"""Rig kinds: typed truth, and dispatch through the kind registries (no if/else on a kind)."""

import numpy as np
import pytest

from testbed.core.dataset import Dataset, Signal
from testbed.core.errors import ScenarioError
from testbed.core.kinds import METRICS
from testbed.core.truth import (
    TRUTH_TYPES,
    MechanicalTruth,
    StructuralTruth,
    Truth,
    TruthError,
    register_truth,
    truth_type,
)
from testbed.pipeline.scenario import Scenario, load_scenario
from testbed.pipeline.signal_chain import (
    SIGNAL_CHAINS,
    SIGNAL_SCHEMAS,
    SignalChain,
    measure,
    register_signal_chain,
)
from testbed.scoring.scorers import SCORERS, failed_scores, register_scorer, score


def structural(n=3, m=2):
    eye_n, eye_m = np.eye(n), np.eye(m)
    return {"M": eye_n, "C": eye_n, "K": eye_n, "frequencies_hz": np.arange(1.0, n + 1),
            "damping_ratios": np.full(n, 0.01), "modes": eye_n, "sensor_modes": eye_m,
            "Mr": eye_m, "Cr": eye_m, "Kr": eye_m}


def test_every_kind_has_truth_chain_scorer_and_catalogue():
    assert set(METRICS) == set(TRUTH_TYPES) == set(SIGNAL_CHAINS) == set(SCORERS)
    assert SIGNAL_SCHEMAS == {k: c.schema for k, c in SIGNAL_CHAINS.items()}


def test_structural_truth_round_trip_and_shapes():
    d = structural()
    t = StructuralTruth.from_dict(d)
    assert t.T is None and set(t.to_dict()) == set(d)
    np.testing.assert_array_equal(t.to_dict()["Mr"], d["Mr"])
    assert truth_type("structural") is StructuralTruth
    assert StructuralTruth.fields()["Mr"]["unit"] == "kg"


@pytest.mark.parametrize("change, match", [
    (lambda d: d.pop("Kr"), "missing 'Kr'"),
    (lambda d: d.update(stiffness=np.eye(2)), "unknown key 'stiffness'"),
    (lambda d: d.update(Kr=np.eye(3)), r"'Kr' has shape \(3, 3\), expected \(m, m\) with m = 2"),
    (lambda d: d.update(frequencies_hz=np.ones((3, 1))), "'frequencies_hz' has shape"),
    (lambda d: d.update(k3=np.array([1.0, 2.0])), "'k3' has shape"),
    (lambda d: d.update(M=np.full((3, 3), np.nan)), "'M' holds non-finite"),
])
def test_structural_truth_errors_name_the_key(change, match):
    d = structural()
    change(d)
    with pytest.raises(TruthError, match=match) as e:
        StructuralTruth.validate(d)
    assert e.value.key is not None and e.value.key in match


def test_units_of_unknown_keys_are_refused():
    with pytest.raises(TruthError, match="unit for 'Q'"):
        StructuralTruth.validate(structural(), {"Mr": "kg", "Q": "J"})
    StructuralTruth.validate(structural(), {"Mr": "kg"})  # a missing unit is the declared one


def test_mechanical_truth_text_terms():
    d = {"equation_terms": ["ddth1", "u1"], "equation_coef": np.array([[1.0, -1.0]]),
         "theta0": np.zeros(4), "dtheta0": np.zeros(4)}
    assert MechanicalTruth.from_dict(d).equation_terms == ["ddth1", "u1"]
    with pytest.raises(TruthError, match="'equation_terms' must be a list of str"):
        MechanicalTruth.validate({**d, "equation_terms": np.zeros(2)})
    with pytest.raises(TruthError, match=r"'equation_coef' has shape \(1, 3\).*t = 2"):
        MechanicalTruth.validate({**d, "equation_coef": np.ones((1, 3))})


def test_readers_take_the_truth_typed():
    measured = {"x": Signal(np.zeros((2, 4)), ("x1", "x2"), "m")}
    ds = Dataset(100.0, measured, truth=structural(), attrs={"kind": "structural"})
    t = ds.truth_as(StructuralTruth)
    assert isinstance(t, StructuralTruth) and isinstance(ds.typed_truth, StructuralTruth)
    np.testing.assert_array_equal(t.frequencies_hz, [1.0, 2.0, 3.0])
    with pytest.raises(AttributeError):
        t.frequency_hz  # noqa: B018  (a misspelt field fails where it is written)
    with pytest.raises(TruthError, match=r"rig kind 'structural' \(StructuralTruth\), not MechanicalTruth"):
        ds.truth_as(MechanicalTruth)
    # a dataset that records no kind is read as the type asked for, and validated
    bare = Dataset(100.0, measured, truth=structural())
    assert bare.truth_as(StructuralTruth).Mr.shape == (2, 2)
    with pytest.raises(TruthError, match="missing 'equation_terms'"):
        bare.truth_as(MechanicalTruth)
    with pytest.raises(TruthError, match="records no rig kind"):
        bare.typed_truth  # noqa: B018  (the property raises)


def test_a_second_truth_type_for_a_kind_is_refused():
    class Other(Truth):
        kind = "structural"

    with pytest.raises(ValueError, match="registered already"):
        register_truth(Other)
    with pytest.raises(TruthError, match="no truth type for rig kind 'optical'"):
        truth_type("optical")


def test_scenario_carries_its_rigs_kind():
    assert load_scenario("cantilever_stiff_impact").kind == "structural"
    assert load_scenario("fivebar_multisine").kind == "mechanical"
    assert Scenario(name="x", rig="fivebar").kind == "mechanical"  # filled from the rig
    with pytest.raises(ScenarioError, match=r"scenario\.kind"):
        Scenario(name="x", rig="fivebar", kind="structural")
    with pytest.raises(ScenarioError, match=r"scenario\.rig"):
        Scenario(name="x", rig="no_such_rig")


def test_unknown_kinds_are_refused_by_every_registry():
    with pytest.raises(ValueError, match="unknown rig kind 'optical'"):
        measure(None, {}, "optical")
    with pytest.raises(KeyError, match="no scorer for rig kind 'optical'"):
        score("optical", None, None, None, None)
    with pytest.raises(KeyError, match="no score catalogue"):
        failed_scores("optical", "why")
    with pytest.raises(ValueError, match="has no score catalogue"):
        register_scorer("optical", lambda *a: None)


def test_a_new_kind_registers_its_chain_without_editing_the_dispatch():
    calls = []
    chain = SignalChain("optical_test", {}, lambda ds, cfg: calls.append(ds) or "measured")
    try:
        register_signal_chain(chain)
        assert measure("dataset", {}, "optical_test") == "measured" and calls == ["dataset"]
        with pytest.raises(ValueError, match="registered already"):
            register_signal_chain(SignalChain("optical_test", {}, lambda ds, cfg: None))
    finally:
        SIGNAL_CHAINS.pop("optical_test", None)
        SIGNAL_SCHEMAS.pop("optical_test", None)
