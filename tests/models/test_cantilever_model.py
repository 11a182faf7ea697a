"""Cantilever model and truth without time stepping: frequencies, K, cubic base, SEREP."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from models.cantilever import build_model, eb_frequencies
from models.cantilever.simulate import choose_stepping, state_matrix
from models.cantilever.truth import residual_flexibility, serep, truncated_static_load
from testbed.pipeline.scenario import scenario_from_dict


def scenario(rig=None, simulation=None, excitation=None):
    raw = {"scenario": {"name": "t", "rig": "cantilever"}, "rig": rig or {},
           "simulation": simulation or {}, "excitation": {"type": "impact", **(excitation or {})}}
    return scenario_from_dict(raw)


def built(**rig):
    sc = scenario(rig)
    return build_model(sc.rig_params, sc.simulation, sc.excitation)


def rel_err(b, n_modes=2):
    """Relative frequency error of the chain vs Euler-Bernoulli, first ``n_modes`` modes."""
    t, _ = b.truth()
    return t["frequencies_hz"][:n_modes] / t["eb_frequencies_hz"][:n_modes] - 1.0


def test_euler_bernoulli_clamped_roots():
    # Independent check of the characteristic-equation solver: the classic clamped-free
    # eigenvalues lambda_i = 1.8751, 4.6941, 7.8548, 10.9955 (cos cosh = -1).
    ei, mu, L = 1.0, 1.0, 1.0
    f = eb_frequencies(ei, 1.0, mu, L)
    lam = np.sqrt(f * 2 * np.pi)
    np.testing.assert_allclose(lam, [1.875104069, 4.694091133, 7.854757438, 10.99554073], rtol=1e-9)
    # A stiff base spring tends to the clamped beam, the gap falling as 1/k_r; a soft
    # one lowers every frequency.
    clamped = eb_frequencies(210e9, 2.5e-9, 2.355, 0.3175)
    gap = [eb_frequencies(210e9, 2.5e-9, 2.355, 0.3175, k_r=k) / clamped - 1 for k in (1e8, 1e10)]
    assert np.all(gap[0] < 0) and np.all(np.abs(gap[0]) < 1e-4)
    np.testing.assert_allclose(gap[0] / gap[1], 100.0, rtol=1e-3)
    assert np.all(eb_frequencies(210e9, 2.5e-9, 2.355, 0.3175, k_r=2000.0) < clamped)


@pytest.mark.parametrize("base", ["stiff", "soft"])
def test_default_model_within_half_percent_of_euler_bernoulli(base):
    # Discretisation error at N = 10 (measured: stiff -0.14 %, -0.39 %; soft -0.04 %, +0.00 %).
    err = rel_err(built(base=base))
    assert np.all(np.abs(err) < 0.005), err


def test_error_falls_with_n_as_n_squared():
    errs = np.array([rel_err(built(n_segments=n)) for n in (5, 10, 20)])
    assert np.all(np.abs(errs[1:]) < np.abs(errs[:-1]))
    # Second-order discretisation: from N = 10 to 20 the error falls by ~4 (3..5 allows for
    # higher-order terms; measured 3.8 and 3.4 for modes 1 and 2).
    ratio = errs[2] / errs[1]
    assert np.all((ratio > 1 / 5) & (ratio < 1 / 3)), ratio
    # Soft base: mode 1 converges monotonically (mode 2 is already at +0.001 % at N = 10
    # and changes sign, so its |error| is not monotone).
    soft = [abs(rel_err(built(base="soft", n_segments=n), 1)[0]) for n in (5, 10, 20)]
    assert soft[0] > soft[1] > soft[2]


def test_vertex_chain_matches_reference_figures():
    # joint_offset = 0 is the chain of rigs.md (root hinge 2EI/l): -0.46 %, -1.56 % at N = 10
    # there.  Different code, same physics: agreement to 0.01 percentage point.
    err = rel_err(built(joint_offset=0.0))
    np.testing.assert_allclose(err * 100, [-0.46, -1.56], atol=0.01)


@pytest.mark.parametrize("base", ["stiff", "soft"])
def test_stiffness_is_finite_difference_of_passive_force(base):
    b = built(base=base)
    m, d = b.model, mujoco.MjData(b.model)
    h = 1e-7  # rad; cubic contributes k3 h^2 = 2.5e-5 N m/rad (1e-8 of K) to the soft root
    kfd = np.zeros_like(b.K)
    for i in range(m.nv):
        f = []
        for s in (h, -h):
            d.qpos[:] = 0.0
            d.qpos[i] = s
            d.qvel[:] = 0.0
            mujoco.mj_forward(m, d)
            f.append(d.qfrc_passive.copy())
        kfd[:, i] = -(f[0] - f[1]) / (2 * h)
    np.testing.assert_allclose(kfd, b.K, rtol=0, atol=1e-7 * np.abs(b.K).max())
    np.testing.assert_allclose(m.dof_damping, b.params.beta * np.diag(b.K), rtol=1e-14)
    np.testing.assert_allclose(b.C, b.params.beta * b.K, rtol=1e-14)


def test_soft_base_moment_is_k1_q_plus_k3_q_cubed():
    b = built(base="soft", base_k1=2000.0, base_k3=2.5e9)
    d = mujoco.MjData(b.model)
    for q in np.linspace(-2e-3, 2e-3, 9):
        d.qpos[:] = 0.0
        d.qpos[0] = q
        mujoco.mj_forward(b.model, d)
        assert d.qfrc_passive[0] == pytest.approx(-(2000.0 * q + 2.5e9 * q**3), rel=1e-12, abs=1e-15)
    t, _ = b.truth()
    assert t["k3"] == 2.5e9
    np.testing.assert_array_equal(t["cubic_map"], b.red.T[0])
    # The cubic's reduced load holds the truncated modes' static response: under a static unit
    # base moment the reduced model reads at the sensors what the full one does (Kr^-1 d =
    # Js K^-1 e0, an identity of the static condensation: round-off only), SEREP's T^T e0
    # alone misses the truncated modes' share (measured 0.16-0.49 % per sensor here: small in
    # displacement, but Kr weighs it by the sensed modes' stiffness: 0.76 x and 9 deg in Mr^-1
    # terms on the shipped soft beam, its dynamic residual 0.30 -> 0.03).
    e0 = np.eye(b.model.nv)[0]
    full = b.Js @ np.linalg.solve(b.K, e0)
    np.testing.assert_allclose(np.linalg.solve(t["Kr"], t["cubic_direction"]), full,
                               rtol=1e-8, atol=1e-12 * np.abs(full).max())
    assert not np.allclose(np.linalg.solve(t["Kr"], b.red.T[0]), full, rtol=1e-3, atol=0.0)
    assert built(base="stiff").truth()[0]["k3"] == 0.0


@pytest.mark.parametrize("base", ["stiff", "soft"])
def test_serep_reduction(base):
    b = built(base=base)
    t, _ = b.truth()
    m = len(b.sensors)
    lam = np.sort(np.linalg.eigvals(np.linalg.solve(t["Mr"], t["Kr"])).real)
    np.testing.assert_allclose(np.sqrt(lam) / (2 * np.pi), t["frequencies_hz"][:m], rtol=1e-9)
    # Sensor coordinates: Js T = I, so a force at the tip sensor maps to a unit vector.
    np.testing.assert_allclose(b.Js @ b.red.T, np.eye(m), atol=1e-9)
    np.testing.assert_allclose(t["force_map"], [0, 0, 1], atol=1e-9)
    np.testing.assert_allclose(t["Cr"], b.params.beta * t["Kr"], rtol=1e-9, atol=1e-12)
    # Mass-normalised modes; the reduced modes at the sensors are the full ones.
    np.testing.assert_allclose(t["modes"].T @ t["M"] @ t["modes"], np.eye(b.model.nv), atol=1e-9)
    np.testing.assert_allclose(t["sensor_modes"].T @ t["Mr"] @ t["sensor_modes"], np.eye(m),
                               atol=1e-9)


def test_mass_and_damping_truth():
    b = built()
    t, units = b.truth()
    assert t["damping_ratios"][0] == pytest.approx(0.01, rel=1e-12)
    np.testing.assert_allclose(t["damping_ratios"], b.params.beta * 2 * np.pi * t["frequencies_hz"] / 2)
    # The moving segments' mass: beam mass minus the clamped stub (a l of the first segment).
    seg_mass = sum(b.model.body_mass[1:])
    stub = b.params.joint_offset * b.params.segment_length * b.params.mass_per_length
    assert seg_mass == pytest.approx(b.params.total_mass - stub, rel=1e-12)
    assert b.params.total_mass == pytest.approx(7850 * 0.03 * 0.01 * 0.3175, rel=1e-12)
    assert set(units) == set(t)


def test_rk4_step_respects_stability_and_accuracy_bounds():
    b = built()
    st = b.stepping
    eig = np.abs(np.linalg.eigvals(state_matrix(b.M, b.C, b.K))).max()
    assert st.integrator == "RK4"
    assert st.timestep * eig <= 2.0 + 1e-12
    assert st.timestep * np.pi * 12800 <= 0.49
    assert st.timestep * st.substeps == pytest.approx(1 / 12800, rel=1e-12)
    imp = choose_stepping(b.M, b.C, b.K, 12800.0, "implicitfast")
    assert imp.timestep * np.pi * 12800 <= 0.109 + 1e-12


def _chain(n: int = 3) -> tuple[np.ndarray, np.ndarray]:
    """A fixed-free spring-mass chain of ``n`` unequal masses [kg] and springs [N/m]."""
    M = np.diag([1.0, 0.7, 0.4][:n])
    k = np.array([3.0e4, 2.0e4, 1.5e4][:n])
    K = np.diag(k + np.append(k[1:], 0.0)) - np.diag(k[1:], 1) - np.diag(k[1:], -1)
    return M, K


def test_truncated_static_load_on_a_chain():
    """The correction on a 3-DOF chain reduced to 2 sensed masses, against the exact response.

    A load on the root mass at frequency ``w`` well below the truncated mode: the full chain's
    steady state at the sensors, ``Js (K - w^2 M)^-1 l`` (computed directly), against the
    reduced model's ``(Kr - w^2 Mr)^-1 b`` with SEREP's ``b = T^T l`` and with
    ``b = T^T l + Kr Js R l``.  Static (``w = 0``) the corrected load is exact to round-off;
    quasi-static its error is second order in ``w / w_3`` (the neglected ``Mr s''``), SEREP's
    is not.
    """
    M, K = _chain()
    lam, phi = np.linalg.eigh(np.linalg.solve(np.linalg.cholesky(M), np.linalg.solve(
        np.linalg.cholesky(M), K).T))
    phi = np.linalg.solve(np.linalg.cholesky(M).T, phi)  # mass-normalised, ascending
    Js = np.eye(3)[1:]  # the two outer masses are sensed
    red = serep(M, np.zeros_like(K), K, Js, phi)
    R = residual_flexibility(K, phi, 2)
    load = np.array([1.0, 0.0, 0.0])
    b_serep = red.T.T @ load
    b_corr = b_serep + truncated_static_load(red.Kr, Js, R, load)
    w3 = np.sqrt(lam[2])
    errs = {}
    for ratio in (0.0, 0.05, 0.1):
        w2 = (ratio * w3) ** 2
        exact = Js @ np.linalg.solve(K - w2 * M, load)
        errs[ratio] = [np.linalg.norm(np.linalg.solve(red.Kr - w2 * red.Mr, b) - exact)
                       / np.linalg.norm(exact) for b in (b_serep, b_corr)]
    assert errs[0.0][1] < 1e-12, errs  # static condensation: exact (round-off)
    assert errs[0.0][0] > 1e-3, errs  # SEREP's Galerkin load misses the truncated mode (0.146)
    # quasi-static: the corrected error is (w / w3)^2 (measured 0.0025 and 0.0100: x4 from 0.05 to
    # 0.1, 10 % for the higher-order terms), far below SEREP's (0.142, 0.131)
    assert errs[0.1][1] / errs[0.05][1] == pytest.approx(4.0, rel=0.1), errs
    assert errs[0.1][1] < 0.1 * errs[0.1][0], errs
