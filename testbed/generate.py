"""Scenario -> Dataset: the named rig simulates, then seeded sensor noise and provenance."""

from __future__ import annotations

import copy
from collections.abc import Callable

import numpy as np

from testbed.dataset import Dataset, Signal
from testbed.provenance import git_commit, versions
from testbed.scenario import Scenario


def add_noise(data: np.ndarray, rms_percent: float, rng: np.random.Generator) -> np.ndarray:
    """White Gaussian noise with standard deviation ``rms_percent`` % of each row's RMS.

    The RMS is taken about the channel's mean: an absolute joint angle's offset depends only on
    where its zero is put (1.78 rad for the five-bar's th1 against a +-0.4 rad motion), so noise
    scaled with the total RMS would depend on a coordinate choice.  For zero-mean signals such
    as accelerations the two are the same.

    Parameters
    ----------
    data : ndarray, shape (n_channels, n_samples)
    rms_percent : float
        Noise standard deviation as a percentage of the noise-free channel's RMS about its mean.
    rng : numpy Generator
    """
    if rms_percent == 0:
        return data.copy()
    rms = np.std(data, axis=1, keepdims=True)
    return data + rng.standard_normal(data.shape) * (rms_percent / 100.0) * rms


def noise_free_scenario(scenario: Scenario) -> Scenario:
    """The same simulation without sensor noise (seed 0): what :func:`generate` can start from."""
    return scenario.replace(noise={**scenario.noise, "rms_percent": 0.0}, seed=0)


def generate(scenario: Scenario, progress: Callable[[float], None] | None = None,
             clean: Dataset | None = None) -> Dataset:
    """Simulate ``scenario`` with its rig and add its sensor noise.

    The seed drives only the noise: another seed changes the measured signals of
    ``scenario.noise["signals"]`` and nothing else.  The noise-free measured
    signals are kept in ``reference`` under the same names.

    Parameters
    ----------
    clean : Dataset, optional
        The dataset of :func:`noise_free_scenario` of ``scenario``; given, the rig is not run
        again and the result is bit-identical to a fresh simulation (noise is added to the
        same noise-free arrays with the same generator).
    """
    from models import RIGS

    if clean is None:
        ds = RIGS.get(scenario.rig)(scenario).simulate(progress=progress)
    else:
        if clean.attrs.get("data_hash") != noise_free_scenario(scenario).data_hash():
            raise ValueError("the clean dataset belongs to another simulation than this scenario")
        ds = copy.deepcopy(clean)
        for name in scenario.noise["signals"]:  # restore what the rig produced
            ds.measured[name] = ds.reference.pop(name)
    rng = np.random.default_rng(scenario.seed)
    for name in scenario.noise["signals"]:
        clean = ds.measured[name]
        ds.reference.setdefault(name, Signal(clean.data.copy(), clean.channels, clean.unit,
                                             clean.positions))
        ds.measured[name] = Signal(add_noise(clean.data, scenario.noise["rms_percent"], rng),
                                   clean.channels, clean.unit, clean.positions)
    ds.attrs.update(rig=scenario.rig, seed=scenario.seed, scenario=scenario.to_dict(),
                    scenario_name=scenario.name, data_hash=scenario.data_hash(),
                    versions=versions(), git_commit=git_commit())
    ds.attrs["content_hash"] = ds.content_hash()
    return ds
