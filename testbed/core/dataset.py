"""One simulated run: measured signals, noise-free reference signals, exact truth, provenance.

Stored as one HDF5 file (h5py), data apart from code and config stored with data,
as PDEBench does.  Layout::

    /                       attrs: format, rig, seed, fs [Hz], scenario (canonical JSON),
                                   versions (JSON), git_commit, gravity, content_hash, ...
    /measured/<name>        (channels, samples) what a lab records (noisy if noise was asked)
    /reference/<name>       (channels, samples) the same quantities, noise-free, and the
                            true states (e.g. sensor displacements) no lab would have
    /truth/<name>           exact truth arrays (M, K, frequencies, ...); attr ``unit``
    /prior                  attrs: prior knowledge an identifier may be given (e.g. total mass)

Every signal dataset carries attrs ``unit``, ``channels`` and, where defined,
``positions`` [m].  Writes are atomic: the file appears whole or not at all.  Reads are
verified: :meth:`Dataset.load` recomputes the content hash and compares it with the stored
one, and an unreadable, foreign or altered file raises :class:`DatasetError` naming the file.
"""

from __future__ import annotations

import hashlib
import io
import json
import numbers
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, TypeVar

import numpy as np

from testbed.core import arguments as args
from testbed.core.atomic import atomic_write
from testbed.core.errors import ArgumentError, TestbedError
from testbed.core.lazy import lazy_module
from testbed.core.measurement import check_prior_values
from testbed.core.truth import Truth, TruthError, truth_type

h5py = lazy_module("h5py")  # imported on first use: `testbed list` does not pay for it

#: Format written.  /2: the content hash covers the data-defining attributes only (see
#: :meth:`Dataset.content_hash`); /1 files hashed every attribute but versions and commit.
FORMAT = "sysid-testbed-dataset/2"
#: Formats read (a /1 file is verified against the hash it was written with).
READ_FORMATS = ("sysid-testbed-dataset/1", FORMAT)

T = TypeVar("T", bound=Truth)

#: Keys of the ``scenario`` attribute that decide the data (as :meth:`Scenario.data_dict`); the
#: name, description, tags, signal chain, ``[identify]`` and ``[score]`` do not.
DATA_KEYS = ("rig", "rig_params", "simulation", "excitation", "noise", "seed")
#: Attributes that describe how or where the data were made or by which scenario file, not what
#: they are: left out of the content hash.  ``kind`` follows from ``rig`` (which is hashed);
#: leaving it out keeps the hashes of files written before it was recorded.
_NOT_CONTENT = ("versions", "git_commit", "content_hash", "created", "scenario", "scenario_name",
                "kind")


class DatasetError(TestbedError, ValueError):
    """A dataset file cannot be read, is not a dataset, or its content does not match its hash.

    Parameters
    ----------
    path : path-like
        The offending file.
    reason : str
        What is wrong with it.
    """

    def __init__(self, path: str | os.PathLike, reason: str) -> None:
        self.path, self.reason = Path(path), reason
        super().__init__(f"{path}: {reason}")


