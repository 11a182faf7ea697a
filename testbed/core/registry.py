"""Name-keyed registries with tags, in the manner of dm_control's suite.

Rigs (``models``) and identifiers (``identify``) register themselves under a
name; scenario files refer to those names.  Adding a rig or an identifier is
adding a module with a registration, touching nothing else.

Entries come from three places, and each remembers which (:meth:`Registry.origin`,
shown by ``testbed list``):

- ``builtin``: a module of the registry's own package (imported on first lookup);
- an *entry point* of an installed distribution, in the group
  :data:`IDENTIFIER_ENTRY_POINTS` or :data:`RIG_ENTRY_POINTS`, loaded on first lookup.
  It names a module (whose import registers its classes) or a class (registered under its
  ``name`` attribute)::

      [project.entry-points."sysid_testbed.identifiers"]
      my_method = "my_package.my_method:MyMethod"

- a plugin *file* or module imported at run time (:func:`import_plugin`; ``--plugin FILE.py``
  on the command line, ``plugins = [...]`` in a study).
"""

from __future__ import annotations

import importlib
import importlib.metadata
import importlib.util
import os
import pkgutil
import re
import stat
import sys
import types
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from testbed.core.errors import (
    TestbedError,
    UnknownNameError,
    exception_text,
    show_value,
    unusable_path,
)
from testbed.core.exit_guard import no_process_exit
from testbed.core.lazy import configure_loaded
from testbed.core.process_state import kept_process_state
from testbed.core.schema import unknown_key_hint

#: Entry-point group of identifiers from other distributions.
IDENTIFIER_ENTRY_POINTS = "sysid_testbed.identifiers"
#: Entry-point group of rigs from other distributions.
RIG_ENTRY_POINTS = "sysid_testbed.rigs"
#: Prefix of the module names under which plugin files are imported (see :func:`import_plugin`).
PLUGIN_MODULE_PREFIX = "_testbed_plugin_"
#: A registered name: what a scenario's ``rig`` or ``[identify] method`` can name and a cache
#: file's name can start with (the scenario names' pattern).  A plugin registering ``5`` made
#: `testbed list` an internal error (TypeError sorting the names), ``"../up"`` a rig whose cache
#: files went outside the cache folder, ``""`` or ``"x\ny"`` names no file can spell (round 12).
REGISTERED_NAME = r"[A-Za-z0-9_][A-Za-z0-9_.-]{0,127}"
REGISTERED_NAME_DOC = ("a name of letters, digits, '_', '.', '-' (at most 128, not starting with "
                       "'.' or '-')")


class PluginError(TestbedError):
    """A plugin (file, module or entry point) that cannot be imported or registers nothing."""


def plugin_module_name(path: str | Path) -> str:
    """The module name a plugin file is imported under: derived from its absolute path, so the
    same file is imported once per process however it is named."""
    path = Path(path).resolve()
    return PLUGIN_MODULE_PREFIX + "".join(c if c.isalnum() else "_" for c in str(path))


