"""Study files: a method comparison over scenarios x noise levels x seeds x identifiers.

A study is a TOML file in ``studies/``::

    [study]
    name = "default"                    # = file stem
    description = "..."
    scenarios = ["cantilever_stiff_impact", "fivebar_multisine"]   # names in scenarios/ or paths
    noise = [0.0, 1.0, 5.0]             # sensor noise, % of channel RMS (replaces the scenario's)
    seeds = [0, 1, 2]                   # noise seeds (replace the scenario's seed)
    identifiers = ["ls_sindy", "sindy_pi"]
    plugins = []                        # optional: modules (dotted names or .py paths) that
                                        # register extra rigs / identifiers

    [identifiers.ls_sindy]              # optional hyperparameters, checked like a scenario's
    rcond = 1e-8                        # [identify] table against the identifier's declared
                                        # hyperparameters

    [thresholds.ls_sindy]               # optional bars for this identifier only, like a
    trac_min = 0.9                      # scenario's [score] table

    [families.beams]                    # optional: scenarios drawn from ranges
    base = "cantilever_stiff_impact"    # (testbed.studies.family)
    members = 50

Thresholds per identifier: a cell of identifier ``m`` is held to ``[thresholds.m]`` when the
study declares it; otherwise to its scenario's ``[score]`` only if that scenario's
``[identify]`` names ``m`` (the bars were set for that method) or the scenario names no
identifier (its bars are declared for whichever the study brings); otherwise to nothing (its
verdict is "no verdict" and it counts in no pass rate).  An identifier is never held to bars
set for another.  Family members carry no ``[score]`` of their own.

The grid is every (scenario, noise, seed, identifier).  A combination whose
identifier kind ("structural" / "mechanical") differs from the scenario rig's
kind cannot be run (a structural identifier has no model of a linkage) and is
skipped: :meth:`Study.skipped` lists those, and the study is rejected if an
identifier, or a scenario, matches nothing.  Every problem raises
:class:`~testbed.core.errors.ScenarioError` naming the file, the key, the value and
what is allowed.  Scenario paths are relative to the study file.  Each runnable
(scenario, identifier) pair is also checked as a scenario's ``[identify]`` would be
(term names for the rig's channels, windows against its record, simulation budget),
with the study's hyperparameters over the scenario's own where the identifier is the
scenario's method, so a study fails at load, not in its hundredth cell.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from testbed.core.budget import STUDY_CELL_BUDGET
from testbed.core.errors import BudgetError, InputError, ScenarioError
from testbed.core.registry import import_plugin
from testbed.core.schema import ONE_LINE, ONE_LINE_DOC, Field, validate_header
from testbed.pipeline.plugins import IDENTIFIERS, RIGS
from testbed.pipeline.scenario import (
    MAX_SEED,
    NAME_PATTERN,
    NAME_PATTERN_DOC,
    SCENARIO_DIR,
    Scenario,
    _check_stem,
    _validate_identify,
    _validate_score,
    check_identifier_for_rig,
    file_problem,
    load_scenario,
    read_toml_file,
    resolve_path,
    shipped_dir,
)
from testbed.studies.family import (
    MEMBER_SEP,
    Family,
    family_members,
    family_of,
    parse_family,
    write_members,
)

#: Shipped study files, found by name (``$TESTBED_STUDIES`` overrides).
STUDY_DIR = Path(os.environ.get("TESTBED_STUDIES", shipped_dir("studies")))

STUDY_SCHEMA = {
    "name": Field(str, doc="study name; must equal the file name without .toml",
                  pattern=NAME_PATTERN, pattern_doc=NAME_PATTERN_DOC),
    "description": Field(str, "", pattern=ONE_LINE, pattern_doc=ONE_LINE_DOC,
                         doc="one line for listings and reports"),
    "scenarios": Field(list, [], item_type=str,
                       doc="scenario names (in scenarios/) or .toml paths relative to the study file "
                           "(may be empty when the study declares [families.<name>])"),
    "noise": Field(list, item_type=float, min_items=1, min=0.0, max=100.0, unit="% of channel RMS",
                   doc="sensor-noise levels; each replaces the scenario's [noise] rms_percent"),
    "seeds": Field(list, item_type=int, min_items=1, min=0, max=MAX_SEED,
                   doc="noise seeds; each replaces the scenario's seed"),
    "identifiers": Field(list, item_type=str, min_items=1, doc="registered identifier names"),
    "plugins": Field(list, [], item_type=str,
                     doc="modules (dotted names or .py paths relative to the study file) imported "
                         "before validation and in every worker; they register extra rigs or "
                         "identifiers"),
}
SECTIONS = ("study", "identifiers", "families", "thresholds")


@dataclass(frozen=True)
class Study:
    """A validated study.

    Attributes
    ----------
    name, description : str
    scenarios : tuple of Scenario
        As loaded from their files (noise and seed are replaced per cell).
    noise : tuple of float
        Noise levels [% of channel RMS].
    seeds : tuple of int
    identifiers : tuple of str
    params : dict of str to dict
        Hyperparameters per identifier (``{}`` where the study gives none).
    plugins : tuple of str
        Absolute paths or dotted module names, imported before any lookup.
    thresholds : dict of str to dict
        Bars per identifier (``{metric: {"min"|"max": value}}``); see the module docs.
    families : tuple of Family
        The declared families; their members are in ``scenarios`` (after the named ones).
    path : str, optional
        The study file.
    """

    name: str
    scenarios: tuple[Scenario, ...]
    noise: tuple[float, ...]
    seeds: tuple[int, ...]
    identifiers: tuple[str, ...]
    description: str = ""
    params: dict[str, dict[str, Any]] = field(default_factory=dict)
    plugins: tuple[str, ...] = ()
    thresholds: dict[str, dict[str, dict[str, float]]] = field(default_factory=dict)
    families: tuple[Family, ...] = ()
    path: str | None = field(default=None, compare=False)

    def combinations(self) -> list[tuple[Scenario, str]]:
        """(scenario, identifier) pairs whose kinds agree, in study order.

        Each scenario's ``score`` is the bars that identifier is held to
        (:meth:`thresholds_for`), so a sweep judges every cell by its own identifier's bars.
        """
        return [(sc.replace(score=self.thresholds_for(sc, m)), m) for sc in self.scenarios
                for m in self.identifiers if sc.kind == _identifier_kind(m)]

    def thresholds_for(self, scenario: Scenario, identifier: str) -> dict[str, dict[str, float]]:
        """The bars ``identifier`` is held to on ``scenario`` (see the module docs)."""
        if identifier in self.thresholds:
            return self.thresholds[identifier]
        if scenario.identify is None or scenario.identify.get("method") == identifier:
            return scenario.score
        return {}

    def skipped(self) -> list[tuple[str, str, str]]:
        """(scenario, identifier, reason) of the pairs left out because the kinds differ."""
        return [(sc.name, m, f"identifier kind {_identifier_kind(m)!r} != rig kind {sc.kind!r}")
                for sc in self.scenarios for m in self.identifiers
                if sc.kind != _identifier_kind(m)]

    def n_cells(self) -> int:
        """Number of runnable cells: combinations x noise levels x seeds."""
        return len(self.combinations()) * len(self.noise) * len(self.seeds)


def _identifier_kind(name: str) -> str:
    """Kind of the registered identifier ``name`` (a scenario carries its rig's: ``Scenario.kind``)."""
    return IDENTIFIERS.get(name).kind


def import_plugins(plugins: tuple[str, ...] | list[str]) -> None:
    """Import each plugin once (a dotted module name, or a ``.py`` file path): the one
    importer, :func:`testbed.core.registry.import_plugin` (a file is imported under a module
    name derived from its absolute path, so its registrations run once per process)."""
    for p in plugins:
        import_plugin(p)


def resolve_study_path(name_or_path: str | os.PathLike) -> Path:
    """A path as given, or ``studies/<name>.toml`` for a bare study name."""
    return resolve_path(name_or_path, STUDY_DIR)


def _no_duplicates(values: list, file: str, key: str) -> None:
    seen = set()
    for i, v in enumerate(values):
        if v in seen:
            raise ScenarioError(file, f"{key}[{i}]", v, f"duplicate; each entry of {key} must be unique")
        seen.add(v)


def load_study(name_or_path: str | os.PathLike,
               progress: Callable[[str], None] | None = None) -> Study:
    """Read and validate a study file (a path, or a name in ``studies/``).

    Parameters
    ----------
    name_or_path : str or os.PathLike
        A ``.toml`` path, or the name of a shipped study (its file stem).
    progress : callable, optional
        Receives a line before a large family is drawn and as it is drawn
        (:func:`testbed.studies.family.family_members`).

    Returns
    -------
    Study
        The grid (scenarios x noise levels x seeds x identifiers), validated.

    Raises
    ------
    ScenarioError
        For a missing or malformed file, an unknown section or key, a value of
        the wrong type or out of bounds, an empty or duplicated list entry, an
        unknown scenario or identifier, bad hyperparameters, or a grid with
        nothing to run.
    """
    path = resolve_study_path(name_or_path)
    file = str(path)
    _check_stem(path, "study", STUDY_DIR)
    raw = read_toml_file(path, "study")
    return study_from_dict(raw, file=file, base=path.parent, stem=path.stem, progress=progress)


def study_from_dict(raw: dict[str, Any], *, file: str = "<dict>", base: Path | None = None,
                    stem: str | None = None,
                    progress: Callable[[str], None] | None = None) -> Study:
    """Validate a study given as a dict of TOML tables (paths relative to ``base``); ``progress``
    as in :func:`load_study`."""
    base = base if base is not None else Path.cwd()
    _check_raw_grid(raw, file)
    head = validate_header(raw, sections=SECTIONS, header="study", schema=STUDY_SCHEMA, file=file,
                           stem=stem, other=("scenario", "a scenario file (it has [scenario]), not a "
                                                         "study; run it with `testbed run`"))
    for key in ("scenarios", "noise", "seeds", "identifiers", "plugins"):
        _no_duplicates(head[key], file, f"study.{key}")
    fam_table = raw.get("families", {})
    if not isinstance(fam_table, dict):
        raise ScenarioError(file, "families", fam_table, "expected tables [families.<name>]")
    if not head["scenarios"] and not fam_table:
        raise ScenarioError(file, "study.scenarios", [], "at least one scenario, or a "
                                                          "[families.<name>] table")

    plugins = tuple(str((base / p).resolve()) if p.endswith(".py") else p for p in head["plugins"])
    for i, p in enumerate(plugins):
        try:
            import_plugins([p])
        except Exception as e:
            raise ScenarioError(file, f"study.plugins[{i}]", head["plugins"][i],
                                f"an importable module or .py file; importing failed: "
                                f"{type(e).__name__}: {e}") from None

    for i, m in enumerate(head["identifiers"]):
        if m not in IDENTIFIERS:
            raise ScenarioError(file, f"study.identifiers[{i}]", m,
                                "expected a registered identifier, one of "
                                + ", ".join(IDENTIFIERS.names()))

    scenarios = []
    for i, s in enumerate(head["scenarios"]):
        spath = resolve_path(s)
        if not spath.is_absolute() and (s.endswith(".toml") or len(Path(s).parts) > 1):
            spath = base / spath
        problem = file_problem(spath, "scenario")
        if problem is not None and not problem.startswith("no such"):
            raise ScenarioError(file, f"study.scenarios[{i}]", s, f"{spath}: {problem}")
        if problem is not None:
            known = sorted(p.stem for p in SCENARIO_DIR.glob("*.toml"))
            raise ScenarioError(file, f"study.scenarios[{i}]", s,
                                f"no scenario file {spath}; expected a name among "
                                f"{', '.join(known) or '(none in ' + str(SCENARIO_DIR) + ')'} "
                                "or a .toml path relative to the study file")
        scenarios.append(load_scenario(spath, standalone=False))  # bars for the study's identifiers

    families = tuple(parse_family(n, t, file=file, base_dir=base) for n, t in fam_table.items())
    # the grid's size before its members are drawn and validated (36 ms each, 0.27 s under
    # load): 10,000 members x 11 noise levels were drawn for 6 minutes, then refused for it
    kinds = [_identifier_kind(m) for m in head["identifiers"]]
    _check_cell_budget(sum(kinds.count(sc.kind) for sc in scenarios)
                       + sum(f.members * kinds.count(f.base.kind) for f in families),
                       head, families, file)
    for fam in families:
        try:
            scenarios.extend(family_members(fam, progress))
        except ScenarioError as e:  # no member drawn: the study file's ranges, named as such
            if not e.file.startswith("<family"):
                raise
            raise ScenarioError(file, e.key, e.value, e.allowed) from None
    params = _validate_params(raw.get("identifiers", {}), head["identifiers"], file)
    thresholds = _validate_thresholds(raw.get("thresholds", {}), head["identifiers"], file)
    study = Study(name=head["name"], description=head["description"], scenarios=tuple(scenarios),
                  noise=tuple(head["noise"]), seeds=tuple(head["seeds"]),
                  identifiers=tuple(head["identifiers"]), params=params, plugins=plugins,
                  thresholds=thresholds, families=families, path=file)
    _check_grid(study, head, file)
    _check_cells(study, file)
    return study


def _check_cells(study: Study, file: str) -> None:
    """Each runnable (scenario, identifier) pair's hyperparameters against the scenario's data.

    The study's hyperparameters go over the scenario's own ``[identify]`` table where the
    identifier is the scenario's method (as the sweep runs them).
    """

    for sc, m in study.combinations():
        own = sc.identify if sc.identify and sc.identify["method"] == m else {"method": m}
        params = {**own, **study.params.get(m, {})}
        try:
            check_identifier_for_rig(RIGS.get(sc.rig), sc.rig_params, sc.simulation, params,
                                     file=file, section=f"identifiers.{m}")
        except ScenarioError as e:
            raise type(e)(file, e.key, e.value, f"{e.allowed} (for scenario {sc.name!r})") from None


def _validate_thresholds(table: Any, identifiers: list[str],
                         file: str) -> dict[str, dict[str, dict[str, float]]]:
    """``[thresholds.<identifier>]`` tables, each checked like a scenario's ``[score]`` against the
    scores of the identifier's kind."""
    if not isinstance(table, dict):
        raise ScenarioError(file, "thresholds", table, "expected tables [thresholds.<identifier>]")
    out = {}
    for name, sub in table.items():
        key = f"thresholds.{name}"
        if name not in identifiers:
            raise ScenarioError(file, key, sub, "thresholds for an identifier not in "
                                "study.identifiers; allowed: " + ", ".join(identifiers))
        try:
            out[name] = _validate_score(sub, _identifier_kind(name), file)
        except ScenarioError as e:
            k = (e.key or "").replace("score", key, 1)
            raise ScenarioError(file, k, e.value, e.allowed) from None
    return out


def write_family(study: Study | str | os.PathLike, out_dir: str | os.PathLike,
                 family: str | None = None) -> list[Path]:
    """Write the members of a study's families as scenario files ``<out_dir>/<member>.toml``.

    Parameters
    ----------
    study : Study or str or path
        A loaded study, or its name / file (loaded with :func:`load_study`).
    out_dir : path
        Created if missing; files are written atomically.
    family : str, optional
        Only this family (default: every family of the study).

    Returns
    -------
    list of Path
        The written files, in family and member order.  Each reruns alone with
        ``testbed run <file>`` (members carry their base's ``[identify]`` and, as ``[score]``,
        the study's bars for that identifier, :meth:`Study.thresholds_for`) and reloads to a
        Scenario equal to the member with those bars.

    Raises
    ------
    ScenarioError
        If the study declares no family (of that name).
    """
    st = study if isinstance(study, Study) else load_study(study)
    fams = [f for f in st.families if family is None or f.name == family]
    if not fams:
        raise ScenarioError(str(st.path), "families", family,
                            "a family of the study: " + (", ".join(f.name for f in st.families)
                                                          or "(the study declares none)"))
    names = {f.member_name(k) for f in fams for k in range(f.members)}
    _check_no_stale_members(Path(out_dir), fams, names)
    # each member carries the bars the study holds its own [identify] method to, so that it
    # reruns alone with a verdict
    return write_members([sc.replace(score=st.thresholds_for(sc, sc.identify["method"]))
                          if sc.identify else sc
                          for sc in st.scenarios if sc.name in names], out_dir)


def _check_no_stale_members(out: Path, fams: list[Family], names: set[str]) -> None:
    """Refuse to write into ``out`` beside member files of the written families that this write
    does not produce (``<family>__<k>.toml`` with ``k`` at or beyond the family's ``members``).

    Written into a folder that held a larger draw of the family, the new members replaced
    theirs and the rest stayed in silence (round 12: 10 members, then 2, left 8 files of the
    old draw beside the 2 new ones, which a run or sweep over the folder then took as members).
    """
    if not out.is_dir():
        return
    wanted = {f.name for f in fams}
    stale = sorted(p.name for p in out.glob(f"*{MEMBER_SEP}*.toml")
                   if family_of(p.stem) in wanted and p.stem != family_of(p.stem)
                   and p.stem not in names)
    if stale:
        members = ", ".join(f"{f.name}: {f.members}" for f in fams)
        raise InputError(f"{out}: holds {len(stale)} member file(s) this write does not "
                         f"produce ({', '.join(stale[:3])}{', ...' if len(stale) > 3 else ''}; "
                         f"the families now have {members} members); expected a folder without "
                         "them: remove them or write to another folder")


def _validate_params(table: Any, identifiers: list[str], file: str) -> dict[str, dict[str, Any]]:
    if not isinstance(table, dict):
        raise ScenarioError(file, "identifiers", table, "expected tables [identifiers.<name>]")
    params: dict[str, dict[str, Any]] = {m: {} for m in identifiers}
    for name, sub in table.items():
        key = f"identifiers.{name}"
        if name not in identifiers:
            raise ScenarioError(file, key, sub, "hyperparameters for an identifier not in "
                                "study.identifiers; allowed: " + ", ".join(identifiers))
        if not isinstance(sub, dict):
            raise ScenarioError(file, key, sub, f"expected a table [{key}] of hyperparameters")
        if "method" in sub:
            raise ScenarioError(file, f"{key}.method", sub["method"],
                                "not allowed here: the table name is the identifier")
        try:
            checked = _validate_identify({"method": name, **sub}, file)
        except ScenarioError as e:
            k = (e.key or "").replace("identify.", f"{key}.", 1)
            # the keys the message names are this table's too ("here identify.optimizer = ...")
            allowed = e.allowed.replace("identify.", f"{key}.") if e.allowed else e.allowed
            raise ScenarioError(file, k, e.value, allowed) from None
        assert checked is not None
        checked.pop("method")
        # ints given for float hyperparameters come back widened, so 1 and 1.0 are one cell
        params[name] = checked
    return params


def _check_cell_budget(n_pairs: int, head: dict[str, Any], families: tuple, file: str) -> None:
    """Refuse a grid of more than :data:`STUDY_CELL_BUDGET` cells (``n_pairs`` scenario-identifier
    pairs x noise levels x seeds), naming its longest factor."""
    cells = n_pairs * len(head["noise"]) * len(head["seeds"])
    if cells > STUDY_CELL_BUDGET:
        factors = {"study.scenarios": (len(head["scenarios"]), head["scenarios"]),
                   **{f"families.{f.name}.members": (f.members, f.members) for f in families},
                   "study.identifiers": (len(head["identifiers"]), head["identifiers"]),
                   "study.noise": (len(head["noise"]), head["noise"]),
                   "study.seeds": (len(head["seeds"]), head["seeds"])}
        key = max(factors, key=lambda k: factors[k][0])  # the longest: first in this order on a tie
        raise BudgetError(file, key, factors[key][1],
                          f"the grid has {cells} cells ({n_pairs} scenario-identifier pairs x "
                          f"{len(head['noise'])} noise levels x {len(head['seeds'])} seeds); the "
                          f"budget is {STUDY_CELL_BUDGET} (testbed.core.budget.STUDY_CELL_BUDGET)")


def _check_raw_grid(raw: dict[str, Any], file: str) -> None:
    """Refuse, before any value is checked, a grid whose noise levels times seeds alone exceed
    :data:`STUDY_CELL_BUDGET` (every cell has at least one scenario-identifier pair, and a study
    with none is refused anyway), naming the longer list.

    The schema checks each item first, about 5 us each: a study of 10**7 seeds took ~50 s to
    be refused for its size (round 26).  Lists only: another type is the schema's to name.
    """
    head = raw.get("study") if isinstance(raw, dict) else None
    lists = {k: head[k] for k in ("noise", "seeds")
             if isinstance(head, dict) and isinstance(head.get(k), list)} if head else {}
    if len(lists) < 2:
        return
    cells = len(lists["noise"]) * len(lists["seeds"])
    if cells > STUDY_CELL_BUDGET:
        key = max(lists, key=lambda k: len(lists[k]))  # noise on a tie
        raise BudgetError(file, f"study.{key}", lists[key],
                          f"the grid has at least {cells} cells ({len(lists['noise'])} noise levels "
                          f"x {len(lists['seeds'])} seeds, each with one scenario-identifier pair "
                          f"or more); the budget is {STUDY_CELL_BUDGET} "
                          "(testbed.core.budget.STUDY_CELL_BUDGET)")


def _check_grid(study: Study, head: dict[str, Any], file: str) -> None:
    pairs = study.combinations()
    _check_cell_budget(len(pairs), head, study.families, file)
    for i, m in enumerate(study.identifiers):
        if not any(pm == m for _, pm in pairs):
            raise ScenarioError(file, f"study.identifiers[{i}]", m,
                                f"a {_identifier_kind(m)} identifier but no scenario has a rig of that "
                                "kind; every cell of it would be skipped")
    named = len(head.get("scenarios") or ())
    for i, sc in enumerate(study.scenarios):
        if not any(ps.name == sc.name for ps, _ in pairs):
            if i < named:
                key, value, what = f"study.scenarios[{i}]", head["scenarios"][i], "rig kind"
            else:  # a family member (after the named scenarios): name its family
                fam = next(f for f in study.families if f.name == family_of(sc.name))
                key, value, what = f"families.{fam.name}", fam.base.name, "its members' rig kind"
            raise ScenarioError(file, key, value,
                                f"{what} {sc.kind!r} but no identifier of that kind is listed "
                                f"(study.identifiers: {', '.join(study.identifiers)}); every cell "
                                "of it would be skipped")
    names = [sc.name for sc in study.scenarios]
    _no_duplicates(names, file, "study.scenarios (names)")

