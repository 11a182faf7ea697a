"""Errors a user can act on: each names the file, the key, the value and what is allowed."""

from __future__ import annotations

from typing import Any


class TestbedError(Exception):
    """Base of the errors the CLI prints as one line, without a traceback."""

    __test__ = False  # not a pytest test class despite the name


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
        parts = [self.file]
        if key is not None:
            parts.append(f"key '{key}'")
        if value is not ...:
            parts.append(f"value {value!r}")
        msg = ": ".join(parts)
        super().__init__(f"{msg}: {allowed}" if allowed else msg)


class RigError(TestbedError):
    """A rig cannot be built or simulated as asked (e.g. a linkage that cannot close)."""


class IdentificationError(TestbedError):
    """An identifier could not produce a model from the data given."""


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
