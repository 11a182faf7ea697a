"""The exact truth of a dataset, typed per rig kind.

A rig writes its truth as ``Dataset.truth``, a flat mapping ``name -> array`` (or list of
str) stored under ``/truth`` of the HDF5 file with a unit per name.  What those names are,
their units and shapes is declared here, one dataclass per kind, so that the readers
(scorers, figures, export, summaries) and the writers (the rigs) share one contract:

* :class:`StructuralTruth`: M, C, K, modes and their reduction to the sensors;
* :class:`MechanicalTruth`: the implicit equations of motion, the initial state, the
  physical parameters;
* :class:`DynamicalTruth`: the implicit first-order equations of a state-space system, its
  state names, initial state and parameters.

``Dataset.truth`` stays the plain mapping (the stored format is unchanged);
:meth:`Truth.from_dict` validates such a mapping (missing, unknown and misshapen keys raise
:class:`TruthError` naming the key) and gives the dataclass, :meth:`Truth.to_dict` gives the
mapping back.  :class:`~testbed.core.dataset.Dataset` validates its truth against
``TRUTH_TYPES[dataset.kind]`` when it is saved and loaded, and readers take it typed,
never by key: ``dataset.truth_as(StructuralTruth).frequencies_hz`` (a reader of one kind, e.g.
a scorer) or ``dataset.typed_truth`` (a reader of any kind, e.g. a summary).

Shapes are declared with symbols: every field with symbol ``n`` must have the same length
along it (e.g. ``M`` is ``(n, n)`` and ``frequencies_hz`` ``(n,)``).  A new kind adds a
dataclass subclassing :class:`Truth` with :func:`register_truth`.
"""

# ruff: noqa: RUF009  (``_f`` returns a dataclasses.field with metadata; it is not a default value)
from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar, Self

import numpy as np

from testbed.core.errors import RegistrationError, TestbedError, show_value

__all__ = ["TRUTH_TYPES", "DynamicalTruth", "MechanicalTruth", "StructuralTruth", "Truth", "TruthError",
           "register_truth", "truth_field", "truth_type"]


class TruthError(TestbedError, ValueError):
    """A truth mapping that does not fit its kind's declaration.

    Attributes
    ----------
    key : str or None
        The offending truth name (None for a problem of the whole mapping).
    """

    def __init__(self, message: str, key: str | None = None) -> None:
        self.key = key
        super().__init__(message)


def truth_field(shape: tuple[str | int, ...], unit: str, doc: str, *, required: bool = True,
                text: bool = False) -> Any:
    """A field of a kind's truth dataclass: its symbolic shape, unit (as rigs write it) and
    meaning.

    Parameters
    ----------
    shape : tuple of str or int
        Symbolic shape, e.g. ``("n", "n")``; ``()`` for a scalar.  Every field using a symbol
        must have the same length along it.
    unit : str
        SI unit as the rig writes it (``""`` for a dimensionless value).
    doc : str
        Meaning.
    required : bool
        False for an optional field (default None).
    text : bool
        True for a list of names instead of an array.

    Returns
    -------
    dataclasses.Field
        To assign in a :class:`Truth` subclass body.
    """
    meta = {"shape": shape, "unit": unit, "doc": doc, "text": text}
    return field(metadata=meta) if required else field(default=None, metadata=meta)


_f = truth_field  # the short name the declarations below use


