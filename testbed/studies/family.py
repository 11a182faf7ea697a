"""Scenario families: many scenarios drawn from declared ranges, reproducibly from one seed.

A study may declare families next to (or instead of) its hand-made scenarios::

    [families.beams]
    base = "cantilever_stiff_impact"   # scenario the members start from (name or path)
    members = 50                       # how many
    seed = 0                           # the family's seed (members never depend on the noise seeds)

    [families.beams.rig]               # one entry per key to vary; others keep the base's value
    length = {uniform = [0.2, 0.5]}            # float, uniform in [lo, hi]
    thickness = {log_uniform = [0.004, 0.012]} # float, log-uniform in [lo, hi]
    n_segments = {integers = [8, 16]}          # int, uniform in [lo, hi] (both included)
    n_segments = {log_integers = [8, 60]}      # int, log-uniform in [lo - 1/2, hi + 1/2], rounded
    base = {choices = ["stiff", "soft"]}       # one of the choices, equally likely
    damping_ratio = 0.01                       # a plain value: fixed for every member

The tables ``rig``, ``simulation``, ``excitation`` and ``signal`` take such entries for the
rig's own keys (checked by the rig's schema when a member is validated) and, for the
``cantilever`` rig, a few derived keys (:data:`CANTILEVER_DERIVED`) whose rules are stated
there: ``material``, ``n_sensors``, ``base_k1_ratio``, ``cubic_fraction`` and
``excitation.location = "sensor"``.  For the ``fivebar`` rig the base's start pose
(``th1_0`` / ``th4_0``) is dropped unless the family sets it, so the rig picks a usable pose
for every drawn geometry.

Drawing rule (deterministic): member ``k`` (0-based) is drawn by the numpy Generator
``default_rng([seed, k, attempt])`` with ``attempt = 0``; if the drawn parameters are refused
by validation (the rig's checks, the budget, or a family rule such as a mode above the
Nyquist frequency), it is drawn again with ``attempt = 1, 2, ...`` up to :data:`MAX_ATTEMPTS`.
Member ``k`` therefore does not depend on the member count or on other members, and the same
seed gives identical members.  Keys are drawn in the order of the file, tables in the order
rig, simulation, excitation, signal, so adding a key at the end of a table changes only
that key's values.

A member is a full :class:`~testbed.pipeline.scenario.Scenario` named ``<family>__<kkk>``,
tagged ``family:<family>``; :func:`write_members` writes each as a scenario file that
``testbed run`` can rerun alone and that reloads to an equal Scenario
(:func:`testbed.studies.study.write_family`).  Members keep the
base's ``[identify]`` (its hyperparameters were chosen for its method) but not its
``[score]``: those bars were set on the base scenario, so members are held only to the
study's thresholds per identifier.
"""

from __future__ import annotations

import math
import os
import re
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from testbed.core.atomic import FileKind, atomic_write_text, refuse_foreign
from testbed.core.errors import ScenarioError
from testbed.core.schema import ONE_LINE, ONE_LINE_DOC, Field, check_value, validate_table
from testbed.pipeline.plugins import RIGS
from testbed.pipeline.scenario import (
    NAME_PATTERN,
    NAME_PATTERN_DOC,
    Scenario,
    _read_toml,
    file_problem,
    resolve_path,
    scenario_from_dict,
)
from testbed.pipeline.signal_chain import SIGNAL_SCHEMAS

#: Draws per member before the family is refused: a range so narrow that 100 independent
#: draws are all invalid is a mistake in the study file, not bad luck (the shipped families
#: need at most a few redraws per member).
MAX_ATTEMPTS = 100
#: Separator of family and member index in a member's name (not used by shipped scenarios).
MEMBER_SEP = "__"

