"""SINDy-PI (Kaheman, Kutz & Brunton 2020) on one shared Gram matrix.

For every candidate left-hand-side term j a sparse regression ``Theta_j ~ Theta_{-j} xi`` by
sequentially thresholded least squares over a sweep of thresholds.  All candidates share one
Gram matrix ``G = Theta^T Theta``: first solutions from one inverse, thresholded refits as one
batched solve per round (:func:`identify._implicit.stlsq_sweep`), held-out errors from the
validation Gram matrix.  No per-candidate convex solver and no pass over the samples after the
Gram matrices are formed.

Model selection (``selection="holdout"``): the last ``val_fraction`` of the record (in time)
is held out, as the SINDy-PI authors do.  One implicit equation is picked per input (= per
actuated coordinate, the row of ``input_map`` the input acts on): the model whose input-k terms
dominate every other input's, with the fewest terms among those whose normalised held-out
residual is within tolerance of the best (:func:`identify._implicit.select_models`).
``selection="rollout"`` shortlists ``n_rollout`` such models per input and keeps the
combination whose free simulation over the validation window has the smallest angle RMSE.

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

from collections.abc import Sequence
from itertools import product
from typing import Any

import numpy as np

from identify import IDENTIFIERS
from identify._base import Identifier
from identify._implicit import DEFAULT_THRESHOLDS, Sweep, grams, select_models, split_index, stlsq_sweep
from identify._mechsim import CLOSURE_RTOL, ImplicitModel, LoopClosure
from identify._weak import weak_matrix
from identify.library import Library, fivebar_library, generic_mechanical_library
from testbed.errors import IdentificationError
from testbed.gram import normalized_gram, ordered_independent
from testbed.measurement import Measurement, Trajectory
from testbed.signal import lowpass

#: Rollout angle-RMSE differences below 1e-4 rad [rad] count as ties (then fewer terms win):
#: far below the 0.05 rad the paper reports and below what chaos-sensitive rollouts resolve.
ROLLOUT_ATOL = 1e-4


def make_library(spec: Any, data: Measurement) -> Library:
    """``"fivebar"``, ``"fivebar_full"``, ``"generic"``, a Library, or a list of term names."""
    n_in = 0 if data.u is None else data.u.shape[0]
    if isinstance(spec, Library):
        return spec
    if spec == "fivebar":
        return fivebar_library(n_inputs=n_in)
    if spec == "fivebar_full":
        return fivebar_library(kind="full", n_inputs=n_in)
    if spec == "generic":
        return generic_mechanical_library(data.n_channels, n_in)
    if isinstance(spec, Sequence) and not isinstance(spec, str):
        return Library(list(spec), data.n_channels, n_in)
    raise ValueError(f"library must be 'fivebar', 'fivebar_full', 'generic', a Library or a list "
                     f"of term names, got {spec!r}")


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


def find_closure(data: Measurement, passive: np.ndarray) -> LoopClosure | None:
    """Loop closure for the passive coordinates: prior (b) if it fits the data, else fitted (a).

    The declared prior is used if it closes the measured loop to ``CLOSURE_RTOL`` (largest
    error) or, on noisy angles, if its RMS closure error is within twice that of the
    least-squares closure fitted to the same angles (the noise floor: any closure, the true one
    included, leaves that much).  A wrong convention or a link length wrong by a few percent
    leaves an error of that order, far above the floor of smoothed angles (~1e-3).
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
        cl = LoopClosure.from_data(data.x, passive)
    except IdentificationError as exc:
        raise IdentificationError(f"{exc}{note}") from exc
    cl.source += note
    return cl


