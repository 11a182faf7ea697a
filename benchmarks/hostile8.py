"""Eighth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case runs in-process; it is a *finding* when it ends in anything but one error line naming
the file (a :class:`~testbed.core.errors.TestbedError`, status 2 at the command line) or a
verdict: another exception (an internal error), a hang past its timeout, a line of several
lines, or -- for a scenario that runs -- a NaN score without a failure naming its reason, or a
pass with a NaN score or a failure.  Run from the repository root::

    python -m benchmarks.hostile8 [family ...]      # all families when none is named

Families: ``datasets`` (a hand-made dataset file edited and saved again, so its content hash
is right: rate NaN, 0, -1, 5e-324, 1e300; samples NaN, inf, 1e300, 5e-324, zero; channels cut
to 0, 1 or half their samples, repeated or without units; positions of the wrong length, NaN
or 1e300; priors NaN, negative, text; each read for ``identify`` and exported to UFF and
SEP-005), ``terms`` (library and ``lhs`` terms of a mechanical and a dynamical scenario:
malformed, index 0, powers of 1e9, the other kinds' names; loaded and run), ``extremes``
(every number, choice and switch of ``[rig]``, ``[simulation]``,
``[excitation]``, ``[noise]``, ``[signal]`` and ``[identify]`` of five shipped scenarios set
to finite extremes -- 1e300, -1e300, 1e-300, 5e-324, -0.0, 0, 1e15, -1, 1e-15 for numbers,
0, -1, 2**53 + 1, 2**62, 1e9 for integers, every allowed word, both switches -- loaded, and
run on a shortened record when accepted).
Prints one line a finding and the counts; exits 1 if any finding.  ``extremes`` takes about
an hour on one core (about 1,100 loads, 500 of them run).
"""

from __future__ import annotations

import copy
import math
import sys
from collections import Counter
from pathlib import Path

from benchmarks import _hostile

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 120  # a case longer than this is a hang (the slowest run below takes about 20 s)

#: Shipped scenarios whose keys are set to extremes, and the record each is cut to [s] so that
#: a case runs in seconds (a cut too short for a setting is itself refused in one line).
BASES = {"michaelis_menten": 4.0, "cartpole": 1.0, "fivebar_multisine": 1.0,
         "cantilever_stiff_impact_lsq": 0.2, "cantilever_stiff_impact": 0.2}
FLOATS = [1e300, -1e300, 1e-300, -1e-300, 5e-324, -0.0, 0.0, 1e15, -1.0, 1e-15]
INTS = [0, -1, 2**53 + 1, 2**62, 10**9]
FLOAT_LISTS = [[], [1e300], [5e-324, 1e300], [-0.0, -0.0], [0.0, 1e-300]]


# ------------------------------------------------------------------ datasets

#: Edits a reader or exporter may take (finite values; whether they can be identified is the
#: signal chain's question, not the reader's); every other edit must be refused.
MAY_PASS = ("fs=1e+300", "samples ", "unit unknown", "channels repeated", "positions 1e300",
            "positions repeated", "prior 1e300", "no force")


