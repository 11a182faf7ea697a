"""Tenth malformed-input round: the two findings left open by the ninth, and those of
``benchmarks/hostile10.py`` (docs/history.md, malformed-input audits), each refused in one line
by the layer that owns the check.
"""

from __future__ import annotations

import h5py
import numpy as np
import pytest

from testbed.core.dataset import Dataset, DatasetError, Signal
from testbed.pipeline.importers import MeasuredDataError, read_measured
from testbed.reporting.export import export_dataset

FS = 1000.0  # Hz; 400 samples of a 7 Hz sine: any rate and length the readers accept


def _saved(tmp_path) -> object:
    """A hand-made record (no kind: no truth to validate), saved with its content hash."""
    t = np.arange(400) / FS
    acc = np.vstack([np.sin(2 * np.pi * 7 * t) * (k + 1) for k in range(2)])
    ds = Dataset(FS, {"acceleration": Signal(acc, ("acc1", "acc2"), "m/s^2", np.array([0.1, 0.2])),
                      "force": Signal(np.exp(-t / 0.01)[None, :], ("force",), "N", np.array([0.2]))})
    return ds.save(tmp_path / "d.h5")


# ------------------------------------------------------------------ left open by round 9

def _add_root_group(f):
    f.create_group("notes").attrs["who"] = "me"


def _add_root_dataset(f):
    f["extra"] = np.arange(3.0)


def _add_measured_dataset(f):
    f["measured/extra"] = np.ones((1, 400))


def _add_signal_attr(f):
    f["measured/force"].attrs["gain"] = 2.0


def _add_group_under_measured(f):
    f["measured"].create_group("sub")


def _soft_link(f):
    f["measured/copy"] = h5py.SoftLink("/measured/force")


def _delete_prior(f):
    del f["prior"]


def _dataset_under_prior(f):
    f["prior/total_mass"] = 0.7


@pytest.mark.parametrize("edit, fragment", [
    # read without a word: outside the content hash
    (_add_root_group, "/notes: not part of a dataset file (its root holds the groups measured, "
                      "reference, truth, prior"),
    (_add_root_dataset, "/extra: not part of a dataset file"),
    (_add_signal_attr, "/measured/force: unknown attribute 'gain' (allowed: unit, channels"),
    (_soft_link, "/measured/copy: a SoftLink (to '/measured/force')"),
    (_dataset_under_prior, "/prior/total_mass: the prior is held in the group's attributes"),
    # "unreadable dataset file (KeyError: ... 'channels')"
    (_add_measured_dataset, "/measured/extra: no attribute 'unit' (a member of /measured carries "
                            "unit, channels)"),
    (_add_group_under_measured, "/measured/sub: a group; /measured holds datasets only"),
    (_delete_prior, "/prior: missing (a dataset file's root holds the groups"),
])
def test_a_dataset_file_with_members_outside_its_layout_is_refused_naming_them(tmp_path, edit, fragment):
    p = _saved(tmp_path)
    assert read_measured(p).signals  # the file as written is read
    with h5py.File(p, "a") as f:
        edit(f)
    for read in (Dataset.load, read_measured):
        with pytest.raises((DatasetError, MeasuredDataError)) as e:
            read(p)
        assert fragment in str(e.value) and "\n" not in str(e.value), str(e.value)


def _uff(tmp_path) -> bytes:
    (out,) = export_dataset(_saved(tmp_path), "uff", tmp_path / "d.uff")
    return out.read_bytes()


@pytest.mark.parametrize("where, fragment", [
    ("between", "line 7 ('junk 1 2 3') lies outside every UFF block"),
    ("first", "line 1 ('junk 1 2 3') lies outside every UFF block"),
    ("last", "('junk 1 2 3') lies outside every UFF block"),
])
def test_a_line_of_junk_outside_the_uff_blocks_is_refused_naming_it(tmp_path, where, fragment):
    # pyuff reads only what lies between a block's start and end '    -1' and skipped the rest
    data = _uff(tmp_path)
    assert data.startswith(b"    -1\n") and data.count(b"    -1\n    -1\n") >= 1
    i = {"between": data.find(b"    -1\n    -1\n") + 7, "first": 0, "last": len(data)}[where]
    p = tmp_path / "junk.uff"
    p.write_bytes(data[:i] + b"junk 1 2 3\n" + data[i:])
    if where == "last":  # the tail check ("does not end with a block end") would catch it first
        p.write_bytes(data[:i] + b"junk 1 2 3\n    -1\n")
        fragment = "unpaired UFF block delimiter"
    with pytest.raises(MeasuredDataError) as e:
        read_measured(p)
    assert fragment in str(e.value) and "\n" not in str(e.value), str(e.value)


