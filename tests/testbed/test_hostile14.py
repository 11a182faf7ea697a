"""Fourteenth malformed-input round: the findings of ``benchmarks/hostile14.py`` (docs/history.md,
malformed-input audits), each fixed in the layer that owns it.
"""

from __future__ import annotations

import os
import re
import socket

import pytest

from testbed.core.errors import InputError

# ------------------------------------------------------------------ the `testbed list` index


@pytest.mark.parametrize("node", ["fifo", "zero"])
def test_an_index_that_is_a_fifo_or_device_is_computed_not_read(tmp_path, monkeypatch, node):
    from testbed.core import stamped

    # a FIFO at the index's path blocked `testbed list` for ever; a link to /dev/zero read
    # until memory ran out
    monkeypatch.setenv(stamped.INDEX_VARIABLE, str(tmp_path))
    path = tmp_path / stamped._key("t")
    if node == "fifo":
        os.mkfifo(path)
    else:
        path.symlink_to("/dev/zero")
    built = []

    def build():
        built.append(1)
        return ["v"], [], []

    assert stamped.stamped_value("t", build) == ["v"] and built == [1]
    assert path.is_fifo() if node == "fifo" else path.is_symlink()  # left as it was


def test_an_index_larger_than_any_index_is_not_read(tmp_path, monkeypatch):
    from testbed.core import stamped

    monkeypatch.setattr(stamped, "MAX_INDEX_BYTES", 10)
    path = tmp_path / "i.json"
    path.write_text('{"format": 2}')
    with pytest.raises(OSError, match="not a regular file of at most 10 bytes"):
        stamped._read_regular(path)
    assert stamped._read(path, lambda v: True) is None


@pytest.mark.parametrize("edit", ["flip", "no sections"])
def test_an_index_whose_content_is_not_its_checksums_is_computed(tmp_path, monkeypatch, edit):
    import json
    import time

    from testbed.core import stamped

    # a bit flipped in a scenario's description was listed as flipped; a value edited to a
    # listing of no sections printed nothing, status 0 (the shape check passes both)
    monkeypatch.setenv(stamped.INDEX_VARIABLE, str(tmp_path / "index"))
    monkeypatch.setattr(stamped, "_implicit", lambda: (set(), set()))
    monkeypatch.setattr(stamped, "_IMPORTED_AT", time.time())
    src = tmp_path / "a.txt"
    src.write_text("alpha")
    old = time.time() - 3600
    os.utime(src, (old, old))
    built = []

    def build():
        built.append(1)
        return [["scenarios", ["name"], [[src.read_text()]]]], [src], []

    assert stamped.stamped_value("list", build) == [["scenarios", ["name"], [["alpha"]]]]
    assert stamped.stamped_value("list", build) and built == [1]  # kept, read back
    path = tmp_path / "index" / stamped._key("list")
    index = json.loads(path.read_text())
    index["value"] = [] if edit == "no sections" else [["scenarios", ["name"], [["alphA"]]]]
    path.write_text(json.dumps(index))
    assert stamped.stamped_value("list", build) == [["scenarios", ["name"], [["alpha"]]]]
    assert built == [1, 1]


# ------------------------------------------------------------------ `testbed serve`'s socket


@pytest.mark.parametrize("what", ["file", "fifo", "folder", "link"])
def test_serve_never_removes_what_is_not_a_socket(tmp_path, what):
    from testbed import server

    # a regular file named by $TESTBED_SERVER_SOCKET was deleted (its content lost) and a
    # socket bound in its place; a folder ended `serve` in "[Errno 21] Is a directory"
    path = tmp_path / "s"
    if what == "file":
        path.write_text("precious")
    elif what == "fifo":
        os.mkfifo(path)
    elif what == "folder":
        path.mkdir()
    else:
        path.symlink_to(tmp_path / "elsewhere")
    kind = {"file": "a file", "fifo": "a FIFO", "folder": "a folder", "link": "a symbolic link"}
    with pytest.raises(InputError, match=f"holds {kind[what]}, which the server would remove"):
        server._refuse_if_served(path)
    assert os.path.lexists(path)
    if what == "file":
        assert path.read_text() == "precious"


