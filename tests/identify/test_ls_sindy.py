"""LeastSquaresSINDy and the shared structural helpers, on exact synthetic chains.

The synthetic 3-DOF chain and its exact data come from ``benchmarks/bench_sgd_sindy.py``
(loaded by path: ``benchmarks`` is not a package).
"""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from benchmarks import bench_sgd_sindy as bench
from identify import IDENTIFIERS
from identify._cubic_rule import CUBIC_CHIRP_MIN
from identify._record import best_scale
from identify._structural_sim import simulate_structural
from identify.ls_sindy import LeastSquaresSINDy, reach_moves
from identify.structural import _decaying_only, check_physical, deflection_shapes, modal, modal_peaks
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure
from testbed.scoring.run import make_identifier, run_scenario
from testbed.studies.study import load_study
from testbed.studies.sweep import expand

UNSEEN = Path(__file__).resolve().parents[2] / "benchmarks" / "unseen"
FAMILIES = Path(__file__).resolve().parents[2] / "studies" / "families.toml"


@pytest.fixture(scope="module")
def lumped():
    sysd = bench.chain_system(coupled=False, damping="proportional")
    return sysd, bench.chain_measurement(sysd)


@pytest.fixture(scope="module")
def coupled():
    sysd = bench.chain_system(coupled=True, damping="nonproportional")
    return sysd, bench.chain_measurement(sysd)


def _rel(a, b):
    return np.linalg.norm(a - b) / np.linalg.norm(b)


def test_registered():
    assert IDENTIFIERS.get("ls_sindy") is LeastSquaresSINDy
    assert LeastSquaresSINDy.kind == "structural"


def test_recovers_minv_k_exactly_for_diagonal_mass(lumped):
    sysd, data = lumped
    model = LeastSquaresSINDy().fit(data)
    P = np.linalg.solve(sysd["M"], sysd["K"])
    Q = np.linalg.solve(sysd["M"], sysd["C"])
    # exact data (integrator rtol 1e-11): the regression is consistent, so only rounding and the
    # integrator's error remain; 1e-7 leaves 3-4 orders of margin over the measured ~1e-10
    assert _rel(np.linalg.solve(model.M_, model.K_), P) < 1e-7
    assert _rel(np.linalg.solve(model.M_, model.C_), Q) < 1e-6
    assert np.isclose(np.trace(model.M_), data.prior["reduced_mass_trace"], rtol=1e-14)
    assert np.allclose(model.M_, np.diag(np.diag(model.M_)))  # identity-scaled, by construction
    f_true, _ = modal(sysd["M"], sysd["K"])
    assert np.allclose(model.natural_frequencies_, f_true, rtol=1e-8)
    assert model.K3_ is None and model.n_steps_ == 0


def test_coupled_mass_gives_asymmetric_k(coupled):
    """The regression's M^-1 K is still exact, but with M_ diagonal K_ = M_ M^-1 K is not
    symmetric (the holds off: this is the least-squares solve's property)."""
    sysd, data = coupled
    model = LeastSquaresSINDy(eigen_hold=False, decay_hold=False).fit(data)
    # exact data: the regression is consistent, M^-1 K to rounding (measured 4e-15; 1e-7 as above)
    assert _rel(np.linalg.solve(model.M_, model.K_), np.linalg.solve(sysd["M"], sysd["K"])) < 1e-7
    # measured 0.38: with M_ diagonal and M coupled, K_ = M_ M^-1 K is far from symmetric
    assert _rel(model.K_, model.K_.T) > 0.1


def test_holds_on_exact_nonproportional_data(coupled):
    """The default holds on exact data of a non-proportionally damped chain.

    The decay hold reads each mode's decay through the model's real modes, which do not
    decouple a non-proportionally damped structure exactly: measured, M^-1 K moves by 4.8e-6
    and M^-1 C by 1.3e-4 (relative) from the exact regression, the frequencies by at most
    2.4e-6.  The bounds leave 4x margin; the shapes are not touched, K stays non-symmetric.
    """
    sysd, data = coupled
    model = LeastSquaresSINDy().fit(data)
    # measured 4.8e-6, 1.3e-4 and 2.4e-6 for the three bounds below (see the docstring): 4x margin
    assert _rel(np.linalg.solve(model.M_, model.K_), np.linalg.solve(sysd["M"], sysd["K"])) < 2e-5
    assert _rel(np.linalg.solve(model.M_, model.C_), np.linalg.solve(sysd["M"], sysd["C"])) < 5e-4
    f_true, _ = modal(sysd["M"], sysd["K"])
    assert np.allclose(model.natural_frequencies_, f_true, rtol=1e-5)
    assert model.fit_tilt_ and "rule" in model.fit_tilt_rule_
    assert "free decay" in model.decay_rule_ and "paired" in model.eigen_rule_
    # measured 0.38, as without the holds: the holds do not symmetrise K_
    assert _rel(model.K_, model.K_.T) > 0.1


def test_tilt_falls_back_to_flat_when_non_physical(coupled, monkeypatch):
    """fit_tilt=None: a tilted fit refused as non-physical is replaced by the flat one;
    fit_tilt=True keeps the refusal."""
    import identify.ls_sindy as ls
    from testbed.core.errors import IdentificationError

    real = ls.LeastSquaresSINDy._check_physical

    def refuse_tilted(self):
        if self.fit_tilt_:
            raise IdentificationError("non-physical model: test")
        real(self)

    monkeypatch.setattr(ls.LeastSquaresSINDy, "_check_physical", refuse_tilted)
    _, data = coupled
    model = LeastSquaresSINDy().fit(data)
    assert model.fit_tilt_ is False and "fitted flat" in model.fit_tilt_rule_
    with pytest.raises(IdentificationError):
        LeastSquaresSINDy(fit_tilt=True).fit(data)


def test_tilted_fit_kept_when_the_holds_make_it_physical(lumped, monkeypatch):
    """fit_tilt=None: a tilted fit with growing modes that the holds repair is kept.

    The tilted solve's damping is negated (every mode grows; the stiffness stays exact, as on
    soft-base member 004, where the tilted stiffness was right and a damping pole grew).  The
    decay hold reads each mode's decay from the exact data and replaces the fit's damping, so
    the held tilted model is physical and kept; fit_tilt=True keeps the refusal, and without
    the decay hold nothing repairs the damping and the flat fit replaces it.
    """
    import identify.ls_sindy as ls
    from testbed.core.errors import IdentificationError

    real = ls.LeastSquaresSINDy._solve

    def grow_tilted(self, data, lib, masses):
        real(self, data, lib, masses)
        if self.fit_tilt_:
            self.coef_[:, lib.blocks["v"]] += 2.0 * self.C_ / masses[:, None]
            self.C_ = -self.C_

    monkeypatch.setattr(ls.LeastSquaresSINDy, "_solve", grow_tilted)
    sysd, data = lumped
    model = LeastSquaresSINDy().fit(data)
    assert model.fit_tilt_ and "physical after the holds" in model.fit_tilt_rule_
    f_true, _ = modal(sysd["M"], sysd["K"])
    # exact data: the holds place each mode within the decay fit's error; 1e-5 as in
    # test_holds_on_exact_nonproportional_data
    assert np.allclose(model.natural_frequencies_, f_true, rtol=1e-5)
    Q = np.linalg.solve(sysd["M"], sysd["C"])
    # proportional damping: the decay hold restores M^-1 C to the decay fits' accuracy
    # (measured 1.3e-4 on the non-proportional chain; the same bound)
    assert _rel(np.linalg.solve(model.M_, model.C_), Q) < 5e-4
    with pytest.raises(IdentificationError):
        LeastSquaresSINDy(fit_tilt=True).fit(data)
    flat = LeastSquaresSINDy(decay_hold=False).fit(data)
    assert flat.fit_tilt_ is False and "fitted flat" in flat.fit_tilt_rule_
    assert not hasattr(flat, "modal_decay_")