FAMILY_SCHEMA = {
    "base": Field(str, doc="scenario the members start from (name in scenarios/ or .toml path "
                           "relative to the study file)"),
    "members": Field(int, min=1, max=10000, doc="number of members"),
    "seed": Field(int, 0, min=0, doc="seed of the members' parameters (numpy Generator)"),
    "description": Field(str, "", pattern=ONE_LINE, pattern_doc=ONE_LINE_DOC, doc="one line for listings"),
}
RANGE_TABLES = ("rig", "simulation", "excitation", "signal")
DISTRIBUTIONS = ("uniform", "log_uniform", "integers", "log_integers", "choices")
#: The integers numpy's Generator draws (int64).
INT64_MIN, INT64_MAX = -(2**63), 2**63 - 1

#: Materials a cantilever family may name: Young's modulus E [Pa] and density rho [kg/m^3]
#: (handbook values at room temperature; any other material is given by E and rho ranges).
MATERIALS: dict[str, tuple[float, float]] = {
    "steel": (210e9, 7850.0),
    "aluminium": (70e9, 2700.0),
    "titanium": (114e9, 4430.0),
    "brass": (100e9, 8500.0),
    "glass_epoxy": (24e9, 1900.0),
}

#: A member's highest sensed mode (as many modes as sensors) must lie below this fraction of
#: the sample rate: the signal chain and the identifiers' spectral peaks need it resolved
#: below the Nyquist frequency (0.5) with room for its anti-alias roll-off.
MAX_MODE_FRACTION_OF_FS = 0.35
#: Segments per sensed mode at least: a hinge chain of N segments reproduces mode k of the
#: continuous beam within ~1 % only while N >= ~3 k (the shipped 10-segment beam: modes 1-3
#: within 0.4 %), so a member with s sensors has at least 3 s segments.
MIN_SEGMENTS_PER_MODE = 3
#: Periods of mode 1 the record must hold at least: the signal chain's high-pass (10 Hz by
#: default), its end effects and a spectral peak need many cycles of the slowest mode; the
#: shipped stiff beam has 80 (80 Hz over 1 s), and a first family run with 6-40 periods
#: (mode 1 at 11-110 Hz over 0.5 s) failed on most members with mode 1 below 40 Hz
#: (TRAC 0.0-0.3 for least squares at 0 % noise), i.e. on the set-up, not the method.
MIN_MODE1_PERIODS = 20
#: Largest damping ratio of the highest sensed mode: the rig's damping is stiffness-
#: proportional (C = beta K, so zeta_k = zeta_1 f_k / f_1); a mode damped 30 % loses 85 % of
#: its amplitude per cycle, so its free decay holds about one cycle and its frequency and
#: damping cannot be measured: a model with that mode in its sensor coordinates is not
#: determined by the record (first family run: members with zeta_N > 0.3 gave unstable poles).
MAX_SENSED_DAMPING = 0.3
#: Smallest gap between two drawn sensors and between a sensor and the root [fraction of the
#: length]: two accelerometers closer than 5 % of the beam see nearly the same motion and make
#: the sensor-coordinate model ill-conditioned by construction, not by the method.
MIN_SENSOR_GAP = 0.05

#: Derived keys of cantilever families and their rules.
CANTILEVER_DERIVED = {
    "rig.material": "a name in MATERIALS: sets E and rho",
    "checks": "every sensed mode (as many as sensors, Euler-Bernoulli estimate) below "
              "MAX_MODE_FRACTION_OF_FS * sample_rate, at least MIN_SEGMENTS_PER_MODE segments "
              "per sensed mode, at least MIN_MODE1_PERIODS periods of mode 1 in the record, "
              "the highest sensed mode damped at most MAX_SENSED_DAMPING",
    "rig.n_sensors": "number of accelerometers; positions uniform on (0, L], sorted, conditioned "
                     "on being at least MIN_SENSOR_GAP * L apart and from the root (drawn "
                     "directly, see _cantilever_rules), rounded down to 0.1 mm",
    "rig.base_k1_ratio": "soft base: base_k1 = ratio * E I / L (I = width thickness^3 / 12); "
                         "1.2 is the shipped soft base",
    "rig.cubic_fraction": "soft base: cubic base moment at the estimated peak base rotation as "
                          "a fraction of the linear one, k3 q^2 / k1; base_k3 is derived "
                          "(see peak_base_rotation)",
    "excitation.location = 'sensor'": "the impact lands on one of the sensors, equally likely "
                                      "(the signal chain needs it on a sensor)",
    "signal.highpass_hz = 'auto'": "half the Euler-Bernoulli estimate of mode 1 on the member's "
                                   "base (the noisy-record chain's 40 Hz for the shipped beam's "
                                   "80 Hz), 0.1 Hz; the rig's rule, as in a scenario "
                                   "(models/cantilever/euler_bernoulli.py auto_cutoff)",
    "signal.lowpass_hz = 'auto'": "the low-pass between the last sensed mode n and mode n + 1: "
                                  "sqrt(f_n f_(n+1)) of the clamped Euler-Bernoulli estimates, "
                                  "0.1 Hz; the rig's rule, as in a scenario",
}


