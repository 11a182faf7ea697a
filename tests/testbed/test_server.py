"""The resident server (``testbed serve``): a served command is the same command, a client that
dies leaves no process behind, a server of other sources or environment is not used."""

from __future__ import annotations

import contextlib
import json
import os
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from testbed import cli
from tests._processes import alive, state

ROOT = Path(__file__).resolve().parents[2]
pytestmark = [pytest.mark.xdist_group("server"),
              pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork + SCM_RIGHTS")]
#: Seconds to wait for a server to listen: imports (about 3 s of CPU) and a Michaelis-Menten
#: warm-up on a 2-core machine that other tests keep busy.
START_TIMEOUT_S = 180


def _env(tmp: Path, **extra) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "TESTBED_NO_SERVER"}
    cache = os.environ.get("TESTBED_TEST_CACHE", str(ROOT / ".cache" / "test-datasets"))
    return {**env, "TESTBED_SERVER_SOCKET": str(tmp / "sock" / "s.sock"), "TESTBED_CACHE": cache,
            "PYTHONPATH": str(ROOT), "MPLBACKEND": "Agg", **extra}


def _testbed(args, env, cwd, **kw):
    return subprocess.run([sys.executable, "-m", "testbed.cli", *args], env=env, cwd=cwd,
                          capture_output=True, text=True, timeout=300, **kw)


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    """A server warmed on the scenario the tests run; its log; stopped (and checked gone) after."""
    tmp = tmp_path_factory.mktemp("server")
    (tmp / "sock").mkdir(mode=0o700)
    env = _env(tmp)
    log = open(tmp / "log", "w+")
    proc = subprocess.Popen([sys.executable, "-m", "testbed.cli", "serve", "--idle", "600",
                             "--warm-up", "michaelis_menten"], env=env, cwd=tmp,
                            stdout=log, stderr=subprocess.STDOUT)
    t0 = time.monotonic()
    while "listening" not in (tmp / "log").read_text():
        assert proc.poll() is None, (tmp / "log").read_text()
        assert time.monotonic() - t0 < START_TIMEOUT_S, "the server did not start"
        time.sleep(0.2)
    yield tmp, env, proc
    proc.send_signal(signal.SIGTERM)
    assert proc.wait(timeout=30) == 0
    assert not (tmp / "sock" / "s.sock").exists()  # the socket goes with it
    log.close()


def _served_lines(tmp: Path) -> list[str]:
    return [ln for ln in (tmp / "log").read_text().splitlines() if ln.startswith("testbed server:")]


def _run_json(out: Path) -> dict:
    (run,) = [p for p in (out / "michaelis_menten").iterdir() if p.is_dir()]
    d = json.loads((run / "run.json").read_text())
    # the time stamps differ, and so does the seal over them (run store /2: the SHA-256 of the
    # other keys; run.npz's own digest is compared as every other field is)
    return {k: v for k, v in d.items() if k not in ("created", "fit_time", "sha256")}, run


def test_a_served_run_is_the_same_run(server):
    tmp, env, _ = server
    before = len(_served_lines(tmp))
    served = _testbed(["run", "michaelis_menten", "--out", "served"], env, tmp)
    alone = _testbed(["run", "michaelis_menten", "--out", "alone"], {**env, "TESTBED_NO_SERVER": "1"}, tmp)
    assert served.returncode == alone.returncode == 0, served.stderr + alone.stderr
    new = _served_lines(tmp)[before:]
    assert any(ln.startswith("testbed server: run michaelis_menten --out served") for ln in new), new
    assert not any("--out alone" in ln for ln in new)
    (a, run_a), (b, run_b) = _run_json(tmp / "served"), _run_json(tmp / "alone")
    assert a == b  # every score, setting and provenance field but the time stamps
    for f in ("run.npz", "coefficients.png", "joint_angles.png"):  # bit for bit
        assert (run_a / f).read_bytes() == (run_b / f).read_bytes(), f
    # the output the user sees is the command's own (but the --out folder and the times; the
    # table's title is centred, so its padding moves with the fit time's digits, printed
    # ``:.2f``: 9.99 s and 10.00 s differ by a character; at load 12 on 2026-11-27 the two
    # titles differed by one space of padding, nothing else, in two cold runs)
    def shown(r, out):
        text = re.sub(r"^ *(.*)\(fit [0-9.]+ s\) *$", r"\1(fit)", r.stdout.replace(out, "X"), flags=re.M)
        return re.sub(r"/\d{8}T\d{6}Z-s0", "/TIME-s0", text)

    assert shown(served, "served") == shown(alone, "alone")


