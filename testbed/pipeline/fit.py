"""Identify a model from measured data in a file: no simulation, no truth (``testbed identify``).

The file (UFF58, SEP-005 JSON, CSV or a dataset HDF5, :mod:`testbed.pipeline.importers`) goes
through the rig kind's signal chain and the chosen identifier, as a scenario's measurements do;
the result is the fitted model, its equations and, for a structural model, its matrices and
modal parameters, as a JSON-ready dict (:func:`model_summary`).  Nothing is scored against a
truth: the only figure of merit is the identifier's truth-free ``score`` (R^2 of the predicted
accelerations) where it has one.
"""

from __future__ import annotations

import contextlib
import math
import os
import re
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from testbed.core.errors import (
    IdentificationError,
    InputError,
    PluginMethodError,
    ScenarioError,
    TestbedError,
    exception_text,
)
from testbed.core.exit_guard import no_process_exit
from testbed.core.measurement import Measurement
from testbed.core.process_state import kept_process_state
from testbed.core.registry import builtin_class
from testbed.numerics.clipping import Clipping
from testbed.numerics.shapes import modal_from_matrices
from testbed.pipeline import plugins
from testbed.pipeline.importers import measurement_and_clipping
from testbed.pipeline.scenario import check_identifier_for_record, load_scenario, other_identifiers
from testbed.pipeline.signal_chain import SIGNAL_SCHEMAS


@dataclass
class FitResult:
    """A model identified from a file.

    Attributes
    ----------
    model : Identifier
        The fitted identifier.
    data : Measurement
        What it was fitted on (after the signal chain).
    kind : str
        Rig kind whose signal chain ran (``"structural"`` or ``"mechanical"``).
    method : str
        Registered identifier name.
    source : str
        The data file.
    fit_time : float
        Wall time of ``fit`` [s].
    clipped : tuple of Clipping
        The record's channels holding a clip level (a saturated sensor:
        :mod:`testbed.numerics.clipping`); said, nothing refused.
    """

    model: Any
    data: Measurement
    kind: str
    method: str
    source: str
    fit_time: float
    clipped: tuple[Clipping, ...] = ()

    def summary(self) -> dict[str, Any]:
        """JSON-ready description: :func:`model_summary` plus the source and the data's shape."""
        out = {"source": self.source, "kind": self.kind, "method": self.method,
               "fit_time_s": self.fit_time, "fs_hz": self.data.fs, "n_samples": self.data.n_samples,
               "channels": list(self.data.channels)}
        if self.clipped:  # stored with the model: a saturated sensor's record
            out["clipped_sensors"] = [c.as_dict() for c in self.clipped]
        out.update(model_summary(self.model, self.data))
        return out


#: Exceptions of a fit that are its model blowing up on the data, not a bug: a singular or
#: non-convergent linear-algebra problem, a division by zero, an overflow.  A run scores them
#: as a failed fit (:func:`testbed.scoring.run.run_scenario`); ``identify`` reports them as one.
NUMERICAL_BREAKDOWN = (ArithmeticError, np.linalg.LinAlgError)