def test_serve_still_removes_a_dead_servers_socket(tmp_path):
    from testbed import server

    path = tmp_path / "s"
    dead = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    dead.bind(str(path))
    dead.close()  # bound, never listening: what a killed server leaves
    server._refuse_if_served(path)
    assert not os.path.lexists(path)


# ------------------------------------------------------------------ entry-point plugins


def _entry_point(site, value: str, source: str):
    """A distribution in the folder ``site`` with one entry point ``x = value`` in a private
    group, and its module ``fake14mod`` of ``source``; a registry reading that group."""
    from testbed.core.registry import Registry

    dist = site / "fake14-0.1.dist-info"
    dist.mkdir(parents=True)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: fake14\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text(f"[testbed_hostile14]\nx = {value}\n")
    (site / "fake14mod.py").write_text(source)
    return Registry("identifier", entry_points="testbed_hostile14")


@pytest.mark.parametrize("value, source, message", [
    # sys.exit(0) at import ended `testbed list` and `testbed run` with status 0, no output
    ("fake14mod", "import sys\nsys.exit(0)\n", "SystemExit: 0"),
    # a function or an instance was loaded and ignored in silence
    ("fake14mod:f", "def f():\n    pass\n", "names an object of type 'function'"),
    ("fake14mod:obj", "obj = 5\n", "names an object of type 'int'"),
])
def test_an_entry_point_that_exits_or_names_no_class_is_refused(tmp_path, monkeypatch, value,
                                                                 source, message):
    from testbed.core.registry import PluginError

    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(__import__("sys").modules, "fake14mod", raising=False)
    reg = _entry_point(tmp_path, value, source)
    with pytest.raises(PluginError, match=f"entry point x = {value} .*{message}"):
        reg.names()
    monkeypatch.delitem(__import__("sys").modules, "fake14mod", raising=False)


def test_an_entry_point_naming_a_class_still_registers_it(tmp_path, monkeypatch):
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(__import__("sys").modules, "fake14mod", raising=False)
    reg = _entry_point(tmp_path, "fake14mod:C", "class C:\n    name = 'c14'\n")
    assert reg.names() == ["c14"] and reg.origin("c14") == "entry point x (fake14)"
    monkeypatch.delitem(__import__("sys").modules, "fake14mod", raising=False)


# ------------------------------------------------------------------ UFF58 units, declared twice


def _uff58(path, label: str, spec: int, len_exp: int = 1):
    """One UFF58 time record of 64 samples at 100 Hz: ``label`` and specific data type
    ``spec`` (with ``len_exp``) as its ordinate's declared unit."""
    import numpy as np
    import pyuff

    t = np.arange(64) / 100.0
    rec = pyuff.prepare_58(
        binary=0, func_type=1, ver_num=0, load_case_id=0, id1="acceleration/acc1", id2="",
        id3="", id4="", id5="", rsp_ent_name="acc1", rsp_node=1, rsp_dir=3, ref_ent_name="NONE",
        ref_node=0, ref_dir=0, data=np.sin(2 * np.pi * 5 * t), x=t, abscissa_spacing=1,
        abscissa_spec_data_type=17, abscissa_len_unit_exp=0, abscissa_force_unit_exp=0,
        abscissa_temp_unit_exp=0, abscissa_axis_units_lab="s", ordinate_spec_data_type=spec,
        ordinate_len_unit_exp=len_exp, ordinate_force_unit_exp=0, ordinate_temp_unit_exp=0,
        ordinate_axis_units_lab=label, orddenom_spec_data_type=0, z_axis_spec_data_type=0,
        z_axis_value=0.0)
    pyuff.UFF(str(path)).write_sets([rec], mode="overwrite")
    return path


