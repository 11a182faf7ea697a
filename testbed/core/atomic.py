"""Atomic file writes: a temporary file in the target's folder, flushed to disk, then renamed.

A reader sees the old file or the new one, never a half-written one, and an interrupted
write leaves no partial file behind.
"""

from __future__ import annotations

import codecs
import contextlib
import errno
import os
import re
import shutil
import stat
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import NamedTuple

from testbed.core.budget import IDENTIFY_TEXT_BUDGET_BYTES
from testbed.core.errors import InputError, terminal_safe

# mkstemp creates 0600 files; the result gets the permissions a plain open() would give
# (read once at import: os.umask can only be read by setting it)
_UMASK = os.umask(0o022)
os.umask(_UMASK)

#: errno values of a write refused for want of room: the disk full, a quota reached, or the
#: file-size limit of the process (``ulimit -f``; Python ignores SIGXFSZ, so the write fails).
NO_ROOM = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)


def no_room(e: BaseException, path: str | os.PathLike) -> InputError | None:
    """The one-line error for a write of ``path`` that failed for want of room, else None.

    Recognised by the exception's errno (an ``OSError``) or, for libraries that wrap it in
    their own message (h5py's ``RuntimeError: ... errno = 27, error message = 'File too
    large'``), by that errno or its text in the message.  Such a failure was an internal error
    ("please report it") naming no file.
    """
    code = None
    seen: set[int] = set()
    cause: BaseException | None = e
    # along the chain of exceptions: pyuff replaces the OSError of its write by a bare
    # "Exception: Error writing data-set #58" raised while handling it (its __context__): `testbed
    # export` on a full disk was an internal error (round 12)
    while cause is not None and code is None and id(cause) not in seen:
        seen.add(id(cause))
        code = getattr(cause, "errno", None)
        if code not in NO_ROOM:
            text = str(cause)
            code = next((n for n in NO_ROOM if f"errno = {n}," in text or os.strerror(n) in text),
                        None)
        cause = cause.__cause__ or cause.__context__
    if code is None:
        return None
    return InputError(f"{path}: cannot be written: {os.strerror(code)} (the disk or a quota is "
                      "full, or the file-size limit `ulimit -f` is reached); nothing was left "
                      "half-written: make room and run the command again")


#: Temporary files and folders being written (:func:`in_flight`): what a process ended at once
#: (:func:`testbed.core.interrupts.exit_now`, no ``finally`` runs) removes first.
_IN_FLIGHT: set[str] = set()


def begin_in_flight(tmp: str | os.PathLike) -> None:
    """Mark ``tmp`` (a temporary file or folder) as being written, until :func:`end_in_flight`."""
    _IN_FLIGHT.add(os.fspath(tmp))


def end_in_flight(tmp: str | os.PathLike) -> None:
    """``tmp`` is renamed into place or removed: no longer being written."""
    _IN_FLIGHT.discard(os.fspath(tmp))


@contextlib.contextmanager
def in_flight(tmp: str | os.PathLike) -> Iterator[None]:
    """Mark ``tmp`` (a temporary file or folder) as being written while the block runs."""
    begin_in_flight(tmp)
    try:
        yield
    finally:
        end_in_flight(tmp)


def remove_in_flight() -> None:
    """Remove every temporary file and folder being written (:func:`in_flight`), in silence:
    for a process about to end without unwinding, so that it leaves nothing half-written."""
    for tmp in list(_IN_FLIGHT):
        if os.path.isdir(tmp) and not os.path.islink(tmp):
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            with contextlib.suppress(OSError):
                os.unlink(tmp)


def not_regular(path: Path) -> None:
    """Raise InputError if something other than a regular file or a folder is at ``path`` (a
    device, FIFO or socket, which a rename onto it would replace); nothing there passes."""
    try:
        mode = os.stat(path).st_mode
    except (OSError, ValueError):  # nothing there, or a path that names nothing: the write says
        return
    if not (stat.S_ISREG(mode) or stat.S_ISDIR(mode)):  # (a folder: the rename's own error)
        raise InputError(f"{path}: exists and is not a regular file (a FIFO, socket or device, "
                         "which the written file would replace); expected a file path")


