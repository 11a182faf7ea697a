"""SINDy-PI (Kaheman, Kutz & Brunton 2020) on one shared Gram matrix.

For every candidate left-hand-side term j a sparse regression ``Theta_j ~ Theta_{-j} xi`` by
sequentially thresholded least squares over a sweep of thresholds.  All candidates share one
Gram matrix ``G = Theta^T Theta``: first solutions from one inverse, thresholded refits by
downdating one Cholesky factor in a compiled loop (:func:`identify._implicit.stlsq_sweep`),
held-out errors from the
validation Gram matrix.  No per-candidate convex solver and no pass over the samples after the
Gram matrices are formed.

Model selection (``selection="holdout"``): the last ``val_fraction`` of the record (in time)
is held out, as the SINDy-PI authors do.  One implicit equation is picked per input (= per
actuated coordinate, the row of ``input_map`` the input acts on): the model whose input-k terms
dominate every other input's, with the fewest terms among those whose normalised held-out
residual is within tolerance of the best (:func:`identify._implicit.select_models`).
``selection="rollout"`` shortlists ``n_rollout`` such models per input and keeps the
combination whose simulations of the measured angles have the smallest RMSE: the trimmed
record cut into ``rollout_segments`` segments, each simulated from the measured state at its
start (:meth:`_ImplicitMechanical._rollout_error`); ties (within ``selection_rtol`` and
``ROLLOUT_ATOL``) go to fewer terms.  The noise rule takes it where a declared low-pass chain
derived the rates from noisy angles (see :func:`noise_knobs`), else the held-out rule.

Replay rule (:meth:`SINDyPI._replay_check`, ``replay_rule_``, ``replay_rmse_``): where the
noise rule chose the held-out selection (exact data; noisy angles with recorded rates), the
chosen equations must replay the trimmed record from its first measured state within
``EXACT_REPLAY_MAX`` + ``REPLAY_NOISE_FACTOR`` x the noise std, and must exist for every input;
else the record left the equations non-unique (a one-tone record such as the paper's sine
replay: held-out error 1e-15, yet the simulation loses the loop) and they are chosen again by
rollout over the whole trimmed record among the ``n_rollout`` best per input of the unpruned
library (the first fit wins ties).  Not with ``ensemble`` (the bags' aggregate is none of the
models compared).  Measured (within 0.0501 rad; 2026-11-26): the paper's sine replay on five
unseen five-bars (benchmarks/unseen/unseen_linkages.toml, fb_sine) at 0 / 1 / 3 / 5 % angle
noise 4 / 4 / 3 / 3 -> 5 / 5 / 5 / 4 of 5, none lost (the one left: no loop closure found at
5 %); 14 more sine-replay five-bars of those ranges (seed 23; its right 1 % fits set the noise
factor) clean 14 -> 14 (values unchanged), 1 % 11 -> 13 (two held-out fits had found no model
for an input; the others unchanged); unseen cart-poles (benchmarks/unseen/unseen_other.toml)
at 0 / 1 / 5 % 5 / 5 / 3 -> 5 / 5 / 5 (cartpoles__000 clean: right equations now, coef_error
1 -> 6e-7); the 30 family five-bars clean 30 -> 30 (values unchanged), 1 % with recorded
rates 30 -> 30 (one re-chosen: 0.0082 -> 0.0020 rad), with chain-derived rates 29 -> 29
(values unchanged).  Cost: one simulation of the record (angles only) per fit:
fivebar_multisine 0.21 -> 0.35 s of CPU, fivebar_sine_replay 0.18 -> 0.28 s.

Record rule (:meth:`_ImplicitMechanical._record_rule`, ``record_rule_``, ``record_replay``):
the rollout selection leaves out every shortlisted combination whose simulation of the whole
record from its first measured state diverges (loses the loop closure) or follows the measured
angles less than rest does (``REPLAY_REST_RATIO``; round 9's ``fb9_asym3`` and ``fb9_mixed`` at
1 %: F -> P), while another is left;
where none is left, or none even simulated its rollout segments (:class:`NoSimulationError`,
which ended the fit until 2026-11-27; round 7's fbsine__002 at 3 %, seed 4: F -> P, 0.0078
rad), the fit is redone over the unpruned library (:meth:`SINDyPI._unpruned_refit`); where no
combination of that one replays the record either, the first fit's ``WIDE_ROLLOUT`` best
models per input are searched for combinations that do (:meth:`SINDyPI._wide_record`, closed
chains; session 20: the paper's sine on family geometry fbs41__009 at 2 % and round 15's
fb15_cranks_0p8_1p5_3s at 2 % s63, "diverged" -> 0.0015 / 0.017 rad).
Measured (2026-11-26): the paper's sine input on the 30
family geometries at 1 % noise with chain-derived rates 27 -> 29 / 30 within 0.0501 rad; the
30 family five-bars with chain-derived rates (clean and 1 %) and with recorded rates (clean
and 1 %) unchanged, value for value.

Inertia rule (:meth:`_ImplicitMechanical._inertia_rule`, ``inertia_rule_``; SINDy-PI only, not
the pysindy peer): before the rollout selection simulates its shortlist, a combination whose
input gain ``d ddq_a / du`` changes the sign of its determinant on the record's states (the
measured actuated states, the passive ones by the loop closure) is left out: a mechanism's
reduced inertia cannot vanish where its chain assembles, and every simulation through such a
state blows up.  Where none is left the ``WIDE_ROLLOUT`` best per input are searched; where
none is left there either the fit fails with :data:`INERTIA_FAILURE` (after the unpruned
library's refit).  Open chains (more solved coordinates than inputs) and the held-out
selection are not reached (the replay rule simulates the held-out choice).

Underactuated open chains (a cart-pole: inputs on some coordinates, no loop; the loop closure
is used only where the data declare one, :func:`closed_chain`): one equation per coordinate. An
actuated coordinate's as above; a passive coordinate's has no input term, so its candidates
come from a second sweep over the input-free columns only (with the inputs present, its
left-hand side's regression has two exact solutions and the least-squares mix carries inputs),
picked by :func:`identify._implicit.select_passive_models` among the models holding its
acceleration (the held-out ranking's first pick tested per unit of the part holding that
acceleration: on a small swing an identity of nearly equal columns, ``ddth1 - cos(th2)*ddth1``,
wins per unit of its left-hand side; round 21's heavy long pole at 1-1.5 %: law_error 0.084-27.7
-> 0.015-0.018). The input's equation is ranked by its held-out residual per unit of its input's
part (:func:`identify._implicit.input_errors`), not per unit of its left-hand side: the
declared actuation makes the input's part the force the equation attributes to the actuator,
and that ratio does not change when an input-free equation (the passive one) is added, where
the left-hand-side ratio rewards the passive equation plus a small input admixture (round 16's
``cp16_3s`` clean: the pole's equation taken twice, law_error 0.855 -> 0.0073). Measured on 161
cart-pole cells (rounds 9-16 and the two shipped ones): 112 -> 118 passes (docs/known-gaps.md
"SINDy-PI: the cart-pole's input equation (session 18)"). Pruning is off there: the passive
equations ARE exact input-free dependencies among the columns. The model is simulated by
solving the n x n system for every acceleration at each state. Measured on
``scenarios/cartpole.toml``: exact (raw coefficients to 6e-15, rollout 3e-11 over 10 s); at 1 %
noise the rollout RMSE is 0.008-0.012 over five seeds with dense equations
(``cartpole_noise1.toml``).

Simulation: the equations are solved for the actuated accelerations; passive coordinates of a
closed chain come from the loop closure, taken (b) from ``data.prior`` (``l1``..``l4`` and
``L0`` [m] as the five-bar rig declares them, or ``link_lengths`` / ``base_length``; paper
convention ``l1 e1 + l2 e2 - l3 e3 - l4 e4 = (L0, 0)``) if it closes the measured loop (to the
noise floor on noisy angles), else (a) fitted to the measured angles
(:class:`identify._mechsim.LoopClosure`).  Sampled inputs are interpolated linearly or, with
``input_hold="zoh"``, as zero-order holds.

Noisy data: ``reconcile`` (default on) replaces the passive angles, rates and accelerations by
those the closure implies, so the kinematic identities hold exactly again; ``column_lowpass_hz``
filters every library column alike (the equations stay exact) to cut derivative noise.

Noise rule (:func:`noise_knobs`, every setting overridable): the angles' white-noise level
(as the signal chain declares it, ``Measurement.noise_std``, else robust 4th differences,
:func:`testbed.numerics.noise_std`) and band (99.9 % of the
noise-corrected power, or where the rest is no longer significant against the noise,
:func:`testbed.numerics.signal_band`) choose the column low-pass
(off on exact data, 1.5x the band otherwise), the edge trim, the ridge, the form and the LHS
candidates; rates a low-pass chain derived from the noisy angles (a declared ``passband``) get
the strong form with the column low-pass, the input terms as LHS, a ridge in proportion to
the noise variance (at least the chain's own error, ``CHAIN_REL_FLOOR``, clean angles alike)
and the rollout selection; data the differences call exact but whose exact
fit leaves a held-out error above ``EXACT_HOLDOUT_MAX`` (angles an undeclared chain smoothed)
get the weak form with that LHS and ridge.  The values used are fitted attributes
(``column_lowpass_hz_``, ``edge_trim_``, ``ridge_``, ``formulation_``, ``weak_window_s_``,
``lhs_``, ``selection_``) and ``noise_rule_`` says why.  Measured on the 30 five-bar family
members (studies/families.toml) at default settings: within the paper's 0.0501 rad 30/30 at
1 % angle noise (12/30 before the rule; median 7.4e-4 rad, worst 0.030) and 30/30 clean
(all <= 3e-6 rad, unchanged); the paper's sine input at 0.5-5 % noise <= 9e-6 rad.  With the
rates estimated by the low-pass chain (``derivatives = "lowpass"``, automatic cut-off and end
fits) at 1 %: 29/30 family members with the rollout selection (25/30 with the held-out one,
12/30 with the weak form and 0.1 s end fits), at 5 % 18/30 (14/30 held-out), clean 29/30
(13/30 when the noise estimate of ~0 sent them to the exact-data ridge), the paper's sine
input 6 of seeds 0-5 (<= 0.0060 rad; ``scenarios/fivebar_sine_replay_noise1``).  On an open
chain (a cart-pole) with such rates the strong fit is compared with a weak one by their
segmented rollouts and the smaller kept (:meth:`SINDyPI._open_chain_form`,
``formulation_rule_``).

Ensembling (``ensemble=N``): E-SINDy bagging of the selected models over moving-block
bootstraps of the training rows, with ``coef_std_`` and ``inclusion_probability_``; off by
default (measured worse on the family, see the class docs).

Weak form (``formulation="weak"``): the rows of the regression are integrals of the library
against smooth compactly supported test functions instead of samples, with the acceleration
terms integrated by parts (:mod:`identify._weak`): angles and rates suffice, so the noise of
estimated accelerations never enters.

Kinematic identities: on loop-closed data, products of trig factors with accelerations and
velocities obey exact linear relations that contain no input (loop constraint times trig
factors).  They make the implicit equations non-unique.  With ``prune_tol`` set, input-free
columns that are (to ``prune_tol``) combinations of earlier library columns on the data are
dropped (ordered pivoted Cholesky; library order is priority) and listed in ``pruned_terms_``.
"""

from __future__ import annotations

import dataclasses
import sys
from collections.abc import Callable, Sequence
from itertools import pairwise, product
from typing import Any, ClassVar, TextIO

import numpy as np

from identify import IDENTIFIERS
from identify._base import Identifier
from identify._implicit import (
    DEFAULT_THRESHOLDS,
    NoModelError,
    Sweep,
    bagged_models,
    block_grams,
    canonical_scale,
    grams,
    merge_sweeps,
    select_models,
    select_passive_models,
    split_index,
    stlsq_sweep,
)
from identify._mechsim import CLOSURE_RTOL, ImplicitModel, LoopClosure, band_whiteness
from identify._weak import check_window, held_midpoints, weak_matrix
from identify.library import Library, fivebar_library, generic_mechanical_library
from testbed.core.errors import IdentificationError
from testbed.core.measurement import Measurement, Trajectory
from testbed.core.schema import ErrorFn, Field, KeyUse
from testbed.numerics.derivatives import (
    CUTOFF_GAIN,
    CUTOFF_HARMONIC,
    harmonic_droop,
    noise_weight,
    relative_noise,
)
from testbed.numerics.filters import cutoff_problem, lowpass, mismatch_cutoff, zero_phase_droop
from testbed.numerics.gram import normalized_gram, ordered_independent
from testbed.numerics.noise import noise_std, signal_band

#: Rollout angle-RMSE differences below 1e-4 rad [rad] count as ties (then fewer terms win):
#: far below the 0.05 rad the paper reports and below what chaos-sensitive rollouts resolve.
#: On clean angles under a declared chain the band narrows with the chain's droop
#: (:func:`rollout_atol`).
ROLLOUT_ATOL = 1e-4


def chain_droop(band_hz: float, chain_cutoff_hz: float) -> float:
    """The droop [-] a declared low-pass chain applied at the motion's second harmonic: ``1 -``
    the zero-phase gain of an order-``CHAIN_ORDER`` Butterworth with the chain's cut-off
    ``chain_cutoff_hz`` [Hz] at ``CUTOFF_HARMONIC x band_hz`` [Hz]
    (:func:`testbed.numerics.filters.zero_phase_droop`).  The chain's automatic cut-off
    applies about the droop it asked (:func:`testbed.numerics.derivatives.harmonic_droop`,
    to 9e-5 relative: the chain asks it as a gain, ``1 - droop``; the band here is read on the
    smoothed angles, the chain's on the raw ones: alike on clean angles); a user's
    ``cutoff_hz`` applies its own.  The measurement declares the pass band,
    not the order (``CHAIN_ORDER``, as :func:`input_column_cutoff`)."""
    return float(zero_phase_droop(CUTOFF_HARMONIC * float(band_hz), float(chain_cutoff_hz),
                                  CHAIN_ORDER))


def rollout_atol(noise_rel: float, droop: float = 0.0) -> float:
    """The rollout selection's tie band [rad] where a declared low-pass chain derived the rates.

    The rollouts are compared with the chain's smoothed angles, whose own error scales with
    the chain's droop at the second harmonic: ``ROLLOUT_ATOL`` at the noisy rule's ``1 -
    CUTOFF_GAIN`` (1 %), narrowed in proportion to the droop below it.  The droop is the larger
    of the one the chain applied (``droop``, :func:`chain_droop`: a user's ``cutoff_hz`` below
    the automatic one droops more, review 28d M1) and the one the automatic chain asks at the
    angles' noise (:func:`testbed.numerics.derivatives.harmonic_droop` of ``noise_rel``), at
    most 1 %: on clean angles under the automatic chain (droop ``CLEAN_DROOP`` 1e-12) 1e-14
    rad, so the relative tie (``selection_rtol``, 10 %) alone decides there (1e-7 rad at
    session 27's droop 1e-5, the order of the simulator's step error, 6e-7 rad at 1 ms);
    exactly ``ROLLOUT_ATOL`` from ``NOISY_NOISE_REL`` up; continuous in the noise and in the
    cut-off.  With 1e-4 rad on clean records the band was as wide as the clean bar, and a
    sparser combination 10-100x worse in rollout won the tie (round 20's short-crank
    multisine: 2.7e-5 against 1.0e-6 rad on the record).

    Parameters
    ----------
    noise_rel : float
        Relative noise of the angles (:func:`testbed.numerics.derivatives.relative_noise`).
    droop : float
        The droop the chain applied at the second harmonic [-] (:func:`chain_droop`); 0: the
        automatic chain's.

    Returns
    -------
    float
        Tie band [rad].
    """
    if noise_weight(noise_rel) >= 1.0:
        return ROLLOUT_ATOL
    share = max(harmonic_droop(noise_rel), float(droop)) / (1.0 - CUTOFF_GAIN)
    return float(ROLLOUT_ATOL * min(share, 1.0))

#: The record rule's rest baseline [-]: a combination whose simulation of the whole record
#: leaves some coordinate farther (RMSE) from the measured angles than that coordinate's RMSE
#: about its first measured value does not replay the record (closed chains:
#: :meth:`_ImplicitMechanical._replays_record`).  1: the model that never moves.
REPLAY_REST_RATIO = 1.0

#: The inertia rule's wider search [-]: where no shortlisted combination keeps its reduced
#: inertia on the record, the ``WIDE_ROLLOUT`` best models per input are searched (the bound
#: of ``n_rollout``, 10: 100 pairs for two inputs), and at most the shortlist's number of
#: combinations that pass, nearest the top of the held-out ranking, are simulated.
WIDE_ROLLOUT = 10

#: The fit's error where no candidate keeps its reduced inertia on the record.
INERTIA_FAILURE = "every candidate model's reduced inertia vanishes on the record"


def by_rank(wide: list[list[tuple[int, int]]], seen: set | frozenset) -> list[tuple]:
    """The combinations of one model per input from ``wide`` (each input's models, best
    held-out rank first) not in ``seen``, nearest the top of the ranking first: by the largest,
    then the summed rank of their equations, then the ranks in input order (a total order: no
    tie left to the sort)."""
    rank = [{p: r for r, p in enumerate(w)} for w in wide]
    extra = [c for c in product(*wide) if c not in seen]
    extra.sort(key=lambda c: (max(rk[p] for rk, p in zip(rank, c, strict=True)),
                              sum(rk[p] for rk, p in zip(rank, c, strict=True)),
                              [rk[p] for rk, p in zip(rank, c, strict=True)]))
    return extra


@dataclasses.dataclass(frozen=True)
class _WideContext:
    """What the record rule's wider search (:meth:`SINDyPI._wide_record`) needs of the fit
    whose rollout selection it extends: the sweep, the kept library columns, each input's
    columns among them, the solved coordinates, the edge trim [samples], the combinations
    already judged and the shortlist's size."""

    sweep: Sweep
    kidx: np.ndarray
    loc_cols: list
    solved: np.ndarray
    i0: int
    seen: frozenset
    n_short: int


#: :func:`gain_crossing`'s zero band, in units of eps times the largest |determinant| on the
#: record: the determinant is a 2 x 2 product of accelerations the compiled kernel evaluates
#: with a few hundred flops of libm sin / cos (an ulp each), so its round-off is some tens of
#: eps of the largest term; 64 is above that, and a determinant within it of zero at some
#: state is singular there to working precision, whichever sign its last bits give it.
GAIN_ZERO_EPS = 64.0


def gain_crossing(det: np.ndarray) -> int:
    """The first state at which the input gain's determinant ``det`` (N,) is zero, not finite
    or of the other sign than at the first state; -1 where it keeps one strict sign.

    A mechanism's reduced inertia is positive definite wherever its chain assembles, so the
    determinant of ``d ddq_a / du`` (its inverse, up to the inputs' scales) keeps one sign
    along any recorded path; a model whose determinant crosses zero (or passes through a
    pole: the equations singular in the accelerations) there is no model of it.

    Zero is a band, not a bit: ``|det| <= GAIN_ZERO_EPS * eps * max |det|`` (over the finite
    states) counts as zero, so a determinant that touches zero at round-off's level is excluded
    whichever sign the last bit gives it (the compiled sin / cos differ by an ulp between CPUs)."""
    det = np.asarray(det, dtype=float)
    if det.size == 0:
        return -1
    finite = np.isfinite(det)
    scale = float(np.max(np.abs(det[finite]))) if finite.any() else 0.0
    zero = np.abs(np.where(finite, det, 0.0)) <= GAIN_ZERO_EPS * np.finfo(float).eps * scale
    s0 = 0.0 if zero[0] or not finite[0] else np.sign(det[0])
    bad = ~finite | zero | (np.sign(det) != s0)
    return int(np.argmax(bad)) if bad.any() else -1


