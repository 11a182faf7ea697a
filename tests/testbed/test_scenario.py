"""Scenario loading: every malformed field gives one clear message; extends; CLI exit code."""

import re

import pytest

from testbed.cli import main
from testbed.errors import ScenarioError
from testbed.scenario import load_scenario, scenario_from_dict

GOOD = """
[scenario]
name = "{name}"
rig = "cantilever"
seed = 1
[rig]
n_segments = 6
[simulation]
duration = 0.05
"""


def _write(tmp_path, text, name="s"):
    p = tmp_path / f"{name}.toml"
    p.write_text(text.replace("{name}", name))
    return p


def test_good_file_loads_with_defaults(tmp_path):
    sc = load_scenario(_write(tmp_path, GOOD))
    assert sc.rig == "cantilever" and sc.seed == 1 and sc.rig_params["n_segments"] == 6
    assert sc.noise["rms_percent"] == 0.0 and sc.noise["signals"] == ["acceleration"]
    assert sc.excitation["type"] == "impact"
    assert sc.identify is None and sc.score == {}


@pytest.mark.parametrize(("extra", "key", "fragment"), [
    ("[rig]\nlenght = 1.0\n", "rig.lenght", "unknown key"),
    ('[rig]\nlength = "long"\n', "rig.length", "expected a number"),
    ("[rig]\nlength = -0.3\n", "rig.length", "value -0.3"),
    ("[rig]\nn_segments = 1\n", "rig.n_segments", ">= 2"),
    ("[rig]\nsensors = [0.1, 0.5]\n", "rig.sensors", "0.5"),
    ('[rig]\nbase = "wobbly"\n', "rig.base", "'stiff', 'soft'"),
    ("[noise]\nrms_percent = -1.0\n", "noise.rms_percent", ">= 0"),
    ('[noise]\nsignals = ["force", "strain"]\n', "noise.signals", "strain"),
    ("[wind]\nspeed = 3\n", "wind", "unknown section"),
    ('[identify]\nmethod = "magic"\n', "identify.method", "expected one of"),
    ('[identify]\nmethod = "ls_sindy"\nwarp = 9\n', "identify.warp", "unknown hyperparameter"),
    ("[score]\ntrac_above = 0.9\n", "score.trac_above", "<metric>_min or <metric>_max"),
    ("[score]\nmagic_min = 0.9\n", "score.magic_min", "<metric>_min or <metric>_max"),
])
def test_each_malformed_field_gives_its_clear_error(tmp_path, extra, key, fragment):
    text = GOOD
    section = extra.split("]")[0] + "]"
    if section in text:  # merge into the existing table, replacing a key it sets again
        for line in extra.splitlines()[1:]:
            key_set = line.split("=")[0].strip()
            text = re.sub(rf"^{key_set} = .*\n", "", text, flags=re.M)
        text = text.replace(section + "\n", extra)
    else:
        text = text + extra
    p = _write(tmp_path, text)
    with pytest.raises(ScenarioError) as e:
        load_scenario(p)
    msg = str(e.value)
    assert msg.startswith(str(p)), msg
    assert f"'{key}'" in msg, msg
    assert fragment in msg, msg


def test_missing_file(tmp_path):
    with pytest.raises(ScenarioError, match="no such scenario file"):
        load_scenario(tmp_path / "nope.toml")


def test_name_must_match_file_and_rig_must_exist(tmp_path):
    with pytest.raises(ScenarioError, match="must equal the file name"):
        load_scenario(_write(tmp_path, GOOD.replace('name = "{name}"', 'name = "other"')))
    with pytest.raises(ScenarioError, match="unknown rig 'tower'"):
        load_scenario(_write(tmp_path, GOOD.replace('rig = "cantilever"', 'rig = "tower"')))


def test_invalid_toml(tmp_path):
    with pytest.raises(ScenarioError, match="not valid TOML"):
        load_scenario(_write(tmp_path, "[scenario\nname=1"))


def test_extends_overrides_key_by_key(tmp_path):
    _write(tmp_path, GOOD, name="base")
    child = _write(tmp_path, '[scenario]\nname = "child"\nextends = "base.toml"\n[noise]\nrms_percent = 5\n',
                   name="child")
    sc = load_scenario(child)
    assert sc.name == "child" and sc.rig_params["n_segments"] == 6 and sc.noise["rms_percent"] == 5.0
    base = load_scenario(tmp_path / "base.toml")
    assert sc.data_hash() != base.data_hash()
    assert sc.replace(noise=base.noise).data_hash() == base.data_hash()


def test_extends_cycle(tmp_path):
    _write(tmp_path, '[scenario]\nname = "a"\nrig = "cantilever"\nextends = "b.toml"\n', name="a")
    _write(tmp_path, '[scenario]\nname = "b"\nrig = "cantilever"\nextends = "a.toml"\n', name="b")
    with pytest.raises(ScenarioError, match="cycle"):
        load_scenario(tmp_path / "a.toml")


def test_dict_form_validates_too():
    with pytest.raises(ScenarioError, match=r"<dict>: key 'rig.n_segments'"):
        scenario_from_dict({"scenario": {"name": "x", "rig": "cantilever"}, "rig": {"n_segments": 0}})


def test_cli_prints_one_line_and_exits_2(tmp_path, capsys):
    p = _write(tmp_path, GOOD.replace("n_segments = 6", "n_segments = -4"))
    assert main(["generate", str(p)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert "rig.n_segments" in err and "-4" in err


def test_extends_replaces_identify_whole_and_keeps_the_parents_score(tmp_path):
    parent = GOOD + '[identify]\nmethod = "sgd_sindy"\nepochs = 7\n[score]\ntrac_min = 0.9\nmac_min = 0.9\n'
    _write(tmp_path, parent, name="base")
    own = _write(tmp_path, '[scenario]\nname = "own"\nextends = "base.toml"\n'
                 '[identify]\nmethod = "ls_sindy"\n[score]\ntrac_min = 0.5\n', name="own")
    sc = load_scenario(own)
    assert sc.identify == {"method": "ls_sindy"}  # no epochs inherited from sgd_sindy
    assert sc.score == {"trac": {"min": 0.5}}  # no mac_min inherited
    # a child that replaces [identify] but states no [score] keeps its parent's bars (it must
    # never pass with no bars at all)
    bare = _write(tmp_path, '[scenario]\nname = "bare"\nextends = "base.toml"\n'
                  '[identify]\nmethod = "ls_sindy"\n', name="bare")
    assert load_scenario(bare).score == {"trac": {"min": 0.9}, "mac": {"min": 0.9}}
    noisy = _write(tmp_path, '[scenario]\nname = "noisy"\nextends = "base.toml"\n[noise]\nrms_percent = 1\n',
                   name="noisy")
    sc = load_scenario(noisy)
    assert sc.identify == {"method": "sgd_sindy", "epochs": 7} and set(sc.score) == {"trac", "mac"}
