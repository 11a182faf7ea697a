"""How well a fitted structural model reproduces the record it was fitted on (no truth).

One routine, :func:`record_agreement`, shared by the identifiers that judge a fitted model by
its own record: ``sgd_sindy`` (the SGD's result against its held warm start,
:func:`identify.sgd_sindy.keep_sgd_rule`, its cubic trial, its input map) and ``ls_sindy`` (the
free window's fitted input map against none, its cubic trial: step 4b); and the two tests their
rules share: :func:`clearly_more` (the margin of a real difference) and :func:`extra_modes` (a
model mode no measured peak located among them).
"""

from __future__ import annotations

import numpy as np

from identify._structural_sim import RK4_STABILITY_BOUND, sample_rate_pole
from identify.structural import MODE_SEPARATION, StructuralIdentifier
from testbed.core.errors import TestbedError
from testbed.core.measurement import Measurement, Trajectory
from testbed.numerics.initial_state import MAX_ITERATIONS, fit_initial_state
from testbed.numerics.shapes import trac

#: The margin of a real difference between two models' record agreements: the one explains
#: clearly more where it leaves under 1 / this of the other's unexplained share (``1 - a``); a
#: smaller difference is within what the start fit and the noise move (session 22's review: the
#: stiff beam's input map decided by 1.5e-7 of TRAC).  One margin for every rule that compares
#: two fits by their records (``sgd_sindy``'s keep rule and cubic trial, both identifiers'
#: input-map drop, ``ls_sindy``'s step 4b).
AGREEMENT_RATIO = 2.0
#: The tie band of a plain "higher" between two record agreements (``ls_sindy``'s step 4d):
#: one must leave under ``1 / AGREEMENT_TIE`` of the other's unexplained share, one part in a
#: million.  Far above the agreement's rounding (a float64 sum over the record of an RK4
#: simulation: ~1e-12 relative, what a BLAS kernel can move), far below the differences a rule
#: reads (the gate's near ties 1e-4 of TRAC); a tie keeps the model as it stands, so no choice
#: is decided by the kernel's rounding.
AGREEMENT_TIE = 1.0 + 1e-6


def clearly_more(a_new: float, a_old: float, ratio: float = AGREEMENT_RATIO) -> bool:
    """Whether a record agreement ``a_new`` [-] explains clearly more than ``a_old``: it leaves
    under ``1 / ratio`` of the other's unexplained share (a NaN on either side: False)."""
    return bool(1.0 - a_old > ratio * (1.0 - a_new))


def extra_modes(modes_hz: np.ndarray, peaks_hz: np.ndarray,
                baseline_hz: np.ndarray | None = None) -> bool:
    """Whether a model puts more modes among the measured peaks (below the highest, and
    :data:`identify.structural.MODE_SEPARATION` above it) than peaks were located [Hz]: a mode
    no peak located among them is the fit's, not the record's (False without peaks; a NaN
    frequency, a non-positive stiffness, is no mode among them).  With ``baseline_hz`` (the
    model it would replace), more than the larger of the peaks and the baseline's own count
    there: a real mode no peak located (a heavily damped one between the peaks, one below the
    band) is the record's in both and refuses neither (review 27f)."""
    peaks = np.asarray(peaks_hz, dtype=float)
    if not peaks.size:
        return False
    top = peaks.max() * (1.0 + MODE_SEPARATION)
    allowed = peaks.size if baseline_hz is None else max(
        peaks.size, int(np.count_nonzero(np.asarray(baseline_hz, dtype=float) < top)))
    return bool(np.count_nonzero(np.asarray(modes_hz, dtype=float) < top) > allowed)


def without_input_map(model: StructuralIdentifier, data: Measurement, a_fit: float,
                      note_fit: str = "", ratio: float = AGREEMENT_RATIO
                      ) -> tuple[bool, float, str]:
    """Whether a fitted model's input map goes: the model with it explains ``a_fit`` of its
    record (:func:`record_agreement`), the same model with a zero map is judged here, and the map
    is dropped where the model without it leaves at most ``1 / ratio`` of what the model with it
    leaves unexplained, or where only it has an agreement (``ls_sindy``'s step 6 and
    ``sgd_sindy``'s kept model: one rule).

    Returns
    -------
    (bool, float, str)
        Whether the map was dropped (``model.input_map_`` left zero; else restored as it was),
        the agreement without it [-] (NaN: not simulated) and the figures: both agreements and
        unexplained shares, with their notes.
    """
    fitted = model.input_map_
    model.input_map_ = np.zeros_like(np.asarray(fitted, dtype=float))
    a_none, note_none = record_agreement(model, data)

    def show(a: float, note: str) -> str:
        return f"{a:.6g}" + (f" ({note})" if note else "")

    figures = (f"record agreement (TRAC) with the map {show(a_fit, note_fit)}, without "
               f"{show(a_none, note_none)}; unexplained shares {1.0 - a_fit:.3g} and "
               f"{1.0 - a_none:.3g}")
    drop = bool(np.isfinite(a_none) and (not np.isfinite(a_fit)
                                         or ratio * (1.0 - a_none) <= 1.0 - a_fit))
    if not drop:
        model.input_map_ = fitted
    return drop, float(a_none), figures


#: The openings of :func:`record_agreement`'s notes for a simulation from the record's own start
#: that failed: written there and read by :func:`identify.sgd_sindy.cubic_diverges`, one
#: spelling for both.
SIMULATION_FAILED = "simulation failed"
SIMULATION_NOT_FINITE = "simulation not finite"


