"""Session 25 (pi27): a motion-defined automatic cut-off for clean records, measured, not adopted.

The candidate (docs/known-gaps.md, "A motion-defined clean cut-off measured against the
review's corners"): the chain's cut-off is the larger of the harmonic rule
(:func:`testbed.pipeline.signal_chain.auto_cutoff`) and the lowest cut-off that passes the
angles' band end ``F`` with 99 % amplitude (``harmonic_cutoff(F, order, harmonic=1)``), where

- the noise level of a channel is ``sqrt(noise_std^2 + (q^2 / 12))``: the 4th-difference
  estimate plus the record's quantisation, ``q`` the lattice step where every sample-to-sample
  step is a whole number of the smallest (an encoder), else the float spacing of the channel's
  largest magnitude (a large offset's own resolution);
- the level the band end is judged against is that noise level, at least ``R0`` (1e-6, SINDy-PI's
  exact-data level ``NOISE_FREE_REL``) of the channel's RMS about its mean: the chain resolves
  the motion to that level and no finer, so a clean record and one with noise below it are
  judged alike;
- ``F`` = the lowest frequency above which the motion's variance is at most that level squared,
  or no longer significant against the noise floor (``signal_band``'s test): read on the
  periodogram of the angles' 4th difference tapered by Hann cubed (the low tones' window
  leakage suppressed by ``(f0 / f)^8`` and ``k^-18``), divided back by the difference's gain,
  and summed from the top (no difference of large sums).

No threshold switches it: the noisy limit is the harmonic rule (F falls below twice the band).

Usage::

    PYTHONPATH=CHECKOUT .venv/bin/python benchmarks/heldout/pi27_cutoff_probe.py guards [--lobe]
    PYTHONPATH=CHECKOUT .venv/bin/python benchmarks/heldout/pi27_cutoff_probe.py run TOML SEED \
        NOISE [signal.KEY=VALUE ...] [identify.KEY=VALUE ...]

``guards`` runs the six corners of ``tests/testbed/pipeline/test_mechanical_noise_declared.py``
(review 24d) with ``auto_cutoff`` replaced by the candidate (``--lobe``: ``F`` read one main
lobe of the taper lower); ``run`` runs one scenario at a seed and noise level with settings
overridden (values Python literals) and prints its verdict and SINDy-PI's noise rule.
"""

from __future__ import annotations

import ast
import dataclasses
import importlib.util
import sys
from pathlib import Path

import numpy as np

import testbed
from testbed.numerics import derivatives as der
from testbed.numerics import noise as ne
from testbed.scoring.run import run_scenario

#: Relative level below which the chain does not resolve the motion (NOISE_FREE_REL).
R0 = 1e-6
#: Order of the prewhitening difference (the noise estimate's).
DIFF_ORDER = 4
#: Power of the Hann taper: sidelobes fall as k^-(3 HP) in power (Hann: k^-6).
HANN_POWER = 3
#: Significance of the power left above the band end (noise.SIGNIFICANCE_Z).
Z = ne.SIGNIFICANCE_Z
#: Pass the band end with this amplitude gain (derivatives.CUTOFF_GAIN, 99 %).
GAIN = der.CUTOFF_GAIN


def quantisation_std(x: np.ndarray) -> np.ndarray:
    """``q / sqrt(12)`` per row [unit of x]: ``q`` the lattice step of a quantised row (every
    nonzero step a whole number of the smallest), else the float spacing of its largest
    magnitude; shape (n_channels,)."""
    out = []
    for r in np.atleast_2d(np.asarray(x, dtype=float)):
        steps = np.abs(np.diff(r))
        steps = steps[steps > 0]
        q = float(np.spacing(np.max(np.abs(r))))
        if steps.size:
            s = float(steps.min())
            k = steps / s
            if s > q and np.all(np.abs(k - np.round(k)) <= 64 * q / s * np.maximum(k, 1)):
                q = s
        out.append(q / np.sqrt(12.0))
    return np.array(out)