NAMED_LIBRARIES = ("fivebar", "fivebar_full", "generic")

# Hyperparameter declarations shared by the SINDy-PI identifiers (sindy_pi, pysindy_pi,
# sindy_pi_linear); each bound carries its reason.
LIBRARY_FIELD = Field(str, "fivebar", choices=NAMED_LIBRARIES,
                      also=Field(list, item_type=str, min_items=1),
                      doc="candidate terms: a named library ('fivebar': the reduced five-bar "
                          "equations' terms) or a list of term names such as 'sin(th2-th3)*u1'")
LHS_FIELD = Field(list, None, item_type=str, min_items=1,
                  doc="candidate left-hand-side terms (library term names); default every kept "
                      "column")
THRESHOLDS_FIELD = Field(list, None, item_type=float, min=0.0, min_items=1,
                         doc="ascending thresholds on normalised coefficients; default 0 and 12 "
                             "values log-spaced over 1e-6..0.32")
# <= 1: a ridge of the order of the unit diagonal of the normalised Gram matrix swamps the data
RIDGE_FIELD = Field(float, 1e-14, min=0.0, max=1.0,
                    doc="ridge added to the unit-diagonal normalised Gram matrix")
# 1000 rounds: thresholding converges in a few; more only burns time
MAX_ITER_FIELD = Field(int, 20, min=1, max=1000, doc="thresholding rounds per threshold")
# (0, 1): both the training and the held-out part must hold samples
VAL_FRACTION_FIELD = Field(float, 0.2, min=0.0, max=1.0, min_inclusive=False, max_inclusive=False,
                           doc="held-out fraction at the end of the record")
SELECTION_FIELD = Field(str, "holdout", choices=("holdout", "rollout"),
                        doc="model selection by held-out residual, or by simulating shortlisted "
                            "models over segments of the trimmed record")
SELECTION_RTOL_FIELD = Field(float, 0.1, min=0.0,
                             doc="relative held-out error tolerance of the parsimony rule")
SELECTION_ATOL_FIELD = Field(float, 1e-12, min=0.0,
                             doc="absolute held-out error tolerance of the parsimony rule")
# 10 per input: the rollout tries n_rollout^n_inputs combinations (100 for two inputs)
N_ROLLOUT_FIELD = Field(int, 3, min=1, max=10, doc="models shortlisted per input for rollout selection")
# 1: one free simulation of the trimmed record; 100: segments of a few hundredths of a
# second on a 5 s record test one-step prediction, not a simulation.  Default 6, measured on
# the 30 family five-bars at 1 % noise with chain-derived rates (segments of 0.6-0.7 s):
# 1 segment 28/30 within 0.0501 rad, 2, 3 or 4: 28/30, 6: 29/30 (noise_knobs, item 4)
ROLLOUT_SEGMENTS_FIELD = Field(int, 6, min=1, max=100,
                               doc="segments of the trimmed record the rollout selection "
                                   "simulates, each from the measured state at its start")
# [0, 1): the residual variance of a unit-norm column is at most 1
PRUNE_TOL_FIELD = Field(float, 1e-9, min=0.0, max=1.0, max_inclusive=False,
                        doc="residual variance below which an input-free column counts as a "
                            "combination of earlier ones")
# (0, 1] s: the five-bar's motion is below 2 Hz; a step above 1 s resolves nothing
SIM_DT_FIELD = Field(float, None, unit="s", min=0.0, min_inclusive=False, max=1.0,
                     doc="RK4 step of the identified model's simulation; none = 1 ms, 0.5 ms, "
                         "then the sample interval and its halves, the first that the next "
                         "moves the simulation by at most 2.5e-6 of the motion (the rule, "
                         "sim_dt_rule_)")
RECONCILE_FIELD = Field(bool, True, doc="replace passive angles, rates and accelerations by those "
                                        "the loop closure implies")
COLUMN_LOWPASS_FIELD = Field(float, None, unit="Hz", min=0.0, min_inclusive=False,
                             doc="zero-phase low-pass cut-off applied to every library column "
                                 "(below the Nyquist frequency); default off")
COLUMN_LOWPASS_ORDER_FIELD = Field(int, 4, min=1, max=16,
                                   doc="Butterworth order of the column low-pass (one pass)")
EDGE_TRIM_FIELD = Field(float, 0.0, unit="s", min=0.0,
                        doc="seconds dropped at each end of the record (less than half of it)")
INPUT_HOLD_FIELD = Field(str, None, choices=("linear", "zoh"),
                         doc="sampled inputs in simulations: continuous (linear) or zero-order "
                             "hold; none = as the data declare it, else linear (input_hold_rule_)")

COMMON_HYPERPARAMETERS = {
    "library": LIBRARY_FIELD, "lhs": LHS_FIELD, "val_fraction": VAL_FRACTION_FIELD,
    "selection": SELECTION_FIELD, "selection_rtol": SELECTION_RTOL_FIELD,
    "selection_atol": SELECTION_ATOL_FIELD, "n_rollout": N_ROLLOUT_FIELD,
    "rollout_segments": ROLLOUT_SEGMENTS_FIELD,
    "prune_tol": PRUNE_TOL_FIELD, "sim_dt": SIM_DT_FIELD, "reconcile": RECONCILE_FIELD,
    "column_lowpass_hz": COLUMN_LOWPASS_FIELD, "column_lowpass_order": COLUMN_LOWPASS_ORDER_FIELD,
    "edge_trim": EDGE_TRIM_FIELD, "input_hold": INPUT_HOLD_FIELD,
}


class NoSimulationError(IdentificationError):
    """No shortlisted combination of the rollout selection simulated its segments."""


def ordered_fields(fields: dict[str, Field], order: tuple[str, ...]) -> dict[str, Field]:
    """``fields`` in the given key order (that of ``__init__``, for the guide)."""
    return {k: fields[k] for k in order}


def check_thresholds(params: dict[str, Any], error: ErrorFn) -> None:
    """``thresholds`` (if given) must be ascending and distinct."""
    thr = params.get("thresholds")
    if thr is not None and any(b <= a for a, b in pairwise(thr)):
        error("thresholds", thr, "expected strictly ascending values")


def library_for(spec: Any, n_channels: int, n_inputs: int) -> Library:
    """The library a ``library`` hyperparameter names, for data of this shape.

    Parameters
    ----------
    spec : str, Library or sequence of str
        ``"fivebar"``, ``"fivebar_full"``, ``"generic"``, a Library, or term names.
    n_channels, n_inputs : int
        Coordinates and inputs of the data.

    Raises
    ------
    ValueError
        For an unknown name, an unknown term or a term the data's shape cannot provide.
    """
    if isinstance(spec, Library):
        return spec
    if spec == "fivebar":
        return fivebar_library(n_inputs=n_inputs)
    if spec == "fivebar_full":
        return fivebar_library(kind="full", n_inputs=n_inputs)
    if spec == "generic":
        return generic_mechanical_library(n_channels, n_inputs)
    if isinstance(spec, Sequence) and not isinstance(spec, str):
        lib = Library(list(spec), n_channels, n_inputs)
        aliased = lib.structural_terms()
        if aliased:  # 'x1' fitted as th1, then "cannot evaluate factor 'x1'" in scoring
            raise ValueError(f"term {aliased[0]!r} uses the structural names x, v, a; a "
                             "mechanical library names th, dth, ddth, u")
        return lib
    raise ValueError(f"library must be 'fivebar', 'fivebar_full', 'generic', a Library or a list "
                     f"of term names, got {spec!r}")


def make_library(spec: Any, data: Measurement) -> Library:
    """``"fivebar"``, ``"fivebar_full"``, ``"generic"``, a Library, or a list of term names.

    Raises
    ------
    IdentificationError
        If the library does not fit the data (unknown terms, more coordinates or inputs than
        the data have).
    """
    n_in = 0 if data.u is None else data.u.shape[0]
    try:
        return library_for(spec, data.n_channels, n_in)
    except ValueError as e:
        raise IdentificationError(f"library {spec!r} does not fit the data ({data.n_channels} "
                                  f"channels, {n_in} inputs): {e}") from None


def check_terms(params: dict[str, Any], n_channels: int, n_inputs: int, error: ErrorFn) -> None:
    """``library`` and ``lhs`` against the data's shape: every term known, each input held by a
    term, every ``lhs`` term in the library (before data-dependent pruning)."""
    try:
        lib = library_for(params["library"], n_channels, n_inputs)
    except (ValueError, TypeError) as e:
        error("library", params["library"], f"a library for {n_channels} channels and {n_inputs} "
                                            f"inputs: {e}")
        return
    if lib.n_coords > n_channels or lib.n_inputs > n_inputs:  # a library written for other data
        error("library", params["library"],
              f"a library of the data's {n_channels} coordinates and {n_inputs} inputs (a list of "
              f"terms, or 'generic'); its terms use {lib.n_coords} coordinates and "
              f"{lib.n_inputs} inputs")
        return
    bare = [k + 1 for k in range(n_inputs) if lib.input_columns(k).size == 0]
    if bare:  # each input's own equation is selected (_implicit.select_models): none could hold it
        error("library", params["library"],
              f"a library with a term on each of the data's {n_inputs} inputs (every input gets "
              f"its own implicit equation); no term holds {', '.join(f'u{k}' for k in bare)}")
        return
    if params.get("lhs") is None:
        return
    try:
        wanted = Library(list(params["lhs"]), lib.n_coords, lib.n_inputs).names
    except (ValueError, TypeError) as e:
        error("lhs", params["lhs"], f"term names of the library: {e}")
        return
    missing = [w for w in wanted if w not in set(lib.names)]
    if missing:
        error("lhs", params["lhs"], f"terms of the library; not in it: {', '.join(missing)}")


def check_record(params: dict[str, Any], fs: float, n_samples: int, error: ErrorFn) -> None:
    """Column low-pass below Nyquist and an edge trim that leaves samples."""
    cut = params.get("column_lowpass_hz")
    problem = cutoff_problem(cut, fs) if cut else None  # None or 0: no low-pass
    if problem:
        error("column_lowpass_hz", cut, problem)
    record_s = n_samples / fs
    if params["edge_trim"] is not None and not 2 * params["edge_trim"] < record_s:
        error("edge_trim", params["edge_trim"], f"expected less than half the record "
                                               f"({record_s:g} s)")


def rollout_steps(params: dict[str, Any], record_s: float) -> tuple[float, str]:
    """RK4 steps of scoring's simulation over the record, plus the rollout selection's
    simulations of up to ``n_rollout^2`` model pairs (two inputs) over the record (its
    segments cover the trimmed record once) and, without an ensemble, the record rule's wider
    search's of up to ``WIDE_ROLLOUT^2 - n_rollout^2`` more (a worst case: it runs only where
    no shortlisted pair replays the record), and the step rule's simulations where ``sim_dt``
    is None; ``selection`` None (by the noise rule) counts as rollout."""
    dt = params["sim_dt"] or SIM_DT_START
    steps = record_s / dt
    if params["selection"] in ("rollout", None):
        pairs = 1 + params["n_rollout"] ** 2
        if not params.get("ensemble"):
            # the record rule's wider search (``_wide_record``): at most one simulation of the
            # record per pair of the first fit's WIDE_ROLLOUT best per input not yet simulated
            pairs += max(0, WIDE_ROLLOUT**2 - params["n_rollout"] ** 2)
        steps *= pairs
    if params["sim_dt"] is None:
        # the step rule (:func:`choose_sim_dt`), as it goes on a 10 kHz record that 1 ms does
        # not resolve: simulations at 1 and 0.5 ms, then at the 0.1 and 0.05 ms grid steps
        steps += record_s / SIM_DT_START * (1 + 2 + 10 + 20)
    return steps, "sim_dt"


#: First RK4 step [s] of the step rule (:func:`choose_sim_dt`): on the shipped five-bar records
#: (10 kHz, motions below 2 Hz) the exact equations simulate within 6e-7 rad of the measured
#: angles at 1 ms, 8e-8 rad at 0.25 ms.
SIM_DT_START = 1e-3
#: The step rule's tolerance, relative to each coordinate's measured range: a step is kept when
#: the next (finer) step moves no simulated coordinate by more than this share of its range.
#: On the five-bars' motions (0.6-0.8 rad) that is about 2e-6 rad: a fifth of the tightest clean
#: bar shipped (1e-5 rad, ``fivebar_multisine``), 1/50 of the family's (1e-4 rad) and 2e4x below
#: the noisy one (0.0501 rad), so the integration does not decide a verdict.  Measured: the
#: shipped multisine linkage moves by 1.5e-6 from 1 to 0.5 ms (1 ms kept, 6e-7 rad from its
#: angles), a 0.1 m, 0.05 kg one by 0.9 % (then 0.1 ms, 5e-9 rad).
SIM_DT_REL_TOL = 2.5e-6
#: At most this many refinements after the first two steps (down to 1/16 of the sample
#: interval).
SIM_DT_MAX_HALVINGS = 5


def sim_dt_candidates(fs: float) -> list[float]:
    """The steps [s] the step rule tries, in order: :data:`SIM_DT_START` and its half, then
    the sample interval ``1 / fs`` and its halves where it is shorter (else further halves).

    Steps on the inputs' sample grid: a held (or sampled-and-interpolated) input changes its
    slope at the samples, and a step that straddles such a change integrates it only to
    O(h^2), not RK4's O(h^4): measured on a 0.1 m, 0.05 kg five-bar (10 kHz record, exact
    equations) halving 1 ms -> 31 us moved its simulation by 0.9, 3.0, 1.3, 0.33, 0.08 % of
    the range (a factor 4 per halving), while one step per sample interval simulates it
    within 5e-9 rad (the shipped multisine linkage within 3e-13 rad).
    """
    interval = 1.0 / fs
    half = SIM_DT_START / 2
    first = interval if interval < half else half / 2
    return [SIM_DT_START, half] + [first / 2 ** k for k in range(SIM_DT_MAX_HALVINGS)]


def choose_sim_dt(simulate: Callable[[float], np.ndarray], x: np.ndarray,
                  fs: float, step_scale: float = 1.0) -> tuple[float, str]:
    """The step rule: the first of :func:`sim_dt_candidates` whose simulation the next
    candidate moves by at most :data:`SIM_DT_REL_TOL` of the motion (Richardson's test on the
    identified model itself).  A simulation that fails at two successive steps fails for the
    model, not the step: then :data:`SIM_DT_START` is kept (the scored simulation names the
    failure) without trying finer steps, whose failing simulations cost the most.

    Parameters
    ----------
    simulate : callable
        ``simulate(dt)`` -> the simulated coordinates (n_channels, n_samples) over the record
        at RK4 step ``dt`` [s]; raises :class:`IdentificationError` if the simulation fails.
    x : ndarray, shape (n_channels, n_samples)
        The measured coordinates (their ranges scale the tolerance).
    fs : float
        Sample rate of the record [Hz].
    step_scale : float
        Factor [-] on every candidate step, the fallback :data:`SIM_DT_START` included (a stiff
        law's start, :mod:`identify.sindy_pi_dynamical`; 1 for the mechanical rule).

    Returns
    -------
    (float, str)
        The step [s] and the rule's sentence (``sim_dt_rule_``).
    """
    scale = np.ptp(x, axis=1)
    scale = np.where(scale > 0, scale, 1.0)[:, None]
    steps = [dt * step_scale for dt in sim_dt_candidates(fs)]
    start = steps[0]
    prev = cur = None
    for k, dt in enumerate(steps):
        failed_before = k > 0 and cur is None
        try:
            cur = simulate(dt)
        except IdentificationError:
            cur = None
        if cur is None and failed_before:  # a failure that a finer step does not cure
            return start, (f"{start:g} s: the model's simulation fails at "
                                  f"{steps[k - 1]:.3g} s and {dt:.3g} s alike (the step does "
                                  "not decide it)")
        if cur is not None and prev is not None:
            moved = float(np.max(np.abs(cur - prev) / scale))
            if moved <= SIM_DT_REL_TOL:
                return steps[k - 1], (f"{steps[k - 1]:.4g} s: a step of {dt:.3g} s moves the "
                                      f"simulation by {moved:.2g} of the motion's range "
                                      f"(<= {SIM_DT_REL_TOL:g})")
        prev = cur
    if cur is None:
        return start, (f"{start:g} s: the model's simulation fails at the finest "
                       f"step, {steps[-1]:.3g} s (the step does not decide it)")
    return steps[-1], (f"{steps[-1]:.3g} s: not converged to {SIM_DT_REL_TOL:g} of the "
                       f"motion's range at any step from {start:g} s (the finest kept)")


def prune_dependent(G: np.ndarray, protected: np.ndarray, tol: float) -> np.ndarray:
    """Keep-mask: drop unprotected columns dependent on earlier unprotected ones.

    Ordered pivoted Cholesky over the unprotected columns only (the input-free ones: their
    dependencies are kinematic identities, whereas the equations sought contain inputs): a
    column is dropped if its residual variance (unit-norm column) after projection on the kept
    earlier ones is below ``tol``.
    """
    kept, _, _ = ordered_independent(normalized_gram(G)[0], np.flatnonzero(~protected), tol)
    keep = protected.copy()
    keep[kept] = True
    return keep


def closed_chain(data: Measurement, passive: np.ndarray) -> bool:
    """Whether the passive coordinates come from a loop closure (else: an open chain).

    A closure is used where the data declare one: ``data.prior`` holds link lengths
    (:meth:`identify._mechsim.LoopClosure.from_prior`), or the shape is the planar single loop
    (2 passive of 4 coordinates), whose closure :func:`find_closure` fits to the angles when
    the prior is silent.  Any other underactuated system (a cart-pole: 1 passive of 2) is an
    open chain, identified with one input-free equation per passive coordinate.
    """
    if passive.size == 0:
        return False
    if LoopClosure.from_prior(data.prior, passive) is not None:
        return True
    return passive.size == 2 and data.n_channels == 4


#: Where the record determines no closure, a declared prior is kept if its closure error is
#: white noise of the angles' declared band: its whiteness
#: (:meth:`identify._mechsim.LoopClosure.whiteness`) at most WHITE_CLOSURE_MARGIN times that
#: of white noise low-passed to the band (:func:`identify._mechsim.band_whiteness`, see
#: :func:`white_closure_max`).  sqrt(2): the prior is kept while its systematic closure error
#: (which the sample-to-sample differences cancel) is at most the noise's own RMS, i.e. while
#: the record cannot tell it from the noise.  Measured on rounds 14-16's five-bars with the
#: angles raw (docs/known-gaps.md "SINDy-PI: the closure's whiteness bar (session 18)"): the
#: true prior 1.077-1.08 against 1.070 x sqrt(2) = 1.51 at 4.43 of 5 kHz; priors 1 % wrong
#: from 1.72 up.  It replaces a fixed 2, which kept priors the record refutes (1.72) and would
#: refuse the true one behind a 2 kHz chain (2.10).
WHITE_CLOSURE_MARGIN = float(np.sqrt(2.0))


def white_closure_max(data: Measurement) -> float:
    """The whiteness bar of :func:`find_closure` for the angles of ``data`` [-].

    ``WHITE_CLOSURE_MARGIN x band_whiteness(f)``, ``f`` the upper edge of ``data.passband``
    (the band the angles carry: the signal chain's low-pass, or the column low-pass the fit
    applied before the closure) over the Nyquist frequency; 1 without a declared band (the
    angles as sampled).
    """
    nyquist = data.fs / 2.0
    high = nyquist if data.passband is None else min(float(data.passband[1]), nyquist)
    return WHITE_CLOSURE_MARGIN * band_whiteness(high / nyquist)