def test_a_users_mistake_is_one_line_through_the_server(server):
    tmp, env, _ = server
    before = len(_served_lines(tmp))
    r = _testbed(["run", "no_such_scenario"], env, tmp)
    assert r.returncode == cli.EXIT_USAGE
    assert r.stderr.startswith("error: ") and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "Traceback" not in r.stderr
    assert any("no_such_scenario" in ln for ln in _served_lines(tmp)[before:])


def test_another_import_time_environment_runs_alone(server):
    tmp, env, _ = server
    # another BLAS kernel than the server's, whichever the suite runs with
    other_kernel = "Sandybridge" if env.get("OPENBLAS_CORETYPE") == "Haswell" else "Haswell"
    before = len(_served_lines(tmp))
    r = _testbed(["run", "michaelis_menten", "--out", "other-kernel", "--no-figures"],
                 {**env, "OPENBLAS_CORETYPE": other_kernel}, tmp)
    assert r.returncode == 0, r.stderr
    new = _served_lines(tmp)[before:]
    assert any("refused a command from another key" in ln for ln in new), new
    assert (tmp / "other-kernel" / "michaelis_menten").is_dir()


def test_a_killed_client_leaves_no_process(server):
    tmp, env, _ = server
    before = len(_served_lines(tmp))
    # a five-bar generation into an empty cache takes seconds: long enough to kill the client
    client = subprocess.Popen([sys.executable, "-m", "testbed.cli", "run", "fivebar_multisine",
                               "--out", "killed", "--cache", str(tmp / "empty-cache")],
                              env=env, cwd=tmp, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    t0 = time.monotonic()
    while not any("(pid " in ln for ln in _served_lines(tmp)[before:]):
        assert time.monotonic() - t0 < 60 and client.poll() is None
        time.sleep(0.05)
    (line,) = [ln for ln in _served_lines(tmp)[before:] if "(pid " in ln]
    child = int(line.rsplit("(pid ", 1)[1].rstrip(")"))
    client.send_signal(signal.SIGKILL)
    client.wait()
    t0 = time.monotonic()
    while _alive(child):
        assert time.monotonic() - t0 < 10, f"served child {child} outlived its client"
        time.sleep(0.05)


def _alive(pid: int) -> bool:
    return alive(pid)  # a zombie is reaped soon by the server


def test_serve_refuses_a_shared_socket_folder(tmp_path, monkeypatch, capsys):
    shared = tmp_path / "shared"
    shared.mkdir(mode=0o755)
    shared.chmod(0o755)
    monkeypatch.setenv("TESTBED_SERVER_SOCKET", str(shared / "s.sock"))
    assert cli.main(["serve", "--warm-up", "none"]) == cli.EXIT_USAGE
    err = capsys.readouterr().err
    assert err.startswith("error: ") and "0700" in err and str(shared) in err


def test_a_second_server_on_the_socket_is_refused(server):
    tmp, env, proc = server
    r = _testbed(["serve", "--warm-up", "none"], env, tmp)
    assert r.returncode == cli.EXIT_USAGE
    assert r.stderr.startswith("error: ") and "already listening" in r.stderr, r.stderr
    assert proc.poll() is None and (tmp / "sock" / "s.sock").exists()  # the first one serves on


# ---------------------------------------------------------------- hostile clients, dying servers
# A server of the real loop that imports nothing and whose commands sleep (``sleep SECONDS``, or
# ``sleep FILE``: until the test makes FILE, for a command that must run until the test is done
# with it): it starts in about a second, so these tests can kill it.
_FAKE = """
import os, sys, time
import testbed.cli as c, testbed.server as s
c._blas_threads()  # as `testbed serve` (cli.main) does before serving: part of the key
s._preload = lambda: None
def main(argv):  # sleep SECONDS|FILE [STATUS [AT-EXIT-TEXT]]: SECONDS, or until FILE exists
    try:
        time.sleep(float(argv[1]))
    except ValueError:
        while not os.path.exists(argv[1]):
            time.sleep(0.01)
    print("slept", flush=True)
    if len(argv) > 3:  # printed at exit (a command alone prints it; loky's exit hooks are such)
        import atexit
        atexit.register(print, argv[3], flush=True)
    return int(argv[2]) if len(argv) > 2 else 0
s.serve(main, idle=60, warm_up=None)
"""


@pytest.fixture
def sleeper(tmp_path):
    """A sleeping-commands server (see ``_FAKE``): its process, environment, folder, log."""
    (tmp_path / "sock").mkdir(mode=0o700)
    env = _env(tmp_path)
    log = open(tmp_path / "log", "w+")
    proc = subprocess.Popen([sys.executable, "-c", _FAKE], env=env, cwd=tmp_path, stdout=log,
                            stderr=subprocess.STDOUT)
    t0 = time.monotonic()
    while "listening" not in (tmp_path / "log").read_text():
        assert proc.poll() is None, (tmp_path / "log").read_text()
        assert time.monotonic() - t0 < 60, "the server did not start"
        time.sleep(0.05)
    yield proc, env, tmp_path
    if proc.poll() is None:
        proc.kill()
    proc.wait()
    log.close()


def _client(env, cwd, *args):
    return subprocess.Popen([sys.executable, "-m", "testbed.cli", *args], env=env, cwd=cwd,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _wait_for(pred, what, timeout=20.0):
    t0 = time.monotonic()
    while not pred():
        assert time.monotonic() - t0 < timeout, what() if callable(what) else what
        time.sleep(0.02)


def _pids(tmp: Path) -> list[int]:
    return [int(ln.rsplit("(pid ", 1)[1].rstrip(")")) for ln in _served_lines(tmp) if "(pid " in ln]


def test_a_killed_server_stops_its_commands_and_each_client_says_so(sleeper):
    proc, env, tmp = sleeper
    clients = [_client(env, tmp, "sleep", "60") for _ in range(2)]
    _wait_for(lambda: len(_pids(tmp)) == 2, "two commands started")
    proc.kill()  # SIGKILL: the clients must not wait for their commands (nor one for the other's)
    for c in clients:
        out, err = c.communicate(timeout=10)
        assert c.returncode == 128 + signal.SIGKILL, err
        assert err.startswith("error: the testbed server ended") and err.count("\n") == 1, err
        assert "slept" not in out
    for pid in _pids(tmp):
        _wait_for(lambda p=pid: not _alive(p), f"command {pid} outlived its server", 10)


def test_a_stopped_server_stops_its_commands_and_each_client_says_so(sleeper):
    proc, env, tmp = sleeper
    c = _client(env, tmp, "sleep", "60")
    _wait_for(lambda: len(_pids(tmp)) == 1, "the command started")
    proc.terminate()
    assert proc.wait(timeout=10) == 0
    _, err = c.communicate(timeout=10)
    assert c.returncode == 128 + signal.SIGKILL and err.startswith("error: the testbed server ended")
    assert not (tmp / "sock" / "s.sock").exists()
    _wait_for(lambda: not _alive(_pids(tmp)[0]), "the command outlived its server", 10)


def _raw(env) -> socket.socket:
    s = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    s.connect(env["TESTBED_SERVER_SOCKET"])
    return s


def test_a_silent_client_does_not_hold_the_others(sleeper):
    proc, env, tmp = sleeper
    silent = _raw(env)  # connects and sends nothing (a stopped client, another program)
    try:
        c = _client(env, tmp, "sleep", "0", "1")
        out, err = c.communicate(timeout=30)
        assert (c.returncode, out) == (1, "slept\n"), err  # served, with its own status
    finally:
        silent.close()
    assert proc.poll() is None


def test_damaged_requests_are_refused_and_leave_no_descriptor(sleeper):
    import array
    import struct

    proc, env, _ = sleeper
    fds = lambda: len(os.listdir(f"/proc/{proc.pid}/fd"))  # noqa: E731
    before = fds()
    deep = b"[" * 200_000 + b"]" * 200_000  # past the JSON parser's recursion limit
    for body in (b"{not json", b"[1, 2]", b'{"key": "x"}', b'{"argv": 1}', deep):
        s = _raw(env)
        s.sendmsg([struct.pack("!I", len(body)) + body],
                  [(socket.SOL_SOCKET, socket.SCM_RIGHTS, array.array("i", (0, 1, 2)))])
        s.settimeout(10)
        assert b"a damaged request" in s.recv(1000)
        s.close()
    _wait_for(lambda: fds() == before, f"descriptors {before} -> {fds()}", 5)
    assert proc.poll() is None


def test_a_client_gone_before_the_reply_neither_stops_the_server_nor_runs(sleeper):
    from testbed.server import _send, server_key

    proc, env, tmp = sleeper
    s = _raw(env)
    request = {"argv": ["sleep", "60"], "cwd": str(tmp), "env": env, "umask": 0o022,
               "key": server_key(env)}
    _send(s, request, (0, 1, 2))
    s.close()  # before the server's reply
    _wait_for(lambda: len(_pids(tmp)) == 1, "the command started")
    _wait_for(lambda: not _alive(_pids(tmp)[0]), "a command without a client ran on", 10)
    c = _client(env, tmp, "sleep", "0")
    assert c.communicate(timeout=30)[0] == "slept\n" and c.returncode == 0
    assert proc.poll() is None


def test_ctrl_c_before_the_server_answers_is_one_line(tmp_path):
    (tmp_path / "sock").mkdir(mode=0o700)
    env = _env(tmp_path)
    mute = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)  # a server that never answers
    mute.bind(env["TESTBED_SERVER_SOCKET"])
    mute.listen(1)
    mute.settimeout(30)
    c = _client(env, tmp_path, "runs", "ls")  # (`list` is not served: it runs alone)
    conn, _ = mute.accept()
    conn.settimeout(30)
    assert conn.recv(4)  # the request came: the client now waits for the reply
    c.send_signal(signal.SIGINT)
    _, err = c.communicate(timeout=30)
    conn.close()
    mute.close()
    assert (c.returncode, err) == (cli.EXIT_INTERRUPTED, "error: interrupted\n")


def test_a_served_command_does_its_exit_work_before_its_client_returns(sleeper):
    _, env, tmp = sleeper  # (a served sweep's loky workers and resource tracker: stopped, silent)
    c = _client(env, tmp, "sleep", "0", "0", "at exit")
    out, err = c.communicate(timeout=30)
    assert (c.returncode, out, err) == (0, "slept\nat exit\n", "")


def test_changed_sources_end_the_server_after_its_running_commands(sleeper):
    proc, env, tmp = sleeper
    go = tmp / "go"  # the running command ends once the late one is refused (it slept 4 s)
    running = _client(env, tmp, "sleep", str(go), "0")
    _wait_for(lambda: len(_pids(tmp)) == 1, "the command started")
    source = ROOT / "testbed" / "server.py"
    st = source.stat()
    os.utime(source, ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000))  # "edited"
    try:
        # another command is refused (another key) and runs alone: here no 'sleep' command
        late = _testbed(["sleep", "0"], env, tmp)
        assert late.returncode == cli.EXIT_USAGE and "invalid choice: 'sleep'" in late.stderr
        assert running.poll() is None  # (it was running all along)
        go.touch()
        out, err = running.communicate(timeout=30)  # the running one ends as it would
        assert (running.returncode, out, err) == (0, "slept\n", "")
        assert proc.wait(timeout=10) == 0
    finally:
        os.utime(source, ns=(st.st_atime_ns, st.st_mtime_ns))  # (the module's server: its key)
        go.touch()  # (whatever failed: no command left waiting)
    assert any("sources changed" in ln for ln in _served_lines(tmp))
    assert not (tmp / "sock" / "s.sock").exists()


