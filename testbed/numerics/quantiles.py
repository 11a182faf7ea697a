"""Quartiles of a score over cells, infinite scores counted (summary and report tables).

A score of +inf (a coefficient error against a true coefficient of 0, a diverged simulation's
error) is a value, the worst there is: leaving it out of a median reported the median of the
other cells (round 13: the default study's ``sindy_pi`` at 5 % noise, ``coef_error`` 84.4 over 5
of its 6 finished cells, the sixth being inf). NaN is no value (a score the rig kind or the
run did not define) and is left out; the callers say how many cells a median stands on.
"""

from __future__ import annotations

import math
from collections.abc import Iterable

import numpy as np


def _linear(s: np.ndarray, q: float) -> float:
    """numpy's ``"linear"`` percentile ``q`` [%] of the sorted ``s``, infinities kept: between a
    finite and an infinite neighbour it is the infinite one (any positive weight on it), at a
    neighbour itself (weight 0) that neighbour, between -inf and +inf undefined (NaN)."""
    h = (s.size - 1) * q / 100.0
    lo = math.floor(h)
    hi = min(lo + 1, s.size - 1)
    t = h - lo
    a, b = float(s[lo]), float(s[hi])
    if t == 0.0 or a == b:
        return a
    if math.isinf(a) or math.isinf(b):
        return math.nan if (math.isinf(a) and math.isinf(b)) else (a if math.isinf(a) else b)
    # numpy's own interpolation (numpy.lib._function_base_impl._lerp), to the bit
    return a + (b - a) * t if t < 0.5 else b - (b - a) * (1 - t)


def quartiles(values: Iterable[float]) -> tuple[float, float, float, int]:
    """25th, 50th and 75th percentiles of ``values`` and how many values they stand on.

    Parameters
    ----------
    values : iterable of float
        Scores of a group of cells [the score's unit]; NaN (and None) are left out, +-inf kept.

    Returns
    -------
    (q25, median, q75, n)
        numpy's default ``"linear"`` percentiles, bit-identical to :func:`numpy.percentile`
        where every value is finite; NaN for all three when ``n`` is 0.
    """
    v = np.asarray([x for x in values if x is not None], dtype=float)
    v = np.sort(v[~np.isnan(v)])
    if v.size == 0:
        return math.nan, math.nan, math.nan, 0
    if np.all(np.isfinite(v)):
        q25, med, q75 = np.percentile(v, [25, 50, 75])
        return float(q25), float(med), float(q75), int(v.size)
    return _linear(v, 25.0), _linear(v, 50.0), _linear(v, 75.0), int(v.size)
