"""Twenty-second malformed-input round: the findings of ``benchmarks/hostile22.py``
(docs/known-gaps.md, "Malformed-input round 22"), each fixed in the layer that owns it.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

import h5py
import pytest

from testbed import cli
from testbed.core.atomic import atomic_write_text
from testbed.core.dataset import Dataset
from testbed.core.errors import InputError
from testbed.pipeline.importers import MeasuredDataError, load_dataset
from testbed.reporting.export import export_dataset
from tests.testbed._saved_record import saved_record


def _one_error_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert "Traceback" not in err and len(lines) == 1 and lines[0].startswith("error: "), err
    return lines[0]


# ------------------------------------------------------------------ --cache with --no-cache

@pytest.mark.parametrize("argv", [
    ["generate", "michaelis_menten", "--cache", "c", "--no-cache"],
    ["generate", "michaelis_menten", "--no-cache", "--cache", "c"],
    ["run", "michaelis_menten", "--cache", "c", "--no-cache"],
])
def test_cache_and_no_cache_together_are_refused(cli_in_process, tmp_path, argv):
    """Both given: --no-cache won in silence (the cache named was neither read nor filled)."""
    p = cli_in_process(*argv, "-o", str(tmp_path / "o"), cwd=tmp_path)
    assert p.returncode == 2
    assert "not allowed with argument" in _one_error_line(p.stderr)
    assert not (tmp_path / "c").exists() and not (tmp_path / "o").exists()


# ------------------------------------------------------------------ output targets

def test_a_read_only_output_file_is_refused_and_kept(tmp_path):
    """As root, ``chmod a-w`` was no guard: the file was replaced, mode and all."""
    ro = tmp_path / "keep.json"
    ro.write_text("keep")
    ro.chmod(0o444)
    for target in (ro, tmp_path / "link.json"):
        if target != ro:
            target.symlink_to(ro)
        with pytest.raises(InputError, match="read-only"):
            cli._output_file(target, "--output")
    assert ro.read_text() == "keep"


def test_an_output_path_ending_in_a_separator_is_refused(cli_in_process, tmp_path):
    """``-o out/`` wrote a file named ``out``."""
    p = cli_in_process("generate", "michaelis_menten", "-o", f"{tmp_path / 'newdir'}/",
                       "--no-cache", cwd=tmp_path)
    assert p.returncode == 2 and "path separator" in _one_error_line(p.stderr)
    assert not (tmp_path / "newdir").exists()


def test_a_dangling_output_link_is_refused(tmp_path):
    """The link was replaced by the written file (its target never written)."""
    link = tmp_path / "dangle.h5"
    link.symlink_to(tmp_path / "nowhere" / "x.h5")
    with pytest.raises(InputError, match=r"symbolic link to .*does not exist"):
        cli._output_file(link, "--output")


def test_a_read_only_output_folder_is_refused(tmp_path):
    """Root's probe (a temporary file created) passes in a folder without write bits."""
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(0o555)
    try:
        with pytest.raises(InputError, match="read-only"):
            cli._output_file(folder / "x.h5", "--output")
    finally:
        folder.chmod(0o755)


def test_identify_refuses_a_read_only_model_file(cli_in_process, tmp_path):
    data = saved_record(tmp_path)
    ro = tmp_path / "model.json"
    ro.write_text("keep")
    ro.chmod(0o444)
    p = cli_in_process("identify", str(data), "--kind", "structural", "--method", "ls_sindy",
                       "-o", str(ro), cwd=tmp_path)
    assert p.returncode == 2 and "read-only" in _one_error_line(p.stderr)
    assert ro.read_text() == "keep"


# ------------------------------------------------------------------ atomic writes

