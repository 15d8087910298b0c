"""The march's kernels (kernels.protocol). A step held at a load (newton_at_load): the gap and
the indentation solved together must zero the residual numpy computes at the indentation
found, carry the load asked for, and be the state the ordinary Newton solve finds at that
indentation. Newton's start settled at the crack tip (settle_tip): the residual there falls,
no other node moves. A factorization with its crack-tip zone ahead of the tip
(factorize_ahead): placed where asked, the rest of it the ordinary one's, kept while the tip
lies far enough inside the zone, and Newton with it finds the ordinary solve's state. The
dwell's predictors on the clock log(t - origin) (predictor_steps, held_guess): exact for a
quadratic in that clock, and the plain extrapolation in time without an origin."""
import numpy as np
import pytest

from sweep.engine.initial import ElasticSolver, relaxed_state
from sweep.engine.mesh import uniform_mesh
from sweep.engine.problem import lj_constants
from sweep.kernels import solve as ks
from sweep.kernels.interface import lennard_jones, lj_traction_and_stiffness
from sweep.kernels import jacobian as jac
from sweep.kernels.protocol import (RECENT_DELTA, RECENT_DWELL, RECENT_T, SETTLE_WALL_POWER,
                                    factorize_ahead, held_guess, newton_at_load,
                                    predictor_steps)
from sweep.kernels.solve import predict, settle_tip

N = 120
TOL = 1e-10        # units of h0


def _step():
    """One unloading-like step from the relaxed elastic state at delta = 1 (C_eff < 1, a
    history vector), as tests/kernels/test_newton.py makes it."""
    mesh = uniform_mesh(N, 3.0)
    A, r = np.array(mesh.influence), np.asarray(mesh.r)
    h0, c = lj_constants(3.24)
    el = ElasticSolver(A, r, h0, c, 1e-10)
    h_start, _ = relaxed_state(el, delta0=1.0)
    return A, r, h0, c, h_start, np.asarray(mesh.load_weights)


def _load(h, h0, c, wP):
    sig, d = np.empty(h.size), np.empty(h.size)
    lj_traction_and_stiffness(h, h0, c, sig, d)
    return 2.0 * np.pi * wP @ sig, sig


@pytest.mark.parametrize("extra", [0.3, -0.2])
def test_the_held_step_carries_the_load_at_the_indentation_it_found(extra):
    A, r, h0, c, h_start, wP = _step()
    ceff, H = 0.8, -0.05 * np.exp(-r)
    delta = 1.0
    g = -delta + h0 + 0.5 * r ** 2
    force = _load(h_start, h0, c, wP)[0] + extra
    h = h_start.copy()
    cache, stats = ks.new_jacobian_cache(N), np.zeros(ks.N_STATS, np.int64)
    law = lennard_jones(h0, c, N)
    mesh = ks.MeshArrays(A, r, wP, np.inf)            # inf: no LJ tail, as _load
    ok, shift = newton_at_load(h, g, mesh, ceff, H, law, force,
                               np.array([TOL * h0, 1e-9 * abs(force)]), 40, cache, stats)
    assert ok
    assert np.sign(shift) == np.sign(extra)           # more load, more indentation
    P, sig = _load(h, h0, c, wP)
    assert abs(P - force) <= 1e-9 * abs(force)
    g_found = -(delta + shift) + h0 + 0.5 * r ** 2
    assert np.max(np.abs(h - g_found - A @ (ceff * sig - H))) <= TOL * h0
    # the ordinary solve at that indentation finds the same state
    h_plain = h_start.copy()
    assert ks.newton(h_plain, g_found, A, ceff, H, law, TOL * h0, 40,
                     ks.new_jacobian_cache(N), np.zeros(ks.N_STATS, np.int64))
    assert np.max(np.abs(h_plain - h)) <= 1e-6 * h0



