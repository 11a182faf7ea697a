"""Sixteenth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile16 [family ...]      # all families when none is named
    HOSTILE16_ONLY=fivebar python -m benchmarks.hostile16 records   # the records named so

Families (combinations rounds 1-15 did not try):

``records``
    Valid-looking but degenerate measured records of every rig, exported to SEP-005 (or CSV)
    and given to ``testbed identify`` with *every* identifier of the rig's kind (in-process,
    :func:`testbed.cli.main`): 4, 10 and 20 samples after the impact, an all-zero force, a
    response channel replaced by a pure sine, a record that is all noise, the impact at the last
    sample, a constant input, the rate relabelled 1 Hz and 1 MHz, a CSV time base starting at
    ``t0 = 1e9`` s, a five-bar whose angles wrap past +-pi, a cart-pole whose pole angle (and
    its rate and acceleration) are in degrees under the unit ``rad``, a kinetics record of
    constant, sine or noise states.  An internal error, a traceback, a refusal in more than one
    line, NaN in the output without a reason, or a record whose content contradicts itself
    accepted with status 0 is a finding.
``studies``
    A study whose cells all fail (a hyperparameter no fit survives), ``summary`` and ``report``
    of its results; a results file of one study given to ``report``, ``summary`` and ``sweep
    --results`` of another; a sweep ended by SIGTERM and resumed with ``--jobs 2`` (its rows
    equal to an uninterrupted sweep's).
``runfolders``
    ``testbed runs`` / ``report`` / ``identify``-free reads of a run folder with its
    ``run.json``, model or dataset file missing, emptied, edited (verdict, scores, scenario,
    seed) or replaced by a folder: anything but a listing, a report or one refusal line, or an
    edit shown as if it were the run's, is a finding.
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

try:
    from benchmarks import _hostile
except ImportError:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks import _hostile

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 180

#: every identifier of each rig kind (``testbed list``)
IDENTIFIERS = {
    "structural": ["ls_sindy", "sgd_sindy", "sgd_sindy_coefficients", "sindy_pi_linear", "pysindy",
                   "pysindy_ensemble", "pysindy_sr3", "pysindy_weak"],
    "mechanical": ["sindy_pi", "pysindy_pi"],
    "dynamical": ["sindy_pi_dynamical"],
}
#: the shipped scenario each kind's records come from, and how many samples of it to keep
BASES = {"structural": ("cantilever_stiff_impact", None), "mechanical": ("fivebar_multisine", 20000),
         "cartpole": ("cartpole", None), "dynamical": ("michaelis_menten", None)}


def cli_inprocess(argv: list[str]) -> tuple[int, str, str]:
    """``testbed argv`` in this process: (status, stdout, stderr)."""
    from testbed import cli

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        status = cli.main(argv)
    return status, out.getvalue(), err.getvalue()


def judged(status: int, out: str, err: str, must_refuse: bool = False) -> str | None:
    """A finding of a finished in-process command, or None."""
    lines = [ln for ln in err.splitlines() if ln.strip()]
    if "Traceback" in err or "internal error" in err or status not in (0, 1, 2):
        return f"status {status}: {lines[-1][:240] if lines else ''}"
    if status == 2 and len([ln for ln in lines if ln.startswith("error")]) != 1:
        return f"refused in {len(lines)} lines: {err[:240]!r}"
    words = out.lower().replace(",", " ").replace("|", " ").split()
    if status == 0 and any(w in ("nan", "nan%", "+nan", "-nan") for w in words):
        return "NaN in the output of a model accepted with status 0"
    r2 = re.search(r"R\^2 of the predicted [a-z]+ \(truth-free\): (\S+)", out)
    if status == 0 and r2 and _float(r2.group(1)) < 0:
        return f"accepted with status 0, R^2 {r2.group(1)}: the model predicts worse than zero"
    if must_refuse and status == 0:
        tail = [ln for ln in out.splitlines() if ln.strip()][-3:]
        return f"accepted with status 0: {' / '.join(tail)[:240]}"
    return None


def _float(text: str) -> float:
    try:
        return float(text.rstrip(".,;"))
    except ValueError:
        return math.nan


# ------------------------------------------------------------------ records


def _base_records(work: Path) -> dict[str, tuple[list[dict], dict]]:
    """Each base's SEP-005 channel list (cut) and its dataset prior."""
    import testbed

    got = {}
    for key, (name, keep) in BASES.items():
        h5 = work / f"{name}.h5"
        js = work / f"{name}.json"
        if not js.exists():
            for argv in (["generate", name, "-o", str(h5)], ["export", str(h5), "--format", "sep005",
                                                              "-o", str(js)]):
                status, _, err = cli_inprocess(argv)
                if status:
                    raise RuntimeError(f"{argv}: {err}")
        chans = json.loads(js.read_text())
        if keep:
            for c in chans:
                c["data"] = c["data"][:keep]
        got[key] = (chans, dict(testbed.read_measured(h5).prior))
    return got