@dataclass(frozen=True)
class Family:
    """A validated family declaration.

    Attributes
    ----------
    name : str
    base : Scenario
        The scenario members start from.
    members : int
    seed : int
    ranges : dict of str to dict
        Per table (``rig``, ``simulation``, ``excitation``, ``signal``): key -> fixed value or
        ``{distribution: arguments}``.
    description : str
    """

    name: str
    base: Scenario
    members: int
    seed: int = 0
    ranges: dict[str, dict[str, Any]] = field(default_factory=dict)
    description: str = ""

    def member_name(self, k: int) -> str:
        return f"{self.name}{MEMBER_SEP}{k:03d}"


def family_of(scenario_name: str) -> str:
    """The family of a member's name (``<family>__<kkk>``), or the name itself for a scenario."""
    head, sep, tail = scenario_name.rpartition(MEMBER_SEP)
    return head if sep and tail.isdigit() else scenario_name


# --------------------------------------------------------------------------- declaration
def parse_family(name: str, table: Any, *, file: str, base_dir: Path) -> Family:
    """Validate one ``[families.<name>]`` table (ranges are checked here, values when drawn).

    Raises
    ------
    ScenarioError
        Naming the key: an unknown key, a malformed range, an unknown base scenario.
    """
    key = f"families.{name}"
    if not re.fullmatch(NAME_PATTERN, name) or MEMBER_SEP in name:
        raise ScenarioError(file, key, name, f"a family name must be {NAME_PATTERN_DOC}, without "
                                             f"{MEMBER_SEP!r}")
    if not isinstance(table, dict):
        raise ScenarioError(file, key, table, f"expected a table [{key}]")
    head_raw = {k: v for k, v in table.items() if k not in RANGE_TABLES}
    head = validate_table(head_raw, FAMILY_SCHEMA, file=file, section=key)
    bpath = resolve_path(head["base"])
    if not bpath.is_absolute() and (head["base"].endswith(".toml") or len(Path(head["base"]).parts) > 1):
        bpath = base_dir / bpath
    problem = file_problem(bpath, "scenario")
    if problem is not None:
        raise ScenarioError(file, f"{key}.base", head["base"],
                            f"no scenario file {bpath}" if problem.startswith("no such")
                            else f"{bpath}: {problem}")
    raw = _read_toml(bpath)
    base = scenario_from_dict(raw, file=str(bpath), stem=bpath.stem, standalone=False)
    ranges: dict[str, dict[str, Any]] = {}
    for t in RANGE_TABLES:
        sub = table.get(t, {})
        if not isinstance(sub, dict):
            raise ScenarioError(file, f"{key}.{t}", sub, f"expected a table [{key}.{t}]")
        for k, spec in sub.items():
            _check_spec(spec, file, f"{key}.{t}.{k}")
        ranges[t] = dict(sub)
    fam = Family(name=name, base=base, members=head["members"], seed=head["seed"], ranges=ranges,
                 description=head["description"])
    _check_range_keys(fam, file, key)
    if base.rig == "cantilever":
        _check_cantilever_keys(fam, file, key)
    return fam


