"""Ninth malformed-input round: the three findings left open by the eighth, and those of
``benchmarks/hostile9.py`` (docs/history.md, malformed-input audits), each refused in one line
by the layer that owns the check, or made explicit.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

from testbed.core.errors import ScenarioError
from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml, scenario_from_dict


def _load(name: str, **tables) -> object:
    """The shipped scenario ``name`` with ``tables`` (section -> {key: value}) merged in."""
    raw = copy.deepcopy(_read_toml(SCENARIO_DIR / f"{name}.toml"))
    for section, keys in tables.items():
        raw.setdefault(section, {}).update(keys)
    return scenario_from_dict(raw, file=f"{name}.toml", stem=name)


# ------------------------------------------------------------------ left open by round 8

@pytest.mark.parametrize("rig, key, fragment", [
    # beta = 2 zeta / omega_1 underflowed to 0: the beam was simulated undamped (refused for
    # damping_ratio = 0) and its damping scores were inf with no reason given
    ({"damping_ratio": 5e-324}, "rig.damping_ratio", "expected in [5.79"),
    ({"damping_ratio": 1e-307}, "rig.damping_ratio", "an undamped chain in all but name"),
    ({"damping_ratio": 0.0, "damping_beta": 5e-324}, "rig.damping_beta",
     "expected 0 (derived from damping_ratio) or at least 2.225e-308 s"),
])
def test_a_damping_whose_beta_underflows_is_refused_naming_its_key(rig, key, fragment):
    with pytest.raises(ScenarioError) as e:
        _load("cantilever_stiff_impact", rig=rig)
    assert e.value.key == key and fragment in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("rig", [{"damping_ratio": 1e-300},
                                 {"damping_ratio": 0.0, "damping_beta": 1e-300}])
def test_a_tiny_but_normal_damping_is_still_accepted(rig):
    assert _load("cantilever_stiff_impact", rig=rig).rig_params["damping_ratio"] == rig["damping_ratio"]


def test_relative_error_of_a_true_matrix_of_1e_minus_297_does_not_underflow():
    # damping_ratio = 1e-300: ||Cr||'s sum of squares underflowed to 0 and Cr_error and
    # MinvC_error were inf by that alone
    from testbed.scoring.metrics import relative_error

    c = np.diag([1.0, 2.0, 3.0]) * 1e-297
    assert relative_error(2 * c, c) == 1.0
    assert relative_error(np.zeros((2, 2)), np.zeros((2, 2))) == 0.0
    assert relative_error(np.ones((2, 2)), np.zeros((2, 2))) == np.inf
    rng = np.random.default_rng(9)  # exact: a power of two changes no bit of the ratio
    for _ in range(200):
        a = rng.normal(size=(3, 3)) * 10.0 ** rng.uniform(-30, 30)
        b = a + rng.normal(size=(3, 3)) * 10.0 ** rng.uniform(-35, 30)
        assert relative_error(b, a) == float(np.linalg.norm(b - a) / np.linalg.norm(a))


@pytest.mark.parametrize("name, signal, key", [
    # accepted and ignored: the recorded derivatives read no Savitzky-Golay window
    ("michaelis_menten", {"window": 2**53 + 1}, "signal.window"),
    ("fivebar_multisine", {"window": 301}, "signal.window"),
    ("fivebar_multisine", {"polyorder": 3}, "signal.polyorder"),
    ("fivebar_multisine", {"cutoff_hz": 4.0}, "signal.cutoff_hz"),
    ("fivebar_multisine", {"derivatives": "estimated", "edge_fit_s": 0.1}, "signal.edge_fit_s"),
    ("cantilever_stiff_impact", {"lowpass_order": 4}, "signal.lowpass_order"),
])
def test_a_signal_key_the_chain_would_not_read_is_refused(name, signal, key):
    with pytest.raises(ScenarioError) as e:
        _load(name, signal=signal)
    assert e.value.key == key and "so it would be ignored" in str(e.value)


@pytest.mark.parametrize("name, signal", [
    ("michaelis_menten", {"window": 21}),  # its default: a table written out whole lists it
    ("michaelis_menten", {"derivatives": "estimated", "window": 31}),
    ("fivebar_multisine", {"derivatives": "lowpass", "cutoff_hz": 4.0, "edge_fit_s": 0.5}),
    ("cantilever_stiff_impact", {"lowpass_order": 4, "lowpass_hz": 3000.0}),
])
def test_a_signal_key_the_chain_reads_is_accepted(name, signal):
    sc = _load(name, signal=signal)
    assert all(sc.signal[k] == v for k, v in signal.items())


FAMILY_STUDY = """
[study]
name = "fam"
noise = [0.0]
seeds = [0]
identifiers = ["ls_sindy"]

[families.beams]
base = "cantilever_stiff_impact"
members = 4

