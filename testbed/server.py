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
  numba, MuJoCo, matplotlib, ``PYTHON*``, ``TESTBED_*``); otherwise, or if no server
  answers, it runs the command itself.  A server whose sources changed refuses new commands
  and exits when its running ones have ended;
- only the user who started it may use it (the socket's folder is private, mode 0700, and the
  server checks each client's uid with ``SO_PEERCRED``);
- Ctrl-C in the client is sent on to the child (the command ends as it would alone, status
  130); Ctrl-Z stops the command's process group with the client, ``fg`` resumes both; a
  client that dies (``kill -9`` included) has its child's process group killed by the server,
  so no process is left behind; the server exits after ``idle`` seconds without a command,
  removing its socket;
- a server that dies (``kill -9`` included) or is stopped takes its running commands with it
  (``PR_SET_PDEATHSIG``; the client also kills the command's group) and each client prints one
  line, status :data:`SERVER_GONE_STATUS`; a signal that reaches the client before the server
  started its command ends the client as it would alone (Ctrl-C: one line, status 130);
- the server never waits on one client: a request is read when it has arrived, a connection
  that sends nothing is dropped after :data:`REQUEST_TIMEOUT_S`, a damaged request is refused
  (its descriptors closed), a client gone before the reply has its command killed;
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
from collections.abc import Callable
from pathlib import Path

__all__ = ["IMPORT_TIME_VARIABLES", "serve", "server_key", "socket_path", "try_server"]

#: Environment variables read when the libraries load (or by the interpreter at start): a
#: served command sees the server's values of these, so any difference sends the command to
#: run by itself.
IMPORT_TIME_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS",
                         "OPENBLAS_CORETYPE", "MUJOCO_GL", "MPLBACKEND", "MPLCONFIGDIR")
#: Prefixes of further import-time variables (numba's JIT and cache settings, the interpreter's,
#: the testbed's own: ``TESTBED_SCENARIOS`` and ``TESTBED_STUDIES`` are read when their modules
#: load, so a served command with other ones listed and ran the server's scenarios).
IMPORT_TIME_PREFIXES = ("NUMBA_", "PYTHON", "TESTBED_")
#: The server's own variables: not keyed (a client that sees them set uses the server anyway).
SERVER_VARIABLES = ("TESTBED_SERVER_SOCKET", "TESTBED_NO_SERVER")
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
        if (k in IMPORT_TIME_VARIABLES or k.startswith(IMPORT_TIME_PREFIXES)) and k not in SERVER_VARIABLES:
            h.update(f"{k}={env[k]}".encode())
    return h.hexdigest()


def _send(sock: socket.socket, obj: dict, fds: tuple[int, ...] = ()) -> None:
    data = json.dumps(obj).encode()
    msg = struct.pack("!I", len(data)) + data
    if fds:
        sock.sendmsg([msg], [(socket.SOL_SOCKET, socket.SCM_RIGHTS, array.array("i", fds))])
    else:
        sock.sendall(msg)


def _recv(sock: socket.socket, with_fds: int = 0,
          deadline: float | None = None) -> tuple[dict | None, list[int]]:
    """One framed JSON message (and up to ``with_fds`` descriptors); None at end of stream.

    ``deadline`` (a :func:`time.monotonic` instant) bounds the whole read, not each piece: a
    socket timeout alone let a peer sending a byte every 1.5 s hold the server, and every
    client waiting on it, for as long as it liked (round 11: 15 s for a 100-byte request, one
    command waiting throughout); past it ``TimeoutError`` (an OSError) is raised.
    """
    def recv(n: int) -> bytes:
        if deadline is not None:
            left = deadline - time.monotonic()
            if left <= 0:
                raise TimeoutError("the request did not arrive in time")
            sock.settimeout(left)
        return sock.recv(n)

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
        more = recv(4 - len(head))
        if not more:
            return None, fds
        head += more
    (n,) = struct.unpack("!I", head)
    if n > MAX_REQUEST:
        return None, fds
    body = b""
    while len(body) < n:
        more = recv(n - len(body))
        if not more:
            return None, fds
        body += more
    try:
        return json.loads(body), fds
    except (ValueError, RecursionError):  # garbage or nested past the parser's stack (a
        return None, fds                  # damaged request); the caller closes the descriptors


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
        The command's exit status, or None when no (matching) server took it.  A signal
        (Ctrl-C) before the server started the command ends it as alone (status 130 and one
        line for Ctrl-C); a server that ends while the command runs (killed, stopped) stops the
        command: one line, status :data:`SERVER_GONE_STATUS`.
    """
    if os.environ.get("TESTBED_NO_SERVER") or not sys.platform.startswith("linux"):
        return None
    path = socket_path()
    if not path.exists():
        return None
    if not all(_is_open(fd) for fd in (0, 1, 2)):
        return None  # a closed standard stream (``>&-``): alone the command sees it closed
    env = dict(os.environ)
    key = server_key(env)  # before connecting: a server waits for the request, not for this
    for s in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            s.flush()
    mask = os.umask(0o022)
    os.umask(mask)
    child: list[int] = []
    stop_pending: list[bool] = []

    def on_signal(signum, frame):  # forwarded: the command ends as it would alone
        if not child:
            raise _Signalled(signum)
        with contextlib.suppress(OSError):
            os.kill(child[0], signum)

    def on_stop(signum, frame):  # Ctrl-Z: the command (its whole group) stops with the client
        if not child:  # not started yet, or its pid on the way: stop both once it is known
            stop_pending.append(True)
            return
        with contextlib.suppress(OSError):
            os.killpg(child[0], signal.SIGSTOP)
            signal.signal(signal.SIGTSTP, signal.SIG_DFL)
            os.kill(os.getpid(), signal.SIGTSTP)  # stopped here until `fg` / SIGCONT
            signal.signal(signal.SIGTSTP, on_stop)
            os.killpg(child[0], signal.SIGCONT)

    old = {s: signal.signal(s, on_signal) for s in (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)}
    old[signal.SIGTSTP] = signal.signal(signal.SIGTSTP, on_stop)
    sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
    try:
        try:
            sock.connect(str(path))
            uid = struct.unpack("3i", sock.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED,
                                                      struct.calcsize("3i")))[1]
            if uid != os.getuid():
                return None
            _send(sock, {"argv": argv, "cwd": os.getcwd(), "env": env, "umask": mask,
                         "key": key}, (0, 1, 2))
            reply, _ = _recv(sock)
            if reply is None or "pid" not in reply:
                return None  # refused (another key) or gone: run here
            child.append(int(reply["pid"]))
            if stop_pending:  # a Ctrl-Z that came before the pid
                on_stop(signal.SIGTSTP, None)
        except OSError:
            return None
        except _Signalled as e:  # before the command started (the server kills it if it did)
            sock.close()
            return _as_alone(e.signum, old)
        with contextlib.suppress(OSError, ValueError):
            reply, _ = _recv(sock)
            if reply and "status" in reply:
                return int(reply["status"])
        # the server ended (or was killed) while the command ran: stop the command with it
        with contextlib.suppress(OSError):
            os.killpg(child[0], signal.SIGKILL)
        print(f"error: the testbed server ended while the command ran ({path}); the command was "
              "stopped: run it again", file=sys.stderr, flush=True)
        return SERVER_GONE_STATUS
    finally:
        for s, h in old.items():
            signal.signal(s, h)
        sock.close()


def _is_open(fd: int) -> bool:
    """Whether descriptor ``fd`` is open."""
    try:
        os.fstat(fd)
    except OSError:
        return False
    return True


#: A client's status when its server ended while the command ran (the command was killed:
#: 128 + SIGKILL, as a shell reports a killed command).
SERVER_GONE_STATUS = 128 + 9


class _Signalled(Exception):
    """A signal reached the client before the server started its command."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


def _as_alone(signum: int, handlers: dict) -> int:
    """End as the command alone would on ``signum`` before it did any work."""
    if signum == signal.SIGINT:
        from testbed.core.errors import EXIT_INTERRUPTED

        print("error: interrupted", file=sys.stderr, flush=True)
        return EXIT_INTERRUPTED
    signal.signal(signum, handlers.get(signum, signal.SIG_DFL))
    os.kill(os.getpid(), signum)  # SIGTERM / SIGHUP: killed by it, as alone
    return 128 + signum


# ---------------------------------------------------------------- server


def _preload() -> None:
    """Import what commands use, so that forked children find it loaded."""
    import importlib

    from testbed.reporting.mplconfig import ensure_config_dir

    ensure_config_dir()  # a folder matplotlib can write, before PRELOAD imports it
    for name in PRELOAD:
        importlib.import_module(name)
    from testbed.pipeline.plugins import IDENTIFIERS, RIGS

    RIGS.names(), IDENTIFIERS.names()  # the registries import their modules on first lookup


def _warm_up(scenario: str | None, log, command: Callable[[list[str]], int]) -> None:
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

    from testbed.core.errors import EXIT_FAIL
    from testbed.reporting import drawer

    tmp = tempfile.mkdtemp(prefix="testbed-server-warm-up-")
    try:
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()) as err:
            status = command(["run", scenario, "--out", tmp])
        if status not in (0, EXIT_FAIL):
            log(f"testbed server: warm-up skipped ({err.getvalue().strip()[:200]})")
        # the run's figures were drawn in forked processes: fonts and the PNG encoder are
        # loaded here too, and the frames of its figures (figure, axes, ticks) are made here,
        # so that each command's drawing processes inherit them (testbed.reporting.frames)
        drawer._warm_up()
        drawer.prepare_frames(Path(tmp) / scenario)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def _child(request: dict, fds: list[int], inherited: list, server: int,
           command: Callable[[list[str]], int]) -> None:
    """In the forked child: become the client's command, run it, exit with its status.

    ``inherited`` are the server's sockets, selector and descriptors, closed here: a child that
    held another client's connection would keep that client waiting after the server died.
    The child is killed with the server (``PR_SET_PDEATHSIG``); its client then says so.
    """
    from testbed.core.errors import EXIT_INTERNAL

    status = EXIT_INTERNAL
    try:
        from testbed.reporting.drawer import _die_with_parent

        os.setpgid(0, 0)  # its own group: the server can end it with everything it started
        _die_with_parent(server)
        for obj in inherited:
            with contextlib.suppress(OSError):
                if isinstance(obj, int):
                    os.close(obj)
                else:
                    obj.close()
        for target, fd in zip((0, 1, 2), fds, strict=True):
            os.dup2(fd, target)
        for fd in fds:
            if fd > 2:
                os.close(fd)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        signal.signal(signal.SIGCHLD, signal.SIG_DFL)
        signal.set_wakeup_fd(-1)
        sys.stdin = open(0, closefd=False)
        sys.stdout = open(1, "w", buffering=1 if os.isatty(1) else -1, closefd=False)
        sys.stderr = open(2, "w", buffering=1, errors="backslashreplace", closefd=False)
        why = _enter_folder(request["cwd"])
        if why:
            from testbed.core.errors import EXIT_USAGE

            print(why, file=sys.stderr)
            status = EXIT_USAGE
            return
        os.umask(int(request["umask"]))  # files are created as the client would create them
        os.environ.clear()
        os.environ.update(request["env"])
        sys.argv = ["testbed", *request["argv"]]
        status = command(list(request["argv"]))
    except SystemExit as e:
        status = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    except BaseException as e:  # one line, as the command itself would print
        with contextlib.suppress(BaseException):
            print(f"internal error (a bug, not your input): testbed server: {type(e).__name__}: {e}",
                  file=sys.stderr, flush=True)
    finally:
        with contextlib.suppress(BaseException):
            _exit_work()
        for s in (sys.stdout, sys.stderr):
            with contextlib.suppress(BaseException):
                s.flush()
        os._exit(status)


