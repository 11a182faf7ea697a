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
from testbed.core.registry import IDENTIFIER_ENTRY_POINTS, RIG_ENTRY_POINTS, PluginError, import_plugin

__all__ = ["IDENTIFIERS", "IDENTIFIER_ENTRY_POINTS", "RIGS", "RIG_ENTRY_POINTS", "PluginError",
           "identifier_class", "load_plugins", "make_identifier", "registry_folders",
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


def registry_folders() -> list[str]:
    """The folders whose modules the registries import (``identify/``, ``models/``): a module
    added or removed there is an entry added or removed."""
    return [str(p) for reg in (IDENTIFIERS, RIGS) if reg.package is not None
            for p in importlib.import_module(reg.package).__path__]


def make_identifier(identify: dict[str, Any] | None, scenario_name: str = "") -> Any:
    """A fresh identifier from a scenario's ``[identify]`` table (method + hyperparameters)."""
    if identify is None:
        raise ScenarioError(scenario_name or "<scenario>", "identify", allowed="no [identify] table")
    params = {k: v for k, v in identify.items() if k != "method"}
    return IDENTIFIERS.get(identify["method"])(**params)


def load_plugins(plugins: Iterable[str]) -> list[str]:
    """Import plugins so that their rigs and identifiers register.

    Parameters
    ----------
    plugins : iterable of str
        ``.py`` file paths or dotted module names; one already imported in this process is
        not imported again.

    Returns
    -------
    list of str
        What each added, in order: ``"identifier foo"``, ``"rig bar"``.

    Raises
    ------
    PluginError
        If a plugin cannot be imported, or registers no rig and no identifier (most likely
        the wrong file).
    """
    added = []
    for p in plugins:
        before = set(IDENTIFIERS.names()), set(RIGS.names())
        module = import_plugin(p)
        new = ([f"identifier {n}" for n in IDENTIFIERS.names() if n not in before[0]]
               + [f"rig {n}" for n in RIGS.names() if n not in before[1]])
        known = [n for reg in (IDENTIFIERS, RIGS) for n in reg.names()
                 if getattr(reg.get(n), "__module__", None) == module.__name__]
        if not new and not known:
            raise PluginError(f"plugin {p}: registers no identifier and no rig (decorate a class "
                              "with @IDENTIFIERS.register(name) or @RIGS.register(name))")
        added += new
    return added
