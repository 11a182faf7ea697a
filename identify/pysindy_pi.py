"""pysindy 2.1.0's ``SINDyPI`` optimiser behind our interface, on our library matrix.

The optimiser solves, for every candidate column j, the convex problem
``min ||Theta_j - Theta xi||^2 + lambda ||xi||_1`` s.t. ``xi_j = 0`` with cvxpy (one OSQP
problem per column, each carrying all samples).  We call its ``fit`` directly on the identical
library matrix our :class:`~identify.sindy_pi.SINDyPI` uses (no ``ps.SINDy`` wrapper, so no
second library build), with ``normalize_columns=False`` (its rescaling is wrong in 2.1.0;
``normalize=True`` divides the columns by their norms ourselves instead), then
run the same model selection (one equation per input, held-out error and parsimony) and the
same simulation.  Its result is one model per candidate (a single ``reg_weight_lam``).

``qr=True`` feeds the p x p factor R of ``Theta_train = Q R`` instead of the samples: the
objective is identical (``||Q (R_j - R xi)||^2 = ||R_j - R xi||^2``) and each problem is p x p.

Failures are errors, not zeros: pysindy 2.1.0 turns an infeasible or failed cvxpy solve into
zero (or NaN) coefficients with at most a warning; we raise
:class:`~testbed.core.errors.IdentificationError` naming the candidates concerned.
"""

from __future__ import annotations

import contextlib
import io
import math
import warnings
from collections.abc import Sequence
from typing import Any, ClassVar

import numpy as np

from identify import IDENTIFIERS
from identify._implicit import Sweep, _errors
from identify.sindy_pi import COMMON_HYPERPARAMETERS, _ImplicitMechanical, ordered_fields
from testbed.core.errors import IdentificationError
from testbed.core.schema import Field, KeyUse

#: Training samples pysindy's SINDyPI is given when ``stride`` is left to the rule: one OSQP
#: problem per candidate, each carrying every sample.  Measured on fivebar_multisine (32
#: candidates, 80,000 training samples, shared 2-core machine): every 10th sample (8,000)
#: fits in 23 s; all 80,000 ran past 4 min (and past 10 min before) without finishing.
PYSINDY_MAX_SAMPLES = 8000


def stride_rule(n_train: int, stride: int | None, qr: bool) -> tuple[int, str]:
    """The training-sample stride given to pysindy, and the rule that chose it.

    Parameters
    ----------
    n_train : int
        Training rows of the library matrix.
    stride : int or None
        The user's stride (kept as given), or None for the rule.
    qr : bool
        Whether pysindy is fed the p x p R factor (then every sample counts, whatever the
        stride).

    Returns
    -------
    (stride, rule)
        The stride (>= 1) and a sentence saying why.
    """
    if qr:
        return 1, "qr: pysindy gets the p x p R factor of every training sample (no stride)"
    if stride is not None:
        return int(stride), f"user-set: 1 in {int(stride)} of {n_train} training samples"
    chosen = max(1, math.ceil(n_train / PYSINDY_MAX_SAMPLES))
    return chosen, (f"rule: 1 in {chosen} of {n_train} training samples, at most "
                    f"{PYSINDY_MAX_SAMPLES} (one OSQP problem per candidate carries them all)")


def pysindy_pi_coef(X: np.ndarray, cand: np.ndarray, reg_weight_lam: float, tol: float,
                    max_iter: int) -> np.ndarray:
    """Run pysindy's SINDyPI on the rows of X; return xi (len(cand), p), row c the model of cand[c].

    Raises
    ------
    IdentificationError
        If the optimiser raises, warns of an infeasible solve, or returns non-finite or
        all-zero coefficients for any candidate.
    """
    import pysindy as ps  # local: importing pysindy costs ~1 s

    opt = ps.SINDyPI(reg_weight_lam=reg_weight_lam, tol=tol, max_iter=max_iter,
                     model_subset=[int(c) for c in cand], normalize_columns=False)
    with warnings.catch_warnings(record=True) as caught, contextlib.redirect_stdout(io.StringIO()):
        warnings.simplefilter("always")
        try:
            opt.fit(X, X[:, int(cand[0])])  # y is unused by SINDyPI._reduce; one column keeps
        except Exception as exc:            # the initial lstsq of BaseOptimizer.fit cheap
            raise IdentificationError(f"pysindy SINDyPI failed: {exc}") from exc
    bad_warn = [str(w.message) for w in caught if "nfeasible" in str(w.message)]
    xi = np.asarray(opt.coef_, dtype=float)[cand]
    # "zero": no coefficient contributes 1e-8 of the left-hand side's norm (OSQP's tolerance
    # is 1e-5, so a genuine model is far above this); this also catches zero columns
    s = np.linalg.norm(X, axis=0)
    contrib = np.abs(xi) * s[None, :]
    finite = np.all(np.isfinite(xi), axis=1)
    bad = np.flatnonzero(~finite | (np.nan_to_num(contrib).max(axis=1) <= 1e-8 * s[cand]))
    if bad.size or bad_warn:
        raise IdentificationError(f"pysindy SINDyPI returned zero/NaN coefficients for candidate "
                                  f"columns {cand[bad].tolist()} {bad_warn[:2]}")
    return xi