def test_a_closed_standard_stream_runs_alone(sleeper):
    _, env, tmp = sleeper  # (sent, the connection itself took its number: the command's output
    # went into it and the client reported a dead server)
    r = subprocess.run([sys.executable, "-m", "testbed.cli", "sleep", "0"], env=env, cwd=tmp,
                       stdin=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, timeout=60,
                       preexec_fn=lambda: os.close(1))
    assert r.returncode == cli.EXIT_USAGE and "invalid choice: 'sleep'" in r.stderr, r.stderr
    assert not _pids(tmp)


def test_ctrl_z_stops_the_command_with_its_client(sleeper):
    _, env, tmp = sleeper  # (the command is in its own process group: the terminal stops only
    # the client, and before this the command ran on in the background)
    # the client in a process group of its own, as a shell starts a job: the kernel discards a
    # SIGTSTP whose default action would stop a process of an orphaned group (POSIX), which a
    # test worker's group can be
    go = tmp / "go"  # the command ends once resumed and told to (it slept 3 s)
    c = subprocess.Popen([sys.executable, "-m", "testbed.cli", "sleep", str(go)], env=env, cwd=tmp,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, process_group=0)
    _wait_for(lambda: len(_pids(tmp)) == 1, "the command started")
    # (a Ctrl-Z before the client has the pid, as here under load, waits for it)
    c.send_signal(signal.SIGTSTP)
    _wait_for(lambda: state(c.pid) == "T" and state(_pids(tmp)[0]) == "T",
              lambda: f"both stopped (client {state(c.pid)}, command {state(_pids(tmp)[0])})", 10)
    time.sleep(0.5)
    assert c.poll() is None and state(_pids(tmp)[0]) == "T"  # (not resumed by anything else)
    c.send_signal(signal.SIGCONT)
    go.touch()
    out, err = c.communicate(timeout=30)
    assert (c.returncode, out, err) == (0, "slept\n", "")