def test_cubic_recovered_by_lstsq():
    sysd = bench.chain_system(coupled=False, damping="proportional", k3=2.0e12)
    data = bench.chain_measurement(sysd)
    model = LeastSquaresSINDy(cubic=True).fit(data)
    want = np.linalg.solve(sysd["M"], sysd["K3"])
    got = np.linalg.solve(model.M_, model.K3_)
    # exact data: only rounding and the integrator's error remain (measured 3.9e-13); 1e-5 as for
    # the other exact-data cubic recoveries (test_cubic_terms_chosen_by_rule)
    assert _rel(got, want) < 1e-5


def test_cubic_terms_chosen_by_rule(lumped):
    """Default cubic=None: a cubic force correlates with the linear model's residual and the
    x^3 columns enter; on a linear chain they stay out (exact data: correlation ~ rounding)."""
    _, linear = lumped
    model = LeastSquaresSINDy().fit(linear)
    assert model.cubic_ is False and model.K3_ is None
    assert "cubic terms out" in model.cubic_rule_
    sysd = bench.chain_system(coupled=False, damping="proportional", k3=2.0e12)
    model = LeastSquaresSINDy().fit(bench.chain_measurement(sysd))
    assert model.cubic_ is True and "cubic terms in" in model.cubic_rule_
    got = np.linalg.solve(model.M_, model.K3_)
    assert _rel(got, np.linalg.solve(sysd["M"], sysd["K3"])) < 1e-5  # as cubic=True below
    assert LeastSquaresSINDy(cubic=False).fit(bench.chain_measurement(sysd)).cubic_rule_ == "user setting"


def test_simulate_matches_independent_integration(coupled):
    """Exact ZOH discretisation vs DOP853 at rtol 1e-11: agreement to ~1e-9 of the amplitude."""
    sysd, data = coupled
    traj = simulate_structural(sysd["M"], sysd["C"], sysd["K"], None, None, data.x[:, 0], data.xd[:, 0],
                               data.t)
    for got, want in zip(traj, (data.x, data.xd, data.xdd), strict=True):
        # measured 1.6e-11, 2.2e-11, 3.4e-11 (x, xd, xdd: the integrator's rtol 1e-11); 1e-7 leaves
        # 3 orders of margin
        assert np.max(np.abs(got - want)) < 1e-7 * np.max(np.abs(want))


def test_simulate_cubic_rk4_matches_independent_integration():
    sysd = bench.chain_system(coupled=True, k3=2.0e12)
    data = bench.chain_measurement(sysd)
    traj = simulate_structural(sysd["M"], sysd["C"], sysd["K"], sysd["K3"], None, data.x[:, 0],
                               data.xd[:, 0], data.t)
    # RK4 at omega h <= 0.1: phase error ~ (omega h)^5/120 per step over ~2e4 sub-steps of the
    # highest mode -> ~1e-3 relative; measured ~2e-4
    assert np.max(np.abs(traj.xdd - data.xdd)) < 2e-3 * np.max(np.abs(data.xdd))


def test_simulate_with_input_uses_input_map(coupled):
    """A held tip force through input_map: exact ZOH path vs the RK4 path (forced by a negligible
    cubic term, 1e-30 N/m^3), which holds the input over each interval the same way."""
    _, data = coupled
    model = LeastSquaresSINDy().fit(data)
    n_t = 640
    t = data.t[:n_t]
    u = np.zeros((1, n_t))
    u[0, :3] = 100.0  # 100 N over 3 samples
    lin = model.simulate(np.zeros(3), np.zeros(3), t, u)
    tiny = np.full((3, 3), 1e-30)
    rk4 = simulate_structural(model.M_, model.C_, model.K_, tiny, model.input_map_, np.zeros(3), np.zeros(3),
                              t, u)
    # RK4 at omega h <= 0.1 over 640 samples: relative error ~1e-5 (measured), bound 1e-4
    assert np.max(np.abs(lin.x - rk4.x)) < 1e-4 * np.max(np.abs(lin.x))
    assert np.max(np.abs(lin.x[2])) > 0
    with pytest.raises(ValueError):
        model.simulate(np.zeros(3), np.zeros(3), t, u[:, :-1])


def test_equations_and_params(coupled):
    _, data = coupled
    model = LeastSquaresSINDy(cubic=True).fit(data)
    eqs = model.equations()
    assert len(eqs) == 3 and all("x1^3" in e for e in eqs)
    assert model.clone().get_params() == model.get_params()
    with pytest.raises(ValueError, match="mass_prior"):
        LeastSquaresSINDy(mass_prior="nope").fit(data)


@pytest.fixture(scope="module")
def hardening():
    sysd = bench.chain_system(coupled=False, damping="proportional", k3=2.0e12)
    return sysd, bench.chain_measurement(sysd)


def test_cubic_library_fitted_tilted_by_rule(hardening):
    """fit_tilt=None tilts the cubic library's fit as the linear one's (soft-base family:
    mode 2 of members 000, 008, 016 off 19.9 / 11.4 / 8.2 % flat, 4.9 / 3.3 / 0.95 % tilted);
    exact data: the equation is the same, so the cubic is still recovered."""
    sysd, data = hardening
    model = LeastSquaresSINDy().fit(data)
    assert model.cubic_ is True and model.fit_tilt_ and "(rule)" in model.fit_tilt_rule_
    got = np.linalg.solve(model.M_, model.K3_)
    # exact data: the tilted equation is the same equation, so as flat (measured 3.9e-13; 1e-5 as
    # in test_cubic_recovered_by_lstsq)
    assert _rel(got, np.linalg.solve(sysd["M"], sysd["K3"])) < 1e-5
    flat = LeastSquaresSINDy(fit_tilt=False).fit(data)
    assert flat.fit_tilt_ is False and flat.cubic_ is True


def test_cubic_tilt_refused_is_fitted_flat_without_the_held_try(hardening, monkeypatch):
    """fit_tilt=None, cubic library: a non-physical tilted fit goes flat at once (the
    eigenvalue hold does not act on a cubic model; held and kept, soft-base members 002 and
    003 fell to TRAC 0.88 and 0.14)."""
    import identify.ls_sindy as ls
    from testbed.core.errors import IdentificationError

    real = ls.LeastSquaresSINDy._check_physical
    held = []

    def refuse_tilted(self):
        if self.fit_tilt_:
            raise IdentificationError("non-physical model: test")
        real(self)

    monkeypatch.setattr(ls.LeastSquaresSINDy, "_check_physical", refuse_tilted)
    monkeypatch.setattr(ls.LeastSquaresSINDy, "_held_physical", lambda self, hold: held.append(1))
    _, data = hardening
    model = LeastSquaresSINDy().fit(data)
    assert model.cubic_ is True and model.fit_tilt_ is False and not held
    assert "cubic library: fitted flat" in model.fit_tilt_rule_


def test_cubic_refused_when_it_contradicts_the_measured_backbone(hardening, monkeypatch):
    """cubic=None: a fitted cubic whose own backbone shift has the opposite sign of a mode's
    measured decay chirp (soft-base member 014: the cubic softened mode 2, -0.99 Hz, which
    the decay showed hardening, +1.66 Hz; the model diverged in the scorer's simulation) is
    refused and the linear library fitted; the user's cubic=True keeps it."""
    import identify._modal_damping as md

    _, data = hardening
    kept = LeastSquaresSINDy().fit(data)  # the real cubic: its backbone agrees with the decays
    assert kept.cubic_ is True and "refused" not in kept.cubic_rule_
    monkeypatch.setattr(md, "backbone_shift", lambda M, K, K3, dec: -dec.chirp)
    model = LeastSquaresSINDy().fit(data)
    # the linear library fitted (no x^3 column); this record hardens, so step 4c moves mode 1
    # (paired with its 90.24 Hz peak, chirp +0.0078 > CUBIC_CHIRP_MIN) to its limit and gives
    # it a rank-one cubic on its own equation (record agreement 0.999139 -> 0.999208, x 0.95)
    assert model.cubic_ is False and not any("^3" in nm for nm in model.feature_names_)
    assert "moved to its limit, with a cubic on that mode alone" in model.backbone_cubic_rule_
    assert np.linalg.matrix_rank(model.K3_) == 1
    assert "cubic terms in; the fitted cubic model refused (its cubic shifts mode" in model.cubic_rule_
    assert LeastSquaresSINDy(cubic=True).fit(data).K3_ is not None