@IDENTIFIERS.register("pysindy_pi", tags=("mechanical", "implicit", "baseline"))
class PySINDyPI(_ImplicitMechanical):
    """pysindy's SINDyPI (cvxpy/OSQP, L1) with our library, selection and simulation.

    Parameters
    ----------
    library, lhs, val_fraction, selection, selection_rtol, selection_atol, n_rollout,
    rollout_segments, prune_tol, sim_dt, reconcile, column_lowpass_hz, column_lowpass_order,
    edge_trim, input_hold
        As :class:`~identify.sindy_pi.SINDyPI`.
    reg_weight_lam : float
        L1 weight of pysindy's objective.  1e-6 is the value of pysindy's SINDy-PI example; on
        unit-norm columns pysindy's default 0.1 shrinks the coefficients by ~100 % (measured on
        the double pendulum, 10k x 20) and 1e-3 by ~2 %.
    tol : float
        OSQP absolute and relative tolerance (pysindy's default 1e-5).
    max_iter : int
        OSQP iteration limit (pysindy's default 10000).
    qr : bool
        Feed the p x p R factor of the training library matrix instead of the samples.
    normalize : bool
        Divide the columns by their training norms before the optimiser (and read the
        coefficients back in those units) instead of pysindy's ``normalize_columns``, whose
        rescaling is wrong in 2.1.0.  The L1 weight then acts on normalised coefficients.
        Measured: on raw columns spanning 43..8200 in norm (double pendulum, 10k x 20), OSQP
        declares several candidates infeasible; normalised, every candidate solves.
    support_tol : float
        A coefficient counts as nonzero if above ``support_tol`` times the row's largest
        (L1 via OSQP gives no exact zeros); 0 keeps pysindy's result as it is.
    stride : int or None
        Give pysindy every ``stride``-th training sample only (its cost grows with the samples:
        one OSQP problem per candidate, each carrying all of them).  The held-out selection
        still uses every sample.  None (default): the rule :func:`stride_rule`, at most
        :data:`PYSINDY_MAX_SAMPLES` samples; 1 gives it all; ignored with ``qr=True``, whose
        problems are p x p whatever the samples.

    Attributes
    ----------
    stride_ : int
        The stride used.
    stride_rule_ : str
        Why (user-set, the rule, or ``qr``).
    """

    name = "pysindy_pi"
    deterministic = True  # OSQP, single-threaded; refitted to the bit in test_conformance
    hyperparameters: ClassVar[dict[str, Field]] = ordered_fields({
        **COMMON_HYPERPARAMETERS,
        "reg_weight_lam": Field(float, 1e-6, min=0.0, doc="L1 weight of pysindy's objective"),
        # OSQP's tolerances are relative and absolute: above 1 they accept anything
        "tol": Field(float, 1e-5, min=0.0, min_inclusive=False, max=1.0,
                     doc="OSQP absolute and relative tolerance"),
        # 1e6: 100x pysindy's default; each iteration of 32 problems costs milliseconds
        "max_iter": Field(int, 10000, min=1, max=1000000, doc="OSQP iteration limit"),
        "qr": Field(bool, False, doc="feed the p x p R factor instead of the samples"),
        "normalize": Field(bool, True, doc="divide the columns by their training norms first"),
        # [0, 1): relative to the row's largest coefficient; 1 would keep none but it
        "support_tol": Field(float, 0.0, min=0.0, max=1.0, max_inclusive=False,
                             doc="coefficients above support_tol times the row's largest count "
                                 "as nonzero"),
        "stride": Field(int, None, min=1,
                        doc="give pysindy every stride-th training sample; none = at most "
                            f"{PYSINDY_MAX_SAMPLES} samples (the rule, stride_rule_)"),
    }, (
        "library", "lhs", "reg_weight_lam", "tol", "max_iter", "qr", "normalize", "support_tol",
        "stride", "val_fraction", "selection", "selection_rtol", "selection_atol", "n_rollout",
        "rollout_segments", "prune_tol", "sim_dt", "reconcile", "column_lowpass_hz",
        "column_lowpass_order", "edge_trim", "input_hold"))  # __init__ order, for the guide
    #: Keys the fit reads only under another setting (benchmarks/hostile10.py ``combos``:
    #: ``rollout_segments = 3`` under the held-out selection fitted the same model to the bit;
    #: so did ``n_rollout = 5`` there, and ``stride = 7`` with ``qr``, on the double pendulum).
    used_when: ClassVar[dict[str, KeyUse]] = {
        "rollout_segments": KeyUse("selection", lambda v: v == "rollout", "selection = 'rollout'"),
        "n_rollout": KeyUse("selection", lambda v: v == "rollout", "selection = 'rollout'"),
        "stride": KeyUse("qr", lambda v: not v, "qr = false (the R factor carries every sample)"),
    }

    def __init__(self, library: Any = "fivebar", lhs: Sequence[str] | None = None,
                 reg_weight_lam: float = 1e-6, tol: float = 1e-5, max_iter: int = 10000,
                 qr: bool = False, normalize: bool = True, support_tol: float = 0.0,
                 stride: int | None = None,
                 val_fraction: float = 0.2,
                 selection: str = "holdout", selection_rtol: float = 0.1,
                 selection_atol: float = 1e-12, n_rollout: int = 3, rollout_segments: int = 6,
                 prune_tol: float | None = 1e-9, sim_dt: float | None = None, reconcile: bool = True,
                 column_lowpass_hz: float | None = None, column_lowpass_order: int = 4,
                 edge_trim: float = 0.0, input_hold: str | None = None):
        self.library = library
        self.lhs = lhs
        self.reg_weight_lam = reg_weight_lam
        self.tol = tol
        self.max_iter = max_iter
        self.qr = qr
        self.normalize = normalize
        self.support_tol = support_tol
        self.stride = stride
        self.val_fraction = val_fraction
        self.selection = selection
        self.selection_rtol = selection_rtol
        self.selection_atol = selection_atol
        self.n_rollout = n_rollout
        self.rollout_segments = rollout_segments
        self.prune_tol = prune_tol
        self.sim_dt = sim_dt
        self.reconcile = reconcile
        self.column_lowpass_hz = column_lowpass_hz
        self.column_lowpass_order = column_lowpass_order
        self.edge_trim = edge_trim
        self.input_hold = input_hold

    def _sweep(self, G_train, G_val, cand, Theta_train):
        s = np.sqrt(np.clip(np.diag(G_train), 1e-300, None))
        X = Theta_train / s if self.normalize else Theta_train
        if self.stride is not None and int(self.stride) < 1:
            raise ValueError(f"stride must be a positive integer, got {self.stride}")
        self.stride_, self.stride_rule_ = stride_rule(X.shape[0], self.stride, self.qr)
        X = np.linalg.qr(X, mode="r") if self.qr else np.ascontiguousarray(X[::self.stride_])
        if X.shape[0] < X.shape[1]:
            # fewer rows than library columns: each candidate's regression (p - 1 unknowns) is
            # underdetermined, so the model would be the optimizer's choice, not the record's
            # (a 1000-sample record at stride 999 gave a model from 2 samples, status 0)
            most = max(1, Theta_train.shape[0] // X.shape[1])
            raise self._param_error(
                "stride", self.stride_,
                f"leaves {X.shape[0]} of {Theta_train.shape[0]} training samples, fewer than the "
                f"library's {X.shape[1]} terms; at most {most}")
        xi = pysindy_pi_coef(X, cand, self.reg_weight_lam, self.tol, self.max_iter)
        idx = np.arange(cand.size)
        w = -xi
        w[idx, cand] = 1.0
        if self.support_tol > 0:
            w[np.abs(w) <= self.support_tol * np.abs(w).max(axis=1, keepdims=True)] = 0.0
        W = (w if self.normalize else w * s[None, :] / s[cand][:, None])[None]
        Gn, Gv = G_train / np.outer(s, s), G_val / np.outer(s, s)
        return Sweep(scale=s, candidates=cand, thresholds=np.array([self.reg_weight_lam]), W=W,
                     val_error=_errors(W, Gv, cand), train_error=_errors(W, Gn, cand),
                     nnz=np.count_nonzero(W, axis=2))
