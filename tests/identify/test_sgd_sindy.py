"""SGDSINDy on exact synthetic 3-DOF chains (``benchmarks/bench_sgd_sindy.py``).

Epochs: the fits here use 400 epochs = 10,000 gradient steps (25 mini-batches of 128 per
pass over 3200 samples), 4 % of the paper's full-pass budget, so that the whole file runs in
well under a minute on one core; the benchmark shows the targets are met far earlier.
"""

from __future__ import annotations

import copy
import dataclasses

import numpy as np
import pytest

from benchmarks import bench_sgd_sindy as bench
from identify import IDENTIFIERS
from identify._record import record_agreement
from identify._structural_sim import RK4_STABILITY_BOUND, sample_rate_pole
from identify.sgd_sindy import (
    SGD_AGREEMENT_FLOOR,
    SGD_AGREEMENT_RATIO,
    UNEXPLAINED_RECORD,
    SGDSINDy,
    keep_sgd_rule,
    record_rule,
)
from identify.sgd_sindy_coefficients import SGDSINDyCoefficients
from identify.structural import modal
from testbed.core.errors import IdentificationError
from testbed.scoring.metrics import mac_matrix, pair_modes, trac

EPOCHS = 400
K3_TRUE = 2.0e12  # N/m^3 at DOF 1: cubic force ~10 % of the linear one at the peak (x1 ~ 7e-5 m)


def _rel(a, b):
    return np.linalg.norm(a - b) / np.linalg.norm(b)


@pytest.fixture(scope="module")
def linear():
    sysd = bench.chain_system(coupled=True, damping="nonproportional")
    data = bench.chain_measurement(sysd)
    return sysd, data, SGDSINDy(epochs=EPOCHS).fit(data)


@pytest.fixture(scope="module")
def cubic_fits():
    lin_sys = bench.chain_system(coupled=True)
    duff_sys = bench.chain_system(coupled=True, k3=K3_TRUE)
    lin = SGDSINDy(epochs=EPOCHS, cubic=True).fit(bench.chain_measurement(lin_sys))
    duff = SGDSINDy(epochs=EPOCHS, cubic=True).fit(bench.chain_measurement(duff_sys))
    return lin_sys, lin, duff_sys, duff


def test_registered():
    assert IDENTIFIERS.get("sgd_sindy") is SGDSINDy
    assert IDENTIFIERS.get("sgd_sindy_coefficients") is SGDSINDyCoefficients
    assert SGDSINDy.kind == SGDSINDyCoefficients.kind == "structural"


def test_linear_chain_dynamics(linear):
    sysd, data, model = linear
    f_true, phi_true = modal(sysd["M"], sysd["K"])
    # frequencies: the eigen penalty targets spectral peaks measured to ~2e-5; 1 % is the
    # brief's target, measured error ~1e-5
    assert np.max(np.abs(model.natural_frequencies_ / f_true - 1)) < 0.01
    mac = mac_matrix(phi_true, model.modes_)
    assert np.all(mac[np.arange(3), pair_modes(mac)] > 0.99)  # measured > 0.9999
    traj = model.simulate(data.x[:, 0], data.xd[:, 0], data.t)
    assert np.all(trac(data.xdd, traj.xdd) > 0.99)  # measured 0.996-0.998
    # M^-1 K is what free vibration determines: measured 4e-4 relative
    assert _rel(np.linalg.solve(model.M_, model.K_), np.linalg.solve(sysd["M"], sysd["K"])) < 5e-3


def test_mass_normalisation_and_symmetry(linear):
    _, data, model = linear
    # trace(M_) equals the mass prior by construction (class docs, Attributes): equal to rounding
    assert np.isclose(np.trace(model.M_), data.prior["reduced_mass_trace"], rtol=1e-12)
    assert np.all(model.masses_ > 0)
    for A in (model.M_, model.K_):
        assert _rel(A, A.T) < 1e-3  # symmetry penalty; measured ~2e-5


