"""The ``testbed`` command: a thin face over the library (no logic of its own).

Every command maps to one library call.  A user's mistake (a bad scenario or study file,
an unknown name, a missing folder, a file that is not a dataset, a bad option value, an
unreachable Dask scheduler) prints one line ``error: ...`` and exits with status 2, never
a traceback.  A bug prints one line saying it is an internal error and exits with status
3; the global ``--debug`` flag re-raises it with its traceback.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import errno
import functools
import gc
import os
import re
import signal
import socket
import stat
import sys
import threading
import warnings
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any
from urllib.parse import urlsplit

from testbed.core import interrupts  # armed on import by testbed/__init__.py, before this module
from testbed.core.atomic import (
    HDF5_FILE,
    HTML_FILE,
    IDENTIFIED_JSON_FILE,
    IDENTIFIED_MARKDOWN_FILE,
    SEP005_FILE,
    UFF_FILE,
    FileKind,
    refuse_foreign,
)
from testbed.core.errors import (
    EXIT_FAIL,
    EXIT_INTERNAL,
    EXIT_INTERRUPTED,
    EXIT_USAGE,
    InputError,
    ScenarioError,
    TestbedError,
    exception_text,
    printable,
    show_value,
    terminal_safe,
    unusable_path,
)
from testbed.core.exit_guard import late_exit_calls
from testbed.core.numbertext import plain_number
from testbed.core.registry import REGISTERED_NAME, REGISTERED_NAME_DOC

#: Status when the reader of standard output went away: a shell's for a command ended by SIGPIPE.
EXIT_BROKEN_PIPE = 128 + 13
#: Thread-count variables of the BLAS libraries numpy and scipy load (OpenBLAS, MKL, an OpenMP
#: build).  If the user sets none, a command runs its BLAS on one thread (:func:`_blas_threads`).
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "OMP_NUM_THREADS")
#: Seconds to wait for a Dask scheduler to accept a connection before calling it
#: unreachable: a live scheduler on a LAN answers in milliseconds.
DASK_CONNECT_TIMEOUT_S = 5.0


#: Namespace attribute where :class:`_StoreOnce` records the options given so far (removed
#: before the arguments are returned).
_GIVEN = "_testbed_options_given"


class _StoreOnce(argparse._StoreAction):
    """argparse's ``store`` that refuses an option given twice with another value.

    argparse keeps the last value in silence: ``sweep --jobs 1 ... --jobs 2`` ran on two
    processes, ``run --seed 1 --seed 2`` under seed 2, ``report -o a -o b`` wrote ``b``
    (round 11).  The same value twice changes nothing and passes; options that add up
    (``--plugin``, ``--param``) are ``append`` actions and unaffected.
    """

    def __call__(self, parser, namespace, values, option_string=None):
        given = namespace.__dict__.setdefault(_GIVEN, {})
        if self.dest in given and given[self.dest][1] != values:
            first, value = given[self.dest]
            raise argparse.ArgumentError(
                self, f"given twice ({first} {show_value(value)}, then {option_string} "
                      f"{show_value(values)}); give it once")
        given[self.dest] = (option_string, values)
        setattr(namespace, self.dest, values)


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (``error: ...``, status 2) instead of usage + message, and
    an option given twice with different values refused (:class:`_StoreOnce`)."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.register("action", None, _StoreOnce)
        self.register("action", "store", _StoreOnce)

    def parse_known_args(self, args=None, namespace=None):
        ns, rest = super().parse_known_args(args, namespace)
        ns.__dict__.pop(_GIVEN, None)
        # `run A --no-figures B`: argparse takes the names of a list positional (nargs "+")
        # in one run only, and B was refused as "unrecognized arguments" (round 22); names
        # left over are the list's when nothing else is left over
        # after a `--` every word is a positional's, as argparse reads it where no option came
        # before (review 27e: `runs ls -o DIR -- NAME` was "unrecognized arguments: -- NAME")
        literal = rest[:1] == ["--"]
        words = rest[1:] if literal else rest
        many = [a for a in self._actions if not a.option_strings and a.nargs in ("+", "*")]
        if words and len(many) == 1 and (literal or not any(r.startswith("-") for r in words)):
            setattr(ns, many[0].dest, [*(getattr(ns, many[0].dest) or []), *words])
            rest = words = []
        # `runs ls -o out/runs cantilever`: the same for an optional positional (nargs "?")
        # left empty when the positional before it was taken alone (round 27: "unrecognized
        # arguments: cantilever"); one name left over is its value
        maybe = [a for a in self._actions if not a.option_strings and a.nargs == "?"]
        # ("-" and "-1" too: argparse's own test, as it reads them in the first place)
        if (len(words) == 1 and (literal or self._parse_optional(words[0]) is None)
                and len(maybe) == 1 and getattr(ns, maybe[0].dest, None) is None):
            value = self._get_values(maybe[0], words)
            setattr(ns, maybe[0].dest, value)
            rest = []
        return ns, rest

    def error(self, message: str) -> None:  # type: ignore[override]
        print(f"error: {self.prog}: {_one_line(message)} (see {self.prog} --help)", file=sys.stderr)
        sys.exit(EXIT_USAGE)


def _plain_number(text: str) -> str:
    """``text`` if it is a number written in ASCII (:func:`testbed.core.numbertext.plain_number`:
    ``--seed \uff13`` ran seed 3 and ``--fs 1_000`` read 1000 Hz, round 19), else ValueError."""
    core = plain_number(text)
    if core is None:
        raise ValueError(text)
    return core


def _float(text: str) -> float:
    """An argparse type: a number written in ASCII (:func:`_plain_number`), as ``float()``."""
    try:
        return float(_plain_number(text))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number (ASCII digits), got "
                                         f"{show_value(text)}") from None


def _int_at_least(low: int, high: int | None = None) -> Callable[[str], int]:
    """An argparse type: an integer >= ``low`` (and <= ``high``), refused in one line otherwise."""

    def parse(text: str) -> int:
        try:
            value = int(_plain_number(text))
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected an integer >= {low}, "
                                             f"got {show_value(text)}") from None
        if value < low:  # (each value cut: a 4,000-digit one made a 4 kB line)
            raise argparse.ArgumentTypeError(f"expected an integer >= {low}, got {show_value(value)}")
        if high is not None and value > high:
            raise argparse.ArgumentTypeError(f"expected an integer <= {high}, got {show_value(value)}")
        return value

    return parse


def _path_text(text: str) -> str:
    """An argparse type for a path option: any text but the empty one, which names the current
    folder: `run --out ""` wrote its run and index among the user's files, `--cache ""` its
    datasets (a script's `--out "$DIR"` with the variable unset)."""
    if not text:
        raise argparse.ArgumentTypeError("an empty path; expected a file or folder name")
    if text[-1].isspace() and not os.path.lexists(text):
        # round 23: `--cache "c\n"` (a name pasted with its line end), `--out "runs "` or
        # `--cache " "` made a folder whose name ends in an invisible character, in silence; the
        # next command without it used another folder (the data simulated again, the runs
        # listed elsewhere).  A path that exists so is the user's own, and is taken.
        raise argparse.ArgumentTypeError(f"{text!r} ends in a blank or line end and "
                                         "names nothing yet; expected a name without trailing "
                                         "whitespace (or one that exists)")
    return text


def _nonempty(what: str) -> Callable[[str], str]:
    """An argparse type for a name or address: any text but the empty one (or blanks), which
    was taken as "not given": `sweep --dask ""` (a script's "$ADDR" unset) ran the sweep here,
    `serve --warm-up ""` skipped the warm-up (round 11)."""

    def parse(text: str) -> str:
        if not text.strip():
            raise argparse.ArgumentTypeError(f"an empty value; expected {what}")
        return text

    return parse


def _seed(text: str) -> int:
    """A noise seed: an integer >= 0 (numpy's generators take no negative seeds) that fits the
    64-bit integers datasets and results store, as a scenario's ``seed``
    (:data:`testbed.pipeline.scenario.MAX_SEED`)."""
    from testbed.pipeline.scenario import MAX_SEED

    return _int_at_least(0, MAX_SEED)(text)


#: Most sweep workers per CPU: each worker is a process that loads numpy, scipy and MuJoCo
#: (about 300 MB) and runs one thread, so more than a few per core only share it;
#: ``--jobs 100000`` started workers until the shared machine stalled (load 25).
JOBS_PER_CPU = 4

#: A worker count: an integer >= 1 and at most :data:`JOBS_PER_CPU` per CPU of this machine.
_jobs = _int_at_least(1, JOBS_PER_CPU * (os.cpu_count() or 1))

#: Longest ``serve --idle`` [s]: the selector's longest wait, 2^31 - 1 ms (about 24.8 days);
#: ``--idle inf`` was an internal error (OverflowError) after the warm-up.
MAX_IDLE_S = (2**31 - 1) / 1000


def _stat(path: Path, option: str = "") -> os.stat_result | None:
    """``path.stat()``, or None if nothing is there (a dangling link, a missing parent).

    Raises
    ------
    InputError
        For a path that can name nothing (a name too long for the file system, a NUL byte, a
        symbolic-link loop): an OSError or a RuntimeError from deep in a command before.
    """
    from testbed.core.errors import _one_line as escaped  # a NUL or newline shown escaped

    where = escaped(f"{option} {path}" if option else str(path))
    try:
        return path.stat()
    except (OSError, ValueError) as e:
        why = unusable_path(e)
        if why is None:
            return None
        raise InputError(f"{where}: not a usable path ({why})") from None


def _existing_file(path: Path, what: str) -> Path:
    st = _stat(path)
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise InputError(f"{path}: is a folder; expected {what}")
    if st is None:
        raise InputError(f"{path}: no such file; expected {what}")
    if not stat.S_ISREG(st.st_mode):  # a FIFO or a device: a read would block or never end
        raise InputError(f"{path}: not a regular file (a FIFO, socket or device); expected {what}")
    return path


def _writable_in(path: Path, option: str, start: Path) -> None:
    """Refuse ``path`` unless a file can be created in ``start`` or, if it does not exist yet,
    its nearest existing parent folder.

    Probed by creating (and removing) a temporary file there: permission bits alone do not
    tell root that ``/proc`` or a read-only mount refuses it.  A folder without a write
    permission bit is refused too: root's probe passes there (round 22).
    """
    import tempfile

    folder = start
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():
        raise InputError(f"{option} {path}: {folder} is a file, not a folder; expected a path in "
                         "a folder you can write")
    mode = folder.stat().st_mode
    if not mode & 0o222:  # as root the probe passes: chmod a-w was no guard
        raise InputError(f"{option} {path}: {folder} is read-only (mode "
                         f"{stat.S_IMODE(mode):04o}); expected a path in a "
                         "folder you can write")
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as e:
        raise InputError(f"{option} {path}: cannot write in {folder} "
                         f"({e.strerror or type(e).__name__}); expected a path in a folder you "
                         "can write") from None


#: The most symbolic links an output path is followed through (the kernel's MAXSYMLINKS).
MAX_LINKS = 40


def _link_target(path: Path, option: str) -> Path:
    """The path ``path`` names through its own symbolic links (``path`` if it is none).

    A link is followed only where it is owned by the current user or by the owner of the
    folder it lies in (the rule of the kernel's ``fs.protected_symlinks``, which a link read
    by the program itself bypasses): as root, ``generate -o`` a link another user planted in a
    shared folder had overwritten the root-only file it named (review 23a).  The folders on
    the way are the kernel's to follow (and to refuse).

    Raises
    ------
    InputError
        For a link of another user in another user's folder, or more than :data:`MAX_LINKS`.
    """
    me = os.geteuid() if hasattr(os, "geteuid") else None  # (Windows: no owners to compare)
    for _ in range(MAX_LINKS):
        if not path.is_symlink():
            return path
        owner, folder_owner = os.lstat(path).st_uid, os.stat(path.parent).st_uid
        if me is not None and owner not in (me, folder_owner):
            raise InputError(f"{option} {path}: a symbolic link of user {owner} in a folder of "
                             f"user {folder_owner}, which another user may have planted; "
                             f"expected a file path, or a link of yours (user {me}) or of the "
                             "folder's owner")
        path = path.parent / os.readlink(path)  # (a link's relative target: from its folder)
    raise InputError(f"{option} {path}: more than {MAX_LINKS} symbolic links on the way; "
                     "expected a file path")


def _foreign_output(path: Path, option: str, kind: FileKind) -> None:
    """Refuse an existing file at ``path`` that is not ``kind`` or cannot be read
    (:func:`~testbed.core.atomic.refuse_foreign`, the one such check), naming ``option``.  A
    file of the kind (an earlier run's output) or an empty one is replaced, as before."""
    refuse_foreign(path, kind, f"{option} {terminal_safe(str(path))}")


def _output_file(path: str | os.PathLike, option: str, *, inputs: tuple[Path, ...] = (),
                 kind: FileKind | None = None) -> Path:
    """A file a command will write, checked before any work: not a folder, not a device or
    FIFO (written atomically, the file would replace it: as root, ``--results /dev/full``
    replaced the device node), not one of its ``inputs`` (nothing the user gave is
    overwritten), in a folder that can be written.

    Round 22: not a text ending in a path separator (``-o out/`` wrote a file named ``out``),
    not a symbolic link to nothing (it was replaced by the file, the link lost), not a file
    without a write permission bit (as root, ``chmod a-w`` was no guard: the file was
    replaced and its mode with it).  Review 23a: nor a text ending in ``.`` or ``..``
    (``-o newdir/.`` wrote a file named ``newdir``).

    Returns
    -------
    Path
        The file to write: ``path``, or for a symbolic link the file it names
        (:func:`_link_target`; :func:`~testbed.core.atomic.atomic_write` replaces a link
        itself), whose folder is the one checked.
    """
    text = os.fspath(path)
    if isinstance(text, str) and text.endswith(("/", os.sep)):
        raise InputError(f"{option} {text}: ends in a path separator, which names a folder; "
                         "expected a file path")
    if isinstance(text, str) and os.path.basename(text) in (".", ".."):
        raise InputError(f"{option} {text}: ends in '{os.path.basename(text)}', which names a "
                         "folder; expected a file path")
    path = Path(path)
    st = _stat(path, option)
    if st is None and path.is_symlink():
        raise InputError(f"{option} {path}: a symbolic link to {os.readlink(path)}, which does not "
                         "exist; expected a file path (or a link to an existing file)")
    if st is not None and stat.S_ISDIR(st.st_mode):
        raise InputError(f"{option} {path}: is a folder; expected a file path")
    if st is not None and not stat.S_ISREG(st.st_mode):
        raise InputError(f"{option} {path}: exists and is not a regular file (a FIFO, socket or "
                         "device, which the written file would replace); expected a file path")
    if st is not None and not st.st_mode & 0o222:
        raise InputError(f"{option} {path}: exists and is read-only (mode "
                         f"{stat.S_IMODE(st.st_mode):04o}), which the written file would "
                         "replace; expected a writable file or a new path")
    for given in inputs:
        if path.resolve() == given.resolve():
            raise InputError(f"{option} {path}: is the input file; expected another path (the "
                             "input would be overwritten)")
    target = _link_target(path, option)
    # the folder written: a link's target's (a link to a file in a 0555 folder had passed, the
    # write then failing on its temporary file; the reverse refused: review 23a)
    _writable_in(path, option, target.parent)
    if kind is not None:  # last: the checks above name a link or a folder more precisely
        _foreign_output(target, option, kind)
    return target


def _given_files(*groups: Any) -> tuple[Path, ...]:
    """The files among ``groups`` of paths (scenario files read, ``--plugin`` files or
    modules): what a command's output must not replace.  A name ending in ``.toml`` or
    ``.py`` in any case, or any existing file (a module name is neither: ``s.TOML`` had been
    let through and replaced)."""
    return tuple(Path(p) for g in groups for p in g
                 if str(p).lower().endswith((".toml", ".py")) or os.path.isfile(p))


def _output_folder(path: Path, option: str) -> Path:
    """A folder a command will write into (created on use), checked before any work."""
    st = _stat(path, option)
    if st is not None and not stat.S_ISDIR(st.st_mode):
        raise InputError(f"{option} {path}: exists and is not a folder; expected a folder")
    for folder in (p := Path(os.path.abspath(path)), *p.parents):
        with contextlib.suppress(OSError):
            if (folder / "run.json").is_file():  # (runs written there were lost to its rewrite)
                raise InputError(f"{option} {path}: inside the run folder {folder}, which the "
                                 "run store replaces whole when it saves that run again; expected "
                                 "a folder outside any run")
    _writable_in(path, option, path)
    return path


def _is_not_folder(path: Path, option: str) -> bool:
    """Whether something other than a folder is at ``path`` (nothing there: False)."""
    st = _stat(path, option)
    return st is not None and not stat.S_ISDIR(st.st_mode)


def _cache_folder(cache: str | None) -> str | None:
    """A ``--cache`` folder, or without one ``$TESTBED_CACHE`` (created on use), must not be an
    existing file."""
    from testbed.pipeline.cache import default_cache_dir

    if cache is None and os.environ.get("TESTBED_CACHE") == "":
        # Path("") is the current folder: cache entries were written among the user's files
        # (`--cache ""` is refused by its option's type, :func:`_path_text`)
        raise InputError("$TESTBED_CACHE '': an empty path; expected the dataset cache folder "
                         "(unset it for the default)")
    if cache is not None and _is_not_folder(Path(cache), "--cache"):
        raise InputError(f"--cache {cache}: not a folder")
    if cache is None and _is_not_folder(default_cache_dir(), "$TESTBED_CACHE"):
        where = "$TESTBED_CACHE" if os.environ.get("TESTBED_CACHE") else "the default cache"
        raise InputError(f"{where} {default_cache_dir()}: not a folder; expected the dataset "
                         "cache folder")
    path = Path(cache) if cache is not None else default_cache_dir()
    where = "--cache" if cache is not None else (
        "$TESTBED_CACHE" if os.environ.get("TESTBED_CACHE") else "the default cache")
    _creatable_folder(path, where)
    return cache


def _creatable_folder(path: Path, where: str) -> None:
    """Refuse a folder that is missing and cannot be created: a symbolic link to nothing, or
    a file on its way.  Each was an OSError naming no option ("[Errno 17] File exists",
    "[Errno 20] Not a directory") after the simulation."""
    if path.is_dir():
        return
    if path.is_symlink():
        raise InputError(f"{where} {path}: a symbolic link to {os.readlink(path)}, which does not "
                         "exist; expected the dataset cache folder")
    folder = path.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent
    if not folder.is_dir():
        raise InputError(f"{where} {path}: {folder} is a file, not a folder; expected the dataset "
                         "cache folder")
    # a folder where nothing can be created (/proc, /sys): `run` ended in "error: [Errno 2] No
    # such file or directory: '/proc/x'" after its simulation, a sweep failed every cell with it
    # (round 12).  Probed by a file created and removed; a folder we may not write (EACCES,
    # EROFS) passes: a read-only cache serves what it holds (testbed.pipeline.cache)
    import tempfile

    from testbed.pipeline.cache import NOT_WRITABLE

    try:
        fd, probe = tempfile.mkstemp(prefix=".testbed-probe-", dir=folder)
    except OSError as e:
        if e.errno in NOT_WRITABLE:
            return
        raise InputError(f"{where} {path}: cannot be created in {folder} ({e.strerror or e}); "
                         "expected the dataset cache folder in a folder that holds files") from None
    os.close(fd)
    os.unlink(probe)


def _dataset_file(path: Path) -> Path:
    """A dataset file written by ``testbed generate`` (HDF5 of this format), else InputError."""
    import h5py

    from testbed.core.dataset import FORMAT

    _existing_file(path, "a dataset .h5 file written by `testbed generate`")
    if not h5py.is_hdf5(path):
        raise InputError(f"{path}: not an HDF5 file; expected a dataset written by `testbed generate`")
    try:
        with h5py.File(path, "r") as f:
            fmt = f.attrs.get("format")
    except OSError as e:
        raise InputError(f"{path}: cannot be read as HDF5: {e}") from None
    if fmt != FORMAT:
        raise InputError(f"{path}: an HDF5 file but not a testbed dataset (format {fmt!r}, "
                         f"expected {FORMAT!r})")
    return path


def _results_file(path: Path) -> Path:
    """A sweep results file that :func:`testbed.studies.results.read_results` can read, else InputError."""
    from testbed.studies.results import ResultsError, parts_dir, read_results

    # a sweep killed (SIGKILL, a lost machine) before its first consolidation leaves only its
    # rows, `<path>.parts/`: "no such file" refused them (round 12); the sweep resumes from them
    if _stat(path) is not None or not parts_dir(path).is_dir():
        _existing_file(path, "a sweep results file (from `testbed sweep`)")
    try:
        read_results(path)
    except ResultsError as e:  # with what is wrong with it (a column missing, a row damaged)
        why = str(e).removeprefix(f"{path}: ")
        raise InputError(f"{path}: not a sweep results file: {why}") from None
    except Exception as e:  # any failure to parse the user's file is a property of the file
        raise InputError(f"{path}: not a sweep results file ({type(e).__name__})") from None
    return path


def _run_folder(path: Path) -> Path:
    """A run folder :func:`testbed.studies.runstore.load_run` can read, else InputError."""
    from testbed.studies.runstore import load_run

    try:
        load_run(path)
    except ValueError as e:  # load_run's own checks (a JSONDecodeError is one too) say what
        # (the folder's path once: said again inside, it ate the 200 characters of the reason)
        why = _one_line(e).replace(f"{path}{os.sep}", "").removeprefix(f"{path}: ")
        raise InputError(f"{path}: not a run folder written by `testbed run` "
                         f"({type(e).__name__}: {why[:300]})") from None
    except Exception as e:  # any failure to read the user's folder is a property of the folder
        raise InputError(f"{path}: not a run folder written by `testbed run` "
                         f"({type(e).__name__})") from None
    return path


def check_dask_address(address: str) -> None:
    """Refuse a malformed or unreachable scheduler address before the sweep starts.

    Raises
    ------
    InputError
        If the address is not ``[tcp://]host:port`` or no scheduler accepts a TCP connection
        there within :data:`DASK_CONNECT_TIMEOUT_S` seconds.
    """
    try:  # "tcp://[::1" (an unclosed IPv6 bracket): urlsplit's ValueError, an internal error
        parts = urlsplit(address if "://" in address else f"tcp://{address}")
        host, port = parts.hostname, parts.port
    except ValueError:
        parts, host, port = None, None, None
    if parts is None or parts.scheme not in ("tcp", "tls") or not host or port is None:
        raise InputError(f"--dask {show_value(address)}: expected a scheduler address tcp://host:port")
    try:
        with socket.create_connection((host, port), timeout=DASK_CONNECT_TIMEOUT_S):
            pass
    except UnicodeError as e:  # a host name IDNA cannot encode (an empty label "a..b", one of
        # 64 characters, a lone surrogate): the idna codec's UnicodeError, an internal error
        raise InputError(f"--dask {show_value(address)}: host {show_value(host)} is not a host "
                         f"name ({e}); expected a scheduler address tcp://host:port") from None
    except OSError as e:
        raise InputError(f"--dask {show_value(address)}: cannot reach a Dask scheduler there "
                         f"({e.strerror or type(e).__name__})") from None
    if parts.scheme == "tcp":
        why = _dask_identity_problem(f"tcp://{parts.netloc}")
        if why is not None:
            raise InputError(f"--dask {show_value(address)}: no Dask scheduler answers there "
                             f"({why})")


def _dask_identity_problem(address: str) -> str | None:
    """Ask the server at ``address`` who it is (the Dask ``identity`` call); why it is no Dask
    scheduler, or None.  A port held by another server (an HTTP one) made the Dask client read
    its reply as a message length and ask for 3 EiB: a MemoryError, an internal error of
    ``sweep``; one that closed at once failed after the sweep had begun."""
    import asyncio

    from distributed.comm import connect

    async def identity() -> object:
        comm = await connect(address, timeout=DASK_CONNECT_TIMEOUT_S)
        try:
            await comm.write({"op": "identity"})
            return await asyncio.wait_for(comm.read(), DASK_CONNECT_TIMEOUT_S)
        finally:
            comm.abort()

    try:  # one time limit for it all: distributed's own handshake read waits for ever
        reply = asyncio.run(asyncio.wait_for(identity(), 2 * DASK_CONNECT_TIMEOUT_S))
    except TimeoutError:
        return f"no reply within {2 * DASK_CONNECT_TIMEOUT_S:g} s"
    except Exception as e:  # whatever the server sent, it is not a scheduler
        return f"{type(e).__name__}: {' '.join(str(e).split())[:120]}"
    if not (isinstance(reply, dict) and reply.get("type") == "Scheduler"):
        return f"it answered as {reply.get('type') if isinstance(reply, dict) else type(reply).__name__}"
    return None


@contextlib.contextmanager
def _rig_errors_name(sc) -> Iterator[None]:
    """A rig that cannot simulate the scenario's parameters (it diverged, the beam did not move)
    is the scenario file's problem: its error names the file."""
    from testbed.core.errors import RigError

    try:
        yield
    except RigError as e:
        raise RigError(f"{sc.path or sc.name}: {e}") from None


def _progress():
    from testbed.reporting.progress import progress_bar

    return progress_bar


def _load_plugins(args: argparse.Namespace) -> tuple[str, ...]:
    """Import the ``--plugin`` files/modules; return them (file paths made absolute)."""
    from testbed.pipeline.plugins import load_plugins

    given = tuple(getattr(args, "plugin", None) or ())
    load_plugins(given)
    return tuple(str(Path(p).resolve()) if p.endswith(".py") else p for p in given)


def _list_sections() -> tuple[list, list[str], list[str]]:
    """What `testbed list` prints, as ``(title, columns, rows)`` sections, and the files and
    folders it read beyond the modules it imported (for :func:`stamped_value`)."""
    from testbed.pipeline.plugins import IDENTIFIERS, RIGS, registry_folders
    from testbed.pipeline.scenario import SCENARIO_DIR, list_scenarios, recording_reads

    sections = []
    for title, registry in (("rigs", RIGS), ("identifiers", IDENTIFIERS)):
        rows = [(n, registry.get(n).kind, ", ".join(sorted(registry.tags(n))), registry.origin(n))
                for n in registry.names()]
        sections.append((title, ("name", "kind", "tags", "from"), rows))
    with recording_reads() as read:
        scenarios = list_scenarios(check_cost=False)  # budgets: at run time
    rows = [(s.name, s.rig, (s.identify or {}).get("method", "-"), f"{s.noise['rms_percent']:g}",
             s.description) for s in scenarios]
    sections.append(("scenarios", ("name", "rig", "identifier", "noise %", "description"), rows))
    return sections, read, [*registry_folders(), str(SCENARIO_DIR)]


def _list_shape(sections: object) -> bool:
    """Whether a kept listing has the shape :func:`_list_sections` gives (as JSON returns it):
    sections ``[title, columns, rows]`` of text, each row as long as its columns."""
    def texts(x: object) -> bool:
        return isinstance(x, list) and all(isinstance(v, str) for v in x)

    return isinstance(sections, list) and all(
        isinstance(sec, list) and len(sec) == 3 and isinstance(sec[0], str) and texts(sec[1])
        and isinstance(sec[2], list) and all(texts(r) and len(r) == len(sec[1]) for r in sec[2])
        for sec in sections)


def cmd_list(args: argparse.Namespace) -> int:
    if getattr(args, "plugin", None) or "models" in sys.modules or "identify" in sys.modules:
        # a plugin file's registrations, or a process that has the registries already (and may
        # hold registrations made in memory: a test's, a notebook's): listed afresh
        _load_plugins(args)
        sections = _list_sections()[0]
    else:
        # from the index while every file it was computed from is unchanged
        # (testbed.core.stamped: 0.1 s instead of importing every rig and identifier)
        from testbed.core.stamped import stamped_value

        sections = stamped_value("list", _list_sections, valid=_list_shape)
    if args.plain or not sys.stdout.isatty():
        # piped into another program: every field whole, tab-separated, one header per section
        for title, cols, rows in sections:
            print(f"# {title}")
            print("\t".join(cols))
            for r in rows:
                print("\t".join(r))
        return 0
    from rich.table import Table

    from testbed.core.terminal import make_console

    con = make_console()
    for title, cols, rows in sections:
        t = Table(title=title)
        for c in cols:
            t.add_column(c, overflow="fold")
        for r in rows:
            t.add_row(*r)
        con.print(t)
    return 0


def cmd_generate(args: argparse.Namespace) -> int:
    from testbed.pipeline.cache import DatasetCache
    from testbed.pipeline.generate import generate
    from testbed.pipeline.scenario import load_scenario, recording_reads
    from testbed.reporting.console import print_truth_summary

    plugins = _load_plugins(args)  # a plugin rig's scenario, as `run` takes it
    with recording_reads() as read:  # the scenario and the files it extends
        sc = load_scenario(args.scenario)
    if args.seed is not None:
        sc = sc.replace(seed=args.seed)
    # -o the scenario file itself (or a file it extends, or a plugin) replaced it with the
    # dataset, status 0 (round 17)
    out = _output_file(args.output or f"{sc.name}-seed{sc.seed}.h5", "--output",
                       inputs=_given_files(read, plugins), kind=HDF5_FILE)
    with _progress()(f"generating {sc.name}") as bar:
        # through the run cache unless --no-cache: a later `testbed run` of it simulates nothing
        cache = None if args.no_cache else DatasetCache(_cache_folder(args.cache))
        with _rig_errors_name(sc):
            ds = generate(sc, progress=bar) if cache is None else cache.get(sc, bar)
    ds.save(out)
    print_truth_summary(ds)
    print(f"wrote {terminal_safe(str(out))} (content hash {ds.attrs['content_hash'][:16]})")
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    from testbed.numerics.clipping import from_table
    from testbed.pipeline.cache import DatasetCache
    from testbed.pipeline.scenario import load_scenario
    from testbed.reporting.console import print_score_table
    from testbed.reporting.drawer import figure_drawer
    from testbed.reporting.progress import run_progress
    from testbed.reporting.report import runs_index_html
    from testbed.scoring.run import run_scenario
    from testbed.studies.runstore import INDEX, save_new_run, scenario_folder

    _load_plugins(args)
    _output_folder(Path(args.out), "--out")
    cache = None if args.no_cache else DatasetCache(_cache_folder(args.cache))
    ok = True
    # the figures are drawn by a process forked now: it imports matplotlib during the fit
    with figure_drawer(enabled=not args.no_figures) as figures:
        scenarios = [load_scenario(name) for name in args.scenario]  # every file checked first
        for sc in scenarios:
            if sc.identify is None:  # was found after simulating, naming the scenario, not its file
                raise ScenarioError(sc.path or sc.name, "identify",
                                    allowed="missing [identify] table: `testbed run` fits and "
                                            "scores an identifier (method = ...); `testbed "
                                            "generate` simulates a scenario without one")
        for sc in scenarios:
            if args.seed is not None:
                sc = sc.replace(seed=args.seed)
            scenario_folder(args.out, sc.name)  # refused before the work, not after
            refuse_foreign(Path(args.out) / INDEX, HTML_FILE,
                           expected="another --out folder, or remove the file")  # likewise
            if figures is not None:  # its frames made while the run computes
                figures.prepare(args.out, sc.name)
            with run_progress(sc.name) as phase:
                with _rig_errors_name(sc):
                    result = run_scenario(sc, cache=cache, phase=phase)
                with phase("figures" if figures else "save"):
                    run_dir = save_new_run(result, args.out, figures=figures, index=runs_index_html)
            print_score_table(result)
            for c in from_table(result.scores.details.get("clipped_sensors") or {}):
                print(f"warning: {terminal_safe(sc.name)}: {c.describe()} (the record's verdict "
                      "stands; a failed bar says so)", file=sys.stderr)
            print(f"run written to {terminal_safe(str(run_dir))} "
                  f"(all runs: {terminal_safe(str(Path(args.out) / INDEX))})")
            ok &= result.passed
    return 0 if ok else EXIT_FAIL


def cmd_report(args: argparse.Namespace) -> int:
    from testbed.reporting.report import refuse_foreign_outputs, write_report
    from testbed.studies.results import parts_dir
    from testbed.studies.runstore import RunStoreError, resolve_run

    source = Path(args.source)
    _output_folder(Path(args.output), "--output")
    # a name too long for the file system, a NUL or a link loop: one line naming it (round 13:
    # `--runs` of 5,000 characters was Path.is_dir's OSError 36, an internal error)
    _stat(source)
    if args.runs is not None:
        _stat(Path(args.runs), "--runs")
    if source.is_file() or (not source.exists() and parts_dir(source).is_dir()):
        _results_file(source)  # (only its rows, `<source>.parts/`: a sweep killed at once)
        if Path(args.output).resolve() == parts_dir(source).resolve():
            # the sweep's next consolidation deletes every file there but the *.bad ones
            raise InputError(f"--output {args.output}: the folder of {source}'s row files, whose "
                             "other files the sweep deletes; expected another folder")
    else:
        try:  # a run folder, a scenario's folder of runs (its latest) or a scenario name
            source = _run_folder(resolve_run(source, args.runs))
        except RunStoreError:
            if not source.exists():
                raise InputError(f"{source}: no such run folder or results file (nor a scenario "
                                 f"with runs in {args.runs})") from None
            raise InputError(f"{source}: not a run folder written by `testbed run`") from None
    # the user's own file of a report's name in the folder named (round 27: replaced in silence)
    refuse_foreign_outputs(args.output, option="--output")
    html = write_report(source, Path(args.output))
    print(f"report: {terminal_safe(str(html.resolve()))}")
    return 0


def cmd_export(args: argparse.Namespace) -> int:
    from testbed.reporting.export import export_dataset

    data = _dataset_file(Path(args.dataset))
    default = data.with_suffix(".uff" if args.format == "uff" else ".sep005.json")
    out = _output_file(args.output or default, "--output", inputs=(data,),
                       kind=UFF_FILE if args.format == "uff" else SEP005_FILE)
    for p in export_dataset(data, args.format, out, note=print):
        print(f"wrote {terminal_safe(str(p))}")
    return 0


def _stderr_line(line: str) -> None:
    """A progress line on standard error (a large family's drawing)."""
    print(line, file=sys.stderr, flush=True)


def cmd_sweep(args: argparse.Namespace) -> int:
    from testbed.studies.study import load_study
    from testbed.studies.sweep import SweepStats, run_sweep

    extra = _load_plugins(args)
    results = None
    if args.results:  # before the study's load, which simulates nothing but takes seconds
        results = _output_file(args.results, "--results")  # (a link: the file it names)
    study = load_study(args.study, progress=_stderr_line)
    if extra:  # the workers import them too
        study = dataclasses.replace(study, plugins=tuple(dict.fromkeys(study.plugins + extra)))
    stats = SweepStats()
    if args.dask:
        if args.jobs is not None:  # the Dask backend runs as many cells as the cluster has workers
            raise InputError(f"--jobs {args.jobs}: not with --dask (the scheduler's workers run "
                             "the cells; start as many workers as should run at once)")
        check_dask_address(args.dask)
    try:
        results = run_sweep(study, jobs=args.jobs or 1, dask_address=args.dask,
                            results=results,
                            cache_dir=_cache_folder(args.cache), retry_failed=args.retry_failed,
                            stats=stats)
    except (OSError, TimeoutError) as e:
        if not args.dask:
            raise
        # the port answered but no scheduler served it (or it went away): the address is wrong
        raise InputError(f"--dask {show_value(args.dask)}: the Dask scheduler failed: "
                         f"{type(e).__name__}: {e}") from None
    print(f"results: {terminal_safe(str(results))}")
    return EXIT_FAIL if stats.failed_total else 0


def cmd_summary(args: argparse.Namespace) -> int:
    from testbed.studies.statistics import print_summary

    print_summary(_results_file(Path(args.results)), by=args.by)
    return 0


def cmd_family(args: argparse.Namespace) -> int:
    from testbed.studies.study import load_study, write_family

    out = _output_folder(Path(args.out), "--out")
    paths = write_family(load_study(args.study, progress=_stderr_line), out, family=args.family)
    print(f"wrote {len(paths)} member scenario(s) to {terminal_safe(str(args.out))}; rerun one "
          f"with `testbed run {terminal_safe(str(paths[0] if paths else args.out))}`")
    return 0


def cmd_cache(args: argparse.Namespace) -> int:
    from testbed.pipeline.cache import DatasetCache

    cache = DatasetCache(_cache_folder(args.cache))
    if args.action == "ls":
        entries = cache.entries()
        for p, size in entries:
            print(f"{size / 1e6:8.2f} MB  {terminal_safe(str(p))}")
        print(f"{len(entries)} dataset(s) in {terminal_safe(str(cache.directory))}")
    else:
        print(f"removed {cache.clear()} dataset(s) from {terminal_safe(str(cache.directory))}")
    return 0


def _key_values(items: list[str] | None, option: str, *, numbers: bool) -> dict:
    """``KEY=VALUE`` options as a dict; a value is read as TOML (``3``, ``1e-3``, ``true``,
    ``"text"``), a bare word as a string; with ``numbers`` every value must be a number."""
    import tomllib

    out: dict = {}
    for item in items or []:
        key, sep, text = item.partition("=")
        if not sep or not key.strip():
            raise InputError(f"{option} {show_value(item)}: expected KEY=VALUE")
        if not text.strip():  # `--units acc1=` overrode the file's unit with none: "has no unit"
            raise InputError(f"{option} {show_value(item)}: no value after '='; expected KEY=VALUE")
        try:
            value = tomllib.loads(f"v = {text}")["v"]
        except (tomllib.TOMLDecodeError, ValueError):  # ValueError: over 4300 digits
            value = text
        if numbers and (isinstance(value, bool) or not isinstance(value, (int, float))):
            raise InputError(f"{option} {show_value(item)}: the value must be a number")
        if key.strip() in out:  # the last one silently won
            raise InputError(f"{option} {show_value(item)}: {show_value(key.strip())[1:-1]} is given "
                             "twice; give each key once")
        out[key.strip()] = float(value) if numbers else value
    return out


def cmd_identify(args: argparse.Namespace) -> int:
    import json

    from testbed.core.atomic import atomic_write_text
    from testbed.pipeline.fit import identify_file
    from testbed.pipeline.importers import clipping_lines
    from testbed.pipeline.scenario import load_scenario, recording_reads
    from testbed.reporting.identified import render_identified
    from testbed.reporting.progress import run_progress
    from testbed.scoring.scorers import fitted_model_failures, prediction_r2

    plugins = _load_plugins(args)
    units = None
    if args.units:
        per_channel = ["=" in u for u in args.units]
        if (any(per_channel) and not all(per_channel)) or (not any(per_channel) and len(args.units) > 1):
            raise InputError(f"--units {' '.join(args.units)}: expected one unit for every channel "
                             "(--units g) or one CHANNEL=UNIT per option, not both or several units")
        units = _key_values(args.units, "--units", numbers=False) if per_channel[0] else args.units[0]
        if isinstance(units, str) and not units.strip():
            raise InputError(f"--units {show_value(units)}: no unit; expected a unit for every "
                             "channel (--units g) or CHANNEL=UNIT")
        # after TOML parsing (review 25a): `x/x=""` is an empty text and `x/x=' '` a blank one,
        # which the raw text's check above let through to "channel ... has no unit"
        for name, unit in (units.items() if isinstance(units, dict) else ()):
            if isinstance(unit, str) and not unit.strip():
                raise InputError(f"--units {show_value(name)[1:-1]}={show_value(unit)}: no unit for channel "
                                 f"{show_value(name)}; expected CHANNEL=UNIT (--units "
                                 "acceleration/acc1=g)")
    data = _existing_file(Path(args.data), "a measured-data file (UFF58, SEP-005 JSON, CSV or HDF5)")
    # nor the --scenario file or a plugin (-o s.toml replaced the scenario: round 17)
    read: list[str] = []
    if args.scenario:  # the scenario and every file it extends (as `generate` protects them)
        with recording_reads() as read:
            load_scenario(args.scenario)
    given = (data, *_given_files(read, plugins))
    named = Path(args.output or f"{data.stem}.model.json")
    out = _output_file(named, "--output", inputs=given)  # (a link: the file it names)
    # the report beside the path named (a link's too); the same file as the model (round 17:
    # `-o m.md`; .MD: the same file where names ignore case, as on macOS and Windows; review
    # 23a: a link to its own report's path) replaced the model it reports
    if named.suffix.lower() == ".md":
        raise InputError(f"--output {terminal_safe(str(named))}: its report goes to the same path "
                         "with the suffix .md, so the report would replace the model; expected a "
                         "path not ending in .md (e.g. the default, <data>.model.json)")
    md = _output_file(named.with_suffix(".md"), "--output (its .md report)", inputs=given)
    if md.resolve() == out.resolve():
        raise InputError(f"--output {terminal_safe(str(named))}: names the file of its own report "
                         f"{terminal_safe(str(named.with_suffix('.md')))}, which would replace the "
                         "model; expected another path")
    _foreign_output(out, "--output", IDENTIFIED_JSON_FILE)
    _foreign_output(md, "--output (its .md report)", IDENTIFIED_MARKDOWN_FILE)
    with run_progress(data.name) as phase:
        result = identify_file(data, scenario=args.scenario, kind=args.kind, method=args.method,
                               params=_key_values(args.param, "--param", numbers=False),
                               format=args.format, fs=args.fs, units=units,
                               prior=_key_values(args.prior, "--prior", numbers=True), phase=phase)
    for line in clipping_lines(data, result.clipped):  # said, not refused: the model is written
        print(f"warning: {terminal_safe(line)}", file=sys.stderr)
    summary = result.summary()
    failures = fitted_model_failures(result.model, prediction_r2(result.model, result.data))
    if failures is not None:
        summary["physical_failures"] = failures
    text = json.dumps(summary, indent=1, allow_nan=True) + "\n"
    report = render_identified(summary)
    atomic_write_text(out, text)
    atomic_write_text(md, report)
    print(report, end="")
    print(f"model written to {terminal_safe(str(out))} (report {terminal_safe(str(md))})")
    if failures:
        what = ("unusable model" if set(failures) <= {"coefficients", "prediction"}
                else "physically impossible model")
        print(f"FAIL: {what}: {'; '.join(failures.values())}")
        return EXIT_FAIL
    return 0


def cmd_runs(args: argparse.Namespace) -> int:
    from testbed.studies.runstore import list_runs

    if args.out is None:  # the default folder: no runs yet is an empty history
        args.out = "out/runs"
    elif _stat(Path(args.out), "--out") is None:  # a folder the user named: a typo lists nothing
        raise InputError(f"--out {args.out}: no such folder; expected the folder of runs "
                         "(from `testbed run --out`)")
    if Path(args.out).exists() and not Path(args.out).is_dir():
        raise InputError(f"--out {args.out}: not a folder; expected the folder of runs "
                         "(from `testbed run --out`)")
    if args.scenario is not None and not re.fullmatch(REGISTERED_NAME, args.scenario):
        # "", a blank, a path or a newline named no scenario and listed an empty table in
        # silence (round 25)
        raise InputError(f"runs ls {show_value(args.scenario)}: not a scenario name; expected "
                         f"{REGISTERED_NAME_DOC} (the scenario's name, as `testbed runs ls` lists it)")
    damaged: list[Path] = []
    runs = list_runs(args.out, scenario=args.scenario, damaged=damaged)
    if damaged:  # left out of the table, but never silently
        print(f"warning: {len(damaged)} run folder(s) left out, their run.json is damaged, missing or of "
              f"another format: {', '.join(map(str, damaged))}", file=sys.stderr)
    if args.scenario is not None and not runs:
        # a name that matches no run (a typo, or a scenario not run yet) said so, not an empty
        # table alone (round 25); the listing on standard output stays as it was
        print(f"no runs of scenario {show_value(args.scenario)} in {terminal_safe(args.out)}",
              file=sys.stderr)
    cols = ("scenario", "seed", "time (UTC)", "identifier", "verdict", "path")
    rows = [(r["scenario"], str(r["seed"]), r["created"].replace("+00:00", "Z"), r["identifier"],
             r["verdict"], str(r["path"])) for r in runs]
    if args.plain or not sys.stdout.isatty():
        # piped into another program: every field whole, tab-separated, oldest first
        print("\t".join(cols))
        for row in rows:
            print("\t".join(row))
        return 0
    from rich.table import Table

    from testbed.core.terminal import make_console

    # a terminal: the run's folder name, not its whole path (the title says where it is)
    t = Table(title=f"{len(runs)} run(s), oldest first; folders {Path(args.out) / '<scenario>' / '<run>'}")
    for c in (*cols[:-1], "run"):
        t.add_column(c, overflow="fold")
    for r, row in zip(runs, rows, strict=True):
        t.add_row(*row[:-1], r["path"].name if r["path"].parent.name == r["scenario"]
                  else str(r["path"]))
    make_console().print(t)
    return 0


#: Longest socket path [bytes]: Linux's ``sockaddr_un.sun_path`` holds 108 bytes with the
#: terminating NUL; a longer $TESTBED_SERVER_SOCKET was an internal error (OSError).
MAX_SOCKET_PATH = 107


def cmd_serve(args: argparse.Namespace) -> int:
    from testbed.server import serve, socket_path

    where = socket_path()
    if len(os.fsencode(where)) > MAX_SOCKET_PATH:
        raise InputError(f"socket path {where} ($TESTBED_SERVER_SOCKET or the default): "
                         f"{len(os.fsencode(where))} bytes; expected at most {MAX_SOCKET_PATH} "
                         "(the longest Unix socket address)")

    if not 0 < args.idle <= MAX_IDLE_S:
        raise InputError(f"--idle {args.idle}: expected a positive number of seconds, at most "
                         f"{MAX_IDLE_S:g} (2^31 - 1 ms)")
    return serve(main, idle=args.idle, warm_up=None if args.warm_up == "none" else args.warm_up,
                 warm_up_command=_main)


def cmd_demo(args: argparse.Namespace) -> int:
    from testbed.reporting.demo import run_demo

    return run_demo(_output_folder(Path(args.out), "--out"))


def build_parser() -> argparse.ArgumentParser:
    from testbed import __version__

    plugin_help = ("import this plugin first: a .py file or a dotted module that registers "
                   "identifiers or rigs (repeatable)")
    p = _Parser(prog="testbed", description="Validate system-identification methods on physics "
                                            "simulations with exact ground truth; "
                                            "`testbed COMMAND --help` for each command.")
    p.add_argument("--version", action="version", version=f"testbed (sysid-testbed) {__version__}",
                   help="print the version and exit")
    p.add_argument("--debug", action="store_true",
                   help="show the traceback of an internal error instead of one line")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    ls = sub.add_parser("list", help="registered rigs, identifiers (with where each came from) and "
                                     "scenarios")
    ls.add_argument("--plugin", action="append", metavar="FILE.py", type=_path_text, help=plugin_help)
    ls.add_argument("--plain", action="store_true",
                    help="tab-separated lines, nothing cut (the default when not a terminal)")
    ls.set_defaults(fn=cmd_list)

    g = sub.add_parser("generate", help="simulate a scenario and write its dataset (HDF5)")
    g.add_argument("scenario", help="scenario name or .toml path")
    g.add_argument("-o", "--output", type=_path_text, help="output file (default <scenario>-seed<N>.h5)")
    g.add_argument("--seed", type=_seed, help="override the scenario's seed")
    # one or the other: with both, --no-cache won without a word (the cache named was not
    # filled; round 22)
    gc = g.add_mutually_exclusive_group()
    gc.add_argument("--cache", type=_path_text,
                    help="dataset cache folder it also fills (default .cache/datasets)")
    gc.add_argument("--no-cache", action="store_true", help="generate afresh, fill no cache")
    g.add_argument("--plugin", action="append", metavar="FILE.py", type=_path_text, help=plugin_help)
    g.set_defaults(fn=cmd_generate)

    r = sub.add_parser("run", help="generate or reuse data, identify, score, write figures")
    r.add_argument("scenario", nargs="+", help="scenario names or .toml paths")
    r.add_argument("-o", "--out", default="out/runs", type=_path_text,
                   help="folder for run results (default out/runs)")
    r.add_argument("--seed", type=_seed, help="override the scenario's seed")
    rc = r.add_mutually_exclusive_group()  # one or the other (round 22, as `generate`)
    rc.add_argument("--cache", type=_path_text,
                    help="dataset cache folder (default .cache/datasets or $TESTBED_CACHE)")
    rc.add_argument("--no-cache", action="store_true", help="generate afresh, store nothing")
    r.add_argument("--no-figures", action="store_true", help="skip the figures")
    r.add_argument("--plugin", action="append", metavar="FILE.py", type=_path_text, help=plugin_help)
    r.set_defaults(fn=cmd_run)

    i = sub.add_parser("identify", help="fit an identifier to measured data from a file (no truth "
                                        "needed): model, modal parameters, JSON")
    i.add_argument("data", help="measured data: .uff/.unv (UFF58), .json (SEP-005), .csv/.tsv/.txt, "
                                ".h5 (a testbed dataset: measured signals only)")
    i.add_argument("--scenario", help="scenario (name or .toml) whose rig kind, [signal] chain and "
                                      "[identify] table to use")
    i.add_argument("--kind", choices=("structural", "mechanical", "dynamical"),
                   help="rig kind of the data (which signal chain); needed without --scenario")
    i.add_argument("--method", help="registered identifier (see `testbed list`); default the "
                                    "scenario's")
    i.add_argument("--param", action="append", metavar="NAME=VALUE",
                   help="identifier hyperparameter, value as in TOML (repeatable)")
    i.add_argument("--fs", type=_float, help="sample rate [Hz] (needed for a CSV without a time column)")
    i.add_argument("--units", action="append", metavar="UNIT|CHANNEL=UNIT",
                   help="unit of every channel, or of one channel (repeatable), e.g. g, mm, N")
    i.add_argument("--prior", action="append", metavar="KEY=VALUE",
                   help="declared prior knowledge in SI units, e.g. total_mass=0.7 [kg] (repeatable)")
    i.add_argument("--format", choices=("uff", "sep005", "csv", "hdf5"),
                   help="file format (default from the suffix)")
    i.add_argument("-o", "--output", type=_path_text,
                   help="JSON file of the fitted model (default <data>.model.json)")
    i.add_argument("--plugin", action="append", metavar="FILE.py", type=_path_text, help=plugin_help)
    i.set_defaults(fn=cmd_identify)

    rep = sub.add_parser("report", help="HTML + markdown report of a run folder or sweep results")
    rep.add_argument("source", type=_path_text,
                     help="a run folder (from `testbed run`), a scenario's folder of runs "
                          "or a scenario name (its latest run), or a sweep results file")
    rep.add_argument("-o", "--output", required=True, type=_path_text, help="report folder")
    rep.add_argument("--runs", default="out/runs", type=_path_text,
                     help="where a scenario name's runs are (default out/runs)")
    rep.set_defaults(fn=cmd_report)

    e = sub.add_parser("export", help="export a dataset to UFF (58/55) or SEP-005 JSON")
    e.add_argument("dataset", help="dataset .h5 file")
    e.add_argument("--format", required=True, choices=("uff", "sep005"),
                   help="uff: UFF58 time records + UFF55 true modes; sep005: SEP-005 channels as JSON")
    e.add_argument("-o", "--output", type=_path_text, help="output file (default next to the dataset)")
    e.set_defaults(fn=cmd_export)

    s = sub.add_parser("sweep", help="run a method-comparison study (scenarios x noise x seeds x methods)")
    s.add_argument("study", help="study .toml file")
    s.add_argument("--jobs", type=_jobs, default=None,
                   help="parallel worker processes (joblib loky; default 1; not with --dask)")
    s.add_argument("--dask", type=_nonempty("a scheduler address, e.g. tcp://127.0.0.1:8786"),
                   help="dask.distributed scheduler address (runs through joblib's dask backend)")
    s.add_argument("--results", type=_path_text, help="results file (default out/studies/<study>.parquet)")
    s.add_argument("--cache", type=_path_text, help="dataset cache folder")
    s.add_argument("--retry-failed", action="store_true", help="run the cells recorded as failed again")
    s.add_argument("--plugin", action="append", metavar="FILE.py", type=_path_text, help=plugin_help)
    s.set_defaults(fn=cmd_sweep)

    sm = sub.add_parser("summary", help="median, spread and pass rate per identifier and noise level")
    sm.add_argument("results", help="results file of a sweep")
    sm.add_argument("--by", choices=("identifier", "scenario", "family"), default="identifier",
                    help="group rows per identifier (default), per scenario or per family, "
                         "each x identifier x noise")
    sm.set_defaults(fn=cmd_summary)

    fam = sub.add_parser("family", help="write the members of a study's scenario families")
    fam.add_argument("action", choices=("write",), help="write: one scenario file per member")
    fam.add_argument("study", help="study name or .toml path declaring [families.<name>]")
    fam.add_argument("-o", "--out", required=True, type=_path_text,
                     help="folder for the member scenario files")
    fam.add_argument("--family", help="only this family (default: every family of the study)")
    fam.set_defaults(fn=cmd_family)

    c = sub.add_parser("cache", help="list or clear the dataset cache")
    c.add_argument("action", choices=("ls", "clear"), help="ls: list the datasets; clear: delete them")
    c.add_argument("--cache", type=_path_text,
                   help="dataset cache folder (default .cache/datasets or $TESTBED_CACHE)")

    rs = sub.add_parser("runs", help="list the runs saved by `testbed run` (the run history)")
    rs.add_argument("action", choices=("ls",), help="ls: one row per run, oldest first")
    rs.add_argument("scenario", nargs="?", help="only the runs of this scenario")
    rs.add_argument("-o", "--out", default=None, type=_path_text,
                    help="folder of the runs (default out/runs)")
    rs.add_argument("--plain", action="store_true",
                    help="tab-separated lines, nothing cut (the default when not a terminal)")
    rs.set_defaults(fn=cmd_runs)
    c.set_defaults(fn=cmd_cache)

    d = sub.add_parser("demo", help="the main job: scored scenario runs and their report")
    d.add_argument("--out", default="out/demo", type=_path_text, help="output folder (default out/demo)")
    d.set_defaults(fn=cmd_demo)

    sv = sub.add_parser("serve", help="keep the libraries loaded: later commands fork from this process "
                        "and skip their imports (see testbed.server)")
    sv.add_argument("--idle", type=_float, default=900.0,
                    help="seconds without a command before the server exits (default 900)")
    sv.add_argument("--warm-up", default="cantilever_stiff_impact", metavar="SCENARIO",
                    type=_nonempty("a scenario name, or 'none'"),
                    help="scenario run once at start to warm the caches, or 'none' "
                         "(default cantilever_stiff_impact)")
    sv.set_defaults(fn=cmd_serve)
    return p


#: A word (a run of characters without a space: a path, a value) of an error line longer than
#: this [characters] is shown as its head and tail: a scenario, results or dataset path of
#: 100,000 characters (under Linux's 128 kB an argument) made a 100 kB error line (round 14).
MAX_WORD_CHARS = 1000
_LONG_WORD = re.compile(rf"\S{{{MAX_WORD_CHARS + 1},}}")


def _cut_word(m: re.Match) -> str:
    w, keep = m.group(0), (MAX_WORD_CHARS - 40) // 2
    return f"{w[:keep]}[... {len(w) - 2 * keep} characters ...]{w[-keep:]}"


def _one_line(text: object) -> str:
    """``text`` as one printable line: runs of whitespace as one space, every other control
    character escaped (an ESC in a `--prior` key, a `report` source or a `summary` file went
    raw to the terminal, round 14), a word over :data:`MAX_WORD_CHARS` cut in its middle."""
    return _LONG_WORD.sub(_cut_word, printable(" ".join(str(text).split())))


def _blas_threads() -> None:
    """One BLAS thread for the command unless the user set a thread count (before numpy loads).

    The testbed's matrices are small (a run's least squares are 12,800 x 12, its models 3-60
    states): a second BLAS thread has nothing to share and spins while it waits.  Measured on
    the 2-core machine under load (`testbed run cantilever_stiff_impact --no-figures`, 5 paired
    runs): 6.24 s CPU with the default two OpenBLAS threads, 3.88 s with one; the fit alone
    4.2 -> 1.6 s.  With one thread the results are also those of the tests, ``make`` and the
    benchmarks, which all run on one: the scored simulation's last bits depend on the thread
    count (TRAC 0.9999973639080992 with two threads, ...1009 with one).  Without effect when
    numpy is already imported (the library called from Python: the caller's threads).
    """
    if not any(v in os.environ for v in BLAS_THREAD_VARIABLES):
        for v in BLAS_THREAD_VARIABLES:
            os.environ[v] = "1"


#: Allocations between two young-generation garbage collections during a command (Python's
#: default: 700).  Importing scipy.signal, numba and matplotlib makes hundreds of thousands of
#: objects, none of them garbage: at the default the collector runs hundreds of times over
#: them.  Measured on `testbed run cantilever_stiff_impact` (2 cores at load 20, 3 interleaved
#: rounds): 6.0-6.6 s of CPU at the default, 5.1-6.4 s at 50,000 (5.4-5.8 s with the collector
#: off); peak memory 273 MiB in all three.
GC_THRESHOLD = (50_000, 20, 100)


class Terminated(KeyboardInterrupt):
    """SIGTERM or SIGHUP (``kill``, ``timeout``, a batch scheduler, a closed terminal), raised in
    the main thread like Ctrl-C's KeyboardInterrupt, so that a command so ended stops its
    workers and keeps its finished work the same way and says so on one line.  Before, the
    default action ended the process at once: exit status -15 and joblib's multi-line warning
    about the workers' shared-memory folders instead of ``error: interrupted``."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum = signum


#: Set by the handlers below when they run: the console program's signal watchdog
#: (:func:`testbed.core.interrupts.watchdog`) ends the process if it is not set in time.
_handled: threading.Event | None = None


def _raise_terminated(signum: int, frame: object) -> None:
    if _handled is not None:
        _handled.set()
    raise Terminated(signum)


def _raise_interrupt(signum: int, frame: object) -> None:
    if _handled is not None:
        _handled.set()
    signal.default_int_handler(signum, frame)


@contextlib.contextmanager
def _terminate_as_interrupt(console: bool = False) -> Iterator[None]:
    """SIGTERM and SIGHUP raise :class:`Terminated` while a command runs (only where their
    action is the default one and only in the main thread: a caller's own handlers stay), and
    an interrupt Python could not raise is delivered again (:func:`_redeliver_interrupt`).

    In the console program (``console``) a watchdog thread also ends the process in one line
    if the main thread has not started handling Ctrl-C, SIGTERM or SIGHUP within
    :data:`testbed.core.interrupts.GRACE_S`: Python runs a signal's handler only between two
    bytecodes, and an identifier's numba kernel (compiled, ``nogil``) held the main thread for
    the whole fit (28 s after a SIGTERM, measured) before the run said "interrupted"."""
    global _handled
    installed = {}
    # the console program's own handler (testbed.core.interrupts, set while it imports) counts
    # as the default here and is put back after: no moment is left with Python's handler alone
    armed = interrupts.exit_at_once
    if threading.current_thread() is threading.main_thread():
        for s in (signal.SIGTERM, signal.SIGHUP):
            if signal.getsignal(s) in (signal.SIG_DFL, armed):
                installed[s] = signal.signal(s, _raise_terminated)
        if console and signal.getsignal(signal.SIGINT) in (signal.default_int_handler, armed):
            installed[signal.SIGINT] = signal.signal(signal.SIGINT, _raise_interrupt)
    hook = sys.unraisablehook
    sys.unraisablehook = functools.partial(_redeliver_interrupt, hook)
    try:
        with (interrupts.watchdog(tuple(installed)) if console and installed
              else contextlib.nullcontext()) as handled:
            _handled = handled
            yield
    finally:
        _handled = None
        sys.unraisablehook = hook
        for s, handler in installed.items():
            signal.signal(s, handler)


#: Delay before an interrupt that could not be raised is sent again [s]: long enough for the
#: callback that swallowed it (a few bytecodes) to have returned, short against a user's wait.
REDELIVER_S = 0.01


def _redeliver_interrupt(hook: Callable[[Any], None], unraisable: Any) -> None:
    """``sys.unraisablehook`` while a command runs: a Ctrl-C (or SIGTERM, SIGHUP) whose
    KeyboardInterrupt was raised inside a callback Python cannot raise from (a weak reference's,
    e.g. the import system's module locks; a ``__del__``) is sent to the process again a moment
    later, in silence; anything else goes to ``hook``.  Before, such an interrupt printed
    "Exception ignored in ... Traceback ... KeyboardInterrupt" and was lost: a Ctrl-C in the
    first second of `testbed run` let the run finish with status 0."""
    if not isinstance(unraisable.exc_value, KeyboardInterrupt):
        hook(unraisable)
        return
    signum = getattr(unraisable.exc_value, "signum", signal.SIGINT)

    def send() -> None:  # sent: no longer pending (review 29a L7: a timer that had fired stayed
        # in the list, one more each interrupt of a long-lived process)
        with contextlib.suppress(ValueError):
            _REDELIVERIES.remove(timer)
        os.kill(os.getpid(), signum)

    timer = threading.Timer(REDELIVER_S, send)
    timer.daemon = True
    _REDELIVERIES.append(timer)
    timer.start()


#: Redeliveries of an interrupt not yet sent (:func:`_redeliver_interrupt`), cancelled once the
#: command has handled one (:func:`_interrupted`)
_REDELIVERIES: list[threading.Timer] = []


def main(argv: list[str] | None = None) -> int:
    """Run one command; return the exit status (0 ok, 1 a run failed its bars, 2 a user's
    mistake, 3 an internal error, 130 interrupted; 128 + the signal's number when ended by
    SIGTERM or SIGHUP)."""
    _blas_threads()
    try:
        if argv is None:  # the console program (not a call from Python): a resident server may run it
            status = _served(sys.argv[1:])
            if status is not None:
                return status
        before = gc.get_threshold()
        gc.set_threshold(*GC_THRESHOLD)  # restored below: main() is also called from Python
        late_exit_calls()  # an earlier command's, in this process (main() called from Python)
        try:
            with _terminate_as_interrupt(console=argv is None), _stdout_writes_file_names():
                try:
                    return _main(argv)
                finally:  # after the verdict, and after an interrupt too (review 22c)
                    _say_late_exits()
        finally:
            gc.set_threshold(*before)
    except KeyboardInterrupt as e:
        # a Ctrl-C outside the command's own handling (while its options were parsed, in a
        # busy machine's first second) printed a 30-line traceback and ended by SIGINT (-2)
        return _interrupted(e)


def _say_late_exits() -> None:
    """One warning line for the ``os._exit`` calls that threads a plugin's fit left running
    made after the fit (:func:`testbed.core.exit_guard.late_exit_calls`): each ended its
    thread, not the command, whose verdict stands (hostile round 21: the command had ended with
    the thread's status and no verdict)."""
    calls = late_exit_calls()
    if calls:
        shown = ", ".join(f"{terminal_safe(name)!s} os._exit({code!r})" for name, code in calls[:3])
        more = f" and {len(calls) - 3} more" if len(calls) > 3 else ""
        print(f"warning: {len(calls)} thread(s) a plugin's code left running called os._exit after "
              f"its fit had returned ({shown}{more}): each ended its own thread, not this command",
              file=sys.stderr, flush=True)


@contextlib.contextmanager
def _stdout_writes_file_names() -> Iterator[None]:
    """Standard output writes a file name whose bytes are not text in its encoding as those
    bytes (:func:`testbed.core.atomic._file_name_bytes`) while a command runs, instead of
    raising UnicodeEncodeError: "run written to <a folder named in Latin-1>" was an internal
    error after the run was saved.  The caller's error handler is put back after."""
    from testbed.core.atomic import FILE_NAME_ERRORS

    stream = sys.stdout
    errors = getattr(stream, "errors", None)
    try:
        stream.reconfigure(errors=FILE_NAME_ERRORS)
    except (AttributeError, ValueError, OSError):  # not a TextIOWrapper, or closed
        yield
        return
    try:
        yield
    finally:
        with contextlib.suppress(AttributeError, ValueError, OSError):
            stream.reconfigure(errors=errors)


def _served(argv: list[str]) -> int | None:
    """The command's status if a resident ``testbed serve`` ran it (:mod:`testbed.server`)."""
    if not argv or argv[0] == "serve" or os.environ.get("TESTBED_NO_SERVER"):
        return None
    if argv[0] == "list" and not any(a.startswith("--plugin") for a in argv):
        # alone it prints from its index (testbed.core.stamped: 0.17 s of CPU), or lists and
        # rewrites the index; a server's child lists afresh (its registries are loaded) and
        # cannot write the index (its modules were read when the server started)
        return None
    from testbed.server import socket_path, try_server

    try:
        present = socket_path().exists()
    except OSError:  # $TESTBED_SERVER_SOCKET of 10,000 characters (ENAMETOOLONG): was a traceback
        return None  # no server can listen there: the command runs alone
    return try_server(argv) if present else None


def _env_folders() -> None:
    """``$TESTBED_SCENARIOS`` and ``$TESTBED_STUDIES``, where set, must be folders: a typo left
    every command without scenarios ("no scenario named ...", `testbed list` empty, exit 0)
    and a name too long for the file system was an internal error."""
    for var, what in (("TESTBED_SCENARIOS", "scenario"), ("TESTBED_STUDIES", "study")):
        value = os.environ.get(var)
        if value is None:
            continue
        st = _stat(Path(value), f"${var}") if value else None
        if st is None or not stat.S_ISDIR(st.st_mode):
            raise InputError(f"${var} {show_value(value)}: {'not a folder' if st else 'no such folder'}; "
                             f"expected the folder of {what} files (unset it for the shipped ones)")


def _main(argv: list[str] | None) -> int:
    args = build_parser().parse_args(argv)
    if args.debug:
        return _run(args)
    # Python warnings of the libraries (numpy's overflow, a RuntimeWarning of scipy) wait until
    # the command ends: a command that ends in its one error line shows that line alone (the
    # warnings preceded it: several lines); one that ends in its verdict shows them after it
    with warnings.catch_warnings(record=True) as caught:
        status = _run(args)
    if status in (0, EXIT_FAIL):
        for w in caught:
            warnings.showwarning(_first_line(w.message), w.category, w.filename, w.lineno, w.file,
                                 w.line)
    return status


def _first_line(message: Warning | str) -> Warning | str:
    """A warning's message cut to its first line: numba's for a malformed ``$NUMBA_NUM_THREADS``
    carries the whole traceback of its failed parse (9 lines after the verdict)."""
    lines = str(message).splitlines()
    if len(lines) <= 1:
        return message
    return f"{lines[0]} [{len(lines) - 1} more line(s): `testbed --debug ...` shows them]"


def _run(args: argparse.Namespace) -> int:
    try:
        _env_folders()
        if sys.stdout is None and args.command != "serve":  # `testbed run x >&-`
            # (was an internal error, AttributeError 'NoneType' ... 'isatty'; `list` printed
            # nothing with status 0; `serve` writes nothing there and runs as before)
            raise InputError("standard output is closed (file descriptor 1); give the command "
                             "somewhere to write (> /dev/null to discard what it prints)")
        return args.fn(args)
    except TestbedError as e:
        print(f"error: {_one_line(e)}", file=sys.stderr)
        return EXIT_USAGE
    except KeyError as e:
        text = str(e.args[0]) if e.args else ""
        if not text.startswith("unknown "):  # the registries' own: "unknown rig 'x'; allowed: ..."
            return _internal(e, args)
        print(f"error: {_one_line(text)}", file=sys.stderr)
        return EXIT_USAGE
    except (FileNotFoundError, PermissionError, IsADirectoryError, NotADirectoryError,
            FileExistsError) as e:  # a path the user gave (an output folder, a file)
        if args.debug:
            raise
        print(f"error: {_one_line(_no_cwd(e) or e)}", file=sys.stderr)
        return EXIT_USAGE
    except KeyboardInterrupt as e:
        return _interrupted(e)
    except BrokenPipeError:  # the reader went away (`testbed list | head -1`): stop quietly
        _quiet_stdout()
        return EXIT_BROKEN_PIPE
    except Exception as e:
        if isinstance(e, OSError) and _stdout_failed(e):
            print(f"error: cannot write to standard output: {e.strerror} (a full disk or "
                  "/dev/full, or a file descriptor not open for writing)", file=sys.stderr)
            _quiet_stdout()
            return EXIT_USAGE
        refusal = _backend_refusal(e) or _descriptor_limit(e)
        if refusal is not None and not args.debug:
            print(f"error: {refusal}", file=sys.stderr)
            return EXIT_USAGE
        interrupt = _interrupt_within(e)
        return _internal(e, args) if interrupt is None else _interrupted(interrupt)


def _backend_refusal(e: BaseException) -> str | None:
    """matplotlib's refusal of ``$MPLBACKEND`` as one line, if ``e`` is that."""
    if "MPLBACKEND" not in os.environ:
        return None
    from testbed.reporting.mplconfig import backend_refusal

    return backend_refusal(e)


def _no_cwd(e: OSError) -> str | None:
    """The message for ``e`` if it is the current folder that is gone (deleted while the shell
    stayed in it: ``os.getcwd()`` fails), else None.  It read "[Errno 2] No such file or
    directory", naming nothing, for a relative path or a default folder (the cache, ``out``)."""
    if not isinstance(e, FileNotFoundError) or e.filename is not None:
        return None
    try:
        os.getcwd()
    except FileNotFoundError:
        return ("the current folder no longer exists (deleted?); cd to a folder that exists, "
                "or give absolute paths and --out/--cache")
    return None


#: errno values of a write to standard output that cannot succeed: no room (a full disk,
#: /dev/full, a quota, `ulimit -f`), a descriptor not open for writing (``1</dev/null``), or
#: a device error.
STDOUT_WRITE_ERRNOS = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG, errno.EBADF, errno.EIO)


def _stdout_failed(e: OSError) -> bool:
    """Whether ``e`` (naming no file) is standard output refusing its writes: a write of zero
    bytes to it fails too (``/dev/full``, a descriptor not open for writing), or it is a file
    on a disk without room.  Was an internal error ("please report it") for
    `testbed list > /dev/full` or `testbed run ... 1</dev/null`."""
    if e.filename is not None or e.errno not in STDOUT_WRITE_ERRNOS:
        return False
    try:
        os.write(1, b"")
        return e.errno in (errno.ENOSPC, errno.EDQUOT, errno.EFBIG) and stat.S_ISREG(os.fstat(1).st_mode)
    except OSError:
        return True


def _interrupted(e: KeyboardInterrupt) -> int:
    """One line for Ctrl-C (status 130), SIGTERM or SIGHUP (128 + its number).

    A redelivery still pending (:data:`_REDELIVERIES`) is cancelled: the interrupt it carries
    is this one, handled.  An import interrupted inside its module lock's callback both
    scheduled one and failed with the KeyboardInterrupt within; the second delivery, 10 ms
    later, came after "error: interrupted" and ended the process by SIGINT in the
    interpreter's shutdown (status -2), or printed the line twice (hostile round 29)."""
    while _REDELIVERIES:
        _REDELIVERIES.pop().cancel()
    if isinstance(e, Terminated):
        print(f"error: interrupted by {signal.Signals(e.signum).name}", file=sys.stderr)
        return 128 + e.signum
    print("error: interrupted", file=sys.stderr)
    return EXIT_INTERRUPTED


def _descriptor_limit(e: BaseException) -> str | None:
    """One line for an exception raised from running out of file descriptors (EMFILE: the
    process's ``ulimit -n``; ENFILE: the system's), else None.  Under ``ulimit -n 8`` `testbed
    run` was an internal error ("OSError: [Errno 24] Too many open files", round 17): a limit of
    the environment, as a full disk is (:func:`testbed.core.atomic.no_room`)."""
    seen: set[int] = set()
    while e is not None and id(e) not in seen:
        if isinstance(e, OSError) and e.errno in (errno.EMFILE, errno.ENFILE):
            if e.errno == errno.ENFILE:
                return ("too many open files in the system (ENFILE); close some programs and run "
                        "the command again")
            try:
                import resource  # (POSIX only)

                limit = f"may open {resource.getrlimit(resource.RLIMIT_NOFILE)[0]}"
            except ImportError:
                limit = "has reached its limit"
            return (f"too many open files: this process {limit} (`ulimit -n`); the command "
                    "needs a few dozen: raise the limit (e.g. `ulimit -n 1024`) and run it again")
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return None


def _interrupt_within(e: BaseException) -> KeyboardInterrupt | None:
    """The interrupt ``e`` was raised from (its ``__cause__`` / ``__context__`` chain), or None.

    A C extension whose import is interrupted (pybind11's: MuJoCo's, matplotlib's) raises
    ``ImportError: initialization failed`` from the KeyboardInterrupt: a SIGTERM in a run's
    first seconds was an internal error ("please report it")."""
    seen: set[int] = set()
    while e is not None and id(e) not in seen:
        if isinstance(e, KeyboardInterrupt):
            return e
        seen.add(id(e))
        e = e.__cause__ or e.__context__
    return None


def _quiet_stdout() -> None:
    """Point standard output at /dev/null, so the interpreter's last flush into a closed pipe
    prints nothing either (Python's documented remedy, "Note on SIGPIPE")."""
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)


def _internal(e: BaseException, args: argparse.Namespace) -> int:
    """One line for a bug (status 3); with ``--debug`` re-raise it for its traceback."""
    if args.debug:
        raise e
    # (exception_text: an exception whose __str__ raises ended here in a traceback, round 28)
    print(f"internal error (a bug, not your input): {type(e).__name__}: "
          f"{_one_line(exception_text(e))[:300]}; "
          f"rerun as `testbed --debug {args.command} ...` for the traceback, and please report it",
          file=sys.stderr)
    return EXIT_INTERNAL


if __name__ == "__main__":
    sys.exit(main())