def test_cubic_refused_when_its_simulation_diverges(hardening, monkeypatch):
    """cubic=None: a cubic model whose own simulation from the measured start turns
    non-finite (a softening escape; soft-base member 019 tilted) or leaves CUBIC_BLOWUP x the
    measured peak is refused and the linear library fitted."""
    import identify.ls_sindy as ls
    from testbed.core.errors import DivergenceError

    _, data = hardening
    real = ls.LeastSquaresSINDy.simulate

    def diverge(self, x0, xd0, t, u=None):
        if self.K3_ is not None:
            raise DivergenceError("cubic structural model diverged (state not finite)", time=0.1)
        return real(self, x0, xd0, t, u)

    monkeypatch.setattr(ls.LeastSquaresSINDy, "simulate", diverge)
    model = LeastSquaresSINDy().fit(data)
    assert model.cubic_ is False and model.K3_ is None and "diverges" in model.cubic_rule_

    def blow_up(self, x0, xd0, t, u=None):
        traj = real(self, x0, xd0, t, u)
        return type(traj)(traj.x * (2.0 * ls.CUBIC_BLOWUP if self.K3_ is not None else 1.0),
                          traj.xd, traj.xdd)

    monkeypatch.setattr(ls.LeastSquaresSINDy, "simulate", blow_up)
    model = LeastSquaresSINDy().fit(data)
    assert model.cubic_ is False and "leaves" in model.cubic_rule_


def test_unlocated_mode_moves_to_its_measured_decay(lumped, monkeypatch):
    """A mode no measured peak located takes its decay fit's frequency wherever it lies.

    The solve's mode 3 is detuned 8 % (as the least-squares fit leaves a weak, heavily damped
    top mode: clamped family member 016's mode 4, 10 % high, its decay fit 0.8 % off) and the
    peak search is made to return modes 1-2 only (the top mode has no peak in the chain's
    band).  Paired with no peak, mode 3 is not bound to one spectral line of the fit's value:
    the decay hold moves it to its measured decay, exact here to the decay fit's error (1e-5,
    as in test_holds_on_exact_nonproportional_data).  The same hold without the exemption
    leaves it where the fit put it (within one line plus the peak offset, 0.2 Hz here).
    """
    import dataclasses

    import identify.ls_sindy as ls
    from identify._modal_damping import decay_hold, set_eigenvalues
    from identify._sgd_matrix import fit_window

    sysd, data = lumped
    f_true, _ = modal(sysd["M"], sysd["K"])
    real_solve, real_peaks = ls.LeastSquaresSINDy._solve, ls.modal_peaks

    def detune(self, data, lib, masses):
        real_solve(self, data, lib, masses)
        f = modal(self.M_, self.K_)[0]
        lam = np.array([np.nan, np.nan, (2 * np.pi * 1.08 * f[2]) ** 2])
        self._set_stiffness(set_eigenvalues(self.M_, self.K_, lam), masses[:, None], lib.blocks["d"])

    def two_peaks(data, *a, **k):
        ps = real_peaks(data, *a, **k)
        return dataclasses.replace(ps, peaks=ps.peaks[ps.peaks < 0.85 * f_true[2]])

    monkeypatch.setattr(ls.LeastSquaresSINDy, "_solve", detune)
    monkeypatch.setattr(ls, "modal_peaks", two_peaks)
    model = LeastSquaresSINDy().fit(data)
    assert model.eigen_targets_[2] == 0 and model.eigen_targets_[:2].all()
    assert "modes [3], which no measured peak located" in model.decay_rule_
    # the decay fit's error on exact data (docstring): 1e-5, as in test_holds_on_exact_nonproportional_data
    assert np.allclose(model.natural_frequencies_, f_true, rtol=1e-5)
    # the hold as it was (no mode exempt from the one-line bound): mode 3 stays 8 % high
    fitted = LeastSquaresSINDy(decay_hold=False).fit(data)
    held = decay_hold(data, fitted.M_, fitted.C_, fitted.K_, fit_window(data, 0.0),
                      lambda on, lam: set_eigenvalues(fitted.M_, fitted.K_, np.where(on, lam, np.nan)))
    assert modal(fitted.M_, held.K)[0][2] == pytest.approx(1.08 * f_true[2], rel=1e-3)


def test_unlocated_mode_not_moved_onto_another_mode(lumped, monkeypatch):
    """An unlocated mode's decay that lies nearer another mode's frequency than its own followed
    that mode's leakage (clamped family member 033 at 1 % noise: the unlocated mode 4 at
    452.7 Hz decayed at 412.8 Hz, mode 3's): the mode keeps its frequency; its own measured
    frequency it takes."""
    import dataclasses

    import identify._modal_damping as md
    from identify._sgd_matrix import fit_window

    sysd, data = lumped
    M, C, K = sysd["M"], sysd["C"], sysd["K"]
    w = 2 * np.pi * modal(M, K)[0]
    real = md.modal_decay

    def decay_at(lam3):
        def fake(*a, **k):
            dec = real(*a, **k)
            lam = dec.lam_model.copy()
            lam[2] = lam3
            return dataclasses.replace(dec, lam_model=lam, shift=np.abs(np.sqrt(lam) - w) / (2 * np.pi))
        return fake

    def hold():
        return md.decay_hold(data, M, C, K, fit_window(data, 0.0),
                             lambda on, lam: md.set_eigenvalues(M, K, np.where(on, lam, np.nan)),
                             unlocated=np.array([False, False, True]))

    monkeypatch.setattr(md, "modal_decay", decay_at((1.05 * w[1]) ** 2))  # nearer mode 2's
    held = hold()
    assert modal(M, held.K)[0][2] == pytest.approx(w[2] / (2 * np.pi), rel=1e-6)
    assert "which no measured peak located" not in held.rule
    # nearer its own (modes 90, 235, 343 Hz)
    monkeypatch.setattr(md, "modal_decay", decay_at((0.9 * w[2]) ** 2))
    held = hold()
    assert modal(M, held.K)[0][2] == pytest.approx(0.9 * w[2] / (2 * np.pi), rel=1e-9)
    assert "modes [3], which no measured peak located" in held.rule


def test_band_refused_non_physical_is_dropped(lumped, monkeypatch):
    """fit_band_hz=None: a fit in the band by rule refused as non-physical (tilted and flat)
    is made again without the band, where a mode below the cut-off the band removed cannot be
    checked (round 15's ``b15_soft_long_al_L0p8_cf0p3``); a band the user set keeps the
    refusal, and the band's refusal is raised when the fit without it is refused too."""
    import identify.ls_sindy as ls
    from testbed.core.errors import IdentificationError

    _, data = lumped
    band = LeastSquaresSINDy().fit(data).fit_band_hz_
    assert band > 0.0  # the band by rule acts on this record
    real = ls.LeastSquaresSINDy._check_physical

    def refuse_banded(self):
        if self.fit_band_hz_ > 0.0:
            raise IdentificationError("non-physical model: banded test")
        real(self)

    monkeypatch.setattr(ls.LeastSquaresSINDy, "_check_physical", refuse_banded)
    model = LeastSquaresSINDy().fit(data)
    assert model.fit_band_hz_ == 0.0
    assert "refused: its fit is non-physical" in model.fit_band_rule_
    assert model.fit_band_rule_.endswith("no band")
    with pytest.raises(IdentificationError, match="banded test"):
        LeastSquaresSINDy(fit_band_hz=band).fit(data)

    def refuse_all(self):
        raise IdentificationError("non-physical model: " + (
            "banded test" if self.fit_band_hz_ > 0.0 else "no-band test"))

    monkeypatch.setattr(ls.LeastSquaresSINDy, "_check_physical", refuse_all)
    with pytest.raises(IdentificationError, match="banded test"):
        LeastSquaresSINDy().fit(data)


