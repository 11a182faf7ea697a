"""Diagnosis of one soft-base member with its truth (never seen by an identifier).

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/soft_diagnose.py STUDY.toml MEMBER [NOISE]

Prints, for modes 1-2: the truth's undamped frequencies; the first-order hardening of each mode
at the record's start and in its last fifth (the truth's own cubic through its modes); the
frequency the clean record's late part shows (the truth's modal coordinate, zero crossings);
the linear frequencies a least-squares fit of the record gives with the truth's own cubic
subtracted (oracle cubic), with none (linear) and the identifiers' own fits stage by stage.
"""

from __future__ import annotations

import sys

import numpy as np
import scipy.linalg as sla

from identify.ls_sindy import LeastSquaresSINDy
from identify.sgd_sindy import SGDSINDy
from identify.structural import (
    Library,
    build_library,
    fit_band_cutoff,
    matrices_from_coef,
    modal,
    modal_peaks,
    solve_rows,
    tilt_library,
)
from testbed.numerics.filters import elliptic_highpass
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.signal_chain import measure
from testbed.scoring.run import noise_free
from testbed.studies.study import load_study
from testbed.studies.sweep import expand


def member(study: str, name: str, noise: float):
    for cell in expand(load_study(study)):
        if cell.scenario.name == name and cell.noise == noise and cell.identifier == "ls_sindy":
            return cell.scenario
    raise SystemExit(f"no member {name}")


def zero_cross_freq(a: np.ndarray, fs: float) -> float:
    s = np.signbit(a)
    idx = np.flatnonzero(s[1:] != s[:-1])
    if idx.size < 3:
        return float("nan")
    # linear interpolation of crossing times
    t = idx + a[idx] / (a[idx] - a[idx + 1])
    return float((idx.size - 1) / 2.0 / ((t[-1] - t[0]) / fs))


def oracle_fit(data, cub_acc: np.ndarray | None, peaks: np.ndarray, tilt: bool = True):
    """Linear least squares of ``x'' - cub_acc`` (cub_acc over the whole record) in the
    identifier's fit band; returns undamped frequencies [Hz]."""
    s = int(data.free_start)
    fc, _ = fit_band_cutoff(data, None, peaks)
    full = build_library(data, coupled_mass=False, cubic=False, start=0, drift=True,
                         input_coupling=True)
    tgt = full.target + (cub_acc if cub_acc is not None else 0.0)  # x'' + Mr^-1 d k3 (c.x)^3 = linear
    hp = (lambda z: elliptic_highpass(z, data.fs, fc, 5)[:, s:]) if fc > 0 else (lambda z: z[:, s:])
    lib = Library(hp(full.theta), hp(tgt), full.mask, full.names, full.blocks)
    if tilt:
        lib = tilt_library(lib)
    n = lib.target.shape[0]
    M, _, K, _ = matrices_from_coef(solve_rows(lib), lib.blocks, np.ones(n))
    return modal(M, K)[0]


def direction_fit(data, c: np.ndarray, peaks: np.ndarray) -> np.ndarray:
    """As :func:`oracle_fit` with one cubic column ``(c . x)^3`` (the truth's direction ``c``,
    a free coefficient per row) in place of the subtracted cubic; undamped frequencies [Hz]."""
    s = int(data.free_start)
    fc, _ = fit_band_cutoff(data, None, peaks)
    full = build_library(data, coupled_mass=False, cubic=False, start=0, drift=True,
                         input_coupling=True)
    theta = np.vstack([full.theta, (c @ np.asarray(data.x, dtype=float)) ** 3])
    mask = np.hstack([full.mask, np.ones((full.mask.shape[0], 1), dtype=bool)])
    hp = (lambda z: elliptic_highpass(z, data.fs, fc, 5)[:, s:]) if fc > 0 else (lambda z: z[:, s:])
    lib = tilt_library(Library(hp(theta), hp(full.target), mask, [*full.names, "cx^3"],
                               full.blocks))
    n = lib.target.shape[0]
    M, _, K, _ = matrices_from_coef(solve_rows(lib), lib.blocks, np.ones(n))
    return modal(M, K)[0]


