"""A small hand-made record saved as a dataset file, and a record with a clipped sensor, for the
malformed-input tests."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np

from testbed.core.dataset import Dataset, Signal

FS = 1000.0  # Hz; 400 samples of a 7 Hz sine: any rate and length the readers accept


def saved_record(tmp_path: Path) -> Path:
    """A hand-made record (no kind: no truth to validate), saved with its content hash."""
    t = np.arange(400) / FS
    acc = np.vstack([np.sin(2 * np.pi * 7 * t) * (k + 1) for k in range(2)])
    ds = Dataset(FS, {"acceleration": Signal(acc, ("acc1", "acc2"), "m/s^2"),
                      "force": Signal(np.exp(-t / 0.01)[None, :], ("force",), "N")})
    return ds.save(tmp_path / "d.h5")


def clipped_acc1(ds: Dataset, share: float = 0.1) -> tuple[Dataset, float]:
    """``ds`` with its first acceleration channel clipped at ``share`` of its peak (a saturated
    sensor, hostile round 20), and the clip level [m/s^2]."""
    s = ds.measured["acceleration"]
    a = s.data.copy()
    lim = share * float(np.max(np.abs(a[0])))
    a[0] = np.clip(a[0], -lim, lim)
    return dataclasses.replace(ds, measured={**ds.measured,
                                             "acceleration": dataclasses.replace(s, data=a)}), lim
