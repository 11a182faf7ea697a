"""The scorers' start fit: :func:`testbed.numerics.initial_state.fit_initial_state`, re-exported
(one implementation, below the identifiers' floor since ``sgd_sindy`` uses it too)."""

from testbed.numerics.initial_state import fit_initial_state as fit_initial_state  # re-exported

__all__ = ["fit_initial_state"]
