"""Name-keyed registries with tags, in the manner of dm_control's suite.

Rigs (``models``) and identifiers (``identify``) register themselves under a
name; scenario files refer to those names.  Adding a rig or an identifier is
adding a module with a registration, touching nothing else.
"""

from __future__ import annotations

import importlib
import pkgutil
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any


@dataclass
class Registry:
    """A mapping ``name -> object`` with tags per name.

    Parameters
    ----------
    kind : str
        What the entries are ("rig", "identifier"), used in error messages.
    package : str, optional
        Dotted name of a package whose submodules are imported on first
        lookup, so that their registrations run.
    """

    kind: str
    package: str | None = None
    _entries: dict[str, Any] = field(default_factory=dict)
    _tags: dict[str, frozenset[str]] = field(default_factory=dict)
    _loaded: bool = False

    def register(self, name: str, *, tags: Iterable[str] = ()) -> Callable[[Any], Any]:
        """Class decorator registering ``obj`` under ``name`` with ``tags``."""

        def deco(obj: Any) -> Any:
            if name in self._entries and self._entries[name] is not obj:
                raise ValueError(f"{self.kind} {name!r} is registered twice")
            self._entries[name] = obj
            self._tags[name] = frozenset(tags)
            return obj

        return deco

    def _load(self) -> None:
        if self._loaded or self.package is None:
            return
        self._loaded = True
        pkg = importlib.import_module(self.package)
        for info in pkgutil.iter_modules(pkg.__path__):
            if not info.name.startswith("_"):
                importlib.import_module(f"{self.package}.{info.name}")

    def get(self, name: str) -> Any:
        """Return the entry called ``name``; KeyError naming what is allowed."""
        self._load()
        try:
            return self._entries[name]
        except KeyError:
            allowed = ", ".join(sorted(self._entries)) or "(none registered)"
            raise KeyError(f"unknown {self.kind} {name!r}; allowed: {allowed}") from None

    def names(self, tag: str | None = None) -> list[str]:
        """Sorted names, optionally only those carrying ``tag``."""
        self._load()
        return sorted(n for n in self._entries if tag is None or tag in self._tags[n])

    def tags(self, name: str) -> frozenset[str]:
        self.get(name)
        return self._tags[name]

    def __contains__(self, name: str) -> bool:
        self._load()
        return name in self._entries
