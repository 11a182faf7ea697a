"""``identify._base``: what the base class of every identifier does for one that leaves a part out."""

from __future__ import annotations

import copy
import os
import subprocess
import sys
import textwrap
from decimal import Decimal
from fractions import Fraction
from pathlib import Path

import numpy as np
import pytest

from identify._base import Identifier
from testbed.core.errors import (
    HyperparameterError,
    IdentificationError,
    TestbedError,
    UnsupportedError,
)
from testbed.core.measurement import Measurement


class _NoSimulate(Identifier):
    """A structural identifier (as a user's plugin) that implements fit and nothing else."""

    name = "no_simulate"
    kind = "structural"

    def fit(self, data: Measurement) -> _NoSimulate:
        n = data.n_channels
        self.M_, self.C_, self.K_ = np.eye(n), np.zeros((n, n)), np.eye(n)
        self.channels_ = tuple(data.channels)
        return self


def test_simulate_left_out_is_one_line_naming_the_class():
    # hostile round 19: `testbed run` of a plugin without simulate ended in "internal error (a
    # bug, not your input): NotImplementedError: " (the base's bare NotImplementedError)
    x = np.sin(np.arange(50) / 5.0)[None, :]
    model = _NoSimulate().fit(Measurement(100.0, x, x, x, ("x1",)))
    with pytest.raises(UnsupportedError, match=r"^_NoSimulate\.simulate: not implemented; the "
                                               r"scorer integrates") as e:
        model.simulate(np.zeros(1), np.zeros(1), np.arange(5) / 100.0)
    assert isinstance(e.value, NotImplementedError) and isinstance(e.value, TestbedError)
    assert "\n" not in str(e.value)


class _ReturnsNone(_NoSimulate):
    """A plugin whose fit sets its model and forgets ``return self``."""

    name = "returns_none"

    def fit(self, data: Measurement) -> None:
        super().fit(data)


class _ReturnsOther(_NoSimulate):
    """A plugin whose fit returns a fresh instance instead of itself."""

    name = "returns_other"

    def fit(self, data: Measurement) -> _NoSimulate:
        return _NoSimulate().fit(data)


@pytest.mark.parametrize("cls, shown", [(_ReturnsNone, "None"), (_ReturnsOther, "a _NoSimulate")])
def test_a_fit_that_does_not_return_self_is_refused_in_one_line(cls, shown):
    # hostile round 19's open item: `_ReturnsNone().fit(d)` handed the API user None (the
    # chain `Id().fit(d).equations()` then failed on None) and `testbed run` scored it as fitted
    x = np.sin(np.arange(50) / 5.0)[None, :]
    with pytest.raises(IdentificationError, match=rf"^{cls.__name__}\.fit returned {shown}, not "
                                                   r"the identifier itself; .*returns self") as e:
        cls().fit(Measurement(100.0, x, x, x, ("x1",)))
    assert "\n" not in str(e.value)


class _Tuned(_NoSimulate):
    """A plugin with a float, an int and a list hyperparameter, declared by ``__init__``."""

    name = "tuned"

    def __init__(self, ridge: float = 1e-12, degree: int = 2, lhs: list | None = None) -> None:
        self.ridge, self.degree, self.lhs = ridge, degree, lhs


@pytest.mark.parametrize("key, value", [
    ("ridge", Decimal("1e-12")), ("ridge", Fraction(1, 10**12)), ("ridge", 1e-12 + 0j),
    ("ridge", b"1e-12"), ("ridge", np.array([1e-12])), ("degree", np.array(3)),
    ("lhs", {"x"}), ("lhs", (t for t in ["x"])), ("lhs", np.array(["x"])),
])
def test_a_hyperparameter_in_a_form_no_scenario_file_holds_is_refused(key, value):
    # hostile round 20: such values were "left to the algorithm" (as a Library object is):
    # sindy_pi_dynamical's fit then raised a raw TypeError (Decimal, complex, Fraction, bytes,
    # a 1-element array), and lhs={"x"} fitted another model in silence
    with pytest.raises(HyperparameterError, match=rf"^_Tuned: key 'tuned\.{key}': value .*expected "
                                                  r"a Python \w+, as a scenario file gives it") as e:
        _Tuned(**{key: value}).check_params()
    assert "\n" not in str(e.value)


@pytest.mark.parametrize("key, value", [("ridge", np.float64(1e-10)), ("degree", np.int64(3)),
                                        ("lhs", ("x",)), ("ridge", np.float32(0.5))])
