"""Twenty-sixth malformed-input round: the findings of ``benchmarks/hostile26.py``
(docs/known-gaps.md, "Malformed-input round 26"), each fixed in the layer that owns it.

In-process and on arrays of a few samples: the behaviour under test is a constructor's or a
reader's, not a process's.
"""

from __future__ import annotations

import numpy as np
import pytest

from testbed import cli
from testbed.core.arguments import array
from testbed.core.dataset import Dataset, Signal
from testbed.core.errors import ArgumentError
from testbed.core.numbertext import plain_number
from testbed.pipeline.importers import MeasuredDataError, read_measured

#: A scalar-prior dataset's content hash under the code before round 26 (test below).
HASH_BEFORE = "5453e20969ac3783999838a54873f7ebc4aacd989891d7655cbaa5956a41a298"

ROWS = np.array([[0.0, -1.0, 2.0, 3.0, 4.0], [1.0, 2.0, 3.0, 4.0, 5.0]])  # integers: exact as int


def _refused(*words: str, **kw) -> str:
    kw = {"data": ROWS, "channels": ("a", "b"), "unit": "m", **kw}
    with pytest.raises(ArgumentError) as e:
        Signal(**kw)
    text = str(e.value)
    assert "\n" not in text and text.startswith("Signal") and all(w in text for w in words), text
    return text


def _masked_one() -> np.ma.MaskedArray:
    a = np.ma.masked_array(ROWS.copy(), mask=False)
    a.mask[0, 2] = True
    return a


# ------------------------------------------------------------------ Signal's samples

@pytest.mark.parametrize("make", [
    _masked_one,
    lambda: ROWS + 1j,
    lambda: ROWS.astype(complex),  # no imaginary part: still refused, not cast
    lambda: ROWS > 1,
    lambda: ROWS.astype(object),
    lambda: ROWS.astype(str),
    lambda: (ROWS * 1e3).astype("datetime64[ms]"),
    lambda: np.zeros(ROWS.shape, dtype=[("v", "f8")]),
    lambda: np.array(1.0),
    lambda: ROWS[None],
], ids=["masked", "complex", "complex-real", "boolean", "object", "text", "datetime",
        "structured", "0-d", "3-D"])
def test_signal_refuses_samples_of_a_kind_no_record_holds(make):
    # old: every one was taken (np.ascontiguousarray(dtype=float)): the value under a mask
    # measured, the imaginary part dropped with a ComplexWarning, booleans as 0 / 1, texts and
    # datetimes parsed as numbers, a 0-d as one sample (round 25's open (c))
    _refused("data", data=make())


@pytest.mark.parametrize("make", [
    lambda: ROWS.astype(int),
    lambda: ROWS.astype(">f8"),
    lambda: np.asfortranarray(ROWS),
    lambda: np.repeat(ROWS, 2, axis=1)[:, ::2],  # a view: not contiguous
    lambda: ROWS.tolist(),
    lambda: np.ma.masked_array(ROWS, mask=False),
], ids=["integer", "big-endian", "Fortran", "strided", "list", "masked-nothing"])
def test_signal_reads_every_real_layout_as_the_same_c_ordered_float64(make):
    s = Signal(make(), ("a", "b"), "m")
    assert s.data.dtype == np.float64 and s.data.flags.c_contiguous
    np.testing.assert_array_equal(s.data, ROWS)


def test_signal_reads_a_read_only_array_and_a_flat_row_as_before():
    ro = ROWS.copy()
    ro.flags.writeable = False
    np.testing.assert_array_equal(Signal(ro, ("a", "b"), "m").data, ROWS)
    flat = Signal([1, 2, 3], ("a",), "m")  # one channel given flat: one row
    assert flat.data.shape == (1, 3) and flat.data.dtype == np.float64


def test_signal_lets_non_finite_samples_through_for_the_chain_to_name():
    # a recorded NaN is named by channel and sample where it is measured (rounds 17-25), not
    # refused as an array by the constructor
    a = ROWS.copy()
    a[1, -1] = np.nan
    assert np.isnan(Signal(a, ("a", "b"), "m").data[1, -1])


# ------------------------------------------------------------------ Signal's other fields

@pytest.mark.parametrize("channels", ["ab", 5, None, ("a",), ("a", 5)],
                         ids=["one text", "a number", "None", "one for two rows", "a number item"])
def test_signal_refuses_channels_that_are_not_one_text_per_row(channels):
    # old: "ab" was read as ('a', 'b'); 5 and None TypeError; a count mismatch a plain ValueError
    _refused("channels", channels=channels)


@pytest.mark.parametrize("unit", [5, b"m", None], ids=["a number", "bytes", "None"])
def test_signal_refuses_a_unit_that_is_not_a_text(unit):
    # old: taken; then "'int' object has no attribute 'split'" in channel_units
    _refused("unit", unit=unit)


