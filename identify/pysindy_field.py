"""pysindy's optimizers and its weak form as structural identifiers (the field, beside our own).

The model class is least-squares SINDy's (:mod:`identify.ls_sindy`):
``x''_i = sum_j xi_v[i, j] x'_j + xi_d[i, j] x_j (+ xi_c[i, j] x_j^3) (+ g_i (B u)_i)`` on the
free-vibration window, and the matrices come from the coefficients and the declared mass prior
exactly as there (:func:`identify.structural.matrices_from_coef` with equal diagonal masses
``m_hat / n``).  What changes is who solves the regression:

``strong`` form (``weak = false``)
    The features of :func:`identify.structural.build_library`, each column divided by its RMS
    and each target by its RMS, are handed to a pysindy optimizer's ``fit(Theta, y)``, one
    channel at a time (a channel may use only its own forcing column, as in ``ls_sindy``).
    Thresholds therefore act on a standardised scale (a coefficient of 0.05 means the feature
    explains about 5 % of the target's RMS).
``weak`` form (``weak = true``)
    pysindy's ``WeakPDELibrary`` (linear ``PolynomialLibrary``) integrates the first-order
    system ``z = [x, x']`` against ``n_windows`` compactly supported test functions, so no
    measured acceleration is differentiated or used; the rows of ``x''`` give ``xi_v``, ``xi_d``.
    Linear library only (a cubic weak fit is refused when the scenario loads).  If the window
    holds a nonzero input, the forcing ``(B u)_j`` [N] enters as pysindy's control input (every
    channel's, where ``ls_sindy`` lets a channel use only its own).

Optimizers: ``"stlsq"`` (sequentially thresholded ridge, ``threshold``, ``alpha``), ``"sr3"``
(``reg_weight_lam``, ``regularizer``) and ``"ensemble"`` (pysindy's ``EnsembleOptimizer``
bagging ``n_models`` STLSQ fits on resampled rows, median aggregate; seeded by ``seed``).

Only the structural kind: the five-bar's equations are implicit (no explicit ``x'' = f``), the
case of ``pysindy_pi``.
"""

from __future__ import annotations

import contextlib
import dataclasses
import io
import types
import warnings
from typing import Any, ClassVar

import numpy as np

from identify import IDENTIFIERS
from identify.ls_sindy import MASS_PRIOR_FIELD
from identify.structural import StructuralIdentifier, build_library, mass_prior_value, matrices_from_coef
from testbed.core.errors import IdentificationError
from testbed.core.measurement import Measurement
from testbed.core.schema import ErrorFn, Field, KeyUse

OPTIMIZERS = ("stlsq", "sr3", "ensemble")


def _quiet():
    """pysindy 2.1 warns about axis labels and convergence on every fit; keep the console clean
    (convergence is judged by the scores, not by pysindy's warnings)."""
    stack = contextlib.ExitStack()
    stack.enter_context(warnings.catch_warnings())
    warnings.simplefilter("ignore")
    stack.enter_context(contextlib.redirect_stdout(io.StringIO()))
    return stack