class FileKind(NamedTuple):
    """A kind of file a command writes: an existing file at the path written that is not of the
    kind is someone else's (:func:`foreign_head`).

    ``heads``: the leading parts a file of the kind may begin with; a part may be a pattern of
    bytes, matched at the start (of the first :data:`PATTERN_READ` bytes).  ``text``: compared
    after leading blanks and a UTF-8 byte-order mark (a text format); a binary one (HDF5, PNG,
    Parquet) byte for byte (review 28: Parquet's ``PAR1``, all ASCII, was read as a text kind,
    so a file of blanks then ``PAR1`` passed).  ``ours``: where a format is anyone's (PNG,
    JSON, HDF5, UFF), the marker the testbed writes in its own files of the kind, read from the
    open file (review 28b M2: a user's own ``fit_time.png`` in a report folder, or a
    ``settings.json`` given to ``identify -o``, was replaced because it was a PNG / JSON).
    """

    what: str
    heads: tuple[bytes | re.Pattern[bytes], ...]
    text: bool = False
    ours: Callable[[int], bool] | None = None


#: How many bytes a :data:`FileKind`'s pattern is matched in [bytes].
PATTERN_READ = 1024
#: The PNG text chunk every figure the testbed writes carries (``reporting.figures.png_bytes``):
#: the keyword ``Software`` and this value, before the image data (review 28b M2)
PNG_SOFTWARE = "sysid-testbed"
#: How much of a UFF file :func:`_uff_ours` reads at a time [bytes]
UFF_CHUNK = 1 << 20
#: The start of a UFF58 record (``58`` ASCII, ``58b`` binary) after its ``-1`` delimiter
_UFF58_START = re.compile(rb"\n\s*-1\n\s*58b?[ \t]")
#: Every UFF58 record the testbed writes states its rate on ID line 5 as ``fs <rate> Hz,
#: sysid-testbed`` (``reporting.export``, since the line was written)
_UFF_MARK = re.compile(rb"\n\s*-1\n\s*58b?[ \t][^\n]*\n(?:[^\n]*\n){4}fs [^\n]*Hz, sysid-testbed\b")
#: The most of a file a marker check reads [bytes]: the largest JSON output
#: :func:`_json_document` parses, and the farthest :func:`_uff_ours` looks for a UFF file's
#: first UFF58 record.  The largest text file ``identify`` reads
#: (``testbed.core.budget.IDENTIFY_TEXT_BUDGET_BYTES``, review 29a L5: a second, unexplained
#: 256 MiB).  A larger file is told as not the testbed's: a SEP-005 export of its own over
#: 256 MiB (about 3e7 samples; the scenario budget allows more) is then refused as a target of
#: another export (not measured in practice: docs/known-gaps.md)
MARK_READ = IDENTIFY_TEXT_BUDGET_BYTES
#: The keys every model summary ``identify`` writes holds (``testbed.pipeline.fit``), which no
#: one else's JSON holds together: the identified model's marker
IDENTIFIED_KEYS = frozenset({"source", "kind", "method", "fs_hz", "n_samples", "identifier"})
#: The keys every channel of a SEP-005 export holds besides SEP-005's own (``reporting.export``)
SEP005_KEYS = frozenset({"name", "data", "fs", "content_hash", "group"})


def _png_ours(fd: int) -> bool:
    """True for a PNG whose text chunks before its image data hold ``Software`` =
    :data:`PNG_SOFTWARE` (the chunks walked by their lengths, at most 64 of them)."""
    pos = 8
    for _ in range(64):
        head = os.pread(fd, 8, pos)
        if len(head) < 8:
            return False
        size, tag = int.from_bytes(head[:4], "big"), head[4:]
        if tag in (b"IDAT", b"IEND"):
            return False
        if tag == b"tEXt" and size < 4096:
            key, _, value = os.pread(fd, size, pos + 8).partition(b"\0")
            if key == b"Software" and value == PNG_SOFTWARE.encode():
                return True
        pos += 12 + size
    return False


def _hdf5_ours(fd: int) -> bool:
    """True for an HDF5 file whose root attribute ``format`` is the testbed's dataset format
    (``sysid-testbed-dataset/<n>``: every dataset written since the attribute was)."""
    import h5py

    try:
        with os.fdopen(os.dup(fd), "rb") as fh, h5py.File(fh, "r") as f:
            value = f.attrs.get("format")
    except Exception:
        return False
    if isinstance(value, bytes):
        value = value.decode("utf-8", "replace")
    return isinstance(value, str) and value.startswith("sysid-testbed-dataset/")


def _json_document(fd: int) -> object:
    """The JSON document of the open file, or None (too large, not UTF-8, not JSON)."""
    import json

    size = os.fstat(fd).st_size
    if size > MARK_READ:
        return None
    try:  # the file's size, not the limit: a small file is not given a 256 MiB buffer
        return json.loads(os.pread(fd, size, 0).decode("utf-8-sig"))
    except (ValueError, RecursionError):  # RecursionError: a user's deeply nested document
        # ('[' * 100000) is not ours either (review 29a M2: it was "internal error")
        return None


