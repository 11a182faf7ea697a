"""Mode 2's linear frequency from its own equation with the cross term, on soft-base members.

Usage::

    PYTHONPATH=. .venv/bin/python benchmarks/heldout/soft21_mode2_cross.py STUDY.toml PREFIX \
        [NOISE] [IDENT] > out.tsv

Issue #15, class (i): a soft base's mode 2 dies while mode 1 still swings near its first
amplitude, so mode 2's record frequency is stiffened by the cubic's tangent stiffness at mode 1's
amplitude, ``3 k3 b_1^2 b_2^2 q_1^2 q_2`` in mode 2's equation (``b_k = c . phi_k``).  Averaged
over mode 1's cycle that term is all but constant over mode 2's life (``exp(-2 sigma_1 t)`` keeps
0.91-0.94 of itself: known-gaps, condition 380-570), but sample by sample ``q_1^2`` swings
between 0 and ``A_1^2`` twice per mode-1 period: an equation-error regression of mode 2's modal
acceleration on ``q_1^2 q_2`` reads the cross term from that swing (the sidebands at
``w_2 +- 2 w_1``), not from the envelope.

For each member (the identifier sees the record only; the truth is used to score the estimate):
the identifier's model (``IDENT``, default settings) gives the modes ``Phi``; the record's modal
coordinates ``q = Phi^-1 x`` (and ``q', q''``) over mode 2's life (its fitted decay to 1e-3,
from the free start) are regressed, mode 2's row,
``q_2'' = -w^2 q_2 - d q_2' - kappa q_1^2 q_2 - g q_1^3 - mu q_2^3 - nu q_1 q_2^2 + a q_1 + b q_1'``
(+ the chain's drift waveforms), and ``w / 2 pi`` is the estimate (``lin``: without the cubic
columns, the record's hardened frequency).  Printed: the truth's undamped f2, the model's f2,
the estimate with and without the cross columns, and the same on the truth's own modes
(diagnosis: what the regression can give at best), signed errors [%].
"""

from __future__ import annotations

import sys

import numpy as np
import scipy.linalg as sla

from identify.structural import fit_band_cutoff, modal, modal_peaks
from testbed.numerics.filters import elliptic_highpass
from testbed.pipeline import plugins
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.signal_chain import measure
from testbed.studies.study import load_study
from testbed.studies.sweep import expand


def cross_regression(data, Phi: np.ndarray, sigma2: float, cross: bool = True,
                     fc: float = 0.0, w_acc: np.ndarray | None = None) -> float:
    """Mode 2's undamped frequency [Hz] from its modal equation (module docstring).

    ``Phi`` (n, n) the modes (columns, ascending), ``sigma2`` [1/s] mode 2's decay rate (the
    window ends where its envelope has fallen to 1e-3: ``ln(1e3) / sigma2``), ``fc`` [Hz] the
    identifier's fit-band high-pass (:func:`identify.structural.fit_band_cutoff`), applied to
    every column after the products are formed, as the identifier's library is.
    """
    s = int(data.free_start)
    n_win = int(min(data.x.shape[1] - s, np.log(1e3) / max(sigma2, 1e-9) * data.fs))
    q = np.linalg.solve(Phi, np.asarray(data.x, float))
    qd = np.linalg.solve(Phi, np.asarray(data.xd, float))
    qdd = np.linalg.solve(Phi, np.asarray(data.xdd, float))
    q1, q2, q1d, q2d = q[0], q[1], qd[0], qd[1]
    cols = [q2, q2d, q1, q1d]
    if cross:
        p1, p2 = q1, q2
        if w_acc is not None:  # the products from the measured accelerations, -q''/w^2
            p1, p2 = -qdd[0] / w_acc[0] ** 2, -qdd[1] / w_acc[1] ** 2
        cols += [p1 * p1 * p2, p1 ** 3, p2 ** 3, p1 * p2 * p2]
    if getattr(data, "drift_basis", None) is not None:
        cols += list(np.asarray(data.drift_basis, float))
    A = np.vstack([*cols, qdd[1]])
    if fc > 0:
        A = elliptic_highpass(A, data.fs, fc, 5)
    A = A[:, s:s + n_win]
    A, y = A[:-1].T, A[-1]
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    coef = np.linalg.lstsq(A / scale, -y, rcond=None)[0] / scale
    w2 = coef[0]
    cross_regression.last = coef
    return float(np.sqrt(w2) / (2 * np.pi)) if w2 > 0 else float("nan")


