"""A resident ``testbed`` process: commands forked from it skip the libraries' import.

``testbed run cantilever_stiff_impact`` spends about 0.8 s of CPU on its own work and the rest
importing the libraries it uses (scipy.signal, numba's cached kernels, MuJoCo, h5py, matplotlib;
``benchmarks/bench_cli.py``).  ``testbed serve`` imports them once and waits on a Unix socket;
while it runs, each ``testbed`` command sends it its arguments, working folder, environment and
its own standard input, output and error (``SCM_RIGHTS``), and the server forks a child that runs
the command exactly as :func:`testbed.cli.main` would in the client, writing straight to the
client's terminal or pipes.  The client waits for the child's exit status and returns it.  The
child is a fork of a process that has only imported modules, so a command's output, files and
exit status are those of the same command run alone (tested).

Rules, so that a served command is never a different command:

- the client uses a server only if the server's *key* equals its own: the Python executable, the
  project's source files (their paths, sizes and modification times) and every environment
  variable read when the libraries load (:data:`IMPORT_TIME_VARIABLES`: BLAS thread counts,
  numba, MuJoCo, matplotlib, ``PYTHON*``); otherwise, or if no server answers, it runs the
  command itself.  A server whose sources changed refuses and exits;
- only the user who started it may use it (the socket's folder is private, mode 0700, and the
  server checks each client's uid with ``SO_PEERCRED``);
- Ctrl-C in the client is sent on to the child (the command ends as it would alone, status
  130); a client that dies (``kill -9`` included) has its child's process group killed by the
  server, so no process is left behind; the server exits after ``idle`` seconds without a
  command, removing its socket;
- ``TESTBED_NO_SERVER=1`` makes a command run itself whatever is listening.

The child gets the client's arguments, folder, environment, umask and standard streams; not
its resource limits or priority.  Plugins named by ``--plugin`` or a study are loaded by each
child afresh; entry-point plugins installed after the server started need a new server.
"""

from __future__ import annotations

import array
import contextlib
import hashlib
import json
import os
import selectors
import signal
import socket
import struct
import sys
import time
from pathlib import Path

__all__ = ["IMPORT_TIME_VARIABLES", "serve", "server_key", "socket_path", "try_server"]

#: Environment variables read when the libraries load (or by the interpreter at start): a
#: served command sees the server's values of these, so any difference sends the command to
#: run by itself.
IMPORT_TIME_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS",
                         "OPENBLAS_CORETYPE", "MUJOCO_GL", "MPLBACKEND", "MPLCONFIGDIR")
#: Prefixes of further import-time variables (numba's JIT and cache settings, the interpreter's).
IMPORT_TIME_PREFIXES = ("NUMBA_", "PYTHON")
#: Default seconds a server waits for a command before it exits.
IDLE_S = 900.0
#: Modules a server imports at start (matplotlib picks the backend a command alone would:
#: ``MPLBACKEND`` is keyed).
PRELOAD = ("h5py", "matplotlib.pyplot", "scipy.signal", "testbed.reporting.drawer",
           "testbed.reporting.report", "testbed.scoring.run", "testbed.studies.runstore")
#: The scenario a server runs once at start to warm its caches (:func:`_warm_up`).
WARM_UP = "cantilever_stiff_impact"
#: Largest request accepted from a client [bytes] (argv, cwd and environment as JSON).
MAX_REQUEST = 1 << 20
_ROOT = Path(__file__).resolve().parent.parent
_SOURCES = ("testbed", "identify", "models")


def socket_path() -> Path:
    """The server's socket: ``$TESTBED_SERVER_SOCKET``, else a private per-user folder."""
    if os.environ.get("TESTBED_SERVER_SOCKET"):
        return Path(os.environ["TESTBED_SERVER_SOCKET"])
    base = os.environ.get("XDG_RUNTIME_DIR") or f"/tmp/testbed-{os.getuid()}"
    return Path(base) / "testbed-server.sock"


