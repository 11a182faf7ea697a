"""Perturbation round 16: valid but untuned inputs, drawn by a seeded generator.

Each case takes a shipped scenario (``scenarios/*.toml``), changes one to three things within
physical ranges (beam length, segments, sensors, soft base k1 / k3, damping, hammer force or
place, record length, sample rate, noise 0.5-5 %, seed; five-bar geometry or input amplitude;
cart-pole masses and length; Michaelis-Menten Km / Vmax / jx / x0) and swaps the identifier for
another one of the rig's kind (``testbed list``).  Each case is written as a scenario file under
``benchmarks/unseen/perturb16/`` (it ``extends`` the shipped file, so it can be re-run alone) and
run through the console script (``testbed run FILE -o OUT --no-figures``) with a 240 s limit (a
hang).  One summary line per case (tab-separated) goes to stdout and to
``benchmarks/unseen/perturb16/summary.tsv``.

A case's simulation cost is capped by the draw itself (beam records <= 2 s, <= 20 segments,
five-bar records <= 3 s), so a case takes well under 40 s for the fast identifiers.

Run from the repository root::

    python benchmarks/perturb16.py --write          # write the case files only
    python benchmarks/perturb16.py --run [--from K] # write and run (sequential, one process)
"""

from __future__ import annotations

import argparse
import json
import os
import random
import subprocess
import sys
import time
import tomllib
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT_DIR = ROOT / "benchmarks" / "unseen" / "perturb16"
SEED = 16
N_CASES = 120

KIND_IDENTIFIERS = {
    "cantilever": ["ls_sindy", "sgd_sindy", "sgd_sindy_coefficients", "sindy_pi_linear", "pysindy",
                   "pysindy_sr3", "pysindy_ensemble", "pysindy_weak"],
    "fivebar": ["sindy_pi", "pysindy_pi"],
    "cartpole": ["sindy_pi", "pysindy_pi"],
    "michaelis_menten": ["sindy_pi_dynamical"],
}
#: [identify] keys a swapped-in identifier keeps from the shipped scenario when it declares them
#: (a researcher swapping sindy_pi for pysindy_pi keeps the library)
CARRY = ("library", "input_hold", "sim_dt", "cubic", "degree", "formulation", "weak_window_s",
         "weak_windows")


def _fmt(v: object) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, float):
        return repr(float(f"{v:.4g}"))
    if isinstance(v, list):
        return "[" + ", ".join(_fmt(x) for x in v) + "]"
    return str(v)


def _merged(path: Path) -> dict:
    raw = tomllib.loads(path.read_text())
    parent = raw.get("scenario", {}).get("extends")
    if parent:
        base = _merged((path.parent / parent).resolve())
        for k, v in raw.items():
            if isinstance(v, dict) and k in base and k not in ("identify", "score"):
                base[k] = {**base[k], **v}
            else:
                base[k] = v
        return base
    return raw


#: Draws every rig shares: option -> (table, key, draw(rng)); the case name gets ``{option}{value}``
_COMMON = {
    "noise": ("noise", "rms_percent", lambda rng: round(rng.uniform(0.5, 5.0), 2)),
    "seed": ("scenario", "seed", lambda rng: rng.randint(1, 999)),
}


def _set(rng: random.Random, ch: dict, opt: str, spec: tuple) -> str:
    """Draw ``spec``'s value into ``ch[table][key]``; the case name's part."""
    table, key, draw = spec
    v = draw(rng)
    ch[table][key] = v
    return f"{opt}{v}"