def fit_or_fail(model: Any, data: Measurement, method: str | None = None) -> None:
    """``model.fit(data)``; a :data:`NUMERICAL_BREAKDOWN` becomes an :class:`IdentificationError`
    saying so (the identifier could not produce a model from these data).

    ``method``: the registered name ``model`` was made from.  Any other exception raised by a
    user's plugin identifier (not a built-in one, whose exception is a testbed bug and stays
    one) becomes an :class:`IdentificationError` naming the identifier and its file: the
    user's own code failed, and a run scores it as a failed fit instead of calling it an
    internal error of the testbed.
    """
    builtin = builtin_class(type(model))  # (the rule of identify._base._called too: 28a L5)
    try:
        # a plugin's os._exit(0) in fit ended a run with status 0 and no verdict (round 19)
        # under numpy's own float error state (a caller's or an earlier plugin's
        # np.seterr(all="raise") failed a built-in fit); a plugin's np.seterr and os.chdir are
        # undone after it (hostile round 20)
        with no_process_exit() if not builtin else contextlib.nullcontext(), \
                kept_process_state():
            model.fit(data)
    except NUMERICAL_BREAKDOWN as e:
        raise IdentificationError(f"numerical breakdown ({type(e).__name__}: "
                                  f"{exception_text(e) or 'no message'})") from None
    except TestbedError:
        raise
    except BaseException as e:  # a plugin's sys.exit(0) ended a run with exit 0, no verdict;
        # its GeneratorExit (any BaseException but Ctrl-C) was a traceback, status 1 (round 19)
        if builtin or isinstance(e, KeyboardInterrupt):
            raise
        raise IdentificationError(f"{_plugin_named(model, method)} raised "
                                  f"{type(e).__name__}: {exception_text(e)}") from None
    if not builtin:
        problem = fitted_shape_problem(model)
        if problem is not None:
            raise IdentificationError(f"{_plugin_named(model, method)} fitted {problem}")


def _plugin_named(model: Any, method: str | None) -> str:
    """A plugin identifier as :func:`fit_or_fail`'s failures name it: ``identifier NAME (from
    ORIGIN)``, ``NAME`` the registered ``method`` (else the class's name), ``ORIGIN`` where
    the registry says it came from (a class registered under a built-in's name, or none:
    its module)."""
    origin = plugins.IDENTIFIERS.origin(method) if method is not None else "builtin"
    if origin == "builtin":
        origin = f"module {type(model).__module__}"
    return f"identifier {method or type(model).__name__} (from {origin})"


def fitted_shape_problem(model: Any) -> str | None:
    """What is wrong with the shapes of a fitted model's results, or None.

    The contract of :class:`identify._base.Identifier`: a structural model's ``M_``, ``C_``,
    ``K_`` (and ``K3_`` unless None) are real square matrices of one size (n_dof, n_dof); a
    model with ``coef_`` holds a real 2-D array (n_equations, n_features), with one column
    per name of ``feature_names_`` where it has them.  Checked for a user's plugin, whose
    wrong shapes were an internal error of the scoring or the JSON ("a bug, not your input").
    """
    def real(name: str) -> np.ndarray | str:
        value = getattr(model, name)
        try:
            kind = np.asarray(value).dtype
            # complex was cast to real with a ComplexWarning on stderr (its imaginary part
            # dropped), float16 was "internal error: array type float16 is unsupported in
            # linalg" of the scoring, booleans read as 0 / 1 (hostile round 19)
            if kind.kind == "c":
                return f"{name} of complex dtype {kind}; expected real numbers (float64)"
            if kind.kind == "b" or kind == np.float16:
                return (f"{name} of dtype {kind}; expected real numbers of float32 or float64 "
                        "(numpy's linear algebra takes no float16)")
            a = np.asarray(value, dtype=float)
        except (TypeError, ValueError) as e:
            return f"{name} that is not an array of real numbers ({type(e).__name__}: {e})"
        return a

    if getattr(model, "kind", "") == "structural" or hasattr(model, "M_"):
        names = [k for k in ("M_", "C_", "K_", "K3_") if getattr(model, k, None) is not None]
        if not {"M_", "C_", "K_"} <= set(names):
            return "no M_, C_ and K_ (a structural model's matrices)"
        arrays = [real(k) for k in names]
        bad = next((a for a in arrays if isinstance(a, str)), None)
        if bad is not None:
            return bad
        n = arrays[0].shape[0] if arrays[0].ndim == 2 else -1
        for k, a in zip(names, arrays, strict=True):
            if a.shape != (n, n) or n < 1:
                return (f"{k} of shape {a.shape}; expected square matrices of one size "
                        f"(n_dof, n_dof), M_ being {arrays[0].shape}")
        return None
    if getattr(model, "coef_", None) is not None:
        coef = real("coef_")
        if isinstance(coef, str):
            return coef
        names = getattr(model, "feature_names_", None)
        if coef.ndim != 2 or (names is not None and coef.shape[1] != len(names)):
            n = "" if names is None else f", {len(names)} features as feature_names_ has"
            return f"coef_ of shape {coef.shape}; expected (n_equations, n_features){n}"
    return None