[families.beams.rig]
length = {uniform = [0.3, 0.35]}
"""


def test_a_large_family_is_announced_and_its_drawing_shown(tmp_path, monkeypatch):
    # 10,000 members drew for 6-45 minutes before a sweep's first line, in silence
    from testbed.studies import family
    from testbed.studies.study import load_study

    monkeypatch.setattr(family, "ANNOUNCE_MEMBERS", 3)  # 4 members stand for 10,000
    p = tmp_path / "fam.toml"
    p.write_text(FAMILY_STUDY)
    lines: list[str] = []
    study = load_study(p, progress=lines.append)
    assert len(study.scenarios) == 4
    assert lines[0].startswith("drawing family beams: 4 members, each validated as a scenario")
    assert [x.split(" (")[0] for x in lines[1:]] == [
        f"family beams: {k} of 4 members drawn" for k in (1, 2, 3, 4)]
    quiet: list[str] = []
    monkeypatch.setattr(family, "ANNOUNCE_MEMBERS", 4)
    load_study(p, progress=quiet.append)
    assert quiet == []


def test_base_spring_keys_given_with_a_clamped_base_are_refused():
    # accepted and ignored: a clamped base has no spring
    for key, value in (("base_k1", 5000.0), ("base_k3", 1e6)):
        with pytest.raises(ScenarioError) as e:
            _load("cantilever_stiff_impact", rig={key: value})
        assert e.value.key == f"rig.{key}" and "read only with base = 'soft'" in str(e.value)
    assert _load("cantilever_soft_impact", rig={"base_k1": 5000.0}).rig_params["base_k1"] == 5000.0


# ------------------------------------------------------------------ round 9's own findings

@pytest.mark.parametrize("params, key", [
    # numpy's legacy global seed takes 32 bits: "ValueError: Seed must be between 0 and
    # 2**32 - 1" in the fit
    ({"seed": 2**53 + 1}, "identify.seed"),
    # one STLSQ fit per bagged model: 2**53 + 1 ran past any time limit
    ({"optimizer": "ensemble", "n_models": 2**53 + 1}, "identify.n_models"),
])
def test_pysindy_settings_its_fit_cannot_take_are_refused_at_load(params, key):
    with pytest.raises(ScenarioError) as e:
        _load("cantilever_stiff_impact_pysindy", identify={"method": "pysindy", **params})
    assert e.value.key == key


def test_a_model_whose_every_coefficient_is_zero_is_a_failure_with_its_reasons():
    # pysindy with threshold = 1e300 keeps no coefficient: M only, C = K = 0; TRAC and the
    # damping ratios were NaN with no failure naming why
    from testbed.scoring.run import run_scenario

    sc = _load("cantilever_stiff_impact", simulation={"duration": 0.1},
               identify={"method": "pysindy", "threshold": 1e300})
    result = run_scenario(sc)
    failures = result.scores.failures
    assert not result.passed
    assert "3 identified mode(s) without stiffness" in failures["stiffness"]
    assert failures["trac"].startswith("TRAC undefined on acc1")


@pytest.mark.parametrize("name, rig, key", [
    # I_yy = m s^2 / 12 overflowed: "key 'rig': ... (34, 'Numerical result out of range')"
    ("cantilever_stiff_impact", {"length": 1e300}, "rig.length"),
    # the model's mode 1 underflowed to 0 Hz (beta = inf): "key 'rig': ... infs or NaNs"
    ("cantilever_stiff_impact", {"length": 1e100}, "rig.length"),
    ("cantilever_soft_impact", {"base_k1": 1e100}, "rig.base_k1"),
])
def test_a_beam_that_cannot_be_built_is_refused_naming_a_key(name, rig, key):
    with np.errstate(all="ignore"), pytest.raises(ScenarioError) as e:
        _load(name, rig=rig)
    assert e.value.key == key and "\n" not in str(e.value)


@pytest.mark.parametrize("text, line", [
    ("t,x\n" + "".join(f"{k / 100},{k}\n" for k in range(50)) + "1" * 200_000 + ",1\n", 52),
    ("t," + "x" * 200_000 + "\n0,1\n0.01,2\n", 1),
], ids=["long field", "long name"])
def test_a_csv_field_over_the_csv_modules_limit_is_refused_naming_its_line(tmp_path, text, line):
    # csv.Error "field larger than field limit (131072)": an internal error of `identify`
    from testbed.pipeline.importers import MeasuredDataError, read_measured

    p = tmp_path / "long.csv"
    p.write_text(text)
    with pytest.raises(MeasuredDataError, match=f"line {line}: field larger than field limit"):
        read_measured(p, units="m")


def test_a_sep005_file_with_an_integer_of_5001_digits_is_refused(tmp_path):
    # Python's int conversion limit (4,300 digits) raised a bare ValueError: an internal error
    from testbed.pipeline.importers import MeasuredDataError, read_measured

    p = tmp_path / "big.sep005.json"
    p.write_text('[{"name": "acc1", "unit_str": "m/s^2", "fs": 100.0, "data": [1' + "0" * 5000
                 + ', 2.0, 3.0]}]')
    with pytest.raises(MeasuredDataError, match=r"not a SEP-005 JSON file .*thousands of digits"):
        read_measured(p)