@dataclass
class Signal:
    """A group of sampled channels sharing a unit.

    Parameters
    ----------
    data : ndarray, shape (n_channels, n_samples)
    channels : tuple of str
        One name per row.
    unit : str
        SI unit of every channel, e.g. ``"m/s^2"``; or one per channel, comma-separated, for a
        group of mixed coordinates (``"m, rad"``: a cart's position and a pole's angle).
    positions : ndarray, shape (n_channels,), optional
        Position of each channel along the structure [m], where defined.
    acts_on : tuple of str, optional
        For an input signal (e.g. joint torques): per row, the name of the coordinate channel
        (of another signal, e.g. ``"th1"`` of ``theta``) the input acts on.  A signal chain
        builds its ``Measurement.input_map`` from it.
    """

    data: np.ndarray
    channels: tuple[str, ...]
    unit: str
    positions: np.ndarray | None = None
    acts_on: tuple[str, ...] | None = None

    def channel_units(self) -> list[str]:
        """One unit per channel: ``unit`` split at commas when it names one per channel, else
        ``unit`` for every channel."""
        units = [u.strip() for u in self.unit.split(",")]
        return units if len(units) == len(self.channels) else [self.unit] * len(self.channels)

    def __post_init__(self) -> None:
        """Check every field where a signal is made (the API's, a rig's and a reader's), by the
        shared rules of :mod:`testbed.core.arguments`: ``data`` a real array of one row per
        channel (a flat one is one channel), read as float64 in C order; NaN and inf are let
        through (the signal chain names a non-finite sample by channel and sample); ``channels``
        a list or tuple of texts, one per row; ``unit`` a text; ``positions`` real numbers (their
        count and finiteness named by the readers that use them); ``acts_on`` texts, one per
        row.

        The API's ``Signal`` took a masked array (the value under a mask measured), complex
        samples (the imaginary part dropped with a warning), booleans (read as 0 / 1), object,
        text and datetime arrays, ``channels="x"`` (read per character) and a ``unit`` of 5
        (round 25's open (c), round 26): each is refused in one line.

        Raises
        ------
        ArgumentError
            Naming the field, its value (an array by shape and dtype) and what is allowed.
        """
        where = "Signal"
        data = self.data
        if (isinstance(data, np.ndarray) and data.ndim == 1) or (
                isinstance(data, (list, tuple)) and _flat(data)):
            data = data[None, :] if isinstance(data, np.ndarray) else [list(data)]
        # C order always: a reduction over a row (e.g. the noise's RMS) then sums in one fixed
        # order whether the array came from a rig (often a transposed view) or from a file
        self.data = np.ascontiguousarray(args.array(where, "data", data, (None, None),
                                                    finite=False))
        rows = self.data.shape[0]
        self.channels = _texts(where, "channels", self.channels, rows)
        if not isinstance(self.unit, str):
            raise ArgumentError(where, "unit", self.unit, "expected a text (an SI unit, e.g. "
                                "'m/s^2', or one per channel, comma-separated)")
        if self.positions is not None:
            # real numbers (not text, complex, boolean), as float64; their count and finiteness
            # are the readers' to name where a chain reads them (a dynamical record has none to
            # read), in their words ("positions of shape (1,) for 3 channel(s)", round 8)
            dims = (None,) * np.ndim(self.positions) if _shaped(self.positions) else (None,)
            self.positions = args.array(where, "positions", self.positions, dims, finite=False)
        if self.acts_on is not None:
            self.acts_on = _texts(where, "acts_on", self.acts_on, rows)


def _texts(where: str, name: str, value: Any, rows: int) -> tuple[str, ...]:
    """``value`` (a list or tuple of ``rows`` texts, or a 1-D array of them) as a tuple; a
    single text is refused (it would be read as one name per character).  Whether the names
    are distinct and printable is the :class:`~testbed.core.measurement.Measurement`'s rule
    (a reader names a file's duplicate or blank channel in its own words)."""
    if isinstance(value, np.ndarray) and value.ndim == 1:
        value = value.tolist()
    if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) for v in value) \
            or len(value) != rows:
        raise ArgumentError(where, name, value, f"expected a tuple of {rows} text(s), one per "
                            "row of data")
    return tuple(value)


