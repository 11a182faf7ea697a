"""Tenth malformed-input round: generated hostile inputs, counted by family (docs/history.md).

Each case runs in-process (the harness, ``benchmarks/_hostile.py``) and is a *finding* when it
ends in anything but a verdict or one error line naming the file, key and value -- or, here,
when a setting is accepted and has no effect.  Run from the repository root::

    python -m benchmarks.hostile10 [family ...]      # all families when none is named

Families (where rounds 1-9 went least):

``combos``
    Identifier hyperparameters each valid alone, contradictory together: a key that one
    setting of another key makes the identifier skip (pysindy's ``n_models`` with
    ``optimizer = "stlsq"``, ``sgd_sindy``'s ``l1_threshold`` with ``cubic = false``,
    ``sindy_pi``'s ``n_rollout`` with ``selection = "holdout"``, the weak form's windows with
    the strong one, ...).  A case is loaded; when accepted, fitted twice on a short record, with
    the key at its default and at another value: identical fitted models are a finding (the
    setting was accepted and ignored); a model that differs says the key is read (no finding).
``edges``
    Every number of the cart-pole's and the Michaelis-Menten rig's ``[rig]``,
    ``[simulation]`` and ``[excitation]`` tables (and the beam's ``[rig]``) at float64's and
    int64's edges: 2**63, 2**64, -2**63 - 1, 10**30, the largest float, the least normal and
    subnormal numbers, -0.0; loaded, and run on a short record when accepted.
``roundtrip``
    A generated dataset edited with h5py without rehashing (the rate, a channel's name, the
    channels' order, one sample, an attribute removed), cut at 10-90 %, and its UFF and SEP-005
    exports edited (rate, channel order, a block twice); each read by ``Dataset.load``,
    ``read_measured`` and ``export_dataset``.
``extends``
    Scenario files that extend others: chains through a study file, a folder, a file that
    is not TOML, a parent of another rig kind, a parent path with ``..`` and a link, a child
    replacing a parent's table with a value and a value with a table.
``dask``
    ``testbed sweep --dask`` at malformed and unreachable loopback addresses, a port held by
    a server that speaks no Dask, and ``--jobs`` given with ``--dask``.

Prints one line a finding and the counts; exits 1 if any finding.
"""

from __future__ import annotations

import contextlib
import copy
import io
import os
import socket
import sys
import threading
from collections import Counter
from pathlib import Path

import numpy as np

from benchmarks import _hostile

ROOT = Path(__file__).resolve().parent.parent
TIMEOUT_S = 120  # a case longer than this is a hang (the slowest fit below takes about 20 s)

#: The scenario each kind's identifiers are fitted on, and the record it is cut to [s].
BASES = {"structural": ("cantilever_stiff_impact", 0.2), "mechanical": ("cartpole", 1.0),
         "dynamical": ("michaelis_menten", 4.0)}