class PySINDyField(StructuralIdentifier):
    """A pysindy optimizer (STLSQ, SR3, ensemble) on the structural SINDy library, strong or weak.

    Parameters
    ----------
    optimizer : {"stlsq", "sr3", "ensemble"}
        pysindy's ``STLSQ``, ``SR3`` or ``EnsembleOptimizer(STLSQ)``.
    threshold : float
        STLSQ threshold on the standardised coefficients (also the ensemble's); dimensionless.
    alpha : float
        STLSQ ridge weight on the standardised problem; dimensionless.
    reg_weight_lam : float
        SR3 regularisation weight (``reg_weight_lam``); dimensionless.
    regularizer : {"L0", "L1"}
        SR3 regulariser.
    max_iter : int
        Iterations of STLSQ / SR3.
    n_models : int
        Bagged models of the ensemble.
    seed : int
        Seed of the ensemble's resampling (numpy's global generator, restored afterwards).
    weak : bool
        Weak (integral) form with pysindy's ``WeakPDELibrary`` instead of the strong form.
    n_windows : int
        Test-function windows of the weak form (pysindy's ``K``).
    cubic : bool
        Add the cubic displacement features ``x_j^3`` (strong form only).
    mass_prior : {"reduced_mass_trace", "total_mass"}
        Key of ``data.prior`` giving the mass scale [kg], as in ``ls_sindy``.

    Attributes
    ----------
    M_, C_, K_ : ndarray, shape (n, n)
        ``M_ = (m_hat / n) I`` [kg], ``C_`` [N s/m], ``K_`` [N/m] (see ``ls_sindy``).
    K3_ : ndarray or None
        [N/m^3] if ``cubic``.
    coef_ : ndarray, shape (n, n_features)
        Coefficients in SI units, row i predicts ``x''_i``; ``feature_names_`` names the columns.
    natural_frequencies_ : ndarray
        [Hz] from ``eig(K_, M_)``.
    n_steps_ : int
        0 (no stepped training of ours).
    """

    name = "pysindy"
    deterministic = True  # pysindy's draws seeded by ``seed``; refitted to the bit in test_conformance
    hyperparameters: ClassVar[dict[str, Field]] = {
        "optimizer": Field(str, "stlsq", choices=OPTIMIZERS, doc="pysindy optimizer: STLSQ, SR3 or "
                                                                   "EnsembleOptimizer(STLSQ)"),
        "threshold": Field(float, 0.001, min=0.0, doc="STLSQ threshold on standardised coefficients"),
        "alpha": Field(float, 1e-8, min=0.0, doc="STLSQ ridge weight (standardised problem)"),
        "reg_weight_lam": Field(float, 1e-6, min=0.0, doc="SR3 regularisation weight"),
        "regularizer": Field(str, "L1", choices=("L0", "L1"), doc="SR3 regulariser"),
        "max_iter": Field(int, 30, min=1, doc="iterations of STLSQ / SR3"),
        # each bagged model is one STLSQ fit: 2**53 + 1 of them ran past any time limit
        # (round 9); 1000 is 50 times the default
        "n_models": Field(int, 20, min=2, max=1000, doc="bagged models of the ensemble optimizer"),
        # numpy's legacy global generator, which pysindy's ensemble draws from, takes seeds of
        # 32 bits: 2**53 + 1 was "ValueError: Seed must be between 0 and 2**32 - 1" in the fit
        "seed": Field(int, 0, min=0, max=2**32 - 1, doc="seed of the ensemble's resampling"),
        "weak": Field(bool, False, doc="weak (integral) form with pysindy's WeakPDELibrary"),
        "n_windows": Field(int, 200, min=4, doc="test-function windows of the weak form (pysindy's K)"),
        "cubic": Field(bool, False, doc="add the cubic displacement features x_j^3 (strong form only)"),
        "mass_prior": MASS_PRIOR_FIELD,
    }
    #: What each optimizer reads (:meth:`_make_optimizer`); the seed draws the ensemble's bags
    #: and the weak form's random domain centres (pysindy's WeakPDELibrary), nothing else.
    used_when: ClassVar[dict[str, KeyUse]] = {
        "threshold": KeyUse("optimizer", lambda v: v != "sr3", "optimizer = 'stlsq' or 'ensemble'"),
        "alpha": KeyUse("optimizer", lambda v: v != "sr3", "optimizer = 'stlsq' or 'ensemble'"),
        "reg_weight_lam": KeyUse("optimizer", lambda v: v == "sr3", "optimizer = 'sr3'"),
        "regularizer": KeyUse("optimizer", lambda v: v == "sr3", "optimizer = 'sr3'"),
        "n_models": KeyUse("optimizer", lambda v: v == "ensemble", "optimizer = 'ensemble'"),
        "seed": KeyUse(("optimizer", "weak"), lambda opt, weak: opt == "ensemble" or weak,
                       "optimizer = 'ensemble' or weak = true"),
        "n_windows": KeyUse("weak", lambda v: v, "weak = true"),
    }

    def __init__(self, optimizer: str = "stlsq", threshold: float = 0.001, alpha: float = 1e-8,
                 reg_weight_lam: float = 1e-6, regularizer: str = "L1", max_iter: int = 30,
                 n_models: int = 20, seed: int = 0, weak: bool = False, n_windows: int = 200,
                 cubic: bool = False, mass_prior: str = "reduced_mass_trace"):
        self.optimizer = optimizer
        self.threshold = threshold
        self.alpha = alpha
        self.reg_weight_lam = reg_weight_lam
        self.regularizer = regularizer
        self.max_iter = max_iter
        self.n_models = n_models
        self.seed = seed
        self.weak = weak
        self.n_windows = n_windows
        self.cubic = cubic
        self.mass_prior = mass_prior

    @classmethod
    def check_hyperparameters(cls, params: dict[str, Any], error: ErrorFn) -> None:
        if params["weak"] and params["cubic"]:
            error("cubic", True, "false with weak = true (the weak form here is linear only)")

    def _make_optimizer(self) -> Any:
        import pysindy as ps  # heavy (cvxpy, sklearn): only when a fit needs it

        stlsq = ps.STLSQ(threshold=float(self.threshold), alpha=float(self.alpha),
                         max_iter=int(self.max_iter), unbias=True)
        if self.optimizer == "stlsq":
            return stlsq
        if self.optimizer == "sr3":
            return ps.SR3(reg_weight_lam=float(self.reg_weight_lam), regularizer=self.regularizer,
                          max_iter=int(self.max_iter), unbias=True)
        return ps.EnsembleOptimizer(stlsq, bagging=True, n_models=int(self.n_models))

    def _seeded(self):
        """Run the ensemble's resampling from ``seed`` and leave numpy's global state as it was."""
        state = np.random.get_state()  # noqa: NPY002 (pysindy draws from the global generator)
        np.random.seed(int(self.seed))  # noqa: NPY002
        stack = contextlib.ExitStack()
        stack.callback(np.random.set_state, state)
        return stack

    def fit(self, data: Measurement) -> PySINDyField:
        """Fit on ``data`` (signals only; the mass prior from ``data.prior``); returns ``self``.

        Raises
        ------
        IdentificationError
            If the optimizer returns non-finite coefficients, or the record is too short for
            the weak form's windows.
        """
        self.check_params()
        m_hat = mass_prior_value(data, self.mass_prior)
        n = data.n_channels
        with _quiet(), self._seeded():
            if self.weak:
                coef, names, blocks = self._fit_weak(data)
            else:
                coef, names, blocks = self._fit_strong(data)
        if not np.all(np.isfinite(coef)):
            raise IdentificationError(f"pysindy {self.optimizer} returned non-finite coefficients")
        self.coef_ = coef
        self.feature_names_ = names
        self.channels_ = tuple(data.channels)
        self.M_, self.C_, self.K_, self.K3_ = matrices_from_coef(coef, blocks, np.full(n, m_hat / n))
        self.input_map_ = None if data.input_map is None else np.asarray(data.input_map, dtype=float)
        self.n_steps_ = 0
        self._finish_fit(data)
        return self

    def _fit_strong(self, data: Measurement) -> tuple[np.ndarray, list[str], dict[str, slice]]:
        from sklearn.base import clone  # lazy: scikit-learn's import costs ~0.7 s

        lib = build_library(data, coupled_mass=False, cubic=bool(self.cubic))
        n, p = lib.target.shape[0], lib.theta.shape[0]
        scale = np.sqrt(np.mean(lib.theta**2, axis=1))
        scale[scale == 0] = 1.0
        phi = (lib.theta / scale[:, None]).T
        template = self._make_optimizer()
        coef = np.zeros((n, p))
        for i in range(n):
            cols = np.flatnonzero(lib.mask[i])
            ys = np.sqrt(np.mean(lib.target[i] ** 2)) or 1.0
            opt = clone(template).fit(phi[:, cols], lib.target[i][:, None] / ys)
            coef[i, cols] = np.asarray(opt.coef_).reshape(-1) * ys / scale[cols]
        return coef, lib.names, lib.blocks

    def _fit_weak(self, data: Measurement) -> tuple[np.ndarray, list[str], dict[str, slice]]:
        import pysindy as ps

        s = data.free_start
        x, xd = np.asarray(data.x, dtype=float)[:, s:], np.asarray(data.xd, dtype=float)[:, s:]
        n, m = x.shape
        if m < 4 * int(self.n_windows):
            raise IdentificationError(f"weak form: {m} samples for {self.n_windows} windows; need "
                                      "at least 4 samples per window")
        f = None
        if data.u is not None and data.input_map is not None:
            f = np.asarray(data.input_map, dtype=float) @ np.asarray(data.u, dtype=float)[:, s:]
            f = f if np.any(f != 0.0) else None
        z = np.vstack([x, xd])
        sz = np.sqrt(np.mean(z**2, axis=1))
        sz[sz == 0] = 1.0
        t = np.arange(m) / data.fs
        lib = ps.WeakPDELibrary(function_library=ps.PolynomialLibrary(degree=1, include_bias=False),
                                spatiotemporal_grid=t, K=int(self.n_windows), p=4)
        model = ps.SINDy(feature_library=lib, optimizer=self._make_optimizer())
        if f is None:
            model.fit((z / sz[:, None]).T, t=t)
        else:  # the forcing (B u)_j [N] as pysindy's control input, scaled like the states
            sf = np.sqrt(np.mean(f**2, axis=1))
            sf[sf == 0] = 1.0
            model.fit((z / sz[:, None]).T, t=t, u=(f / sf[:, None]).T)
            sz = np.concatenate([sz, sf])
        xi = np.asarray(model.coefficients())  # rows d/dt (z_k / sz_k) on features z_j / sz_j (, f_j / sf_j)
        acc = xi[n:] * sz[n:2 * n, None] / sz[None, :]  # x''_i on [x, x' (, B u)] in SI units
        coef = np.hstack([acc[:, n:2 * n], acc[:, :n], acc[:, 2 * n:]])
        names = [f"v{j + 1}" for j in range(n)] + [f"x{j + 1}" for j in range(n)]
        blocks = {"v": slice(0, n), "d": slice(n, 2 * n)}
        if f is not None:
            names += [f"f{j + 1}" for j in range(n)]
            blocks["f"] = slice(2 * n, 3 * n)
        return coef, names, blocks