@pytest.fixture(scope="module")
def r20_stiff_002_fit(dataset_cache):
    """Round 20's r20_stiff__002 at 1 % noise, seed 117, and its ``ls_sindy`` fit (shared by the
    two tests below: one fit, as their assertions read the same model)."""
    member = {m.name: m for m in load_study(UNSEEN / "round20_families.toml").scenarios}[
        "r20_stiff__002"]
    sc = member.with_noise(1.0).replace(seed=117)
    ds = dataset_cache.get(sc)
    return ds, LeastSquaresSINDy().fit(measure(ds, sc.signal, sc.kind))


def test_an_unlocated_mode_with_an_unpaired_peak_in_its_band_is_fitted_from_that_peak(
        r20_stiff_002_fit):
    """Round 20's r20_stiff__002 (round20_families.toml; mode 1 at 10.79 Hz, 0.19 % damped,
    two sensors) at 1 % noise, seed 117: the tilted fit put mode 1 at 29.83 Hz, beyond the
    pairing distance of the accepted 10.81 Hz peak, and its modal coordinate's decay fit
    converged at 29.14 Hz (mode 1 170 % off).  Fitted from the peak no mode took (the decay
    hold's ``free_peaks_hz``), mode 1 lies within the issue's 1 % of the engine's truth
    (measured 0.08 %)."""
    ds, model = r20_stiff_002_fit
    assert "fitted from the accepted peak no mode was paired with" in model.decay_rule_
    f_true = np.asarray(ds.truth["frequencies_hz"])[:2]
    np.testing.assert_allclose(model.natural_frequencies_, f_true, rtol=0.01)


def test_a_mode_fitted_from_an_unpaired_peak_takes_that_fits_shape(r20_stiff_002_fit):
    """The same cell: mode 1's frequency came from the peak, its shape was the tilted fit's
    (MAC 0.35 against the engine's sensor shape; the tilt weighs mode 1 1/39 of mode 2).  The
    peak's fit on every channel measures each channel's amplitude of that one decay; mode 1
    takes it (``set_shapes``; measured MAC 0.9999), above the issue's 0.95."""
    ds, model = r20_stiff_002_fit
    phi = np.real(modal(model.M_, model.K_)[1][:, 0])
    true = np.asarray(ds.truth["sensor_modes"], dtype=float)[:, 0]
    mac = (phi @ true) ** 2 / ((phi @ phi) * (true @ true))
    assert mac >= 0.95  # the bar (old code: 0.35)
    assert "modes [1] shaped by that fit" in model.decay_rule_


def test_a_cubic_models_unlocated_mode_with_no_backbone_takes_its_exponential_decay(
        dataset_cache):
    """Round 20's r20_soft__003 clean (round20_families.toml, seed 117): the cubic library (by
    rule), one accepted peak (mode 1); mode 2 (267.2 Hz, 8.4 % damped) was the cubic fit's
    239.4 Hz (-10.4 %), its backbone decay fit not first order (c = -113 Hz).  Its exponential
    decay (269.0 Hz) is taken: mode 2 within the issue's 1 % (measured 0.99 %; the truth is
    the engine's)."""
    member = {m.name: m for m in load_study(UNSEEN / "round20_families.toml").scenarios}[
        "r20_soft__003"]
    sc = member.replace(seed=117)
    ds = dataset_cache.get(sc)
    model = LeastSquaresSINDy().fit(measure(ds, sc.signal, sc.kind))
    assert model.cubic_
    f_true = np.asarray(ds.truth["frequencies_hz"])[:2]
    assert abs(model.natural_frequencies_[1] / f_true[1] - 1.0) <= 0.01  # old code: 0.104
    assert "from an exponential decay fit" in model.decay_rule_


def _study_cell(study: str, name: str, noise: float, seed: int):
    """The ``ls_sindy`` cell ``name`` at ``noise`` [%] and ``seed`` of benchmarks/unseen/``study``
    (the sweep's own expansion: its settings and thresholds)."""
    cells = [c for c in expand(load_study(UNSEEN / study)) if c.identifier == "ls_sindy"
             and c.scenario.name == name and c.noise == noise and c.scenario.seed == seed]
    assert len(cells) == 1
    return cells[0].scenario


def test_the_free_windows_input_term_is_dropped_where_the_record_is_explained_better_without(
        dataset_cache):
    """Round 20's ``r20_soft__000`` clean (round20_families.toml, seed 117; round 20's open item):
    the regression's input map over the free window (the hammer's chain-filtered tail) made the
    model's simulation from the record's start follow its record with TRAC 0.637 (its smallest
    channel; the scored TRAC against the engine's truth 0.637 too).  Without it the same model
    follows its record with 0.988 (record agreement, no truth), so step 6 drops the term:
    scored TRAC 0.637 -> 0.988, above the study's bar 0.90 (old code: 0.637, failing)."""
    sc = _study_cell("round20_families.toml", "r20_soft__000", 0.0, 117)
    res = run_scenario(sc, dataset=dataset_cache.get(sc))
    assert "input term dropped" in res.model.input_map_rule_
    assert not np.any(res.model.input_map_)
    # coef_ describes the model returned: its input columns zeroed with the map (review 22d)
    cols = [i for i, nm in enumerate(res.model.feature_names_) if nm.startswith("f")]
    assert cols and not np.any(res.model.coef_[:, cols])
    assert res.scores.values["trac"] >= 0.90  # the study's bar (measured 0.988; old code 0.637)
    assert res.passed
    # the same rig at 1 %: the model without the map explains hardly more (record agreement
    # 0.9905 against 0.9901, 1.05x less unexplained, where the rule asks 2x): kept, not decided
    # by differences the start fit and the noise move (review 22d)
    sc = _study_cell("round20_families.toml", "r20_soft__000", 1.0, 117)
    res = run_scenario(sc, dataset=dataset_cache.get(sc))
    assert "fitted input term kept" in res.model.input_map_rule_ and res.passed


def test_the_hammer_at_0p1_l_drops_its_free_windows_input_term(dataset_cache):
    """Round 20's ``b20_st_hit0p1`` (the hammer at 0.1 L, sensors 0.1 / 0.5 / 1 L) at 3 % noise,
    seed 112 (issue #15; branch beam22's diagnosis): the regression's input map over the free
    window was [-6.0, 2.05, -12.6] where the engine-consistent one is [0.60, 0.67, 1.36], and
    held scored TRAC at 0.758.  The model follows its record with 0.717 with it, 0.919 without
    (record agreement), so step 6 drops it: scored TRAC 0.973 (old code 0.758, failing)."""
    sc = (load_scenario(UNSEEN / "round20" / "b20_st_hit0p1.toml")
          .replace(identify={"method": "ls_sindy"}).with_noise(3.0).replace(seed=112))
    res = run_scenario(sc, dataset=dataset_cache.get(sc))
    assert "input term dropped" in res.model.input_map_rule_
    assert res.scores.values["trac"] >= 0.90  # the scenario's bar (measured 0.973; old 0.758)
    assert res.passed


def test_the_free_windows_input_term_is_kept_where_the_record_needs_it(dataset_cache):
    """Round 20's ``b20_st_s2_hit0p1_z3`` at 3 % noise, seed 113 (round20_beams_seeds.toml; the
    hammer at 0.1 L, two sensors, 3 % damped): the fitted input map explains more of the record
    (record agreement 0.346 against 0.320 without), so it is kept: scored TRAC 0.922, a pass.
    Dropping the term unconditionally (the probe of branch beam22) scored 0.860, a failure
    against the study's bar 0.90: the rule must come from the record, and this is the case
    that fails if it does not."""
    sc = _study_cell("round20_beams_seeds.toml", "b20_st_s2_hit0p1_z3", 3.0, 113)
    res = run_scenario(sc, dataset=dataset_cache.get(sc))
    assert "fitted input term kept" in res.model.input_map_rule_
    assert np.any(res.model.input_map_)
    assert res.scores.values["trac"] >= 0.90  # the study's bar (measured 0.922; dropped 0.860)


