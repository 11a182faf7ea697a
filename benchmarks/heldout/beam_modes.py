"""Signed mode-1/2 frequency errors of every beam cell of a family study, for the cause classes.

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/beam_modes.py \
        benchmarks/heldout/families_heldout.toml > out.tsv

Runs each beam cell (default settings, as the sweep) and prints one line per cell: member,
identifier, noise, signed frequency errors of modes 1-2 [%], true damping of modes 1-2,
the model's cubic force ratio and the member's cubic fraction (soft base), TRAC and the
truth's own reduced-model TRAC (the scorer's floor), and the identifier's failure if any.
"""

from __future__ import annotations

import sys

import numpy as np

from testbed.pipeline.cache import DatasetCache
from testbed.scoring.run import run_scenario
from testbed.studies.study import load_study
from testbed.studies.sweep import expand


def main(study_path: str, cache: str = ".cache") -> None:
    cells = [c for c in expand(load_study(study_path)) if c.scenario.rig == "cantilever"]
    print("member\tidentifier\tnoise\tdf1_%\tdf2_%\tzeta1\tzeta2\tK3_force_ratio\ttrac\t"
          "truth_trac\tfailure")
    for c in cells:
        res = run_scenario(c.scenario, cache=DatasetCache(cache))
        d, v = res.scores.details, res.scores.values
        f_id, f_true = np.asarray(d.get("f_id", [])), np.asarray(d.get("f_true", []))
        z_true = np.asarray(d.get("z_true", [np.nan, np.nan]))
        pair = np.asarray(d.get("pair", [-1, -1]))
        df = [100 * (f_id[pair[k]] / f_true[k] - 1) if k < pair.size and pair[k] >= 0 else np.nan
              for k in (0, 1)]
        floor = np.min(d["truth_trac"]) if "truth_trac" in d else np.nan
        print(f"{c.scenario.name}\t{c.identifier}\t{c.noise:g}\t{df[0]:+.2f}\t{df[1]:+.2f}\t"
              f"{z_true[0]:.3f}\t{z_true[1]:.3f}\t{v.get('K3_force_ratio', np.nan):.3g}\t"
              f"{v.get('trac', np.nan):.3f}\t{floor:.3f}\t{res.failure or ''}", flush=True)


if __name__ == "__main__":
    main(*sys.argv[1:])
