"""SGD-SINDy and its helpers on the real cantilever data (scenario ``cantilever_stiff_impact``).

The stiff cantilever: true modes 82.77 / 517.4 / 1447 Hz, damping ratios 0.010 / 0.063 / 0.175
(``C = beta K``), 3 sensors at L/3, 2L/3, L, 12.8 kHz, 1 s, tip impact.  Mode 2 lives in the
first ~30 ms of the free decay and mode 3 in the first ~3 ms, which is what makes this case hard.
The dataset is generated once per session through the shared ``dataset_cache`` fixture.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import identify.sgd_sindy as sgd_module
from identify.sgd_sindy import SGDSINDy
from identify.structural import check_physical, measured_frequencies
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure
from testbed.scoring.run import noise_free, run_scenario
from testbed.scoring.scorers import score_structural
from testbed.studies.study import load_study
from testbed.studies.sweep import expand

ROUND16 = Path(__file__).resolve().parents[2] / "benchmarks" / "unseen" / "round16"
ROUND19 = ROUND16.parent / "round19"
ROUND20 = ROUND16.parent / "round20"
ROUND21 = ROUND16.parent / "round21"


@pytest.fixture(scope="module")
def stiff(dataset_cache):
    sc = load_scenario("cantilever_stiff_impact")
    ds = dataset_cache.get(sc)
    return ds, measure(ds, sc.signal, "structural"), measure(noise_free(ds), sc.signal, "structural")


def test_measured_frequencies_find_modes_1_and_2(stiff):
    """The rectangular window keeps mode 2 (a Hann window suppressed it: only 82.76 Hz was found).

    Measured: 82.767 Hz (true 82.766, 1e-5) and 515.88 Hz (true 517.40, -0.29 %: the peak of a
    mode damped at zeta 0.063 in the spectrum of a decay that starts 1 ms after the pulse).
    Mode 3 (zeta 0.175, ~40 samples of ringing) gives no peak 6 dB above its surroundings.
    """
    ds, data, _ = stiff
    f_true = np.asarray(ds.truth["frequencies_hz"])[:2]
    f = measured_frequencies(data, 3)
    assert f.size == 2
    assert np.all(np.abs(f / f_true - 1) < 0.005)  # measured 1e-5 and 2.9e-3


def test_deterministic_and_finite_on_real_data(stiff):
    _, data, _ = stiff
    a = SGDSINDy(epochs=2, steps_per_epoch=20).fit(data)
    b = SGDSINDy(epochs=2, steps_per_epoch=20).fit(data)
    assert np.array_equal(a.coef_, b.coef_)
    assert np.all(np.isfinite(a.coef_)) and np.all(np.isfinite(a.M_))
    assert a.n_steps_ == 40


def test_stiff_targets_at_reduced_budget(stiff):
    """The issue's stiff targets after 20 epochs (2,000 gradient steps, 0.2 % of the paper's budget).

    Measured: TRAC >= 0.994, MAC 1.000, frequency error 0.64 %; the paper-literal coefficient
    form (``sgd_sindy_coefficients``) diverges here (its null space, see identify/_sgd_matrix.py).
    """
    ds, data, clean = stiff
    model = SGDSINDy(epochs=20).fit(data)
    assert model.n_steps_ == 2000
    v = score_structural(ds, data, clean, model).values
    # the targets are the paper's modes 1-2 (mode 3 is scored and reported too)
    assert v["trac"] >= 0.95 and np.min([v["mac_mode1"], v["mac_mode2"]]) >= 0.95
    assert np.max([v["freq_error_mode1"], v["freq_error_mode2"]]) <= 0.01
    assert np.all(np.linalg.eigvalsh(model.M_) > 0)  # symmetric positive definite by construction
    np.testing.assert_allclose(np.trace(model.M_), data.prior["reduced_mass_trace"], rtol=1e-12)


def test_five_sensors_at_12k8_place_the_unresolved_mode_in_the_warm_start(dataset_cache):
    """Round 16's b16_ti_n32_s5 (five sensors at 12.8 kHz on 32 segments; mode 5 at 4619 Hz,
    57 % damped, past the peak band's 4522 Hz top): the tilted warm start fits mode 5 with a
    negative stiffness (a pole at +2.99e10 1/s); the old code fell back flat and the SGD
    diverged (modes at 136 / 241 / 6878 Hz, TRAC 4.6e-8).  With the unresolved mode placed in
    the warm start (identify._sgd_matrix.unresolved_warm_start): tilted, modes 1-3 within the
    issue's 1 % of the engine's truth (measured 6.8e-5, 2.9e-4, 2.9e-3)."""
    sc = load_scenario(ROUND16 / "b16_ti_n32_s5.toml")
    ds = dataset_cache.get(sc)
    model = SGDSINDy().fit(measure(ds, sc.signal, "structural"))
    assert "placed at that top" in model.unresolved_rule_
    assert model.fit_tilt_
    f_true = np.asarray(ds.truth["frequencies_hz"])[:3]
    np.testing.assert_allclose(model.natural_frequencies_[:3], f_true, rtol=0.01)
    check_physical(model.M_, model.C_, model.K_)
    # a user's narrower search range is no limit of the record: nothing is placed (review,
    # session 18: freq_range [10, 2000] Hz placed mode 4, 2795 Hz true, at 2010 Hz, and
    # [10, 1000] Hz two modes at one frequency, a raw LinAlgError)
    for freq_range in ([10.0, 2000.0], [10.0, 1000.0]):
        user = SGDSINDy(freq_range=freq_range).fit(measure(ds, sc.signal, "structural"))
        assert "placed at that top" not in user.unresolved_rule_


def test_a_placed_warm_start_whose_damping_grows_is_projected_not_fitted_flat(dataset_cache):
    """Round 19's b19_st_s5_hitmid (the shipped beam, five sensors, the hammer at mid-span),
    clean: two peaks located (82.77 / 515.6 Hz; modes 3-5 damped 17-57 %).  In the fit band the
    tilted warm start is refused for a negative stiffness that its damping's projection does
    not remove; the unresolved mode placed at the band's top, the warm start still grew (a
    resolved mode's own damping fitted negative: a pole at +4096 +1.35e4j 1/s), so it was
    refused too and fitted flat: two more negative stiffnesses, the SGD's model at 3.2 / 293 /
    1272 / 2128 / 25241 Hz, and without the band (session 20's refusal) TRAC 0.024 with mode
    1's MAC 0.28 (its warm start's higher modes copying mode 1's shape).  Now the placed warm
    start gets the damping projection the tilted one gets (``_physical_placed``) and stays
    tilted in the band: measured TRAC 0.998, modes 1-2 within 0.01 %, MAC 1.000 / 1.000."""
    sc = load_scenario(ROUND19 / "b19_st_s5_hitmid.toml")
    ds = dataset_cache.get(sc)
    data = measure(ds, sc.signal, "structural")
    model = SGDSINDy().fit(data)
    assert "placed at that top" in model.unresolved_rule_
    assert "projected onto the positive semi-definite cone" in model.unresolved_rule_
    assert model.fit_tilt_ and model.fit_band_hz_ > 0.0
    assert model.record_rule_.startswith("the kept model explains its record")
    v = score_structural(ds, data, measure(noise_free(ds), sc.signal, "structural"), model).values
    # issue #15's bars (TRAC and MAC >= 0.95, modes 1-2 within 1 %); the old code: TRAC 0.024,
    # mode 1 MAC 0.28
    assert v["trac"] >= 0.95 and np.min([v["mac_mode1"], v["mac_mode2"]]) >= 0.95
    assert np.max([v["freq_error_mode1"], v["freq_error_mode2"]]) <= 0.01


def test_a_mode_1_the_band_removed_is_refitted_without_the_band(dataset_cache, monkeypatch):
    """Round 19's b19_ti_L0p9_n18_s5_2s at 2 % noise (seed 102, its study's): mode 1 at 10.12 Hz,
    1.2 % above the chain's 10 Hz high-pass, gives no accepted peak, so the band's cut-off
    (0.7 x 63.36 Hz) removed it and the model in the band put it at 100 Hz (888 % off, record
    agreement 0.086, scored TRAC 0.086).  Its record agreement refuses the band; without it
    (agreement 0.971, measured) modes 1-2 are within issue #15's 1 % (measured 0.16 / 0.003 %).

    The refit without the band reads the default peak search the first fit made of the same
    record (issue #13: it searched again for each refit, three searches, 0.014 s of CPU each
    here): one search a fit.  The model is bit for bit the one a fresh search for every use
    gives (the search is a function of the record and ``lower_modes`` alone): measured on 411
    ``sgd_sindy`` cells, M, C, K, K3 hashed (docs/known-gaps.md, sgd25); a second fit here to
    show it again cost 14 s of the suite's tail and is left to that measurement."""
    sc = load_scenario(ROUND19 / "b19_ti_L0p9_n18_s5_2s.toml").with_noise(2.0).replace(seed=102)
    ds = dataset_cache.get(sc)
    data = measure(ds, sc.signal, "structural")
    searched = []
    real = sgd_module.modal_peaks

    def counted(*args, **kwargs):
        searched.append(args[1:])
        return real(*args, **kwargs)

    monkeypatch.setattr(sgd_module, "modal_peaks", counted)
    model = SGDSINDy().fit(data)
    assert "refused: the model fitted in it does not explain its record" in model.fit_band_rule_
    assert model.record_rule_.startswith("the kept model explains its record")
    f_true = np.asarray(ds.truth["frequencies_hz"])[:2]
    np.testing.assert_allclose(model.natural_frequencies_[:2], f_true, rtol=0.01)  # issue #15
    assert len(searched) == 1  # the old code: 3 (the same default search for each refit)


