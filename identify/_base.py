"""The estimator contract (scikit-learn / pysindy style) every identifier follows.

- ``__init__`` only stores hyperparameters, under the names of its arguments;
- ``fit(data) -> self`` with ``data`` a :class:`~testbed.measurement.Measurement`;
- learned results end in ``_`` (``M_``, ``C_``, ``K_``, ``K3_``, ``coef_``) and exist
  only after ``fit``;
- ``simulate(x0, xd0, t, u=None)`` integrates the identified model;
- ``equations()`` returns the identified equations as text.
"""

from __future__ import annotations

import inspect
from typing import Any, ClassVar

import numpy as np

from testbed.measurement import Measurement, Trajectory


class Identifier:
    """Base class; subclasses implement :meth:`fit`, :meth:`simulate`, :meth:`equations`."""

    name: ClassVar[str] = ""
    #: "structural" identifiers expose M_, C_, K_ (and K3_); "mechanical" ones coef_.
    kind: ClassVar[str] = ""

    @classmethod
    def _param_names(cls) -> list[str]:
        sig = inspect.signature(cls.__init__)
        return [p for p in sig.parameters if p != "self"]

    def get_params(self) -> dict[str, Any]:
        return {k: getattr(self, k) for k in self._param_names()}

    def set_params(self, **params: Any) -> Identifier:
        allowed = self._param_names()
        for k, v in params.items():
            if k not in allowed:
                raise ValueError(f"{type(self).__name__} has no hyperparameter {k!r}; "
                                 f"allowed: {', '.join(allowed)}")
            setattr(self, k, v)
        return self

    def clone(self) -> Identifier:
        """A new unfitted estimator with the same hyperparameters."""
        return type(self)(**self.get_params())

    def fit(self, data: Measurement) -> Identifier:
        raise NotImplementedError

    def simulate(self, x0: np.ndarray, xd0: np.ndarray, t: np.ndarray,
                 u: np.ndarray | None = None) -> Trajectory:
        raise NotImplementedError

    def equations(self, precision: int = 4) -> list[str]:
        raise NotImplementedError

    def is_fitted(self) -> bool:
        return any(k.endswith("_") and not k.startswith("_") for k in vars(self))

    def __repr__(self) -> str:
        args = ", ".join(f"{k}={v!r}" for k, v in self.get_params().items())
        return f"{type(self).__name__}({args})"
