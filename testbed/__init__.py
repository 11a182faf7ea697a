"""sysid-testbed: validate system-identification methods against exact physics truth.

Flow (see README): scenario file -> rig simulates (models/) -> dataset (HDF5) ->
signal chain -> identifier (identify/) -> scores against the truth -> report.
"""

__version__ = "0.1.0"