def server_key(env: dict[str, str] | None = None) -> str:
    """What a served command must share with the server (see the module docstring).

    Parameters
    ----------
    env : dict, optional
        The environment to key (default ``os.environ``).

    Returns
    -------
    str
        A SHA-256 hex digest.
    """
    env = os.environ if env is None else env
    h = hashlib.sha256(sys.executable.encode())
    for pkg in _SOURCES:
        for dirpath, dirnames, filenames in os.walk(_ROOT / pkg):
            dirnames[:] = sorted(d for d in dirnames if d != "__pycache__")
            for f in sorted(filenames):
                if f.endswith(".py"):
                    st = os.stat(os.path.join(dirpath, f))
                    h.update(f"{dirpath}/{f}:{st.st_size}:{st.st_mtime_ns}".encode())
    for k in sorted(env):
        if k in IMPORT_TIME_VARIABLES or k.startswith(IMPORT_TIME_PREFIXES):
            h.update(f"{k}={env[k]}".encode())
    return h.hexdigest()


def _send(sock: socket.socket, obj: dict, fds: tuple[int, ...] = ()) -> None:
    data = json.dumps(obj).encode()
    msg = struct.pack("!I", len(data)) + data
    if fds:
        sock.sendmsg([msg], [(socket.SOL_SOCKET, socket.SCM_RIGHTS, array.array("i", fds))])
    else:
        sock.sendall(msg)


def _recv(sock: socket.socket, with_fds: int = 0) -> tuple[dict | None, list[int]]:
    """One framed JSON message (and up to ``with_fds`` descriptors); None at end of stream."""
    fds: list[int] = []
    head = b""
    if with_fds:
        head, anc, _, _ = sock.recvmsg(4, socket.CMSG_SPACE(with_fds * array.array("i").itemsize))
        for level, kind, data in anc:
            if level == socket.SOL_SOCKET and kind == socket.SCM_RIGHTS:
                a = array.array("i")
                a.frombytes(data[:len(data) - len(data) % a.itemsize])
                fds.extend(a)
    while len(head) < 4:
        more = sock.recv(4 - len(head))
        if not more:
            return None, fds
        head += more
    (n,) = struct.unpack("!I", head)
    if n > MAX_REQUEST:
        return None, fds
    body = b""
    while len(body) < n:
        more = sock.recv(n - len(body))
        if not more:
            return None, fds
        body += more
    return json.loads(body), fds


# ---------------------------------------------------------------- client