def test_the_held_step_carries_the_load_with_its_lennard_jones_tail():
    # with the mesh's tail (kernels.solve.load) the load held is 2 pi wP . sigma plus the
    # LJ attraction beyond the edge, the last gap continued rigidly; the tail's derivative is
    # not in the bordered update and Newton still converges
    from sweep.kernels.interface import tail_load
    A, r, h0, c, h_start, wP = _step()
    tail = uniform_mesh(N, 3.0).tail_rise
    ceff, H = 0.8, -0.05 * np.exp(-r)
    g = -1.0 + h0 + 0.5 * r ** 2
    force = _load(h_start, h0, c, wP)[0] + 0.3
    h = h_start.copy()
    cache, stats = ks.new_jacobian_cache(N), np.zeros(ks.N_STATS, np.int64)
    ok, shift = newton_at_load(h, g, ks.MeshArrays(A, r, wP, tail), ceff, H,
                               lennard_jones(h0, c, N), force,
                               np.array([TOL * h0, 1e-9 * abs(force)]), 40, cache, stats)
    assert ok
    P, sig = _load(h, h0, c, wP)
    P_tail = tail_load(h[-1] + tail, h0, c)
    assert abs(P + P_tail - force) <= 1e-9 * abs(force)
    assert abs(P_tail) > 1e3 * 1e-9 * abs(force)        # the tail did count
    g_found = g - shift
    assert np.max(np.abs(h - g_found - A @ (ceff * sig - H))) <= TOL * h0


def test_settling_the_tip_lowers_its_residual_and_moves_no_other_node():
    """The equilibrium at delta = 1 with the gaps of ten nodes at the crack tip off by 2 %
    (an extrapolated start's error there): settle_tip brings the residual of those nodes down
    by orders (numpy's residual), and leaves every other gap as it was."""
    A, r, h0, c, h_start, _ = _step()
    law = lennard_jones(h0, c, N)
    g = -1.0 + h0 + 0.5 * r ** 2
    tip = int(np.argmin(np.abs(h_start - 3.0 ** (1.0 / 6.0) * h0)))
    lo, hi = tip - 5, tip + 5
    h = h_start.copy()
    h[lo:hi] *= 1.02

    def tip_residual(x):
        sig = _load(x, h0, c, np.zeros(N))[1]          # the traction (C_eff 1, H 0)
        return np.max(np.abs((x - g - A @ sig)[lo:hi]))

    before = tip_residual(h)
    start = h.copy()
    first, after = settle_tip(h, g, A, 1.0, np.zeros(N), law, lo, hi, 3)
    assert first == pytest.approx(before, rel=1e-9)
    assert tip_residual(h) == pytest.approx(after, rel=1e-6, abs=1e-14)
    assert after < 1e-3 * before
    assert np.array_equal(h[:lo], start[:lo]) and np.array_equal(h[hi:], start[hi:])


def test_the_wall_step_opens_a_node_in_the_wall_as_far_as_its_power_law_says():
    """wall_step: Newton's step itself where it closes a gap, where the node is outside the
    repulsive wall (h >= h0), or at ``wall`` 0 (bitwise); a small opening step in the wall
    (dh << h / wall) nearly itself; a large one taken to h0, never beyond h0 unless the
    step itself goes there, never short of the step."""
    from sweep.kernels.solve import wall_step
    h0, p = 1.0, SETTLE_WALL_POWER
    for h, dh in ((0.7, -0.01), (1.3, 0.2), (2.0, -0.5)):
        assert wall_step(h, dh, h0, p) == h + dh
    for h, dh in ((0.7, 0.01), (0.99, 0.2)):
        assert wall_step(h, dh, h0, 0.0) == h + dh
    assert wall_step(0.98, 1e-5, h0, p) == pytest.approx(0.98 + 1e-5, rel=1e-8)
    assert wall_step(0.7, 0.7 / 9.0, h0, p) == h0        # Newton's step deep in an h^-9 wall
    assert wall_step(0.7, 0.5, h0, p) == 0.7 + 0.5
    moved = wall_step(0.7, 0.01, h0, p)
    assert 0.7 + 0.01 < moved < h0