def dataset_cases(work: Path) -> list[tuple[str, object]]:
    """An edited, rehashed dataset file read for ``identify`` and exported to both formats."""
    import numpy as np

    from testbed.core.dataset import Dataset, Signal
    from testbed.pipeline.importers import read_measured
    from testbed.reporting.export import export_dataset

    fs = 1000.0
    t = np.arange(400) / fs

    def base() -> Dataset:
        acc = np.vstack([np.sin(2 * np.pi * 7 * t) * (k + 1) for k in range(3)])
        return Dataset(fs, {"acceleration": Signal(acc, ("acc1", "acc2", "acc3"), "m/s^2",
                                                   np.array([0.1, 0.2, 0.3])),
                            "force": Signal(np.exp(-t / 0.01)[None, :], ("force",), "N",
                                            np.array([0.3]))},
                       prior={"total_mass": 0.7})

    def data(sig, fn):
        def edit(d):
            d.measured[sig].data = fn(d.measured[sig].data)
        return edit

    def attr(sig, name, value):
        def edit(d):
            setattr(d.measured[sig], name, value)
        return edit

    at5 = lambda v: (lambda a: np.where(np.arange(a.shape[1]) == 5, v, a))  # noqa: E731
    edits = {f"fs={v!r}": (lambda d, v=v: setattr(d, "fs", v))
             for v in (math.nan, math.inf, 0.0, -1.0, 5e-324, 1e300)}
    edits.update({
        "sample nan": data("acceleration", at5(np.nan)), "sample -inf": data("acceleration", at5(-np.inf)),
        "samples x1e300": data("acceleration", lambda a: a * 1e300),
        "samples x5e-324": data("acceleration", lambda a: a * 5e-324),
        "samples zero": data("acceleration", lambda a: a * 0),
        "samples int": data("acceleration", lambda a: (a * 1000).astype(np.int64)),
        "samples float16": data("acceleration", lambda a: a.astype(np.float16)),
        "cut to 0": data("acceleration", lambda a: a[:, :0]),
        "cut to 1": data("acceleration", lambda a: a[:, :1]),
        "cut to half": data("acceleration", lambda a: a[:, :200]),
        "force cut": data("force", lambda a: a[:, :100]),
        "no measured": lambda d: d.measured.clear(),
        "no force": lambda d: d.measured.pop("force"),
        "unit empty": attr("acceleration", "unit", ""),
        "unit unknown": attr("acceleration", "unit", "furlong"),
        "channels repeated": attr("acceleration", "channels", ("a", "a", "a")),
        "positions 1 of 3": attr("acceleration", "positions", np.array([0.1])),
        "positions nan": attr("acceleration", "positions", np.array([np.nan, 0.2, 0.3])),
        "positions 1e300": attr("acceleration", "positions", np.array([0.1, 0.2, 1e300])),
        "positions repeated": attr("acceleration", "positions", np.array([0.2, 0.2, 0.2])),
        "force 2 rows 1 position": lambda d: (attr("force", "data", np.vstack([np.exp(-t / 0.01)] * 2))(d),
                                              attr("force", "channels", ("f1", "f2"))(d)),
        "prior nan": lambda d: d.prior.update(total_mass=math.nan),
        "prior -1": lambda d: d.prior.update(total_mass=-1.0),
        "prior text": lambda d: d.prior.update(total_mass="heavy"),
        "prior 1e300": lambda d: d.prior.update(reduced_mass_trace=1e300),
    })
    d_dir = work / "datasets"
    d_dir.mkdir(exist_ok=True)
    cases = []
    for i, (name, edit) in enumerate(edits.items()):
        path = d_dir / f"case{i:02d}.h5"

        def make(path=path, edit=edit):
            if not path.exists():
                ds = base()
                edit(ds)
                ds.save(path)  # a new content hash: the file is consistent with itself
            return path

        refuse = not name.startswith(MAY_PASS)

        def read(make=make, refuse=refuse):
            read_measured(make()).to_dataset()
            return "accepted, expected refused" if refuse else None

        def export(fmt, make=make, out=d_dir / f"out{i:02d}", refuse=refuse):
            export_dataset(make(), fmt, out.with_suffix(f".{fmt}"))
            return "written, expected refused" if refuse else None

        cases.append((f"identify-read {name}", read))
        cases += [(f"export {fmt} {name}", lambda fmt=fmt, export=export: export(fmt))
                  for fmt in ("uff", "sep005")]
    return cases


# ------------------------------------------------------------------ extremes

def _sections(raw: dict):
    from testbed.pipeline.plugins import IDENTIFIERS, RIGS
    from testbed.pipeline.scenario import NOISE_SCHEMA
    from testbed.pipeline.signal_chain import SIGNAL_SCHEMAS

    rig = RIGS.get(raw["scenario"]["rig"])
    etype = raw.get("excitation", {}).get("type", rig.default_excitation)
    yield "rig", rig.rig_schema
    yield "simulation", rig.simulation_schema
    yield "excitation", rig.excitation_schemas[etype]
    yield "noise", NOISE_SCHEMA
    yield "signal", SIGNAL_SCHEMAS[rig.kind]
    if raw.get("identify"):
        yield "identify", IDENTIFIERS.get(raw["identify"]["method"]).hyperparameters