@pytest.mark.xfail(strict=True, reason="M is fixed only through the ~1 % damping forces (non-proportional "
                   "C); in 10,000 steps SGD-SINDy fits M^-1 C to ~30 % and M_ is ~60 % off (measured). "
                   "A closed-form symmetric solve on exact M^-1 K, M^-1 C recovers it to 1e-15.")
def test_recovers_coupled_mass_and_stiffness(linear):
    sysd, _, model = linear
    # the 5 % the xfail reason measures against (M_ ~60 % off): recovering M and K, not their ratio
    assert _rel(model.M_, sysd["M"]) < 0.05
    assert _rel(model.K_, sysd["K"]) < 0.05


def test_cubic_term_recovered_and_absent(cubic_fits):
    _, lin, duff_sys, duff = cubic_fits
    want = np.linalg.solve(duff_sys["M"], duff_sys["K3"])  # M^-1 K3: mass-scale free
    got = np.linalg.solve(duff.M_, duff.K3_)
    # Measured after 10,000 steps (matrix parametrisation, lasso then debiased): relative
    # error 0.026 (least squares gets 1e-5 on these exact data; the SGD stops short of it);
    # the cubic spring sits on the right coordinate (the lasso keeps column 1 only).
    # Asserted with a 2x margin on the error; the column ratio with a margin for any
    # platform where a small term survives.
    assert _rel(got, want) < 0.1
    col = np.linalg.norm(got, axis=0)
    assert col[0] >= 20.0 * np.linalg.norm(col[1:])
    # the linear structure's K3 is clearly smaller than the nonlinear one's: measured exactly 0
    assert np.linalg.norm(lin.K3_) <= 0.2 * np.linalg.norm(duff.K3_)


def test_linear_k3_hundredfold_smaller(cubic_fits):
    """The paper's Eq. 21 contrast: the linear structure's cubic matrix at least 100x smaller in
    norm than the nonlinear one's (the lasso on the partial-correlation scale keeps no cubic
    term on the linear chain: largest partial correlation 0.031 against the threshold 0.2)."""
    _, lin, _, duff = cubic_fits
    # the Eq. 21 contrast's factor 100 (docstring): measured exactly 0 on the linear chain
    assert np.linalg.norm(lin.K3_) <= 0.01 * np.linalg.norm(duff.K3_)


def test_deterministic_and_seeded(linear):
    _, data, _ = linear
    a = SGDSINDy(epochs=4, random_state=3).fit(data)
    b = SGDSINDy(epochs=4, random_state=3).fit(data)
    c = SGDSINDy(epochs=4, random_state=4).fit(data)
    assert np.array_equal(a.coef_, b.coef_)
    assert not np.array_equal(a.coef_, c.coef_)


def test_tilt_rule(linear, cubic_fits):
    """fit_tilt=None: tilted on the linear library and on the cubic one alike (ls_sindy's rule;
    soft-base member 000 clean: mode 2 27.6 % off flat, 0.23 % tilted), the Duffing chain
    keeping its cubic term; the linear chain's lasso keeps none."""
    _, _, model = linear
    _, lin, _, duff = cubic_fits
    for m in (model, lin, duff):
        assert m.fit_tilt_ and m.fit_tilt_rule_.endswith("first difference of every row (rule)")
    assert not np.any(lin.K3_)
    assert np.any(duff.K3_)


def test_cubic_library_without_cubic_term_keeps_flat_when_tilt_refused(monkeypatch):
    """The cubic library's tilted warm start refused as non-physical: fitted flat, and when the
    flat one kept no x^3 term its linear columns are tried tilted; a non-physical tilted warm
    start leaves it flat (the same model as fit_tilt=False), with the reasons."""
    import identify._sgd_matrix as sm
    from testbed.core.errors import IdentificationError

    data = bench.chain_measurement(bench.chain_system(coupled=True))
    flat = SGDSINDy(epochs=4, cubic=True, fit_tilt=False).fit(data)

    def refuse(*args, **kwargs):
        raise IdentificationError("non-physical model: test")

    monkeypatch.setattr(sm, "check_physical", refuse)
    model = SGDSINDy(epochs=4, cubic=True).fit(data)
    assert model.fit_tilt_ is False and "tilted refused: non-physical model: test" in model.fit_tilt_rule_
    assert model.fit_tilt_rule_.startswith("rule: the tilted warm start was refused")
    assert np.array_equal(model.coef_, flat.coef_)