#: The cantilever's derived keys of ``[families.<name>.rig]`` (:data:`CANTILEVER_DERIVED`) that
#: take numbers, and what they allow (``material`` is checked against :data:`MATERIALS`).
CANTILEVER_DERIVED_FIELDS = {
    "n_sensors": Field(int, min=1, doc="number of accelerometers (0 would mean the rig's "
                                       "default three)"),
    "base_k1_ratio": Field(float, min=0.0, min_inclusive=False, doc="base_k1 / (E I / L)"),
    "cubic_fraction": Field(float, min=0.0, doc="k3 q_peak^2 / k1"),
}


def _check_range_keys(fam: Family, file: str, key: str) -> None:
    """Every key of a family's range tables is one the base rig declares, and every value a
    distribution can draw (both ends of a range, every choice) is one its field allows.

    A typo or a range wholly outside the allowed values used to surface only after every draw
    of member 0 was refused, as ``<family ...>``.
    """
    rig_cls = RIGS.get(fam.base.rig)
    schemas = {"rig": dict(rig_cls.rig_schema), "simulation": rig_cls.simulation_schema,
               "excitation": rig_cls.excitation_schemas.get(fam.base.excitation.get("type"), {}),
               "signal": SIGNAL_SCHEMAS[rig_cls.kind]}
    derived = {"material"} if fam.base.rig == "cantilever" else set()
    if fam.base.rig == "cantilever":
        schemas["rig"].update(CANTILEVER_DERIVED_FIELDS)
    for table, sub in fam.ranges.items():
        schema = schemas.get(table, {})
        for k, spec in sub.items():
            where = f"{key}.{table}.{k}"
            if (table, k) == ("excitation", "type") or (table == "rig" and k in derived):
                continue  # checked in every member / by _check_cantilever_keys
            if k not in schema:
                raise ScenarioError(file, where, spec, f"unknown key; allowed keys in "
                                                       f"[{key}.{table}]: "
                                                       + ", ".join(sorted(schema) + sorted(derived)))
            if isinstance(spec, dict):
                (dist, values), = spec.items()
                for v in values:
                    check_value(v, schema[k], file=file, key=f"{where}.{dist}")
            elif not (fam.base.rig == "cantilever" and spec == _CANTILEVER_WORDS.get((table, k))):
                # a fixed value too: the cantilever's rules compute with it before a member is
                # validated ("abc" for a length was a TypeError there)
                check_value(spec, schema[k], file=file, key=where)


#: Words the cantilever's derived keys take in place of a value (:data:`CANTILEVER_DERIVED`).
_CANTILEVER_WORDS = {("excitation", "location"): "sensor", ("signal", "highpass_hz"): "auto",
                     ("signal", "lowpass_hz"): "auto"}


def _check_spec(spec: Any, file: str, key: str) -> None:
    if not isinstance(spec, dict):
        return  # a fixed value: the rig's schema checks it in every member
    if len(spec) != 1 or next(iter(spec)) not in DISTRIBUTIONS:
        raise ScenarioError(file, key, spec, "a fixed value or one of {uniform = [lo, hi]}, "
                                             "{log_uniform = [lo, hi]}, {integers = [lo, hi]}, "
                                             "{log_integers = [lo, hi]}, {choices = [...]}")
    (dist, arg), = spec.items()
    if dist == "choices":
        if not isinstance(arg, list) or not arg:
            raise ScenarioError(file, f"{key}.choices", arg, "a non-empty list")
        return
    ok = (isinstance(arg, list) and len(arg) == 2
          and all(isinstance(a, (int, float)) and not isinstance(a, bool) and math.isfinite(a)
                  for a in arg) and arg[0] <= arg[1])
    if dist in ("integers", "log_integers"):
        # numpy draws int64: [0, 2**64] was "ValueError: high is out of bounds for int64"
        ok = ok and all(isinstance(a, int) and INT64_MIN <= a <= INT64_MAX for a in arg)
    if dist in ("log_uniform", "log_integers"):
        ok = ok and arg[0] > 0
    if dist == "uniform":  # numpy draws lo + (hi - lo) u: a width beyond float64 overflowed
        ok = ok and math.isfinite(float(arg[1]) - float(arg[0]))
    if not ok:
        raise ScenarioError(file, f"{key}.{dist}", arg,
                            "[lo, hi] with lo <= hi"
                            + (", integers within int64 (-2**63 to 2**63 - 1)"
                               if dist in ("integers", "log_integers") else "")
                            + (", lo > 0" if dist in ("log_uniform", "log_integers") else "")
                            + (", hi - lo finite in float64" if dist == "uniform" else ""))


