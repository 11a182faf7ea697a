"""``testbed.core.errors``: every error of the project reads as one line."""

from __future__ import annotations

import pytest

from testbed.core.dataset import Dataset, DatasetError
from testbed.core.errors import InputError, TestbedError


@pytest.mark.parametrize("path", ["a\nb.h5", "a\rb.h5", "a\0b.h5", "a\u2028b.h5"])
def test_a_dataset_error_of_a_path_with_a_control_character_is_one_line(path):
    # hostile round 19: Dataset.load("a\nb.h5") raised "a\nb.h5: no such file", two lines
    # through the Python API (the command line escaped its own error line)
    with pytest.raises(DatasetError) as e:
        Dataset.load(path)
    text = str(e.value)
    assert len(text.splitlines()) == 1 and "\0" not in text, repr(text)
    assert text.endswith(": no such file")


def test_every_testbed_error_escapes_its_text_once():
    e = InputError("line one\nline two \\n kept")
    assert str(e) == "line one\\nline two \\n kept"
    assert isinstance(e, TestbedError) and e.args == ("line one\nline two \\n kept",)
