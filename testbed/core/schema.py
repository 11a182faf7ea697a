"""Declarative schemas for scenario tables: each key's type, unit, default and limits.

A schema is a ``dict[str, Field]``.  :func:`validate_table` checks one TOML table
against it and returns the table with defaults filled in; every problem raises a
:class:`~testbed.core.errors.ScenarioError` naming the file, the key, the value and
what is allowed.  The same schemas generate the scenario-file guide, so the
documentation cannot drift from what is accepted.
"""

from __future__ import annotations

import difflib
import math
import re
import sys
import unicodedata
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, replace
from typing import Any

from testbed.core.errors import ScenarioError

REQUIRED = object()

#: A free text shown on one line (a description, a tag): no control character.  A scenario's
#: description holding a newline split its row of `testbed list --plain` in two (a script
#: reading the tab-separated rows read a broken one), a tab added a column, an ESC sequence
#: went raw to the terminal (round 14).  C0 and C1 controls, DEL and the Unicode line and
#: paragraph separators.
ONE_LINE = "[^\\x00-\\x1f\\x7f-\\x9f\\u2028\\u2029]*"
ONE_LINE_DOC = "of one line without control characters (newline, tab, escape)"
#: Unicode categories of characters that show nothing on their own: controls (Cc), format
#: characters (Cf: zero-width space and joiners, direction marks, the byte-order mark, the
#: interlinear annotation marks, the tag characters), spaces of every width (Zs), line and
#: paragraph separators (Zl, Zp), and marks that combine with a character before them (Mn,
#: Me: a variation selector, the combining grapheme joiner), which alone have none to show on
UNSEEN_CATEGORIES = frozenset({"Cc", "Cf", "Zs", "Zl", "Zp", "Mn", "Me"})
#: Letters (category Lo) drawn as nothing: the Hangul fillers
HANGUL_FILLERS = frozenset("\u115f\u1160\u3164\uffa0")


def visible(text: str) -> bool:
    """Whether ``text`` holds a character that shows: one outside :data:`UNSEEN_CATEGORIES`
    and not a Hangul filler.  A tag of one zero-width space was listed as a gap and selected
    nothing (hostile round 29); its hand-made list let ``\\U000E0020`` (a tag space) or
    ``\\uFFF9`` (an annotation anchor) alone pass (review 29a L4): the rule is now Unicode's
    categories (``unicodedata``)."""
    return any(unicodedata.category(c) not in UNSEEN_CATEGORIES and c not in HANGUL_FILLERS
               for c in text)


VISIBLE_DOC = "not blank or invisible characters alone"

_TYPE_NAMES = {bool: "a boolean", int: "an integer", float: "a number", str: "a string",
               list: "a list", dict: "a table", object: "any value"}
_ITEM_NAMES = {bool: "booleans", int: "integers", float: "numbers", str: "strings"}


