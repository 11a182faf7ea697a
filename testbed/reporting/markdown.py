"""Free text in the markdown the testbed writes (``report.md``, ``testbed identify``'s report):
shown as written, never read as markup.

A scenario's description, a channel's name, a plugin's exception or equations are the user's
text.  Written into markdown as they are, ``<img src=x onerror=...>`` is raw HTML to a markdown
renderer and ``![x](https://...)`` an image it fetches (hostile round 19's open item: the HTML
report escaped them, its markdown twin did not).  The rule here: no HTML (``&``, ``<``, ``>``
as entities), no link or image (``[`` backslash-escaped: every link and image opens with one),
no code span or table cell broken (backtick, ``|`` and backslash escaped), one line (line ends
as spaces); and code blocks fenced by more backticks than any run inside them, so their text
cannot close the fence.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

_ESCAPES = str.maketrans({"&": "&amp;", "<": "&lt;", ">": "&gt;", "[": "\\[", "`": "\\`",
                          "|": "\\|", "\\": "\\\\", "\n": " ", "\r": " "})


def md_text(text: Any) -> str:
    """``str(text)`` as inline markdown on one line in which no HTML, link, image, code span or
    table cell break takes effect (``&``, ``<``, ``>``, ``[``, backtick, ``|`` and backslash
    escaped); emphasis marks (``*``, ``_``) and a leading ``#`` are left as they are."""
    return str(text).translate(_ESCAPES)


def md_code_block(lines: Sequence[str]) -> list[str]:
    """``lines`` as a fenced code block (the fence, the lines, the fence): its fence is longer
    than the longest run of backticks in ``lines`` (at least three), so no line closes it."""
    runs = [len(m) for line in lines for m in re.findall(r"`+", line)]
    fence = "`" * max(3, max(runs, default=0) + 1)
    return [fence, *lines, fence]