@dataclass(frozen=True)
class Truth:
    """Base of the typed truth of one rig kind (see the module docstring)."""

    #: The rig kind this truth belongs to.
    kind: ClassVar[str] = ""

    @classmethod
    def fields(cls) -> dict[str, dict[str, Any]]:
        """Declaration per truth name: ``shape``, ``unit``, ``doc``, ``text``, ``required``."""
        return {f.name: {**f.metadata, "required": f.default is dataclasses.MISSING}
                for f in dataclasses.fields(cls)}

    @classmethod
    def validate(cls, truth: Mapping[str, Any], units: Mapping[str, str] | None = None) -> None:
        """Check a truth mapping (and its units) against this declaration.

        Parameters
        ----------
        truth : mapping of str to array_like or list of str
        units : mapping of str to str, optional
            Unit of truth names (``Dataset.truth_units``); it may name only keys of ``truth``
            (a name without a unit has the declared one, :meth:`units`).

        Raises
        ------
        TruthError
            Naming the first missing required key, unknown key, value of the wrong kind
            (text vs numbers, non-finite numbers) or of the wrong shape, or a unit of a name
            the truth does not hold.
        """
        decl = cls.fields()
        where = f"{cls.kind} truth"
        missing = [k for k, d in decl.items() if d["required"] and k not in truth]
        if missing:
            raise TruthError(f"{where}: missing {missing[0]!r} (required: "
                             f"{', '.join(k for k, d in decl.items() if d['required'])})",
                             missing[0])
        for k in truth:
            if k not in decl:
                raise TruthError(f"{where}: unknown key {k!r}; declared: {', '.join(decl)}", k)
        sizes: dict[str, tuple[int, str]] = {}
        for k, v in truth.items():
            d = decl[k]
            if d["text"]:
                if not (isinstance(v, (list, tuple)) and all(isinstance(x, str) for x in v)):
                    raise TruthError(f"{where}: {k!r} must be a list of str, got {type(v).__name__}", k)
                shape: tuple[int, ...] = (len(v),)
            else:
                try:
                    a = np.asarray(v, dtype=float)
                except (TypeError, ValueError):
                    raise TruthError(f"{where}: {k!r} must be numeric, got {type(v).__name__}",
                                     k) from None
                if not np.all(np.isfinite(a)):
                    raise TruthError(f"{where}: {k!r} holds non-finite values", k)
                shape = a.shape
            want = d["shape"]
            if len(shape) != len(want):
                raise TruthError(f"{where}: {k!r} has shape {shape}, expected "
                                 f"{_shape_doc(want)} ({len(want)} dimensions)", k)
            for n, s in zip(shape, want, strict=True):
                if isinstance(s, int):
                    if n != s:
                        raise TruthError(f"{where}: {k!r} has shape {shape}, expected "
                                         f"{_shape_doc(want)}", k)
                elif s in sizes and sizes[s][0] != n:
                    other, first = sizes[s][1], sizes[s][0]
                    raise TruthError(f"{where}: {k!r} has shape {shape}, expected "
                                     f"{_shape_doc(want)} with {s} = {first} (from {other!r})", k)
                else:
                    sizes.setdefault(s, (n, k))
        extra = sorted(set(units or {}) - set(truth))
        if extra:
            raise TruthError(f"{where}: a unit for {extra[0]!r}, which the truth does not hold",
                             extra[0])

    @classmethod
    def from_dict(cls, truth: Mapping[str, Any], units: Mapping[str, str] | None = None) -> Self:
        """The validated typed truth of a mapping (:meth:`validate`); arrays as float ndarrays,
        text as lists of str, absent optional fields None."""
        cls.validate(truth, units)
        decl = cls.fields()
        return cls(**{k: (list(v) if decl[k]["text"] else np.asarray(v, dtype=float))
                      for k, v in truth.items()})

    def to_dict(self) -> dict[str, Any]:
        """The mapping stored as ``Dataset.truth`` (absent optional fields left out)."""
        return {f.name: getattr(self, f.name) for f in dataclasses.fields(self)
                if getattr(self, f.name) is not None}

    @classmethod
    def units(cls) -> dict[str, str]:
        """Declared unit per truth name (a rig may state its own, e.g. for its coordinates)."""
        return {k: d["unit"] for k, d in cls.fields().items()}


def _shape_doc(shape: tuple[str | int, ...]) -> str:
    return "(" + ", ".join(str(s) for s in shape) + ("," if len(shape) == 1 else "") + ")"