def test_blank_lines_between_uff_blocks_are_read(tmp_path):
    data = _uff(tmp_path)
    i = data.find(b"    -1\n    -1\n") + 7
    p = tmp_path / "blank.uff"
    p.write_bytes(data[:i] + b"\n   \n" + data[i:])
    assert read_measured(p).signals.keys() == read_measured(tmp_path / "d.uff").signals.keys()


# ------------------------------------------------------------------ round 10: combinations

@pytest.mark.parametrize("method, params, key, fragment", [
    # each fitted the same model to the bit as without the key (benchmarks/hostile10.py combos)
    ("pysindy", {"optimizer": "stlsq", "n_models": 5}, "n_models", "read only with optimizer = 'ensemble'"),
    ("pysindy", {"optimizer": "stlsq", "seed": 3}, "seed",
     "here identify.optimizer = 'stlsq', identify.weak = False"),
    ("pysindy_sr3", {"threshold": 0.1}, "threshold", "read only with optimizer = 'stlsq' or 'ensemble'"),
    ("pysindy", {"optimizer": "ensemble", "regularizer": "L0"}, "regularizer", "optimizer = 'sr3'"),
    ("pysindy", {"n_windows": 50}, "n_windows", "read only with weak = true"),
    ("sgd_sindy", {"gradient": "full", "batch_size": 64}, "batch_size", "gradient = 'minibatch'"),
    ("sgd_sindy", {"gradient": "full", "random_state": 3}, "random_state", "gradient = 'minibatch'"),
    ("sgd_sindy", {"cubic": False, "l1_threshold": 0.5}, "l1_threshold", "the cubic library"),
    ("sgd_sindy", {"cubic": True, "l1": "none", "l1_debias": 0.1}, "l1_debias", "l1 = 'cubic'"),
    ("sgd_sindy", {"cubic": False, "cubic_form": "direction"}, "cubic_form", "the cubic library"),
    ("sgd_sindy", {"eigen": False, "freq_range": [5.0, 2000.0]}, "freq_range", "eigen = true"),
    ("sgd_sindy", {"anneal": False, "alpha_max": 0.5}, "alpha_max", "anneal = true"),
    ("sgd_sindy", {"decay_hold": False, "decay_backbone": False}, "decay_backbone", "decay_hold = true"),
    ("ls_sindy", {"cubic": False, "decay_backbone": False}, "decay_backbone", "the cubic library"),
    ("sgd_sindy_coefficients", {"mass_learning_rate": 0.1}, "mass_learning_rate",
     "mass_update = 'symmetry' or 'eq6'"),
    ("sindy_pi", {"selection": "holdout", "n_rollout": 5}, "n_rollout", "selection = 'rollout'"),
    ("sindy_pi", {"column_lowpass_hz": 0.0, "column_lowpass_order": 2}, "column_lowpass_order",
     "a column low-pass"),
    ("sindy_pi", {"formulation": "strong", "weak_degree": 2}, "weak_degree", "formulation = 'weak'"),
    ("sindy_pi", {"ensemble_seed": 4}, "ensemble_seed", "read only with ensemble > 0"),
    ("pysindy_pi", {"rollout_segments": 3}, "rollout_segments", "selection = 'rollout'"),
    ("pysindy_pi", {"n_rollout": 5}, "n_rollout", "selection = 'rollout'"),
    ("pysindy_pi", {"qr": True, "stride": 7}, "stride", "qr = false"),
    ("sindy_pi_dynamical", {"weak_windows": 50}, "weak_windows", "formulation = 'weak'"),
    ("sindy_pi_dynamical", {"library": ["1", "x", "dx", "x*dx"], "degree": 3}, "degree",
     "the default library"),
])
def test_a_hyperparameter_the_identifier_would_not_read_is_refused_naming_its_switch(method, params,
                                                                                   key, fragment):
    from testbed.core.errors import ScenarioError
    from testbed.pipeline.plugins import IDENTIFIERS

    with pytest.raises(ScenarioError) as e:
        IDENTIFIERS.get(method).validate_hyperparameters(params, file="s.toml")
    assert e.value.key == f"identify.{key}" and fragment in str(e.value), str(e.value)
    assert "so it would be ignored" in str(e.value) and "\n" not in str(e.value)


@pytest.mark.parametrize("method, params", [
    ("pysindy_ensemble", {"n_models": 5, "seed": 3}),   # read by the ensemble
    ("pysindy", {"weak": True, "seed": 3}),              # the weak form's random domain centres
    ("pysindy", {"optimizer": "stlsq", "n_models": 20}),  # at its default: a table written whole
    ("sgd_sindy", {"l1_threshold": 0.5}),                 # cubic by rule (None) may read it
    ("sgd_sindy", {"gradient": "full", "steps_per_epoch": 3}),  # read: steps of the full gradient
    ("sindy_pi_dynamical", {"formulation": "weak", "weak_windows": 50}),
    ("sindy_pi", {"n_rollout": 5, "weak_degree": 2}),     # selection and formulation by rule
    ("sindy_pi", {"ensemble": 3, "ensemble_seed": 4}),
    ("pysindy_pi", {"selection": "rollout", "n_rollout": 5}),
    ("pysindy_pi", {"stride": 7}),
])
def test_a_hyperparameter_the_identifier_reads_is_still_accepted(method, params):
    from testbed.pipeline.plugins import IDENTIFIERS

    full = IDENTIFIERS.get(method).validate_hyperparameters(params)
    assert all(full[k] == v for k, v in params.items())