class _ImplicitMechanical(Identifier):
    """Fit pipeline shared by SINDy-PI and the pysindy wrapper; subclasses supply _sweep."""

    kind = "mechanical"

    def _sweep(self, G_train: np.ndarray, G_val: np.ndarray, cand: np.ndarray,
               Theta_train: np.ndarray) -> Sweep:
        raise NotImplementedError

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
        Theta = lib.evaluate(x, xd, xdd, data.u)
        if self.column_lowpass_hz:
            Theta = lowpass(np.ascontiguousarray(Theta.T), data.fs, self.column_lowpass_hz,
                            self.column_lowpass_order).T
        i0 = round(self.edge_trim * data.fs)
        if i0:
            if 2 * i0 >= data.n_samples:
                raise IdentificationError(f"edge_trim {self.edge_trim} s leaves no samples")
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
        form = getattr(self, "formulation", "strong")
        if form == "strong":
            Theta, i0 = self._library_matrix(lib, data)
            n_tr = split_index(Theta.shape[0], self.val_fraction)
            return Theta, n_tr, i0, i0 + n_tr
        if form != "weak":
            raise ValueError(f"formulation must be 'strong' or 'weak', got {form!r}")
        if self.column_lowpass_hz:
            raise ValueError("column_lowpass_hz applies to the strong form only (the weak form's "
                             "test functions filter; integration by parts needs unfiltered columns)")
        x, xd, xdd = data.x, data.xd, data.xdd
        if self.reconcile and self.closure_ is not None:
            x, xd, xdd = self.closure_.reconcile(x, xd, xdd)
        i0 = round(self.edge_trim * data.fs)
        n = data.n_samples - 2 * i0
        if n < 2:
            raise IdentificationError(f"edge_trim {self.edge_trim} s leaves no samples")
        sl = slice(i0, data.n_samples - i0)
        u = None if data.u is None else data.u[:, sl]
        xdd = None if xdd is None else xdd[:, sl]
        wf = weak_matrix(lib, x[:, sl], xd[:, sl], xdd, u, data.fs, self.weak_window_s,
                         self.weak_n_windows, self.weak_degree)
        split = split_index(n, self.val_fraction)
        tr = wf.starts + wf.length <= split
        va = wf.starts >= split
        if tr.sum() < 2 or va.sum() < 2:
            raise IdentificationError(f"{tr.sum()} training and {va.sum()} validation windows: "
                                      "shorten weak_window_s or add weak_n_windows")
        self.weak_strong_columns_ = wf.strong_columns
        return np.concatenate([wf.V[tr], wf.V[va]]), int(tr.sum()), i0, i0 + split

    def fit(self, data: Measurement) -> _ImplicitMechanical:
        if data.u is None or data.input_map is None:
            raise IdentificationError(f"{self.name} needs measured inputs and their input_map")
        imap = np.abs(np.asarray(data.input_map)) > 0
        actuated = np.array([int(np.argmax(imap[:, k])) for k in range(imap.shape[1])])
        passive = np.flatnonzero(~imap.any(axis=1))
        self.closure_ = find_closure(data, passive)
        lib = make_library(self.library, data)
        Theta, n_tr, i0, v0 = self._regression_matrix(lib, data)
        G_tr, G_v = grams(Theta, n_tr)
        in_cols = [lib.input_columns(k) for k in range(data.u.shape[0])]
        has_u = np.zeros(len(lib), dtype=bool)
        has_u[np.concatenate(in_cols)] = True
        keep = np.ones(len(lib), bool)
        if self.prune_tol is not None:
            keep = prune_dependent(G_tr + G_v, has_u, self.prune_tol)
        kidx = np.flatnonzero(keep)
        self.pruned_terms_ = [lib.names[c] for c in np.flatnonzero(~keep)]
        names = [lib.names[c] for c in kidx]
        if self.lhs is None:
            cand = np.arange(kidx.size)
        else:
            pos = {n: i for i, n in enumerate(names)}
            wanted = Library(list(self.lhs), lib.n_coords, lib.n_inputs).names
            missing = [w for w in wanted if w not in pos]
            if missing:
                raise IdentificationError(f"lhs terms not in the (pruned) library: {missing}")
            cand = np.array([pos[w] for w in wanted])
        sw = self._sweep(G_tr[np.ix_(kidx, kidx)], G_v[np.ix_(kidx, kidx)], cand,
                         Theta[:n_tr][:, kidx])
        loc_cols = [np.flatnonzero(np.isin(kidx, c)) for c in in_cols]
        top = self.n_rollout if self.selection == "rollout" else 1
        if self.selection not in ("holdout", "rollout"):
            raise ValueError(f"selection must be 'holdout' or 'rollout', got {self.selection!r}")
        picks = select_models(sw, loc_cols, self.selection_rtol, self.selection_atol, top)
        self.feature_names_ = list(lib.names)
        self.actuated_ = actuated
        self._library_ = lib

        def build(choice):
            coef = np.zeros((len(choice), len(lib)))
            for r, (t, c) in enumerate(choice):
                coef[r, kidx] = sw.coef(t, c)
            return coef

        best = [p[0] for p in picks]
        if self.selection == "rollout":
            sl = slice(v0, data.n_samples - i0)
            scores = []
            for combo in product(*picks):
                try:
                    m = ImplicitModel(lib, build(combo), actuated, self.closure_)
                    tr = m.simulate(data.x[:, v0], data.xd[:, v0], data.t[sl], data.u[:, sl],
                                    self.sim_dt, self.input_hold)
                    scores.append(float(np.sqrt(np.mean((tr.x - data.x[:, sl]) ** 2))))
                except IdentificationError:
                    scores.append(np.inf)
            if not np.isfinite(min(scores)):
                raise IdentificationError("no shortlisted model combination could be simulated")
            combos = list(product(*picks))
            size = [sum(int(sw.nnz[t, c]) for t, c in cb) for cb in combos]
            ok = np.array(scores) <= min(scores) * (1 + self.selection_rtol) + ROLLOUT_ATOL
            best = list(combos[min(np.flatnonzero(ok), key=lambda i: (size[i], scores[i]))])
            self.rollout_rmse_ = float(scores[combos.index(tuple(best))])
        self.coef_ = build(best)
        self.lhs_terms_ = [names[sw.candidates[c]] for _, c in best]
        self.selected_thresholds_ = np.array([sw.thresholds[t] for t, _ in best])
        self.validation_errors_ = np.array([sw.val_error[t, c] for t, c in best])
        self.sweep_ = sw
        self.model_ = ImplicitModel(lib, self.coef_, actuated, self.closure_)
        return self

    def simulate(self, x0: np.ndarray, xd0: np.ndarray, t: np.ndarray,
                 u: np.ndarray | None = None) -> Trajectory:
        """Free simulation from (x0, xd0) under inputs u (n_inputs, len(t)) at times t [s]."""
        if not hasattr(self, "model_"):
            raise IdentificationError(f"{self.name}: fit before simulate")
        return self.model_.simulate(x0, xd0, t, u, self.sim_dt, self.input_hold)

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
        Candidate left-hand-side terms; default every (kept) column.
    thresholds : sequence of float, optional
        Ascending thresholds on normalised coefficients; default 0 and 12 values log-spaced
        over 1e-6..0.32.
    ridge : float
        Ridge added to the unit-diagonal normalised Gram matrix (see ``stlsq_sweep``).
    max_iter : int
        Thresholding rounds per threshold.
    val_fraction : float
        Held-out fraction at the end of the record.
    selection : {"holdout", "rollout"}
    selection_rtol, selection_atol : float
        Held-out error tolerances of the parsimony rule (see ``select_models``).
    n_rollout : int
        Models shortlisted per input for ``selection="rollout"``.
    prune_tol : float or None
        Residual variance (of a unit-norm column) below which an input-free column counts as a
        combination of earlier ones; 1e-9 (residual norm 3e-5) catches exact kinematic
        identities on clean data and leaves independent terms alone.  None disables.
    sim_dt : float
        RK4 step of the simulation [s]; 1e-3 s resolves motions up to ~20 Hz to 1e-8 (RK4
        error ~ (h w)^4 / 120).
    reconcile : bool
        Replace the passive angles, rates and accelerations by those the loop closure implies
        from the actuated ones before building the library
        (:meth:`identify._mechsim.LoopClosure.reconcile`).  No effect on exact data; on noisy
        angles it restores the exact kinematic identities, so ``prune_tol`` can remove them.
    column_lowpass_hz : float or None
        Cut-off [Hz] of a zero-phase Butterworth low-pass applied to every library column
        before the regression (None: off).  The equations hold for filtered columns exactly
        (one linear filter for all), while the noise of estimated derivatives, broadband, is
        cut; set it above the band of the motion's products (the implicit equations need
        excitation, not fidelity to the raw signals).
    column_lowpass_order : int
        Order of that filter (one pass).
    edge_trim : float
        Seconds dropped at each end of the record before the regression (edge effects of the
        derivative estimate and of the column filter); 0 keeps every sample.
    input_hold : {"linear", "zoh"}
        What the sampled inputs stand for in simulations: a continuous signal or a zero-order
        hold (see :meth:`identify._mechsim.ImplicitModel.simulate`).  Actuators driven by a
        DAC (the five-bar rig) hold; the wrong choice costs an impulse of half a sample.
    formulation : {"strong", "weak"}
        ``"strong"``: one regression row per sample of the library.  ``"weak"``: one row per
        test function, ``int phi_k Theta dt`` (:func:`identify._weak.weak_matrix`), with the
        acceleration terms integrated by parts so that only angles and rates enter (no second
        derivative of noisy angles); the held-out split is by time windows (windows
        straddling the split are dropped).  ``column_lowpass_hz`` must then be None.
    weak_window_s : float
        Support of each test function [s] (weak form); a few times the shortest period of
        the motion's products is a good start (1 s on the five-bar's 0.1-1.5 Hz multisine).
    weak_n_windows : int
        Number of equally spaced, overlapping test functions over the trimmed record.
    weak_degree : int
        Exponent p of the test function ``(1 - s^2)^p`` (>= 2).

    Attributes
    ----------
    coef_ : ndarray, shape (n_inputs, n_terms)
        One implicit equation per input, scaled to max |coef| = 1, the first non-negligible term
        in library order positive (:func:`identify._implicit.canonical_scale`).
    feature_names_, lhs_terms_, selected_thresholds_, validation_errors_, pruned_terms_,
    closure_, sweep_, model_
    weak_strong_columns_ : list of str
        Weak form only: acceleration terms integrated with the measured accelerations (no
        exact integration by parts; :class:`identify._weak.WeakForm`).
    """

    name = "sindy_pi"

    def __init__(self, library: Any = "fivebar", lhs: Sequence[str] | None = None,
                 thresholds: Sequence[float] | None = None, ridge: float = 1e-14, max_iter: int = 20,
                 val_fraction: float = 0.2, selection: str = "holdout", selection_rtol: float = 0.1,
                 selection_atol: float = 1e-12, n_rollout: int = 3, prune_tol: float | None = 1e-9,
                 sim_dt: float = 1e-3, reconcile: bool = True,
                 column_lowpass_hz: float | None = None, column_lowpass_order: int = 4,
                 edge_trim: float = 0.0, input_hold: str = "linear", formulation: str = "strong",
                 weak_window_s: float = 0.5, weak_n_windows: int = 400, weak_degree: int = 4):
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

    def _sweep(self, G_train, G_val, cand, Theta_train):
        thr = DEFAULT_THRESHOLDS if self.thresholds is None else np.asarray(self.thresholds)
        return stlsq_sweep(G_train, G_val, cand, thr, self.ridge, self.max_iter)