def test_a_mode_the_others_outlive_has_its_target_lowered_by_their_stiffening(dataset_cache):
    """Round 19's b19_soft_r8_cf2_f75 (the shipped beam on k1 = 8 EI/L, cubic fraction 2, 75
    N), clean: mode 2's peak (466.2 Hz) rings hardened by mode 1's motion, which outlives it
    (measured decay rates 4.34 and 199.4 1/s), and its own chirp, read by the backbone decay
    fit, holds only part of it (backbone 462.8 Hz; the engine's linear mode 2 446.9 Hz).  The
    cross stiffening was subtracted only from modes whose decay does not chirp, so the model's
    mode 2 was 2.90 % off.  Now a mode the other located modes outlive has it subtracted too
    (14.6 Hz): measured 0.11 % off, TRAC 0.983 -> 0.992."""
    sc = load_scenario(ROUND19 / "b19_soft_r8_cf2_f75.toml")
    ds = dataset_cache.get(sc)
    data = measure(ds, sc.signal, "structural")
    model = SGDSINDy().fit(data)
    assert re.search(r"other modes' motion over each mode's life: modes \[1, 2\]",
                     model.eigen_backbone_rule_)
    v = score_structural(ds, data, measure(noise_free(ds), sc.signal, "structural"), model).values
    # issue #15's 1 % bar on mode 2 (the old code 2.90 %) and TRAC 0.95
    assert abs(v["freq_error_mode2"]) <= 0.01 and v["trac"] >= 0.95


