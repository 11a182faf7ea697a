"""Round 27's findings (``benchmarks/hostile27.py``): the command line's options walked from its
own parser, each given odd values."""

from __future__ import annotations

import argparse

import pytest

from testbed import cli
from testbed.core.atomic import IDENTIFIED_MARKDOWN_FILE


def _parse(*argv: str) -> argparse.Namespace:
    return cli.build_parser().parse_args(list(argv))


def _refusal(capsys, *argv: str) -> str:
    with pytest.raises(SystemExit) as e:
        _parse(*argv)
    assert e.value.code == cli.EXIT_USAGE
    lines = [ln for ln in capsys.readouterr().err.splitlines() if ln.strip()]
    assert len(lines) == 1, lines
    return lines[0]


def test_runs_ls_takes_its_scenario_after_an_option():
    # was "unrecognized arguments: michaelis_menten": argparse took `ls` alone as the positionals
    args = _parse("runs", "ls", "-o", "out/runs", "michaelis_menten")
    assert args.scenario == "michaelis_menten" and args.out == "out/runs"
    assert _parse("runs", "ls", "michaelis_menten", "-o", "x").scenario == "michaelis_menten"
    assert _parse("runs", "ls", "-o", "x").scenario is None
    # what argparse reads as a positional where it stands first, it reads so here too (the
    # command then names it: not a scenario name)
    assert _parse("runs", "ls", "-o", "x", "-1").scenario == "-1"
    assert _parse("runs", "ls", "-o", "x", "-").scenario == "-"


def test_runs_ls_still_refuses_two_scenarios_and_a_stray_option(capsys):
    assert "unrecognized arguments: a b" in _refusal(capsys, "runs", "ls", "-o", "x", "a", "b")
    assert "unrecognized arguments: --nope" in _refusal(capsys, "runs", "ls", "-o", "x", "--nope")


@pytest.mark.parametrize("argv", [("report", "", "-o", "r"),
                                  ("report", "michaelis_menten", "--runs", "", "-o", "r")])
def test_report_refuses_an_empty_source_or_runs_folder(capsys, argv):
    # `report ""` read the current folder as the run folder ("error: .: not a run folder"), and
    # `--runs ""` looked for the scenario's runs there (a script's "$RUN" unset)
    line = _refusal(capsys, *argv)
    assert "an empty path" in line and ("source" in line or "--runs" in line)


PNG = b"\x89PNG\r\n\x1a\n" + bytes(range(64))


@pytest.mark.parametrize("kind", [cli.HDF5_FILE, cli.IDENTIFIED_JSON_FILE, cli.SEP005_FILE,
                                  cli.UFF_FILE, IDENTIFIED_MARKDOWN_FILE])
def test_an_output_of_another_kind_is_refused_and_left_as_it_is(tmp_path, kind):
    # `generate -o photo.png` replaced the picture by a dataset, status 0 (as identify / export)
    photo = tmp_path / "photo.png"
    photo.write_bytes(PNG)
    with pytest.raises(cli.InputError, match=r"--output .*photo\.png: exists and is not "):
        cli._output_file(photo, "--output", kind=kind)
    assert photo.read_bytes() == PNG


#: An earlier UFF export's first record and the head of its first UFF58 (ID line 5 the marker)
UFF_HEAD = (b"    -1\n   164\n         1  SI\n    -1\n    -1\n    58b     1     2\n"
            b"x/x\ngeneral [mM]\nscenario s seed 0\ncontent hash 00\nfs 100.0 Hz, sysid-testbed\n")


def _earlier_h5(path):
    import h5py
    with h5py.File(path, "w") as f:
        f.attrs["format"] = "sysid-testbed-dataset/2"
    return path.read_bytes()


@pytest.mark.parametrize("kind, head", [
    (cli.HDF5_FILE, _earlier_h5),
    (cli.IDENTIFIED_JSON_FILE, b'\xef\xbb\xbf \n{"source": "d.h5", "kind": "dynamical", '
                               b'"method": "m", "fs_hz": 1, "n_samples": 2, "identifier": {}}'),
    (cli.SEP005_FILE, b'[{"name": "x/x", "data": [1], "fs": 1, "content_hash": "0", "group": "measured"}]'),
    (cli.UFF_FILE, UFF_HEAD), (IDENTIFIED_MARKDOWN_FILE, b"# Identified model: m\n"),
    (cli.IDENTIFIED_JSON_FILE, b"")])
def test_an_output_of_its_own_kind_or_empty_is_replaced_as_before(tmp_path, kind, head):
    earlier = tmp_path / "earlier.out"
    if callable(head):
        head(earlier)
    else:
        earlier.write_bytes(head)
    assert cli._output_file(earlier, "--output", kind=kind) == earlier