#: (identifier, the switch setting, the key, another value of it): cases where the key's
#: description says the identifier reads it only under another setting of the switch.
COMBOS = [
    ("pysindy", {"optimizer": "stlsq"}, "n_models", 5),
    ("pysindy", {"optimizer": "stlsq"}, "reg_weight_lam", 0.1),
    ("pysindy", {"optimizer": "stlsq"}, "regularizer", "L0"),
    ("pysindy", {"optimizer": "stlsq"}, "seed", 3),
    ("pysindy", {"optimizer": "sr3"}, "threshold", 0.1),
    ("pysindy", {"optimizer": "sr3"}, "alpha", 0.1),
    ("pysindy", {"optimizer": "sr3"}, "n_models", 5),
    ("pysindy", {"optimizer": "ensemble"}, "reg_weight_lam", 0.1),
    ("pysindy", {"optimizer": "ensemble"}, "seed", 3),
    ("pysindy", {"weak": False}, "n_windows", 50),
    ("pysindy", {"weak": True}, "seed", 3),
    ("sgd_sindy", {"gradient": "full"}, "batch_size", 64),
    ("sgd_sindy", {"gradient": "full"}, "random_state", 3),
    ("sgd_sindy", {"gradient": "full"}, "steps_per_epoch", 3),
    ("sgd_sindy", {"cubic": False}, "l1_threshold", 0.5),
    ("sgd_sindy", {"cubic": False}, "l1_debias", 0.1),
    ("sgd_sindy", {"cubic": False}, "l1", "none"),
    ("sgd_sindy", {"cubic": False}, "cubic_form", "direction"),
    ("sgd_sindy", {"cubic": False}, "decay_backbone", False),
    ("sgd_sindy", {"cubic": False}, "eigen_backbone", False),
    ("sgd_sindy", {"cubic": True, "l1": "none"}, "l1_threshold", 0.5),
    ("sgd_sindy", {"cubic": True, "l1": "none"}, "l1_debias", 0.1),
    ("sgd_sindy", {"eigen": False}, "epsilon", 0.5),
    ("sgd_sindy", {"eigen": False}, "alpha_init", 0.5),
    ("sgd_sindy", {"eigen": False}, "eigen_hold", False),
    ("sgd_sindy", {"eigen": False}, "n_modes", 2),
    ("sgd_sindy", {"eigen": False}, "freq_range", [5.0, 2000.0]),
    ("sgd_sindy", {"anneal": False}, "alpha_max", 0.5),
    ("sgd_sindy", {"anneal": False}, "beta", 0.5),
    ("sgd_sindy", {"init": "zeros"}, "keep_sgd", True),
    ("sgd_sindy", {"decay_hold": False}, "decay_backbone", False),
    ("ls_sindy", {"cubic": False}, "decay_backbone", False),
    ("ls_sindy", {"decay_hold": False}, "decay_backbone", False),
    ("sgd_sindy_coefficients", {"mass_update": "lstsq"}, "mass_learning_rate", 0.1),
    ("sgd_sindy_coefficients", {"eigen": False}, "epsilon", 0.5),
    ("sgd_sindy_coefficients", {"gradient_dummy": None}, "", None),  # placeholder, dropped
    ("sindy_pi", {"selection": "holdout"}, "n_rollout", 5),
    ("sindy_pi", {"selection": "holdout"}, "rollout_segments", 3),
    ("sindy_pi", {"selection": "holdout"}, "record_replay", False),
    ("sindy_pi", {"column_lowpass_hz": 0.0}, "column_lowpass_order", 2),
    ("sindy_pi", {"formulation": "strong"}, "weak_n_windows", 100),
    ("sindy_pi", {"formulation": "strong"}, "weak_degree", 2),
    ("sindy_pi", {"formulation": "strong"}, "weak_window_s", 0.3),
    ("sindy_pi", {"ensemble": 0}, "ensemble_blocks", 5),
    ("sindy_pi", {"ensemble": 0}, "ensemble_seed", 4),
    ("sindy_pi", {"ensemble": 0}, "ensemble_aggregate", "mean"),
    ("sindy_pi_dynamical", {"formulation": "strong"}, "weak_windows", 50),
    ("sindy_pi_dynamical", {"formulation": "strong"}, "weak_window_s", 0.2),
    ("sindy_pi_dynamical", {"formulation": "strong"}, "weak_degree", 2),
    ("sindy_pi_dynamical", {"library": ["1", "x", "dx", "x*dx"]}, "degree", 3),
    ("pysindy_pi", {"selection": "holdout"}, "n_rollout", 5),
    ("pysindy_pi", {"selection": "holdout"}, "rollout_segments", 3),
]
COMBOS = [c for c in COMBOS if c[2]]
#: Settings every fit of an identifier starts from: the five-bar's library cannot describe the
#: cart-pole (refused at load, which would hide every case).
BASE_PARAMS = {"sindy_pi": {"library": "generic"}, "pysindy_pi": {"library": "generic"}}


def _raw(kind: str) -> tuple[str, dict]:
    return _hostile.base_scenario(BASES, kind)


def _fitted(model) -> dict:
    """The fitted model's arrays and numbers (attributes ending in ``_``)."""
    out = {}
    for k, v in vars(model).items():
        if k.endswith("_") and not k.startswith("_"):
            if isinstance(v, np.ndarray) and v.dtype.kind in "fc":
                out[k] = v.tobytes()
            elif isinstance(v, (int, float, str, bool)) or v is None:
                out[k] = v
    return out


_BASELINES: dict = {}


