"""testbed.cli's output files (``-o``, ``--results``): review 23a of round 22's fixes.

A link given as ``-o`` is written through only where it is the user's or its folder
owner's; the folder checked is the one written; a name ending in ``.`` or ``..`` is a folder.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import pytest

from testbed import cli
from testbed.core.errors import InputError
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.scenario import load_scenario
from tests.testbed._saved_record import saved_record

#: Another user's id (``nobody`` on Linux), for the tests root alone can run.
OTHER = 65534

as_root = pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() != 0,
                             reason="only root can make a link or folder of another user")


def _one_error_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert "Traceback" not in err and len(lines) == 1 and lines[0].startswith("error: "), err
    return lines[0]


def _victim(folder: Path) -> Path:
    """A private file (0600) that no command here may write."""
    folder.mkdir(exist_ok=True)
    victim = folder / "victim.conf"
    victim.write_text("keep")
    victim.chmod(0o600)
    return victim


# ------------------------------------------------------------------ links of other users

def test_generate_replaces_a_link_planted_in_its_cache_not_the_file_it_names(
        cli_in_process, tmp_path):
    """The reviewer's reproducer: a link named like a cache entry in a shared (1777) cache
    folder, to a root-only file; `generate --cache shared -o gen.h5` overwrote that file."""
    victim = _victim(tmp_path / "rootonly")
    shared = tmp_path / "shared"
    shared.mkdir()
    shared.chmod(0o1777)
    entry = DatasetCache(shared).path(load_scenario("michaelis_menten"))
    entry.symlink_to(victim)
    if getattr(os, "geteuid", lambda: -1)() == 0:
        os.lchown(entry, OTHER, OTHER)  # planted by another user
    p = cli_in_process("generate", "michaelis_menten", "--cache", str(shared), "-o",
                       str(tmp_path / "gen.h5"), cwd=tmp_path)
    assert p.returncode == 0, p.stderr
    assert victim.read_text() == "keep"
    assert entry.is_file() and not entry.is_symlink() and (tmp_path / "gen.h5").is_file()


@as_root
@pytest.mark.parametrize("mode", [0o1777, 0o755])
def test_an_output_link_of_another_user_in_a_folder_not_theirs_is_refused(
        cli_in_process, tmp_path, mode):
    """As root, ``-o`` a link another user planted wrote the root-only file it named (the
    kernel's protected-symlinks rule bypassed by resolving the link in the program)."""
    victim = _victim(tmp_path / "rootonly")
    folder = tmp_path / "shared"
    folder.mkdir()
    folder.chmod(mode)
    link = folder / "out.h5"
    link.symlink_to(victim)
    os.lchown(link, OTHER, OTHER)
    with pytest.raises(InputError, match=f"a symbolic link of user {OTHER} in a folder of user 0"):
        cli._output_file(link, "--output")
    p = cli_in_process("generate", "michaelis_menten", "--no-cache", "-o", str(link),
                       cwd=tmp_path)
    assert p.returncode == 2 and "symbolic link of user" in _one_error_line(p.stderr)
    assert victim.read_text() == "keep" and link.is_symlink()


@as_root
def test_a_link_of_the_folders_owner_is_followed(tmp_path):
    """The kernel's rule: a link owned by the owner of the folder it lies in is followed."""
    target = tmp_path / "real.json"
    target.write_text("old")
    folder = tmp_path / "theirs"
    folder.mkdir()
    os.chown(folder, OTHER, OTHER)
    link = folder / "out.json"
    link.symlink_to(target)
    os.lchown(link, OTHER, OTHER)
    assert cli._output_file(link, "--output") == target


def test_a_chain_of_own_links_is_followed_to_its_file(tmp_path):
    """A link to a link (relative targets, each from its own folder) names the last file."""
    (tmp_path / "a").mkdir()
    real = tmp_path / "a" / "real.json"
    real.write_text("old")
    (tmp_path / "a" / "first.json").symlink_to("real.json")
    link = tmp_path / "second.json"
    link.symlink_to(Path("a") / "first.json")
    assert cli._output_file(link, "--output").resolve() == real.resolve()


# ------------------------------------------------------------------ the folder written

def test_a_link_into_a_read_only_folder_is_refused(tmp_path):
    """The link's own folder was checked: a link to a file in a 0555 folder passed (as a
    user the write then failed naming its temporary file; as root it succeeded)."""
    ro = tmp_path / "ro"
    ro.mkdir()
    (ro / "f.json").write_text("old")
    link = tmp_path / "link.json"
    link.symlink_to(ro / "f.json")
    ro.chmod(0o555)
    try:
        with pytest.raises(InputError, match=rf"{ro} is read-only \(mode 0555\)"):
            cli._output_file(link, "--output")
    finally:
        ro.chmod(0o755)


def test_a_link_in_a_read_only_folder_to_a_writable_one_is_written(tmp_path):
    """The reverse was refused, though the write (in the target's folder) succeeds."""
    real = tmp_path / "real.json"
    real.write_text("old")
    ro = tmp_path / "ro"
    ro.mkdir()
    link = ro / "link.json"
    link.symlink_to(real)
    ro.chmod(0o555)
    try:
        assert cli._output_file(link, "--output") == real
    finally:
        ro.chmod(0o755)


# ------------------------------------------------------------------ names of folders

@pytest.mark.parametrize("last", [".", ".."])
def test_an_output_path_ending_in_dot_or_dot_dot_is_refused(cli_in_process, tmp_path, last):
    """``-o newdir/.`` wrote a file named ``newdir`` (``Path`` drops a trailing ``/.``)."""
    with pytest.raises(InputError, match=re.escape(f"ends in '{last}'")):
        cli._output_file(f"{tmp_path / 'x'}/{last}", "--output")
    p = cli_in_process("generate", "michaelis_menten", "--no-cache", "-o", f"newdir/{last}",
                       cwd=tmp_path)
    assert p.returncode == 2 and "which names a folder" in _one_error_line(p.stderr)
    assert sorted(q.name for q in tmp_path.iterdir()) == []


def test_identify_refuses_a_model_link_to_its_own_report(cli_in_process, tmp_path):
    """``-o m.json``, a link to ``m.md``: the report would replace the model it reports."""
    data = saved_record(tmp_path)
    (tmp_path / "m.md").write_text("old")
    (tmp_path / "m.json").symlink_to("m.md")
    p = cli_in_process("identify", str(data), "--kind", "structural", "--method", "ls_sindy",
                       "-o", "m.json", cwd=tmp_path)
    assert p.returncode == 2 and "names the file of its own report" in _one_error_line(p.stderr)
    assert (tmp_path / "m.md").read_text() == "old"
