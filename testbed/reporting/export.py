"""Datasets other tools read: Universal File Format (UFF 58 / 55, via pyuff) and SEP-005 JSON.

UFF
    In this order: one UFF164 *units* record (SI: metre, newton, kelvin; every
    factor 1), one UFF2411 *nodes* record (double precision) with one node per
    position-carrying channel at its position [m] along the beam (x; y = z = 0)
    and one UFF82 *trace line* through those nodes in order of position (so a
    modal viewer can draw the beam), then one binary UFF58 *time response* record
    (function type 1, double precision, even abscissa in seconds) per measured channel, with the abscissa and
    ordinate *specific data types*, SI unit exponents and unit labels filled in,
    the response node and direction, and the signal / scenario / content hash in
    the ID lines.  The UFF58 header keeps the sample interval to 6 significant
    digits only (format E13.5), so ID line 5 also states the exact ``fs``.  For a
    dataset of a structural kind (its truth a
    :class:`~testbed.core.truth.StructuralTruth`) one UFF55 *normal mode* record per
    sensor mode follows: frequency [Hz], viscous damping ratio, modal mass [kg]
    (``phi^T Mr phi`` with the reduced mass matrix ``Mr``: 1 for the cantilever's
    mass-normalised SEREP shapes) and the mode shape at the sensor nodes (nodes =
    sensors).  ID line 2 states frequency and damping as plain numbers
    (``82.7660 Hz, zeta 0.010000``).  A dataset that records no kind (hand-made, or
    imported) has no declared truth, and gets no modes.

    A mechanism without positions (the five-bar: absolute link angles th1..th4,
    whose moving joints have no fixed place, and no mode shapes to draw) gets
    neither 2411 nor 82: there is no geometry to draw.
SEP-005
    The SDyPy unified timeseries (SEP 5): a list with one dict per channel holding
    the compulsory ``name`` (unique), ``data``, ``unit_str`` and ``fs`` [Hz], plus
    ``unit_tex``, ``quantity``, ``node``, ``direction``, ``position_m``, ``group``
    and ``content_hash``.  The JSON file is that list with ``data`` as lists of
    float; :func:`read_sep005` gives ``data`` back as the ndarray the standard asks for.

Node numbers: channels with positions [m] (the cantilever's sensors and the
impact force) are numbered 1, 2, ... by position, so a force and the sensor it
acts at share a node; coordinates without positions (joint angles and their rates)
take the number in their name (``th3``, ``dth3``, ``ddth3`` -> 3), else their row
index + 1.  An input (force, torque) is put at the node of the coordinate it acts
on according to the rig's signal chain (:func:`testbed.pipeline.signal_chain.measure` and its
``input_map``): the five-bar's ``u1`` at ``th1`` (node 1) and ``u2`` at ``th4``
(node 4), never the number in the input's name.
"""

from __future__ import annotations

import json
import os
import re
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from testbed.core.atomic import atomic_write, atomic_write_text
from testbed.core.dataset import Dataset, Signal
from testbed.core.errors import ArgumentError
from testbed.core.truth import StructuralTruth
from testbed.pipeline.importers import (
    check_recorded,
    read_dataset_file,
)
from testbed.pipeline.plugins import RIGS
from testbed.pipeline.signal_chain import measure

#: unit -> (quantity, UFF specific data type, length exponent, force exponent, rotational, LaTeX)
UNITS: dict[str, tuple[str, int, int, int, bool, str]] = {
    "m/s^2": ("acceleration", 12, 1, 0, False, r"m/s$^2$"),
    "m/s": ("velocity", 11, 1, 0, False, "m/s"),
    "m": ("displacement", 8, 1, 0, False, "m"),
    "N": ("force", 13, 0, 1, False, "N"),
    "rad": ("angle", 8, 0, 0, True, "rad"),
    "rad/s": ("angular velocity", 11, 0, 0, True, "rad/s"),
    "rad/s^2": ("angular acceleration", 12, 0, 0, True, r"rad/s$^2$"),
    "N m": ("torque", 13, 1, 1, True, r"N$\cdot$m"),
    "N*m": ("torque", 13, 1, 1, True, r"N$\cdot$m"),
    "Nm": ("torque", 13, 1, 1, True, r"N$\cdot$m"),
}
#: UFF direction codes: translation along +Z (the bending direction), rotation about +Z (the plane normal).
DIR_TRANSLATION, DIR_ROTATION = 3, 6
TIME_SPEC_TYPE = 17


