"""Errors a user can act on: each names the file, the key, the value and what is allowed."""

from __future__ import annotations

import errno
import unicodedata
from typing import Any

#: Longest rendering of an offending value in a message [characters]: a message stays one
#: readable line even for a 10,000-item list or a megabyte string.
MAX_VALUE_CHARS = 120


def _one_line(text: str) -> str:
    """``text`` with control characters escaped, so a message is always one line."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


#: ``text`` with control characters escaped (the command line's error lines; public name).
printable = _one_line

#: Characters that are neither C0/C1 controls nor line separators but change how a terminal or
#: an editor shows the text around them: bidirectional controls and marks (a right-to-left
#: override reorders what follows) and zero-width characters that hide inside a name.
HIDDEN_FORMAT = frozenset("\u061c\u200b\u200e\u200f\u202a\u202b\u202c\u202d\u202e"
                          "\u2060\u2066\u2067\u2068\u2069\ufeff")


def is_control(c: str) -> bool:
    """Whether the character ``c`` controls a terminal or a text's layout rather than showing.

    Rule: the C0 and C1 controls and DEL (Unicode category Cc: newline, tab, ESC, NUL), the line
    and paragraph separators (Zl, Zp) and :data:`HIDDEN_FORMAT`.  Every other character shows,
    spaces of every width included (a no-break space U+00A0 from a spreadsheet, U+202F from a
    French-locale export), and so do the surrogates Python decodes undecodable file-name bytes
    to: a reader's own data, to be kept as given.
    """
    return unicodedata.category(c) in ("Cc", "Zl", "Zp") or c in HIDDEN_FORMAT


def terminal_safe(text: str) -> str:
    """``text`` with only the :func:`is_control` characters escaped (``\\x1b``, ``\\u202e``).

    For a path the command wrote, printed so that it can be copied: a file name in any script
    and with any spaces stays as it is, an escape sequence cannot reach the terminal.
    """
    return "".join(repr(c)[1:-1] if is_control(c) else c for c in text)


def _cut(text: str, limit: int = MAX_VALUE_CHARS, marker: str = "[...]") -> str:
    """``text`` as it is up to ``limit`` characters, else cut, the cut marked by ``marker``.

    A marker holding ``{n}`` is formatted with the number of characters cut and follows the
    first ``limit`` characters (the count says what is missing: :func:`exception_text`'s
    ``[... N more characters]``); any other takes the place of its own length in them, so the
    text stays ``limit`` characters long (a value shown in a message: ``[...]``)."""
    if len(text) <= limit:
        return text
    if "{n}" in marker:
        return text[:limit] + marker.format(n=len(text) - limit)
    return text[:limit - len(marker)] + marker


def unusable_path(e: BaseException) -> str | None:
    """Why a path whose ``os.stat`` raised ``e`` can name nothing (a name too long for the file
    system, a NUL byte, a symbolic-link loop, ...), or None where nothing is there (the caller
    says what is missing).  The command line's and the API's one reading (hostile round 28:
    ``testbed.read_results("x" * 5000)`` was OSError 36 from inside)."""
    if isinstance(e, ValueError):
        return "it contains a NUL byte"
    code = getattr(e, "errno", None)
    if code in (errno.ENOENT, errno.ENOTDIR):
        return None
    return ({errno.ELOOP: "a symbolic link that loops",
             errno.ENAMETOOLONG: "a file name too long for the file system"}.get(code)
            or getattr(e, "strerror", None) or type(e).__name__)


#: Characters of an exception's text :func:`exception_text` keeps: a plugin's 100,000-character
#: message made a failed fit's reason, and every table and report holding it, that long
#: (review 28a L6); the head says what failed
MAX_EXCEPTION_CHARS = 1000


def exception_text(e: BaseException) -> str:
    """``str(e)`` on one line (blanks collapsed) and cut to :data:`MAX_EXCEPTION_CHARS`
    characters (the cut marked ``[... N more characters]``), or a stand-in naming its type where
    the exception's own ``__str__`` raises: a plugin's exception whose ``__str__`` raised turned
    a failed fit into an internal error (hostile round 28).  The one reading of an exception
    not the testbed's own (a plugin's fit, simulate, import; a sweep cell's error)."""
    try:
        text = str(e)
    except Exception:
        return f"(no message: {type(e).__name__}.__str__ failed)"
    return _cut(" ".join(text.split()), MAX_EXCEPTION_CHARS, "[... {n} more characters]")


