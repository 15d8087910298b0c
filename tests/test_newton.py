"""The restricted, low-rank-corrected Newton step of the kernel against a dense numpy solve of
the same system, and the Newton solve against the residual it claims to zero."""
import numpy as np
import pytest

from kernels import jacobian as jac
from kernels import solve as ks
from kernels.interface import lj_traction_and_stiffness
from sweep.mesh import uniform_mesh
from sweep.solver import lj_constants


def _problem(N=60, seed=1):
    rng = np.random.default_rng(seed)
    mesh = uniform_mesh(N, 3.0)
    A = np.array(mesh.influence)
    h0, c = lj_constants(3.24)
    r = np.asarray(mesh.r)
    # a contact-like gap: h0 inside r < 1.5, opening outside, with a perturbation
    h = np.maximum(h0 * (1.0 + 0.2 * rng.random(N)), 0.5 * (r - 1.5) ** 2 + h0)
    return A, h, h0, c, rng


def _dense_jacobian(A, h, h0, c, ceff):
    sig, d = np.empty(h.size), np.empty(h.size)
    lj_traction_and_stiffness(h, h0, c, sig, d)
    return np.eye(h.size) - ceff * A * d[None, :], d


def _factorize(h, A, ceff, h0, c, cache):
    return jac.factorize(h, A, ceff, h0, c, cache[jac.CACHE_FACTOR], cache[jac.CACHE_E_BASE],
                         cache[jac.CACHE_SLOT_OF], cache[jac.CACHE_STATE])


@pytest.mark.parametrize("moved", [3, 25])
def test_woodbury_newton_step_equals_dense_solve(moved):
    A, h, h0, c, rng = _problem()
    ceff = 0.7
    cache = jac.new_jacobian_cache(h.size, kmax=40, eta=0.0)      # eta = 0: exact corrections
    _factorize(h, A, ceff, h0, c, cache)
    # the stiffness moves at a few nodes (the crack tip region)
    h2 = h.copy()
    idx = rng.choice(h.size, moved, replace=False)
    h2[idx] *= 1.0 + 0.3 * rng.random(moved)
    J, d = _dense_jacobian(A, h2, h0, c, ceff)
    F = rng.standard_normal(h.size)
    stats = np.zeros(ks.N_STATS, np.int64)
    dh, ok = jac.newton_direction(F, d, A, ceff, *cache, stats, ks.STAT_COLUMNS)
    assert ok
    assert stats[ks.STAT_COLUMNS] == moved            # one column per moved node
    np.testing.assert_allclose(dh, -np.linalg.solve(J, F), rtol=1e-9, atol=1e-12)


def test_restricted_factorization_inverts_the_base_jacobian():
    # the base keeps only the interacting prefix S (far-field stiffness set to zero): its
    # inverse applied to any vector must equal a dense solve with that base Jacobian
    A, h, h0, c, rng = _problem(N=80, seed=2)
    r = np.linspace(0.0, 3.0, 80)
    h = h + np.where(r > 2.0, 5.0 * (r - 2.0) ** 2, 0.0)     # a far field wide open
    ceff = 0.55
    cache = jac.new_jacobian_cache(h.size)
    m = _factorize(h, A, ceff, h0, c, cache)
    _, d = _dense_jacobian(A, h, h0, c, ceff)
    assert 0 < m < h.size                                # the far field is left out
    e_b = np.where(np.arange(h.size) < m, ceff * d, 0.0)
    np.testing.assert_array_equal(cache[jac.CACHE_E_BASE], e_b)
    J_b = np.eye(h.size) - A * e_b[None, :]
    X = rng.standard_normal((h.size, 3))
    Y = jac.apply_base(X, cache[jac.CACHE_FACTOR], cache[jac.CACHE_E_BASE], m)
    np.testing.assert_allclose(J_b @ Y, X, atol=1e-10)
    # the columns left out are the identity to within SUBSET_EPS
    far = np.arange(m, h.size)
    assert np.all(np.diag(A)[far] * np.abs(ceff * d[far]) <= jac.SUBSET_EPS)


