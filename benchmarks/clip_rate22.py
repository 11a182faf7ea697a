"""Round 21's open item (b), measured: a rate clipped within 5 % of its signal's motion (a
10 % cut of a kinetics decay's rate) was not told.  The rule now also compares each held run
step by step (``testbed.numerics.clipping.LOCAL_STEPS``): this prints, over every record of the
dataset cache(s) given (default ``.cache/datasets``) of a kind with rate pairs, the alarms on
the records as stored and on their 16-bit copies, and by kind the share told of their
channels clipped at 10 % and 50 % of their range from the extreme the record starts or ends
nearer and at +-(1 - share) of the peak about the mean (``benchmarks/clip_ends21.py``'s copies),
and the alarms on records at rest then moving as ``s**p`` (review 23a: a constant jerk, p = 3,
makes every moving step misfit alike, and its rest was called clipped)::

    python -m benchmarks.clip_rate22 [cache folder ...]
"""

from __future__ import annotations

import sys
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks.clip_ends21 import clipped_both, clipped_from_end, quantised  # noqa: E402
from testbed.numerics.clipping import rate_contradicted_levels  # noqa: E402
from testbed.pipeline.importers import RATE_PAIRS  # noqa: E402

#: The share of the record's range cut away by a clip from its end [-] (the +-peak copies keep
#: 1 - share of the peak)
SHARES = (0.1, 0.5)


#: The rest-then-power records: sample rates [Hz], the share of the record at rest [-] and
#: the powers of the motion ``s**p`` after it
REST_FS, REST_SHARES, REST_POWERS = (100.0, 1000.0, 12800.0), (0.1, 0.3, 0.6), (2, 3, 4, 5)


def rest_then_power() -> tuple[list[str], int]:
    """The alarms (as "fs share p float|16 bit") on noise-free records of 4 s at rest, then
    ``a = s**p``, ``d = p s**(p-1)``, as floats and quantised to 16 bits, and their count."""
    alarms, n = [], 0
    for fs in REST_FS:
        t = np.arange(int(4 * fs)) / fs
        for share in REST_SHARES:
            s = np.maximum(t - share * t[-1], 0.0)
            for p in REST_POWERS:
                a, d = s ** p, p * s ** (p - 1)
                for how, aa, dd in (("float", a, d), ("16 bit", quantised(a, 16), quantised(d, 16))):
                    n += 1
                    if rate_contradicted_levels(aa, dd, fs):
                        alarms.append(f"{fs:g} Hz {share:g} p={p} {how}")
    return alarms, n


def main(folders: list[str]) -> int:
    rest_alarms, n_rest = rest_then_power()
    print(f"alarms on {n_rest} records at rest then s**p: {len(rest_alarms)} {rest_alarms[:6]}")
    alarms: dict[str, list[str]] = {"float": [], "16 bit": []}
    told: dict[tuple[str, str], list[bool]] = {}
    n_records = n_channels = 0
    for folder in folders or [str(ROOT / ".cache" / "datasets")]:
        for path in sorted(Path(folder).glob("*.h5")):
            try:
                with h5py.File(path, "r") as f:
                    kind = f.attrs.get("kind")
                    kind = kind.decode() if isinstance(kind, bytes) else str(kind)
                    pairs = RATE_PAIRS.get(kind, ())
                    if not pairs:
                        continue
                    fs = float(f.attrs["fs"])
                    m = {k: np.asarray(f["measured"][k][()], dtype=float) for k in f["measured"]}
            except Exception:
                continue
            n_records += 1
            for g, dg in pairs:
                if g not in m or dg not in m or m[g].shape != m[dg].shape:
                    continue
                for a, d in zip(m[g], m[dg], strict=True):
                    n_channels += 1
                    if rate_contradicted_levels(a, d, fs):
                        alarms["float"].append(f"{path.name} {g}")
                    if rate_contradicted_levels(quantised(a, 16), quantised(d, 16), fs):
                        alarms["16 bit"].append(f"{path.name} {g}")
                    for share in SHARES:
                        for name, clip in (("from the end", lambda y, s=share: clipped_from_end(y, s)),
                                           ("+-peak", lambda y, s=share: clipped_both(y, 1 - s))):
                            for which in ("signal", "rate"):
                                aa = clip(a) if which == "signal" else a
                                dd = clip(d) if which == "rate" else d
                                told.setdefault((kind, f"{which} {name} {100 * share:g} %"), []).append(
                                    bool(rate_contradicted_levels(aa, dd, fs)))
    print(f"{n_records} records with rate pairs, {n_channels} channel pairs")
    for k, v in alarms.items():
        print(f"alarms on the records {k}: {len(v)} {v[:6]}")
    for (kind, how), v in sorted(told.items()):
        print(f"{kind}: {how}: {sum(v)} of {len(v)} told")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