def _variant(name: str, tags: tuple[str, ...], doc: str, **defaults: Any) -> type:
    """A registered subclass of :class:`PySINDyField` that differs only in some defaults (so a
    study can compare the variants side by side under their own names)."""
    base = PySINDyField.__init__
    kw = dict(zip(PySINDyField._param_names(), base.__defaults__, strict=True)) | defaults
    init = types.FunctionType(base.__code__, base.__globals__, "__init__", tuple(kw.values()),
                              base.__closure__)
    init.__annotations__ = dict(base.__annotations__)
    init.__doc__ = base.__doc__
    init.__qualname__ = f"{name}.__init__"
    hyper = {k: (dataclasses.replace(f, default=defaults[k]) if k in defaults else f)
             for k, f in PySINDyField.hyperparameters.items()}
    cls = type(f"PySINDy_{name}", (PySINDyField,), {
        "__init__": init, "name": name, "hyperparameters": hyper, "__module__": __name__,
        "deterministic": True,
        "__doc__": f"{doc}\n\n    Same model, parameters and attributes as :class:`PySINDyField`; "
                   f"defaults: {', '.join(f'{k}={v!r}' for k, v in defaults.items())}."})
    return IDENTIFIERS.register(name, tags=tags)(cls)


IDENTIFIERS.register("pysindy", tags=("structural", "pysindy", "peer"))(PySINDyField)
PySINDySR3 = _variant("pysindy_sr3", ("structural", "pysindy", "peer"),
                      "pysindy's SR3 on the structural library.", optimizer="sr3")
PySINDyEnsemble = _variant("pysindy_ensemble", ("structural", "pysindy", "peer"),
                           "pysindy's EnsembleOptimizer (bagged STLSQ) on the structural library.",
                           optimizer="ensemble")
PySINDyWeak = _variant("pysindy_weak", ("structural", "pysindy", "peer", "weak"),
                       "pysindy's weak form (WeakPDELibrary) with STLSQ on the linear structural "
                       "library.", weak=True)
