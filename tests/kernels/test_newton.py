"""The Newton step of the kernel (kept factorization of the contact, crack-tip zone exact)
against a dense numpy solve of the Jacobian it documents, and the Newton solve against the
residual it claims to zero."""
import numpy as np
import pytest

from sweep.kernels import jacobian as jac
from sweep.kernels import solve as ks
from sweep.kernels.interface import (ZONE_SIZE, crossing_radius, lennard_jones,
                                    lj_traction_and_stiffness)
from sweep.engine.mesh import uniform_mesh
from sweep.engine.problem import lj_constants


def _problem(N=200, seed=1, contact=1.8):
    rng = np.random.default_rng(seed)
    mesh = uniform_mesh(N, 3.0)
    A = np.array(mesh.influence)
    h0, c = lj_constants(3.24)
    r = np.asarray(mesh.r)
    # a contact-like gap: about h0 inside r < contact, opening outside, with a perturbation
    h = np.maximum(h0 * (1.0 + 0.15 * rng.random(N)), 0.5 * (r - contact) ** 2 + h0)
    h += np.where(r > contact + 0.4, 5.0 * (r - contact - 0.4) ** 2, 0.0)   # far field open
    return A, h, h0, c, rng


def _stiffness(h, h0, c, ceff):
    sig, d = np.empty(h.size), np.empty(h.size)
    lj_traction_and_stiffness(h, h0, c, sig, d)
    return ceff * d, d


def _factorize(h, A, ceff, h0, c, cache):
    return jac.factorize(h, A, ceff, h0, c, np.zeros(h.size), np.zeros(ZONE_SIZE), cache)


def _direction(F, d, A, ceff, cache, stats):
    return jac.newton_direction(F, d, np.zeros(d.size), A, ceff, cache, stats, ks.STAT_ZONE)


def _sets(cache):
    st = cache[jac.CACHE_STATE]
    return st[jac.STATE_SUBSET], st[jac.STATE_ZONE_LO], st[jac.STATE_ZONE_HI]


def _assert_solves(dh, J, F):
    """dh = -J^{-1} F to within single precision: K's and Sigma's factors, X and
    A_ZB diag(E_b) are float32 (kernels.jacobian.FACTOR_DTYPE), so the normwise error bound
    of an LU solve is cond(J) * eps32 (measured here about 300 times below it; a wrong
    factorization or a wrong set of nodes is off by order one)."""
    ref = -np.linalg.solve(J, F)
    error = np.linalg.norm(dh - ref) / np.linalg.norm(ref)
    assert error <= np.linalg.cond(J) * np.finfo(np.float32).eps, error


def test_factorized_jacobian_inverts_the_restricted_jacobian():
    # at the state it was factorized at, the direction is the dense solve of J with the
    # far field (columns beyond S) left out, and those columns are the identity to
    # within SUBSET_EPS
    A, h, h0, c, rng = _problem()
    ceff = 0.55
    cache = jac.new_jacobian_cache(h.size)
    m = _factorize(h, A, ceff, h0, c, cache)
    m_, lo, hi = _sets(cache)
    E, d = _stiffness(h, h0, c, ceff)
    assert 0 < lo < hi < m < h.size                      # interior, zone, tail and far field
    tip = jac.crack_tip_index(d, np.zeros(d.size))
    assert lo == tip - jac.ZONE_IN and hi == min(tip + jac.ZONE_OUT, m)
    E_b = np.where(np.arange(h.size) < m, E, 0.0)
    F = rng.standard_normal(h.size)
    stats = np.zeros(ks.N_STATS, np.int64)
    dh, ok = _direction(F, d, A, ceff, cache, stats)
    assert ok
    J_b = np.eye(h.size) - A * E_b[None, :]
    _assert_solves(dh, J_b, F)
    far = np.arange(m, h.size)
    assert np.all(np.diag(A)[far] * np.abs(E[far]) <= jac.SUBSET_EPS)


