"""The one rule that reads a number written as text (command line, CSV cells)."""

import pytest

from testbed.core.numbertext import plain_number


@pytest.mark.parametrize(("text", "core"), [
    (" 1.5\t", "1.5"), ("\u00a02", "2"), ("\u30001e3", "1e3"), ("-inf", "-inf"), (".5", ".5"),
])
def test_blanks_of_any_script_around_a_number_are_read_past(text, core):
    assert plain_number(text) == core


@pytest.mark.parametrize("text", [
    "\x1c5", "5\x1f", "\x855", "5\u2028",   # controls and separators are no blanks (review 27a)
    "1_0", "\u0661", "0x10", "", " ",
])
def test_what_is_not_a_plain_number_is_refused(text):
    assert plain_number(text) is None
