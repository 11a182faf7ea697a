"""The sample-rate attributes of a dataset file (``fs``, ``fs_unit``), checked as stored.

:meth:`testbed.core.dataset.Dataset.load` reads ``fs`` with ``float()`` and no unit: the text
``"100"`` and ``True`` were read as rates, a complex rate lost its imaginary part (with a warning
over two lines), and ``fs_unit`` (which the content hash leaves out) was never read, so ``"kHz"``
was taken as Hz in silence (malformed-input round 17).  Checking it there would change the file
the dataset cache keys hash, so its readers (the importers, the exporters, the cache) check the
attributes here first.  Its own module: the cache needs it without the importers' imports
(``testbed list`` imports no SciPy).
"""

from __future__ import annotations

import os

import numpy as np

from testbed.core.lazy import lazy_module

h5py = lazy_module("h5py")

#: How far [relative] a dataset file's ``fs`` may lie from the rate its stored scenario records
#: at, for the cache (``testbed.pipeline.cache``) and the importers alike: a plugin rig may write
#: a derived rate 1 / (k dt) an ulp or so from its scenario's; an exact comparison would refuse
#: every read of its cache.
SCENARIO_RATE_RTOL = 1e-12


def off_scenario_rate(fs: float, rate: float) -> bool:
    """Whether a file's ``fs`` [Hz] lies further than :data:`SCENARIO_RATE_RTOL` from the
    ``rate`` [Hz] its scenario records at (NaN counts as off)."""
    return not abs(fs - rate) <= SCENARIO_RATE_RTOL * abs(rate)


def fs_attribute_problem(path: str | os.PathLike) -> str | None:
    """What is wrong with a dataset file's root ``fs`` (not one real number) or ``fs_unit`` (not
    ``"Hz"``), or None; None too for a file that cannot be opened (its reader names that).

    Parameters
    ----------
    path : path-like
        An HDF5 dataset file.

    Returns
    -------
    str or None
        The attribute, its value and what is allowed, in one line.
    """
    try:
        with h5py.File(path, "r") as h:
            attrs = {k: h.attrs[k] for k in ("fs", "fs_unit") if k in h.attrs}
    except Exception:
        return None
    fs = attrs.get("fs")
    if fs is not None and not (isinstance(fs, (np.floating, np.integer, float, int))
                               and not isinstance(fs, (bool, np.bool_))):
        shown = fs.item() if isinstance(fs, np.generic) else fs  # named as 'True', not
        shown = shown.decode(errors="replace") if isinstance(shown, bytes) else shown  # np.True_
        return (f"attribute fs={shown!r} ({type(fs).__name__}); expected one real number, the "
                "sample rate [Hz]")
    unit = attrs.get("fs_unit")
    unit = unit.decode(errors="replace") if isinstance(unit, bytes) else unit
    if unit is not None and unit != "Hz":
        return f"attribute fs_unit={unit!r}; expected 'Hz' (the unit the sample rate fs is read in)"
    return None