def test_settling_a_node_deep_in_the_wall_converges_with_the_wall_step():
    """The equilibrium at delta = 1 with the gap of the last closed node at the crack tip
    put at 0.7 of its value, deep in the repulsive wall (the start the dwell's
    extrapolation gave on the quarter-resolution mesh): three iterations of settle_tip
    with the wall step bring the tip's residual orders below Newton's steps alone (which
    lengthen the gap by about h/9 an iteration), and with enough iterations both reach the
    same state. Measured: from 16, 0.71 after three plain iterations, 1.7e-5 with the wall
    step; both 4e-16 after ten."""
    A, r, h0, c, h_start, _ = _step()
    law = lennard_jones(h0, c, N)
    g = -1.0 + h0 + 0.5 * r ** 2
    closed = np.nonzero(h_start < h0)[0]
    node = int(closed[-1])
    lo, hi = node - 5, node + 5
    start = h_start.copy()
    start[node] *= 0.7
    runs = {}
    for wall in (0.0, SETTLE_WALL_POWER):
        h = start.copy()
        runs[wall] = settle_tip(h, g, A, 1.0, np.zeros(N), law, lo, hi, 3, wall)
        converged = start.copy()
        settle_tip(converged, g, A, 1.0, np.zeros(N), law, lo, hi, 40, wall)
        runs[wall, "state"] = converged
    (first, plain), (_, walled) = runs[0.0], runs[SETTLE_WALL_POWER]
    assert walled < 1e-3 * plain < 1e-3 * first
    assert np.max(np.abs(runs[0.0, "state"] - runs[SETTLE_WALL_POWER, "state"])) <= 1e-9 * h0


def test_the_zone_ahead_of_the_tip_is_placed_there_and_newton_finds_the_same_state():
    A, r, h0, c, h_start, _ = _step()
    law = lennard_jones(h0, c, N)
    ceff, H, ahead = 0.8, -0.05 * np.exp(-r), 12
    g = -1.0 + h0 + 0.5 * r ** 2
    sig, d = np.empty(N), np.empty(N)
    lj_traction_and_stiffness(h_start, h0, c, sig, d)
    tip = jac.crack_tip_index(d, np.zeros(N))
    assert tip - jac.ZONE_IN + ahead > 0          # the zone's inner end is not cut at r = 0
    cache, stats = ks.new_jacobian_cache(N), np.zeros(ks.N_STATS, np.int64)
    assert factorize_ahead(h_start, A, ceff, law, ahead, 10, cache, stats)
    state = cache[jac.CACHE_STATE]
    lo, hi, m = state[jac.STATE_ZONE_LO], state[jac.STATE_ZONE_HI], state[jac.STATE_SUBSET]
    assert lo == tip + ahead - jac.ZONE_IN and hi == min(tip + ahead + jac.ZONE_OUT, m)
    assert stats[ks.STAT_FACTOR] == 1
    # outside the zone the stiffness factorized is the state's own, as the ordinary one's
    plain = ks.new_jacobian_cache(N)
    jac.factorize(h_start, A, ceff, h0, c, law.h_old, law.zone, plain)
    outside = np.r_[0:lo, hi:N]
    assert np.array_equal(cache[jac.CACHE_E][outside], plain[jac.CACHE_E][outside])
    # kept while the tip lies at least ``least`` nodes inside the zone's outer end
    assert not factorize_ahead(h_start, A, ceff, law, ahead, hi - tip, cache, stats)
    assert factorize_ahead(h_start, A, ceff, law, ahead, hi - tip + 1, cache, stats)
    # Newton with it: the state the ordinary solve finds
    start = h_start * (1.0 + 0.01 * np.exp(-r))
    h, h_plain = start.copy(), start.copy()
    assert ks.newton(h, g, A, ceff, H, law, TOL * h0, 40, cache, stats)
    assert ks.newton(h_plain, g, A, ceff, H, law, TOL * h0, 40, ks.new_jacobian_cache(N),
                     np.zeros(ks.N_STATS, np.int64))
    assert np.max(np.abs(h - h_plain)) <= 1e-6 * h0