def test_another_scenario_folder_runs_alone(sleeper):
    _, env, tmp = sleeper  # (read when testbed.pipeline.scenario loads: served, a command
    # listed and ran the server's scenarios, not the folder it was given)
    for var in ("TESTBED_SCENARIOS", "TESTBED_STUDIES"):
        r = _testbed(["sleep", "0"], {**env, var: str(tmp)}, tmp)
        assert r.returncode == cli.EXIT_USAGE and "invalid choice: 'sleep'" in r.stderr, r.stderr
    assert not _pids(tmp)
    assert sum("refused a command from another key" in ln for ln in _served_lines(tmp)) == 2


def _start_with(monkeypatch, peer_open: bool, log_fails: bool = False):
    """``server._start`` of a request whose forked child is a stand-in (a ``sleep`` in its own
    group), its client one end of a socket pair (closed when not ``peer_open``); returns the
    log lines, each with whether the client's end held the pid reply when it was written (with
    ``log_fails``, a log that raises OSError: whether the connection was registered at each
    call, in place of the lines), the
    stand-in's pid, and its status if ``_start`` stopped it (else None)."""
    import selectors

    from testbed import server

    stand_in = subprocess.Popen(["sleep", "30"], start_new_session=True)
    monkeypatch.setattr(server.os, "fork", lambda: stand_in.pid)
    conn, client = socket.socketpair(socket.AF_UNIX, socket.SOCK_STREAM)
    if not peer_open:
        client.close()
    lines: list[tuple[str, bool]] = []
    registered: list[bool] = []

    def log(text):
        registered.append(conn.fileno() in {k.fd for k in st.sel.get_map().values()})
        if log_fails:
            raise OSError(28, "No space left on device")
        held = False
        if peer_open:
            try:
                held = bool(client.recv(64, socket.MSG_PEEK | socket.MSG_DONTWAIT))
            except BlockingIOError:
                pass
        lines.append((text, held))

    st = server._Server.__new__(server._Server)
    st.log, st.running, st.sel = log, {}, selectors.DefaultSelector()
    try:
        server._start(st, conn, {"argv": ["sleep", "60"]}, [])
        ended = None  # the stand-in's status if _start stopped it (within 5 s), else None
        with contextlib.suppress(subprocess.TimeoutExpired):
            ended = stand_in.wait(timeout=0.05 if peer_open else 5)
        return (registered if log_fails else lines), stand_in.pid, ended
    finally:
        st.sel.close()
        conn.close()
        if peer_open:
            client.close()
        with contextlib.suppress(ProcessLookupError):
            os.killpg(stand_in.pid, signal.SIGKILL)
        stand_in.wait()