@dataclass(frozen=True)
class Field:
    """One key of a scenario table.

    Parameters
    ----------
    type : type
        ``float``, ``int``, ``bool``, ``str``, ``list`` or ``dict``.  An integer
        is accepted where a float is expected; a boolean never counts as a number.
    default : Any
        Value used when the key is absent; ``REQUIRED`` if it must be given.
    unit : str
        Physical unit, for error messages and the guide ("" if dimensionless).
    doc : str
        One line for the guide.
    choices : tuple, optional
        The allowed values.
    min, max : float, optional
        Bounds; ``min_inclusive`` / ``max_inclusive`` say whether they are allowed.
    item_type : type, optional
        Element type of a list.
    min_items, max_items : int, optional
        Length limits of a list.
    pattern : str, optional
        Regular expression a string (or every string item of a list) must match whole.
    pattern_doc : str
        The pattern in words, for messages and the guide.
    visible : bool
        A string (or every string item of a list) must hold a character that shows
        (:func:`visible`); :meth:`describe` says so (:data:`VISIBLE_DOC`, in front of
        ``pattern_doc``).
    also : Field, optional
        An alternative form that is accepted too (e.g. a named library or a list of term
        names); the value is accepted if it satisfies this field or ``also``.

    Notes
    -----
    A ``default`` of None means "optional, no value": the key may be left out (TOML has no
    null), and when given it is checked like any other.  Floats must always be finite.
    """

    type: type
    default: Any = REQUIRED
    unit: str = ""
    doc: str = ""
    choices: tuple | None = None
    min: float | None = None
    max: float | None = None
    min_inclusive: bool = True
    max_inclusive: bool = True
    item_type: type | None = None
    min_items: int | None = None
    max_items: int | None = None
    pattern: str | None = None
    pattern_doc: str = ""
    also: Field | None = None
    visible: bool = False

    @property
    def required(self) -> bool:
        return self.default is REQUIRED

    def describe(self) -> str:
        """What is allowed, in words (used in error messages and the guide)."""
        own = self._describe_own()
        return own if self.also is None else f"{own}, or {self.also.describe()}"

    def _describe_own(self) -> str:
        what = _TYPE_NAMES.get(self.type, self.type.__name__)
        if self.type is list and self.item_type is not None:
            what = f"a list of {_ITEM_NAMES.get(self.item_type, self.item_type.__name__)}"
        if self.choices is not None:
            return "one of " + ", ".join(repr(c) for c in self.choices)
        bounds = []
        if self.min is not None:
            bounds.append((">= " if self.min_inclusive else "> ") + _bound(self.min))
        if self.max is not None:
            bounds.append(("<= " if self.max_inclusive else "< ") + _bound(self.max))
        if self.type is list and self.min_items:
            bounds.append(f"with at least {self.min_items} item(s)")
        if self.type is list and self.max_items is not None:
            bounds.append(f"with at most {self.max_items} item(s)")
        # the visible rule in front of the pattern's words, said here for every visible field
        # (reader 29: each caller had to add VISIBLE_DOC to its pattern_doc by hand)
        words = [VISIBLE_DOC] if self.visible else []
        if self.pattern is not None and self.pattern_doc.startswith(("a ", "an ")):
            what = self.pattern_doc  # "expected a string a name of letters ..." read badly
        elif self.pattern is not None:
            words.append(self.pattern_doc or f"matching {self.pattern}")
        if words:
            bounds.append(", ".join(words))
        unit = f" [{self.unit}]" if self.unit else ""
        return what + (" " + " and ".join(bounds) if bounds else "") + unit


def _bound(v: float) -> str:
    """A bound in short form (``1e+06``), exact where that would round an integer (2**63 - 1)."""
    text = f"{v:g}"
    return str(v) if isinstance(v, int) and float(text) != v else text


def _is_type(value: Any, typ: type) -> bool:
    if typ is float:
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if typ is int:
        return isinstance(value, int) and not isinstance(value, bool)
    return isinstance(value, typ)


#: Integers a setting may hold: those of 64 bits, as numpy, HDF5 and the results tables store
#: them (a count of 2**70 samples was an internal error of numpy, "Maximum allowed size
#: exceeded", where a rig sets no maximum of its own).
INT64_MIN, INT64_MAX = -(2**63), 2**63 - 1


def _check_number(value: float, f: Field) -> bool:
    if isinstance(value, float) and not math.isfinite(value):
        return False
    if f.type is int and not INT64_MIN <= value <= INT64_MAX:
        return False
    if f.type is float and isinstance(value, int) and abs(value) > sys.float_info.max:
        return False  # float(10**400) raised OverflowError: an internal error
    if f.min is not None and (value < f.min or (value == f.min and not f.min_inclusive)):
        return False
    return not (f.max is not None and (value > f.max or (value == f.max and not f.max_inclusive)))