def try_server(argv: list[str]) -> int | None:
    """Run ``argv`` in the resident server if one with this key listens; else None.

    Parameters
    ----------
    argv : list of str
        The command's arguments (without the program name).

    Returns
    -------
    int or None
        The command's exit status, or None when no (matching) server took it.
    """
    if os.environ.get("TESTBED_NO_SERVER") or not sys.platform.startswith("linux"):
        return None
    path = socket_path()
    if not path.exists():
        return None
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    try:
        sock.connect(str(path))
        uid = struct.unpack("3i", sock.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED,
                                                  struct.calcsize("3i")))[1]
        if uid != os.getuid():
            return None
        env = dict(os.environ)
        for s in (sys.stdout, sys.stderr):
            with contextlib.suppress(Exception):
                s.flush()
        mask = os.umask(0o022)
        os.umask(mask)
        _send(sock, {"argv": argv, "cwd": os.getcwd(), "env": env, "umask": mask,
                     "key": server_key(env)}, (0, 1, 2))
        reply, _ = _recv(sock)
        if reply is None or "pid" not in reply:
            return None  # refused (another key) or gone: run here
        child = int(reply["pid"])
    except OSError:
        sock.close()
        return None

    def forward(signum, frame):  # the command ends as it would alone
        with contextlib.suppress(OSError):
            os.kill(child, signum)

    old = {s: signal.signal(s, forward) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    try:
        while True:
            try:
                reply, _ = _recv(sock)
                break
            except InterruptedError:
                continue
        return int(reply["status"]) if reply and "status" in reply else 3
    finally:
        for s, h in old.items():
            signal.signal(s, h)
        sock.close()


# ---------------------------------------------------------------- server


def _preload() -> None:
    """Import what commands use, so that forked children find it loaded."""
    import importlib

    for name in PRELOAD:
        importlib.import_module(name)
    from testbed.pipeline.plugins import IDENTIFIERS, RIGS

    RIGS.names(), IDENTIFIERS.names()  # the registries import their modules on first lookup


def _warm_up(scenario: str | None, log) -> None:
    """Run one scored scenario with figures in a scratch folder, silently.

    What a first run in a process pays besides imports (numba loading its cached kernels, the
    filter designs' caches, matplotlib's fonts) is then paid once here, not by every command;
    these are caches of pure functions, so a command's results do not change (tested).  A
    warm-up that fails is logged and skipped: the server works without it.
    """
    if not scenario:
        return
    import io
    import shutil
    import tempfile

    from testbed import cli

    tmp = tempfile.mkdtemp(prefix="testbed-server-warm-up-")
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()) as err:
            status = cli._main(["run", scenario, "--out", tmp])
        if status not in (0, cli.EXIT_FAIL):
            log(f"testbed server: warm-up skipped ({err.getvalue().strip()[:200]})")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _child(conn: socket.socket, listener: socket.socket, request: dict, fds: list[int]) -> None:
    """In the forked child: become the client's command, run it, exit with its status."""
    from testbed import cli

    try:
        listener.close()
        os.setpgid(0, 0)  # its own group: the server can end it with everything it started
        for target, fd in zip((0, 1, 2), fds, strict=True):
            os.dup2(fd, target)
        for fd in fds:
            os.close(fd)
        conn.close()
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        signal.signal(signal.SIGCHLD, signal.SIG_DFL)
        signal.set_wakeup_fd(-1)
        os.chdir(request["cwd"])
        os.umask(int(request["umask"]))  # files are created as the client would create them
        os.environ.clear()
        os.environ.update(request["env"])
        sys.stdin = open(0, closefd=False)
        sys.stdout = open(1, "w", buffering=1 if os.isatty(1) else -1, closefd=False)
        sys.stderr = open(2, "w", buffering=1, errors="backslashreplace", closefd=False)
        sys.argv = ["testbed", *request["argv"]]
        status = cli.main(list(request["argv"]))
    except SystemExit as e:
        status = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    except BaseException as e:  # one line, as the command itself would print
        with contextlib.suppress(Exception):
            print(f"internal error (a bug, not your input): testbed server: {type(e).__name__}: {e}",
                  file=sys.stderr, flush=True)
        status = cli.EXIT_INTERNAL
    for s in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            s.flush()
    os._exit(status)


