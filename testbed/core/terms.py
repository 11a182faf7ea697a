"""Names of library terms, shared by rig truths and identifier libraries.

A term is a product of factors joined by ``*``.  Factors:

- coordinates ``th1``..``thN``, velocities ``dth1``, accelerations ``ddth1``,
  inputs ``u1``; powers as ``dth2^2``;
- trigonometric functions of one coordinate, ``sin(th1)``, or of a difference
  with the lower index first, ``cos(th1-th2)``;
- ``1`` for the constant term.

:func:`canonical` puts factors in one order (trig factors, then coordinates,
velocities, accelerations, inputs; alphabetical within a group) so that the
same product always has the same name.  Scoring matches identified and true
coefficients by these names.
"""

from __future__ import annotations

import re

_ORDER = (("sin(", 0), ("cos(", 0), ("ddth", 3), ("dth", 2), ("th", 1), ("u", 4), ("x", 1),
          ("v", 2), ("a", 3))
_DIFF = re.compile(r"^(sin|cos)\(th(\d+)-th(\d+)\)$")


def _factor_key(f: str) -> tuple[int, str]:
    for prefix, group in _ORDER:
        if f.startswith(prefix):
            return group, f
    return 5, f


def _normalise_factor(f: str) -> tuple[str, int]:
    """Return (factor, sign): ``sin(th2-th1)`` -> (``sin(th1-th2)``, -1)."""
    f = f.strip()
    m = _DIFF.match(f)
    if m and int(m.group(2)) > int(m.group(3)):
        fn, a, b = m.groups()
        return f"{fn}(th{b}-th{a})", (-1 if fn == "sin" else 1)
    return f, 1


def canonical(term: str) -> tuple[str, int]:
    """Canonical name of a product term and the sign picked up on the way.

    >>> canonical("ddth2*sin(th3-th2)")
    ('sin(th2-th3)*ddth2', -1)
    """
    if term.strip() == "1":
        return "1", 1
    sign = 1
    counts: dict[str, int] = {}  # powers counted, not expanded: 'x^999999999' made 1e9 names
    for raw in term.split("*"):
        base, _, power = raw.partition("^")
        f, s = _normalise_factor(base)
        n = int(power) if power else 1
        sign *= s**n
        counts[f] = counts.get(f, 0) + max(n, 0)  # a power <= 0 adds no factor
    out = [f if counts[f] == 1 else f"{f}^{counts[f]}"
           for f in sorted(counts, key=_factor_key) if counts[f] > 0]
    return "*".join(out), sign
