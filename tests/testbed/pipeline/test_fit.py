"""``testbed.pipeline.fit``: a user's plugin identifier whose fit raises is a failed fit."""

from __future__ import annotations

import numpy as np
import pytest

from identify.sindy_pi_dynamical import SINDyPIDynamical
from testbed.core.errors import IdentificationError
from testbed.core.measurement import Measurement
from testbed.pipeline import plugins
from testbed.pipeline.fit import fit_or_fail


class _Raises(SINDyPIDynamical):
    """A plugin's identifier whose fit raises ``error``."""

    error: BaseException = GeneratorExit("done")

    def fit(self, data):
        raise self.error


class _Skipped(BaseException):
    """As pytest's ``Skipped``: a BaseException a helper module may raise."""


def _data() -> Measurement:
    x = np.linspace(1.0, 2.0, 50)[None, :]
    return Measurement(100.0, x, x, x, ("x",))


@pytest.mark.parametrize("error", [GeneratorExit("done"), _Skipped("no mujoco"), SystemExit(0)])
def test_a_plugin_fit_raising_a_base_exception_is_a_failed_fit(monkeypatch, error):
    # hostile round 19: GeneratorExit (any BaseException but SystemExit and Ctrl-C) from a
    # plugin's fit was a traceback of `testbed run`, status 1, no verdict
    monkeypatch.setattr(plugins.IDENTIFIERS, "origin", lambda name: "file /home/me/rogue.py")
    model = _Raises()
    model.error = error
    with pytest.raises(IdentificationError, match=f"identifier rogue \\(from file /home/me/rogue.py\\) "
                                                  f"raised {type(error).__name__}"):
        fit_or_fail(model, _data(), "rogue")


def test_ctrl_c_in_a_plugin_fit_stays_an_interrupt(monkeypatch):
    monkeypatch.setattr(plugins.IDENTIFIERS, "origin", lambda name: "file /home/me/rogue.py")
    model = _Raises()
    model.error = KeyboardInterrupt()
    with pytest.raises(KeyboardInterrupt):
        fit_or_fail(model, _data(), "rogue")
