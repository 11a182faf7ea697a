"""Twenty-third malformed-input round: the findings of ``benchmarks/hostile23.py``
(docs/known-gaps.md, "Malformed-input round 23"), each fixed in the layer that owns it.
"""

from __future__ import annotations

import json
import re
from pathlib import Path

import h5py
import pytest

from testbed.core.dataset import Dataset
from testbed.core.errors import ScenarioError
from testbed.core.schema import Field, validate_table
from testbed.pipeline.importers import MeasuredDataError, from_sep005, read_measured
from testbed.pipeline.scenario import SCENARIO_DIR, load_scenario
from testbed.reporting.export import export_dataset


def _one_error_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert "Traceback" not in err and len(lines) == 1 and lines[0].startswith("error: "), err
    return lines[0]


# ------------------------------------------------------------------ keys one slip away

SCHEMA = {"Vmax": Field(float, 1.0), "x0": Field(float, 1.0), "thresholds": Field(list, None),
          "duration": Field(float, 1.0)}


@pytest.mark.parametrize(("key", "meant"), [
    ("vmax", "Vmax"),        # case
    ("xo", "x0"),            # one letter, a short key (difflib's ratio 0.5)
    ("threshold", "thresholds"),
    ("duraton", "duration"),
])
def test_an_unknown_key_names_the_key_meant(key, meant):
    """Refused before with the allowed keys only, naming none of them as the one meant."""
    allowed = r"unknown key; allowed keys in \[rig\]: .*"
    with pytest.raises(ScenarioError, match=rf"{allowed} \(did you mean '{meant}'\?\)$"):
        validate_table({key: 1.0}, SCHEMA, file="f.toml", section="rig")


def test_an_unrelated_unknown_key_suggests_nothing():
    with pytest.raises(ScenarioError) as e:
        validate_table({"zzz": 1.0}, SCHEMA, file="f.toml", section="rig")
    assert "did you mean" not in str(e.value) and "unknown key; allowed keys in [rig]" in str(e.value)


def _scenario(tmp_path: Path, stem: str, old: str, new: str) -> Path:
    text = (SCENARIO_DIR / "michaelis_menten.toml").read_text()
    text = text.replace('name = "michaelis_menten"', f'name = "{stem}"')
    assert old in text
    path = tmp_path / f"{stem}.toml"
    path.write_text(text.replace(old, new, 1))
    return path


@pytest.mark.parametrize(("old", "new", "home"), [
    ("[rig]\n", "[rig]\nsample_rate = 100.0\n", "[simulation]"),
    ("[simulation]\n", "[simulation]\nseed = 1\n", "[scenario]"),
    ("[simulation]\n", "[simulation]\nKm = 0.3\n", "[rig]"),
    ("[noise]\n", '[noise]\nderivatives = "recorded"\n', "[signal]"),
])
def test_a_key_in_another_table_names_its_table(tmp_path, old, new, home):
    """`sample_rate` under [rig] was refused listing [rig]'s keys, not where it belongs."""
    with pytest.raises(ScenarioError, match=rf"is a key of {re.escape(home)}"):
        load_scenario(_scenario(tmp_path, "wrong_table", old, new))


def test_a_key_given_twice_names_the_key(tmp_path):
    """tomllib's "Cannot overwrite a value (at line 18, column 9)" named no key."""
    path = _scenario(tmp_path, "twice", "Km = 0.3\n", "Km = 0.3\nKm = 0.4\n")
    with pytest.raises(ScenarioError, match=r"key 'rig\.Km' is given twice \(line \d+\)"):
        load_scenario(path)


@pytest.fixture(scope="module")
def mm_file(tmp_path_factory) -> Path:
    from testbed import cli

    d = tmp_path_factory.mktemp("mm")
    assert cli.main(["generate", "michaelis_menten", "-o", str(d / "mm.h5"), "--cache", str(d / "c")]) == 0
    return d / "mm.h5"


@pytest.mark.parametrize(("param", "named"), [
    # n_modes is a key of the structural sgd_sindy only, which cannot fit a kinetics record:
    # no place to name (review 24a), the allowed keys alone
    ("n_modes=3", "weak_window_s, weak_windows"),
    ("threshold=0.1", "(did you mean 'thresholds'?)"),
])
def test_a_param_of_another_identifier_names_it(cli_in_process, mm_file, tmp_path, param, named):
    """`identify --param threshold=0.1` for sindy_pi_dynamical listed its 15 keys, not the key
    meant."""
    p = cli_in_process("identify", str(mm_file), "--kind", "dynamical", "--method",
                       "sindy_pi_dynamical", "--param", param, "-o", str(tmp_path / "m.json"),
                       cwd=tmp_path)
    assert p.returncode == 2
    assert _one_error_line(p.stderr).endswith(named)


@pytest.mark.parametrize(("argv", "meant"), [
    (["identify", "{data}", "--kind", "dynamical", "--method", "sindy_pi_dinamical"], "sindy_pi_dynamical"),
    (["run", "michaelis_menton"], "michaelis_menten"),
])
def test_a_name_one_slip_away_names_the_one_meant(cli_in_process, mm_file, tmp_path, argv, meant):
    """An unknown identifier or scenario name was refused listing every known name."""
    p = cli_in_process(*(a.format(data=mm_file) for a in argv), cwd=tmp_path)
    assert p.returncode == 2
    assert _one_error_line(p.stderr).endswith(f"(did you mean {meant!r}?)")