def test_a_warm_start_whose_stiffness_has_a_complex_pair_is_fitted_flat_not_a_breakdown(
        dataset_cache):
    """Round 20's b20_st_hit0p1 (sensors 0.1 / 0.5 / 1 L, the hammer at 0.1 L) at 3 % noise,
    seed 113: the tilted warm start grows, its damping's projection does not help, and the
    uncoupled regression's ``A = M^-1 K`` has modes 2-3 coalesced into a complex pair (532.5
    +- 11.7j Hz), whose shapes' real parts are one vector: the old code solved with that
    singular matrix ("fit failed: numerical breakdown (LinAlgError: Singular matrix)").  Now
    the placement states why it does not act (``_sgd_matrix.complex_stiffness_pair``) and the
    fit falls back flat: a scored model (measured TRAC 0.795, modes 1-2 within 0.02 %; the
    cell then fails its TRAC bar as the study's other seeds do at 3 %)."""
    sc = load_scenario(ROUND20 / "b20_st_hit0p1.toml").with_noise(3.0).replace(seed=113)
    ds = dataset_cache.get(sc)
    data = measure(ds, sc.signal, "structural")
    model = SGDSINDy().fit(data)
    assert "complex eigenvalue pair" in model.unresolved_rule_
    assert not model.fit_tilt_
    check_physical(model.M_, model.C_, model.K_)
    v = score_structural(ds, data, measure(noise_free(ds), sc.signal, "structural"), model).values
    assert np.max([v["freq_error_mode1"], v["freq_error_mode2"]]) <= 0.01  # measured 7e-5, 1.3e-4
    assert np.isfinite(v["trac"])


def test_a_cubic_model_whose_simulation_and_warm_start_diverge_is_refused_for_the_linear(
        dataset_cache):
    """Round 20's soft family member r20_soft__006 (round20_families.toml: a stiff soft base
    with cubic fraction 0.6-1.2) at 1 % noise, seed 117, with the shipped soft scenario's
    ``cubic = true``: the fitted ``K3`` (mixed signs in one column, no potential's gradient)
    made the SGD's model and its held warm start both diverge from the record's own start
    (at 31 / 24 ms), and the keep rule kept the SGD's result: scored "diverged: cubic
    structural model diverged", TRAC NaN.  Now such a cubic model is refused and the linear
    library fitted (``sgd_sindy.cubic_diverges``): measured TRAC 0.976, modes 1-2 within
    0.18 / 0.46 %."""
    member = {m.name: m for m in load_study(ROUND20.parent / "round20_families.toml").scenarios}[
        "r20_soft__006"]
    sc = member.with_noise(1.0).replace(seed=117)
    ds = dataset_cache.get(sc)
    data = measure(ds, sc.signal, "structural")
    model = SGDSINDy(cubic=True).fit(data)
    # which test meets the failing cubic first (refused for its simulation, or doubted against
    # the measured decay and then outexplained by the linear refit, whose rival's simulation
    # failed) is decided by the SGD's last bits (numba compiles for the host CPU: round 21's
    # b21_soft_root3 below took the second route on a Zen 5 EPYC); the outcome is the claim
    rule = model.cubic_rule_
    assert rule.endswith("cubic terms out") and ("its simulation from the record's own start "
                                                  "fails" in rule or "(its simulation failed)" in rule)
    assert not model.cubic_ and model.K3_ is None
    v = score_structural(ds, data, measure(noise_free(ds), sc.signal, "structural"), model).values
    # issue #15's bars (TRAC and MAC >= 0.95, modes 1-2 within 1 %); the old code: TRAC NaN
    assert v["trac"] >= 0.95 and np.min([v["mac_mode1"], v["mac_mode2"]]) >= 0.95
    assert np.max([v["freq_error_mode1"], v["freq_error_mode2"]]) <= 0.01