def test_identify_refuses_a_report_path_holding_another_file(cli_in_process, tmp_path):
    from tests.testbed._saved_record import saved_record

    data = saved_record(tmp_path)
    (tmp_path / "m.md").write_bytes(PNG)
    p = cli_in_process("identify", str(data), "--kind", "structural", "--method", "ls_sindy",
                       "-o", "m.json", cwd=tmp_path)
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    assert p.returncode == 2 and len(lines) == 1 and "(its .md report) m.md" in lines[0]
    assert (tmp_path / "m.md").read_bytes() == PNG and not (tmp_path / "m.json").exists()


def test_generate_refuses_to_replace_a_file_of_another_kind(cli_in_process, tmp_path):
    (tmp_path / "photo.png").write_bytes(PNG)
    p = cli_in_process("generate", "michaelis_menten", "--no-cache", "-o", "photo.png",
                       cwd=tmp_path)
    assert p.returncode == 2 and "is not an HDF5 dataset" in p.stderr
    assert (tmp_path / "photo.png").read_bytes() == PNG


@pytest.mark.parametrize("stated, refused", [
    (b"fs ...... Hz", True), (b"fs nan    Hz", True), (b"fs -inf   Hz", True),
    (b"fs 1e999  Hz", True), (b"fs 0.0000 Hz", True), (b"fs 1e+03  Hz", False),
    (b"fs 1000.0 Hz", False)])
def test_a_uff_id_line_rate_that_is_no_positive_number_is_refused(tmp_path, stated, refused):
    # "fs ..... Hz" was float()'s ValueError (an internal error); "fs nan Hz" was read past
    from testbed.pipeline.importers import MeasuredDataError, read_measured
    from testbed.reporting.export import export_dataset
    from tests.testbed._saved_record import saved_record

    uff = tmp_path / "d.uff"
    export_dataset(saved_record(tmp_path), "uff", uff)
    data = uff.read_bytes()
    assert data.count(b"fs 1000.0 Hz") >= 1  # the export states the exact rate (1000 Hz)
    uff.write_bytes(data.replace(b"fs 1000.0 Hz", stated))
    if refused:
        with pytest.raises(MeasuredDataError, match="its ID line states the rate"):
            read_measured(uff)
    else:
        assert read_measured(uff).fs == 1000.0


def test_family_write_refuses_a_members_path_holding_the_users_file_and_writes_nothing(tmp_path):
    # `family write -o mine/` replaced the user's own mine/<member>.toml (or any file there)
    from testbed.core.errors import InputError
    from testbed.pipeline.scenario import load_scenario
    from testbed.studies.family import write_members

    a = load_scenario("michaelis_menten")
    b = a.replace(name="kinetics_b")
    (tmp_path / "kinetics_b.toml").write_text('[scenario]\nname = "kinetics_b"\n')
    with pytest.raises(InputError, match=r"kinetics_b\.toml: exists and is not a member file"):
        write_members([a, b], tmp_path)
    assert not (tmp_path / "michaelis_menten.toml").exists()  # checked before any write
    (tmp_path / "kinetics_b.toml").unlink()
    first = write_members([a, b], tmp_path)
    assert write_members([a, b], tmp_path) == first  # its own files: replaced as before


@pytest.mark.parametrize("name", ["report.html", "report.md"])
def test_report_refuses_a_folder_holding_the_users_file_of_its_name(cli_in_process, tmp_path,
                                                                    name):
    from benchmarks._hostile import results_row
    from testbed.studies.results import write_rows

    res = write_rows(tmp_path / "r.parquet", [results_row()], study="s")
    out = tmp_path / "rep"
    out.mkdir()
    (out / name).write_bytes(PNG)
    p = cli_in_process("report", str(res), "-o", str(out), cwd=tmp_path)
    assert p.returncode == 2 and f"{name}: exists and is not a" in p.stderr
    assert (out / name).read_bytes() == PNG
    (out / name).unlink()
    assert cli_in_process("report", str(res), "-o", str(out), cwd=tmp_path).returncode == 0
    # its own earlier report is replaced, as before
    assert cli_in_process("report", str(res), "-o", str(out), cwd=tmp_path).returncode == 0


def test_report_refuses_a_folder_holding_the_users_file_of_a_figures_name(cli_in_process,
                                                                          tmp_path):
    from benchmarks._hostile import results_row
    from testbed.studies.results import write_rows

    res = write_rows(tmp_path / "r.parquet", [results_row()], study="s")
    out = tmp_path / "rep"
    out.mkdir()
    (out / "fit_time.png").write_bytes(b"my notes, not a picture")
    p = cli_in_process("report", str(res), "-o", str(out), cwd=tmp_path)
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    assert p.returncode == 2 and len(lines) == 1 and "fit_time.png: exists and is not a PNG" in lines[0]
    assert (out / "fit_time.png").read_bytes() == b"my notes, not a picture"
