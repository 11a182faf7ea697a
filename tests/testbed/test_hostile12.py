"""Twelfth malformed-input round: the findings of ``benchmarks/hostile12.py`` (docs/history.md,
malformed-input audits), each refused in one line by the layer that owns the check.
"""

from __future__ import annotations

import copy
import errno
import math

import pytest

from benchmarks import _hostile
from testbed.core.errors import InputError, TestbedError
from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml, scenario_from_dict

_row = _hostile.results_row


def _grid() -> list[dict]:
    return [_row(cell="c1"), _row(cell="c2", seed=1), _row(cell="c3", noise=1.0)]


# ------------------------------------------------------------------ results files

def test_a_row_copied_under_another_cell_key_is_refused_by_readers_not_by_the_sweep(tmp_path):
    from testbed.studies.results import ResultsError, read_results, write_part, write_rows

    # `testbed summary` counted it: "4 cells", a pass rate over 2 at noise 0 where the grid has 1
    res = write_rows(tmp_path / "r.parquet", [*_grid(), _row(cell="c9")], study="s")
    with pytest.raises(ResultsError, match=r"cells 'c1' and 'c9' are both scenario "
                                           r"'michaelis_menten', noise 0 %, seed 0"):
        read_results(res)
    # the sweep that owns the file drops cells no longer in its grid (a study edited mid-sweep)
    assert len(read_results(res, resuming=True)) == 4
    # the same as a row file beside the consolidated file
    res2 = write_rows(tmp_path / "r2.parquet", _grid(), study="s")
    write_part(res2, _row(cell="c9"))
    with pytest.raises(ResultsError, match="expected one row per cell"):
        read_results(res2)


def test_rows_of_two_studies_are_refused_by_readers(tmp_path):
    from testbed.studies.results import ResultsError, read_results, write_part, write_rows

    # `testbed summary` named the first row's study and merged the other's rows in silence
    res = write_rows(tmp_path / "r.parquet", _grid(), study="s")
    write_part(res, _row(cell="c9", study="t", seed=5))
    with pytest.raises(ResultsError, match="rows of studies 's', 't'"):
        read_results(res)
    res2 = write_rows(tmp_path / "r2.parquet", _grid(), study="other")  # the file's name: not its rows'
    with pytest.raises(ResultsError, match="study 's', the file's is 'other'"):
        read_results(res2)
    # a row without a study name is the file's own, as the sweep reads it (review, round 12)
    res3 = write_rows(tmp_path / "r3.parquet", [*_grid(), _row(cell="c4", seed=4, study="")],
                      study="s")
    assert len(read_results(res3)) == 4


def test_summary_and_report_read_the_rows_of_a_sweep_killed_before_consolidating(tmp_path, capsys):
    from testbed.cli import main
    from testbed.studies.results import write_part

    # a sweep killed by SIGKILL on its first run leaves only `<results>.parts/`: both commands
    # said "no such file" of rows the sweep itself resumes from
    res = tmp_path / "r.parquet"
    for r in _grid():
        write_part(res, r)
    assert main(["summary", str(res)]) == 0
    assert "3 cells from" in capsys.readouterr().out.replace("\n", " ")
    assert main(["summary", str(tmp_path / "none.parquet")]) == 2  # still refused without rows
    assert "no such file" in capsys.readouterr().err


# ------------------------------------------------------------------ -0.0

@pytest.mark.parametrize("base, section, key", [
    ("michaelis_menten", "noise", "rms_percent"), ("michaelis_menten", "rig", "x0"),
    ("cartpole", "rig", "cart_damping"), ("cantilever_stiff_impact", "excitation", "start"),
])
def test_minus_zero_is_zero_the_same_data_and_cells(base, section, key):
    # -0.0 hashed to other data than 0.0: the same record simulated and cached twice, its
    # cells other cells, reported as "noise -0 %"
    raw = _read_toml(SCENARIO_DIR / f"{base}.toml")
    raw["scenario"].pop("extends", None)
    raw.pop("score", None)
    a, b = copy.deepcopy(raw), copy.deepcopy(raw)
    a[section][key], b[section][key] = 0.0, -0.0
    sa, sb = scenario_from_dict(a), scenario_from_dict(b)
    assert sa.data_hash() == sb.data_hash()


def test_a_study_noise_level_of_minus_zero_is_zero():
    from testbed.studies.study import study_from_dict

    raw = {"study": {"name": "h12", "scenarios": ["michaelis_menten"], "noise": [-0.0, 1.0],
                     "seeds": [0], "identifiers": ["sindy_pi_dynamical"]}}
    st = study_from_dict(raw, stem="h12")
    assert math.copysign(1.0, st.noise[0]) == 1.0


# ------------------------------------------------------------------ family write

_FAMILY = """[study]
name = "fam"
scenarios = []
noise = [0.0]
seeds = [0]
identifiers = ["sindy_pi"]
[families.cp]
base = "cartpole"
members = {members}
[families.cp.rig]
pole_length = {{uniform = [0.4, 0.6]}}
"""