@pytest.mark.parametrize("label, spec, refused", [
    ("m/s^2", 8, True),   # a displacement record labelled as an acceleration: read as one
    ("m", 12, True),      # an acceleration record labelled in metres
    ("N", 12, True),
    ("m/s^2", 12, False),  # agreeing
    ("g", 12, False),      # the codes' quantity in another unit: read by the label, as before
    ("m/s^2", 0, False),   # no quantity coded (type 0, unknown): the label alone
])
def test_a_uff_record_whose_label_and_codes_disagree_is_refused(tmp_path, label, spec, refused):
    from testbed.pipeline.importers import MeasuredDataError, read_measured

    path = _uff58(tmp_path / "r.uff", label, spec)
    if refused:
        with pytest.raises(MeasuredDataError, match=f"ordinate unit label '{re.escape(label)}' .* disagrees "
                                                    f"with its specific data type {spec}"):
            read_measured(path)
    else:
        unit = read_measured(path).signals["acceleration/acc1"][0]
        assert unit == "m/s^2"


# ------------------------------------------------------------------ hostile channel names


@pytest.mark.parametrize("name", ["acceleration/acc\n2", "acceleration/acc\x002",
                                  "acceleration/acc\x1b[31mRED", "acceleration/acc\u200b2",
                                  "acceleration/acc\u200f2"])
def test_a_channel_name_with_a_control_or_invisible_character_is_refused(name):
    import numpy as np

    from testbed.pipeline.importers import MeasuredDataError, from_sep005

    # a newline, NUL or terminal escape in a SEP-005 or UFF name went on to the console (an
    # ESC sequence coloured it), the model's JSON and its report's markdown
    x = np.sin(np.arange(100) / 10.0)
    chans = [{"name": "acceleration/acc1", "data": x, "fs": 100.0, "unit_str": "m/s^2"},
             {"name": name, "data": x + 1, "fs": 100.0, "unit_str": "m/s^2"}]
    with pytest.raises(MeasuredDataError, match="holds the control or invisible character"):
        from_sep005(chans)
    chans[1]["name"] = "acceleration/accé 2"  # printable Unicode and a space: read as before
    assert list(from_sep005(chans).signals) == ["acceleration/acc1", "acceleration/accé 2"]


@pytest.mark.parametrize("space", ["\u00a0", "\u202f", "\u00ad", "\u3000"])
def test_a_channel_name_with_a_spreadsheets_space_is_read(space):
    """The refusal above caught a spreadsheet's no-break space (U+00A0), a French-locale export's
    narrow one (U+202F) and a soft hyphen (review of round 14): characters that show, or show
    as a space, are a lab's own names and are read as given."""
    import numpy as np

    from testbed.pipeline.importers import from_sep005

    x = np.sin(np.arange(100) / 10.0)
    name = f"acceleration/acc{space}2"
    chans = [{"name": "acceleration/acc1", "data": x, "fs": 100.0, "unit_str": "m/s^2"},
             {"name": name, "data": x + 1, "fs": 100.0, "unit_str": "m/s^2"}]
    assert list(from_sep005(chans).signals) == ["acceleration/acc1", name]


def test_a_written_path_keeps_its_spaces_and_escapes_its_controls():
    from testbed.core.errors import terminal_safe

    assert terminal_safe("runs/caf\udce9 a\u202fb\u00a0c") == "runs/caf\udce9 a\u202fb\u00a0c"
    assert terminal_safe("e\x1b[31m\u202e.h5\n") == "e\\x1b[31m\\u202e.h5\\n"


# ------------------------------------------------------------------ one-line texts


@pytest.mark.parametrize("text", ["two\nlines", "a\ttab", "an \x1b[31mESC", "a\u2028separator",
                                  "a\x7fDEL", "a\x85NEL"])
@pytest.mark.parametrize("where", ["scenario.description", "scenario.tags", "study.description",
                                   "family.description"])
