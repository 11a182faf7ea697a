"""Benchmark: generating the default stiff cantilever vs a bare MuJoCo rollout of it.

``generate`` (rig build + truth + ``rig.simulate`` + noise + provenance) of 1 s of
``cantilever_stiff_impact`` against the strongest fair bare loop: one
``mujoco.rollout.rollout`` call on the same compiled model, same timestep and
number of steps, from rest, with zero control and no processing.  Both are
timed in the same process, interleaved; medians of several repeats.

A second figure: generating 1 s of a 60-segment beam with the automatic stepping
(implicitfast, 29 substeps) against the stepping the rig used before (RK4 at its
stability limit, 22,411 substeps), the latter timed on a short slice of record and
extrapolated (running it fully would take hours).

Run: ``OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_cantilever.py``.
"""

from __future__ import annotations

import statistics
import time

import mujoco
import mujoco.rollout
import numpy as np
from threadpoolctl import threadpool_limits

from models.cantilever import CantileverRig
from testbed.pipeline.generate import generate
from testbed.pipeline.scenario import load_scenario

TARGET_RATIO = 1.5
REPEATS = 5
FINE_SEGMENTS = 60
FINE_TARGET_S = 30.0  # the goal: 1 s of a 60-segment beam in under 30 s on one core
OLD_SLICE_SAMPLES = 4  # samples of record the old stepping is timed on (~90,000 RK4 steps)


def _interleaved_medians(fns, repeats: int = REPEATS) -> list[float]:
    """Median wall time of each function, run in turn (a, b, a, b, ...) so that a change
    in machine load during the run hits both alike."""
    times: list[list[float]] = [[] for _ in fns]
    for _ in range(repeats):
        for i, fn in enumerate(fns):
            t0 = time.perf_counter()
            fn()
            times[i].append(time.perf_counter() - t0)
    return [statistics.median(t) for t in times]


def accuracy() -> list[dict]:
    """Discretisation error vs Euler-Bernoulli per N, and SEREP vs MuJoCo response error."""
    from scipy.signal import butter, sosfiltfilt

    from models.cantilever import build_model, simulate_reduced
    from models.cantilever.simulate import half_sine

    rows = []
    for base in ("stiff", "soft"):
        sc = load_scenario(f"cantilever_{base}_impact")
        for n in (5, 10, 20, 40):
            b = build_model({**sc.rig_params, "n_segments": n}, sc.simulation, sc.excitation)
            t, _ = b.truth()
            err = 100 * (t["frequencies_hz"][:3] / t["eb_frequencies_hz"][:3] - 1)
            rows.append({"name": f"cantilever_{base}_N{n}_freq_error", "value": float(np.abs(err[:2]).max()),
                         "unit": "%", "target": 0.5 if n == 10 else None,
                         "ok": bool(n != 10 or np.abs(err[:2]).max() < 0.5),
                         "note": "f1, f2, f3 vs Euler-Bernoulli: " + ", ".join(f"{e:+.3f} %" for e in err)})
        for k3 in ((0.0, sc.rig_params["base_k3"]) if base == "soft" else (0.0,)):
            run_sc = sc.replace(rig_params={**sc.rig_params, "base_k3": k3},
                                simulation={**sc.simulation, "duration": 0.25})
            ds = CantileverRig(run_sc).simulate()
            t, exc = ds.truth, run_sc.excitation
            f = half_sine(exc["peak_force"], exc["pulse_duration"], exc["start"])
            _, _, udd = simulate_reduced(t["Mr"], t["Cr"], t["Kr"], t["force_map"],
                                         lambda x, f=f: float(f(x)),
                                         ds.t, (exc["start"], exc["start"] + exc["pulse_duration"]),
                                         k3=float(t["k3"]), cubic_direction=t["cubic_direction"],
                                         cubic_map=t["cubic_map"])
            fr = t["frequencies_hz"]
            sos = butter(8, np.sqrt(fr[2] * fr[3]), fs=ds.fs, output="sos")
            a = sosfiltfilt(sos, ds.reference["acceleration"].data, axis=1)
            r = sosfiltfilt(sos, udd, axis=1)
            i0 = ds.attrs["free_start"] + int(0.005 * ds.fs)
            err = np.sqrt(np.mean((a[:, i0:] - r[:, i0:]) ** 2, 1) / np.mean(a[:, i0:] ** 2, 1))
            # 1 %: the acceptance of the linear reduction; 5 %: the reduced cubic is approximate
            # (the cubic moment also drives the modes SEREP leaves out).
            target = 0.01 if k3 == 0 else 0.05
            rows.append({"name": f"cantilever_{base}_k3_{k3:g}_serep_rms_error", "value": float(err.max()),
                         "unit": "", "target": target, "ok": bool(err.max() < target),
                         "note": "relative RMS per sensor, low-passed between f3 and f4, pulse left out: "
                                 + ", ".join(f"{e:.2e}" for e in err)})
    return rows