@dataclass
class Dataset:
    """Signals, truth and provenance of one run.  See the module docstring for the layout.

    Attributes
    ----------
    fs : float
        Sample rate [Hz].
    measured, reference : dict of str to Signal
    truth : dict of str to ndarray (or list of str)
    truth_units : dict of str to str
    prior : dict of str to float
        Prior knowledge an identifier may use (never the answer itself).
    attrs : dict
        Provenance: ``rig``, ``kind`` (the rig's kind), ``seed``, ``scenario`` (canonical
        JSON), ``versions``, ``git_commit``, ``gravity`` and anything else the rig records.

    Notes
    -----
    ``truth`` is a plain mapping (what is stored, and what a rig writes); its declaration is
    the kind's typed truth (:mod:`testbed.core.truth`), and readers take it as that dataclass:
    :attr:`typed_truth` (a reader of any kind) or :meth:`truth_as` (a reader of one kind, e.g. a
    scorer), never by key.  A dataset that names its kind
    (``attrs["kind"]``) has its truth validated when saved and loaded
    (:meth:`check_truth`), so a missing, unknown or misshapen truth key is an error naming
    the key; one that does not (a hand-made or imported dataset) is not checked.
    """

    fs: float
    measured: dict[str, Signal]
    reference: dict[str, Signal] = field(default_factory=dict)
    truth: dict[str, Any] = field(default_factory=dict)
    truth_units: dict[str, str] = field(default_factory=dict)
    prior: dict[str, float] = field(default_factory=dict)
    attrs: dict[str, Any] = field(default_factory=dict)

    @property
    def n_samples(self) -> int:
        return next(iter(self.measured.values())).data.shape[1]

    @property
    def t(self) -> np.ndarray:
        """Sample times [s], shape (n_samples,)."""
        return np.arange(self.n_samples) / self.fs

    @property
    def kind(self) -> str | None:
        """The kind of the rig that made the data (``attrs["kind"]``), None if not recorded."""
        kind = self.attrs.get("kind")
        return str(kind) if kind else None

    @property
    def typed_truth(self) -> Truth:
        """The truth as its kind's dataclass (:mod:`testbed.core.truth`), validated.

        Raises
        ------
        TruthError
            If the dataset records no kind, or the truth does not fit the kind's declaration.
        """
        if self.kind is None:
            raise TruthError("the dataset records no rig kind (attrs['kind']); its truth has "
                             "no declared type")
        return truth_type(self.kind).from_dict(self.truth, self.truth_units)

    def truth_as(self, cls: type[T]) -> T:
        """The truth as ``cls`` (a kind's dataclass, e.g. ``StructuralTruth``), validated.

        What a reader that needs one kind's truth calls (a scorer, an exporter of modes): its
        fields are attributes, so a misspelt name is an ``AttributeError`` where it is written,
        not a missing key at run time.  A dataset that records its kind gives that kind's
        truth type, which must be ``cls`` or a subclass; one that records none (a hand-made
        dataset) is read as ``cls``.

        Raises
        ------
        TruthError
            If the recorded kind's truth is not a ``cls``, or the truth does not fit ``cls``
            (naming the missing, unknown or misshapen key).
        """
        typ = cls if self.kind is None else truth_type(self.kind)
        if not issubclass(typ, cls):
            raise TruthError(f"the dataset's truth is of rig kind {self.kind!r} ({typ.__name__}), "
                             f"not {cls.__name__}")
        return typ.from_dict(self.truth, self.truth_units)

    def check_truth(self) -> None:
        """Validate the truth against its kind's declaration, if the dataset records a kind.

        Raises
        ------
        TruthError
            Naming the missing, unknown or misshapen key, or a kind without a truth type.
        """
        if self.kind is not None:
            truth_type(self.kind).validate(self.truth, self.truth_units)

    def content_hash(self) -> str:
        """SHA-256 of everything that is data: signals, truth, prior, sample rate, and the
        data-defining attributes (rig, seed, the scenario's :data:`DATA_KEYS` sections, what
        the rig records, e.g. ``gravity``).

        Left out: versions, commit, the hash itself, and what only names or judges the data
        (the scenario's name, description, tags, signal chain, ``[identify]``, ``[score]``).
        The hash thus names the content: two scenarios that differ only in identifier or
        thresholds give the same hash, and so does the same scenario and seed on any machine
        whose physics engine gives the same numbers.
        """
        meta = {k: v for k, v in self.attrs.items() if k not in _NOT_CONTENT}
        scenario = self.attrs.get("scenario")
        if isinstance(scenario, dict):
            meta["scenario"] = {k: scenario[k] for k in DATA_KEYS if k in scenario}
        return self._hash(meta)

    def _legacy_content_hash(self) -> str:
        """The hash a format /1 file was written with (every attribute but versions and commit)."""
        return self._hash({k: v for k, v in self.attrs.items()
                           if k not in ("versions", "git_commit", "content_hash", "created")})

    def _hash(self, meta: dict[str, Any]) -> str:
        h = hashlib.sha256()
        # a list prior (``link_lengths``) is stored as an HDF5 array and read back as one: it is
        # hashed as that array is (``default=str``), or a saved dataset failed its own load's
        # verification (round 26); a scalar prior, every rig's, is hashed as before
        prior = {k: (str(np.asarray(v)) if isinstance(v, (list, tuple)) else v)
                 for k, v in self.prior.items()}
        # fs as the float the file stores, numpy scalars as the Python numbers a load reads
        # back (review 27a: fs = 100, attrs {"n": np.int64(3)} saved files whose own load
        # failed its hash check)
        # under numpy's default print options: a list or array prior is hashed by its printed
        # form, which a session's np.set_printoptions changed (a file saved under the defaults
        # failed its load's check after precision=3: read 27b); the same bytes as before
        with np.printoptions(precision=8, threshold=1000, edgeitems=3, linewidth=75,
                             suppress=False, floatmode="maxprec", sign="-", legacy=False):
            h.update(json.dumps({"fs": float(self.fs), "prior": prior, "attrs": meta},
                                sort_keys=True, default=_json_scalar).encode())
        for group, signals in (("measured", self.measured), ("reference", self.reference)):
            for name in sorted(signals):
                s = signals[name]
                h.update(f"{group}/{name}|{s.unit}|{','.join(s.channels)}".encode())
                h.update(np.ascontiguousarray(s.data, dtype="<f8").tobytes())
                if s.positions is not None:
                    h.update(np.ascontiguousarray(s.positions, dtype="<f8").tobytes())
                if s.acts_on is not None:  # left out when absent: older hashes stay valid
                    h.update(("acts_on|" + "\x1f".join(s.acts_on)).encode())
        for name in sorted(self.truth):
            h.update(f"truth/{name}|{self.truth_units.get(name, '')}".encode())
            v = self.truth[name]
            if isinstance(v, (list, tuple)) and v and isinstance(v[0], str):
                h.update("\x1f".join(v).encode())
            else:
                h.update(np.ascontiguousarray(np.asarray(v, dtype=float), dtype="<f8").tobytes())
        return h.hexdigest()

    def check_saveable(self) -> None:
        """Refuse, naming the field, key and value, what :meth:`save` would write as a file that
        :meth:`load` refuses or reads back otherwise, or fail on inside the HDF5 library.

        The rules: ``fs`` a finite rate > 0; at least one measured signal; every signal's,
        truth's and prior's name a non-empty text without ``/`` (HDF5 makes it a path of
        groups) or NUL, and not ``.``; a signal's channel names, unit and ``acts_on``, truth
        texts and truth units without NUL (HDF5's texts end at one); ``attrs`` keys
        texts other than the file's own (``format``, ``fs``, ``fs_unit``, ``json_attrs``),
        values a text, a number within int64 / float64 or JSON; the prior as
        :func:`~testbed.core.measurement.prior_ok` takes it; a truth value real numbers or a
        list of texts.  Before round 26 a hand-made dataset's save was TypeError, ValueError
        or OverflowError from inside (an attribute of a set, 10**400, a signal named ""), or
        wrote a file its own load refused (a signal named ``a/b``, an attribute ``fs``, a prior
        ``[1, 2]``, ``fs = "100"``, a complex truth).

        Raises
        ------
        ArgumentError
        """
        where = "Dataset.save"
        args.real(where, "fs", self.fs, low=0.0, low_open=True)
        if not isinstance(self.measured, dict) or not self.measured:
            raise ArgumentError(where, "measured", self.measured, "expected a dict of at least "
                                "one signal name to Signal")
        for group in ("measured", "reference"):
            signals = getattr(self, group)
            if not isinstance(signals, dict):
                raise ArgumentError(where, group, signals, "expected a dict of signal name to Signal")
            for name, sig in signals.items():
                _member_name(where, f"{group} name", name)
                if not isinstance(sig, Signal):
                    raise ArgumentError(where, f"{group}[{name!r}]", args.describe(sig),
                                        "expected a Signal(data, channels, unit)", described=True)
                if any("\x00" in t for t in (*sig.channels, sig.unit, *(sig.acts_on or ()))):
                    raise ArgumentError(where, f"{group}[{name!r}] names", (*sig.channels, sig.unit),
                                        "expected texts without NUL (HDF5's texts end at one)")
        for k, v in self.attrs.items():
            _check_attr(where, k, v)
        for name in self.prior:
            _member_name(where, "prior name", name)
        check_prior_values(where, self.prior)
        for name, v in self.truth.items():
            _member_name(where, "truth name", name)
            unit = self.truth_units.get(name, "")
            if not isinstance(unit, str) or "\x00" in unit:
                raise ArgumentError(where, f"truth_units[{name!r}]", unit,
                                    "expected a text without NUL (HDF5's texts end at one)")
            text = isinstance(v, (list, tuple)) and v and all(isinstance(x, str) for x in v)
            if text and any("\x00" in x for x in v):
                raise ArgumentError(where, f"truth[{name!r}]", v,
                                    "expected texts without NUL (HDF5's texts end at one)")
            number = isinstance(v, (numbers.Real, np.number)) and not isinstance(v, (bool, np.bool_))
            if not (text or number):
                args.array(where, f"truth[{name!r}]", v, (None,) * np.ndim(v) if _shaped(v) else
                           (None,), finite=False)

    # ------------------------------------------------------------------ HDF5
    def save(self, path: str | os.PathLike) -> Path:
        """Write atomically to ``path`` (a temporary file in the same folder, then rename).

        Raises
        ------
        TruthError
            If the dataset records a kind and its truth does not fit it (nothing is written).
        ArgumentError
            If a field cannot be written as :meth:`load` reads it back (:meth:`check_saveable`;
            nothing is written).
        """
        self.check_saveable()
        self.check_truth()
        self.attrs["content_hash"] = self.content_hash()

        def write(tmp: str) -> None:
            # built in memory, then written in one plain write: an HDF5 library that meets a
            # full disk (or `ulimit -f`) while writing a file printed tracebacks from its
            # finalizers and then crashed the process (SIGBUS, SIGSEGV); a plain write fails
            # with an OSError, named by :func:`~testbed.core.atomic.atomic_write`
            buffer = io.BytesIO()
            with h5py.File(buffer, "w", track_order=True) as f:
                self._write(f)
            with open(tmp, "wb") as fh:
                fh.write(buffer.getbuffer())

        return atomic_write(path, write)

    def _write(self, f: h5py.File) -> None:
        f.attrs["format"] = FORMAT
        f.attrs["fs"] = float(self.fs)
        f.attrs["fs_unit"] = "Hz"
        json_keys = []
        for k, v in self.attrs.items():
            if isinstance(v, (str, int, float, np.integer, np.floating, np.bool_)):
                f.attrs[k] = v
            else:
                f.attrs[k] = json.dumps(v, sort_keys=True)
                json_keys.append(k)
        f.attrs["json_attrs"] = json.dumps(json_keys)
        for group, signals in (("measured", self.measured), ("reference", self.reference)):
            g = f.create_group(group)
            for name, s in signals.items():
                d = g.create_dataset(name, data=s.data, track_times=False)
                d.attrs["unit"] = s.unit
                d.attrs["channels"] = list(s.channels)
                d.attrs["layout"] = "channels x samples"
                if s.positions is not None:
                    d.attrs["positions"] = s.positions
                    d.attrs["positions_unit"] = "m"
                if s.acts_on is not None:
                    d.attrs["acts_on"] = list(s.acts_on)
        g = f.create_group("truth")
        for name, v in self.truth.items():
            if isinstance(v, (list, tuple)) and v and isinstance(v[0], str):
                d = g.create_dataset(name, data=np.array(v, dtype=h5py.string_dtype()),
                                     track_times=False)
            else:
                d = g.create_dataset(name, data=np.asarray(v), track_times=False)
            d.attrs["unit"] = self.truth_units.get(name, "")
        p = f.create_group("prior")
        for k, v in self.prior.items():
            p.attrs[k] = v

    @classmethod
    def load(cls, path: str | os.PathLike, *, verify: bool = True) -> Dataset:
        """Read a file written by :meth:`save`; the result equals the saved object.

        Parameters
        ----------
        path : path-like
        verify : bool
            Recompute the content hash and compare it with the stored one.

        Raises
        ------
        DatasetError
            If the file is missing, not HDF5, truncated or otherwise unreadable, not a
            dataset of this format, or (``verify``) its content does not match its hash.
        """
        try:
            ds, fmt = cls._read(path)
        except DatasetError:
            raise
        except FileNotFoundError:
            raise DatasetError(path, "no such file") from None
        except Exception as e:  # h5py raises OSError, KeyError, ValueError ... for damaged files
            why = " ".join(str(e).split())  # one line, whatever the HDF5 library's message
            raise DatasetError(path, f"unreadable dataset file ({type(e).__name__}: {why})") from None
        if verify:
            stored = ds.attrs.get("content_hash")
            if not stored:
                raise DatasetError(path, "no content hash stored; cannot verify")
            actual = ds._legacy_content_hash() if fmt != FORMAT else ds.content_hash()
            if actual != stored:
                raise DatasetError(path, "content does not match its stored content hash "
                                         "(the file was altered or damaged)")
            if fmt != FORMAT:  # verified as written; in memory it carries this format's hash
                ds.attrs["content_hash"] = ds.content_hash()
        try:
            ds.check_truth()
        except TruthError as e:
            raise DatasetError(path, str(e)) from None
        return ds

    @classmethod
    def _read(cls, path: str | os.PathLike) -> tuple[Dataset, str]:
        """(the dataset, its file's format) without verification."""
        if not Path(path).is_file():
            raise FileNotFoundError(path)
        with h5py.File(path, "r") as f:
            fmt = f.attrs.get("format")
            fmt = fmt.decode() if isinstance(fmt, bytes) else fmt
            if fmt not in READ_FORMATS:
                raise DatasetError(path, f"not a {FORMAT} file (format={fmt!r})")
            attrs: dict[str, Any] = {}
            json_keys = set(json.loads(f.attrs.get("json_attrs", "[]")))
            for k, v in f.attrs.items():
                if k in ("format", "fs", "fs_unit", "json_attrs"):
                    continue
                if isinstance(v, bytes):
                    v = v.decode()
                if k in json_keys:
                    v = json.loads(v)
                elif isinstance(v, np.generic):
                    v = v.item()
                attrs[k] = v
            _check_layout(path, f)
            groups: dict[str, dict[str, Signal]] = {}
            for group in ("measured", "reference"):
                groups[group] = {}
                for name, d in f[group].items():
                    if d.dtype.kind not in "fiu" or d.ndim not in (1, 2):
                        # complex lost its imaginary part (with a warning), strings were parsed
                        # as numbers and a 3-D array read as one flat channel
                        raise DatasetError(path, f"signal {group}/{name}: {d.dtype} data of shape "
                                                 f"{d.shape}; expected real numbers, one row per "
                                                 "channel")
                    pos = d.attrs.get("positions")
                    acts = d.attrs.get("acts_on")
                    groups[group][name] = Signal(d[()], tuple(str(c) for c in d.attrs["channels"]),
                                                 str(d.attrs["unit"]),
                                                 None if pos is None else np.asarray(pos),
                                                 None if acts is None else tuple(str(c) for c in acts))
            truth, units = {}, {}
            for name, d in f["truth"].items():
                if d.dtype.kind not in "fiuOS":
                    # a complex truth passed the hash check: the hash (and the typed truth)
                    # cast it to real, dropping an altered imaginary part with a warning
                    raise DatasetError(path, f"truth/{name}: {d.dtype} data; expected real "
                                             "numbers or text")
                v = d[()]
                if d.dtype.kind in "OS":
                    v = [x.decode() if isinstance(x, bytes) else str(x) for x in v]
                truth[name] = v
                units[name] = str(d.attrs["unit"])
            prior = {k: (v.item() if isinstance(v, np.generic) else v) for k, v in f["prior"].attrs.items()}
            ds = cls(float(f.attrs["fs"]), groups["measured"], groups["reference"], truth, units,
                     prior, attrs)
            return ds, fmt