def test_a_projected_warm_start_whose_modes_miss_the_peaks_falls_back_flat(dataset_cache):
    """Round 20's b20_soft_r1p2_cf0p3_root2 (a 1.2 EI/L soft base, cubic fraction 0.3, two
    sensors at 0.1 / 0.2 L) at 1 % noise, seed 118 (its study's): the tilted warm start grew
    (a pole at +192 +478j 1/s) and, its damping projected, was kept "physical then" with modes
    at 81.8 / 283.5 Hz against the peaks at 39.8 / 389.5 Hz; the SGD from it put mode 1 213 %
    off (TRAC 0.28).  A projected warm start with no mode near the lowest measured peak
    (``_sgd_matrix.lowest_peak_unpaired``) is fitted flat too, and the flat fit's model
    explains more of its record (measured record agreement 0.993 against 0.275): kept, scored
    TRAC 0.994, modes 1-2 within 0.93 %."""
    sc = load_scenario(ROUND20 / "b20_soft_r1p2_cf0p3_root2.toml").with_noise(1.0).replace(
        seed=118)
    ds = dataset_cache.get(sc)
    data = measure(ds, sc.signal, "structural")
    model = SGDSINDy().fit(data)
    v = score_structural(ds, data, measure(noise_free(ds), sc.signal, "structural"), model).values
    # issue #15's bars; the old code: mode 1 213 % off, TRAC 0.28
    assert v["trac"] >= 0.95 and np.min([v["mac_mode1"], v["mac_mode2"]]) >= 0.95
    assert np.max([v["freq_error_mode1"], v["freq_error_mode2"]]) <= 0.01
    assert "its stiffness, not its damping, is wrong" in model.fit_tilt_rule_
    assert model.fit_tilt_rule_.endswith("refit kept") and not model.fit_tilt_


def _family_member(dataset_cache, name: str):
    """A member of ``studies/families.toml``, clean: dataset, measurement, noise-free measurement."""
    study = load_study(ROUND16.parents[2] / "studies" / "families.toml")
    sc = {m.name: m for m in study.scenarios}[name]
    ds = dataset_cache.get(sc)
    return ds, measure(ds, sc.signal, "structural"), measure(noise_free(ds), sc.signal, "structural")


def test_a_decay_frequency_of_an_outlived_mode_is_lowered_by_its_target_s_cross_stiffening(
        dataset_cache):
    """Families' soft member 012, clean, ``cubic = true`` (the shipped soft scenario's table):
    mode 2's target was its backbone less the cross stiffening mode 1's motion adds over its
    life (235.3 Hz; truth 234.30), and the decay hold then moved mode 2 onto its measured decay
    frequency, which rings with that same stiffening (238.1 Hz): 1.60 % high, the issue's 1 %
    missed.  Now the decay hold's frequency of a mode the others outlive is lowered by the same
    shift: measured 0.67 %, TRAC 0.981 -> 0.990."""
    ds, data, clean = _family_member(dataset_cache, "beams_soft__012")
    model = SGDSINDy(cubic=True).fit(data)
    assert "decay frequencies less the cross stiffening" in model.decay_rule_
    v = score_structural(ds, data, clean, model).values
    # issue #15's bars (the old code: mode 2 1.60 %)
    assert v["trac"] >= 0.95 and np.min([v["mac_mode1"], v["mac_mode2"]]) >= 0.95
    assert np.max([v["freq_error_mode1"], v["freq_error_mode2"]]) <= 0.01


