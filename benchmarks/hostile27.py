"""Twenty-seventh malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile27 [family ...]      # all families when none is named

Families (what rounds 1-26 did not try; their families are listed in ``hostile21.py`` to
``hostile26.py``):

``flags``
    Every subcommand x every option and positional of the command line, *generated from the
    argparse parser itself* (:func:`testbed.cli.build_parser` walked, so an option added later
    is tried without an edit here), each given the odd values of :data:`ODD`: empty, ``-``,
    NaN, inf, -1, 0, 1e400, a folder, a missing file, a file of the wrong kind (a PNG), Unicode
    and a word of 5,000 characters; a flag that takes no value is given ``--flag=x``.  Each
    case is a cheap valid command of that subcommand (a Michaelis-Menten record, a one-cell
    study) with that one value changed, run in-process through ``testbed.cli.main(argv)`` in a
    scratch folder (``demo`` and ``serve`` with their long job, :func:`run_demo` and
    :func:`serve`, replaced by a stub: their options and checks are the subject, not a demo
    run or a resident server); the values ``""`` and the long word as processes too.  A
    traceback, an internal error, a refusal in more than one line, a refusal that names neither
    the option nor its value, a declared argument refused as "unrecognized", the PNG replaced
    by a command's output (nothing is lost), or a number option (``--seed``, ``--fs``, ``--jobs``,
    ``--idle``) accepting NaN / inf / 1e400 / "", is a finding.
``stores``
    A sweep's results file (Parquet) and a run folder corrupted in each way: cut short, zero
    bytes, another format (a CSV / JSON under the Parquet name), a row with NaN where a
    number is checked, a column of the wrong type, a missing column, a foreign format version
    in the schema metadata, a cell twice; then ``sweep`` resumed on it, ``report`` and
    ``summary``; a run folder's ``run.json`` cut short, emptied, edited, its arrays file
    removed, then ``report`` and ``runs ls``.  A traceback, a refusal in more than one line, or
    a report / summary / sweep that goes on over a file it could not verify (status 0 with the
    damaged row counted), is a finding.
``cache``
    The Michaelis-Menten clean cache entry (a private copy of the cache) cut in half, emptied,
    its stored content hash edited, a sample edited, ``fs`` edited, the entry or its folder
    read-only, the entry a folder, a dangling link or a JSON file; then ``generate`` and
    ``run``.  A traceback, a dataset written whose content hash differs from a fresh
    ``--no-cache`` one, or a refusal where the entry could be simulated again (not a folder
    that is the user's), is a finding.
``kill``
    ``generate`` and a 4-cell ``sweep`` in their own session sent SIGKILL, SIGINT or SIGTERM
    after 0.3-7 s, then rerun.  A process of the session left (/proc), an output that does
    not load whole, a temporary file after SIGINT / SIGTERM, a traceback, or a rerun that does
    not report exactly the rows on disk as "already done" or ends with other than 4 cells once
    each, is a finding.
``served``
    A ``testbed serve`` on a private socket sent damaged requests (a header only, half a
    request, a length of 2**32 - 1, not JSON, JSON nested 100,000 deep, no or two descriptors,
    fields of the wrong type, 100,000 arguments), two clients at once, a client killed
    mid-command.  A real command not served in 5 s after each, two outputs that differ, or
    the server's command children left after their client died, is a finding.
``roundtrip``
    The kinetics record exported as SEP-005 and UFF and identified back: another model than the
    dataset's own is a finding; the SEP-005 export with its metadata edited (``fs`` 0 / -100 /
    a text / null, one channel's ``fs`` or length changed, a null sample, a name twice, an
    unknown unit): anything but a one-line refusal is a finding (an unknown key, the
    ``content_hash`` or ``group`` edited: the same model); the UFF export's ID line 5 rate
    (``fs 100.0 Hz``) replaced by no number, NaN, -inf, 1e999, 0, another rate (refused) or
    1e+02 / free text (the same model).

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import shutil
import sys
from pathlib import Path

try:
    from benchmarks import _hostile, hostile19
except ImportError:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks import _hostile, hostile19

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 240
MM = hostile19.MM
CACHE = hostile19.CACHE
cli_inprocess = _hostile.cli_inprocess
judged = _hostile.judged

#: The odd values every option and positional is given (label -> value; ``{w}`` the scratch
#: folder).
ODD = {
    "empty": "",
    "dash": "-",
    "NaN": "NaN",
    "inf": "inf",
    "-1": "-1",
    "0": "0",
    "1e400": "1e400",
    "a folder": "{w}/adir",
    "a missing file": "{w}/missing/none.h5",
    "a file of the wrong kind": "{w}/picture.png",
    "unicode": "\u03a9\u2713\U0001d11e",
    "a long word": "x" * 5000,
}
#: The values a number option must refuse (each is no number of its range).
NOT_A_NUMBER = {"empty", "NaN", "inf", "1e400"}
#: Options whose value is a number (their type's function names).
NUMBER_TYPES = {"_float", "_seed", "_jobs", "_int_at_least"}

#: The file of the wrong kind: a PNG's signature and bytes.
PICTURE = b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 4

STUDY = f"""[study]
name = "h27"
scenarios = ["{MM}"]
noise = [0.0]
seeds = [0]
identifiers = ["sindy_pi_dynamical"]
"""


def _fixtures(w: Path) -> dict[str, Path]:
    """The scratch folder's inputs: a record, a one-cell study and its results, a run."""
    (w / "adir").mkdir(exist_ok=True)
    (w / "picture.png").write_bytes(PICTURE)
    study = w / "h27.toml"
    study.write_text(STUDY)
    h5 = hostile19._generated(w, MM)
    results = w / "results.parquet"
    if not results.exists():
        status, _, err = cli_inprocess(["sweep", str(study), "--results", str(results),
                                        "--cache", str(CACHE)])
        if status not in (0, 1):
            raise RuntimeError(f"sweep: {err[-300:]}")
    runs = w / "runs"
    if not runs.exists():
        status, _, err = cli_inprocess(["run", MM, "-o", str(runs), "--cache", str(CACHE),
                                        "--no-figures"])
        if status not in (0, 1):
            raise RuntimeError(f"run: {err[-300:]}")
    return {"h5": h5, "study": study, "results": results, "runs": runs}


