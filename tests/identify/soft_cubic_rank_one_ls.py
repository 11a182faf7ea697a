"""The rank-one cubic inside ``ls_sindy``'s own regression, beside its diagonal cubic. Per member.

Not a test (no ``test_`` prefix): a diagnosis script (issue #15, the soft base).  On a soft-base
member's measured record (the scenario's own data and chain), it fits ``ls_sindy``'s first
regression (diagonal mass ``m_hat / n``, velocity, displacement, input and drift columns in
every row, the fit band's high-pass chosen by ``ls_sindy``'s rule, one difference of tilt) with
the cubic block in two forms, least squares jointly with the linear columns:

- ``diag``: the n features ``x_j^3`` (``ls_sindy`` with ``cubic = true``, before its holds);
- ``rank1``: one feature ``(a . x)^3`` shared by every row, ``b`` free per row, ``a`` by
  variable projection (:func:`identify._cubic_form.fit_rank_one`, the linear columns
  projected out, the band and the tilt as its ``transform``).

It prints, for each form, ``K3_accel_error`` and ``K3_force_error`` (the scorer's measures,
along the chain's noise-free displacement of the fit window) and the cross term: mode 2's
first-order eigenvalue shift from the cubic's tangent stiffness at ``x = A phi_1`` (the
truth's mode 1 at its RMS amplitude on the window times sqrt 2; the same displacement for
every model), in % of its linear eigenvalue, with each model's own left and right modes; and
the truth's.  No holds, no rule: the regression alone.

    PYTHONPATH=$PWD .venv/bin/python tests/identify/soft_cubic_rank_one_ls.py DIR [0,7] [noise%] [oracle]

``oracle`` (last): the record replaced by the reduced truth's own simulation, clean (as
``soft_cubic_floor.py``'s oracle): the regression's own floor, without the MuJoCo model's
unreduced modes.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
from soft_cubic_floor import oracle_dataset  # this folder: the script's own (run as a script)

from identify._cubic_form import cubic_jacobian, fit_rank_one
from identify.structural import (
    FIT_BAND_ORDER,
    build_library,
    fit_band_cutoff,
    mass_prior_value,
    modal_peaks,
    tilt_rows,
)
from testbed.core.truth import StructuralTruth
from testbed.numerics.filters import elliptic_highpass
from testbed.pipeline.cache import DatasetCache
from testbed.pipeline.scenario import load_scenario
from testbed.pipeline.signal_chain import measure
from testbed.scoring import metrics
from testbed.scoring.run import noise_free


def mode2_shift(M: np.ndarray, K: np.ndarray, J: np.ndarray) -> float:
    """First-order relative shift [%] of the second-lowest eigenvalue of ``M^-1 K`` by ``J``."""
    lam, R = np.linalg.eig(np.linalg.solve(M, K))
    order = np.argsort(lam.real)
    lam, R = lam[order].real, R[:, order].real
    L = np.linalg.inv(R).T  # left eigenvectors, l_k^T r_k = 1
    return float(L[:, 1] @ np.linalg.solve(M, J) @ R[:, 1] / lam[1] * 100.0)


def member(path: Path, cache: DatasetCache, noise: float | None, use_oracle: bool = False) -> str:
    from scipy.linalg import eigh

    sc = load_scenario(path)
    if noise is not None:
        sc = dataclasses.replace(sc, noise={**sc.noise, "rms_percent": noise})
    ds = cache.get(sc)
    tr = ds.truth_as(StructuralTruth)
    if use_oracle:
        ds = oracle_dataset(sc, ds, tr)
    data = measure(ds, sc.signal, sc.kind)
    clean = measure(noise_free(ds), sc.signal, sc.kind)
    n, s = data.n_channels, int(data.free_start)
    m = mass_prior_value(data, "reduced_mass_trace") / n
    peaks = modal_peaks(data).peaks
    fc, _ = fit_band_cutoff(data, None, peaks)

    def T(z: np.ndarray) -> np.ndarray:  # the fit band's high-pass, the window, the tilt
        z = elliptic_highpass(z, data.fs, fc, FIT_BAND_ORDER) if fc > 0 else z
        return tilt_rows(z[..., s:])[0]

    full = build_library(data, coupled_mass=False, cubic=False, start=0, drift=True,
                         input_coupling=True)
    lin, y = T(full.theta), T(full.target)
    sc_lin = np.sqrt(np.mean(lin**2, axis=1))
    sc_lin[sc_lin == 0] = 1.0
    U, sv, _ = np.linalg.svd((lin / sc_lin[:, None]).T, full_matrices=False)
    Q = U[:, sv > 1e-10 * sv[0]]
    yp = y - (y @ Q) @ Q.T
    x = np.asarray(data.x, dtype=float)
    d = full.blocks["d"]

    def linear(cub: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        coef = np.linalg.lstsq(lin.T, (y - cub).T, rcond=None)[0].T
        return m * np.eye(n), -m * coef[:, d]

    # diagonal: n features x_j^3, jointly (projected) with the linear columns
    f3 = T(x**3)
    f3p = f3 - (f3 @ Q) @ Q.T
    Bd = np.linalg.lstsq(f3p.T, yp.T, rcond=None)[0].T  # (n, n), acceleration per m^3
    Md, Kd = linear(Bd @ f3)
    K3d, Ad = -m * Bd, None
    # rank one
    a, b = fit_rank_one(x, yp, Q=Q, transform=T)
    Mo, Ko = linear(np.outer(b, T(((a @ x) ** 3)[None, :])[0]))
    K3o, Ao = -m * b[:, None], a[None, :]

    x_ref = np.asarray(clean.x, dtype=float)[:, s:]
    f_true = np.outer(tr.cubic_direction, float(tr.k3) * (tr.cubic_map @ x_ref) ** 3)
    _, phi = eigh(tr.Kr, tr.Mr)
    q1 = phi[:, 0] @ tr.Mr @ x_ref
    x1 = np.sqrt(2.0) * float(np.sqrt(np.mean(q1**2))) * phi[:, 0]
    true_shift = mode2_shift(tr.Mr, tr.Kr, cubic_jacobian(float(tr.k3) * tr.cubic_direction[:, None],
                                                          x1, tr.cubic_map[None, :]))
    c = tr.cubic_map / np.linalg.norm(tr.cubic_map)
    out = f"{sc.name}: n {n} | truth shift {true_shift:.2f} %"
    for name, M, K, K3, A in (("diag", Md, Kd, K3d, Ad), ("rank1", Mo, Ko, K3o, Ao)):
        f_id = K3 @ (x_ref**3 if A is None else (A @ x_ref) ** 3)
        fe = np.linalg.norm(f_id - f_true) / np.linalg.norm(f_true)
        ae = metrics.cubic_acceleration_error(M, f_id, tr.Mr, f_true)
        sh = mode2_shift(M, K, cubic_jacobian(K3, x1, A))
        out += f" | {name} accel {ae:.3f} force {fe:.3f} shift {sh:.2f} %"
    out += f" | angle {np.degrees(np.arccos(min(1.0, abs(float(a @ c))))):.1f} deg"
    return out


def main(argv: list[str]) -> None:
    files = sorted(Path(argv[1]).glob("*.toml"))
    if len(argv) > 2 and argv[2]:
        files = [files[int(k)] for k in argv[2].split(",")]
    use_oracle = argv[-1] == "oracle"
    if use_oracle:
        argv = argv[:-1]
    noise = float(argv[3]) if len(argv) > 3 else None
    cache = DatasetCache()
    for f in files:
        print(member(f, cache, noise, use_oracle), flush=True)


if __name__ == "__main__":
    main(sys.argv)
