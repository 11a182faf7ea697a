"""The simulated rigs and their exact ground truth.

Rigs register in :data:`RIGS` by name with tags; every module of this package is imported on
first lookup, then the entry points of the group ``sysid_testbed.rigs`` of installed
distributions.  ``models`` never imports ``identify`` or the metrics: a rig does not know who
will judge it.  :class:`Rig` (the rig contract, imported on first use) is public.
"""

from __future__ import annotations

import importlib
from typing import Any

from testbed.core.registry import RIG_ENTRY_POINTS, Registry

RIGS = Registry("rig", package="models", entry_points=RIG_ENTRY_POINTS)

__all__ = ["RIGS", "Rig"]


def __getattr__(name: str) -> Any:
    if name != "Rig":
        raise AttributeError(f"module 'models' has no attribute {name!r}")
    value = importlib.import_module("models._base").Rig
    globals()[name] = value
    return value
