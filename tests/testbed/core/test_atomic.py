"""testbed.core.atomic: all or nothing, and ordinary permissions."""

import os
import stat

import pytest

from testbed.core.atomic import atomic_write, atomic_write_text
from testbed.core.dataset import Dataset
from tests.testbed._saved_record import saved_record


def _umask() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return umask


def test_writes_and_replaces(tmp_path):
    p = atomic_write_text(tmp_path / "sub" / "a.txt", "one")
    assert p.read_text() == "one"
    atomic_write_text(p, "two")
    assert p.read_text() == "two"
    assert sorted(x.name for x in p.parent.iterdir()) == ["a.txt"]
    umask = os.umask(0)
    os.umask(umask)
    assert p.stat().st_mode & 0o777 == 0o666 & ~umask


def test_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    p = atomic_write_text(tmp_path / "a.txt", "old")

    def boom(tmp):
        open(tmp, "w").write("half")
        raise RuntimeError("interrupted")

    with pytest.raises(RuntimeError):
        atomic_write(p, boom)
    assert p.read_text() == "old"
    assert [x.name for x in tmp_path.iterdir()] == ["a.txt"]


# ------------------------------------------------------------------ review 23a

def test_a_link_is_replaced_itself_and_what_it_names_kept(tmp_path):
    """Round 22 wrote through any link (``realpath``), for every caller: a link planted in a
    shared cache folder under an entry's name made root overwrite the file it named."""
    victim = tmp_path / "victim.conf"
    victim.write_text("keep")
    victim.chmod(0o600)
    link = tmp_path / "entry.h5"
    link.symlink_to(victim)
    assert atomic_write_text(link, "new") == link
    assert not link.is_symlink() and link.read_text() == "new"
    assert victim.read_text() == "keep"
    # the new file's mode is the default, not the named file's
    assert stat.S_IMODE(link.stat().st_mode) == 0o666 & ~_umask()
    dangling = tmp_path / "dangling.h5"
    dangling.symlink_to(tmp_path / "gone" / "x.h5")
    atomic_write_text(dangling, "new")
    assert dangling.read_text() == "new" and not (tmp_path / "gone").exists()


def test_a_planted_cache_entry_link_is_replaced_not_followed(tmp_path):
    """The reviewer's path: `Dataset.save` of a cache entry whose name is a link (to a
    root-only file): the entry is written, the file it named kept."""
    victim = tmp_path / "rootonly.conf"
    victim.write_text("keep")
    entry = tmp_path / "cache" / "michaelis_menten-0.h5"
    entry.parent.mkdir()
    entry.symlink_to(victim)
    ds = Dataset.load(saved_record(tmp_path))
    ds.save(entry)
    assert victim.read_text() == "keep" and not entry.is_symlink()
    assert Dataset.load(entry).content_hash() == ds.content_hash()


def test_a_replaced_file_loses_setuid_setgid_and_sticky(tmp_path):
    """Its permission bits were copied whole (``S_IMODE``): a setuid file kept its bit while
    the new content got the writer as owner."""
    p = tmp_path / "tool"
    p.write_text("old")
    p.chmod(0o6755 | stat.S_ISVTX)
    if not stat.S_IMODE(p.stat().st_mode) & stat.S_ISUID:
        pytest.skip("this file system keeps no setuid bit")
    atomic_write_text(p, "new")
    assert stat.S_IMODE(p.stat().st_mode) == 0o755 and p.read_text() == "new"


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0,
                    reason="only root can give a file to another user")
def test_a_replaced_file_keeps_its_owner_and_group(tmp_path):
    """As root, a user's file came back root's (its bits kept: a 0600 file of theirs was
    then unreadable to them)."""
    p = tmp_path / "theirs.json"
    p.write_text("old")
    p.chmod(0o600)
    os.chown(p, 65534, 65534)
    atomic_write_text(p, "new")
    st = p.stat()
    assert (st.st_uid, st.st_gid, stat.S_IMODE(st.st_mode)) == (65534, 65534, 0o600)


