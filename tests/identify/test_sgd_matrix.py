"""The cubic-term selection of SGD-SINDy's matrix parametrisation (identify/_sgd_matrix.py):
the warm start's lasso, on the partial-correlation scale, and the SGD's proximal step."""

import numpy as np
import pytest

from benchmarks import bench_sgd_sindy as bench
from identify._sgd_matrix import cubic_profile, warm_start
from identify.sgd_sindy import SGDSINDy


def _signals(k3):
    d = bench.chain_measurement(bench.chain_system(coupled=True, k3=k3))
    return d, (d.xdd, d.xd, d.x, d.x**3)


def _partial_corr(xdd, xd, x, x3):
    pr = cubic_profile(xdd, xd, x, x3)
    g = pr["Er"].T @ pr["Zr"] / xdd.shape[1]
    return g / np.outer(pr["rho"], pr["sigma"])


@pytest.mark.parametrize("k3", [0.0, 2.0e10, 2.0e12])
def test_lasso_keeps_a_row_empty_exactly_below_its_partial_correlation(k3):
    """Lasso optimality: a row's cubic block is zero iff every partial correlation of the row
    is at most the threshold.  Thresholds 1 % either side of the row's largest one."""
    _, sig = _signals(k3)
    corr = np.abs(_partial_corr(*sig))
    for row in range(3):
        top = corr[row].max()
        above = warm_start(*sig, m_hat=1.0, l1_threshold=1.01 * top)
        below = warm_start(*sig, m_hat=1.0, l1_threshold=0.99 * top)
        # K3 = M0 A3 mixes rows, so compare the uncoupled block A3 = M0^-1 K3 (the solve
        # leaves round-off, 1e-16 relative, where the lasso put exact zeros)
        a3_above = np.abs(np.linalg.solve(above[0], above[3])[row]).max()
        a3_below = np.abs(np.linalg.solve(below[0], below[3])[row]).max()
        assert a3_below > 0.0 and a3_above <= 1e-12 * a3_below


def test_partial_correlation_scale_is_free_of_units():
    """Rescaling the signals (other units, other amplitudes) changes no partial correlation."""
    _, (xdd, xd, x, x3) = _signals(2.0e12)
    c1 = _partial_corr(xdd, xd, x, x3)
    c2 = _partial_corr(7.0 * xdd, 7.0 * xd, 7.0 * x, 343.0 * x3)
    assert np.allclose(c1, c2, atol=1e-9)


def test_sgd_holds_the_lasso_zero_pattern_and_debiases():
    """From the warm start, the SGD keeps rejected terms at zero, and with debiasing the kept
    term ends closer to least squares than with the lasso throughout."""
    data, _ = _signals(2.0e12)
    deb = SGDSINDy(epochs=40, cubic=True).fit(data)
    raw = SGDSINDy(epochs=40, cubic=True, l1_debias=0.0).fit(data)
    ls = SGDSINDy(epochs=40, cubic=True, l1="none").fit(data)
    assert np.all(deb.K3_[:, 1:] == 0.0) and np.all(raw.K3_[:, 1:] == 0.0)
    assert np.all(ls.K3_[:, 1:] != 0.0)  # least squares spreads onto every column
    want = np.linalg.solve(ls.M_, ls.K3_)[:, 0]
    err = [np.linalg.norm(np.linalg.solve(m.M_, m.K3_)[:, 0] - want) for m in (deb, raw)]
    assert err[0] < err[1]
    assert deb.history_["alpha_l1"][-1] == 0.0 and raw.history_["alpha_l1"][-1] > 0.0


@pytest.mark.parametrize("bad", [{"l1_threshold": -0.1}, {"l1_debias": 1.0}, {"l1_debias": -0.5}])
def test_bad_l1_settings_are_refused(bad):
    data, _ = _signals(0.0)
    with pytest.raises(ValueError, match=next(iter(bad))):
        SGDSINDy(epochs=1, cubic=True, **bad).fit(data)