def test_a_diverging_cubic_whose_warm_start_is_not_simulated_is_refused_for_the_linear(
        dataset_cache):
    """Round 21's b21_soft_root3 (a soft base read at 0.15 / 0.25 / 0.35 L), clean, default
    settings (the cubic in by rule): the SGD's cubic model diverges from the record's own start
    (18.6 ms) and its held warm start is not simulated (a linear pole past RK4's bound at the
    sample rate), so neither has a record agreement; the refusal asked both to *fail*, the keep
    rule kept the SGD's result, scored "diverged" (TRAC NaN).  Now a diverging SGD result whose
    warm start has no agreement either is refused and the linear library fitted: measured TRAC
    0.995, modes 1-2 1.43 / 1.90 % (the study's bars, 2.6 %; the issue's 1 % open).  Then
    ``ls_sindy``'s step 4c (``SGDSINDy._backbone_cubic``, branch sgd29) moves that linear
    model's mode 1 to its backbone limit with a one-mode cubic: mode 1 1.43 -> 0.07 %, TRAC
    0.9954 -> 0.9945 (within the step's margin), mode 2 unchanged."""
    sc = load_scenario(ROUND21 / "b21_soft_root3.toml")
    ds = dataset_cache.get(sc)
    data = measure(ds, sc.signal, "structural")
    model = SGDSINDy().fit(data)
    # which test meets the failing cubic first (refused for its simulation, or doubted against
    # the measured decay and then outexplained by the linear refit, whose rival's simulation
    # failed) is decided by the SGD's last bits: numba compiles for the host CPU (FMA or not),
    # and an AMD EPYC took the second route (speed27, 2026-11-29); the outcome is the claim
    rule = model.cubic_rule_
    assert rule.endswith("cubic terms out") and ("its simulation from the record's own start "
                                                  "fails" in rule or "(its simulation failed)" in rule)
    assert not model.cubic_  # the linear library; its only cubic is step 4c's, on mode 1
    assert "moved to its limit, with a cubic on that mode alone" in model.backbone_cubic_rule_
    assert np.linalg.matrix_rank(model.K3_) == 1
    # review 29c M1: the record rule states the moved model's own agreement (0.9945), not the
    # keep rule's of the unmoved one (0.9954); the input map kept, so the delivered model is it
    assert "; rule: kept," in model.input_map_rule_
    a_moved, _ = sgd_module.record_agreement(model, data)  # (0.2 s: one linear-plus-cubic run)
    assert f"(TRAC) {a_moved:.4g} >=" in model.record_rule_
    v = score_structural(ds, data, measure(noise_free(ds), sc.signal, "structural"), model).values
    # the round's bars (the families': TRAC and MAC of modes 1-2 > 0.90, modes 1-2 within 2.6
    # %); the old code: TRAC NaN
    assert v["trac"] > 0.90 and np.min([v["mac_mode1"], v["mac_mode2"]]) > 0.90
    assert np.max(np.abs([v["freq_error_mode1"], v["freq_error_mode2"]])) < 0.026
    assert v["freq_error_mode1"] <= 0.01  # issue #15's bar: measured 0.07 % (before 4c 1.43 %)


def test_a_bump_of_noise_on_a_stronger_modes_leakage_is_no_eigenvalue_target(dataset_cache):
    """Round 22's magnesium at 1.8 kHz, two sensors, 5 % noise, seed 139 (the truth is the
    engine's: mode 2 508.7 Hz, 6.25 % damped).  The SGD's peak search took a 171.1 Hz bump of
    noise on mode 1's leakage as mode 2, and the eigenvalue target put mode 2 there: 172 Hz,
    66.2 % off with MAC 0.9996, TRAC 0.9955 (old code).  Its search now has ``ls_sindy``'s
    rule 4b (``modal_peaks(..., ringing=True)``): the bump neither rings nor decays beyond
    noise, and mode 2 is the 489.6 Hz peak's; measured 0.74 %, TRAC 0.9996."""
    study = load_study(ROUND16.parent / "round22_beams_more.toml")
    cells = [c for c in expand(study) if c.identifier == "sgd_sindy"
             and c.scenario.name == "b22_mg_fs1k8_s2" and c.noise == 5.0 and c.scenario.seed == 139]
    assert len(cells) == 1
    sc = cells[0].scenario
    res = run_scenario(sc, dataset=dataset_cache.get(sc))
    v = res.scores.values
    assert v["freq_error_mode2"] <= 0.026  # measured 0.74 % (old code 66.2 %); the study's bar
    assert v["freq_error_mode1"] <= 0.001  # measured 0.004 %: mode 1 untouched
    assert v["trac"] >= 0.99  # measured 0.9996 (old 0.9955)
    assert not np.any(np.abs(res.model.measured_frequencies_ - 171.1) < 1.0)


def test_every_projected_warm_start_is_compared_with_the_flat_fit(dataset_cache):
    """Families' clamped member 009, clean: the tilted warm start grew (a pole at +1304 1/s)
    and, its damping projected, carried the lowest peak, so it was kept without a comparison;
    the SGD from it explained 0.847 of its record (modes within 0.06 %, the study's TRAC 0.90
    missed).  The projection is a repair the record did not choose: every projected warm
    start is now fitted flat too, and the flat model kept where the projected fit leaves more
    than ``SGD_AGREEMENT_RATIO`` (2) x its unexplained share of the record (here 0.153 against
    0.063, 2.4 x: measured TRAC 0.937, modes 1-2 within 0.13 %).

    Session 27 (sgd27): that model, with the same poles as ``ls_sindy``'s to 4 digits, explained
    its record less under the impact's tail through the record's gain at the driving point
    (0.937) than with no force at all (0.977): the input map is now dropped where the model
    explains its record clearly better without it (``ls_sindy``'s step 6, ratio 2), and the
    cell meets issue #15's bars (measured TRAC 0.977, modes 1-2 within 0.13 %)."""
    ds, data, clean = _family_member(dataset_cache, "beams_stiff__009")
    model = SGDSINDy().fit(data)
    v = score_structural(ds, data, clean, model).values
    # issue #15's bars (old code: TRAC 0.847, then 0.937 with the map kept)
    assert v["trac"] >= 0.95 and np.min([v["mac_mode1"], v["mac_mode2"]]) >= 0.95
    assert np.max([v["freq_error_mode1"], v["freq_error_mode2"]]) <= 0.01
    assert "the projection is a repair the record did not choose" in model.fit_tilt_rule_
    assert model.fit_tilt_rule_.endswith("refit kept") and not model.fit_tilt_
    assert "dropped" in model.input_map_rule_ and not np.any(model.input_map_)


