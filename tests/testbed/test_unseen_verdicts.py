"""Rigs nobody tuned, round 3 (benchmarks/unseen/round3_*.toml): regression tests of the
findings, each fast.  Every run must end in a score table or one clear error line, within the
machine's budget, at default settings."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks import sindy_pi_problems
from identify import pysindy_pi
from identify.pysindy_pi import PYSINDY_MAX_SAMPLES, PySINDyPI, stride_rule


# ------------------------------------------- pysindy_pi at default settings finishes
def test_stride_rule_caps_the_samples_pysindy_gets():
    # fivebar_multisine at defaults: 80,000 training samples ran past 4 min with every sample
    # given to OSQP (stride 1 was the default); the rule gives it every 10th (the shipped
    # fivebar_multisine_pysindy's own stride = 10)
    assert stride_rule(80_000, None, False)[0] == 10
    assert stride_rule(PYSINDY_MAX_SAMPLES, None, False)[0] == 1
    assert stride_rule(PYSINDY_MAX_SAMPLES + 1, None, False)[0] == 2
    for n in (1, 999, 8_001, 80_000, 1_234_567):
        s, rule = stride_rule(n, None, False)
        assert len(range(0, n, s)) <= PYSINDY_MAX_SAMPLES and rule.startswith("rule")
    assert stride_rule(80_000, 3, False) == (3, "user-set: 1 in 3 of 80000 training samples")
    assert stride_rule(80_000, None, True)[0] == 1  # qr: p x p problems, every sample


def test_pysindy_pi_default_stride_is_the_rule(monkeypatch):
    p = sindy_pi_problems.double_pendulum(duration=2.0, fs=1e3, amp=10.0)
    lib = [*p.truth_terms, "cos(th2)"]
    monkeypatch.setattr(pysindy_pi, "PYSINDY_MAX_SAMPLES", 500)
    m = PySINDyPI(library=lib).fit(p.data)
    n_train = round(p.data.n_samples * (1 - m.val_fraction))
    assert abs(m.stride_ - np.ceil(n_train / 500)) <= 1 and m.stride_ >= 3
    assert m.stride_rule_.startswith(f"rule: 1 in {m.stride_} of")
    user = PySINDyPI(library=lib, stride=2).fit(p.data)
    assert user.stride_ == 2 and user.stride_rule_.startswith("user-set")
    assert np.all(np.isfinite(m.coef_)) and np.all(np.isfinite(user.coef_))