def test_a_free_text_with_a_control_character_is_refused(text, where):
    from testbed.core.errors import ScenarioError
    from testbed.core.schema import check_value
    from testbed.pipeline.scenario import HEADER_SCHEMA
    from testbed.studies.family import FAMILY_SCHEMA
    from testbed.studies.study import STUDY_SCHEMA

    # a scenario's description with a newline split its row of `testbed list --plain` in two,
    # a tab added a column, an ESC sequence went raw to the terminal
    schema = {"scenario": HEADER_SCHEMA, "study": STUDY_SCHEMA, "family": FAMILY_SCHEMA}
    table, key = where.split(".")
    field = schema[table][key]
    value = [text] if field.type is list else text
    with pytest.raises(ScenarioError, match="without control characters"):
        check_value(value, field, file="f.toml", key=where)
    ok = ["Ünïcode — text, 'quoted' [1 %]"] if field.type is list else "Ünïcode — text, 'quoted' [1 %]"
    assert check_value(ok, field, file="f.toml", key=where) == ok


# ------------------------------------------------------------------ error lines


@pytest.mark.parametrize("argv", [["summary", "x\x1b[31mRED"], ["report", "x\x1b[31mRED", "-o", "r"],
                                  ["list", "--bogus\x1b[31m"]])
def test_an_error_line_never_carries_a_control_character(argv, capsys, tmp_path, monkeypatch):
    from testbed.cli import main

    # the ESC of a `summary` file, a `report` source or a `--prior` key went raw to the terminal
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("TESTBED_NO_SERVER", "1")
    try:
        status = main(argv)
    except SystemExit as e:  # (argparse's own refusal exits)
        status = e.code
    assert status == 2
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "\\x1b[31m" in err and "\x1b" not in err
    assert err.count("\n") == 1


# ------------------------------------------------------------------ served requests


@pytest.mark.parametrize("change, why", [
    ({"env": {"X": "\ud800"}}, "an environment variable the system cannot hold"),
    ({"env": {"\ud800": "1"}}, "an environment variable the system cannot hold"),
    ({"cwd": "/tmp/\ud800"}, "a cwd the system cannot hold"),
])
def test_a_request_holding_a_lone_surrogate_is_refused(change, why):
    from testbed import server

    # JSON carries a lone surrogate; the child's os.environ or os.chdir raised
    # UnicodeEncodeError: "internal error (a bug, not your input)", status 3
    request = {"argv": ["list"], "cwd": "/tmp", "env": {"HOME": "/root"}, "umask": 0o22, **change}
    assert server._bad_field(request) == why
    # what the testbed's own client sends: undecodable bytes as surrogateescape's \udc80-\udcff
    request.update(cwd="/tmp", env={"X": os.fsdecode(b"\xff")})
    assert server._bad_field(request) == ""


@pytest.mark.parametrize("argv", [["summary", "x" * 100_000], ["export", "y" * 100_000, "--format", "uff"]])
def test_an_error_line_cuts_a_path_of_100000_characters(argv, capsys, tmp_path, monkeypatch):
    from testbed.cli import MAX_WORD_CHARS, main

    # a path under Linux's 128 kB an argument made a 100 kB "one line" error
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("TESTBED_NO_SERVER", "1")
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and len(err) < MAX_WORD_CHARS + 200
    assert "characters ...]" in err and err.rstrip().endswith("too long for the file system)")


def test_a_plugin_file_name_too_long_for_the_file_system_is_one_error_line():
    from testbed.core.registry import PluginError, import_plugin

    # `run --plugin <100,000 characters>.py`: OSError 36 from Path.resolve, an internal error
    with pytest.raises(PluginError, match="not a usable path"):
        import_plugin("x" * 100_000 + ".py")


def test_a_written_path_is_printed_with_its_control_characters_escaped(cli_in_process, tmp_path):
    """``generate -o $'e\\x1b[31m.h5'`` printed its "wrote" line with the ESC raw (round 14's
    open item): every line naming a path the command wrote escapes it as the error lines do."""
    from testbed.pipeline.scenario import SCENARIO_DIR

    text = (SCENARIO_DIR / "michaelis_menten.toml").read_text()
    (tmp_path / "michaelis_menten.toml").write_text(text)
    done = cli_in_process("generate", "michaelis_menten.toml", "-o", "e\x1b[31m.h5", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "e\x1b[31m.h5").is_file()
    assert "\x1b" not in done.stdout and "wrote e\\x1b[31m.h5" in done.stdout