@pytest.mark.parametrize("positions", ["0.1", np.array([0.1j, 0.2]), np.array([True, False]),
                                       [[0.1], [0.2, 0.3]]],
                         ids=["a text", "complex", "boolean", "ragged"])
def test_signal_refuses_positions_that_are_not_real_numbers(positions):
    # (their count and finiteness are the readers' to name: tests/testbed/test_hostile8.py)
    _refused("positions", positions=positions)


@pytest.mark.parametrize("acts_on", ["xy", ("x",)], ids=["one text", "one for two rows"])
def test_signal_refuses_acts_on_that_is_not_one_text_per_row(acts_on):
    _refused("acts_on", acts_on=acts_on)


def test_array_without_the_finite_rule_still_refuses_every_other_kind():
    a = np.array([[np.nan, np.inf]])
    assert array("f", "x", a, (None, None), finite=False) is a
    with pytest.raises(ArgumentError, match="NaN or infinite"):
        array("f", "x", a, (None, None))
    with pytest.raises(ArgumentError, match="dtype bool"):
        array("f", "x", a > 0, (None, None), finite=False)


# ------------------------------------------------------------------ numbers written as text

@pytest.mark.parametrize("text", ["1_5", "\u0661.\u0665", "\uff11.\uff15", "1.5\u00a0\u0665"],
                         ids=["underscore", "arabic-indic", "fullwidth", "mixed"])
def test_plain_number_refuses_what_float_reads_beyond_ascii(text):
    assert plain_number(text) is None


@pytest.mark.parametrize("text", ["1.5", " +1.5E0 ", "\u00a01.5\u2009", "-inf", "NaN", ".5", "7."])
def test_plain_number_takes_ascii_numbers_between_blanks_of_any_script(text):
    assert float(plain_number(text)) == float(text) or np.isnan(float(plain_number(text)))


def _csv(tmp_path, cell: str):
    rows = ["t [s],x [m]"] + [f"{k / 100!r},{0.1 * k!r}" for k in range(20)]
    rows[7] = f"{6 / 100!r},{cell}"
    path = tmp_path / "rec.csv"
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return path


@pytest.mark.parametrize("cell", ["0_6", "\u0660.\u0666", "\u0660.6"],
                         ids=["underscore", "arabic-indic", "one arabic-indic digit"])
def test_csv_cell_in_other_digits_or_with_underscores_refused_naming_line(tmp_path, cell):
    # old: float() read "0_6" as 6.0 and Arabic-Indic digits as ours, and the record was fitted
    with pytest.raises(MeasuredDataError) as e:
        read_measured(_csv(tmp_path, cell))
    text = str(e.value)
    assert "\n" not in text and "line 8" in text and "ASCII digits" in text, text


@pytest.mark.parametrize("cell", [" 0.6 ", "\u00a00.6", "+6E-1"], ids=["blanks", "nbsp", "exponent"])
def test_csv_cell_spellings_of_the_same_number_still_read(tmp_path, cell):
    data = read_measured(_csv(tmp_path, cell))
    assert data.signals["x"][1][6] == 0.6


def test_command_line_numbers_keep_the_ascii_rule():
    assert cli._plain_number(" 3 ") == "3"
    for text in ("\uff13", "1_000", "\u0663"):
        with pytest.raises(ValueError):
            cli._plain_number(text)


# ------------------------------------------------------------------ Dataset.save of a hand-made dataset

def _dataset(**kw) -> Dataset:
    return Dataset(**{"fs": 100.0, "measured": {"x": Signal(np.arange(10.0), ("x",), "m")}, **kw})


@pytest.mark.parametrize("kw, field", [
    ({"attrs": {"s": {1, 2}}}, "attrs['s']"),
    ({"attrs": {"b": b"\x00"}}, "attrs['b']"),
    ({"attrs": {"h": 10 ** 400}}, "attrs['h']"),
    ({"attrs": {"fs": 5}}, "attrs key"),
    ({"attrs": {"format": "x"}}, "attrs key"),
    ({"prior": {"total_mass": "0.7"}}, "prior['total_mass']"),
    ({"prior": {"total_mass": [1.0, 2.0]}}, "prior['total_mass']"),
    ({"prior": {"total_mass": float("nan")}}, "prior['total_mass']"),
    ({"fs": -100.0}, "fs"),
    ({"truth": {"M": "abc"}}, "truth['M']"),
    ({"truth": {"M": [[1.0, 2.0], [3.0]]}}, "truth['M']"),
    ({"truth": {"M": np.array([1j])}}, "truth['M']"),
    ({"measured": {"a/b": Signal(np.arange(3.0), ("x",), "m")}}, "measured name"),
    ({"measured": {"": Signal(np.arange(3.0), ("x",), "m")}}, "measured name"),
    ({"measured": {}}, "measured"),
    ({"measured": {"x": np.arange(3.0)}}, "measured['x']"),
    ({"fs": "100"}, "fs"),
    ({"fs": 10 ** 400}, "fs"),
    ({"measured": {"x": Signal(np.arange(3.0), ("x\x00",), "m")}}, "names"),
], ids=["attrs set", "attrs bytes", "attrs 10**400", "attrs fs", "attrs format", "prior text",
        "prior list", "prior NaN", "fs -100", "truth text", "truth ragged", "truth complex",
        "name a/b", "name empty", "no measured", "bare array", "fs text", "fs 10**400", "channel NUL"])