def fine_beam() -> list[dict]:
    """1 s of a 60-segment beam: automatic stepping against the old RK4 stepping (extrapolated)."""
    from models.cantilever.simulate import choose_stepping, half_sine, rollout_sensors

    sc = load_scenario("cantilever_stiff_impact")
    sc = sc.replace(rig_params={**sc.rig_params, "n_segments": FINE_SEGMENTS})
    with threadpool_limits(1):
        t0, c0 = time.perf_counter(), time.process_time()
        ds = generate(sc)
        t_new, cpu_new = time.perf_counter() - t0, time.process_time() - c0
    b = CantileverRig(sc).built
    fs = sc.simulation["sample_rate"]
    old = choose_stepping(b.M, b.C, b.K, fs, "RK4")  # what "auto" meant before
    b.model.opt.integrator = mujoco.mjtIntegrator.mjINT_RK4
    b.model.opt.timestep = old.timestep
    exc = sc.excitation
    force = half_sine(exc["peak_force"], exc["pulse_duration"], exc["start"])
    # The slice starts at t = 0 (rest, no force yet): the cost per step does not depend on
    # the state, so the slice's time scales to the record by its number of steps.
    ctrl = force((np.arange(OLD_SLICE_SAMPLES * old.substeps) + 0.5) * old.timestep)
    with threadpool_limits(1):
        t0 = time.perf_counter()
        rollout_sensors(b.model, np.zeros(b.model.nq), ctrl, old.substeps)
        t_slice = time.perf_counter() - t0
    n = round(sc.simulation["duration"] * fs)
    t_old = t_slice * n / OLD_SLICE_SAMPLES
    st = ds.attrs
    return [
        {"name": "cantilever_N60_generate_1s", "value": t_new, "unit": "s", "target": FINE_TARGET_S,
         "ok": bool(t_new < FINE_TARGET_S),
         "note": f"generate() of 1 s, 60 segments, {st['integrator']} with {st['substeps']} substeps "
                 f"(automatic), one BLAS thread; CPU {cpu_new:.1f} s; the issue's absolute goal"},
        {"name": "cantilever_N60_old_over_auto", "value": t_old / t_new, "unit": "", "target": None,
         "ok": None,
         "note": f"old stepping RK4 with {old.substeps} substeps: {t_slice:.2f} s for "
                 f"{OLD_SLICE_SAMPLES} samples, extrapolated x{n // OLD_SLICE_SAMPLES} to "
                 f"{t_old:.0f} s for 1 s (rollout only: a lower bound on the old generate)"},
    ]


def run(repeats: int = REPEATS) -> list[dict]:
    """Time both and return one dict per figure (name, value, unit, target, ok, note)."""
    sc = load_scenario("cantilever_stiff_impact").with_noise(1.0)
    built = CantileverRig(sc).built
    model = built.model
    nstep = round(sc.simulation["duration"] * sc.simulation["sample_rate"]) * built.stepping.substeps
    data = mujoco.MjData(model)
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    state0 = np.zeros((1, mujoco.mj_stateSize(model, spec)))
    mujoco.mj_getState(model, data, state0[0], spec)
    control = np.zeros((1, nstep, model.nu))

    def bare() -> None:
        mujoco.rollout.rollout(model, data, state0, control)

    generate(sc)  # warm-up (imports, registry)
    t_gen, t_bare = _interleaved_medians([lambda: generate(sc), bare], repeats)
    ratio = t_gen / t_bare
    return [
        *accuracy(),
        *fine_beam(),
        {"name": "cantilever_generate_1s", "value": t_gen, "unit": "s", "target": None, "ok": True,
         "note": f"median of {repeats}; generate() of 1 s, {nstep} RK4 steps "
                 f"(dt = {built.stepping.timestep:.3g} s, {built.stepping.substeps} substeps), "
                 "1 % noise"},
        {"name": "cantilever_bare_rollout_1s", "value": t_bare, "unit": "s", "target": None,
         "ok": True, "note": f"median of {repeats}; one mujoco.rollout call, same model and nstep"},
        {"name": "cantilever_generate_over_bare", "value": ratio, "unit": "", "target": TARGET_RATIO,
         "ok": bool(ratio <= TARGET_RATIO),
         "note": f"{1e6 * t_bare / nstep:.2f} us per bare step"},
    ]


if __name__ == "__main__":
    for row in run():
        target = "" if row["target"] is None else f" (target <= {row['target']})"
        flag = "-" if row["ok"] is None else ("ok" if row["ok"] else "MISSED")
        print(f"{row['name']:32s} {row['value']:10.4g} {row['unit']:2s}{target} {flag}  {row['note']}")