def test_a_key_of_another_identifier_is_named_without_a_near_spelling():
    """Review 24a: a key that is another identifier's (of the same kind) was also given a
    near spelling of this one's, of another meaning ('ridge' for pysindy_pi -> 'stride'); a
    one-letter key was one edit from every other ('G' -> 'E')."""
    from testbed.core.schema import unknown_key_hint
    from testbed.pipeline.plugins import IDENTIFIERS
    from testbed.pipeline.scenario import other_identifiers

    declared = IDENTIFIERS.get("pysindy_pi").declared_hyperparameters()
    assert unknown_key_hint("ridge", declared, other_identifiers("pysindy_pi")) == \
        " ('ridge' is a key of sindy_pi)"
    assert "sgd_sindy" not in other_identifiers("sindy_pi_dynamical")  # another kind
    assert unknown_key_hint("G", ["E", "rho"]) == ""
    assert unknown_key_hint("xo", ["x0"]) == " (did you mean 'x0'?)"


# ------------------------------------------------------------------ directions

def _channels(directions: dict[str, str]) -> list[dict]:
    import numpy as np

    t = np.arange(400) / 1000.0
    return [{"name": f"acceleration/{n}", "data": (np.sin(2 * np.pi * 7 * t) * (k + 1)).tolist(),
             "fs": 1000.0, "unit_str": "m/s^2", "direction": d}
            for k, (n, d) in enumerate(directions.items())]


def test_channels_pointing_opposite_ways_are_read_in_one_frame():
    """A sensor declared -Z beside sensors declared +Z was read as +Z: its sign flipped in
    silence (the mode shape's, and the model's coupling through it).  Its first mend refused
    the file, which refused valid files (review 24a: a hammer's force declared -Z beside +Z
    accelerometers); the code says which way the transducer points, so its samples are
    negated into the others' frame."""
    import numpy as np

    plain = read_measured_sep005(_channels({"acc1": "+Z", "acc2": "+Z", "acc3": "+Z"}))
    flipped = _channels({"acc1": "+Z", "acc2": "-Z", "acc3": "+Z"})
    flipped[1]["data"] = [-v for v in flipped[1]["data"]]  # an upside-down sensor's samples
    data = read_measured_sep005(flipped)
    assert data.directions == plain.directions == {f"acceleration/acc{k}": 3 for k in (1, 2, 3)}
    for name, (unit, x) in plain.signals.items():
        assert data.signals[name][0] == unit and np.array_equal(data.signals[name][1], x)


def test_channels_all_along_one_signed_axis_are_read():
    data = read_measured_sep005(_channels({"acc1": "-Z", "acc2": "-Z"}))
    assert data.directions == {"acceleration/acc1": -3, "acceleration/acc2": -3}


def read_measured_sep005(channels: list[dict]):
    return from_sep005(channels, source="<test>")


# ------------------------------------------------------------------ a dataset file against itself

def _edited(src: Path, dst: Path, edit) -> Path:
    dst.write_bytes(src.read_bytes())
    with h5py.File(dst, "r+") as f:
        edit(f)
    ds = Dataset.load(dst, verify=False)
    with h5py.File(dst, "r+") as f:  # the content hash made anew, as a user's edit would
        f.attrs["content_hash"] = ds.content_hash()
    return dst


def _scenario_rate_times(factor: float):
    def edit(f):
        sc = json.loads(f.attrs["scenario"])
        sc["simulation"]["sample_rate"] *= factor
        f.attrs["scenario"] = json.dumps(sc)
    return edit


def test_a_rate_its_own_scenario_contradicts_is_refused(mm_file, tmp_path):
    """fs 1 % off the rate the file's own scenario records at was read with status 0 (the cache
    refuses such an entry; identify and export did not)."""
    path = _edited(mm_file, tmp_path / "rate.h5", _scenario_rate_times(1.01))
    with pytest.raises(MeasuredDataError, match=r"fs=100\.0 Hz but its scenario .* records at 101\.0\d* Hz"):
        read_measured(path)
    with pytest.raises(MeasuredDataError, match=r"records at 101\.0\d* Hz"):
        export_dataset(path, "sep005", tmp_path / "out.json")


def test_a_layout_attribute_other_than_channels_by_samples_is_refused(mm_file, tmp_path):
    """The reader takes rows as channels whatever `layout` says: "samples x channels" was read
    as channels x samples in silence."""
    path = _edited(mm_file, tmp_path / "layout.h5",
                   lambda f: f["measured/x"].attrs.__setitem__("layout", "samples x channels"))
    with pytest.raises(MeasuredDataError, match=r"/measured/x: attribute layout='samples x channels'"):
        read_measured(path)


def test_the_clean_file_still_reads(mm_file):
    assert read_measured(mm_file).fs == 100.0


# ------------------------------------------------------------------ trailing whitespace

@pytest.mark.parametrize("name", ["c\n", "c ", "c\t", " "])
def test_a_path_ending_in_whitespace_is_refused(cli_in_process, tmp_path, name):
    """`--cache "c\\n"` made a folder whose name ends in a line end, in silence."""
    p = cli_in_process("generate", "michaelis_menten", "-o", str(tmp_path / "o.h5"), "--cache",
                       name, cwd=tmp_path)
    assert p.returncode == 2
    assert "ends in a blank or line end" in _one_error_line(p.stderr)
    assert sorted(x.name for x in tmp_path.iterdir()) == []


def test_an_existing_path_ending_in_whitespace_is_taken(cli_in_process, tmp_path):
    (tmp_path / "c ").mkdir()
    p = cli_in_process("generate", "michaelis_menten", "-o", str(tmp_path / "o.h5"), "--cache",
                       "c ", cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert list((tmp_path / "c ").glob("*.h5"))
