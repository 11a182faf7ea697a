"""Checks of the arguments the public Python API is given, done once where an argument enters.

Each check returns the value in the form the code below it expects (a Python ``int`` for a
numpy integer, a float64 array for an integer or float32 one) or raises
:class:`~testbed.core.errors.ArgumentError` naming the function (``where``), the argument, the
value and what is allowed.  The rules, the same for every entry point:

- a number is a real Python or numpy number, never a boolean (``True`` is not ``1`` here) nor
  text; it must be finite unless said otherwise;
- an integer is an ``int`` or a numpy integer (a float such as ``2.0`` is refused: a count or
  an index given as a float is a mistake somewhere upstream);
- an array of signals is real-valued with an integer or floating dtype (boolean, complex,
  object and text arrays are refused, not cast), is returned as float64 (float32 input is
  widened, so that results do not depend on the caller's dtype), has the stated number of
  dimensions and shape, and holds only finite values;
- a path is text or an ``os.PathLike``, not empty.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from testbed.core.errors import ArgumentError, is_control, unusable_path


def integer(where: str, name: str, value: Any, *, low: int | None = None,
            high: int | None = None) -> int:
    """``value`` as an ``int`` in ``[low, high]`` (either bound optional)."""
    ok = isinstance(value, numbers.Integral) and not isinstance(value, (bool, np.bool_))
    if ok:
        value = int(value)
        ok = (low is None or value >= low) and (high is None or value <= high)
    if not ok:
        raise ArgumentError(where, name, value, f"expected an integer{_range(low, high)}")
    return value


def finite_real(value: Any) -> float | None:
    """``value`` as a finite ``float`` if it is a real number (not a boolean) that float64 holds,
    else None: an integer beyond float64's range (a JSON ``10**400``) is None, where ``float``
    raised OverflowError (round 25: an internal error of ``identify`` on a SEP-005 ``fs``)."""
    if not isinstance(value, numbers.Real) or isinstance(value, (bool, np.bool_)):
        return None
    try:
        x = float(value)
    except OverflowError:
        return None
    return x if math.isfinite(x) else None


def real(where: str, name: str, value: Any, *, low: float | None = None,
         high: float | None = None, low_open: bool = False) -> float:
    """``value`` as a finite ``float`` in ``[low, high]`` (``(low, high]`` when ``low_open``)."""
    x = finite_real(value)
    ok = x is not None and (low is None or (x > low if low_open else x >= low)) \
        and (high is None or x <= high)
    if not ok:
        left = "(" if low_open else "["
        bounds = f" in {left}{low:g}, {high:g}]" if low is not None and high is not None else (
            f" {'>' if low_open else '>='} {low:g}" if low is not None else
            f" <= {high:g}" if high is not None else "")
        raise ArgumentError(where, name, value, f"expected a finite number{bounds}")
    return x


def choice(where: str, name: str, value: Any, allowed: Sequence[Any]) -> Any:
    """``value`` if it is one of ``allowed`` (compared by type and value: ``1`` is not ``True``)."""
    if not any(type(value) is type(a) and value == a for a in allowed):
        raise ArgumentError(where, name, value,
                            "expected one of " + ", ".join(repr(a) for a in allowed))
    return value


def names(where: str, name: str, value: Any, *, count: int | None = None) -> tuple[str, ...]:
    """``value`` (a list or tuple of distinct non-empty texts, ``count`` of them if given) as a
    tuple; a single text is refused (it would be read as one name per character)."""
    # a control character (a newline, ESC) split the equations and tables that show the name
    # (round 25: a channel "a\nb" was fitted and printed on two lines)
    ok = isinstance(value, (list, tuple)) and all(
        isinstance(v, str) and v and not any(is_control(c) for c in v) for v in value) \
        and len(set(value)) == len(value)
    if not ok or (count is not None and len(value) != count):
        many = f"{count} " if count is not None else ""
        raise ArgumentError(where, name, value, f"expected a tuple of {many}distinct non-empty "
                            "names (text without control characters)")
    return tuple(value)


def path(where: str, name: str, value: Any) -> str | os.PathLike:
    """``value`` if it is a non-empty text or an ``os.PathLike`` the system can name
    (:func:`~testbed.core.errors.unusable_path`; a missing file passes: the function says so)."""
    if not isinstance(value, (str, os.PathLike)) or not os.fspath(value):
        raise ArgumentError(where, name, value, "expected a path (text or os.PathLike), not empty")
    try:
        os.stat(value)
    except (OSError, ValueError) as e:
        why = unusable_path(e)
        if why is not None:
            raise ArgumentError(where, name, value, f"expected a usable path, not {why}") from None
    return value


def describe(a: Any) -> str:
    """An array's shape and dtype in words (its values are not shown: they may be millions)."""
    if isinstance(a, np.ndarray):
        return f"array of shape {a.shape} and dtype {a.dtype}"
    return f"a {type(a).__name__}"


