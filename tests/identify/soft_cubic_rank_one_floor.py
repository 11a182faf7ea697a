"""The soft base's cubic floor in two library forms: diagonal ``K3 x^3`` and rank one ``b (a . x)^3``.

Not a test (no ``test_`` prefix): a script that prints one line per soft-base member (issue #15).
Given the truth's reduced linear model (``Mr, Cr, Kr``) on the *oracle* data (the reduced
truth itself, cubic included, simulated by :func:`models.cantilever.truth.simulate_reduced`)
passed through the scenario's signal chain (what an identifier gets), it fits the cubic
force by least squares in each form and reports its acceleration error against the truth's
cubic ``k3 d (c . x)^3`` (``K3_accel_error``'s measure: relative RMS of ``Mr^-1 f``):

- ``diag``: the n features ``x_j^3`` with a full ``K3`` (n x n), as
  ``tests/identify/soft_cubic_floor.py``'s ``chain``;
- ``rank1``: ``b (a . x)^3`` with a unit direction ``a`` and a free ``b`` (n,), by variable
  projection (:func:`identify._cubic.fit_rank_one`): for a given ``a`` the best ``b`` is linear
  least squares, and ``a`` is optimised on the sphere from several deterministic starts;
- ``|Fx-x|``, ``|xm-Fx|``: how far the chain's filter alone moves the exact displacement on
  the window, and how far the measured one is from that (integration, rest offset), relative
  to the exact displacement's norm;
- ``F[x^3]``: the diagonal and ``@c`` cubic with features in the chain's order, the chain's
  filter applied to the cube of the exact displacement (the filtered equation's own term);
  ``F[xm^3]`` the same with the measured displacement's cube (what an identifier could form);
- ``raw``: the same on the oracle's exact signals (no chain), with the directions' angles;
- ``sym``: the symmetric rank one ``g a (a . x)^3`` (one scalar ``g``: the force of the
  potential ``g (a . x)^4 / 4``, as the truth's, whose ``d`` and ``c`` are the same vector);
- ``rank1@c``: ``b (c . x)^3`` with the truth's own direction ``c`` and ``b`` fitted (chain);
- ``angle``: the angle [deg] between the fitted ``a`` and the truth's ``c`` (chain);
- ``mode-2 shift``: the cross term, each cubic's (truth, diagonal, rank one; chain fits)
  tangent stiffness at ``x = A phi_1`` along ``phi_2`` over ``phi_2^T Kr phi_2`` [%], ``A``
  mode 1's RMS amplitude on the window times sqrt 2 (``phi`` the truth's reduced modes).

    PYTHONPATH=$PWD .venv/bin/python tests/identify/soft_cubic_rank_one_floor.py DIR [0,7,12]

Trailing ``signal.KEY=VALUE`` arguments override the scenario's chain (a diagnosis: which part
of the chain sets the floor).  ``DIR`` holds the members written by
``testbed family write studies/families.toml -o DIR
--family beams_soft``; datasets go through the ordinary cache.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from soft_cubic_floor import oracle_dataset  # this folder: the script's own (run as a script)

from identify._cubic_form import cubic_jacobian, fit_rank_one
from identify._sgd_matrix import NUISANCE_RCOND, nuisance_basis, project_out
from testbed.core.truth import StructuralTruth
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure


def floors(truth: StructuralTruth, x: np.ndarray, xd: np.ndarray, xdd: np.ndarray,
           W: np.ndarray | None) -> tuple[float, float, float]:
    """Acceleration errors of the diagonal and rank-one least-squares cubics, and the angle."""
    f = np.outer(truth.cubic_direction, float(truth.k3) * (truth.cubic_map @ x) ** 3)
    a_true = np.linalg.solve(truth.Mr, f)
    lin = truth.Mr @ xdd + truth.Cr @ xd + truth.Kr @ x
    linp, x3p = project_out(W, lin, x**3) if W is not None else (lin, x**3)
    K3 = np.linalg.lstsq(x3p.T, -linp.T, rcond=None)[0].T
    e_diag = np.linalg.norm(np.linalg.solve(truth.Mr, K3 @ x**3) - a_true) / np.linalg.norm(a_true)
    Q = None
    if W is not None and W.shape[1]:
        U, sv, _ = np.linalg.svd(W / np.sqrt(np.mean(W**2, axis=0))[None, :], full_matrices=False)
        Q = U[:, sv > NUISANCE_RCOND * sv[0]]  # project_out's own basis
    a, b = fit_rank_one(x, -linp, Q=Q)
    e_r1 = np.linalg.norm(np.linalg.solve(truth.Mr, np.outer(b, (a @ x) ** 3)) - a_true) \
        / np.linalg.norm(a_true)
    a_s, b_s = fit_rank_one(x, -linp, Q=Q, symmetric=True)
    e_s = np.linalg.norm(np.linalg.solve(truth.Mr, np.outer(b_s, (a_s @ x) ** 3)) - a_true) \
        / np.linalg.norm(a_true)
    c = truth.cubic_map / np.linalg.norm(truth.cubic_map)
    ang_s = float(np.degrees(np.arccos(min(1.0, abs(float(a_s @ c))))))
    zc = (c @ x) ** 3
    zcp = zc - (zc @ Q) @ Q.T if Q is not None else zc
    bc = (-linp @ zcp) / float(zcp @ zcp)
    e_c = np.linalg.norm(np.linalg.solve(truth.Mr, np.outer(bc, zc)) - a_true) / np.linalg.norm(a_true)
    ang = float(np.degrees(np.arccos(min(1.0, abs(float(a @ c))))))
    # the cross term: mode 2's stiffening by mode 1's amplitude, as each cubic's tangent
    # stiffness at x = A phi_1 along phi_2, relative to phi_2's linear stiffness
    from scipy.linalg import eigh
    _, phi = eigh(truth.Kr, truth.Mr)
    q1 = phi[:, 0] @ truth.Mr @ x
    x1 = np.sqrt(2.0) * float(np.sqrt(np.mean(q1**2))) * phi[:, 0]
    k22 = float(phi[:, 1] @ truth.Kr @ phi[:, 1])
    shift = [float(phi[:, 1] @ Jm @ phi[:, 1]) / k22 * 100.0 for Jm in (
        cubic_jacobian(float(truth.k3) * truth.cubic_direction[:, None], x1, truth.cubic_map[None, :]),
        cubic_jacobian(K3, x1), cubic_jacobian(b[:, None], x1, a[None, :]),
        cubic_jacobian(b_s[:, None], x1, a_s[None, :]))]
    return float(e_diag), float(e_r1), ang, shift, float(e_c), float(e_s), ang_s


def chain_order(truth: StructuralTruth, x: np.ndarray, xd: np.ndarray, xdd: np.ndarray,
                W: np.ndarray, x_exact: np.ndarray, chain) -> tuple[float, float]:
    """The diagonal and the truth-direction cubic with their features taken in the chain's
    order, ``F[x^3]`` (``F`` the chain's filter applied to the cube of the exact displacement,
    as the equation of the filtered signals has it) instead of ``(F x)^3``: acceleration
    errors as :func:`floors`'s, along the exact displacement of the window (the cubic's
    coefficients are compared: its features are not the measured cube)."""
    xe = x_exact[:, -x.shape[1]:]
    f = np.outer(truth.cubic_direction, float(truth.k3) * (truth.cubic_map @ xe) ** 3)
    a_true = np.linalg.solve(truth.Mr, f)
    lin = truth.Mr @ xdd + truth.Cr @ xd + truth.Kr @ x
    out = []
    for A in (None, truth.cubic_map[None, :]):
        feat = chain(x_exact**3 if A is None else (A @ x_exact) ** 3)[:, -x.shape[1]:]
        linp, fp = project_out(W, lin, feat)
        K3 = np.linalg.lstsq(fp.T, -linp.T, rcond=None)[0].T
        ze = xe**3 if A is None else (A @ xe) ** 3
        out.append(float(np.linalg.norm(np.linalg.solve(truth.Mr, K3 @ ze) - a_true)
                         / np.linalg.norm(a_true)))
    return out[0], out[1]


def member(path: Path, cache: DatasetCache, signal: dict | None = None) -> str:
    sc = load_scenario(path)
    ds = cache.get(sc)
    tr = ds.truth_as(StructuralTruth)
    start = int(ds.attrs["free_start"]) + 200
    oracle = oracle_dataset(sc, ds, tr)
    u, ud, udd = (oracle.reference[k].data for k in ("displacement", "velocity", "acceleration"))
    raw_d, raw_r, raw_ang, _, _, raw_s, raw_ang_s = floors(tr, u[:, start:], ud[:, start:],
                                                           udd[:, start:], None)
    m = measure(oracle, {**sc.signal, **(signal or {})}, sc.kind)
    i0 = m.free_start
    W = nuisance_basis(m, i0, m.n_samples)[0]
    window = [np.asarray(a, float)[:, i0:] for a in (m.x, m.xd, m.xdd)]
    ch_d, ch_r, ang, sh, ch_c, ch_s, ang_s = floors(tr, *window, W)
    from testbed.numerics import filters as sig
    cfg = {**sc.signal, **(signal or {})}
    fs = float(ds.fs)

    def chain(z: np.ndarray) -> np.ndarray:  # the force's filter: low-pass, high-pass twice
        if cfg["lowpass_hz"] > 0:
            z = sig.lowpass(z, fs, cfg["lowpass_hz"], int(cfg["lowpass_order"]))
        for _ in range(2):
            z = sig.elliptic_highpass(z, fs, cfg["highpass_hz"], int(cfg["highpass_order"]),
                                      cfg["ripple_db"], cfg["stop_db"])
        return z

    co_d, co_c = chain_order(tr, *window, W, u, chain)
    cm_d, cm_c = chain_order(tr, *window, W, np.asarray(m.x, float), chain)
    Fu = chain(u)
    rel = float(np.linalg.norm(u[:, i0:]))
    e_F = float(np.linalg.norm((Fu - u)[:, i0:])) / rel
    e_m = float(np.linalg.norm((np.asarray(m.x, float) - Fu)[:, i0:])) / rel
    return (f"{sc.name}: n {u.shape[0]} | |Fx-x| {e_F:.3f} |xm-Fx| {e_m:.3f}"
            f" | F[x^3] diag {co_d:.3f} @c {co_c:.3f} F[xm^3] diag {cm_d:.3f} @c {cm_c:.3f}"
            f" | raw diag {raw_d:.4f} rank1 {raw_r:.4f} sym {raw_s:.4f}"
            f" angle {raw_ang:.1f} sym {raw_ang_s:.1f} deg"
            f" | chain diag {ch_d:.3f} rank1 {ch_r:.3f} sym {ch_s:.3f} rank1@c {ch_c:.3f}"
            f" angle {ang:.1f} sym {ang_s:.1f} deg | mode-2 shift % truth {sh[0]:.2f}"
            f" diag {sh[1]:.2f} rank1 {sh[2]:.2f} sym {sh[3]:.2f}")


def main(argv: list[str]) -> None:
    signal = {}
    while argv[-1].startswith("signal."):  # e.g. signal.highpass_hz=1 (a diagnosis of the chain)
        k, v = argv.pop()[len("signal."):].split("=")
        signal[k] = float(v)
    files = sorted(Path(argv[1]).glob("*.toml"))
    if len(argv) > 2:
        files = [files[int(k)] for k in argv[2].split(",")]
    cache = DatasetCache()
    for f in files:
        print(member(f, cache, signal), flush=True)


if __name__ == "__main__":
    main(sys.argv)
