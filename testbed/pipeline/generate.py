"""Scenario -> Dataset: the named rig simulates without noise, then seeded sensor noise and provenance.

Every dataset is made in two steps, whichever path asks for it:

1. :func:`simulate_clean` runs the rig on :func:`noise_free_scenario` of the scenario (the
   seed and the noise level do not reach the simulation), giving the *clean* dataset;
2. :func:`derive` adds the scenario's noise to the clean arrays with the scenario's seed.

:func:`generate` does both; the dataset cache (:mod:`testbed.pipeline.cache`) stores step 1 once per
rig configuration and runs step 2 on load.  Since step 2 is one function of (clean arrays,
noise spec, seed) and computes its statistics over C-ordered rows (see
:class:`~testbed.core.dataset.Signal`), both paths give bit-identical data.
"""

from __future__ import annotations

import copy
from collections.abc import Callable

import numpy as np

from testbed.core.dataset import Dataset, Signal
from testbed.core.errors import RigError, TestbedError, exception_text
from testbed.core.provenance import git_commit, versions
from testbed.core.rate_attrs import off_scenario_rate
from testbed.core.truth import TruthError
from testbed.pipeline.plugins import RIGS, rig_class
from testbed.pipeline.scenario import Scenario


def add_noise(data: np.ndarray, rms_percent: float, rng: np.random.Generator) -> np.ndarray:
    """White Gaussian noise with standard deviation ``rms_percent`` % of each row's RMS.

    The RMS is taken about the channel's mean: an absolute joint angle's offset depends only on
    where its zero is put (1.78 rad for the five-bar's th1 against a +-0.4 rad motion), so noise
    scaled with the total RMS would depend on a coordinate choice.  For zero-mean signals such
    as accelerations the two are the same.

    The statistics are computed on a C-ordered float64 copy, so the result depends on the
    values of ``data`` only, never on its memory layout (numpy sums a contiguous row pairwise
    and a strided one in another order, which differ in the last bit).

    Parameters
    ----------
    data : ndarray, shape (n_channels, n_samples)
    rms_percent : float
        Noise standard deviation as a percentage of the noise-free channel's RMS about its mean.
    rng : numpy Generator
    """
    data = np.ascontiguousarray(data, dtype=np.float64)
    if rms_percent == 0:
        return data.copy()
    rms = np.std(data, axis=1, keepdims=True)
    return data + rng.standard_normal(data.shape) * (rms_percent / 100.0) * rms


def noise_free_scenario(scenario: Scenario) -> Scenario:
    """The same simulation without sensor noise (seed 0): what :func:`derive` starts from."""
    return scenario.replace(noise={**scenario.noise, "rms_percent": 0.0}, seed=0)


def _stamp(ds: Dataset, scenario: Scenario) -> Dataset:
    ds.attrs.update(rig=scenario.rig, seed=scenario.seed, scenario=scenario.to_dict(),
                    scenario_name=scenario.name, data_hash=scenario.data_hash())
    ds.attrs["content_hash"] = ds.content_hash()
    return ds


def _simulate_rig(scenario: Scenario, progress: Callable[[float], None] | None) -> Dataset:
    """The rig of ``scenario`` built and run.  Any exception of a user's plugin rig (not a
    built-in one, whose exception is a testbed bug and stays one) becomes a :class:`RigError`
    naming the rig and its file, as a plugin identifier's does in its fit
    (:func:`testbed.pipeline.fit.fit_or_fail`): a plugin rig given ``n_samples = 2**62`` raised
    numpy's "array is too big", an internal error "please report it"."""
    origin = RIGS.origin(scenario.rig)
    try:
        return RIGS.get(scenario.rig)(scenario).simulate(progress=progress)
    except TestbedError:
        raise
    except (Exception, SystemExit) as e:
        if origin == "builtin":
            raise
        raise RigError(f"rig {scenario.rig} (from {origin}) raised {type(e).__name__}: "
                       f"{exception_text(e)}") from None


def record_problem(ds: Dataset, scenario: Scenario) -> str | None:
    """How ``ds``'s rate or length differs from the record ``scenario`` asks for, or None.

    The record is :meth:`Rig.record` of the rig's noise-free ``[simulation]`` table (rate [Hz]
    and number of samples; the default ``round(duration * sample_rate)`` samples); a rig that
    declares none is not checked.  The rate is compared within
    :data:`~testbed.core.rate_attrs.SCENARIO_RATE_RTOL` (a rate written as a float), the
    number of samples exactly (a count).  One rule for both places a dataset is read:
    :func:`simulate_clean` (the rig's contract) and the dataset cache (an edited entry).

    Parameters
    ----------
    ds : Dataset
        A clean dataset of ``scenario``'s rig.
    scenario : Scenario
        The scenario it records.

    Returns
    -------
    str or None
        E.g. ``"holds 1001 samples; its scenario records 1000"``.
    """
    record = rig_class(scenario.rig).record(noise_free_scenario(scenario).simulation)
    if record is None:
        return None
    fs, n = float(record[0]), int(record[1])
    if off_scenario_rate(float(ds.fs), fs):
        return f"has fs={ds.fs!r} Hz; its scenario records at {fs!r} Hz"
    if ds.measured and ds.n_samples != n:
        return f"holds {ds.n_samples} samples; its scenario records {n}"
    return None