def _ch(chans: list[dict], suffix: str) -> dict:
    return next(c for c in chans if c["name"].endswith(suffix))


def _structural_mutations(chans: list[dict]) -> dict[str, tuple[list[dict], bool]]:
    """name -> (channels, must be refused)."""
    import numpy as np

    rng = np.random.default_rng(16)
    force = np.asarray(_ch(chans, "force")["data"])
    end = int(np.flatnonzero(force)[-1]) + 1
    fs = float(chans[0]["fs"])

    def edit(fn) -> list[dict]:
        new = json.loads(json.dumps(chans))
        fn(new)
        return new

    def cut(k: int):
        def f(new):
            for c in new:
                c["data"] = c["data"][:end + k]
        return f

    def setdata(suffix: str, values):
        def f(new):
            _ch(new, suffix)["data"] = [float(v) for v in values]
        return f

    n = force.size
    t = np.arange(n) / fs
    muts: dict[str, tuple[list[dict], bool]] = {}
    # after the pulse, the chain's free_margin_s (and the low-pass's settling) is added to the
    # pulse's end: a record cut a few samples after the pulse leaves 0..20 samples of free decay
    for k in (4, 10, 20, 40, 80):
        muts[f"{k} samples after the pulse"] = (edit(cut(k)), False)
    muts["force all zero"] = (edit(setdata("force", np.zeros(n))), False)
    muts["impact at the last sample"] = (edit(setdata("force", np.r_[np.zeros(n - 1), 50.0])), False)
    muts["impact at the first sample only"] = (edit(setdata("force", np.r_[50.0, np.zeros(n - 1)])), False)
    muts["constant force"] = (edit(setdata("force", np.full(n, 3.0))), False)
    muts["acc2 a pure sine"] = (edit(setdata("acc2", 50 * np.sin(2 * np.pi * 137.0 * t))), False)
    muts["all channels noise"] = (edit(lambda new: [c.__setitem__("data", rng.normal(size=n).tolist())
                                                    for c in new]), False)
    muts["responses noise, force kept"] = (
        edit(lambda new: [c.__setitem__("data", rng.normal(size=n).tolist())
                                                             for c in new if "acc" in c["name"]]), False)
    muts["acc3 a copy of acc1 plus 1e-9 noise"] = (
        edit(setdata("acc3", np.asarray(_ch(chans, "acc1")["data"])
                     * (1 + 1e-9 * rng.normal(size=n)))), False)
    muts["acc1 negated copy of acc2"] = (edit(setdata("acc1", -np.asarray(_ch(chans, "acc2")["data"]))), True)
    muts["fs relabelled 1 Hz"] = (edit(lambda new: [c.__setitem__("fs", 1.0) for c in new]), False)
    muts["fs relabelled 1 MHz"] = (edit(lambda new: [c.__setitem__("fs", 1e6) for c in new]), False)
    muts["fs relabelled 100 Hz"] = (edit(lambda new: [c.__setitem__("fs", 100.0) for c in new]), False)
    muts["force negative pulse"] = (edit(setdata("force", -force)), False)
    muts["record 3 samples long"] = (
        edit(lambda new: [c.__setitem__("data", c["data"][:3]) for c in new]), False)
    return muts