def record_agreement(model: StructuralIdentifier, data: Measurement,
                     iterations: int = MAX_ITERATIONS,
                     sims: dict[bytes, Trajectory] | None = None) -> tuple[float, str]:
    """How well a fitted model's simulated response reproduces the measured record [-].

    The model is simulated from ``data.free_start`` to the record's end under the measured
    input, from the start whose accelerations best match the measured ones (least squares,
    :func:`testbed.numerics.initial_state.fit_initial_state`, the scorer's, from the measured
    state: the chain's integration constants are not the model's error), and compared with
    the measured accelerations ``data.xdd`` by TRAC per channel
    (:func:`testbed.numerics.shapes.trac`).  Only the measured record enters, never the truth.

    The cost is bounded by rule: a linear model is simulated exactly at any pole speed (its
    transition matrix, :func:`identify._structural_sim.simulate_structural`); a cubic model is
    integrated by RK4 whose sub-steps grow with its fastest pole, so one whose linear part has
    a pole beyond :data:`identify._structural_sim.RK4_STABILITY_BOUND` per sample interval
    (:func:`identify._structural_sim.sample_rate_pole`: a pole the record cannot resolve; a
    warm start of soft-base member 001 had one at -3.2e6 rad/s, 16 s per simulation) is not
    simulated: NaN, with the reason.

    Parameters
    ----------
    model : StructuralIdentifier
        Fitted (``M_``, ``C_``, ``K_``, ``K3_``, ``input_map_``).
    data : Measurement
        The record it was fitted on.
    iterations : int
        Gauss-Newton iterations of the start fit at most (default the scorer's).
    sims : dict, optional
        The model's simulations over this record by start (``(x0, xd0)``'s bytes), filled
        here; pass the same dict to a second call on the same model and record (more
        iterations): its first iteration is then read, not simulated again.

    Returns
    -------
    agreement : float
        The smallest channel's TRAC in [0, 1]; NaN when the model was not simulated, the
        simulation fails or is not finite (a diverging model).
    note : str
        Why the agreement is NaN ("" when it is not).
    """
    dt = 1.0 / float(data.fs)
    if model.K3_ is not None and np.any(model.K3_ != 0.0):
        rate = sample_rate_pole(model.M_, model.C_, model.K_, dt)
        if not rate <= RK4_STABILITY_BOUND:
            return float("nan"), (
                f"not simulated: a cubic model whose linear part has a pole of {rate / dt:.3g} "
                f"rad/s, |lambda| dt = {rate:.3g} beyond RK4's stability bound "
                f"{RK4_STABILITY_BOUND:g} (unresolved at the sample rate)")
    i0 = int(data.free_start)
    t = np.arange(data.n_samples - i0) * dt
    u = None if data.u is None or model.input_map_ is None else data.u[:, i0:]
    ref = np.asarray(data.xdd, dtype=float)[:, i0:]
    sims = {} if sims is None else sims

    def simulate(x0: np.ndarray, xd0: np.ndarray) -> Trajectory:
        """The model's response from ``(x0, xd0)``, each start simulated once (the fitted start
        is the start fit's last accepted iterate)."""
        key = np.concatenate([x0, xd0]).tobytes()
        if key not in sims:
            sims[key] = model.simulate(x0, xd0, t, u)
        return sims[key]

    try:
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            x0, xd0 = fit_initial_state(simulate, data.x[:, i0], data.xd[:, i0], ref,
                                        max_iterations=iterations)
            tr = trac(ref, simulate(x0, xd0).xdd)
    except (TestbedError, np.linalg.LinAlgError, ValueError, FloatingPointError) as e:
        return float("nan"), f"{SIMULATION_FAILED}: {e}"
    if not np.all(np.isfinite(tr)):
        return float("nan"), SIMULATION_NOT_FINITE
    return float(np.min(tr)), ""


#: The scales :func:`best_scale` tries first, ascending from 0 (the term left out) to 3 x its
#: first estimate: a grid wide enough for a harmonic-balance size off by its first order
#: (soft-base members 001 / 004 clean: best at 1.19 / 0.85 x), then refined between the best
#: grid point's neighbours.
SCALE_GRID = (0.0, 0.03, 0.1, 0.3, 0.6, 1.0, 1.5, 2.0, 3.0)


def best_scale(agreement, grid: tuple[float, ...] = SCALE_GRID, xatol: float = 0.01
               ) -> tuple[float, float]:
    """The scale ``s`` of a model's term that maximises its record agreement (output error).

    ``agreement(s)`` is evaluated on ``grid`` (a NaN, a failed simulation, counts as -1), then
    maximised by bounded Brent between the best grid point's neighbours (to ``xatol``); the
    best value seen wins, ties to the smaller scale (the smaller term).

    Parameters
    ----------
    agreement : callable
        ``agreement(s) -> float`` [-], e.g. :func:`record_agreement` of the model with the term
        scaled by ``s``.
    grid : tuple of float
        Scales tried first, ascending [-].
    xatol : float
        Brent's tolerance on ``s`` [-].

    Returns
    -------
    (float, float)
        The best scale and its agreement (NaN where every simulation failed).
    """
    from scipy.optimize import minimize_scalar

    seen: dict[float, float] = {}

    def loss(s: float) -> float:
        s = float(s)
        if s not in seen:
            a = float(agreement(s))
            seen[s] = a if np.isfinite(a) else -1.0
        return 1.0 - seen[s]

    values = [loss(s) for s in grid]
    k = int(np.argmin(values))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, len(grid) - 1)]
    if hi > lo:
        minimize_scalar(loss, bounds=(lo, hi), method="bounded", options={"xatol": xatol})
    best = max(seen.values())
    s = min(q for q, a in seen.items() if a == best)
    return s, (best if best > -1.0 else float("nan"))
