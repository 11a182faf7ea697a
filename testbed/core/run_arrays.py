"""What a run's ``run.npz`` may hold: one constant, read by its writer
(:mod:`testbed.studies.runstore`) and its checker (:func:`testbed.reporting.report.check_run_npz`).
"""

from __future__ import annotations

#: The dtype kinds of a run's stored arrays (numbers and text, nothing pickled): bool, signed
#: and unsigned integers, floats, complex, text.
RUN_ARRAY_KINDS = "biufcU"

#: The first bytes :func:`numpy.load` takes for a zip (an ``.npz``): a zip's local file header,
#: or the end-of-archive record an empty zip starts with (numpy's own test, ``_npyio_impl``).
ZIP_SIGNATURES = (b"PK\x03\x04", b"PK\x05\x06")