def _mechanical_mutations(chans: list[dict], cartpole: bool) -> dict[str, tuple[list[dict], bool]]:
    import numpy as np

    rng = np.random.default_rng(16)

    def edit(fn) -> list[dict]:
        new = json.loads(json.dumps(chans))
        fn(new)
        return new

    n = len(chans[0]["data"])
    muts: dict[str, tuple[list[dict], bool]] = {}
    if cartpole:
        def degrees(new):
            for suffix in ("/th", "/dth", "/ddth"):
                c = _ch(new, suffix)
                c["data"] = [v * 180 / math.pi for v in c["data"]]
        # consistent in degrees: no check of the record can tell (left to the identifier)
        muts["pole angle in degrees (rates too) labelled rad"] = (edit(degrees), False)

        def degrees_angle_only(new):
            c = _ch(new, "theta/th")
            c["data"] = [v * 180 / math.pi for v in c["data"]]
        muts["pole angle alone in degrees labelled rad"] = (edit(degrees_angle_only), True)
    else:
        def wrapped(new):  # the same angles, wrapped at their median: half of each jumps by 2 pi
            for c in new:
                if c["name"].startswith("theta/"):
                    cut = float(np.median(c["data"]))
                    c["data"] = [v - 2 * math.pi if v > cut else v for v in c["data"]]
        muts["angles wrapped (a cut at their median)"] = (edit(wrapped), True)

        def shifted(new):
            for c in new:
                if c["name"].startswith("theta/"):
                    c["data"] = [v + 2 * math.pi for v in c["data"]]
        muts["angles shifted by 2 pi"] = (edit(shifted), False)
    muts["inputs constant"] = (edit(lambda new: [c.__setitem__("data", [1.0] * n) for c in new
                                                 if c["name"].startswith("torque/")]), False)
    muts["inputs zero"] = (edit(lambda new: [c.__setitem__("data", [0.0] * n) for c in new
                                             if c["name"].startswith("torque/")]), False)
    muts["all noise"] = (
        edit(lambda new: [c.__setitem__("data", rng.normal(size=n).tolist()) for c in new]), False)

    def rates_copied(new):
        for c in new:
            if c["name"].startswith("dtheta/"):
                c["data"] = _ch(new, "theta/" + c["name"].split("/d")[-1])["data"]
    muts["rates the angles' copy"] = (edit(rates_copied), True)
    muts["fs relabelled 1 Hz"] = (edit(lambda new: [c.__setitem__("fs", 1.0) for c in new]), False)
    muts["fs relabelled 1 MHz"] = (edit(lambda new: [c.__setitem__("fs", 1e6) for c in new]), False)
    muts["20 samples"] = (edit(lambda new: [c.__setitem__("data", c["data"][:20]) for c in new]), False)
    muts["4 samples"] = (edit(lambda new: [c.__setitem__("data", c["data"][:4]) for c in new]), False)
    return muts


def _dynamical_mutations(chans: list[dict]) -> dict[str, tuple[list[dict], bool]]:
    import numpy as np

    rng = np.random.default_rng(16)
    n = len(chans[0]["data"])
    t = np.arange(n) / float(chans[0]["fs"])

    def edit(fn) -> list[dict]:
        new = json.loads(json.dumps(chans))
        fn(new)
        return new

    def states(x, dx):
        def f(new):
            _ch(new, "x/x")["data"] = [float(v) for v in x]
            _ch(new, "dx/dx")["data"] = [float(v) for v in dx]
        return f

    w = 2 * np.pi * 0.5
    return {
        "a pure sine state": (edit(states(1 + 0.5 * np.sin(w * t), 0.5 * w * np.cos(w * t))), False),
        "noise states": (edit(states(rng.normal(size=n), rng.normal(size=n))), False),
        "dx the negated rate": (edit(states(np.asarray(_ch(chans, "x/x")["data"]),
                                            -np.asarray(_ch(chans, "dx/dx")["data"]))), True),
        "4 samples": (edit(lambda new: [c.__setitem__("data", c["data"][:4]) for c in new]), False),
        "fs relabelled 1 Hz": (edit(lambda new: [c.__setitem__("fs", 1.0) for c in new]), False),
        "fs relabelled 1 MHz": (edit(lambda new: [c.__setitem__("fs", 1e6) for c in new]), False),
    }


