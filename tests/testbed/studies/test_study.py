"""Study files: the grid, kind-mismatch skipping, and a clear error for every malformation.

A plugin file registers toy rigs and identifiers of both kinds (validation only;
nothing here is simulated), so these tests do not depend on the real rigs.
"""

from __future__ import annotations

import sys
import textwrap
from pathlib import Path

import pytest

from testbed.core.errors import ScenarioError
from testbed.studies.study import STUDY_DIR, load_study

PLUGIN = '''
from identify import IDENTIFIERS
from identify._base import Identifier
from models import RIGS
from models._base import Rig
from testbed.core.schema import Field


class _Toy(Rig):
    simulation_schema = {"n_samples": Field(int, 10)}
    excitation_schemas = {"none": {}}
    default_excitation = "none"
    measured_signals = ("theta",)
    noisy_signals = ("theta",)


@RIGS.register("st_mech_rig")
class MechRig(_Toy):
    kind = "mechanical"


@RIGS.register("st_struct_rig")
class StructRig(_Toy):
    kind = "structural"


@IDENTIFIERS.register("st_mech_id")
class MechId(Identifier):
    kind = "mechanical"

    def __init__(self, alpha: float = 0.1, n_iter: int = 10, solver: str = "lsq"):
        self.alpha, self.n_iter, self.solver = alpha, n_iter, solver


@IDENTIFIERS.register("st_struct_id")
class StructId(Identifier):
    kind = "structural"

    def __init__(self, threshold: float = 0.0):
        self.threshold = threshold
'''

VALID = """
[study]
name = "{name}"
description = "toys"
scenarios = ["mech.toml", "struct.toml"]
noise = [0.0, 1.0, 5.0]
seeds = [0, 1, 2]
identifiers = ["st_mech_id", "st_struct_id"]
plugins = ["plugin.py"]

[identifiers.st_mech_id]
alpha = 1
solver = "qr"
"""


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    """The toy files; afterwards the registries and modules are as before, so the toy rigs and
    identifiers do not leak into other tests (e.g. the generated scenario guide)."""
    from identify import IDENTIFIERS
    from models import RIGS

    saved = [(r, r.snapshot()) for r in (RIGS, IDENTIFIERS)]
    modules = set(sys.modules)
    d = tmp_path_factory.mktemp("study")
    (d / "plugin.py").write_text(PLUGIN)
    (d / "broken_plugin.py").write_text("raise RuntimeError('plugin broke')\n")
    for name, rig in (("mech", "st_mech_rig"), ("struct", "st_struct_rig")):
        (d / f"{name}.toml").write_text(f'[scenario]\nname = "{name}"\nrig = "{rig}"\n')
    yield d
    for r, snap in saved:
        r.restore(snap)
    for m in set(sys.modules) - modules:
        if m.startswith("_testbed_plugin_"):
            del sys.modules[m]


def write(folder: Path, name: str, text: str) -> Path:
    p = folder / f"{name}.toml"
    p.write_text(textwrap.dedent(text))
    return p


def test_valid_study_grid_and_skipped_kinds(folder):
    study = load_study(write(folder, "ok", VALID.format(name="ok")))
    assert study.name == "ok" and study.description == "toys"
    assert [s.name for s in study.scenarios] == ["mech", "struct"]
    assert study.noise == (0.0, 1.0, 5.0) and study.seeds == (0, 1, 2)
    # integers are accepted for floats and widened, unset hyperparameters stay default
    assert study.params == {"st_mech_id": {"alpha": 1.0, "solver": "qr"}, "st_struct_id": {}}
    assert isinstance(study.params["st_mech_id"]["alpha"], float)
    assert [(s.name, m) for s, m in study.combinations()] == [("mech", "st_mech_id"),
                                                              ("struct", "st_struct_id")]
    assert [(s, m) for s, m, _ in study.skipped()] == [("mech", "st_struct_id"), ("struct", "st_mech_id")]
    assert "identifier kind 'structural' != rig kind 'mechanical'" in study.skipped()[0][2]
    assert study.n_cells() == 2 * 3 * 3


def _replace(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new)


BASE = VALID.format(name="bad")