def serve(idle: float = IDLE_S, path: Path | None = None, log=None,
          warm_up: str | None = WARM_UP) -> int:
    """Listen for commands until ``idle`` seconds pass without one (or SIGTERM / Ctrl-C).

    Parameters
    ----------
    idle : float
        Seconds without a running or new command before the server exits.
    path : Path, optional
        The socket (default :func:`socket_path`).
    log : callable, optional
        ``log(text)`` for one line per command served (default: standard error).
    warm_up : str or None
        Scenario run once at start to warm the caches (:func:`_warm_up`); None: none.

    Returns
    -------
    int
        0.
    """
    log = log or (lambda text: print(text, file=sys.stderr, flush=True))
    path = path or socket_path()
    path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    if path.parent.stat().st_uid != os.getuid() or path.parent.stat().st_mode & 0o077:
        from testbed.core.errors import InputError

        raise InputError(f"{path.parent}: the server's socket folder must be private to you "
                         "(mode 0700); set TESTBED_SERVER_SOCKET to a path in one")
    start_env = dict(os.environ)  # as the client's: before the libraries set their defaults
    key = server_key(start_env)
    _refuse_if_served(path)
    _preload()
    _warm_up(warm_up, log)
    with contextlib.suppress(FileNotFoundError):
        path.unlink()  # (a server that started meanwhile loses its socket to this one)
    listener = _bind(path)
    inode = path.stat().st_ino
    rfd, wfd = os.pipe()
    os.set_blocking(wfd, False)
    signal.set_wakeup_fd(wfd)
    signal.signal(signal.SIGCHLD, lambda *a: None)
    stop = []
    signal.signal(signal.SIGTERM, lambda *a: stop.append(1))
    sel = selectors.DefaultSelector()
    sel.register(listener, selectors.EVENT_READ, "accept")
    sel.register(rfd, selectors.EVENT_READ, "signal")
    running: dict[int, socket.socket] = {}  # child pid -> its client's connection
    log(f"testbed server listening on {path} (exits after {idle:g} s idle)")
    last = time.monotonic()
    try:
        while not stop:
            timeout = None if running else max(0.0, idle - (time.monotonic() - last))
            if not running and timeout == 0.0:
                break
            try:
                events = sel.select(timeout)
            except KeyboardInterrupt:
                break
            for sk, _ in events:
                if sk.data == "accept":
                    _accept(listener, key, sel, running, log)
                elif sk.data == "signal":
                    with contextlib.suppress(BlockingIOError):
                        os.read(rfd, 512)
                else:  # a client's connection readable: it went away (kill -9)
                    pid = sk.data
                    with contextlib.suppress(ProcessLookupError):
                        os.killpg(pid, signal.SIGKILL)
            _reap(sel, running, log)
            if events:
                last = time.monotonic()  # idle counts from the last command's end
            if key != server_key(start_env):
                log("testbed server: the sources changed; exiting")
                break
    finally:
        for pid in running:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(pid, signal.SIGKILL)
        with contextlib.suppress(FileNotFoundError):
            if path.stat().st_ino == inode:  # ours still (never another server's)
                path.unlink()
        listener.close()
        signal.set_wakeup_fd(-1)
    return 0


def _refuse_if_served(path: Path) -> None:
    """Refuse to start while another server answers at ``path``; remove a dead one's socket."""
    from testbed.core.errors import InputError

    if path.exists():
        probe = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            probe.connect(str(path))
        except OSError:
            path.unlink()  # left by a server that was killed
        else:
            raise InputError(f"{path}: a testbed server is already listening there; stop it "
                             "first, or set TESTBED_SERVER_SOCKET to another path")
        finally:
            probe.close()


def _bind(path: Path) -> socket.socket:
    """A listening socket at ``path`` (bound after the warm-up: until then clients run alone)."""
    listener = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    listener.bind(str(path))
    listener.listen(16)
    return listener


def _accept(listener, key, sel, running, log) -> None:
    conn, _ = listener.accept()
    try:
        uid = struct.unpack("3i", conn.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED,
                                                  struct.calcsize("3i")))[1]
        request, fds = _recv(conn, with_fds=3)
        why = ("another user" if uid != os.getuid() else "a damaged request"
               if request is None or len(fds) != 3 else "another key (sources, interpreter or "
               "import-time environment)" if request.get("key") != key else "")
        if why:
            for fd in fds:
                os.close(fd)
            _send(conn, {"refused": why})
            conn.close()
            log(f"testbed server: refused a command from {why}")
            return
    except (OSError, ValueError):
        conn.close()
        return
    pid = os.fork()
    if pid == 0:
        _child(conn, listener, request, fds)
    for fd in fds:
        os.close(fd)
    with contextlib.suppress(OSError):
        os.setpgid(pid, pid)  # (also done by the child: whichever runs first)
    _send(conn, {"pid": pid})
    running[pid] = conn
    sel.register(conn, selectors.EVENT_READ, pid)
    log(f"testbed server: {' '.join(request['argv'])} (pid {pid})")


def _reap(sel, running, log) -> None:
    """Send each ended child's exit status to its client."""
    while running:
        try:
            pid, status, usage = os.wait4(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return
        conn = running.pop(pid, None)
        if conn is None:
            continue
        log(f"testbed server: pid {pid} ended ({usage.ru_utime + usage.ru_stime:.2f} s of CPU)")
        sel.unregister(conn)
        with contextlib.suppress(OSError):
            code = os.waitstatus_to_exitcode(status)  # -N: killed by signal N (shell: 128 + N)
            _send(conn, {"status": code if code >= 0 else 128 - code})
        conn.close()
