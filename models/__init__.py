"""The simulated rigs and their exact ground truth.

Rigs register in :data:`RIGS` by name with tags; every module of this package
is imported on first lookup.  ``models`` never imports ``identify`` or the
metrics: a rig does not know who will judge it.
"""

from testbed.core.registry import Registry

RIGS = Registry("rig", package="models")

__all__ = ["RIGS"]
