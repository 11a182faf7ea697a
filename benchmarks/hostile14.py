"""Fourteenth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile14 [family ...]      # all families when none is named

Families (where rounds 1-13 went least):

``index``
    The ``testbed list`` index (:mod:`testbed.core.stamped`) damaged: replaced by a FIFO, a
    link to ``/dev/zero`` or ``/dev/full``, a folder, a link loop; cut at every 10 % of its
    length and one bit flipped there; its value edited to another shape; 20 MB of JSON; two
    listings at once.  A hang, a listing other than the undamaged one, or a status other than
    0 is a finding.
``socket``
    ``testbed serve`` with ``$TESTBED_SERVER_SOCKET`` naming a regular file, a FIFO, a folder,
    a symbolic link, a link loop, a path under a file: anything there removed or changed, or
    an error other than one line, is a finding.
``entrypoints``
    An installed distribution's identifier entry point that raises at import (in two lines),
    calls ``sys.exit(0)``, names a function, an int, a module registering nothing, a class
    under a built-in's name, two entry points registering one name, a name no file can spell:
    ``testbed list`` and ``testbed run``.  Status 0 without the listing or verdict, a
    traceback, or the entry point ignored in silence is a finding.
``envvars``
    Every ``TESTBED_*`` variable the command line reads (``TESTBED_CACHE``,
    ``TESTBED_SCENARIOS``, ``TESTBED_STUDIES``, ``TESTBED_INDEX``, ``TESTBED_SERVER_SOCKET``,
    ``TESTBED_NO_SERVER``) empty, relative, a file, a FIFO, ``/dev/full``, ``/proc/self``, a link
    loop, Unicode, 300 characters, holding a newline: ``list`` and ``generate``.  An internal
    error or a refusal in more than one line is a finding.
``channels``
    A cantilever record exported to SEP-005 (``testbed export``), its channels renamed
    (Unicode look-alikes, a newline, a slash more or less, 2,000 characters, a format string,
    composed against decomposed accents) and its units respelled (``m/s²``, ``M/S^2``,
    ``m/s/s``, ``µm/s^2``, blank, 1,000 characters), then ``testbed identify``: a traceback, a
    refusal in more than one line, or a fit of a channel whose unit was not read is a finding.
``uff``
    The same record exported to UFF, one acceleration record's ordinate given every pairing of
    a specific data type (displacement, velocity, acceleration, force) with a unit label (m,
    mm, m/s, mm/s, m/s^2, g, mm/s^2, N, kN), and its ID line a NUL, an ESC, a DEL or a latin-1
    byte: a record whose label and codes declare different quantities identified, a name with
    a control character identified, or a traceback, is a finding.
``requests``
    A resident server (``testbed serve``) sent requests a client of its own would not: a lone
    surrogate in the environment, an environment name, the folder or an argument, a folder
    that does not exist, an argument of 900 kB, a request over the limit, not JSON, JSON nested
    100,000 deep, one or no descriptor, a client gone before the reply, ``argv`` a string, a
    umask of 2**70, an empty ``argv``.  An internal error or traceback of the command, the
    server ended, or the next command not served is a finding.
``longargs``
    Every path argument and option of the commands at 100,000 characters (Linux allows 128 kB
    an argument; round 13 tried 5,000): an error line longer than the harness's limit
    (:data:`benchmarks._hostile.MAX_LINE_CHARS`) is a finding.
``escapes``
    An ESC sequence in an argument of every command (a scenario, a seed, a study, a results
    file, a report source, a dataset, a cache, an identifier, a ``--prior`` or ``--param`` key,
    a ``--units`` channel, a family, a runs folder, an option, a command, a plugin): a raw ESC
    in the error line (which the terminal obeys) is a finding.
``texts``
    A scenario's description and tags, a study's and a family's description (free texts that
    ``testbed list --plain``, the reports and the console show on one line) holding a newline, a
    tab, an ESC sequence, a carriage return, a Unicode line separator, DEL, a C1 control or a
    NUL: accepted is a finding.
``tomlbytes``
    A shipped scenario's bytes with a byte-order mark, CRLF and lone CR line ends, NUL,
    UTF-16, a form feed, a trailing Ctrl-Z, a vertical tab, Unicode line separators, a line of
    1 MB: loaded (:func:`testbed.pipeline.scenario.load_scenario`).  An exception other than
    one refusal line, or a scenario other than the original's (its cell key) loaded from
    bytes that change nothing TOML reads, is a finding.

``bounds``
    Every numeric setting with a declared bound (:class:`~testbed.core.schema.Field` ``min`` /
    ``max``) of five shipped scenarios (the four rigs, a soft beam: the rig's, simulation's,
    excitation's, noise, signal chain's and identifier's tables) at the bound itself and at the
    next float (or integer) beyond it, or just inside an excluded bound; the accepted ones of
    the two fast rigs (Michaelis-Menten, cart-pole) also run and scored, but for their
    ``[simulation]`` (the budget's: 3600 s of cart-pole is allowed).  A value beyond its
    bound accepted, an exception other than one refusal line, or a scored NaN passing or
    without a reason is a finding.

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import functools
import json
import os
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

from benchmarks import _hostile

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 300
PYTHON = sys.executable
#: The shipped dataset cache: no case simulates anything new.
CACHE = ROOT / ".cache" / "datasets"


def _testbed(argv: list[str], cwd: Path, timeout: float = 120, **env: str) -> subprocess.CompletedProcess:
    """``testbed argv`` in ``cwd`` with the round's environment and ``env`` over it (a value
    of None removes a variable)."""
    e = {**_hostile.ENV, **env}
    e = {k: v for k, v in e.items() if v is not None}
    return subprocess.run([PYTHON, "-m", "testbed.cli", *argv], cwd=cwd, env=e,
                          capture_output=True, text=True, timeout=timeout)


_cli_finding = _hostile.cli_finding


def _hang(argv, cwd, timeout, **env) -> subprocess.CompletedProcess | str:
    try:
        return _testbed(argv, cwd, timeout, **env)
    except subprocess.TimeoutExpired:
        return f"hang > {timeout} s"


# ------------------------------------------------------------------ index

def index_cases(work: Path) -> list[tuple[str, object]]:
    folder = work / "idx"
    plain = ["list", "--plain"]

    def baseline() -> tuple[str, Path]:
        """The undamaged listing (indexes off) and the index file one listing writes."""
        if not (work / "baseline.txt").exists():
            p = _testbed(plain, work, TESTBED_INDEX="")
            (work / "baseline.txt").write_text(p.stdout)
            shutil.rmtree(folder, ignore_errors=True)
            _testbed(plain, work, TESTBED_INDEX=str(folder))
            time.sleep(2.5)  # (stamps younger than 2 s are not kept: testbed.core.stamped)
            _testbed(plain, work, TESTBED_INDEX=str(folder))
            files = list(folder.glob("list-*.json"))
            if len(files) != 1:
                raise RuntimeError(f"no index written in {folder}: {files}")
            shutil.copy(files[0], work / "index.json")
            (work / "index.name").write_text(files[0].name)
        return (work / "baseline.txt").read_text(), folder / (work / "index.name").read_text()

    def case(name: str, damage):
        def run() -> str | None:
            want, path = baseline()
            shutil.rmtree(folder, ignore_errors=True)
            folder.mkdir()
            damage(path, (work / "index.json").read_bytes())
            p = _hang(plain, work, 60, TESTBED_INDEX=str(folder))
            if isinstance(p, str):
                return p
            bad = _cli_finding(p)
            if bad or p.returncode != 0:
                return bad or f"status {p.returncode}: {p.stderr.strip()[-200:]}"
            return None if p.stdout == want else "a listing other than the undamaged one"
        return (f"index {name}", run)

    def cut(frac):
        return lambda path, b: path.write_bytes(b[:int(len(b) * frac)])

    def flip(frac):
        def f(path, b):
            k = min(int(len(b) * frac), len(b) - 1)
            path.write_bytes(b[:k] + bytes([b[k] ^ 0x10]) + b[k + 1:])
        return f

    def value(v):
        def f(path, b):
            d = json.loads(b)
            d["value"] = v
            path.write_text(json.dumps(d))
        return f

    def renamed_row(path, b):  # a row of the right shape but another text: stale by design?
        d = json.loads(b)
        d["value"][0][2][0][0] = "renamed"
        path.write_text(json.dumps(d))

    cases = [
        case("a FIFO", lambda path, b: os.mkfifo(path)),
        case("a link to /dev/zero", lambda path, b: path.symlink_to("/dev/zero")),
        case("a link to /dev/full", lambda path, b: path.symlink_to("/dev/full")),
        case("a folder", lambda path, b: path.mkdir()),
        case("a link loop", lambda path, b: (path.symlink_to(path.name + ".x"),
                                             (path.parent / (path.name + ".x")).symlink_to(path.name))),
        case("20 MB of JSON", lambda path, b: path.write_text(
            json.dumps({"format": 2, "pad": "x" * (20 << 20)}))),
        case("empty", lambda path, b: path.write_bytes(b"")),
    ]
    cases += [case(f"cut at {f:.0%}", cut(f)) for f in (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.99)]
    cases += [case(f"bit flipped at {f:.0%}", flip(f)) for f in (0.0, 0.1, 0.3, 0.5, 0.7, 0.9, 0.99)]
    cases += [case(f"value {v!r}", value(v)) for v in (None, [], [[1, 2, 3]], "x",
                                                     [["a", ["b"], [["c", "d"]]]],
                                                     {"a": 1}, [["t", ["c"], [[5]]]])]

    def racing() -> str | None:
        want, _ = baseline()
        shutil.rmtree(folder, ignore_errors=True)
        e = {**_hostile.ENV, "TESTBED_INDEX": str(folder)}
        ps = [subprocess.Popen([PYTHON, "-m", "testbed.cli", *plain], cwd=work, env=e,
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True) for _ in range(4)]
        outs = [p.communicate(timeout=120) for p in ps]
        bad = [f"status {p.returncode}: {err[-200:]}" for p, (out, err) in zip(ps, outs, strict=True)
               if p.returncode]
        bad += ["a listing other than the undamaged one" for out, _ in outs if out != want]
        return "; ".join(bad) or None

    cases.append(("index: four listings at once", racing))
    return cases


# ------------------------------------------------------------------ socket

def socket_cases(work: Path) -> list[tuple[str, object]]:
    priv = work / "priv"
    priv.mkdir(mode=0o700, exist_ok=True)

    def make(kind: str, path: Path):
        if kind == "file":
            path.write_text("precious")
        elif kind == "fifo":
            os.mkfifo(path)
        elif kind == "folder":
            path.mkdir()
            (path / "inside").write_text("precious")
        elif kind == "link":
            (priv / "target").write_text("precious")
            path.symlink_to(priv / "target")
        elif kind == "link loop":
            path.symlink_to(path)
        elif kind == "under a file":
            path.write_text("precious")
            return path / "s"
        return path

    def snapshot():
        return sorted((p.name, p.is_symlink(), p.is_file() and p.read_text()) for p in priv.rglob("*")
                      if not p.is_fifo() or True)

    def case(kind: str):
        def run() -> str | None:
            for p in priv.iterdir():
                if p.is_dir() and not p.is_symlink():
                    shutil.rmtree(p)
                else:
                    p.unlink()
            sock = make(kind, priv / "s")
            before = snapshot()
            p = _hang(["serve", "--idle", "1", "--warm-up", "none"], work, 60,
                      TESTBED_SERVER_SOCKET=str(sock), TESTBED_NO_SERVER=None)
            if isinstance(p, str):
                return p
            after = snapshot()
            bad = _cli_finding(p)
            if before != after:
                return f"status {p.returncode}; the folder changed: {before} -> {after}"
            return bad
        return (f"serve at a {kind}", run)

    return [case(k) for k in ("file", "fifo", "folder", "link", "link loop", "under a file")]


# ------------------------------------------------------------------ entrypoints

def _distribution(site: Path, entries: str, source: str) -> None:
    shutil.rmtree(site, ignore_errors=True)
    dist = site / "fake14-0.1.dist-info"
    dist.mkdir(parents=True)
    (dist / "METADATA").write_text("Metadata-Version: 2.1\nName: fake14\nVersion: 0.1\n")
    (dist / "entry_points.txt").write_text(f"[sysid_testbed.identifiers]\n{entries}\n")
    (site / "fake14mod.py").write_text(source)


ENTRY_POINTS = {
    "raises in two lines": ("x = fake14mod", "raise RuntimeError('boom\\nsecond line')"),
    "calls sys.exit(0)": ("x = fake14mod", "import sys\nsys.exit(0)"),
    "names a function": ("x = fake14mod:f", "def f():\n    pass"),
    "names an int": ("x = fake14mod:obj", "obj = 5"),
    "a class under a built-in's name": ("ls_sindy = fake14mod:C", "class C:\n    pass"),
    "two registering one name": ("a = fake14mod:C\nb = fake14mod:D",
                                 "class C:\n    name = 'same'\nclass D:\n    name = 'same'"),
    "a name no file can spell": ("x = fake14mod:C", "class C:\n    name = '../up'"),
    "a missing module": ("x = nosuchmodule14:C", ""),
    "a missing attribute": ("x = fake14mod:Nope", "class C:\n    pass"),
}


def entrypoints_cases(work: Path) -> list[tuple[str, object]]:
    def case(name: str, argv: list[str]):
        def run() -> str | None:
            entries, source = ENTRY_POINTS[name]
            site = work / "site"
            _distribution(site, entries, source)
            p = _hang(argv, work, 120, PYTHONPATH=f"{ROOT}{os.pathsep}{site}", TESTBED_INDEX="",
                      TESTBED_CACHE=str(CACHE))
            if isinstance(p, str):
                return p
            bad = _cli_finding(p)
            if bad:
                return bad
            if p.returncode == 0 and argv[0] == "list" and "fake14" not in p.stdout:
                return "status 0, the entry point ignored in silence"
            if p.returncode == 0 and argv[0] == "run" and "PASS" not in p.stdout + p.stderr:
                return f"status 0 without a verdict: {p.stdout[-200:]!r}"
            return None
        return (f"entry point {name}: {argv[0]}", run)

    return [case(n, argv) for n in ENTRY_POINTS
            for argv in (["list", "--plain"],
                         ["run", "michaelis_menten", "--no-figures", "-o", str(work / "out")])]


# ------------------------------------------------------------------ envvars

def envvars_cases(work: Path) -> list[tuple[str, object]]:
    (work / "afile").write_text("x")
    if not (work / "fifo").exists():
        os.mkfifo(work / "fifo")
    if not (work / "loop").is_symlink():
        (work / "loop").symlink_to("loop")
    values = {"empty": "", "relative": "rel", "a file": str(work / "afile"), "a FIFO": str(work / "fifo"),
              "/dev/full": "/dev/full", "/proc/self": "/proc/self", "a link loop": str(work / "loop"),
              "Unicode": str(work / "ünï"), "300 characters": str(work / ("y" * 300)),
              "a newline": str(work / "a\nb"), "a path under a file": str(work / "afile" / "x")}
    variables = ("TESTBED_CACHE", "TESTBED_SCENARIOS", "TESTBED_STUDIES", "TESTBED_INDEX",
                 "TESTBED_SERVER_SOCKET", "TESTBED_NO_SERVER")
    commands = {"list": ["list", "--plain"],
                "generate": ["generate", "michaelis_menten", "-o", "g.h5"]}

    def case(var, label, value, cmd):
        def run() -> str | None:
            env = {var: value}
            if var == "TESTBED_SERVER_SOCKET":
                env["TESTBED_NO_SERVER"] = None
            if var != "TESTBED_CACHE":
                env["TESTBED_CACHE"] = str(CACHE)
            p = _hang(commands[cmd], work, 120, **env)
            return p if isinstance(p, str) else _cli_finding(p)
        return (f"{var} {label}: {cmd}", run)

    return [case(v, lab, val, c) for v in variables for lab, val in values.items() for c in commands]


# ------------------------------------------------------------------ channels

NAMES = {
    "fullwidth look-alike": "acceleration/ａｃｃ1", "a newline": "acceleration/acc\n1",
    "no signal": "acc1", "a slash more": "acceleration/acc1/x", "an empty channel": "acceleration/",
    "an empty signal": "/acc1", "two slashes": "acceleration//acc1",
    "2,000 characters": "acceleration/" + "a" * 2000,
    "a format string": "acceleration/{0}%s", "upper-case signal": "ACCELERATION/acc1",
    "decomposed accent": "acceleration/acce\u0301", "right-to-left mark": "acceleration/acc\u200f1",
    "a space": "acceleration/acc 1", "a tab": "acceleration/acc\t1",
    "zero-width space": "acceleration/acc\u200b1",
}
UNITS = {"m/s²": "m/s²", "M/S^2": "M/S^2", "m/s/s": "m/s/s", "µm/s^2": "µm/s^2", "blank": " ",
         "1,000 characters": "m" * 1000, "NBSP inside": "m/s\u00a0^2", "a newline": "m/s^2\n",
         "N (a force)": "N", "g": "g", "kN": "kN", "rad/s^2": "rad/s^2"}


def channels_cases(work: Path) -> list[tuple[str, object]]:
    src = work / "cs.json"

    def ensure() -> list[dict]:
        if not src.exists():
            h5 = work / "cs.h5"
            _testbed(["generate", "cantilever_stiff_impact", "-o", str(h5), "--cache", str(CACHE)], work)
            _testbed(["export", str(h5), "--format", "sep005", "-o", str(src)], work)
        return json.loads(src.read_text())

    def case(label: str, edit):
        def run() -> str | None:
            chans = ensure()
            edit(chans)
            f = work / f"c_{abs(hash(label))}.json"
            f.write_text(json.dumps(chans))
            p = _hang(["identify", str(f), "--kind", "structural", "--method", "ls_sindy",
                       "--prior", "reduced_mass_trace=0.1", "-o", str(work / "m.json")], work, 120)
            if isinstance(p, str):
                return p
            hidden = [c["name"] for c in chans if not c["name"].isprintable()]
            if p.returncode == 0 and hidden:  # (it reached the console, the JSON, the report)
                return f"identified with a channel name holding a control character: {hidden[0]!r}"
            return _cli_finding(p)
        return (f"channels: {label}", run)

    def rename(name):
        def f(chans):
            chans[1]["name"] = name
        return f

    def unit(u):
        def f(chans):
            chans[0]["unit_str"] = u
        return f

    cases = [case(f"channel named with {k}", rename(v)) for k, v in NAMES.items()]
    cases += [case(f"unit {k}", unit(v)) for k, v in UNITS.items()]
    cases.append(case("the round trip", lambda chans: None))
    return cases


# ------------------------------------------------------------------ requests

def _served(path: Path, request: dict | bytes, fds: int = 3, vanish: bool = False) -> tuple[bytes, bytes]:
    """Send ``request`` (a dict as JSON, or raw bytes after the length) to the server at
    ``path`` with ``fds`` descriptors (standard input, a pipe for output and one for errors);
    the server's replies and what the command wrote to its error pipe."""
    import array
    import socket
    import struct

    s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    s.connect(str(path))
    out_r, out_w = os.pipe()
    err_r, err_w = os.pipe()
    data = request if isinstance(request, bytes) else json.dumps(request).encode()
    msg = struct.pack("!I", len(data)) + data
    s.sendmsg([msg], [(socket.SOL_SOCKET, socket.SCM_RIGHTS, array.array("i", [0, out_w, err_w][:fds]))])
    os.close(out_w)
    os.close(err_w)
    got: dict[int, bytes] = {out_r: b"", err_r: b""}

    def drain(fd: int) -> None:  # (a command blocked on a full pipe never replies)
        while (b := os.read(fd, 1 << 16)):
            got[fd] += b

    readers = [threading.Thread(target=drain, args=(fd,), daemon=True) for fd in got]
    for r in readers:
        r.start()
    replies = b""
    if vanish:
        s.close()
    else:
        s.settimeout(60)
        while (b := s.recv(4096)):
            replies += b
        s.close()
    for r in readers:
        r.join(timeout=10)
    for fd in got:
        os.close(fd)
    return replies, got[err_r]


