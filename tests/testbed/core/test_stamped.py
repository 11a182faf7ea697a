"""testbed.core.stamped: a value kept while the stamps of what it was computed from hold.

The loaded modules' files and ``sys.path``'s folders (recorded for every value) are left out
here (:func:`_no_implicit`): a test process's own modules may be minutes old; the command
line's test (tests/testbed/test_cli_startup.py) runs with them.
"""

from __future__ import annotations

import os
import sys
import time

import pytest

from testbed.core import stamped

#: The implicit stamps as shipped (the fixture below replaces them).
_REAL_IMPLICIT = stamped._implicit

#: A time safely older than the racy window [s before now].
OLD_S = 3600.0


def _backdate(*paths, age: float = OLD_S) -> None:
    t = time.time() - age
    for p in paths:
        os.utime(p, (t, t))


@pytest.fixture
def index(tmp_path, monkeypatch):
    """An index folder of the test's own, without the implicit stamps."""
    monkeypatch.setenv(stamped.INDEX_VARIABLE, str(tmp_path / "index"))
    monkeypatch.setattr(stamped, "_implicit", lambda: (set(), set()))
    monkeypatch.setattr(stamped, "_IMPORTED_AT", time.time())
    return tmp_path / "index"


def _counting(folder):
    """A build reading every ``*.txt`` of ``folder`` (its folder and files recorded), and the
    list of its calls."""
    calls = []

    def build():
        calls.append(1)
        files = sorted(folder.glob("*.txt"))
        return {f.name: f.read_text() for f in files}, files, [folder]

    return build, calls


def _setup(tmp_path):
    data = tmp_path / "data"
    data.mkdir()
    (data / "a.txt").write_text("alpha")
    _backdate(data / "a.txt", data)
    return data


def test_kept_while_nothing_changes(index, tmp_path):
    data = _setup(tmp_path)
    build, calls = _counting(data)
    assert stamped.stamped_value("t", build) == {"a.txt": "alpha"}
    assert stamped.stamped_value("t", build) == {"a.txt": "alpha"}
    assert len(calls) == 1  # the second from the index


def test_a_file_edited_is_computed_again(index, tmp_path):
    data = _setup(tmp_path)
    build, calls = _counting(data)
    stamped.stamped_value("t", build)
    (data / "a.txt").write_text("omega")  # same size, another time
    _backdate(data / "a.txt", age=OLD_S / 2)
    assert stamped.stamped_value("t", build) == {"a.txt": "omega"}
    assert len(calls) == 2


def test_a_file_added_or_removed_is_computed_again(index, tmp_path):
    data = _setup(tmp_path)
    build, calls = _counting(data)
    stamped.stamped_value("t", build)
    (data / "b.txt").write_text("beta")
    assert stamped.stamped_value("t", build) == {"a.txt": "alpha", "b.txt": "beta"}
    (data / "b.txt").unlink()
    assert stamped.stamped_value("t", build) == {"a.txt": "alpha"}
    assert len(calls) == 3


def test_an_absent_file_that_appears_is_computed_again(index, tmp_path):
    data = _setup(tmp_path)
    other = tmp_path / "elsewhere"
    other.mkdir()
    _backdate(other)
    calls = []

    def build():
        calls.append(1)
        f = other / "maybe.txt"
        return f.read_text() if f.exists() else "-", [f], []

    assert stamped.stamped_value("t", build) == "-"
    assert stamped.stamped_value("t", build) == "-"
    (other / "maybe.txt").write_text("here")
    assert stamped.stamped_value("t", build) == "here"
    assert len(calls) == 2
    assert data.is_dir()


def test_racy_stamps_are_not_kept(index, tmp_path):
    """A file changed less than RACY_S before the module's import may change again unseen
    within the file system's time resolution: computed each time until it is older."""
    data = _setup(tmp_path)
    (data / "a.txt").write_text("fresh")
    build, calls = _counting(data)
    stamped.stamped_value("t", build)
    stamped.stamped_value("t", build)
    assert len(calls) == 2 and not index.exists()


def test_a_long_lived_process_does_not_write(index, tmp_path, monkeypatch):
    data = _setup(tmp_path)
    monkeypatch.setattr(stamped, "_IMPORTED_AT", time.time() - stamped.WRITE_WITHIN_S - 1)
    build, calls = _counting(data)
    stamped.stamped_value("t", build)
    stamped.stamped_value("t", build)
    assert len(calls) == 2


def test_a_damaged_index_is_computed_again(index, tmp_path):
    data = _setup(tmp_path)
    build, calls = _counting(data)
    stamped.stamped_value("t", build)
    (kept,) = index.iterdir()
    for text in ("{not json", "[]", '{"format": 1}', '{"format": 1, "value": 1, "files": 3}'):
        kept.write_text(text)
        assert stamped.stamped_value("t", build) == {"a.txt": "alpha"}
    assert len(calls) == 5


def test_turned_off_and_a_failing_build(index, tmp_path, monkeypatch):
    data = _setup(tmp_path)
    build, calls = _counting(data)
    monkeypatch.setenv(stamped.INDEX_VARIABLE, "")
    stamped.stamped_value("t", build)
    stamped.stamped_value("t", build)
    assert len(calls) == 2 and not index.exists()
    monkeypatch.setenv(stamped.INDEX_VARIABLE, str(index))

    def broken():
        raise ValueError("bad scenario")

    with pytest.raises(ValueError, match="bad scenario"):
        stamped.stamped_value("t", broken)
    assert not index.exists()


