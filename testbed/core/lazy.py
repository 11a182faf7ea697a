"""Heavy third-party modules imported on first use, not at start-up.

``testbed list`` imports every rig and identifier module (the registries import their packages)
and must not pay for the engines and libraries they use only when they compute: MuJoCo
(~0.1 s of import), h5py (~0.07 s), SciPy's ``linalg``, ``fft``, ``optimize`` (~0.1-0.3 s).
A module that uses one in many places binds a :class:`LazyModule` at its top instead of the
module itself::

    sla = lazy_module("scipy.linalg")   # nothing imported yet
    ...
    w = sla.eigh(K, M, eigvals_only=True)   # imported here, once

``tests/test_cli_startup.py`` checks that listing the registries imports none of them.

Some packages read the environment when first imported; :data:`IMPORT_ENVIRONMENT` holds the
settings the testbed gives them (only where the user has set none), and :data:`IMPORT_SETUP`
what is set on a package once it is imported (:func:`configure_loaded` applies it to a package a
plugin imported itself).
"""

from __future__ import annotations

import importlib
import os
import sys
from collections.abc import Callable
from types import ModuleType
from typing import Any

from testbed.core.errors import InputError, show_value

__all__ = ["IMPORT_ENVIRONMENT", "IMPORT_SETUP", "LazyModule", "configure_loaded", "lazy_module"]

#: Environment variables set before the first import of a package (by its top-level name),
#: unless the user has set them.  MuJoCo imports its OpenGL renderer unless ``MUJOCO_GL`` is
#: ``disable``, and that import (the ``glfw`` package) starts a second Python process to read
#: the GLFW library's version.  Measured on the 2-core machine under load 15, three fresh
#: processes each: ``import mujoco`` took 0.62-0.99 s of wall time (0.14-0.19 s CPU, 0.04-0.07 s
#: more in the child), 0.31-0.35 s with ``MUJOCO_GL=disable`` (0.08-0.09 s CPU).  The testbed
#: never renders; a plugin that does sets ``MUJOCO_GL`` itself (``glfw``, ``egl``, ``osmesa``).
IMPORT_ENVIRONMENT: dict[str, dict[str, str]] = {"mujoco": {"MUJOCO_GL": "disable"}}


def _quiet_mujoco(mujoco: ModuleType) -> None:
    """Stop MuJoCo's default log handler printing and filing its warnings.

    MuJoCo's C library prints each warning (``WARNING: Nan, Inf or huge value in QACC at DOF 0.
    The simulation is unstable. Time = 0.0001.``) to standard output and appends it to
    ``MUJOCO_LOG.TXT`` in the current folder: a stray file among the user's and a line before the
    command's one error line.  Every rig reads MuJoCo's warning counters after stepping
    (``data.warning``) and raises a :class:`~testbed.core.errors.RigError` naming the reset and
    the keys to change, so the C-level text says nothing the error line does not.  MuJoCo's errors
    are not affected: the Python bindings raise them as exceptions, and they write no file.
    """
    config = mujoco.MjLogConfig.get()
    config.logto_console = False
    config.logto_file = False
    config.set()


#: What is set on a package (by its top-level name) once it is imported, by whoever imports it.
IMPORT_SETUP: dict[str, Callable[[ModuleType], None]] = {"mujoco": _quiet_mujoco}
_SET_UP: set[str] = set()


def configure_loaded() -> None:
    """Apply :data:`IMPORT_SETUP` to each of its packages already imported, once a process.

    Cheap (a lookup in ``sys.modules`` each): called after a plugin is imported, since a plugin
    may import MuJoCo itself rather than through a :class:`LazyModule`.
    """
    for name, setup in IMPORT_SETUP.items():
        module = sys.modules.get(name)
        if module is not None and name not in _SET_UP:
            setup(module)
            _SET_UP.add(name)


class LazyModule:
    """Stands for the module ``name`` and imports it on the first attribute lookup.

    After the import the module's attributes are copied onto the proxy, so later lookups are
    plain instance-attribute lookups (as fast as a module's: the MuJoCo step loops call through
    it); a name the module gains later (a submodule imported afterwards) is still found, through
    :meth:`__getattr__`.

    Parameters
    ----------
    name : str
        Dotted name of the module (``"scipy.linalg"``, ``"mujoco"``).
    """

    def __init__(self, name: str) -> None:
        object.__setattr__(self, "_lazy_name", name)

    def _lazy_load(self) -> ModuleType:
        top = self._lazy_name.partition(".")[0]
        users = {k: os.environ[k] for k in IMPORT_ENVIRONMENT.get(top, {}) if k in os.environ}
        for key, value in IMPORT_ENVIRONMENT.get(top, {}).items():
            os.environ.setdefault(key, value)
        try:
            module = importlib.import_module(self._lazy_name)
        except Exception as e:
            if not users:
                raise
            # MUJOCO_GL=bogus (RuntimeError) or osmesa without its library (AttributeError)
            # were internal errors "please report it"
            said = ", ".join(f"${k} {show_value(v)}" for k, v in users.items())
            raise InputError(f"{said}: importing {top} failed with it ({type(e).__name__}: "
                             f"{show_value(str(e))}); unset it (the testbed never renders: it sets "
                             f"{', '.join(f'{k}={v}' for k, v in IMPORT_ENVIRONMENT[top].items())}) "
                             f"or give a value {top} accepts") from None
        configure_loaded()
        self.__dict__.update(vars(module))
        return module

    def __getattr__(self, attr: str) -> Any:  # only for names not yet on the proxy
        if attr.startswith("__") and attr.endswith("__"):
            raise AttributeError(attr)  # copy, pickle and friends probe these: not a reason to import
        return getattr(self._lazy_load(), attr)

    def __repr__(self) -> str:
        return f"<lazy module {self._lazy_name!r}>"


def lazy_module(name: str) -> Any:
    """A :class:`LazyModule` for ``name`` (typed ``Any``: it is used as the module itself)."""
    return LazyModule(name)