def test_save_refuses_what_it_cannot_write_as_load_reads_it_and_writes_nothing(tmp_path, kw, field):
    # old: TypeError / ValueError / OverflowError / AttributeError from inside, or a file written
    # that its own load refused (a signal named a/b: "a group"; attrs fs / fs "100" / a prior
    # list: "content does not match its stored content hash"; a complex truth)
    path = tmp_path / "d.h5"
    with pytest.raises(ArgumentError) as e:
        _dataset(**kw).save(path)
    text = str(e.value)
    assert "\n" not in text and text.startswith("Dataset.save") and field in text, text
    assert not path.exists()


def test_a_list_prior_and_the_accepted_attributes_round_trip(tmp_path):
    # old: a link_lengths prior (a list: hashed as JSON, read back as an array) failed its own
    # load's verification
    ds = _dataset(prior={"link_lengths": [0.1, 0.2, 0.3]}, truth={"g": 9.81, "names": ["a", "b"]},
                  attrs={"n": float("nan"), "z": None, "j": {"a": [1, 2.5, "x"]}})
    back = Dataset.load(ds.save(tmp_path / "d.h5"))
    assert back.content_hash() == ds.content_hash()
    np.testing.assert_array_equal(back.prior["link_lengths"], [0.1, 0.2, 0.3])


def test_a_scalar_prior_hashes_as_before():
    # every rig's prior is scalar: its datasets' content hashes (and the caches keyed by them)
    # are unchanged by the list rule; this hash was computed with the code before round 26
    ds = _dataset(prior={"total_mass": 0.75})
    assert ds.content_hash() == HASH_BEFORE


# ------------------------------------------------------------------ a huge value in a refusal

@pytest.mark.parametrize("value", [list(range(10 ** 5)), "a\x00" * 100, "x" * 119, "x" * 120,
                                   "x" * 121, "\n" * 300, 10 ** 400, {"k": "\x1b" * 200}],
                         ids=["list", "nuls", "119", "120", "121", "newlines", "big int", "dict"])
def test_show_value_escapes_only_what_it_shows_with_the_same_text(value):
    # old: the whole repr escaped, then cut (9 s of a 10**6-seed study's refusal); the text
    # must be what it was
    from testbed.core.errors import MAX_VALUE_CHARS, _cut, _one_line, show_value

    assert show_value(value) == _cut(_one_line(repr(value)))
    assert len(show_value(value)) <= MAX_VALUE_CHARS


# ------------------------------------------------------------------ a study of 10**6 seeds

def test_a_study_whose_noise_times_seeds_exceed_the_budget_is_refused_before_its_items(monkeypatch):
    # old: every seed checked by the schema first (~5 us each: 10**7 seeds ~50 s), then refused
    from testbed.core.errors import BudgetError
    from testbed.studies import study

    def no_item_checks(*a, **kw):
        raise AssertionError("items checked before the grid's size")

    monkeypatch.setattr(study, "validate_header", no_item_checks)
    raw = {"study": {"name": "s", "scenarios": ["michaelis_menten"], "noise": [0.0, 0.01],
                     "seeds": list(range(60_000)), "identifiers": ["sindy_pi_dynamical"]}}
    with pytest.raises(BudgetError) as e:
        study.study_from_dict(raw, file="s.toml")
    assert e.value.key == "study.seeds" and "at least 120000 cells" in str(e.value)


def test_a_study_within_the_budget_by_its_lists_still_meets_the_exact_count():
    # noise x seeds within the budget: the exact check (pairs x noise x seeds) still decides
    from testbed.core.errors import BudgetError
    from testbed.studies import study

    raw = {"study": {"name": "s", "scenarios": ["michaelis_menten", "michaelis_menten_noise1"],
                     "noise": [0.0], "seeds": list(range(60_000)), "identifiers": ["sindy_pi_dynamical"]}}
    with pytest.raises(BudgetError, match="120000 cells"):
        study.study_from_dict(raw, file="s.toml")