def test_family_write_over_a_larger_draw_is_refused_naming_the_stale_members(tmp_path):
    from testbed.studies.study import write_family

    # 3 members written, then 1 into the same folder: the 2 old files stayed beside the new
    # draw in silence, members for any run or sweep over the folder
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    (tmp_path / "a" / "fam.toml").write_text(_FAMILY.format(members=3))
    (tmp_path / "b" / "fam.toml").write_text(_FAMILY.format(members=1))
    out = tmp_path / "out"
    assert len(write_family(tmp_path / "a" / "fam.toml", out)) == 3
    (out / "notes.toml").write_text("# the user's own file: not a member\n")
    with pytest.raises(InputError, match=r"holds 2 member file\(s\) this write does not produce "
                                         r"\(cp__001.toml, cp__002.toml; the families now have cp: 1"):
        write_family(tmp_path / "b" / "fam.toml", out)
    assert len(write_family(tmp_path / "a" / "fam.toml", out)) == 3  # the same draw again: written


# ------------------------------------------------------------------ identify: channels not read

def test_a_csv_channel_the_chain_does_not_read_is_refused(tmp_path):
    from testbed.pipeline.importers import MeasuredDataError, measurement_from_file

    # a column "y [mM]" beside x and dx was dropped in silence, the model fitted to x alone
    f = tmp_path / "d.csv"
    f.write_text("time [s],x [mM],dx [mM/s],y [mM]\n" + "".join(
        f"{k / 100},{math.exp(-k / 100)},{-math.exp(-k / 100)},{math.exp(-k / 100)}\n"
        for k in range(100)))
    with pytest.raises(MeasuredDataError, match=r"signal 'y' \(channel\(s\) y\) is not read by the "
                                                r"dynamical signal chain, which reads x, dx, input"):
        measurement_from_file(f, "dynamical")
    f.write_text("time [s],x [mM],dx [mM/s]\n" + "".join(
        f"{k / 100},{math.exp(-k / 100)},{-math.exp(-k / 100)}\n" for k in range(100)))
    assert measurement_from_file(f, "dynamical").channels == ("x",)


# ------------------------------------------------------------------ figures on a full disk

def test_a_figure_on_a_full_disk_is_one_line_and_leaves_no_file(tmp_path, monkeypatch):
    from pathlib import Path

    from matplotlib.figure import Figure

    from testbed.reporting.figures import save_figure

    # `testbed report` on a full disk left a PNG of 0 bytes and ended in an internal error
    # (OSError 28 naming no file).  The figure is encoded in memory (png_bytes, round 28: a
    # report checks all its outputs before writing any), so the disk fills at the file's write

    def full(self, data):
        with open(self, "wb") as fh:
            fh.write(data[:4])
        raise OSError(errno.ENOSPC, "No space left on device")

    fig = Figure()
    monkeypatch.setattr(Path, "write_bytes", full)
    with pytest.raises(TestbedError, match=r"score\.png: cannot be written: No space left"):
        save_figure(fig, tmp_path / "score.png")
    assert list(tmp_path.iterdir()) == []


# ------------------------------------------------------------------ a cache folder that cannot be made

def test_a_cache_folder_where_nothing_can_be_created_is_refused_naming_the_option(tmp_path, monkeypatch):
    import tempfile

    from testbed.cli import _cache_folder

    # --cache /proc/x: `run` ended in "error: [Errno 2] No such file or directory: '/proc/x'"
    # after its simulation; a sweep failed each of its cells with it
    def enoent(**kw):
        raise OSError(errno.ENOENT, "No such file or directory")

    monkeypatch.setattr(tempfile, "mkstemp", enoent)
    with pytest.raises(InputError, match=r"--cache .*/c: cannot be created in .* \(No such file"):
        _cache_folder(str(tmp_path / "c"))

    def eacces(**kw):  # a read-only cache still serves what it holds: not refused here
        raise OSError(errno.EACCES, "Permission denied")

    monkeypatch.setattr(tempfile, "mkstemp", eacces)
    assert _cache_folder(str(tmp_path / "c")) == str(tmp_path / "c")


# ------------------------------------------------------------------ a library's own error over a full disk

def test_a_full_disk_behind_a_librarys_own_exception_is_one_line(tmp_path):
    from testbed.core.atomic import atomic_write

    # pyuff replaces the OSError of its write by "Exception: Error writing data-set #58"
    # (raised while handling it): `testbed export` on a full disk was an internal error
    def pyuff_like(tmp: str) -> None:
        try:
            raise OSError(errno.ENOSPC, "No space left on device")
        except Exception:
            raise Exception("Error writing data-set #58")  # noqa: B904 (as pyuff does)

    with pytest.raises(InputError, match=r"x\.uff: cannot be written: No space left"):
        atomic_write(tmp_path / "x.uff", pyuff_like)
    assert list(tmp_path.iterdir()) == []

    def other(tmp: str) -> None:  # any other failure of the library stays what it is
        raise Exception("Error writing data-set #58")

    with pytest.raises(Exception, match="#58"):
        atomic_write(tmp_path / "y.uff", other)


