"""Twenty-eighth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case ends ``ok`` or as a *finding* (the harness, ``benchmarks/_hostile.py``): anything but a
verdict, an output, or one error line naming what is wrong.  Run from the repository root::

    python -m benchmarks.hostile28 [family ...]      # all families when none is named

Families (what rounds 1-27 did not try; their families are listed in ``hostile21.py`` to
``hostile27.py``):

``apiwalk``
    Every public callable of the Python API (``testbed.__all__``, *walked*, so a name added later
    is tried without an edit here) called with one odd value in each of its parameters in turn,
    the others left at their defaults or, where required, given a plain valid value from one
    kinetics run (:func:`_valid_values`; a case whose callable needs a value it has none for is
    not tried: the truth classes, ``SignalChain``): None, True, 0, -1, NaN, "", a
    5,000-character text, bytes, a list, a dict, an ``object()``, a missing path, a folder, a
    NaN array.  An exception other than the testbed's one-line
    errors (``TestbedError``: ``ArgumentError``, ``InputError``, ...) is a finding; so is a
    refusal of more than one line.  Not called: the registering functions (``register_*``),
    the registries, ``run_sweep`` and the error classes.
``plugstate``
    A ``--plugin`` identifier of the kinetics (a subclass of ``sindy_pi_dynamical``) that, in
    its ``fit``, writes into the measurement it was given (before or after fitting), into its
    prior, turns warnings into errors, changes numpy's print options, its random state,
    ``os.environ``, the recursion limit, or prints to standard output; and one that returns NaN,
    infinite or wrongly shaped coefficients.  Each is run (``run_scenario``) and, for the
    state-changing ones, a plain ``sindy_pi_dynamical`` cell is run after it in the same
    process and in one sequential sweep: a verdict that is not one (a traceback, NaN
    passing), or a plain cell whose scores differ from a lone plain run's (the plugin's change
    leaked into the next cell), or a write into the data that changes the writer's own scores
    after its fit, is a finding.
``reportout``
    ``testbed report -o DIR`` of a results file and of a run (with and without its figures)
    into a folder holding an earlier report, with one of the files the report writes replaced
    by the user's own (a text, a JPEG head, a markdown of the user's whose title begins as a
    report's: ``# Study notes`` / ``# Run notes``).  A refused command that changed any file
    of the folder (all outputs must be checked before any is written), or an accepted one
    that replaced the user's file, is a finding.
``csvorder``
    The kinetics record as CSV with its columns in another order (time last, dx before x),
    a column twice (equal, or with other values), time as Unix epoch seconds, in minutes
    declared, descending, and a channel named with the other's unit.  Read to another model
    than the plain file's, or anything but a model or one error line, is a finding.

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import hashlib
import inspect
import json
import math
import os
import shutil
import sys
from pathlib import Path

try:
    from benchmarks import _hostile, hostile19
except ImportError:  # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
    from benchmarks import _hostile, hostile19

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 240
MM = hostile19.MM
CACHE = hostile19.CACHE
cli_inprocess = _hostile.cli_inprocess
judged = _hostile.judged


# ------------------------------------------------------------------ apiwalk

def _odd_values(work: Path) -> dict[str, object]:
    import numpy as np

    (work / "adir").mkdir(exist_ok=True)
    return {
        "None": None, "True": True, "0": 0, "-1": -1, "NaN": float("nan"), "empty text": "",
        "a long text": "x" * 5000, "bytes": b"\x00\xff", "a list": [1, "a", None],
        "a dict": {"a": [1]}, "an object": object(), "a missing path": work / "missing" / "x.toml",
        "a folder": work / "adir", "a NaN array": np.array([np.nan, 1.0]),
    }


def _valid_values(work: Path) -> dict[str, object]:
    """A plain valid value for a required parameter, by name (a parameter without one: the
    odd value's case is not tried), from one run of the kinetics."""

    import testbed
    from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml

    h5 = str(hostile19._generated(work, MM))
    result = testbed.run_scenario(MM, cache=str(CACHE))
    data = result.data
    return {"name": MM, "scenario": MM, "source": MM, "path": h5, "name_or_path": MM,
            "study": str(ROOT / "studies" / "smoke.toml"), "kind": "dynamical",
            "out_dir": str(work / "runs"), "plugins": [], "raw": _read_toml(SCENARIO_DIR / f"{MM}.toml"),
            "result": result, "dataset": result.dataset, "data": data, "model": result.model,
            "scores": result.scores, "checks": [], "fit_time": 0.1, "values": {"x": 1.0},
            "fs": data.fs, "measured": result.dataset.measured, "x": data.x, "xd": data.xd,
            "xdd": data.xdd, "channels": list(data.channels), "signal_cfg": {}, "n_windows": 2,
            "rig": MM, "scenarios": [MM], "noise": [0.0], "seeds": [0],
            "identifiers": ["sindy_pi_dynamical"], "type": float, "shape": (1,), "unit": "m",
            "doc": "a length"}


#: Valid values that differ by callable (a Signal's ``data`` is its samples, not a Measurement).
def _valid_for(name: str, valid: dict[str, object]) -> dict[str, object]:
    import numpy as np

    if name == "Signal":
        return {**valid, "data": np.zeros((1, 8)), "channels": ["a"]}
    return valid


def apiwalk_cases(work: Path) -> list[tuple[str, object]]:
    import testbed
    from testbed.core.errors import TestbedError

    cases = []
    odd = _odd_values(work)
    state: dict = {}
    skip = {"run_sweep", "TestbedError", "IdentificationError", "ArgumentError", "NotFittedError"}

    def valid() -> dict:
        if "v" not in state:
            state["v"] = _valid_values(work)
        return state["v"]

    def case(name: str, param: str, label: str):
        def run():
            fn = getattr(testbed, name)
            sig = inspect.signature(fn)
            kwargs = {}
            for p in sig.parameters.values():
                if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
                    continue
                if p.name == param:
                    kwargs[p.name] = odd[label]
                elif p.default is p.empty:
                    given = _valid_for(name, valid())
                    if p.name not in given:
                        return None  # no plain value to give: not tried
                    kwargs[p.name] = given[p.name]
            here = os.getcwd()
            os.chdir(work)
            try:
                fn(**kwargs)
            except TestbedError:
                raise
            except TypeError as e:
                # Python's own signature errors (a keyword the callable does not take) are not the
                # subject; a TypeError from inside is
                if "unexpected keyword" in str(e) or "positional argument" in str(e):
                    return None
                raise
            finally:
                os.chdir(here)
            return None
        return run

    for name in testbed.__all__:
        if name in skip or name.startswith("_"):
            continue
        obj = getattr(testbed, name)
        if not callable(obj) or name.startswith("register") or name in ("IDENTIFIERS", "RIGS"):
            continue
        try:
            sig = inspect.signature(obj)
        except (TypeError, ValueError):
            continue
        for p in sig.parameters.values():
            if p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD) or p.name in ("self", "cls"):
                continue
            for label in odd:
                cases.append((f"apiwalk {name}({p.name}={label})", case(name, p.name, label)))
    return cases


