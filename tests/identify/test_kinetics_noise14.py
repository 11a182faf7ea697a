"""Session 14 (kinetics under noise): the bias-compensated refit of ``sindy_pi_dynamical``.

Round 13's slow enzyme at 3 % (``benchmarks/unseen/round13/mm13_vmax0p8_jx0p4.toml``, seed 41)
selects the law's four terms, but plain total least squares leaves the ``Km dx`` coefficient
6.8 % low (coef_error 0.068 against the rig's 5 % bar): the weak form's noise inflates the
derivative columns' norms and not the constant's, which pulls the smallest eigenvector.  Taking
the noise's own Gram out (``refit = "compensated"``, the default, where that moves the direction
by more than half its random spread: 1.14 here) gives coef_error 0.007."""

from __future__ import annotations

import numpy as np

from identify.sindy_pi_dynamical import SINDyPIDynamical
from testbed.pipeline.generate import generate
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure
from testbed.scoring.scorers import compare_implicit


def _slow_enzyme_at_3_percent():
    sc = load_scenario("benchmarks/unseen/round13/mm13_vmax0p8_jx0p4.toml")
    sc = sc.replace(seed=41).with_noise(3.0)
    ds = generate(sc)
    params = {k: v for k, v in sc.identify.items() if k != "method"}
    return ds, measure(ds, sc.signal, "dynamical"), params


def test_the_compensated_refit_meets_the_bar_where_plain_total_least_squares_misses_it():
    # one fit (the default): plain total least squares on the same terms measured 0.068
    ds, data, params = _slow_enzyme_at_3_percent()
    truth = ds.truth["equation_terms"], np.asarray(ds.truth["equation_coef"])
    model = SINDyPIDynamical(**params).fit(data)
    assert model.refit == "compensated"   # the default
    assert model.determinacy_[0] < 0.1   # determined (measured 0.047): the refit applies
    cmp = compare_implicit(model.feature_names_, model.coef_, *truth)
    # the rig's bars (EQUATION_BARS: F1 1, 5 %): plain total least squares 0.068, here 0.007
    assert cmp["f1"] == 1.0 and cmp["coef_error"] < 0.05
    assert model.refit_rule_.startswith("compensated") and "compensated for x" in model.refit_rule_
    # the bias moves the direction by about its random spread (measured 1.14): significant
    assert model.compensation_[0] > 0.5


def test_the_noise_gram_is_zero_without_noise_and_nan_for_unusable_rows():
    from identify._determinacy import direction_spread, noise_gram
    x = np.linspace(1.0, 2.0, 50)[None, :]
    rows = lambda z: np.stack([z[0], z[0] ** 2], axis=1)   # noqa: E731
    assert np.array_equal(noise_gram(rows, x, np.array([0.0])), np.zeros((2, 2)))
    zero = lambda z: np.stack([z[0], 0.0 * z[0]], axis=1)   # noqa: E731
    assert np.isnan(noise_gram(zero, x, np.array([0.01]))).all()
    g = noise_gram(rows, x, np.array([0.01]))
    assert np.allclose(g, g.T) and np.all(np.linalg.eigvalsh(g) >= -1e-15)
    assert direction_spread(rows, x, np.array([0.0])) == 0.0
    assert np.isnan(direction_spread(zero, x, np.array([0.01])))
    # more noise, more spread (a 2-term equation's direction on 50 samples)
    assert 0.0 < direction_spread(rows, x, np.array([0.01])) < direction_spread(rows, x,
                                                                                 np.array([0.1]))


def test_the_compensation_stays_out_where_the_bias_is_a_small_part_of_the_noise():
    # the shipped noisy setup at 3 %, seed 3: taking the noise's Gram out moves the direction by
    # 0.14 of its random spread (measured), and applied anyway it cost the rig's 5 % bar
    # (0.049 -> 0.058); below COMPENSATION_SIGNIFICANCE the plain total least squares stays
    from testbed.pipeline.scenario import load_scenario as load
    sc = load("michaelis_menten_noise1")
    sc = sc.replace(seed=3).with_noise(3.0)
    ds = generate(sc)
    data = measure(ds, sc.signal, "dynamical")
    model = SINDyPIDynamical(**{k: v for k, v in sc.identify.items() if k != "method"}).fit(data)
    assert model.compensation_[0] < 0.5 and "compensated for no state" in model.refit_rule_
    cmp = compare_implicit(model.feature_names_, model.coef_, ds.truth["equation_terms"],
                           np.asarray(ds.truth["equation_coef"]))
    assert cmp["f1"] == 1.0 and cmp["coef_error"] < 0.05   # measured 0.0486 (plain fit)
