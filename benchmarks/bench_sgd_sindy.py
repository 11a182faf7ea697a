"""Benchmark of SGD-SINDy: gradient steps to a good model, and cost against least squares.

``run()`` returns rows ``{name, value, unit, target, ok, note}``; ``python
benchmarks/bench_sgd_sindy.py`` prints them.  The synthetic problem (a 3-DOF chain with a
coupled, consistent-type mass matrix and non-proportional damping, exact free-vibration data
after an impact at the tip, 12.8 kHz) is built here by :func:`chain_system` and
:func:`chain_measurement`; the tests of ``identify`` reuse them.  For real data call
:func:`steps_to_targets` with a Measurement and the true frequencies and mode shapes.

Counting: an SGD-SINDy epoch is a full pass over the fit window in mini-batches, so the
paper's budget (Table 1: 10,000 epochs at batch 128) is ``10000 * ceil(n_samples / 128)``
gradient steps; the stricter reading (one mini-batch per epoch = 10,000 steps) is reported too.
"""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from benchmarks._timing import interleaved, machine, spread, timed_once
from identify.ls_sindy import LeastSquaresSINDy
from identify.sgd_sindy import SGDSINDy
from testbed.core.measurement import Measurement
from testbed.scoring.metrics import frequency_error, mac_matrix, pair_modes, trac

FS = 12800.0


def chain_system(coupled: bool = True, damping: str = "nonproportional", k3: float = 0.0,
                 f1: float = 90.0) -> dict[str, np.ndarray]:
    """A 3-DOF chain (ground - 1 - 2 - 3, free tip) in SI units.

    Parameters
    ----------
    coupled : bool
        True: full mass matrix ``0.06 [[4,1,0],[1,4,1],[0,1,2]]`` kg (consistent-mass-like,
        trace 0.6 kg); False: lumped ``diag(0.25, 0.2, 0.15)`` kg.
    damping : {"proportional", "nonproportional"}
        ``C = 1e-5 K`` [s], plus a 3 N s/m dashpot from DOF 1 to ground if non-proportional
        (zeta about 1 % in mode 1).
    k3 : float
        Cubic spring from DOF 1 to ground [N/m^3] (``K3[0, 0]``).
    f1 : float
        First natural frequency [Hz] (K is scaled to it); the others follow (about 3.3 f1, 5.9 f1).

    Returns
    -------
    dict
        ``M``, ``C``, ``K``, ``K3`` (3 x 3) and ``B`` (3 x 1, force at the tip).
    """
    if coupled:
        M = 0.06 * np.array([[4.0, 1.0, 0.0], [1.0, 4.0, 1.0], [0.0, 1.0, 2.0]])
    else:
        M = np.diag([0.25, 0.2, 0.15])
    K = np.array([[2.0, -1.0, 0.0], [-1.0, 2.0, -1.0], [0.0, -1.0, 1.0]])
    lam1 = np.min(np.linalg.eigvals(np.linalg.solve(M, K)).real)
    K = K * (2.0 * np.pi * f1) ** 2 / lam1
    C = 1e-5 * K
    if damping == "nonproportional":
        C = C + np.diag([3.0, 0.0, 0.0])
    elif damping != "proportional":
        raise ValueError(f"damping must be 'proportional' or 'nonproportional', got {damping!r}")
    K3 = np.zeros((3, 3))
    K3[0, 0] = k3
    return {"M": M, "C": C, "K": K, "K3": K3, "B": np.array([[0.0], [0.0], [1.0]])}