def _family_cell(name: str, noise: float):
    """The ``ls_sindy`` cell ``name`` at ``noise`` [%] of studies/families.toml (the sweep's own
    expansion: the family's settings)."""
    cells = [c for c in expand(load_study(FAMILIES)) if c.identifier == "ls_sindy"
             and c.scenario.name == name and c.noise == noise]
    assert len(cells) == 1
    return cells[0].scenario


def test_a_cubic_models_mode_above_what_the_hardening_record_allows_is_moved_and_refitted(
        dataset_cache):
    """Soft-base family members 002 and 010 clean (issue #15; the truth is the engine's).  The
    cubic fit put mode 2 at 216.1 / 392.6 Hz, above the highest linear frequency the hardening
    record allows: its backbone decay limit + one line (206.2 / 389.4 Hz; the peak + one line +
    the damped peak's offset 210.5 / 393.6).  Moved to that limit, 204.2 / 387.4 Hz: mode 2
    6.50 -> 0.52 % and 1.74 -> 0.10 % off (old code: 6.50 / 1.74 %).  With the cubic refitted
    around the held stiffness the model's response follows: TRAC 0.987 -> 0.990 (002), 0.934
    -> 0.943 (010); moved without the refit, 0.958 and 0.857, the model's diagonal cubic still
    pulling mode 2 where the fit had put it."""
    # 010's bar is issue #15's 0.95 since step 4d (beam35: 0.963; without it 0.943)
    for name, trac_min in (("beams_soft__002", 0.98), ("beams_soft__010", 0.95)):
        sc = _family_cell(name, 0.0)
        res = run_scenario(sc, dataset=dataset_cache.get(sc))
        v = res.scores.values
        assert res.model.cubic_ and "the cubic refitted" in res.model.eigen_rule_
        assert v["freq_error_mode2"] <= 0.01  # measured 0.52 / 0.10 % (old 6.50 / 1.74 %)
        assert v["freq_error_mode1"] <= 0.01  # unchanged, 0.58 / 0.02 %
        # measured 0.990 / 0.943 (old code 0.987 / 0.934; moved without the refit 0.958 / 0.857);
        # with step 4d's cubic on mode 1 alone (beam35) 0.992 / 0.963
        assert v["trac"] >= trac_min


def test_a_hardening_record_whose_cubic_the_rule_left_out_gets_it_where_it_explains_clearly_more(
        dataset_cache):
    """Soft-base family member 013 at 1 % noise (issue #15; the truth is the engine's): the
    noise drowns the cubic rule's partial correlations (0.41 flat, 0.626 tilted, under 0.65)
    and the linear model held mode 1 at its amplitude-hardened frequency, 2.41 % high.  Mode
    1's backbone decay chirps +3.7 % (above CUBIC_CHIRP_MIN), so step 4b fits the cubic
    library too; its record agreement 0.9938 against the linear 0.9869 leaves 2.1 x less of
    the record unexplained, so it is kept: mode 1 0.29 %, TRAC 0.994 (old code: linear,
    2.41 %, 0.987)."""
    sc = _family_cell("beams_soft__013", 1.0)
    res = run_scenario(sc, dataset=dataset_cache.get(sc))
    v, m = res.scores.values, res.model
    assert m.cubic_ and "trial (step 4b)" in m.cubic_rule_ and ": kept" in m.cubic_rule_
    assert v["freq_error_mode1"] <= 0.01  # issue #15's bar: measured 0.29 % (old 2.41 %)
    assert v["freq_error_mode2"] <= 0.01  # measured 0.78 % (old 0.83 %)
    assert v["trac"] >= 0.95  # issue #15's bar: measured 0.994 (old 0.987)


def test_a_cubic_models_unlocated_mode_whose_backbone_fit_failed_takes_its_exponential_decay(
        dataset_cache):
    """Soft-base family member 000 at 1 % noise (issue #15; the truth is the engine's: mode 2
    319.7 Hz, 31.8 % damped).  No accepted peak locates mode 2 and its backbone decay fit
    fails (c / wd 0.46, not converged to a taken fit), so the noisy cubic fit's 279.4 Hz stood,
    12.62 % low (errors in variables on a mode with nothing measured behind it).  Refitted as
    an exponential decay, as a converged backbone fit beyond the first order already was:
    322.1 Hz, 0.74 % off (old code 12.62 %); mode 1 and TRAC unchanged (0.25 %, 0.995)."""
    sc = _family_cell("beams_soft__000", 1.0)
    res = run_scenario(sc, dataset=dataset_cache.get(sc))
    v, m = res.scores.values, res.model
    assert m.cubic_ and "or its backbone fit failed), from an exponential" in m.decay_rule_
    assert v["freq_error_mode2"] <= 0.01  # issue #15's bar: measured 0.74 % (old 12.62 %)
    assert v["freq_error_mode1"] <= 0.01  # unchanged 0.25 %
    assert v["trac"] >= 0.95  # unchanged 0.995


def test_a_linear_model_of_a_hardening_record_takes_mode_1s_backbone_limit_and_a_cubic_sized_by_output_error(
        dataset_cache):
    """Soft-base family member 004 clean (issue #15; the truth is the engine's, mode 1 28.06
    Hz).  The cubic library's fit is non-physical (step 4b refuses it) and the linear model
    held mode 1 at its amplitude-averaged 28.49 Hz, 1.54 % high.  Step 4c moves it to its
    backbone decay's linear limit (28.00 Hz) with a cubic on mode 1's equation alone, whose
    strength the record's own simulation sizes (0.85 x the harmonic balance): mode 1 0.21 %,
    record agreement 0.9979 against the linear model's 0.9975 (old code: 1.54 %, TRAC
    0.9975; the same move without the cubic, 0.978)."""
    sc = _family_cell("beams_soft__004", 0.0)
    res = run_scenario(sc, dataset=dataset_cache.get(sc))
    v, m = res.scores.values, res.model
    assert "moved to its limit, with a cubic on that mode alone" in m.backbone_cubic_rule_
    assert m.K3_ is not None and np.linalg.matrix_rank(m.K3_) == 1
    assert v["freq_error_mode1"] <= 0.01  # issue #15's bar: measured 0.21 % (old 1.54 %)
    assert v["freq_error_mode2"] <= 0.01  # unchanged 0.84 % (the step moves mode 1 alone)
    assert v["trac"] >= 0.95  # issue #15's bar: measured 0.998 (old 0.9975)


def test_the_output_error_scale_is_the_best_seen_ties_to_the_smaller_and_nan_never_wins():
    """``best_scale``: a smooth optimum off the grid is refined to the tolerance; a flat
    agreement gives the smallest scale (no term); NaN (a failed simulation) never wins, and
    every NaN gives NaN."""
    s, a = best_scale(lambda s: 0.99 - (s - 0.85) ** 2)
    assert abs(s - 0.85) <= 0.01 and a <= 0.99 and a > 0.99 - 1e-4
    assert best_scale(lambda s: 0.9) == (0.0, 0.9)
    s, a = best_scale(lambda s: float("nan") if s > 0.5 else 0.5 + s)
    assert s <= 0.5 and np.isfinite(a)
    s, a = best_scale(lambda s: float("nan"))
    assert np.isnan(a)


# reach_moves (the cubic library's move selection): synthetic arrays, mode 1's damped
# frequency 22.2 Hz; the chirp just above / below CUBIC_CHIRP_MIN x wd
_WD1 = 2 * np.pi * 22.2
_HARDENS = 1.01 * CUBIC_CHIRP_MIN * _WD1