def _enter_folder(cwd: str) -> str:
    """``os.chdir(cwd)``; the one error line if it cannot be entered ("" if it was).

    The client's folder, removed (or made unreadable) after the client sent it, made the
    served command "internal error (a bug, not your input): ... FileNotFoundError" (round 11);
    alone the command says its current folder no longer exists, in one line, status 2.
    """
    try:
        os.chdir(cwd)
    except OSError as e:
        return (f"error: {cwd}: the current folder cannot be entered ({e.strerror}; deleted?); "
                "cd to a folder that exists")
    return ""


def _exit_work() -> None:
    """What the interpreter does at exit, which the command alone gets and ``os._exit`` skips.

    Joins the threads and runs their exit hooks (loky's executor: its workers stop), then the
    ``atexit`` functions (loky's and multiprocessing's resource trackers clean up).  Without it a
    served ``testbed sweep --jobs 2`` left its workers to notice their parent's death and its
    resource tracker to warn of "leaked" objects on the client's terminal after it returned.
    """
    import atexit
    import threading

    threading._shutdown()  # (private: the interpreter's own call at exit)
    atexit._run_exitfuncs()


class _Server:
    """A server's state: its listener, selector, and the clients it serves."""

    def __init__(self, listener: socket.socket, key: str, log, rfd: int, wfd: int,
                 command: Callable[[list[str]], int]) -> None:
        self.listener: socket.socket | None = listener
        self.key, self.log, self.rfd, self.wfd = key, log, rfd, wfd
        self.command = command
        self.sel = selectors.DefaultSelector()
        self.sel.register(listener, selectors.EVENT_READ, ("accept",))
        self.sel.register(rfd, selectors.EVENT_READ, ("signal",))
        self.running: dict[int, socket.socket] = {}  # child pid -> its client's connection
        self.pending: dict[socket.socket, float] = {}  # connected, no request yet -> deadline