def identify_file(path: str | os.PathLike, *, scenario: str | os.PathLike | None = None,
                  kind: str | None = None, method: str | None = None,
                  params: Mapping[str, Any] | None = None, format: str | None = None,
                  fs: float | None = None, units: str | Mapping[str, str] | None = None,
                  channels: Sequence[str] | None = None, prior: Mapping[str, float] | None = None,
                  phase: Callable[[str], Any] | None = None) -> FitResult:
    """Read measured data, run the signal chain and fit an identifier.

    Parameters
    ----------
    path : path-like
        UFF58 (``.uff``/``.unv``), SEP-005 (``.json``), CSV (``.csv``/``.tsv``/``.txt``) or
        dataset HDF5 (``.h5``) file (see :func:`testbed.pipeline.importers.read_measured`).
    scenario : str or path-like, optional
        A scenario (name or ``.toml`` path) whose rig kind, ``[signal]`` chain and
        ``[identify]`` table are used; ``kind``/``method``/``params`` override its choices.
    kind : {"structural", "mechanical", "dynamical"}, optional
        Rig kind (which signal chain); required without ``scenario``, else must match it.
    method : str, optional
        Registered identifier; default the scenario's ``[identify] method``.
    params : mapping, optional
        Hyperparameters (over the scenario's when the method is the scenario's).
    format, fs, units, channels
        As for :func:`~testbed.pipeline.importers.read_measured` (``fs`` [Hz]).
    prior : mapping of str to float, optional
        Declared prior knowledge, e.g. ``{"total_mass": 0.7}`` [kg] (over the file's own).
    phase : callable, optional
        ``phase(name)`` returns a context manager around each phase ("read and signal chain",
        "fit") yielding ``update(fraction=None, step=None)``; the fit reports the steps its
        identifier reports (:meth:`identify.Identifier.report_progress`).  The reporting
        layer's :func:`testbed.reporting.progress.run_progress` draws them.

    Returns
    -------
    FitResult

    Raises
    ------
    InputError
        Nothing says which kind or method, a method of another kind, bad hyperparameters, a
        ``prior`` key the identifier does not read (:attr:`identify.Identifier.prior_keys`).
    MeasuredDataError, ScenarioError, IdentificationError
        The file, the scenario, or a fit that fails on these data.
    """
    signal: Mapping[str, Any] = {}
    identify: dict[str, Any] = {}
    if scenario is not None:
        sc = load_scenario(scenario)
        sc_kind = plugins.rig_kind(sc.rig)
        if kind is not None and kind != sc_kind:
            raise InputError(f"--kind {kind}: the scenario {sc.name} is of the {sc_kind} kind")
        kind, signal, identify = sc_kind, sc.signal, dict(sc.identify or {})
    if kind is None:
        raise InputError("say which rig kind the data are from: --kind structural|mechanical|dynamical, or "
                         "--scenario NAME")
    if kind not in SIGNAL_SCHEMAS:
        raise InputError(f"--kind {kind!r}: unknown; allowed: {', '.join(SIGNAL_SCHEMAS)}")
    if method is not None and method != identify.get("method"):
        identify = {"method": method}
    if "method" not in identify:
        raise InputError("say which identifier to fit: --method NAME (see `testbed list`), or a "
                         "--scenario with an [identify] table")
    cls = plugins.identifier_class(identify["method"])
    if cls.kind != kind:
        raise InputError(f"identifier {identify['method']} is for {cls.kind} rigs; the data are "
                         f"{kind}")
    declared = getattr(cls, "prior_keys", None)  # None: a plugin that declares none, any key
    unknown = sorted(set(prior or {}) - set(declared)) if declared is not None else []
    if unknown:
        raise InputError(f"--prior {unknown[0]}: identifier {identify['method']} reads no such "
                         f"prior; it reads: {', '.join(declared) or 'none'}")
    hyper = {k: v for k, v in identify.items() if k != "method"} | dict(params or {})
    where = str(scenario or "<command line>")
    with _named_source(params, scenario):
        # an unknown key named with the key probably meant, or the identifier it is a
        # hyperparameter of (round 23: `--param lr=0.1` for sindy_pi_dynamical listed its 15
        # keys, not that lr is sgd_sindy's)
        hyper = cls.validate_hyperparameters(hyper, file=where,
                                             elsewhere=other_identifiers(identify["method"]))
    phase = phase or _no_phase
    with phase("read and signal chain"):
        data, clipped = measurement_and_clipping(path, kind, signal, format=format, fs=fs,
                                                 units=units, channels=channels, prior=prior)
    with _named_source(params, scenario):
        check_against_data(cls, hyper, data, file=where)
    model = cls(**hyper)
    with phase("fit") as update:
        t0 = time.perf_counter()
        to = getattr(model, "progress_to", None)  # a plugin without it reports no steps
        try:
            with to(update) if callable(to) else contextlib.nullcontext():
                fit_or_fail(model, data, identify["method"])
        except IdentificationError as e:
            # the data (or a hyperparameter for them) the identifier cannot take, or the user's
            # own identifier failing: say which file
            raise IdentificationError(f"{path}: {identify['method']} found no model: {e}") from None
        fit_time = time.perf_counter() - t0
    return FitResult(model, data, kind, identify["method"], str(path), fit_time, tuple(clipped))