def test_an_output_link_is_written_through_and_kept(tmp_path):
    """``-o`` a link to a file: the rename had replaced the link, its file left unwritten.
    The CLI resolves the link (review 23a: :func:`atomic_write` replaces a link itself)."""
    real = tmp_path / "real.txt"
    real.write_text("old")
    link = tmp_path / "link.txt"
    link.symlink_to(real)
    out = cli._output_file(link, "--output")
    assert out == real
    atomic_write_text(out, "new")
    assert link.is_symlink() and real.read_text() == "new"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.txt", "real.txt"]


def test_atomic_write_keeps_the_replaced_files_mode(tmp_path):
    """A private file (0600) came back world-readable (0666 less the umask)."""
    p = tmp_path / "private.txt"
    p.write_text("old")
    p.chmod(0o600)
    atomic_write_text(p, "new")
    assert stat.S_IMODE(os.stat(p).st_mode) == 0o600 and p.read_text() == "new"


# ------------------------------------------------------------------ a damaged chunk named

def _damaged(tmp_path: Path, how: dict) -> Path:
    """The saved record with ``measured/acceleration`` rewritten in chunks (``how``), its
    content hash made anew, then a byte in the middle of its first chunk flipped."""
    path = saved_record(tmp_path)
    name = "measured/acceleration"
    with h5py.File(path, "r+") as f:
        attrs, data = dict(f[name].attrs), f[name][()]
        del f[name]
        d = f.create_dataset(name, data=data, chunks=(1, 100), **how)
        for k, v in attrs.items():
            d.attrs[k] = v
    ds = Dataset.load(path, verify=False)
    with h5py.File(path, "r+") as f:
        f.attrs["content_hash"] = ds.content_hash()
        info = f[name].id.get_chunk_info(0)
    with open(path, "r+b") as fh:
        fh.seek(info.byte_offset + info.size // 2)
        b = fh.read(1)
        fh.seek(info.byte_offset + info.size // 2)
        fh.write(bytes([b[0] ^ 0xFF]))
    return path


@pytest.mark.parametrize("how", [{"fletcher32": True}, {"compression": "gzip"}],
                         ids=["fletcher32", "gzip"])
def test_a_damaged_chunk_is_refused_naming_its_array(tmp_path, how):
    """Round 21's open item (a): refused naming the file but not the array."""
    path = _damaged(tmp_path, how)
    with pytest.raises(MeasuredDataError, match="/measured/acceleration: its stored values "
                                                "cannot be read"):
        load_dataset(path)
    with pytest.raises(MeasuredDataError, match="/measured/acceleration"):
        export_dataset(path, "sep005", tmp_path / "e.json")


# ------------------------------------------------------------------ options between names

def test_run_takes_scenario_names_on_both_sides_of_an_option():
    """``run A --no-figures B`` was refused as "unrecognized arguments: B"."""
    args = cli.build_parser().parse_args(["run", "a", "--no-figures", "b", "--seed", "1", "c"])
    assert args.scenario == ["a", "b", "c"] and args.no_figures and args.seed == 1


def test_an_unknown_option_between_names_is_still_refused(capsys):
    with pytest.raises(SystemExit) as e:
        cli.build_parser().parse_args(["run", "a", "--bogus", "b"])
    assert e.value.code == 2
    assert "unrecognized arguments: --bogus b" in _one_error_line(capsys.readouterr().err)


def test_an_unknown_suffix_names_the_command_lines_option(cli_in_process, tmp_path):
    """``export --format sep005 -o d.sep005`` then ``identify d.sep005`` was told "pass
    format=", the Python API's word, not the option to give."""
    data = saved_record(tmp_path)
    out = tmp_path / "d.sep005"
    assert cli_in_process("export", str(data), "--format", "sep005", "-o", str(out),
                          cwd=tmp_path).returncode == 0
    p = cli_in_process("identify", str(out), "--kind", "structural", "--method", "ls_sindy",
                       "-o", str(tmp_path / "m.json"), cwd=tmp_path)
    assert p.returncode == 2
    line = _one_error_line(p.stderr)
    assert "--format on the command line" in line and ".json" in line