def _identified_ours(fd: int) -> bool:
    """True for a model summary ``identify`` wrote (a table holding :data:`IDENTIFIED_KEYS`)."""
    doc = _json_document(fd)
    return isinstance(doc, dict) and IDENTIFIED_KEYS <= doc.keys()


def _sep005_ours(fd: int) -> bool:
    """True for a SEP-005 export of the testbed (channels holding :data:`SEP005_KEYS`)."""
    doc = _json_document(fd)
    return (isinstance(doc, list) and bool(doc)
            and all(isinstance(c, dict) and SEP005_KEYS <= c.keys() for c in doc))


def _uff_ours(fd: int) -> bool:
    """True for a UFF file whose first UFF58 record carries the testbed's ID line 5
    (:data:`_UFF_MARK`).

    The file is read in :data:`UFF_CHUNK` pieces up to that record's start only, at most
    :data:`MARK_READ` bytes: the testbed's export writes its geometry (about 160 bytes a
    node) before it, so a fixed first MiB refused its own export of more than ~6,500 nodes
    (review 29a L5)."""
    tail, pos = b"\n", 0
    while pos < MARK_READ:
        chunk = os.pread(fd, UFF_CHUNK, pos)
        if not chunk:
            return False
        buf, pos = tail + chunk, pos + len(chunk)
        found = _UFF58_START.search(buf)
        if found:  # its six ID lines (80 characters each) follow within PATTERN_READ bytes
            return _UFF_MARK.match(buf + os.pread(fd, PATTERN_READ, pos), found.start()) is not None
        tail = buf[-PATTERN_READ:]  # a record start cut by the chunk's end is found next time
    return False


HDF5_FILE = FileKind("an HDF5 dataset of the testbed", (b"\x89HDF\r\n\x1a\n",), ours=_hdf5_ours)
IDENTIFIED_JSON_FILE = FileKind("a model summary written by `testbed identify`", (b"{",),
                                text=True, ours=_identified_ours)
SEP005_FILE = FileKind("a SEP-005 export of the testbed", (b"[",), text=True, ours=_sep005_ours)
UFF_FILE = FileKind("a UFF export of the testbed", (b"-1",), text=True, ours=_uff_ours)
#: the first line of a run's or a study's markdown report (``testbed.reporting.report``): an
#: HTML comment no renderer shows.  Its title alone (``# Run `` / ``# Study ``, read 27b) let a
#: user's own ``# Study notes`` be replaced (review 27e M2); a report written before this line
#: existed is still recognised, by :data:`LEGACY_REPORT_MARKDOWN`
REPORT_MARKDOWN_MARK = "<!-- sysid-testbed report -->"
#: a report written before the mark: its title and the fixed first paragraph under it (a run's
#: verdict line, a study's cell count), which no one's notes repeat; it is replaced as before
LEGACY_REPORT_MARKDOWN = re.compile(
    rb"# Run [^\n]*\n\n(PASS|FAIL|NO VERDICT): [^\n]*; identifier [^\n]*, fit [^\n]* s\.\n"
    rb"|# Study [^\n]*\n\n\d+ cells: \d+ scenario\(s\), \d+ identifier\(s\) \(")
REPORT_MARKDOWN_FILE = FileKind("a markdown report", (REPORT_MARKDOWN_MARK.encode(),
                                                     LEGACY_REPORT_MARKDOWN), text=True)
#: an identified model's report (``testbed.reporting.identified``: its first line since it was
#: written): a user's own ``notes.md`` beside ``identify -o notes.json`` is not ours (review 27e)
IDENTIFIED_MARKDOWN_FILE = FileKind("an identified model's markdown report",
                                    (b"# Identified model: ",), text=True)
#: the Content-Security-Policy of every page the testbed writes (no network, no script)
REPORT_CSP = "default-src 'none'; img-src data:; style-src 'unsafe-inline'"
#: every HTML page the testbed writes begins so (``testbed.reporting.report``).  The doctype
#: line alone is any HTML5 page's boilerplate (a user's own ``report.html`` passed as ours);
#: with the policy it is the testbed's, as every report written since the policy was (review
#: 27e M2, the HTML's part)
HTML_REPORT_HEAD = ('<!DOCTYPE html>\n<html lang="en"><head><meta charset="utf-8">'
                    f'<meta http-equiv="Content-Security-Policy" content="{REPORT_CSP}">')