#: Typed truth per rig kind, filled by :func:`register_truth`.
TRUTH_TYPES: dict[str, type[Truth]] = {}


def register_truth(cls: type[Truth]) -> type[Truth]:
    """Class decorator: make ``cls`` the truth type of rigs of ``cls.kind``.

    Raises
    ------
    RegistrationError
        (a ValueError) if ``cls`` is not a subclass of :class:`Truth`, declares no kind, or
        another truth type is registered for its kind.
    """
    if not (isinstance(cls, type) and issubclass(cls, Truth)):
        raise RegistrationError(f"register_truth: {show_value(cls)} is not a subclass of "
                                "testbed.Truth")
    if not cls.kind:
        raise RegistrationError(f"{cls.__name__} declares no kind")
    have = TRUTH_TYPES.get(cls.kind)
    if have is not None and have is not cls:
        raise RegistrationError(f"a truth type for rig kind {cls.kind!r} is registered already "
                         f"({have.__name__})")
    TRUTH_TYPES[cls.kind] = cls
    return cls


def truth_type(kind: str) -> type[Truth]:
    """The truth type of rig kind ``kind``.

    Raises
    ------
    TruthError
        If none is registered.
    """
    try:
        return TRUTH_TYPES[kind]
    except KeyError:
        raise TruthError(f"no truth type for rig kind {kind!r}; registered: "
                         f"{', '.join(TRUTH_TYPES) or '(none)'}") from None


@register_truth
@dataclass(frozen=True)
class StructuralTruth(Truth):
    """Truth of a structural rig: a linear (optionally cubic) ``M q'' + C q' + K q = f``.

    Symbols: ``n`` degrees of freedom of the full model (its generalised coordinates ``q``,
    e.g. hinge angles [rad] or mass displacements [m]), ``m`` sensors (the reduced
    coordinates: sensor displacements [m]), ``e`` Euler-Bernoulli frequencies, ``j`` hinges.
    Units of the full-model arrays are those of the rig's coordinates: the cantilever's
    (angles) are given; a rig with displacement coordinates writes kg, N s/m, N/m.

    Attributes
    ----------
    M, C, K : ndarray, shape (n, n)
        Full mass [kg m^2], damping [N m s/rad] and stiffness [N m/rad] matrices.
    frequencies_hz : ndarray, shape (n,)
        Undamped natural frequencies [Hz], ascending.
    damping_ratios : ndarray, shape (n,)
        Modal damping ratios [-].
    modes : ndarray, shape (n, n)
        Mass-normalised mode shapes in columns (``Phi^T M Phi = I``).
    sensor_modes : ndarray, shape (m, m)
        The first ``m`` modes at the sensors [m / sqrt(kg m^2)], columns as ``modes``.
    Mr, Cr, Kr : ndarray, shape (m, m)
        Mass [kg], damping [N s/m] and stiffness [N/m] in sensor coordinates (SEREP
        reduction; the full matrices when the sensors are the coordinates).
    T : ndarray, shape (n, m), optional
        Expansion ``q = T u`` from sensor displacements to coordinates.
    damped_frequencies_hz : ndarray, shape (n,), optional
        Damped natural frequencies [Hz].
    k3 : float, optional
        Cubic stiffness [N m/rad^3] of ``g(u) = k3 d (c . u)^3`` (0: linear).
    cubic_direction, cubic_map : ndarray, shape (m,), optional
        ``d`` and ``c`` of the cubic term [rad/m].
    force_map : ndarray, shape (m,), optional
        How the scalar input force enters the reduced equations [-].
    beta : float, optional
        Stiffness-proportional damping coefficient ``C = beta K`` [s].
    eb_frequencies_hz, eb_frequencies_clamped_hz : ndarray, shape (e,), optional
        Euler-Bernoulli beam frequencies [Hz] (with the rig's base, and clamped).
    sensor_positions : ndarray, shape (m,), optional
        Sensor positions [m].
    joint_positions : ndarray, shape (j,), optional
        Hinge positions [m].
    """

    kind: ClassVar[str] = "structural"

    M: np.ndarray = _f(("n", "n"), "kg m^2", "full mass matrix")
    C: np.ndarray = _f(("n", "n"), "N m s/rad", "full damping matrix")
    K: np.ndarray = _f(("n", "n"), "N m/rad", "full stiffness matrix")
    frequencies_hz: np.ndarray = _f(("n",), "Hz", "undamped natural frequencies, ascending")
    damping_ratios: np.ndarray = _f(("n",), "", "modal damping ratios")
    modes: np.ndarray = _f(("n", "n"), "rad/sqrt(kg m^2)", "mass-normalised modes (columns)")
    sensor_modes: np.ndarray = _f(("m", "m"), "m/sqrt(kg m^2)", "first m modes at the sensors")
    Mr: np.ndarray = _f(("m", "m"), "kg", "mass matrix in sensor coordinates")
    Cr: np.ndarray = _f(("m", "m"), "N s/m", "damping matrix in sensor coordinates")
    Kr: np.ndarray = _f(("m", "m"), "N/m", "stiffness matrix in sensor coordinates")
    T: np.ndarray | None = _f(("n", "m"), "rad/m", "expansion q = T u", required=False)
    damped_frequencies_hz: np.ndarray | None = _f(("n",), "Hz", "damped natural frequencies",
                                                  required=False)
    k3: np.ndarray | None = _f((), "N m/rad^3", "cubic stiffness (0: linear)", required=False)
    cubic_direction: np.ndarray | None = _f(("m",), "rad/m", "direction d of the cubic force",
                                            required=False)
    cubic_map: np.ndarray | None = _f(("m",), "rad/m", "map c of the cubic coordinate",
                                      required=False)
    force_map: np.ndarray | None = _f(("m",), "", "input force in the reduced equations",
                                      required=False)
    beta: np.ndarray | None = _f((), "s", "stiffness-proportional damping C = beta K",
                                 required=False)
    eb_frequencies_hz: np.ndarray | None = _f(("e",), "Hz", "Euler-Bernoulli frequencies",
                                              required=False)
    eb_frequencies_clamped_hz: np.ndarray | None = _f(("e",), "Hz", "Euler-Bernoulli, clamped",
                                                      required=False)
    sensor_positions: np.ndarray | None = _f(("m",), "m", "sensor positions", required=False)
    joint_positions: np.ndarray | None = _f(("j",), "m", "hinge positions", required=False)