def test_tilt_falls_back_to_flat_when_non_physical(linear, monkeypatch):
    """fit_tilt=None: a tilted warm start refused as non-physical is replaced by the flat one
    (the same model as fit_tilt=False); fit_tilt=True keeps the refusal."""
    import identify._sgd_matrix as sm
    from testbed.core.errors import IdentificationError

    def refuse(*args, **kwargs):
        raise IdentificationError("non-physical model: test")

    _, data, _ = linear
    flat = SGDSINDy(epochs=4, fit_tilt=False).fit(data)
    monkeypatch.setattr(sm, "check_physical", refuse)
    model = SGDSINDy(epochs=4).fit(data)
    assert model.fit_tilt_ is False and "fitted flat" in model.fit_tilt_rule_
    assert np.array_equal(model.coef_, flat.coef_)
    with pytest.raises(IdentificationError):
        SGDSINDy(epochs=4, fit_tilt=True).fit(data)


def test_psd_damping_warm_start():
    """An indefinite damping's growing pole is removed by its projection onto the positive
    semi-definite cone; a negative stiffness's is not (None: the flat fallback)."""
    from identify._sgd_matrix import psd_damping_warm_start
    from identify.structural import check_physical

    M, K = np.eye(2), np.diag([1.0e4, 4.0e4])  # kg, N/m: modes at 15.9 and 31.8 Hz
    C = np.array([[2.0, 0.0], [0.0, -5.0]])  # N s/m: the second mode grows
    with pytest.raises(IdentificationError):
        check_physical(M, C, K)
    Cp = psd_damping_warm_start(M, C, K)
    assert np.allclose(Cp, np.diag([2.0, 0.0]))
    check_physical(M, Cp, K)
    assert psd_damping_warm_start(M, C, np.diag([1.0e4, -4.0e4])) is None


def test_tilted_warm_start_with_indefinite_damping_stays_tilted(linear, monkeypatch):
    """fit_tilt=None: a linear tilted warm start whose growing pole is an indefinite damping
    (round 7's b_s6 at 0.5 % noise) keeps the tilt with that damping projected (before:
    refused and fitted flat)."""
    import identify._sgd_matrix as sm

    real = sm.warm_start

    def indefinite(*args, **kwargs):  # the warm start with a negative damping on its top mode
        M, C, K, K3 = real(*args, **kwargs)
        v = np.linalg.eigh(K)[1][:, -1]
        return M, C - 10.0 * np.abs(C).max() * np.outer(v, v), K, K3

    _, data, _ = linear
    monkeypatch.setattr(sm, "warm_start", indefinite)
    model = SGDSINDy(epochs=4).fit(data)
    assert model.fit_tilt_ is True
    assert "kept with its damping projected onto the positive semi-definite cone" in model.fit_tilt_rule_