def test_a_report_into_the_results_row_folder_is_refused(tmp_path, capsys):
    from testbed.cli import main
    from testbed.studies.results import parts_dir, write_rows

    # written there, the report was deleted by the sweep's next consolidation
    res = write_rows(tmp_path / "r.parquet", _grid(), study="s")
    parts_dir(res).mkdir()
    assert main(["report", str(res), "-o", str(parts_dir(res))]) == 2
    assert "the folder of" in capsys.readouterr().err and not list(parts_dir(res).iterdir())


# ------------------------------------------------------------------ plugin names

@pytest.mark.parametrize("name", [5, "", " ", "a b", "a/b", "../up", "x\ny", ".hidden", "-x", "a" * 129])
def test_a_registered_name_no_file_can_spell_is_refused(name):
    from testbed.core.registry import Registry

    # a plugin registering 5 made `testbed list` an internal error (TypeError sorting the
    # names); "../up" a rig whose cache files went outside the cache folder
    reg = Registry("rig")
    with pytest.raises(ValueError, match=r"rig name .*: expected a name of letters, digits"):
        reg.register(name)(type("R", (), {}))
    reg.register("toy.v2-x_1")(type("R", (), {}))  # letters, digits, '_', '.', '-': registered
    assert reg.names() == ["toy.v2-x_1"]


def test_a_plugin_registering_a_bad_name_is_one_line(tmp_path, capsys):
    from testbed.cli import main

    plugin = tmp_path / "p_int.py"
    plugin.write_text("from identify import IDENTIFIERS\n\n@IDENTIFIERS.register(5)\nclass Mine:\n"
                      "    kind = 'structural'\n")
    assert main(["list", "--plugin", str(plugin)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "identifier name 5: expected a name" in err


def test_summary_says_when_its_cells_come_from_two_versions_of_the_code(tmp_path, capsys):
    from testbed.studies.results import write_rows
    from testbed.studies.statistics import print_summary

    # a sweep resumed after a code change pooled both commits' rows in its medians in silence
    rows = [_row(cell="c1", commit="aaa"), _row(cell="c2", seed=1, commit="bbb"),
            _row(cell="c3", noise=1.0, commit="bbb")]
    print_summary(write_rows(tmp_path / "r.parquet", rows, study="s"))
    out = capsys.readouterr().out.replace("\n", " ")
    assert "computed by 2 versions of the code" in out and "aaa x 1, bbb x 2" in out
    print_summary(write_rows(tmp_path / "one.parquet", _grid(), study="s"))
    assert "versions of the code" not in capsys.readouterr().out


# ------------------------------------------------------------------ identify: a channel pasted twice

def _beam_sep005(path, copy_of: int | None = None, perturb: float = 0.0) -> None:
    import json

    import numpy as np

    fs, n = 2000.0, 2000
    t = np.arange(n) / fs
    acc = [np.exp(-2 * t) * (np.sin(2 * np.pi * (30 + 40 * k) * t) + 0.3 * np.sin(2 * np.pi * 170 * t))
           for k in range(3)]
    pos = [0.1, 0.2, 0.3]
    if copy_of is not None:  # a fourth sensor whose column is another's, pasted
        noise = np.random.default_rng(0).standard_normal(n) * perturb * np.std(acc[copy_of])
        acc.append(acc[copy_of] + noise)
        pos.append(0.4)
    force = np.zeros(n)
    force[:10] = 50.0
    chans = [{"name": f"acceleration/acc{i + 1}", "data": a.tolist(), "unit_str": "m/s^2", "fs": fs,
              "position_m": p} for i, (a, p) in enumerate(zip(acc, pos, strict=True))]
    chans.append({"name": "force/force", "data": force.tolist(), "unit_str": "N", "fs": fs,
                  "position_m": 0.3})
    path.write_text(json.dumps(chans))


def test_a_structural_channel_pasted_twice_is_refused_naming_it(tmp_path):
    from testbed.pipeline.importers import MeasuredDataError, measurement_from_file

    # identified with a mode at 1.6e-5 Hz and exit status 0: the two columns of the library
    # are one, and no fit tells their equations apart
    _beam_sep005(tmp_path / "copy.json", copy_of=0)
    with pytest.raises(MeasuredDataError, match=r"'acceleration' channel 'acc4' is a linear "
                                                r"combination of 'acc1', 'acc2', 'acc3' to round-off"):
        measurement_from_file(tmp_path / "copy.json", "structural")
    _beam_sep005(tmp_path / "ok.json")
    assert measurement_from_file(tmp_path / "ok.json", "structural").x.shape[0] == 3
    # two sensors reading nearly alike (1e-9 of the channel's spread apart: a real record's
    # noise is 1e3-1e6 times that) are two channels, not a copy (numpy's rank rule: round-off)
    _beam_sep005(tmp_path / "near.json", copy_of=0, perturb=1e-9)
    assert measurement_from_file(tmp_path / "near.json", "structural").x.shape[0] == 4
