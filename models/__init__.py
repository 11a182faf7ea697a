"""The simulated rigs and their exact ground truth.

Rigs register in :data:`RIGS` by name with tags; every module of this package
is imported on first lookup.  ``models`` never imports ``identify`` or the
metrics: a rig does not know who will judge it.
"""

from testbed.core.registry import RIG_ENTRY_POINTS, Registry

RIGS = Registry("rig", package="models", entry_points=RIG_ENTRY_POINTS)

__all__ = ["RIGS"]
