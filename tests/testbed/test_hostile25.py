"""Twenty-fifth malformed-input round: the findings of ``benchmarks/hostile25.py``
(docs/known-gaps.md, "Malformed-input round 25"), each fixed in the layer that owns it.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import testbed
from benchmarks import bench_sgd_sindy
from identify._base import Identifier, MeasurementSamples
from testbed import cli
from testbed.core.arguments import finite_real, mapping, real
from testbed.core.errors import ArgumentError, ScenarioError
from testbed.core.measurement import PRIOR_RANGE, Measurement, Trajectory, prior_number
from testbed.pipeline.importers import MeasuredDataError, from_sep005
from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml, scenario_from_dict

FS = 100.0
N = 200


def _channels(**change) -> list[dict]:
    """Two SEP-005 channels of one plain record (a sine and its rate), ``change`` applied to
    the first."""
    t = np.arange(N) / FS
    a = {"name": "a", "data": np.sin(2 * np.pi * 3 * t).tolist(), "unit_str": "m", "fs": FS,
         "direction": "+Z"}
    b = {"name": "b", "data": np.cos(2 * np.pi * 5 * t).tolist(), "unit_str": "m", "fs": FS,
         "direction": "+Z"}
    a.update(change)
    return [a, b]


def _refused(chans: list[dict], *words: str) -> str:
    with pytest.raises(MeasuredDataError) as e:
        from_sep005(chans, source="rec.json")
    text = str(e.value)
    assert "\n" not in text and all(w in text for w in words), text
    return text


# ------------------------------------------------------------------ numbers beyond float64

@pytest.mark.parametrize("big", [10 ** 400, 2 ** 1024], ids=["10**400", "2**1024"])
def test_sep005_fs_integer_beyond_float64_refused_naming_fs(big):
    # old: OverflowError ("internal error ... int too large to convert to float") from
    # math.isfinite(fs)
    _refused(_channels(fs=big), "'a'", "fs=", "rate > 0 Hz")


def test_sep005_position_integer_beyond_float64_refused_naming_it():
    # old: OverflowError from check_position's math.isfinite
    _refused(_channels(position_m=10 ** 400), "'a'", "position_m=", "finite number [m]")


def test_finite_real_and_real_refuse_integers_beyond_float64():
    assert finite_real(10 ** 400) is None and finite_real(2 ** 1024) is None
    assert finite_real(True) is None and finite_real(math.nan) is None and finite_real("1") is None
    assert finite_real(2 ** 1023) == 2.0 ** 1023 and finite_real(3) == 3.0
    with pytest.raises(ArgumentError):  # old: OverflowError from float(value)
        real("f()", "x", 10 ** 400)
    assert real("f()", "x", 7) == 7.0 and isinstance(real("f()", "x", 7), float)


# ------------------------------------------------------------------ SEP-005 time as texts

def test_sep005_time_as_texts_refused_like_data():
    # old: np.asarray(["0.0", "0.01", ...], dtype=float) read the texts as numbers in silence
    # (data as texts were refused)
    t = [repr(k / FS) for k in range(N)]
    _refused(_channels(time=t), "'a'", "time values are not numbers")
    _refused(_channels(time=[bool(k % 2) for k in range(N)]), "time values are not numbers")
    _refused(_channels(time=[10 ** 400 + k for k in range(N)]), "time values are not numbers")


def test_sep005_data_messages_kept():
    _refused(_channels(data=["1.5"] * N), "data are not numbers")
    _refused(_channels(data=[10 ** 400] * N), "data are not numbers")


# ------------------------------------------------------------------ SEP-005 direction

@pytest.mark.parametrize("direction", [3.0, True, "up", [3], {"axis": "Z"}, "", "+Z axis"])
def test_sep005_unreadable_direction_refused(direction):
    # old: read as "no direction" in silence (the channel's sign and axis dropped)
    _refused(_channels(direction=direction), "'a'", "direction=", "'+Z'")


@pytest.mark.parametrize("direction, code", [("+z", 3), (3, 3), (None, 0), (" -X rotation ", -4)])
def test_sep005_readable_directions_kept(direction, code):
    if code == -4:  # a rotation needs a rotation's unit
        chans = _channels(direction=direction, unit_str="rad")
        chans[1].update(unit_str="rad", direction="-X rotation")
    else:
        chans = _channels(direction=direction)
    data = from_sep005(chans, source="rec.json")
    assert data.directions.get("a", 0) == code


# ------------------------------------------------------------------ runs ls of no scenario

@pytest.mark.parametrize("name", ["", " ", "a\nb", "/dev/null", "-", "x/y"])
def test_runs_ls_of_a_text_that_is_no_scenario_name_refused(tmp_path, capsys, name):
    # old: status 0 and an empty table, nothing said
    assert cli.main(["runs", "ls", name, "-o", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error: runs ls ") and "not a scenario name" in err


def test_runs_ls_of_a_scenario_without_runs_says_so(tmp_path, capsys):
    assert cli.main(["runs", "ls", "michaelis_menten", "-o", str(tmp_path), "--plain"]) == 0
    out, err = capsys.readouterr()
    assert out.splitlines() == ["scenario\tseed\ttime (UTC)\tidentifier\tverdict\tpath"]
    assert err.strip() == f"no runs of scenario 'michaelis_menten' in {tmp_path}"


# ------------------------------------------------------------------ blank tags

@pytest.mark.parametrize("tags", [[""], [" "], ["beam", "\u00a0"]])
def test_blank_scenario_tag_refused_naming_it(tags):
    raw = _read_toml(SCENARIO_DIR / "michaelis_menten.toml")
    raw["scenario"]["tags"] = tags
    with pytest.raises(ScenarioError, match=r"scenario\.tags\[\d\]"):
        scenario_from_dict(raw, file="m.toml", stem="michaelis_menten")


def test_tags_with_inner_blanks_kept():
    raw = _read_toml(SCENARIO_DIR / "michaelis_menten.toml")
    raw["scenario"]["tags"] = ["two words", "x"]
    assert scenario_from_dict(raw, file="m.toml", stem="michaelis_menten").tags == ("two words", "x")


# ------------------------------------------------------------------ the API's Measurement

def _measurement(**change) -> Measurement:
    t = np.arange(50) / FS
    x = np.vstack([np.sin(2 * np.pi * 3 * t), np.cos(2 * np.pi * 3 * t)])
    kw = {"fs": FS, "x": x, "xd": x, "xdd": x, "channels": ("a", "b"), "prior": {"total_mass": 0.7}}
    kw.update(change)
    return Measurement(**kw)


@pytest.mark.parametrize("value", [10 ** 400, "0.7", True, None, 0.7 + 0j, 5e-324, 1e-300, 1e308,
                                   -1.0, 0.0, [], ["0.7"], [0.1, np.nan], np.ones((2, 2))],
                         ids=["10**400", "text", "True", "None", "complex", "5e-324", "1e-300",
                              "1e308", "-1", "0", "empty list", "list of text", "list with NaN",
                              "2-D array"])
def test_measurement_prior_of_a_value_the_command_line_refuses_is_refused(value):
    # old: 10**400 OverflowError; "0.7" fitted as 0.7 kg, True as 1 kg; None / complex TypeError
    # and 5e-324 / 1e308 LinAlgError inside ls_sindy's fit
    with pytest.raises(ArgumentError, match=r"prior\['total_mass'\].*expected a finite number"):
        _measurement(prior={"total_mass": value})


@pytest.mark.parametrize("value", [0.7, np.float64(0.7), 7, 1e-100, 1e100, [0.1, 0.2, 0.15, 0.2],
                                   np.array([0.1, 0.2, 0.15, 0.2])])
def test_measurement_prior_numbers_and_lists_of_them_kept(value):
    key = "total_mass" if np.ndim(value) == 0 else "link_lengths"  # the one list prior
    m = _measurement(prior={key: value})
    assert m.prior[key] is value


@pytest.mark.parametrize("value", [[0.7], np.array([0.7])])
def test_a_list_for_a_one_number_prior_is_refused(value):
    # review 26b: total_mass=[0.7] was taken, a TypeError inside ls_sindy's fit
    with pytest.raises(ArgumentError, match=r"prior\['total_mass'\]"):
        _measurement(prior={"total_mass": value})


def test_a_prior_changed_after_the_measurement_was_made_is_refused_at_fit():
    # review 26b: the check ran only when the Measurement was made; its prior is a plain dict
    m = _measurement(prior={"total_mass": 0.7})
    m.prior["total_mass"] = "0.7"
    with pytest.raises(ArgumentError, match=r"prior\['total_mass'\]"):
        _Mechanical().fit(m)


def test_importers_prior_rule_is_the_measurements():
    from testbed.pipeline import importers

    assert importers.PRIOR_RANGE is PRIOR_RANGE
    for bad in (10 ** 400, "0.7", True, 5e-324):
        with pytest.raises(MeasuredDataError):
            importers.check_prior("f.json", "total_mass", bad)
    assert prior_number(0.7) == 0.7 and prior_number(np.float32(2.0)) == 2.0
    # one rule with the Measurement's (review 26b): numpy scalars and link_lengths' list kept
    for good in (np.float32(0.7), np.int64(2), np.array(0.7)):
        importers.check_prior("f.json", "total_mass", good)
    importers.check_prior("f.json", "link_lengths", [0.1, 0.2, 0.15, 0.2])


def test_mapping_value_beyond_float64_refused():
    with pytest.raises(ArgumentError):  # old: OverflowError from float(10**400)
        mapping("f()", "prior", {"k": 10 ** 400})


@pytest.mark.parametrize("field", ["x", "xd", "xdd"])
def test_measurement_masked_sample_refused(field):
    # old: np.asarray dropped the mask; the value under it was fitted
    a = np.ma.masked_array(_measurement().x.copy(), mask=False)
    a.mask[0, 5], a.data[0, 5] = True, 1e3
    with pytest.raises(ArgumentError, match=r"1 masked sample"):
        _measurement(**{field: a})


def test_measurement_list_of_masked_rows_refused():
    # review 26b: a list of masked rows passed the check, the value under the mask fitted
    a = np.ma.masked_array(_measurement().x.copy(), mask=False)
    a.mask[0, 5], a.data[0, 5] = True, 1e3
    with pytest.raises(ArgumentError, match=r"1 masked sample"):
        _measurement(x=[a[0], a[1]])


@pytest.mark.parametrize("change", [{"fs": np.float64(FS)}, {"fs": np.int64(int(FS))},
                                    {"direction": np.int64(3)}, {"node": np.int64(3)}])
def test_sep005_numpy_scalars_read_as_numbers(change):
    # review 26b: an in-memory SEP-005 record's numpy scalars were refused (fs, node) or the
    # direction refused with a message naming the integers it is one of
    assert from_sep005(_channels(**change), source="rec.json") is not None


def test_measurement_masked_array_without_a_masked_sample_kept():
    a = np.ma.masked_array(_measurement().x.copy(), mask=False)
    assert np.array_equal(_measurement(x=a).x, np.asarray(a))


@pytest.mark.parametrize("name", ["a\nb", "\x1b[2Ja", "a\tb", "a\u2028b", "a\x00"])
def test_measurement_channel_name_with_a_control_character_refused(name):
    # old: fitted; the equations printed the name over two lines (or the terminal obeyed it)
    with pytest.raises(ArgumentError, match="without control characters"):
        _measurement(channels=(name, "b"))


def test_measurement_channel_names_of_blanks_and_letters_kept():
    assert _measurement(channels=("acc 1", "\u00e9\u540d")).channels == ("acc 1", "\u00e9\u540d")


# ------------------------------------------------------------------ a fitted model's methods

@pytest.fixture(scope="module")
def chain_fit():
    data = bench_sgd_sindy.chain_measurement(bench_sgd_sindy.chain_system(), duration=0.3)
    return testbed.IDENTIFIERS.get("ls_sindy")().fit(data), data


@pytest.mark.parametrize("start", ["end", "past", "last"])
def test_score_of_a_window_with_fewer_than_two_samples_refused(chain_fit, start):
    # old: R^2 = 1.0 for an empty window (a perfect fit of nothing), -inf for one sample
    model, data = chain_fit
    n = data.n_samples
    fs = {"end": n, "past": n + 5, "last": n - 1}[start]
    with pytest.raises(ArgumentError, match="at least 2 samples from free_start"):
        model.score(dataclasses.replace(data, free_start=fs))
    assert model.score(dataclasses.replace(data, free_start=n - 2)) <= 1.0  # two: scored


def test_score_of_a_cv_window_before_the_free_decay_refused(chain_fit):
    # old: a test window ending before free_start scored 1.0 in GridSearchCV
    model, data = chain_fit
    m = MeasurementSamples.of(dataclasses.replace(data, free_start=60))
    with pytest.raises(ArgumentError, match="free_start"):
        model.score(m[20:40])


def test_inputs_of_another_count_than_the_input_map_refused(chain_fit):
    # old: numpy's matmul ValueError
    model, data = chain_fit
    u = np.ones((2, data.n_samples))
    two = dataclasses.replace(data, u=u, input_map=np.hstack([data.input_map, data.input_map]))
    for method in (model.score, model.predict_acceleration):
        with pytest.raises(ArgumentError, match="input row"):
            method(two)
    assert np.isfinite(model.score(data))  # no inputs: free motion, as documented


@pytest.mark.parametrize("xd0, u, words", [
    (np.zeros(2), None, "'xd0'"), (np.full(3, np.nan), None, "'xd0'"), (None, None, "'xd0'"),
    ("0 0 0", None, "'xd0'"), (np.zeros(3), np.ones((5, 4)), "'u'"),
    (np.zeros(3), np.ones((1, 7)), "'u'")])
def test_simulate_checks_xd0_and_u(chain_fit, xd0, u, words):
    # old: "cannot reshape", "array must not contain infs or NaNs", "u must have shape" (raw
    # ValueErrors from inside)
    model, _ = chain_fit
    with pytest.raises(ArgumentError, match=words):
        model.simulate(np.zeros(3), xd0, np.arange(4) / 1e3, u)
    assert model.simulate(np.zeros(3), np.zeros(3), np.arange(4) / 1e3, np.ones((1, 4))).x.shape == (3, 4)
    # review 26b: one input's samples as a flat row, as before round 25
    assert model.simulate(np.zeros(3), np.zeros(3), np.arange(4) / 1e3, np.ones(4)).x.shape == (3, 4)


class _Mechanical(Identifier):
    """A mechanical identifier of the least kind: what the API's guards check is generic."""

    kind = "mechanical"

    def fit(self, data: Measurement, y: None = None) -> _Mechanical:
        self.coef_ = np.zeros(1)
        return self

    def simulate(self, x0, xd0, t, u=None) -> Trajectory:
        z = np.zeros((len(x0), len(t)))
        return Trajectory(z, z, z)