def chain_measurement(sys: dict[str, np.ndarray], duration: float = 0.25, impulse: float = 0.02,
                      fs: float = FS) -> Measurement:
    """Exact free vibration after an ideal tip impulse, integrated independently (DOP853).

    Parameters
    ----------
    sys : dict
        From :func:`chain_system`.
    duration : float
        Record length [s].
    impulse : float
        Tip impulse [N s]: initial velocity ``M^-1 B impulse``, zero displacement.
    fs : float
        Sample rate [Hz].

    Returns
    -------
    Measurement
        ``x``, ``xd``, ``xdd`` exact to ~1e-11 (rtol of the integrator), ``free_start = 0``,
        ``input_map = B``, ``prior = {"reduced_mass_trace": trace(M), "total_mass": 1.0}``.
    """
    M, C, K, K3 = sys["M"], sys["C"], sys["K"], sys["K3"]
    n = M.shape[0]
    Minv = np.linalg.inv(M)

    def rhs(_t: float, z: np.ndarray) -> np.ndarray:
        x, v = z[:n], z[n:]
        return np.concatenate([v, -Minv @ (C @ v + K @ x + K3 @ x**3)])

    t = np.arange(round(duration * fs)) / fs
    z0 = np.concatenate([np.zeros(n), Minv @ sys["B"][:, 0] * impulse])
    sol = solve_ivp(rhs, (0.0, t[-1]), z0, t_eval=t, method="DOP853", rtol=1e-11, atol=1e-15)
    x, v = sol.y[:n], sol.y[n:]
    a = -Minv @ (C @ v + K @ x + K3 @ x**3)
    return Measurement(fs=fs, x=x, xd=v, xdd=a, channels=("s1", "s2", "s3"), input_map=sys["B"],
                       prior={"reduced_mass_trace": float(np.trace(M)), "total_mass": 1.0})


