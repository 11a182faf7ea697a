"""Measured data from files: UFF58, SEP-005 JSON, CSV and the project's HDF5, for identification.

One entry point, :func:`read_measured`, gives an :class:`ImportedData`: the sample rate, one
1-D array per channel in SI units, and where the file says so each channel's node,
direction and position.  :meth:`ImportedData.to_dataset` turns it into a truth-free
:class:`~testbed.core.dataset.Dataset` that :func:`testbed.pipeline.signal_chain.measure` (the rig kind's
signal chain) turns into the :class:`~testbed.core.measurement.Measurement` an identifier fits.

Formats (``format=`` or from the file's suffix)
    ``"uff"`` (``.uff``, ``.unv``)
        Every UFF58 record must be a time response (function type 1) with real ordinates;
        one channel per record, named by ID line 1 (``"acceleration/acc1"`` in this
        project's exports; ``"node<N>:<dir>"`` when ID line 1 is empty).  The sample rate is
        the ``fs ... Hz`` of ID line 5 when present (this project's exports state it exactly),
        else ``1 / abscissa increment`` (6 significant digits in the UFF header).  The unit is
        the ordinate's axis label, else the one its specific data type and unit exponents
        name.  Nodes and directions come from the response node and direction; positions
        [m] from the x coordinate of that node in a UFF2411 or UFF15 record.  A UFF164 record
        must be SI (all factors 1).  Other records (55, 82, ...) are ignored.  A file
        whose last block is unfinished (no closing ``-1``) is refused as truncated.
    ``"sep005"`` (``.json``)
        A JSON list of SEP-005 channel dicts (``name``, ``data``, ``unit_str`` and ``fs`` or
        ``time``), as :func:`testbed.reporting.export.write_sep005` writes, with the optional
        ``node``, ``direction`` and ``position_m`` it adds.  :func:`from_sep005` takes the
        same list in memory (``data`` as list or 1-D ndarray).
    ``"csv"`` (``.csv``, ``.tsv``, ``.txt``)
        A header row of channel names (``"acc1"``, or with a unit: ``"acc1 [m/s^2]"``), then
        one row of numbers per sample; delimiter ``,``, ``;``, tab or blanks (from the
        header); lines starting with ``#`` are skipped.  A column named ``t`` or ``time``
        (unit s, if given) is the time: it must be uniform (each step within 1 % of the
        median step), and ``fs = (n - 1) / (t[-1] - t[0])``; without it ``fs`` must be given.
    ``"hdf5"`` (``.h5``, ``.hdf5``)
        A dataset file of this project (:meth:`Dataset.load`, content hash verified): its
        measured signals only (never the truth or the reference), channels named
        ``"<signal>/<channel>"``, and its declared prior.

Units: every channel ends up in SI.  Accepted: ``m/s^2``, ``m/s``, ``m``, ``N``, ``rad``,
``rad/s``, ``rad/s^2``, ``N m`` (also ``m/s2``, ``N*m``, ``Nm``, ``N.m``, ``rad/s2``), and,
converted to those, ``g`` (9.80665 m/s^2), ``mm``, ``mm/s``, ``mm/s^2``, ``deg``, ``deg/s``,
``deg/s^2``, ``kN``, ``N mm``.  Anything else is an error.

Every problem with the file or the arguments (missing file, unknown format, unreadable
content, non-uniform time, channels of different lengths or rates, NaN or infinite values,
unknown unit or channel) raises :class:`MeasuredDataError`: one line naming the file.
"""

from __future__ import annotations

import csv
import json
import math
import os
import re
import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from testbed.core.arguments import finite_real
from testbed.core.budget import IDENTIFY_BYTES_PER_VALUE, IDENTIFY_TEXT_BUDGET_BYTES, IDENTIFY_VALUE_BUDGET
from testbed.core.dataset import Dataset, DatasetError, Signal
from testbed.core.errors import TestbedError, is_control, show_names, show_text, show_value
from testbed.core.measurement import MIN_FREE_SAMPLES, PRIOR_RANGE, Measurement, prior_ok
from testbed.core.numbertext import plain_number
from testbed.core.rate_attrs import fs_attribute_problem, off_scenario_rate
from testbed.numerics.clipping import Clipping, measured_clipping
from testbed.numerics.noise import noise_std
from testbed.pipeline.plugins import rig_class
from testbed.pipeline.signal_chain import SIGNAL_CHAINS, SIGNAL_SCHEMAS, measure, pulse_span

FORMATS = ("uff", "sep005", "csv", "hdf5")
SUFFIXES = {".uff": "uff", ".unv": "uff", ".json": "sep005", ".csv": "csv", ".tsv": "csv",
            ".txt": "csv", ".h5": "hdf5", ".hdf5": "hdf5"}
#: SI units a channel may have
SI_UNITS = ("m/s^2", "m/s", "m", "N", "rad", "rad/s", "rad/s^2", "N m")
#: other spellings and units -> (SI unit, factor to SI)
UNIT_ALIASES: dict[str, tuple[str, float]] = {
    "m/s2": ("m/s^2", 1.0), "m/s**2": ("m/s^2", 1.0), "m s^-2": ("m/s^2", 1.0),
    "N*m": ("N m", 1.0), "Nm": ("N m", 1.0), "N.m": ("N m", 1.0), "rad/s2": ("rad/s^2", 1.0),
    "g": ("m/s^2", 9.80665), "mm": ("m", 1e-3), "mm/s": ("m/s", 1e-3), "mm/s^2": ("m/s^2", 1e-3),
    "deg": ("rad", math.pi / 180), "deg/s": ("rad/s", math.pi / 180),
    "deg/s^2": ("rad/s^2", math.pi / 180), "kN": ("N", 1e3), "N mm": ("N m", 1e-3),
}
#: Units of the same quantity on a translational and a rotational coordinate: a group may
#: mix these, one unit per channel (a cart-pole's ``theta`` holds the cart's x [m] and the
#: pole's angle [rad]), never two quantities (an acceleration with a force)
SAME_ORDER = {"m": "coordinate", "rad": "coordinate", "m/s": "rate", "rad/s": "rate",
              "m/s^2": "acceleration", "rad/s^2": "acceleration", "N": "load", "N m": "load"}
#: UFF58 ordinate (specific data type, length exponent, force exponent, rotational) -> SI unit
_UFF_UNITS = {(12, 1, 0, False): "m/s^2", (11, 1, 0, False): "m/s", (8, 1, 0, False): "m",
              (13, 0, 1, False): "N", (8, 0, 0, True): "rad", (11, 0, 0, True): "rad/s",
              (12, 0, 0, True): "rad/s^2", (13, 1, 1, True): "N m"}
#: UFF specific data type -> the quantity it declares (:data:`SAME_ORDER`'s words), on a
#: translational or a rotational coordinate alike
_UFF_QUANTITY = {8: "coordinate", 11: "rate", 12: "acceleration", 13: "load"}
#: Largest magnitude [SI unit] a channel may reach: identifier libraries go up to cubes of the
#: signals and their Gram matrices sum squares of those, i.e. sixth powers, over the record;
#: 1e50 keeps (1e50)^6 x 1e6 samples = 1e306 below float64's 1.8e308 (no physical record
#: comes near: an accelerometer saturates below 1e6 m/s^2).
MAX_MAGNITUDE = 1e50
#: The measured response of each rig kind (what moves): a record in which it is constant, or
#: whose peak is below 1 / MAX_MAGNITUDE (sixth powers underflow), holds no motion to identify.
RESPONSE_SIGNAL = {"structural": "acceleration", "mechanical": "theta", "dynamical": "x"}
#: a CSV column of these names (case-insensitive) is the time
TIME_NAMES = ("t", "time")
#: a time column's steps may differ from their median by this fraction
TIME_TOLERANCE = 0.01
#: The ``layout`` attribute of a dataset file's signal arrays (what ``Dataset.save`` writes).
LAYOUT = "channels x samples"
#: a rate declared twice (``--fs`` and the file's; a SEP-005 channel's ``fs`` and ``time``) may
#: differ by this fraction: a time printed to 4 significant digits over a record of 1,000
#: samples (t[-1] to +-5e-4 relative) stays within it; a wrong rate (2x, 1.5 %) does not
DECLARED_RATE_RTOL = 1e-3


class MeasuredDataError(TestbedError, ValueError):
    """A measured-data file cannot be imported as asked.

    Parameters
    ----------
    path : path-like
        The offending file.
    reason : str
        What is wrong with it (one line).
    """

    def __init__(self, path: str | os.PathLike, reason: str) -> None:
        self.path, self.reason = Path(path), " ".join(str(reason).split())
        super().__init__(f"{path}: {self.reason}")  # shown escaped: TestbedError.__str__


@dataclass
class ImportedData:
    """Measured channels of one record, in SI units, without any truth.

    Attributes
    ----------
    fs : float
        Sample rate [Hz].
    signals : dict of str to (str, ndarray)
        Channel name -> (SI unit, samples of shape (n_samples,)), in file order (or the
        order of ``channels=``); every channel has the same length and only finite values.
    source : Path
        The file read.
    format : str
        One of :data:`FORMATS`.
    nodes : dict of str to int
        Node number of the channels whose file gives one (UFF response node, SEP-005 ``node``).
    directions : dict of str to int
        UFF direction code where given (1..3 translation along x, y, z; 4..6 rotation about
        them; negative: the opposite sense).
    positions : dict of str to float
        Position [m] along the structure of the channels whose file gives one.
    prior : dict of str to float
        Declared prior knowledge stored with the data (HDF5 datasets only), e.g. ``total_mass``.
    """

    fs: float
    signals: dict[str, tuple[str, np.ndarray]]
    source: Path
    format: str
    nodes: dict[str, int] = field(default_factory=dict)
    directions: dict[str, int] = field(default_factory=dict)
    positions: dict[str, float] = field(default_factory=dict)
    prior: dict[str, float] = field(default_factory=dict)

    @property
    def n_samples(self) -> int:
        """Number of samples of every channel."""
        return next(iter(self.signals.values()))[1].size

    @property
    def t(self) -> np.ndarray:
        """Sample times [s], shape (n_samples,), starting at 0."""
        return np.arange(self.n_samples) / self.fs

    def to_dataset(self, groups: Mapping[str, Sequence[str]] | None = None,
                   prior: Mapping[str, float] | None = None,
                   acts_on: Mapping[str, Sequence[str]] | None = None) -> Dataset:
        """The channels as a truth-free Dataset, ready for :func:`testbed.pipeline.signal_chain.measure`.

        Parameters
        ----------
        groups : mapping of str to sequence of str, optional
            Signal name -> channel names, e.g. ``{"acceleration": ["a1", "a2", "a3"], "force":
            ["hammer"]}``.  Default: channels named ``"<signal>/<channel>"`` (as exported) are
            grouped by ``<signal>``; any other channel is a signal of its own.  The structural
            chain needs ``"acceleration"`` and ``"force"`` with positions, the mechanical one
            ``"theta"``, ``"dtheta"``, ``"ddtheta"`` (4 channels each) and ``"torque"`` (2).
        prior : mapping of str to float, optional
            Declared prior knowledge (e.g. ``total_mass`` [kg]); updates :attr:`prior`.
        acts_on : mapping of str to sequence of str, optional
            Input signal -> the coordinate channel each of its rows acts on
            (:attr:`Signal.acts_on <testbed.core.dataset.Signal.acts_on>`), e.g. ``{"torque":
            ["th1", "th4"]}``.  Default: a ``"torque"`` group whose every channel shares its
            node with exactly one ``"theta"`` channel acts on those (an exported input sits at
            the node of the coordinate it drives; :mod:`testbed.reporting.export`).

        Returns
        -------
        Dataset
            ``measured`` only (each Signal's channels are the names after ``"/"``), ``fs``,
            ``prior``, and ``attrs["source"]`` / ``attrs["source_format"]``.

        Raises
        ------
        MeasuredDataError
            If a group names an unknown channel, mixes units, or has positions for only
            some of its channels, or a declared prior is not a finite number > 0.
        """
        if prior is not None and not (isinstance(prior, Mapping)
                                      and all(isinstance(k, str) and k for k in prior)):
            # prior=5 was a TypeError (round 17)
            raise MeasuredDataError(self.source, f"prior={prior!r}: expected a mapping of prior "
                                                 "names (non-empty str) to numbers")
        for key, value in dict(prior or {}).items():
            check_prior(self.source, key, value)
        if groups is None:
            grouped: dict[str, list[str]] = {}
            for name in self.signals:
                head, slash, tail = name.partition("/")
                if slash and not (head and tail):
                    # "acceleration/" was a channel named "" and "/x" a signal named "" (round
                    # 19): a report's rows and a `--units` key could not name them
                    raise MeasuredDataError(self.source, f"channel name {name!r}: an empty "
                                                         f"{'signal' if not head else 'channel'} "
                                                         "name around '/'; expected "
                                                         "'<signal>/<channel>' with both named")
                grouped.setdefault(head if slash else name, []).append(name)
        else:
            grouped = _checked_groups(self.source, groups)
        measured = {}
        for g, names in grouped.items():
            unknown = [n for n in names if n not in self.signals]
            if unknown or not names:
                raise MeasuredDataError(self.source, f"group {g!r}: unknown channel(s) "
                                        f"{', '.join(unknown) or '(none given)'}; "
                                        f"has {', '.join(self.signals)}")
            units = [self.signals[n][0] for n in names]
            if len(set(units)) > 1 and len({SAME_ORDER.get(u, u) for u in units}) > 1:
                raise MeasuredDataError(self.source, f"group {g!r} mixes units "
                                                     f"{', '.join(sorted(set(units)))}")
            have = [n in self.positions for n in names]
            if any(have) and not all(have):
                raise MeasuredDataError(self.source, f"group {g!r}: only some channels have positions")
            measured[g] = Signal(np.array([self.signals[n][1] for n in names]),
                                 tuple(n.split("/", 1)[1] if "/" in n else n for n in names),
                                 units[0] if len(set(units)) == 1 else ", ".join(units),
                                 np.array([self.positions[n] for n in names]) if all(have) else None)
        declared = dict(acts_on or {})
        if not declared and "torque" in grouped and "theta" in grouped:
            coords = [(self.nodes.get(n), n.split("/", 1)[-1]) for n in grouped["theta"]]
            targets = []
            for n in grouped["torque"]:
                hits = [c for node, c in coords if node is not None and node == self.nodes.get(n)]
                targets.append(hits[0] if len(hits) == 1 else None)
            if all(t is not None for t in targets):
                declared["torque"] = targets
        for g, names in declared.items():
            if g not in measured:
                raise MeasuredDataError(self.source, f"acts_on names signal {g!r}; has "
                                                     f"{', '.join(measured)}")
            sg = measured[g]
            if len(names) != len(sg.channels):
                raise MeasuredDataError(self.source, f"acts_on of {g!r}: {len(names)} names for "
                                                     f"{len(sg.channels)} channels")
            measured[g] = Signal(sg.data, sg.channels, sg.unit, sg.positions, tuple(names))
        return Dataset(float(self.fs), measured, prior={**self.prior, **dict(prior or {})},
                       attrs={"source": str(self.source), "source_format": self.format})