# ------------------------------------------------------------------ plugstate

_PLUGIN = """from testbed import IDENTIFIERS
import numpy as np
Base = IDENTIFIERS.get("sindy_pi_dynamical")

@IDENTIFIERS.register("NAME")
class P(Base):
    name = "NAME"

    def fit(self, data, *args, **kwargs):
        #BEFORE
        out = super().fit(data, *args, **kwargs)
        #AFTER
        return out
#METHODS
"""


def _scenario(work: Path, method: str) -> Path:
    from testbed.pipeline.scenario import SCENARIO_DIR

    p = work / f"{method}.toml"
    p.write_text(f'[scenario]\nname = "{method}"\nextends = "{SCENARIO_DIR / (MM + ".toml")}"\n'
                 f'[identify]\nmethod = "{method}"\ndegree = 3\n')
    return p


def _scores(result) -> dict:
    return {k: v for k, v in result.scores.values.items() if isinstance(v, float)}


def _same(a: dict, b: dict) -> bool:
    return a.keys() == b.keys() and all(
        (math.isnan(a[k]) and math.isnan(b[k])) or a[k] == b[k] for k in a)


def plugstate_cases(work: Path) -> list[tuple[str, object]]:
    import testbed
    from testbed.core.errors import exception_text

    state: dict = {}

    def plain() -> dict:
        if "plain" not in state:
            state["plain"] = _scores(testbed.run_scenario(str(_scenario(work, "sindy_pi_dynamical")),
                                                          cache=str(CACHE)))
        return state["plain"]

    def case(k: int, label: str, before: str = "", after: str = "", leak: bool = False,
             same_scores: bool = False, sweep: bool = False, methods: str = ""):
        def run():
            import warnings

            import numpy as np
            want = plain()
            name = f"h28_p{k}"
            plugin = work / f"{name}.py"
            plugin.write_text(_PLUGIN.replace("NAME", name).replace("#BEFORE", before)
                              .replace("#AFTER", after).replace("#METHODS", methods))
            testbed.load_plugins([str(plugin)])
            saved = (warnings.filters[:], np.get_printoptions(), dict(os.environ),
                     sys.getrecursionlimit())
            try:
                try:
                    r = testbed.run_scenario(str(_scenario(work, name)), cache=str(CACHE))
                except testbed.TestbedError:
                    raise
                except Exception as e:  # (named here: the harness's str(e) would raise)
                    return f"{type(e).__name__}: {exception_text(e)[:200]}"
                found = _hostile.scored_finding(r)
                if found:
                    return found
                if same_scores and not _same(_scores(r), want):
                    return "the plugin's own scores moved by what it did after its fit"
                if leak:
                    after_scores = _scores(testbed.run_scenario(
                        str(_scenario(work, "sindy_pi_dynamical")), cache=str(CACHE)))
                    if not _same(after_scores, want):
                        return "a plain run after the plugin's scored otherwise (state leaked)"
                if sweep:
                    study = work / "studies" / f"{name}.toml"
                    study.parent.mkdir(exist_ok=True)
                    study.write_text(f'[study]\nname = "{name}"\nscenarios = ["{MM}"]\nnoise = [0.0]\n'
                                     f'seeds = [0]\nidentifiers = ["{name}", "sindy_pi_dynamical"]\n'
                                     f'plugins = ["{plugin}"]\n')
                    res = work / f"{name}.parquet"
                    status, out, err = cli_inprocess(["sweep", str(study), "--results", str(res),
                                                      "--cache", str(CACHE), "--jobs", "1"])
                    found = judged(status, out, err) or (status == 2 and err.strip()[:200])
                    if found:
                        return f"sweep: {found}"
                    rows = testbed.read_results(res)
                    mine = [r for r in rows if r["identifier"] == "sindy_pi_dynamical"]
                    if not mine or mine[0]["status"] != "ok" or not math.isclose(
                            float(mine[0]["coef_error"]), want["coef_error"], rel_tol=0, abs_tol=0):
                        return (f"sweep: the plain cell after the plugin's scored otherwise "
                                f"({mine[0]['coef_error'] if mine else None} vs {want['coef_error']})")
            finally:
                warnings.filters[:] = saved[0]
                np.set_printoptions(**saved[1])
                os.environ.clear()
                os.environ.update(saved[2])
                sys.setrecursionlimit(saved[3])
            return None
        return run

    cases = [
        ("writes x to zero before its fit (sweep: the next cell's data)",
         {"before": "data.x[...] = 0.0", "sweep": True}),
        ("writes x to NaN after its fit", {"after": "data.x[...] = np.nan", "same_scores": True}),
        ("writes dx to NaN after its fit", {"after": "data.xd[...] = np.nan" , "same_scores": True}),
        ("edits its prior", {"before": "data.prior['Km'] = 'x'", "leak": True}),
        ("turns warnings into errors", {"before": "import warnings; warnings.simplefilter('error')",
                                        "leak": True, "sweep": True}),
        ("numpy print options 2 digits",
         {"before": "np.set_printoptions(precision=2, threshold=3)", "leak": True, "sweep": True}),
        ("numpy's global random state seeded",
         {"before": "np.random.seed(123)", "leak": True}),
        ("os.environ TESTBED_CACHE set",
         {"before": "import os; os.environ['TESTBED_CACHE'] = '/proc/none'", "leak": True,
          "sweep": True}),
        ("prints to standard output", {"before": "print('PLUGIN SAYS ' * 100)"}),
        ("recursion limit 60", {"before": "import sys; sys.setrecursionlimit(60)", "leak": True}),
        ("coefficients NaN", {"after": "self.coef_ = np.full_like(np.asarray(self.coef_, float), np.nan)"}),
        ("coefficients inf", {"after": "self.coef_ = np.full_like(np.asarray(self.coef_, float), np.inf)"}),
        ("coefficients of another shape",
         {"after": "self.coef_ = np.zeros((3, 17))"}),
        ("coefficients complex",
         {"after": "self.coef_ = np.asarray(self.coef_, float) + 1j"}),
        ("raises with a 100,000-character multi-line message",
         {"before": "raise ValueError('line\\n' * 12500)"}),
        ("its simulate raises a plain Exception",
         {"methods": "    def simulate(self, *a, **k):\n        raise Exception('mine')\n"}),
        ("its simulate raises an exception whose str() raises",
         {"methods": "    def simulate(self, *a, **k):\n        class E(Exception):\n"
                     "            def __str__(self):\n                raise RuntimeError('x')\n"
                     "        raise E()\n"}),
        ("raises an exception whose str() raises",
         {"before": "class E(Exception):\n            def __str__(self):\n"
                    "                raise RuntimeError('no text')\n        raise E()"}),
    ]
    return [(f"plugstate {label}", case(k, label, **kw)) for k, (label, kw) in enumerate(cases)]