@pytest.fixture(scope="module")
def mechanical_fit():
    u = np.ones((1, 50))
    return _Mechanical().fit(_measurement(u=u, inputs=("torque",)))


@pytest.mark.parametrize("x0, xd0, u, words", [
    (np.zeros(3), np.zeros(2), None, "'x0'"), (np.zeros(2), np.zeros(3), None, "'xd0'"),
    (np.zeros(2), np.full(2, np.nan), None, "'xd0'"), (np.zeros(2), None, None, "'xd0'"),
    (np.zeros(2), np.zeros(2), np.ones((3, 5)), "'u'"), (np.zeros(2), np.zeros(2), np.ones((1, 9)), "'u'"),
    (np.zeros(2), np.zeros(2), np.full((1, 5), np.nan), "'u'"), (np.zeros(2), np.zeros(2), "1", "'u'")])
def test_a_mechanical_models_simulate_checks_x0_xd0_and_u_against_the_fit(mechanical_fit, x0, xd0, u,
                                                                          words):
    # old: sindy_pi took x0 / xd0 / u of other sizes in silence; xd0 None IndexError, u of other
    # length ValueError, a text TypeError
    with pytest.raises(ArgumentError, match=words):
        mechanical_fit.simulate(x0, xd0, np.arange(5) / FS, u)


