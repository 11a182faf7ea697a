"""A free decay too short for the peak search: one named refusal from every identifier that reads its
modes from it (identify.structural.check_peak_band; session 16)."""

from __future__ import annotations

import dataclasses

import pytest

from benchmarks import bench_sgd_sindy as bench
from identify import IDENTIFIERS
from identify.structural import PEAK_BAND_LINES, modal_peaks
from testbed import load_scenario
from testbed.core.errors import IdentificationError
from testbed.pipeline.signal_chain import measure


@pytest.fixture(scope="module")
def chain():
    """Exact 3-DOF chain, 12.8 kHz, no declared pass band (modes 90 / 235 / 343 Hz)."""
    return bench.chain_measurement(bench.chain_system(coupled=False, damping="proportional"))


#: The identifiers that read their modes from the peak search (identify.structural.modal_peaks).
PEAK_SEARCH_IDENTIFIERS = ("ls_sindy", "sgd_sindy", "sgd_sindy_coefficients")


@pytest.mark.parametrize("name", PEAK_SEARCH_IDENTIFIERS)
def test_a_free_decay_too_short_for_the_peak_search_is_refused_by_name(chain, name):
    """4-11 samples after free_start at 12.8 kHz without a pass band: the peak band starts 5
    lines (5 fs / n) above 0 Hz and must stay below 0.45 fs, so n > 5 / 0.45 = 11.1; was a
    raw ValueError from testbed.numerics.spectral ("need 0 <= fmin < fmax <= Nyquist")."""
    for k in (4, 7, 11):
        short = dataclasses.replace(chain, free_start=chain.n_samples - k)
        with pytest.raises(IdentificationError,
                           match=rf"holds {k} samples; the peak search .* needs at least 12 "):
            IDENTIFIERS.get(name)(**({"epochs": 1} if name != "ls_sindy" else {})).fit(short)


def test_the_minimum_follows_the_declared_pass_band(chain):
    """With a 5 kHz low-pass the band's top is 0.8 x 5 kHz = 4 kHz: more than
    5 x 12800 / 4000 = 16 samples are needed (17), and 17 have a band."""
    banded = dataclasses.replace(chain, passband=(10.0, 5000.0))
    assert PEAK_BAND_LINES == 5
    with pytest.raises(IdentificationError, match=r"holds 16 samples; .* needs at least 17 "):
        modal_peaks(dataclasses.replace(banded, free_start=chain.n_samples - 16))
    ps = modal_peaks(dataclasses.replace(banded, free_start=chain.n_samples - 17))
    assert ps.band[0] < ps.band[1]


def test_a_band_the_chain_closes_is_named(chain):
    """A high-pass so near the low-pass that 1.1 hp >= 0.8 lp leaves no band whatever the
    record's length (3300 >= 3200 Hz)."""
    with pytest.raises(IdentificationError, match=r"band .* is empty"):
        modal_peaks(dataclasses.replace(chain, passband=(3000.0, 4000.0)))


def _beam_record(n_sensors: int, dataset_cache):
    """The shipped clamped beam (0.1 s) with ``n_sensors`` evenly spaced, hammer at the last.

    Read through the shared test cache: the two 5-sensor cases are one record (simulated once,
    0.9 s of CPU, instead of once a case)."""
    sc = load_scenario("cantilever_stiff_impact")
    length = sc.rig_params["length"]
    pos = [round(length * (k + 1) / n_sensors, 6) for k in range(n_sensors)]
    sc = sc.replace(rig_params={**sc.rig_params, "sensors": pos, "n_segments": max(10, 3 * n_sensors + 2)},
                    excitation={**sc.excitation, "location": pos[-1]},
                    simulation={**sc.simulation, "duration": 0.1,
                                "sample_rate": 51200.0 if n_sensors > 3 else 12800.0})
    return measure(dataset_cache.get(sc), sc.signal, sc.kind)


@pytest.mark.parametrize(("n_sensors", "name", "k"), [
    (2, "ls_sindy", 33),  # was LinAlgError in backbone_shift (dependent mode shapes)
    (5, "sgd_sindy", 60),  # was LinAlgError inverting the warm start's eigenvectors
    (5, "sgd_sindy", 140),  # was LinAlgError from eigh: the warm start's M not positive definite
])
def test_a_short_free_decay_after_a_long_record_ends_in_a_model_or_a_named_refusal(
        n_sensors, name, k, dataset_cache):
    """free_start k samples before the end of a 0.1 s record (the probe of session 16)."""
    data = _beam_record(n_sensors, dataset_cache)
    short = dataclasses.replace(data, free_start=data.n_samples - k)
    try:
        model = IDENTIFIERS.get(name)().fit(short)
    except IdentificationError:
        return
    assert model.is_fitted()
