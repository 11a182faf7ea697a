"""The compiled SGD-SINDy steps (identify/_compiled.py: ``sgd_steps``): the same arithmetic as
its single-step kernels applied one after the other, and no heap allocation per step."""

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from identify import _compiled as cc

N_SAMPLES, NFA, N = 300, 12, 3


def _problem(bs, seed=0):
    """A small random fit window and state: n = 3, 12 live feature columns of 15 (the input's
    columns zero), the cubic block on a support, three eigenvalue targets."""
    rng = np.random.default_rng(seed)
    Z = np.zeros((N_SAMPLES, 5 * N))
    Z[:, :NFA] = rng.normal(size=(N_SAMPLES, NFA))
    L = np.linalg.cholesky(np.eye(N) + 0.1 * np.ones((N, N)))
    P = np.diag([1.0, 4.0, 9.0]) + 0.05 * rng.normal(size=(N, N))
    Q, R = 0.1 * rng.normal(size=(N, N)), 0.1 * rng.normal(size=(N, N))
    support = np.ones((N, N))
    support[0, 1] = support[2, 0] = 0.0
    return dict(
        Z=Z, nfa=NFA, S_full=Z.T @ Z, n_full=N_SAMPLES, perm=rng.permutation(N_SAMPLES), bs=bs,
        params=(L, P, Q, R), adam=tuple(np.zeros((4, N, N)) for _ in range(3)), t0=7,
        lr=1e-3, m0=0.2, c0=3.0, k0=4e4, sc3=rng.uniform(0.5, 2.0, size=(N, N)),
        s_a=rng.uniform(0.5, 2.0, size=N), lam_hat=np.array([1.5e5, 8e5, 2.1e6]),
        eig_gain=1e-3, has_R=True, support=support, use_support=True,
        lam_l1=np.full((N, N), 1e-2), prox=True, m_hat=0.6)


ORDER = ("Z", "nfa", "S_full", "n_full", "perm", "bs", "n_steps", "params", "adam", "t0", "lr",
         "m0", "c0", "k0", "sc3", "s_a", "lam_hat", "eig_gain", "has_R", "support",
         "use_support", "lam_l1", "prox", "m_hat")


def _reference(p, n_steps):
    """``sgd_steps`` written out in Python from the single-step kernels (batch_loss_grad on
    the gathered mini-batch, window_loss_grad, eig_loss_grad, _adam, project)."""
    L, P, Q, R = p["params"]
    am, av, asc = p["adam"]
    Z, perm, bs = p["Z"], p["perm"], p["bs"]
    Zp = np.ascontiguousarray(Z[perm][:, :p["nfa"]])
    T, TS = np.empty((N, 5 * N)), np.empty((N, 5 * N))
    e2, r, g = np.empty(N), np.empty(N), np.zeros((4, N, N))
    eL, eP = np.zeros((N, N)), np.zeros((N, N))
    args = (L, P, Q, R, p["m0"], p["c0"], p["k0"], p["sc3"], p["s_a"])
    for s in range(n_steps):
        if bs > 0:
            lo = (s * bs) % N_SAMPLES
            hi = min(lo + bs, N_SAMPLES)
            cc.batch_loss_grad(Zp[lo:hi], *args, T, TS, e2, r, *g)
        else:
            cc.window_loss_grad(p["S_full"], p["n_full"], *args, T, TS, e2, *g)
        cc.eig_loss_grad(L, P, p["m0"], p["k0"], p["lam_hat"], eL, eP)
        g[0] += p["eig_gain"] * eL  # elementwise: one multiply and one add per entry
        g[1] += p["eig_gain"] * eP
        t = p["t0"] + s + 1
        for k, X in enumerate((L, P, Q)):
            cc._adam(X, g[k], am[k], av[k], t, p["lr"], 0.9, 0.999, 1e-12, asc[k])
        g[3] *= p["support"]
        cc._adam(R, g[3], am[3], av[3], t, p["lr"], 0.9, 0.999, 1e-12, asc[3])
        a = np.abs(R) - p["lam_l1"] * asc[3]
        R[...] = np.where(a > 0.0, np.copysign(a, R), 0.0) * p["support"]
        cc.project(L, P, Q, R, p["m0"], p["m_hat"])


@pytest.mark.parametrize("bs", [64, 0], ids=["mini-batch", "full-window"])
def test_sgd_steps_is_its_single_step_kernels_bit_for_bit(bs):
    """Hoisting the scratch arrays, gathering the batch per step and summing the residuals in
    registers changed no operation and no order: equal to the last bit, over steps whose
    batches wrap around the epoch (300 samples, batches of 64: the fifth is 44 long)."""
    steps = 12
    a, b = _problem(bs), _problem(bs)
    cc.sgd_steps(*[steps if k == "n_steps" else a[k] for k in ORDER])
    _reference(b, steps)
    for x, y in zip((*a["params"], *a["adam"]), (*b["params"], *b["adam"]), strict=True):
        assert np.array_equal(x, y)
    assert np.all(np.isfinite(a["params"][0])) and not np.array_equal(a["params"][1],
                                                                       _problem(bs)["params"][1])


_ALLOCS = textwrap.dedent("""
    import json, sys
    sys.path.insert(0, {root!r})
    from numba.core.runtime import rtsys
    from tests.identify.test_sgd_kernel import ORDER, _problem
    from identify import _compiled as cc
    p = _problem(64)
    cc.sgd_steps(*[1 if k == "n_steps" else p[k] for k in ORDER])  # loads it, starts the stats
    out = []
    for bs in (64, 0):
        counts = []
        for steps in (1, 41):
            p = _problem(bs)
            before = rtsys.get_allocation_stats().alloc
            cc.sgd_steps(*[steps if k == "n_steps" else p[k] for k in ORDER])
            counts.append(rtsys.get_allocation_stats().alloc - before)
        out.append(counts)
    print(json.dumps(out))
""")


@pytest.mark.slow  # cold: the subprocess compiles the kernels afresh (~20 s of CPU), warm 2.3 s
def test_sgd_steps_allocates_nothing_per_step():
    """Every scratch array is made once per call, none per step (numba puts each temporary
    array on the heap: 14 allocations a step before, a quarter of a served run's steps'
    time).  Counted by numba's documented allocation statistics (NUMBA_NRT_STATS=1), in a
    process of its own since the switch is read at numba's import."""
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    env = {**os.environ, "NUMBA_NRT_STATS": "1", "PYTHONPATH": root}
    done = subprocess.run([sys.executable, "-c", _ALLOCS.format(root=root)], env=env,
                          capture_output=True, text=True, check=True,
                          timeout=600)  # a hang guard only: a cold compile on a loaded 2-core machine
    for one, many in json.loads(done.stdout.strip().splitlines()[-1]):
        assert many == one, (one, many)