def requests_cases(work: Path) -> list[tuple[str, object]]:
    from testbed import server

    folder = work / "srv"
    folder.mkdir(mode=0o700, exist_ok=True)
    sock = folder / "s"
    env = {**_hostile.ENV, "TESTBED_SERVER_SOCKET": str(sock)}
    env.pop("TESTBED_NO_SERVER", None)
    state: dict = {}

    def ensure() -> dict:
        if "proc" not in state or state["proc"].poll() is not None:
            state["proc"] = subprocess.Popen([PYTHON, "-m", "testbed.cli", "serve", "--idle", "120",
                                              "--warm-up", "none"], cwd=work, env=env,
                                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            for _ in range(300):
                if sock.exists():
                    break
                time.sleep(0.1)
        return {"argv": ["list", "--plain"], "cwd": str(work), "env": env, "umask": 0o22,
                "key": server.server_key(env)}

    def case(label, change=None, raw=None, fds=3, vanish=False):
        def run() -> str | None:
            base = ensure()
            request = raw if raw is not None else {**base, **(change or {})}
            replies, err = _served(sock, request, fds, vanish)
            if b"internal error" in err or b"Traceback" in err:
                return f"the command: {err.decode(errors='replace').strip()[-200:]}"
            if state["proc"].poll() is not None:
                return f"the server ended (status {state['proc'].returncode})"
            replies, err = _served(sock, base)  # the server still serves
            if b'"status": 0' not in replies:
                return f"the next command was not served: {replies[:120]!r} {err[-120:]!r}"
            return None
        return (f"requests: {label}", run)

    cases = [
        case("a lone surrogate in the environment", {"env": {**env, "X": "\ud800"}}),
        case("a lone surrogate in an environment name", {"env": {**env, "\ud800": "1"}}),
        case("a lone surrogate in the folder", {"cwd": str(work) + "/\ud800"}),
        case("a lone surrogate in an argument", {"argv": ["list", "\ud800"]}),
        case("a folder that does not exist", {"cwd": "/nonexistent/x"}),
        case("an argument of 900 kB", {"argv": ["run", "x" * 900_000]}),
        case("a request over the limit", raw=b"x" * (server.MAX_REQUEST + 1)),
        case("not JSON", raw=b"{not json"),
        case("JSON nested 100,000 deep", raw=b"[" * 100_000),
        case("one descriptor", fds=1),
        case("no descriptor", fds=0),
        case("a client gone before the reply", vanish=True),
        case("argv a string", {"argv": "list"}),
        case("umask 2**70", {"umask": 2 ** 70}),
        case("an empty argv", {"argv": []}),
    ]

    def stop() -> str | None:
        proc = state.get("proc")
        if proc is not None and proc.poll() is None:
            proc.terminate()
            proc.wait(timeout=30)
        return None

    cases.append(("requests: (the server stopped)", stop))
    return cases


# ------------------------------------------------------------------ longargs

#: A path argument this long [characters]: under Linux's 128 kB an argument (round 13 tried
#: 5,000, under the harness's limit of a line).
LONG = "x" * 100_000


def longargs_cases(work: Path) -> list[tuple[str, object]]:
    argvs = [["run", LONG], ["generate", LONG], ["sweep", LONG], ["summary", LONG],
             ["report", LONG, "-o", "r"], ["export", LONG, "--format", "uff"],
             ["identify", LONG, "--kind", "dynamical"], ["family", "write", LONG, "-o", "f"],
             ["run", "michaelis_menten", "-o", LONG + "/y"], ["runs", "ls", LONG],
             ["run", "michaelis_menten", "--plugin", LONG + ".py"], ["cache", "ls", "--cache", LONG],
             ["identify", "x.csv", "--kind", "dynamical", "--units", LONG + "=m"]]

    def case(argv):
        def run() -> str | None:
            p = _hang(argv, work, 120)
            if isinstance(p, str):
                return p
            longest = max((len(ln) for ln in p.stderr.splitlines()), default=0)
            if longest > _hostile.MAX_LINE_CHARS:
                return f"an error line of {longest} characters"
            return _cli_finding(p)
        return ("longargs: " + " ".join(a if len(a) < 99_000 else "<100,000 chars>" for a in argv), run)

    return [case(a) for a in argvs]


# ------------------------------------------------------------------ escapes

ESC = "\x1b[31mRED"


def escapes_cases(work: Path) -> list[tuple[str, object]]:
    (work / "mm.csv").write_text("t,x [mM],dx [mM/s]\n" + "".join(
        f"{i * 0.1},{1 + 0.1 * i},{0.1 + 0.01 * i}\n" for i in range(40)))
    argvs = [
        ["run", f"x{ESC}"], ["run", "michaelis_menten", "--seed", ESC], ["generate", f"x{ESC}"],
        ["sweep", f"x{ESC}"], ["summary", f"x{ESC}"], ["report", f"x{ESC}", "-o", "r"],
        ["export", f"x{ESC}.h5", "--format", "uff"], ["cache", "ls", "--cache", f"/proc/x{ESC}"],
        ["identify", "mm.csv", "--kind", "dynamical", "--method", f"x{ESC}"],
        ["identify", "mm.csv", "--kind", "dynamical", "--method", "sindy_pi_dynamical",
         "--prior", f"a{ESC}=1"],
        ["identify", "mm.csv", "--kind", "dynamical", "--method", "sindy_pi_dynamical",
         "--param", f"a{ESC}=1"],
        ["identify", "mm.csv", "--kind", "dynamical", "--units", f"x{ESC}=m"],
        ["family", "write", f"x{ESC}", "-o", "f"], ["runs", "ls", f"x{ESC}"], ["list", f"--x{ESC}"],
        [f"x{ESC}"], ["run", "michaelis_menten", "--plugin", f"x{ESC}.py"],
    ]

    def case(argv):
        def run() -> str | None:
            p = _hang(argv, work, 120)
            if isinstance(p, str):
                return p
            if "\x1b" in p.stderr:
                return f"a raw ESC in the error output: {p.stderr.strip()[-160:]!r}"
            return _cli_finding(p)
        return ("escapes: " + " ".join(a.replace(ESC, "<ESC>") for a in argv), run)

    return [case(a) for a in argvs]


# ------------------------------------------------------------------ uff

#: The ordinate line of a UFF58 record as ``testbed export`` writes an acceleration's
#: (record 8: specific data type, length, force and temperature exponents, labels).
_ORDINATE = b"        12    1    0    0 NONE                 m/s^2               "


def uff_cases(work: Path) -> list[tuple[str, object]]:
    src = work / "cs.uff"

    def ensure() -> bytes:
        if not src.exists():
            h5 = work / "cs.h5"
            _testbed(["generate", "cantilever_stiff_impact", "-o", str(h5), "--cache", str(CACHE)], work)
            _testbed(["export", str(h5), "--format", "uff", "-o", str(src)], work)
        return src.read_bytes()

    def case(label: str, edit, must_refuse: bool):
        def run() -> str | None:
            b = ensure()
            at = b.index(b"acceleration/acc2")
            f = work / f"u_{abs(hash(label))}.uff"
            f.write_bytes(edit(b, at))
            p = _hang(["identify", str(f), "--kind", "structural", "--method", "ls_sindy",
                       "--prior", "reduced_mass_trace=0.1", "-o", str(work / "m.json")], work, 120)
            if isinstance(p, str):
                return p
            if must_refuse and p.returncode == 0:
                return "identified"
            return _cli_finding(p)
        return (f"uff: {label}", run)

    def ordinate(spec: int, unit: str):
        new = f"{spec:10d}    1    0    0 NONE                 {unit:<20}".encode("latin-1")

        def f(b, at):
            j = b.index(_ORDINATE, at)
            return b[:j] + new[:len(_ORDINATE)].ljust(len(_ORDINATE)) + b[j + len(_ORDINATE):]
        return f

    def name(new: bytes):
        return lambda b, at: b[:at] + new.ljust(17)[:17] + b[at + 17:]

    quantity = {8: "m", 11: "m/s", 12: "m/s^2", 13: "N"}
    order = {"m": 0, "mm": 0, "m/s": 1, "mm/s": 1, "m/s^2": 2, "g": 2, "mm/s^2": 2, "N": 3, "kN": 3}
    cases = [case(f"type {spec} labelled {unit}", ordinate(spec, unit),
                  order[unit] != order[quantity[spec]])
             for spec in quantity for unit in order]
    cases += [case(f"a name of {k}", name(v), k != "a latin-1 byte")
              for k, v in {"a NUL": b"acceleration/a\x002", "an ESC": b"acceleration/\x1b[31m",
                           "a latin-1 byte": b"acceleration/acc\xe9",
                           "a DEL": b"acceleration/ac\x7f2"}.items()]
    return cases


# ------------------------------------------------------------------ tomlbytes

def tomlbytes_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.scenario import SCENARIO_DIR

    def key_of(path: Path) -> str:
        from testbed.pipeline.scenario import load_scenario

        sc = load_scenario(path)  # (the cell key without the name, which is the file's)
        return json.dumps([sc.data_hash(), sc.signal, sc.identify, sc.score], sort_keys=True)

    def case(base: str, label: str, edit, same: bool):
        def run() -> str | None:
            raw = (SCENARIO_DIR / f"{base}.toml").read_bytes()
            f = work / f"{base}_{abs(hash(label))}.toml"
            f.write_bytes(edit(raw))
            got = key_of(f)  # a refusal (TestbedError) is ok
            if same and got != key_of(SCENARIO_DIR / f"{base}.toml"):
                return "another scenario from bytes TOML reads alike"
            return None
        return (f"{base}: {label}", run)

    edits = {
        "a byte-order mark": (lambda b: b"\xef\xbb\xbf" + b, False),
        "CRLF line ends": (lambda b: b.replace(b"\n", b"\r\n"), True),
        "lone CR line ends": (lambda b: b.replace(b"\n", b"\r"), False),
        "a NUL at the end": (lambda b: b + b"\x00", False),
        "a NUL in a comment": (lambda b: b"# a\x00b\n" + b, False),
        "UTF-16": (lambda b: b.decode().encode("utf-16"), False),
        "UTF-16 without its mark": (lambda b: b.decode().encode("utf-16-le"), False),
        "a form feed": (lambda b: b + b"\x0c\n", False),
        "a trailing Ctrl-Z": (lambda b: b + b"\x1a", False),
        "a vertical tab": (lambda b: b"\x0b" + b, False),
        "a Unicode line separator in a comment": (lambda b: b"# a\xe2\x80\xa8b\n" + b, True),
        "a comment of 1 MB": (lambda b: b"# " + b"x" * (1 << 20) + b"\n" + b, True),
        "no final newline": (lambda b: b.rstrip(b"\n"), True),
        "CRLF and a mark": (lambda b: b"\xef\xbb\xbf" + b.replace(b"\n", b"\r\n"), False),
        "a DEL in a comment": (lambda b: b"# a\x7fb\n" + b, False),
    }
    return [case(base, label, e, same) for base in ("michaelis_menten", "cantilever_stiff_impact",
                                                   "fivebar_multisine", "cartpole")
            for label, (e, same) in edits.items()]


# ------------------------------------------------------------------ bounds

#: The shipped scenarios whose numeric settings the ``bounds`` family sets at their bounds, and
#: whether each accepted value is run and scored too (the two fast rigs).
#: Time limit of one ``bounds`` case [s]: a Michaelis-Menten or cart-pole run takes 2-30 s.
BOUND_TIMEOUT_S = 120
BOUND_BASES = {"michaelis_menten": True, "cartpole": True, "fivebar_multisine": False,
               "cantilever_stiff_impact": False, "cantilever_soft_impact": False}


def _bound_values(f) -> list[tuple[str, object, bool]]:
    """(label, value, allowed by the field's declared bounds) at and beyond each bound."""
    import math

    out = []
    for side, b, incl, away in (("min", f.min, f.min_inclusive, -math.inf),
                                ("max", f.max, f.max_inclusive, math.inf)):
        if b is None or (isinstance(b, float) and not math.isfinite(b)):
            continue
        if f.type is int:
            b = int(math.ceil(b) if side == "min" else math.floor(b))
            if incl or b != (f.min if side == "min" else f.max):
                out += [(f"{side} {b}", b, True),
                        (f"beyond {side} {b}", b + (-1 if side == "min" else 1), False)]
            else:
                out += [(f"{side} {b} (excluded)", b, False),
                        (f"inside {side} {b}", b + (1 if side == "min" else -1), True)]
            continue
        b = float(b)
        if incl:
            out += [(f"{side} {b!r}", b, True), (f"next float beyond {side}", math.nextafter(b, away), False)]
        else:
            out += [(f"{side} {b!r} (excluded)", b, False),
                    (f"next float inside {side}", math.nextafter(b, -away), True)]
    return out


def bounds_cases(work: Path) -> list[tuple[str, object]]:
    import copy

    from testbed.pipeline.plugins import identifier_class, rig_class
    from testbed.pipeline.scenario import NOISE_SCHEMA, SCENARIO_DIR, _read_toml
    from testbed.pipeline.signal_chain import SIGNAL_SCHEMAS

    cases = []
    for base, scored in BOUND_BASES.items():
        raw = _read_toml(SCENARIO_DIR / f"{base}.toml")
        raw["scenario"].pop("extends", None)
        rc = rig_class(raw["scenario"]["rig"])
        etype = raw.get("excitation", {}).get("type", rc.default_excitation)
        schemas = {"rig": rc.rig_schema, "simulation": rc.simulation_schema,
                   "excitation": rc.excitation_schemas.get(etype, {}), "noise": NOISE_SCHEMA,
                   "signal": SIGNAL_SCHEMAS[rc.kind],
                   "identify": identifier_class(raw["identify"]["method"]).declared_hyperparameters()}
        for table, schema in schemas.items():
            for key, f in schema.items():
                if f.type not in (int, float) or (f.min is None and f.max is None):
                    continue
                for label, value, allowed in _bound_values(f):
                    r = copy.deepcopy(raw)
                    r.setdefault(table, {})[key] = value
                    # (a simulation's own bounds are its budget's: 3600 s of the cart-pole is
                    # allowed, and takes longer than a case may; loaded, not run)
                    cases.append((f"{base} {table}.{key} {label} = {value!r}",
                                  functools.partial(_bound_case, r, base, allowed,
                                                    scored and table != "simulation", work)))
    return cases


def _bound_case(raw: dict, base: str, allowed: bool, scored: bool, work: Path) -> str | None:
    from testbed.pipeline.cache import DatasetCache
    from testbed.pipeline.scenario import scenario_from_dict
    from testbed.scoring.run import run_scenario

    sc = scenario_from_dict(raw, file=f"{base}.toml", stem=base)  # a refusal is ok
    if not allowed:
        return "a value beyond the field's declared bound accepted"
    if not scored:
        return None
    return _hostile.scored_finding(run_scenario(sc, cache=DatasetCache(work / "cache")))


# ------------------------------------------------------------------ texts

#: Free texts a listing or a report shows on one line, set to each of these.
TEXTS = {"a newline": "two\nlines", "a tab": "a\ttab", "an ESC sequence": "an \x1b[31mESC",
         "a carriage return": "over\rwritten", "a line separator": "a\u2028b", "a DEL": "a\x7fb",
         "a C1 control": "a\x85b", "a NUL": "a\x00b"}


def texts_cases() -> list[tuple[str, object]]:
    import copy
    import tomllib

    from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml, scenario_from_dict
    from testbed.studies.study import study_from_dict

    mm = _read_toml(SCENARIO_DIR / "michaelis_menten.toml")
    smoke = tomllib.loads((ROOT / "studies" / "smoke.toml").read_text())
    fams = tomllib.loads((ROOT / "studies" / "families.toml").read_text())

    def case(label, load, raw, path, text):
        def run() -> str | None:
            r = copy.deepcopy(raw)
            at = r
            for k in path[:-1]:
                at = at[k]
            at[path[-1]] = [text] if path[-1] == "tags" else text
            load(r)  # a refusal is ok
            return f"{'.'.join(map(str, path))} {text!r} accepted: shown on more than one line"
        return (f"texts: {label}", run)

    loads = [("scenario", mm, ("scenario", "description"),
              lambda r: scenario_from_dict(r, file="michaelis_menten.toml", stem="michaelis_menten")),
             ("scenario", mm, ("scenario", "tags"),
              lambda r: scenario_from_dict(r, file="michaelis_menten.toml", stem="michaelis_menten")),
             ("study", smoke, ("study", "description"),
              lambda r: study_from_dict(r, file="smoke.toml", base=ROOT / "studies", stem="smoke")),
             ("family", fams, ("families", "beams_stiff", "description"),
              lambda r: study_from_dict(r, file="families.toml", base=ROOT / "studies", stem="families"))]
    return [case(f"{what} {'.'.join(map(str, path))} with {k}", load, raw, path, v)
            for what, raw, path, load in loads for k, v in TEXTS.items()]


FAMILIES = {
    **_hostile.families({
        "index": index_cases, "socket": socket_cases, "entrypoints": entrypoints_cases,
        "envvars": envvars_cases, "channels": channels_cases, "tomlbytes": tomlbytes_cases,
        "requests": requests_cases, "longargs": longargs_cases, "escapes": escapes_cases,
        "texts": lambda work: texts_cases(), "uff": uff_cases,
    }, TIMEOUT_S),
    **_hostile.families({"bounds": bounds_cases}, BOUND_TIMEOUT_S),
}


def main(argv: list[str]) -> int:
    os.environ.setdefault("MPLBACKEND", "Agg")
    return _hostile.main(argv, FAMILIES, "hostile14-")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
