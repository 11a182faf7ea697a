"""Identifiers: they fit what a lab would measure and never see the truth.

Every module of this package is imported on first lookup of :data:`IDENTIFIERS`.
``identify`` never imports ``models``.
"""

from testbed.core.registry import IDENTIFIER_ENTRY_POINTS, Registry

IDENTIFIERS = Registry("identifier", package="identify", entry_points=IDENTIFIER_ENTRY_POINTS)

__all__ = ["IDENTIFIERS"]