def check_value(value: Any, f: Field, *, file: str, key: str) -> Any:
    """Check one value against its field; return it (ints widened to float where asked).

    Raises
    ------
    ScenarioError
        Naming ``file``, ``key``, the value and :meth:`Field.describe` (with ``also``: both
        forms).
    """
    if f.also is None:
        return _check_own(value, f, file=file, key=key)
    try:
        return _check_own(value, f, file=file, key=key)
    except ScenarioError:
        try:
            return check_value(value, f.also, file=file, key=key)
        except ScenarioError:
            raise ScenarioError(file, key, value, f"expected {f.describe()}") from None


def _check_own(value: Any, f: Field, *, file: str, key: str) -> Any:
    if not _is_type(value, f.type):
        raise ScenarioError(file, key, value, f"expected {f.describe()}")
    if f.choices is not None and value not in f.choices:
        raise ScenarioError(file, key, value, f"expected {f.describe()}")
    if f.type in (int, float) and not _check_number(value, f):
        # said only where the bounds stated would have taken the value
        within = _check_number(value, replace(f, type=object))
        limit = ("" if not within else " of 64 bits" if f.type is int else " (finite as a float)")
        raise ScenarioError(file, key, value, f"expected {f.describe()}{limit}")
    if f.type is list:
        if f.min_items is not None and len(value) < f.min_items:
            raise ScenarioError(file, key, value, f"expected {f.describe()}")
        if f.max_items is not None and len(value) > f.max_items:
            raise ScenarioError(file, key, value, f"expected {f.describe()}")
        if f.item_type is not None:
            item = Field(f.item_type, min=f.min, max=f.max, min_inclusive=f.min_inclusive,
                         max_inclusive=f.max_inclusive, unit=f.unit, pattern=f.pattern,
                         pattern_doc=f.pattern_doc, visible=f.visible)
            value = [check_value(v, item, file=file, key=f"{key}[{i}]") for i, v in enumerate(value)]
    if f.type is str and f.pattern is not None and not re.fullmatch(f.pattern, value):
        raise ScenarioError(file, key, value, f"expected {f.describe()}")
    if f.type is str and f.visible and not visible(value):
        raise ScenarioError(file, key, value, f"expected {f.describe()}")
    if f.type is float:
        # + 0.0: -0.0 is 0.0 (IEEE -0.0 + 0.0 = +0.0, every other value unchanged); a scenario's
        # `rms_percent = -0.0` hashed to other data and other cells than 0.0 (round 12), the
        # same record cached twice and reported as "noise -0 %"
        value = float(value) + 0.0
    return value


def near_miss(table: Mapping[str, Any], key: str) -> str:
    """``"; given instead: 'metohd' (misspelt?)"`` when ``table`` holds a key spelt like the
    missing ``key`` (case ignored; difflib's ratio >= 0.7), else ``""``.  A misspelt required
    key was refused as the right key "missing", without naming the key the file has."""
    given = {str(k).strip().lower(): str(k) for k in table if k != key}
    close = difflib.get_close_matches(key.lower(), list(given), n=1, cutoff=0.7)
    return f"; given instead: {given[close[0]]!r} (misspelt?)" if close else ""


def unknown_key_hint(key: Any, known: Iterable[str],
                     elsewhere: Mapping[str, Iterable[str]] | None = None) -> str:
    """What an unknown ``key`` was probably meant as, for its refusal: ``" (did you mean
    'Vmax'?)"`` when one of ``known`` is spelt like it (case ignored; difflib's ratio >= 0.7,
    :func:`near_miss`'s), and ``" ('sample_rate' is a key of [simulation])"`` when it is one
    of the keys ``elsewhere`` maps a place (``"[simulation]"``, ``"sgd_sindy"``) to (a key
    known here but for its case first, then a place elsewhere, then a near spelling: the
    first that holds); ``""`` when none does.

    Malformed-input round 23: ``vmax`` for ``Vmax``, ``threshold`` for ``thresholds``,
    ``sample_rate`` under ``[rig]`` and ``--param lr=...`` for an identifier that has no
    learning rate were each refused with the whole list of allowed keys, naming neither the
    key meant nor where the given one belongs.
    """
    if not isinstance(key, str):
        return ""
    known = list(known)
    if key.lower() in {k.lower() for k in known}:
        same = next(k for k in known if k.lower() == key.lower())
        return f" (did you mean {same!r}?)"
    homes = [place for place, keys in (elsewhere or {}).items() if key in keys]
    if homes:  # the key exists, elsewhere: a near spelling here would be another meaning
        return f" ({key!r} is a key of {', '.join(homes)})"   # ('ridge' -> 'stride', review 24a)
    lowered = {k.lower(): k for k in known}
    close = difflib.get_close_matches(key.lower(), list(lowered), n=1, cutoff=0.7) \
        or sorted(k for k in lowered if _one_edit(key.lower(), k))[:1]
    return f" (did you mean {lowered[close[0]]!r}?)" if close else ""