HTML_FILE = FileKind("an HTML report", (HTML_REPORT_HEAD.encode(),), text=True)
PNG_FILE = FileKind("a PNG figure of the testbed", (b"\x89PNG\r\n\x1a\n",), ours=_png_ours)
#: a sweep's results file (Apache Parquet's magic number)
PARQUET_FILE = FileKind("a Parquet results file", (b"PAR1",))


#: What :func:`_inspect` finds at a path: nothing to refuse, a foreign file's head, unreadable
_UNREADABLE = object()


def _inspect(path: Path, kind: FileKind) -> bytes | object | None:
    """One opening of ``path``: None (no file, an empty one, one of the kind, or no regular
    file: :func:`not_regular` names that), the first bytes (at most 64) of a file not of the
    kind, or :data:`_UNREADABLE` for a regular file this process may not read."""
    try:
        # without blocking: a FIFO nobody writes to hung a plain open for good (review 27e);
        # anything but a regular file is left to not_regular (the write's own check) to name
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except PermissionError:
        return _UNREADABLE if os.path.isfile(path) else None
    except (OSError, ValueError):
        return None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            return None
        head = os.read(fd, max(64, *(len(p) if isinstance(p, bytes) else PATTERN_READ
                                      for p in kind.heads)))
        if not head:
            return None
        text = head.removeprefix(b"\xef\xbb\xbf").lstrip() if kind.text else head
        ours = any(text.startswith(p) if isinstance(p, bytes) else p.match(text)
                   for p in kind.heads)
        if ours and kind.ours is not None:
            ours = kind.ours(fd)
    except OSError:
        return None
    finally:
        os.close(fd)
    return None if ours else head[:64]


def foreign_head(path: Path, kind: FileKind) -> bytes | None:
    """The first bytes (at most 64) of an existing, non-empty file at ``path`` that is not
    ``kind``'s, else None (no file, an empty one, one of the kind, no regular file (a FIFO,
    socket or device: :func:`not_regular` names it) or unreadable: :func:`refuse_foreign` names
    that).

    Round 27: ``generate -o photo.png`` replaced the user's picture by a dataset in silence, as
    ``identify`` / ``export -o`` and ``family write`` (a member's name) replaced any file.  A
    file is of the kind if it begins as :attr:`FileKind.heads` says and, for a format anyone
    writes, carries the testbed's marker (:attr:`FileKind.ours`; review 28b M2).
    """
    found = _inspect(path, kind)
    return found if isinstance(found, bytes) else None


def refuse_foreign(path: str | os.PathLike, kind: FileKind, name: str | None = None,
                   expected: str | None = None) -> None:
    """Raise InputError if an existing file at ``path`` is not ``kind`` (:func:`foreign_head`)
    or cannot be read (its kind cannot be told: review 27e, such a file was replaced though
    :func:`foreign_head`'s docstring said the write would name it); a missing path, an empty
    file or one that is not a regular file passes (the write's own checks name those).

    The one refusal of a file a command would replace that is not its own (``generate`` /
    ``identify`` / ``export -o``, ``report``'s every output, ``family write``'s members,
    ``sweep --results``; review 27e: four copies of this text).  ``name`` is how the path is
    shown (default: the path; e.g. ``"--output out.h5"``), ``expected`` what is allowed (default:
    a new path or a file of the kind the command wrote).  The file is opened once (review 28:
    twice, the second reading a file the first had not).
    """
    shown = name or terminal_safe(os.fspath(path))
    what = kind.what
    allowed = expected or f"a new path or {what} this command wrote"
    found = _inspect(Path(path), kind)
    if isinstance(found, bytes):
        raise InputError(f"{shown}: exists and is not {what} (it begins with {found[:16]!r}); "
                         f"expected {allowed} (the file is left as it is)")
    if found is _UNREADABLE:
        raise InputError(f"{shown}: exists and cannot be read, so whether it is {what} cannot be "
                         f"told; expected {allowed} (the file is left as it is)")


def _replaced(path: Path) -> os.stat_result | None:
    """The status of the regular file ``path`` names itself (not through a link), else None."""
    try:
        st = os.lstat(path)
    except (OSError, ValueError):
        return None
    return st if stat.S_ISREG(st.st_mode) else None


