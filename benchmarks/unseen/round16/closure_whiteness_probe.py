"""Probe (session 18, not a scorer): where ``find_closure``'s white branch is reached in
sindy_pi's fit, on rounds 14-16's five-bars.  Usage (repository root, PYTHONPATH=.):

    python benchmarks/unseen/round16/closure_whiteness_probe.py raw|default STUDY.toml ...

``raw``: the chain's ``cutoff_hz`` given 4430 Hz where it low-passes (the angles keep their white
noise); ``default``: the studies' chains.  The fit is stopped right after the closure.  One row
per cell: study, scenario, noise %, seed, fs, chain band [Hz], column cut-off [Hz], f (the band
the closure's angles carry over the Nyquist frequency), the whiteness of the true prior and of
priors with l1, l3, L0 1 % long (None: that prior does not reach the branch), note."""

import dataclasses
import sys

import identify.sindy_pi as sp
from identify._mechsim import LoopClosure
from testbed.core.errors import IdentificationError
from testbed.pipeline.cache import DatasetCache, default_cache_dir
from testbed.pipeline.signal_chain import measure
from testbed.scoring.run import make_identifier
from testbed.studies.study import load_study
from testbed.studies.sweep import expand


class Stop(Exception):
    pass


REC = {}


def branch(data, passive, prior):
    """None if find_closure's white branch is not reached with this prior, else its whiteness."""
    cl = LoopClosure.from_prior(prior, passive)
    if cl.residual(data.x) <= sp.CLOSURE_RTOL:
        return None
    res = cl.residual(data.x, rms=True)
    floor = LoopClosure.from_data(data.x, passive, strict=False).residual(data.x, rms=True)
    if res <= 2.0 * floor:
        return None
    try:
        LoopClosure.from_data(data.x, passive)
        return None
    except IdentificationError:
        return cl.whiteness(data.x)


def spy(data, passive):
    REC["true"] = branch(data, passive, data.prior)
    for k in ("l1", "l3", "L0"):
        REC[k] = branch(data, passive, {**data.prior, k: 1.01 * data.prior[k]})
    raise Stop


sp.find_closure = spy
cache = DatasetCache(default_cache_dir())
raw = sys.argv[1] == "raw"
for s in sys.argv[2:]:
    st = load_study(s)
    for c in expand(st):
        sc = c.scenario
        if sc.rig != "fivebar" or c.identifier != "sindy_pi":
            continue
        if raw and sc.signal.get("derivatives") == "lowpass":
            sc = dataclasses.replace(sc, signal={**sc.signal, "cutoff_hz": 4430.0})
        try:
            ds = cache.get(sc)
        except Exception as e:  # the rig refuses the motion: named, not probed
            print(st.name, sc.name, "refused", repr(e)[:80], sep="\t", flush=True)
            continue
        data = measure(ds, sc.signal, sc.kind)
        m = make_identifier(sc)
        REC.clear()
        try:
            m.fit(data)
            note = "no closure call"
        except Stop:
            note = "ok"
        except Exception as e:  # a probe records every outcome
            note = "raised " + repr(e)[:100]
        nyq = data.fs / 2
        band = data.passband[1] if data.passband is not None else nyq
        cut = getattr(m, "_knobs", None) and m._knobs.get("column_lowpass_hz")
        hi = min(band, cut) if cut else band
        cols = [st.name, sc.name, sc.noise.get("rms_percent"), sc.seed, f"{data.fs:g}", f"{band:g}",
                cut, f"{hi / nyq:.4g}", REC.get("true"), REC.get("l1"), REC.get("l3"), REC.get("L0"),
                note]
        print("\t".join(map(str, cols)), flush=True)
