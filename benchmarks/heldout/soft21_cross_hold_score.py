"""Issue #15 verdicts with mode 2 held at the cross-held decay fit (an oracle bound, not a rule).

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/soft21_cross_hold_score.py STUDY.toml \
        PREFIX [NOISE] [IDENT]

Each member is run as the sweep runs it (:func:`testbed.scoring.run.run_scenario`), once as it
is and once with the fitted model's mode 2 moved (:func:`identify._modal_damping.set_eigenvalues`,
shapes kept) to the frequency of mode 2's decay fit with the cross term held at the truth's
ratio (:func:`soft21_cross_hold.held_fit`; the truth's ``R`` is what no identifier has: this
bounds what a rule that knew it could gain).  The move is made only where the held fit lies
within 5 % of the model's mode 2 (it followed that mode).  Prints both verdicts per member.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import scipy.linalg as sla

from identify._modal_damping import _decay_fit, chain_transients, set_eigenvalues
from identify.structural import modal
from testbed.pipeline import plugins
from testbed.pipeline.cache import DatasetCache
from testbed.scoring.run import run_scenario
from testbed.studies.study import load_study
from testbed.studies.sweep import expand

sys.path.insert(0, str(Path(__file__).parent))
from soft21_cross_hold import held_fit
from tally import issue_verdict

KEEP = ("trac", "mac_mode1", "mac_mode2", "freq_error_mode1", "freq_error_mode2")


def hold_mode2(mod, data, R: float) -> str:
    """Move ``mod``'s mode 2 to the cross-held decay fit's frequency; what was done."""
    fm, Phi = modal(mod.M_, mod.K_)
    s = int(data.free_start)
    qdd = np.linalg.solve(Phi, np.asarray(data.xdd, float)[:, s:])
    t = np.arange(qdd.shape[1]) / data.fs
    nu = chain_transients(getattr(data, "chain_poles", None), t)
    d = np.einsum("ik,ij,jk->k", Phi, mod.C_, Phi)
    w = 2 * np.pi * fm
    s1, wd1, _, ok1, c1, _ = _decay_fit(qdd[0], t, 0.5 * d[0], w[0], True, nu)
    se, *_ = _decay_fit(qdd[1], t, 0.5 * d[1], w[1], False, nu)
    n2 = int(min(t.size, np.log(1e3) / max(se, 1e-9) * data.fs))
    t2, nu2 = t[:n2], (None if nu is None else nu[:n2])
    extra = R * (w[1] / wd1) * c1 * (-np.expm1(-2 * s1 * t2)) / (2 * s1)
    sh, wdh = held_fit(qdd[1, :n2], t2, w[1], se, extra, nu2)
    w2 = float(np.hypot(sh, wdh))
    if not (ok1 and abs(w2 / w[1] - 1) <= 0.05):
        return f"not moved ({w2 / w[1] - 1:+.3%})"
    lam = np.full(len(fm), np.nan)
    lam[1] = w2 * w2
    mod.K_ = set_eigenvalues(mod.M_, mod.K_, lam)
    mod.natural_frequencies_, mod.modes_ = modal(mod.M_, mod.K_)
    return f"moved {w2 / w[1] - 1:+.3%}"


def main() -> None:
    study, prefix = sys.argv[1], sys.argv[2]
    noise = float(sys.argv[3]) if len(sys.argv) > 3 else 0.0
    ident = sys.argv[4] if len(sys.argv) > 4 else "ls_sindy"
    cache = DatasetCache(Path.cwd() / ".cache" / "datasets")
    for cell in expand(load_study(study)):
        sc = cell.scenario
        if not sc.name.startswith(prefix) or cell.noise != noise or cell.identifier != ident:
            continue
        tr = cache.get(sc).typed_truth
        lam, phi = sla.eigh(tr.Kr, tr.Mr)
        b = np.asarray(tr.cubic_map, float) @ phi
        R = 2 * (b[1] / b[0]) ** 2 * lam[0] / lam[1]
        out = []
        for oracle in (False, True):
            mod = plugins.make_identifier(sc.identify, sc.name)
            what = ""
            if oracle:
                fit0 = mod.fit

                def fit(data, fit0=fit0, mod=mod, R=R):
                    fit0(data)
                    nonlocal what
                    try:
                        what = hold_mode2(mod, data, R)
                    except Exception as e:
                        what = f"not moved ({type(e).__name__})"
                    return mod

                mod.fit = fit
            res = run_scenario(sc, cache=cache, model=mod)
            row = {k: float(res.scores.values.get(k, np.nan)) for k in KEEP}
            row.update(status="ok", error="", rig=sc.rig, noise=noise)
            ok, why = issue_verdict(row)
            out.append(f"{'PASS' if ok else 'fail'} {why} f2 {100 * row['freq_error_mode2']:.2f}"
                       f" TRAC {row['trac']:.3f} {what}")
        print(f"{sc.name}\t{ident}\t{noise}\t" + "\t|\t".join(out), flush=True)


if __name__ == "__main__":
    main()