#: Attributes of a dataset file's root that :meth:`Dataset.save` writes itself.
_FILE_ATTRS = ("format", "fs", "fs_unit", "json_attrs")


def _flat(v: list | tuple) -> bool:
    """Whether a list is one flat row of values (a ragged one is not: ``args.array`` names it)."""
    try:
        return np.ndim(v) == 1
    except (ValueError, TypeError):
        return False


def _shaped(v: Any) -> bool:
    """Whether ``np.ndim`` can read ``v``'s dimensions (a ragged list cannot)."""
    try:
        np.ndim(v)
    except (ValueError, TypeError):
        return False
    return True


def _json_scalar(value: Any) -> Any:
    """``json.dumps``' fallback in the content hash: a numpy scalar as its Python number (as a
    load reads it back), anything else as its text."""
    return value.item() if isinstance(value, np.generic) else str(value)


def _member_name(where: str, label: str, name: Any) -> None:
    """Refuse a name HDF5 cannot hold as one member of a group (a text, non-empty, no ``/``
    (a path of groups) or NUL (texts end at one), not ``.``)."""
    if not isinstance(name, str) or not name or name == "." or "/" in name or "\x00" in name:
        raise ArgumentError(where, label, name, "expected a non-empty text without '/' or NUL, "
                            "not '.' (an HDF5 member's name)")


