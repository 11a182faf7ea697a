"""Twenty-fourth malformed-input round: the findings of ``benchmarks/hostile24.py``
(docs/known-gaps.md, "Malformed-input round 24"), each fixed in the layer that owns it.
"""

from __future__ import annotations

import io
import json
import os
import pickle
import re
import zipfile
from pathlib import Path

import h5py
import numpy as np
import pytest
import pyuff

from testbed.core.dataset import Dataset, DatasetError
from testbed.core.run_arrays import check_run_npz
from testbed.pipeline.importers import MeasuredDataError, from_sep005, measurement_from_file, read_measured
from testbed.reporting.export import export_dataset
from testbed.studies import runstore


def _one_error_line(err: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert "Traceback" not in err and len(lines) == 1 and lines[0].startswith("error: "), err
    return lines[0]


# ------------------------------------------------------------------ UFF: a node placed twice

FS = 1000.0
X = np.array([0.1, 0.2, 1 / 3])  # [m]; 1/3 has no short decimal form (UFF15 rounds it)


def _geometry(kind: int, x: np.ndarray) -> dict:
    n = len(x)
    return {"type": kind, "node_nums": np.arange(1, n + 1), "def_cs": np.ones(n, int),
            "disp_cs": np.ones(n, int), "color": np.ones(n, int), "x": np.asarray(x, float),
            "y": np.zeros(n), "z": np.zeros(n)}


def _response(node: int, direction: int = 3) -> dict:
    t = np.arange(400) / FS
    s = pyuff.prepare_58(
        binary=0, id1=f"acceleration/acc{node}", id5=f"fs {FS} Hz", func_type=1, rsp_node=node,
        rsp_dir=direction, ref_node=0, ref_dir=0, ord_data_type=2, num_pts=t.size,
        abscissa_spacing=1, abscissa_min=0.0, abscissa_inc=1 / FS, abscissa_spec_data_type=17,
        ordinate_spec_data_type=12, ordinate_len_unit_exp=1, ordinate_axis_units_lab="m/s^2",
        orddenom_spec_data_type=0, data=np.sin(2 * np.pi * 7 * t) * node, x=t,
        return_full_dict=True)
    # the header fields left unset: 0, and "NONE" for a text (UFF's own blank)
    return {k: (("NONE" if k.endswith(("_lab", "_name")) or k.startswith("id") else 0)
                if v is None else v) for k, v in s.items()}


def _uff(tmp_path: Path, geometry: list[dict], name: str = "beam.uff") -> Path:
    path = tmp_path / name
    sets = [{"type": 164, "units_code": 1, "units_description": "SI", "temp_mode": 1,
             "length": 1.0, "force": 1.0, "temp": 1.0, "temp_offset": 0.0},
            *geometry, *(_response(k) for k in (1, 2, 3))]
    pyuff.UFF(str(path)).write_sets(sets, mode="add")
    return path


def _positions(path: Path) -> list[float]:
    data = read_measured(path)
    return [data.positions[f"acceleration/acc{k}"] for k in (1, 2, 3)]


@pytest.mark.parametrize("geometry", [
    [_geometry(2411, X)],
    [_geometry(2411, X), _geometry(2411, X)],  # the same node list twice
    [_geometry(2411, X), _geometry(15, X)],    # a UFF15 twin, rounded to 6 digits
    [_geometry(15, X), _geometry(2411, X)],    # review 25a: the UFF15 first gave its 6 digits
], ids=["one", "twice-same", "uff15-agrees", "uff15-first"])
def test_a_node_placed_once_or_twice_at_one_place_is_read(tmp_path, geometry):
    got = _positions(_uff(tmp_path, geometry))
    assert np.allclose(got, X, rtol=1e-5, atol=0)  # UFF15's 6 significant digits
    if any(g["type"] == 2411 for g in geometry):
        assert got == list(X)  # UFF2411 writes 16 digits: exact, whichever record comes first


X0 = np.array([0.0, 0.5, 1.0])  # [m]; node 1 at the origin


def _moved(x: np.ndarray, axis: str, by: float) -> dict:
    g = _geometry(2411, x)
    g[axis] = g[axis] + np.array([by, 0.0, 0.0])
    return g


@pytest.mark.parametrize("axis", ["x", "z"])
def test_a_node_at_the_origin_with_float_noise_is_one_place(tmp_path, axis):
    """Review 25a: 0 in one record and -1.2e-16 in another (``L cos(pi/2)``) was refused as
    placed twice: the tolerance was relative to the node's own coordinates (all ~0); it is
    relative to the model's largest coordinate (1 m here)."""
    assert _positions(_uff(tmp_path, [_geometry(2411, X0), _moved(X0, axis, -1.2e-16)])) == list(X0)


def test_a_node_at_the_origin_moved_beyond_the_model_tolerance_is_refused(tmp_path):
    """1 mm in a 1 m model is 1e-3 of it, beyond NODE_RTOL (1e-5)."""
    with pytest.raises(MeasuredDataError, match=r"node 1 is placed twice: at \(0, 0, 0\) m .*"
                                                r"at \(0, 0, 0\.001\) m"):
        read_measured(_uff(tmp_path, [_geometry(2411, X0), _moved(X0, "z", 1e-3)]))


def _twice_in_one(x: np.ndarray) -> dict:
    g = _geometry(2411, x)
    for k in ("node_nums", "def_cs", "disp_cs", "color", "x", "y", "z"):
        g[k] = np.append(g[k], g[k][1])
    g["x"][-1] += 0.05
    return g


@pytest.mark.parametrize(("geometry", "node", "records"), [
    ([_twice_in_one(X)], 2, r"record 2 \(UFF2411\) and at \(0\.25, 0, 0\) m by record 2 \(UFF2411\)"),
    ([_geometry(2411, X), _geometry(2411, X + 0.05)], 1,
     r"record 2 \(UFF2411\) and .* by record 3 \(UFF2411\)"),
    ([_geometry(2411, X), _geometry(15, X + 0.05)], 1, r"record 2 \(UFF2411\) and .* by record 3 \(UFF15\)"),
], ids=["twice-in-one-record", "two-uff2411", "uff2411-and-uff15"])
def test_a_node_placed_at_two_places_is_refused(tmp_path, geometry, node, records):
    """Round 24: the later place was read in silence (and the sensor's position with it)."""
    with pytest.raises(MeasuredDataError, match=rf"node {node} is placed twice: at .*{records}"):
        read_measured(_uff(tmp_path, geometry))


def test_a_uff_without_id_line_1_is_refused_saying_how_to_name_its_channels(tmp_path):
    """fuzz25's open (d): records without ID line 1 (channels named node1:3, ...) were refused
    "dataset has no measured signal 'acceleration' (has node1:3, ...)" naming no way out."""
    path = tmp_path / "beam.uff"
    sets = [_geometry(2411, X), *({**_response(k), "id1": ""} for k in (1, 2, 3))]
    pyuff.UFF(str(path)).write_sets(sets, mode="add")
    with pytest.raises(MeasuredDataError, match=r"has node1:3, .*; 3 UFF58 record\(s\) have no ID line 1 "
                                                r"\(named node<node>:<direction>\): write each "
                                                r"channel's '<signal>/<channel>' there"):
        measurement_from_file(path, "structural")


# ------------------------------------------------------------------ one axis for a structural record

def _sep005(directions: list[str]) -> list[dict]:
    t = np.arange(400) / FS
    return [{"name": f"acceleration/acc{k + 1}", "data": (np.sin(2 * np.pi * 7 * t) * (k + 1)).tolist(),
             "fs": FS, "unit_str": "m/s^2", "direction": d, "position_m": 0.1 * (k + 1)}
            for k, d in enumerate(directions)]


def test_a_structural_record_along_two_axes_is_refused(tmp_path):
    """Round 24: a sensor declared +Y beside +Z ones (UFF rsp_dir 2 beside 3) was fitted with
    status 0 as if it measured along Z (the planar chain has one axis)."""
    path = tmp_path / "beam.json"
    path.write_text(json.dumps(_sep005(["+Z", "+Y", "+Z"])))
    with pytest.raises(MeasuredDataError, match=r"channel 'acceleration/acc2' points along Y \(code 2\) "
                                                r"and channel 'acceleration/acc1' along Z \(code 3\)"):
        measurement_from_file(path, "structural")


@pytest.fixture(scope="module")
def cartpole_sep005(tmp_path_factory) -> Path:
    """A cart-pole record exported as SEP-005: the cart's channels +Z (code 3), the pole's
    +Z rotation (code 6)."""
    from testbed import cli

    d = tmp_path_factory.mktemp("cartpole")
    assert cli.main(["generate", "cartpole", "-o", str(d / "cp.h5"), "--cache", str(d / "c")]) == 0
    [out] = export_dataset(d / "cp.h5", "sep005", d / "cp.json")
    return out


def test_mixed_axes_are_read_where_the_kind_allows_them(cartpole_sep005):
    """The rule is the structural kind's: a cart's translation beside its pole's rotation is a
    mechanical record, read through the mechanical chain (review 25a: the test called only
    the reader, so it would pass with the one-axis check applied to every kind)."""
    data = from_sep005(json.loads(cartpole_sep005.read_text()))
    assert {abs(c) for c in data.directions.values()} == {3, 6}  # two axes, as the test needs
    m = measurement_from_file(cartpole_sep005, "mechanical")
    assert m.channels == ("x", "th") and m.x.shape[0] == 2


# ------------------------------------------------------------------ dataset files' declarations

@pytest.fixture(scope="module")
def mm_file(tmp_path_factory) -> Path:
    from testbed import cli

    d = tmp_path_factory.mktemp("mm")
    assert cli.main(["generate", "michaelis_menten", "-o", str(d / "mm.h5"), "--cache", str(d / "c")]) == 0
    return d / "mm.h5"


def _edited(src: Path, dst: Path, edit) -> Path:
    dst.write_bytes(src.read_bytes())
    with h5py.File(dst, "r+") as f:
        edit(f)
    try:
        ds = Dataset.load(dst, verify=False)
    except DatasetError:  # (an integer acts_on: no hash to make; the checks come first)
        return dst
    with h5py.File(dst, "r+") as f:  # the content hash made anew, as a user's edit would
        f.attrs["content_hash"] = ds.content_hash()
    return dst


def _attrs(where: str, **attrs):
    def edit(f):
        for k, v in attrs.items():
            f[where].attrs[k] = v
    return edit


@pytest.mark.parametrize(("edit", "said"), [
    (_attrs("measured", fs=1.0), r"/measured: attribute 'fs' on the group itself"),
    (_attrs("truth", unit="mM"), r"/truth: attribute 'unit' on the group itself"),
    (_attrs("reference", scale=2.0), r"/reference: attribute 'scale' on the group itself"),
    (_attrs("measured/x", positions=np.array([100.0]), positions_unit="in"),
     r"/measured/x: attribute positions_unit='in'; expected a length unit"),
    (_attrs("measured/x", positions=np.array([100.0]), positions_unit="rad"),
     r"/measured/x: attribute positions_unit='rad'; expected a length unit"),
    (_attrs("measured/x", positions=np.array([0.1]), positions_unit=1.0),
     r"/measured/x: attribute positions_unit=1\.0 \(float64\); expected a text"),
    (_attrs("measured/x", unit=np.bytes_(b"\xff")),
     r"/measured/x: attribute unit=b'\\xff' \(bytes_\); expected a text"),
    (_attrs("measured/x", channels=np.array([b"x"], dtype="S1")),
     r"/measured/x: name b'x' \(bytes_\) in attribute channels"),
    (_attrs("measured/x", acts_on=3), r"/measured/x: attribute acts_on=3 \(int64\); expected a list"),
], ids=["measured-group", "truth-group", "reference-group", "positions-in", "positions-rad",
        "positions-unit-number", "unit-not-utf8", "channel-bytes", "acts-on-integer"])
def test_a_declaration_the_reader_would_not_read_as_it_says_is_refused(mm_file, tmp_path, edit, said):
    """Round 24 (content hash made anew): a group's attribute was kept in silence, positions in
    mm read as metres (export wrote them so), a unit stored as fixed-length bytes read as the
    text "b'mM'", an integer acts_on "unreadable dataset file (TypeError ...)"."""
    path = _edited(mm_file, tmp_path / "edited.h5", edit)
    with pytest.raises(MeasuredDataError, match=said):
        read_measured(path)
    with pytest.raises(MeasuredDataError, match=said):
        export_dataset(path, "sep005", tmp_path / "out.json")


@pytest.mark.parametrize("edit", [_attrs("measured", **{"a" * 5000: 1.0}),
                                  _attrs("measured/x", positions=np.array([0.1]), positions_unit="q" * 5000)],
                         ids=["group-attribute-name", "positions-unit"])
def test_a_long_declaration_is_cut_in_the_message(mm_file, tmp_path, edit):
    """Review 25a: the group's attribute name and positions_unit's value went uncut into the
    line (show_value's cut now, as everywhere)."""
    path = _edited(mm_file, tmp_path / "long.h5", edit)
    with pytest.raises(MeasuredDataError) as e:
        read_measured(path)
    assert len(str(e.value)) < 600 and "..." in str(e.value), str(e.value)[:300]


def test_positions_in_metres_still_read(mm_file, tmp_path):
    path = _edited(mm_file, tmp_path / "m.h5",
                   _attrs("measured/x", positions=np.array([0.1]), positions_unit="m"))
    assert read_measured(path).positions == {"x/x": 0.1}


@pytest.mark.parametrize("unit", ["mm", np.bytes_(b"mm"), np.array(["mm"], dtype=h5py.string_dtype())],
                         ids=["text", "bytes", "one-element-array"])
def test_positions_in_millimetres_are_read_in_metres(mm_file, tmp_path, unit):
    """Review 25a: `positions_unit = "mm"` (a length unit si_unit knows) was refused; it is
    read, and exported, as metres (100 mm = 0.1 m; 1e-3 is exact to a rounding of 0.1)."""
    path = _edited(mm_file, tmp_path / "mm.h5",
                   _attrs("measured/x", positions=np.array([100.0]), positions_unit=unit))
    assert read_measured(path).positions == {"x/x": 100.0 * 1e-3}
    [out] = export_dataset(path, "sep005", tmp_path / "out.json")
    [x] = [c for c in json.loads(out.read_text()) if c["name"] == "x/x"]
    assert x["position_m"] == 100.0 * 1e-3


@pytest.mark.parametrize("unit", [np.bytes_(b"mM"), np.array(["mM"], dtype=h5py.string_dtype()),
                                  np.array([b"mM"], dtype="S2")],
                         ids=["bytes", "one-element-text", "one-element-bytes"])
def test_a_unit_stored_as_bytes_or_in_a_one_element_array_is_decoded(mm_file, tmp_path, unit):
    """Review 25a: a `unit` of fixed-length bytes (as many HDF5 writers store text) was refused
    (and before round 24 read as the text "b'mM'"); it is decoded, here to the file's own mM."""
    path = _edited(mm_file, tmp_path / "u.h5", _attrs("measured/x", unit=unit))
    data = read_measured(path)
    assert data.signals["x/x"][0] == "mM"
    assert measurement_from_file(path, "dynamical") is not None


# ------------------------------------------------------------------ run.npz

class _Marker:
    def __init__(self, path: str) -> None:
        self.path = path

    def __reduce__(self):
        return (os.mkdir, (self.path,))


@pytest.fixture(scope="module")
def mm_run(tmp_path_factory) -> Path:
    from testbed import cli

    d = tmp_path_factory.mktemp("run")
    assert cli.main(["run", "michaelis_menten", "-o", str(d / "runs"), "--no-figures",
                     "--cache", str(d / "c")]) in (0, 1)
    return next((d / "runs" / "michaelis_menten").glob("*/run.json")).parent


def _resealed(src: Path, dst: Path, npz: bytes) -> Path:
    """A copy of run folder ``src`` whose run.npz is ``npz``, its checksums made anew."""
    import shutil

    shutil.copytree(src, dst)
    (dst / "run.npz").write_bytes(npz)
    meta = json.loads((dst / "run.json").read_text())
    meta[runstore.NPZ_DIGEST] = runstore._file_digest(dst / "run.npz")
    meta[runstore.DIGEST] = runstore.meta_digest(meta)
    (dst / "run.json").write_text(json.dumps(meta))
    return dst


def _npz(run: Path, change) -> bytes:
    with np.load(run / "run.npz", allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    change(arrays)
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def _float_key(arrays: dict) -> str:
    return next(k for k, v in arrays.items() if v.dtype.kind == "f" and v.size > 1)


def _npy(a: np.ndarray) -> bytes:
    buf = io.BytesIO()
    np.save(buf, a)
    return buf.getvalue()


def _zip_with_pickle(marker: str) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        z.writestr("model/x.pkl", pickle.dumps(_Marker(marker)))
    return buf.getvalue()


@pytest.mark.parametrize(("make", "said"), [
    (lambda run, m: _npz(run, lambda a: a.__setitem__("details/evil", np.array([_Marker(m)], dtype=object))),
     r"member 'details/evil\.npy' has dtype object \(objects: pickled data, not loaded\)"),
    (lambda run, m: _npz(run, lambda a: a.__setitem__(
        _float_key(a), np.zeros(3, dtype=[("a", "f8"), ("b", "i4")]))), r"has dtype .*\(kind 'V'\)"),
    (lambda run, m: _zip_with_pickle(m), r"member 'model/x\.pkl' is not a \.npy array"),
    (lambda run, m: pickle.dumps(_Marker(m)), r"run\.npz: starts with the bytes b'\\x80\\x04.*not a zip's"),
    # review 25a: a real run's zip appended to a .npy or a pickle (zipfile finds a zip by its
    # end, numpy.load by its first bytes): the check passed and `report` said "(TypeError)"
    (lambda run, m: _npy(np.arange(3.0)) + (run / "run.npz").read_bytes(),
     r"run\.npz: starts with the bytes b'\\x93NUM', not a zip's"),
    (lambda run, m: pickle.dumps(_Marker(m)) + (run / "run.npz").read_bytes(),
     r"run\.npz: starts with the bytes b'\\x80\\x04.*not a zip's"),
], ids=["object-member", "structured-member", "pkl-member", "a-pickle", "npy-then-zip", "pickle-then-zip"])
def test_a_run_npz_of_other_than_plain_arrays_is_refused_unloaded(cli_in_process, mm_run, tmp_path,
                                                                  make, said):
    """Round 24, the run sealed anew: a structured member was an internal error in `testbed
    report`; a .pkl member and a lone pickle were refused naming only "(AttributeError)" /
    "(TypeError)"; no pickle is ever loaded (its code would make the marker folder)."""
    marker = tmp_path / "PICKLE_RAN"
    run = _resealed(mm_run, tmp_path / "runs" / "michaelis_menten" / mm_run.name, make(mm_run, str(marker)))
    with pytest.raises(ValueError, match=said):
        check_run_npz(run)
    with pytest.raises(ValueError, match=said):  # the store's own reader too (fuzz25's open (b):
        runstore.load_run(run)  # AttributeError / TypeError for the .pkl member and the lone pickle)
    p = cli_in_process("report", str(run), "-o", str(tmp_path / "report"), cwd=tmp_path)
    assert p.returncode == 2
    line = _one_error_line(p.stderr)
    assert "not a run folder written by `testbed run`" in line and line.count(str(run)) == 1, line
    assert not marker.exists()


def test_a_plain_run_npz_still_reports(cli_in_process, mm_run, tmp_path):
    run = _resealed(mm_run, tmp_path / "runs" / "michaelis_menten" / mm_run.name,
                    _npz(mm_run, lambda a: a.__setitem__(_float_key(a), a[_float_key(a)].astype(">f8"))))
    check_run_npz(run)
    p = cli_in_process("report", str(run), "-o", str(tmp_path / "report"), cwd=tmp_path)
    assert p.returncode == 0, p.stderr


# ------------------------------------------------------------------ --units with no unit

# channel x/x is one of the file's (x/x, dx/dx); `x/x=""` and `x/x=' '` parse to a blank text
# (review 25a: refused as "channel 'x/x' has no unit" and "... is in mM/s")
@pytest.mark.parametrize("units", [["x/x="], ["x/x= "], [""], [" "], ['x/x=""'], ["x/x=' '"],
                                   ["dx/dx=mM/s", 'x/x=""']])
def test_units_with_no_unit_are_refused_as_such(cli_in_process, mm_file, tmp_path, units):
    """Round 24: `--units acceleration/acc1=` replaced the file's declared unit by none and was
    refused as "channel ... has no unit; declare it with units=" (the option that had just
    declared it)."""
    p = cli_in_process("identify", str(mm_file), "--kind", "dynamical", "--method", "sindy_pi_dynamical",
                       *[a for u in units for a in ("--units", u)], "-o", str(tmp_path / "m.json"),
                       cwd=tmp_path)
    assert p.returncode == 2
    line = _one_error_line(p.stderr)
    assert re.search(r"--units .*: no (value after '='|unit)", line), line


def test_a_coordinate_zero_in_one_record_and_float_noise_in_another_is_one_place(tmp_path):
    """The tolerance is relative to the node's place, not to each coordinate (0 against 1e-17)."""
    other = _geometry(2411, X)
    other["y"] = other["y"] + 1e-17
    assert _positions(_uff(tmp_path, [_geometry(2411, X), other])) == list(X)