def test_keep_sgd_rule():
    """The SGD's result is replaced only when it leaves more than SGD_AGREEMENT_RATIO x the warm
    start's unexplained share of the record and more than SGD_AGREEMENT_FLOOR, or its
    simulation fails where the warm start's does not; with both failing the SGD's failure is
    kept (and scored as one)."""
    r = SGD_AGREEMENT_RATIO
    assert keep_sgd_rule(1.0 - 0.0099 * r, 0.99)[0]  # within r x the warm start's share: kept
    assert not keep_sgd_rule(1.0 - 0.0101 * r, 0.99)[0]
    f = SGD_AGREEMENT_FLOOR  # at most 1 % unexplained: kept whatever the ratio
    assert keep_sgd_rule(1.0 - 0.99 * f, 1.0 - 1e-9)[0] and not keep_sgd_rule(1.0 - 1.01 * f, 1.0 - 1e-9)[0]
    assert keep_sgd_rule(0.999, 0.9)[0]  # better than the warm start
    assert not keep_sgd_rule(float("nan"), 0.9)[0]
    assert keep_sgd_rule(0.5, float("nan"))[0] and keep_sgd_rule(float("nan"), float("nan"))[0]
    keep, why = keep_sgd_rule(0.007, 0.875)  # soft-base member 006, clean (measured)
    assert not keep and why.startswith("rule:") and "0.007" in why and "0.875" in why
    # an SGD result not simulated (an unresolved pole) gives way, its note quoted
    keep, why = keep_sgd_rule(float("nan"), 0.9, ("not simulated: a pole", ""))
    assert not keep and "not simulated: a pole" in why
    # the warm start is not needed when the SGD leaves at most the floor unexplained
    keep, why = keep_sgd_rule(1.0 - 0.5 * f, None)
    assert keep and "warm start not simulated (not needed)" in why
    with pytest.raises(ValueError):
        keep_sgd_rule(1.0 - 2.0 * f, None)


def test_record_agreement_refuses_a_cubic_model_with_an_unresolved_pole(cubic_fits):
    """A cubic model whose linear part has a pole beyond RK4_STABILITY_BOUND per sample is
    not simulated (its RK4 sub-steps would grow with the pole: soft-base member 001's warm
    start, -3.2e6 rad/s, took 16 s per simulation): NaN with the reason.  The same model with
    its own damping is simulated and reproduces the exact Duffing record."""
    _, _, duff_sys, duff = cubic_fits
    data = bench.chain_measurement(duff_sys)
    assert np.any(duff.K3_ != 0.0)
    a, note = record_agreement(duff, data)
    assert a > 0.99 and note == ""  # measured 0.99994
    # a second call on the same model and record reads the first's simulations
    counted = copy.copy(duff)
    calls = []

    def simulate(*args):
        calls.append(1)
        return duff.simulate(*args)

    counted.simulate = simulate
    sims = {}
    record_agreement(counted, data, 1, sims)
    first = len(calls)  # 1 + (2 n + 1) for the iteration; the fitted start is its trial
    assert first == 1 + 2 * 3 + 1 and len(sims) == first
    assert record_agreement(counted, data, sims=sims) == (a, note)  # the same number
    assert len(calls) - first == len(sims) - first < first + 2 * (2 * 3 + 1)
    stiff = copy.copy(duff)
    stiff.C_ = duff.C_ + 1e3 * RK4_STABILITY_BOUND * data.fs * duff.M_  # poles near -2785 fs
    assert sample_rate_pole(stiff.M_, stiff.C_, stiff.K_, 1.0 / data.fs) > RK4_STABILITY_BOUND

    def never(*_args, **_kw):
        raise AssertionError("simulated")

    stiff.simulate = never
    a, note = record_agreement(stiff, data)
    assert np.isnan(a) and note.startswith("not simulated") and "RK4" in note
    linear = copy.copy(stiff)  # a linear model is simulated exactly at any pole speed
    linear.K3_ = None
    del linear.simulate  # the class's own
    a, note = record_agreement(linear, data)
    assert note == "" and np.isfinite(a)