def show_text(text: str) -> str:
    """``text`` as it is (unquoted: a unit, a file's own word) on one line, cut to
    :data:`MAX_VALUE_CHARS` characters.  A unit of 5,000 characters was shown three times in
    one 15,000-character refusal (hostile round 28)."""
    return _cut(_one_line(str(text)[:MAX_VALUE_CHARS + 1]))


def show_value(value: Any) -> str:
    """``repr(value)`` on one line, cut to :data:`MAX_VALUE_CHARS` characters."""
    try:
        text = repr(value)
    except Exception:  # a broken __repr__ must not hide the real error
        text = f"<{type(value).__name__}>"
    # escaped from its head only: each character shows as one or more, so the cut is the same;
    # escaping the whole repr of a 10**6-item list took 9 s of a study's refusal (round 26)
    return _cut(_one_line(text[:MAX_VALUE_CHARS + 1]))


#: Names listed in a message before the rest are counted [names]: a record of 3,000 channels
#: named them all, twice, on one 40 kB line.
MAX_NAMES = 12


def show_names(names: Any) -> str:
    """``names`` comma-separated, the first :data:`MAX_NAMES` of them and a count of the rest."""
    names = [str(n) for n in names]
    shown = ", ".join(_one_line(n) for n in names[:MAX_NAMES])
    return shown if len(names) <= MAX_NAMES else f"{shown} and {len(names) - MAX_NAMES} more"



#: Exit statuses of a command (:func:`testbed.cli.main`, and a command served by
#: :mod:`testbed.server`): a run that failed its bars, a user's mistake, a bug, an interrupt.
EXIT_FAIL, EXIT_USAGE, EXIT_INTERNAL, EXIT_INTERRUPTED = 1, 2, 3, 130

class TestbedError(Exception):
    """Base of the errors the CLI prints as one line, without a traceback.

    Its text is one line wherever it is read (``str(e)``), its control characters escaped:
    a path holding a newline made a DatasetError's or a RunStoreError's text two lines through
    the Python API (hostile round 19; the command line escaped its own lines already).
    """

    __test__ = False  # not a pytest test class despite the name

    def __str__(self) -> str:
        return _one_line(super().__str__())


class ScenarioError(TestbedError):
    """A scenario or study file is missing or malformed.

    Parameters
    ----------
    file : str
        Path of the offending file.
    key : str, optional
        Dotted key, e.g. ``"rig.n_segments"``.
    value : Any, optional
        The offending value.
    allowed : str
        What would have been accepted.
    """

    def __init__(self, file: str, key: str | None = None, value: Any = ..., allowed: str = ""):
        self.file, self.key, self.value, self.allowed = str(file), key, value, allowed
        parts = [_one_line(self.file)]
        if key is not None:
            # cut like a value: an unknown key of 5,000 digits made a 5 kB line
            parts.append(f"key '{_cut(_one_line(str(key)))}'")
        if value is not ...:
            parts.append(f"value {show_value(value)}")
        msg = ": ".join(parts)
        super().__init__(f"{msg}: {_one_line(allowed)}" if allowed else msg)


class BudgetError(ScenarioError):
    """A scenario would need more memory or integration steps than the declared budget
    (:mod:`testbed.core.budget`); raised at load, before anything is simulated."""


class InputError(TestbedError):
    """A command-line input a user gave cannot be used (a missing folder, a file that is not
    a dataset, an unreachable scheduler, a bad option value)."""


class RigError(TestbedError):
    """A rig cannot be built or simulated as asked (e.g. a linkage that cannot close).

    ``key`` and ``value``, when given, name the setting a scenario's refusal blames
    (``"rig.length"``); without them the refusal names the ``rig`` table.
    """

    def __init__(self, message: str, key: str | None = None, value: object = None) -> None:
        super().__init__(message)
        self.key = key
        self.value = value


class IdentificationError(TestbedError):
    """An identifier could not produce a model from the data given."""


