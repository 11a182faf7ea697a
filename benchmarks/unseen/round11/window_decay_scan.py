"""Round 11 (beams): which beam scenario files have a sensed mode 1-2 that dies out before the
free decay begins (the scorer's ``decayed`` reason, ``DECAYED_RATIO``), without simulating.

Not a test: prints each file whose mode 1 or 2 keeps less than 5 % of its amplitude at the
fit window's start, estimated from Euler-Bernoulli frequencies (``round5/truth_floor.py``),
the rig's stiffness-proportional damping (``zeta_k = zeta_1 f_k / f_1``) and the signal
chain's margin after the pulse (``free_margin_s`` or the low-pass's settling).  Measured
2026-11-27 on the 308 loadable beam files of benchmarks/unseen and scenarios/ and the 60
family members (written by ``testbed.studies.study.write_family``): below 0.01 only
round11/b11_z10_s2 (mode 2, 1.2e-3; the scorer's exact figure 1.3e-3) and round4/b_len0p05
(mode 2 above its Nyquist frequency, named out of band).

    PYTHONPATH=$PWD .venv/bin/python benchmarks/unseen/round11/window_decay_scan.py [FILE ...]
"""

from __future__ import annotations

import glob
import importlib.util
import math
import sys
from pathlib import Path

import numpy as np

from testbed.numerics import filters as sig
from testbed.numerics.shapes import slowest_decay_rate
from testbed.pipeline import signal_chain as chain
from testbed.pipeline.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[3]
_SPEC = importlib.util.spec_from_file_location("truth_floor", ROOT / "benchmarks" / "unseen" / "round5" /
                                               "truth_floor.py")
_FLOOR = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(_FLOOR)


def main(files: list[str]) -> None:
    n = 0
    for f in files:
        try:
            sc = load_scenario(f)
        except Exception:  # refusal cases (round 10's 3.2 kHz rigs, ...): not run
            continue
        if sc.kind != "structural" or sc.rig_params.get("E") is None:
            continue
        n += 1
        r, s, fs = sc.rig_params, sc.signal, float(sc.simulation["sample_rate"])
        k1 = r["base_k1"] if r["base"] == "soft" else np.inf
        eb = _FLOOR.eb_frequencies(r["E"], r["width"] * r["thickness"] ** 3 / 12,
                                   r["rho"] * r["width"] * r["thickness"], r["length"], k1, 2)
        w = 2 * np.pi * eb
        z = r["damping_ratio"] * eb / eb[0] if r["damping_ratio"] > 0 else r["damping_beta"] * w / 2
        margin = math.ceil(s["free_margin_s"] * fs)
        if s["lowpass_hz"] > 0:
            margin = max(margin, sig.lowpass_settling(fs, s["lowpass_hz"], s["lowpass_order"],
                                                      chain.LOWPASS_SETTLE_TOL))
        rate = slowest_decay_rate(w, z)
        left = np.exp(-rate * margin / fs)[: min(2, len(r["sensors"]) or 3)]
        if np.any(left < 0.05):
            print(f"{f}: left {np.round(left, 5)}, zeta {np.round(z[:2], 3)}, "
                  f"margin {1e3 * margin / fs:.2f} ms", flush=True)
    print(f"{n} beam files")


if __name__ == "__main__":
    main(sys.argv[1:] or sorted(glob.glob(str(ROOT / "benchmarks" / "unseen" / "*" / "*.toml"))
                                + glob.glob(str(ROOT / "scenarios" / "*.toml"))))