def find_closure(data: Measurement, passive: np.ndarray) -> LoopClosure | None:
    """Loop closure for the passive coordinates: prior (b) if it fits the data, else fitted (a).

    The declared prior is used if it closes the measured loop to ``CLOSURE_RTOL`` (largest
    error) or, on noisy angles, if its RMS closure error is within twice that of the
    least-squares closure fitted to the same angles (the noise floor: any closure, the true one
    included, leaves that much).  A wrong convention or a link length wrong by a few percent
    leaves an error of that order, far above the floor of smoothed angles (~1e-3).  Where the
    record determines no closure (:meth:`LoopClosure.from_data` finds no clear null direction:
    a short or small motion), that fitted floor is no floor, and the prior is kept if its own
    error is white noise of the angles' band (:func:`white_closure_max`); otherwise
    IdentificationError, as before.
    """
    if passive.size == 0:
        return None
    if passive.size != 2 or data.n_channels != 4:
        raise IdentificationError(f"{passive.size} passive coordinates of {data.n_channels}: only "
                                  "the planar single-loop closure (2 of 4) is supported")
    cl = LoopClosure.from_prior(data.prior, passive)
    if cl is not None:
        if cl.residual(data.x) <= CLOSURE_RTOL:
            return cl
        res = cl.residual(data.x, rms=True)
        floor = LoopClosure.from_data(data.x, passive, strict=False).residual(data.x, rms=True)
        if res <= 2.0 * floor:
            cl.source += f"; RMS closure error {res:.3g} of a link, noise floor {floor:.3g}"
            return cl
        note = (f"; the prior link lengths leave an RMS closure error of {res:.3g} of a link "
                f"(noise floor {floor:.3g})")
    else:
        note = "; data.prior has no link lengths (l1..l4, L0)"
    try:
        fitted = LoopClosure.from_data(data.x, passive)
    except IdentificationError as exc:
        # The record determines no closure, so the fitted "floor" above is no noise floor (on a
        # small motion a near-closure of one or two links fits the angles below their noise).
        # A declared prior whose own error is white noise is the record's closure.
        if cl is not None and data.x.shape[1] >= 2:
            white, bar = cl.whiteness(data.x), white_closure_max(data)
            if white <= bar:
                cl.source += (f"{note}; the record determines no closure ({exc}), and the prior's "
                              f"error is white (RMS {white:.3g} x its sample-to-sample part, at most "
                              f"{bar:.3g} in the angles' band): the prior kept")
                return cl
            note += (f"; its error is not white (RMS {white:.3g} x its sample-to-sample part, "
                     f"above {bar:.3g} in the angles' band)")
        raise IdentificationError(f"{exc}{note}") from exc
    fitted.source += note
    return fitted


# --- The noise rule: SINDy-PI's filter, edge trim, ridge and form chosen from the data -------
#: Relative noise (estimated std / channel RMS about its mean) at or below which the data count
#: as exact: 1e-6 is 1e4x the estimator's floor on clean angles (round-off of a 1.8 rad angle
#: differenced 4 times: ~1e-10 of a 0.15 rad swing) and 1e4x below the 1 % noise asked of
#: SINDy-PI, so exact data keep the exact recipe (no filter, no trim, ridge 1e-14).
NOISE_FREE_REL = 1e-6
#: Share of the angles' (noise-floor-corrected) power whose band sets the column low-pass.
BAND_SHARE = 0.999
#: Column low-pass cut-off = CUTOFF_FACTOR x the angles' band: the columns are products of trig
#: factors of the angles with rates, accelerations and inputs, so their band is wider than the
#: angles'.  Measured on the 30 five-bar family members at 1 % noise (cut-offs 1.2-3.3 Hz):
#: factor 1.0 / 1.2 / 1.5 / 2.0 passed 19 / 29 / 30 / 29 of 30 within 0.0501 rad; 1.5 is the
#: middle of that plateau (no filter: 12 / 30; too low a cut-off starves the regression of
#: excitation, too high keeps noise products that pick wrong dense equations).
CUTOFF_FACTOR = 1.5
#: Edge trim = EDGE_PERIODS periods of the cut-off (the zero-phase filter's end transients last
#: about one period of its cut-off at order 4), at most a tenth of the record at each end.
EDGE_PERIODS = 1.0
EDGE_MAX_SHARE = 0.1
#: The cap where a declared low-pass chain derived the rates (strong form): a quarter of the
#: record at each end, so the column filter's end transients (about one period of its
#: cut-off) are trimmed on slow motion too.  The paper's sine replay at 1 % (10 s, 0.45 Hz
#: column filter: 2.2 s wanted): capped at 1 s, seed 3 diverged and seed 5 drifted to
#: 0.019 rad; trimmed 2.2 s, 0.0065 and 0.0014 rad.  The recorded-rate branch keeps
#: EDGE_MAX_SHARE (its family figures were measured with it).
EDGE_MAX_SHARE_DERIVED = 0.25
#: The excitation cap of that trim (:func:`excitation_trim`): the trimmed span keeps at least
#: this share of the inputs' power about their mean.  The inertia is identified from the
#: accelerations the inputs drive; a one-tone record shorter than half the tone's period (the
#: paper's sine, 1 rad/s, on 3 s) holds its largest accelerations at its ends, where the
#: motion turns, and a trim of a quarter of the record at each end kept 18 % of that power
#: (0.75 s of 3 s; "no assembly" at 1.5 %, seeds 111-112).  Half: the trimmed span holds most
#: of the excitation; not binding on the 10 s sine (2.85 s allowed, 2.2 s used) nor on a
#: multisine (its power spread evenly: half is kept by any trim of at most a quarter).
#: Measured (2026-11-28, session 21; docs/known-gaps.md "SINDy-PI: the edge trim of short
#: one-tone records"): it binds on 9 of the 506 SINDy-PI cells of the shipped five-bars and
#: cart-poles, the families, rounds 19-20 and the held-out sets (all 3 s / 5 s sines of rounds
#: 19-20): 7 -> 8 pass; on 23 of rounds 13-18's: 12 -> 14 (one lost); on the new check set
#: benchmarks/heldout/pi21_sine_short.toml 18 -> 17 (one lost; 3 s median 0.0041 -> 0.0018 rad).
EDGE_KEEP_EXCITATION = 0.5
#: Ridge, noisy data included: the 1e-14 round-off safeguard.  A ridge of the order of the
#: noise the filtered columns keep (noise_rel^2 cutoff / (fs / 2), ~4e-8 at 1 %) was measured
#: worse on the 30 five-bar members at 1 % noise (26/30 within 0.0501 rad against 30/30):
#: the equations need the weak directions of the ill-conditioned library that a ridge shrinks.
RIDGE_EXACT = 1e-14
#: Form: strong, with the column low-pass, wherever the rates are recorded or a declared
#: low-pass chain derived them from the angles (``Measurement.passband`` below the Nyquist
#: frequency); weak only where the angles were found smoothed by the held-out test (an
#: undeclared chain, whose ends' quality is unknown).  Declared chain, strong form against
#: weak form (0.8 s windows), trim capped at EDGE_MAX_SHARE, at 1 % with the chain's
#: automatic cut-off and end fits
#: (testbed/pipeline/signal_chain.py EDGE_FIT_PERIODS): 30 five-bar family members 24/30
#: against 15/30 within 0.0501 rad; the paper's sine replay (seeds 0-5) 5/6 against 0/6 (the
#: weak windows, capped at half the held-out span, filter at 1.9 Hz a motion of 0.3 Hz band;
#: the strong form's column filter sits at 0.45 Hz); fivebar_multisine_noise1 seeds 0-5 worst
#: 0.0079 against 0.0075 rad, _noise5 worst 0.027 against 0.024 rad; cartpole_noise1 seeds
#: 0-4 (its 0.1 s end fits) worst 0.014 against 2.79 rad (seed 1).  The weak form had been
#: chosen when the chain's 0.1 s end fits left rate errors of 4-100 % of the rate's std near
#: the ends, which its test functions and trim hid and the strong form's did not.  Earlier:
#: 30 five-bar family members at 5 % angle noise (recorded rates): strong form with the column
#: filter 28/30 within 0.0501 rad, weak form (0.4 s windows on the 5 s records: half the
#: held-out 0.8 s) 10/30.  fivebar_multisine_noise1 (4 Hz chain, 0.1 s end fits), input-term
#: LHS: strong form with the rule's 2.25 Hz
#: column filter diverged or drifted (nan / 0.69 / 0.22 rad, seeds 0-2; only a 3 Hz filter with
#: a 0.5 s trim passed, 2.5 and 3.5 Hz did not), weak form 0.0056 / 0.0127 / 0.0118 rad.
WEAK_PERIODS = 1.5
#: Held-out error (normalised squared residual, :mod:`identify._implicit`) above which data the
#: differences call exact are not: the exact-data fit is then redone with the noisy recipe.
#: Measured with the exact recipe: at most 2.4e-9 on the 30 clean family members, the sine
#: replay and the multisine (most below 1e-12); 2e-5..4e-4 on fivebar_multisine_noise1/5,
#: whose angles the signal chain low-passed at 4 Hz (white-noise std by differences 1e-13).
#: 1e-6 sits 400x above the first and 20x below the second.
EXACT_HOLDOUT_MAX = 1e-6
#: Weak-form ridge = RIDGE_PER_NOISE_VAR x noise_rel^2 (Tikhonov: a ridge in proportion to the
#: noise variance relative to the signal's, which the unit-diagonal Gram matrix of the noisy
#: columns carries, so that its directions below the noise are damped and those above are
#: not).  The factor was measured on fivebar_multisine_noise5 (5 %, weak form, input-term LHS;
#: worst of seeds 0-2): ridge 1e-14 0.36 rad, 3e-5 (factor 0.012) 0.024 rad, and the noise5
#: file's hand-found plateau 1e-5..1e-4 (factor 0.004-0.04); at 1 % it gives 1.2e-6.
RIDGE_PER_NOISE_VAR = 0.012
#: Noise level the ridge of rates a declared low-pass chain derived assumes at least: the
#: chain's own relative error on exact angles (pass-band droop, end fits), which no noise
#: estimate sees.  Measured against the recorded derivatives on family five-bars 000, 002,
#: 006, 011 (clean, automatic cut-off and end fits): accelerations 0.3-1.1 % of RMS inside
#: the record, 0.8-2.3 % with the ends; rates 0.04-0.2 %.  With the floor the clean family
#: gets the ridge 1 % noise gets (1.2e-6) instead of the exact-data 1e-14, whose fits lost
#: the input terms or diverged (13/30 within 0.0501 rad before).
CHAIN_REL_FLOOR = 0.01
#: Clean angles under a declared low-pass chain (relative noise below
#: ``testbed.numerics.derivatives.NOISY_NOISE_REL``): the chain then raised its cut-off to pass the second
#: harmonic with the clean droop (``CLEAN_DROOP``, 4.22 x the noisy rule's cut-off at order 8; 1.54 x before
#: session 28), and the columns are filtered where the column low-pass (order ``n``) takes this many decades
#: off the power ratio at the chain's cut-off: zero-phase gain ``1 / (1 + 10^D)`` there, so a column cut-off
#: ``f_chain / 10^(D / (2 n))`` (order 4: 0.750 x the chain's).  The products the columns form of the chain's
#: transition band (its gain 1/2 at its cut-off, each column distorted differently) are cut tenfold; the band
#: below, which every column holds alike, passes.  Session 26 (pi29) measured hand-set fractions of the
#: chain's cut-off 0.5 / 0.7 / 0.75 / 0.8 / 1.0 (x the 1.6 x raised chain): 1 / 4 / 4 / 3 / 1 of its five
#: clean records within 1e-4 rad; the clean ridge is ``RIDGE_EXACT`` (there 1e-14 / 1.2e-10 / 1.2e-8 / 1.2e-6:
#: 4 / 2 / 1 / 0 of 5).  Between clean and noisy both move geometrically with
#: ``testbed.numerics.derivatives.noise_weight``.
CLEAN_COLUMN_DECADES = 1.0


def chain_column_cutoff(chain_cutoff_hz: float, column_order: int) -> float:
    """Column low-pass cut-off [Hz] on clean angles under a declared chain: the column filter's
    zero-phase power ratio ``(f / fc)^(2 n)`` is ``10^CLEAN_COLUMN_DECADES`` at the chain's
    cut-off ``chain_cutoff_hz`` [Hz]; ``column_order`` = ``n`` (>= 1)."""
    return float(chain_cutoff_hz / 10.0 ** (CLEAN_COLUMN_DECADES / (2 * int(column_order))))


#: Butterworth order taken for a declared chain when its inputs' mismatch is read
#: (:func:`input_column_cutoff`): the mechanical chain's default ``filter_order``; the
#: measurement declares the chain's pass band, not its order.  A chain of lower order droops
#: more below its cut-off than this reads.
CHAIN_ORDER = 8
#: Largest share of the inputs' column-filtered power that may be the chain's mismatch
#: (:func:`testbed.numerics.filters.chain_mismatch_share`) on clean angles: 1e-10, the square
#: of 1e-5.  The mismatch ``f (1 - G_chain) u`` is an error in an input column of relative
#: amplitude up to the share's square root, and so biases that column's coefficient by up to
#: as much; a five-bar model must hold its coefficients to about 1e-5 relative for 1e-4 rad
#: (session 28, pi32: the true equations perturbed by 1e-5 simulate 7e-7 - 3.6e-5 rad off;
#: ``testbed.numerics.derivatives.CLEAN_DROOP``).  (Chosen in session 27 as the square of
#: that session's clean droop, also 1e-5; kept when the droop fell to 1e-12 in session 28: the
#: droop's square, 1e-24, lies far below the shares read on five-bar multisines, 3.5e-14 -
#: 3.4e-12, near the Blackman-Harris periodogram's leakage, and would hold most clean column
#: cut-offs at their ``1.5 x band`` floor, not measured; the droop's gate was measured with
#: 1e-10.)
INPUT_MISMATCH_SHARE = 1e-10


def input_column_cutoff(inputs: np.ndarray | None, fs: float, chain_cutoff_hz: float,
                        column_order: int, low_hz: float, high_hz: float) -> float:
    """The clean column cut-off [Hz] held down to what the measured inputs allow.

    The chain derives the rates and accelerations from the angles, but the inputs enter the
    columns as measured: a column ``f(theta) u`` is paired with accelerations the chain
    low-passed, and differs from them by ``f (1 - G_chain) u``.  An input whose spectrum
    falls off within the band (a multisine, a chirp, a sine replay) has nothing there; a step,
    square wave or impact carries a ``1/f`` tail through the chain's transition band, which a
    column filter a decade down at the chain's cut-off still passes.  Rule: the highest column
    cut-off in ``[low_hz, high_hz]`` whose :func:`testbed.numerics.filters.chain_mismatch_share`
    of the inputs (chain order ``CHAIN_ORDER``) is at most ``INPUT_MISMATCH_SHARE``
    (:func:`testbed.numerics.filters.mismatch_cutoff`: continuous in the inputs, never below
    ``low_hz``, the noisy rule's columns).  Measured: round 16's 2 N steps held 0.5 s share
    1.9e-5 at the clean 5.13 Hz, 1e-10 near 2.4 Hz; the five-bars' multisines and chirps
    3.5e-14 - 3.4e-12 at theirs (kept).

    Parameters
    ----------
    inputs : ndarray, shape (n_inputs, n_samples), or None
        The measured inputs [their units]; None (no input): ``high_hz``.
    fs : float
        Sample rate [Hz].
    chain_cutoff_hz : float
        The chain's declared cut-off [Hz].
    column_order : int
        Order of the column low-pass.
    low_hz, high_hz : float
        The noisy rule's and the clean rule's column cut-offs [Hz].

    Returns
    -------
    float
        Column cut-off [Hz].
    """
    if inputs is None:
        return float(high_hz)
    return mismatch_cutoff(np.atleast_2d(np.asarray(inputs, dtype=float)), fs, chain_cutoff_hz,
                           CHAIN_ORDER, column_order, low_hz, high_hz, INPUT_MISMATCH_SHARE)


#: The rule text of :meth:`SINDyPI.fit`'s refit towards the noisy rule's settings (followed by
#: the weight that fitted).
NOISY_REFIT_TEXT = "the clean recipe's fit failed: fitted again at the noisy rule's weight"
#: The noisy rule's weights :meth:`SINDyPI.fit` tries, in order, where the clean recipe's fit
#: (weight below 1) failed: quarters of the way to the noisy rule, so that the refit keeps the
#: nearest recipe to the clean one that fits (ridge, column cut-off and trim geometric in the
#: weight, :func:`noise_knobs`).  Measured (session 28, pi32): round 26's ``fb26_ground_0p55``
#: clean, whose clean fit fails on a near tie of its inputs' shares (0.993), fitted at the noisy
#: rule's weight 1 scores 9.2e-4 rad, at 0.25 (the first it fits at) 4.7e-7 rad.
REFIT_WEIGHTS = (0.25, 0.5, 0.75, 1.0)


def _same_settings(a: dict[str, Any], b: dict[str, Any]) -> bool:
    """Whether two :func:`noise_knobs` settings are the same recipe (every value equal, floats
    exactly), so the same fit; values that do not compare as one truth value count as
    different (the fit is then done)."""
    try:
        return bool(a == b)
    except ValueError:
        return False


#: Replay check of exact-data fits (:meth:`SINDyPI._replay_check`): the held-out choice must
#: replay the whole record from its measured first state within 1e-4 rad [rad], else the
#: record left the equations non-unique and they are chosen again by rollout.  Measured
#: replays of exact-data fits that are right: the 30 clean family five-bars <= 3e-6 rad, the
#: paper's sine replay 5.8e-6, the sine replays of fb_sine (benchmarks/unseen) 1e-6..1.2e-5;
#: wrong: fb_sine__004 lost its loop at 1.3 s (held-out error 1e-15, every pair of the pruned
#: library's shortlist 0.34 rad or worse).  1e-4 is 8x the largest right one, 500x below
#: the paper's 0.0501 rad, and ROLLOUT_ATOL, the width within which rollouts tie.
EXACT_REPLAY_MAX = ROLLOUT_ATOL
#: Noisy angles (recorded rates, held-out selection): the bar grows by this many times the
#: angles' white-noise std, since the replay starts from a noisy measured state and is
#: compared with noisy angles.  Measured first-fit replays over the noise std at 1 % noise
#: on 11 sine replays whose held-out choice was right (fb_sine's ranges with family seed 23,
#: members 0, 1, 4-8, 10-13; truth errors <= 2.3e-3 rad): 1.05-2.98, and 14.1 (member 10,
#: whose noisy start state the motion amplifies); fb_sine__004 at 1 and 3 %: lost the loop;
#: family five-bar linkages__010 at 1 %: 38 (truth 0.0082 rad; re-chosen 0.0020).  With factor
#: 5 member 10 was re-chosen and passed worse (0.0023 -> 0.011 rad); 20 is above every right one.
REPLAY_NOISE_FACTOR = 20.0
#: The replay rule's damped refit (:meth:`SINDyPI._damped_refit`): where the unpruned library's
#: fit at the noise rule's ridge replays no better than the held-out choice (or fails), it is
#: fitted again with ridge UNPRUNED_RIDGE_PER_TOL x ``prune_tol`` (where that exceeds the rule's:
#: exact data, ridge RIDGE_EXACT; not where the user set ``ridge``).  The columns the pruning
#: drops have a residual variance (unit-norm column, on the record) below ``prune_tol``, so the
#: unit-diagonal Gram matrix of the unpruned library has directions of eigenvalue <= prune_tol
#: that the record does not determine; a ridge r shrinks a direction of eigenvalue l by
#: l / (l + r), so 10 x prune_tol damps each of them at least 11x and biases directions above
#: 1e-6 by under 1 %.  With the exact-data ridge 1e-14 they are free: round 18's clean sine
#: replays at recorded rates had every pair of the unpruned shortlist unsimulable
#: (fb18_f0p5_rec) or at 0.303 rad (fb18_30s_rec), and the held-out choice (0.0157 / 0.0024
#: rad) was kept.  Ridge of that fit, replay of fb18_f0p5_rec: 1e-12 / 1e-10 / 1e-9 first fit
#: kept (0.332 / 0.124 rad / none simulated), 1e-8 9.8e-6, 1e-7 1.5e-5, 1.2e-6 1.3e-5 rad;
#: fb18_30s_rec 1e-8 2.1e-6, 1.2e-6 6.6e-6.  Only a fallback: the same ridge in every unpruned
#: refit lost fb16_amp_0p2_rec (3.6e-5 rad -> no pair simulated, "no assembly" at 4.5 s), whose
#: true equations need directions below 1e-8 that the rule's ridge keeps.
UNPRUNED_RIDGE_PER_TOL = 10.0
#: The settings the noise rule chooses (each a SINDyPI hyperparameter; None = by rule).
#: ``lhs`` is given by the rule as "inputs" (the library's terms with an input factor) or None.
RULE_KNOBS = ("column_lowpass_hz", "edge_trim", "ridge", "formulation", "weak_window_s", "lhs",
              "selection")
