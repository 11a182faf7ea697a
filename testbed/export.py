"""Datasets other tools read: Universal File Format (UFF 58 / 55, via pyuff) and SEP-005 JSON.

UFF
    One binary UFF58 *time response* record (function type 1, double precision,
    even abscissa in seconds) per measured channel, with the abscissa and
    ordinate *specific data types*, SI unit exponents and unit labels filled in,
    the response node and direction, and the signal / scenario / content hash in
    the ID lines.  The UFF58 header keeps the sample interval to 6 significant
    digits only (format E13.5), so ID line 5 also states the exact ``fs``.  For a
    structural truth (``frequencies_hz`` + ``sensor_modes``) one UFF55 *normal mode*
    record per mode follows: frequency [Hz], viscous damping ratio and the mode shape
    at the sensor nodes (nodes = sensors).
SEP-005
    The SDyPy unified timeseries (SEP 5): a list with one dict per channel holding
    the compulsory ``name`` (unique), ``data``, ``unit_str`` and ``fs`` [Hz], plus
    ``unit_tex``, ``quantity``, ``node``, ``direction``, ``position_m``, ``group``
    and ``content_hash``.  The JSON file is that list with ``data`` as lists of
    float; :func:`read_sep005` gives ``data`` back as the ndarray the standard asks for.

Node numbers: channels with positions [m] (the cantilever's sensors and the
impact force) are numbered 1, 2, ... by position, so a force and the sensor it
acts at share a node; channels without positions (joint angles, torques) take the
number in their name (``th3`` -> 3, ``tau1`` -> 1), else their row index + 1.
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path
from typing import Any

import numpy as np

from testbed.atomic import atomic_write, atomic_write_text
from testbed.dataset import Dataset, Signal

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


def node_numbers(ds: Dataset) -> dict[tuple[str, int], int]:
    """Node number of every measured channel, keyed by (signal name, row)."""
    positions = sorted({round(float(p), 12) for s in ds.measured.values() if s.positions is not None
                        for p in s.positions})
    nodes: dict[tuple[str, int], int] = {}
    for name, s in ds.measured.items():
        for i, ch in enumerate(s.channels):
            if s.positions is not None:
                nodes[(name, i)] = positions.index(round(float(s.positions[i]), 12)) + 1
            else:
                m = re.search(r"(\d+)$", ch)
                nodes[(name, i)] = int(m.group(1)) if m else i + 1
    return nodes


def _channels(ds: Dataset) -> list[tuple[str, int, Signal]]:
    return [(name, i, s) for name, s in ds.measured.items() for i in range(len(s.channels))]


def _uff58(ds: Dataset, name: str, i: int, s: Signal, node: int) -> dict[str, Any]:
    import pyuff

    q, spec, len_exp, force_exp, rot, _ = quantity(s.unit)
    scen = str(ds.attrs.get("scenario_name") or ds.attrs.get("rig", ""))
    return pyuff.prepare_58(
        binary=1, func_type=1, ver_num=0, load_case_id=0,
        id1=f"{name}/{s.channels[i]}"[:80], id2=f"{q} [{s.unit}]"[:80],
        id3=f"scenario {scen} seed {ds.attrs.get('seed', '')}"[:80],
        id4=f"content hash {ds.attrs.get('content_hash', '')[:40]}"[:80],
        id5=f"fs {ds.fs!r} Hz, sysid-testbed"[:80],
        rsp_ent_name=s.channels[i][:10], rsp_node=node, rsp_dir=DIR_ROTATION if rot else DIR_TRANSLATION,
        ref_ent_name="NONE", ref_node=0, ref_dir=0,
        data=np.ascontiguousarray(s.data[i], dtype=float), x=ds.t,
        abscissa_spacing=1, abscissa_spec_data_type=TIME_SPEC_TYPE, abscissa_len_unit_exp=0,
        abscissa_force_unit_exp=0, abscissa_temp_unit_exp=0, abscissa_axis_units_lab="s",
        ordinate_spec_data_type=spec, ordinate_len_unit_exp=len_exp, ordinate_force_unit_exp=force_exp,
        ordinate_temp_unit_exp=0, ordinate_axis_units_lab=s.unit[:20],
        orddenom_spec_data_type=0, z_axis_spec_data_type=0, z_axis_value=0.0)


def _uff55(ds: Dataset, sensor_nodes: list[int]) -> list[dict[str, Any]]:
    """One normal-mode record per true mode: the shape at the sensor nodes along the bending direction."""
    import pyuff

    f = np.asarray(ds.truth["frequencies_hz"], dtype=float)
    phi = np.atleast_2d(np.asarray(ds.truth["sensor_modes"], dtype=float))
    zeta = np.asarray(ds.truth.get("damping_ratios", np.zeros_like(f)), dtype=float)
    n = min(f.size, phi.shape[1])
    zero = np.zeros(phi.shape[0])
    sets = []
    for k in range(n):
        shape = {"r1": zero, "r2": zero, "r3": zero, f"r{DIR_TRANSLATION}": phi[:, k]}
        sets.append(pyuff.prepare_55(
            model_type=1, analysis_type=2, data_ch=2, spec_data_type=8, data_type=2, n_data_per_node=3,
            id1=f"true mode {k + 1}", id2=f"{f[k]!r} Hz", id3=f"rig {ds.attrs.get('rig', '')}",
            id4=f"content hash {ds.attrs.get('content_hash', '')[:40]}", id5="sysid-testbed truth",
            **shape, node_nums=np.asarray(sensor_nodes), load_case=1, mode_n=k + 1,
            modal_m=0.0, freq=float(f[k]), modal_damp_vis=float(zeta[k]) if k < zeta.size else 0.0,
            modal_damp_his=0.0))
    return sets


def _sensor_nodes(ds: Dataset, nodes: dict[tuple[str, int], int]) -> list[int] | None:
    """Nodes of the signal the true sensor mode shapes refer to (same row count, with positions)."""
    phi = ds.truth.get("sensor_modes")
    if phi is None or "frequencies_hz" not in ds.truth:
        return None
    rows = np.atleast_2d(np.asarray(phi)).shape[0]
    for name, s in ds.measured.items():
        if len(s.channels) == rows and quantity(s.unit)[0] in ("acceleration", "velocity", "displacement"):
            return [nodes[(name, i)] for i in range(rows)]
    return None


def write_uff(ds: Dataset, out: str | os.PathLike) -> Path:
    """Write every measured channel as UFF58 (and the true modes as UFF55) to ``out``."""
    import pyuff

    nodes = node_numbers(ds)
    sets = [_uff58(ds, name, i, s, nodes[(name, i)]) for name, i, s in _channels(ds)]
    sensor_nodes = _sensor_nodes(ds, nodes)
    if sensor_nodes is not None:
        sets += _uff55(ds, sensor_nodes)
    # pyuff 2.5 truncates the header of a binary 58 written in "overwrite" mode (it reopens the
    # file "wb" for the data), so start from an empty file (the temporary one) and add every set.
    return atomic_write(out, lambda tmp: pyuff.UFF(tmp).write_sets(sets, mode="add"))


def to_sep005(ds: Dataset) -> list[dict[str, Any]]:
    """The measured channels as SEP-005 channel dicts (``data`` as 1-D ndarray)."""
    nodes = node_numbers(ds)
    out = []
    for name, i, s in _channels(ds):
        q, _, _, _, rot, tex = quantity(s.unit)
        ch: dict[str, Any] = {"name": f"{name}/{s.channels[i]}", "data": np.array(s.data[i], dtype=float),
                              "fs": float(ds.fs), "unit_str": s.unit, "unit_tex": tex, "quantity": q,
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


def export_dataset(path: str | os.PathLike, fmt: str, out: str | os.PathLike | None = None) -> list[Path]:
    """Export a dataset file (HDF5 from :meth:`Dataset.save`) to another tool's format.

    Parameters
    ----------
    path : path
        The dataset ``.h5`` file.
    fmt : {"uff", "sep005"}
    out : path, optional
        Output file; default beside the dataset, ``<stem>.uff`` or ``<stem>.sep005.json``.

    Returns
    -------
    list of Path
        The files written.
    """
    path = Path(path)
    ds = Dataset.load(path)
    if fmt == "uff":
        return [write_uff(ds, out or path.with_suffix(".uff"))]
    if fmt == "sep005":
        return [write_sep005(ds, out or path.with_suffix(".sep005.json"))]
    raise ValueError(f"unknown export format {fmt!r}; allowed: 'uff', 'sep005'")