def test_an_unwritable_index_folder_only_costs_time(index, tmp_path, monkeypatch):
    data = _setup(tmp_path)
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    monkeypatch.setenv(stamped.INDEX_VARIABLE, str(blocker / "index"))  # under a file
    build, calls = _counting(data)
    assert stamped.stamped_value("t", build) == {"a.txt": "alpha"}
    assert stamped.stamped_value("t", build) == {"a.txt": "alpha"}
    assert len(calls) == 2




def test_a_module_without_a_file_of_its_own_writes_no_index(index, tmp_path, monkeypatch):
    """A module imported from a zip archive has no file to stamp: its edits could not be seen,
    so nothing is kept; a module file of its own is recorded and kept."""
    data = _setup(tmp_path)
    monkeypatch.setattr(stamped, "_implicit", _REAL_IMPLICIT)
    monkeypatch.setattr(sys, "path", [str(data)])
    monkeypatch.setattr(stamped, "_entry_point_files", set)
    module = tmp_path / "mod.py"
    module.write_text("")
    _backdate(module, data)
    for modules, kept in (({str(tmp_path / "lib.zip" / "mod.py")}, False), ({str(module)}, True)):
        monkeypatch.setattr(stamped, "_module_files", lambda m=modules: set(m))
        build, calls = _counting(data)
        stamped.stamped_value("t", build)
        stamped.stamped_value("t", build)
        assert len(calls) == (1 if kept else 2) and index.exists() == kept


def test_the_index_folder(monkeypatch, tmp_path):
    monkeypatch.delenv(stamped.INDEX_VARIABLE, raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert stamped.index_folder() == tmp_path / "sysid-testbed" / "index"
    monkeypatch.setenv("XDG_CACHE_HOME", "relative")  # invalid (XDG): not under the working folder
    assert stamped.index_folder() is None
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setattr(os.path, "expanduser", lambda p: p)  # no home found: "~" stays "~"
    assert stamped.index_folder() is None
    monkeypatch.setenv(stamped.INDEX_VARIABLE, "")
    assert stamped.index_folder() is None


def test_a_file_replaced_by_one_of_the_same_size_and_time_is_computed_again(index, tmp_path):
    # `cp -p`, `rsync -t`, `touch -r`: same size and modification time, another content; the
    # status-change time (which no user sets) tells
    data = _setup(tmp_path)
    build, calls = _counting(data)
    stamped.stamped_value("t", build)
    st = os.stat(data / "a.txt")
    deadline = time.monotonic() + 5.0  # the file system's time resolution: up to 2 s (FAT)
    while os.stat(data / "a.txt").st_ctime_ns == st.st_ctime_ns and time.monotonic() < deadline:
        time.sleep(0.02)
        (data / "a.txt").write_text("omega")  # as long as "alpha"
        os.utime(data / "a.txt", ns=(st.st_atime_ns, st.st_mtime_ns))
    os.utime(data, ns=(os.stat(data).st_atime_ns, os.stat(data).st_mtime_ns))
    assert stamped.stamped_value("t", build) == {"a.txt": "omega"}
    assert len(calls) == 2


def test_a_kept_value_the_caller_refuses_is_computed_again(index, tmp_path):
    # an index of the right format whose value has another shape (edited by hand) was the
    # caller's TypeError on every `testbed list` until a stamp changed (review, 2026-11-27)
    data = _setup(tmp_path)
    build, calls = _counting(data)
    valid = lambda v: isinstance(v, dict) and all(isinstance(x, str) for x in v.values())  # noqa: E731
    stamped.stamped_value("t", build, valid)
    (kept,) = index.iterdir()
    doc = __import__("json").loads(kept.read_text())
    doc["value"] = {"a.txt": 5}
    kept.write_text(__import__("json").dumps(doc))
    assert stamped.stamped_value("t", build, valid) == {"a.txt": "alpha"}
    doc["value"], doc["files"] = {"a.txt": "forged"}, []  # no stamps: never current
    kept.write_text(__import__("json").dumps(doc))
    assert stamped.stamped_value("t", build, valid) == {"a.txt": "alpha"}
    assert len(calls) == 3


def test_the_working_folder_keys_the_index(index, tmp_path, monkeypatch):
    # a relative TESTBED_SCENARIOS names another folder in another working folder: under the
    # console script no sys.path entry stands for it, and folder B printed folder A's scenarios
    data = _setup(tmp_path)
    build, calls = _counting(data)
    monkeypatch.chdir(tmp_path)
    stamped.stamped_value("t", build)
    stamped.stamped_value("t", build)
    other = tmp_path / "other"
    other.mkdir()
    monkeypatch.chdir(other)
    stamped.stamped_value("t", build)
    assert len(calls) == 2 and len(list(index.iterdir())) == 2


def test_a_folder_on_the_path_holds_while_its_distributions_do(index, tmp_path, monkeypatch):
    # the project's own folder is on sys.path: a file a run writes there (out/, a log) made
    # every listing afresh; a distribution or path file added or removed must not be missed
    data = _setup(tmp_path)
    site = tmp_path / "site"
    site.mkdir()
    monkeypatch.setattr(stamped, "_implicit", lambda: ({str(data / "a.txt")}, {str(site)}))
    build, calls = _counting(data)
    stamped.stamped_value("t", build)
    (site / "MUJOCO_LOG.TXT").write_text("")
    (site / "out").mkdir()
    stamped.stamped_value("t", build)
    assert len(calls) == 1
    (site / "extra.pth").write_text(str(tmp_path))
    stamped.stamped_value("t", build)
    assert len(calls) == 2
    (site / "pkg-1.0.dist-info").mkdir()
    stamped.stamped_value("t", build)
    assert len(calls) == 3
