"""Sixteenth malformed-input round: the findings of ``benchmarks/hostile16.py`` (docs/history.md,
malformed-input audits), each fixed in the layer that owns it.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest


def _synthetic():
    """tests/testbed/_synthetic_runs.py (imported as test_runstore and test_faults do)."""
    if str(Path(__file__).parent) not in sys.path:
        sys.path.insert(0, str(Path(__file__).parent))
    import _synthetic_runs

    return _synthetic_runs


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    """One run in a run history (its folder), written by save_new_run."""
    from testbed.studies.runstore import save_new_run

    out = tmp_path_factory.mktemp("runs")
    return save_new_run(_synthetic().structural_result(n_samples=200), out)


def _copy(saved: Path, tmp_path: Path) -> tuple[Path, Path]:
    import shutil

    out = tmp_path / "runs"
    shutil.copytree(saved.parent.parent, out)
    return out, out / saved.parent.name / saved.name


def _edit_json(run: Path, edit) -> None:
    meta = json.loads((run / "run.json").read_text())
    edit(meta)
    (run / "run.json").write_text(json.dumps(meta, indent=2))


# ------------------------------------------------------------------ run folders

@pytest.mark.parametrize("edit", [
    # a flipped digit of a score, a loosened bar, another seed or scenario: each was listed and
    # reported as the run's own (run.json carried no checksum)
    lambda m: m["scores"].__setitem__(next(iter(m["scores"])), 123.0),
    lambda m: [c.__setitem__("threshold", 1e9) for c in m["checks"]],
    lambda m: m["scenario"].__setitem__("seed", 7),
    lambda m: m["scenario"].__setitem__("name", "cartpole"),
    lambda m: m.__setitem__("fit_time", -1.0),
    lambda m: m.__setitem__("figures", ["../../../x.png"]),
], ids=["score", "threshold", "seed", "scenario", "fit_time", "figures"])
def test_an_edited_run_json_is_refused_as_damaged(saved, tmp_path, edit):
    from testbed.studies.runstore import list_runs, load_run

    out, run = _copy(saved, tmp_path)
    assert len(list_runs(out)) == 1 and load_run(run).meta["format"].endswith("/2")
    _edit_json(run, edit)
    damaged: list = []
    assert list_runs(out, damaged=damaged) == [] and damaged == [run]
    with pytest.raises(ValueError, match=r"does not match its checksum"):
        load_run(run)


@pytest.mark.parametrize("damage", ["flip", "cut", "remove"])
def test_a_damaged_or_missing_run_npz_is_refused(saved, tmp_path, damage):
    from testbed.studies.runstore import list_runs, load_run

    out, run = _copy(saved, tmp_path)
    npz = run / "run.npz"
    data = bytearray(npz.read_bytes())
    if damage == "remove":
        # `testbed report` of a run without its arrays wrote a report without them, status 0
        npz.unlink()
        damaged: list = []
        assert list_runs(out, damaged=damaged) == [] and damaged == [run]
    else:
        # a byte flipped inside a stored member's data may pass zip's own checks
        if damage == "flip":
            data[len(data) // 3] ^= 0x01
        else:
            data = data[: len(data) - 7]
        npz.write_bytes(bytes(data))
    with pytest.raises(ValueError, match=r"run\.npz"):
        load_run(run)


def test_a_run_folder_without_its_run_json_is_named_not_dropped(saved, tmp_path):
    from testbed.studies.runstore import list_runs

    # run.json deleted (or a folder in its place): the folder was left out of the listing in
    # silence, its run.npz and figures still there
    out, run = _copy(saved, tmp_path)
    (run / "run.json").unlink()
    damaged: list = []
    assert list_runs(out, damaged=damaged) == [] and damaged == [run]
    (run / "run.json").mkdir()
    damaged = []
    assert list_runs(out, damaged=damaged) == [] and damaged == [run]


def test_a_v1_run_is_read_as_written(saved, tmp_path):
    from testbed.studies.runstore import DIGEST, NPZ_DIGEST, READ_FORMATS, list_runs, load_run

    # runs written before the checksums (format /1) are still listed and reported
    out, run = _copy(saved, tmp_path)
    _edit_json(run, lambda m: (m.update(format=READ_FORMATS[0]), m.pop(DIGEST), m.pop(NPZ_DIGEST)))
    assert len(list_runs(out)) == 1 and load_run(run).identifier
    # ... but a /2 run whose checksum was removed is not one of them
    _edit_json(run, lambda m: m.update(format=READ_FORMATS[1]))
    with pytest.raises(ValueError, match="checksum"):
        load_run(run)


@pytest.mark.parametrize(("key", "value"), [
    ("name", "a\nb"), ("name", "x\x1b[31m"), ("seed", "s\tx"), ("seed", -1), ("seed", True),
    ("identifier", "id\x1b[32m"),
])
def test_a_v1_run_whose_listed_fields_are_not_one_line_is_damaged(saved, tmp_path, key, value):
    from testbed.studies.runstore import DIGEST, NPZ_DIGEST, READ_FORMATS, list_runs, load_run

    # a /1 run (no checksum) whose scenario name held a newline split its `testbed runs
    # --plain` row in two; a tab added a column, an ESC went raw to the terminal and the report
    out, run = _copy(saved, tmp_path)

    def edit(m):
        m.update(format=READ_FORMATS[0])
        m.pop(DIGEST), m.pop(NPZ_DIGEST)
        (m["identifier"] if key == "identifier" else m["scenario"])[
            "name" if key == "identifier" else key] = value
    _edit_json(run, edit)
    damaged: list = []
    assert list_runs(out, damaged=damaged) == [] and damaged == [run]
    with pytest.raises(ValueError, match=r"control characters|integer >= 0"):
        load_run(run)


def test_a_v1_runs_figures_name_files_inside_its_folder_only(saved, tmp_path):
    from testbed.studies.runstore import DIGEST, NPZ_DIGEST, READ_FORMATS, load_run

    _, run = _copy(saved, tmp_path)
    (tmp_path / "x.png").write_bytes(b"\x89PNG")
    (run / "f.png").write_bytes(b"\x89PNG")
    _edit_json(run, lambda m: (m.update(format=READ_FORMATS[0], figures=["../../../x.png", "f.png", 3]),
                               m.pop(DIGEST), m.pop(NPZ_DIGEST)))
    assert load_run(run).figures == [run / "f.png"]


# ------------------------------------------------------------------ measured records

def _sep005(path: Path, channels: dict[str, tuple[str, list[float], int]], fs: float = 100.0) -> Path:
    """A SEP-005 file of ``name: (unit, data, node)`` channels (an input acts on its node's joint)."""
    path.write_text(json.dumps([{"name": name, "data": data, "fs": fs, "unit_str": unit, "node": node}
                                for name, (unit, data, node) in channels.items()]))
    return path


def _cartpole_like(n: int = 400, fs: float = 100.0):
    import numpy as np

    t = np.arange(n) / fs
    th = 3.0 + 0.5 * np.sin(2 * np.pi * 0.7 * t)  # crosses pi: wrapped, it jumps by 2 pi
    x = 0.1 * np.sin(2 * np.pi * 0.3 * t)
    u = np.sin(2 * np.pi * 1.1 * t)
    return th, x, u


@pytest.mark.parametrize("wrapped", [False, True])
def test_a_wrapped_angle_is_refused_naming_its_channel_and_step(tmp_path, wrapped):
    import math

    import numpy as np

    from testbed.pipeline.importers import MeasuredDataError, measurement_from_file

    # a five-bar record whose angles were wrapped to (-pi, pi] was differentiated into spikes
    # and refused as "loop closure Newton solve did not converge", naming neither
    th, x, u = _cartpole_like()
    if wrapped:
        th = (th + math.pi) % (2 * math.pi) - math.pi
    f = _sep005(tmp_path / "r.json", {"theta/x": ("m", x.tolist(), 1), "theta/th": ("rad", th.tolist(), 2),
                                      "torque/u1": ("N", u.tolist(), 1)})
    if not wrapped:
        m = measurement_from_file(f, "mechanical", {"derivatives": "lowpass"})
        assert np.all(np.isfinite(m.xd))
        return
    with pytest.raises(MeasuredDataError, match=r"'th' steps by [+-]6.2\d* rad between samples \d+ "
                                                r"and \d+: a wrapped angle .*numpy.unwrap"):
        measurement_from_file(f, "mechanical", {"derivatives": "lowpass"})


@pytest.mark.parametrize("edit", ["none", "degrees", "copy", "negated", "biased", "spinning degrees",
                                  "estimated", "long noisy", "quiet channel"])
def test_a_recorded_rate_that_is_not_its_signals_is_refused(tmp_path, edit):
    import math

    import numpy as np

    from testbed.pipeline.importers import MeasuredDataError, measurement_from_file

    # a cart-pole's pole angle logged in degrees under "rad", rates that were a copy of the
    # angles, a kinetics record's negated rate: each was fitted into a model, status 0
    fs, n = 100.0, (30000 if edit == "long noisy" else 400)
    t = np.arange(n) / fs
    w = 2 * np.pi * 0.7
    th, dth, ddth = 0.5 * np.sin(w * t), 0.5 * w * np.cos(w * t), -0.5 * w * w * np.sin(w * t)
    x, dx, ddx = (0.1 * np.sin(0.3 * w * t), 0.03 * w * np.cos(0.3 * w * t),
                  -0.009 * w * w * np.sin(0.3 * w * t))
    chain = {}  # the rates as recorded (the default): the ones the fit reads
    if edit in ("degrees", "estimated"):
        th = th * 180 / math.pi
        if edit == "estimated":  # the recorded rates are not used: nothing to refuse
            chain = {"derivatives": "lowpass"}
    elif edit == "copy":
        dth = th.copy()
    elif edit == "biased":  # a gyroscope's offset, 15 % of the rate's RMS: a linear drift of its
        dth = dth + 0.15 * np.sqrt(np.mean(dth ** 2))  # integral (0.75 of the motion: refused before)
    elif edit == "spinning degrees":  # a link turning at 0.5 rev/s, logged in degrees under "rad":
        th, dth = 2 * np.pi * 0.5 * t + th, 2 * np.pi * 0.5 + dth  # only an offset shows it
        th = th * 180 / math.pi
    elif edit == "long noisy":  # 300 s, white noise of 20 % of the rate's RMS on the rate: its
        dth = dth + 0.2 * np.sqrt(np.mean(dth ** 2)) * np.random.default_rng(1).standard_normal(n)
        # integral over the whole record misfit 0.6 of the motion and was refused
    elif edit == "quiet channel":  # the cart hardly moves: 2 mm under 1 mm of sensor noise
        x = 0.002 * np.sin(0.3 * w * t) + 0.001 * np.random.default_rng(2).standard_normal(n)
        dx, ddx = dx / 50, ddx / 50
    if edit == "negated":  # the dynamical kind's (x, dx)
        f = _sep005(tmp_path / "k.json", {"x/x": ("mM", (1.5 + th).tolist(), 1),
                                          "dx/dx": ("mM/s", (-dth).tolist(), 1)})
        with pytest.raises(MeasuredDataError, match=r"'dx' channel 'dx' is not the rate of 'x' channel 'x'"):
            measurement_from_file(f, "dynamical")
        return
    f = _sep005(tmp_path / "r.json", {"theta/x": ("m", x.tolist(), 1), "theta/th": ("rad", th.tolist(), 2),
                                      "dtheta/dx": ("m/s", dx.tolist(), 1),
                                      "dtheta/dth": ("rad/s", dth.tolist(), 2),
                                      "ddtheta/ddx": ("m/s^2", ddx.tolist(), 1),
                                      "ddtheta/ddth": ("rad/s^2", ddth.tolist(), 2),
                                      "torque/u1": ("N", np.sin(1.1 * w * t).tolist(), 1)}, fs)
    if edit in ("none", "biased", "estimated", "long noisy", "quiet channel"):
        assert measurement_from_file(f, "mechanical", chain).x.shape == (2, n)
        return
    what = "misses"
    if edit == "spinning degrees":
        what = r"drifts .* as if the rate were offset by 5\d\.\d of its RMS; expected at most 0.25"
    with pytest.raises(MeasuredDataError, match=r"'dtheta' channel 'dth' is not the rate of 'theta' "
                                                r"channel 'th': its running integral " + what):
        measurement_from_file(f, "mechanical", chain)