def quantity(unit: str) -> tuple[str, int, int, int, bool, str]:
    """(quantity, UFF specific data type, length exp., force exp., rotational, LaTeX unit) of ``unit``."""
    return UNITS.get(unit.strip(), ("general", 1, 0, 0, False, unit))


def _rig_kind(ds: Dataset) -> str | None:
    """The kind the dataset records, else that of its rig (``attrs["rig"]``) if registered,
    else None (no signal chain to ask)."""
    if ds.kind is not None:
        return ds.kind
    try:
        return str(RIGS.get(str(ds.attrs.get("rig", ""))).kind)
    except KeyError:  # an unregistered or missing rig
        return None


def input_nodes(ds: Dataset, coordinate_nodes: dict[tuple[str, int], int]) -> dict[tuple[str, int], int]:
    """Node of every measured input channel, from the rig's signal chain and its ``input_map``.

    Parameters
    ----------
    ds : Dataset
        Only ``measured``, ``fs``, ``prior`` and ``attrs["rig"]`` are read.
    coordinate_nodes : dict of (str, int) to int
        Node of every measured channel before this correction.

    Returns
    -------
    dict of (str, int) to int
        ``(signal name, row)`` of each input (e.g. ``("torque", 1)``) -> node of the coordinate
        channel ``input_map`` puts it on (``th4``: 4).  Empty when the rig is unknown, the
        signal chain cannot run on the data, or its coordinates and inputs are not measured
        signals of their own.
    """
    kind = _rig_kind(ds)
    if kind is None:
        return {}

    # the cheapest chain of each kind: recorded joint rates (no filtering) for a mechanism
    cfg = {"derivatives": "recorded"} if kind == "mechanical" else {}
    try:
        m = measure(Dataset(ds.fs, ds.measured, prior=dict(ds.prior)), cfg, kind)
    except Exception:  # data the chain cannot take: keep the channel's own numbering
        return {}
    if m.input_map is None or not m.inputs:
        return {}
    coords = next((n for n, s in ds.measured.items() if s.channels == tuple(m.channels)), None)
    inputs = next((n for n, s in ds.measured.items() if s.channels == tuple(m.inputs)), None)
    if coords is None or inputs is None:
        return {}
    imap = np.abs(np.asarray(m.input_map, dtype=float))
    return {(inputs, j): coordinate_nodes[(coords, int(np.argmax(imap[:, j])))]
            for j in range(imap.shape[1]) if imap[:, j].any()}


def node_numbers(ds: Dataset) -> dict[tuple[str, int], int]:
    """Node number of every measured channel, keyed by (signal name, row).

    Positioned channels are numbered by position (1 = nearest the root), others by the number
    in their name; inputs then move to the node of the coordinate they act on
    (:func:`input_nodes`).  See the module docstring.
    """
    nodes: dict[tuple[str, int], int] = {}
    keys = [round(p, 12) for p in node_positions(ds)]
    for name, s in ds.measured.items():
        for i, ch in enumerate(s.channels):
            if s.positions is not None:
                nodes[(name, i)] = keys.index(round(float(s.positions[i]), 12)) + 1
            else:
                m = re.search(r"(\d+)$", ch)
                nodes[(name, i)] = int(m.group(1)) if m else i + 1
    nodes.update(input_nodes(ds, nodes))
    return nodes


def node_positions(ds: Dataset) -> list[float]:
    """Distinct positions [m] of the positioned measured channels, ascending: node k at ``[k - 1]``."""
    first: dict[float, float] = {}  # positions equal to 12 decimals share a node
    for s in ds.measured.values():
        for p in (s.positions if s.positions is not None else ()):
            first.setdefault(round(float(p), 12), float(p))
    return [first[k] for k in sorted(first)]


def _channels(ds: Dataset) -> list[tuple[str, int, Signal]]:
    return [(name, i, s) for name, s in ds.measured.items() for i in range(len(s.channels))]


