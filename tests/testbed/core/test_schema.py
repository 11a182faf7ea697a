"""Schema validation: each bad value gives one message naming file, key, value and what is allowed."""

import pytest

from testbed.core.errors import ScenarioError
from testbed.core.schema import Field, validate_table, validate_variant

SCHEMA = {
    "length": Field(float, 1.0, unit="m", min=0.0, min_inclusive=False),
    "n": Field(int, 3, min=2),
    "base": Field(str, "stiff", choices=("stiff", "soft")),
    "where": Field(list, [], item_type=float, min=0.0),
}


def test_defaults_filled_and_ints_widened():
    out = validate_table({"length": 2, "n": 4}, SCHEMA, file="f.toml", section="rig")
    assert out == {"length": 2.0, "n": 4, "base": "stiff", "where": []}
    assert isinstance(out["length"], float)


@pytest.mark.parametrize(("table", "key", "fragment"), [
    ({"lenght": 1.0}, "rig.lenght",
     "unknown key; allowed keys in [rig]: base, length, n, where (did you mean 'length'?)"),
    ({"length": -1.0}, "rig.length", "> 0 [m]"),
    ({"length": 0.0}, "rig.length", "> 0 [m]"),
    ({"length": "long"}, "rig.length", "expected a number"),
    ({"n": True}, "rig.n", "expected an integer"),
    ({"n": 1}, "rig.n", ">= 2"),
    ({"n": 2.5}, "rig.n", "expected an integer"),
    ({"base": "wobbly"}, "rig.base", "one of 'stiff', 'soft'"),
    ({"where": [0.1, -2.0]}, "rig.where[1]", ">= 0"),
    ({"length": float("nan")}, "rig.length", "> 0"),
])
def test_bad_values_name_file_key_value_and_allowed(table, key, fragment):
    with pytest.raises(ScenarioError) as e:
        validate_table(table, SCHEMA, file="f.toml", section="rig")
    msg = str(e.value)
    assert msg.startswith("f.toml: ")
    assert f"key '{key}'" in msg
    assert fragment in msg
    bad = table[key.split(".")[1].split("[")[0]] if "[" not in key else -2.0
    if key != "rig.lenght":
        assert repr(bad) in msg or "nan" in msg


def test_required_key_missing():
    schema = {"n": Field(int)}
    with pytest.raises(ScenarioError, match=r"key 'rig.n': missing; expected an integer"):
        validate_table({}, schema, file="f.toml", section="rig")


def test_variant_selects_schema_by_type():
    variants = {"impact": {"peak": Field(float, 1.0, unit="N")}, "sine": {"freq": Field(float, 1.0)}}
    assert validate_variant({"type": "sine", "freq": 3}, variants, file="f", section="excitation") == \
        {"type": "sine", "freq": 3.0}
    with pytest.raises(ScenarioError, match=r"key 'excitation.type': value 'hammer': expected one of"):
        validate_variant({"type": "hammer"}, variants, file="f", section="excitation")
    with pytest.raises(ScenarioError, match="unknown key"):
        validate_variant({"type": "sine", "peak": 1.0}, variants, file="f", section="excitation")


def test_pattern_also_and_any_value():
    schema = {
        "name": Field(str, "a", pattern="[a-z]+", pattern_doc="lower-case letters"),
        "library": Field(str, "named", choices=("named",), also=Field(list, item_type=str, min_items=1)),
        "anything": Field(object, None),
    }
    out = validate_table({"library": ["x", "y"], "anything": {"k": 1}}, schema, file="f", section="s")
    assert out == {"name": "a", "library": ["x", "y"], "anything": {"k": 1}}
    with pytest.raises(ScenarioError, match=r"key 's\.name': value 'A/b': expected a string lower-case"):
        validate_table({"name": "A/b"}, schema, file="f", section="s")
    with pytest.raises(ScenarioError, match=r"one of 'named', or a list of strings"):
        validate_table({"library": 5}, schema, file="f", section="s")
    with pytest.raises(ScenarioError, match=r"one of 'named', or a list of strings"):
        validate_table({"library": []}, schema, file="f", section="s")


def test_variant_selector_must_be_a_string():
    with pytest.raises(ScenarioError, match=r"key 'excitation\.type'"):
        validate_variant({"type": {"a": 1}}, {"impact": {}}, file="f", section="excitation")


def test_messages_are_one_line_and_short_whatever_the_value():
    huge = ["x" * 1000] * 1000
    e = ScenarioError("f.toml", "rig.bad\nkey", huge, "expected\na table")
    msg = str(e)
    assert "\n" not in msg and len(msg) < 300, msg
    assert "rig.bad\\nkey" in msg and msg.endswith("expected\\na table") and "[...]" in msg


def test_unknown_section_does_not_echo_its_content():
    from testbed.core.schema import validate_header

    with pytest.raises(ScenarioError) as e:
        validate_header({"study": {"secret": "content"}}, sections=("scenario",), header="scenario",
                        schema={}, file="f", stem=None)
    assert "secret" not in str(e.value) and "unknown section" in str(e.value)


def test_a_visible_field_says_so_without_its_caller_adding_the_words():
    # reader 29: Field.visible relied on each caller putting VISIBLE_DOC into pattern_doc by
    # hand; a field that did not refused a blank tag with a message not saying why
    from testbed.core.schema import ONE_LINE, ONE_LINE_DOC, VISIBLE_DOC

    assert Field(str, visible=True).describe() == f"a string {VISIBLE_DOC}"
    tag = Field(str, pattern=ONE_LINE, pattern_doc=ONE_LINE_DOC, visible=True)
    assert tag.describe() == f"a string {VISIBLE_DOC}, {ONE_LINE_DOC}"
    with pytest.raises(ScenarioError, match=VISIBLE_DOC):
        validate_table({"tag": "\u200b"}, {"tag": tag}, file="f.toml", section="s")