#: The rule's ``lhs`` value for "the library's terms with an input factor".
LHS_INPUT_TERMS = "inputs"


def regression_inputs(data: Measurement, hold: str) -> np.ndarray | None:
    """The inputs paired with the samples of the regression [their units], shape (m, N).

    A held input (``hold == "zoh"``) acts as ``u[k]`` over ``[t_k, t_k+1)``.  Accelerations a
    signal chain derived from the sampled angles (a declared pass band, ``data.passband``)
    are differences of a zero-phase filtered record (``np.gradient`` twice: on a held input
    the weights ``(u[k-2] + 3 u[k-1] + 3 u[k] + u[k+1]) / 8``, centred half a sample back),
    so the input paired with them is ``(u[k-1] + u[k]) / 2`` (``u[0]`` at the first sample),
    exact to first order, the rest ``O((f / fs)^2)`` (a 3 / 7.3 Hz input at 1 kHz: relative
    residual 1.4e-2 with ``u[k]``, 2.4e-4 with this; review 23g): the held signal delayed by
    half a sample, the simulator's ``"zoh"`` convention
    (:meth:`identify._mechsim.ImplicitModel.simulate`).  Otherwise (a linear input, or
    recorded accelerations, which the engine evaluates under ``u[k]``) the samples as given.
    """
    u = data.u
    if u is None or hold != "zoh" or data.passband is None:
        return u
    return held_midpoints(u)