def _uff58(ds: Dataset, name: str, i: int, s: Signal, node: int) -> dict[str, Any]:
    import pyuff

    unit = s.channel_units()[i]
    q, spec, len_exp, force_exp, rot, _ = quantity(unit)
    scen = str(ds.attrs.get("scenario_name") or ds.attrs.get("rig", ""))
    return pyuff.prepare_58(
        binary=1, func_type=1, ver_num=0, load_case_id=0,
        id1=f"{name}/{s.channels[i]}"[:80], id2=f"{q} [{unit}]"[:80],
        id3=f"scenario {scen} seed {ds.attrs.get('seed', '')}"[:80],
        id4=f"content hash {ds.attrs.get('content_hash', '')[:40]}"[:80],
        id5=f"fs {float(ds.fs)!r} Hz, sysid-testbed"[:80],
        rsp_ent_name=s.channels[i][:10], rsp_node=node, rsp_dir=DIR_ROTATION if rot else DIR_TRANSLATION,
        ref_ent_name="NONE", ref_node=0, ref_dir=0,
        data=np.ascontiguousarray(s.data[i], dtype=float), x=ds.t,
        abscissa_spacing=1, abscissa_spec_data_type=TIME_SPEC_TYPE, abscissa_len_unit_exp=0,
        abscissa_force_unit_exp=0, abscissa_temp_unit_exp=0, abscissa_axis_units_lab="s",
        ordinate_spec_data_type=spec, ordinate_len_unit_exp=len_exp, ordinate_force_unit_exp=force_exp,
        ordinate_temp_unit_exp=0, ordinate_axis_units_lab=unit[:20],
        orddenom_spec_data_type=0, z_axis_spec_data_type=0, z_axis_value=0.0)


def structural_truth(ds: Dataset) -> StructuralTruth | None:
    """The dataset's truth if its recorded kind's truth is structural, else None (another
    kind, or no kind recorded: a hand-made or imported dataset, whose truth is undeclared)."""
    truth = ds.typed_truth if ds.kind is not None else None
    return truth if isinstance(truth, StructuralTruth) else None


def modal_masses(truth: StructuralTruth, phi: np.ndarray) -> np.ndarray:
    """Modal mass [kg] of each sensor mode shape: ``diag(phi^T Mr phi)``.

    Parameters
    ----------
    truth : StructuralTruth
        Its reduced mass matrix ``Mr`` [kg], shape (n_sensors, n_sensors).
    phi : ndarray, shape (n_sensors, n_modes)
        Mode shapes in columns [m / sqrt(kg)] (1 for the cantilever's mass-normalised shapes).

    Returns
    -------
    ndarray, shape (n_modes,)
    """
    return np.einsum("ik,ij,jk->k", phi, truth.Mr, phi)


def _uff55(ds: Dataset, truth: StructuralTruth, sensor_nodes: list[int]) -> list[dict[str, Any]]:
    """One normal-mode record per sensor mode: the shape at the sensor nodes along the bending
    direction."""
    import pyuff

    f, zeta, phi = truth.frequencies_hz, truth.damping_ratios, truth.sensor_modes
    n = min(f.size, phi.shape[1])
    mass = modal_masses(truth, phi)
    zero = np.zeros(phi.shape[0])
    sets = []
    for k in range(n):
        z = float(zeta[k])
        shape = {"r1": zero, "r2": zero, "r3": zero, f"r{DIR_TRANSLATION}": phi[:, k]}
        sets.append(pyuff.prepare_55(
            model_type=1, analysis_type=2, data_ch=2, spec_data_type=8, data_type=2, n_data_per_node=3,
            id1=f"true mode {k + 1}", id2=f"{float(f[k]):.4f} Hz, zeta {z:.6f}"[:80],
            id3=f"rig {ds.attrs.get('rig', '')}",
            id4=f"content hash {ds.attrs.get('content_hash', '')[:40]}",
            id5=f"sysid-testbed truth, modal mass {float(mass[k]):.6g} kg"[:80],
            **shape, node_nums=np.asarray(sensor_nodes), load_case=1, mode_n=k + 1,
            modal_m=float(mass[k]), freq=float(f[k]), modal_damp_vis=z, modal_damp_his=0.0))
    return sets


def _uff164() -> dict[str, Any]:
    """Units record: SI (metre, newton, kelvin), every conversion factor 1."""
    import pyuff

    return pyuff.prepare_164(units_code=1, units_description="SI", temp_mode=1, length=1.0,
                             force=1.0, temp=1.0, temp_offset=0.0)