def test_a_projected_warm_start_leaving_a_residue_is_kept_without_a_refit(dataset_cache):
    """Review 24e: a projected warm start that carries every located peak was fitted flat too
    and replaced where the flat fit left half its unexplained share, even where that share is
    a residue (round 20's ``b20_st_L0p6_n6_s4tip_4s`` clean: 7.1e-4 against 3.2e-4, four such
    clean cells, each passing either way; the refit 1.8 s of 8.5 s).  At most
    ``PROJECTED_REFIT_FLOOR`` (1e-3) unexplained, the first fit is kept with no refit, said."""
    sc = load_scenario(ROUND20 / "b20_st_L0p6_n6_s4tip_4s.toml")
    res = run_scenario(sc, dataset=dataset_cache.get(sc))
    rule = res.model.fit_tilt_rule_
    assert "no flat refit, first fit kept" in rule and res.model.fit_tilt_
    assert res.passed  # the study's bars (measured TRAC 0.9993)




def test_a_cubic_that_contradicts_a_measured_decay_is_compared_with_the_linear_fit(
        dataset_cache):
    """Families' soft member 019, clean, ``cubic = true`` (the shipped soft scenario's table):
    the fitted cubic shifts mode 1 by -0.69 Hz at the measured amplitude where its measured
    decay hardens by +0.80 Hz (``ls_sindy``'s ``_cubic_softens`` test); the cubic model
    explains 0.868 of its record, mode 2 3.75 % low.  Now such a cubic is doubted and the
    linear library fitted too; the model that explains more of its record is kept: the linear,
    0.965 (measured: modes 1-2 0.62 / 0.27 % off, the issue's bars met)."""
    ds, data, clean = _family_member(dataset_cache, "beams_soft__019")
    model = SGDSINDy(cubic=True).fit(data)
    assert "the fitted cubic model doubted (its cubic shifts mode 1" in model.cubic_rule_
    assert "the linear refit explains more of its record" in model.cubic_rule_
    assert not model.cubic_
    v = score_structural(ds, data, clean, model).values
    # issue #15's bars (the old code: TRAC 0.868, mode 2 3.75 %)
    assert v["trac"] >= 0.95 and np.min([v["mac_mode1"], v["mac_mode2"]]) >= 0.95
    assert np.max([v["freq_error_mode1"], v["freq_error_mode2"]]) <= 0.01


def test_a_model_with_no_cubic_term_that_leaves_its_record_unexplained_tries_the_cubic(
        dataset_cache):
    """Round 23's brass on a 1 EI/L soft base (the truth's cubic force 0.24 x its linear one)
    at 0.7 % noise, seed 142: the cubic rule's partial correlations (0.595, tilted 0.63) fall
    under its 0.65, the linear model explains 0.964 of its record and puts mode 1 2.3 % high.
    Now a model with no cubic term leaving more than 1 % of its record unexplained is fitted
    again with the whole cubic library, kept where it leaves under half the unexplained share:
    0.9915 (measured: mode 1 0.23 % off, within issue #15's 1 %)."""
    sc = load_scenario(ROUND16.parent / "round23" / "b23_br_soft_r1_cf0p4_hit0p3.toml"
                       ).with_noise(0.7).replace(seed=142)
    ds = dataset_cache.get(sc)
    model = SGDSINDy().fit(measure(ds, sc.signal, "structural"))
    assert "cubic terms out; but that model (no cubic term) leaves" in model.cubic_rule_
    assert model.cubic_ and np.any(model.K3_ != 0.0)
    assert model.cubic is None and model.l1 == "cubic"  # the user's settings stay
    f_true = np.asarray(ds.truth["frequencies_hz"])[:1]
    # issue #15's 1 % on mode 1 (the old code: 2.33 % high)
    np.testing.assert_allclose(model.natural_frequencies_[:1], f_true, rtol=0.01)
    # review 25e: a user's lasso key (read only with l1 = 'cubic') refused the trial's
    # l1 = 'none' in silence: the trial takes the lasso's defaults, the user's value stays
    tuned = SGDSINDy(l1_debias=0.49).fit(measure(ds, sc.signal, "structural"))
    assert tuned.cubic_ and tuned.l1_debias == 0.49
    np.testing.assert_allclose(tuned.natural_frequencies_[:1], f_true, rtol=0.01)


def test_a_users_cubic_without_the_lasso_is_never_doubted(dataset_cache, monkeypatch):
    """Review 25e: the doubt (a cubic contradicting a measured decay compared with the linear
    fit) overrode a user's ``cubic = true``.  It compares the libraries where the data select
    the cubic terms (by rule, or ``cubic = true`` with the lasso, ``l1 = 'cubic'``); ``cubic =
    true`` with ``l1 = 'none'`` asks for the cubic model itself.  Every cubic is made doubted
    here (the test's own stand-in for the decay test) on round 23's brass at 0.7 %."""
    sc = load_scenario(ROUND16.parent / "round23" / "b23_br_soft_r1_cf0p4_hit0p3.toml"
                       ).with_noise(0.7).replace(seed=142)
    data = measure(dataset_cache.get(sc), sc.signal, "structural")
    monkeypatch.setattr(SGDSINDy, "_cubic_contradicts_decay", lambda self: "doubted by the test")
    assert "the fitted cubic model doubted" in SGDSINDy(cubic=True).fit(data).cubic_rule_
    asked = SGDSINDy(cubic=True, l1="none").fit(data)
    assert asked.cubic_ and asked.cubic_rule_ == "user setting"