def _check_cantilever_keys(fam: Family, file: str, key: str) -> None:
    rig = fam.ranges["rig"]
    if "material" in rig:
        spec = rig["material"]
        if isinstance(spec, dict) and "choices" not in spec:
            raise ScenarioError(file, f"{key}.rig.material", spec,
                                "a material name or {choices = [names]}")
        names = spec["choices"] if isinstance(spec, dict) else [spec]
        for n in names:
            if not isinstance(n, str) or n not in MATERIALS:
                raise ScenarioError(file, f"{key}.rig.material", n,
                                    "one of " + ", ".join(MATERIALS) + " (or give E and rho)")
        if "E" in rig or "rho" in rig:
            raise ScenarioError(file, f"{key}.rig.material", spec, "material or E and rho, not both")
    if "n_sensors" in rig and "sensors" in rig:
        raise ScenarioError(file, f"{key}.rig.n_sensors", rig["n_sensors"],
                            "n_sensors (drawn positions) or sensors (fixed positions), not both")
    for k in ("lowpass_hz", "highpass_hz"):
        v = fam.ranges["signal"].get(k)
        if isinstance(v, str) and v != "auto":
            raise ScenarioError(file, f"{key}.signal.{k}", v,
                                "a frequency [Hz], a range, or 'auto' (see CANTILEVER_DERIVED)")
    loc = fam.ranges["excitation"].get("location")
    if isinstance(loc, str) and loc != "sensor":
        raise ScenarioError(file, f"{key}.excitation.location", loc,
                            "a position [m], a range, or 'sensor' (on a drawn sensor)")


# --------------------------------------------------------------------------- drawing
def _draw(spec: Any, rng: np.random.Generator) -> Any:
    if not isinstance(spec, dict):
        return spec
    (dist, arg), = spec.items()
    if dist == "uniform":
        return float(rng.uniform(arg[0], arg[1]))
    if dist == "log_uniform":
        return float(math.exp(rng.uniform(math.log(arg[0]), math.log(arg[1]))))
    if dist == "integers":
        return int(rng.integers(arg[0], arg[1], endpoint=True))
    if dist == "log_integers":  # log-uniform on [lo - 1/2, hi + 1/2], rounded: each integer kept
        x = math.exp(rng.uniform(math.log(arg[0] - 0.5), math.log(arg[1] + 0.5)))
        return int(min(max(round(x), arg[0]), arg[1]))
    return arg[int(rng.integers(len(arg)))]


def peak_base_rotation(rig: dict[str, Any], excitation: dict[str, Any]) -> float:
    """Estimated peak rotation [rad] of a soft base under the hammer (rigid-beam estimate).

    The half-sine pulse gives the impulse ``I = 2 F tau / pi`` [N s] at distance ``a`` from the
    base (the tip if ``location`` is 0), an angular impulse ``H = I a``.  Taking the beam as
    rigid on the base spring (inertia ``J = m L^2 / 3`` about the base, ``m = rho w t L``), the
    base mode has ``omega = sqrt(k1 / J)`` and its peak rotation is ``H / (J omega) =
    H / sqrt(k1 J)``.  On the shipped soft base (50 N, 0.3 ms at the tip, k1 = 2000 N m/rad)
    this gives 4.3e-4 rad against about 4e-4 rad measured (models/cantilever/rig.py); a flexible
    beam on a stiff spring rotates less at its base than the rigid estimate, so the drawn
    fraction is an upper estimate of the realised one (``K3_force_ratio`` reports the realised
    size of the identified cubic force).
    """
    L = rig["length"]
    a = excitation["location"] or L
    impulse = 2.0 * excitation["peak_force"] * excitation["pulse_duration"] / math.pi
    mass = rig["rho"] * rig["width"] * rig["thickness"] * L
    J = mass * L**2 / 3.0
    return impulse * a / math.sqrt(rig["base_k1"] * J)