@contextlib.contextmanager
def _named_source(params: Mapping[str, Any] | None, scenario: Any) -> Iterator[None]:
    """Name ``<command line>`` as the file of a ScenarioError about a hyperparameter given with
    ``--param`` over a scenario's ``[identify]`` table: ``identify --scenario S --param
    max_iter=1`` was refused as "S: key 'identify.max_iter' ... unknown key", naming a file
    that holds no such key (round 15)."""
    try:
        yield
    except ScenarioError as e:
        key = (e.key or "").removeprefix("identify.")
        name = key if key in (params or {}) else re.split(r"[.\[]", key, maxsplit=1)[0]
        if scenario is None or not params or name not in params:
            raise
        raise type(e)("<command line>", e.key, e.value, e.allowed) from None


def check_against_data(cls: Any, hyper: dict[str, Any], data: Measurement, *, file: str) -> None:
    """The identifier's checks against the data's shape and the budget of its simulations, as a
    scenario's are checked against its rig at load
    (:func:`testbed.pipeline.scenario.check_identifier_for_rig`).

    Parameters
    ----------
    cls : type
        The identifier class.
    hyper : dict
        Its complete, validated hyperparameters.
    data : Measurement
        The measurement it is about to fit.
    file : str
        Where the hyperparameters came from (a scenario path or ``"<command line>"``).

    Raises
    ------
    ScenarioError
        A hyperparameter the data's shape refuses (term names for other channels, a window
        longer than the record, a cut-off above the Nyquist frequency), naming ``file``, the key
        ``identify.<name>``, the value and what the data allow; a
        :class:`~testbed.core.errors.BudgetError` for a simulation beyond the step budget.
    """
    n_inputs = 0 if data.u is None else int(np.shape(data.u)[0])
    check_identifier_for_record(cls, hyper, (data.n_channels, n_inputs), float(data.fs),
                                data.n_samples, file=file,
                                detail=f" (data: {data.n_channels} channel(s), {data.n_samples} "
                                       f"samples at {data.fs:g} Hz)")


