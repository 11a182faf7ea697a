"""The fit band's refusal, one rule shared by ls_sindy and sgd_sindy (identify._band_refusal)."""

from __future__ import annotations

import numpy as np
import pytest

from benchmarks import bench_sgd_sindy as bench
from identify._band_refusal import fit_with_band_refusal
from identify.sgd_sindy import SGDSINDy
from testbed.core.errors import IdentificationError


@pytest.fixture(scope="module")
def chain():
    """Exact 3-DOF chain, 12.8 kHz, no declared pass band (modes 90 / 235 / 343 Hz)."""
    return bench.chain_measurement(bench.chain_system(coupled=False, damping="proportional"))


def test_sgd_sindy_refuses_a_band_that_removed_its_mode_1(chain, monkeypatch):
    """ls_sindy's rule, shared: the band set from a peak above mode 1 (mode 1 not located, as
    on round 15's b15_soft_long_al_L0p8_cf0p3) removes mode 1; the fitted mode 1 (90 Hz) lies
    below the cut-off (0.7 x 234.7 Hz), so the fit is made again without a band.  The old
    code kept the band (fit_band_hz_ 164 Hz)."""
    real = SGDSINDy._start_fit

    def start(self, data, search=None):
        lam, peaks = real(self, data, search)
        return lam, None if peaks is None else peaks[1:]  # mode 1's peak not accepted

    monkeypatch.setattr(SGDSINDy, "_start_fit", start)
    model = SGDSINDy(epochs=5).fit(chain)
    assert model.fit_band_hz_ == 0.0
    assert "refused: the fitted mode 1 (90 Hz) lies below it" in model.fit_band_rule_
    assert model.fit_band_rule_.endswith("no band")
    assert model.natural_frequencies_[0] == pytest.approx(90.0, rel=1e-4)
    off = SGDSINDy(epochs=5, fit_band=False).fit(chain)  # no band asked: nothing refused
    assert off.fit_band_hz_ == 0.0 and "refused" not in off.fit_band_rule_


def test_band_refusal_rule_alone():
    """The shared rule: a refused fit in a band by rule is made again without it (the band's
    refusal raised if that is refused too); a user's band is never refused."""
    calls = []
    state = {"cut": 0.0}

    def fit(cut, fail=("band",)):
        calls.append(cut)
        state["cut"] = 50.0 if cut is None else cut
        if ("band" in fail and state["cut"] > 0) or ("all" in fail):
            raise IdentificationError(f"non-physical at {state['cut']}")

    def band():
        return state["cut"], "rule"

    rule = fit_with_band_refusal(fit, band, lambda: 10.0, True)
    assert calls == [None, 0.0] and "refused: its fit is non-physical" in rule
    with pytest.raises(IdentificationError, match="at 50"):
        fit_with_band_refusal(lambda c: fit(c, ("all",)), band, lambda: 10.0, True)
    with pytest.raises(IdentificationError, match="at 50"):
        fit_with_band_refusal(fit, band, lambda: 10.0, False)
    calls.clear()
    rule = fit_with_band_refusal(lambda c: fit(c, ()), band, lambda: 10.0, True)
    assert calls == [None, 0.0] and "mode 1 (10 Hz) lies below it" in rule
    calls.clear()
    assert fit_with_band_refusal(lambda c: fit(c, ()), band, lambda: 60.0, True) is None
    assert calls == [None]
    assert np.isfinite(state["cut"])