def read_measured(path: str | os.PathLike, *, format: str | None = None, fs: float | None = None,
                  units: str | Mapping[str, str] | None = None,
                  channels: Sequence[str] | None = None, own_units: bool = False) -> ImportedData:
    """Read measured data for identification (no truth) from a UFF, SEP-005, CSV or HDF5 file.

    Parameters
    ----------
    path : path-like
        The file.
    format : {"uff", "sep005", "csv", "hdf5"}, optional
        Default from the suffix (see :data:`SUFFIXES`).
    fs : float, optional
        Sample rate [Hz].  Needed for a CSV file without a time column; otherwise, if given,
        it must agree with the file's rate to 0.1 % and then replaces it (exact).
    units : str or mapping of str to str, optional
        Unit of every channel (str) or per channel name; overrides the file's units and is
        required where the file has none (CSV without ``[unit]`` in its header).
    channels : sequence of str, optional
        Keep only these channels, in this order (default: all, in file order).
    own_units : bool
        Keep a unit with no SI form as it is (a ``dynamical`` system's concentrations, "mM",
        "mM/s": its chain converts nothing) instead of refusing it; a testbed dataset of a
        dynamical rig keeps its own units whatever this says.

    Returns
    -------
    ImportedData
        Sample rate [Hz], channels in SI units (shape (n_samples,) each), nodes, directions
        and positions [m] where the file gives them.

    Raises
    ------
    MeasuredDataError
        Missing file, unknown format, unreadable or malformed content, non-uniform time,
        channels of different lengths or rates, non-finite values, unknown unit or channel,
        a declared ``fs`` the file contradicts.
    """
    if not isinstance(path, (str, os.PathLike)) or isinstance(os.fspath(path), bytes):
        # an int or bytes: TypeError from pathlib (round 17)
        raise MeasuredDataError(str(path), f"path={path!r} ({type(path).__name__}); expected a "
                                           "file path (str or os.PathLike)")
    path = Path(path)
    if format is None:
        format = SUFFIXES.get(path.suffix.lower())
        if format is None:
            # the command line's user passes --format, not format= (round 22: `testbed export
            # --format sep005 -o d.sep005` then `identify d.sep005` was told "pass format=")
            raise MeasuredDataError(path, f"cannot tell the format from the suffix {path.suffix!r} "
                                          f"(known: {', '.join(SUFFIXES)}); pass format= "
                                          f"(--format on the command line) one of "
                                          f"{', '.join(FORMATS)}")
    if format not in FORMATS:
        raise MeasuredDataError(path, f"unknown format {format!r}; allowed: {', '.join(FORMATS)}")
    check_selection(path, units, channels)
    if not path.is_file():
        raise MeasuredDataError(path, "no such file")
    if fs is not None and not (isinstance(fs, (int, float)) and math.isfinite(fs) and fs > 0):
        raise MeasuredDataError(path, f"sample rate fs={fs!r} must be a finite number > 0 Hz")
    if format != "hdf5" and path.stat().st_size > IDENTIFY_TEXT_BUDGET_BYTES:
        raise MeasuredDataError(path, f"file size {path.stat().st_size} bytes; expected at most "
                                      f"{IDENTIFY_TEXT_BUDGET_BYTES} bytes for a text file "
                                      "(testbed.core.budget.IDENTIFY_TEXT_BUDGET_BYTES: read into "
                                      "numbers it could exceed the 4 GiB memory budget); cut the "
                                      "record or decimate it")
    reader = {"uff": _read_uff, "sep005": _read_sep005_file, "csv": _read_csv, "hdf5": _read_hdf5}[format]
    raw = reader(path)
    raw.own_units = raw.own_units or own_units
    return _finish(raw, fs, units, channels)


def measurement_from_file(path: str | os.PathLike, kind: str, signal: Mapping[str, Any] | None = None, *,
                          format: str | None = None, fs: float | None = None,
                          units: str | Mapping[str, str] | None = None,
                          channels: Sequence[str] | None = None,
                          groups: Mapping[str, Sequence[str]] | None = None,
                          prior: Mapping[str, float] | None = None) -> Measurement:
    """Read measured data and run the rig kind's signal chain: what an identifier fits.

    ``measure(read_measured(path, ...).to_dataset(groups, prior), signal or {}, kind)``.

    Parameters
    ----------
    path, format, fs, units, channels
        As for :func:`read_measured`.
    kind : {"structural", "mechanical", "dynamical"}
        The rig kind whose chain to run (:data:`testbed.pipeline.signal_chain.SIGNAL_SCHEMAS`).
    signal : mapping, optional
        The ``[signal]`` table (a scenario's ``scenario.signal``); default: the kind's defaults.
    groups, prior
        As for :meth:`ImportedData.to_dataset`.

    Returns
    -------
    Measurement
        ``x``, ``xd``, ``xdd`` of shape (n_channels, n_samples), inputs ``u``, ``input_map``.

    Raises
    ------
    MeasuredDataError
        The file or the arguments (see :func:`read_measured`), or data the chain cannot take
        (wrong signal names or channel counts, no positions for a structural record).
    ScenarioError
        A bad ``signal`` table.

    Warns
    -----
    ClippedSensorWarning
        One per clip level of a channel (:func:`measurement_and_clipping`): the file, the
        channel, the share of its samples at the level and the level.  Nothing is refused.
    """
    data, clipped = measurement_and_clipping(path, kind, signal, format=format, fs=fs, units=units,
                                             channels=channels, groups=groups, prior=prior)
    for line in clipping_lines(path, clipped):  # said, not refused (an API caller's warning)
        warnings.warn(line, ClippedSensorWarning, stacklevel=2)
    return data


class ClippedSensorWarning(UserWarning):
    """A channel of a measured record holds a clip level (:mod:`testbed.numerics.clipping`)."""


def clipping_lines(path: str | os.PathLike, clipped: Sequence[Clipping]) -> list[str]:
    """One warning line per clip level: the file, the channel, the share of samples, the level."""
    return [f"{path}: {c.describe()}; a model of this record may be wrong (the sensor "
            "saturated: the record is not the response there)" for c in clipped]


def measurement_and_clipping(path: str | os.PathLike, kind: str,
                             signal: Mapping[str, Any] | None = None, *,
                             format: str | None = None, fs: float | None = None,
                             units: str | Mapping[str, str] | None = None,
                             channels: Sequence[str] | None = None,
                             groups: Mapping[str, Sequence[str]] | None = None,
                             prior: Mapping[str, float] | None = None
                             ) -> tuple[Measurement, list[Clipping]]:
    """:func:`measurement_from_file` and the record's clipped channels, with no warning.

    Returns
    -------
    Measurement
        As :func:`measurement_from_file`.
    list of Clipping
        The channels of the record as read (before the signal chain, in SI units) holding a
        clip level (:func:`testbed.numerics.clipping.measured_clipping`); empty for most.
    """
    if not isinstance(kind, str) or kind not in SIGNAL_SCHEMAS:
        raise MeasuredDataError(path, f"unknown rig kind {kind!r}; allowed: {', '.join(SIGNAL_SCHEMAS)}")
    if signal is not None and not isinstance(signal, Mapping):  # 5: AttributeError (round 17)
        raise MeasuredDataError(path, f"signal={signal!r} ({type(signal).__name__}); expected "
                                      "a [signal] table (a mapping) or None")
    data = read_measured(path, format=format, fs=fs, units=units, channels=channels,
                         own_units=kind == "dynamical")
    if kind == "structural":
        _check_one_axis(data.source, data.directions)
    ds = data.to_dataset(groups, prior)
    _check_read(data.source, ds, kind)
    _check_response(data.source, ds, kind)
    _check_units(data.source, ds, kind)
    if kind == "mechanical" and RESPONSE_SIGNAL[kind] in ds.measured:  # after the units: in rad
        _check_unwrapped(data.source, ds.measured[RESPONSE_SIGNAL[kind]], RESPONSE_SIGNAL[kind])
    # the rates the fit reads; they judge a held extreme (below) only where this check vouched
    checked = (signal or {}).get("derivatives", "recorded") == "recorded"
    if checked:
        _check_rates(data.source, ds, kind)
    try:
        return (measure(ds, dict(signal or {}), kind),
                measured_clipping(ds.measured, ds.fs, RATE_PAIRS.get(kind, ()) if checked else ()))
    except TestbedError:
        raise
    except ValueError as e:  # the chain's own checks: signal names, channel counts, positions
        raise MeasuredDataError(data.source, f"cannot run the {kind} signal chain: {e}; "
                                             f"signals {show_names(ds.measured)}"
                                             f"{_unnamed_hint(data) if groups is None else ''}") from None


#: A UFF58 record's channel name where its ID line 1 is empty: node and direction code.
_UFF_NODE_NAME = re.compile(r"node-?\d+:-?\d+(#\d+)?")


def _unnamed_hint(data: ImportedData) -> str:
    """A clause saying how to name the channels of UFF58 records without ID line 1 (named by
    the reader ``node<node>:<direction>``: a signal of its own each, which no chain reads), or
    "" where there is none.  Other formats' names without ``"/"`` are signals (a kinetics
    CSV's columns ``x``, ``dx``).

    fuzz25's open (d): such a file was refused "dataset has no measured signal 'acceleration'
    (has node1:3, ...)", naming no way to say which record is which."""
    unnamed = [n for n in data.signals if _UFF_NODE_NAME.fullmatch(n)] if data.format == "uff" else []
    if not unnamed:
        return ""
    return (f"; {len(unnamed)} UFF58 record(s) have no ID line 1 (named node<node>:<direction>): "
            "write each channel's '<signal>/<channel>' there (acceleration/acc1, force/hammer)")


def _check_one_axis(path: Path, directions: Mapping[str, int]) -> None:
    """Refuse a structural record whose channels point along different axes.

    The structural chain reads every acceleration and the force as one coordinate each of a
    planar chain, all along the axis it bends in; round 24: a sensor declared ``+Y`` beside
    ``+Z`` ones (UFF ``rsp_dir`` 2 beside 3, SEP-005 ``direction``) was fitted with status 0 as
    if it measured along Z.  Channels along one axis with either sign are one frame
    (:func:`_honour_direction_signs`); channels without a direction are not judged.

    Raises
    ------
    MeasuredDataError
        Naming a channel of each of two axes.
    """
    first: dict[int, str] = {}
    for name, code in directions.items():
        if code:
            first.setdefault(abs(code), name)
    if len(first) > 1:
        (a, na), (b, nb) = sorted(first.items())[:2]

        def said(code: int) -> str:
            return f"{'XYZ'[(code - 1) % 3]}{' rotation' if code > 3 else ''} (code {code})"

        raise MeasuredDataError(path, f"channel {na!r} points along {said(a)} and channel {nb!r} "
                                      f"along {said(b)}; a structural record is one planar "
                                      "chain: expected every sensor and the force along one axis")