@pytest.mark.parametrize("where", ["zone", "interior"])
def test_zone_exact_and_interior_as_factorized(where):
    # the stiffness moves: in the crack-tip zone the direction follows it exactly (its
    # Schur complement is refactorized); in the interior it stays as factorized (a chord
    # step): either way the direction is the dense solve of that documented Jacobian
    A, h, h0, c, rng = _problem(seed=2)
    ceff = 0.7
    cache = jac.new_jacobian_cache(h.size)
    m = _factorize(h, A, ceff, h0, c, cache)
    _, lo, hi = _sets(cache)
    E_old, _ = _stiffness(h, h0, c, ceff)
    h2 = h.copy()
    nodes = np.arange(lo, hi) if where == "zone" else np.arange(0, lo - jac.ZONE_MARGIN)
    idx = rng.choice(nodes, 12, replace=False)
    h2[idx] = np.minimum(h2[idx] * (1.0 + 0.05 * rng.random(12)), 1.19 * h0)
    E_new, d_new = _stiffness(h2, h0, c, ceff)
    stats = np.zeros(ks.N_STATS, np.int64)
    stats[ks.STAT_ZONE] = 0
    F = rng.standard_normal(h.size)
    dh, ok = _direction(F, d_new, A, ceff, cache, stats)
    assert ok
    i = np.arange(h.size)
    E_used = np.where(i < m, E_old, 0.0)
    E_used[lo:hi] = E_new[lo:hi]                          # the zone as it is now
    J_used = np.eye(h.size) - A * E_used[None, :]
    _assert_solves(dh, J_used, F)
    assert stats[ks.STAT_ZONE] == 1                      # one refresh of the zone
    if where == "interior":                              # a chord step, not the exact one
        J = np.eye(h.size) - A * np.where(i < m, E_new, 0.0)[None, :]
        assert np.max(np.abs(dh + np.linalg.solve(J, F))) > 1e-6


@pytest.mark.parametrize("press", [0.995, 0.98])
def test_drift_scaled_chord_follows_a_pressed_interior(press):
    # a pressed contact (gaps below h0) pressed further after the factorization: the
    # interior's stiffness drifts by 6-28 %. The drift-scaled direction (STATE_SCALED) is
    # nearer the exact Newton direction than the chord's (measured: about a third of its
    # error on both presses); where nothing drifted the two are the same (to rounding: the
    # scaling is 1 computed two ways)
    A, h, h0, c, rng = _problem(seed=3)
    ceff = 0.7
    _, d = _stiffness(h, h0, c, ceff)
    inner = np.arange(jac.crack_tip_index(d, np.zeros(h.size)) - jac.ZONE_IN - 10)
    h[inner] = h0 * (0.97 + 0.01 * rng.random(inner.size))
    cache = jac.new_jacobian_cache(h.size)
    m = _factorize(h, A, ceff, h0, c, cache)
    _, lo, _ = _sets(cache)
    F = rng.standard_normal(h.size)
    stats = np.zeros(ks.N_STATS, np.int64)
    _, d0 = _stiffness(h, h0, c, ceff)
    chord0, _ = _direction(F, d0, A, ceff, cache, stats)
    pressed = h.copy()
    pressed[:lo - jac.ZONE_MARGIN] *= press
    E, d = _stiffness(pressed, h0, c, ceff)
    chord, ok = _direction(F, d, A, ceff, cache, stats)
    jac.use_drift_scaled(cache, True)
    scaled, ok_scaled = _direction(F, d, A, ceff, cache, stats)
    same, _ = _direction(F, d0, A, ceff, cache, stats)
    assert ok and ok_scaled
    np.testing.assert_allclose(same, chord0, rtol=1e-12, atol=1e-12 * np.abs(chord0).max())
    J = np.eye(h.size) - A * np.where(np.arange(h.size) < m, E, 0.0)[None, :]
    exact = -np.linalg.solve(J, F)

    def error(dh):
        return np.linalg.norm(dh - exact) / np.linalg.norm(exact)
    assert error(scaled) < 0.5 * error(chord)


