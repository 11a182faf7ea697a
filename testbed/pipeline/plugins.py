"""The one seam between the application and its plugins: rigs (``models/``) and identifiers
(``identify/``).

Everything in ``testbed`` that needs a rig or an identifier asks here; nothing else in
``testbed`` imports ``models`` or ``identify`` (``tests/test_layers.py`` says so).  The
registries import their packages' modules on first lookup, and plugins from outside the
project join them through :func:`load_plugins` (a study's ``plugins = [...]``).
"""

from __future__ import annotations

import importlib
from collections.abc import Iterable
from typing import Any

from identify import IDENTIFIERS
from models import RIGS
from testbed.core.errors import ScenarioError

__all__ = ["IDENTIFIERS", "RIGS", "identifier_class", "load_plugins", "make_identifier",
           "rig_class", "rig_kind"]


def rig_class(name: str) -> type:
    """The registered rig class ``name`` (KeyError naming the known ones if unknown)."""
    return RIGS.get(name)


def rig_kind(name: str) -> str:
    """Kind (``"structural"``, ``"mechanical"``, ...) of the registered rig ``name``."""
    return RIGS.get(name).kind


def identifier_class(name: str) -> type:
    """The registered identifier class ``name`` (KeyError naming the known ones if unknown)."""
    return IDENTIFIERS.get(name)


def make_identifier(identify: dict[str, Any] | None, scenario_name: str = "") -> Any:
    """A fresh identifier from a scenario's ``[identify]`` table (method + hyperparameters)."""
    if identify is None:
        raise ScenarioError(scenario_name or "<scenario>", "identify", allowed="no [identify] table")
    params = {k: v for k, v in identify.items() if k != "method"}
    return IDENTIFIERS.get(identify["method"])(**params)


def load_plugins(modules: Iterable[str]) -> None:
    """Import plugin modules (dotted names) so that their rigs and identifiers register."""
    for m in modules:
        importlib.import_module(m)
