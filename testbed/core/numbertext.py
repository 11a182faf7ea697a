"""How the testbed reads a number written as text: one rule for the command line's options and
a CSV file's cells (a scenario file's TOML and a SEP-005 file's JSON are read by their own
grammars: TOML reads ``1_5`` and ``0x10``, JSON refuses ``.5`` and ``+1``).  No numpy here:
the command line imports it before it loads numpy.
"""

from __future__ import annotations

import re
import unicodedata

#: A number as the testbed reads one from text: ASCII digits, an optional sign, point and
#: exponent, and the words inf / infinity / nan (which the readers' finite checks refuse where
#: they must).  Python's ``int()`` and ``float()`` also read other scripts' digits and
#: underscores: ``--seed \uff13`` (a fullwidth digit) ran seed 3 and ``--fs 1_000`` read 1000 Hz
#: (hostile round 19); a CSV cell ``1_5`` was read as 15 and ``\u0661.\u0665`` (Arabic-Indic
#: digits) as 1.5 (round 26).
PLAIN_NUMBER = re.compile(r"[+-]?((\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?|inf|infinity|nan)",
                          re.IGNORECASE | re.ASCII)


def plain_number(text: str) -> str | None:
    """``text`` without its surrounding blanks if what is left is a number
    :data:`PLAIN_NUMBER` matches whole, else None.

    A blank is ASCII whitespace or a space separator of any script (Unicode category Zs: a
    no-break or an ideographic space); the other characters ``str.isspace`` takes, controls
    such as the file and unit separators ``\x1c``-``\x1f`` and ``\x85`` and the line and
    paragraph separators, are not (review 27a: ``str.strip`` read ``"\x1c5"`` as 5).

    Give the result to ``float()`` (or ``int()``, which refuses a point or an exponent).
    """
    if PLAIN_NUMBER.fullmatch(text):  # the common cell: no blank to strip (read 27b: 27 x)
        return text
    core = text.strip("".join(c for c in set(text) if _blank(c)))
    return core if PLAIN_NUMBER.fullmatch(core) else None


def _blank(c: str) -> bool:
    """Whether ``c`` is a blank around a number: ASCII whitespace or a Zs space."""
    return c in " \t\n\r\x0b\x0c" or unicodedata.category(c) == "Zs"