def _replaced_mode(st: os.stat_result | None) -> int:
    """The permission bits a written file gets: the read / write / execute bits of the file it
    replaces (``st``; a private file, mode 0600, had come back world-readable: round 22), else
    ``0666`` less the umask.  Never its setuid, setgid or sticky bit (review 23a: a setuid
    file's bit was carried onto the new content, its owner not)."""
    return 0o666 & ~_UMASK if st is None else stat.S_IMODE(st.st_mode) & 0o777


def _keep_owner(tmp: str, st: os.stat_result | None) -> None:
    """Give ``tmp`` the owner and group of the file it replaces (``st``), where allowed: root
    may, a user may set a group of theirs; else the writer's own stay (in silence)."""
    if st is None or not hasattr(os, "chown"):
        return
    with contextlib.suppress(PermissionError):
        os.chown(tmp, st.st_uid, st.st_gid)


def atomic_write(path: str | os.PathLike, write: Callable[[str], None]) -> Path:
    """Call ``write(tmp)`` on a temporary path next to ``path``, then rename it to ``path``.

    Parameters
    ----------
    path : path-like
        The file to create or replace; its folder is created if missing.  A symbolic link
        there is replaced itself (the file it names is left as it was): a caller that means to
        write through a link resolves it first (``testbed.cli._output_file``, for ``-o``).
        A replaced file's owner, group and permission bits (less setuid, setgid and sticky)
        are kept where the writer may set them.
    write : callable
        Writes the whole content to the path it is given (a str).

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    InputError
        If ``path`` exists and is not a regular file (a device, FIFO or socket, or a folder;
        through a link too): the rename
        would replace the node itself.  As root, the drawing process's warm-up figure, saved
        to ``os.devnull`` through this function, replaced ``/dev/null`` with a regular file
        for every process of the machine (round 13).
    """
    path = Path(path)
    # a link is replaced itself (what it names is left as it was): a link planted in a shared
    # cache folder had made root overwrite the file it named (review 23a); `-o` writes through
    # a link the CLI vets (testbed.cli._output_file).  A link to a device or a folder is still
    # refused, as before round 22 (a link to /dev/zero at the index's path is left as it was)
    not_regular(path)
    if path.is_dir():  # the rename's IsADirectoryError named the temporary file (round 17)
        raise InputError(f"{path}: is a folder; expected a file path")
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    try:
        with in_flight(tmp):
            write(tmp)
            with open(tmp, "rb") as fh:
                os.fsync(fh.fileno())
            replaced = _replaced(path)
            _keep_owner(tmp, replaced)  # before the mode: chown clears setuid / setgid bits
            os.chmod(tmp, _replaced_mode(replaced))
            os.replace(tmp, path)
    except BaseException as e:
        Path(tmp).unlink(missing_ok=True)
        full = no_room(e, path)
        if full is not None:
            raise full from None
        raise
    return path


#: The codec error handler of :func:`_file_name_bytes`: text naming files, encoded.
FILE_NAME_ERRORS = "testbed.file_names"


def _file_name_bytes(e: UnicodeError) -> tuple[bytes, int]:
    """A codec error handler: a lone surrogate that stands for a byte of a file name is that
    byte, anything else the encoding cannot write a backslash escape.

    A file name whose bytes are not text in the locale's encoding (a folder named in Latin-1 on
    a UTF-8 system; any non-ASCII name under ``LC_ALL=C`` with Python's UTF-8 mode off) reaches
    Python as lone surrogates U+DC80..U+DCFF (``surrogateescape``), which strict UTF-8 cannot
    write: `testbed run` in such a folder saved its run and then ended in an internal error
    printing "run written to ..." or writing the runs' index page.  Written back as the bytes
    they stand for, the name is the file system's own (as ``ls`` prints it)."""
    if not isinstance(e, UnicodeEncodeError):
        raise e
    out = bytearray()
    for c in e.object[e.start:e.end]:
        code = ord(c)
        out += bytes([code - 0xDC00]) if 0xDC80 <= code <= 0xDCFF else \
            c.encode("ascii", "backslashreplace")
    return bytes(out), e.end


codecs.register_error(FILE_NAME_ERRORS, _file_name_bytes)


def utf8_bytes(text: str) -> bytes:
    """``text`` as UTF-8, a file name in it as the file system's bytes (:func:`_file_name_bytes`)."""
    return text.encode("utf-8", FILE_NAME_ERRORS)


def atomic_write_text(path: str | os.PathLike, text: str) -> Path:
    """:func:`atomic_write` of ``text`` as UTF-8 (:func:`utf8_bytes`)."""
    data = utf8_bytes(text)
    return atomic_write(path, lambda tmp: Path(tmp).write_bytes(data))
