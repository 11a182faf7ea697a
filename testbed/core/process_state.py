"""Process-wide state a user's code may change under the testbed: numpy's floating-point error
state (the testbed computes under numpy's defaults, whatever its caller or a plugin set) and the
working folder (a plugin's ``os.chdir`` is undone).

``np.seterr(all="raise")`` in a user's Python session, or in a plugin's ``fit`` or at its import,
changed the verdicts of built-in identifiers that ran after it (hostile round 20): the shipped
``cantilever_stiff_impact_lsq`` passed, and failed under it ("fit failed: numerical breakdown
(FloatingPointError: underflow encountered in exp)"); ``cantilever_stiff_impact_sindy_pi`` was a
raw FloatingPointError.  In a sequential sweep a plugin's cell so changed the cells after it:
a verdict that depends on what ran before.  The rule: the public API's calls, every fit and
every plugin's import run under :data:`DEFAULTS` (numpy's own), and what a plugin sets is
undone when its import or fit returns.

numpy is not imported here (``testbed list`` does not load it): a state is only set or put back
where numpy is loaded already (a caller who has not imported numpy has set nothing).
"""

from __future__ import annotations

import contextlib
import os
import sys
from collections.abc import Iterator

#: numpy's own floating-point error handling (``np.geterr()`` of a fresh interpreter).
DEFAULTS = {"divide": "warn", "over": "warn", "under": "ignore", "invalid": "warn"}


@contextlib.contextmanager
def numpy_defaults() -> Iterator[None]:
    """Within: numpy's error state is :data:`DEFAULTS`; after: the state before (the defaults
    if numpy was loaded within), whatever the code within set."""
    with kept_numpy_state():
        np = sys.modules.get("numpy")
        if np is not None:
            np.seterr(**DEFAULTS)
        yield


@contextlib.contextmanager
def kept_working_folder() -> Iterator[None]:
    """After: the working folder before, whatever the code within changed it to.

    A plugin's ``os.chdir("/")`` in its fit sent a sequential sweep's relative ``--results
    r.parquet`` to ``/r.parquet`` (hostile round 20).  A working folder that no longer exists
    when entered is left as it is (there is nothing to return to).  The working folder is the
    process's: with two threads inside at once (a Dask worker's), the one that leaves last
    restores what it found, which the first may have changed (not covered)."""
    try:
        before = os.getcwd()
    except OSError:
        before = None
    try:
        yield
    finally:
        if before is not None:
            with contextlib.suppress(OSError):
                if os.getcwd() != before:
                    os.chdir(before)


@contextlib.contextmanager
def kept_numpy_state() -> Iterator[None]:
    """After: numpy's error state before, whatever the code within set (within, the caller's
    state holds: a scorer's ``np.errstate(over="ignore")`` around a model's simulation)."""
    np = sys.modules.get("numpy")
    before = np.geterr() if np is not None else None
    try:
        yield
    finally:
        np = sys.modules.get("numpy")
        if np is not None:
            np.seterr(**(before or DEFAULTS))


@contextlib.contextmanager
def kept_process_state(defaults: bool = True) -> Iterator[None]:
    """:func:`numpy_defaults` (or, without ``defaults``, :func:`kept_numpy_state`) and
    :func:`kept_working_folder` together: around a user's code (a plugin's import, any fit;
    a plugin's simulation, without ``defaults``)."""
    with numpy_defaults() if defaults else kept_numpy_state(), kept_working_folder():
        yield