def test_crack_tip_leaving_the_zone_asks_for_a_new_factorization():
    A, h, h0, c, rng = _problem(seed=3)
    ceff = 0.7
    cache = jac.new_jacobian_cache(h.size)
    _factorize(h, A, ceff, h0, c, cache)
    _, lo, hi = _sets(cache)
    F = rng.standard_normal(h.size)
    stats = np.zeros(ks.N_STATS, np.int64)
    h2 = h.copy()
    h2[lo + jac.ZONE_MARGIN - 1:] = np.maximum(h2[lo + jac.ZONE_MARGIN - 1:], 1.3 * h0)
    _, d2 = _stiffness(h2, h0, c, ceff)
    assert jac.crack_tip_index(d2, np.zeros(d2.size)) < lo + jac.ZONE_MARGIN  # the tip receded past the margin
    _, ok = _direction(F, d2, A, ceff, cache, stats)
    assert not ok
    _factorize(h2, A, ceff, h0, c, cache)                 # refactorized there, it fits again
    dh, ok = _direction(F, d2, A, ceff, cache, stats)
    assert ok and np.all(np.isfinite(dh))


def test_newton_solves_the_discrete_equilibrium():
    # from the relaxed elastic state at delta = 1, one unloading-like step: new indentation,
    # C_eff < 1 and a history vector; Newton must zero the residual computed here by numpy
    from sweep.engine.initial import ElasticSolver, relaxed_state
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
    assert ks.newton(hs, g, A, ceff, H, lennard_jones(h0, c, A.shape[0]), 1e-10 * h0, 40, cache, stats)
    sig, d = np.empty(120), np.empty(120)
    lj_traction_and_stiffness(hs, h0, c, sig, d)
    assert np.max(np.abs(hs - g - A @ (ceff * sig - H))) < 1e-10 * h0
    assert np.max(np.abs(hs - h_start)) > 1e-3 * h0          # it did move


def test_newton_gives_up_past_its_deadline_and_meets_it_unchanged():
    """The cache's deadline (the scene's time budget, read before every iteration): passed,
    Newton returns unconverged without an iteration; far off, it is the solve without one,
    bit for bit."""
    from sweep.engine.initial import ElasticSolver, relaxed_state
    A, _, h0, c, _ = _problem(N=120, seed=3)
    r = np.arange(120) * 3.0 / 119
    h_start, _ = relaxed_state(ElasticSolver(A, r, h0, c, 1e-10), delta0=1.0)
    g = -(1.0 - 0.2 * h0) + h0 + 0.5 * r**2
    H = -0.05 * np.exp(-r)
    law = lennard_jones(h0, c, 120)
    solved = {}
    for seconds in (np.inf, 1e6, -1.0):
        cache, stats = ks.new_jacobian_cache(120), np.zeros(ks.N_STATS, np.int64)
        ks.set_deadline(cache, seconds)
        h = h_start.copy()
        solved[seconds] = (ks.newton(h, g, A, 0.8, H, law, 1e-10 * h0, 40, cache, stats), h,
                           stats[ks.STAT_ITER])
    assert solved[np.inf][0] and solved[np.inf][2] > 0
    assert solved[1e6][0] and solved[1e6][2] == solved[np.inf][2]
    np.testing.assert_array_equal(solved[1e6][1], solved[np.inf][1])
    assert not solved[-1.0][0] and solved[-1.0][2] == 0


