"""Identifiers: they fit what a lab would measure and never see the truth.

Every module of this package is imported on first lookup of :data:`IDENTIFIERS`, then the
entry points of the group ``sysid_testbed.identifiers`` of installed distributions.
``identify`` never imports ``models``.

Public names for writing an identifier (also re-exported by ``testbed``): :data:`IDENTIFIERS`,
:class:`Identifier` (the estimator contract), :class:`StructuralIdentifier` (simulation,
equations and modal results of an ``M, C, K (, K3)`` model) and the structural helpers
:func:`build_library`, :func:`matrices_from_coef`, :func:`mass_prior_value`, :func:`modal`.
They are imported on first use.
"""

from __future__ import annotations

import importlib
from typing import Any

from testbed.core.registry import IDENTIFIER_ENTRY_POINTS, Registry

IDENTIFIERS = Registry("identifier", package="identify", entry_points=IDENTIFIER_ENTRY_POINTS)

_API = {
    "Identifier": "identify._base",
    "StructuralIdentifier": "identify.structural",
    "build_library": "identify.structural",
    "matrices_from_coef": "identify.structural",
    "mass_prior_value": "identify.structural",
    "modal": "identify.structural",
    "MASS_PRIORS": "identify.structural",
}

__all__ = ["IDENTIFIERS", *sorted(_API)]


def __getattr__(name: str) -> Any:
    if name not in _API:
        raise AttributeError(f"module 'identify' has no attribute {name!r}")
    value = getattr(importlib.import_module(_API[name]), name)
    globals()[name] = value
    return value