class PluginMethodError(IdentificationError):
    """A method of a user's plugin identifier (a class outside ``identify``) raised an
    exception of its own (not one of the testbed's): the user's code failed, so the run scores
    it (a failed simulation, a failed equation listing) instead of calling it an internal error
    of the testbed.  Its text names the method and the exception's type."""


class HyperparameterError(IdentificationError, ValueError):
    """An identifier was constructed with a hyperparameter its declaration refuses (checked
    at fit time for estimators built in Python; scenario files are checked at load).  A
    ValueError too, as scikit-learn estimators raise for bad parameters."""


class UnresolvedModelError(IdentificationError):
    """An identified model was not simulated: a pole the record cannot resolve would make its
    integration cost beyond a stated budget.  Scoring turns it into a failed score ("not
    simulated") with its reason."""


def numeric_blow_up(e: BaseException) -> bool:
    """True for an exception by which a simulation's state ran off: a float overflow or
    invalid operation raised (``OverflowError``, ``FloatingPointError``), or scipy's refusal of
    a non-finite state (``ValueError`` "array must not contain infs or NaNs", which the
    scorer's ``simulate_scored`` reads as a divergence of a built-in model's integrator).  A
    plugin's simulate raising one of these has diverged, as a built-in's (review 28a L7: it
    was "simulation failed")."""
    return isinstance(e, (OverflowError, FloatingPointError)) or (
        isinstance(e, ValueError) and "infs or NaNs" in exception_text(e))


class DivergenceError(IdentificationError):
    """A simulation of an identified model failed: non-finite state, blow-up, or a loop closure
    that no longer solves.  Scoring turns it into a failed score with its reason and time.

    Parameters
    ----------
    message : str
        What went wrong.
    time : float, optional
        Simulation time [s] at which it happened (NaN if unknown).
    """

    def __init__(self, message: str, time: float = float("nan")):
        self.time = float(time)
        super().__init__(message if time != time else f"{message} (at t = {time:.4g} s)")


class ArgumentError(TestbedError, ValueError):
    """A public function or class of the Python API was given an argument it cannot use
    (:mod:`testbed.core.arguments`): the message names the function, the argument, its value and
    what is allowed.  A ValueError too, as numpy and scikit-learn raise for bad arguments.

    Parameters
    ----------
    where : str
        The function or class, e.g. ``"Measurement"``, ``"run_sweep"``.
    name : str
        The argument, e.g. ``"xd"``, ``"jobs"``.
    value : Any, optional
        The offending value (shown cut to one line), or a description of it when
        ``described`` (an array's shape and dtype).
    allowed : str
        What would have been accepted.
    """

    def __init__(self, where: str, name: str, value: Any = ..., allowed: str = "", *,
                 described: bool = False):
        self.where, self.name, self.value, self.allowed = where, name, value, allowed
        parts = [_one_line(where), f"argument '{_cut(_one_line(name))}'"]
        if value is not ...:
            parts.append(_cut(_one_line(str(value))) if described else f"value {show_value(value)}")
        msg = ": ".join(parts)
        super().__init__(f"{msg}: {_one_line(allowed)}" if allowed else msg)


class NotFittedError(TestbedError, ValueError, AttributeError):
    """An identifier's result was asked for (``score``, ``equations``, ``simulate``,
    ``predict_acceleration``) before :meth:`~identify._base.Identifier.fit`.  A ValueError and an
    AttributeError too, as scikit-learn's ``NotFittedError``."""


class UnsupportedError(TestbedError, NotImplementedError):
    """An identifier was asked for what its kind of model has not (a mechanical model's
    explicit accelerations: its equations are implicit).  A NotImplementedError too, as it was
    documented before it was one of the project's errors."""


class RegistrationError(TestbedError, ValueError):
    """A rig kind's truth type, signal chain or scorer could not be registered (another one is
    registered for that kind, the kind has no score catalogue, the object is not of the type
    registered).  A ValueError too, as it was before it was one of the project's errors."""


class UnknownNameError(TestbedError, KeyError):
    """A name a registry does not hold (an identifier, a rig): the message lists the allowed
    ones.  A KeyError too, as it was before it was one of the project's errors."""

    def __str__(self) -> str:  # KeyError's own quotes the message: one readable line instead
        return str(self.args[0]) if self.args else ""