def test_a_commands_pid_line_is_logged_once_its_client_holds_the_pid(monkeypatch):
    # speed29: logged before the send, a server killed on seeing the line left its client
    # without the pid, and the client ran the command alone
    lines, pid, ended = _start_with(monkeypatch, peer_open=True)
    assert lines == [(f"testbed server: sleep 60 (pid {pid})", True)] and ended is None


def test_a_commands_pid_line_is_logged_when_its_client_left_before_the_reply(monkeypatch):
    # the reverted fix (1912d47) logged only after a send that succeeded: a client that closed
    # first (EPIPE on a Unix socket) left no line, and test_server's watcher of the log waited
    lines, pid, ended = _start_with(monkeypatch, peer_open=False)
    assert [t for t, _ in lines] == [f"testbed server: sleep 60: its client left before its pid "
                                     f"was sent, so the command was stopped (pid {pid})"]
    assert ended == -signal.SIGKILL


def test_a_commands_connection_is_registered_before_its_pid_line_is_logged(monkeypatch):
    # review 29a L1: logged first, a log that raised OSError (a full disk) left the command
    # unregistered, never stopped when its client died; the OSError no longer escapes _start
    registered, _pid, ended = _start_with(monkeypatch, peer_open=True, log_fails=True)
    assert registered == [True] and ended is None