def _rows(data, Phi: np.ndarray, fc: float):
    """Modal coordinates ``q, q', q''`` (each (n, N)) of the record, and the drift rows."""
    q = np.linalg.solve(Phi, np.asarray(data.x, float))
    qd = np.linalg.solve(Phi, np.asarray(data.xd, float))
    qdd = np.linalg.solve(Phi, np.asarray(data.xdd, float))
    drift = [] if getattr(data, "drift_basis", None) is None else list(np.asarray(data.drift_basis, float))
    return q, qd, qdd, drift


def _lstsq(cols: list, y: np.ndarray, fc: float, data, sl: slice) -> np.ndarray:
    A = np.vstack([*cols, y])
    if fc > 0:
        A = elliptic_highpass(A, data.fs, fc, 5)
    A = A[:, sl]
    A, y = A[:-1].T, A[-1]
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    return np.linalg.lstsq(A / scale, y, rcond=None)[0] / scale


def symmetric_kappa(data, Phi: np.ndarray, sigma2: float, fc: float) -> tuple[float, float, float]:
    """The cross coefficient ``kappa`` of ``q_1^2 q_2`` in mode 2's equation from a symmetric
    rank-one cubic, ``kappa = 3 g^2 / s_1`` (mass-normalised modes): ``s_1`` the ``q_1^3``
    coefficient of mode 1's equation and ``g`` that of mode 2's, both over the whole record
    (mode 1 rings through it); and mode 2's frequency [Hz] over its life with ``kappa`` held.
    Returns ``(s_1, g, f_2)``.
    """
    q, qd, qdd, drift = _rows(data, Phi, fc)
    s = int(data.free_start)
    q1, q2 = q[0], q[1]
    whole = slice(s, None)
    c1 = _lstsq([q1, qd[0], q2, qd[1], q1 ** 3, *drift], -qdd[0], fc, data, whole)
    c2 = _lstsq([q2, qd[1], q1, qd[0], q1 ** 3, *drift], -qdd[1], fc, data, whole)
    s1, g = float(c1[4]), float(c2[4])
    kap = 3 * g * g / s1 if s1 > 0 else 0.0
    n_win = int(min(data.x.shape[1] - s, np.log(1e3) / max(sigma2, 1e-9) * data.fs))
    c = _lstsq([q2, qd[1], q1, qd[0], q1 ** 3, *drift], -qdd[1] - kap * q1 * q1 * q2, fc, data,
               slice(s, s + n_win))
    return s1, g, float(np.sqrt(c[0]) / (2 * np.pi)) if c[0] > 0 else float("nan")


def driving_point_modes(mod, Phi: np.ndarray, data) -> np.ndarray | None:
    """The model's modes rescaled to unit modal mass by the measured force at the driving
    point: each modal coordinate's equation with the model's own frequency and damping,
    ``q_k'' + d_k q_k' + w_k^2 q_k = r_k u``, regressed over the record's start (the pulse and
    as long again after it) for ``r_k = phi_k[j] / alpha_k``, and ``alpha_k^2 = Phi[j, k] / r_k``
    (``j`` the driven sensor); None where modes 1-2 give a non-positive ratio."""
    if data.u is None or data.input_map is None:
        return None
    D = np.asarray(data.input_map, float)
    j = int(np.flatnonzero(D[:, 0])[0])
    u = np.asarray(data.u, float)[0]
    n_end = min(3 * max(int(data.free_start), 1), u.size)
    q = np.linalg.solve(Phi, np.asarray(data.x, float))[:, :n_end]
    qd = np.linalg.solve(Phi, np.asarray(data.xd, float))[:, :n_end]
    qdd = np.linalg.solve(Phi, np.asarray(data.xdd, float))[:, :n_end]
    w2 = np.real(np.diag(Phi.T @ mod.K_ @ Phi))
    d = np.diag(Phi.T @ mod.C_ @ Phi)
    r = np.empty(Phi.shape[1])
    for k in range(Phi.shape[1]):
        y = qdd[k] + d[k] * qd[k] + w2[k] * q[k]
        r[k] = float(u[:n_end] @ y / (u[:n_end] @ u[:n_end]))
    a2 = Phi[j] / r
    if np.any(~(a2[:2] > 0)):
        return None
    a = np.sqrt(np.where(a2 > 0, a2, 1.0))
    return Phi / a