def eb_frequencies(rig: dict[str, Any], n: int) -> np.ndarray:
    """Euler-Bernoulli clamped-free frequencies [Hz] of modes 1..n of the rig's beam (the
    cantilever rig's :meth:`clamped_estimates`)."""
    return RIGS.get("cantilever").clamped_estimates(rig, n)


def _cantilever_rules(fam: Family, rig: dict[str, Any], exc: dict[str, Any],
                      sim: dict[str, Any], signal: dict[str, Any], derived: dict[str, Any],
                      rng: np.random.Generator) -> str | None:
    """Apply the derived cantilever keys in place; return why the draw is refused, or None."""
    if "material" in derived:
        rig["E"], rig["rho"] = MATERIALS[derived["material"]]
    L = rig["length"]
    if "n_sensors" in derived:
        # n sorted uniform positions conditioned on gaps >= g (root to first, between sensors):
        # the n + 1 spacings of sorted uniforms are Dirichlet(1, ..., 1), so the positions are
        # cumulative sums of g + (L - n g) d with d ~ Dirichlet(1^(n+1)) (the last spacing, to
        # the tip, unconstrained): no draw is refused for crowded sensors.
        n = int(derived["n_sensors"])
        g = MIN_SENSOR_GAP * L
        if n * g >= L:
            return f"{n} sensors cannot be {MIN_SENSOR_GAP:g} L apart"
        d = rng.dirichlet(np.ones(n + 1))
        pos = np.cumsum(g + (L - n * g) * d[:n])
        # 0.1 mm: a lab's tape measure, and short decimal files; never beyond the tip
        pos = np.minimum(np.floor(pos * 1e4) / 1e4, L)
        rig["sensors"] = [float(x) for x in pos]
    n_sensors = len(rig["sensors"]) or 3
    if "base_k1_ratio" in derived and rig["base"] == "soft":
        EI = rig["E"] * rig["width"] * rig["thickness"] ** 3 / 12.0
        rig["base_k1"] = float(derived["base_k1_ratio"] * EI / L)
    if rig["base"] != "soft":
        # a clamped base reads no spring: its keys are left at their defaults (None: left out
        # of the member), which the rig refuses otherwise (round 9); the ratio and fraction
        # are drawn all the same, so the other draws do not move
        rig["base_k1"] = rig["base_k3"] = None
    if exc.get("location") == "sensor":
        sensors = rig["sensors"] or [L / 3, 2 * L / 3, L]
        exc["location"] = float(sensors[int(rng.integers(len(sensors)))])
    if "cubic_fraction" in derived:
        if rig["base"] == "soft":
            q = peak_base_rotation(rig, exc)
            rig["base_k3"] = float(derived["cubic_fraction"] * rig["base_k1"] / q**2)
    for key in ("highpass_hz", "lowpass_hz"):
        if signal.get(key) == "auto":
            # the lab's cut-offs from the member's nominal geometry, by the rig's one rule
            # (models/cantilever/euler_bernoulli.py auto_cutoff, also behind a scenario's "auto")
            try:
                signal[key] = RIGS.get(fam.base.rig).auto_signal(rig, key)[0]
            except ValueError as e:
                return f"signal.{key} = 'auto': {e}"
    if rig["n_segments"] < MIN_SEGMENTS_PER_MODE * n_sensors:
        return f"{rig['n_segments']} segments for {n_sensors} sensed modes"
    f = eb_frequencies(rig, n_sensors)
    if f[-1] > MAX_MODE_FRACTION_OF_FS * sim["sample_rate"]:
        return f"mode {n_sensors} at {f[-1]:.0f} Hz"
    if f[0] * sim["duration"] < MIN_MODE1_PERIODS:
        return f"mode 1 at {f[0]:.0f} Hz: {f[0] * sim['duration']:.0f} periods in the record"
    if rig["damping_ratio"] * f[-1] / f[0] > MAX_SENSED_DAMPING:
        return f"mode {n_sensors} damped {rig['damping_ratio'] * f[-1] / f[0]:.2f}"
    return None


