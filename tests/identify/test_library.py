"""Library builders: canonical names, column values against hand-evaluated terms, the
acceleration split, and detection of linear dependence."""

from pathlib import Path

import numpy as np
import pytest

from benchmarks import sindy_pi_problems
from identify.library import (
    Library,
    fivebar_library,
    generic_mechanical_library,
    linear_structural_library,
    near_dependencies,
)
from testbed.core.terms import canonical

ROOT = Path(__file__).resolve().parents[2]



@pytest.fixture(scope="module")
def signals():
    rng = np.random.default_rng(7)
    x, xd, xdd = rng.normal(size=(3, 4, 50))
    return x, xd, xdd, rng.normal(size=(2, 50))


@pytest.mark.parametrize("lib", [fivebar_library(), fivebar_library("full"),
                                 generic_mechanical_library(2, 2), linear_structural_library(3)],
                         ids=["fivebar", "fivebar_full", "generic", "linear"])
def test_names_are_canonical_and_unique(lib):
    assert all(canonical(n) == (n, 1) for n in lib.names)
    assert len(set(lib.names)) == len(lib.names)


def test_sizes_and_true_terms():
    red, full = fivebar_library(), fivebar_library("full")
    assert (len(red), len(full), len(generic_mechanical_library(2, 2))) == (32, 108, 97)
    # the reduced-equation terms come first in the full library (pruning priority)
    assert full.names[:32] == red.names
    for t in ("sin(th2-th3)*ddth1", "cos(th1-th2)*sin(th2-th3)*ddth2", "sin(th1-th2)*sin(th2-th3)*dth2^2",
              "sin(th2-th3)*u1", "sin(th2-th3)*u2", "cos(th3-th4)*sin(th2-th4)*ddth4",
              # elbow damping acts on relative rates: cross terms of both chains
              "sin(th2-th3)*dth2", "sin(th1-th3)*dth1", "sin(th1-th2)*dth4", "sin(th3-th4)*dth1"):
        assert t in red.names


def test_columns_match_hand_evaluated_terms(signals):
    x, xd, xdd, u = signals
    lib = fivebar_library("full")
    T = lib.evaluate(x, xd, xdd, u)
    s = lambda i, j: np.sin(x[i - 1] - x[j - 1])  # noqa: E731
    c = lambda i, j: np.cos(x[i - 1] - x[j - 1])  # noqa: E731
    hand = {
        "sin(th2-th3)*ddth1": s(2, 3) * xdd[0],
        "cos(th1-th2)*sin(th2-th3)*ddth2": c(1, 2) * s(2, 3) * xdd[1],
        "sin(th1-th2)*sin(th2-th3)*dth2^2": s(1, 2) * s(2, 3) * xd[1] ** 2,
        "sin(th1-th2)^2*dth1^2": s(1, 2) ** 2 * xd[0] ** 2,
        "cos(th3-th4)*sin(th2-th4)*ddth4": c(3, 4) * s(2, 4) * xdd[3],
        "sin(th3-th4)*u2": s(3, 4) * u[1],
        "sin(th1-th4)*dth3": s(1, 4) * xd[2],
    }
    for name, col in hand.items():
        np.testing.assert_allclose(T[:, lib.names.index(name)], col, rtol=1e-14, atol=1e-15)
    g = generic_mechanical_library(2, 2)
    Tg = g.evaluate(x[:2], xd[:2], xdd[:2], u)
    for name, col in {"sin(th1)": np.sin(x[0]), "cos(th2)*dth1*dth2": np.cos(x[1]) * xd[0] * xd[1],
                      "cos(th1-th2)*dth2*ddth1": c(1, 2) * xd[1] * xdd[0], "u2": u[1]}.items():
        np.testing.assert_allclose(Tg[:, g.names.index(name)], col, rtol=1e-14, atol=1e-15)


def test_canonical_sign_is_dropped(signals):
    x, xd, xdd, _u = signals
    lib = Library(["ddth2*sin(th3-th2)"], 4, 0)
    assert lib.names == ["sin(th2-th3)*ddth2"]
    np.testing.assert_allclose(lib.evaluate(x, xd, xdd)[:, 0], np.sin(x[1] - x[2]) * xdd[1])


def test_acceleration_split_reconstructs_theta(signals):
    x, xd, xdd, u = signals
    lib = fivebar_library("full")
    free, acc = lib.evaluate_parts(x, xd, u)
    # each column is a product of the same factors, taken apart and put back: equal to rounding
    np.testing.assert_allclose(free + np.einsum("ksc,ks->sc", acc, xdd), lib.evaluate(x, xd, xdd, u),
                               rtol=1e-13, atol=1e-14)


def test_chunked_evaluation_equals_per_sample():
    rng = np.random.default_rng(3)
    x, xd, xdd = rng.normal(size=(3, 4, 9000))  # longer than one 8192-sample chunk
    u = rng.normal(size=(2, 9000))
    lib = fivebar_library()
    T = lib.evaluate(x, xd, xdd, u)
    for k in (0, 8191, 8192, 8999):
        np.testing.assert_array_equal(T[k], lib.evaluate(x[:, k:k + 1], xd[:, k:k + 1],
                                                         xdd[:, k:k + 1], u[:, k:k + 1])[0])


def test_invalid_terms_raise():
    with pytest.raises(ValueError, match="not linear in the accelerations"):
        Library(["ddth1*ddth2"])
    with pytest.raises(ValueError, match="unknown factor"):
        Library(["tan(th1)"])
    with pytest.raises(ValueError, match="duplicate"):
        Library(["sin(th1-th2)*ddth1", "ddth1*sin(th1-th2)"])


def test_near_dependencies_finds_a_trig_identity(signals):
    x, xd, xdd, _u = signals
    lib = Library(["sin(th1-th2)", "cos(th2)*sin(th1)", "cos(th1)*sin(th2)", "dth1", "cos(th1-th2)"])
    T = lib.evaluate(x[:2], xd[:2], xdd[:2])
    groups = near_dependencies(T.T @ T, lib.names)
    assert groups == [["sin(th1-th2)", "cos(th2)*sin(th1)", "cos(th1)*sin(th2)"]]


def test_reduced_fivebar_library_has_two_kinematic_identities():
    """On loop-closed data the 30 input-free reduced columns have exactly two null directions
    (acceleration-level loop constraint times trig factors), the full 108 dozens."""
    P = sindy_pi_problems
    # 10 s: on 4 s the elbow cross-damping columns leave near-dependencies at 1e-11..1e-8; on 10 s
    # the two exact ones (~1e-16) are 9 decades below the next direction (2.6e-7)
    d = P.fivebar(duration=10.0, fs=500.0, amp=1.0).data
    for lib, expected in ((fivebar_library(), 2), (fivebar_library("full"), None)):
        cols = [i for i, n in enumerate(lib.names) if "*u" not in n]
        T = lib.evaluate(d.x, d.xd, d.xdd, d.u)[:, cols]
        n_dep = len(near_dependencies(T.T @ T, [lib.names[i] for i in cols]))
        if expected is None:
            assert n_dep > 20
        else:
            assert n_dep == expected