#: three states of a dwell and the step to take: times since its start (the dwell's steps
#: grow geometrically), the clock's origin a little before the start
DWELL_TIMES = np.array([2.0, 2.0 + 0.013, 2.0 + 0.013 + 0.0169])
DWELL_STEP = 0.022
ORIGIN = 2.0 - 1e-3


def _quadratic_in(clock, coefficients):
    a, b, c = coefficients
    return a + b * clock + c * clock ** 2


@pytest.mark.parametrize("origin", [ORIGIN, np.nan], ids=["dwell clock", "time"])
def test_the_predictor_is_exact_for_a_quadratic_on_its_clock(origin):
    """predict with predictor_steps' steps extrapolates a gap quadratic in log(t - origin)
    exactly (in t where the origin is nan): a closed form, to rounding (gaps that stay above
    the predictor's floor, half the last one)."""
    t2, t1, t0 = DWELL_TIMES               # oldest, previous, newest
    clock = (lambda t: np.log(t - origin)) if np.isfinite(origin) else (lambda t: t)
    coefficients = (np.array([1.0, 0.7, 0.5]), np.array([0.03, -0.01, 0.02]),
                    np.array([0.002, 0.001, -0.003]))
    h = [_quadratic_in(clock(t), coefficients) for t in (t0, t1, t2, t0 + DWELL_STEP)]
    steps = predictor_steps(t0, DWELL_STEP, t0 - t1, t1 - t2, origin)
    if np.isnan(origin):
        assert steps == (DWELL_STEP, t0 - t1, t1 - t2)
    out = np.empty(3)
    assert predict(h[0], h[1], h[2], *steps, out)
    np.testing.assert_allclose(out, h[3], rtol=1e-10)


def test_the_predictor_keeps_time_where_the_origin_is_after_a_state():
    """A state older than the origin (the approach's, before the dwell) leaves the steps in
    time."""
    t0 = DWELL_TIMES[2]
    assert predictor_steps(t0, DWELL_STEP, 0.5, 0.5, ORIGIN) == (DWELL_STEP, 0.5, 0.5)


@pytest.mark.parametrize("origin", [ORIGIN, np.nan], ids=["dwell clock", "time"])
def test_the_held_indentation_is_exact_for_a_quadratic_on_its_clock(origin):
    """held_guess through the dwell's last three records extrapolates an indentation
    quadratic in log(t - origin) exactly (in t where the origin is nan); through two, the
    line on that clock."""
    clock = (lambda t: np.log(t - origin)) if np.isfinite(origin) else (lambda t: t)
    coefficients = (1.3, 0.04, -0.002)
    recent = np.zeros((3, 3))
    recent[RECENT_T] = DWELL_TIMES
    recent[RECENT_DELTA] = [_quadratic_in(clock(t), coefficients) for t in DWELL_TIMES]
    recent[RECENT_DWELL] = [0.0, 1.0, 1.0]          # the dwell's start, then two of its steps
    x = DWELL_TIMES[2] + DWELL_STEP
    assert held_guess(recent, x, origin) == pytest.approx(_quadratic_in(clock(x), coefficients),
                                                          rel=1e-12)
    recent[RECENT_DWELL, 1] = 0.0                   # one step into the dwell: the line
    line = (coefficients[0], coefficients[1], 0.0)
    recent[RECENT_DELTA] = [_quadratic_in(clock(t), line) for t in DWELL_TIMES]
    assert held_guess(recent, x, origin) == pytest.approx(_quadratic_in(clock(x), line),
                                                          rel=1e-12)