def test_newton_solves_the_discrete_equilibrium():
    # from the relaxed elastic state at delta = 1, one unloading-like step: new indentation,
    # C_eff < 1 and a history vector; Newton must zero the residual computed here by numpy
    from sweep.initial import ElasticSolver, relaxed_state
    A, _, h0, c, rng = _problem(N=120, seed=3)
    r = np.arange(120) * 3.0 / 119
    el = ElasticSolver(A, r, h0, c, 1e-10)
    h_start, _ = relaxed_state(el, delta0=1.0)
    g = -(1.0 - 0.2 * h0) + h0 + 0.5 * r**2
    ceff = 0.8
    H = -0.05 * np.exp(-r)
    cache = ks.new_jacobian_cache(120)
    stats = np.zeros(ks.N_STATS, np.int64)
    hs = h_start.copy()
    assert ks.newton(hs, g, A, ceff, H, h0, c, 1e-10 * h0, 40, *cache, stats)
    sig, d = np.empty(120), np.empty(120)
    lj_traction_and_stiffness(hs, h0, c, sig, d)
    assert np.max(np.abs(hs - g - A @ (ceff * sig - H))) < 1e-10 * h0
    assert np.max(np.abs(hs - h_start)) > 1e-3 * h0          # it did move


def test_relaxed_state_is_cached_per_mesh_and_reused_unchanged():
    from sweep.initial import ElasticSolver, relaxed_state
    A, _, h0, c, _ = _problem(N=100, seed=4)
    r = np.arange(100) * 3.0 / 99
    key = ("test-mesh", 100, 3.0 / 99)
    el = ElasticSolver(A, r, h0, c, 1e-10)
    h1, d1 = relaxed_state(el, a0=1.2, mesh_key=key)
    solved = el.stats.copy()
    assert solved[ks.STAT_ITER] > 0
    el2 = ElasticSolver(A, r, h0, c, 1e-10)
    h2, d2 = relaxed_state(el2, a0=1.2, mesh_key=key)
    assert el2.stats[ks.STAT_ITER] == 0                     # nothing solved again
    np.testing.assert_array_equal(h1, h2)
    assert d1 == d2 and h2 is not h1
    h2[:] = 0.0                                             # a copy: the cache is untouched
    h3, _ = relaxed_state(el2, a0=1.2, mesh_key=key)
    np.testing.assert_array_equal(h3, h1)
    # another initial state is solved (its radius within a node spacing of the target: on
    # this coarse mesh a(delta) jumps from node to node)
    h4, _ = relaxed_state(el2, a0=1.4, mesh_key=key)
    assert el2.stats[ks.STAT_ITER] > 0
    assert abs(el2.radius(h4) - 1.4) < r[1]


def test_capacitance_updates_keep_the_newton_step_exact():
    # corrected nodes move again (rank-1 updates of the capacitance inverse) and new nodes
    # join (bordering), over several calls: with eta = 0 every step must stay the exact
    # dense solve of the current Jacobian
    A, h, h0, c, rng = _problem(N=70, seed=4)
    ceff = 0.6
    cache = jac.new_jacobian_cache(h.size, kmax=50, eta=0.0)
    _factorize(h, A, ceff, h0, c, cache)
    stats = np.zeros(ks.N_STATS, np.int64)
    h2 = h.copy()
    moved = set()
    for call in range(4):
        idx = rng.choice(h.size, 6, replace=False)
        moved.update(int(i) for i in idx)
        h2[idx] *= 1.0 + 0.3 * rng.random(6)
        J, d = _dense_jacobian(A, h2, h0, c, ceff)
        F = rng.standard_normal(h.size)
        dh, ok = jac.newton_direction(F, d, A, ceff, *cache, stats, ks.STAT_COLUMNS)
        assert ok
        assert stats[ks.STAT_COLUMNS] == len(moved)    # a column per node, kept across calls
        np.testing.assert_allclose(dh, -np.linalg.solve(J, F), rtol=1e-8, atol=1e-11)