def _one_edit(a: str, b: str) -> bool:
    """Whether ``a`` and ``b`` differ by one letter changed, added or dropped (``xo`` and
    ``x0``: short keys difflib's ratio leaves at 0.5); never for a one-letter key, which is one
    letter from every other (``G`` is not a misspelt ``E``, review 24a)."""
    if abs(len(a) - len(b)) > 1 or a == b or min(len(a), len(b)) < 2:
        return False
    if len(a) == len(b):
        return sum(x != y for x, y in zip(a, b, strict=True)) == 1
    short, long_ = sorted((a, b), key=len)
    return any(long_[:i] + long_[i + 1:] == short for i in range(len(long_)))


def validate_table(table: Mapping[str, Any], schema: Mapping[str, Field], *, file: str,
                   section: str, elsewhere: Mapping[str, Iterable[str]] | None = None) -> dict[str, Any]:
    """Validate ``table`` against ``schema``; return a new dict with defaults filled in.

    ``elsewhere`` maps other places (``"[simulation]"``) to their keys: an unknown key found
    there is named so (:func:`unknown_key_hint`).

    Raises
    ------
    ScenarioError
        For an unknown key (listing the allowed ones, and the one probably meant), a missing
        required key, or a value of the wrong type or out of bounds.
    """
    if not isinstance(table, Mapping):
        raise ScenarioError(file, section, table, "expected a table")
    out: dict[str, Any] = {}
    for key in table:
        if key not in schema:
            allowed = ", ".join(sorted(schema)) or "(no keys)"
            hint = unknown_key_hint(key, schema, elsewhere)
            raise ScenarioError(file, f"{section}.{key}", table[key],
                                f"unknown key; allowed keys in [{section}]: {allowed}{hint}")
    for key, f in schema.items():
        if key in table:
            out[key] = check_value(table[key], f, file=file, key=f"{section}.{key}")
        elif f.required:
            raise ScenarioError(file, f"{section}.{key}", allowed=f"missing; expected {f.describe()}")
        else:
            out[key] = f.default
    return out


def validate_variant(table: Mapping[str, Any], variants: Mapping[str, Mapping[str, Field]], *,
                     file: str, section: str, selector: str = "type") -> dict[str, Any]:
    """Validate a table whose ``selector`` key chooses the schema among ``variants``."""
    if not isinstance(table, Mapping):
        raise ScenarioError(file, section, table, "expected a table")
    kind = table.get(selector, REQUIRED)
    if kind is REQUIRED:
        raise ScenarioError(file, f"{section}.{selector}",
                            allowed="missing; expected one of " + ", ".join(map(repr, variants))
                            + near_miss(table, selector))
    if not isinstance(kind, str) or kind not in variants:
        raise ScenarioError(file, f"{section}.{selector}", kind,
                            "expected one of " + ", ".join(map(repr, variants)))
    rest = {k: v for k, v in table.items() if k != selector}
    out = validate_table(rest, variants[kind], file=file, section=section)
    return {selector: kind, **out}