def import_plugin(spec: str) -> Any:
    """Import one plugin: a ``.py`` file path or a dotted module name; return the module.

    Importing the same plugin again in the same process is a no-op (its registrations run
    once).

    Raises
    ------
    PluginError
        If the file does not exist or the import fails (the message names the plugin and the
        exception).
    """
    if not spec.endswith(".py"):
        try:
            with no_process_exit(), kept_process_state():  # its os._exit(0), np.seterr, os.chdir
                module = importlib.import_module(spec)  # (hostile round 20)
        except BaseException as e:  # (sys.exit(0) in a plugin ended a run with status 0)
            if isinstance(e, KeyboardInterrupt):  # the user's Ctrl-C stays an interrupt
                raise
            raise PluginError(f"plugin {spec}: cannot import it: {type(e).__name__}: "
                              f"{exception_text(e)}; expected a .py file or an importable dotted "
                              "module name") from e
        configure_loaded()  # a plugin importing MuJoCo itself: its C-level log silenced too
        return module
    try:
        is_file = stat.S_ISREG(os.stat(spec).st_mode)  # before resolve(), whose RuntimeError
        path = Path(spec).resolve()  # "Symlink loop" was an internal error (hostile round 29)
    except (OSError, ValueError) as e:  # a name of 100,000 characters: ENAMETOOLONG, an internal
        # error of `run --plugin` (round 14)
        why = unusable_path(e)  # the one reading of such a path (review 28b L7: its own here)
        if why is None:
            raise PluginError(f"plugin {spec}: no such file") from None
        raise PluginError(f"plugin {spec}: not a usable path ({why}); expected a .py file or an "
                          "importable dotted module name") from None
    if not is_file:
        raise PluginError(f"plugin {spec}: not a regular file (a folder, FIFO or device); "
                          "expected a .py file or an importable dotted module name")
    modname = plugin_module_name(path)
    if modname in sys.modules:
        return sys.modules[modname]
    loader_spec = importlib.util.spec_from_file_location(modname, path)
    if loader_spec is None or loader_spec.loader is None:
        raise PluginError(f"plugin {spec}: cannot be imported as a Python module")
    module = importlib.util.module_from_spec(loader_spec)
    sys.modules[modname] = module
    try:
        with no_process_exit(), kept_process_state():  # its os._exit(0), np.seterr, os.chdir
            loader_spec.loader.exec_module(module)  # (hostile round 20)
    except BaseException as e:
        del sys.modules[modname]
        # a plugin's sys.exit(0) ended `testbed run` with status 0 and no verdict; any other
        # BaseException but the user's Ctrl-C (GeneratorExit, pytest's Skipped from a plugin
        # written as a test helper) was a traceback with status 1 (hostile round 19)
        if not isinstance(e, KeyboardInterrupt):
            raise PluginError(f"plugin {spec}: importing it failed: {type(e).__name__}: "
                              f"{exception_text(e)}") from e
        raise
    configure_loaded()  # a plugin importing MuJoCo itself: its C-level log silenced too
    return module


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
    entry_points : str, optional
        Entry-point group whose entries (modules or classes) are loaded on first lookup,
        after the package.
    """

    kind: str
    package: str | None = None
    entry_points: str | None = None
    _entries: dict[str, Any] = field(default_factory=dict)
    _tags: dict[str, frozenset[str]] = field(default_factory=dict)
    _origins: dict[str, str] = field(default_factory=dict)
    _loading_entry_point: str | None = None
    _loaded: bool = False

    def register(self, name: str, *, tags: Iterable[str] = ()) -> Callable[[Any], Any]:
        """Class decorator registering ``obj`` under ``name`` with ``tags``."""

        def deco(obj: Any) -> Any:
            if not isinstance(name, str) or not re.fullmatch(REGISTERED_NAME, name):
                raise ValueError(f"{self.kind} name {name!r}: expected {REGISTERED_NAME_DOC}")
            if name in self._entries and self._entries[name] is not obj:
                raise ValueError(f"{self.kind} {name!r} is registered twice")
            self._entries[name] = obj
            self._tags[name] = frozenset(tags)
            self._origins[name] = self._origin_of(obj)
            return obj

        return deco

    def _origin_of(self, obj: Any) -> str:
        if self._loading_entry_point is not None:
            return self._loading_entry_point
        mod = getattr(obj, "__module__", "") or ""
        if self.package and (mod == self.package or mod.startswith(self.package + ".")):
            return "builtin"
        if mod.startswith(PLUGIN_MODULE_PREFIX):
            return f"file {getattr(sys.modules.get(mod), '__file__', mod)}"
        return f"module {mod}"

    def _load(self) -> None:
        """Import the package's modules and the entry points, once.

        ``_loaded`` is set first so that a module looking the registry up while it is being
        imported sees what has registered so far instead of recursing; if an import fails,
        the flag is reset and the failure raised naming the module, so the next lookup tries
        again rather than silently using a partial registry.
        """
        if self._loaded:
            return
        self._loaded = True
        try:
            if self.package is not None:
                pkg = importlib.import_module(self.package)
                for info in pkgutil.iter_modules(pkg.__path__):
                    if not info.name.startswith("_"):
                        module = f"{self.package}.{info.name}"
                        try:
                            importlib.import_module(module)
                        except PluginError:
                            raise
                        except Exception as e:
                            raise PluginError(f"{self.kind} module {module} failed to import: "
                                              f"{type(e).__name__}: {exception_text(e)}") from e
            if self.entry_points is not None:
                self._load_entry_points()
        except BaseException:
            self._loaded = False
            raise
        configure_loaded()  # an entry point importing MuJoCo itself

    def snapshot(self) -> tuple[dict, dict, dict]:
        """The registry's entries, tags and origins (loaded first), for :meth:`restore`."""
        self._load()
        return dict(self._entries), dict(self._tags), dict(self._origins)

    def restore(self, snap: tuple[dict, dict, dict]) -> None:
        """Return to a :meth:`snapshot`: registrations made since are forgotten (tests and
        plugin experiments in one process)."""
        for mine, saved in zip((self._entries, self._tags, self._origins), snap, strict=True):
            mine.clear()
            mine.update(saved)

    def _load_entry_points(self) -> None:
        seen = set()
        for ep in importlib.metadata.entry_points(group=self.entry_points):
            if (ep.name, ep.value) in seen:  # the same distribution visible twice on sys.path
                continue
            seen.add((ep.name, ep.value))
            dist = getattr(ep.dist, "name", None)
            self._loading_entry_point = f"entry point {ep.name}" + (f" ({dist})" if dist else "")
            try:
                with no_process_exit(), kept_process_state():  # as import_plugin's import
                    obj = ep.load()
                if isinstance(obj, type) and obj not in self._entries.values():
                    name = getattr(obj, "name", "") or ep.name
                    self.register(name, tags=getattr(obj, "tags", ()))(obj)
                elif not isinstance(obj, (type, types.ModuleType)):
                    # a function or an instance was loaded and ignored in silence (round 14)
                    raise PluginError(f"{self.kind} entry point {ep.name} = {ep.value} "
                                      f"({self.entry_points}) names an object of type "
                                      f"{type(obj).__name__!r}; "
                                      "expected a module (whose import registers its classes) "
                                      "or a class")
            except PluginError:
                raise
            except (Exception, SystemExit) as e:
                # (SystemExit: an entry point's sys.exit(0) at import ended `testbed list` and
                # `testbed run` with status 0 and no output, round 14; as a plugin file's)
                raise PluginError(f"{self.kind} entry point {ep.name} = {ep.value} "
                                  f"({self.entry_points}): {type(e).__name__}: {exception_text(e)}") from e
            finally:
                self._loading_entry_point = None

    def get(self, name: str) -> Any:
        """Return the entry called ``name``; UnknownNameError (a KeyError) naming what is
        allowed for a name it does not hold (a value that is not text included)."""
        self._load()
        try:
            return self._entries[name]
        except (KeyError, TypeError):  # TypeError: an unhashable name (a list)
            allowed = ", ".join(sorted(self._entries)) or "(none registered)"
            raise UnknownNameError(f"unknown {self.kind} {show_value(name)}; allowed: {allowed}"
                                   + unknown_key_hint(name, self._entries)) from None

    def names(self, tag: str | None = None) -> list[str]:
        """Sorted names, optionally only those carrying ``tag``."""
        self._load()
        return sorted(n for n in self._entries if tag is None or tag in self._tags[n])

    def tags(self, name: str) -> frozenset[str]:
        """Tags of the entry ``name``."""
        self.get(name)
        return self._tags[name]

    def origin(self, name: str) -> str:
        """Where ``name`` came from: ``"builtin"``, ``"entry point <name> (<distribution>)"``,
        ``"file <path>"`` or ``"module <dotted name>"``."""
        self.get(name)
        return self._origins[name]

    def __contains__(self, name: str) -> bool:
        self._load()
        return name in self._entries


def builtin_class(cls: type) -> bool:
    """True for an identifier class of the testbed's own (defined in the ``identify`` package),
    whose exceptions are the testbed's bugs; any other (a plugin's, a subclass of a built-in
    defined elsewhere) is a user's, whose exceptions are its failures.  The one rule of both
    wrappers of an identifier's methods, :func:`identify._base._called` and
    :func:`testbed.pipeline.fit.fit_or_fail` (review 28a L5: ``_called`` decided by module,
    ``fit_or_fail`` by registry origin, so a built-in class registered again through the API
    under a name of the user's was a plugin to one and a built-in to the other)."""
    return cls.__module__.partition(".")[0] == "identify"