def band_end(x: np.ndarray, fs: float, noise: np.ndarray, level: np.ndarray,
             lobe: bool = False) -> np.ndarray:
    """The candidate's ``F`` per row [Hz] (module docstring); ``noise`` and ``level`` per row
    [unit of x]; ``lobe``: read one main lobe of the taper (HANN_POWER + 1 bins) lower."""
    a = np.atleast_2d(np.asarray(x, dtype=float))
    d = np.diff(a, n=DIFF_ORDER, axis=1)
    m = d.shape[1]
    w = np.hanning(m) ** HANN_POWER
    sw = float(np.sum(w**2))
    P = np.abs(np.fft.rfft((d - d.mean(axis=1, keepdims=True)) * w, axis=1)) ** 2
    f = np.fft.rfftfreq(m, 1.0 / fs)
    gain = (2.0 * np.sin(np.pi * f / fs)) ** (2 * DIFF_ORDER)
    k_above = np.arange(f.size - 1, -1, -1, dtype=float)
    var = ne.window_var(w) * k_above + (ne.FLOOR_REL_ERR * k_above) ** 2 / m
    out = np.zeros(a.shape[0])
    for r in range(a.shape[0]):
        Q = np.zeros(f.size)
        Q[1:] = P[r, 1:] / gain[1:] - noise[r] ** 2 * sw
        tail = np.concatenate([np.cumsum(Q[::-1])[::-1][1:], [0.0]])  # above each bin, from the top
        ok = (2.0 * tail / (m * sw) <= level[r] ** 2) | (tail <= Z * noise[r] ** 2 * sw * np.sqrt(var))
        out[r] = f[max(int(np.argmax(ok)) - (HANN_POWER + 1 if lobe else 0), 1)]
    return out


def candidate_cutoff(theta: np.ndarray, fs: float, order: int, lobe: bool = False) -> float:
    """The candidate's automatic cut-off [Hz] of raw angles ``theta`` (n_joints, n_samples)."""
    x = np.atleast_2d(np.asarray(theta, dtype=float))
    s4 = ne.noise_std(x)
    band = float(ne.signal_band(x, fs, 0.999, s4).max(initial=0.0))
    harmonic = der.harmonic_cutoff(band, order)
    rms = x.std(axis=1)
    noise = np.sqrt(s4**2 + quantisation_std(x) ** 2)
    F = band_end(x, fs, noise, np.maximum(noise, R0 * rms), lobe)
    passes = der.harmonic_cutoff(float(F.max()), order, harmonic=1.0, gain=GAIN)
    return max(harmonic, min(passes, 0.45 * fs))


def guards(lobe: bool) -> None:
    """Review 24d's six corners with ``auto_cutoff`` replaced by the candidate."""
    path = (Path(__file__).resolve().parents[2] / "tests" / "testbed" / "pipeline"
            / "test_mechanical_noise_declared.py")
    spec = importlib.util.spec_from_file_location("corners", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    mod.auto_cutoff = lambda th, fs, order, noise=None: candidate_cutoff(th, fs, order, lobe)
    for name, args in [("test_auto_cutoff_is_continuous_in_the_noise_level", ()),
                       ("test_auto_cutoff_counts_an_encoders_quantisation_as_noise", (12,)),
                       ("test_auto_cutoff_counts_an_encoders_quantisation_as_noise", (14,)),
                       ("test_auto_cutoff_does_not_depend_on_the_records_length", ()),
                       ("test_auto_cutoff_of_a_float_angle_with_a_large_offset", ()),
                       ("test_auto_cutoff_on_the_down_branch_multisine_near_clean", ())]:
        try:
            getattr(mod, name)(*args)
            print("PASS", name, *args)
        except AssertionError as exc:
            print("FAIL", name, *args, str(exc)[:200])


def run(argv: list[str]) -> None:
    """One scenario at a seed and noise level with settings overridden."""
    sc = testbed.load_scenario(argv[0])
    sig, ide = dict(sc.signal), dict(sc.identify)
    for kv in argv[3:]:
        key, value = kv.split("=", 1)
        (sig if key.startswith("signal.") else ide)[key.split(".", 1)[1]] = ast.literal_eval(value)
    sc = dataclasses.replace(sc, seed=int(argv[1]), noise={**sc.noise, "rms_percent": float(argv[2])},
                             signal=sig, identify=ide)
    res = run_scenario(sc)
    s = res.scores.values
    print(f"{sc.name} s{sc.seed} {argv[2]}% {' '.join(argv[3:])}: {'PASS' if res.passed else 'fail'} "
          f"angle_rmse {s.get('angle_rmse', float('nan')):.3g} {(res.failure or '')[:150]}")
    print("   ", getattr(res.model, "noise_rule_", ""))


if __name__ == "__main__":
    if sys.argv[1] == "guards":
        guards("--lobe" in sys.argv)
    else:
        run(sys.argv[2:])