#: Seconds a connected client has to send its request.  A client sends it at once; one that
#: connects and sends nothing (stopped, or not a testbed client) is dropped after this, and
#: meanwhile the server serves the others.
REQUEST_TIMEOUT_S = 10.0
#: Seconds the whole read of a readable request may take (a request is sent in one piece; an
#: environment larger than the socket's buffer arrives in a few, at once).
READ_TIMEOUT_S = 2.0


def serve(command: Callable[[list[str]], int], idle: float = IDLE_S, path: Path | None = None,
          log=None, warm_up: str | None = WARM_UP,
          warm_up_command: Callable[[list[str]], int] | None = None) -> int:
    """Listen for commands until ``idle`` seconds pass without one (or SIGTERM / Ctrl-C).

    When the sources change the server stops taking commands (clients then run alone), lets
    the running ones finish, and exits.  SIGTERM or Ctrl-C kill the running commands (their
    clients say so, status :data:`SERVER_GONE_STATUS`).

    Parameters
    ----------
    command : callable
        ``command(argv) -> status``, what runs a client's command in its forked child (and the
        warm-up): the command line's :func:`testbed.cli.main`, which ``testbed serve`` passes.
        The server is the command line's transport and does not import it.
    idle : float
        Seconds without a running or new command before the server exits.
    path : Path, optional
        The socket (default :func:`socket_path`).
    log : callable, optional
        ``log(text)`` for one line per command served (default: standard error).
    warm_up : str or None
        Scenario run once at start to warm the caches (:func:`_warm_up`); None: none.
    warm_up_command : callable, optional
        What runs the warm-up in the server's own process (default ``command``): ``testbed
        serve`` passes the command line's body without its signal handling, which the
        serving command already holds.

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
    for fd in (0, 1, 2):  # closed, it would be the number of a socket or of a client's stream
        if not _is_open(fd):
            os.open(os.devnull, os.O_RDWR)  # (the lowest free number: this one)
    start_env = dict(os.environ)  # as the client's: before the libraries set their defaults
    key = server_key(start_env)
    _refuse_if_served(path)
    _preload()
    _warm_up(warm_up, log, warm_up_command or command)
    _not_a_socket(path)  # (something other than a socket may have appeared meanwhile)
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
    st = _Server(listener, key, log, rfd, wfd, command)
    log(f"testbed server listening on {path} (exits after {idle:g} s idle)")
    last = time.monotonic()
    try:
        while not stop:
            now = time.monotonic()
            for conn in [c for c, t in st.pending.items() if t <= now]:
                _drop(st, conn)  # connected and sent nothing
            if st.listener is None and not st.running and not st.pending:
                break  # the sources changed and the last command ended
            waits = [t - now for t in st.pending.values()]
            if not st.running and not st.pending:
                if now - last >= idle:
                    break
                waits.append(idle - (now - last))
            try:
                events = st.sel.select(max(0.0, min(waits)) if waits else None)
            except KeyboardInterrupt:
                break
            for sk, _ in events:
                if sk.data[0] == "accept":
                    _accept(st)
                elif sk.data[0] == "signal":
                    with contextlib.suppress(BlockingIOError):
                        os.read(rfd, 512)
                elif sk.data[0] == "request":
                    _request(st, sk.fileobj)
                else:  # a running command's client readable: it went away (kill -9)
                    st.sel.unregister(sk.fileobj)  # (reaped below or at its SIGCHLD)
                    with contextlib.suppress(ProcessLookupError):
                        os.killpg(sk.data[1], signal.SIGKILL)
            _reap(st)
            if events:
                last = time.monotonic()  # idle counts from the last command's end
            if st.listener is not None and key != server_key(start_env):
                log("testbed server: the sources changed; no new commands, exiting after the "
                    "running ones")
                _stop_listening(st, path, inode)
    finally:
        for pid in st.running:
            with contextlib.suppress(ProcessLookupError):
                os.killpg(pid, signal.SIGKILL)
        for conn in [*st.running.values(), *st.pending]:
            conn.close()  # running: the client says the command was stopped; pending: runs alone
        _stop_listening(st, path, inode)
        signal.set_wakeup_fd(-1)
    return 0


def _stop_listening(st: _Server, path: Path, inode: int) -> None:
    """Take no more commands: close the listener and remove the socket (if still this one's)."""
    if st.listener is None:
        return
    st.sel.unregister(st.listener)
    with contextlib.suppress(FileNotFoundError):
        if path.stat().st_ino == inode:  # ours still (never another server's)
            path.unlink()
    st.listener.close()
    st.listener = None


def _not_a_socket(path: Path) -> None:
    """Refuse a ``path`` that holds something other than a socket: the server removes what is
    there before it binds, and a regular file, a FIFO, a link or a folder named by
    ``$TESTBED_SERVER_SOCKET`` was deleted (a file's content lost) or ended `testbed serve` in
    "[Errno 21] Is a directory" (round 14)."""
    import stat

    from testbed.core.errors import InputError

    try:
        mode = os.lstat(path).st_mode
    except FileNotFoundError:
        return
    except OSError as e:
        raise InputError(f"socket path {path} ($TESTBED_SERVER_SOCKET or the default): cannot be "
                         f"looked up ({e.strerror}); expected a free path or a server's socket") \
            from None
    if not stat.S_ISSOCK(mode):
        what = ("a folder" if stat.S_ISDIR(mode) else "a symbolic link" if stat.S_ISLNK(mode)
                else "a FIFO" if stat.S_ISFIFO(mode) else "a file" if stat.S_ISREG(mode)
                else "a device")
        raise InputError(f"socket path {path} ($TESTBED_SERVER_SOCKET or the default): holds "
                         f"{what}, which the server would remove; expected a free path or a "
                         "server's socket")


def _refuse_if_served(path: Path) -> None:
    """Refuse to start while another server answers at ``path``; remove a dead one's socket;
    refuse a path holding anything else (:func:`_not_a_socket`)."""
    from testbed.core.errors import InputError

    _not_a_socket(path)
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


def _accept(st: _Server) -> None:
    """Take a connection; its request is read when it arrives (never waited for here)."""
    try:
        conn, _ = st.listener.accept()
    except OSError:
        return
    st.pending[conn] = time.monotonic() + REQUEST_TIMEOUT_S
    st.sel.register(conn, selectors.EVENT_READ, ("request",))


def _drop(st: _Server, conn: socket.socket) -> None:
    """Forget a connection whose request never came (its client, if any, runs alone)."""
    del st.pending[conn]
    st.sel.unregister(conn)
    conn.close()
    st.log("testbed server: dropped a connection that sent no command")


def _request(st: _Server, conn: socket.socket) -> None:
    """Read a readable connection's request; start its command, or refuse it."""
    del st.pending[conn]
    st.sel.unregister(conn)
    fds: list[int] = []
    try:
        uid = struct.unpack("3i", conn.getsockopt(socket.SOL_SOCKET, socket.SO_PEERCRED,
                                                  struct.calcsize("3i")))[1]
        conn.settimeout(READ_TIMEOUT_S)
        request, fds = _recv(conn, with_fds=3, deadline=time.monotonic() + READ_TIMEOUT_S)
        conn.settimeout(READ_TIMEOUT_S)  # the read left the deadline's last sliver (review)
        why = _refusal(uid, request, fds, st.key)
        if why:
            st.log(f"testbed server: refused a command from {why}")
            with contextlib.suppress(OSError):
                _send(conn, {"refused": why})
            conn.close()
            return
        _start(st, conn, request, fds)
    except (OSError, ValueError):  # (a timeout is an OSError)
        conn.close()
    finally:
        for fd in fds:
            with contextlib.suppress(OSError):
                os.close(fd)


def _refusal(uid: int, request, fds: list[int], key: str) -> str:
    """Why a request is not served ("" if it is)."""
    if uid != os.getuid():
        return "another user"
    r = request
    ok = (isinstance(r, dict) and len(fds) == 3 and isinstance(r.get("argv"), list)
          and all(isinstance(a, str) for a in r["argv"]) and isinstance(r.get("cwd"), str)
          and isinstance(r.get("env"), dict) and isinstance(r.get("umask"), int)
          and all(isinstance(k, str) and isinstance(v, str) for k, v in r["env"].items()))
    if not ok:
        return "a damaged request"
    bad = _bad_field(r)
    if bad:
        return f"a damaged request ({bad})"
    if r.get("key") != key:
        return "another key (sources, interpreter or import-time environment)"
    return ""


def _bad_field(r: dict) -> str:
    """What in a well-formed request the child could not apply ("" if nothing).

    Each of these made the forked child print "internal error (a bug, not your input)" (round
    11): a umask outside 0-0o777 (``os.umask``'s OverflowError; -1 or ``true`` were applied as
    0o777 and 1), a ``cwd`` that is not an absolute path or holds a NUL byte, an environment
    name that is empty or holds ``=`` or NUL, a value or argument holding NUL (the operating
    system's C strings cannot), a ``cwd`` or environment holding a lone surrogate the file
    system's encoding cannot hold (round 14).  The testbed's own client sends none of them.
    """
    if isinstance(r["umask"], bool) or not 0 <= r["umask"] <= 0o777:
        return "umask outside 0-0o777"
    if not r["cwd"].startswith("/") or "\0" in r["cwd"]:
        return "cwd not an absolute path"
    if not _encodable(r["cwd"]):
        return "a cwd the system cannot hold"
    if any(not k or "=" in k or "\0" in k or "\0" in v or not (_encodable(k) and _encodable(v))
           for k, v in r["env"].items()):
        return "an environment variable the system cannot hold"
    if any("\0" in a for a in r["argv"]):
        return "an argument holding a NUL byte"
    return ""


def _encodable(text: str) -> bool:
    """Whether ``text`` has a form in the file system's encoding: a lone surrogate such as
    ``\ud800`` in a request's environment or folder (JSON can carry one; the testbed's own
    client, decoding with ``surrogateescape``, sends none) made the child's ``os.environ`` or
    ``os.chdir`` an internal error (round 14)."""
    try:
        os.fsencode(text)
    except UnicodeEncodeError:
        return False
    return True


def _start(st: _Server, conn: socket.socket, request: dict, fds: list[int]) -> None:
    """Fork the command's child; tell the client its pid (or kill it if the client is gone)."""
    try:
        pid = os.fork()
    except OSError as e:
        st.log(f"testbed server: cannot fork ({e}); the command runs alone")
        with contextlib.suppress(OSError):
            _send(conn, {"refused": "cannot fork"})
        conn.close()
        return
    if pid == 0:
        _child(request, fds, [st.sel, *(s for s in (st.listener,) if s), conn, *st.running.values(),
                              *st.pending, st.rfd, st.wfd], os.getppid(), st.command)
    with contextlib.suppress(OSError):
        os.setpgid(pid, pid)  # (also done by the child: whichever runs first)
    st.running[pid] = conn
    command = " ".join(request["argv"])
    # The "(pid N)" line is written after the send, in both outcomes.  Before it (speed29's
    # find), a server killed on seeing the line could leave its client without the pid; that
    # client read the end of the connection as "no server took it" and ran the command alone.
    # Written only after a send that succeeded (1912d47, reverted), it was never written for a
    # client that had closed its end before the reply: on a Unix socket the send then fails at
    # once (EPIPE), so under load, where the close came first, a watcher of the log waited in
    # vain (test_server's "client gone before the reply" test, intermittently)
    try:
        _send(conn, {"pid": pid})
    except OSError:  # the client went away meanwhile (killed, Ctrl-C): so does its command
        with contextlib.suppress(ProcessLookupError):
            os.killpg(pid, signal.SIGKILL)
        with contextlib.suppress(OSError):
            st.log(f"testbed server: {command}: its client left before its pid was sent, so "
                   f"the command was stopped (pid {pid})")
        return
    # registered before the line: a log that raised (a full disk, a log file removed) left the
    # command unregistered, never stopped when its client died (review 29a L1)
    st.sel.register(conn, selectors.EVENT_READ, ("running", pid))
    with contextlib.suppress(OSError):
        st.log(f"testbed server: {command} (pid {pid})")


def _reap(st: _Server) -> None:
    """Send each ended child's exit status to its client."""
    while st.running:
        try:
            pid, status, usage = os.wait4(-1, os.WNOHANG)
        except ChildProcessError:
            return
        if pid == 0:
            return
        conn = st.running.pop(pid, None)
        if conn is None:
            continue
        st.log(f"testbed server: pid {pid} ended ({usage.ru_utime + usage.ru_stime:.2f} s of CPU)")
        with contextlib.suppress(KeyError, ValueError):
            st.sel.unregister(conn)
        with contextlib.suppress(OSError):
            code = os.waitstatus_to_exitcode(status)  # -N: killed by signal N (shell: 128 + N)
            _send(conn, {"status": code if code >= 0 else 128 - code})
        conn.close()