def _draw_beam(rng: random.Random, sc: dict, ch: dict, ident: str) -> list[str]:
    rig, sim, exc = sc["rig"], sc["simulation"], sc["excitation"]
    what = []
    options = ["length", "segments", "sensors", "damping", "force", "place", "duration", "rate",
               "noise", "seed", "base"]
    for opt in rng.sample(options, rng.randint(1, 3)):
        if opt == "length":
            L = round(rng.uniform(0.15, 0.8), 3)
            scale = L / rig["length"]
            ch["rig"]["length"] = L
            if rig.get("sensors"):
                ch["rig"]["sensors"] = [round(s * scale, 4) for s in rig["sensors"]]
            if exc.get("location", 0.0):
                ch["excitation"]["location"] = round(exc["location"] * scale, 4)
            what.append(f"L{L}")
        elif opt == "segments":
            n = rng.randint(6, 20)
            ch["rig"]["n_segments"] = n
            what.append(f"n{n}")
        elif opt == "sensors":
            L = ch["rig"].get("length", rig["length"])
            k = rng.randint(2, 5)
            ch["rig"]["sensors"] = [round(L * (i + 1) / k, 4) for i in range(k)]
            what.append(f"s{k}")
        elif opt == "damping":
            z = round(10 ** rng.uniform(-3, -1.7), 4)
            ch["rig"]["damping_ratio"] = z
            what.append(f"z{z}")
        elif opt == "force":
            f = round(10 ** rng.uniform(1, 2.3), 1)
            ch["excitation"]["peak_force"] = f
            what.append(f"f{f}")
        elif opt == "place":
            L = ch["rig"].get("length", rig["length"])
            loc = round(L * rng.uniform(0.4, 1.0), 4)
            ch["excitation"]["location"] = loc
            what.append(f"h{loc}")
        elif opt == "duration":
            d = round(rng.uniform(0.3, 2.0), 2)
            ch["simulation"]["duration"] = d
            what.append(f"d{d}")
        elif opt == "rate":
            fs = rng.choice([6400.0, 25600.0])
            ch["simulation"]["sample_rate"] = fs
            what.append(f"fs{fs:g}")
        elif opt in _COMMON:
            what.append(_set(rng, ch, opt, _COMMON[opt]))
        elif opt == "base":
            if rig.get("base") == "soft":
                k1 = round(10 ** rng.uniform(2.9, 3.9), 0)
                k3 = float(f"{10 ** rng.uniform(8, 10):.3g}")
                ch["rig"]["base_k1"], ch["rig"]["base_k3"] = k1, k3
                what.append(f"k1_{k1:g}_k3_{k3:g}")
            else:
                z = round(10 ** rng.uniform(-3, -1.7), 4)
                ch["rig"]["damping_ratio"] = z
                what.append(f"z{z}")
    # sensors drawn before a new length are laid out on the new length (same count)
    if "length" in ch["rig"] and "sensors" in ch["rig"] and \
            max(ch["rig"]["sensors"]) > ch["rig"]["length"]:
        L, k = ch["rig"]["length"], len(ch["rig"]["sensors"])
        ch["rig"]["sensors"] = [round(L * (i + 1) / k, 4) for i in range(k)]
    # the rig takes the hammer at the tip or on a sensor (its force must be measured where a
    # sensor sits): a drawn place is moved to the nearest sensor, as a researcher would
    loc = ch["excitation"].get("location")
    if loc:
        L = ch["rig"].get("length", rig["length"])
        sensors = ch["rig"].get("sensors") or rig.get("sensors") or [L / 3, 2 * L / 3, L]
        if "length" in ch["rig"] and not ch["rig"].get("sensors") and not rig.get("sensors"):
            sensors = [L / 3, 2 * L / 3, L]
        ch["excitation"]["location"] = round(min(sensors, key=lambda s: abs(s - loc)), 4)
    # cost cap: the slow identifiers get at most 1 s of record
    if ident.startswith("sgd_sindy") or ident == "pysindy_ensemble":
        if ch["simulation"].get("duration", sim["duration"]) > 1.0:
            ch["simulation"]["duration"] = 1.0
            what.append("d1cap")
    return what


def _draw_fivebar(rng: random.Random, sc: dict, ch: dict) -> list[str]:
    what = []
    for opt in rng.sample(["geometry", "amplitude", "duration", "noise", "seed", "mass"],
                          rng.randint(1, 3)):
        if opt == "geometry":
            key = rng.choice(["l1", "l2", "l3", "l4", "L0"])
            v = round(rng.uniform(0.8, 1.25), 3)
            ch["rig"][key] = v
            what.append(f"{key}_{v}")
        elif opt == "amplitude":
            a = sc["excitation"]["amplitude"] * round(rng.uniform(0.5, 1.5), 2)
            ch["excitation"]["amplitude"] = round(a, 4)
            what.append(f"amp{a:.3g}")
        elif opt == "duration":
            d = round(rng.uniform(3.0, 10.0), 1)
            ch["simulation"]["duration"] = d
            what.append(f"d{d}")
        elif opt in _COMMON:
            what.append(_set(rng, ch, opt, _COMMON[opt]))
        elif opt == "mass":
            key = rng.choice(["m1", "m2", "m3", "m4"])
            v = round(rng.uniform(0.5, 2.0), 2)
            ch["rig"][key] = v
            what.append(f"{key}_{v}")
    # cost cap: a five-bar record at 1e-4 s costs ~8 s of simulation per second recorded
    if ch["simulation"].get("duration", sc["simulation"]["duration"]) > 3.0:
        ch["simulation"]["duration"] = 3.0
        what.append("d3cap")
    return what


#: The cart-pole's and the kinetics' draws, in the order the options are sampled from
_CARTPOLE = {
    "cart_mass": ("rig", "cart_mass", lambda rng: round(rng.uniform(0.5, 3.0), 2)),
    "pole_mass": ("rig", "pole_mass", lambda rng: round(rng.uniform(0.1, 2.0), 2)),
    "pole_length": ("rig", "pole_length", lambda rng: round(rng.uniform(0.3, 1.5), 2)),
    "amplitude": ("excitation", "amplitude", lambda rng: round(rng.uniform(0.5, 3.0), 2)),
    **_COMMON,
}
_MM = {
    "Km": ("rig", "Km", lambda rng: round(10 ** rng.uniform(-1, 0.5), 3)),
    "Vmax": ("rig", "Vmax", lambda rng: round(rng.uniform(1.0, 5.0), 2)),
    "jx": ("rig", "jx", lambda rng: round(rng.uniform(0.2, 0.9), 2)),
    "x0": ("rig", "x0", lambda rng: round(rng.uniform(0.5, 5.0), 2)),
    **_COMMON,
}