def _combo(m: str, switch: dict, key: str, value) -> str | None:
    from testbed.core.errors import TestbedError
    from testbed.pipeline.plugins import IDENTIFIERS
    from testbed.pipeline.scenario import scenario_from_dict
    from testbed.scoring.run import run_scenario

    cls = IDENTIFIERS.get(m)
    base, raw0 = _raw(cls.kind)

    def fit(params):
        raw = copy.deepcopy(raw0)
        raw["identify"] = {"method": m, **BASE_PARAMS.get(m, {}), **params}
        return run_scenario(scenario_from_dict(raw, file="x.toml", stem=base))

    bkey = (m, tuple(sorted((k, repr(v)) for k, v in switch.items())))
    if bkey not in _BASELINES:
        try:
            _BASELINES[bkey] = fit(switch)
        except TestbedError as e:  # the case would test nothing
            _BASELINES[bkey] = f"the switch alone is refused: {str(e)[:160]}"
    ref = _BASELINES[bkey]
    if isinstance(ref, str):
        return ref
    try:
        alt = fit({**switch, key: value})
    except TestbedError:
        return None  # refused in one line (the harness checks the line)
    if ref.model is None or alt.model is None:
        return None  # a scored failure before a model: nothing to compare
    if _fitted(ref.model) == _fitted(alt.model):
        return (f"accepted and ignored: identify.{key} = {value!r} with "
                f"{', '.join(f'{k} = {v!r}' for k, v in switch.items())} fits the same model")
    return None


def combo_cases() -> list[tuple[str, object]]:
    only = os.environ.get("HOSTILE10_IDENTIFIERS", "")  # comma-separated, to rerun a few
    return [(f"{m}: {switch} + {key} = {value!r}",
             lambda m=m, s=switch, k=key, v=value: _combo(m, s, k, v))
            for m, switch, key, value in COMBOS if not only or m in only.split(",")]


# ------------------------------------------------------------------ edges of the numbers

EDGE_VALUES = [2**63, 2**64, -(2**63) - 1, 10**30, 1.7976931348623157e308, -1.7976931348623157e308,
               2.2250738585072014e-308, 5e-324, -0.0]
#: Rigs whose [rig], [simulation] and [excitation] numbers are set to the edges, and the record
#: [s] an accepted case is run on.
EDGE_BASES = {"cartpole": 0.5, "michaelis_menten": 2.0, "cantilever_stiff_impact": 0.05}


def _edge(raw: dict, base: str) -> str | None:
    from testbed.pipeline.scenario import scenario_from_dict
    from testbed.scoring.run import run_scenario

    sc = scenario_from_dict(raw, file="x.toml", stem=base)
    return _hostile.scored_finding(run_scenario(sc))


def edge_cases() -> list[tuple[str, object]]:
    from testbed.pipeline.scenario import SCENARIO_DIR, _read_toml

    cases = []
    for base, cut in EDGE_BASES.items():
        raw0 = _read_toml(SCENARIO_DIR / f"{base}.toml")
        raw0["scenario"].pop("extends", None)
        raw0.pop("score", None)
        tables = ("rig",) if base.startswith("cantilever") else ("rig", "simulation", "excitation")
        for table in tables:
            for key, old in raw0.get(table, {}).items():
                if isinstance(old, bool) or not isinstance(old, (int, float)):
                    continue
                for value in EDGE_VALUES:
                    raw = copy.deepcopy(raw0)
                    if not (table == "simulation" and key == "duration"):
                        raw["simulation"]["duration"] = min(cut, raw["simulation"].get("duration", cut))
                    raw[table][key] = value
                    cases.append((f"{base}: {table}.{key} = {value!r}",
                                  lambda raw=raw, base=base: _edge(raw, base)))
    return cases


# ------------------------------------------------------------------ round trips

def _read_all(path: Path, must_refuse: bool) -> str | None:
    """A finding of reading ``path`` (a dataset, UFF or SEP-005 file) by every reader."""
    from testbed.core.dataset import Dataset
    from testbed.core.errors import TestbedError
    from testbed.pipeline.importers import read_measured
    from testbed.reporting.export import export_dataset

    readers = [("read_measured", lambda: read_measured(path))]
    if path.suffix == ".h5":
        readers += [("Dataset.load", lambda: Dataset.load(path)),
                    ("export", lambda: export_dataset(path, "sep005", path.with_suffix(".out.json")))]
    for name, read in readers:
        try:
            read()
        except TestbedError as e:
            if "\n" in str(e):
                return f"{name}: two lines: {str(e)[:200]!r}"
            continue
        except Exception as e:
            return f"{name}: {type(e).__name__}: {str(e)[:200]}"
        if must_refuse:
            return f"{name}: read an edited file without a word"
    return None