@contextlib.contextmanager
def _no_phase(name: str) -> Iterator[Callable[..., None]]:
    yield lambda fraction=None, step=None: None


def _array(a: Any) -> Any:
    return None if a is None else np.asarray(a, dtype=float).tolist()


def modal_parameters(M: np.ndarray, C: np.ndarray, K: np.ndarray) -> dict[str, list[float]]:
    """The modes of ``M x'' + C x' + K x = 0`` as the scorer reports them, sorted by frequency.

    Parameters
    ----------
    M, C, K : ndarray, shape (n, n)
        Mass [kg], damping [N s/m] and stiffness [N/m] matrices.

    Returns
    -------
    dict
        ``frequency_hz`` (undamped natural frequency ``w_n / 2 pi`` [Hz]) and ``damping_ratio``
        [-] of each of the n modes (:func:`testbed.numerics.shapes.modal_from_matrices`: one
        mode per pair of eigenvalues, an overdamped one with a ratio above 1; None for a mode
        the model cannot give, e.g. an unstable one or every mode of a mass matrix that is not
        positive definite).
    """
    f, zeta, _ = modal_from_matrices(M, C, K, strict=False)
    return {"frequency_hz": [None if not math.isfinite(x) else float(x) for x in f],
            "damping_ratio": [None if not math.isfinite(x) else float(x) for x in zeta]}


def model_summary(model: Any, data: Measurement | None = None) -> dict[str, Any]:
    """A fitted identifier as a JSON-ready dict.

    Keys: ``identifier`` (name, class, hyperparameters), ``equations`` (text), ``rules`` (the
    fitted ``*rule_`` strings: which setting a rule chose from the data, and why); for a structural
    model ``matrices`` (``M`` [kg], ``C`` [N s/m], ``K`` [N/m], ``K3`` [N/m^3] or None) and
    ``modal`` (:func:`modal_parameters`); for a mechanical one ``coefficients`` (``coef`` with
    ``feature_names``); with ``data``, ``r2`` (the model's truth-free ``score(data)``, None where
    the model has none).

    Parameters
    ----------
    model : Identifier
        A fitted identifier.
    data : Measurement, optional
        The measurement it was fitted to, for ``r2``.

    Returns
    -------
    dict
        The keys above; arrays as nested lists.
    """
    params = {k: v for k, v in model.get_params(deep=False).items()
              if isinstance(v, (bool, int, float, str, list, tuple, type(None)))}
    out: dict[str, Any] = {"identifier": {"name": getattr(model, "name", ""),
                                          "class": f"{type(model).__module__}.{type(model).__qualname__}",
                                          "params": params},
                           "equations": list(model.equations())}
    rules = {k: v for k, v in vars(model).items()
             if k.endswith("rule_") and not k.startswith("_") and isinstance(v, str)}
    if rules:  # the settings chosen from the data, and why (e.g. noise_rule_, peak_band_rule_)
        out["rules"] = rules
    if hasattr(model, "M_"):
        M, C, K = (np.asarray(getattr(model, k), dtype=float) for k in ("M_", "C_", "K_"))
        out["matrices"] = {"M": _array(M), "C": _array(C), "K": _array(K),
                           "K3": _array(getattr(model, "K3_", None)),
                           "units": {"M": "kg", "C": "N s/m", "K": "N/m", "K3": "N/m^3"}}
        out["modal"] = modal_parameters(M, C, K)
    elif hasattr(model, "coef_"):
        out["coefficients"] = {"coef": _array(model.coef_),
                               "feature_names": list(getattr(model, "feature_names_", []))}
    if data is not None:
        try:
            out["r2"] = float(model.score(data))
        except (NotImplementedError, PluginMethodError):  # none, or a plugin's own failed: the
            out["r2"] = None  # scored prediction says so (scorers.prediction_r2)
    return out
