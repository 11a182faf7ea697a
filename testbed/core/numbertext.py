"""How the testbed reads a number written as text: one rule for the command line's options and
a CSV file's cells (a scenario file's TOML and a SEP-005 file's JSON have their own grammar,
which is the same rule).  No numpy here: the command line imports it before it loads numpy.
"""

from __future__ import annotations

import re

#: A number as the testbed reads one from text: ASCII digits, an optional sign, point and
#: exponent, and the words inf / infinity / nan (which the readers' finite checks refuse where
#: they must).  Python's ``int()`` and ``float()`` also read other scripts' digits and
#: underscores: ``--seed \uff13`` (a fullwidth digit) ran seed 3 and ``--fs 1_000`` read 1000 Hz
#: (hostile round 19); a CSV cell ``1_5`` was read as 15 and ``\u0661.\u0665`` (Arabic-Indic
#: digits) as 1.5 (round 26), where TOML and JSON refuse both.
PLAIN_NUMBER = re.compile(r"[+-]?((\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?|inf|infinity|nan)",
                          re.IGNORECASE | re.ASCII)


def plain_number(text: str) -> str | None:
    """``text`` without its surrounding blanks (``str.strip``: a blank of any script is a blank)
    if what is left is a number :data:`PLAIN_NUMBER` matches whole, else None.

    Give the result to ``float()`` (or ``int()``, which refuses a point or an exponent).
    """
    core = text.strip()
    return core if PLAIN_NUMBER.fullmatch(core) else None