def roundtrip_cases(work: Path) -> list[tuple[str, object]]:
    import json

    import h5py

    from testbed.cli import main as cli

    made: dict[str, Path] = {}

    def dataset(name: str) -> Path:
        if name not in made:
            p = work / f"{name}.h5"
            with contextlib.redirect_stdout(io.StringIO()):
                cli(["generate", name, "-o", str(p)])
            made[name] = p
        return made[name]

    def edited(name: str, tag: str, edit) -> Path:
        src = dataset(name)
        p = work / f"{name}-{tag}.h5"
        p.write_bytes(src.read_bytes())
        if callable(edit):
            with h5py.File(p, "a") as f:
                edit(f)
        else:  # a fraction to cut the file at
            p.write_bytes(src.read_bytes()[: int(src.stat().st_size * edit)])
        return p

    def first_signal(f):
        """The first measured signal of more than one channel (else the first)."""
        sigs = list(f["measured"].values())
        multi = [d for d in sigs if d.shape[0] > 1]
        return (multi or sigs)[0]

    def positioned(f):
        return next((d for d in f["measured"].values() if "positions" in d.attrs), None)

    def set_attr(where, key, fn):
        def edit(f):
            obj = f if where == "/" else (first_signal(f) if where == "signal" else f[where])
            k, change = key, fn
            if k == "positions":
                obj = positioned(f)
                if obj is None:  # no positions in this rig's file: the edit is a change of unit
                    obj, k, change = first_signal(f), "unit", lambda v: "mm"
            obj.attrs[k] = change(obj.attrs[k])
        return edit

    def del_attr(where, key):
        def edit(f):
            obj = f if where == "/" else first_signal(f)
            del obj.attrs[key]
        return edit

    def one_sample(f):
        d = first_signal(f)
        a = d[()]
        a.flat[a.size // 2] += 1.0
        d[...] = a

    def reorder(f):
        d = first_signal(f)
        if d.shape[0] > 1:
            d[...] = d[()][::-1]
            d.attrs["channels"] = list(d.attrs["channels"])[::-1]
        else:  # one channel a signal (Michaelis-Menten): two signals' samples swapped
            a, b = list(f["measured"].values())[:2]
            xa, xb = a[()], b[()]
            a[...], b[...] = xb, xa

    content = {  # edits of content, not rehashed: each must be refused
        "fs x2": set_attr("/", "fs", lambda v: v * 2),
        "fs 5e-324": set_attr("/", "fs", lambda v: 5e-324),
        "a channel renamed": set_attr("signal", "channels", lambda v: ["zz", *list(v)[1:]]),
        "a unit changed": set_attr("signal", "unit", lambda v: "mm"),
        "a position moved": set_attr("signal", "positions", lambda v: np.asarray(v) + 0.01),
        "one sample": one_sample,
        "channels reordered with their rows": reorder,
        "seed changed": set_attr("/", "seed", lambda v: int(v) + 1),
        "content hash removed": del_attr("/", "content_hash"),
        "format removed": del_attr("/", "format"),
        "unit removed": del_attr("signal", "unit"),
    }
    neutral = {  # provenance or a cut: refused or read, never a crash
        "kind removed": del_attr("/", "kind"),
        "versions removed": del_attr("/", "versions"),
        "layout removed": del_attr("signal", "layout"),
    }
    cases = []
    for name in ("michaelis_menten", "cartpole"):
        for tag, edit in content.items():
            cases.append((f"{name}.h5, {tag}, not rehashed",
                          lambda n=name, t=tag, e=edit: _read_all(edited(n, t.replace(" ", "_"), e), True)))
        for tag, edit in neutral.items():
            cases.append((f"{name}.h5, {tag}",
                          lambda n=name, t=tag, e=edit: _read_all(edited(n, t.replace(" ", "_"), e), False)))
        for frac in (0.1, 0.3, 0.5, 0.7, 0.9, 0.99):
            cases.append((f"{name}.h5 cut at {frac:.0%}",
                          lambda n=name, fr=frac: _read_all(edited(n, f"cut{fr}", fr), True)))

    def exported(name: str, fmt: str) -> Path:
        from testbed.reporting.export import export_dataset
        out = work / f"{name}.{ 'uff' if fmt == 'uff' else 'json'}"
        if not out.exists():
            export_dataset(dataset(name), fmt, out)
        return out

    def sep_edit(name: str, tag: str, fn, must: bool):
        def case():
            doc = json.loads(exported(name, "sep005").read_text())
            fn(doc)
            p = work / f"{name}-{tag.replace(' ', '_')}.json"
            p.write_text(json.dumps(doc))
            return _read_all(p, must)
        return case

    def chans(doc):
        return doc if isinstance(doc, list) else doc.get("channels", doc)

    def dup_first(doc):
        c = chans(doc)
        c.append(copy.deepcopy(c[0]))

    def rate(doc):
        chans(doc)[0]["fs"] = float(chans(doc)[0]["fs"]) * 2

    def uff_edit(name: str, tag: str, fn, must: bool):
        def case():
            data = exported(name, "uff").read_bytes()
            p = work / f"{name}-{tag.replace(' ', '_')}.uff"
            p.write_bytes(fn(data))
            return _read_all(p, must)
        return case

    def uff_blocks(data: bytes) -> list[bytes]:
        tags = [i for i in range(len(data)) if data.startswith(b"    -1\n", i)
                and (i == 0 or data[i - 1:i] == b"\n")]
        return [data[a:b + 7] for a, b in zip(tags[0::2], tags[1::2], strict=False)]

    def uff_dup_last(data: bytes) -> bytes:
        return data + uff_blocks(data)[-1]

    def uff_reversed(data: bytes) -> bytes:
        return b"".join(reversed(uff_blocks(data)))

    def uff_junk(data: bytes) -> bytes:
        b = uff_blocks(data)
        return b[0] + b"junk\n" + b"".join(b[1:])

    for name in ("michaelis_menten", "cartpole"):
        cases += [
            (f"{name} SEP-005, channels reversed",
             sep_edit(name, "rev", lambda d: chans(d).reverse(), False)),
            (f"{name} SEP-005, a channel twice", sep_edit(name, "dup", dup_first, True)),
            (f"{name} SEP-005, one channel's rate x2", sep_edit(name, "rate", rate, True)),
            (f"{name} UFF, the last block twice", uff_edit(name, "dup", uff_dup_last, True)),
            (f"{name} UFF, blocks reversed", uff_edit(name, "rev", uff_reversed, False)),
            (f"{name} UFF, junk between blocks", uff_edit(name, "junk", uff_junk, True)),
        ]
    return cases


# ------------------------------------------------------------------ extends

def extends_cases(work: Path) -> list[tuple[str, object]]:
    from testbed.pipeline.scenario import SCENARIO_DIR, load_scenario

    d = work / "ext"
    d.mkdir(exist_ok=True)
    mm = SCENARIO_DIR / "michaelis_menten.toml"
    cant = SCENARIO_DIR / "cantilever_stiff_impact.toml"
    (d / "study.toml").write_text('[study]\nname = "s"\nscenarios = ["michaelis_menten"]\n'
                                 'noise = [0.0]\nseeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')
    (d / "junk.toml").write_text("this is = = not toml\n")
    (d / "folder.toml").mkdir(exist_ok=True)
    (d / "empty.toml").write_text("")
    with contextlib.suppress(FileExistsError):
        os.symlink(mm, d / "link.toml")
    (d / "a.toml").write_text('[scenario]\nname = "a"\nextends = "b.toml"\n')
    (d / "b.toml").write_text('[scenario]\nname = "b"\nextends = "a.toml"\n')
    children = {
        "a study file": 'extends = "study.toml"',
        "a file that is not TOML": 'extends = "junk.toml"',
        "a folder": 'extends = "folder.toml"',
        "an empty file": 'extends = "empty.toml"',
        "a link": 'extends = "link.toml"',
        "a parent with ..": f'extends = "../../{os.path.relpath(mm, work)}"',
        "an absolute path": f'extends = "{mm}"',
        "a cycle of two": 'extends = "a.toml"',
        "a blank": 'extends = " "',
        "a NUL": 'extends = "x\\u0000.toml"',
        "the cantilever, rig switched to the cart-pole": f'extends = "{cant}"\nrig = "cartpole"',
        "the cantilever, identify switched to sindy_pi":
            f'extends = "{cant}"\n[identify]\nmethod = "sindy_pi"',
        "mm with [rig] replaced by a number":
            f'extends = "{mm}"\n[simulation]\nduration = 2.0\n[noise]\nrms_percent = "x"',
    }
    cases = []
    for tag, body in children.items():
        def case(tag=tag, body=body):
            head, _, rest = body.partition("\n")
            p = d / f"c_{abs(hash(tag)) % 10**8}.toml"
            p.write_text(f'[scenario]\nname = "{p.stem}"\n{head}\n{rest}\n')
            load_scenario(p)
            return None
        cases.append((f"extends {tag}", case))
    # a child that replaces a parent's table by a value, and a value by a table
    for tag, text in {"[noise] replaced by a number": "noise = 3\n",
                      "seed replaced by a table": "[scenario.seed]\nx = 1\n",
                      "[rig] replaced by a list": "rig_params = [1]\nrig = [1]\n"}.items():
        def case(text=text, tag=tag):
            p = d / f"v_{abs(hash(tag)) % 10**8}.toml"
            if text.startswith("["):
                p.write_text(f'[scenario]\nname = "{p.stem}"\nextends = "{mm}"\n' + text)
            else:
                p.write_text(text + f'[scenario]\nname = "{p.stem}"\nextends = "{mm}"\n')
            load_scenario(p)
            return None
        cases.append((f"extends michaelis_menten, {tag}", case))
    return cases


# ------------------------------------------------------------------ Dask

def _junk_server(reply: bytes | None) -> tuple[str, threading.Event]:
    """A loopback server that answers every connection with ``reply`` and closes it (None:
    holds it open and says nothing); its address and the event that stops it."""
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(8)
    srv.settimeout(0.2)
    stop = threading.Event()
    held: list[socket.socket] = []

    def serve():
        while not stop.is_set():
            try:
                conn, _ = srv.accept()
            except OSError:
                continue
            if reply is None:
                held.append(conn)
                continue
            with conn:
                with contextlib.suppress(OSError):
                    conn.sendall(reply)
        for conn in held:
            conn.close()
        srv.close()

    threading.Thread(target=serve, daemon=True).start()
    return f"tcp://127.0.0.1:{srv.getsockname()[1]}", stop


def dask_cases(work: Path) -> list[tuple[str, object]]:
    from benchmarks.hostile9 import _cli

    study = work / "dtiny.toml"
    study.write_text('[study]\nname = "dtiny"\nscenarios = ["michaelis_menten"]\nnoise = [0.0]\n'
                     'seeds = [0]\nidentifiers = ["sindy_pi_dynamical"]\n')
    addresses = ["", " ", "tcp://", "tcp://127.0.0.1", "tcp://127.0.0.1:0", "tcp://127.0.0.1:65536",
                 "tcp://127.0.0.1:-1", "tcp://127.0.0.1:1", "127.0.0.1:1", "tcp://[::1]:1",
                 "tcp://localhost:1", "/etc/passwd", str(study), "file:///tmp/x", "inproc://x",
                 "ucx://127.0.0.1:1", "tcp://127.0.0.1:99999999999999999999", "tcp://é:1",
                 "tcp://127.0.0.1:1/path?x=1", "tcp://127.0.0.1:x", "tcp://user:pw@127.0.0.1:1"]
    cases = [(f"sweep --dask {a!r}",
              lambda a=a: _cli(["sweep", str(study), "--results", str(work / "d.parquet"),
                                "--dask", a])) for a in addresses]

    def junk(reply: bytes):
        def case():
            addr, stop = _junk_server(reply)
            try:
                return _cli(["sweep", str(study), "--results", str(work / "d.parquet"),
                             "--dask", addr])
            finally:
                stop.set()
        return case

    cases += [("sweep --dask at a server that answers HTTP", junk(b"HTTP/1.0 200 OK\r\n\r\n")),
              ("sweep --dask at a server that closes at once", junk(b"")),
              ("sweep --dask at a server that never answers", junk(None))]

    def jobs_with_dask():
        addr, stop = _junk_server(b"")
        try:
            err = io.StringIO()
            with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
                from testbed.cli import main
                try:
                    main(["sweep", str(study), "--results", str(work / "d.parquet"),
                          "--jobs", "2", "--dask", addr])
                except SystemExit:
                    pass
            if "--jobs" not in err.getvalue():
                return f"--jobs 2 with --dask: not named ({err.getvalue().strip()[:160]!r})"
            return None
        finally:
            stop.set()

    cases.append(("sweep --jobs 2 --dask (jobs ignored by the Dask backend)", jobs_with_dask))
    return cases


def run_inprocess(cases) -> Counter:
    """Each case returns a finding's description or None (a verdict, or refused in one line)."""
    return _hostile.run_inprocess(cases, TIMEOUT_S, lambda finding: finding)


FAMILIES = {
    "combos": lambda work: run_inprocess(combo_cases()),
    "edges": lambda work: run_inprocess(edge_cases()),
    "roundtrip": lambda work: run_inprocess(roundtrip_cases(work)),
    "extends": lambda work: run_inprocess(extends_cases(work)),
    "dask": lambda work: run_inprocess(dask_cases(work)),
}


def main(argv: list[str]) -> int:
    os.environ.setdefault("MPLBACKEND", "Agg")
    return _hostile.main(argv, FAMILIES, "hostile10-")


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