def draw_member(fam: Family, k: int, refusals: list[str] | None = None) -> tuple[Scenario, int]:
    """Member ``k`` of a family and the attempt that gave it (see the module docs).

    ``refusals``, if given, receives the reason of every refused draw (for reports).

    Raises
    ------
    ScenarioError
        If :data:`MAX_ATTEMPTS` draws are all refused (the last reason given).
    """
    base = fam.base
    why = ""
    for attempt in range(MAX_ATTEMPTS):
        rng = np.random.default_rng([fam.seed, k, attempt])
        tables = {"rig": dict(base.rig_params), "simulation": dict(base.simulation),
                  "excitation": dict(base.excitation), "signal": dict(base.signal)}
        for key in base.rules:  # a base's "auto" cut-off follows each member, not the base
            if key.startswith("signal."):
                tables["signal"][key.removeprefix("signal.")] = "auto"
        if base.rig == "fivebar":
            for key in ("th1_0", "th4_0"):  # the rig picks a usable pose for the drawn geometry
                if key not in fam.ranges["rig"]:
                    tables["rig"].pop(key, None)
        derived: dict[str, Any] = {}
        for t in RANGE_TABLES:
            for key, spec in fam.ranges[t].items():
                value = _draw(spec, rng)
                if base.rig == "cantilever" and t == "rig" and key in (
                        "material", "n_sensors", "base_k1_ratio", "cubic_fraction"):
                    derived[key] = value
                else:
                    tables[t][key] = value
        if base.rig == "cantilever":
            try:
                why = _cantilever_rules(fam, tables["rig"], tables["excitation"],
                                        tables["simulation"], tables["signal"], derived, rng) or ""
            except (OverflowError, ZeroDivisionError) as e:  # e.g. a length of 1e300 m squared
                why = f"the Euler-Bernoulli estimates leave float64 ({e})"
            if why:
                if refusals is not None:
                    refusals.append(why)
                continue
        raw = member_dict(fam, k, attempt, tables)
        try:
            return scenario_from_dict(raw, file=f"<family {fam.name} member {k}>",
                                      stem=fam.member_name(k), standalone=False), attempt
        except ScenarioError as e:
            why = f"{e.key}: {e.allowed}"
            if refusals is not None:
                refusals.append(why)
    raise ScenarioError(f"<family {fam.name}>", f"families.{fam.name}", k,
                        f"member {k}: {MAX_ATTEMPTS} draws all refused (last: {why}); widen or "
                        "move the ranges")


def member_dict(fam: Family, k: int, attempt: int, tables: dict[str, dict[str, Any]]) -> dict[str, Any]:
    """The scenario tables of a member (values ``None`` left out: they are the defaults)."""
    base = fam.base
    raw: dict[str, Any] = {
        "scenario": {"name": fam.member_name(k), "rig": base.rig, "seed": base.seed,
                     "description": f"member {k} of family {fam.name} (seed {fam.seed}, draw "
                                    f"{attempt}) from {base.name}",
                     "tags": sorted({*base.tags, f"family:{fam.name}"})},
        **{t: {key: v for key, v in tables[t].items() if v is not None} for t in RANGE_TABLES},
        "noise": dict(base.noise),
    }
    if base.identify is not None:
        raw["identify"] = dict(base.identify)
    return raw


#: A family of more members than this is announced before it is drawn, and its progress given
#: at every tenth of it (:func:`family_members`): each member is drawn and validated as a
#: scenario, 36-270 ms a member on the shared machine (round 7), so 10,000 members took 6-45
#: minutes in silence before a sweep's first line.  The shipped families have 8-40 members.
ANNOUNCE_MEMBERS = 100
#: Seconds a member may take to draw under load (round 7's slowest, 0.27 s), for the announcement.
SLOW_MEMBER_S = 0.27