def _geometry(ds: Dataset) -> list[dict[str, Any]]:
    """UFF2411 nodes at the channel positions [m] along x, and a UFF82 trace line through them.

    Empty when no measured channel has a position (the five-bar: see the module docstring).
    """
    import pyuff

    pos = node_positions(ds)
    if not pos:
        return []
    n = len(pos)
    nums = np.arange(1, n + 1, dtype=int)
    sets = [pyuff.prepare_2411(node_nums=nums, def_cs=np.zeros(n, dtype=int),
                               disp_cs=np.zeros(n, dtype=int), color=np.full(n, 8, dtype=int),
                               x=np.asarray(pos, dtype=float), y=np.zeros(n), z=np.zeros(n))]
    if n > 1:
        sets.append(pyuff.prepare_82(trace_num=1, n_nodes=n, color=8, id="sensors along the beam",
                                     nodes=nums))
    return sets


def _sensor_nodes(ds: Dataset, truth: StructuralTruth, nodes: dict[tuple[str, int], int]
                  ) -> list[int] | None:
    """Nodes of the signal the true sensor mode shapes refer to (same row count, a motion)."""
    rows = truth.sensor_modes.shape[0]
    for name, s in ds.measured.items():
        if len(s.channels) == rows and quantity(s.unit)[0] in ("acceleration", "velocity", "displacement"):
            return [nodes[(name, i)] for i in range(rows)]
    return None


def _a_dataset(where: str, ds: Any) -> None:
    """Refuse an exporter's ``ds`` that is not a :class:`Dataset`: 5, None or a dict was an
    AttributeError from inside (round 17)."""
    if not isinstance(ds, Dataset):
        raise ArgumentError(where, "ds", ds, f"of type {type(ds).__name__}; expected a Dataset "
                                             "(Dataset.load of a dataset file)")


#: Characters of a UFF record's ID line (ID line 1 holds a channel's ``<signal>/<channel>``).
UFF_ID_LINE_CHARS = 80


def _check_uff_names(ds: Dataset) -> None:
    """Refuse a channel whose ``<signal>/<channel>`` a UFF58 record cannot hold as it is.

    Hostile round 19: a name of more than :data:`UFF_ID_LINE_CHARS` characters was cut to the
    ID line in silence (two channels sharing their first 80 characters read back as
    ``acceleration/aaa...`` and ``acceleration/aaa...#5``), and blanks at either end of a name
    were dropped (UFF lines lose trailing blanks): the file read back named other channels
    than the dataset's.

    Raises
    ------
    ArgumentError
        Naming the channel, its length and what fits (SEP-005 JSON keeps any name).
    """
    for name, i, s in _channels(ds):
        full = f"{name}/{s.channels[i]}"
        if len(full) > UFF_ID_LINE_CHARS or full != full.strip():
            why = (f"{len(full)} characters; a UFF ID line holds {UFF_ID_LINE_CHARS}"
                   if len(full) > UFF_ID_LINE_CHARS else "blanks at its ends, which a UFF line "
                   "drops")
            raise ArgumentError("write_uff", "ds", f"channel {full[:100]!r}",
                                f"has {why}: the file would name another channel; expected names "
                                "that fit (or --format sep005, which keeps any name)",
                                described=True)


def write_uff(ds: Dataset, out: str | os.PathLike) -> Path:
    """Write units (164), geometry (2411, 82), every measured channel (58) and the true modes (55).

    Parameters
    ----------
    ds : Dataset
    out : path

    Returns
    -------
    Path
        ``out``, written atomically.
    """
    import pyuff

    _a_dataset("write_uff", ds)
    _check_uff_names(ds)
    nodes = node_numbers(ds)
    sets = [_uff164(), *_geometry(ds)]
    sets += [_uff58(ds, name, i, s, nodes[(name, i)]) for name, i, s in _channels(ds)]
    truth = structural_truth(ds)
    sensor_nodes = None if truth is None else _sensor_nodes(ds, truth, nodes)
    if truth is not None and sensor_nodes is not None:
        sets += _uff55(ds, truth, sensor_nodes)
    # pyuff 2.5 truncates the header of a binary 58 written in "overwrite" mode (it reopens the
    # file "wb" for the data), so start from an empty file (the temporary one) and add every set.
    return atomic_write(out, lambda tmp: pyuff.UFF(tmp).write_sets(sets, mode="add"))