def test_a_cubic_tilted_warm_start_with_a_growing_pole_has_its_damping_projected(dataset_cache):
    """Round 24's ``b24_soft_r2p7_cf0p45_z0p2`` (a 2.7 EI/L soft base, cubic fraction 0.45,
    0.2 % damping) at 1 % noise, seed 152: the cubic came in by rule and the tilted cubic warm
    start had mode 1's pole at +0.40 +329j 1/s (a damping ratio of -0.12 %, the 0.2 % truth's
    sign lost to the noise).  The damping projection that repairs a linear tilted warm start
    was not tried on a cubic one: refused, fitted flat, mode 3 at 982 Hz for the 1256 Hz peak
    (20 % off, TRAC 0.779).  Now a cubic warm start's damping is projected too where its growth
    is one the record does not resolve (+0.40 1/s over the 0.99 s free decay, under e-fold:
    ``_sgd_matrix.UNRESOLVED_GROWTH``), and the projected fit kept where it explains clearly
    more than the flat refit (record agreement 0.9915 against 0.779).  Measured TRAC 0.994,
    modes 1-3 within 0.55 / 0.62 / 1.6 %."""
    sc = load_scenario(ROUND16.parent / "round24" / "b24_soft_r2p7_cf0p45_z0p2.toml"
                       ).with_noise(1.0).replace(seed=152)
    ds = dataset_cache.get(sc)
    data = measure(ds, sc.signal, "structural")
    model = SGDSINDy().fit(data)
    assert model.cubic_ and "cubic terms in" in model.cubic_rule_
    assert "kept with its damping projected onto the positive semi-definite cone" \
        in model.fit_tilt_rule_
    v = score_structural(ds, data, measure(noise_free(ds), sc.signal, "structural"), model).values
    # the round's TRAC bar 0.9 and issue #15's 0.95 (the old code: 0.779, mode 3 20 % off);
    # mode 3 within 3 %: its peak itself lies 2.1 % above the truth (1256 against 1230 Hz)
    assert v["trac"] >= 0.95
    assert v["freq_error_mode3"] <= 0.03


def test_a_cubic_warm_start_growing_at_a_located_mode_has_its_damping_projected(dataset_cache):
    """The same rig at 3 % noise, seed 152 (session 27): mode 1's pole at +1.52 +328.5j 1/s
    grows by 1.5 over the free decay, past ``UNRESOLVED_GROWTH``, so it was fitted flat: mode 3
    72 % off, TRAC 0.493.  The growing pole is mode 1, which the measured 53.9 Hz peak locates
    (``_sgd_matrix.growing_mode_located``): the record holds its ringing, so its damping is
    projected and the projected fit kept where it explains clearly more than the flat refit
    (record agreement 0.993 against 0.493).  Measured TRAC 0.993, modes 1-3 within 0.55 /
    0.45 / 1.7 %."""
    sc = load_scenario(ROUND16.parent / "round24" / "b24_soft_r2p7_cf0p45_z0p2.toml"
                       ).with_noise(3.0).replace(seed=152)
    ds = dataset_cache.get(sc)
    data = measure(ds, sc.signal, "structural")
    model = SGDSINDy().fit(data)
    assert model.cubic_ and "kept with its damping projected" in model.fit_tilt_rule_
    assert model.fit_tilt_rule_.endswith("first fit kept")
    v = score_structural(ds, data, measure(noise_free(ds), sc.signal, "structural"), model).values
    # issue #15's bars (the old code: TRAC 0.493, mode 3 72 % off); mode 3 within 3 % as above
    assert v["trac"] >= 0.95 and max(v["freq_error_mode1"], v["freq_error_mode2"]) <= 0.01
    assert v["freq_error_mode3"] <= 0.03


