"""Scenario files: rig + excitation + noise + signal chain + identifier + score thresholds.

A scenario is a TOML file in ``scenarios/``::

    [scenario]            name (= file stem), rig, seed, description, tags, extends
    [rig]                 the rig's parameters (schema from the rig)
    [simulation]          duration, sample rate ... (schema from the rig)
    [excitation]          type = ... and that type's parameters (schema from the rig)
    [noise]               rms_percent, signals
    [signal]              the signal chain a lab would apply (schema by rig kind)
    [identify]            method = registered identifier, plus its hyperparameters
    [score]               <metric>_min / <metric>_max thresholds

``extends = "other.toml"`` (path relative to the file) starts from another
scenario and overrides it key by key, so variants (noise levels, identifiers)
state only what differs.  Two tables are replaced whole rather than merged:
``[identify]`` (a new identifier must not inherit another's hyperparameters) and
``[score]``.  A child that sets ``excitation.type`` to another value inherits only the
parent's excitation keys its new type also reads (amplitude, centring gains).
**A child keeps its parent's ``[score]`` unless it declares its own** (even when it
replaces ``[identify]``): a variant is held to its parent's bars until it states
new ones, and never passes with no bars at all.  ``[score]`` without ``[identify]``
is an error in a scenario run on its own (there would be nothing to score); a study
may use such a scenario, its identifiers being held to the scenario's bars.

Everything is checked when the file loads, before anything is simulated: every key's
type and range (the rig's, the signal chain's and the identifier's declared
hyperparameters), cross-key rules (cut-offs below the Nyquist frequency, windows shorter
than the record, the impact on a sensor, an identifier of the rig's kind, term names the
data can provide) and the budget of memory and integration steps
(:mod:`testbed.core.budget`).  Every problem raises :class:`ScenarioError` naming the file,
the key, the value and what is allowed; files that are not UTF-8 TOML, nested too deeply,
too large or not scenarios get one line without their content.
"""

from __future__ import annotations

import contextlib
import copy
import dataclasses
import hashlib
import json
import math
import operator
import os
import re
import stat
import sys
import tomllib
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from testbed.core.budget import check_cost, check_steps
from testbed.core.errors import ArgumentError, BudgetError, RigError, ScenarioError, unusable_path
from testbed.core.kinds import metric_names, metric_range
from testbed.core.registry import REGISTERED_NAME, REGISTERED_NAME_DOC
from testbed.core.schema import (
    ONE_LINE,
    ONE_LINE_DOC,
    Field,
    near_miss,
    unknown_key_hint,
    validate_header,
    validate_table,
    validate_variant,
)
from testbed.pipeline.plugins import IDENTIFIERS, RIGS
from testbed.pipeline.signal_chain import (
    SIGNAL_SCHEMAS,
    check_free_decay,
    check_keys_used,
    check_signal,
    rig_auto_keys,
)

#: Scenario and study names: a safe file stem (no path separators, not "." or "..").
NAME_PATTERN, NAME_PATTERN_DOC = REGISTERED_NAME, REGISTERED_NAME_DOC  # one rule (core)
#: Largest scenario or study file read [bytes]: the shipped ones are under 5 kB.
MAX_FILE_BYTES = 1 << 20
#: Deepest nesting of tables and lists accepted: scenario and study files need 3
#: ([identifiers.<name>] holding a list); 16 leaves room without risking recursion limits.
MAX_DEPTH = 16
#: Longest chain of ``extends``: the shipped scenarios use 2.
MAX_EXTENDS = 32



def shipped_dir(what: str) -> Path:
    """Folder of the shipped ``"scenarios"`` or ``"studies"`` files.

    In an installed wheel they are package data, ``testbed/data/<what>`` (``pyproject.toml``
    maps the checkout's top-level folders there); in a checkout (editable install, or
    ``PYTHONPATH``) they are the top-level folders ``<what>/`` themselves, the source of truth.
    """
    installed = Path(__file__).resolve().parents[1] / "data" / what
    if installed.is_dir():
        return installed
    return Path(__file__).resolve().parents[2] / what


#: Shipped scenario files, found by name (``$TESTBED_SCENARIOS`` overrides).
SCENARIO_DIR = Path(os.environ.get("TESTBED_SCENARIOS", shipped_dir("scenarios")))

#: Largest noise seed: seeds are stored as 64-bit signed integers (HDF5 dataset attributes,
#: the results file's ``seed`` column), which hold at most 2**63 - 1.
MAX_SEED = 2**63 - 1

HEADER_SCHEMA = {
    "name": Field(str, doc="scenario name; must equal the file name without .toml",
                  pattern=NAME_PATTERN, pattern_doc=NAME_PATTERN_DOC),
    "rig": Field(str, doc="registered rig name (see `testbed list`)"),
    "seed": Field(int, 0, min=0, max=MAX_SEED, doc="seed of the measurement noise"),
    "description": Field(str, "", pattern=ONE_LINE, pattern_doc=ONE_LINE_DOC, doc="one line for listings"),
    # a tag "" or of blanks alone (a no-break space too) selects nothing and lists as a gap
    # (round 25: accepted)
    "tags": Field(list, [], item_type=str, pattern=ONE_LINE, visible=True,
                  pattern_doc=ONE_LINE_DOC, doc="free tags for selecting scenarios"),
    "extends": Field(str, "", doc="scenario file this one starts from (relative path)"),
}

