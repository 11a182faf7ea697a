"""How well can a sensor-coordinate model place the soft base's cubic force? Per family member.

Not a test (no ``test_`` prefix): a script that prints one line per soft-base member (issue #15)
with four measurements, none of which an identifier sees:

- ``q0``: relative RMS difference between the SEREP truth's base rotation ``c . x`` (``c`` =
  ``cubic_map``, ``x`` the exact sensor displacements) and MuJoCo's own base joint angle, and
  the same for its cube (the truth's cubic force along the motion), after the record's
  impact and 200 samples;
- ``raw``: the least-squares diagonal cubic ``K3 x^3`` given the truth's reduced linear model
  (``Mr, Cr, Kr``) on the *oracle* data (the reduced truth itself, cubic included, simulated
  by :func:`models.cantilever.truth.simulate_reduced`), on its exact signals; its
  acceleration error against the truth's cubic (``K3_accel_error``'s measure);
- ``chain``: the same on the oracle data passed through the scenario's signal chain (what an
  identifier gets): the floor the chain alone sets, since the oracle obeys the reduced truth
  exactly;
- ``oracle <identifier>``: the identifier (default settings) fitted on the chain's oracle data
  and scored as usual: ``K3_force_error`` and ``K3_accel_error``.

    PYTHONPATH=$PWD .venv/bin/python tests/identify/soft_cubic_floor.py DIR [0,7,12,18]

``DIR`` holds the members written by ``testbed family write studies/families.toml -o DIR``;
datasets go through the ordinary cache.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np

from identify._sgd_matrix import nuisance_basis, project_out
from testbed.core.truth import StructuralTruth
from testbed.pipeline import plugins
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure
from testbed.scoring.run import run_scenario


def base_angle_error(scenario, truth: StructuralTruth, x: np.ndarray, start: int) -> tuple[float, float]:
    """Relative RMS error of SEREP's base rotation and of its cube against MuJoCo's base joint."""
    import mujoco
    from mujoco import rollout

    from models.cantilever.rig import CantileverRig
    from models.cantilever.simulate import half_sine

    b = CantileverRig(scenario).built
    exc, st = scenario.excitation, b.stepping
    force = half_sine(exc["peak_force"], exc["pulse_duration"], exc["start"])
    control = force((np.arange(x.shape[1] * st.substeps) + 0.5) * st.timestep)
    data = mujoco.MjData(b.model)
    mujoco.mj_forward(b.model, data)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    s0 = np.zeros(mujoco.mj_stateSize(b.model, spec))
    mujoco.mj_getState(b.model, data, s0, spec)
    states, _ = rollout.rollout(b.model, data, s0[None, :], control[None, :, None])
    q0 = states[0, ::st.substeps, 1][start:]  # state = [time, qpos...]; joint 0 is the base
    q0s = (truth.cubic_map @ x)[start:]
    return (float(np.linalg.norm(q0s - q0) / np.linalg.norm(q0)),
            float(np.linalg.norm(q0s**3 - q0**3) / np.linalg.norm(q0**3)))


def floor(truth: StructuralTruth, x: np.ndarray, xd: np.ndarray, xdd: np.ndarray,
          W: np.ndarray | None) -> float:
    """Acceleration error of the least-squares ``K3 x^3`` given the truth's linear model."""
    f = np.outer(truth.cubic_direction, float(truth.k3) * (truth.cubic_map @ x) ** 3)
    lin = truth.Mr @ xdd + truth.Cr @ xd + truth.Kr @ x
    linp, x3p = project_out(W, lin, x**3) if W is not None else (lin, x**3)
    K3 = np.linalg.lstsq(x3p.T, -linp.T, rcond=None)[0].T
    a_true = np.linalg.solve(truth.Mr, f)
    return float(np.linalg.norm(np.linalg.solve(truth.Mr, K3 @ x**3) - a_true) / np.linalg.norm(a_true))


def oracle_dataset(sc, ds, tr: StructuralTruth):
    """The dataset with its signals replaced by the reduced truth's own (cubic included;
    :func:`models.cantilever.truth.simulate_reduced`): a model of the identifier's form then
    exists exactly.  Used by this script and its rank-one companions."""
    from models.cantilever.simulate import half_sine
    from models.cantilever.truth import simulate_reduced

    exc = sc.excitation
    fo = half_sine(exc["peak_force"], exc["pulse_duration"], exc["start"])
    u, ud, udd = simulate_reduced(tr.Mr, tr.Cr, tr.Kr, tr.force_map, lambda t: float(fo(t)), ds.t,
                                  (exc["start"], exc["start"] + exc["pulse_duration"]),
                                  k3=float(tr.k3), cubic_direction=tr.cubic_direction,
                                  cubic_map=tr.cubic_map, rtol=1e-9)
    ref = {**ds.reference,
           "acceleration": dataclasses.replace(ds.reference["acceleration"], data=udd),
           "displacement": dataclasses.replace(ds.reference["displacement"], data=u),
           "velocity": dataclasses.replace(ds.reference["velocity"], data=ud)}
    return dataclasses.replace(ds, reference=ref, measured={
        **ds.measured, "acceleration": dataclasses.replace(ds.measured["acceleration"], data=udd)})


def member(path: Path, cache: DatasetCache) -> str:
    sc = load_scenario(path)
    ds = cache.get(sc)
    tr = ds.truth_as(StructuralTruth)
    start = int(ds.attrs["free_start"]) + 200
    e_q, e_q3 = base_angle_error(sc, tr, ds.reference["displacement"].data, start)
    oracle = oracle_dataset(sc, ds, tr)
    u, ud, udd = (oracle.reference[k].data for k in ("displacement", "velocity", "acceleration"))
    raw = floor(tr, u[:, start:], ud[:, start:], udd[:, start:], None)
    m = measure(oracle, sc.signal, sc.kind)
    i0 = m.free_start
    W = nuisance_basis(m, i0, m.n_samples)[0]
    chain = floor(tr, *(np.asarray(a, float)[:, i0:] for a in (m.x, m.xd, m.xdd)), W)
    line = (f"{sc.name}: q0 {e_q:.3f} q0^3 {e_q3:.3f} | floor raw {raw:.3f} chain {chain:.3f} | oracle")
    for name in ("sgd_sindy", "ls_sindy"):
        r = run_scenario(sc, dataset=oracle, model=plugins.make_identifier({"method": name}, sc.name))
        v = r.scores.values
        line += (f" {name} force {v.get('K3_force_error', np.nan):.3f}"
                 f" accel {v.get('K3_accel_error', np.nan):.3f}")
    return line


def main(argv: list[str]) -> None:
    files = sorted(Path(argv[1]).glob("*.toml"))
    if len(argv) > 2:
        files = [files[int(k)] for k in argv[2].split(",")]
    cache = DatasetCache()
    for f in files:
        print(member(f, cache), flush=True)


if __name__ == "__main__":
    main(sys.argv)