def test_a_mechanical_models_simulate_as_fitted_and_refitted(mechanical_fit):
    t = np.arange(5) / FS
    assert mechanical_fit.simulate(np.zeros(2), np.zeros(2), t, np.ones((1, 5))).x.shape == (2, 5)
    assert mechanical_fit.simulate(np.zeros(2), np.zeros(2), t, None).x.shape == (2, 5)  # free
    # review 26b: a single input's samples as one flat row (an array or a list), as the
    # identifiers' np.atleast_2d reads them and users pass them
    assert mechanical_fit.simulate(np.zeros(2), np.zeros(2), t, np.ones(5)).x.shape == (2, 5)
    assert mechanical_fit.simulate(np.zeros(2), np.zeros(2), t, [1.0] * 5).x.shape == (2, 5)
    with pytest.raises(ArgumentError, match="'u'"):
        mechanical_fit.simulate(np.zeros(2), np.zeros(2), t, np.ones(4))
    refit = _Mechanical().fit(_measurement(u=np.ones((1, 50)), inputs=("torque",)))
    refit.fit(_measurement(channels=("a", "b")))  # the same model refitted: no inputs now
    with pytest.raises(ArgumentError, match="'u'"):
        refit.simulate(np.zeros(2), np.zeros(2), t, np.ones((1, 5)))


# ------------------------------------------------------------------ identify_file's arguments

@pytest.mark.parametrize("kw, name", [
    ({"params": [1]}, "params"), ({"prior": [("total_mass", 1.0)]}, "prior"), ({"phase": 5}, "phase"),
    ({"kind": 5}, "kind"), ({"method": 5}, "method"), ({"method": ""}, "method")])
def test_identify_file_checks_its_arguments_where_the_call_enters(tmp_path, kw, name):
    # old: params=[1] and phase=5 TypeErrors from inside; prior=[(k, v)] read as a list of keys
    # ("--prior ('total_mass', 1.0): ... reads no such prior"); kind=5 refused as "--kind 5"
    with pytest.raises(ArgumentError, match=rf"identify_file: argument '{name}'"):
        testbed.identify_file(tmp_path / "absent.csv", **{"kind": "dynamical", **kw})