NOISE_SCHEMA = {
    "rms_percent": Field(float, 0.0, unit="% of channel RMS", min=0.0, max=100.0,
                         doc="white Gaussian sensor noise, standard deviation as % of each "
                             "channel's noise-free RMS about its mean"),
    "signals": Field(list, None, item_type=str,
                     doc="measured signals that get noise (default: the rig's sensors)"),
}

SECTIONS = ("scenario", "rig", "simulation", "excitation", "noise", "signal", "identify", "score")


@dataclass(frozen=True)
class Scenario:
    """A validated scenario.  Sections are plain dicts with defaults filled in.

    ``kind`` is the rig's kind (``"structural"``, ``"mechanical"``, ...), taken from the
    registered rig when the scenario is built: every later step (signal chain, scorer, run
    store, study) reads it here instead of asking the registry again.  Left empty in a direct
    construction, it is filled from the registry; a kind that contradicts the rig's is refused.

    ``rules`` holds the settings the loader resolved by a stated rule, ``"section.key"`` ->
    the rule with the estimates it used (e.g. ``"signal.lowpass_hz"`` written as ``"auto"``:
    the section holds the resolved value, see :func:`resolve_auto_signal`); run.json keeps both.
    """

    name: str
    rig: str
    seed: int = 0
    description: str = ""
    tags: tuple[str, ...] = ()
    rig_params: dict[str, Any] = field(default_factory=dict)
    simulation: dict[str, Any] = field(default_factory=dict)
    excitation: dict[str, Any] = field(default_factory=dict)
    noise: dict[str, Any] = field(default_factory=dict)
    signal: dict[str, Any] = field(default_factory=dict)
    identify: dict[str, Any] | None = None
    score: dict[str, dict[str, float]] = field(default_factory=dict)
    path: str | None = field(default=None, compare=False)
    kind: str = ""
    rules: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        # a numpy integer seed (np.int64 from an array of seeds) is a seed; it was kept as one
        # and failed at the provenance's JSON ("Object of type int64 is not JSON serializable"),
        # and a float seed at numpy's SeedSequence (round 18, the API)
        seed = self.seed
        try:  # an integer of any integer type (numpy's too, not imported here), no truth value
            if type(seed).__name__ in ("bool", "bool_"):
                raise TypeError
            object.__setattr__(self, "seed", operator.index(seed))
        except TypeError:
            raise ArgumentError("Scenario", "seed", seed, f"of type {type(seed).__name__}; expected "
                                f"an integer in [0, {MAX_SEED}]") from None
        if not 0 <= self.seed <= MAX_SEED:
            raise ArgumentError("Scenario", "seed", seed, f"expected an integer in [0, {MAX_SEED}]")
        if not isinstance(self.kind, str):  # (round 28: an array was numpy's "truth value ...
            # is ambiguous" below)
            raise ArgumentError("Scenario", "kind", self.kind, "expected a rig kind (text), or "
                                "empty: the rig's own")
        try:
            rig_kind = RIGS.get(self.rig).kind
        except KeyError as e:
            if self.kind:  # a scenario of a rig not registered here (e.g. read back from a run)
                return
            raise ScenarioError(self.path or self.name, "scenario.rig", self.rig, str(e.args[0])) from None
        if not self.kind:
            object.__setattr__(self, "kind", rig_kind)
        elif self.kind != rig_kind:
            raise ScenarioError(self.path or self.name, "scenario.kind", self.kind,
                                f"rig {self.rig!r} is of kind {rig_kind!r}")

    def to_dict(self) -> dict[str, Any]:
        """Plain, JSON-able form (the file path left out)."""
        d = dataclasses.asdict(self)
        d.pop("path")
        d["tags"] = list(self.tags)
        return d

    def data_dict(self) -> dict[str, Any]:
        """The parts that determine the generated data (not identifier, score, name)."""
        return {"rig": self.rig, "rig_params": self.rig_params, "simulation": self.simulation,
                "excitation": self.excitation, "noise": self.noise, "seed": self.seed}

    def data_hash(self) -> str:
        """SHA-256 of :meth:`data_dict`: scenarios that differ only in identifier share data."""
        blob = json.dumps(self.data_dict(), sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(blob.encode()).hexdigest()

    def replace(self, **changes: Any) -> Scenario:
        return dataclasses.replace(self, **changes)

    def with_noise(self, rms_percent: float) -> Scenario:
        return self.replace(noise={**self.noise, "rms_percent": float(rms_percent)})


def _keep_what_the_new_type_reads(base: dict, child: dict) -> None:
    """Where ``child`` sets ``excitation.type`` to another than its parent's, drop from the
    parent's ``[excitation]`` (in place) the keys the new type does not declare: a chirp child
    of a multisine cart-pole was refused for the inherited ``f_min``, a key it could not remove
    (round 14), while the keys both types read (amplitude, the centring gains) carry over as
    every other inherited key does.  An unknown rig or type keeps nothing of the parent's table
    (the child's is then refused or validated on its own)."""
    old, new = base.get("excitation"), child.get("excitation")
    if not (isinstance(old, dict) and isinstance(new, dict) and "type" in new
            and new["type"] != old.get("type", new["type"])):
        return
    header = {**(base.get("scenario") or {}), **(child.get("scenario") or {})}
    try:
        schema = RIGS.get(header.get("rig")).excitation_schemas.get(new["type"], {})
    except (KeyError, TypeError, AttributeError):
        schema = {}
    base["excitation"] = {k: v for k, v in old.items() if k in schema}


def _deep_merge(base: dict, over: dict) -> dict:
    out = copy.deepcopy(base)
    for k, v in over.items():
        # [identify] and [score] are replaced whole: a new identifier must not inherit another's
        # hyperparameters, and a child's bars replace its parent's
        if isinstance(v, dict) and isinstance(out.get(k), dict) and k not in ("identify", "score"):
            out[k] = _deep_merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def file_problem(path: Path, what: str) -> str | None:
    """Why ``path`` cannot be read as a ``what`` (scenario, study) file, in words; None if it is
    a regular file (or a link to one).

    Never raises: a name too long for the file system, a symbolic-link loop, a dangling link, a
    NUL in the name, a folder and a FIFO or device (whose read would block or never end) each
    get their own words instead of an OSError or a misleading "no such file".
    """
    try:
        st = path.stat()
    except (OSError, ValueError) as e:  # (ValueError: an embedded NUL byte)
        why = unusable_path(e)  # the one reading of such a path (review 28b L7: its own here)
        if why is not None:
            return f"not a usable path ({why})"
        with contextlib.suppress(OSError):
            if path.is_symlink():
                return f"a symbolic link to {os.readlink(path)!r}, which does not exist"
        return f"no such {what} file"
    if stat.S_ISDIR(st.st_mode):
        return f"is a folder; expected a {what} .toml file"
    if not stat.S_ISREG(st.st_mode):
        return f"not a regular file (a FIFO, socket or device); expected a {what} .toml file"
    return None


def _depth_exceeds(obj: Any, limit: int) -> bool:
    """Whether tables and lists nest deeper than ``limit`` (iterative: no recursion)."""
    stack = [(obj, 0)]
    while stack:
        o, d = stack.pop()
        if d > limit:
            return True
        if isinstance(o, dict):
            stack.extend((v, d + 1) for v in o.values())
        elif isinstance(o, list):
            stack.extend((v, d + 1) for v in o)
    return False


#: Files read by :func:`read_toml_file` while a :func:`recording_reads` is open, else None.
_reads: list[str] | None = None


@contextlib.contextmanager
def recording_reads() -> Iterator[list[str]]:
    """A list that collects the absolute path of every file :func:`read_toml_file` reads in the
    block (a scenario and the files it extends): what a listing depends on."""
    global _reads
    before, _reads = _reads, []
    try:
        yield _reads
    finally:
        if before is not None:
            before.extend(_reads)
        _reads = before


def read_toml_file(path: Path, what: str) -> dict:
    """Read one TOML file defensively: one clear :class:`ScenarioError`, never its content.

    Parameters
    ----------
    path : Path
    what : str
        "scenario" or "study", for messages.

    Raises
    ------
    ScenarioError
        Missing, a folder, unreadable, larger than :data:`MAX_FILE_BYTES`, not UTF-8, not
        valid TOML, or nested deeper than :data:`MAX_DEPTH`.
    """
    file = str(path)
    if _reads is not None:
        _reads.append(os.path.abspath(path))
    problem = file_problem(path, what)
    if problem is not None:
        raise ScenarioError(file, allowed=problem)
    try:
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise ScenarioError(file, allowed=f"{size} bytes; a {what} file is at most "
                                              f"{MAX_FILE_BYTES} bytes of TOML")
        data = path.read_bytes()
    except OSError as e:
        raise ScenarioError(file, allowed=f"cannot be read: {e.strerror or type(e).__name__}") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as e:
        raise ScenarioError(file, allowed=f"not UTF-8 text (byte {e.start}); a {what} file is "
                                          "UTF-8 TOML") from None
    if text.startswith("\ufeff"):  # Windows editors' "UTF-8 with BOM"; TOML forbids it
        raise ScenarioError(file, allowed=f"starts with a byte-order mark (U+FEFF); a {what} file "
                                          "is UTF-8 TOML without one (save it as plain UTF-8)")
    if "\x00" in text:
        raise ScenarioError(file, allowed=f"contains NUL bytes (a binary file?); a {what} file is "
                                          "UTF-8 TOML")
    for n, line in enumerate(text.splitlines(), 1):
        # a dotted key of thousands of parts nests thousands of tables, and tomllib takes
        # seconds (quadratic) to build them: refuse it before parsing
        stripped = line.lstrip()
        if stripped.startswith("#") or ("=" not in stripped and not stripped.startswith("[")):
            continue
        head = stripped.split("=", 1)[0].split("#", 1)[0]
        if head.count(".") > MAX_DEPTH:
            raise ScenarioError(file, allowed=f"not a {what} file: a key on line {n} is nested "
                                              f"deeper than {MAX_DEPTH}")
    try:
        raw = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise ScenarioError(file, allowed=f"not valid TOML: {_given_twice(text, str(e)) or e}") from None
    except RecursionError:
        raise ScenarioError(file, allowed=f"not a {what} file: TOML nested too deeply") from None
    except ValueError as e:  # an integer beyond Python's str-to-int limit: an internal error before
        raise ScenarioError(file, allowed=_long_integer(text) or f"not valid TOML: {e}") from None
    if _depth_exceeds(raw, MAX_DEPTH):
        raise ScenarioError(file, allowed=f"not a {what} file: tables or lists nested deeper "
                                          f"than {MAX_DEPTH}")
    return raw


_AT_LINE = re.compile(r"\(at (?:line (\d+), column \d+|end of document)\)$")
_TABLE_HEADER = re.compile(r"^\s*\[\[?\s*([^\[\]#]+?)\s*\]\]?\s*(?:#.*)?$")


def _given_twice(text: str, message: str) -> str | None:
    """tomllib's "Cannot overwrite a value (at line 18, column 9)" as the key given twice,
    with its table and line (``"key 'rig.Km' is given twice (line 18); give each key once"``),
    or None where the message is another or the line holds no key.  Round 23: a key repeated
    in its table was refused naming a line and column, not the key."""
    m = _AT_LINE.search(message)
    if not message.startswith("Cannot overwrite a value") or m is None:
        return None
    lines = text.split("\n")  # (TOML's lines: splitlines also breaks at U+2028, review 24a)
    if m.group(1):
        n = int(m.group(1))
    else:  # the last line holding something
        n = max((k for k, ln in enumerate(lines, 1) if ln.strip()), default=0)
    if not 1 <= n <= len(lines) or "=" not in lines[n - 1]:
        return None
    key = lines[n - 1].split("=", 1)[0].strip()
    table = next((h.group(1) for ln in reversed(lines[:n - 1])
                  if (h := _TABLE_HEADER.match(ln)) is not None), "")
    dotted = f"{table}.{key}" if table else key
    return f"key {dotted!r} is given twice (line {n}); give each key once"


def _long_integer(text: str) -> str | None:
    """Where ``text`` has an integer too long for Python to read (``sys.get_int_max_str_digits``:
    4300 digits by default), as a message; None if it has none."""
    limit = sys.get_int_max_str_digits()
    if limit == 0:  # no limit set
        return None
    m = re.search(rf"\d(?:_?\d){{{limit},}}", text)
    if m is None:
        return None
    line = text.count("\n", 0, m.start()) + 1
    return (f"not valid TOML: an integer of more than {limit} digits (at line {line}); no "
            "setting takes a number that long")


def _read_toml(path: Path, chain: tuple[Path, ...] = ()) -> dict:
    raw = read_toml_file(path, "scenario")
    if "scenario" not in raw and "study" in raw:
        raise ScenarioError(str(path), allowed="a study file (it has [study]), not a scenario; "
                                               "run it with `testbed sweep`")
    header = raw.get("scenario", {})
    parent = header.get("extends") if isinstance(header, dict) else None
    if parent:
        if not isinstance(parent, str):
            raise ScenarioError(str(path), "scenario.extends", parent, "expected a file path string")
        if len(chain) >= MAX_EXTENDS:
            raise ScenarioError(str(path), "scenario.extends", parent,
                                f"a chain of at most {MAX_EXTENDS} files")
        try:
            ppath = (path.parent / parent).resolve()
        except (OSError, RuntimeError, ValueError) as e:
            raise ScenarioError(str(path), "scenario.extends", parent, f"not a usable path: {e}") \
                from None
        if ppath in chain or ppath == path.resolve():
            raise ScenarioError(str(path), "scenario.extends", parent, "extends itself (a cycle)")
        problem = file_problem(ppath, "scenario")
        if problem is not None:
            raise ScenarioError(str(path), "scenario.extends", parent,
                                f"no such file {ppath}" if problem.startswith("no such")
                                else f"{ppath}: {problem}")
        try:
            base = _read_toml(ppath, (*chain, path.resolve()))
            _check_parent(base, ppath)
        except ScenarioError as e:
            raise type(e)(e.file, e.key, e.value,
                          f"{e.allowed + ' ' if e.allowed else ''}(extended by {path})") from None
        if not isinstance(base.get("scenario", {}), dict):
            raise ScenarioError(str(ppath), "scenario", base["scenario"], "expected a table")
        base.setdefault("scenario", {}).pop("extends", None)
        base["scenario"].pop("description", None)
        base["scenario"].pop("tags", None)
        _keep_what_the_new_type_reads(base, raw)
        # a child keeps its parent's [score] unless it declares its own (see the module docs)
        raw = _deep_merge(base, raw)
    return raw


def _check_parent(base: dict, ppath: Path) -> None:
    """Validate the parent ``ppath`` (its tables ``base``, its own parents merged in) as a
    scenario of its own, as a study would use it, but for its budget (a child may shorten a
    run its parent could not afford) and its name (a parent copied under another file name
    keeps a name the child replaces); raises ScenarioError naming the parent's file.

    A child overriding or dropping its parent's malformed keys (a description with a tab, an
    ``x0 = "two"``, an ``[identify]`` it replaces) was loaded while the parent, run alone, was
    refused (round 15).
    """
    with contextlib.suppress(BudgetError):
        scenario_from_dict(copy.deepcopy(base), file=str(ppath), stem=None, standalone=False,
                           check_cost=False)


def resolve_path(name_or_path: str | os.PathLike, directory: Path | None = None) -> Path:
    """A path as given, or ``<directory>/<name>.toml`` for a bare name (default directory: the
    shipped scenarios).

    A bare name is taken as a path only if it names a file: a folder of that name in the
    working directory (``testbed run X --out .`` writes its runs to ``./X/``) must not hide
    the scenario ``X``.
    """
    if not os.fspath(name_or_path).strip():
        # Path("") is ".": `testbed run ""` (a script's "$NAME" unset) was refused as the file
        # "scenarios/..toml" of name "." (round 11)
        raise ScenarioError(repr(os.fspath(name_or_path)),
                            allowed="an empty name; expected a name (see `testbed list`) or a "
                                    ".toml path")
    p = Path(name_or_path)
    if p.suffix == ".toml" or len(p.parts) > 1 or file_problem(p, "") is None:
        return p
    return (SCENARIO_DIR if directory is None else directory) / f"{p}.toml"


def _check_stem(path: Path, what: str, directory: Path) -> None:
    """Refuse a folder, and a file whose stem is not a safe name (e.g. ``..toml``, stem ``.``)."""
    problem = file_problem(path, what)
    if problem is not None and not problem.startswith("no such"):
        raise ScenarioError(str(path), allowed=problem)
    if not re.fullmatch(NAME_PATTERN, path.stem):
        raise ScenarioError(str(path), f"{what}.name", path.stem,
                            f"the file name without .toml must be {NAME_PATTERN_DOC}")
    if problem is not None and path.parent == directory:
        known = sorted(p.stem for p in directory.glob("*.toml"))
        raise ScenarioError(str(path), allowed=f"no {what} named {path.stem!r}; known: "
                                               + (", ".join(known) or f"(none in {directory})")
                                               + unknown_key_hint(path.stem, known))


def load_scenario(name_or_path: str | os.PathLike, *, standalone: bool = True,
                  check_cost: bool = True) -> Scenario:
    """Read and validate a scenario file (a path, or a name in ``scenarios/``).

    Parameters
    ----------
    name_or_path : str or os.PathLike
        A ``.toml`` path, or the name of a shipped scenario (its file stem).
    standalone : bool, default True
        False for a study's scenario, whose identifiers come from the study: ``[score]`` is
        then allowed without ``[identify]``.
    check_cost : bool, default True
        False skips the simulation budget (:func:`check_rig_cost`), which builds the rig's
        model (MuJoCo for the cantilever): for a listing, not for a run.

    Returns
    -------
    Scenario
        Every section validated against its schema, defaults filled in.

    Raises
    ------
    ScenarioError
        For any problem of the file or a file it extends (see the module docs); its
        subclass :class:`~testbed.core.errors.BudgetError` for a run over budget.
    """
    if not (isinstance(name_or_path, (str, os.PathLike)) and isinstance(os.fspath(name_or_path), str)):
        # bytes, None or a number: pathlib's TypeError (round 18, the API)
        raise ArgumentError("load_scenario", "name_or_path", name_or_path,
                            f"of type {type(name_or_path).__name__}; expected a scenario name or a "
                            ".toml path (str or os.PathLike)")
    path = resolve_path(name_or_path)
    _check_stem(path, "scenario", SCENARIO_DIR)
    raw = _read_toml(path)
    return scenario_from_dict(raw, file=str(path), stem=path.stem, standalone=standalone,
                              check_cost=check_cost)


def scenario_from_dict(raw: dict[str, Any], *, file: str = "<dict>", stem: str | None = None,
                       standalone: bool = True, check_cost: bool = True) -> Scenario:
    """Validate a scenario given as a dict of TOML tables.

    Parameters
    ----------
    raw : dict
        The scenario's tables (``scenario``, ``rig``, ``simulation``, ``excitation``, ``noise``,
        ``signal``, ``identify``, ``score``) as :func:`tomllib.loads` gives them.
    file : str, default "<dict>"
        The name error messages give the scenario.
    stem : str, optional
        The file name without ``.toml``, which ``scenario.name`` must equal; None: unchecked.
    standalone, check_cost : bool, default True
        As in :func:`load_scenario`.

    Returns
    -------
    Scenario
        Every section validated against its schema, defaults filled in.

    Raises
    ------
    ScenarioError
        For any problem of the tables; its subclass :class:`~testbed.core.errors.BudgetError`
        for a run over budget.
    """

    head = validate_header(raw, sections=SECTIONS, header="scenario", schema=HEADER_SCHEMA, file=file,
                           stem=stem, other=("study", "a study (it has [study]), not a scenario; run "
                                                      "it with `testbed sweep`"))
    try:
        rig_cls = RIGS.get(head["rig"])
    except KeyError as e:
        raise ScenarioError(file, "scenario.rig", head["rig"], str(e.args[0])) from None

    # each table's keys, to name the table an unknown key belongs in (round 23: `sample_rate`
    # under [rig] was refused listing [rig]'s keys only)
    tables = {"[scenario]": HEADER_SCHEMA, "[rig]": rig_cls.rig_schema,
              "[simulation]": rig_cls.simulation_schema, "[noise]": NOISE_SCHEMA,
              "[signal]": SIGNAL_SCHEMAS[rig_cls.kind]}

    def others(section: str) -> dict[str, Any]:
        return {t: keys for t, keys in tables.items() if t != f"[{section}]"}

    rig_params = validate_table(raw.get("rig", {}), rig_cls.rig_schema, file=file, section="rig",
                                elsewhere=others("rig"))
    simulation = validate_table(raw.get("simulation", {}), rig_cls.simulation_schema, file=file,
                                section="simulation", elsewhere=others("simulation"))
    excitation = validate_variant(raw.get("excitation", {"type": rig_cls.default_excitation}),
                                  rig_cls.excitation_schemas, file=file, section="excitation")
    noise = validate_table(raw.get("noise", {}), NOISE_SCHEMA, file=file, section="noise",
                           elsewhere=others("noise"))
    if noise["signals"] is None:
        noise["signals"] = list(rig_cls.noisy_signals)
    for i, s in enumerate(noise["signals"]):
        if s not in rig_cls.measured_signals:
            raise ScenarioError(file, "noise.signals", s,
                                "expected measured signals among " + ", ".join(rig_cls.measured_signals))
        if s in noise["signals"][:i]:
            raise ScenarioError(file, f"noise.signals[{i}]", s, "duplicate; each signal gets noise once")

    def error(key: str, value: Any, allowed: str) -> None:
        raise ScenarioError(file, key, value, allowed)

    rig_cls.check(rig_params, simulation, excitation, error)
    if check_cost:
        # before the checks against the record: a record over budget (sample_rate = 1e308) is
        # refused for its size, not for a window "longer than the record's 4.6e-290 s" (the
        # sample count is capped at 2**62)
        check_rig_cost(rig_cls, rig_params, simulation, excitation, file=file)
    signal = validate_table(raw.get("signal", {}), SIGNAL_SCHEMAS[rig_cls.kind], file=file,
                            section="signal", elsewhere=others("signal"))
    rules = resolve_auto_signal(rig_cls, rig_params, signal, file)

    def chain_error(key: str, value: Any, allowed: str) -> None:
        # a cut-off the scenario wrote as "auto" is named as written, with the rule that
        # resolved it (its estimates say which mode put it where: round 7, six sensors on a
        # 0.32 m beam put mode 6 at 7 kHz and the low-pass above the Nyquist frequency)
        if key in rules:
            fix = ""
            if allowed.startswith("expected below the Nyquist"):
                # what is allowed, not only what is wrong (round 15: three sensors at 3.2 kHz
                # put the low-pass between modes 3 and 4 above the Nyquist frequency)
                fs = float(simulation["sample_rate"])
                fix = (f"; write a cut-off below {fs / 2:g} Hz, or a simulation.sample_rate above "
                       f"{2 * float(value):g} Hz (twice the cut-off 'auto' gave)")
            raise ScenarioError(file, key, "auto",
                                f"{allowed}; 'auto' resolved it to {rules[key]}{fix}")
        raise ScenarioError(file, key, value, allowed)

    check_keys_used(rig_cls.kind, raw.get("signal", {}), signal, chain_error)
    record = rig_cls.record(simulation)
    if record is not None:
        check_signal(rig_cls.kind, signal, *record, chain_error)
        if rig_cls.kind == "structural" and {"start", "pulse_duration"} <= excitation.keys():
            # an impact (the structural chain's excitation): its free decay must hold samples
            check_free_decay(signal, *record, excitation["start"], excitation["pulse_duration"],
                             chain_error)
    identify = _validate_identify(raw.get("identify"), file, kind=rig_cls.kind,
                                  rig_kind_source=f"rig {head['rig']!r}")
    score = _validate_score(raw.get("score", {}), rig_cls.kind, file)
    if score and identify is None and standalone:
        raise ScenarioError(file, "score", allowed="[score] needs an [identify] table: there is no "
                                                   "identified model to score")
    if identify is not None:
        check_identifier_for_rig(rig_cls, rig_params, simulation, identify, file=file)
    return Scenario(name=head["name"], rig=head["rig"], seed=head["seed"],
                    description=head["description"], tags=tuple(head["tags"]),
                    rig_params=rig_params, simulation=simulation, excitation=excitation,
                    noise=noise, signal=signal, identify=identify, score=score, path=file,
                    kind=rig_cls.kind, rules=rules)


def resolve_auto_signal(rig_cls: Any, rig_params: dict[str, Any], signal: dict[str, Any],
                        file: str) -> dict[str, str]:
    """Resolve the ``[signal]`` keys a scenario gives as ``"auto"`` from the rig, in place.

    A rig that lists the key in ``auto_signal_keys`` resolves it by its ``auto_signal(rig,
    key) -> (value, rule)`` (the cantilever: its filter cut-offs from the nominal geometry,
    :func:`models.cantilever.euler_bernoulli.auto_cutoff`).  Keys whose chain resolves
    ``"auto"`` itself from the record (the mechanical chain's ``cutoff_hz``) are left alone.

    Returns
    -------
    dict of str to str
        ``"signal.<key>"`` -> the rule and the value it gave, for :attr:`Scenario.rules`.

    Raises
    ------
    ScenarioError
        In one line, naming the key, if the rig has no rule for it or its rule cannot resolve it.
    """
    rules: dict[str, str] = {}
    keys = getattr(rig_cls, "auto_signal_keys", ())
    chain_auto = rig_auto_keys(rig_cls.kind)
    for key, value in signal.items():
        if value != "auto" or key not in chain_auto:
            continue
        if key not in keys:
            raise ScenarioError(file, f"signal.{key}", value,
                                f"a frequency [Hz]: rig {rig_cls.name or rig_cls.__name__!r} has "
                                "no estimate of its modes to resolve 'auto' from")
        try:
            signal[key], rule = rig_cls.auto_signal(rig_params, key)
        except ValueError as e:
            raise ScenarioError(file, f"signal.{key}", value, f"a frequency [Hz] ('auto' cannot "
                                                              f"be resolved here: {e})") from None
        rules[f"signal.{key}"] = f"{signal[key]:g} Hz by {rule}"
    return rules


def check_rig_cost(rig_cls: Any, rig_params: dict[str, Any], simulation: dict[str, Any],
                   excitation: dict[str, Any], *, file: str) -> None:
    """Refuse a scenario whose simulation would exceed the budget (:mod:`testbed.core.budget`).

    Raises
    ------
    BudgetError
        Naming the key that drives the cost.
    ScenarioError
        If the rig cannot even be built from these (valid but extreme) parameters.
    """

    try:
        cost = rig_cls.cost(rig_params, simulation, excitation)
    except RigError as e:
        if getattr(e, "key", None):
            raise ScenarioError(file, e.key, e.value, str(e)) from None
        raise ScenarioError(file, "rig", allowed=str(e)) from None
    if cost is not None:
        check_cost(cost, file)


def check_identifier_for_rig(rig_cls: Any, rig_params: dict[str, Any], simulation: dict[str, Any],
                             identify: dict[str, Any], *, file: str,
                             section: str = "identify") -> None:
    """Checks of an identifier's hyperparameters against a rig's data, before any simulation.

    ``identify`` holds ``method`` and the given hyperparameters.  Checked: the identifier's
    :meth:`~identify._base.Identifier.check_data_shape` (term names for the rig's channels
    and inputs, frequencies against the Nyquist frequency, windows against the record) and
    the steps of simulating the identified model over the record (:mod:`testbed.core.budget`).
    """

    cls = IDENTIFIERS.get(identify["method"])
    params = {k: v for k, v in identify.items() if k != "method"}
    full = cls.validate_hyperparameters(params, file=file, section=section)
    record = rig_cls.record(simulation)
    if record is None:
        return
    fs, n_samples = record

    check_identifier_for_record(cls, full, rig_cls.measurement_shape(rig_params), fs, n_samples,
                                file=file, section=section)


def check_identifier_for_record(cls: Any, full: dict[str, Any], shape: tuple[int, int] | None,
                                fs: float, n_samples: int, *, file: str,
                                section: str = "identify", detail: str = "") -> None:
    """An identifier's :meth:`~identify._base.Identifier.check_data_shape` (skipped when
    ``shape``, (channels, inputs), is unknown) and its simulation's step budget, on a record of
    ``n_samples`` at ``fs`` [Hz]; ``full``: its complete, validated hyperparameters.  A refused
    value raises :class:`ScenarioError` naming ``file`` and ``<section>.<name>``, ``detail``
    appended to what is allowed."""

    def error(name: str, value: Any, allowed: str) -> None:
        raise ScenarioError(file, f"{section}.{name}", value, allowed + detail)

    if shape is not None:
        cls.check_data_shape(full, shape[0], shape[1], fs, n_samples, error)
    steps, key = cls.simulation_steps(full, n_samples / fs)
    if key:
        # unset: the identifier chooses it from the data (e.g. sindy_pi's step rule); the
        # line says so instead of showing None
        value = full[key] if full[key] is not None else "unset (chosen from the data)"
        check_steps(steps, file, f"{section}.{key}", value)


def other_identifiers(method: str) -> dict[str, Any]:
    """Every registered identifier of ``method``'s kind but ``method``, by name, mapped to its
    declared hyperparameters: where an unknown hyperparameter of ``method`` belongs
    (:func:`~testbed.core.schema.unknown_key_hint`).  Identifiers of another kind are no
    place to name: they cannot fit the record (review 24a: ``n_modes`` for
    ``sindy_pi_dynamical`` pointed to the structural ``sgd_sindy``)."""
    out: dict[str, Any] = {}
    try:
        kind = IDENTIFIERS.get(method).kind
    except Exception:  # an unknown method: its own refusal names it
        return out
    for name in IDENTIFIERS.names():
        if name != method:
            try:
                cls = IDENTIFIERS.get(name)
                if cls.kind == kind:
                    out[name] = cls.declared_hyperparameters()
            except Exception:  # a plugin's broken declaration: it is no place to name
                continue
    return out


def _validate_identify(table: Any, file: str, *, kind: str | None = None,
                       rig_kind_source: str = "the rig") -> dict[str, Any] | None:
    """``method`` and the given hyperparameters, checked against the identifier's declaration.

    Only the keys given are returned (floats widened), so a scenario's identity does not
    change when a default does.  With ``kind``, an identifier of another kind is refused.
    """
    if table is None:
        return None
    if not isinstance(table, dict):
        raise ScenarioError(file, "identify", table, "expected a table")
    method = table.get("method")
    if method is None:
        raise ScenarioError(file, "identify.method",
                            allowed="missing; expected one of " + ", ".join(IDENTIFIERS.names())
                            + near_miss(table, "method"))
    if not isinstance(method, str) or method not in IDENTIFIERS:
        raise ScenarioError(file, "identify.method", method,
                            "expected one of " + ", ".join(IDENTIFIERS.names())
                            + unknown_key_hint(method, IDENTIFIERS.names()))
    cls = IDENTIFIERS.get(method)
    if kind is not None and cls.kind != kind:
        same = [n for n in IDENTIFIERS.names() if IDENTIFIERS.get(n).kind == kind]
        raise ScenarioError(file, "identify.method", method,
                            f"a {cls.kind!r} identifier cannot identify {rig_kind_source}, whose "
                            f"kind is {kind!r}; expected one of " + (", ".join(same) or "(none)"))
    params = {k: v for k, v in table.items() if k != "method"}
    declared = cls.declared_hyperparameters()
    for key, value in params.items():
        if key not in declared:
            raise ScenarioError(file, f"identify.{key}", value,
                                f"unknown hyperparameter of {method}; allowed: "
                                + ", ".join(sorted(declared))
                                + unknown_key_hint(key, declared, other_identifiers(method)))
    full = cls.validate_hyperparameters(params, file=file, section="identify")
    return {"method": method, **{k: full[k] for k in params}}


def _validate_score(table: Any, kind: str, file: str) -> dict[str, dict[str, float]]:
    if not isinstance(table, dict):
        raise ScenarioError(file, "score", table, "expected a table")
    names = metric_names(kind)
    out: dict[str, dict[str, float]] = {}
    for key, value in table.items():
        base, _, bound = key.rpartition("_")
        if bound not in ("min", "max") or base not in names:
            raise ScenarioError(file, f"score.{key}", value,
                                "expected <metric>_min or <metric>_max with metric one of "
                                + ", ".join(sorted(names)))
        if not isinstance(value, (int, float)) or isinstance(value, bool) \
                or not math.isfinite(value):
            raise ScenarioError(file, f"score.{key}", value, "expected a finite number")
        low, high = metric_range(base)
        if not low <= value <= high:
            raise ScenarioError(file, f"score.{key}", value,
                                f"expected a number >= {low:g}" + (f" and <= {high:g}" if
                                                                   math.isfinite(high) else "")
                                + f": {base} takes values in that range, so this bar could "
                                + ("never pass" if (bound == "max") == (value < low) else
                                   "never fail"))
        out.setdefault(base, {})[bound] = float(value)
    for base, bounds in out.items():
        if "min" in bounds and "max" in bounds and bounds["min"] > bounds["max"]:
            raise ScenarioError(file, f"score.{base}_min", bounds["min"],
                                f"expected at most {base}_max ({bounds['max']:g}): no score "
                                "could pass")
    return out


def list_scenarios(directory: Path | None = None, *, check_cost: bool = True) -> list[Scenario]:
    """Every scenario file in a folder, validated.

    Parameters
    ----------
    directory : Path, optional
        The folder of ``*.toml`` scenario files; default the shipped ``scenarios/``.
    check_cost : bool, default True
        As in :func:`load_scenario`.

    Returns
    -------
    list of Scenario
        Sorted by file name.

    Raises
    ------
    ScenarioError
        For the first file that does not validate.
    """
    directory = directory or SCENARIO_DIR
    return [load_scenario(p, check_cost=check_cost) for p in sorted(Path(directory).glob("*.toml"))]