# ------------------------------------------------------------------ reportout

_FOREIGN = {
    "a text": b"my own notes, not a report\n",
    "a JPEG head": b"\xff\xd8\xff\xe0\x00\x10JFIF\x00" + bytes(200),
}


def _snapshot(folder: Path) -> dict[str, tuple]:
    out = {}
    for p in sorted(folder.iterdir()):
        st = p.stat()
        out[p.name] = (st.st_ino, st.st_mtime_ns, hashlib.sha256(p.read_bytes()).hexdigest())
    return out


def reportout_cases(work: Path) -> list[tuple[str, object]]:
    state: dict = {}

    def sources() -> dict[str, Path]:
        if "s" not in state:
            study = work / "h28.toml"
            study.write_text(f'[study]\nname = "h28"\nscenarios = ["{MM}"]\nnoise = [0.0]\n'
                             'seeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')
            results = work / "results.parquet"
            status, _, err = cli_inprocess(["sweep", str(study), "--results", str(results),
                                            "--cache", str(CACHE)])
            if status not in (0, 1):
                raise RuntimeError(err[-300:])
            s = {"results": results}
            for label, more in (("run without figures", ["--no-figures"]), ("run with figures", [])):
                runs = work / label.replace(" ", "_")
                status, _, err = cli_inprocess(["run", MM, "-o", str(runs), "--cache", str(CACHE),
                                                *more])
                if status not in (0, 1):
                    raise RuntimeError(err[-300:])
                s[label] = next(p.parent for p in runs.rglob("run.json"))
            state["s"] = s
        return state["s"]

    def case(source: str, index: int, label: str):
        def run():
            src = sources()[source]
            out = work / f"rep_{source.replace(' ', '_')}_{index}_{label.replace(' ', '_')}"
            shutil.rmtree(out, ignore_errors=True)
            for _ in range(2):  # its own earlier report is replaced
                status, o, err = cli_inprocess(["report", str(src), "-o", str(out)])
                if status != 0:
                    return f"the plain report: {judged(status, o, err) or err.strip()[:200]}"
            names = sorted(p.name for p in out.iterdir())
            if index >= len(names):
                return None
            name = names[index]
            content = (b"# Study notes\n\nmine\n" if label == "a titled markdown" and source == "results"
                       else b"# Run notes\n\nmine\n" if label == "a titled markdown"
                       else _FOREIGN[label])
            if label == "a titled markdown" and not name.endswith(".md"):
                return None
            (out / name).write_bytes(content)
            before = _snapshot(out)
            status, o, err = cli_inprocess(["report", str(src), "-o", str(out)])
            found = judged(status, o, err)
            if found:
                return found
            after = _snapshot(out)
            if (out / name).read_bytes() != content:
                return f"status {status}: the user's {name} replaced"
            if status == 2 and after != before:
                changed = sorted(k for k in set(before) | set(after) if before.get(k) != after.get(k))
                return f"refused ({err.strip()[:80]!r}) after writing {changed}"
            return None
        return run

    cases = []
    for source in ("results", "run without figures", "run with figures"):
        for index in range(12):  # every file a report writes (fewer: the case is skipped)
            for label in (*_FOREIGN, "a titled markdown"):
                cases.append((f"reportout {source} file #{index} {label}", case(source, index, label)))
    return cases