def _check_read(path: Path, ds: Dataset, kind: str) -> None:
    """Refuse a signal the kind's chain never reads (:attr:`SignalChain.signals
    <testbed.pipeline.signal_chain.SignalChain.signals>`): a CSV's column ``y [mM]`` beside
    ``x`` and ``dx`` was dropped in silence and the model fitted to ``x`` alone (round 12)."""
    known = SIGNAL_CHAINS[kind].signals
    if RESPONSE_SIGNAL.get(kind) not in ds.measured:
        return  # data of another kind, or without their response: the chain says what is missing
    extra = [g for g in ds.measured if known is not None and g not in known]
    if extra:
        sig = ds.measured[extra[0]]
        raise MeasuredDataError(path, f"signal {extra[0]!r} (channel(s) {', '.join(sig.channels)}) "
                                      f"is not read by the {kind} signal chain, which reads "
                                      f"{', '.join(known)}; expected only those (leave the others "
                                      "out of the file, or name each channel "
                                      f"'<signal>/<channel>', e.g. '{known[0]}/{sig.channels[0]}')")


def _check_response(path: Path, ds: Dataset, kind: str) -> None:
    """Refuse a record whose response (:data:`RESPONSE_SIGNAL`) does not move, in which one
    channel does not move (a dead sensor), or whose sensors share a position (their equations
    would be the same)."""
    sig = ds.measured.get(RESPONSE_SIGNAL.get(kind, ""))
    if sig is None:
        return  # the chain says what is missing
    peaks = np.ptp(sig.data, axis=1)
    if not np.any(peaks > 1.0 / MAX_MAGNITUDE):
        raise MeasuredDataError(path, f"the {RESPONSE_SIGNAL[kind]!r} channels do not move "
                                      f"(largest peak-to-peak {float(peaks.max()):.3g} {sig.unit}): "
                                      "no motion to identify")
    dead = np.flatnonzero(~(peaks > 1.0 / MAX_MAGNITUDE))
    if dead.size:  # a dead sensor or a locked coordinate: its equation has nothing to fit
        raise MeasuredDataError(path, f"{RESPONSE_SIGNAL[kind]!r} channel "
                                      f"{sig.channels[dead[0]]!r} does not move (peak-to-peak "
                                      f"{float(peaks[dead[0]]):.3g} {sig.unit}) while others do: "
                                      "its equation cannot be identified; expected every channel "
                                      "to move (leave a dead sensor out of the file)")
    if sig.positions is not None and len(set(sig.positions.tolist())) < len(sig.positions):
        raise MeasuredDataError(path, f"the {RESPONSE_SIGNAL[kind]!r} channels share a position "
                                      f"({', '.join(f'{p:g}' for p in sig.positions)} m); expected "
                                      "one sensor per position")
    if kind == "structural":
        _check_pulse_ends(path, ds)
        _check_independent(path, sig, RESPONSE_SIGNAL[kind])


def _check_pulse_ends(path: Path, ds: Dataset) -> None:
    """Refuse a structural record whose force pulse has not ended ``MIN_FREE_SAMPLES`` samples
    before the record does: cut inside the impact, it holds no free decay to fit.

    Round 18: a beam record cut two samples into the pulse was refused as "'acceleration'
    channel 'acc3' is a linear combination of 'acc1', 'acc2'" (every channel zero but for two
    samples): one line, not the cause.  The pulse is the chain's own
    (:func:`~testbed.pipeline.signal_chain.pulse_span`)."""
    force = ds.measured.get("force")
    if force is None or force.data.ndim != 2 or not np.all(np.isfinite(force.data)):
        return  # the chain says what is missing; the reader refuses non-finite samples
    n = force.data.shape[1]
    start, end = pulse_span(force.data)
    if end > 0 and n - end < MIN_FREE_SAMPLES:
        mag = np.max(np.abs(force.data), axis=0)
        raise MeasuredDataError(path, f"the force pulse (from sample {start}) has not ended "
                                      f"{MIN_FREE_SAMPLES} samples before the record's last "
                                      f"(sample {n - 1}, force {mag[-1] / mag.max():.3g} of its "
                                      "peak): the record was cut inside the impact and holds no "
                                      "free decay to identify; expected the whole pulse and the "
                                      "decay after it")


def _check_unwrapped(path: Path, sig: Signal, name: str) -> None:
    """Refuse an angle channel (unit ``rad``) that steps by pi rad or more between two samples.

    An angle wrapped to (-pi, pi] (as many loggers store it) jumps by 2 pi where it crosses the
    cut: the signal chain differentiated the jump into spikes of 2 pi fs rad/s and the fit
    ended in "loop closure Newton solve did not converge" (round 16), naming neither the
    channel nor the wrap.  The rule: a step of pi rad or more in one sample is not motion the
    record can resolve (at half a turn a sample the direction of rotation is lost, as a
    frequency at Nyquist's), so it is a wrap or a glitch either way.  Over the 423 five-bar and
    cart-pole records of the dataset caches (noisy ones included) the largest step is 0.044 rad,
    72 times below the bound.
    """
    for ch, unit, row in zip(sig.channels, sig.channel_units(), np.asarray(sig.data), strict=True):
        if unit != "rad" or row.size < 2:
            continue
        steps = np.abs(np.diff(row))
        k = int(np.argmax(steps))
        if steps[k] >= math.pi:
            raise MeasuredDataError(path, f"{name!r} channel {ch!r} steps by "
                                          f"{row[k + 1] - row[k]:+.4g} rad between samples {k} "
                                          f"and {k + 1}: a wrapped angle (or a glitch)? expected "
                                          "a continuous angle, steps below pi rad a sample "
                                          "(unwrap it, e.g. numpy.unwrap)")


def _check_independent(path: Path, sig: Signal, name: str) -> None:
    """Refuse response channels that are linearly dependent to round-off: numpy's rank rule
    (singular values below ``s_max * max(shape) * eps``), naming the first channel that the
    ones before it give.

    An exact copy of a channel under another name and position (a column pasted twice) was
    identified with a mode at 1.6e-5 Hz and exit status 0 (round 12): the library's columns of
    the two are the same, and no fit can tell their equations apart.  Checked on the structural
    kind only, whose sensors sit at distinct points of a continuum: over the 935 cantilever
    records of the dataset caches the least singular value is 9.2e7 times the rule's bound.  A
    linkage's joint angles may be dependent by its motion: a five-bar test record driven alike
    at both inputs holds ``th4 = th1`` to 4e-11 rad (rank 3 of 4 by this rule), and its
    identifiers model the loop.
    """
    data = np.asarray(sig.data, dtype=float)
    if data.shape[0] < 2 or data.shape[1] < data.shape[0] or not np.all(np.isfinite(data)):
        return  # (non-finite samples are refused by the reader; fewer samples than channels
        # bound the rank whatever the channels: that record's length is the identifiers' to judge)
    for j in range(2, data.shape[0] + 1):
        if np.linalg.matrix_rank(data[:j]) < j:
            raise MeasuredDataError(path, f"{name!r} channel {sig.channels[j - 1]!r} is a linear "
                                          f"combination of {', '.join(map(repr, sig.channels[:j - 1]))} "
                                          "to round-off (a copy or a multiple of another?): their "
                                          "equations cannot be told apart; expected independent "
                                          "channels (leave the copy out of the file)")


#: Recorded (signal, its time derivative) pairs of a rig kind, checked against each other
RATE_PAIRS = {"mechanical": (("theta", "dtheta"), ("dtheta", "ddtheta")), "dynamical": (("x", "dx"),)}
#: Largest misfit of a recorded signal and the running integral of its recorded rate, relative
#: to the signal's own motion (RMS about their mean offset), before the pair is refused.  Over
#: the 1,019 pairs of the 425 five-bar and cart-pole and 169 Michaelis-Menten records of the
#: dataset caches the largest misfit is 0.021 (a cart-pole sampled at 100 Hz: the trapezoid
#: rule's own error; 0.017 for a stiff kinetics member), 24 times below the bound; white noise
#: of 5 % or 20 % of each channel's RMS on every signal and rate gives 0.05 or 0.20 (measured on
#: the shipped five-bar, cart-pole and kinetics records).  A rate in other units (rad/s beside
#: an angle in degrees, 57x) leaves 0.98 of the motion, a rate that is not the signal's (a copy
#: of the angle, its negative) 1 or more.
RATE_MISFIT_MAX = 0.5
#: Largest constant offset of a recorded rate, relative to its RMS, taken as the sensor's bias
#: (a gyroscope's or an accelerometer's offset integrates to a linear drift, which the misfit
#: above leaves aside) before the pair is refused: a rate of a signal that mostly ramps (a
#: spinning link) logged in other units shows its mismatch only as such an offset (57x, degrees
#: under rad: an offset of 56 times the rate's mean).  Over the 1,103 pairs of the cached
#: five-bar, cart-pole and kinetics records (noisy ones included) the largest is 2.7e-4 (a
#: cart-pole), the largest misfit with the offset set aside 0.021, as without.
RATE_BIAS_MAX = 0.25
#: Length of the windows the rate check compares over, in periods of the pair's own motion
#: (:func:`rate_misfit`): white noise of 20 % of the rate's RMS then misfits about 0.2 of the
#: motion whatever the record's length (over the whole of a 300 s record at 100 Hz it was 0.60).
RATE_WINDOW_PERIODS = 4.0


def _check_rates(path: Path, ds: Dataset, kind: str) -> None:
    """Refuse a recorded rate that is not the time derivative of its recorded signal: the
    running trapezoid integral of the rate must follow the signal to :data:`RATE_MISFIT_MAX`
    of its motion once a constant offset of the rate (a sensor's bias, a linear drift of the
    integral) is set aside, and that offset must stay within :data:`RATE_BIAS_MAX` of the
    rate's RMS, channel by channel (:data:`RATE_PAIRS`; :func:`rate_misfit`).

    A cart-pole whose pole angle was logged in degrees under the unit ``rad`` (its rate in
    rad/s), a five-bar whose rates were a copy of its angles and a Michaelis-Menten record whose
    ``dx`` was the negated rate were each fitted into a model with status 0 (round 16): the
    identifiers read the rates as given.  A record whose signal and rate are both scaled alike
    (all in degrees) is consistent and not caught here.  Checked only where the chain reads the
    recorded rates (``derivatives = 'recorded'``, the default): estimated from the signal, the
    recorded ones are not used, and a poor gyroscope is no reason to refuse the record.
    """
    for g, dg in RATE_PAIRS.get(kind, ()):
        if g not in ds.measured or dg not in ds.measured:
            continue
        x, dx = ds.measured[g], ds.measured[dg]
        a, d = np.asarray(x.data, dtype=float), np.asarray(dx.data, dtype=float)
        if a.shape != d.shape or a.shape[1] < 3:
            continue  # the chain says the shapes differ
        misfit, bias = rate_misfit(a, d, ds.fs)
        for k, ch in enumerate(x.channels):
            what = None
            if misfit[k] > RATE_MISFIT_MAX:
                what = (f"its running integral misses {misfit[k]:.3g} of that channel's motion "
                        f"(RMS, an offset and a drift aside); expected at most {RATE_MISFIT_MAX:g}")
            elif bias[k] > RATE_BIAS_MAX:
                what = (f"its running integral drifts from the signal as if the rate were offset "
                        f"by {bias[k]:.3g} of its RMS; expected at most {RATE_BIAS_MAX:g} (a "
                        "sensor's bias)")
            if what:
                raise MeasuredDataError(path, f"signal {dg!r} channel {dx.channels[k]!r} is not the "
                                              f"rate of {g!r} channel {ch!r}: {what} (a rate in other "
                                              "units, e.g. degrees under rad, or of another channel? "
                                              "or estimate the rates from the signal: [signal] "
                                              "derivatives = 'estimated')")