def test_a_wandering_sgd_gives_way_to_the_held_warm_start(linear):
    """A step of 1.0 (standardised units) without the eigenvalue penalty and decay hold walks the
    linear chain's modes 15-47 % off (mode 1 75.0 Hz for 90.0, record agreement 0.033:
    measured); the rule keeps the held warm start instead, exactly the ``epochs=0`` model, while
    ``history_`` and ``n_steps_`` report the SGD that ran.  ``keep_sgd`` forces either."""
    _, data, _ = linear
    kw = {"epochs": 20, "learning_rate": 1.0, "eigen": False, "decay_hold": False}
    guarded = SGDSINDy(**kw).fit(data)
    wander = SGDSINDy(keep_sgd=True, **kw).fit(data)
    warm = SGDSINDy(keep_sgd=False, **kw).fit(data)
    held = SGDSINDy(**{**kw, "epochs": 0}).fit(data)
    assert guarded.keep_sgd_ is False and guarded.keep_sgd_rule_.startswith("rule: the SGD leaves")
    a = guarded.record_agreement_
    assert a["sgd"] < 0.1 and a["warm_start"] > 0.9999  # measured 0.033 and 0.99998
    for m in (warm, held):
        np.testing.assert_array_equal(guarded.K_, m.K_)
        np.testing.assert_array_equal(guarded.coef_, m.coef_)
    assert guarded.n_steps_ == wander.n_steps_ > 0 and warm.n_steps_ == held.n_steps_ == 0
    assert wander.keep_sgd_ and wander.keep_sgd_rule_ == "keep_sgd = True (user setting)"
    assert warm.keep_sgd_ is False and held.keep_sgd_ is False
    assert not hasattr(wander, "record_agreement_")
    f_true = modal(*(bench.chain_system(coupled=True, damping="nonproportional")[k]
                     for k in ("M", "K")))[0]
    assert np.max(np.abs(wander.natural_frequencies_ / f_true - 1)) > 0.1  # measured 0.47
    assert np.max(np.abs(guarded.natural_frequencies_ / f_true - 1)) < 0.01  # measured 2e-5


def test_the_sgd_kept_where_it_reproduces_the_record(linear):
    """The default fit on the linear chain keeps its SGD: it leaves at most SGD_AGREEMENT_FLOOR
    of the record unexplained (agreement 0.9999996, measured), which keeps it whatever the warm
    start's, so the warm start is not simulated."""
    _, _, model = linear
    assert model.keep_sgd_ and model.keep_sgd_rule_.startswith("rule: the SGD kept, it leaves")
    assert "warm start not simulated (not needed)" in model.keep_sgd_rule_
    assert list(model.record_agreement_) == ["sgd"]
    assert model.record_agreement_["sgd"] > 0.9999  # measured 0.9999996


def test_record_rule_names_a_model_that_does_not_explain_its_record(linear):
    """``record_rule`` names a kept model whose record agreement is below UNEXPLAINED_RECORD,
    with its real poles: one DOF of 1 kg, 1 N/m and 1e3 N s/m has the poles -1e-3 and
    -1e3 + 1e-3 1/s (zeta 500, as round 19's b19_st_s5_hitmid's 3.2 Hz "mode", zeta 8.2e4); a
    NaN agreement (a cubic model not simulated: families' soft 014 / 015, which pass) is not
    judged.  A sound model at 5 % rms noise (the studies'
    top level) loses about 0.0025 of its agreement, far above the bound."""
    M, C, K = np.eye(1), np.array([[1e3]]), np.eye(1)
    bad = record_rule(1.6e-6, M, C, K)
    assert "does NOT explain its record" in bad and "1.6e-06 < 0.5" in bad
    assert "2 of its 2 poles are real" in bad and "-0.001 to -1000 1/s" in bad
    assert record_rule(float("nan"), M, C, K).startswith("not judged")  # not simulated
    ringing = record_rule(0.3, M, np.array([[0.02]]), K)
    assert "does NOT explain" in ringing and "every pole of it rings" in ringing
    noisy = 1.0 / (1.0 + 0.05 ** 2)  # TRAC of the exact response against a 5 % rms noisy record
    assert noisy > UNEXPLAINED_RECORD and "explains its record" in record_rule(noisy, M, C, K)
    _, _, model = linear  # the default fit on the chain explains its record
    assert model.record_rule_.startswith("the kept model explains its record")