@register_truth
@dataclass(frozen=True)
class MechanicalTruth(Truth):
    """Truth of a mechanical (multibody) rig: implicit equations of motion in library terms.

    Symbols: ``n`` coordinates (joint angles), ``a`` actuated coordinates, ``q`` equations,
    ``t`` true terms, ``l`` links, ``d`` damped joints.

    Attributes
    ----------
    equation_terms : list of str, length t
        Names of the true terms (:mod:`testbed.core.terms` syntax).
    equation_coef : ndarray, shape (q, t)
        Coefficients, each row divided by its largest-magnitude entry [-].
    theta0, dtheta0 : ndarray, shape (n,), optional
        Initial angles [rad] and rates [rad/s] (the scorer starts the identified model's
        simulation there; without them, at the recorded first sample).
    equation_scale : ndarray, shape (q,), optional
        The divisor of each row [N m^3].
    mass_matrix_q0 : ndarray, shape (n, n), optional
        Mass matrix in the coordinates at the initial state [kg m^2].
    reduced_mass_matrix_q0 : ndarray, shape (a, a), optional
        Mass matrix reduced to the actuated coordinates at the initial state [kg m^2].
    link_lengths, link_masses, link_inertias, link_com : ndarray, shape (l,), optional
        Lengths [m], masses [kg], inertias about the centre of mass [kg m^2], centre-of-mass
        distances from the proximal joint [m].
    base_length : float, optional
        Length of the ground link [m].
    joint_damping : ndarray, shape (d,), optional
        Viscous damping of the modelled joints [N m s/rad].
    gravity : float, optional
        Gravitational acceleration [m/s^2] (0: horizontal plane).
    """

    kind: ClassVar[str] = "mechanical"

    equation_terms: list[str] = _f(("t",), "", "names of the true terms", text=True)
    equation_coef: np.ndarray = _f(("q", "t"), "1 (row max |coef| = 1)", "normalised coefficients")
    theta0: np.ndarray | None = _f(("n",), "rad", "initial angles", required=False)
    dtheta0: np.ndarray | None = _f(("n",), "rad/s", "initial rates", required=False)
    equation_scale: np.ndarray | None = _f(("q",), "N m^3", "row divisors", required=False)
    mass_matrix_q0: np.ndarray | None = _f(("n", "n"), "kg m^2", "mass matrix at the start",
                                           required=False)
    reduced_mass_matrix_q0: np.ndarray | None = _f(("a", "a"), "kg m^2",
                                                   "reduced mass matrix at the start",
                                                   required=False)
    link_lengths: np.ndarray | None = _f(("l",), "m", "link lengths", required=False)
    base_length: np.ndarray | None = _f((), "m", "ground link length", required=False)
    link_masses: np.ndarray | None = _f(("l",), "kg", "link masses", required=False)
    link_inertias: np.ndarray | None = _f(("l",), "kg m^2", "link inertias", required=False)
    link_com: np.ndarray | None = _f(("l",), "m", "centre-of-mass distances", required=False)
    joint_damping: np.ndarray | None = _f(("d",), "N m s/rad", "joint damping", required=False)
    gravity: np.ndarray | None = _f((), "m/s^2", "gravitational acceleration", required=False)