def _bases(w: Path, f: dict[str, Path]) -> dict[str, list[str]]:
    """A cheap valid command of each subcommand (its argv after the subcommand's name)."""
    return {
        "list": ["--plain"],
        "generate": [MM, "-o", str(w / "g.h5"), "--cache", str(CACHE)],
        "run": [MM, "-o", str(w / "runs2"), "--cache", str(CACHE), "--no-figures"],
        "identify": [str(f["h5"]), "--scenario", MM, "-o", str(w / "m.json")],
        "report": [str(f["results"]), "-o", str(w / "rep")],
        "export": [str(f["h5"]), "--format", "sep005", "-o", str(w / "x.json")],
        "sweep": [str(f["study"]), "--results", str(f["results"]), "--cache", str(CACHE)],
        "summary": [str(f["results"])],
        "family": ["write", "paper_000_contrast_family", "-o", str(w / "fam")],
        "cache": ["ls", "--cache", str(CACHE)],
        "runs": ["ls", "-o", str(f["runs"])],
        "demo": ["--out", str(w / "demo")],
        "serve": ["--idle", "5", "--warm-up", "none"],
    }


def _subparsers(p: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    for a in p._actions:
        if isinstance(a, argparse._SubParsersAction):
            return dict(a.choices)
    return {}


def _with_value(base: list[str], action: argparse.Action, positional_index: int,
                value: str) -> list[str]:
    """``base`` with ``action`` given ``value`` (a positional replaced in place, an option's
    value replaced or the option appended; a flag as ``--flag=value``)."""
    argv = list(base)
    if not action.option_strings:
        pos = [i for i, a in enumerate(argv) if not a.startswith("-") and
               (i == 0 or not argv[i - 1].startswith("-"))]
        if positional_index < len(pos):
            argv[pos[positional_index]] = value
        else:
            argv.append(value)
        return argv
    long = max(action.option_strings, key=len)
    if action.nargs == 0:
        return [*argv, f"{long}={value}"]
    for i, a in enumerate(argv):
        if a in action.option_strings and i + 1 < len(argv):
            argv[i + 1] = value
            return argv
    # a value starting with '-' is read as an option when separate: give it as --opt=value
    return [*argv, f"{long}={value}"]


def _names(action: argparse.Action) -> list[str]:
    return [*action.option_strings, action.dest, str(action.metavar or "")]


def _flag_finding(status: int, out: str, err: str, action: argparse.Action, label: str,
                  value: str) -> str | None:
    finding = judged(status, out, err)
    if finding:
        return finding
    kind = getattr(action.type, "__name__", "") or getattr(action.type, "__qualname__", "")
    number = any(kind.startswith(t) for t in NUMBER_TYPES) or "_int_at_least" in repr(action.type)
    if number and label in NOT_A_NUMBER and status != 2:
        return f"number option accepted {value!r} with status {status}"
    if status == 2 and "unrecognized arguments" in err:
        # the value went to the option or positional it was given for: argparse's own
        # ordering rule refused a command a user may write (`runs ls -o DIR NAME`)
        return f"a declared argument refused as unrecognized: {err.strip()[:160]!r}"
    if status == 2:
        line = err.strip()
        shown = value[:40] or "''"
        if not any(n and n in line for n in _names(action)) and shown not in line:
            return f"refusal names neither option nor value: {line[:200]!r}"
    return None


@contextlib.contextmanager
def _stubbed_long_jobs():
    """``run_demo`` and ``serve`` replaced by stubs returning 0 (their options are the subject)."""
    from testbed import server
    from testbed.reporting import demo

    saved = demo.run_demo, server.serve
    demo.run_demo = lambda out, *a, **k: 0
    server.serve = lambda *a, **k: 0
    try:
        yield
    finally:
        demo.run_demo, server.serve = saved


def flags_cases(work: Path) -> list[tuple[str, object]]:
    from testbed import cli

    cases = []
    state: dict = {}
    parsers = _subparsers(cli.build_parser())

    def setup():
        if "f" not in state:
            state["f"] = _fixtures(work)
            state["bases"] = _bases(work, state["f"])
        return state["bases"]

    def case(cmd, action, index, label, raw):
        def run():
            bases = setup()
            value = raw.replace("{w}", str(work))
            argv = [cmd, *_with_value(bases[cmd], action, index, value)]
            here = os.getcwd()
            os.chdir(work)
            try:
                with _stubbed_long_jobs():
                    status, out, err = cli_inprocess(argv)
            finally:
                os.chdir(here)
                if label == "a folder":  # a command may have written into it
                    shutil.rmtree(work / "adir", ignore_errors=True)
                    (work / "adir").mkdir()
            picture = work / "picture.png"
            if picture.read_bytes() != PICTURE:  # the user's file replaced (nothing is lost)
                picture.write_bytes(PICTURE)
                return f"status {status}: a file of another kind (a PNG) replaced"
            if os.environ.get("HOSTILE27_TRACE"):
                print(f"  {cmd} {action.dest} {label}: {status} "
                      f"{(err.strip().splitlines() or [''])[-1][:150]!r}", flush=True)
            return _flag_finding(status, out, err, action, label, value)
        return run

    def proc_case(cmd, action, index, label, raw):
        def run():
            bases = setup()
            value = raw.replace("{w}", str(work))
            argv = [cmd, *_with_value(bases[cmd], action, index, value)]
            if cmd in ("demo", "serve"):
                return None  # their long jobs are stubbed in-process only
            p = _hostile.testbed_cli(argv, work, TIMEOUT_S)
            return _hostile.cli_finding(p) or _flag_finding(p.returncode, p.stdout, p.stderr,
                                                            action, label, value)
        return run

    for cmd, sp in parsers.items():
        index = 0
        for action in sp._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            pos_index = index if not action.option_strings else 0
            if not action.option_strings:
                index += 1
            name = (action.option_strings or [action.dest])[-1]
            for label, raw in ODD.items():
                cases.append((f"{cmd} {name} {label}", case(cmd, action, pos_index, label, raw)))
            for label in ("empty", "a long word"):
                cases.append((f"{cmd} {name} {label} (process)",
                              proc_case(cmd, action, pos_index, label, ODD[label])))
    return cases


# ------------------------------------------------------------------ stores

def _results_variants(pa, pq, src: Path) -> dict[str, object]:
    """label -> writer(path) of a damaged copy of the results file ``src``."""
    import pyarrow.csv as pacsv

    table = pq.read_table(src)
    data = src.read_bytes()

    def with_table(t):
        return lambda p: pq.write_table(t, p)

    def column(name, values, typ=None):
        i = table.schema.get_field_index(name)
        arr = pa.array(values, type=typ) if typ else pa.array(values)
        return with_table(table.set_column(i, pa.field(name, arr.type), arr))

    n = table.num_rows
    meta = dict(table.schema.metadata or {})
    foreign = {**meta, b"format": b"sysid-testbed-results/99"}
    return {
        "cut in half": lambda p: p.write_bytes(data[: len(data) // 2]),
        "zero bytes": lambda p: p.write_bytes(b""),
        "a CSV under the name": lambda p: pacsv.write_csv(table, str(p)),
        "JSON under the name": lambda p: p.write_text(json.dumps({"rows": []})),
        "noise NaN": column("noise", [float("nan")] * n),
        "noise a text": column("noise", ["0.0"] * n),
        "passed a text": column("passed", ["yes"] * n),
        "seed a float": column("seed", [0.5] * n),
        "coef_error NaN": column("coef_error", [float("nan")] * n) if "coef_error" in
        table.column_names else with_table(table),
        "no status column": with_table(table.drop(["status"])),
        "no row_sha256 column": with_table(table.drop(["row_sha256"])),
        "foreign format version": with_table(table.replace_schema_metadata(foreign)),
        "no metadata": with_table(table.replace_schema_metadata(None)),
        "a cell twice": with_table(pa.concat_tables([table, table])),
        "no rows": with_table(table.slice(0, 0)),
    }


def stores_cases(work: Path) -> list[tuple[str, object]]:
    import pyarrow as pa
    import pyarrow.parquet as pq

    cases = []
    state: dict = {}

    def setup():
        if "f" not in state:
            state["f"] = _fixtures(work)
        return state["f"]

    labels = ["cut in half", "zero bytes", "a CSV under the name", "JSON under the name",
              "noise NaN", "noise a text", "passed a text", "seed a float", "coef_error NaN",
              "no status column", "no row_sha256 column", "foreign format version",
              "no metadata", "a cell twice", "no rows"]

    def results_case(label, cmd):
        def run():
            f = setup()
            d = work / f"r_{hostile19._safe(label)}_{cmd}"
            shutil.rmtree(d, ignore_errors=True)
            d.mkdir()
            path = d / "results.parquet"
            _results_variants(pa, pq, f["results"])[label](path)
            before = path.read_bytes()
            if cmd == "sweep":
                argv = ["sweep", str(f["study"]), "--results", str(path), "--cache", str(CACHE)]
            elif cmd == "report":
                argv = ["report", str(path), "-o", str(d / "rep")]
            else:
                argv = ["summary", str(path)]
            status, out, err = cli_inprocess(argv)
            finding = judged(status, out, err)
            if finding:
                return finding
            if status != 2 and label not in ("no rows",) and cmd != "sweep":
                return f"{cmd} accepted with status {status}: {(out.strip() or err.strip())[:160]!r}"
            if cmd == "sweep" and status != 2 and path.read_bytes() == before and \
                    label not in ("no rows",):
                return f"sweep status {status} and the damaged file left as it was"
            return None
        return run

    for label in labels:
        for cmd in ("sweep", "report", "summary"):
            cases.append((f"results {label} / {cmd}", results_case(label, cmd)))

    def run_dir():
        f = setup()
        found = sorted(p.parent for p in f["runs"].rglob("run.json"))
        if not found:
            raise RuntimeError("no run folder")
        return found[0]

    def run_variants():
        def edit(key, value):
            def w(p):
                meta = json.loads((p / "run.json").read_text())
                meta[key] = value
                (p / "run.json").write_text(json.dumps(meta))
            return w

        def remove(pattern):
            def w(p):
                for q in p.glob(pattern):
                    q.unlink()
            return w

        return {
            "run.json cut in half": lambda p: (p / "run.json").write_bytes(
                (p / "run.json").read_bytes()[:100]),
            "run.json zero bytes": lambda p: (p / "run.json").write_bytes(b""),
            "run.json a list": lambda p: (p / "run.json").write_text("[]"),
            "run.json passed flipped": edit("passed", "maybe"),
            "run.json scenario a number": edit("scenario", 5),
            "arrays removed": remove("*.npz"),
            "run.json removed": remove("run.json"),
        }

    def run_case(label, cmd):
        def run():
            src = run_dir()
            base = work / f"runs_{hostile19._safe(label)}_{cmd}"
            shutil.rmtree(base, ignore_errors=True)
            shutil.copytree(setup()["runs"], base)
            target = base / src.relative_to(setup()["runs"])
            run_variants()[label](target)
            argv = (["report", str(target), "-o", str(work / "rep_run")] if cmd == "report"
                    else ["runs", "ls", "-o", str(base)])
            status, out, err = cli_inprocess(argv)
            finding = judged(status, out, err)
            if finding:
                return finding
            if cmd == "report" and status == 0:
                return f"report of a damaged run accepted: {out.strip()[:160]!r}"
            return None
        return run

    for label in ["run.json cut in half", "run.json zero bytes", "run.json a list",
                  "run.json passed flipped", "run.json scenario a number", "arrays removed",
                  "run.json removed"]:
        for cmd in ("report", "runs"):
            cases.append((f"run folder {label} / {cmd}", run_case(label, cmd)))
    return cases


# ------------------------------------------------------------------ cache

def _mm_entry(cache: Path) -> Path:
    """The Michaelis-Menten clean entry of the private ``cache`` folder (made once)."""
    found = sorted(cache.glob(f"{MM}-*.h5"))
    if not found:
        status, _, err = cli_inprocess(["generate", MM, "--cache", str(cache), "-o",
                                        str(cache.parent / "fill.h5")])
        if status != 0:
            raise RuntimeError(f"generate: {err[-300:]}")
        found = sorted(cache.glob(f"{MM}-*.h5"))
    return found[0]


def _content_hash(path: Path) -> str:
    from testbed.core.dataset import Dataset

    return Dataset.load(path).content_hash()


#: Cache damage a command may refuse (one line naming the entry) rather than simulate past: a
#: folder where the entry's file is (the user's, not removed), a read-only cache folder (as
#: root no guard, so simulated past here).
REFUSED_ENTRIES = {"the entry a folder", "the folder read-only"}


def cache_cases(work: Path) -> list[tuple[str, object]]:
    import h5py

    state: dict = {}
    pristine = work / "pristine"

    def setup():
        if "entry" not in state:
            pristine.mkdir(exist_ok=True)
            entry = _mm_entry(pristine)
            state["entry"] = entry
            out = work / "clean.h5"
            status, _, err = cli_inprocess(["generate", MM, "--no-cache", "-o", str(out)])
            if status != 0:
                raise RuntimeError(err[-300:])
            state["hash"] = _content_hash(out)
        return state["entry"]

    def attr(name, value):
        def w(p):
            with h5py.File(p, "r+") as f:
                f.attrs[name] = value
        return w

    def data_edit(p):
        with h5py.File(p, "r+") as f:
            def first(name, obj):
                if isinstance(obj, h5py.Dataset) and obj.dtype.kind == "f" and obj.size > 3:
                    a = obj[()]
                    a.flat[2] += 1.0
                    obj[...] = a
                    return True
                return None
            f.visititems(first)

    def hash_attr(p):
        with h5py.File(p, "r+") as f:
            key = next((k for k in f.attrs if "hash" in k), None)
            if key is None:
                raise RuntimeError(f"no hash attribute in {list(f.attrs)}")
            f.attrs[key] = "0" * 32

    def readonly_dir(p):
        p.parent.chmod(0o555)

    def readonly_file(p):
        p.chmod(0o444)

    def folder(p):
        p.unlink()
        p.mkdir()

    def dangling(p):
        p.unlink()
        p.symlink_to(p.parent / "nowhere.h5")

    variants = {
        "cut in half": lambda p: p.write_bytes(p.read_bytes()[: p.stat().st_size // 2]),
        "zero bytes": lambda p: p.write_bytes(b""),
        "the stored hash edited": hash_attr,
        "a sample edited": data_edit,
        "fs edited": attr("fs", 123.0),
        "the folder read-only": readonly_dir,
        "the entry read-only": readonly_file,
        "the entry a folder": folder,
        "the entry a dangling link": dangling,
        "a JSON file under its name": lambda p: p.write_text("{}"),
    }

    def case(label, cmd):
        def run():
            entry = setup()
            cache = work / f"c_{hostile19._safe(label)}_{cmd}"
            if cache.exists():
                cache.chmod(0o755)
                shutil.rmtree(cache)
            shutil.copytree(entry.parent, cache)
            variants[label](cache / entry.name)
            out = work / f"o_{hostile19._safe(label)}_{cmd}"
            shutil.rmtree(out, ignore_errors=True)
            try:
                if cmd == "generate":
                    argv = ["generate", MM, "--cache", str(cache), "-o", str(out) + ".h5"]
                else:
                    argv = ["run", MM, "--cache", str(cache), "-o", str(out), "--no-figures"]
                status, o, err = cli_inprocess(argv)
            finally:
                cache.chmod(0o755)
            finding = judged(status, o, err)
            if finding:
                return finding
            if cmd == "generate" and status == 0:
                got = _content_hash(Path(str(out) + ".h5"))
                if got != state["hash"]:
                    return f"generate wrote another dataset ({got[:12]} != {state['hash'][:12]})"
            if status == 2 and label not in REFUSED_ENTRIES:
                return f"{cmd} refused over a damaged cache entry: {err.strip()[:160]!r}"
            return None
        return run

    return [(f"cache entry {label} / {cmd}", case(label, cmd))
            for label in variants for cmd in ("generate", "run")]


# ------------------------------------------------------------------ kills

def _session_alive(sid: int) -> list[int]:
    """Process ids in session ``sid`` (from /proc), zombies left out."""
    alive = []
    for d in Path("/proc").iterdir():
        if not d.name.isdigit():
            continue
        try:
            stat_text = (d / "stat").read_text()
        except OSError:
            continue
        fields = stat_text.rsplit(")", 1)[1].split()
        if fields[0] != "Z" and int(fields[3]) == sid:
            alive.append(int(d.name))
    return alive


def kill_cases(work: Path) -> list[tuple[str, object]]:
    import signal
    import subprocess
    import time

    study = work / "k27.toml"
    study.write_text(STUDY.replace('name = "h27"', 'name = "k27"')
                     .replace("noise = [0.0]", "noise = [0.0, 1.0]")
                     .replace("seeds = [0]", "seeds = [0, 1]"))
    cases = []

    def start(argv, name):
        log = open(work / f"{name}.err", "w")
        return subprocess.Popen([sys.executable, "-m", "testbed.cli", *argv], cwd=work,
                                env=_hostile.ENV, stdout=subprocess.DEVNULL, stderr=log,
                                start_new_session=True)

    def stop(p, sig, delay):
        time.sleep(delay)
        if p.poll() is None:
            os.kill(p.pid, sig)
        try:
            p.wait(60)
        except subprocess.TimeoutExpired:
            return "did not end within 60 s of the signal"
        for _ in range(50):
            left = _session_alive(p.pid)
            if not left:
                return None
            time.sleep(0.1)
        for pid in left:
            with contextlib.suppress(OSError):
                os.kill(pid, signal.SIGKILL)
        return f"processes left behind: {left}"

    def gen_case(sig, delay):
        def run():
            name = f"g_{sig.name}_{delay}"
            out = work / f"{name}.h5"
            p = start(["generate", MM, "--no-cache", "-o", str(out)], name)
            finding = stop(p, sig, delay)
            if finding:
                return finding
            if out.exists():
                try:
                    _content_hash(out)
                except Exception as e:  # a half file: the finding
                    return f"a damaged output left: {type(e).__name__}: {str(e)[:120]}"
            tmp = [q.name for q in work.iterdir() if q.name.startswith(f".{name}") or
                   (q.name.startswith(name) and q.suffix == ".tmp")]
            if tmp and sig != signal.SIGKILL:
                return f"temporary files left after {sig.name}: {tmp}"
            err = (work / f"{name}.err").read_text()
            if "Traceback" in err:
                return f"a traceback after {sig.name}: {err.strip().splitlines()[-1][:160]!r}"
            again = _hostile.testbed_cli(["generate", MM, "--no-cache", "-o", str(out)], work,
                                         TIMEOUT_S)
            return _hostile.cli_finding(again) or (
                None if again.returncode == 0 else f"rerun status {again.returncode}")
        return run

    def sweep_case(sig, delay):
        def run():
            from testbed.studies.results import read_results

            name = f"s_{sig.name}_{delay}"
            results = work / f"{name}.parquet"
            p = start(["sweep", str(study), "--results", str(results), "--cache", str(CACHE)],
                      name)
            finding = stop(p, sig, delay)
            if finding:
                return finding
            err = (work / f"{name}.err").read_text()
            if "Traceback" in err:
                return f"a traceback after {sig.name}: {err.strip().splitlines()[-1][:160]!r}"
            done = len(read_results(results)) if results.exists() or \
                (work / f"{name}.parquet.parts").exists() else 0
            again = _hostile.testbed_cli(["sweep", str(study), "--results", str(results),
                                          "--cache", str(CACHE)], work, TIMEOUT_S)
            finding = _hostile.cli_finding(again)
            if finding:
                return finding
            if f"{done} already done" not in again.stdout + again.stderr:
                return (f"{done} rows before the rerun; it said "
                        f"{(again.stdout + again.stderr).strip().splitlines()[:1]}")
            rows = read_results(results)
            if len(rows) != 4 or len({r['cell'] for r in rows}) != 4:
                return f"{len(rows)} rows after the rerun; expected 4 cells once each"
            return None
        return run

    for sig in (signal.SIGKILL, signal.SIGINT, signal.SIGTERM):
        for delay in (0.3, 1.5, 3.0):
            cases.append((f"generate {sig.name} after {delay} s", gen_case(sig, delay)))
        for delay in (1.5, 4.0, 7.0):
            cases.append((f"sweep {sig.name} after {delay} s", sweep_case(sig, delay)))
    return cases


# ------------------------------------------------------------------ roundtrip

def roundtrip_cases(work: Path) -> list[tuple[str, object]]:
    """Every export format identified back: the same model as the dataset's own; the SEP-005
    export with its metadata edited: refused in one line, or (an unknown key, the source
    dataset's hash, which no importer can verify without the truth) the same model."""
    state: dict = {}

    def model_of(path, *more):
        out = path.with_suffix(path.suffix + ".model.json")
        status, _, err = cli_inprocess(["identify", str(path), "--scenario", MM, "-o", str(out),
                                        *more])
        if status not in (0, 1):
            raise RuntimeError(f"identify {path.name}: {err.strip()[:200]}")
        return json.loads(out.read_text())

    def case(fmt):
        def run():
            h5 = hostile19._generated(work, MM)
            if "ref" not in state:
                state["ref"] = model_of(h5)
            out = work / ("mm.uff" if fmt == "uff" else "mm.sep005.json")
            status, o, err = cli_inprocess(["export", str(h5), "--format", fmt, "-o", str(out)])
            if status != 0:
                return judged(status, o, err) or f"export status {status}: {err.strip()[:160]}"
            got = model_of(out)
            a, b = state["ref"].get("coefficients"), got.get("coefficients")
            if not isinstance(a, dict) or not isinstance(b, dict):
                return f"no coefficients in the model JSON: {sorted(got)[:8]}"
            if a.get("feature_names") != b.get("feature_names"):
                return f"{fmt} round trip fitted another library: {b.get('feature_names')}"
            a, b = a.get("coef"), b.get("coef")
            import numpy as np

            a, b = np.asarray(a, float), np.asarray(b, float)
            # the export writes each sample as text at 17 significant digits (SEP-005) or as
            # float64 (UFF): the same numbers, so the fit agrees to rounding (1e-9 relative)
            if a.shape != b.shape or not np.allclose(a, b, rtol=1e-9, atol=1e-12):
                return f"{fmt} round trip fitted another model: max |diff| {np.max(np.abs(a - b)):.3g}"
            return None
        return run

    def edit(change, expect):
        """The SEP-005 export with ``change(channels)`` applied, identified: ``expect`` "refuse"
        (one line) or "same" (the clean model)."""
        def run():
            h5 = hostile19._generated(work, MM)
            src = work / "base.sep005.json"
            if not src.exists():
                status, _, err = cli_inprocess(["export", str(h5), "--format", "sep005", "-o",
                                                str(src)])
                if status != 0:
                    return f"export: {err.strip()[:160]}"
            if "ref" not in state:
                state["ref"] = model_of(h5)
            channels = json.loads(src.read_text())
            change(channels)
            state["n"] = state.get("n", 0) + 1
            path = work / f"edit{state['n']}.json"
            path.write_text(json.dumps(channels))
            out = path.with_suffix(".model.json")
            status, o, err = cli_inprocess(["identify", str(path), "--scenario", MM, "-o",
                                            str(out)])
            finding = judged(status, o, err, refuse=expect == "refuse")
            if finding or expect == "refuse":
                return finding
            got = json.loads(out.read_text()).get("coefficients")
            if got != state["ref"].get("coefficients"):
                return f"accepted, another model: {got}"
            return None
        return run

    def each(key, value):
        def change(chs):
            for c in chs:
                c[key] = value
        return change

    def first(key, value):
        def change(chs):
            chs[0][key] = value
        return change

    def cut(chs):
        chs[0]["data"] = chs[0]["data"][:200]

    def null_sample(chs):
        chs[0]["data"][5] = None

    def twice(chs):
        chs[1]["name"] = chs[0]["name"]

    edits = [("fs 0 everywhere", each("fs", 0.0), "refuse"),
             ("fs -100 everywhere", each("fs", -100.0), "refuse"),
             ("fs a text everywhere", each("fs", "100"), "refuse"),
             ("fs null everywhere", each("fs", None), "refuse"),
             ("fs of one channel halved", first("fs", 50.0), "refuse"),
             ("one channel cut to half its samples", cut, "refuse"),
             ("a null sample", null_sample, "refuse"),
             ("two channels of one name", twice, "refuse"),
             ("unit_str of one channel unknown", first("unit_str", "furlong"), "refuse"),
             ("unit_str a number", first("unit_str", 5), "refuse"),
             ("an unknown key", first("colour", "red"), "same"),
             ("content_hash edited", each("content_hash", "0" * 64), "same"),
             # `group` is the export's note of where a channel came from ("measured": only
             # measured signals are exported); SEP-005 does not define it and other tools
             # write their own words there, so the importer reads past it
             ("group another", first("group", "truth"), "same")]
    def uff_edit(stated, expect):
        """The UFF export with every ID line 5's ``fs 100.0 Hz`` replaced by ``stated`` (the
        same length: the binary records keep their layout)."""
        def run():
            h5 = hostile19._generated(work, MM)
            src = work / "base.uff"
            if not src.exists():
                status, _, err = cli_inprocess(["export", str(h5), "--format", "uff", "-o",
                                                str(src)])
                if status != 0:
                    return f"export: {err.strip()[:160]}"
            if "ref" not in state:
                state["ref"] = model_of(h5)
            data = src.read_bytes()
            if b"fs 100.0 Hz" not in data or len(stated) != len(b"fs 100.0 Hz"):
                return "the export's ID line 5 is not 'fs 100.0 Hz'"
            state["n"] = state.get("n", 0) + 1
            path = work / f"edit{state['n']}.uff"
            path.write_bytes(data.replace(b"fs 100.0 Hz", stated))
            out = path.with_suffix(".model.json")
            status, o, err = cli_inprocess(["identify", str(path), "--scenario", MM, "-o",
                                            str(out)])
            finding = judged(status, o, err, refuse=expect == "refuse")
            if finding or expect == "refuse":
                return finding
            got = json.loads(out.read_text()).get("coefficients")
            return None if got == state["ref"].get("coefficients") else f"another model: {got}"
        return run

    uff_edits = [(b"fs ..... Hz", "refuse"), (b"fs nan   Hz", "refuse"), (b"fs -inf  Hz", "refuse"),
                 (b"fs 1e999 Hz", "refuse"), (b"fs 0.000 Hz", "refuse"), (b"fs 900.0 Hz", "refuse"),
                 (b"fs 100.1 Hz", "refuse"), (b"fs 1e+02 Hz", "same"),
                 # free text another tool may write there: no rate stated, the header's taken
                 (b"fs about Hz", "same")]
    return [(f"export {fmt} then identify", case(fmt)) for fmt in ("sep005", "uff")] + [
        (f"uff ID line 5 {stated.decode()!r}", uff_edit(stated, expect))
        for stated, expect in uff_edits] + [
        (f"sep005 edited: {label}", edit(change, expect)) for label, change, expect in edits]


# ------------------------------------------------------------------ served

def _children(pid: int) -> list[int]:
    """Live (not zombie) processes whose parent is ``pid`` (from /proc)."""
    out = []
    for d in Path("/proc").iterdir():
        if d.name.isdigit():
            try:
                fields = (d / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if fields[0] != "Z" and int(fields[1]) == pid:
                out.append(int(d.name))
    return out


def served_cases(work: Path) -> list[tuple[str, object]]:
    import array
    import socket
    import struct
    import subprocess
    import threading
    import time

    from testbed.server import server_key

    folder = work / "srv"
    folder.mkdir(mode=0o700, exist_ok=True)
    sock = folder / "s.sock"
    env = {**_hostile.ENV, "TESTBED_SERVER_SOCKET": str(sock)}
    env.pop("TESTBED_NO_SERVER")
    state: dict = {}

    def client(argv, timeout=120):
        return subprocess.run([sys.executable, "-m", "testbed.cli", *argv], cwd=work, env=env,
                              capture_output=True, text=True, timeout=timeout)

    def start():
        log = open(folder / "log", "w")
        state["proc"] = subprocess.Popen([sys.executable, "-m", "testbed.cli", "serve", "--idle",
                                          "300", "--warm-up", "none"], env=env, stderr=log,
                                         stdout=subprocess.DEVNULL, start_new_session=True)
        t0 = time.monotonic()
        while not sock.exists():
            if state["proc"].poll() is not None or time.monotonic() - t0 > 120:
                return "the server did not start"
            time.sleep(0.2)
        return None

    def still_serves(after):
        """A real command after ``after``: served (the log grows), status 0, within 5 s."""
        def run():
            if "proc" not in state:
                return "no server"
            note = after()
            t0 = time.monotonic()
            p = client(["list", "--plain"])
            dt = time.monotonic() - t0
            if p.returncode != 0:
                return f"status {p.returncode} after it: {p.stderr.strip()[:160]!r}"
            if state["proc"].poll() is not None:
                return f"the server ended ({state['proc'].returncode})"
            return note or (f"a real command waited {dt:.1f} s" if dt > 5.0 else None)
        return run

    def raw(head: bytes, body: bytes, fds=(0, 1, 2), close_early=False):
        def send():
            with socket.socket(socket.AF_UNIX) as c:
                c.connect(str(sock))
                c.sendmsg([head + body], [(socket.SOL_SOCKET, socket.SCM_RIGHTS,
                                           array.array("i", fds))] if fds else [])
                if close_early:
                    return None
                c.settimeout(30)
                with contextlib.suppress(OSError):
                    reply = c.recv(4096)
                    if reply and b"refused" not in reply and b"status" not in reply:
                        return f"reply {reply[:120]!r}"
            return None
        return send

    def request(**change):
        r = {"argv": ["list", "--plain"], "cwd": str(work), "env": dict(env), "umask": 0o022,
             "key": server_key(env)}
        r.update(change)
        data = json.dumps(r).encode()
        return struct.pack("!I", len(data)), data

    def both_at_once():
        outs = {}

        def one(i):
            outs[i] = client(["export", str(state["h5"]), "--format", "sep005", "-o",
                              str(work / f"two{i}.json")])
        state.setdefault("h5", hostile19._generated(work, MM))
        ts = [threading.Thread(target=one, args=(i,)) for i in range(2)]
        for t in ts:
            t.start()
        for t in ts:
            t.join(120)
        if any(outs[i].returncode != 0 for i in outs):
            return f"statuses {[outs[i].returncode for i in outs]}: {outs[0].stderr[:120]!r}"
        if (work / "two0.json").read_bytes() != (work / "two1.json").read_bytes():
            return "two clients at once wrote different exports"
        return None

    def client_killed():
        server = state["proc"].pid
        p = subprocess.Popen([sys.executable, "-m", "testbed.cli", "generate", MM, "--no-cache",
                              "-o", str(work / "killed.h5")], cwd=work, env=env,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(1.0)
        p.kill()
        p.wait(30)
        for _ in range(100):
            if not _children(server):
                return None
            time.sleep(0.1)
        return f"the server's command children left after its client was killed: {_children(server)}"

    def stop():
        proc = state.get("proc")
        if proc is None:
            return None
        proc.terminate()
        proc.wait(30)
        return None if not sock.exists() else "the socket was left"

    head, body = request()
    big = struct.pack("!I", 2**32 - 1)
    cases = [("start", start)]
    for label, after in [
            ("a header only, then gone", raw(head, b"", close_early=True)),
            ("half a request, then gone", raw(head, body[: len(body) // 2], close_early=True)),
            ("a length of 2**32 - 1", raw(big, b"{}")),
            ("a length of 2**32 - 1, then gone", raw(big, b"{", close_early=True)),
            ("not JSON", raw(struct.pack("!I", 9), b"not json!")),
            ("JSON nested 100,000 deep", raw(struct.pack("!I", 200000), b"[" * 100000 + b"]" * 100000)),
            ("no descriptors", raw(head, body, fds=())),
            ("two descriptors", raw(head, body, fds=(1, 2))),
            ("argv a text", raw(*request(argv="list --plain"))),
            ("argv of numbers", raw(*request(argv=[1, 2]))),
            ("argv of 100,000 words", raw(*request(argv=["list"] + ["--plain"] * 100000))),
            ("env a list", raw(*request(env=["A=B"]))),
            ("umask a float", raw(*request(umask=18.0))),
            ("key missing", raw(*request(key=None))),
            ("two clients at once", both_at_once),
            ("a client killed mid-command", client_killed)]:
        cases.append((f"server: {label}", still_serves(after)))
    cases.append(("stop", stop))
    return cases


FAMILIES = _hostile.families({"flags": flags_cases, "stores": stores_cases, "cache": cache_cases,
                              "kill": kill_cases, "roundtrip": roundtrip_cases,
                              "served": served_cases}, TIMEOUT_S)

if __name__ == "__main__":
    raise SystemExit(_hostile.main(sys.argv[1:], FAMILIES, "hostile27-"))