def to_sep005(ds: Dataset) -> list[dict[str, Any]]:
    """The measured channels as SEP-005 channel dicts (``data`` as 1-D ndarray)."""
    _a_dataset("to_sep005", ds)
    nodes = node_numbers(ds)
    out = []
    for name, i, s in _channels(ds):
        unit = s.channel_units()[i]
        q, _, _, _, rot, tex = quantity(unit)
        ch: dict[str, Any] = {"name": f"{name}/{s.channels[i]}", "data": np.array(s.data[i], dtype=float),
                              "fs": float(ds.fs), "unit_str": unit, "unit_tex": tex, "quantity": q,
                              "node": nodes[(name, i)],
                              "direction": ("+Z rotation" if rot else "+Z"), "group": "measured",
                              "content_hash": str(ds.attrs.get("content_hash", ""))}
        if s.positions is not None:
            ch["position_m"] = float(s.positions[i])
        out.append(ch)
    return out


def write_sep005(ds: Dataset, out: str | os.PathLike) -> Path:
    """Write :func:`to_sep005` of ``ds`` as JSON (``data`` as lists of float) to ``out``."""
    channels = [{**c, "data": c["data"].tolist()} for c in to_sep005(ds)]
    return atomic_write_text(out, json.dumps(channels))


def read_sep005(path: str | os.PathLike) -> list[dict[str, Any]]:
    """The SEP-005 channel list of a file from :func:`write_sep005`, ``data`` as ndarray."""
    return [{**c, "data": np.asarray(c["data"], dtype=float)} for c in json.loads(Path(path).read_text())]


def export_dataset(path: str | os.PathLike, fmt: str, out: str | os.PathLike | None = None,
                   note: Callable[[str], None] | None = None) -> list[Path]:
    """Export a dataset file (HDF5 from :meth:`Dataset.save`) to another tool's format.

    Neither format carries the dataset's declared prior (``total_mass``, ``reduced_mass_trace``
    [kg], link lengths [m]): an identifier that needs it refused the exported record ("prior has no
    'reduced_mass_trace'", round 14).  ``note`` is told the prior left out, as the ``--prior``
    options that give it back to ``testbed identify``.

    Parameters
    ----------
    path : path
        The dataset ``.h5`` file.
    fmt : {"uff", "sep005"}
    out : path, optional
        Output file; default beside the dataset, ``<stem>.uff`` or ``<stem>.sep005.json``.
    note : callable, optional
        ``note(line)`` with one line naming the prior the format leaves out (none: not called).

    Returns
    -------
    list of Path
        The files written.

    Raises
    ------
    DatasetError, MeasuredDataError
        The file is no dataset (or fails its hash), or its measured signals cannot be read as
        they are (:func:`testbed.pipeline.importers.check_recorded`).
    """
    # the export API's own arguments, before any reading: an unknown format was a ValueError
    # after the file was read, and a path or output of another type a TypeError (round 17)
    if fmt not in ("uff", "sep005"):
        raise ArgumentError("export_dataset", "fmt", fmt, "unknown export format; allowed: "
                                                          "'uff', 'sep005'")
    for name, value in (("path", path), ("out", out)):
        if not (isinstance(value, (str, os.PathLike)) and isinstance(os.fspath(value), str)) \
                and not (name == "out" and value is None):
            raise ArgumentError("export_dataset", name, value, f"of type {type(value).__name__}; "
                                                               "expected a file path (str or os.PathLike)")
    path = Path(path)
    # its rate and storage checked, naming a damaged array (round 22); a unit stored as bytes
    # decoded and positions in mm converted to metres, as the file declares them (review 25a)
    ds = read_dataset_file(path)
    check_recorded(ds, path)  # an edited, rehashed file: NaN rate or samples, cut channels
    if fmt == "uff":
        written = [write_uff(ds, out or path.with_suffix(".uff"))]
    else:
        written = [write_sep005(ds, out or path.with_suffix(".sep005.json"))]
    if note is not None and ds.prior:
        given = " ".join(f"--prior {k}={float(v)!r}" for k, v in sorted(ds.prior.items()))
        note(f"note: {fmt} files carry no prior; give it back when identifying: {given} (SI units)")
    return written
