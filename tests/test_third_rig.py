"""A third rig added from outside the project runs end to end, touching nothing generic.

The rig (``tests/springmass_rig.py``, a two-mass spring chain in MuJoCo, kind "structural")
joins through the plugin seam; its scenario is a dict built here.  It is generated, put
through the structural signal chain, identified by ``ls_sindy``, scored against its exact
truth, saved as a run and rendered as a report: every one of those steps is reached through
the kind's registries (signal chain, scorer, truth type), none by the rig's name.
"""

import json
import sys

import h5py
import numpy as np
import pytest

from testbed.core.dataset import Dataset, DatasetError
from testbed.core.truth import StructuralTruth, TruthError
from testbed.pipeline.plugins import RIGS, load_plugins
from testbed.pipeline.scenario import scenario_from_dict
from testbed.reporting.figures import save_run_figures
from testbed.reporting.report import write_report
from testbed.scoring.run import run_scenario
from testbed.studies.runstore import load_run, save_run

PLUGIN = "tests.springmass_rig"


@pytest.fixture(scope="module", autouse=True)
def plugin():
    """The rig joins the registry for this module's tests only (other tests list every rig)."""
    snap = RIGS.snapshot()
    load_plugins([PLUGIN])
    yield
    RIGS.restore(snap)
    sys.modules.pop(PLUGIN, None)

RIG = {"m1": 1.0, "m2": 0.5, "k1": 1e5, "k2": 5e4, "beta": 9e-5}  # 35.6 Hz, 71.2 Hz; zeta 1 %, 2 %
FS = 8192.0

#: Bars of the clean-data run.  ``ls_sindy`` fits M^-1 K and M^-1 C of the free decay by
#: least squares; on noise-free data of a model whose structure the library holds exactly
#: (two coordinates, linear springs and dampers) what is left is the signal chain's
#: discretisation: it integrates accelerations with the trapezoid rule, whose gain is
#: ``(w dt / 2) / tan(w dt / 2) ~ 1 - (w dt)^2 / 12`` (2.5e-4 at the upper mode, 71 Hz at
#: 8192 Hz), and the identified frequencies inherit a bias of that order: measured 3.6e-4
#: (3.9e-3 with twice the stiffness at 4096 Hz, 4x the (w dt)^2).  The RK4 simulation
#: (w dt <= 0.007: ~1e-11) and the filters (linear, applied alike to every signal, so the
#: equation of motion holds for the filtered signals) add far less.  The frequency bias also
#: drifts the simulated response's phase over the decay, so TRAC measured 0.9975 rather than
#: 1 - 1e-7; MAC (shapes only) 1 - 3e-8.  Bars: frequency 1e-3 (3x the measured bias), TRAC
#: 0.99 (4x the measured 1 - TRAC), MAC 0.9999.  A wrong input map, sensor order or truth in
#: other coordinates misses them by decades.
FREQ_ERROR_MAX = 1e-3
TRAC_MIN = 0.99
MAC_MIN = 0.9999


def scenario(**identify):
    raw = {"scenario": {"name": "springmass_impulse", "rig": "springmass",
                        "description": "two masses, impulse on mass 2"},
           "rig": dict(RIG),
           "simulation": {"duration": 1.0, "sample_rate": FS},
           "excitation": {"type": "impulse", "peak_force": 100.0, "pulse_duration": 1e-3,
                          "start": 0.01},
           "identify": {"method": "ls_sindy", **identify},
           "score": {"trac_min": TRAC_MIN, "mac_min": MAC_MIN, "freq_error_max": FREQ_ERROR_MAX}}
    return scenario_from_dict(raw, file="<springmass test>")


@pytest.fixture(scope="module")
def result():
    return run_scenario(scenario())


def test_the_rig_is_a_plugin_of_its_declared_kind():
    assert "springmass" in RIGS
    sc = scenario()
    assert sc.kind == "structural" == RIGS.get("springmass").kind