def rate_misfit(a: np.ndarray, d: np.ndarray, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """How far recorded rates are from the time derivatives of their recorded signals.

    The running trapezoid integral of each rate is compared with its signal in windows of
    :data:`RATE_WINDOW_PERIODS` of the pair's own period ``2 pi rms(d) / rms(a - mean a)`` (the
    whole record if shorter): an error of the rate that the integral would pile up over a long
    record (white noise, a slowly wandering offset) counts over a few periods only, as the
    motion does.  In each window the integral starts afresh and the misfit's mean and linear
    drift (a constant offset of the rate) are set aside.

    Parameters
    ----------
    a, d : ndarray, shape (n_channels, n_samples)
        The signals and their recorded rates (``d`` in ``a``'s unit per second).
    fs : float
        Sample rate [Hz].

    Returns
    -------
    misfit : ndarray, shape (n_channels,)
        RMS of the windows' misfits relative to the signal's RMS about its mean [-], where that
        motion stands above three times the signal's white-noise level (``noise_std``); 0 where
        it does not (a channel that hardly moves: nothing to check).
    bias : ndarray, shape (n_channels,)
        The rate's constant offset over the whole record (the whole-record misfit's slope)
        relative to the rate's RMS [-] (0 where the rate is identically 0).
    """
    n = a.shape[1]
    motion = np.sqrt(np.mean((a - a.mean(axis=1, keepdims=True)) ** 2, axis=1))
    rate = np.sqrt(np.mean(d ** 2, axis=1))
    floor = 3.0 * noise_std(a) if n >= 16 else np.zeros(a.shape[0])
    misfit, bias = np.zeros(a.shape[0]), np.zeros(a.shape[0])
    for k in range(a.shape[0]):
        if rate[k] > 0:
            bias[k] = abs(_detrended(a[k], d[k], fs)[1]) / rate[k]
        if not motion[k] > floor[k]:
            continue
        w = n if not rate[k] > 0 else int(min(n, max(3, RATE_WINDOW_PERIODS * 2 * np.pi * fs
                                                          * motion[k] / rate[k])))
        res = [_detrended(a[k, i:i + w], d[k, i:i + w], fs)[0] for i in range(0, n - w + 1, w)]
        res += [] if n % w < 3 else [_detrended(a[k, n - w:], d[k, n - w:], fs)[0]]
        misfit[k] = np.sqrt(np.mean(np.concatenate(res) ** 2)) / motion[k]
    return misfit, bias


def _detrended(a: np.ndarray, d: np.ndarray, fs: float) -> tuple[np.ndarray, float]:
    """The signal less its rate's running integral, mean and linear drift removed, and the
    drift's slope [unit/s] (the rate's constant offset, sign flipped)."""
    integral = np.concatenate([[0.0], np.cumsum((d[1:] + d[:-1]) * 0.5) / fs])
    # the time in samples, not seconds: at fs = 1e200 Hz tt @ tt [s^2] underflowed to 0 (a
    # ZeroDivisionError, round 17); the slope per sample is then scaled to per second
    k = np.arange(a.size) - 0.5 * (a.size - 1)
    res = a - integral
    res = res - res.mean()
    per_sample = float(res @ k) / float(k @ k) if a.size > 1 else 0.0
    return res - per_sample * k, per_sample * fs


#: What each measured signal of a rig kind holds (:data:`SAME_ORDER` of its unit); a
#: dynamical rig's ``dx`` is checked against its ``x`` instead (:func:`_check_units`).
SIGNAL_ORDER = {
    "structural": {"acceleration": "acceleration", "force": "load"},
    "mechanical": {"theta": "coordinate", "dtheta": "rate", "ddtheta": "acceleration",
                   "torque": "load"},
}
#: The SI unit of the time derivative of a quantity in an SI unit
RATE_OF = {"m": "m/s", "m/s": "m/s^2", "rad": "rad/s", "rad/s": "rad/s^2"}


def _check_units(path: Path, ds: Dataset, kind: str) -> None:
    """Refuse signals whose units are not what the kind's chain reads them as: an acceleration
    given in m, a rate in N, a dynamical ``dx`` that is not the rate of its ``x``.

    Raises
    ------
    MeasuredDataError
        Naming the signal, the channel, its unit and the unit (or kind of quantity) expected.
    """
    for g, want in SIGNAL_ORDER.get(kind, {}).items():
        if g not in ds.measured:
            continue  # the chain says what is missing
        sig = ds.measured[g]
        for ch, unit in zip(sig.channels, sig.channel_units(), strict=True):
            if SAME_ORDER.get(unit) != want:
                allowed = ", ".join(u for u, o in SAME_ORDER.items() if o == want)
                raise MeasuredDataError(path, f"signal {g!r} channel {show_value(ch)} is in "
                                              f"{show_text(unit)}; the {kind} chain reads {g!r} "
                                              f"as a {want} ({allowed})")
    if kind == "mechanical":
        _check_mechanical_units(path, ds)
    if kind == "dynamical" and "x" in ds.measured and "dx" in ds.measured:
        x, dx = ds.measured["x"], ds.measured["dx"]
        if len(x.channels) != len(dx.channels):
            return  # the chain says the row counts differ
        for ch, ux, ud in zip(dx.channels, x.channel_units(), dx.channel_units(), strict=True):
            rate = RATE_OF.get(ux, f"{ux}/s")
            if ud != rate:
                raise MeasuredDataError(path, f"signal 'dx' channel {show_value(ch)} is in {show_text(ud)}; "
                                              f"expected {show_text(rate)}, the rate of its state's "
                                              f"{show_text(ux)}")


#: The load that drives a coordinate of each SI unit: a force a translation, a moment a rotation.
LOAD_ON = {"m": "N", "rad": "N m"}


def _check_mechanical_units(path: Path, ds: Dataset) -> None:
    """Refuse a mechanical record whose units disagree channel by channel: a rate that is not
    in its coordinate's unit per second (``theta`` "rad, m" beside ``dtheta`` "m/s, rad/s"),
    or an input whose load does not drive the coordinate it acts on (a moment "N m" on a cart's
    position in m).  Each was fitted with status 0 (round 17): the checks above read every
    unit alone."""
    m = ds.measured
    for g, dg in RATE_PAIRS["mechanical"]:
        if g not in m or dg not in m or len(m[g].channels) != len(m[dg].channels):
            continue  # the chain says what is missing
        for ch, dch, u, du in zip(m[g].channels, m[dg].channels, m[g].channel_units(),
                                  m[dg].channel_units(), strict=True):
            if u in RATE_OF and du != RATE_OF[u]:
                raise MeasuredDataError(path, f"signal {dg!r} channel {show_value(dch)} is in "
                                              f"{show_text(du)}; expected {RATE_OF[u]}, the rate of "
                                              f"{g!r} channel {show_value(ch)} in {u}")
    coords = dict(zip(m["theta"].channels, m["theta"].channel_units(), strict=True)) \
        if "theta" in m else {}
    for g, sig in m.items():
        for ch, unit, target in zip(sig.channels, sig.channel_units(), sig.acts_on or (), strict=False):
            want = LOAD_ON.get(coords.get(target, ""))
            if want is not None and unit != want:
                raise MeasuredDataError(path, f"signal {g!r} channel {show_value(ch)} is in "
                                              f"{show_text(unit)} but acts on 'theta' channel "
                                              f"{show_value(target)} in {show_text(coords[target])}; "
                                              f"expected {want} (a force drives a translation, a "
                                              "moment a rotation)")


def from_sep005(channel_dicts: Sequence[Mapping[str, Any]], *, source: str | os.PathLike = "<sep005>",
                fs: float | None = None, units: str | Mapping[str, str] | None = None,
                channels: Sequence[str] | None = None) -> ImportedData:
    """:class:`ImportedData` from an in-memory SEP-005 channel list (e.g. another SDyPy tool's).

    Parameters
    ----------
    channel_dicts : sequence of mapping
        SEP-005 channels: ``name``, ``data`` (list or ndarray of shape (n_samples,)),
        ``unit_str`` and ``fs`` [Hz] or ``time`` [s]; optional ``node``, ``direction`` (int)
        and ``position_m`` [m].
    source : str or path-like
        What to name in errors and :attr:`ImportedData.source`.
    fs, units, channels
        As for :func:`read_measured`.

    Returns
    -------
    ImportedData
    """
    check_selection(source, units, channels)
    return _finish(_parse_sep005(Path(source), channel_dicts), fs, units, channels)


# --------------------------------------------------------------------------- shared checks
def _names(names: Any) -> bool:
    """Whether ``names`` is a collection of channel names: any iterable of ``str`` (a list, a
    tuple, a numpy array of ``str_``, a pandas Index) other than text itself or a mapping."""
    if isinstance(names, (str, bytes, Mapping)) or not isinstance(names, Iterable):
        return False
    return all(isinstance(c, str) for c in names)


def _checked_groups(source: Path, groups: Any) -> dict[str, list[str]]:
    """``groups`` of :meth:`ImportedData.to_dataset` as ``{signal: [channel, ...]}``, refused
    unless a mapping of signal names (non-empty text without ``/`` or control characters: a
    dataset file's group path) to lists of channel names, no channel given twice and no two
    channels of a signal sharing the name after their ``"/"``.  ``groups=5`` was an
    AttributeError, and a channel twice, a signal named ``""``, ``"a/b"`` or ``5`` made a
    Dataset (round 17)."""
    if not isinstance(groups, Mapping):
        raise MeasuredDataError(source, f"groups={groups!r}: expected a mapping of signal name to "
                                        "channel names")
    seen: dict[str, str] = {}
    out: dict[str, list[str]] = {}
    for g, chs in groups.items():
        if not isinstance(g, str) or not g or "/" in g or any(is_control(c) for c in g):
            raise MeasuredDataError(source, f"groups: signal name {g!r}; expected non-empty text "
                                            "without '/' or control characters")
        if not _names(chs):
            raise MeasuredDataError(source, f"group {g!r}: {chs!r}; expected a list of channel "
                                            "names (str)")
        short: set[str] = set()
        for c in chs:
            if c in seen:
                raise MeasuredDataError(source, f"channel {c!r} is given twice (in group "
                                                f"{seen[c]!r} and {g!r}); expected each at most once")
            seen[c] = g
            tail = c.split("/", 1)[1] if "/" in c else c
            if tail in short:
                raise MeasuredDataError(source, f"group {g!r}: two channels named {tail!r} after "
                                                "their '/'; expected one name per channel")
            short.add(tail)
        out[g] = list(chs)
    return out


def check_selection(source: str | os.PathLike, units: Any, channels: Any) -> None:
    """Refuse ``units`` that are not a unit (str) or a mapping of channel name to unit, and
    ``channels`` that are not a non-empty sequence of names: ``units=5`` was an AttributeError
    and ``channels=[]`` a ValueError of ``max()`` (round 17)."""
    if units is not None and not (isinstance(units, str) or (
            isinstance(units, Mapping) and all(isinstance(k, str) and isinstance(v, str)
                                               for k, v in units.items()))):
        raise MeasuredDataError(source, f"units={show_value(units)}: expected a unit (str) or a "
                                        "mapping of channel name to unit (str to str)")
    if channels is not None and (not _names(channels) or not list(channels)):
        raise MeasuredDataError(source, f"channels={show_value(channels)}: expected a non-empty list of "
                                        "channel names (str)")


@dataclass
class _Raw:
    """What a reader found, before units, selection and checks."""

    source: Path
    format: str
    fs: float | None
    data: dict[str, np.ndarray]
    units: dict[str, str | None]
    nodes: dict[str, int] = field(default_factory=dict)
    directions: dict[str, int] = field(default_factory=dict)
    positions: dict[str, float] = field(default_factory=dict)
    prior: dict[str, float] = field(default_factory=dict)
    #: time [s] of each channel's first sample, where the file states it per channel (a
    #: SEP-005 channel's ``time``, a UFF58 record's abscissa)
    starts: dict[str, float] = field(default_factory=dict)
    #: channels of ``starts`` whose start the file does not state (a SEP-005 channel with
    #: ``fs`` alone beside channels with a ``time``: taken as t = 0)
    implied_starts: set[str] = field(default_factory=set)
    #: the file's units are its rig's own and stay as they are (a testbed dataset of a
    #: ``dynamical`` rig: concentrations and the like have no SI form to convert to)
    own_units: bool = False


def si_unit(unit: str) -> tuple[str, float]:
    """(SI unit, factor to SI) of a unit string; ``("", nan)`` if unknown.

    Parameters
    ----------
    unit : str
        E.g. ``"m/s^2"``, ``"g"``, ``"N*m"``.
    """
    u = " ".join(unit.split())
    if u in SI_UNITS:
        return u, 1.0
    return UNIT_ALIASES.get(u, ("", math.nan))


def _check_declared_unit(path: Path, name: str, given: str | None, declared: str | None) -> None:
    """Refuse a unit given for a channel (``units=``, ``--units``) that contradicts the unit its
    file declares, as a declared ``fs`` the file contradicts is refused.

    Both must be units of :func:`si_unit` and name another SI unit or another factor: a file's
    unit that has no SI form ("general", a typo) is the case ``units=`` is there for.  Round
    18: ``--units acceleration/acc1=g`` on a SEP-005 beam whose ``unit_str`` says ``m/s^2``
    scaled that channel by 9.81 and fitted with status 0.

    Raises
    ------
    MeasuredDataError
    """
    if not given or not declared or given == declared:
        return
    (g_si, g_factor), (d_si, d_factor) = si_unit(given), si_unit(declared)
    if g_si and d_si and (g_si != d_si or not math.isclose(g_factor, d_factor, rel_tol=1e-12)):
        raise MeasuredDataError(path, f"channel {name!r}: units= gives {given!r} but the file "
                                      f"declares {declared!r}; a unit given must agree with the "
                                      "file's (leave it out for a channel whose file names its unit)")


def _finish(raw: _Raw, fs: float | None, units: str | Mapping[str, str] | None,
            channels: Sequence[str] | None, *, max_magnitude: float = MAX_MAGNITUDE) -> ImportedData:
    path = raw.source
    if not raw.data:
        raise MeasuredDataError(path, "no channels found")
    names = list(raw.data)
    for n in names:
        # a newline, a NUL or a terminal escape in a name went on to the console (an ESC
        # sequence coloured it), the model's JSON and its report's markdown (round 14)
        bad = next((c for c in n if is_control(c)), None)
        if bad is not None:
            raise MeasuredDataError(path, f"channel name {n!r} holds the control or invisible "
                                          f"character {bad!r} (U+{ord(bad):04X}); expected a name "
                                          "without control, bidirectional or zero-width characters")
    if channels is not None:
        missing = [c for c in channels if c not in raw.data]
        if missing:
            raise MeasuredDataError(path, f"no channel {', '.join(map(repr, missing))}; "
                                          f"has {', '.join(names)}")
        if len(set(channels)) != len(channels):
            raise MeasuredDataError(path, "channels= names a channel twice")
        names = list(channels)
    if isinstance(units, Mapping):
        unknown = [c for c in units if c not in raw.data]
        if unknown:
            raise MeasuredDataError(path, f"units= names unknown channel(s) {', '.join(unknown)}; "
                                          f"has {', '.join(raw.data)}")
    lengths = {n: raw.data[n].size for n in names}
    if len(set(lengths.values())) > 1:
        detail = ", ".join(f"{n} {k}" for n, k in lengths.items())
        raise MeasuredDataError(path, f"channels have different lengths ({detail} samples)")
    check_record_size(path, max(lengths.values()), len(names))
    if min(lengths.values()) < 2:
        raise MeasuredDataError(path, "fewer than 2 samples")
    rate = raw.fs
    if fs is not None:
        if rate is not None and abs(rate / fs - 1) > DECLARED_RATE_RTOL:
            raise MeasuredDataError(path, f"declared fs={fs:g} Hz but the file's rate is {rate:.9g} Hz")
        rate = float(fs)
    if rate is None:
        raise MeasuredDataError(path, "no time column (t or time) and no sample rate; pass fs= [Hz]")
    if not (math.isfinite(rate) and rate > 0):  # a dataset file's fs attribute of 0, -100 or NaN
        raise MeasuredDataError(path, f"sample rate {rate:g} Hz; expected a finite rate > 0 Hz")
    n = max(lengths.values())
    if not math.isfinite((n - 1) / rate):  # 5e-324 Hz: "inf steps" was blamed on identify.sim_dt
        raise MeasuredDataError(path, f"sample rate {rate:g} Hz: {n} samples would last forever "
                                      "(the duration overflows); expected a rate whose record lasts "
                                      "a finite time")
    _check_starts(path, {n: raw.starts[n] for n in names if n in raw.starts}, rate,
                  raw.implied_starts)
    signals = {}
    for n in names:
        unit = units if isinstance(units, str) else (units or {}).get(n, raw.units.get(n))
        _check_declared_unit(path, n, unit, raw.units.get(n))
        if not unit:
            raise MeasuredDataError(path, f"channel {n!r} has no unit; declare it with units=")
        si, factor = si_unit(unit)
        if not si and raw.own_units:
            si, factor = unit, 1.0
        if not si:
            raise MeasuredDataError(path, f"channel {n!r}: unknown unit {unit!r}; allowed: "
                                          f"{', '.join(SI_UNITS + tuple(UNIT_ALIASES))}")
        _check_direction(path, n, raw.directions.get(n, 0), si)
        x = np.asarray(raw.data[n], dtype=float)
        bad = np.flatnonzero(~np.isfinite(x))
        if bad.size:
            raise MeasuredDataError(path, f"channel {n!r} has {bad.size} NaN or infinite value(s), "
                                          f"the first at sample {bad[0]}")
        x = x * factor if factor != 1.0 else x.copy()
        peak = float(np.max(np.abs(x)))
        if peak > max_magnitude:
            raise MeasuredDataError(path, f"channel {n!r} reaches |value| {peak:.3g} {si}; "
                                          f"expected at most {max_magnitude:g} (larger values "
                                          "overflow the identifiers' sums of sixth powers)")
        signals[n] = (si, x)
    keep = set(names)
    # (a direction is stored only where it is not 0: the kept channels' own, their signs honoured)
    directions = _honour_direction_signs(
        {k: v for k, v in raw.directions.items() if k in keep}, signals)
    for key, value in raw.prior.items():  # a dataset file's own (an edited attribute)
        check_prior(path, key, value)
    return ImportedData(float(rate), signals, path, raw.format,
                        nodes={k: v for k, v in raw.nodes.items() if k in keep},
                        directions=directions,
                        positions={k: v for k, v in raw.positions.items() if k in keep},
                        prior=dict(raw.prior))


#: The SI units of rotations (an angle, its rates, a moment); the other SI units translate.
ROTATIONAL_UNITS = ("rad", "rad/s", "rad/s^2", "N m")


def _check_direction(path: Path, name: str, direction: int, si: str) -> None:
    """Refuse a channel whose direction and unit disagree: a rotation (UFF direction code
    +-4..6, SEP-005 ``"... rotation"``) measured in a translation's unit or the reverse (an
    acceleration in m/s^2 about X was read with status 0, round 17).  Units outside the SI
    ones (a dynamical rig's own) and channels without a direction are not checked."""
    if abs(direction) > 6:  # (a SEP-005 direction 9 or a UFF rsp_dir 9 read as a translation)
        raise MeasuredDataError(path, f"channel {name!r}: direction code {direction}; expected -6 "
                                      "to 6 (1-3 translations along X, Y, Z, 4-6 rotations about "
                                      "them, 0 none)")
    if not direction or si not in SI_UNITS:
        return
    turns, unit_turns = abs(direction) in (4, 5, 6), si in ROTATIONAL_UNITS
    if turns != unit_turns:
        axis = "XYZ"[(abs(direction) - 1) % 3]
        said = f"{'-' if direction < 0 else '+'}{axis}{' rotation' if turns else ''}"
        raise MeasuredDataError(path, f"channel {name!r}: direction {said} (code {direction}) "
                                      f"is a {'rotation' if turns else 'translation'} but its unit "
                                      f"{si!r} is a {'rotation' if unit_turns else 'translation'}'s; "
                                      "expected a direction and a unit of one kind")


def _honour_direction_signs(directions: Mapping[str, int],
                            signals: dict[str, tuple[str, np.ndarray]]) -> dict[str, int]:
    """Read channels that point opposite ways along one axis in one frame: where an axis holds
    both signs (UFF codes 3 and -3, SEP-005 ``+Z`` and ``-Z``), each channel declared along its
    negative direction has its samples negated in ``signals`` (in place) and its direction made
    positive; the directions returned.  A code says which way the transducer points (UFF 58's
    and SEP-005's meaning), so a sensor mounted upside down, or a hammer's force declared
    ``-Z`` beside ``+Z`` accelerometers, reads to the frame of the others.  Before round 23 a
    ``-Z`` sensor beside ``+Z`` ones was read as if it pointed along ``+Z`` (its mode shape's
    sign, and the model's coupling through it, reversed in silence); its first mend refused
    such files, which refused valid ones (review 24a).  Channels all along one signed axis (every
    one ``-Z``) are one frame, read as they are: the structural and mechanical models are odd
    in their signals, so a frame flipped as a whole is the same model."""
    positive = {c for c in directions.values() if c > 0}
    out = dict(directions)
    for name, code in directions.items():
        if code < 0 and -code in positive:
            si, x = signals[name]
            signals[name] = (si, -x)
            out[name] = -code
    return out


def _check_starts(path: Path, starts: Mapping[str, float], fs: float,
                  implied: set[str] | frozenset[str] = frozenset()) -> None:
    """Refuse channels whose first samples were taken at different times: the readers line
    the channels up sample by sample, so a force recorded 0.3 s after its responses (a SEP-005
    channel's ``time`` or a UFF58 record's abscissa starting later) was fitted as if
    simultaneous, with status 0 (round 17).  Within half a sample step [s] they agree (a
    time stamp's rounding).  A channel of ``implied`` states no start (``fs`` alone) and is
    named as such."""
    if len(starts) < 2:
        return
    (first, t0), (worst, tw) = next(iter(starts.items())), max(
        starts.items(), key=lambda kv: abs(kv[1] - next(iter(starts.values()))))
    if abs(tw - t0) > 0.5 / fs:
        def said(name: str, t: float) -> str:
            if name in implied:
                return f"channel {name!r} gives fs alone (no time: read as starting at t = 0 s)"
            return f"channel {name!r} starts at t = {t:.9g} s"
        raise MeasuredDataError(path, f"{said(worst, tw)}, {said(first, t0)}: "
                                      f"{abs(tw - t0) * fs:.3g} samples apart; expected every "
                                      "channel to start at one time (within half a sample step; "
                                      "give every channel a time, or none)")


def check_prior(source: str | os.PathLike, key: str, value: Any) -> None:
    """Refuse a declared prior that is not a finite number in :data:`PRIOR_RANGE`: every prior
    an identifier reads is a size, a mass [kg] or a length [m] (given with ``--prior`` or stored
    in a dataset file, whose ``prior`` attributes a user may have edited: NaN, -1 or text were
    read in silence)."""
    lo, hi = PRIOR_RANGE
    # (an int beyond float64, 10**400, is refused: math.isfinite raised OverflowError)
    # one rule with the API's Measurement (review 26b: numpy scalars and link_lengths' list)
    if not prior_ok(key, value):
        raise MeasuredDataError(source, f"prior {key}={value!r}: expected a finite number from "
                                        f"{lo:g} to {hi:g} (a mass [kg] or a length [m]; beyond, "
                                        "the identified matrices leave float64's range)")


def check_position(source: str | os.PathLike, channel: str, value: Any, key: str) -> float:
    """A channel's position [m] as a float, or refused naming ``key`` (the file's own name for
    it: SEP-005's ``position_m``, a dataset's ``positions``, a UFF node's coordinate) unless a
    finite number: a NaN position was kept in silence and placed the sensor nowhere."""
    value = value.item() if isinstance(value, np.generic) else value  # named as 'nan', not
    x = finite_real(value) if isinstance(value, (int, float)) else None  # 'np.float64(nan)'
    if x is None:  # (an integer of 400 digits was float()'s OverflowError: round 25)
        raise MeasuredDataError(source, f"channel {channel!r}: {key}={show_value(value)}; expected "
                                        f"a finite number [m] (or no {key})")
    return x


def check_record_size(path: Path, n_samples: int, n_channels: int) -> None:
    """Refuse a record of more than :data:`~testbed.core.budget.IDENTIFY_VALUE_BUDGET` values
    (``n_samples`` x ``n_channels``): it would exceed the memory budget in the signal chain and
    the identifier (a 1e7-row CSV took minutes and gigabytes before)."""
    if n_samples * n_channels > IDENTIFY_VALUE_BUDGET:
        raise MeasuredDataError(path, f"{n_samples} samples x {n_channels} channel(s) = "
                                      f"{n_samples * n_channels} values; expected at most "
                                      f"{IDENTIFY_VALUE_BUDGET} (testbed.core.budget."
                                      "IDENTIFY_VALUE_BUDGET: the 4 GiB memory budget at "
                                      f"{IDENTIFY_BYTES_PER_VALUE} bytes a value); cut the record, "
                                      "decimate it or keep fewer channels")


def uniform_rate(path: Path, t: np.ndarray, what: str = "time column") -> float:
    """Sample rate [Hz] of uniformly spaced times ``t`` [s], shape (n,); raises if not uniform."""
    t = np.asarray(t, dtype=float)
    if t.size < 2:
        raise MeasuredDataError(path, f"{what}: fewer than 2 samples")
    if not np.all(np.isfinite(t)):
        raise MeasuredDataError(path, f"{what} has NaN or infinite values")
    dt = np.diff(t)
    step = float(np.median(dt))
    if not step > 0:
        raise MeasuredDataError(path, f"{what} does not increase")
    worst = int(np.argmax(np.abs(dt - step)))
    if abs(dt[worst] - step) > TIME_TOLERANCE * step:
        raise MeasuredDataError(path, f"{what} is not uniform: step {dt[worst]:.6g} s after "
                                      f"t = {t[worst]:.6g} s against a median step of {step:.6g} s")
    return (t.size - 1) / float(t[-1] - t[0])


# --------------------------------------------------------------------------- readers
def _read_hdf5(path: Path) -> _Raw:
    _check_hdf5_size(path)
    return _raw_from_dataset(path, read_dataset_file(path))


def unreadable_array(path: str | os.PathLike) -> str | None:
    """The first array of a dataset file (under ``/measured``, ``/reference``, ``/truth``)
    whose stored values cannot be read, as ``"/group/name: ..."`` with the HDF5 library's
    reason in one line, or None (every array reads, or the file does not open).

    Round 21's open item (a): a chunk whose fletcher32 checksum or gzip stream was damaged was
    refused as "unreadable dataset file (OSError: Can't synchronously read data (filter
    returned failure during read))", naming the file but not the array.
    """
    import h5py

    try:
        h = h5py.File(path, "r")
    except Exception:
        return None
    with h:
        for group in ("measured", "reference", "truth"):
            g = h.get(group)
            if not isinstance(g, h5py.Group):
                continue
            for name in g:
                d = g.get(name)
                if not isinstance(d, h5py.Dataset):
                    continue
                try:
                    d[()]
                except Exception as e:
                    why = " ".join(str(e).split())
                    return (f"/{group}/{name}: its stored values cannot be read "
                            f"({type(e).__name__}: {why}); the file is damaged")
    return None


def load_dataset(path: str | os.PathLike) -> Dataset:
    """:meth:`Dataset.load` (content hash verified), its refusal naming the array whose
    stored values cannot be read where one cannot (:func:`unreadable_array`).

    Raises
    ------
    MeasuredDataError
        Naming ``path`` and what is wrong.
    """
    try:
        return Dataset.load(path)
    except DatasetError as e:
        raise MeasuredDataError(path, unreadable_array(path) or e.reason) from None


def check_recorded(ds: Dataset, path: str | os.PathLike) -> None:
    """Refuse a loaded dataset file whose measured signals a reader could not take as they are.

    The checks of :func:`read_measured` on its ``.h5`` form (a finite rate > 0 and a finite
    duration, channels of one length of at least 2 samples, known units, finite values, one
    finite position per positioned channel, finite positive priors), less its bound on the
    magnitude of values, which is the identifiers' (:data:`MAX_MAGNITUDE`), and less its list
    of known units (an exporter writes a unit as it is, "general" where it knows none).  For the exporters:
    a dataset rehashed after an edit (fs NaN, a NaN sample, channels cut to other lengths)
    was written out as a UFF or SEP-005 file in silence.

    Raises
    ------
    MeasuredDataError
        Naming ``path`` and what is wrong.
    """
    raw = _raw_from_dataset(Path(path), ds)
    raw.own_units = True  # written as they are: an exporter converts no unit
    _finish(raw, None, None, None, max_magnitude=math.inf)


def _raw_from_dataset(path: Path, ds: Dataset) -> _Raw:
    """The measured signals of a loaded dataset file as a reader's raw record."""
    _check_scenario_rate(path, ds)
    raw = _Raw(path, "hdf5", float(ds.fs), {}, {}, prior=dict(ds.prior),
               own_units=ds.attrs.get("kind") == "dynamical")
    for g, s in ds.measured.items():
        per_channel = s.channel_units()  # "m, rad": a cart's position and a pole's angle
        if s.positions is not None and np.shape(s.positions) != (len(s.channels),):
            # one position for three channels was an internal error (IndexError)
            raise MeasuredDataError(path, f"signal measured/{g}: positions of shape "
                                          f"{np.shape(s.positions)} for {len(s.channels)} "
                                          "channel(s); expected one position [m] per channel")
        for i, ch in enumerate(s.channels):
            name = f"{g}/{ch}"
            if name in raw.data:  # the later channel replaced the earlier in silence (round 17:
                # a record of three accelerations fitted on two, status 1 with a poor model)
                raise MeasuredDataError(path, f"signal measured/{g} names channel {ch!r} twice "
                                              f"(channels {', '.join(map(repr, s.channels))}); "
                                              "expected one name per channel")
            raw.data[name], raw.units[name] = s.data[i], per_channel[i]
            if s.positions is not None:
                raw.positions[name] = check_position(path, name, s.positions[i], "positions")
    # inputs that declare the coordinates they act on (Signal.acts_on) keep that, as node
    # numbers the way a UFF file states it: a coordinate channel and the inputs driving it share
    # a node, which ImportedData.to_dataset turns back into acts_on
    driven = {g: s for g, s in ds.measured.items() if s.acts_on}
    if driven:
        node: dict[str, int] = {}
        for g, s in ds.measured.items():
            if g not in driven:
                for ch in s.channels:
                    raw.nodes[f"{g}/{ch}"] = node.setdefault(ch, len(node) + 1)
        for g, s in driven.items():
            for ch, target in zip(s.channels, s.acts_on, strict=True):
                if target in node:
                    raw.nodes[f"{g}/{ch}"] = node[target]
    return raw


def _check_scenario_rate(path: Path, ds: Dataset) -> None:
    """Refuse a dataset file whose ``fs`` is not the rate its own stored scenario records at
    (``Rig.record`` of its ``[simulation]`` table, where its rig is registered here and declares
    one).  The cache refuses such an entry; ``identify`` and ``export`` read one (an edit of
    ``fs`` or of the scenario's ``sample_rate`` by 1 %, its content hash made anew) with status
    0, every frequency 1 % off (malformed-input round 23).  A file without a scenario (a lab's
    record written as a dataset) or of a rig not registered here states no rate to check."""
    scenario = ds.attrs.get("scenario")
    simulation = scenario.get("simulation") if isinstance(scenario, Mapping) else None
    rig = ds.attrs.get("rig")
    if not isinstance(simulation, Mapping) or not isinstance(rig, str):
        return
    try:
        record = rig_class(rig).record(dict(simulation))
        rate = None if record is None else float(record[0])
    except Exception:  # an unregistered rig, or a table its rig cannot read: nothing stated
        return
    if rate is not None and off_scenario_rate(float(ds.fs), rate):
        raise MeasuredDataError(path, f"attribute fs={float(ds.fs)!r} Hz but its scenario "
                                      f"(attribute scenario, [simulation]) records at {rate!r} Hz; "
                                      "the file contradicts itself (expected equal rates)")


def check_hdf5_rate(path: str | os.PathLike) -> None:
    """Refuse a dataset file whose root attribute ``fs`` is not one real number, or whose
    ``fs_unit`` is not ``"Hz"`` (a file that cannot be opened is left to :meth:`Dataset.load`).

    :meth:`Dataset.load` read ``fs`` with ``float()``: the text ``"100"`` and ``True`` were
    read as rates, a complex rate lost its imaginary part (with a warning over two lines), and
    ``fs_unit`` (which the content hash leaves out) was never read, so ``"kHz"`` was taken as
    Hz in silence (round 17).

    Raises
    ------
    MeasuredDataError
        Naming ``path``, the attribute, its value and what is allowed.
    """
    problem = fs_attribute_problem(path)
    if problem:
        raise MeasuredDataError(path, problem)


def check_hdf5_storage(path: str | os.PathLike) -> None:
    """Refuse a dataset file one of whose arrays keeps its values in another file, or is
    compressed by an HDF5 filter this installation cannot decode.  A file that cannot be opened
    is left to :meth:`Dataset.load`.

    Round 18: ``measured/x`` made a virtual dataset over an array of another file (or kept in
    external raw storage), its content hash made anew, was fitted by ``testbed identify``
    (status 0) and exported: the record the model came from was not the file named, and its
    values change with a file the command line never names.  (External and soft links are
    refused by the reader's layout check.)  An array compressed by a filter without a plugin
    here (Blosc, id 32001) was refused as "can't open directory (/usr/local/lib/plugin)":
    one line, naming no array and no filter.

    Raises
    ------
    MeasuredDataError
        Naming ``path``, the array and where its values live or the filter.
    """
    import h5py

    found: list[str] = []

    def visit(name: str, obj: Any) -> None:
        if found or not isinstance(obj, h5py.Dataset):
            return
        raw_layout = obj.attrs.get("layout")
        layout = _attr_text(raw_layout)  # text, bytes or a one-element array of either
        if raw_layout is not None and layout != LAYOUT:
            layout = layout if layout is not None else _plain(raw_layout)
            # the reader takes rows as channels whatever this says: a file whose arrays claim
            # "samples x channels" was read as channels x samples in silence (round 23)
            found.append(f"/{name}: attribute layout={layout!r}; expected {LAYOUT!r} (each row "
                         "one channel, as the reader takes it)")
            return
        plist = obj.id.get_create_plist()
        if obj.is_virtual:
            sources = sorted({m.file_name for m in obj.virtual_sources()})
            found.append(f"/{name}: a virtual dataset (its values read from "
                         f"{', '.join(sources) or 'other files'}); a dataset file holds its "
                         "values itself")
        elif plist.get_external_count() > 0:
            files = [plist.get_external(i)[0].decode(errors="replace")
                     for i in range(plist.get_external_count())]
            found.append(f"/{name}: stored in external file(s) {', '.join(files)}; a dataset "
                         "file holds its values itself")
        for k in range(plist.get_nfilters()):
            code, _flags, _values, fname = plist.get_filter(k)
            if not found and not h5py.h5z.filter_avail(code):
                shown = fname.decode(errors="replace") if isinstance(fname, bytes) else str(fname)
                found.append(f"/{name}: compressed by the HDF5 filter {shown!r} (id {code}), "
                             "which this installation cannot decode (no plugin for it); "
                             "allowed: uncompressed, gzip, LZF, shuffle, scale-offset, fletcher32 "
                             "(or install that filter's plugin)")

    try:
        h = h5py.File(path, "r")
    except Exception:  # not an HDF5 file we can open: Dataset.load names it
        return
    with h:
        for group in ("measured", "reference", "truth"):
            try:
                member = h.get(group, getlink=True)
                if isinstance(member, h5py.HardLink) and isinstance(h[group], h5py.Group):
                    h[group].visititems(lambda n, o, g=group: visit(f"{g}/{n}", o))
            except Exception as e:  # fail closed: an array whose storage cannot be read
                found.append(f"/{group}: the storage of its arrays cannot be inspected "
                             f"({type(e).__name__}: {e}); a dataset file holds plain arrays")
            if found:
                break
    if found:
        raise MeasuredDataError(path, found[0])


#: The unit of a dataset file's ``positions`` attributes: :meth:`Dataset.save` writes
#: ``positions_unit = "m"``; another length unit of :func:`si_unit` (``"mm"``) is read and
#: its positions converted to it.
POSITIONS_UNIT = "m"


def _attr_text(v: Any) -> str | None:
    """An HDF5 attribute as the text it holds, or None: a text, fixed-length bytes (as many
    HDF5 writers store text, decoded as UTF-8), or a one-element array of either."""
    if isinstance(v, np.ndarray) and v.size == 1 and v.dtype.kind in "OSU":
        v = v.reshape(-1)[0]
    if isinstance(v, (bytes, np.bytes_)):
        try:
            return bytes(v).decode("utf-8")
        except UnicodeDecodeError:
            return None
    return str(v) if isinstance(v, str) else None


def _plain(v: Any) -> Any:
    """A numpy attribute value as Python's (``1.0``, not ``np.float64(1.0)``), for
    :func:`~testbed.core.errors.show_value`."""
    return v.tolist() if isinstance(v, np.ndarray) else v.item() if isinstance(v, np.generic) else v


def check_hdf5_declarations(path: str | os.PathLike) -> dict[tuple[str, str], tuple[str | None, float]]:
    """Refuse a dataset file one of whose declarations the reader would not read as it says;
    return how to read the others that :meth:`Dataset.load` reads otherwise.

    Round 24, each with the content hash made anew: an attribute on the ``/measured``,
    ``/reference`` or ``/truth`` group itself (``fs = 1.0`` on ``/measured``; the writer puts
    none there, the hash covers none, nothing reads it) was kept in silence;
    ``positions_unit = "mm"`` was read as metres, and a file whose positions were in
    millimetres and said so was exported as metres; a ``unit`` stored as fixed-length bytes
    (``np.bytes_``, as many HDF5 writers store text) was read as the text ``"b'mM'"`` and
    refused for another reason ("expected b'mM'/s").  Review 25a: those are valid spellings,
    read as they say (:func:`apply_hdf5_declarations`): a ``unit`` or ``positions_unit`` of
    bytes or a one-element text array is decoded, and positions in a length unit of
    :func:`si_unit` are converted to metres.  A file that cannot be opened, or whose layout
    is not a dataset file's, is left to :meth:`Dataset.load`.

    Returns
    -------
    dict of (group, name) to (str or None, float)
        For each signal read otherwise than :meth:`Dataset.load` does: its unit decoded (None:
        as loaded) and the factor [m per positions unit] of its positions.

    Raises
    ------
    MeasuredDataError
        Naming ``path``, the group or array, the attribute, its value and what is allowed.
    """
    import h5py

    reads: dict[tuple[str, str], tuple[str | None, float]] = {}
    try:
        h = h5py.File(path, "r")
    except Exception:
        return reads
    with h:
        for group in ("measured", "reference", "truth"):
            g = h.get(group)
            if not isinstance(g, h5py.Group):
                continue
            for key in g.attrs:
                raise MeasuredDataError(path, f"/{group}: attribute {show_value(key)} on the group "
                                              "itself (read by nothing, outside the content hash); "
                                              f"a dataset file's /{group} group carries no attribute")
            if group == "truth":
                continue
            for name in g:
                d = g.get(name)
                if not isinstance(d, h5py.Dataset):
                    continue
                where = f"/{group}/{name}"
                unit, factor = None, 1.0
                for key in ("unit", "positions_unit"):
                    if key not in d.attrs:
                        continue
                    v = d.attrs[key]
                    text = _attr_text(v)
                    if text is None:
                        raise MeasuredDataError(path, f"{where}: attribute {key}={show_value(_plain(v))} "
                                                      f"({type(v).__name__}); expected a text "
                                                      "(a UTF-8 string, or its bytes)")
                    if key == "unit" and not isinstance(v, str):
                        unit = text
                    if key == "positions_unit" and text != POSITIONS_UNIT:
                        si, factor = si_unit(text)
                        if si != POSITIONS_UNIT:
                            raise MeasuredDataError(path, f"{where}: attribute positions_unit="
                                                          f"{show_value(text)}; expected a length "
                                                          f"unit ({POSITIONS_UNIT!r}, 'mm')")
                if unit is not None or factor != 1.0:
                    reads[(group, name)] = (unit, factor)
                for key in ("channels", "acts_on"):
                    names = d.attrs.get(key)
                    if key == "acts_on" and names is not None and not isinstance(names, np.ndarray):
                        # an integer was "unreadable dataset file (TypeError: 'numpy.int64'
                        # object is not iterable)", naming no attribute
                        raise MeasuredDataError(path, f"{where}: attribute acts_on="
                                                      f"{show_value(_plain(names))} "
                                                      f"({type(names).__name__}); expected a list "
                                                      "of coordinate names, one per channel")
                    if isinstance(names, np.ndarray) and names.dtype.kind in "OS":
                        odd = next((c for c in names.ravel() if not isinstance(c, str)), None)
                        if odd is not None:
                            raise MeasuredDataError(path, f"{where}: name {show_value(_plain(odd))} "
                                                          f"({type(odd).__name__}) in attribute "
                                                          f"{key}; expected texts (variable-length "
                                                          "UTF-8 strings)")
    return reads


def apply_hdf5_declarations(ds: Dataset, reads: Mapping[tuple[str, str], tuple[str | None, float]]
                            ) -> Dataset:
    """``ds`` with its signals read as their file declares (:func:`check_hdf5_declarations`):
    each listed signal's unit decoded and its positions converted to metres.  The content hash
    in ``ds.attrs`` stays the file's (it names the file read)."""
    for (group, name), (unit, factor) in reads.items():
        signals = ds.measured if group == "measured" else ds.reference
        s = signals.get(name)
        if s is None:
            continue
        if unit is not None:
            s.unit = unit
        if s.positions is not None:
            s.positions = s.positions * factor
    return ds


def read_dataset_file(path: str | os.PathLike) -> Dataset:
    """A dataset file read as it declares: :func:`check_hdf5_rate`, :func:`check_hdf5_storage`,
    :func:`check_hdf5_declarations`, :func:`load_dataset` (content hash verified),
    :func:`apply_hdf5_declarations`.

    Raises
    ------
    MeasuredDataError
    """
    check_hdf5_rate(path)
    check_hdf5_storage(path)
    reads = check_hdf5_declarations(path)
    return apply_hdf5_declarations(load_dataset(path), reads)


def _check_hdf5_size(path: Path) -> None:
    """The record's size from the file's metadata, before its arrays are read: each
    ``measured/<signal>`` array of shape (channels, samples) (unreadable layouts are left to
    :meth:`Dataset.load` to name)."""
    import h5py

    try:
        with h5py.File(path, "r") as h:
            group = h.get("measured")
            shapes = ([getattr(g, "shape", ()) for g in group.values()]
                      if isinstance(group, h5py.Group) else [])
    except Exception:
        return
    shapes = [s for s in shapes if len(s) == 2]
    if shapes:
        check_record_size(path, max(s[1] for s in shapes), sum(s[0] for s in shapes))


def _read_sep005_file(path: Path) -> _Raw:
    try:
        # utf-8-sig: a byte-order mark is read past, as in a CSV file
        content = json.loads(path.read_text(encoding="utf-8-sig"), object_pairs_hook=_unique_keys)
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as e:
        raise MeasuredDataError(path, f"not a SEP-005 JSON file ({type(e).__name__}: {e})") from None
    except RecursionError:  # arrays nested thousands deep: no channel list of SEP-005
        raise MeasuredDataError(path, "not a SEP-005 JSON file: nested too deeply") from None
    except _DuplicateKey as e:
        raise MeasuredDataError(path, f"key {e.args[0]!r} is given twice in one object; give each "
                                      "key once") from None
    except ValueError as e:  # an integer of over 4,300 digits: Python's int conversion limit
        # (round 9: an internal error of `identify`); no SEP-005 value needs one
        raise MeasuredDataError(path, f"not a SEP-005 JSON file ({str(e).split(':')[0]}: a "
                                      "number of thousands of digits)") from None
    return _parse_sep005(path, content)


class _DuplicateKey(Exception):
    """A JSON object names a key twice (json.loads kept the last one silently)."""


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in pairs:
        if k in out:
            raise _DuplicateKey(k)
        out[k] = v
    return out


def _parse_sep005(path: Path, content: Any) -> _Raw:
    if isinstance(content, Mapping):
        content = [content]
    if not isinstance(content, Sequence) or isinstance(content, str) or not content:
        raise MeasuredDataError(path, "SEP-005 data must be a non-empty list of channel dicts")
    raw = _Raw(path, "sep005", None, {}, {})
    rates: dict[str, float] = {}
    for k, c in enumerate(content):
        if not isinstance(c, Mapping):
            raise MeasuredDataError(path, f"SEP-005 channel {k} is not a dict")
        name = c.get("name")
        if not isinstance(name, str) or not name:
            raise MeasuredDataError(path, f"SEP-005 channel {k} has no name")
        if name in raw.data:
            raise MeasuredDataError(path, f"SEP-005 channel name {name!r} is not unique")
        if "data" not in c:
            raise MeasuredDataError(path, f"SEP-005 channel {name!r} has no data")
        values = c["data"]
        if np.ma.isMaskedArray(values) and np.ma.getmaskarray(values).any():
            # np.asarray dropped the mask: a masked (missing) sample was read as a value
            # (round 17)
            raise MeasuredDataError(path, f"SEP-005 channel {name!r}: data are a masked array "
                                          f"with {int(np.ma.getmaskarray(values).sum())} masked "
                                          "sample(s); fill or cut them")
        data = _sep005_numbers(path, name, values, "data")
        if data.ndim != 1:
            raise MeasuredDataError(path, f"SEP-005 channel {name!r}: data of shape {data.shape}; "
                                          "only 1-D channels are supported")
        if "fs" in c:
            f = c["fs"].item() if isinstance(c["fs"], np.generic) else c["fs"]  # (review 26b)
            rate = finite_real(f) if isinstance(f, (int, float)) else None
            if rate is None or rate <= 0:  # (an integer of 400 digits: OverflowError, round 25)
                raise MeasuredDataError(path, f"SEP-005 channel {name!r}: fs={show_value(f)} is not "
                                              "a rate > 0 Hz")
            rates[name] = rate
        if "time" in c:
            t = _sep005_numbers(path, name, c["time"], "time")
            if t.shape != data.shape:
                raise MeasuredDataError(path, f"SEP-005 channel {name!r}: time of shape {t.shape} "
                                              f"for data of shape {data.shape}; expected one time "
                                              "per sample")
            rate = uniform_rate(path, t, f"channel {name!r} time")
            raw.starts[name] = float(t[0])
            # both given: fs won in silence (fs = 50 over a 100 Hz time: every frequency halved)
            if name in rates and abs(rate / rates[name] - 1) > DECLARED_RATE_RTOL:
                raise MeasuredDataError(path, f"SEP-005 channel {name!r}: fs={rates[name]:g} Hz but "
                                              f"its time says {rate:.9g} Hz; give one, or both agreeing")
            rates.setdefault(name, rate)
        if name not in rates:
            raise MeasuredDataError(path, f"SEP-005 channel {name!r} has neither fs nor time")
        unit = c.get("unit_str")
        if unit is not None and not isinstance(unit, str):  # 5 was read as the unit "5"
            raise MeasuredDataError(path, f"SEP-005 channel {name!r}: unit_str={unit!r} is not a "
                                          "string")
        raw.data[name], raw.units[name] = data, (unit or None)
        # the optional keys: a value of the wrong kind was dropped in silence (position_m NaN
        # or "0.3", node 1.5), or kept (node -1)
        node = c.get("node")
        node = node.item() if isinstance(node, np.generic) else node  # (review 26b)
        if node is not None:
            if not (isinstance(node, int) and not isinstance(node, bool) and node >= 1):
                raise MeasuredDataError(path, f"SEP-005 channel {name!r}: node={node!r}; expected "
                                              "an integer >= 1 (or no node key)")
            raw.nodes[name] = node
        direction = _direction(path, name, c.get("direction"))
        if direction:
            raw.directions[name] = direction
        pos = c.get("position_m")
        if pos is not None:
            raw.positions[name] = check_position(path, name, pos, "position_m")
    raw.fs = _common_rate(path, rates, 1e-9)
    if raw.starts:
        # channels of one file, some with a `time` and some with `fs` alone (round 18, open
        # item d): an fs-only channel states no start, and was lined up sample by sample with
        # a timed channel starting 0.3 s later, in silence.  SEP-005 reads an fs-only channel
        # as sampled from t = 0, so it is checked as starting there.
        for name in raw.data:
            if name not in raw.starts:
                raw.starts[name] = 0.0
                raw.implied_starts.add(name)
    return raw


_DIRECTION = re.compile(r"^\s*([-+]?)\s*([XYZ])\s*(rotation)?\s*$", re.IGNORECASE)


def _direction(path: Path, name: str, value: Any) -> int:
    """UFF direction code of an int or a text such as ``"+Z"`` / ``"-X rotation"``; 0 if none
    (``None``).  Anything else is refused: a direction of ``3.0``, ``true``, ``"up"``, ``[3]`` or
    ``"+Z axis"`` was read as none in silence (round 25), its channel's sign with it."""
    if value is None:
        return 0
    value = value.item() if isinstance(value, np.generic) else value  # np.int64(3) (review 26b)
    if isinstance(value, int) and not isinstance(value, bool):
        return value
    m = _DIRECTION.match(value) if isinstance(value, str) else None
    if m is None:
        raise MeasuredDataError(path, f"SEP-005 channel {name!r}: direction={show_value(value)}; "
                                      "expected a text such as '+Z' or '-X rotation', an integer "
                                      "code -6 to 6, or no direction key")
    code = "XYZ".index(m.group(2).upper()) + 1 + (3 if m.group(3) else 0)
    return -code if m.group(1) == "-" else code


def _sep005_numbers(path: Path, name: str, values: Any, key: str) -> np.ndarray:
    """A SEP-005 channel's ``data`` or ``time`` as floats, or refused naming the channel and the
    key: JSON strings and booleans are not numbers (``np.asarray`` read ``"1.5"`` and ``true`` as
    numbers: time stamps as texts were read so in silence, round 25), nor is a ``null``; an array
    given in memory must hold real numbers (complex lost its imaginary part)."""
    what = f"SEP-005 channel {name!r}: {'data are' if key == 'data' else key + ' values are'}"
    if (isinstance(values, np.ndarray) and values.dtype.kind not in "fiu") or (
            isinstance(values, (list, tuple)) and any(isinstance(v, (bool, str)) for v in values)):
        raise MeasuredDataError(path, f"{what} not numbers")
    try:
        return np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise MeasuredDataError(path, f"{what} not numbers") from None
    except OverflowError:  # a JSON integer such as 10**400: no float64 holds it
        raise MeasuredDataError(path, f"{what} not numbers of float64's range (an integer "
                                      "beyond float64's range, 1.8e308)") from None


def _common_rate(path: Path, rates: dict[str, float], rtol: float) -> float:
    first = next(iter(rates.values()))
    for name, f in rates.items():
        if abs(f / first - 1) > rtol:
            raise MeasuredDataError(path, f"channels have different sample rates ({name!r}: {f:.9g} Hz, "
                                          f"{next(iter(rates))!r}: {first:.9g} Hz)")
    return first


_HEADER = re.compile(r"^\s*(?P<name>.*?)\s*(?:[\[(](?P<unit>[^\])]*)[\])])?\s*$")


def _read_csv(path: Path) -> _Raw:
    try:
        # utf-8-sig: a byte-order mark (spreadsheets write one) is not part of the first name
        # (it hid the time column "t" of such a file: "no time column")
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as e:
        raise MeasuredDataError(path, f"not UTF-8 text (byte {e.object[e.start]:#04x} at offset "
                                      f"{e.start}); save it as UTF-8") from None
    except OSError as e:
        raise MeasuredDataError(path, f"not a text file ({type(e).__name__}: {e})") from None
    if "\x00" in text:  # UTF-16 without a byte-order mark decodes as UTF-8 with a NUL a character
        # (round 9: "'\x000\x00.' is not a number"); no number or name holds a NUL
        raise MeasuredDataError(path, f"holds a NUL byte (offset {text.index(chr(0))}): not UTF-8 "
                                      "text (UTF-16, or binary?); save it as UTF-8")
    lines = [(k + 1, ln) for k, ln in enumerate(text.splitlines())
             if ln.strip() and not ln.lstrip().startswith("#")]
    if len(lines) < 2:
        raise MeasuredDataError(path, "need a header row and at least one row of numbers")
    head = lines[0][1]
    delim = next((d for d in (",", ";", "\t") if d in head), None)

    def split(line: str, lineno: int) -> list[str]:
        try:
            return next(csv.reader([line], delimiter=delim)) if delim else line.split()
        except csv.Error as e:  # a field over csv's limit (a line of 10 MB): csv.Error, an
            # internal error of `identify` (round 9)
            raise MeasuredDataError(path, f"line {lineno}: {e} characters; a number or a "
                                          "column name is far shorter") from None

    header = [_HEADER.match(h).groupdict() for h in split(head, lines[0][0])]  # type: ignore[union-attr]
    names = [h["name"] for h in header]
    if any(not n for n in names) or len(set(names)) != len(names):
        # the one at fault, not every name: a header of 3,000 columns made a 40 kB line
        empty = [k + 1 for k, n in enumerate(names) if not n]
        twice = next((n for k, n in enumerate(names) if n in names[:k]), "")
        fault = f"column {empty[0]} has no name" if empty else f"{twice!r} names more than one column"
        raise MeasuredDataError(path, f"header names must be non-empty and unique: {fault} "
                                      f"(of {len(names)}: {show_names(names)})")
    # every column but the time is a channel: refuse before converting a row
    check_record_size(path, len(lines) - 1, max(1, len(names) - sum(n.lower() in TIME_NAMES for n in names)))
    rows = []
    for lineno, line in lines[1:]:
        cells = split(line, lineno)
        if len(cells) != len(names):
            raise MeasuredDataError(path, f"line {lineno} has {len(cells)} fields, the header {len(names)}")
        try:
            rows.append([_csv_number(c) for c in cells])
        except ValueError:
            bad = next(c for c in cells if not _is_float(c))
            hint = (" (a decimal comma? write a point)" if _is_float(bad.replace(",", ".")) else
                    " (write it in ASCII digits, without underscores)" if _is_python_float(bad)
                    else "")
            raise MeasuredDataError(path, f"line {lineno}: {bad.strip()!r} is not a number{hint}") from None
    table = np.array(rows, dtype=float).T
    raw = _Raw(path, "csv", None, {}, {})
    for h, col in zip(header, table, strict=True):
        if h["name"].lower() in TIME_NAMES:
            if raw.fs is not None:
                raise MeasuredDataError(path, "more than one time column")
            unit = (h["unit"] or "s").strip()
            if unit != "s":
                raise MeasuredDataError(path, f"time column unit {unit!r}; expected s")
            raw.fs = uniform_rate(path, col)
        else:
            raw.data[h["name"]], raw.units[h["name"]] = col, (h["unit"] or "").strip() or None
    return raw


def _csv_number(cell: str) -> float:
    """A CSV cell's number (:func:`~testbed.core.numbertext.plain_number`'s rule), else
    ValueError: ``float()`` alone read ``1_5`` as 15 and Arabic-Indic or other scripts' digits as
    ours (round 26)."""
    core = plain_number(cell)
    if core is None:
        raise ValueError(cell)
    return float(core)


def _is_float(s: str) -> bool:
    """Whether ``s`` is a CSV cell's number (:func:`_csv_number`)."""
    return plain_number(s) is not None


def _is_python_float(s: str) -> bool:
    """Whether Python's ``float()`` reads ``s`` (other scripts' digits, underscores)."""
    try:
        float(s)
    except ValueError:
        return False
    return True


def _read_uff(path: Path) -> _Raw:
    import pyuff

    # every UFF block ends with a line "    -1"; pyuff silently drops an unfinished last block
    with path.open("rb") as fh:
        fh.seek(max(0, path.stat().st_size - 64))
        tail = fh.read().rstrip()
    if not re.search(rb"(^|\s)-1$", tail):
        raise MeasuredDataError(path, "not a complete UFF file: it does not end with a block end "
                                      "'-1' (truncated, or not UFF)")
    _check_uff_blocks(path, path.read_bytes())
    try:
        uff = pyuff.UFF(str(path))
        types = list(uff.get_set_types())
        sets = [uff.read_sets(i) for i in range(len(types))]
    except Exception as e:  # pyuff raises bare Exception (and others) for damaged files
        raise MeasuredDataError(path, f"unreadable UFF file ({type(e).__name__}: {e})") from None
    if not any(int(t) == 58 for t in types):
        raise MeasuredDataError(path, "no UFF58 (function at nodal DOF) record")
    placed: dict[int, tuple[np.ndarray, str, int]] = {}
    raw = _Raw(path, "uff", None, {}, {})
    rates: dict[str, float] = {}
    for k, s in enumerate(sets):
        kind = int(s.get("type", 0))
        if kind == 164:
            factors = [float(s.get(key, 1.0)) for key in ("length", "force")]
            if factors != [1.0, 1.0]:
                raise MeasuredDataError(path, f"units record (164, code {s.get('units_code')}) is not SI: "
                                              f"length factor {factors[0]:g}, force factor {factors[1]:g}")
        elif kind in (15, 2411):
            _add_nodes(path, k, kind, s, placed)
        elif kind == 58:
            name, rate = _uff58_channel(path, k, s, raw)
            rates[name] = rate
    for name, node in raw.nodes.items():
        if node in placed:
            raw.positions[name] = check_position(path, name, float(placed[node][0][0]),
                                                 f"node {node} x")
    raw.fs = _common_rate(path, rates, 1e-5)
    return raw


#: Relative difference [-] within which two geometry records' coordinates of one node agree
#: (relative to the model's largest coordinate): a UFF15 record writes them with 6 significant
#: digits (E13.5, rounding within 5e-6 of the value), so a UFF15 and a UFF2411 record (16
#: digits) of one node, or two UFF15 records each rounded, differ by up to 1e-5 of it.
NODE_RTOL = 1e-5


def _add_nodes(path: Path, k: int, kind: int, s: Mapping[str, Any],
               placed: dict[int, tuple[np.ndarray, str, int]]) -> None:
    """Add the nodes of one geometry record (UFF15 or UFF2411, the ``k``-th record) to
    ``placed`` (node -> ((x, y, z) [m], where it was given, the record's kind)).

    Round 24: a node given twice at different places (twice in one UFF2411 record, in two
    geometry records, by a UFF2411 and a UFF15 record) was read at the last place in silence,
    and the sensor's position with it.  A node given twice at one place (within
    :data:`NODE_RTOL` of the model's largest coordinate, over every node placed so far and
    this record's) is read once, at its UFF2411 place where one record is a UFF2411 (16
    digits) and the other a UFF15 (6 digits), whichever comes first.

    Review 25a: the tolerance was relative to the node's own coordinates, so a node at the
    origin written 0 in one record and -1.2e-16 in another (``L cos(pi/2)``) was refused as
    placed twice; and a UFF15 record before a UFF2411 one gave its 6 digits.

    Raises
    ------
    MeasuredDataError
        Naming the node, both places and the records that give them.
    """
    where = f"record {k + 1} (UFF{kind})"
    xyz = np.column_stack([np.atleast_1d(np.asarray(s.get(c, np.zeros(len(s["node_nums"]))),
                                                    dtype=float))
                           for c in ("x", "y", "z")])
    # the model's size [m]: its largest coordinate over the nodes placed so far and this record's
    scale = max([float(np.max(np.abs(xyz), initial=0.0))]
                + [float(np.max(np.abs(at))) for at, _, _ in placed.values()])
    for node, at in zip(s["node_nums"], xyz, strict=True):
        node = int(node)
        if node in placed:
            before, said, said_kind = placed[node]
            if not np.all(np.abs(at - before) <= NODE_RTOL * scale):
                def show(v: np.ndarray) -> str:
                    return "(" + ", ".join(f"{c:.9g}" for c in v) + ")"

                raise MeasuredDataError(path, f"node {node} is placed twice: at {show(before)} m by "
                                              f"{said} and at {show(at)} m by {where}; expected one "
                                              "place per node (coordinates within "
                                              f"{NODE_RTOL:g} of the model's largest, {scale:.6g} m)")
            if not (kind == 2411 and said_kind == 15):
                continue  # the first place stays, unless a UFF2411 record gives more digits
        placed[node] = (at, where, kind)


#: The block delimiter as pyuff finds it: ``    -1`` then a line end, the file's end, or blanks
#: to column 80 (``pyuff.UFF.refresh``).
_UFF_TAG = re.compile(rb"    -1(?=\r|\n|$| {74})")


def _check_uff_blocks(path: Path, data: bytes) -> None:
    """Refuse text outside the UFF blocks: pyuff reads only what lies between a start and an
    end delimiter ``    -1`` and skips anything else in silence (a line of junk between two
    blocks, a header before the first one), so such a file is not read as if it were whole.

    Raises
    ------
    MeasuredDataError
        Naming the first line outside every block, or an unpaired delimiter.
    """
    tags = [m.start() for m in _UFF_TAG.finditer(data)]
    if len(tags) % 2:
        line = data.count(b"\n", 0, tags[-1]) + 1
        raise MeasuredDataError(path, f"an unpaired UFF block delimiter '-1' (the last at line "
                                      f"{line}): every block starts and ends with a line '    -1'")
    # the gaps: the file's start to the first start tag, each end tag's line to the next start
    ends = [0] + [data.find(b"\n", t) + 1 or len(data) for t in tags[1::2]]
    starts = [*tags[0::2], len(data)]
    for lo, hi in zip(ends, starts, strict=True):
        stray = data[lo:hi]
        if stray.strip():
            at = lo + len(stray) - len(stray.lstrip())
            line = data.count(b"\n", 0, at) + 1
            text = data[at:data.find(b"\n", at) if b"\n" in data[at:hi] else hi].rstrip()
            raise MeasuredDataError(path, f"line {line} ({text[:40].decode('latin-1')!r}) lies outside "
                                          "every UFF block (between one block's end '-1' and the "
                                          "next one's start '-1'); a UFF file holds only blocks")


#: ``fs <rate> Hz`` in a UFF58 record's ID line 5 (this project's exports state the exact rate
#: there): the rate's characters of a number, or NaN / inf spelled out (round 27: "fs nan Hz"
#: was read past, the header's rounded increment taken; "fs ..... Hz" was float()'s
#: ValueError, an internal error).
_FS_ID = re.compile(r"\bfs\s+([-+0-9.eE]+|[-+]?(?i:nan|inf(?:inity)?))\s*Hz")


def _id_rate(path: Path, where: str, text: str) -> float:
    """The rate [Hz] an ID line states as ``text``: a finite number > 0, else refused."""
    number = plain_number(text)
    rate = float(number) if number is not None else math.nan
    if not (math.isfinite(rate) and rate > 0):
        raise MeasuredDataError(path, f"{where}: its ID line states the rate 'fs {text} Hz'; "
                                      "expected a finite number of Hz > 0")
    return rate


def _uff58_channel(path: Path, k: int, s: dict[str, Any], raw: _Raw) -> tuple[str, float]:
    """Add one UFF58 record to ``raw``; its channel name and sample rate [Hz]."""
    node, direction = int(s.get("rsp_node", 0)), int(s.get("rsp_dir", 0))
    name = str(s.get("id1", "")).strip() or f"node{node}:{direction}"
    where = f"record {k + 1} ({name})"
    if int(s.get("func_type", 0)) != 1:
        raise MeasuredDataError(path, f"{where} is function type {s.get('func_type')}, "
                                      "not a time response (1)")
    data = np.asarray(s.get("data", []))
    if np.iscomplexobj(data):
        raise MeasuredDataError(path, f"{where} has complex ordinates; a time response is real")
    if name in raw.data:
        name = f"{name}#{k + 1}"
    if "num_pts" in s and int(s["num_pts"]) != data.size:  # (a damaged header was read past)
        raise MeasuredDataError(path, f"{where}: its header declares {int(s['num_pts'])} values, "
                                      f"its data hold {data.size}")
    m = _FS_ID.search(str(s.get("id5", "")))
    even = int(s.get("abscissa_spacing", 1)) == 1
    if even:
        inc = float(s.get("abscissa_inc", 0.0))
        if not inc > 0:  # (a testbed file's exact rate in its ID line hid an increment of 0 or NaN)
            raise MeasuredDataError(path, f"{where}: abscissa increment {inc!r} s is not > 0")
    if m is not None:
        rate = _id_rate(path, where, m.group(1))
        # the increment is written with 6 significant digits (rounding within 5e-6)
        if even and not abs(inc * rate - 1.0) <= 1e-5:
            raise MeasuredDataError(path, f"{where}: abscissa increment {inc!r} s disagrees with "
                                          f"the rate {rate:g} Hz of its ID line")
    elif even:
        rate = 1.0 / inc
    else:
        rate = uniform_rate(path, np.asarray(s["x"], dtype=float), f"{where} abscissa")
    if int(s.get("abscissa_spec_data_type", 17)) not in (0, 17):
        raise MeasuredDataError(path, f"{where}: abscissa is specific data type "
                                      f"{s.get('abscissa_spec_data_type')}, not time (17)")
    label = str(s.get("ordinate_axis_units_lab", "")).strip()
    key = (int(s.get("ordinate_spec_data_type", 0)), int(s.get("ordinate_len_unit_exp", 0)),
           int(s.get("ordinate_force_unit_exp", 0)), abs(direction) in (4, 5, 6))
    if not label or label.upper() == "NONE":
        label = _UFF_UNITS.get(key, "")
    elif key[0] in _UFF_QUANTITY:
        # both declared: a displacement record (type 8) labelled m/s^2 was read as an
        # acceleration by its label in silence (round 14); a label of the type's quantity in
        # another unit (g, mm) is read by the label, as before
        coded, labelled = _UFF_QUANTITY[key[0]], SAME_ORDER.get(si_unit(label)[0])
        if labelled is not None and labelled != coded:
            def a(w: str) -> str:
                return f"{'an' if w[0] in 'aeiou' else 'a'} {w}"

            raise MeasuredDataError(path, f"{where}: ordinate unit label {label!r} ({a(labelled)}) "
                                          f"disagrees with its specific data type {key[0]} "
                                          f"({a(coded)}); expected a label of the quantity the "
                                          "type declares")
    raw.data[name], raw.units[name] = data.astype(float), label or None
    start = float(s.get("abscissa_min", 0.0)) if even else float(np.asarray(s["x"], dtype=float)[0])
    if math.isfinite(start):
        raw.starts[name] = start
    if node > 0:
        raw.nodes[name] = node
    if direction:
        raw.directions[name] = direction
    return name, rate