def _check_attr(where: str, key: Any, value: Any) -> None:
    """Refuse an ``attrs`` entry :meth:`Dataset.save` cannot write as :meth:`Dataset.load` reads it."""
    if not isinstance(key, str) or not key or key in _FILE_ATTRS or "\x00" in key:
        raise ArgumentError(where, "attrs key", key, "expected a non-empty text without NUL, none "
                            f"of the file's own {', '.join(_FILE_ATTRS)}")
    if isinstance(value, (bool, np.bool_)) or isinstance(value, (float, np.floating)):
        return
    if isinstance(value, (int, np.integer)):
        if not -2**63 <= int(value) < 2**63:
            raise ArgumentError(where, f"attrs[{key!r}]", value, "expected an integer within int64")
        return
    if isinstance(value, str):
        if "\x00" in value:
            raise ArgumentError(where, f"attrs[{key!r}]", value, "expected a text without NUL")
        return
    try:
        json.dumps(value, sort_keys=True)
    except (TypeError, ValueError) as e:
        raise ArgumentError(where, f"attrs[{key!r}]", value, "expected a text, a number or a "
                            f"JSON value ({e})") from None


#: The groups at a dataset file's root (the module docstring's layout); nothing else is read.
ROOT_GROUPS = ("measured", "reference", "truth", "prior")
#: Attributes a signal dataset carries (``unit`` and ``channels`` required) and a truth one.
SIGNAL_ATTRS = ("unit", "channels", "layout", "positions", "positions_unit", "acts_on")
TRUTH_ATTRS = ("unit",)