def test_a_fifo_at_an_output_path_is_refused_at_once_not_read(tmp_path):
    """Review 27e: foreign_head opened a FIFO nobody writes to and hung for good (``report -o``,
    ``family write``); it is now no regular file, left to not_regular to name in one line."""
    from testbed.core.atomic import REPORT_MARKDOWN_FILE, foreign_head, not_regular
    from testbed.core.errors import InputError

    fifo = tmp_path / "report.md"
    os.mkfifo(fifo)
    assert foreign_head(fifo, REPORT_MARKDOWN_FILE) is None  # returns at once (O_NONBLOCK)
    with pytest.raises(InputError, match="not a regular file"):
        not_regular(fifo)
    (tmp_path / "mine.md").write_bytes(b"\x89PNG\r\n\x1a\n")
    assert foreign_head(tmp_path / "mine.md", REPORT_MARKDOWN_FILE) == b"\x89PNG\r\n\x1a\n"


def test_a_users_own_page_or_notes_of_the_same_format_are_foreign(tmp_path):
    """Review 27e: any ``<`` / ``#`` file passed as ours, so ``report -o`` replaced the user's own
    ``report.html`` and ``identify -o notes.json`` their ``notes.md``; the testbed's own files
    begin with a fixed prefix (the HTML report's doctype line, the identified model's title)."""
    from testbed.core.atomic import HTML_FILE, HTML_REPORT_HEAD, IDENTIFIED_MARKDOWN_FILE, foreign_head

    page, notes = tmp_path / "report.html", tmp_path / "notes.md"
    page.write_text("<p>my page</p>\n")
    notes.write_text("# My lab notes\n")
    assert foreign_head(page, HTML_FILE) and foreign_head(notes, IDENTIFIED_MARKDOWN_FILE)
    page.write_text('<!DOCTYPE html>\n<html lang="en"><head>')  # any HTML5 page's first line:
    assert foreign_head(page, HTML_FILE)  # not enough (hostile round 28)
    page.write_text(HTML_REPORT_HEAD + "<title>Run x</title>")
    notes.write_text("# Identified model: ls_sindy\n")
    assert foreign_head(page, HTML_FILE) is None
    assert foreign_head(notes, IDENTIFIED_MARKDOWN_FILE) is None


@pytest.mark.parametrize("kind", ["IDENTIFIED_JSON_FILE", "SEP005_FILE"])
def test_a_deeply_nested_json_at_an_output_path_is_foreign_not_an_internal_error(tmp_path, kind):
    # review 29a M2: json's RecursionError escaped _json_document ("internal error")
    from testbed.core import atomic
    from testbed.core.errors import InputError

    p = tmp_path / "out.json"
    nested = "[" * 100000 + "]" * 100000  # a table's head for a model summary, a list's else
    p.write_text('{"a": ' + nested + "}" if kind == "IDENTIFIED_JSON_FILE" else nested)
    with pytest.raises(InputError, match=r"out\.json"):
        atomic.refuse_foreign(p, getattr(atomic, kind))


#: A UFF58 record's head as reporting.export writes it (ID line 5 the testbed's marker)
_UFF58 = (b"    -1\n    58b     1     2\nx/x\ngeneral [mM]\nscenario s seed 0\ncontent hash 00\n"
          b"fs 100.0 Hz, sysid-testbed\n")


@pytest.mark.parametrize("geometry_bytes", [0, 3 << 20, (1 << 20) - 7])
def test_our_uff_export_of_many_nodes_is_ours(tmp_path, geometry_bytes):
    # review 29a L5: the marker was looked for in the first MiB only, so an export of more than
    # ~6,500 nodes (geometry first, ~160 bytes a node) was refused as foreign by its own writer
    from testbed.core.atomic import UFF_FILE, foreign_head

    node = b"         1         0         0        11\n   0.0000000000000e+00   0.0e+00   0.0e+00\n"
    head = b"    -1\n   164\n         1  SI\n    -1\n    -1\n  2411\n"
    geometry = (node * (geometry_bytes // len(node) + 1))[:geometry_bytes]
    p = tmp_path / "out.uff"
    p.write_bytes(head + geometry + b"\n    -1\n" + _UFF58)
    assert foreign_head(p, UFF_FILE) is None
    p.write_bytes(head + geometry + b"\n    -1\n" + _UFF58.replace(b"sysid-testbed", b"my-logger"))
    assert foreign_head(p, UFF_FILE)  # a UFF whose first 58 record is someone else's