def main() -> None:
    study, prefix = sys.argv[1], sys.argv[2]
    noise = float(sys.argv[3]) if len(sys.argv) > 3 else 0.0
    ident = sys.argv[4] if len(sys.argv) > 4 else "ls_sindy"
    cache = DatasetCache()
    print("member\tf2_true\tzeta2\tmodel\tmodel_cross_acc\tmodel_lin\tmodel_cross\ttruthmodes_lin\ttruthmodes_cross")
    for cell in expand(load_study(study)):
        sc = cell.scenario
        if not sc.name.startswith(prefix) or cell.noise != noise or cell.identifier != ident:
            continue
        ds = cache.get(sc)
        tr = ds.typed_truth
        data = measure(ds, sc.signal, sc.kind)
        f2 = float(np.asarray(tr.frequencies_hz)[1])
        z2 = float(np.asarray(tr.damping_ratios)[1])
        try:
            mod = plugins.make_identifier(sc.identify, sc.name).fit(data)
        except Exception as e:  # a refusal: no model, no row
            print(f"{sc.name}\t{f2:.3f}\t{z2:.3f}\t{type(e).__name__}", flush=True)
            continue
        try:
            fm, Phi = modal(mod.M_, mod.K_)
            _ = np.linalg.inv(Phi)
        except np.linalg.LinAlgError:
            print(f"{sc.name}\t{f2:.3f}\t{z2:.3f}\tsingular modes", flush=True)
            continue
        d = np.einsum("ik,ij,jk->k", Phi, mod.C_, Phi)
        sigma2 = 0.5 * float(d[1])
        _, phi_t = sla.eigh(tr.Kr, tr.Mr)
        fc = fit_band_cutoff(data, None, modal_peaks(data).peaks)[0]
        wm = 2 * np.pi * fm
        row = [fm[1] if len(fm) > 1 else np.nan,
               cross_regression(data, Phi, sigma2, True, fc, wm),
               cross_regression(data, Phi, sigma2, False, fc), cross_regression(data, Phi, sigma2, True, fc),
               cross_regression(data, phi_t, z2 * 2 * np.pi * f2, False, fc)
               if phi_t.shape[0] == data.x.shape[0] else np.nan,
               cross_regression(data, phi_t, z2 * 2 * np.pi * f2, True, fc)
               if phi_t.shape[0] == data.x.shape[0] else np.nan]
        # the truth's own cross and forcing coefficients in mode 2's equation (symmetric cubic
        # k3 c (c . x)^3 in Mr's coordinates, b_k = c . phi_k, mass-normalised phi)
        b = np.asarray(tr.cubic_map, float) @ phi_t
        k3 = float(tr.k3 or 0.0)
        kap, g = 3 * k3 * b[0] ** 2 * b[1] ** 2, k3 * b[1] * b[0] ** 3
        cf = getattr(cross_regression, "last", np.full(6, np.nan))
        try:
            s1, gg, f2s = symmetric_kappa(data, phi_t, z2 * 2 * np.pi * f2, fc)
        except np.linalg.LinAlgError:
            s1 = gg = f2s = np.nan
        P = driving_point_modes(mod, Phi, data)
        if P is not None:
            s1m, gm, f2m = symmetric_kappa(data, P, sigma2, fc)
            bm = (gm / s1m) ** 2 if s1m > 0 else np.nan
            nr = [np.linalg.norm(P[:, k]) / np.linalg.norm(phi_t[:, k]) for k in (0, 1)]
        else:
            bm, f2m, nr = np.nan, np.nan, [np.nan, np.nan]
        sym0 = (f"\tnorm1,2 {nr[0]:.3f} {nr[1]:.3f}\tmodel (b2/b1)^2 {bm / (b[1] / b[0]) ** 2:.3f}"
                f"\tmodel_f2_sym {100 * (f2m / f2 - 1):+.2f}")
        sym = sym0 + (f"\ts1 {s1 / (k3 * b[0] ** 4):.3f}\tg {gg / g:.3f}"
                      f"\tkappa_sym {3 * gg * gg / s1 / kap:.3f}"
               f"\tf2_sym {100 * (f2s / f2 - 1):+.2f}")
        print(f"{sc.name}\t{f2:.3f}\t{z2:.3f}\t"
              + "\t".join(f"{100 * (v / f2 - 1):+.2f}" for v in row)
              + f"\tkappa_fit/true {cf[4] / kap:.3f}\tg_fit/true {cf[5] / g:.3f}" + sym, flush=True)


if __name__ == "__main__":
    main()