# ------------------------------------------------------------------ csvorder

def csvorder_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.core.dataset import Dataset

    state: dict = {}

    def record():
        if "r" not in state:
            ds = Dataset.load(hostile19._generated(work, MM))
            state["r"] = ds.fs, ds.measured["x"].data[0].tolist(), ds.measured["dx"].data[0].tolist()
        return state["r"]

    def table(head: list[str], cols: list[list]) -> str:
        return ",".join(head) + "\n" + "".join(",".join(repr(c) for c in row) + "\n"
                                               for row in zip(*cols, strict=True))

    def identify(path: Path) -> tuple[int, str, str]:
        return cli_inprocess(["identify", str(path), "--kind", "dynamical", "--method",
                              "sindy_pi_dynamical", "-o", f"{path}.model.json"])

    def equations(path: Path) -> list:
        return json.loads(Path(f"{path}.model.json").read_text()).get("equations")

    def case(label: str, make, refuse: bool = False):
        def run():
            fs, x, dx = record()
            t = [k / fs for k in range(len(x))]
            clean = work / "clean.csv"
            if not Path(f"{clean}.model.json").exists():
                clean.write_text(table(["time [s]", "x [mM]", "dx [mM/s]"], [t, x, dx]))
                found = judged(*identify(clean))
                if found:
                    return f"the clean file: {found}"
            path = work / f"{hostile19._safe(label)}.csv"
            path.write_text(make(t, x, dx))
            status, out, err = identify(path)
            found = judged(status, out, err, refuse=refuse)
            if found or status != 0:
                return found
            if equations(path) != equations(clean):
                return "read, but its model differs from the clean file's"
            return None
        return run

    return [(f"csvorder {label}", case(label, make, *more)) for label, make, *more in [
        ("time last", lambda t, x, dx: table(["x [mM]", "dx [mM/s]", "time [s]"], [x, dx, t])),
        ("dx before x", lambda t, x, dx: table(["time [s]", "dx [mM/s]", "x [mM]"], [t, dx, x])),
        ("x twice, equal", lambda t, x, dx: table(["time [s]", "x [mM]", "dx [mM/s]", "x [mM]"],
                                                  [t, x, dx, x]), True),
        ("x twice, other values", lambda t, x, dx: table(
            ["time [s]", "x [mM]", "dx [mM/s]", "x [mM]"], [t, x, dx, [2 * v for v in x]]), True),
        ("time twice", lambda t, x, dx: table(["time [s]", "x [mM]", "time [s]", "dx [mM/s]"],
                                              [t, x, t, dx]), True),
        ("time in Unix epoch seconds", lambda t, x, dx: table(
            ["time [s]", "x [mM]", "dx [mM/s]"], [[1.7e9 + v for v in t], x, dx])),
        ("time in minutes, declared", lambda t, x, dx: table(
            ["time [min]", "x [mM]", "dx [mM/s]"], [[v / 60 for v in t], x, dx])),
        ("time descending", lambda t, x, dx: table(
            ["time [s]", "x [mM]", "dx [mM/s]"], [t[::-1], x, dx]), True),
        ("time descending, rows reversed", lambda t, x, dx: table(
            ["time [s]", "x [mM]", "dx [mM/s]"], [t[::-1], x[::-1], dx[::-1]]), True),
        ("a time column of zeros", lambda t, x, dx: table(
            ["time [s]", "x [mM]", "dx [mM/s]"], [[0.0] * len(t), x, dx]), True),
        ("dx named dx with x's unit", lambda t, x, dx: table(
            ["time [s]", "x [mM]", "dx [mM]"], [t, x, dx]), True),
    ]]


FAMILIES = _hostile.families({"apiwalk": apiwalk_cases, "plugstate": plugstate_cases,
                              "reportout": reportout_cases, "csvorder": csvorder_cases}, TIMEOUT_S)

if __name__ == "__main__":
    sys.exit(_hostile.main(sys.argv[1:], FAMILIES, "hostile28_"))