def test_numpy_numbers_and_tuples_are_still_read_as_their_plain_values(key, value):
    _Tuned(**{key: value}).check_params()


def test_a_plugins_simulate_calling_os_exit_is_an_identification_error():
    # hostile round 20: a plugin's os._exit(0) in simulate (the scorer calls it) ended
    # `testbed run` with status 0 and no verdict.  In a child: on the old code the call ends
    # the process it is made in.
    code = textwrap.dedent("""
        import os
        import numpy as np
        from identify._base import Identifier
        from testbed.core.errors import IdentificationError
        from testbed.core.measurement import Measurement

        class Exits(Identifier):
            name, kind = "exits", "structural"

            def fit(self, data):
                n = data.n_channels
                self.M_, self.C_, self.K_ = np.eye(n), np.zeros((n, n)), np.eye(n)
                self.channels_ = tuple(data.channels)
                return self

            def simulate(self, x0, xd0, t, u=None):
                os._exit(0)

            def equations(self, precision=4):
                os._exit(0)

        x = np.sin(np.arange(50) / 5.0)[None, :]
        model = Exits().fit(Measurement(100.0, x, x, x, ("x1",)))
        for call in (lambda: model.simulate(np.zeros(1), np.zeros(1), np.arange(5) / 100.0),
                     model.equations):  # (equations: the review of session 21)
            try:
                call()
            except IdentificationError as e:
                print(e)
        """)
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).resolve().parents[2])}
    p = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                       timeout=120)
    lines = p.stdout.splitlines()
    assert p.returncode == 0 and len(lines) == 2, (p.returncode, p.stdout, p.stderr[-300:])
    assert lines[0].startswith("Exits.simulate: os._exit(0) called, which would have ended")
    assert lines[1].startswith("Exits.equations: os._exit(0) called, which would have ended")


class _SetsErr(_NoSimulate):
    """A plugin whose simulate sets numpy's float errors to raise."""

    name = "sets_err"

    def simulate(self, x0, xd0, t, u=None):
        from testbed.core.measurement import Trajectory

        np.seterr(all="raise")
        return Trajectory(*(np.zeros((1, len(t))),) * 3)


def test_a_plugins_simulate_leaves_numpys_error_state_as_it_was():
    x = np.sin(np.arange(50) / 5.0)[None, :]
    model = _SetsErr().fit(Measurement(100.0, x, x, x, ("x1",)))
    before = np.geterr()
    try:
        model.simulate(np.zeros(1), np.zeros(1), np.arange(5) / 100.0)
        assert np.geterr() == before
    finally:
        np.seterr(**before)


def test_an_undeclared_plugins_hyperparameter_may_be_any_value():
    """A plugin that declares nothing types its ``__init__`` arguments ``object`` ("any value"):
    an array or a set there is the plugin's own to read (review, session 21: the refusal of
    values no scenario file holds had reached them too)."""

    class Weighted(_NoSimulate):
        name = "weighted"

        def __init__(self, weights=None, terms=None):
            self.weights, self.terms = weights, terms

    Weighted(weights=np.ones(3), terms={"x", "y"}).check_params()


def _noise_record() -> Measurement:
    x = np.random.default_rng(0).normal(size=(2, 4000))
    return Measurement(fs=1000.0, x=x, xd=x, xdd=x, channels=("a", "b"))


class _Learns(Identifier):
    kind = "structural"

    def fit(self, data):
        self.coef_ = 1.0
        return self


def test_a_fit_starts_afresh_yet_keeps_what_its_own_outer_fit_set():
    """A fit removes an earlier fit's learned attributes (SGDSINDy's refit once compared an
    earlier fit's record_agreement_ with its own), at the outermost fit only (session 22's
    review): a mixin's fit listed before the identifier's keeps what it set before
    super().fit, and a copy made during a fit carries no mark that would stop its own later
    fits from starting afresh."""
    class Mixin:
        def fit(self, data):
            self.started_ = "set before super().fit"
            return super().fit(data)

    class WithMixin(Mixin, _Learns):
        pass

    class Snapshots(_Learns):
        def fit(self, data):
            super().fit(data)
            self.snapshot_ = copy.deepcopy(self)
            return self

    data = _noise_record()
    assert WithMixin().fit(data).started_ == "set before super().fit"
    m = _Learns().fit(data)
    m.stale_ = "from an earlier fit"
    assert not hasattr(m.fit(data), "stale_")
    snap = Snapshots().fit(data).snapshot_
    snap.stale_ = "from an earlier fit"
    assert not hasattr(snap.fit(data), "stale_")
