"""Round 27's findings (``benchmarks/hostile27.py``): the command line's options walked from its
own parser, each given odd values."""

from __future__ import annotations

import argparse

import pytest

from testbed import cli


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