def _draw_table(table: dict) -> Callable[[random.Random, dict, dict], list[str]]:
    """A rig's drawer: one to three of ``table``'s options, each drawn into its key."""
    def draw(rng: random.Random, sc: dict, ch: dict) -> list[str]:
        return [_set(rng, ch, opt, table[opt]) for opt in rng.sample(list(table), rng.randint(1, 3))]
    return draw


_draw_cartpole = _draw_table(_CARTPOLE)
_draw_mm = _draw_table(_MM)


def draw_cases(n: int = N_CASES, seed: int = SEED) -> list[tuple[str, str, dict]]:
    """The round's cases: (name, scenario file text, {"base", "identifier", "what"})."""
    rng = random.Random(seed)
    shipped = sorted((ROOT / "scenarios").glob("*.toml"))
    cases = []
    for i in range(n):
        path = rng.choice(shipped)
        sc = _merged(path)
        rig = sc["scenario"]["rig"]
        base_ident = sc.get("identify", {}).get("method")
        others = [m for m in KIND_IDENTIFIERS[rig] if m != base_ident] or KIND_IDENTIFIERS[rig]
        ident = rng.choice(others)
        ch: dict[str, dict] = {t: {} for t in ("scenario", "rig", "simulation", "excitation",
                                                "noise")}
        if rig == "cantilever":
            what = _draw_beam(rng, sc, ch, ident)
        else:
            what = {"fivebar": _draw_fivebar, "cartpole": _draw_cartpole,
                    "michaelis_menten": _draw_mm}[rig](rng, sc, ch)
        name = f"p16_{i:03d}_{path.stem}_{ident}"
        ident_table = {"method": ident}
        for k in CARRY:
            if k in sc.get("identify", {}) and _declares(ident, k):
                ident_table[k] = sc["identify"][k]
        lines = [f"# Perturbation round 16, case {i}: {path.stem} with {', '.join(what)}; "
                 f"identifier {ident} (shipped: {base_ident})", "", "[scenario]",
                 f'extends = "../../../scenarios/{path.name}"', f'name = "{name}"',
                 f'description = "Perturbation round 16: {path.stem}, {" ".join(what)}, {ident}"']
        lines += [f"{k} = {_fmt(v)}" for k, v in ch["scenario"].items()]
        for table in ("rig", "simulation", "excitation", "noise"):
            if ch[table]:
                lines += ["", f"[{table}]"] + [f"{k} = {_fmt(v)}" for k, v in ch[table].items()]
        lines += ["", "[identify]"] + [f"{k} = {_fmt(v)}" for k, v in ident_table.items()]
        cases.append((name, "\n".join(lines) + "\n",
                      {"base": path.stem, "identifier": ident, "what": " ".join(what)}))
    return cases


_DECLARED: dict[str, set] = {}


def _declares(ident: str, key: str) -> bool:
    if ident not in _DECLARED:
        sys.path.insert(0, str(ROOT))
        from testbed import IDENTIFIERS
        _DECLARED[ident] = set(IDENTIFIERS.get(ident).declared_hyperparameters())
    return key in _DECLARED[ident]


def _run(name: str, out: Path) -> str:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "OMP_NUM_THREADS": "1",
           "OPENBLAS_NUM_THREADS": "1", "TESTBED_NO_SERVER": "1"}
    exe = ROOT / ".venv" / "bin" / "testbed"
    t0 = time.perf_counter()
    try:
        p = subprocess.run([str(exe), "run", str(OUT_DIR / f"{name}.toml"), "-o", str(out),
                            "--no-figures"], capture_output=True, text=True, env=env, timeout=240,
                           cwd=ROOT)
        rc, so, se = p.returncode, p.stdout, p.stderr
    except subprocess.TimeoutExpired:
        rc, so, se = "HANG", "", ""
    wall = time.perf_counter() - t0
    verdict = "?"
    for line in so.splitlines():
        if "verdict" in line.lower() or line.startswith(("PASS", "FAIL")):
            verdict = line.strip()[:160]
    tail = (se.strip().splitlines() or [""])[-1][:300]
    return f"{name}\trc={rc}\t{wall:.1f}s\t{verdict}\t{tail}"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true")
    ap.add_argument("--run", action="store_true")
    ap.add_argument("--from", dest="start", type=int, default=0)
    ap.add_argument("--out", default="/tmp/perturb16_runs")
    ap.add_argument("--exclude", default="", help="skip cases whose name has this text")
    ap.add_argument("--only", default="", help="run only cases whose name has this text")
    a = ap.parse_args()
    OUT_DIR.mkdir(parents=True, exist_ok=True)
    cases = draw_cases()
    for name, text, _meta in cases:
        (OUT_DIR / f"{name}.toml").write_text(text)
    if a.run:
        with open(OUT_DIR / "summary.tsv", "a") as f:
            for name, _, _meta in cases[a.start:]:
                if (a.exclude and a.exclude in name) or (a.only and a.only not in name):
                    continue
                line = _run(name, Path(a.out))
                print(line, flush=True)
                f.write(line + "\n")
                f.flush()


if __name__ == "__main__":
    main()