def test_solves_ended_on_the_predicted_residual_meet_the_tolerance():
    # a continuation in the indentation (linear predictor): where the residual predicted
    # after the first update (the contraction last measured times |F|) is below
    # PREDICTED_RESIDUAL tol, the solve ends without computing it; computed here by numpy,
    # it must still be within tol, for those solves and for the others
    from sweep.engine.initial import ElasticSolver, relaxed_state
    N = 120
    A, _, h0, c, _ = _problem(N=N, seed=3)
    r = np.arange(N) * 3.0 / (N - 1)
    h, _ = relaxed_state(ElasticSolver(A, r, h0, c, 1e-10), delta0=1.0)
    ceff, tol = 0.8, 1e-8 * h0
    H = -0.05 * np.exp(-r)
    cache = ks.new_jacobian_cache(N)
    stats = np.zeros(ks.N_STATS, np.int64)
    prev = h.copy()
    sig, d = np.empty(N), np.empty(N)
    ended = {True: [], False: []}
    for n, delta in enumerate(1.0 - np.arange(1, 60) * 1e-4):
        g = -delta + h0 + 0.5 * r**2
        guess = 2.0 * h - prev if n > 0 else h.copy()
        before = stats[ks.STAT_PREDICTED]
        assert ks.newton(guess, g, A, ceff, H, lennard_jones(h0, c, A.shape[0]), tol, 40, cache, stats)
        lj_traction_and_stiffness(guess, h0, c, sig, d)
        residual = np.max(np.abs(guess - g - A @ (ceff * sig - H)))
        ended[bool(stats[ks.STAT_PREDICTED] > before)].append(residual / tol)
        prev, h = h, guess
    assert len(ended[True]) >= 10 and len(ended[False]) >= 10   # measured 29 and 30
    assert max(ended[True]) <= 1.0 and max(ended[False]) <= 1.0     # measured 0.58, 0.57


def test_relaxed_state_is_cached_per_mesh_and_reused_unchanged():
    from sweep.engine.initial import ElasticSolver, relaxed_state
    A, _, h0, c, _ = _problem(N=100, seed=4)
    r = np.arange(100) * 3.0 / 99
    key = ("test-mesh", 100, 3.0 / 99)
    el = ElasticSolver(A, r, h0, c, 1e-10)
    h1, d1 = relaxed_state(el, a0=1.2, mesh_key=key)
    solved = el.stats.copy()
    assert solved[ks.STAT_ITER] > 0
    el2 = ElasticSolver(A, r, h0, c, 1e-10)
    el2.solve = lambda *args: pytest.fail("a cached state was solved again")
    h2, d2 = relaxed_state(el2, a0=1.2, mesh_key=key)
    del el2.solve
    # the counts of the solve it kept, as if solved: a row's Newton iterations do not
    # depend on what its process solved before (issue 33 item 3)
    np.testing.assert_array_equal(el2.stats, solved)
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


def test_relax_reaches_the_equilibrium_newton_finds():
    # the pseudo-transient fallback (LU through kernels.blas) from the same start as Newton:
    # it must zero the residual computed here by numpy and land on Newton's solution
    from sweep.engine.initial import ElasticSolver, relaxed_state
    N = 120
    A, _, h0, c, _ = _problem(N=N, seed=3)
    r = np.arange(N) * 3.0 / (N - 1)
    h_start, _ = relaxed_state(ElasticSolver(A, r, h0, c, 1e-10), delta0=1.0)
    g = -(1.0 - 0.2 * h0) + h0 + 0.5 * r**2
    ceff, H = 0.8, -0.05 * np.exp(-r)
    stats = np.zeros(ks.N_STATS, np.int64)
    hn = h_start.copy()
    assert ks.newton(hn, g, A, ceff, H, lennard_jones(h0, c, A.shape[0]), 1e-10 * h0, 40,
                     ks.new_jacobian_cache(N), stats)
    hr = h_start.copy()
    assert ks.relax(hr, g, A, ceff, H, lennard_jones(h0, c, N), 1e-10 * h0, ks.RELAX_MAX_ITER,
                    stats, np.inf)
    sig, d = np.empty(N), np.empty(N)
    lj_traction_and_stiffness(hr, h0, c, sig, d)
    assert np.max(np.abs(hr - g - A @ (ceff * sig - H))) < 1e-10 * h0
    assert np.max(np.abs(hr - hn)) < 1e-8 * h0