def excitation_trim(u: np.ndarray, fs: float, keep: float | None = None) -> float:
    """The longest edge trim [s] (the same at each end) whose span keeps at least ``keep`` of
    the inputs' power about their mean (summed over inputs); the half record where the inputs
    do not vary.

    Parameters
    ----------
    u : ndarray, shape (n_inputs, n_samples)
        Measured inputs [their units].
    fs : float
        Sample rate [Hz].
    keep : float, optional
        Share of the power the trimmed span keeps, in [0, 1]; default ``EDGE_KEEP_EXCITATION``.
    """
    keep = EDGE_KEEP_EXCITATION if keep is None else keep
    u = np.atleast_2d(np.asarray(u, dtype=float))
    p = np.sum((u - u.mean(axis=1, keepdims=True)) ** 2, axis=0)
    n = p.size
    c = np.concatenate([[0.0], np.cumsum(p)])
    if not c[-1] > 0:
        return 0.5 * n / fs
    i = np.arange((n + 1) // 2)
    ok = np.flatnonzero(c[n - i] - c[i] >= keep * c[-1])
    return float(ok.max()) / fs


def noise_knobs(x: np.ndarray, fs: float, val_fraction: float, user: dict[str, Any],
                smoothed: float | None = None, declared: np.ndarray | None = None,
                passband: tuple[float, float] | None = None, ruled: tuple[str, ...] = (),
                *, inputs: np.ndarray | None = None, column_order: int = 4,
                min_weight: float = 0.0
                ) -> tuple[dict[str, Any], str, dict[str, Any]]:
    """SINDy-PI's noise-dependent settings from the angles, and the rule that chose them.

    Rule (each setting the user gave is kept as given):

    1. ``noise_rel`` = the largest over channels of the white-noise std over the channel's RMS
       about its mean: the std the signal chain declared (``declared``, estimated on the raw
       angles before it smoothed them) or else that of the angles as given
       (:func:`testbed.numerics.noise.noise_std`); the band ``band_hz`` = the largest over
       channels of the frequency holding ``BAND_SHARE`` of the noise-corrected power of the
       angles as given, or above which the power left is no longer significant against the
       noise floor's fluctuation (:func:`testbed.numerics.noise.signal_band`).
    2. ``noise_rel <= NOISE_FREE_REL`` and no declared low-pass chain derived the rates
       (item 4 otherwise): exact data: strong form, no column filter, no edge
       trim, ridge ``RIDGE_EXACT``, every LHS candidate.  Unless ``smoothed`` is given: the
       fit with that recipe left a held-out error above ``EXACT_HOLDOUT_MAX`` (angles smoothed
       by a signal chain that did not declare their noise), then as 4.
    3. Noisy, rates not derived from the angles by a filter (no ``passband`` below Nyquist):
       strong form, column low-pass at ``CUTOFF_FACTOR * band_hz`` (below Nyquist), edge trim
       ``EDGE_PERIODS / cutoff`` (the user's cut-off if set; at most ``EDGE_MAX_SHARE`` of
       the record), ridge ``RIDGE_EXACT``, every LHS candidate.
    4. Noisy, rates and accelerations derived by a low-pass chain (``passband[1] < fs / 2``, or
       ``smoothed``): the strong form with the column low-pass and edge trim of item 3 for a declared chain
       (the trim at most ``EDGE_MAX_SHARE_DERIVED`` of the record, and at most the longest trim
       whose span keeps ``EDGE_KEEP_EXCITATION`` of the ``inputs``' power about their mean,
       :func:`excitation_trim`); for ``smoothed`` data without a
       declared pass band the weak form (no acceleration of the noisy angles enters), test functions
       of ``WEAK_PERIODS / band_hz`` seconds (at most half the held-out span), edge trim
       ``EDGE_PERIODS * window / WEAK_PERIODS``; either way ridge ``RIDGE_PER_NOISE_VAR *
       noise_rel^2`` (for a declared chain ``noise_rel`` at least ``CHAIN_REL_FLOOR``, the
       chain's own error on exact angles, so clean angles take this branch too), and LHS
       candidates the terms with an input factor (``"inputs"``): the inputs are
       measured exactly, so an equation is written for its exact input term, never for a term the
       noise dominates.  Clean angles under a declared chain move towards the clean recipe
       with the weight ``w`` = :func:`testbed.numerics.derivatives.noise_weight` of
       ``noise_rel`` (0 below 1e-5, 1 from 1e-3, log-linear between; the chain's cut-off moves
       with it): column cut-off ``(CUTOFF_FACTOR band)^w (clean)^(1 - w)``, ``clean`` a
       decade down at the chain's cut-off (:func:`chain_column_cutoff`) unless the measured
       inputs' spectrum reaches the chain's transition band (steps, square waves, impacts:
       :func:`input_column_cutoff` then holds it down, never below ``CUTOFF_FACTOR band``), ridge
       ``ridge^w RIDGE_EXACT^(1 - w)``, rollout ties within :func:`rollout_atol` (the droop the
       chain applied at ``2 band``, :func:`chain_droop`, or the automatic chain's at this noise
       if larger, x ``ROLLOUT_ATOL`` / 1 %); from 1e-3 up exactly the settings above.
       For a declared chain (``passband``) the models are chosen by rollout
       (``selection="rollout"``: ``n_rollout`` shortlisted per input by held-out error, the
       combination that simulates the measured angles best over ``rollout_segments`` segments
       of the trimmed record); elsewhere by held-out error (``"holdout"``).  The held-out
       equation error of the derived columns ranks alike models that simulate within 0.001
       rad and beyond 0.1 rad: measured on the 30 family five-bars at 1 % noise (the chain's
       automatic cut-off and end fits), holdout 25/30 within 0.0501 rad, rollout over the
       held-out window 26/30 (two members lost), over the trimmed record in one piece 28/30
       (one lost), in 2, 3 or 4 segments 28/30, in 6 segments 29/30 (none lost); at 5 % 14 ->
       18/30 (none lost).  One simulation of the whole record ranks by the luck of its start
       state's error, which the five-bar's motion amplifies; short segments judge each
       candidate's prediction, not that luck.
    5. ``formulation`` given by the user: that form, with the window, trim and ridge of its
       branch above (the weak form's window as in 4).

    Parameters
    ----------
    x : ndarray, shape (n_channels, n_samples)
        Measured angles [rad] (as the signal chain delivers them).
    fs : float
        Sample rate [Hz].
    val_fraction : float
        Held-out share of the record (bounds the weak window).
    user : dict
        The user's settings (``None`` = by rule) of ``column_lowpass_hz``, ``edge_trim``,
        ``ridge``, ``formulation``, ``weak_window_s``.
    smoothed : float, optional
        The largest held-out error of a first fit with the exact-data recipe, when it
        exceeded ``EXACT_HOLDOUT_MAX``.
    declared : ndarray, shape (n_channels,), optional
        White-noise std of each raw angle [rad] as the signal chain declared it
        (``Measurement.noise_std``).
    passband : (float, float), optional
        The chain's declared pass band [Hz] (``Measurement.passband``).
    ruled : tuple of str
        Keys of ``user`` set by a rule of the caller, not by the user (the open chain's form
        comparison, :meth:`SINDyPI._open_chain_form`): used as given, not reported as the
        user's.
    inputs : ndarray, shape (n_inputs, n_samples), optional
        The measured inputs [their units]: cap the declared chain's edge trim so that the
        trimmed span keeps ``EDGE_KEEP_EXCITATION`` of their power (:func:`excitation_trim`).
    column_order : int
        Order of the column low-pass (the clean chain's column cut-off, :func:`chain_column_cutoff`).
    min_weight : float
        The noisy rule's weight is at least this, in [0, 1] (the refits of :meth:`SINDyPI.fit`
        where the clean recipe's fit failed: ``REFIT_WEIGHTS``).

    Returns
    -------
    knobs : dict
        The settings of ``RULE_KNOBS`` used (``lhs``: None, ``"inputs"`` or the user's list),
        and ``rollout_atol``, the rollout selection's tie band [rad].
    rule : str
        One line: the estimates, the branch taken and which settings the user overrode.
    estimates : dict
        ``noise_std`` (per channel [rad]), ``noise_rel``, ``band_hz``, and ``noise_weight``,
        the noisy rule's weight used (1 unless a declared chain's clean recipe entered).
    """
    sig_x = noise_std(x)
    sig = sig_x if declared is None else np.asarray(declared, dtype=float)
    noise_rel = relative_noise(x, sig)
    # the band of the angles as given: their own floor (a chain's smoothing removed the rest)
    band = float(signal_band(x, fs, BAND_SHARE, sig_x).max(initial=0.0))
    record_s = x.shape[1] / fs
    est = {"noise_std": sig, "noise_rel": noise_rel, "band_hz": band, "noise_weight": 1.0}
    source = "differences" if declared is None else "declared by the signal chain"
    head = (f"noise {100 * noise_rel:.3g} % of RMS ({source}), band {band:.3g} Hz "
            f"({BAND_SHARE:g} of power)")
    span = record_s * (1 - 2 * EDGE_MAX_SHARE)
    window = min(WEAK_PERIODS / band, 0.5 * val_fraction * span) if band > 0 else 0.5
    if smoothed is not None:
        head += (f"; exact-data fit left held-out error {smoothed:.3g} > {EXACT_HOLDOUT_MAX:g}: "
                 "smoothed noise")
    filtered = passband is not None and float(passband[1]) < fs / 2
    if filtered:
        head += f"; chain low-pass {float(passband[1]):.3g} Hz"
    # rates a declared low-pass chain derived are estimates whatever the angles' noise: never
    # the exact-data recipe (its ridge 1e-14 lets the chain's own error pick the model)
    if (noise_rel <= NOISE_FREE_REL and smoothed is None and not filtered) or band <= 0.0:
        form = user.get("formulation") or "strong"
        rule = {"formulation": form, "column_lowpass_hz": 0.0, "edge_trim": 0.0,
                "ridge": RIDGE_EXACT, "weak_window_s": window if form == "weak" else None,
                "lhs": None, "selection": "holdout", "rollout_atol": ROLLOUT_ATOL}
        branch = f"exact data (<= {NOISE_FREE_REL:g}): {form} form, no column filter, no trim"
    else:
        derived = filtered or smoothed is not None
        capped = ""
        # a declared low-pass chain: the strong form (see the note above WEAK_PERIODS); an
        # undeclared smoother (ends of unknown quality): the weak form
        form = user.get("formulation") or ("weak" if smoothed is not None and not filtered
                                           else "strong")
        # the noisy rule's weight (1 unless a declared chain derived the rates of angles
        # whose noise is below NOISY_NOISE_REL): the clean recipe's share is 1 - w
        # (declared: an undeclared level is read off angles the chain smoothed, which always
        # look near-exact: review 27d, a 2 % record read as clean; the noisy rule is the safe one)
        w = noise_weight(noise_rel) if filtered and declared is not None else 1.0
        w = max(w, min(float(min_weight), 1.0))
        est["noise_weight"] = w
        if form == "strong":
            auto_cut = min(CUTOFF_FACTOR * band, 0.45 * fs)
            branch = (f"noisy: strong form, column low-pass {CUTOFF_FACTOR:g} x band = "
                      f"{CUTOFF_FACTOR * band:.3g} Hz")
            if w < 1.0:
                decade_cut = chain_column_cutoff(float(passband[1]), column_order)
                clean_cut = input_column_cutoff(inputs, fs, float(passband[1]), column_order,
                                                auto_cut, decade_cut)
                held = (f"; the inputs' chain mismatch holds it to {clean_cut:.3g} Hz"
                        if clean_cut < decade_cut else "")
                auto_cut = auto_cut**w * clean_cut ** (1.0 - w)
                branch = (f"noisy: strong form, column low-pass {auto_cut:.3g} Hz ({CUTOFF_FACTOR:g}"
                          f" x band)^{w:.3g} x ({CLEAN_COLUMN_DECADES:g} decade at the chain's "
                          f"cut-off, {decade_cut:.3g} Hz{held})^{1 - w:.3g}")
            cut = user.get("column_lowpass_hz") or auto_cut
        else:
            cut = WEAK_PERIODS / window
            branch = f"noisy: weak form, test functions {WEAK_PERIODS:g} / band = {window:.3g} s"
        if derived:
            state = "clean angles" if noise_rel <= NOISE_FREE_REL and smoothed is None else "noisy"
            branch = branch.replace("noisy:", f"{state}, rates derived by a low-pass:")
        cap = EDGE_MAX_SHARE_DERIVED if filtered and form == "strong" else EDGE_MAX_SHARE
        trim = min(EDGE_PERIODS / cut, cap * record_s)
        if filtered and form == "strong" and inputs is not None:
            keep_trim = excitation_trim(inputs, fs)
            if keep_trim < trim:
                trim = keep_trim
                capped = (f" (capped to keep {EDGE_KEEP_EXCITATION:g} of the inputs' power "
                          "about their mean)")
        level = max(noise_rel, CHAIN_REL_FLOOR) if filtered else noise_rel
        ridge = max(RIDGE_PER_NOISE_VAR * level**2, RIDGE_EXACT) if derived else RIDGE_EXACT
        if w < 1.0:  # clean angles under a declared chain: towards the exact-data ridge
            ridge = ridge**w * RIDGE_EXACT ** (1.0 - w)
        lhs = LHS_INPUT_TERMS if derived else None
        # a declared chain's derived rates: the held-out equation error ranks alike candidates
        # that simulate within 0.001 rad and beyond 0.1 rad (measured: see the docs, item 4)
        selection = "rollout" if filtered else "holdout"
        rule = {"formulation": form, "column_lowpass_hz": cut if form == "strong" else 0.0,
                "edge_trim": trim, "ridge": ridge,
                "weak_window_s": window if form == "weak" else None, "lhs": lhs,
                "selection": selection,
                "rollout_atol": (rollout_atol(noise_rel, chain_droop(band, float(passband[1])))
                                 if w < 1.0 else ROLLOUT_ATOL)}
        branch += f", edge trim {trim:.3g} s{capped}, ridge {ridge:.3g}"
        if filtered and noise_rel < CHAIN_REL_FLOOR:
            branch += f" (noise below the chain's own error floor {CHAIN_REL_FLOOR:g})"
        if w < 1.0:
            branch += f" (noisy rule's weight {w:.3g}: ridge {RIDGE_EXACT:g} on clean angles)"
        if lhs is not None:
            branch += ", LHS the input terms"
        if selection == "rollout":
            branch += ", models chosen by rollout on the measured angles"
            if rule["rollout_atol"] != ROLLOUT_ATOL:
                branch += f" (ties within {rule['rollout_atol']:.3g} rad)"
    knobs = {k: (user[k] if user.get(k) is not None else v) for k, v in rule.items()}
    given = [k for k in rule if user.get(k) is not None and k not in ruled]
    text = f"{head}; {branch}" + (f"; user setting: {', '.join(given)}" if given else "")
    return knobs, text, est


class _ImplicitMechanical(Identifier):
    """Fit pipeline shared by SINDy-PI and the pysindy wrapper; subclasses supply _sweep."""

    kind = "mechanical"
    prior_keys = LoopClosure.PRIOR_KEYS
    #: The inertia rule of the rollout selection (:meth:`_inertia_rule`): SINDy-PI's own; the
    #: pysindy peer keeps the selection it was measured with.
    _inertia_rule_on: ClassVar[bool] = False
    #: An open chain's passive equation tested per unit of its acceleration's part
    #: (:func:`identify._implicit.select_passive_models` with ``G_val``): SINDy-PI's own; the
    #: pysindy peer keeps the selection it was measured with (per unit of the left-hand side).
    _passive_acc_rule_on: ClassVar[bool] = False

    def _sweep(self, G_train: np.ndarray, G_val: np.ndarray, cand: np.ndarray,
               Theta_train: np.ndarray) -> Sweep:
        raise NotImplementedError

    def _choose_knobs(self, data: Measurement) -> dict[str, Any]:
        """Data-dependent settings of this fit (``column_lowpass_hz``, ``edge_trim``,
        ``formulation``, ``weak_window_s``): the hyperparameters as set.  SINDy-PI overrides
        this with its noise rule (:func:`noise_knobs`)."""
        return {"column_lowpass_hz": self.column_lowpass_hz, "edge_trim": self.edge_trim,
                "formulation": getattr(self, "formulation", "strong"),
                "weak_window_s": getattr(self, "weak_window_s", None), "lhs": self.lhs,
                "selection": self.selection}

    def _knob(self, name: str) -> Any:
        """A setting of this fit: the rule's (``_choose_knobs``) where it set one, else the
        hyperparameter."""
        knobs = getattr(self, "_knobs", None)
        return knobs[name] if knobs is not None and name in knobs else getattr(self, name)

    def _library_matrix(self, lib: Library, data: Measurement) -> tuple[np.ndarray, int]:
        """Library matrix of the (reconciled) data, column-filtered and trimmed; first sample.

        Every column obeys the same linear equations at every sample, so a linear
        time-invariant filter applied to all columns alike keeps them exact: the column
        low-pass removes the broadband noise of estimated derivatives (whose products with
        slow trig factors stay broadband) without biasing the equations.
        """
        x, xd, xdd = data.x, data.xd, data.xdd
        if self.reconcile and self.closure_ is not None:
            x, xd, xdd = self.closure_.reconcile(x, xd, xdd)
        Theta = lib.evaluate(x, xd, xdd, regression_inputs(data, self.input_hold_))
        cut = self._knob("column_lowpass_hz")
        if cut:
            Theta = lowpass(np.ascontiguousarray(Theta.T), data.fs, cut,
                            self.column_lowpass_order).T
        trim = self._knob("edge_trim")
        i0 = round(trim * data.fs)
        if i0:
            if 2 * i0 >= data.n_samples:
                raise IdentificationError(f"edge_trim {trim} s leaves no samples")
            Theta = Theta[i0:data.n_samples - i0]
        return Theta, i0

    def _regression_matrix(self, lib: Library, data: Measurement) -> tuple[np.ndarray, int, int, int]:
        """Rows of the regression, training rows first: (matrix, n_train, i0, v0).

        ``i0`` is the edge trim [samples], ``v0`` the first sample of the validation part of
        the record.  Strong form: the library's samples (:meth:`_library_matrix`).  Weak form
        (``formulation="weak"``): test-function integrals over the trimmed record
        (:func:`identify._weak.weak_matrix`); windows wholly before the split time are
        training rows, wholly after it validation rows, those straddling it are dropped.
        """
        form = self._knob("formulation")
        if form == "strong":
            Theta, i0 = self._library_matrix(lib, data)
            n_tr = split_index(Theta.shape[0], self.val_fraction)
            return Theta, n_tr, i0, i0 + n_tr
        if form != "weak":
            raise ValueError(f"formulation must be 'strong' or 'weak', got {form!r}")
        if self._knob("column_lowpass_hz"):
            raise ValueError("column_lowpass_hz applies to the strong form only (the weak form's "
                             "test functions filter; integration by parts needs unfiltered columns)")
        x, xd, xdd = data.x, data.xd, data.xdd
        if self.reconcile and self.closure_ is not None:
            x, xd, xdd = self.closure_.reconcile(x, xd, xdd)
        trim = self._knob("edge_trim")
        i0 = round(trim * data.fs)
        n = data.n_samples - 2 * i0
        if n < 2:
            raise IdentificationError(f"edge_trim {trim} s leaves no samples")
        sl = slice(i0, data.n_samples - i0)
        u = None if data.u is None else data.u[:, sl]
        xdd = None if xdd is None else xdd[:, sl]
        wf = weak_matrix(lib, x[:, sl], xd[:, sl], xdd, u, data.fs, self._knob("weak_window_s"),
                         self.weak_n_windows, self.weak_degree, self.input_hold_)
        split = split_index(n, self.val_fraction)
        tr = wf.starts + wf.length <= split
        va = wf.starts >= split
        if tr.sum() < 2 or va.sum() < 2:
            raise IdentificationError(f"{tr.sum()} training and {va.sum()} validation windows: "
                                      "shorten weak_window_s or add weak_n_windows")
        self.weak_strong_columns_ = wf.strong_columns
        return np.concatenate([wf.V[tr], wf.V[va]]), int(tr.sum()), i0, i0 + split

    @classmethod
    def check_data_shape(cls, params, n_channels, n_inputs, fs, n_samples, error):
        """Library and lhs terms, column low-pass and edge trim against the data's shape."""
        check_terms(params, n_channels, n_inputs, error)
        check_record(params, fs, n_samples, error)

    @classmethod
    def simulation_steps(cls, params, record_s):
        """See :func:`rollout_steps`."""
        return rollout_steps(params, record_s)

    def fit(self, data: Measurement) -> _ImplicitMechanical:
        self.check_params()
        if data.u is None or data.input_map is None:
            raise IdentificationError(f"{self.name} needs measured inputs and their input_map")
        imap = np.abs(np.asarray(data.input_map)) > 0
        actuated = np.array([int(np.argmax(imap[:, k])) for k in range(imap.shape[1])])
        passive = np.flatnonzero(~imap.any(axis=1))
        self._knobs = None
        self.__dict__.pop("sim_dt_", None)  # candidates are simulated at the rule's first step,
        self._choose_input_hold(data)        # never at a step an earlier fit chose
        self._knobs = self._choose_knobs(data)
        cut = self._knobs["column_lowpass_hz"]
        self.closure_ = None  # fully actuated, or an open chain: one equation per coordinate
        closed = closed_chain(data, passive)
        if closed and cut:
            # the closure is found on angles low-passed as the columns are: white angle noise
            # on a small motion otherwise outweighs the loop's own residual
            sl = slice(round(self._knobs["edge_trim"] * data.fs),
                       data.n_samples - round(self._knobs["edge_trim"] * data.fs))
            xs = lowpass(data.x, data.fs, cut, self.column_lowpass_order)
            band = (0.0, min(cut, data.fs / 2.0 if data.passband is None else data.passband[1]))
            self.closure_ = find_closure(dataclasses.replace(data, x=xs[:, sl], xd=data.xd[:, sl],
                                                             xdd=data.xdd[:, sl], u=None,
                                                             passband=band),
                                         passive)
        elif closed:
            self.closure_ = find_closure(data, passive)
        lib = make_library(self.library, data)
        Theta, n_tr, i0, _v0 = self._regression_matrix(lib, data)
        G_tr, G_v = grams(Theta, n_tr)
        in_cols = [lib.input_columns(k) for k in range(data.u.shape[0])]
        has_u = np.zeros(len(lib), dtype=bool)
        has_u[np.concatenate(in_cols)] = True
        keep = np.ones(len(lib), bool)
        open_chain = self.closure_ is None and passive.size > 0
        # An open chain's passive equations ARE exact input-free dependencies among the
        # columns (and it has no loop identities): pruning would delete them
        prune_tol = self._knob("prune_tol")
        if prune_tol is not None and not open_chain:
            keep = prune_dependent(G_tr + G_v, has_u, prune_tol)
        kidx = np.flatnonzero(keep)
        self.pruned_terms_ = [lib.names[c] for c in np.flatnonzero(~keep)]
        names = [lib.names[c] for c in kidx]
        lhs = self._knob("lhs")
        if lhs is None:
            cand = np.arange(kidx.size)
        else:
            pos = {n: i for i, n in enumerate(names)}
            wanted = Library(list(lhs), lib.n_coords, lib.n_inputs).names
            missing = [w for w in wanted if w not in pos]
            if missing:
                raise IdentificationError(f"lhs terms not in the (pruned) library: {missing}")
            cand = np.array([pos[w] for w in wanted])
        G_vk, n_val = G_v[np.ix_(kidx, kidx)], Theta.shape[0] - n_tr  # read-only below
        sw = self._sweep(G_tr[np.ix_(kidx, kidx)], G_vk, cand, Theta[:n_tr][:, kidx])
        loc_cols = [np.flatnonzero(np.isin(kidx, c)) for c in in_cols]
        selection = self._knob("selection")
        top = self.n_rollout if selection == "rollout" else 1
        if selection not in ("holdout", "rollout"):
            raise ValueError(f"selection must be 'holdout' or 'rollout', got {selection!r}")
        if open_chain:
            # The passive coordinates' equations hold without inputs: swept again on the
            # input-free columns only (with the inputs present, a left-hand side's regression
            # has two exact solutions on clean data, and its least-squares mix carries inputs)
            free = np.flatnonzero(~has_u[kidx])
            fcand = np.flatnonzero(np.isin(free, cand))
            if fcand.size == 0:
                raise IdentificationError(
                    f"lhs holds no input-free term, but coordinates {(passive + 1).tolist()} are "
                    "passive in an open chain: their equations have no input; add their "
                    "terms to lhs (e.g. their accelerations)")
            sw = merge_sweeps(sw, self._sweep(G_tr[np.ix_(kidx[free], kidx[free])],
                                              G_v[np.ix_(kidx[free], kidx[free])], fcand,
                                              Theta[:n_tr][:, kidx[free]]), free)
        # An open chain's input equations are ranked per unit of their input's part: a passive
        # equation plus a small input admixture is an exact combination whose residual per unit
        # of its left-hand side falls as the admixture squared (identify._implicit.input_errors)
        picks = select_models(sw, loc_cols, self.selection_rtol, self.selection_atol, top,
                              G_vk if open_chain else None, n_val)
        solved = actuated
        if open_chain:
            acc = lib.acc_index[kidx]
            # the first pick tested per unit of the part holding the passive coordinate's
            # acceleration: a near-exact identity of nearly equal columns (X, cos(th2)*X on a
            # small swing) written on its own left-hand side wins per unit of that side
            picks += select_passive_models(sw, loc_cols, [np.flatnonzero(acc == p) for p in passive],
                                           self.selection_rtol, self.selection_atol, top,
                                           [f"{i + 1} ({data.channels[i]})" for i in passive],
                                           G_vk if self._passive_acc_rule_on else None, n_val)
            solved = np.concatenate([actuated, passive])
        self.feature_names_ = list(lib.names)
        self.actuated_ = solved
        self.passive_ = passive
        self._library_ = lib

        def build(choice):
            coef = np.zeros((len(choice), len(lib)))
            for r, (t, c) in enumerate(choice):
                coef[r, kidx] = sw.coef(t, c)
            return coef

        best = [p[0] for p in picks]
        self.record_replays_ = None
        self.record_rule_ = ("not applied: models chosen by held-out error"
                             if selection != "rollout" else "")
        self.inertia_rule_ = "not applied: " + (
            "models chosen by held-out error" if selection != "rollout" else
            "off for this identifier" if not self._inertia_rule_on else
            "an open chain (more solved coordinates than inputs)" if open_chain else "")
        self._wide_ctx = None
        if selection == "rollout":
            combos = list(product(*picks))
            models = [ImplicitModel(lib, build(combo), solved, self.closure_) for combo in combos]
            keep = np.ones(len(models), dtype=bool)
            # what the record rule's wider search (SINDyPI._wide_record) needs of this fit
            self._wide_ctx = _WideContext(sw, kidx, loc_cols, solved, i0, frozenset(combos),
                                          len(combos))
            if self.inertia_rule_ == "not applied: ":
                combos, models, keep = self._inertia_rule(
                    combos, models, data,
                    lambda: select_models(sw, loc_cols, self.selection_rtol,
                                          self.selection_atol, WIDE_ROLLOUT),
                    lambda combo: ImplicitModel(lib, build(combo), solved, self.closure_))
                self._wide_ctx = dataclasses.replace(self._wide_ctx,
                                                     seen=self._wide_ctx.seen | frozenset(combos))
            scores = [self._rollout_error(m, data, i0, self._knob("rollout_segments")) if k
                      else np.inf for m, k in zip(models, keep, strict=True)]
            if not np.isfinite(min(scores)):
                self.record_rule_ = "not reached: no shortlisted combination simulated its segments"
                self.record_replays_ = np.zeros(len(models), dtype=bool)
                self._record_finite = self.record_replays_
                raise NoSimulationError("no shortlisted model combination could be simulated")
            scores = self._record_rule(scores, models, data)
            size = [sum(int(sw.nnz[t, c]) for t, c in cb) for cb in combos]
            atol = (getattr(self, "_knobs", None) or {}).get("rollout_atol", ROLLOUT_ATOL)
            ok = np.array(scores) <= min(scores) * (1 + self.selection_rtol) + atol
            chosen = min(np.flatnonzero(ok), key=lambda i: (size[i], scores[i]))
            best = list(combos[chosen])
            self.rollout_rmse_ = float(scores[chosen])
        self.coef_ = build(best)
        if getattr(self, "ensemble", 0):
            if open_chain:
                raise IdentificationError("ensemble: bagging refits each equation on every column, "
                                          "which would put inputs into the passive coordinates' "
                                          "equations of an open chain; set ensemble = 0")
            self._bag(Theta[:n_tr][:, kidx], G_vk, best, sw, kidx, len(lib))
        self._adopt(best, sw, kidx, solved, data)
        return self

    def _adopt(self, best: list[tuple[int, int]], sw: Sweep, kidx: np.ndarray,
               solved: np.ndarray, data: Measurement) -> None:
        """Make ``best`` (one (threshold, candidate) of ``sw`` per solved coordinate) the fitted
        model: ``lhs_terms_``, ``selected_thresholds_``, ``validation_errors_``, ``sweep_``,
        ``model_`` from ``coef_`` (set by the caller), then the step rule (``sim_dt_``)."""
        lib = self._library_
        self.lhs_terms_ = [lib.names[kidx[sw.candidates[c]]] for _, c in best]
        self.selected_thresholds_ = np.array([sw.thresholds[t] for t, _ in best])
        self.validation_errors_ = np.array([sw.val_error[t, c] for t, c in best])
        self.sweep_ = sw
        self.model_ = ImplicitModel(lib, self.coef_, solved, self.closure_)
        self._choose_sim_dt(data)

    def _inertia_rule(self, combos: list[tuple], models: list[ImplicitModel], data: Measurement,
                      wider: Callable[[], list[list[tuple[int, int]]]],
                      make: Callable[[tuple], ImplicitModel]
                      ) -> tuple[list[tuple], list[ImplicitModel], np.ndarray]:
        """The inertia rule of the rollout selection (``inertia_rule_``): the combinations
        whose reduced inertia vanishes on the record's states are not simulated.

        Rule: a mechanism's reduced inertia (the actuated coordinates' mass matrix after the
        loop closure) is positive definite wherever its chain assembles, so the determinant
        of a model's input gain ``d ddq_a / du`` keeps one sign along the recorded path
        (:func:`gain_crossing` on :meth:`ImplicitModel.gain_determinants` at the measured
        actuated states, every ``0.5 sim_dt fs``-th one (the half step at which the RK4
        simulations evaluate the model: a narrower excursion they step over too; 5x fewer
        states at 10 kHz and 1 ms: 0.25-0.29 s of CPU per call on a 10 s record, about 1.5 s at
        every state),
        with the passive ones the loop closure gives, as every simulation
        completes them (:meth:`ImplicitModel.complete`): off the closure's manifold the
        library's loop identities do not cancel, and on the measured noisy passive angles a
        determinant of -4e-7 read +1e-3 on ``fb15_cranks_0p8_1p5_3s`` at 5 %; the sign itself
        is not fixed: along one path the input is a function of the state, and exact pairs
        of both signs fit one record).  A
        combination whose determinant changes sign there (or that cannot be solved for the
        accelerations at some recorded state) blows up in every simulation through that
        state: no model of the record.  Where no shortlisted combination is left, the
        ``WIDE_ROLLOUT`` best models per input (``wider``) are searched, and the combinations
        left there, at most as many as the shortlist held, nearest the top of the held-out
        ranking (the largest, then the summed, rank of their equations), are simulated; where
        none is left there either, :class:`NoSimulationError` names the failure
        (:data:`INERTIA_FAILURE`).  Where the closure cannot be evaluated at a recorded state
        (collinear passive links) the rule cannot judge: every combination is kept.
        Measured (2026-11-28, session 19; docs/known-gaps.md "SINDy-PI: the inertia rule"):
        137 five-bar cells of rounds 14-17 and the five shipped five-bar scenarios, 118 -> 120
        passes (``fb17_all_diff_ground_short`` 3 % and ``fb16_amp_0p2`` 4 % from the wider
        search), none lost; the rule acted on 62 (49 unchanged to the bit, 3 passes moved,
        8 failures now named otherwise); the 30 family five-bars clean and 1 % never reach it
        (held-out selection).

        Returns
        -------
        combos, models : list
            The combinations to score (the shortlist, or the wider search's).
        keep : ndarray of bool
            Which of them the rule keeps (the others are scored inf).
        """
        try:
            judge = self._inertia_judge(data, models[0])
        except IdentificationError as exc:
            self.inertia_rule_ = f"not applied: the loop closure at the recorded states: {exc}"
            return combos, models, np.ones(len(models), dtype=bool)
        keep, when, why = judge(models)
        if why:
            self.inertia_rule_ = f"not applied: at a recorded state the {why}"
            return combos, models, keep
        head = (f"{int(keep.sum())} of {keep.size} shortlisted combinations keep the sign of "
                "their input gain's determinant on the record's states")
        if keep.all():
            self.inertia_rule_ = f"{head}: none excluded"
            return combos, models, keep
        lost = (f"(reduced inertia vanishing at t = {min(when):.4g} - {max(when):.4g} s)")
        if keep.any():
            self.inertia_rule_ = f"{head}: the others excluded {lost}"
            return combos, models, keep
        extra = by_rank(wider(), set(combos))
        xmodels = [make(c) for c in extra]
        xkeep, _, xwhy = judge(xmodels)
        if xwhy:
            xkeep[:] = False
        take = np.flatnonzero(xkeep)[:len(combos)]
        wide_head = (f"{head}: none {lost}; {int(xkeep.sum())} of {len(extra)} more among the "
                     f"{WIDE_ROLLOUT} best per input keep it")
        if take.size == 0:
            self.inertia_rule_ = f"{wide_head}: {INERTIA_FAILURE}"
            self.record_rule_ = "not reached: " + INERTIA_FAILURE
            self.record_replays_ = np.zeros(len(models), dtype=bool)
            self._record_finite = self.record_replays_
            raise NoSimulationError(
                f"{INERTIA_FAILURE} (the determinant of its input gain d ddq_a / du changes "
                f"sign on the record's states, {len(models) + len(extra)} combinations of the "
                f"{WIDE_ROLLOUT} best per input)")
        self.inertia_rule_ = f"{wide_head}: the first {take.size} of those simulated"
        return ([extra[i] for i in take], [xmodels[i] for i in take],
                np.ones(take.size, dtype=bool))

    def _inertia_judge(self, data: Measurement, model: ImplicitModel
                       ) -> Callable[[list[ImplicitModel]], tuple[np.ndarray, list[float], str]]:
        """The inertia rule's test (:meth:`_inertia_rule`) on this record: a function of a list
        of models returning which keep the sign of their gain's determinant on the record's
        states, the times [s] at which the others' vanishes, and, where the closure stopped
        the kernel at a recorded state, its message (then every model is kept: no judgement).

        Raises
        ------
        IdentificationError
            The loop closure (``model``'s, shared by every model of the fit) does not assemble
            at some recorded state.
        """
        u = np.asarray(data.u, dtype=float)[:self._library_.n_inputs]
        scale = np.sqrt(np.mean(u ** 2, axis=1))
        scale = np.where(np.isfinite(scale) & (scale > 0), scale, 1.0)
        # every recorded state the simulations' RK4 stages resolve: a stride of half the step
        stride = max(1, int(0.5 * self._step() * data.fs + 1e-9))
        # the states the models are simulated through: the closure's passive rows
        q, dq = model.complete(np.asarray(data.x, dtype=float)[:, ::stride],
                               np.asarray(data.xd, dtype=float)[:, ::stride])

        def judge(ms: list[ImplicitModel]) -> tuple[np.ndarray, list[float], str]:
            keep, when = np.ones(len(ms), dtype=bool), []
            for i, m in enumerate(ms):
                det, s, why = m.gain_determinants(q, dq, scale)
                j = s if why == "singular" else gain_crossing(det) if det is not None else -1
                if det is None and why not in ("singular", "not square"):
                    return np.ones(len(ms), dtype=bool), [], why  # the closure: no judgement
                if j >= 0:
                    keep[i] = False
                    when.append(float(data.t[j * stride]))
            return keep, when, ""

        return judge

    def _choose_input_hold(self, data: Measurement) -> None:
        """``input_hold_``: the user's, else the data's declared hold
        (``Measurement.input_hold``), else linear (a continuous signal); ``input_hold_rule_``."""
        if self.input_hold is not None:
            self.input_hold_, self.input_hold_rule_ = self.input_hold, "user-set"
        elif data.input_hold is not None:
            self.input_hold_ = data.input_hold
            self.input_hold_rule_ = f"{data.input_hold}: as the data declare their inputs"
        else:
            self.input_hold_ = "linear"
            self.input_hold_rule_ = "linear: the data declare no hold (a continuous signal)"

    def _step(self) -> float:
        """The RK4 step of this fit's simulations [s]: the user's, the step rule's once
        chosen, else :data:`SIM_DT_START` (the rollout selection's candidates)."""
        if self.sim_dt is not None:
            return self.sim_dt
        return getattr(self, "sim_dt_", SIM_DT_START)

    def _choose_sim_dt(self, data: Measurement) -> None:
        """``sim_dt_``: the user's, else :func:`choose_sim_dt` on the fitted model, simulated
        as the rollout selection does (:meth:`_segment_rollouts`); ``sim_dt_rule_``."""
        if self.sim_dt is not None:
            self.sim_dt_, self.sim_dt_rule_ = self.sim_dt, "user-set"
            return
        model = self.model_
        i0 = round(self._knob("edge_trim") * data.fs)
        segments = self._knob("rollout_segments")

        def simulate(dt: float) -> np.ndarray:
            return self._segment_rollouts(model, data, i0, segments, dt)

        self.sim_dt_, self.sim_dt_rule_ = choose_sim_dt(simulate, data.x[:, i0:data.n_samples - i0],
                                                        data.fs)

    def _segment_rollouts(self, model: ImplicitModel, data: Measurement, i0: int, segments: int,
                          dt: float) -> np.ndarray:
        """The simulated coordinates (n_channels, n - 2 i0) over the trimmed record
        ``[i0, n - i0)`` cut into ``segments`` equal parts, each simulated from the measured
        state at its start with RK4 step ``dt`` [s] (a part of fewer than 2 samples is the
        measured one).

        Raises
        ------
        IdentificationError
            A simulation failed.
        """
        n = data.n_samples - 2 * i0
        edges = i0 + np.arange(segments + 1) * n // segments
        out = data.x[:, i0:i0 + n].copy()
        for a, b in pairwise(edges):
            if b - a < 2:
                continue
            out[:, a - i0:b - i0] = model.simulate(data.x[:, a], data.xd[:, a], data.t[a:b],
                                                   data.u[:, a:b], dt, self.input_hold_,
                                                   angles_only=True).x
        return out

    def _replays_record(self, model: ImplicitModel, data: Measurement) -> bool:
        """Whether ``model`` replays the record: both parts of :meth:`_replay_status`."""
        return all(self._replay_status(model, data))

    def _replay_status(self, model: ImplicitModel, data: Measurement) -> tuple[bool, bool]:
        """Whether ``model`` simulates the whole record, from its first measured state under
        the measured inputs, without losing its loop closure or diverging; and whether that
        simulation stays nearer the record than rest does (angles only; see
        :meth:`_record_rule`).

        Rest: the record's first measured state held for the whole record.  A simulation
        whose RMSE against the measured angles exceeds, on some coordinate, that
        coordinate's RMSE about its first measured value (``REPLAY_REST_RATIO`` = 1) follows
        the record less than a model that never moves does: it is no model of that record,
        however finite.  The error is compared only with that baseline of the record itself,
        never used to rank (one long simulation ranks by its start state's luck).  Closed
        chains only (a loop closure, ``closure_``): the loop holds every coordinate near the
        record, whereas an open chain's free coordinate (a cart on its rail under replayed
        forces) integrates the error of the chain's start-rate estimate (cart-pole
        ``cp9_light_pole_short`` at 1 %: 0.054 m/s, every one of 9 pairs 1.2-15 x farther
        than rest on the cart, good and bad alike), so rest is no baseline there.  Measured on
        round 9's five-bars: the pairs that lost their loop from the true start 1.1-6.9 x
        rest on some coordinate, those that held it 0.015-0.06 x.
        """
        try:
            sim = model.simulate(data.x[:, 0], data.xd[:, 0], data.t, data.u, self._step(),
                                 self.input_hold_, angles_only=True).x
        except IdentificationError:
            return False, False
        if not np.isfinite(sim).all():
            return False, False
        if getattr(self, "closure_", None) is None:
            return True, True
        x = np.asarray(data.x, dtype=float)
        err = np.sqrt(np.mean((sim - x) ** 2, axis=1))
        rest = np.sqrt(np.mean((x - x[:, :1]) ** 2, axis=1))
        return True, bool(np.all(err <= REPLAY_REST_RATIO * rest))

    def _record_rule(self, scores: list[float], models: list[ImplicitModel],
                     data: Measurement) -> list[float]:
        """The record rule of the rollout selection (``record_replay``; ``record_rule_``,
        ``record_replays_``): the rollout scores with every shortlisted combination that cannot
        simulate the whole record (:meth:`_replays_record`) set to inf, unless none can.

        Rule: the segments of the rollout selection last a sixth of the trimmed record, so a
        combination that predicts each segment well may still lose its loop closure over a
        longer stretch of the record, or outside the trimmed span, where the scored simulation
        of the whole record goes.  A combination whose simulation of the whole record from its
        first measured state (the chain's estimate, a perturbed start) diverges, or ends
        farther from the measured angles than rest (:meth:`_replays_record`), is not a model
        of that record and is not chosen while another can be; the error of that simulation is
        not used to rank (one long simulation ranks by the luck of its start state, see
        :meth:`_rollout_error`), only its failure.  Where none stays nearer than rest but
        some do not diverge, those are kept (the divergence test alone, the rule before the
        rest baseline) and ``record_replays_`` is all False, so the unpruned refit is tried
        (:meth:`SINDyPI._unpruned_refit`).  The rest baseline since 2026-11-27
        (round 9): on ``fb9_asym3`` and ``fb9_mixed`` at 1 % (seed 9) the one pair left by the
        divergence test followed the record 4.7 / 4.0 x worse than rest (0.157 rad on a 0.07
        rad swing) and lost its loop from the true start; with it none is left, the unpruned
        library's pair is chosen: 0.0030 / 8.0e-4 rad.  Measured (2026-11-26): the paper's sine
        input on the 30 family geometries at 1 % noise with chain-derived rates
        (benchmarks/unseen/round5_linkages_sine.toml), 27 -> 28 of 30 within 0.0501 rad, none
        lost (fbsine__024 chose a pair that predicted every segment to 1e-4 rad but lost its
        loop at 6.5 s of the record from the measured start and at 2.0 s from the true one).
        ``record_replay = False`` turns the rule off; combinations whose rollout failed are not
        simulated again.
        """
        flag = getattr(self, "record_replay", None)
        if flag is False:
            self.record_replays_ = None
            self.record_rule_ = "user-set: off (rollout scores alone)"
            return scores
        status = np.array([self._replay_status(m, data) if np.isfinite(s) else (False, False)
                           for s, m in zip(scores, models, strict=True)], dtype=bool)
        finite, ok = status[:, 0], status[:, 0] & status[:, 1]
        self.record_replays_ = ok
        self._record_finite = finite
        head = (f"{int(ok.sum())} of {ok.size} shortlisted combinations simulate the whole record "
                "from its first measured state")
        if not ok.any():
            if finite.any() and not finite.all():
                # the divergence test alone, as before the rest baseline
                self.record_rule_ = (f"{head} nearer than rest; {int(finite.sum())} simulate it "
                                     "without diverging: the others excluded (the divergence "
                                     "test alone)")
                return [s if k else np.inf for s, k in zip(scores, finite, strict=True)]
            self.record_rule_ = f"{head}: none excluded (the rollout scores alone)"
            return scores
        self.record_rule_ = (f"{head}: the others (closure lost, diverged or farther than "
                             "rest) excluded" if not ok.all() else f"{head}: none excluded")
        return [s if k else np.inf for s, k in zip(scores, ok, strict=True)]

    def _rollout_error(self, model: ImplicitModel, data: Measurement, i0: int,
                       segments: int) -> float:
        """Simulation error of a candidate model on the measured angles [rad] (inf if a
        simulation fails): the trimmed record ``[i0, n - i0)`` cut into ``segments`` equal
        parts, each simulated from the measured state at its start
        (:meth:`_segment_rollouts`); the largest over coordinates of the RMSE over all
        segments' samples.

        Segments, not one simulation: the five-bar's motion amplifies a state error, so one
        simulation of the whole record from the chain's estimated start state ranks
        candidates by that error's luck (measured on the 30 family five-bars at 1 % noise,
        rates from the low-pass chain: 1 segment picked the model that failed on 2 members, 6
        segments on none).
        """
        n = data.n_samples - 2 * i0
        try:
            sim = self._segment_rollouts(model, data, i0, segments, self._step())
        except IdentificationError:
            return np.inf
        err = float(np.sqrt(np.sum((sim - data.x[:, i0:i0 + n]) ** 2, axis=1) / n).max())
        return err if np.isfinite(err) else np.inf

    def _bag(self, Theta_train: np.ndarray, G_val: np.ndarray, best: list[tuple[int, int]],
             sw: Sweep, kidx: np.ndarray, n_terms: int) -> None:
        """E-SINDy bagging of the selected models (:func:`identify._implicit.bagged_models`):
        ``coef_`` becomes the median model, with ``coef_std_`` and ``inclusion_probability_``
        (scaled as ``coef_``)."""
        blocks = block_grams(Theta_train, self.ensemble_blocks)
        ens = bagged_models(blocks, G_val, best, sw, self.ensemble, self._knob("ridge"),
                            self.max_iter, np.random.default_rng(self.ensemble_seed),
                            aggregate=self.ensemble_aggregate)
        coef = np.zeros((len(best), n_terms))
        std = np.zeros_like(coef)
        inc = np.zeros_like(coef)
        coef[:, kidx], std[:, kidx], inc[:, kidx] = ens.coef, ens.std, ens.inclusion
        for r in range(len(best)):
            scaled = canonical_scale(coef[r])
            big = np.abs(coef[r]).max(initial=0.0)
            if big > 0:
                std[r] /= big
            coef[r] = scaled
        self.coef_ = coef
        self.coef_std_ = std
        self.inclusion_probability_ = inc

    def simulate(self, x0: np.ndarray, xd0: np.ndarray, t: np.ndarray,
                 u: np.ndarray | None = None) -> Trajectory:
        """Free simulation from (x0, xd0) under inputs u (n_inputs, len(t)) at times t [s]
        (at least 2, increasing, spanning at most :data:`~identify._mechsim.MAX_SIM_STEPS`
        steps: ArgumentError otherwise)."""
        if not hasattr(self, "model_"):
            raise IdentificationError(f"{self.name}: fit before simulate")
        return self.model_.simulate(x0, xd0, t, u, self._step(), self.input_hold_,
                                    where=f"{type(self).__name__}.simulate")

    def equations(self, precision: int = 4) -> list[str]:
        """One line per identified implicit equation, ``0 = c1*term1 + ...``."""
        out = []
        for row in self.coef_:
            terms = [f"{c:+.{precision}g}*{n}" for c, n in zip(row, self.feature_names_, strict=True)
                     if c != 0]
            out.append("0 = " + " ".join(terms))
        return out


@IDENTIFIERS.register("sindy_pi", tags=("mechanical", "implicit", "sparse"))
class SINDyPI(_ImplicitMechanical):
    """SINDy-PI by shared-Gram thresholded least squares.

    Parameters
    ----------
    library : str, Library or list of str
        ``"fivebar"`` (the reduced-equation library), ``"fivebar_full"``, ``"generic"``, a
        :class:`~identify.library.Library` or term names.
    lhs : list of str, optional
        Candidate left-hand-side terms; default by the noise rule: the terms with an input
        factor where a low-pass chain derived the rates from noisy angles, else every (kept)
        column.
    thresholds : sequence of float, optional
        Ascending thresholds on normalised coefficients; default 0 and 12 values log-spaced
        over 1e-6..0.32.
    ridge : float, optional
        Ridge added to the unit-diagonal normalised Gram matrix (see ``stlsq_sweep``);
        default by the noise rule (:func:`noise_knobs`: 1e-14).
    max_iter : int
        Thresholding rounds per threshold.
    val_fraction : float
        Held-out fraction at the end of the record.
    selection : {"holdout", "rollout"}, optional
        Model selection by held-out equation error and parsimony, or by simulating the
        ``n_rollout`` best per input against the measured angles (see the module docs);
        default by the noise rule: rollout where a declared low-pass chain derived the rates
        from noisy angles, else holdout.
    selection_rtol, selection_atol : float
        Held-out error tolerances of the parsimony rule (see ``select_models``).
    n_rollout : int
        Models shortlisted per input for ``selection="rollout"``.
    rollout_segments : int
        Segments of the trimmed record the rollout selection simulates, each from the measured
        state at its start (one simulation of the whole record ranks by the luck of its start
        state's error, which the five-bar's motion amplifies; see
        :meth:`_ImplicitMechanical._rollout_error`).
    record_replay : bool or None
        The record rule of the rollout selection (:meth:`_ImplicitMechanical._record_rule`,
        ``record_rule_``): a shortlisted combination whose simulation of the whole record from
        its first measured state diverges is not chosen while another is left, and where none
        is left the fit is redone over the unpruned library (:meth:`_unpruned_refit`).  None
        (default) applies it wherever models are chosen by rollout; False turns it off.
    prune_tol : float or None
        Residual variance (of a unit-norm column) below which an input-free column counts as a
        combination of earlier ones; 1e-9 (residual norm 3e-5) catches exact kinematic
        identities on clean data and leaves independent terms alone.  None disables.
    sim_dt : float, optional
        RK4 step of the simulation [s]; 1e-3 s resolves motions up to ~20 Hz to 1e-8 (RK4
        error ~ (h w)^4 / 120).  Default by the step rule (:func:`choose_sim_dt`,
        ``sim_dt_``, ``sim_dt_rule_``): 1 ms, 0.5 ms, then the sample interval and its halves,
        the first that the next moves the fitted model's simulation of the record by at most
        2.5e-6 of the motion's range (a 0.1 m, 0.05 kg five-bar needs 0.1 ms: at 1 ms its exact
        equations drift 0.03 rad).
    reconcile : bool
        Replace the passive angles, rates and accelerations by those the loop closure implies
        from the actuated ones before building the library
        (:meth:`identify._mechsim.LoopClosure.reconcile`).  No effect on exact data; on noisy
        angles it restores the exact kinematic identities, so ``prune_tol`` can remove them.
    column_lowpass_hz : float, optional
        Cut-off [Hz] of a zero-phase Butterworth low-pass applied to every library column
        before the regression (0: off; default by the noise rule: off on exact data, 1.5x the
        angles' band on noisy ones).  The equations hold for filtered columns exactly
        (one linear filter for all), while the noise of estimated derivatives, broadband, is
        cut; set it above the band of the motion's products (the implicit equations need
        excitation, not fidelity to the raw signals).
    column_lowpass_order : int
        Order of that filter (one pass).
    edge_trim : float, optional
        Seconds dropped at each end of the record before the regression (edge effects of the
        derivative estimate and of the column filter); 0 keeps every sample; default by the
        noise rule (0 on exact data, one period of the column cut-off on noisy ones).
    input_hold : {"linear", "zoh"}, optional
        What the sampled inputs stand for in simulations: a continuous signal or a zero-order
        hold (see :meth:`identify._mechsim.ImplicitModel.simulate`).  Actuators driven by a
        DAC (the five-bar rig) hold; the wrong choice costs an impulse of half a sample.
        Default: as the data declare it (``Measurement.input_hold``: the five-bar and
        cart-pole rigs declare their torques held), else linear (``input_hold_``,
        ``input_hold_rule_``).
    formulation : {"strong", "weak"}, optional
        Default by the noise rule: ``"weak"`` where angles an undeclared chain smoothed were
        detected by the held-out test, else ``"strong"`` (measured better at 1 and 5 % with
        recorded rates, and at 1 % with rates a declared low-pass chain derived).  ``"strong"``: one
        regression row per sample of the library.  ``"weak"``: one row per
        test function, ``int phi_k Theta dt`` (:func:`identify._weak.weak_matrix`), with the
        acceleration terms integrated by parts so that only angles and rates enter (no second
        derivative of noisy angles); the held-out split is by time windows (windows
        straddling the split are dropped).  ``column_lowpass_hz`` must then be None or 0.
    weak_window_s : float, optional
        Support of each test function [s] (weak form); default by the noise rule, 1.5
        periods of the angles' band (1 s on the five-bar's 0.1-1.5 Hz multisine), at most
        half the held-out span.
    weak_n_windows : int
        Number of equally spaced, overlapping test functions over the trimmed record.
    weak_degree : int
        Exponent p of the test function ``(1 - s^2)^p`` (>= 2).
    ensemble : int
        E-SINDy bagging (0: off): refit the selected models on this many moving-block
        bootstraps of the training rows and keep the per-term median (or mean) with the
        terms present in at least half the bags (:func:`identify._implicit.bagged_models`).
        Off by default: on the 30 five-bar family members, 20 bags passed (within 0.0501
        rad) at 1 % noise 18 (median) / 14 (mean) / 28 (refit) against 30 without, at 5 %
        10 (median) / 24 (refit) against 28 (the library is ill-conditioned; per-term
        aggregates of equations that differ along its weak directions are not an equation
        that simulates well).  The uncertainty it reports is the use.
    ensemble_blocks : int
        Contiguous blocks of training rows the bags draw from (with replacement).
    ensemble_seed : int
        Seed of the draws (a fit is reproducible).
    ensemble_aggregate : {"median", "mean", "refit"}
        Per-term median (E-SINDy's bragging) or mean (bagging), or a least-squares refit on
        all training rows of the terms in at least half the bags.

    Attributes
    ----------
    coef_ : ndarray, shape (n_inputs + n_open_passive, n_terms)
        One implicit equation per input, then (open chains) one per passive coordinate, scaled
        to max |coef| = 1, the first non-negligible term in library order positive
        (:func:`identify._implicit.canonical_scale`).
    actuated_ : ndarray of int, shape (n_equations,)
        The coordinate each equation is solved for (actuated, then open-chain passive ones).
    passive_ : ndarray of int
        Coordinates no input drives (given by the closure, or by their own equations).
    feature_names_, lhs_terms_, selected_thresholds_, validation_errors_, pruned_terms_,
    closure_, sweep_, model_
    weak_strong_columns_ : list of str
        Weak form only: acceleration terms integrated with the measured accelerations (no
        exact integration by parts; :class:`identify._weak.WeakForm`).
    column_lowpass_hz_, edge_trim_, ridge_, formulation_, weak_window_s_, lhs_, selection_
        The settings used (the user's where given, else the noise rule's; ``lhs_`` None =
        every kept column).
    rollout_rmse_ : float
        With ``selection_ == "rollout"``: the chosen combination's segmented simulation error
        on the measured angles [rad] (:meth:`_ImplicitMechanical._rollout_error`).
    replay_rmse_ : float or None
        Where the replay rule applied (:meth:`_replay_check`): the final model's simulation
        error over the trimmed record from its first measured state [rad]; else None.
    replay_rule_ : str
        Whether the replay rule applied, the replay and its bar, and what it decided.
    inertia_rule_ : str
        The rollout selection's inertia rule (:meth:`_ImplicitMechanical._inertia_rule`) in
        the final fit: whether it applied, how many shortlisted combinations keep the sign of
        their input gain's determinant on the record's states, the times at which the others'
        reduced inertia vanishes, and what the wider search found.
    formulation_rule_ : str
        The open chain's form comparison (:meth:`_open_chain_form`): whether it applied, both
        forms' segmented rollout errors [rad or m] and the form kept.
    noise_rule_ : str
        The rule's estimates, the branch it took and the settings the user overrode.
    noise_std_ : ndarray, shape (n_channels,)
        White-noise std of each measured angle [rad]: the chain's declaration
        (``Measurement.noise_std``) or :func:`testbed.numerics.noise_std` of the angles.
    noise_rel_, band_hz_ : float
        Largest relative noise (std / RMS about the mean) and angles' band [Hz] over channels.
    coef_std_, inclusion_probability_ : ndarray, shape (n_inputs, n_terms)
        With ``ensemble``: standard deviation of each coefficient over the bags (scaled as
        ``coef_``) and the share of bags holding each term.
    """

    name = "sindy_pi"
    _inertia_rule_on = True
    _passive_acc_rule_on = True
    #: The record rule's wider search (:meth:`_wide_record`); a switch for probes that
    #: measure it against the rule without it.
    _wide_record_on: ClassVar[bool] = True
    deterministic = True  # ensembles drawn from ``ensemble_seed``; refitted to the bit in test_conformance
    hyperparameters: ClassVar[dict[str, Field]] = ordered_fields({
        **COMMON_HYPERPARAMETERS,
        "lhs": Field(list, None, item_type=str, min_items=1,
                     doc="candidate left-hand-side terms (library term names); default by the "
                         "noise rule (the input terms where a low-pass chain derived the rates "
                         "from noisy angles, else every kept column)"),
        "thresholds": THRESHOLDS_FIELD,
        "selection": Field(str, None, choices=("holdout", "rollout"),
                           doc="model selection by held-out residual, or by simulating "
                               "shortlisted models over the trimmed record; default by the "
                               "noise rule (rollout where a low-pass chain derived the rates "
                               "from noisy angles, else holdout)"),
        "record_replay": Field(bool, None,
                               doc="rollout selection: leave out shortlisted combinations whose "
                                   "simulation of the whole record from its first measured "
                                   "state diverges, and refit over the unpruned library when "
                                   "none is left; default on (the record rule, record_rule_)"),
        "ridge": Field(float, None, min=0.0, max=1.0,
                       doc="ridge added to the unit-diagonal normalised Gram matrix; default by "
                           "the noise rule (1e-14 on exact data)"),
        "max_iter": MAX_ITER_FIELD,
        # 0 = off, None = by the noise rule
        "column_lowpass_hz": Field(float, None, unit="Hz", min=0.0,
                                   doc="zero-phase low-pass cut-off applied to every library "
                                       "column (below the Nyquist frequency; 0: off); default "
                                       "by the noise rule"),
        "edge_trim": Field(float, None, unit="s", min=0.0,
                           doc="seconds dropped at each end of the record (less than half of "
                               "it); default by the noise rule"),
        "formulation": Field(str, None, choices=("strong", "weak"),
                             doc="one regression row per sample, or per test-function integral; "
                                 "default by the noise rule (an open chain with chain-derived "
                                 "rates: the form whose segmented rollout is smaller, "
                                 "formulation_rule_)"),
        "weak_window_s": Field(float, None, unit="s", min=0.0, min_inclusive=False,
                               doc="support of each test function (weak form; shorter than the "
                                   "record); default by the noise rule"),
        # >= 4: the held-out split needs at least 2 training and 2 validation windows
        "weak_n_windows": Field(int, 400, min=4, max=100000,
                                doc="number of overlapping test functions (weak form)"),
        # >= 2: the test function (1 - s^2)^p and its first derivative must vanish at the ends;
        # 16: higher powers concentrate the support to a fraction of the window
        "weak_degree": Field(int, 4, min=2, max=16, doc="exponent p of the test function (1 - s^2)^p"),
        # 0 = off; 1 bag is no ensemble; 1000: each bag reruns the sweep of the selected models
        "ensemble": Field(int, 0, min=0, max=1000,
                          doc="bags of E-SINDy bagging (block bootstrap of the training rows, "
                              "median coefficients, inclusion probabilities); 0: off"),
        # >= 2 blocks to resample; 1000: blocks of a few rows resample noise, not the motion
        "ensemble_blocks": Field(int, 20, min=2, max=1000,
                                 doc="contiguous blocks of training rows the bags resample"),
        "ensemble_seed": Field(int, 0, min=0, doc="seed of the bags' block draws"),
        "ensemble_aggregate": Field(str, "median", choices=("median", "mean", "refit"),
                                    doc="per-term median (bragging) or mean (bagging) over the "
                                        "bags, or a refit of the terms the bags keep"),
    }, (
        "library", "lhs", "thresholds", "ridge", "max_iter", "val_fraction", "selection",
        "selection_rtol", "selection_atol", "n_rollout", "rollout_segments", "record_replay",
        "prune_tol", "sim_dt", "reconcile", "column_lowpass_hz", "column_lowpass_order",
        "edge_trim", "input_hold", "formulation",
        "weak_window_s", "weak_n_windows", "weak_degree", "ensemble", "ensemble_blocks",
        "ensemble_seed", "ensemble_aggregate"))  # __init__ order, for the guide
    #: Keys the fit reads only under another setting (measured 2026-11-27, benchmarks/hostile10.py
    #: ``combos``: each given otherwise fitted the same model to the bit).  ``selection`` and
    #: ``column_lowpass_hz`` None are rules, which may choose the rollout or a low-pass.
    used_when: ClassVar[dict[str, KeyUse]] = {
        "n_rollout": KeyUse("selection", lambda v: v != "holdout", "selection = 'rollout' (or the rule)"),
        "rollout_segments": KeyUse("selection", lambda v: v != "holdout",
                                   "selection = 'rollout' (or the rule)"),
        "record_replay": KeyUse("selection", lambda v: v != "holdout",
                                "selection = 'rollout' (or the rule)"),
        "column_lowpass_order": KeyUse("column_lowpass_hz", lambda v: v != 0,
                                       "a column low-pass (column_lowpass_hz > 0 or the rule)"),
        "weak_n_windows": KeyUse("formulation", lambda v: v != "strong",
                                 "formulation = 'weak' (or the rule)"),
        "weak_degree": KeyUse("formulation", lambda v: v != "strong", "formulation = 'weak' (or the rule)"),
        "ensemble_blocks": KeyUse("ensemble", lambda v: v > 0, "ensemble > 0"),
        "ensemble_seed": KeyUse("ensemble", lambda v: v > 0, "ensemble > 0"),
        "ensemble_aggregate": KeyUse("ensemble", lambda v: v > 0, "ensemble > 0"),
    }

    @classmethod
    def check_hyperparameters(cls, params, error):
        """Ascending thresholds; the weak form filters itself (no column low-pass)."""
        check_thresholds(params, error)
        if params["formulation"] == "weak" and params["column_lowpass_hz"]:
            error("column_lowpass_hz", params["column_lowpass_hz"],
                  "not with formulation = 'weak' (its test functions filter; integration by "
                  "parts needs unfiltered columns)")

    @classmethod
    def check_data_shape(cls, params, n_channels, n_inputs, fs, n_samples, error):
        """As the shared checks, plus a weak window shorter than the record."""
        super().check_data_shape(params, n_channels, n_inputs, fs, n_samples, error)
        # "weak", or None (by rule, which may choose the weak form and then takes the window
        # as given: 1e-300 s was a ValueError of the fit, "a test function needs at least 3
        # samples, got 1")
        if params["formulation"] != "strong" and params["weak_window_s"] is not None:
            span = n_samples / fs - 2 * (params["edge_trim"] or 0.0)
            if not params["weak_window_s"] < span:
                error("weak_window_s", params["weak_window_s"],
                      f"expected shorter than the trimmed record ({span:g} s)")
            check_window(params["weak_window_s"], fs, n_samples, error)

    def __init__(self, library: Any = "fivebar", lhs: Sequence[str] | None = None,
                 thresholds: Sequence[float] | None = None, ridge: float | None = None,
                 max_iter: int = 20,
                 val_fraction: float = 0.2, selection: str | None = None,
                 selection_rtol: float = 0.1, selection_atol: float = 1e-12, n_rollout: int = 3,
                 rollout_segments: int = 6, record_replay: bool | None = None,
                 prune_tol: float | None = 1e-9,
                 sim_dt: float | None = None, reconcile: bool = True,
                 column_lowpass_hz: float | None = None, column_lowpass_order: int = 4,
                 edge_trim: float | None = None, input_hold: str | None = None,
                 formulation: str | None = None, weak_window_s: float | None = None,
                 weak_n_windows: int = 400, weak_degree: int = 4, ensemble: int = 0,
                 ensemble_blocks: int = 20, ensemble_seed: int = 0,
                 ensemble_aggregate: str = "median"):
        self.library = library
        self.lhs = lhs
        self.thresholds = thresholds
        self.ridge = ridge
        self.max_iter = max_iter
        self.val_fraction = val_fraction
        self.selection = selection
        self.selection_rtol = selection_rtol
        self.selection_atol = selection_atol
        self.n_rollout = n_rollout
        self.rollout_segments = rollout_segments
        self.record_replay = record_replay
        self.prune_tol = prune_tol
        self.sim_dt = sim_dt
        self.reconcile = reconcile
        self.column_lowpass_hz = column_lowpass_hz
        self.column_lowpass_order = column_lowpass_order
        self.edge_trim = edge_trim
        self.input_hold = input_hold
        self.formulation = formulation
        self.weak_window_s = weak_window_s
        self.weak_n_windows = weak_n_windows
        self.weak_degree = weak_degree
        self.ensemble = ensemble
        self.ensemble_blocks = ensemble_blocks
        self.ensemble_seed = ensemble_seed
        self.ensemble_aggregate = ensemble_aggregate

    def summary(self, precision: int = 4) -> list[str]:
        """The equations, then ``# noise rule: ...`` and, with ``ensemble``, one line per
        equation of ``term: coef +- std (inclusion probability)`` for its non-zero terms."""
        out = list(self.equations(precision))
        out.append(f"# noise rule: {self.noise_rule_}")
        if hasattr(self, "coef_std_"):
            for r, row in enumerate(self.coef_):
                terms = [f"{n}: {c:+.{precision}g} +- {sd:.2g} (p {pi:.2f})"
                         for n, c, sd, pi in zip(self.feature_names_, row, self.coef_std_[r],
                                                 self.inclusion_probability_[r], strict=True)
                         if pi > 0]
                out.append(f"# ensemble, equation {r + 1}: " + "; ".join(terms))
        return out

    def print(self, precision: int = 4, file: TextIO | None = None) -> None:
        """Print :meth:`summary` (the equations, the noise rule, the ensemble's uncertainty)."""
        for line in self.summary(precision):
            print(line, file=file or sys.stdout)

    def _rule_settings(self, data: Measurement, weight: float
                       ) -> tuple[dict[str, Any], str, dict[str, Any]]:
        """:func:`noise_knobs` on the measured angles with this instance's settings, the
        noisy rule's weight at least ``weight`` (the refits of :meth:`fit`)."""
        user = {k: getattr(self, k) for k in RULE_KNOBS}
        ruled: tuple[str, ...] = ()
        if getattr(self, "_weak_trial", False):  # the open chain's form comparison (see fit)
            user["formulation"], ruled = "weak", ("formulation",)
        return noise_knobs(data.x, data.fs, self.val_fraction, user,
                           getattr(self, "_smoothed", None), data.noise_std, data.passband,
                           ruled, inputs=data.u, column_order=self.column_lowpass_order,
                           min_weight=weight)

    def _choose_knobs(self, data: Measurement) -> dict[str, Any]:
        """The noise rule (:func:`noise_knobs`) on the measured angles; stored as fitted
        attributes and ``noise_rule_``."""
        knobs, rule, est = self._rule_settings(data, getattr(self, "_refit_weight", 0.0))
        self._noise_weight = est["noise_weight"]
        if getattr(self, "_refit_weight", 0.0) > 0.0:
            rule += f"; {NOISY_REFIT_TEXT} {self._refit_weight:.3g}"
        if getattr(self, "_weak_trial", False):
            rule += "; weak form: the open chain's form comparison (formulation_rule_)"
        if knobs["lhs"] == LHS_INPUT_TERMS:
            imap = np.abs(np.asarray(data.input_map)) > 0
            passive = np.flatnonzero(~imap.any(axis=1))
            if passive.size and not closed_chain(data, passive):
                # an open chain's passive equations have no input term: every candidate stays
                knobs["lhs"] = None
                rule += " (open chain: every LHS candidate)"
            else:
                lib = make_library(self.library, data)
                cols = sorted(set(np.concatenate([lib.input_columns(k)
                                                  for k in range(data.u.shape[0])]).tolist()))
                knobs["lhs"] = [lib.names[c] for c in cols]
        replay = getattr(self, "_replay", None)
        if replay is not None:  # the replay check failed (see fit): every rule setting else kept
            knobs.update(selection="rollout", prune_tol=None, rollout_segments=1)
        if getattr(self, "_unpruned", False):  # the record rule's second fit (see fit)
            knobs.update(prune_tol=None)
        if replay is not None and getattr(self, "_damped", False):  # see _pool_refit
            knobs["ridge"] = UNPRUNED_RIDGE_PER_TOL * self.prune_tol
            rule += (f"; unpruned library, damped: ridge {knobs['ridge']:.3g} "
                     f"({UNPRUNED_RIDGE_PER_TOL:g} x prune_tol)")
        for k in RULE_KNOBS:
            setattr(self, f"{k}_", knobs[k])
        self.noise_rule_ = rule
        self.noise_std_ = est["noise_std"]
        self.noise_rel_ = est["noise_rel"]
        self.band_hz_ = est["band_hz"]
        return knobs

    def fit(self, data: Measurement) -> SINDyPI:
        """Fit (see the class docs and :meth:`_fit_recipe`); where the fit under a declared
        chain's clean recipe (the noise rule's weight ``w`` below 1, :func:`noise_knobs`) fails,
        it is done again at each of the noisy rule's weights ``REFIT_WEIGHTS`` above
        ``w`` in turn (0.25, 0.5, 0.75, 1: ridge, column cut-off and trim a quarter, half, ...
        of the way, geometrically, to the noisy rule's under the same chain, the tie band the
        clean chain's up to 0.75 and the noisy rule's ``ROLLOUT_ATOL`` at 1), the first that
        fits kept and named in the rule text; a weight whose settings equal those of a fit
        already tried (what the user fixed does not move: :meth:`_refit_ladder`) is not fitted
        again; if every one fails, the first failure is raised with the last's reason.

        Why: the clean recipe's exact-data ridge (``RIDGE_EXACT``) leaves equations the record
        does not make unique to the round-off's choice; where that choice fails a fit-time
        check (round 26's ``fb26_ground_0p55``, clean: no model with input 1 dominant, largest
        share 0.993 of input 2's; with ridge 1.2e-10, the columns at 1.5 x band or the noisy
        rule's trim alone it fits and scores 2.4e-7 / 1.9e-6 / 3.3e-7 rad), the nearest recipe
        that fits is the least departure from the clean one.  Measured (session 28, pi32): that
        record fits at 0.25 and scores 4.7e-7 rad (at weight 1 at once, the rule of session 27,
        9.2e-4), so both routes of the near tie, refit or not, score within 1e-4 rad (review
        27d M3: the verdict no longer hangs on the round-off).  Nothing changes where the first
        fit succeeds (no other clean five-bar or cart-pole of rounds 16-26 refits).  Held out
        (the 30 five-bars of ``benchmarks/heldout/fivebar_noise_validation.toml`` with the
        chain-derived rates, clean): 5 refit; weight 1 at once 0.153 / 0.0139 / 0.0033 /
        0.0090 / 0.030 rad, the ladder 0.0034 / 4.6e-4 / 9.9e-5 / 4.5e-4 / 5.2e-6.
        """
        self._refit_weight = 0.0
        self._noise_weight = 1.0
        start = dict(self.__dict__)
        try:
            return self._fit_recipe(data)
        except IdentificationError as exc:
            if not getattr(self, "_noise_weight", 1.0) < 1.0:
                raise
            first, clean_w = exc, self._noise_weight
        last = first
        try:
            ladder, same = self._refit_ladder(data, start, clean_w)
            for w in ladder:
                self.__dict__.clear()  # nothing a failed fit learned decides the refit's rules
                self.__dict__.update(start)
                self._refit_weight = w
                try:
                    return self._fit_recipe(data)
                except IdentificationError as exc:
                    last = exc
            skipped = (f"; {', '.join(f'{w:.3g}' for w in same)} change no setting the fit "
                       "already tried: not fitted again" if same else "")
            if not ladder:
                raise IdentificationError(f"{first} (the clean recipe's fit failed; the noisy "
                                          f"rule's weights{skipped[1:]})") from None
            tried = ", ".join(f"{w:.3g}" for w in ladder)
            raise IdentificationError(f"{first} (the clean recipe's fit failed and so did the "
                                      f"noisy rule's weights {tried}{skipped}; the last: "
                                      f"{last})") from None
        finally:
            self._refit_weight = 0.0

    def _refit_ladder(self, data: Measurement, start: dict[str, Any], clean_w: float
                      ) -> tuple[list[float], list[float]]:
        """The weights of ``REFIT_WEIGHTS`` above ``clean_w`` that :meth:`fit` fits again, and
        those it skips: a weight whose rule settings (:func:`noise_knobs`, with the settings
        the user fixed: ``start``, the instance before the first fit) equal those of a fit
        already tried would repeat that fit (review 28d M2: with the user's ``ridge`` and
        ``column_lowpass_hz`` the weights 0.25-0.75 move nothing, the tie band moves at 1)."""
        seen = []
        ladder, same = [], []
        for w in [clean_w, *(w for w in REFIT_WEIGHTS if w > clean_w)]:
            self.__dict__.clear()
            self.__dict__.update(start)
            knobs = self._rule_settings(data, w)[0]
            if any(_same_settings(knobs, k) for k in seen):
                same.append(w)
            else:
                seen.append(knobs)
                if w != clean_w:
                    ladder.append(w)
        self.__dict__.clear()
        self.__dict__.update(start)
        return ladder, same

    def _fit_recipe(self, data: Measurement) -> SINDyPI:
        """One fit under the noise rule; data the noise rule took for exact whose fit leaves a
        held-out error above ``EXACT_HOLDOUT_MAX`` are fitted again with the noisy recipe;
        a held-out choice that fails the replay rule, or finds no model for an input, is
        chosen again by rollout (:meth:`_replay_check`)."""
        self._smoothed = None
        self._replay = None
        self._unpruned = False
        self._record_finite = None
        self.formulation_rule_ = "not applied: the held-out selection found no model (replay rule)"
        try:
            super().fit(data)
        except NoModelError as exc:
            if not self._replay_rule_applies():
                raise
            self._pool_refit(data, np.inf, f"held-out selection: {exc}", None)
            return self
        except NoSimulationError as exc:
            # the record rule's second fit (_unpruned_refit) where not even the segments simulate
            if not self._unpruned_refit(data):
                raise IdentificationError(f"{exc} (nor over the unpruned library: "
                                          f"{self.record_rule_})") from None
            self._replay_check(data)
            self._open_chain_form(data)
            return self
        worst = float(np.max(self.validation_errors_))
        if (self.noise_rel_ <= NOISE_FREE_REL and self.column_lowpass_hz_ == 0.0
                and self.column_lowpass_hz is None and self.formulation_ == "strong"
                and worst > EXACT_HOLDOUT_MAX):
            self._smoothed = worst
            super().fit(data)
        self._unpruned_refit(data)
        self._replay_check(data)
        self._open_chain_form(data)
        return self

    def _open_chain_form(self, data: Measurement) -> None:
        """The open chain's form comparison (``formulation_rule_``): where the noise rule
        chose the strong form with rollout selection (rates a declared low-pass chain derived)
        on an open chain (a passive coordinate without a loop closure: a cart-pole), the fit is
        redone in the weak form (the rule's window, trim and ridge for it, as if the user had
        set ``formulation = "weak"``), and the weak fit is kept only if its chosen model's
        segmented rollout error (:meth:`_ImplicitMechanical._rollout_error`, ``rollout_segments``
        segments) over the span both fits keep (the larger of the two edge trims) is smaller
        than the strong one's beyond the rollout selection's tie: ``strong > weak (1 +
        selection_rtol) + ROLLOUT_ATOL``; a tie, a failed weak fit or a non-finite error keeps
        the strong one (the noise rule's form, and a margin no BLAS round-off crosses).

        Why: an open chain's free coordinate (the cart on its rail) integrates every error of
        its equation when simulated under the replayed force, so the strong form's errors in
        the chain-derived accelerations and in the column low-pass show as drift; the weak
        form integrates the acceleration terms by parts (no derivative of the noisy angles
        beyond the rates).  Neither form is better on every record (short records cap the weak
        form's test functions: family cart-pole cpchain__000 at 3 %, 4.3 s, weak 12.3 rad,
        strong 0.013), so the record decides by the same segmented rollout that chooses among
        each form's shortlist.  Measured 2026-11-27 on 80 cart-pole cells (rounds 6, 7, 9, 10,
        11, round 5's cpchain family at 0.5 / 1 / 3 %, cartpole_noise1 at 1 % seeds 0-4;
        benchmarks/unseen/round11/open_chain_form_members.tsv): within 0.0501 44 -> 60, none
        lost.  Closed chains (five-bars) never reach it.
        """
        self.formulation_rule_ = "not applied: " + (
            "formulation user-set" if self.formulation is not None else
            # a user's column low-pass is refused with the weak form (check_params)
            "column_lowpass_hz user-set" if self.column_lowpass_hz else
            "ensemble" if self.ensemble else
            "not the strong form with rollout selection" if not (
                getattr(self, "formulation_", None) == "strong" and self.selection is None
                and getattr(self, "selection_", None) == "rollout") else "")
        if self.formulation_rule_ != "not applied: ":
            return
        imap = np.abs(np.asarray(data.input_map)) > 0
        passive = np.flatnonzero(~imap.any(axis=1))
        if passive.size == 0 or closed_chain(data, passive):
            self.formulation_rule_ = ("not applied: no open chain (every coordinate actuated or a "
                                      "loop closure)")
            return
        segments = self._knob("rollout_segments")
        strong = dict(self.__dict__)
        trims = [self.edge_trim_]
        self._weak_trial = True
        try:
            self._fit_weak(data)
            trims.append(self.edge_trim_)
        except IdentificationError as exc:
            self.__dict__.clear()
            self.__dict__.update(strong)
            self.formulation_rule_ = f"open chain: the weak form's fit failed ({exc}): strong form kept"
            return
        finally:
            self._weak_trial = False
        weak = dict(self.__dict__)
        i0 = round(max(trims) * data.fs)
        weak_err = self._rollout_error(self.model_, data, i0, segments)
        self.__dict__.clear()  # nothing of the weak fit stays with the strong one
        self.__dict__.update(strong)
        strong_err = self._rollout_error(self.model_, data, i0, segments)
        head = (f"open chain, rates by a declared low-pass: segmented rollout over "
                f"[{max(trims):.3g} s, end - {max(trims):.3g} s] strong {strong_err:.4g}, "
                f"weak {weak_err:.4g}")
        # the rollout selection's tie (selection_rtol, ROLLOUT_ATOL) goes to the strong form
        if np.isfinite(weak_err) and strong_err > weak_err * (1 + self.selection_rtol) + ROLLOUT_ATOL:
            self.__dict__.clear()
            self.__dict__.update(weak)
            self.formulation_rule_ = f"{head}: weak form kept (smaller beyond the tie)"
        else:
            self.formulation_rule_ = f"{head}: strong form kept (the weak not smaller beyond the tie)"

    def _fit_weak(self, data: Measurement) -> None:
        """The weak-form fit of :meth:`_open_chain_form`: the fit of :meth:`fit` with the
        form set by that rule (the record rule's refit included), without the comparison."""
        self._smoothed = None
        self._replay = None
        self._unpruned = False
        self._record_finite = None
        try:
            super().fit(data)
        except NoSimulationError as exc:
            if not self._unpruned_refit(data):
                raise IdentificationError(f"{exc} (nor over the unpruned library)") from None
            return
        self._unpruned_refit(data)

    def _unpruned_refit(self, data: Measurement) -> bool:
        """The record rule's second fit (:meth:`_record_rule`): where no shortlisted
        combination of the rollout selection simulates the whole record (or not even its
        segments, :class:`NoSimulationError`), the fit is redone over
        the library without pruning (the replay rule's pool: on a record that leaves the
        equations non-unique the pruning takes its coincidental dependencies for kinematic
        identities, see :meth:`_replay_check`), and kept if one of its combinations replays
        the whole record nearer than rest, or, where none of the first fit's simulated the
        whole record at all, if one simulates it; else the first fit stays (whose record
        rule then excludes the combinations that diverge, as before the rest baseline; a
        scored failure, if it fails), unless the record rule's wider search
        (:meth:`_wide_record`) finds combinations among the first fit's ``WIDE_ROLLOUT`` best
        per input that replay the record.  Not when
        the user set ``prune_tol`` to None already or ``record_replay = False``.  Returns
        whether the unpruned fit, or the wider search's choice, was kept.
        Measured (2026-11-26): fbsine__010 (the paper's sine input on family geometry 010 at
        1 % noise, chain-derived rates): none of the pruned library's 9 pairs simulated the
        record (the scored model lost its loop at 5.4 s); the unpruned library's choice
        scored 7.2e-4 rad.
        """
        ok = getattr(self, "record_replays_", None)
        if (ok is None or ok.any() or self._knob("prune_tol") is None
                or getattr(self, "record_replay", None) is False):
            return False
        first = dict(self.__dict__)
        head = self.record_rule_
        self._unpruned = True
        try:
            super().fit(data)
        except IdentificationError as exc:
            self.__dict__.update(first)
            return self._wide_record(
                data, f"{head}; the unpruned library's fit failed ({exc})")
        finally:
            self._unpruned = False
        # kept where one of its combinations replays the record nearer than rest; or, where
        # none of the first fit's even simulated it, one simulates it (the divergence test)
        first_finite = first.get("_record_finite")
        never = first_finite is None or not np.any(first_finite)
        if not (self.record_replays_.any()
                or (never and np.any(getattr(self, "_record_finite", False)))):
            self.__dict__.update(first)
            return self._wide_record(data, f"{head}; none of the unpruned library's either")
        self.record_rule_ = f"{head}; fitted again over the unpruned library: {self.record_rule_}"
        return True

    def _wide_record(self, data: Measurement, head: str) -> bool:
        """The record rule's wider search, its last step: where neither the shortlist nor the
        unpruned library's (:meth:`_unpruned_refit`) holds a combination that replays the whole
        record (:meth:`_replays_record`: from its first measured state, without losing the loop
        closure, nearer the measured angles than rest), the first fit's ``WIDE_ROLLOUT`` best
        models per input are searched, nearest the top of the held-out ranking first
        (:func:`by_rank`), leaving out those the inertia rule excludes; the first combinations
        that replay the record, at most as many as the shortlist held, are scored by their
        segmented rollout and chosen among as the shortlist is (the tie rule, then fewer
        terms).  Sets ``record_rule_`` (``head`` and what the search found); returns whether
        a combination was adopted (else the first fit is kept, as before: its record rule's
        choice, which then fails its replay).  Closed chains only (the rest baseline is a
        closed chain's, :meth:`_replay_status`); not with ``ensemble`` (the bags' aggregate is
        none of the combinations compared).

        Why: the held-out ranking of a one-tone record (the paper's sine) does not order the
        equations by how they simulate; where its top ``n_rollout`` per input all lose the
        record, lower-ranked ones may hold it (``fbs41__009`` at 2 %, the paper's sine on a
        family geometry: the top 3 x 3 replay nothing, the ranks 4-6 replay the record with
        segmented rollouts of 2e-5 - 7e-5 rad against 0.002-0.016).  Measured (2026-11-28,
        session 20; benchmarks/heldout/wide_record_probe.py, table wide_record_members.tsv):
        249 five-bar cells (rounds 14-18's sine, sine-seed and multisine studies, round 18's
        seeds, benchmarks/heldout's sine studies, the three shipped five-bars with estimated
        rates), 218 -> 223 passes, none lost; reached on 23: F -> P ``fb15_cranks_1p3_0p7_20s``
        1 % s61 / 2 % s64 (diverged at 12.07 / 3.32 s -> 0.0034 rad), ``fb15_cranks_0p8_1p5_3s``
        2 % s63 (0.32 s -> 0.017), ``fb18_30s`` 4 % (6.34 s -> 0.0012), ``fbs41__009`` 2 %
        (4.27 s -> 0.0015); passes moved 0.018 -> 0.0013 (``fb14_cranks_2p2`` 2 % s52),
        0.040 -> 0.0052 (``fb15_cranks_1p6_1_5s`` 2 % s63), 0.024 -> 0.0039, 0.0045 -> 0.0016;
        14 unchanged (none of the wider search's pairs replays: first fit kept).  Cost: one
        simulation of the record per pair searched, in this branch only (``fb18_30s``: 8.9 ->
        17.2 s of CPU).
        """
        ctx = getattr(self, "_wide_ctx", None)
        why = ("ensemble" if self.ensemble else "no rollout selection" if ctx is None
               else "an open chain" if getattr(self, "closure_", None) is None
               else "off for this identifier" if not self._wide_record_on else "")
        if why:
            self.record_rule_ = f"{head}: first fit kept (no wider search: {why})"
            return False
        state = dict(self.__dict__)
        self.__dict__.pop("sim_dt_", None)  # the rollout selection's step (SIM_DT_START)
        lib, sw = self._library_, ctx.sweep
        extra = by_rank(select_models(sw, ctx.loc_cols, self.selection_rtol, self.selection_atol,
                                      WIDE_ROLLOUT), ctx.seen)

        def build(choice: tuple) -> np.ndarray:
            coef = np.zeros((len(choice), len(lib)))
            for r, (t, c) in enumerate(choice):
                coef[r, ctx.kidx] = sw.coef(t, c)
            return coef

        found, models, excluded = [], [], 0
        judge = None
        for c in extra:
            m = ImplicitModel(lib, build(c), ctx.solved, self.closure_)
            if self._inertia_rule_on:
                if judge is None:
                    try:
                        judge = self._inertia_judge(data, m)
                    except IdentificationError:
                        judge = lambda ms: (np.ones(len(ms), dtype=bool), [], "no closure")  # noqa: E731
                keep, _, no = judge([m])
                if not no and not keep[0]:
                    excluded += 1
                    continue
            if self._replays_record(m, data):
                found.append(c)
                models.append(m)
                if len(found) >= ctx.n_short:
                    break
        searched = (f"the {WIDE_ROLLOUT} best per input searched ({len(extra)} more "
                    f"combinations, {excluded} excluded by the inertia rule)")
        scores = [self._rollout_error(m, data, ctx.i0, self._knob("rollout_segments"))
                  for m in models]
        if not np.isfinite(min(scores, default=np.inf)):
            self.__dict__.clear()
            self.__dict__.update(state)
            self.record_rule_ = f"{head}; {searched}: none replays the record: first fit kept"
            return False
        size = [sum(int(sw.nnz[t, c]) for t, c in cb) for cb in found]
        ok = np.array(scores) <= min(scores) * (1 + self.selection_rtol) + ROLLOUT_ATOL
        chosen = min(np.flatnonzero(ok), key=lambda i: (size[i], scores[i]))
        self.coef_ = build(found[chosen])
        self.rollout_rmse_ = float(scores[chosen])
        self.record_replays_ = np.ones(len(found), dtype=bool)
        self._record_finite = self.record_replays_
        self._adopt(list(found[chosen]), sw, ctx.kidx, ctx.solved, data)
        self.record_rule_ = (f"{head}; {searched}: the first {len(found)} that replay the record "
                             f"scored, chosen by rollout: {self.rollout_rmse_:.3g} rad")
        return True

    def _replay_rule_applies(self) -> bool:
        """The noise rule (not the user) chose the held-out selection, for the strong form,
        without ensembling (the bags' aggregate is none of the models a rollout compares)."""
        return (self.selection is None and self.selection_ == "holdout" and self._smoothed is None
                and self.formulation_ == "strong" and not self.ensemble)

    def _replay_check(self, data: Measurement) -> None:
        """The replay rule: a held-out choice's model must replay the record; else the
        equations are chosen again by rollout.  Sets ``replay_rmse_`` and ``replay_rule_``.

        Rule: where the noise rule chose the held-out selection (exact data, or noisy angles
        with recorded rates; the user set no ``selection``) for the strong form, the chosen
        equations are simulated over the trimmed record from its measured first state
        (:meth:`_rollout_error`, one segment).  An RMSE above ``EXACT_REPLAY_MAX +
        REPLAY_NOISE_FACTOR * noise_std`` (the largest channel's white-noise std,
        ``noise_std_``) says the record left the equations non-unique (several fit the rates
        to the noise or round-off, and the held-out error cannot tell the one whose
        simulation holds); so does a held-out fit that finds no model for some input (every
        candidate of the pruned library carries another input more).  The fit is then
        redone with ``selection="rollout"`` over the library without pruning (on such a
        record the pruning takes the record's coincidental dependencies for kinematic
        identities, so the kept columns cannot express the true equations off the record),
        the ``n_rollout`` best models per input by held-out error, each pair simulated over
        the trimmed record in one segment (its drift, which segments hide).  The first fit
        is kept unless the second replays better beyond the rollout selection's tie rule
        (``selection_rtol``, ``ROLLOUT_ATOL``; :meth:`_pool_refit`).
        """
        self.replay_rmse_ = None
        self.replay_rule_ = ("no replay check (models not chosen by held-out error by the rule, "
                             "or ensembled)")
        if not self._replay_rule_applies():
            return
        err = self._rollout_error(self.model_, data, round(self.edge_trim_ * data.fs), 1)
        self.replay_rmse_ = err
        sigma = float(np.max(self.noise_std_, initial=0.0))
        bar = EXACT_REPLAY_MAX + REPLAY_NOISE_FACTOR * sigma
        head = (f"held-out selection: replay of the record {err:.3g} rad (<= {bar:.3g} required: "
                f"{EXACT_REPLAY_MAX:g} + {REPLAY_NOISE_FACTOR:g} x noise std {sigma:.3g})")
        if err <= bar:
            self.replay_rule_ = f"{head}: kept"
            return
        self._pool_refit(data, err, head, dict(self.__dict__))

    def _pool_refit(self, data: Measurement, err: float, head: str,
                    first: dict[str, Any] | None) -> None:
        """The replay rule's second fit (see :meth:`_replay_check`); ``first`` is the first
        fit's state (None: it found no model), kept unless ``err`` [rad], its replay, exceeds
        the second's by more than the tie rule; where it does not, or the second fit fails,
        the damped refit (:meth:`_damped_refit`) is tried before the first fit is kept."""
        self._replay = err
        try:
            super().fit(data)
            # the second model's replay at its own chosen step (``sim_dt_``, the step the user's
            # simulation takes), as ``err`` is the first's: the rollout selection ranked its
            # candidates at SIM_DT_START, and where the step rule then chose a finer step the
            # ranking's RMSE is not this model's replay (fb_sine__004 clean: 9.832e-4 rad at
            # 1 ms against 9.819e-4 at the chosen 0.05 ms)
            again = self._rollout_error(self.model_, data, round(self.edge_trim_ * data.fs), 1)
            why = ""
        except IdentificationError as exc:
            if first is None and not self._damped_refit(data, err, head, np.inf):
                raise IdentificationError(f"{head}; the replay rule's rollout over the unpruned "
                                          f"library failed too: {exc}") from exc
            if first is None:
                return
            again, why = np.inf, f" ({exc})"
        # the rollout selection's tie rule: the first fit (the held-out choice) wins ties
        if (not err > again * (1 + self.selection_rtol) + ROLLOUT_ATOL
                and self._damped_refit(data, err, head, again)):
            return
        if first is not None and not err > again * (1 + self.selection_rtol) + ROLLOUT_ATOL:
            self.__dict__.update(first)
            self.replay_rule_ = (f"{head}: equations non-unique on this record; rollout over "
                                 f"the unpruned library replayed no better, within the tie rule "
                                 f"({again:.3g} rad{why}): first fit kept")
            return
        self.replay_rmse_ = again
        self.replay_rule_ = (f"{head}: equations non-unique on this record; chosen again by "
                             f"rollout over the trimmed record among the unpruned library's "
                             f"{self.n_rollout} best per input: {again:.3g} rad")

    def _damped_ridge(self) -> float | None:
        """The damped refit's ridge: ``UNPRUNED_RIDGE_PER_TOL * prune_tol`` where it exceeds the
        noise rule's; None where the user set ``ridge`` or ``prune_tol = None``, or it does not."""
        if self.ridge is not None or self.prune_tol is None:
            return None
        floor = UNPRUNED_RIDGE_PER_TOL * self.prune_tol
        return floor if floor > self.ridge_ else None

    def _damped_refit(self, data: Measurement, err: float, head: str, again: float) -> bool:
        """The replay rule's damped refit: where the unpruned library's fit at the noise rule's
        ridge replayed no better than the first fit (``again`` [rad] against ``err``, by the
        tie rule; inf: it failed), it is fitted again with the ridge
        :meth:`_damped_ridge` (see ``UNPRUNED_RIDGE_PER_TOL``) and kept (True) if its replay
        beats ``err`` beyond the tie rule; else nothing of it stays (False)."""
        damped = self._damped_ridge()
        if damped is None:
            return False
        state = dict(self.__dict__)
        self._damped = True
        try:
            super().fit(data)
            new = self._rollout_error(self.model_, data, round(self.edge_trim_ * data.fs), 1)
        except IdentificationError:
            new = np.inf
        finally:
            self._damped = False
        if not err > new * (1 + self.selection_rtol) + ROLLOUT_ATOL:
            self.__dict__.clear()
            self.__dict__.update(state)
            return False
        self.replay_rmse_ = new
        self.replay_rule_ = (f"{head}: equations non-unique on this record; rollout over the "
                             f"unpruned library at the rule's ridge replayed no better "
                             f"({again:.3g} rad); chosen again by rollout with ridge {damped:.3g} "
                             f"among its {self.n_rollout} best per input: {new:.3g} rad")
        return True

    def _sweep(self, G_train, G_val, cand, Theta_train):
        thr = DEFAULT_THRESHOLDS if self.thresholds is None else np.asarray(self.thresholds)
        return stlsq_sweep(G_train, G_val, cand, thr, self._knob("ridge"), self.max_iter)