def _csv_from(chans: list[dict], t0: float) -> str:
    fs = float(chans[0]["fs"])
    head = ["t [s]"] + [f"{c['name']} [{c['unit_str']}]" for c in chans]
    rows = [",".join(head)]
    for k in range(len(chans[0]["data"])):
        rows.append(",".join([repr(t0 + k / fs)] + [repr(c["data"][k]) for c in chans]))
    return "\n".join(rows) + "\n"


def record_cases(work: Path) -> list[tuple[str, object]]:
    bases = _base_records(work)
    cases = []

    def case(label: str, kind: str, method: str, chans: list[dict], prior: dict, must_refuse: bool,
             suffix: str = ".json", text: str | None = None, params: dict | None = None):
        def fn():
            f = work / f"r{abs(hash((label, method))) % 10**9}{suffix}"
            f.write_text(text if text is not None else json.dumps(chans))
            argv = ["identify", str(f), "--kind", kind, "--method", method,
                    "-o", str(f.with_suffix(".model.json"))]
            for k, v in prior.items():
                argv += ["--prior", f"{k}={v!r}"]
            for k, v in (params or {}).items():
                argv += ["--param", f"{k}={json.dumps(v)}"]
            return judged(*cli_inprocess(argv), must_refuse=must_refuse)
        return f"{label} / {method}", fn

    chans, prior = bases["structural"]
    # structural identifiers read reduced_mass_trace; the rest of the prior is not theirs
    sprior = {"reduced_mass_trace": prior["reduced_mass_trace"]}
    for label, (new, refuse) in _structural_mutations(chans).items():
        for m in IDENTIFIERS["structural"]:
            cases.append(case(f"cantilever: {label}", "structural", m, new, sprior, refuse))
    short = [dict(c, data=c["data"][:3000]) for c in chans]
    for t0 in (1e9, 1e6, -1e9):
        for m in ("ls_sindy", "sgd_sindy"):
            cases.append(case(f"cantilever CSV, t0 = {t0:g} s", "structural", m, short, sprior, False,
                              ".csv", _csv_from(short, t0)))
    from testbed.pipeline.scenario import load_scenario

    # the cart-pole's own library and input hold (the mechanical identifiers' default library is
    # the five-bar's, which a cart-pole record is refused for before any check of the record)
    cart = {k: v for k, v in load_scenario("cartpole").identify.items() if k in ("library", "input_hold")}
    for key in ("mechanical", "cartpole"):
        chans, prior = bases[key]
        for label, (new, refuse) in _mechanical_mutations(chans, key == "cartpole").items():
            for m in IDENTIFIERS["mechanical"]:
                cases.append(case(f"{BASES[key][0]}: {label}", "mechanical", m, new, {}, refuse,
                                  params=cart if key == "cartpole" else None))
    chans, prior = bases["dynamical"]
    for label, (new, refuse) in _dynamical_mutations(chans).items():
        cases.append(case(f"michaelis_menten: {label}", "dynamical", "sindy_pi_dynamical", new, {}, refuse))
    only = os.environ.get("HOSTILE16_ONLY")  # substrings (comma-separated) of the cases to run
    return [c for c in cases if not only or any(o in c[0] for o in only.split(","))]


# ------------------------------------------------------------------ run folders

def _edit_json(edit):
    def f(run: Path) -> None:
        meta = json.loads((run / "run.json").read_text())
        edit(meta)
        (run / "run.json").write_text(json.dumps(meta, indent=2))
    return f


def _flip(name: str, at: float):
    def f(run: Path) -> None:
        data = bytearray((run / name).read_bytes())
        data[int(len(data) * at)] ^= 0x10
        (run / name).write_bytes(bytes(data))
    return f


def _replace_by_folder(name: str):
    def f(run: Path) -> None:
        (run / name).unlink()
        (run / name).mkdir()
    return f