def _values(f) -> list:
    if f.choices is not None:
        return list(f.choices)
    if f.type is float:
        return FLOATS
    if f.type is int:
        return INTS
    if f.type is bool:
        return [True, False]
    if f.type is list and f.item_type is float:
        return FLOAT_LISTS
    return []


def _run(raw: dict, base: str) -> str | None:
    from testbed.pipeline.scenario import scenario_from_dict
    from testbed.scoring.run import run_scenario

    return _hostile.scored_finding(run_scenario(scenario_from_dict(raw, file="x.toml", stem=base)))


def extreme_cases() -> list[tuple[str, object]]:
    from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml

    cases = []
    for base, cut in BASES.items():
        raw0 = _read_toml(SCENARIO_DIR / f"{base}.toml")
        raw0["scenario"].pop("extends", None)
        if "duration" in raw0["simulation"]:
            raw0["simulation"]["duration"] = min(raw0["simulation"]["duration"], cut)
        for section, schema in list(_sections(raw0)):
            for key, f in schema.items():
                for value in _values(f):
                    raw = copy.deepcopy(raw0)
                    raw.setdefault(section, {})[key] = value
                    cases.append((f"{base}: {section}.{key} = {value!r}",
                                  lambda raw=raw, base=base: _run(raw, base)))
    return cases


#: Library terms added to a shipped library (or given as its ``lhs``): malformed, out of the
#: data's range, of huge powers, of the other kinds' names.
TERMS = ["sin(th2", "th0", "th3", "u0", "u2", "th1^0", "th1^-1", "th1^1e300", "th1^99999",
         "th1^999999999", "th1^2.5", "th1^3", "*".join(["dth1"] * 200), "ddth1*ddth2", "ddth1^2",
         "1", "0", "", " ", "ddth1 ", "DDTH1", "sin(sin(th2))", "sin(th0)", "cos(th1-th0)",
         "cos(th2)^2*ddth1", "exp(th1)", "th1/th2", "th1**2", "thé", "dth2^2", "u1^2", "x1",
         "v1", "a1", "x", "dx", "y", "x^99999", "x^200*dx", "dx^2", "ddx"]


def term_cases() -> list[tuple[str, object]]:
    """Each of :data:`TERMS` added to the library of a mechanical (cart-pole, sindy_pi) and a
    dynamical (Michaelis-Menten, sindy_pi_dynamical) scenario, and given as their ``lhs``."""
    from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml

    cases = []
    for base, cut in (("cartpole", 2.0), ("michaelis_menten", 4.0)):
        raw0 = _read_toml(SCENARIO_DIR / f"{base}.toml")
        raw0["simulation"]["duration"] = cut
        library = raw0["identify"].get("library") or ["1", "x", "dx", "x*dx", "x^2*dx", "x^2"]
        for term in TERMS:
            for key, value in (("library", [*library, term]), ("lhs", [term])):
                raw = copy.deepcopy(raw0)
                raw["identify"]["library"] = list(library)
                raw["identify"][key] = value
                cases.append((f"{base}: identify.{key} with {term[:40]!r}",
                              lambda raw=raw, base=base: _run(raw, base)))
    return cases


def run_inprocess(cases) -> Counter:
    """Each case returns a finding's description or None (a verdict, or refused in one line)."""
    return _hostile.run_inprocess(cases, TIMEOUT_S, lambda finding: finding)


def main(argv: list[str]) -> int:
    return _hostile.main(argv, {
        "datasets": lambda work: run_inprocess(dataset_cases(work)),
        "terms": lambda work: run_inprocess(term_cases()),
        "extremes": lambda work: run_inprocess(extreme_cases()),
    }, "hostile8-")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