def array(where: str, name: str, value: Any, shape: tuple[int | None, ...], *,
          complex_ok: bool = False, finite: bool = True) -> np.ndarray:
    """``value`` as a float64 array (complex128 if ``complex_ok``; finite unless ``finite`` is
    False) of ``shape`` (``None``: any length along that axis).

    An ndarray or a nested list of numbers is accepted; boolean, object, text, datetime and
    structured dtypes are refused, and so is complex unless ``complex_ok``, and a masked array
    with a masked value.  A float64 array is returned as it is (not copied), a non-contiguous
    one too.  ``finite=False`` lets NaN and inf through (a recorded signal, whose non-finite
    samples its reader names by channel and sample).
    """
    want = ("finite " if finite else "") + ("complex" if complex_ok else "real")
    dims = " x ".join("any" if n is None else str(n) for n in shape)
    allowed = f"expected a {want} array of shape ({dims})"
    if not isinstance(value, (np.ndarray, list, tuple)):
        raise ArgumentError(where, name, describe(value), allowed, described=True)
    try:  # a list of masked rows too (review 26b)
        mask = (np.ma.getmaskarray(np.ma.asarray(value))
                if np.ma.isMaskedArray(value) or isinstance(value, (list, tuple)) else None)
    except (ValueError, TypeError):  # a ragged list: refused below
        mask = None
    if mask is not None and mask.any():
        # np.asarray dropped the mask: a masked (missing) sample was fitted as the value under
        # it (round 25; the SEP-005 reader's rule since round 17)
        masked = int(mask.sum())
        raise ArgumentError(where, name, describe(value), f"{allowed} ({masked} masked sample(s) "
                            "given: fill or cut them)", described=True)
    try:
        a = np.asarray(value)
    except (ValueError, TypeError):  # a ragged list
        raise ArgumentError(where, name, describe(value), allowed + " (a ragged list given)",
                            described=True) from None
    kinds = "iufc" if complex_ok else "iuf"
    if a.dtype.kind not in kinds:
        raise ArgumentError(where, name, describe(a), allowed + f" (dtype {a.dtype} refused)",
                            described=True)
    if a.ndim != len(shape) or any(n is not None and m != n for m, n in zip(a.shape, shape, strict=True)):
        raise ArgumentError(where, name, describe(a), allowed, described=True)
    a = a.astype(complex if a.dtype.kind == "c" else float, copy=False)
    if finite and a.size and not np.all(np.isfinite(a)):
        bad = int(a.size - np.count_nonzero(np.isfinite(a)))
        raise ArgumentError(where, name, describe(a), f"{allowed}; {bad} value(s) are NaN or "
                            "infinite", described=True)
    return a


def mapping(where: str, name: str, value: Any) -> dict[str, Any]:
    """``value`` (a mapping with text keys, numbers among its values finite) as a dict."""
    if not isinstance(value, Mapping) or not all(isinstance(k, str) for k in value):
        raise ArgumentError(where, name, value, "expected a dict with text keys")
    for k, v in value.items():
        # (finite_real: float(10**400) raised OverflowError, round 25)
        if isinstance(v, numbers.Real) and not isinstance(v, bool) and finite_real(v) is None:
            raise ArgumentError(where, f"{name}[{k!r}]", v, "expected a finite number")
    return dict(value)


def _range(low: int | None, high: int | None) -> str:
    if low is not None and high is not None:
        return f" in [{low}, {high}]"
    if low is not None:
        return f" >= {low}"
    return f" <= {high}" if high is not None else ""