@pytest.mark.parametrize("stiffness", [0.3, 3.0])
def test_newton_with_a_compliant_machine_is_the_rigid_solve_at_d_minus_p_over_k(stiffness):
    # the machine at D, spring K: the solved gap must be the rigid machine's equilibrium at
    # the sphere's indentation delta = D - P/K (numpy's residual there), and the iterations
    # must converge (the Sherman-Morrison direction, checked against numpy's dense solve to
    # 5e-5 at K = 0.3 from this start)
    from sweep.engine.initial import ElasticSolver, relaxed_state
    N = 120
    A, _, h0, c, _ = _problem(N=N, seed=3)
    r = np.arange(N) * 3.0 / (N - 1)
    wP = np.asarray(uniform_mesh(N, 3.0).load_weights, float)
    h_start, _ = relaxed_state(ElasticSolver(A, r, h0, c, 1e-10), delta0=1.0)
    sig, d = np.empty(N), np.empty(N)
    lj_traction_and_stiffness(h_start, h0, c, sig, d)
    # the machine where the spring holds the start's load at an indentation 0.05 h0 less
    ceff, D = 0.95, 1.0 - 0.05 * h0 + 2.0 * np.pi * wP @ sig / stiffness
    H = -0.01 * np.exp(-r)
    cache = ks.new_jacobian_cache(N)
    stats = np.zeros(ks.N_STATS, np.int64)
    hs = h_start.copy()
    assert ks.newton_machine(hs, -D + h0 + 0.5 * r**2, A, ceff, H,
                             lennard_jones(h0, c, N), 1e-11 * h0, 40, cache, stats,
                             ks.Machine(1.0 / stiffness, wP, np.inf))   # inf: no LJ tail, as P
    lj_traction_and_stiffness(hs, h0, c, sig, d)
    P = 2.0 * np.pi * wP @ sig
    delta = D - P / stiffness
    assert abs(delta - (1.0 - 0.05 * h0)) > 1e-2 * h0         # the spring did move
    g = -delta + h0 + 0.5 * r**2
    assert np.max(np.abs(hs - g - A @ (ceff * sig - H))) < 1e-10 * h0
    # measured 9 and 16 iterations at K = 3 and 0.3 (8 for a rigid machine, K = 1e6)
    assert stats[ks.STAT_ITER] <= 20


def test_a_compliant_machine_carries_the_load_with_its_lennard_jones_tail():
    # the same solve with the mesh's tail (the LJ attraction beyond the edge, kernels.solve.load):
    # the spring's load is 2 pi wP . sigma + tail_load(h_end), h_end the last gap continued
    # rigidly; the tail's derivative is not in the Jacobian and Newton still converges
    from sweep.engine.initial import ElasticSolver, relaxed_state
    from sweep.kernels.interface import tail_load
    N, stiffness = 120, 0.3
    A, _, h0, c, _ = _problem(N=N, seed=3)
    mesh = uniform_mesh(N, 3.0)
    r, wP, tail = np.asarray(mesh.r), np.asarray(mesh.load_weights, float), mesh.tail_rise
    assert tail == pytest.approx(0.5 * ((3.0 + r[1]) ** 2 - 9.0))
    h_start, _ = relaxed_state(ElasticSolver(A, r, h0, c, 1e-10), delta0=1.0)
    sig, d = np.empty(N), np.empty(N)
    ceff, H = 0.95, -0.01 * np.exp(-r)
    D = 1.0 - 0.05 * h0
    stats = np.zeros(ks.N_STATS, np.int64)
    hs = h_start.copy()
    assert ks.newton_machine(hs, -D + h0 + 0.5 * r**2, A, ceff, H, lennard_jones(h0, c, N),
                             1e-11 * h0, 40, ks.new_jacobian_cache(N), stats,
                             ks.Machine(1.0 / stiffness, wP, tail))
    lj_traction_and_stiffness(hs, h0, c, sig, d)
    P_tail = tail_load(hs[-1] + tail, h0, c)
    assert P_tail < 0.0
    P = 2.0 * np.pi * wP @ sig + P_tail
    g = -(D - P / stiffness) + h0 + 0.5 * r**2
    assert np.max(np.abs(hs - g - A @ (ceff * sig - H))) < 1e-10 * h0
    # without the tail the spring would sit elsewhere by P_tail / K, far beyond the tolerance
    assert abs(P_tail / stiffness) > 1e3 * 1e-10 * h0
    assert stats[ks.STAT_ITER] <= 20