def simulate_clean(scenario: Scenario, progress: Callable[[float], None] | None = None) -> Dataset:
    """The rig's noise-free dataset of ``scenario``: the clean dataset :func:`derive` starts from.

    The rig runs :func:`noise_free_scenario` of ``scenario``; the noisy signals' noise-free
    arrays are kept in ``reference`` under the same names, as in every dataset.  The dataset
    records the rig's kind (``attrs["kind"]``) and its truth is validated against the kind's
    declaration (:mod:`testbed.core.truth`).

    Raises
    ------
    RigError
        If the rig's truth has a missing, unknown or misshapen key (named), or its dataset's
        rate or number of samples is not the record :meth:`Rig.record` declares
        (:func:`record_problem`; review 29a M1: a plugin rig of ``round(duration * fs) + 1``
        samples was accepted here, then its cache entry refused on every read).
    """

    clean_sc = noise_free_scenario(scenario)
    ds = _simulate_rig(clean_sc, progress)
    problem = record_problem(ds, clean_sc)
    if problem:  # the Rig.simulate contract: the record Rig.record declares, sample for sample
        raise RigError(f"rig {clean_sc.rig!r} (from {RIGS.origin(clean_sc.rig)}) simulated a "
                       f"dataset that {problem} "
                       "(Rig.simulate must record Rig.record's rate and number of samples)")
    ds.attrs["kind"] = clean_sc.kind
    # one order whichever path made the dataset: HDF5 hands groups back sorted by name, a rig
    # writes them in its own (a run's npz and report tables listed truth and prior keys in one
    # order when simulated, in another when read from the cache)
    ds.truth, ds.truth_units, ds.prior = (dict(sorted(d.items()))
                                          for d in (ds.truth, ds.truth_units, ds.prior))
    try:  # the rig's truth must be its kind's declared truth (testbed.core.truth)
        ds.check_truth()
    except TruthError as e:
        raise RigError(f"rig {clean_sc.rig!r} wrote a truth that does not fit its kind: {e}") from None
    ds.attrs.update(versions=versions(), git_commit=git_commit())
    return derive(ds, clean_sc)


def derive(clean: Dataset, scenario: Scenario) -> Dataset:
    """``scenario``'s dataset from the clean dataset of the same simulation: seeded noise added.

    A pure function of (``clean``'s arrays, ``scenario.noise``, ``scenario.seed``): the
    generator is ``default_rng(seed)``, drawn signal by signal in ``noise["signals"]`` order.
    The noise-free array of each noisy signal is ``clean.reference[name]`` if there, else
    ``clean.measured[name]`` (a raw rig output); it is kept in ``reference[name]``.

    Parameters
    ----------
    clean : Dataset
        Of :func:`simulate_clean` (or a raw rig simulation of :func:`noise_free_scenario`).
    scenario : Scenario
        Gives the noise spec and seed, and the provenance recorded in ``attrs``.

    Raises
    ------
    ValueError
        If ``clean`` records a simulation other than ``scenario``'s.
    """
    want = noise_free_scenario(scenario).data_hash()
    have = clean.attrs.get("data_hash")
    if have is not None and have not in (want, scenario.data_hash()):
        raise ValueError("the clean dataset belongs to another simulation than this scenario")
    ds = copy.deepcopy(clean)
    rng = np.random.default_rng(scenario.seed)
    for name in scenario.noise["signals"]:
        raw = ds.reference.get(name, ds.measured[name])
        ds.reference[name] = Signal(raw.data.copy(), raw.channels, raw.unit, raw.positions,
                                    raw.acts_on)
        ds.measured[name] = Signal(add_noise(raw.data, scenario.noise["rms_percent"], rng),
                                   raw.channels, raw.unit, raw.positions, raw.acts_on)
    return _stamp(ds, scenario)


def generate(scenario: Scenario, progress: Callable[[float], None] | None = None,
             clean: Dataset | None = None) -> Dataset:
    """Simulate ``scenario`` with its rig and add its sensor noise.

    The seed drives only the noise: another seed changes the measured signals of
    ``scenario.noise["signals"]`` and nothing else.  The noise-free measured
    signals are kept in ``reference`` under the same names.

    Parameters
    ----------
    scenario : Scenario
        What to simulate: rig, simulation, excitation, noise and seed.
    progress : callable, optional
        ``progress(fraction)`` with the fraction of the simulation done, in [0, 1].
    clean : Dataset, optional
        The clean dataset of ``scenario`` (:func:`simulate_clean`); given, the rig is not run
        again.  Either way the result is :func:`derive` of the same clean arrays, so it is
        bit-identical.

    Returns
    -------
    Dataset
        The measured signals with the scenario's seeded noise, the noise-free ones in
        ``reference``, the exact truth and the provenance.
    """
    if clean is None:
        clean = simulate_clean(scenario, progress)
    return derive(clean, scenario)
