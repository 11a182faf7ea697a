"""The ``testbed`` command: a thin face over the library (no logic of its own).

Every command maps to one library call; user errors (bad scenario or study
files, unknown names) print one clear line and exit with status 2.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from testbed.errors import TestbedError

EXIT_FAIL, EXIT_USAGE = 1, 2


def _progress():
    from testbed.progress import progress_bar

    return progress_bar


def cmd_list(args: argparse.Namespace) -> int:
    from rich.console import Console
    from rich.table import Table

    from identify import IDENTIFIERS
    from models import RIGS
    from testbed.scenario import list_scenarios

    con = Console()
    for title, registry in (("rigs", RIGS), ("identifiers", IDENTIFIERS)):
        t = Table(title=title)
        for c in ("name", "kind", "tags"):
            t.add_column(c)
        for n in registry.names():
            t.add_row(n, registry.get(n).kind, ", ".join(sorted(registry.tags(n))))
        con.print(t)
    t = Table(title="scenarios")
    for c in ("name", "rig", "identifier", "noise %", "description"):
        t.add_column(c)
    for s in list_scenarios():
        t.add_row(s.name, s.rig, (s.identify or {}).get("method", "-"), f"{s.noise['rms_percent']:g}",
                  s.description)
    con.print(t)
    return 0


def cmd_generate(args: argparse.Namespace) -> int:
    from testbed.cache import DatasetCache
    from testbed.generate import generate
    from testbed.scenario import load_scenario
    from testbed.summaries import print_truth_summary

    sc = load_scenario(args.scenario)
    if args.seed is not None:
        sc = sc.replace(seed=args.seed)
    with _progress()(f"generating {sc.name}") as bar:
        # through the run cache unless --no-cache: a later `testbed run` of it simulates nothing
        ds = generate(sc, progress=bar) if args.no_cache else DatasetCache(args.cache).get(sc, bar)
    out = Path(args.output or f"{sc.name}-seed{sc.seed}.h5")
    ds.save(out)
    print_truth_summary(ds)
    print(f"wrote {out} (content hash {ds.attrs['content_hash'][:16]})")
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    from testbed.cache import DatasetCache
    from testbed.run import run_scenario
    from testbed.runstore import run_folder, save_run
    from testbed.scenario import load_scenario
    from testbed.summaries import print_score_table

    cache = None if args.no_cache else DatasetCache(args.cache)
    ok = True
    for name in args.scenario:
        sc = load_scenario(name)
        if args.seed is not None:
            sc = sc.replace(seed=args.seed)
        run_dir = run_folder(args.out, sc.name)  # refused before the work, not after
        with _progress()(f"{sc.name}: data") as bar:
            result = run_scenario(sc, cache=cache, progress=bar)
        run_dir = save_run(result, run_dir, figures=not args.no_figures)
        print_score_table(result)
        print(f"run written to {run_dir}")
        ok &= result.passed
    return 0 if ok else EXIT_FAIL


def cmd_report(args: argparse.Namespace) -> int:
    from testbed.report import write_report

    html = write_report(Path(args.source), Path(args.output))
    print(f"report: {html.resolve()}")
    return 0


def cmd_export(args: argparse.Namespace) -> int:
    from testbed.export import export_dataset

    for p in export_dataset(Path(args.dataset), args.format, Path(args.output) if args.output else None):
        print(f"wrote {p}")
    return 0


def cmd_sweep(args: argparse.Namespace) -> int:
    from testbed.study import load_study
    from testbed.sweep import SweepStats, run_sweep

    study = load_study(args.study)
    stats = SweepStats()
    results = run_sweep(study, jobs=args.jobs, dask_address=args.dask,
                        results=Path(args.results) if args.results else None,
                        cache_dir=args.cache, retry_failed=args.retry_failed, stats=stats)
    print(f"results: {results}")
    return EXIT_FAIL if stats.failed_total else 0


def cmd_summary(args: argparse.Namespace) -> int:
    from testbed.summary import print_summary

    print_summary(Path(args.results))
    return 0


def cmd_cache(args: argparse.Namespace) -> int:
    from testbed.cache import DatasetCache

    cache = DatasetCache(args.cache)
    if args.action == "ls":
        entries = cache.entries()
        for p, size in entries:
            print(f"{size / 1e6:8.2f} MB  {p}")
        print(f"{len(entries)} dataset(s) in {cache.directory}")
    else:
        print(f"removed {cache.clear()} dataset(s) from {cache.directory}")
    return 0


def cmd_demo(args: argparse.Namespace) -> int:
    from testbed.demo import run_demo

    return run_demo(Path(args.out))


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="testbed", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)
    sub.add_parser("list", help="registered rigs, identifiers and scenarios").set_defaults(fn=cmd_list)

    g = sub.add_parser("generate", help="simulate a scenario and write its dataset (HDF5)")
    g.add_argument("scenario", help="scenario name or .toml path")
    g.add_argument("-o", "--output", help="output file (default <scenario>-seed<N>.h5)")
    g.add_argument("--seed", type=int, help="override the scenario's seed")
    g.add_argument("--cache", help="dataset cache folder it also fills (default .cache/datasets)")
    g.add_argument("--no-cache", action="store_true", help="generate afresh, fill no cache")
    g.set_defaults(fn=cmd_generate)

    r = sub.add_parser("run", help="generate or reuse data, identify, score, write figures")
    r.add_argument("scenario", nargs="+", help="scenario names or .toml paths")
    r.add_argument("-o", "--out", default="out/runs", help="folder for run results (default out/runs)")
    r.add_argument("--seed", type=int, help="override the scenario's seed")
    r.add_argument("--cache", help="dataset cache folder (default .cache/datasets or $TESTBED_CACHE)")
    r.add_argument("--no-cache", action="store_true", help="generate afresh, store nothing")
    r.add_argument("--no-figures", action="store_true", help="skip the figures")
    r.set_defaults(fn=cmd_run)

    rep = sub.add_parser("report", help="HTML + markdown report of a run folder or sweep results")
    rep.add_argument("source", help="a run folder (from `testbed run`) or a sweep results file")
    rep.add_argument("-o", "--output", required=True, help="report folder")
    rep.set_defaults(fn=cmd_report)

    e = sub.add_parser("export", help="export a dataset to UFF (58/55) or SEP-005 JSON")
    e.add_argument("dataset", help="dataset .h5 file")
    e.add_argument("--format", required=True, choices=("uff", "sep005"))
    e.add_argument("-o", "--output", help="output file (default next to the dataset)")
    e.set_defaults(fn=cmd_export)

    s = sub.add_parser("sweep", help="run a method-comparison study (scenarios x noise x seeds x methods)")
    s.add_argument("study", help="study .toml file")
    s.add_argument("--jobs", type=int, default=1, help="parallel worker processes (joblib loky)")
    s.add_argument("--dask", help="dask.distributed scheduler address (runs through joblib's dask backend)")
    s.add_argument("--results", help="results file (default out/studies/<study>.parquet)")
    s.add_argument("--cache", help="dataset cache folder")
    s.add_argument("--retry-failed", action="store_true", help="run the cells recorded as failed again")
    s.set_defaults(fn=cmd_sweep)

    sm = sub.add_parser("summary", help="median, spread and pass rate per identifier and noise level")
    sm.add_argument("results", help="results file of a sweep")
    sm.set_defaults(fn=cmd_summary)

    c = sub.add_parser("cache", help="list or clear the dataset cache")
    c.add_argument("action", choices=("ls", "clear"))
    c.add_argument("--cache", help="dataset cache folder")
    c.set_defaults(fn=cmd_cache)

    d = sub.add_parser("demo", help="the main job: scored scenario runs and their report")
    d.add_argument("--out", default="out/demo")
    d.set_defaults(fn=cmd_demo)
    return p


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.fn(args)
    except TestbedError as e:
        print(f"error: {e}", file=sys.stderr)
        return EXIT_USAGE
    except KeyError as e:  # unknown registered name
        print(f"error: {e.args[0]}", file=sys.stderr)
        return EXIT_USAGE


if __name__ == "__main__":
    sys.exit(main())
