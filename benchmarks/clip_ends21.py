"""Round 20's open item (b), measured: can a clipped sensor whose rail is the record's start or
end (a kinetics decay clipped from its first sample) be told from a record at rest there?

Candidate rule (not adopted unless the numbers below separate): where a channel of a (signal,
rate) pair (``testbed.pipeline.importers.RATE_PAIRS``) holds its extreme on a run of at least
``testbed.numerics.clipping.MIN_RUN`` samples touching the record's first or last sample, the
pair's other channel says whether it moved there: the signal's change over the run less the
trapezoid integral of the rate over it, relative to the signal's motion (RMS about its mean),
is ``mismatch``.  At rest both are ~0; a clipped signal is constant while its rate integrates
to the motion it missed, a clipped rate integrates to less than the signal moved.

Measured with the rule as shipped (``testbed.numerics.clipping.rate_contradicted_levels``,
which also keeps the quantisation of both channels and skips a constant channel): prints, over
every record of the dataset cache(s) given (default ``.cache/datasets``) of a kind with rate
pairs, its alarms on the records as stored and on their 16-bit copies, and by kind the share
told of their channels clipped at 50 % (from the extreme the record starts or ends nearer, and
at +-50 % of the peak about the mean)::

    python -m benchmarks.clip_ends21 [cache folder ...]
"""

from __future__ import annotations

import sys
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from testbed.numerics.clipping import MIN_RUN, rate_contradicted_levels  # noqa: E402
from testbed.pipeline.importers import RATE_PAIRS  # noqa: E402

#: The share of the record's range (or peak) cut away by the clip [-]
FRACTIONS = (0.1, 0.3, 0.5, 0.7, 0.9)


def end_runs(y: np.ndarray, ends_only: bool = True) -> list[slice]:
    """Runs at the record's extreme (>= MIN_RUN samples): those touching its first or last
    sample, or (``ends_only`` False) every run; each slice reaches one sample past the run on
    the inside (where the record leaves the level)."""
    out = []
    n = y.size
    for level in (y.max(), y.min()):
        d = np.diff(np.r_[0, (y == level).astype(np.int8), 0])
        starts, stops = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
        for a, b in zip(starts, stops, strict=True):
            if b - a < MIN_RUN or (ends_only and 0 < a and b < n):
                continue
            out.append(slice(max(a - 1, 0), min(b + 1, n)))
    return out


def mismatch(a: np.ndarray, d: np.ndarray, fs: float, run: slice) -> float:
    """|change of ``a`` over ``run`` - trapezoid integral of ``d`` over it| / RMS motion of a."""
    motion = float(np.sqrt(np.mean((a - a.mean()) ** 2)))
    seg_a, seg_d = a[run], d[run]
    integral = float(np.sum((seg_d[1:] + seg_d[:-1]) * 0.5) / fs)
    return abs(float(seg_a[-1] - seg_a[0]) - integral) / motion if motion > 0 else 0.0


def pair_mismatches(a: np.ndarray, d: np.ndarray, fs: float, ends_only: bool = True) -> list[float]:
    """The mismatch of every run held by the signal ``a`` or its rate ``d`` (one channel)."""
    return [mismatch(a, d, fs, r) for y in (a, d) for r in end_runs(y, ends_only)]


def quantised(y: np.ndarray, bits: int) -> np.ndarray:
    q = float(np.max(np.abs(y))) / 2 ** (bits - 1)
    return np.round(y / q) * q if q > 0 else y


def clipped_both(y: np.ndarray, frac: float) -> np.ndarray:
    """``y`` clipped at +-``frac`` of its peak about its mean (session 21's copies)."""
    m = float(np.mean(y))
    lim = frac * float(np.max(np.abs(y - m)))
    return np.clip(y, m - lim, m + lim)


def clipped_from_end(y: np.ndarray, frac: float) -> np.ndarray:
    """``y`` clipped at ``frac`` of its range from the extreme its first sample is nearer."""
    lo, hi = float(y.min()), float(y.max())
    if abs(y[0] - hi) <= abs(y[0] - lo):
        return np.minimum(y, hi - frac * (hi - lo))
    return np.maximum(y, lo + frac * (hi - lo))


def main(folders: list[str]) -> int:
    """The shipped rule (:func:`testbed.numerics.clipping.rate_contradicted_levels`) on every
    rate pair of the records: alarms on them as stored and on their 16-bit copies, and the
    share told of their channels clipped at 50 % (from the end the record starts or ends
    nearer, and at +-50 % of the peak about the mean), by kind."""
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
                    for name, clip in (("from the end", clipped_from_end), ("+-50 %", clipped_both)):
                        for which in ("signal", "rate"):
                            aa = clip(a, 0.5) if which == "signal" else a
                            dd = clip(d, 0.5) if which == "rate" else d
                            told.setdefault((kind, f"{which} {name}"), []).append(
                                bool(rate_contradicted_levels(aa, dd, fs)))
    print(f"{n_records} records with rate pairs, {n_channels} channel pairs")
    for k, v in alarms.items():
        print(f"alarms on the records {k}: {len(v)} {v[:4]}")
    for (kind, how), v in sorted(told.items()):
        print(f"{kind}: {how} clipped at 50 %: {sum(v)} of {len(v)} told")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