def test_reach_moves_acts_only_where_the_record_is_seen_hardening():
    """A mode above its reach moves only where mode 1's backbone chirp exceeds CUBIC_CHIRP_MIN
    of its frequency; below it, or with mode 1's fit not taken (NaN), nothing moves and the
    reason names mode 1's c / wd against the bound."""
    f, reach, limit = np.array([22.0, 216.0]), np.array([23.0, 206.2]), np.array([np.nan, 204.2])
    move, to, why = reach_moves(f, reach, limit, _HARDENS, _WD1)
    assert move.tolist() == [False, True] and to[1] == 204.2 and why == ""
    move, _, why = reach_moves(f, reach, limit, 0.99 * CUBIC_CHIRP_MIN * _WD1, _WD1)
    assert not move.any() and "not seen hardening" in why and "c / wd 0.00693 <= 0.007" in why
    move, _, why = reach_moves(f, reach, limit, np.nan, _WD1)
    assert not move.any() and "mode 1's backbone decay fit not taken" in why


def test_reach_moves_leaves_a_mode_within_its_reach():
    """Only a mode above its reach moves: both targets here lie nearest their own modes, so
    without that condition both would move (mode 2 up from 200 to 204.2 Hz)."""
    f, reach, limit = np.array([22.0, 200.0]), np.array([23.0, 206.2]), np.array([22.2, 204.2])
    move, _, why = reach_moves(f, reach, limit, _HARDENS, _WD1)
    assert not move.any()
    assert "every mode within its reach (22 <= 23 Hz, 200 <= 206.2 Hz)" in why


def test_reach_moves_goes_to_the_limit_where_it_bounds_else_to_the_reach():
    """The target is the read backbone limit where it lies at or below the reach (it set the
    reach: limit + one line), else the reach (the peak's bound was lower), never above it."""
    f = np.array([22.0, 216.0, 900.0])
    reach, limit = np.array([23.0, 206.2, 880.0]), np.array([np.nan, 204.2, 885.0])
    move, to, _ = reach_moves(f, reach, limit, _HARDENS, _WD1)
    assert move.tolist() == [False, True, True]
    assert to[1] == 204.2 and to[2] == 880.0


def test_reach_moves_refuses_a_target_nearer_another_mode():
    """A mode whose target lies nearer another mode's frequency than its own is left (that
    limit followed the other mode: round 21's spurious 466 Hz mode 3 moved to mode 2's 424 Hz
    limit), and the reason says which; a mode beside it still moves."""
    f = np.array([22.0, 440.0, 466.0])
    reach, limit = np.array([23.0, 430.0, 445.0]), np.array([np.nan, np.nan, 424.0])
    move, to, why = reach_moves(f, reach, limit, _HARDENS, _WD1)
    assert move.tolist() == [False, True, False] and to[1] == 430.0
    assert "mode 3 above its reach (466 > 445 Hz) left: its target 424 Hz lies nearer mode 2's" in why


def _moved_soft_002(dataset_cache, monkeypatch, spoil, cubic):
    """Soft-base member 002 clean (the reach rule moves its mode 2, 216.3 -> 204.2 Hz) fitted
    with ``cubic`` and the refit after the move followed by ``spoil(model)``."""
    refit = LeastSquaresSINDy._refit_cubic

    def spoiled(self, data, rows, masses):
        refit(self, data, rows, masses)
        spoil(self)

    monkeypatch.setattr(LeastSquaresSINDy, "_refit_cubic", spoiled)
    sc = _family_cell("beams_soft__002", 0.0)
    model = make_identifier(sc)
    model.cubic = cubic
    return run_scenario(sc, dataset=dataset_cache.get(sc), model=model)


def test_a_move_whose_refitted_model_grows_is_undone(dataset_cache, monkeypatch):
    """A forced case (the refit's damping negated: a move that makes the model grow, as 13 of
    20,000 random 2-DOF models with coupled damping do; the review's grow.py).  The moved model
    is checked: it grows, so the fit is restored as it stood before the move (mode 2 at 216.3
    Hz, 6.5 % off the truth) and kept with its cubic; the rule says "not moved" and why.  Old
    code: the growing model went on, the rule's cubic was then refused whole (its simulation
    leaves the record).  Unspoilt, the move sets eigen_targets_ (mode 2's paired peak) and
    eigen_shift_ (216.3 -> 204.2 Hz: 5.6 %), which the old code left at 0."""
    res = _moved_soft_002(dataset_cache, monkeypatch, lambda m: None, None)
    m = res.model
    assert "the cubic refitted" in m.eigen_rule_ and "the fit's frequencies" not in m.eigen_rule_
    assert m.eigen_targets_[0] == 0 and 204.0 < m.eigen_targets_[1] < 206.2  # peak 205.2 Hz
    assert m.eigen_shift_ == pytest.approx(1 - 204.2 / 216.3, abs=1e-3)

    def grow(model):
        model.C_ = -model.C_

    res = _moved_soft_002(dataset_cache, monkeypatch, grow, None)
    m = res.model
    assert m.cubic_ and "not moved" in m.eigen_rule_ and "grows" in m.eigen_rule_
    check_physical(m.M_, m.C_, m.K_)  # restored: physical
    assert m.eigen_shift_ == 0.0 and not np.any(m.eigen_targets_)
    assert res.scores.values["freq_error_mode2"] > 0.05  # the unmoved 6.50 %


def test_a_move_whose_refitted_cubic_softens_or_leaves_the_record_is_undone(dataset_cache,
                                                                         monkeypatch):
    """With the user's ``cubic = True`` the refitted cubic is checked too (the old code checked
    only a cubic the rule chose, and never after the move).  Forced case: the refit's cubic
    negated and scaled 1000 x, a softening cubic that the record's hardening decays contradict
    and whose simulation escapes; the move is undone (mode 2 back at 216.3 Hz, 6.5 % off) and
    the rule says why."""
    def soften(model):
        model.K3_ = -1e3 * model.K3_

    res = _moved_soft_002(dataset_cache, monkeypatch, soften, True)
    m = res.model
    assert m.cubic_ and "not moved" in m.eigen_rule_ and "refused" in m.eigen_rule_
    assert res.scores.values["freq_error_mode2"] > 0.05  # the unmoved 6.50 %


def _round22_cell(study: str, name: str, noise: float, seed: int):
    """The ``ls_sindy`` cell of a round 22 beam study (the sweep's own expansion)."""
    cells = [c for c in expand(load_study(UNSEEN / study)) if c.identifier == "ls_sindy"
             and c.scenario.name == name and c.noise == noise and c.scenario.seed == seed]
    assert len(cells) == 1
    return cells[0].scenario


def test_a_bump_of_noise_on_a_stronger_modes_leakage_is_not_taken_as_a_mode(dataset_cache):
    """Round 22's magnesium at 1.8 kHz, two sensors, 5 % noise, seed 139 (the truth is the
    engine's: mode 2 508.7 Hz, 6.25 % damped).  The peak search took a 171.1 Hz bump of noise
    on mode 1's rectangular-window leakage (-36 dB, 6 dB prominent) as the second mode, and
    the eigenvalue hold paired the fit's 199.5 Hz with it: mode 2 at 172.1 Hz, 66 % off (old
    code).  It neither rings at its own frequency (lock 0.141, noise's bar 0.289) nor decays
    over the window (band power, first half / second, 1.14, noise's bar 1.57): rejected, as are
    the bumps after it, and the 489.6 Hz peak that does decay (1.48 > 1.34) is mode 2's: 505.0
    Hz."""
    sc = _round22_cell("round22_beams_more.toml", "b22_mg_fs1k8_s2", 5.0, 139)
    res = run_scenario(sc, dataset=dataset_cache.get(sc))
    v = res.scores.values
    assert v["freq_error_mode2"] <= 0.026  # measured 0.73 % (old code 66.2 %); the study's bar
    assert v["freq_error_mode1"] <= 0.001  # measured 0.013 %: mode 1 untouched
    assert v["trac"] >= 0.99  # measured 0.9996 (old 0.9956)
    why = [r for f, r in modal_peaks(res.data, ringing=True).rejected if abs(f - 171.1) < 1.0]
    assert why and "neither rings at its own frequency" in why[0]
    assert abs(modal_peaks(res.data).peaks[1] - 171.1) < 1.0  # the other identifiers' search