def main() -> None:
    study, name = sys.argv[1], sys.argv[2]
    noise = float(sys.argv[3]) if len(sys.argv) > 3 else 0.0
    sc = member(study, name, noise)
    ds = DatasetCache().get(sc)
    tr = ds.typed_truth
    data = measure(ds, sc.signal, sc.kind)
    clean = measure(noise_free(ds), sc.signal, sc.kind)
    m = data.x.shape[0]
    f_true = np.asarray(tr.frequencies_hz)[:m]
    z_true = np.asarray(tr.damping_ratios)[:m]
    lam, phi = sla.eigh(tr.Kr, tr.Mr)
    print(f"{name} noise {noise}: sensors {m}, rig {sc.rig}")
    print("  truth f [Hz]", np.round(f_true[:3], 3), "reduced", np.round(np.sqrt(lam[:3]) / 2 / np.pi, 3),
          "zeta", np.round(z_true[:3], 4))
    k3 = float(tr.k3 or 0.0)
    c, d = np.asarray(tr.cubic_map), np.asarray(tr.cubic_direction)
    s = int(data.free_start)
    a = np.linalg.solve(phi, clean.x)  # modal coordinates of the clean record
    n = clean.x.shape[1]
    # first-order backbone: dw/w = 3/8 gamma_k A_k^2 / w_k^2, gamma_k = k3 (d.phi_k)(c.phi_k)^3
    gam = k3 * (d @ phi) * (c @ phi) ** 3
    for k in range(min(2, m)):
        env = lambda seg: float(np.max(np.abs(seg)))  # noqa: E731
        A0 = env(a[k, s:s + int(0.02 * data.fs)])
        Al = env(a[k, n - n // 5:])
        sh0 = 3 / 8 * gam[k] * A0 ** 2 / lam[k]
        shl = 3 / 8 * gam[k] * Al ** 2 / lam[k]
        late = zero_cross_freq(a[k, n - 2 * n // 5:], data.fs)
        early = zero_cross_freq(a[k, s:s + n // 5], data.fs)
        print(f"  mode {k + 1}: hardening start {100 * sh0:+.2f} %, last fifth {100 * shl:+.3f} %;"
              f" zero-cross freq early {early:.3f} ({100 * (early / f_true[k] - 1):+.2f} %),"
              f" last 2/5 {late:.3f} ({100 * (late / f_true[k] - 1):+.2f} %)")
    # cross term: mode 2's shift from the cubic's tangent stiffness at mode 1's RMS amplitude
    if m >= 2:
        A1 = np.sqrt(np.mean(a[0, s:] ** 2))
        tang = 3 * k3 * (d @ phi[:, 1]) * (c @ phi[:, 1]) * (c @ phi[:, 0]) ** 2 * A1 ** 2
        print(f"  cross: mode 2 tangent shift at mode 1's RMS {100 * 0.5 * tang / lam[1]:+.3f} %")
    peaks = modal_peaks(data).peaks
    print("  peaks", np.round(peaks, 3))
    for lab, dat in (("record", data),) if noise == 0 else (("record", data), ("clean chain", clean)):
        cub = np.linalg.solve(tr.Mr, np.outer(d, k3 * (c @ dat.x) ** 3))
        fo = oracle_fit(dat, cub, peaks)
        fl = oracle_fit(dat, None, peaks)
        fdir = direction_fit(dat, c, peaks)
        print(f"  {lab}: LS tilted with one (c . x)^3 column (the truth's direction, fitted size):",
              " ".join(f"{100 * (fdir[k] / f_true[k] - 1):+.2f}%" for k in range(min(3, m))))
        print(f"  {lab}: LS tilted with the truth's cubic subtracted:",
              " ".join(f"{100 * (fo[k] / f_true[k] - 1):+.2f}%" for k in range(min(3, m))),
              "| linear:", " ".join(f"{100 * (fl[k] / f_true[k] - 1):+.2f}%" for k in range(min(3, m))))
    for cls, kw in ((LeastSquaresSINDy, {}), (LeastSquaresSINDy, {"decay_hold": False}),
                    (LeastSquaresSINDy, {"cubic": False}), (LeastSquaresSINDy, {"cubic": True}),
                    (SGDSINDy, {})):
        try:
            mod = cls(**kw).fit(data)
        except Exception as e:
            print(f"  {cls.name} {kw}: {type(e).__name__} {e}")
            continue
        f = np.asarray(mod.natural_frequencies_)
        err = [100 * (f[np.argmin(abs(f - f_true[k]))] / f_true[k] - 1) for k in range(min(2, m))]
        dec = getattr(mod, "modal_decay_", None)
        ds_ = ""
        if dec is not None:
            wd = dec.omega_d[:2] / 2 / np.pi
            ds_ = (" decay wd " + " ".join(f"{100 * (w / f_true[k] - 1):+.2f}%" for k, w in enumerate(wd))
                   + " taken " + str(dec.taken[:2].tolist()))
            if dec.chirp is not None:
                ds_ += " chirp/wd " + " ".join(f"{x:+.4f}" for x in dec.chirp[:2] / dec.omega_d[:2])
        print(f"  {cls.name} {kw}: cubic {getattr(mod, 'K3_', None) is not None},"
              f" modes 1-2 {err[0]:+.2f} {err[1] if len(err) > 1 else float('nan'):+.2f} %;{ds_}")


if __name__ == "__main__":
    main()
