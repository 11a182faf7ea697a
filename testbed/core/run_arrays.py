"""What a run's ``run.npz`` may hold, and its check: the constants read by its writer and
reader (:mod:`testbed.studies.runstore`) and :func:`check_run_npz`, which the reader
(:func:`~testbed.studies.runstore.load_run`) calls before any array is loaded.
"""

from __future__ import annotations

import os
import zipfile
from pathlib import Path

import numpy as np

#: The dtype kinds of a run's stored arrays (numbers and text, nothing pickled): bool, signed
#: and unsigned integers, floats, complex, text.
RUN_ARRAY_KINDS = "biufcU"

#: The first bytes :func:`numpy.load` takes for a zip (an ``.npz``): a zip's local file header,
#: or the end-of-archive record an empty zip starts with (numpy's own test, ``_npyio_impl``).
ZIP_SIGNATURES = (b"PK\x03\x04", b"PK\x05\x06")


def check_run_npz(run_dir: str | os.PathLike) -> None:
    """Refuse a run folder's ``run.npz`` that is not a zip of plain ``.npy`` arrays, reading
    each member's header only (no array is loaded, no pickle unpickled).

    Round 24, each run sealed anew (its npz checksum and ``run.json``'s own): a member of a
    structured dtype was "internal error ... TypeError: Cannot cast array data" in ``testbed
    report``; a zip member that is no ``.npy`` (``model/x.pkl``) came back from
    :func:`numpy.load` as bytes ("(AttributeError)"), and a lone ``.npy`` under the name
    ``run.npz`` as an array ("(TypeError)"), both naming nothing.  A missing ``run.npz`` is
    :func:`~testbed.studies.runstore.load_run`'s to judge.

    The first bytes decide, as they do for :func:`numpy.load` (:data:`ZIP_SIGNATURES`):
    :class:`zipfile.ZipFile` finds a zip by its directory at the file's end, so a ``.npy`` or
    a pickle with a real run's zip appended passed (review 25a) and :func:`numpy.load` read
    the ``.npy`` ("(TypeError)" again) or unpickled.

    Raises
    ------
    ValueError
        Naming the file, the member and what a run.npz holds.
    """
    npz = Path(run_dir) / "run.npz"
    if not npz.is_file():
        return
    allowed = "a run.npz is a zip of .npy arrays of numbers or text"
    try:
        with open(npz, "rb") as fh:
            head = fh.read(4)
    except OSError as e:
        raise ValueError(f"{npz}: cannot be read ({' '.join(str(e).split())}); {allowed}") from None
    if not head.startswith(ZIP_SIGNATURES):
        raise ValueError(f"{npz}: starts with the bytes {head!r}, not a zip's "
                         f"({' or '.join(map(repr, ZIP_SIGNATURES))}); {allowed}")
    try:
        archive = zipfile.ZipFile(npz)
    except (zipfile.BadZipFile, OSError, ValueError) as e:
        raise ValueError(f"{npz}: not a zip archive ({' '.join(str(e).split())}); {allowed}") from None
    with archive:
        for info in archive.infolist():
            name = info.filename
            if not name.endswith(".npy"):
                raise ValueError(f"{npz}: member {name!r} is not a .npy array; {allowed}")
            try:
                with archive.open(info) as fh:
                    version = np.lib.format.read_magic(fh)
                    read = (np.lib.format.read_array_header_1_0 if version == (1, 0)
                            else np.lib.format.read_array_header_2_0)
                    _shape, _fortran, dtype = read(fh)
            except Exception as e:  # a damaged header, an unknown version, a bad zip entry
                raise ValueError(f"{npz}: member {name!r} has no readable .npy header "
                                 f"({type(e).__name__}: {' '.join(str(e).split())[:120]}); "
                                 f"{allowed}") from None
            if dtype.kind not in RUN_ARRAY_KINDS or dtype.fields is not None or dtype.hasobject:
                what = "objects: pickled data, not loaded" if dtype.hasobject else f"kind {dtype.kind!r}"
                raise ValueError(f"{npz}: member {name!r} has dtype {dtype} ({what}); {allowed} "
                                 f"(dtype kinds {', '.join(RUN_ARRAY_KINDS)})")