def _check_layout(path: str | os.PathLike, f: h5py.File) -> None:
    """Refuse a file whose layout is not the one :meth:`Dataset.save` writes, naming the member.

    What lies outside :data:`ROOT_GROUPS`, or an attribute a reader does not know, is outside
    the content hash and would be read without a word (an extra group at the root, a signal's
    extra attribute) or fail deep in the reader (an extra dataset under ``measured/`` without
    its ``channels``: "KeyError"); so each is refused naming the key and what is allowed.

    Raises
    ------
    DatasetError
    """
    allowed = ", ".join(ROOT_GROUPS)
    for name in f:
        if name not in ROOT_GROUPS:
            raise DatasetError(path, f"/{name}: not part of a dataset file (its root holds the "
                                     f"groups {allowed}; nothing else is read)")
    for group in ROOT_GROUPS:
        _check_hard_link(path, f, group)
        if not isinstance(f.get(group), h5py.Group):
            what = "missing" if group not in f else "not a group"
            raise DatasetError(path, f"/{group}: {what} (a dataset file's root holds the groups "
                                     f"{allowed})")
    if len(f["prior"]):
        raise DatasetError(path, f"/prior/{next(iter(f['prior']))}: the prior is held in the "
                                 "group's attributes; it has no members")
    for group, keys, required in (("measured", SIGNAL_ATTRS, ("unit", "channels")),
                                  ("reference", SIGNAL_ATTRS, ("unit", "channels")),
                                  ("truth", TRUTH_ATTRS, ("unit",))):
        for name in f[group]:
            where = f"/{group}/{name}"
            _check_hard_link(path, f[group], name, where)
            d = f[group][name]
            if not isinstance(d, h5py.Dataset):
                raise DatasetError(path, f"{where}: a group; /{group} holds datasets only")
            for key in required:
                if key not in d.attrs:
                    raise DatasetError(path, f"{where}: no attribute {key!r} (a member of "
                                             f"/{group} carries {', '.join(required)})")
            for key in d.attrs:
                if key not in keys:
                    raise DatasetError(path, f"{where}: unknown attribute {key!r} (allowed: "
                                             f"{', '.join(keys)})")


def _check_hard_link(path: str | os.PathLike, group: h5py.Group, name: str, where: str = "") -> None:
    """Refuse a soft or external link: its target (elsewhere in the file, or in another file)
    would be read as this member's content."""
    link = group.get(name, getlink=True)
    if link is not None and not isinstance(link, h5py.HardLink):
        raise DatasetError(path, f"{where or '/' + name}: a {type(link).__name__} (to "
                                 f"{getattr(link, 'path', '?')!r}); a dataset file holds its "
                                 "members itself")