def test_engine_truth_matches_the_independent_derivation(result):
    """M, K, C from MuJoCo equal the chain's textbook matrices; frequencies and damping ratios
    are those of the first-order system's poles."""
    m1, m2, k1, k2, beta = (RIG[k] for k in ("m1", "m2", "k1", "k2", "beta"))
    tr = result.dataset.typed_truth
    assert isinstance(tr, StructuralTruth)
    K = np.array([[k1 + k2, -k2], [-k2, k2]])
    # the engine's matrices are assembled in floating point (inertias, Jacobians): 1e-12
    # relative is ~1e4 eps, far below any modelling error
    np.testing.assert_allclose(tr.M, np.diag([m1, m2]), rtol=0, atol=1e-12 * m1)
    np.testing.assert_allclose(tr.K, K, rtol=0, atol=1e-12 * k1)
    np.testing.assert_allclose(tr.C, beta * K, rtol=0, atol=1e-12 * beta * k1)
    A = np.block([[np.zeros((2, 2)), np.eye(2)],
                  [-np.linalg.solve(tr.M, tr.K), -np.linalg.solve(tr.M, tr.C)]])
    poles = np.linalg.eigvals(A)
    poles = poles[poles.imag > 0][np.argsort(np.abs(poles[poles.imag > 0]))]
    np.testing.assert_allclose(np.abs(poles) / (2 * np.pi), tr.frequencies_hz, rtol=1e-12)
    np.testing.assert_allclose(-poles.real / np.abs(poles), tr.damping_ratios, rtol=1e-9)
    np.testing.assert_allclose(tr.modes.T @ tr.M @ tr.modes, np.eye(2), atol=1e-12)


def test_the_measured_accelerations_are_the_engine_motion(result):
    """The accelerometers read the second derivative of the recorded displacements
    (central differences, relative error (omega / fs)^2 / 12 ~ 2.5e-4 at 71 Hz / 8192 Hz; 2e-3
    leaves room for the second mode's share and the record's edges)."""
    ds = result.dataset
    acc, x = ds.measured["acceleration"].data, ds.reference["displacement"].data
    fd = (x[:, 2:] - 2 * x[:, 1:-1] + x[:, :-2]) * ds.fs**2
    i0 = int(0.02 * ds.fs)  # after the pulse: the force's kink would dominate the differences
    err = np.abs(fd[:, i0:] - acc[:, i0 + 1:-1]).max() / np.abs(acc[:, i0:]).max()
    assert err < 2e-3, err


def test_end_to_end_run_is_near_exact_on_clean_data(result):
    v = result.scores.values
    assert not result.scores.failures, result.scores.failures
    assert v["freq_error"] < FREQ_ERROR_MAX, v
    assert v["trac"] > TRAC_MIN and v["mac"] > MAC_MIN, v
    # least squares in sensor coordinates recovers M^-1 K exactly up to the filters
    assert v["MinvK_error"] < 1e-2, v
    assert result.passed
    # the input map the chain built from the data: the force acts on mass 2 only
    np.testing.assert_array_equal(result.data.input_map, [[0.0], [1.0]])


def test_the_run_is_saved_and_reported(result, tmp_path):
    run_dir = save_run(result, tmp_path / "runs" / "springmass_impulse", figures=save_run_figures)
    saved = load_run(run_dir)
    meta = json.loads((run_dir / "run.json").read_text())
    assert meta["kind"] == "structural" and saved.kind == "structural"
    assert meta["verdict"] == "pass"
    np.testing.assert_array_equal(saved.truth["Kr"], result.dataset.truth["Kr"])
    html = write_report(run_dir, tmp_path / "report")
    text = html.read_text()
    assert "springmass" in text and "freq_error" in text


def test_truth_is_validated_on_save_and_load(result, tmp_path):
    ds = result.dataset  # generate(scenario()), made once by the module's run (11 s loaded)
    assert ds.kind == "structural"
    path = ds.save(tmp_path / "chain.h5")
    back = Dataset.load(path)
    np.testing.assert_array_equal(back.typed_truth.M, ds.typed_truth.M)
    # a truth key of the wrong shape is named when saving ...
    bad = Dataset(ds.fs, ds.measured, ds.reference, {**ds.truth, "Kr": np.eye(3)}, ds.truth_units,
                  ds.prior, dict(ds.attrs))
    with pytest.raises(TruthError, match="'Kr' has shape \\(3, 3\\)"):
        bad.save(tmp_path / "bad.h5")
    # ... and a file whose truth lost a required key is refused when loading
    lost = Dataset(ds.fs, ds.measured, ds.reference, {k: v for k, v in ds.truth.items() if k != "Mr"},
                   {k: v for k, v in ds.truth_units.items() if k != "Mr"}, ds.prior,
                   {k: v for k, v in ds.attrs.items() if k != "kind"})
    p2 = lost.save(tmp_path / "lost.h5")  # no kind recorded: not checked when written
    with h5py.File(p2, "r+") as f:
        f.attrs["kind"] = "structural"  # not part of the content hash: the file stays verified
    with pytest.raises(DatasetError, match="missing 'Mr'"):
        Dataset.load(p2)