def _latest(name: str):
    def f(run: Path) -> None:
        (run.parent / "latest.json").write_text(json.dumps({"run": name, "created": "x", "seed": 0}))
    return f


#: name -> (damage to a run folder, whether the damaged run must be refused or left out)
RUN_DAMAGE = {
    "run.json missing": (lambda r: (r / "run.json").unlink(), True),
    "run.json empty": (lambda r: (r / "run.json").write_text(""), True),
    "run.json a folder": (_replace_by_folder("run.json"), True),
    "run.npz missing": (lambda r: (r / "run.npz").unlink(), True),
    "run.npz cut in half": (lambda r: (r / "run.npz").write_bytes(
        (r / "run.npz").read_bytes()[:(r / "run.npz").stat().st_size // 2]), True),
    "run.npz a bit flipped at 10 %": (_flip("run.npz", 0.1), True),
    "run.npz a bit flipped at 50 %": (_flip("run.npz", 0.5), True),
    "run.npz a bit flipped at 90 %": (_flip("run.npz", 0.9), True),
    "run.json a bit flipped at 50 %": (_flip("run.json", 0.5), True),
    "a score edited with its check": (_edit_json(lambda m: (
        m["scores"].__setitem__("coef_error", 2.0),
        [c.__setitem__("value", 2.0) for c in m["checks"] if c["metric"] == "coef_error"])), True),
    "every bar loosened to 1e9": (
        _edit_json(lambda m: [c.__setitem__("threshold", 1e9) for c in m["checks"]]), True),
    "scenario renamed": (_edit_json(lambda m: m["scenario"].__setitem__("name", "cartpole")), True),
    "seed edited": (_edit_json(lambda m: m["scenario"].__setitem__("seed", 7)), True),
    "seed text with an ESC": (_edit_json(lambda m: m["scenario"].__setitem__("seed", "x\x1b[31m")), True),
    "created a number": (_edit_json(lambda m: m.__setitem__("created", 5)), True),
    "figures outside the folder": (
        _edit_json(lambda m: m.__setitem__("figures", ["../../../etc/passwd"])), True),
    "fit_time -1": (_edit_json(lambda m: m.__setitem__("fit_time", -1.0)), True),
    "a check's bound 'between'": (
        _edit_json(lambda m: [c.__setitem__("bound", "between") for c in m["checks"]]), True),
    "a figure missing": (lambda r: next(r.glob("*.png")).unlink() if list(r.glob("*.png")) else None, False),
    "latest.json naming a missing run": (_latest("nope"), False),
    "latest.json naming ..": (_latest(".."), False),
    "latest.json naming /etc": (_latest("/etc"), False),
}


def runfolder_cases(work: Path) -> list[tuple[str, object]]:
    out = work / "runs"
    if not out.exists():
        status, _, err = cli_inprocess(["run", "michaelis_menten", "--out", str(out)])
        if status not in (0, 1):
            raise RuntimeError(err)
    src = next((out / "michaelis_menten").glob("2*"))
    cases = []
    for name, (damage, refused) in RUN_DAMAGE.items():
        def fn(name=name, damage=damage, refused=refused):
            root = work / f"d{abs(hash(name)) % 10**8}"
            shutil.rmtree(root, ignore_errors=True)
            shutil.copytree(out / "michaelis_menten", root / "michaelis_menten")
            run = root / "michaelis_menten" / src.name
            damage(run)
            found = []
            listed = cli_inprocess(["runs", "ls", "-o", str(root)])
            found.append(judged(*listed))
            # the listing reads run.json alone (verified); the arrays are verified where read
            arrays_only = name.startswith("run.npz") and "missing" not in name
            if refused and not arrays_only and src.name in listed[1]:
                found.append("listed as the run's own")
            elif refused and not arrays_only and src.name not in listed[2]:
                found.append("left out of the listing in silence")
            for argv in (["report", str(run), "-o", str(root / "rep")],
                         ["report", "michaelis_menten", "--runs", str(root), "-o", str(root / "rep2")]):
                status, o, e = cli_inprocess(argv)
                found.append(judged(status, o, e))
                if refused and status == 0 and argv[1] == str(run):
                    found.append("reported as the run's own")
            found = [f for f in found if f]
            return "; ".join(found) or None
        cases.append((f"run folder: {name}", fn))
    return cases


# ------------------------------------------------------------------ studies

STUDY = """[study]
name = "{name}"
scenarios = ["michaelis_menten"]
noise = [0.0, 1.0]
seeds = [0, 1]
identifiers = ["sindy_pi_dynamical"]
"""


def _rows(path: Path) -> dict[str, dict]:
    from testbed.studies.results import read_results

    drop = ("fit_time", "data_time", "cell_time", "row_sha256", "versions", "commit")
    return {r["cell"]: {k: v for k, v in r.items() if k not in drop} for r in read_results(path)}


def study_cases(work: Path) -> list[tuple[str, object]]:
    s16 = work / "s16.toml"
    s16.write_text(STUDY.format(name="s16"))
    fail = work / "fail16.toml"
    fail.write_text(STUDY.format(name="fail16").replace("noise = [0.0, 1.0]", "noise = [0.0]")
                    + "\n[thresholds.sindy_pi_dynamical]\ncoef_error_max = 1e-300\n")

    def all_fail():
        res = work / "fail16.parquet"
        found = [judged(*cli_inprocess(["sweep", str(fail), "--results", str(res)]))]
        status, out, err = cli_inprocess(["summary", str(res)])
        found.append(judged(status, out, err))
        if "0 % of 2" not in out:
            found.append("summary does not show 0 % of 2 passing")
        status, out, err = cli_inprocess(["report", str(res), "-o", str(work / "rep_fail")])
        found.append(judged(status, out, err))
        md = (work / "rep_fail" / "report.md").read_text() if status == 0 else ""
        if "0/2 (0 %)" not in md or "coef_error > 1e-300" not in md:
            found.append("report does not show every cell failing, and why")
        return "; ".join(f for f in found if f) or None

    def cross_study():
        ref = work / "fail16.parquet"
        found = []
        for argv in (["sweep", str(s16), "--results", str(ref)],):
            status, _, err = cli_inprocess(argv)
            if status != 2 or "holds rows of study 'fail16'" not in err:
                found.append(f"sweep of another study's results: status {status}")
        return "; ".join(found) or None

    def interrupted_then_two_jobs():
        res, ref = work / "int.parquet", work / "ref.parquet"
        proc = subprocess.Popen([sys.executable, "-m", "testbed.cli", "sweep", str(s16),
                                 "--results", str(res)],
                                cwd=work, env=_hostile.ENV, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                text=True)
        parts = Path(f"{res}.parts")
        t0 = time.monotonic()
        while time.monotonic() - t0 < 150 and not (parts.is_dir() and any(parts.glob("*.json"))):
            time.sleep(0.5)
        proc.send_signal(signal.SIGTERM)
        _, err = proc.communicate(timeout=60)
        if proc.returncode != 128 + signal.SIGTERM or "interrupted by SIGTERM" not in err:
            return f"SIGTERM: status {proc.returncode}, {err.strip().splitlines()[-1:]}"
        found = [judged(*cli_inprocess(["sweep", str(s16), "--jobs", "2", "--results", str(res)]))]
        found.append(judged(*cli_inprocess(["sweep", str(s16), "--jobs", "1", "--results", str(ref)])))
        a, b = _rows(res), _rows(ref)
        if a != b:
            found.append(f"resumed rows differ from an uninterrupted sweep's: "
                         f"{sorted(k for k in a.keys() | b.keys() if a.get(k) != b.get(k))}")
        return "; ".join(f for f in found if f) or None

    return [("a study whose cells all fail", all_fail),
            ("a sweep into another study's results", cross_study),
            ("a sweep ended by SIGTERM, resumed with --jobs 2", interrupted_then_two_jobs)]


FAMILIES = _hostile.families({
    "records": record_cases,
    "runfolders": runfolder_cases,
    "studies": study_cases,
}, TIMEOUT_S)


def main(argv: list[str]) -> int:
    os.environ.setdefault("TESTBED_NO_SERVER", "1")
    return _hostile.main(argv, FAMILIES, "hostile16-")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