@register_truth
@dataclass(frozen=True)
class DynamicalTruth(Truth):
    """Truth of a dynamical rig: first-order ODEs ``dx/dt = f(x, u)`` as implicit equations.

    Symbols: ``n`` states, ``q`` equations (one per state, row i the equation of state i),
    ``t`` true terms, ``k`` parameters.  A term is a product of factors (:mod:`testbed.core.terms`
    syntax) over the state names, their time derivatives spelt ``d<state>`` (``dx`` for
    ``x``) and input names; ``1`` is the constant term.  Each equation is linear in the
    derivatives, e.g. Michaelis-Menten ``(Km + x) dx - jx (Km + x) + Vmax x = 0``.

    Attributes
    ----------
    equation_terms : list of str, length t
        Names of the true terms.
    equation_coef : ndarray, shape (q, t)
        Coefficients, each row divided by its largest-magnitude entry [-] (an implicit
        equation holds up to scale).
    state_names : list of str, length n
        Names of the states, as the measured ``"x"`` signal names its channels.
    x0 : ndarray, shape (n,)
        Initial state [unit of each state] (the scorer starts the identified model there).
    parameter_names : list of str, length k
        Names of the physical parameters the equations were derived from.
    parameter_values : ndarray, shape (k,)
        Their values [units as the rig's schema states them].
    equation_scale : ndarray, shape (q,), optional
        The divisor of each row [unit of the rig's equation].
    """

    kind: ClassVar[str] = "dynamical"

    equation_terms: list[str] = _f(("t",), "", "names of the true terms", text=True)
    equation_coef: np.ndarray = _f(("q", "t"), "1 (row max |coef| = 1)", "normalised coefficients")
    state_names: list[str] = _f(("n",), "", "names of the states", text=True)
    x0: np.ndarray = _f(("n",), "unit of each state", "initial state")
    parameter_names: list[str] = _f(("k",), "", "names of the physical parameters", text=True)
    parameter_values: np.ndarray = _f(("k",), "as the rig schema", "values of the parameters")
    equation_scale: np.ndarray | None = _f(("q",), "unit of the equation", "row divisors",
                                           required=False)