def test_an_identifier_built_in_python_with_an_unread_setting_is_refused_at_fit_time():
    from identify.pysindy_field import PySINDyField
    from testbed.core.errors import HyperparameterError

    with pytest.raises(HyperparameterError, match=r"pysindy\.n_models"):
        PySINDyField(optimizer="sr3", n_models=5).check_params()


# ------------------------------------------------------------------ round 10: Dask

def _server(reply: bytes):
    import socket
    import threading

    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(4)

    def serve():  # every connection answered at once, until the socket is closed
        while True:
            try:
                conn, _ = srv.accept()
            except OSError:
                return
            with conn:
                conn.sendall(reply)

    threading.Thread(target=serve, daemon=True).start()
    return srv, f"tcp://127.0.0.1:{srv.getsockname()[1]}"


@pytest.mark.parametrize("reply", [b"HTTP/1.0 200 OK\r\n\r\n", b""])
def test_a_dask_address_held_by_another_server_is_refused_before_the_sweep(reply):
    # an HTTP reply was read as a message length (MemoryError: 3 EiB, an internal error of
    # `sweep`); a server closing at once failed after the sweep's first line
    from testbed.cli import check_dask_address
    from testbed.core.errors import InputError

    srv, address = _server(reply)
    with srv, pytest.raises(InputError) as e:
        check_dask_address(address)
    assert "no Dask scheduler answers there" in str(e.value) and "\n" not in str(e.value)


def test_a_running_dask_scheduler_passes_the_check():
    import asyncio

    from distributed import Scheduler

    from testbed.cli import check_dask_address

    async def main():
        async with Scheduler(host="127.0.0.1", port=0, dashboard_address=None) as s:
            await asyncio.get_running_loop().run_in_executor(None, check_dask_address, s.address)

    asyncio.run(main())


def test_jobs_given_with_dask_is_refused_naming_both(tmp_path, capsys):
    # the Dask backend runs as many cells as the cluster has workers: --jobs was ignored
    from testbed.cli import main

    study = tmp_path / "s.toml"
    study.write_text('[study]\nname = "s"\nscenarios = ["michaelis_menten"]\nnoise = [0.0]\n'
                     'seeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')
    status = main(["sweep", str(study), "--jobs", "2", "--dask", "tcp://127.0.0.1:1",
                   "--results", str(tmp_path / "r.parquet")])
    err = [x for x in capsys.readouterr().err.splitlines() if x.startswith("error")]
    assert status == 2 and len(err) == 1 and "--jobs 2: not with --dask" in err[0], err


# ------------------------------------------------------------------ round 10: float edges

@pytest.mark.parametrize("rig, key", [
    # Vmax x0 overflowed: solve_ivp's "Required step size is less than spacing between
    # numbers" was a RuntimeError, an internal error
    ({"x0": 1.7976931348623157e308}, "rig.x0"),
    ({"Vmax": 1e308}, "rig.Vmax"),
])
def test_a_kinetics_rate_that_overflows_is_refused_naming_its_key(rig, key):
    import copy

    from testbed.core.errors import ScenarioError
    from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml, scenario_from_dict

    raw = copy.deepcopy(_read_toml(SCENARIO_DIR / "michaelis_menten.toml"))
    raw["rig"].update(rig)
    with pytest.raises(ScenarioError) as e:
        scenario_from_dict(raw, file="m.toml", stem="michaelis_menten")
    assert e.value.key == key and "is finite" in str(e.value) and "\n" not in str(e.value)


def test_a_study_table_with_an_unread_setting_names_its_own_keys(tmp_path):
    # the switch was named "identify.library", a key the study file does not have
    from testbed.core.errors import ScenarioError
    from testbed.studies.study import study_from_dict

    raw = {"study": {"name": "s", "scenarios": ["michaelis_menten"], "noise": [0.0], "seeds": [0],
                     "identifiers": ["sindy_pi_dynamical"]},
           "identifiers": {"sindy_pi_dynamical": {"library": ["1", "x", "dx", "x*dx"], "degree": 3}}}
    with pytest.raises(ScenarioError) as e:
        study_from_dict(raw, file="s.toml", base=tmp_path)
    assert e.value.key == "identifiers.sindy_pi_dynamical.degree"
    assert "here identifiers.sindy_pi_dynamical.library = " in str(e.value)
    assert "identify." not in str(e.value)