def test_history(linear):
    _, data, model = linear
    h = model.history_
    for key in ("alpha_sym", "alpha_eig", "alpha_l1", "loss_data", "loss_sym", "loss_eig", "n_steps"):
        assert h[key].shape == (EPOCHS + 1,)
    steps_per_epoch = int(np.ceil(data.n_samples / 128))
    assert np.array_equal(h["n_steps"], np.arange(EPOCHS + 1) * steps_per_epoch)
    assert model.n_steps_ == h["n_steps"][-1]
    # alpha_max, default 1: the annealed weights never exceed their cap (identify/sgd_sindy.py, 3.)
    assert np.all(np.isfinite(h["alpha_sym"])) and np.all(h["alpha_eig"] <= 1.0)
    assert h["loss_data"][-1] < 1e-4  # standardised MSE; measured ~2e-6


def test_options_run(linear):
    _, data, _ = linear
    for kw in ({"init": "zeros", "eigen": False, "anneal": False}, {"steps_per_epoch": 1, "l1": "none"},
               {"gradient": "full"}, {"mass_prior": "total_mass"}):
        m = SGDSINDy(epochs=3, **kw).fit(data)
        assert np.all(np.isfinite(m.coef_)), kw
    assert np.isclose(np.trace(m.M_), 1.0)  # the declared total_mass prior [kg]
    assert SGDSINDy(epochs=3, steps_per_epoch=1).fit(data).n_steps_ == 3
    for bad in ({"l1": "bad"}, {"l1": "all"}):  # the matrix form has L1 on the cubic block only
        with pytest.raises(ValueError, match="l1"):
            SGDSINDy(**bad).fit(data)


def test_coefficient_form_options_run(linear):
    """``sgd_sindy_coefficients``: the paper's literal form and its mass updates and optimisers."""
    _, data, _ = linear
    for kw in ({"mass_update": "eq6"}, {"mass_update": "symmetry"}, {"optimizer": "sgd"},
               {"init": "zeros", "eigen": False, "anneal": False}, {"steps_per_epoch": 1, "l1": "all"},
               {"symmetry": ""}, {"mass_prior": "total_mass"}):
        m = SGDSINDyCoefficients(epochs=3, **kw).fit(data)
        assert np.all(np.isfinite(m.coef_)), kw
        assert m.history_["loss_data"].shape == (4,), kw
    # Eq. 5 at its fixed point after every step: sum m = the declared total_mass prior, 1 kg
    assert np.isclose(np.trace(m.M_), 1.0, rtol=1e-12)
    assert SGDSINDyCoefficients(epochs=3, steps_per_epoch=1).fit(data).n_steps_ == 3
    with pytest.raises(ValueError, match="l1"):
        SGDSINDyCoefficients(l1="bad").fit(data)


@pytest.fixture(scope="module")
def forced():
    """The chain under a half-sine impact at the tip (samples 10-40) whose decaying tail
    (2 ms) runs into the fit window (from sample 48): exact model signals, no chain."""
    from identify._structural_sim import simulate_structural

    sysd = bench.chain_system(coupled=True, damping="nonproportional")
    fs, n_t, start = bench.FS, 3200, 48
    t = np.arange(n_t) / fs
    u = np.where((t >= 10 / fs) & (t < 40 / fs), np.sin(np.pi * (t * fs - 10) / 30), 0.0)
    u += np.where(t >= 40 / fs, 0.05 * np.exp(-(t - 40 / fs) / 2e-3), 0.0)
    u = 20.0 * u[None, :]
    tr = simulate_structural(sysd["M"], sysd["C"], sysd["K"], None, sysd["B"], np.zeros(3),
                             np.zeros(3), t, u)
    data = dataclasses.replace(bench.chain_measurement(sysd, duration=n_t / fs),
                               x=tr.x, xd=tr.xd, xdd=tr.xdd, u=u, free_start=start)
    return sysd, data