def test_the_noise_rule_keeps_a_fast_decaying_mode_and_a_lightly_damped_one(dataset_cache):
    """Family members, clean.  Soft 014: mode 2 (208.7 Hz, -1.1 dB) decays within a few of
    its periods, so its lock over the window (:func:`testbed.numerics.spectral.own_lock`, whose
    ends are dropped) is 0.148, and a lock rule alone rejected it (mode 1 0.53 -> 1.43 %); its
    band's power falls 98 x from the window's first half to its second: kept.  Clamped 005:
    mode 1 (52.2 Hz, 1 % damped) barely decays over the 0.49 s record (2.35, under noise's
    2.54), and a decay rule alone rejected it (mode 1 546 % off); it rings (lock 0.99): kept."""
    for name, f in (("beams_soft__014", 208.7), ("beams_stiff__005", 52.2)):
        sc = _family_cell(name, 0.0)
        data = run_scenario(sc, dataset=dataset_cache.get(sc)).data
        ps = modal_peaks(data, ringing=True)
        assert np.any(np.abs(ps.peaks - f) < 1.0), name


def test_a_candidate_the_noise_rule_cannot_test_is_kept():
    """Review 23f: rule 4b rejected a clean 1 %-damped 30 Hz mode (half mode 1's amplitude)
    on a 0.2 s record, its lock not finite (the window too short for the frequency): a test
    that cannot decide keeps the candidate."""
    fs, n = 1800.0, 360
    t = np.arange(n) / fs
    sh1, sh2 = np.array([1.0, 0.6]), np.array([1.0, -0.8])
    x = (np.sin(2 * np.pi * 80 * t) * np.exp(-2 * np.pi * 0.01 * 80 * t))[None] * sh1[:, None] \
        + 0.5 * (np.sin(2 * np.pi * 30 * t) * np.exp(-2 * np.pi * 0.01 * 30 * t))[None] * sh2[:, None]
    rejected: list = []
    kept = _decaying_only(SimpleNamespace(xdd=x, fs=fs), 0, np.array([80.0, 30.0]),
                          np.array([sh1, sh2]).astype(complex), [0, 1], rejected, 20.0)
    assert kept == [0, 1] and rejected == []


HELDOUT = Path(__file__).resolve().parents[2] / "benchmarks" / "heldout" / "families_heldout.toml"


@pytest.mark.parametrize("name", ["beams_stiff__011", "beams_stiff__017"])
def test_a_free_peaks_fit_that_failed_beside_an_unfitted_stronger_decay_is_tried_again(
        dataset_cache, name):
    """Held-out clamped 011 and 017 at 1 % noise (families_heldout.toml, seed 0): the tilted
    fit put modes 1-2 beyond the pairing distance of both accepted peaks (011: 93.9 / 217.4 Hz
    against peaks 44.78 / 283.7 Hz), so both were fitted from their free peaks, mode 1 first;
    mode 2 (11 % damped, the strongest peak) was not yet profiled out, mode 1's fit ran to its
    band's top and was not taken, and mode 1 kept the fit's 93.9 Hz (110 % off; 017: 106 %).
    Tried again with mode 2's taken decay profiled out it converges at 44.74 Hz, 1.8 % damped
    (measured 0.11 % / 0.003 % off), within the issue's 1 % of the engine's truth."""
    member = {m.name: m for m in load_study(HELDOUT).scenarios}[name]
    sc = member.with_noise(1.0).replace(seed=0)
    ds = dataset_cache.get(sc)
    model = LeastSquaresSINDy().fit(measure(ds, sc.signal, sc.kind))
    assert "modes [1, 2] fitted from the accepted peak" in model.decay_rule_
    f_true = np.asarray(ds.truth["frequencies_hz"])[:2]
    np.testing.assert_allclose(model.natural_frequencies_, f_true, rtol=0.01)  # the bar


def _round22(study: str, name: str, noise: float, seed: int, dataset_cache):
    member = {m.name: m for m in load_study(UNSEEN / study).scenarios}[name]
    sc = member.with_noise(noise).replace(seed=seed)
    ds = dataset_cache.get(sc)
    return ds, measure(ds, sc.signal, sc.kind)


def test_noise_in_the_chains_ringing_zone_does_not_take_a_modes_place(dataset_cache):
    """Round 22's ``b22_st_jo0`` at 5 % noise, seed 133 (three sensors; modes 82.5, 511.3,
    1417 Hz): a 12.42 Hz candidate below 2 x the 10 Hz high-pass, -31 dB, locked 0.28 at
    most 0.46 within 15 % of it (noise's own bar there, 1.46, above 2 / pi) and losing no band
    power (0.71 under noise's 3.4), was kept as one of three peaks and pushed mode 3 out (the
    fit's 1417 Hz mode paired with nothing: 98.7 % off).  Now rejected as noise; mode 3's peak
    is kept and every scored mode lies within the issue's 1 % (measured 0.76 %)."""
    ds, data = _round22("round22_beams_noise_s133.toml", "b22_st_jo0", 5.0, 133, dataset_cache)
    ps = modal_peaks(data, ringing=True)
    assert ps.peaks.min() > 2.0 * data.passband[0]
    assert any(abs(f - 12.42) < 0.1 and "noise, not a mode" in why for f, why in ps.rejected)
    model = LeastSquaresSINDy().fit(data)
    f_true = np.asarray(ds.truth["frequencies_hz"])[:3]
    np.testing.assert_allclose(model.natural_frequencies_, f_true, rtol=0.01)


def test_a_mode_the_high_pass_bends_keeps_its_place_in_the_ringing_zone(dataset_cache):
    """Round 22's ``b22_cu_L0p65_t8_n15`` at 2 % noise, seed 136: mode 1 at 11.05 Hz (1.1 x
    the high-pass) peaks at 12.58 Hz, where it locks 0.24 only (its phase drifts 1.5 Hz
    against that frequency); at 10.94 Hz, within 15 %, it locks 1.000.  The ringing zone's
    noise test takes the largest lock there and keeps it (a lock at the peak alone rejected it:
    mode 1 0.95 -> 567 % off)."""
    ds, data = _round22("round22_beams_extra.toml", "b22_cu_L0p65_t8_n15", 2.0, 136,
                        dataset_cache)
    ps = modal_peaks(data, ringing=True)
    assert np.any(np.abs(ps.peaks - 12.58) < 0.1)
    model = LeastSquaresSINDy().fit(data)
    f_true = np.asarray(ds.truth["frequencies_hz"])[0]
    assert model.natural_frequencies_[0] == pytest.approx(f_true, rel=0.026)  # the study's bar


def test_a_weak_mode_in_the_ringing_zone_locked_above_noise_is_kept_on_a_long_record():
    """Review 24c: in the chain's ringing zone (at most 2 x the 10 Hz high-pass) the lock's bar
    was 2 / pi even where noise's own bar is lower (a long window: 0.500 over 4 s at 15 Hz), so
    a weak, lightly damped 15 Hz mode locked at 0.58 (above noise's bar, under 2 / pi) whose
    power barely falls was rejected as noise; above the zone the same candidate is kept.  Now
    the zone's bar is capped by noise's, as above it.  Synthetic record (4 s at 2 kHz, a strong
    80 Hz mode, the 15 Hz one at 1 % of its amplitude, white noise 10 % of the strong mode)."""
    fs, t = 2000.0, np.arange(8000) / 2000.0
    rng = np.random.default_rng(2)
    s1 = 5.0 * np.exp(-0.002 * 2 * np.pi * 80.0 * t) * np.sin(2 * np.pi * 80.0 * t)
    s2 = 0.05 * np.exp(-0.002 * 2 * np.pi * 15.0 * t) * np.sin(2 * np.pi * 15.0 * t + 0.3)
    x = np.vstack([s1 + s2, 0.6 * s1 - 0.8 * s2]) + 0.5 * rng.standard_normal((2, t.size))
    freqs = np.array([80.0, 15.0])
    shapes = deflection_shapes(x, fs, freqs, pad=8)
    data = SimpleNamespace(xdd=x, fs=fs)
    rejected: list = []
    assert _decaying_only(data, 0, freqs, shapes, [0, 1], rejected, 20.0) == [0, 1], rejected


