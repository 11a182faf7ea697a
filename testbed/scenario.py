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
state only what differs.  Every problem raises :class:`ScenarioError` naming the
file, the key, the value and what is allowed.
"""

from __future__ import annotations

import copy
import dataclasses
import hashlib
import inspect
import json
import os
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from testbed.errors import ScenarioError
from testbed.schema import Field, validate_header, validate_table

SCENARIO_DIR = Path(os.environ.get("TESTBED_SCENARIOS",
                                   Path(__file__).resolve().parent.parent / "scenarios"))

HEADER_SCHEMA = {
    "name": Field(str, doc="scenario name; must equal the file name without .toml"),
    "rig": Field(str, doc="registered rig name (see `testbed list`)"),
    "seed": Field(int, 0, min=0, doc="seed of the measurement noise"),
    "description": Field(str, "", doc="one line for listings"),
    "tags": Field(list, [], item_type=str, doc="free tags for selecting scenarios"),
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
    """A validated scenario.  Sections are plain dicts with defaults filled in."""

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

    def to_dict(self) -> dict[str, Any]:
        """Plain, JSON-able form (the file path left out)."""
        d = dataclasses.asdict(self)
        d.pop("path")
        d["tags"] = list(self.tags)
        return d

    def canonical_json(self) -> str:
        return json.dumps(self.to_dict(), sort_keys=True, separators=(",", ":"))

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


def _deep_merge(base: dict, over: dict) -> dict:
    out = copy.deepcopy(base)
    for k, v in over.items():
        # [identify] and [score] belong together to one file: a child's tables replace the
        # parent's whole (a new identifier must not inherit another's hyperparameters or bars)
        if isinstance(v, dict) and isinstance(out.get(k), dict) and k not in ("identify", "score"):
            out[k] = _deep_merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out


def _read_toml(path: Path, chain: tuple[Path, ...] = ()) -> dict:
    if not path.is_file():
        raise ScenarioError(str(path), allowed="no such scenario file")
    try:
        raw = tomllib.loads(path.read_text())
    except tomllib.TOMLDecodeError as e:
        raise ScenarioError(str(path), allowed=f"not valid TOML: {e}") from None
    header = raw.get("scenario", {})
    parent = header.get("extends") if isinstance(header, dict) else None
    if parent:
        if not isinstance(parent, str):
            raise ScenarioError(str(path), "scenario.extends", parent, "expected a file path string")
        ppath = (path.parent / parent).resolve()
        if ppath in chain or ppath == path.resolve():
            raise ScenarioError(str(path), "scenario.extends", parent, "extends itself (a cycle)")
        if not ppath.is_file():
            raise ScenarioError(str(path), "scenario.extends", parent, f"no such file {ppath}")
        base = _read_toml(ppath, (*chain, path.resolve()))
        base.setdefault("scenario", {}).pop("extends", None)
        base["scenario"].pop("description", None)
        base["scenario"].pop("tags", None)
        if "identify" in raw and "score" not in raw:  # thresholds belong to the identifier
            base.pop("score", None)
        raw = _deep_merge(base, raw)
    return raw


def resolve_path(name_or_path: str | os.PathLike) -> Path:
    """A path as given, or ``scenarios/<name>.toml`` for a bare scenario name."""
    p = Path(name_or_path)
    if p.suffix == ".toml" or p.exists() or len(p.parts) > 1:
        return p
    return SCENARIO_DIR / f"{p}.toml"


def load_scenario(name_or_path: str | os.PathLike) -> Scenario:
    """Read and validate a scenario file (a path, or a name in ``scenarios/``)."""
    path = resolve_path(name_or_path)
    raw = _read_toml(path)
    return scenario_from_dict(raw, file=str(path), stem=path.stem)


def scenario_from_dict(raw: dict[str, Any], *, file: str = "<dict>",
                       stem: str | None = None) -> Scenario:
    """Validate a scenario given as a dict of TOML tables."""
    from models import RIGS  # the rig owns the schema of its sections

    head = validate_header(raw, sections=SECTIONS, header="scenario", schema=HEADER_SCHEMA, file=file,
                           stem=stem)
    try:
        rig_cls = RIGS.get(head["rig"])
    except KeyError as e:
        raise ScenarioError(file, "scenario.rig", head["rig"], str(e.args[0])) from None

    rig_params = validate_table(raw.get("rig", {}), rig_cls.rig_schema, file=file, section="rig")
    simulation = validate_table(raw.get("simulation", {}), rig_cls.simulation_schema, file=file,
                                section="simulation")
    from testbed.schema import validate_variant
    excitation = validate_variant(raw.get("excitation", {"type": rig_cls.default_excitation}),
                                  rig_cls.excitation_schemas, file=file, section="excitation")
    noise = validate_table(raw.get("noise", {}), NOISE_SCHEMA, file=file, section="noise")
    if noise["signals"] is None:
        noise["signals"] = list(rig_cls.noisy_signals)
    for s in noise["signals"]:
        if s not in rig_cls.measured_signals:
            raise ScenarioError(file, "noise.signals", s,
                                "expected measured signals among " + ", ".join(rig_cls.measured_signals))

    def error(key: str, value: Any, allowed: str) -> None:
        raise ScenarioError(file, key, value, allowed)

    rig_cls.check(rig_params, simulation, excitation, error)

    from testbed.preprocess import SIGNAL_SCHEMAS
    signal = validate_table(raw.get("signal", {}), SIGNAL_SCHEMAS[rig_cls.kind], file=file,
                            section="signal")
    identify = _validate_identify(raw.get("identify"), file)
    score = _validate_score(raw.get("score", {}), rig_cls.kind, file)
    return Scenario(name=head["name"], rig=head["rig"], seed=head["seed"],
                    description=head["description"], tags=tuple(head["tags"]),
                    rig_params=rig_params, simulation=simulation, excitation=excitation,
                    noise=noise, signal=signal, identify=identify, score=score, path=file)


def _validate_identify(table: Any, file: str) -> dict[str, Any] | None:
    if table is None:
        return None
    if not isinstance(table, dict):
        raise ScenarioError(file, "identify", table, "expected a table")
    from identify import IDENTIFIERS
    method = table.get("method")
    if method is None:
        raise ScenarioError(file, "identify.method",
                            allowed="missing; expected one of " + ", ".join(IDENTIFIERS.names()))
    if method not in IDENTIFIERS:
        raise ScenarioError(file, "identify.method", method,
                            "expected one of " + ", ".join(IDENTIFIERS.names()))
    cls = IDENTIFIERS.get(method)
    params = inspect.signature(cls.__init__).parameters
    defaults = {k: p.default for k, p in params.items() if k != "self"}
    out: dict[str, Any] = {"method": method}
    for key, value in table.items():
        if key == "method":
            continue
        if key not in defaults:
            raise ScenarioError(file, f"identify.{key}", value,
                                f"unknown hyperparameter of {method}; allowed: "
                                + ", ".join(sorted(defaults)))
        d = defaults[key]
        if d is not None and d is not inspect.Parameter.empty:
            want = float if isinstance(d, float) else type(d)
            ok = isinstance(value, (int, float)) and not isinstance(value, bool) \
                if want is float else isinstance(value, want)
            if not ok:
                raise ScenarioError(file, f"identify.{key}", value,
                                    f"expected {want.__name__} like the default {d!r}")
        out[key] = value
    return out


def _validate_score(table: Any, kind: str, file: str) -> dict[str, dict[str, float]]:
    if not isinstance(table, dict):
        raise ScenarioError(file, "score", table, "expected a table")
    from testbed.scoring import metric_names
    names = metric_names(kind)
    out: dict[str, dict[str, float]] = {}
    for key, value in table.items():
        base, _, bound = key.rpartition("_")
        if bound not in ("min", "max") or base not in names:
            raise ScenarioError(file, f"score.{key}", value,
                                "expected <metric>_min or <metric>_max with metric one of "
                                + ", ".join(sorted(names)))
        if not isinstance(value, (int, float)) or isinstance(value, bool):
            raise ScenarioError(file, f"score.{key}", value, "expected a number")
        out.setdefault(base, {})[bound] = float(value)
    return out


def list_scenarios(directory: Path | None = None) -> list[Scenario]:
    """Every scenario file in ``directory`` (default ``scenarios/``), validated, sorted by name."""
    directory = directory or SCENARIO_DIR
    return [load_scenario(p) for p in sorted(Path(directory).glob("*.toml"))]