def test_a_doubted_cubic_stays_only_where_it_explains_clearly_more(dataset_cache):
    """Review 25e: a cubic contradicting a measured decay was compared with the linear refit
    by the higher record agreement alone, so a 1e-3 tie decided the library.  Round 20's
    ``r20_soft__001`` at 1 % noise, seed 117 (``cubic = true``, the shipped soft table): the
    cubic shifts mode 2 by +0.066 Hz where the decay softens it by 0.014 Hz; the cubic explains
    0.997 of its record, the linear refit 0.996, and the cubic was kept.  Now the doubted cubic
    stays only where it leaves under 1 / ``SGD_AGREEMENT_RATIO`` of the linear's unexplained
    share (``_clearly_more``, the trial's margin for a cubic over a linear model): the linear
    model (measured: TRAC 0.996, modes 1-2 within 0.19 / 0.77 %, issue #15's bars held)."""
    member = {m.name: m for m in load_study(ROUND20.parent / "round20_families.toml").scenarios}[
        "r20_soft__001"]
    sc = member.with_noise(1.0).replace(seed=117)
    ds = dataset_cache.get(sc)
    data = measure(ds, sc.signal, "structural")
    model = SGDSINDy(cubic=True).fit(data)
    assert "the fitted cubic model doubted" in model.cubic_rule_
    assert "the cubic model does not explain clearly more of its record" in model.cubic_rule_
    assert not model.cubic_  # the old code: the cubic kept on 0.997 against 0.996
    v = score_structural(ds, data, measure(noise_free(ds), sc.signal, "structural"), model).values
    assert v["trac"] >= 0.95 and np.min([v["mac_mode1"], v["mac_mode2"]]) >= 0.95
    assert np.max([v["freq_error_mode1"], v["freq_error_mode2"]]) <= 0.01


def test_step_4c_acts_on_a_linear_model_whose_cubic_terms_were_the_datas(monkeypatch):
    """``ls_sindy``'s step 4c in ``sgd_sindy`` (:meth:`SGDSINDy._backbone_cubic`; review 29c
    L8, the rule alone, in milliseconds: ``b21_soft_root3``'s end-to-end test is the check
    that it fires on a real record).  It acts on a model with no kept cubic whose cubic terms
    were the data's to select (``cubic`` None, or true with ``l1 = 'cubic'`` and ``K3_`` all
    zero: families' soft member 001 clean, mode 1 2.95 -> 0.88 %, TRAC 0.937 -> 0.980,
    measured on branch sgd29), with ``ls_sindy``'s margin (L4); not with ``l1 = 'none'``, a
    nonzero ``K3_`` or ``cubic`` false.  Where it acts, ``coef_`` follows the moved ``K_`` and
    ``K3_``, and ``record_rule_`` is stated on the moved model's agreement (M1).  The step's
    own function is stood in for (known symmetric ``K``, rank-one ``K3``, the moved model's
    agreement 0.98, which it returns: not simulated again)."""
    from testbed.core.measurement import Measurement

    m = np.array([2.0, 1.0])
    K0 = np.array([[3.0e4, -1.0e4], [-1.0e4, 2.0e4]])
    K_new = np.array([[2.9e4, -1.0e4], [-1.0e4, 2.0e4]])
    K3_new = np.outer([1.0, -0.5], [2.0e9, -1.0e9])
    ratios: list[float] = []

    def backbone(model, data, peaks, ratio):
        ratios.append(ratio)
        return K_new, K3_new, "mode 1 moved to its limit, with a cubic on that mode alone", 0.98

    monkeypatch.setattr(sgd_module, "backbone_cubic", backbone)
    data = Measurement(fs=100.0, x=np.zeros((2, 8)), xd=np.zeros((2, 8)), xdd=np.zeros((2, 8)),
                       channels=("s1", "s2"))

    def fitted(cubic: bool | None, l1: str, K3: np.ndarray | None) -> SGDSINDy:
        est = SGDSINDy(cubic=cubic, l1=l1)
        lib = 8 if K3 is not None else 6  # a, v, d (and c) blocks of two columns
        est.M_, est.C_, est.K_, est.K3_ = np.diag(m), 1e-3 * K0, K0.copy(), K3
        est.coef_ = np.zeros((2, lib))
        est.coef_[:, 4:6] = -K0 / m[:, None]
        est.peaks_, est.cubic_ = np.array([10.0, 30.0]), K3 is not None
        est._d_block, est._c_block = slice(4, 6), (slice(6, 8) if K3 is not None else None)
        est.record_rule_ = "stale"
        return est

    for cubic, l1, K3, fires in ((True, "cubic", np.zeros((2, 2)), True),
                                 (None, "cubic", None, True),
                                 (True, "none", np.zeros((2, 2)), False),
                                 (True, "cubic", 1e9 * np.eye(2), False),
                                 (False, "cubic", None, False)):
        est = fitted(cubic, l1, K3)
        moved = est._backbone_cubic(data)
        assert (moved is not None) == fires, (cubic, l1)
        assert ("moved to its limit" in est.backbone_cubic_rule_) == fires
        if not fires:
            assert est.record_rule_ == "stale" and np.array_equal(est.K_, K0)
            continue
        assert moved == (0.98, "") and ratios[-1] == sgd_module.CUBIC_TRIAL_RATIO
        assert "explains its record (record agreement (TRAC) 0.98" in est.record_rule_
        assert np.array_equal(est.K_, K_new) and np.array_equal(est.K3_, K3_new)
        # (the displacement block is updated by the difference: rounding of one subtraction)
        np.testing.assert_allclose(est.coef_[:, 4:6], -K_new / m[:, None], rtol=1e-12)
        if K3 is not None:
            np.testing.assert_array_equal(est.coef_[:, 6:8], -K3_new / m[:, None])