def test_input_map_from_the_record_when_the_window_gain_is_refused(forced, monkeypatch):
    """The window's gain M^-1 B refused at the driving point (a non-positive modal mass) is
    replaced by the record's (pulse included); an accepted window gain is kept."""
    import identify.sgd_sindy as ss

    sysd, data = forced
    want = np.linalg.solve(sysd["M"], sysd["B"])
    kept = SGDSINDy(epochs=4).fit(data)
    assert "window" in kept.input_map_rule_ and "driving point" in kept.mass_scaling_rule_
    real = ss.fit_matrix_sgd

    def refused_window(*args, **kwargs):
        out = real(*args, **kwargs)
        # the record's gain recovers the true one on these exact signals
        g = np.linalg.solve(out.M, out.input_map_record)
        assert _rel(g, want) < 0.02
        return dataclasses.replace(out, input_map=-out.input_map)  # negative modal masses

    monkeypatch.setattr(ss, "fit_matrix_sgd", refused_window)
    model = SGDSINDy(epochs=4).fit(data)
    assert "record" in model.input_map_rule_ and "non-positive" in model.input_map_rule_
    assert "driving point" in model.mass_scaling_rule_
    # as the record's gain above on these exact signals: measured 3.2e-4, the bound 0.02 is 60x that
    assert _rel(np.linalg.solve(model.M_, model.input_map_), want) < 0.02


def test_an_input_map_is_dropped_only_where_the_record_is_clearly_better_without_it(
        forced, monkeypatch):
    """``ls_sindy``'s step 6 on the kept model (``_choose_input_map``): on exact signals whose
    force tail runs into the fit window the map is needed (unexplained 4.5e-7 with it, 4.2e-6
    without: kept); a map that explains the record worse than none (here the fitted map
    negated, as the impact's tail through a reduced model's gain did on families' clamped
    member 009) is dropped, and the rule states both agreements."""
    import identify.sgd_sindy as ss

    _, data = forced
    kept = SGDSINDy(epochs=4).fit(data)
    assert "rule: kept" in kept.input_map_rule_ and np.any(kept.input_map_ != 0.0)
    real = ss.SGDSINDy._fit_with

    def wrong_sign(self, *args, **kwargs):
        out = real(self, *args, **kwargs)
        self.input_map_ = -3.0 * self.input_map_  # a gain that drives the wrong way
        return out

    monkeypatch.setattr(ss.SGDSINDy, "_fit_with", wrong_sign)
    model = SGDSINDy(epochs=4).fit(data)
    assert "dropped" in model.input_map_rule_ and not np.any(model.input_map_)
    assert "with the map" in model.input_map_rule_ and "without" in model.input_map_rule_
    np.testing.assert_array_equal(model.K_, kept.K_)  # only the map changed


def test_the_default_peak_search_runs_once_per_fit(linear, monkeypatch):
    """modal_peaks(data) serves the cubic rule, the eigenvalue targets and the fit band's
    cut-off (it ran four times); a search of the user's n_modes is its own."""
    import identify.sgd_sindy as ss
    import identify.structural as st

    _, data, _ = linear
    before = SGDSINDy(epochs=2).fit(data)
    calls = []
    real = st.modal_peaks

    def counted(*args, **kwargs):
        calls.append((args[1:], kwargs))
        return real(*args, **kwargs)

    monkeypatch.setattr(ss, "modal_peaks", counted)
    monkeypatch.setattr(st, "modal_peaks", counted)
    after = SGDSINDy(epochs=2).fit(data)
    assert len(calls) == 1
    assert np.array_equal(after.coef_, before.coef_)
    for attr in ("cubic_rule_", "fit_band_hz_", "fit_band_rule_", "peak_band_rule_"):
        assert getattr(after, attr) == getattr(before, attr), attr
    assert np.array_equal(after.measured_frequencies_, before.measured_frequencies_)
    calls.clear()
    SGDSINDy(epochs=2, n_modes=1).fit(data)
    assert len(calls) == 2  # the default search (cubic rule, fit band) and the n_modes one