def _pz_traction(h, h_old, h0, c, rate_scale, xi):
    """The process zone's traction in numpy, from the law's definition (docs/design.md, "The
    process zone in the BEM"): m(q) sigma_LJ on the tensile side, q = (h - h_old) rate_scale;
    the power law itself (the nodes of this step open far beyond its smoothed range)."""
    x3 = (h0 / h) ** 3
    lj = -c * (x3 - x3 ** 3)
    q = np.maximum((h - h_old) * rate_scale, 0.0)
    return np.where(h > h0, (1.0 + q ** xi) * lj, lj)


def test_settling_the_tip_with_a_process_zone_lowers_its_residual_and_keeps_the_solution():
    """A process-zone step (kernels.solve.solve_step settles its cubic start at the crack tip,
    ZONE_SETTLE_NODES): from the relaxed elastic state, an unloading step of 0.2 h0 whose
    start misses the solution at the tip by 1e-3 h0 (a fifth of the step's opening there, as a
    cubic extrapolation's miss can be). settle_tip lowers the residual of the
    settled nodes (numpy's, of the law as documented) by orders and moves no other node; Newton
    from the settled start and from the unsettled one reach the same state, within their
    tolerance."""
    from sweep.engine.initial import ElasticSolver, relaxed_state
    from sweep.kernels.interface import Interface, smoothing_rate

    N = 160
    A, _, h0, c, _ = _problem(N=N)
    r = np.arange(N) * 3.0 / (N - 1)
    el = ElasticSolver(A, r, h0, c, 1e-10)
    h_start, _ = relaxed_state(el, delta0=1.0)
    xi, rate_scale = 0.5, 50.0 / h0                  # m - 1 = 1 at an opening of h0 / 50
    law = Interface(h0, c, h_start.copy(), np.array([rate_scale, xi, smoothing_rate(xi)]))
    g = -(1.0 - 0.2 * h0) + h0 + 0.5 * r ** 2
    ceff, H, tol = 0.8, -0.05 * np.exp(-r), 1e-10 * h0

    def newton(h):
        ok = ks.newton(h, g, A, ceff, H, law, tol, 40, ks.new_jacobian_cache(N),
                       np.zeros(ks.N_STATS, np.int64))
        return ok, h

    ok, solution = newton(h_start.copy())
    assert ok
    F = solution - g - A @ (ceff * _pz_traction(solution, h_start, h0, c, rate_scale, xi) - H)
    assert np.max(np.abs(F)) <= tol                  # the kernel's law is the documented one
    tip = int(np.searchsorted(r, crossing_radius(solution, r, 3.0 ** (1.0 / 6.0) * h0)))
    lo, hi = tip - ks.ZONE_SETTLE_NODES, tip + ks.ZONE_SETTLE_NODES
    zone_term = np.maximum((solution - h_start) * rate_scale, 0.0) ** xi
    assert 0 < lo and hi < N and zone_term[lo:hi].max() > 0.3      # the zone acts at the tip
    start = solution.copy()
    start[lo:hi] += 1e-3 * h0 * np.sin(np.pi * (np.arange(hi - lo) + 0.5) / (hi - lo))

    def tip_residual(h):
        F = h - g - A @ (ceff * _pz_traction(h, h_start, h0, c, rate_scale, xi) - H)
        return np.max(np.abs(F[lo:hi]))

    settled = start.copy()
    first, after = ks.settle_tip(settled, g, A, ceff, H, law, lo, hi, ks.ZONE_SETTLE_ITER)
    assert first == pytest.approx(tip_residual(start), rel=1e-9)
    assert tip_residual(settled) == pytest.approx(after, rel=1e-6, abs=1e-14)
    assert after < 1e-2 * first
    assert np.array_equal(settled[:lo], start[:lo]) and np.array_equal(settled[hi:], start[hi:])
    for h in (start, settled):
        ok, found = newton(h.copy())
        assert ok and np.max(np.abs(found - solution)) <= 1e-8 * h0