CASES = {
    # id: (file text, key named in the error, fragment of the message)
    "unknown section": (BASE + "\n[extra]\na = 1\n", "extra", "unknown section"),
    "unknown key": (_replace(BASE, 'description = "toys"', 'descr = "toys"'), "study.descr",
                    "unknown key; allowed keys in [study]"),
    "missing key": (_replace(BASE, "seeds = [0, 1, 2]\n", ""), "study.seeds", "missing"),
    "wrong type": (_replace(BASE, "noise = [0.0, 1.0, 5.0]", 'noise = "5"'), "study.noise",
                   "expected a list of"),
    "wrong item type": (_replace(BASE, "seeds = [0, 1, 2]", "seeds = [0, 1.5]"), "study.seeds[1]",
                        "expected an integer"),
    "bool seed": (_replace(BASE, "seeds = [0, 1, 2]", "seeds = [true]"), "study.seeds[0]",
                  "expected an integer"),
    "empty seeds": (_replace(BASE, "seeds = [0, 1, 2]", "seeds = []"), "study.seeds",
                    "with at least 1 item"),
    "empty identifiers": (_replace(BASE, 'identifiers = ["st_mech_id", "st_struct_id"]',
                                   "identifiers = []"), "study.identifiers", "at least 1 item"),
    "negative noise": (_replace(BASE, "noise = [0.0, 1.0, 5.0]", "noise = [1.0, -2.0]"),
                       "study.noise[1]", ">= 0"),
    "negative seed": (_replace(BASE, "seeds = [0, 1, 2]", "seeds = [-1]"), "study.seeds[0]", ">= 0"),
    "duplicate seeds": (_replace(BASE, "seeds = [0, 1, 2]", "seeds = [0, 1, 0]"), "study.seeds[2]",
                        "duplicate"),
    "duplicate noise": (_replace(BASE, "noise = [0.0, 1.0, 5.0]", "noise = [1, 1.0]"), "study.noise[1]",
                        "duplicate"),
    "unknown scenario": (_replace(BASE, '"struct.toml"]', '"nope"]'), "study.scenarios[1]",
                         "no scenario file"),
    "unknown identifier": (_replace(BASE, '"st_struct_id"]', '"st_nope"]'), "study.identifiers[1]",
                           "expected a registered identifier, one of"),
    "name not stem": (_replace(BASE, 'name = "bad"', 'name = "other"'), "study.name",
                      "must equal the file name"),
    "unknown hyperparameter": (BASE + "beta = 2\n", "identifiers.st_mech_id.beta",
                               "unknown hyperparameter of st_mech_id; allowed: alpha, n_iter, solver"),
    "hyperparameter type": (_replace(BASE, 'solver = "qr"', "solver = 3"), "identifiers.st_mech_id.solver",
                            "expected a string"),
    "int hyperparameter as float": (BASE + "n_iter = 2.5\n", "identifiers.st_mech_id.n_iter",
                                    "expected an integer"),
    "method in table": (BASE + 'method = "x"\n', "identifiers.st_mech_id.method", "not allowed here"),
    "params of unlisted identifier": (BASE + "[identifiers.st_other]\na = 1\n", "identifiers.st_other",
                                      "not in study.identifiers"),
    "identifier matching no rig": (_replace(BASE, '["mech.toml", "struct.toml"]', '["mech.toml"]'),
                                   "study.identifiers[1]", "every cell of it would be skipped"),
    "scenario matching no identifier": (_replace(BASE, '["st_mech_id", "st_struct_id"]',
                                                 '["st_struct_id"]').replace(
        "[identifiers.st_mech_id]\nalpha = 1\nsolver = \"qr\"\n", ""), "study.scenarios[0]",
        "every cell of it would be skipped"),
    "broken plugin": (_replace(BASE, '"plugin.py"]', '"plugin.py", "broken_plugin.py"]'),
                      "study.plugins[1]", "RuntimeError: plugin broke"),
    "missing [study]": ("[identifiers.x]\na = 1\n", "study", "missing [study] table"),
    # seeds are stored as 64-bit signed integers (HDF5 attributes, the results' seed column)
    "seed beyond 64 bits": (_replace(BASE, "seeds = [0, 1, 2]", "seeds = [9223372036854775808]"),
                            "study.seeds[0]", "<= 9223372036854775807"),
    # every score is >= 0: a negative bar could never pass (was accepted)
    "negative threshold": (BASE + "[thresholds.st_mech_id]\nangle_rmse_max = -1.0\n",
                           "thresholds.st_mech_id.angle_rmse_max", "could never pass"),
}


@pytest.mark.parametrize("case", list(CASES))
def test_malformed_study_names_file_key_and_allowed(folder, case):
    text, key, fragment = CASES[case]
    path = write(folder, "bad", text)
    with pytest.raises(ScenarioError) as err:
        load_study(path)
    e = err.value
    assert e.file == str(path)
    assert e.key == key, str(e)
    assert fragment in str(e)


def test_not_toml_and_missing_file(folder):
    with pytest.raises(ScenarioError, match="not valid TOML"):
        load_study(write(folder, "broken", "[study\n"))
    with pytest.raises(ScenarioError, match="no such study file"):
        load_study(folder / "absent.toml")


def test_bare_name_resolves_in_studies_folder():
    with pytest.raises(ScenarioError) as err:
        load_study("no_such_study_name")
    assert err.value.file == str(STUDY_DIR / "no_such_study_name.toml")


@pytest.mark.parametrize("name", sorted(p.stem for p in STUDY_DIR.glob("*.toml")))
def test_shipped_studies_are_valid(name):
    study = load_study(name)
    assert study.n_cells() > 0
    from testbed.studies.sweep import expand

    assert len({c.key for c in expand(study)}) == study.n_cells()


def test_family_of_a_kind_no_identifier_fits_names_the_family():
    # round 5 (benchmarks/unseen/round5/mm_study_kind_mismatch.toml): a kinetics family beside a
    # cart-pole one, only a mechanical identifier listed; the members follow the named
    # scenarios, so indexing study.scenarios by a member's position ended in an IndexError
    path = Path(__file__).resolve().parents[3] / "benchmarks" / "unseen" / "round5" / \
        "mm_study_kind_mismatch.toml"
    with pytest.raises(ScenarioError) as err:
        load_study(path)
    e = err.value
    assert e.key == "families.mm" and e.value == "michaelis_menten"
    assert "rig kind 'dynamical'" in str(e) and "study.identifiers: sindy_pi" in str(e)
