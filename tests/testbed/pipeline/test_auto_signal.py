"""``signal.highpass_hz`` / ``signal.lowpass_hz = "auto"`` in a scenario file: resolved from the
rig's nominal geometry when the scenario is loaded (the cantilever's
:func:`models.cantilever.euler_bernoulli.auto_cutoff`, the same rule a family member's
``"auto"`` gets), recorded with its rule, refused in one line where it cannot be resolved."""

from __future__ import annotations

import math
import sys

import numpy as np
import pytest

from models.cantilever import eb_frequencies
from testbed.core.errors import ScenarioError
from testbed.pipeline.plugins import RIGS, load_plugins
from testbed.pipeline.scenario import scenario_from_dict
from testbed.pipeline.signal_chain import measure
from testbed.studies.family import draw_member, parse_family

#: The rule rounds to 0.1 Hz; the clamped table's 4 decimals of beta_k L move a cut-off by
#: < 1e-4 relative (1e-3 Hz at 1 kHz) against the boundary determinant's roots: 0.06 Hz covers both.
ROUNDING_HZ = 0.06


def raw(rig=None, signal=None, simulation=None, excitation=None):
    return {"scenario": {"name": "t", "rig": "cantilever", "seed": 0}, "rig": rig or {},
            "simulation": {"duration": 0.1, **(simulation or {})},
            "excitation": {"type": "impact", **(excitation or {})}, "signal": signal or {}}


def section(r):
    """E I [N m^2] and mass per length [kg/m] of a rig table with the schema's defaults."""
    full = {"E": 210e9, "rho": 7850.0, "width": 0.03, "thickness": 0.01, "length": 0.3175, **r}
    return (full["E"] * full["width"] * full["thickness"] ** 3 / 12,
            full["rho"] * full["width"] * full["thickness"], full["length"])


@pytest.mark.parametrize("sensors", [[0.15, 0.3175], [0.1, 0.2, 0.3175], [0.08, 0.16, 0.24, 0.3175]])
def test_lowpass_auto_between_the_last_sensed_mode_and_the_next(sensors):
    sc = scenario_from_dict(raw(rig={"sensors": sensors}, signal={"lowpass_hz": "auto"}))
    n = len(sensors)
    ei, mu, L = section({})
    f = eb_frequencies(ei, 1.0, mu, L, n + 1)  # the boundary determinant's roots
    assert sc.signal["lowpass_hz"] == pytest.approx(math.sqrt(f[n - 1] * f[n]), abs=ROUNDING_HZ)
    assert f[n - 1] < sc.signal["lowpass_hz"] < f[n]
    rule = sc.rules["signal.lowpass_hz"]
    assert rule.startswith(f"{sc.signal['lowpass_hz']:g} Hz by 'auto'") and f"mode {n + 1}" in rule
    assert sc.signal["highpass_hz"] == 10.0 and "signal.highpass_hz" not in sc.rules  # the default
    assert sc.to_dict()["rules"] == sc.rules  # what run.json keeps beside the resolved value


def test_auto_on_the_default_sensors_and_a_given_number_has_no_rule():
    sc = scenario_from_dict(raw(signal={"lowpass_hz": "auto"}))  # L/3, 2L/3, L: three modes
    assert "mode 3 (one per sensor) and mode 4" in sc.rules["signal.lowpass_hz"]
    given = scenario_from_dict(raw(signal={"lowpass_hz": sc.signal["lowpass_hz"]}))
    assert given.signal == sc.signal and given.rules == {}
    assert given.data_hash() == sc.data_hash()  # the data do not depend on how the cut-off was given


def test_highpass_auto_follows_a_soft_base():
    """Half of mode 1 on the base: a soft base (k1 L / EI = 1.2) puts mode 1 at 0.48 of the
    clamped estimate, where half the clamped one would sit just above it."""
    stiff = scenario_from_dict(raw(signal={"highpass_hz": "auto"}))
    soft = scenario_from_dict(raw(rig={"base": "soft", "base_k1": 2000.0},
                                  signal={"highpass_hz": "auto"}))
    ei, mu, L = section({})
    f_clamped = eb_frequencies(ei, 1.0, mu, L, 1)[0]
    f_soft = eb_frequencies(ei, 1.0, mu, L, 1, k_r=2000.0)[0]
    assert stiff.signal["highpass_hz"] == pytest.approx(f_clamped / 2, abs=ROUNDING_HZ)
    assert soft.signal["highpass_hz"] == pytest.approx(f_soft / 2, abs=ROUNDING_HZ)
    assert soft.signal["highpass_hz"] < f_soft < f_clamped / 2
    assert "soft base (k1 = 2000 N m/rad)" in soft.rules["signal.highpass_hz"]