def test_an_unlocated_modes_decay_is_searched_where_the_peak_search_could_not_see(
        dataset_cache):
    """Round 23's beryllium at 3.2 kHz with a 1.5 kHz low-pass (``b23_be_fs3k2_s2_lp1k5``) at
    2 % noise, seed 144: mode 2 (1246 Hz, 6.25 % damped) lies above the peak band's 0.8 x the
    low-pass (1200 Hz), so no peak locates it; the fit's mode 2 is an unstable 360 Hz pole and
    its modal coordinate's decay fit, started there, stopped in a local minimum at 346 Hz (r2
    0.060; 72 % off) and was taken.  From starts across the part of its band above the peak
    band (1200-1500 Hz) the least residual lies at 1244 Hz (r2 0.074); the every-channel fit
    then gives 1242.7 Hz (measured 0.21 % off), within the study's 2.6 %."""
    member = {m.name: m for m in load_study(UNSEEN / "round23_beams_extra.toml").scenarios}[
        "b23_be_fs3k2_s2_lp1k5"]
    sc = member.with_noise(2.0).replace(seed=144)
    ds = dataset_cache.get(sc)
    model = LeastSquaresSINDy().fit(measure(ds, sc.signal, sc.kind))
    f_true = np.asarray(ds.truth["frequencies_hz"])[:2]
    np.testing.assert_allclose(model.natural_frequencies_, f_true, rtol=0.026)  # the study's bar


def test_a_middle_mode_no_peak_located_is_not_spread_over_its_band(dataset_cache):
    """``b21_soft_root3`` at 4 % noise, seed 123 (round21_beams_noise_s123): on a tilted fit
    whose three modes all lie low (14.9 / 27.4 / 48.3 Hz) the unstable, unlocated mode 2 had,
    under starts spread across its whole band (beam27's form), taken an undamped 28.8 Hz
    minimum, and mode 1 was scored 27.1 % off (TRAC 0.944).  Its band lies wholly inside the
    peak band, which the peak search saw: no spread; mode 1 1.70 % off (measured), the study's
    bar 2.6 %."""
    member = {m.name: m for m in
              load_study(UNSEEN / "round21_beams_noise_s123.toml").scenarios}["b21_soft_root3"]
    sc = member.with_noise(4.0).replace(seed=123)
    ds = dataset_cache.get(sc)
    model = LeastSquaresSINDy().fit(measure(ds, sc.signal, sc.kind))
    f_true = np.asarray(ds.truth["frequencies_hz"])[0]
    assert model.natural_frequencies_[0] == pytest.approx(f_true, rel=0.026)  # the study's bar


def test_reach_moves_raises_a_mode_below_its_floor_to_its_backbone_limit():
    """With a floor (``hardened_floor``) a mode standing below it moves up to its read backbone
    limit (b23_soft_s2neartip at 2 %: 345.1 < 371.7 Hz, to 389.5 Hz); a mode between its floor
    and its reach stays, and a NaN floor bounds nothing."""
    f = np.array([39.6, 345.1])
    reach, limit = np.array([40.6, 390.5]), np.array([39.6, 389.5])
    move, to, why = reach_moves(f, reach, limit, _HARDENS, _WD1, np.array([np.nan, 371.7]))
    assert move.tolist() == [False, True] and to[1] == 389.5 and why == ""
    move, _, why = reach_moves(f, reach, limit, _HARDENS, _WD1, np.array([np.nan, 340.0]))
    assert not move.any() and "and above its floor" in why
    move, _, _ = reach_moves(f, reach, limit, 0.99 * CUBIC_CHIRP_MIN * _WD1, _WD1,
                             np.array([np.nan, 371.7]))
    assert not move.any()  # the record not seen hardening: no bound either way


def test_reach_moves_raises_a_mode_below_its_floor_to_the_floors_own_limit():
    """``floor_limit_hz``: a mode below a floor read from a fit not taken (``beyond_limit``,
    where ``limit_hz`` is NaN) moves up to that limit (b24_soft_r2_cf0p3_z1p5_s2 at 3 % s155:
    379.9 < 382.8 Hz, to 402.6 Hz in the fit's domain); without it the target stays NaN-free
    only where a taken limit exists, as before."""
    f = np.array([47.54, 379.9])
    reach, limit = np.array([48.55, 416.75]), np.array([47.55, np.nan])
    low = np.array([47.55, 402.57])
    move, to, why = reach_moves(f, reach, limit, _HARDENS, _WD1, np.array([np.nan, 382.8]), low)
    assert move.tolist() == [False, True] and to[1] == 402.57 and why == ""
    move, _, why = reach_moves(f, reach, limit, _HARDENS, _WD1, np.array([np.nan, 370.0]), low)
    assert not move.any() and "and above its floor" in why
    # review 26c: a floor's target above the mode's reach moves it to the reach (the upper
    # bound holds), said (the old code moved it to 402.57 Hz, above its own 395 Hz bound)
    capped = np.array([48.55, 395.0])
    move, to, why = reach_moves(f, capped, limit, _HARDENS, _WD1, np.array([np.nan, 382.8]), low)
    assert move.tolist() == [False, True] and to[1] == 395.0 and "moved to the reach" in why


def test_a_located_modes_limit_beyond_the_first_order_still_bounds_it_from_below(dataset_cache):
    """``b24_soft_r2_cf0p3_z1p5_s2`` (round 24: 2 EI/L base, cubic 0.3, two sensors) at 3 %
    noise, seed 155: the cubic fit put mode 2 at 379.9 Hz (true 398.3, 4.62 % off) and nothing
    moved it: its backbone decay fit (397.9 Hz damped, 13 % damped, r2 0.997, the squared
    amplitude gone by the window's end) was not taken for its shift ``c / wd`` 0.14 >
    BACKBONE_MAX_SHIFT, so no limit and no floor.  That fit's limit still bounds the mode from
    below (``beyond_limit``): floor 382.8 Hz (mode 1's stiffening c / wd 0.047 off it), mode 2
    raised to the limit, measured 0.75 % off (TRAC 0.9991 -> 0.9996).  The bar is the issue's
    1 % (the old code: 4.62 %)."""
    member = {m.name: m for m in load_study(UNSEEN / "round24_beams_more.toml").scenarios}[
        "b24_soft_r2_cf0p3_z1p5_s2"]
    sc = member.with_noise(3.0).replace(seed=155)
    ds = dataset_cache.get(sc)
    model = LeastSquaresSINDy().fit(measure(ds, sc.signal, sc.kind))
    f_true = np.asarray(ds.truth["frequencies_hz"])[:2]
    assert model.cubic_ is True
    np.testing.assert_allclose(model.natural_frequencies_, f_true, rtol=0.01)  # issue #15's bar
    assert "modes [2] stood below the lowest it allows" in model.eigen_rule_


def test_a_cubic_mode_far_below_what_the_hardening_record_allows_is_raised(dataset_cache):
    """``b23_soft_s2neartip`` (the shipped soft base, two sensors near the tip) at 2 % noise,
    seed 142: the cubic fit put mode 2 at 344.3 Hz (true 386.6, 10.9 % off), and nothing moved
    it (the reach bounds from above; the decay hold moves a cubic model's frequency within one
    line).  Its backbone decay fit reads the limit 389.5 Hz (undamped), and mode 1's measured
    stiffening is 4.3 % of its frequency: the floor 371.7 Hz.  Raised to the limit and the
    cubic refitted: measured 0.44 % off, TRAC 0.9958 -> 0.9992; the study's bar 2.6 %."""
    member = {m.name: m for m in load_study(UNSEEN / "round23_beams_noise.toml").scenarios}[
        "b23_soft_s2neartip"]
    sc = member.with_noise(2.0).replace(seed=142)
    ds = dataset_cache.get(sc)
    model = LeastSquaresSINDy().fit(measure(ds, sc.signal, sc.kind))
    f_true = np.asarray(ds.truth["frequencies_hz"])[:2]
    np.testing.assert_allclose(model.natural_frequencies_, f_true, rtol=0.026)  # the study's bar
