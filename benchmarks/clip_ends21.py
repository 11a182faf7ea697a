"""Round 20's open item (b), measured: can a clipped sensor whose rail is the record's start or
end (a kinetics decay clipped from its first sample) be told from a record at rest there?

Candidate rule (not adopted unless the numbers below separate): where a channel of a (signal,
rate) pair (``testbed.pipeline.importers.RATE_PAIRS``) holds its extreme on a run of at least
``testbed.numerics.clipping.MIN_RUN`` samples touching the record's first or last sample, the
pair's other channel says whether it moved there: the signal's change over the run less the
trapezoid integral of the rate over it, relative to the signal's motion (RMS about its mean),
is ``mismatch``.  At rest both are ~0; a clipped signal is constant while its rate integrates
to the motion it missed, a clipped rate integrates to less than the signal moved.

Prints, over every record of the dataset cache(s) given (default ``.cache/datasets``) of a
kind with rate pairs, the largest ``mismatch`` of the unclipped records' end runs (false-alarm
margin) and, for each record's channels clipped at 10-90 % of their range from the extreme the
record starts or ends at, the smallest ``mismatch`` (the rule's reach)::

    python -m benchmarks.clip_ends21 [cache folder ...]
"""

from __future__ import annotations

import sys
from pathlib import Path

import h5py
import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from testbed.numerics.clipping import MIN_RUN  # noqa: E402
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
    clean: list[tuple[float, str]] = []
    told: dict[float, list[float]] = {f: [] for f in FRACTIONS}
    told_both: dict[float, list[float]] = {f: [] for f in FRACTIONS}
    n_records = 0
    for folder in folders or [str(ROOT / ".cache" / "datasets")]:
        for path in sorted(Path(folder).glob("*.h5")):
            try:
                with h5py.File(path, "r") as f:
                    kind = f.attrs.get("kind")
                    kind = kind.decode() if isinstance(kind, bytes) else kind
                    pairs = RATE_PAIRS.get(str(kind), ())
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
                    for bits in (None, 16, 12):
                        qa, qd = (a, d) if bits is None else (quantised(a, bits), quantised(d, bits))
                        clean += [(v, f"{path.name} {g}/{dg} {bits or 'float'}")
                                  for v in pair_mismatches(qa, qd, fs, ends_only=False)]
                    for frac in FRACTIONS:
                        for which in ("signal", "rate"):
                            for clip, store in ((clipped_from_end, told), (clipped_both, told_both)):
                                aa = clip(a, 1 - frac) if which == "signal" else a
                                dd = clip(d, 1 - frac) if which == "rate" else d
                                v = pair_mismatches(aa, dd, fs, ends_only=False)
                                store[frac].append(max(v) if v else 0.0)
    clean.sort(reverse=True)
    print(f"{n_records} records with rate pairs; {len(clean)} held runs of unclipped channels "
          "(float, 16- and 12-bit copies)")
    print("largest unclipped mismatches:", [(round(v, 4), n) for v, n in clean[:6]])
    for name, store in (("from the end it starts or ends nearer", told), ("at +-frac of the peak",
                                                                          told_both)):
        for frac, vals in store.items():
            v = np.asarray(vals)
            print(f"clipped {name}, {int(100 * frac)} % cut: {v.size} channels, quantiles 5/50 % "
                  f"{np.quantile(v, 0.05):.4g} / {np.quantile(v, 0.5):.4g}, above 0.05: "
                  f"{np.mean(v > 0.05):.3f}, no held run: {np.mean(v == 0):.3f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