def test_refused_in_one_line_where_it_cannot_be_resolved():
    # a 40 m, 1 mm strip: mode 1 at 5e-4 Hz, half of it rounds to 0 Hz
    with pytest.raises(ScenarioError) as e:
        scenario_from_dict(raw(rig={"length": 40.0, "thickness": 0.001, "n_segments": 2,
                                        "sensors": [20.0, 40.0]},
                               signal={"highpass_hz": "auto"}, simulation={"duration": 0.01}))
    msg = str(e.value)
    assert "\n" not in msg and "signal.highpass_hz" in msg and "'auto'" in msg and "0 Hz" in msg
    # only the word "auto" is a word the key takes
    with pytest.raises(ScenarioError, match=r"signal\.lowpass_hz"):
        scenario_from_dict(raw(signal={"lowpass_hz": "Auto"}))
    # a cut-off above the Nyquist frequency is refused as a number would be, naming the key
    # (a 1 ms pulse: the default 0.3 ms one falls between two samples at 2 kHz, refused first)
    with pytest.raises(ScenarioError, match=r"signal\.lowpass_hz.*Nyquist") as e:
        scenario_from_dict(raw(signal={"lowpass_hz": "auto"}, simulation={"sample_rate": 2000.0},
                               excitation={"pulse_duration": 1e-3}))
    # ... and the line says what is allowed: a number below the Nyquist frequency, or a sample
    # rate above twice the cut-off 'auto' gave (round 15: three sensors at 3.2 kHz)
    msg = str(e.value)
    cut = float(msg.split("'auto' resolved it to ")[1].split(" Hz")[0])
    assert "below 1000 Hz" in msg and f"sample_rate above {2 * cut:g} Hz" in msg and "\n" not in msg


def test_a_rig_without_an_estimate_refuses_auto():
    snap = RIGS.snapshot()
    load_plugins(["tests.springmass_rig"])
    try:
        with pytest.raises(ScenarioError) as e:
            scenario_from_dict({"scenario": {"name": "t", "rig": "springmass"},
                                "rig": {"m1": 1.0, "m2": 0.5, "k1": 1e5, "k2": 5e4, "beta": 9e-5},
                                "simulation": {"duration": 0.5, "sample_rate": 8192.0},
                                "excitation": {"type": "impulse"},
                                "signal": {"lowpass_hz": "auto"}})
    finally:
        RIGS.restore(snap)
        sys.modules.pop("tests.springmass_rig", None)
    msg = str(e.value)
    assert "\n" not in msg and "signal.lowpass_hz" in msg and "no estimate of its modes" in msg


def test_measure_refuses_an_unresolved_auto():
    """A chain called without a scenario (a table handed to measure directly) has no rig."""
    sc = scenario_from_dict(raw())
    with pytest.raises(ScenarioError, match=r"signal\.lowpass_hz.*no rig"):
        measure(None, {**sc.signal, "lowpass_hz": "auto"}, "structural")


def test_a_family_base_with_auto_resolves_it_per_member(tmp_path):
    base = tmp_path / "base_auto.toml"
    base.write_text('[scenario]\nname = "base_auto"\nrig = "cantilever"\n\n[rig]\n'
                    'sensors = [0.2, 0.3175]\n\n[simulation]\nduration = 0.5\n\n'
                    '[excitation]\ntype = "impact"\nlocation = 0.2\n\n[signal]\nlowpass_hz = "auto"\n')
    fam = parse_family("lengths", {"base": str(base), "members": 2, "seed": 0,
                                   "rig": {"length": {"uniform": [0.35, 0.5]},
                                           "sensors": [0.2, 0.35]}},
                       file=str(tmp_path / "study.toml"), base_dir=tmp_path)
    for k in range(2):
        sc = draw_member(fam, k)[0]
        ei, mu, _ = section({})
        f = eb_frequencies(ei, 1.0, mu, sc.rig_params["length"], 3)
        assert f[1] < sc.signal["lowpass_hz"] < f[2]  # the member's modes, not the base's
        assert sc.signal["lowpass_hz"] == pytest.approx(np.sqrt(f[1] * f[2]), abs=ROUNDING_HZ)