def family_members(fam: Family, progress: Callable[[str], None] | None = None) -> list[Scenario]:
    """Every member of a family, in index order (see the module docs for the drawing rule).

    Parameters
    ----------
    fam : Family
        The family.
    progress : callable, optional
        ``progress(line)`` receives one line before a family of more than
        :data:`ANNOUNCE_MEMBERS` members is drawn, with the time it may take, and one at every
        tenth of its members (the ``testbed`` command prints them to standard error).
    """
    loud = progress is not None and fam.members > ANNOUNCE_MEMBERS
    if loud:
        most = fam.members * SLOW_MEMBER_S
        progress(f"drawing family {fam.name}: {fam.members} members, each validated as a "
                 f"scenario (up to {SLOW_MEMBER_S:g} s a member: up to "
                 + (f"{most / 60:.0f} min)" if most >= 60 else f"{most:.0f} s)"))
    step = math.ceil(fam.members / 10)
    t0 = time.perf_counter()
    members = []
    for k in range(fam.members):
        members.append(draw_member(fam, k)[0])
        if loud and ((k + 1) % step == 0 or k + 1 == fam.members):
            progress(f"family {fam.name}: {k + 1} of {fam.members} members drawn "
                     f"({time.perf_counter() - t0:.0f} s)")
    return members


# --------------------------------------------------------------------------- writing
def _toml_value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ValueError(f"cannot write {v} to TOML")
        return repr(v)  # shortest repr: reads back to the identical float
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def scenario_toml(sc: Scenario) -> str:
    """A scenario as TOML text that :func:`~testbed.pipeline.scenario.load_scenario` reads back to
    an equal Scenario (``None`` values, i.e. defaults chosen by the rig, are left out)."""
    lines = ["# Written by testbed.studies.study.write_family: a member of a scenario family.",
             "", "[scenario]"]
    head = {"name": sc.name, "rig": sc.rig, "seed": sc.seed, "description": sc.description,
            "tags": list(sc.tags)}
    lines += [f"{k} = {_toml_value(v)}" for k, v in head.items()]
    tables = {"rig": sc.rig_params, "simulation": sc.simulation, "excitation": sc.excitation,
              "noise": sc.noise, "signal": sc.signal, "identify": sc.identify or {}}
    for t, d in tables.items():
        if not d:
            continue
        lines += ["", f"[{t}]"] + [f"{k} = {_toml_value(v)}" for k, v in d.items() if v is not None]
    if sc.score:
        lines += ["", "[score]"] + [f"{m}_{b} = {_toml_value(x)}"
                                    for m, bounds in sc.score.items() for b, x in bounds.items()]
    return "\n".join(lines) + "\n"


#: The first line of every member file (:func:`scenario_toml`): a file at a member's path that
#: begins otherwise is the user's and is not replaced (:func:`write_members`).
MEMBER_FILE = FileKind("a member file written by `testbed family write`",
                       (b"# Written by testbed.studies.study.write_family",), text=True)


def write_members(members: list[Scenario], out_dir: str | os.PathLike) -> list[Path]:
    """Write scenarios as ``<out_dir>/<name>.toml`` (atomically; the folder is created).

    A file at a member's path that is not a member file (:data:`MEMBER_FILE`: the user's own
    scenario of that name, or any other file) is refused before anything is written (round
    27: it was replaced); an earlier member file is replaced, as before.

    Returns
    -------
    list of Path
        The written files, in the given order; each reloads to a Scenario equal to its member.

    Raises
    ------
    InputError
        A member's path holds another file.
    """
    out = Path(out_dir)
    for sc in members:
        p = out / f"{sc.name}.toml"
        refuse_foreign(p, MEMBER_FILE, expected="another --out folder, or remove the file")
    out.mkdir(parents=True, exist_ok=True)
    written = []
    for sc in members:
        p = out / f"{sc.name}.toml"
        atomic_write_text(p, scenario_toml(sc))
        written.append(p)
    return written