def true_modal(sys: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """True undamped frequencies [Hz] (ascending) and mode shapes (columns) of ``sys``."""
    from identify.structural import modal

    return modal(sys["M"], sys["K"])


def scores(model: SGDSINDy | LeastSquaresSINDy, data: Measurement, f_true: np.ndarray,
           phi_true: np.ndarray) -> dict[str, float]:
    """Smallest TRAC (simulated vs measured accelerations), smallest MAC, largest freq error."""
    traj = model.simulate(data.x[:, data.free_start], data.xd[:, data.free_start],
                          data.t[data.free_start:])
    tr = trac(data.xdd[:, data.free_start:], traj.xdd)
    mac = mac_matrix(phi_true, model.modes_)
    pair = pair_modes(mac)
    ferr = frequency_error(model.natural_frequencies_[pair], f_true)
    return {"trac": float(np.nanmin(np.nan_to_num(tr, nan=0.0))),
            "mac": float(np.min(mac[np.arange(len(pair)), pair])),
            "freq_error": float(np.max(np.nan_to_num(ferr, nan=np.inf)))}


def _meets(s: dict[str, float], trac_min: float, mac_min: float, ferr_max: float) -> bool:
    return s["trac"] >= trac_min and s["mac"] >= mac_min and s["freq_error"] <= ferr_max


def steps_to_targets(data: Measurement, f_true: np.ndarray, phi_true: np.ndarray, *, init: str = "zeros",
                     trac_min: float = 0.95, mac_min: float = 0.95, ferr_max: float = 0.01,
                     max_epochs: int = 10000, scorer=None, **params) -> tuple[int | None, dict[str, float]]:
    """Fewest gradient steps after which SGD-SINDy meets all three targets.

    A fit of E epochs is exactly the first E epochs of a longer fit (deterministic seed, the
    annealing acts per epoch), so the epoch count is found by doubling then bisection.

    Parameters
    ----------
    data : Measurement
    f_true : ndarray, shape (m,)
        True natural frequencies [Hz].
    phi_true : ndarray, shape (n, m)
        True mode shapes at the sensors (columns).
    init : str
        SGD-SINDy ``init``.
    trac_min, mac_min, ferr_max : float
        Targets (TRAC, MAC >= 0.95; frequency error <= 1 %).
    max_epochs : int
        Give up beyond this.
    **params
        Further SGD-SINDy hyperparameters.

    Returns
    -------
    steps : int or None
        Gradient steps (``n_steps_``) of the shortest fit meeting the targets; None if none did.
    scores : dict
        Its scores (or those of the ``max_epochs`` fit).
    """
    def fit(e: int) -> tuple[SGDSINDy, dict[str, float]]:
        model = SGDSINDy(epochs=e, init=init, **params).fit(data)
        if scorer is not None:
            return model, scorer(model)
        return model, scores(model, data, f_true, phi_true)

    lo, hi = 0, 1
    model, s = fit(0)
    if _meets(s, trac_min, mac_min, ferr_max):
        return 0, s
    while True:
        model, s = fit(hi)
        if _meets(s, trac_min, mac_min, ferr_max):
            break
        if hi >= max_epochs:
            return None, s
        lo, hi = hi, min(2 * hi, max_epochs)
    best = (model.n_steps_, s)
    while hi - lo > 1:
        mid = (lo + hi) // 2
        model, s_mid = fit(mid)
        if _meets(s_mid, trac_min, mac_min, ferr_max):
            hi, best = mid, (model.n_steps_, s_mid)
        else:
            lo = mid
    return best


def cantilever_case():
    """The stiff cantilever scenario's measurement and a scorer identical to its scored test."""
    from testbed.pipeline.cache import DatasetCache
    from testbed.pipeline.scenario import load_scenario
    from testbed.pipeline.signal_chain import measure
    from testbed.scoring.run import noise_free
    from testbed.scoring.scorers import score_structural

    sc = load_scenario("cantilever_stiff_impact")
    ds = DatasetCache().get(sc)
    data = measure(ds, sc.signal, "structural")
    clean = measure(noise_free(ds), sc.signal, "structural")

    def scorer(model: SGDSINDy) -> dict[str, float]:
        # the stiff scenario's targets are on the paper's modes 1-2 (scored by name since every
        # sensed mode is scored; mode 3 at 1.45 kHz is ~4 % off for every method, a signal-chain
        # limit, see the README's known gaps)
        v = score_structural(ds, data, clean, model).values
        return {"trac": v["trac"], "mac": min(v["mac_mode1"], v["mac_mode2"]),
                "freq_error": max(v["freq_error_mode1"], v["freq_error_mode2"])}

    return sc, data, scorer


#: Adam step for SGD from zero coefficients.  Table 1's 1.5e-4 is a step on the paper's raw
#: coefficients; here steps are relative to the data's own scale of each matrix, and from zero
#: the stiffness must travel ~(f3 / f1)^2 ~ 300 of those units (measured on the stiff scenario:
#: 1.5e-4 leaves mode 2 at 315 Hz after 100,000 steps; 3e-3 meets the targets; 1.5e-2 stalls
#: at TRAC 0.46).
ZERO_INIT_LR = 3e-3
#: The paper's full budget (1,000,000 mini-batch steps) must run in under this on one core.
FULL_BUDGET_S = 30.0


def run(default_epochs: int | None = None) -> list[dict]:
    """Gradient steps to the stiff-scenario scores, and wall time against least squares.

    On the stiff cantilever scenario (its data, signal chain and scoring: TRAC >= 0.95 at every
    sensor, MAC >= 0.95 and frequency error <= 1 % on modes 1-2).  The paper's budget is
    10,000 epochs at batch 128; an epoch here is one pass over the fit window, so the budget is
    10,000 x ceil(N / 128) gradient steps.  ``init="zeros"`` is SGD from nothing, at Table 1's
    step and at ``ZERO_INIT_LR``; ``init="lstsq"`` (the default) starts from the symmetric
    least-squares warm start.  The search (doubling, then bisection) finds a fit that meets the
    targets, not necessarily the earliest (SGD scores are not monotone in the steps), so where
    it finds one the note also gives the scores at 10 % of the budget.

    Returns
    -------
    list of dict
        Rows with keys ``name``, ``value``, ``unit``, ``target``, ``ok``, ``note``.
    """
    sc, data, scorer = cantilever_case()
    epochs = int(default_epochs or sc.identify.get("epochs", 100))
    n_samp = data.n_samples - data.free_start
    budget_pass = 10000 * int(np.ceil(n_samp / 128))
    rows = []
    tenth = budget_pass // int(np.ceil(n_samp / 128)) // 10  # epochs in 10 % of the budget
    for init, lr in (("zeros", 1.5e-4), ("zeros", ZERO_INIT_LR), ("lstsq", 1.5e-4)):
        steps, s = steps_to_targets(data, None, None, init=init, scorer=scorer, max_epochs=tenth,
                                    learning_rate=lr)
        val = float("nan") if steps is None else float(steps)
        frac = val / budget_pass
        note = ("not reached within 10 % of the budget (scores there): " if steps is None else
                f"{100 * frac:.2f} % of the paper's budget: ")
        note += f"TRAC {s['trac']:.4f}, MAC {s['mac']:.4f}, freq error {100 * s['freq_error']:.3f} %"
        if steps is not None and steps > 0:  # SGD scores move: say where they are at 10 %
            s10 = scorer(SGDSINDy(epochs=tenth, init=init, learning_rate=lr).fit(data))
            note += (f"; at 10 % of the budget TRAC {s10['trac']:.4f}, MAC {s10['mac']:.4f}, "
                     f"freq error {100 * s10['freq_error']:.3f} %")
        rows.append({"name": f"steps_to_targets_init_{init}_lr_{lr:g}", "value": val,
                     "unit": "gradient steps",
                     "target": f"<= 10 % of {budget_pass} (10000 epochs x ceil({n_samp}/128))",
                     "ok": bool(steps is not None and frac <= 0.10), "note": note})
    t = interleaved({"sgd": lambda: SGDSINDy(epochs=epochs).fit(data),
                     "lstsq": lambda: LeastSquaresSINDy().fit(data)}, 3)
    model = SGDSINDy(epochs=epochs).fit(data)
    s = scorer(model)
    t_sgd, t_ls = float(np.median(t["sgd"])), float(np.median(t["lstsq"]))
    us = 1e6 * t_sgd / max(model.n_steps_, 1)
    rows.append({"name": "wall_time_scenario_fit", "value": t_sgd, "unit": "s", "target": "report",
                 "ok": None,
                 "note": f"SGDSINDy(epochs={epochs}) = {model.n_steps_} steps, {spread(t['sgd'])} s "
                         f"(~{us:.1f} us/step with the fixed costs: warm start, spectral peaks); "
                         f"TRAC {s['trac']:.4f}, MAC {s['mac']:.4f}, freq error "
                         f"{100 * s['freq_error']:.3f} %"})
    rows.append({"name": "wall_time_lstsq_fit", "value": t_ls, "unit": "s", "target": "floor", "ok": None,
                 "note": f"LeastSquaresSINDy().fit on the same data, {spread(t['lstsq'])} s"})
    rows.append({"name": "wall_time_ratio_sgd_over_lstsq", "value": t_sgd / t_ls, "unit": "x",
                 "target": "report", "ok": None,
                 "note": "same data, same run, interleaved, one BLAS thread"})
    # the paper's full budget: 10,000 epochs of ceil(N / 128) mini-batches of 128
    spe = int(np.ceil(n_samp / 128))
    t_full, full = timed_once(lambda: SGDSINDy(epochs=10000).fit(data))
    sf = scorer(full)
    ok = (t_full < FULL_BUDGET_S and sf["trac"] >= 0.95 and sf["mac"] >= 0.95
          and sf["freq_error"] <= 0.01)
    rows.append({"name": "full_budget_1e6_steps", "value": t_full, "unit": "s",
                 "target": f"< {FULL_BUDGET_S:g} s with the scenario's targets met", "ok": bool(ok),
                 "note": f"SGDSINDy(epochs=10000) = {full.n_steps_} steps (10000 x {spe}), "
                         f"{1e6 * t_full / full.n_steps_:.1f} us/step on one core (was 140-290); "
                         f"TRAC {sf['trac']:.4f}, MAC {sf['mac']:.4f}, freq error "
                         f"{100 * sf['freq_error']:.3f} %; {machine()}"})
    return rows


if __name__ == "__main__":
    for r in run():
        print(f"{r['name']:34s} {r['value']:14.6g} {r['unit']:15s} ok={r['ok']!s:5s} target: {r['target']}")
        print(f"{'':34s} {r['note']}")