def validate_header(raw: Any, *, sections: tuple[str, ...], header: str,
                    schema: Mapping[str, Field], file: str, stem: str | None,
                    other: tuple[str, str] | None = None) -> dict[str, Any]:
    """Check a TOML document's sections and validate its header table.

    ``raw`` must be a table of sections, each one of ``sections``; the ``[header]`` table must
    be present and valid; its ``name`` must equal ``stem`` (the file name without ``.toml``)
    when given.  ``other`` is ``(header, what)`` of the other kind of file (a study where a
    scenario is expected, and back): a document with that header and without ``[header]`` is
    refused with ``what`` (saying which file it is and how to run it).
    """
    if not isinstance(raw, Mapping):
        raise ScenarioError(file, allowed="expected a table of sections")
    if other is not None and header not in raw and other[0] in raw:
        raise ScenarioError(file, allowed=other[1])
    for section in raw:
        if section not in sections:
            # the section's content is not echoed: it may be a whole foreign file's
            raise ScenarioError(file, section,
                                allowed="unknown section; allowed: "
                                + ", ".join(f"[{s}]" for s in sections))
    if header not in raw:
        raise ScenarioError(file, header, allowed=f"missing [{header}] table")
    head = validate_table(raw[header], schema, file=file, section=header)
    if stem is not None and head["name"] != stem:
        raise ScenarioError(file, f"{header}.name", head["name"],
                            f"must equal the file name without .toml ({stem!r})")
    return head


ErrorFn = Callable[[str, Any, str], None]
"""``error(key, value, allowed)``: report a problem (it raises)."""


@dataclass(frozen=True)
class KeyUse:
    """When a table's key is read: only while ``switch`` (another key of the table, or several)
    satisfies ``reads``, described in words by ``when`` (e.g. ``"derivatives = 'estimated'"``).

    Attributes
    ----------
    switch : str or tuple of str
        The key (or keys) deciding whether the key is read.
    reads : callable
        ``reads(value)`` with the switch's validated value (one argument per key of a tuple
        ``switch``): True when the key is read.
    when : str
        The setting under which it is read, in words.
    """

    switch: str | tuple[str, ...]
    reads: Callable[..., bool]
    when: str

    @property
    def switches(self) -> tuple[str, ...]:
        return (self.switch,) if isinstance(self.switch, str) else self.switch

    def read_in(self, cfg: Mapping[str, Any]) -> bool:
        """Whether the key is read under the validated table ``cfg``."""
        return bool(self.reads(*(cfg[k] for k in self.switches)))


def check_keys_used(given: Mapping[str, Any], cfg: Mapping[str, Any],
                    schema: Mapping[str, Field], used_when: Mapping[str, KeyUse | tuple[KeyUse, ...]],
                    section: str, error: ErrorFn) -> None:
    """Refuse a key the table gives which its reader will not read under the table's other keys.

    Parameters
    ----------
    given : mapping
        The table as written (before defaults are filled in).
    cfg : mapping
        The same table validated, defaults filled in.
    schema : mapping of str to Field
        The table's schema (for each key's default).
    used_when : mapping of str to KeyUse or tuple of KeyUse
        The keys read only under a setting of others (all of a tuple's uses must hold).
    section : str
        The table's name in messages (``"signal"``, ``"identify"``).
    error : callable
        ``error(key, value, allowed)`` with the bare key, called on the first problem (it
        raises).

    Notes
    -----
    Rule: a key given with a value other than its default, while a key it depends on is set
    so that the reader does not read it, is refused (``signal.window = 301`` with recorded
    derivatives, ``identify.n_models = 5`` with ``optimizer = "stlsq"``, were accepted and
    ignored).  A key given at its default is accepted: a table written out whole (a family
    member, a run read back) lists every key at its default.
    """
    for key, uses in used_when.items():
        if key not in given or given[key] == schema[key].default:
            continue
        for use in (uses,) if isinstance(uses, KeyUse) else uses:
            if not use.read_in(cfg):
                here = ", ".join(f"{section}.{k} = {cfg[k]!r}" for k in use.switches)
                keys = " or ".join(f"{section}.{k}" for k in use.switches)
                error(key, given[key], f"read only with {use.when}; here {here}, so it would "
                                       f"be ignored: remove it or set {keys}")
