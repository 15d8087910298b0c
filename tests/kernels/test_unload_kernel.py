"""The unloading kernel is resumable: a run continued in chunks (state handed back and
forth: gap, Prony modes, step, records) reproduces the run done in one go.

This is the interface a tip-following mesh and a wall-time budget build on. Its step
predictors are exact for polynomials in time of their order.
"""
import numpy as np
import pytest

from sweep.kernels.solve import (N_STATS, STAT_ITER, STATUS_DONE, STATUS_STEP_LIMIT,
                                 STATUS_TIME_BUDGET, Physics, Records, RunState,
                                 StepControl, new_jacobian_cache, set_deadline, unload)
from sweep.engine.initial import ElasticSolver, relaxed_state
from sweep.engine.problem import prepare
from sweep.scene import Numerics, Scene
from sweep.engine.bem import MAX_NEWTON_ITER, STEP_TOL, STOP_TRAVEL_SPACINGS

SCENE = Scene(n=0.8, k=0.2, mu=3.24, a0=1.5, rate=10.0)
NUMERICS = Numerics(mesh="uniform", nodes=120, domain=3.0, step=0.25, da_max=1.0,
                    prony_rtol=1e-3, tol=1e-10, pull_off_rtol=0.0)


def _run(chunk, deadline_s=np.inf):
    pb = prepare(SCENE, NUMERICS)
    el = ElasticSolver(pb.A, pb.mesh.r, pb.h0, pb.c, NUMERICS.tol)
    h, delta0 = relaxed_state(el, a0=SCENE.a0)
    N, M = pb.mesh.nodes, pb.prony_weights.size
    q, step, sigma = np.zeros((M, N)), np.zeros(1), np.zeros(N)
    out = [np.empty(NUMERICS.max_steps + 1) for _ in range(5)]
    stats = np.zeros(N_STATS, np.int64)
    cache = new_jacobian_cache(N)
    n, calls = 0, 0
    while True:
        h_out = np.empty(N)
        set_deadline(cache, deadline_s)
        limit = NUMERICS.max_steps if chunk is None else min(n + chunk, NUMERICS.max_steps)
        control = StepControl(NUMERICS.step, NUMERICS.min_step, NUMERICS.da_max * pb.mesh.spacing,
                              STEP_TOL, NUMERICS.tol, MAX_NEWTON_ITER, limit, pb.stop_mode,
                              STOP_TRAVEL_SPACINGS * pb.mesh.spacing, *pb.tip_range,
                              NUMERICS.da_max * pb.mesh.spacing, 0.0)
        status, n = unload(pb.mesh_arrays(),
                           Physics(pb.h0, pb.c, pb.prony_weights, pb.prony_times, SCENE.rate,
                                   pb.hdot_c, pb.pz_xi),
                           control, RunState(h, delta0, q, n, step, sigma, np.zeros(N)), Records(*out, h_out),
                           cache, stats)
        calls += 1
        h = h_out
        if status != STATUS_STEP_LIMIT or limit >= NUMERICS.max_steps:
            break
    return status, n, calls, [x[:n] for x in out], stats


def test_unloading_resumed_in_chunks_reproduces_one_run():
    s1, n1, c1, (t1, d1, P1, a1, _), _ = _run(None)
    s2, n2, c2, (t2, d2, P2, a2, _), _ = _run(5)
    assert s1 == s2 == STATUS_DONE
    assert c1 == 1 and c2 >= 5
    # the predictor restarts at each resume, so the steps may differ slightly: compare
    # the load minimum (pull-off) and the indentation where it occurs
    assert abs(P1.min() - P2.min()) < 1e-7 * abs(P1.min())
    assert abs(d1[P1.argmin()] - d2[P2.argmin()]) < 2 * NUMERICS.step * prepare(SCENE, NUMERICS).h0
    # the records of a resumed run continue in time
    assert np.all(np.diff(t2) > 0)


def test_a_deadline_the_run_meets_changes_nothing():
    """The kernel reads its deadline (the scene's time budget) before every try of a step
    and every Newton iteration; a run that ends before it is the run without one, bit for
    bit."""
    s1, n1, _, records1, stats1 = _run(None)
    s2, n2, _, records2, stats2 = _run(None, deadline_s=1e6)
    assert s1 == s2 == STATUS_DONE and n1 == n2
    for x, y in zip(records1, records2):
        np.testing.assert_array_equal(x, y)
    np.testing.assert_array_equal(stats1, stats2)


def test_a_passed_deadline_ends_the_kernel_before_its_first_step():
    """Past its deadline the kernel takes no step and says so: one chunk of a large mesh
    ran for minutes past the scene's budget when only the driver checked it, between
    chunks."""
    status, n, calls, records, stats = _run(None, deadline_s=-1.0)
    assert status == STATUS_TIME_BUDGET and calls == 1
    assert n == 1 and stats[STAT_ITER] == 0          # record 0, the initial state, alone


def test_solver_in_small_chunks_gives_the_same_result(monkeypatch):
    from sweep.engine import bem as solver
    one = solver.simulate(SCENE, NUMERICS)
    monkeypatch.setattr(solver, "CHUNK_STEPS", 4)
    chunked = solver.simulate(SCENE, NUMERICS)
    assert one.ok and chunked.ok
    assert abs(one.pull_off - chunked.pull_off) < 1e-7 * one.pull_off
    assert chunked.steps == one.steps


def test_time_budget_ends_a_run_failed_with_the_reason(monkeypatch):
    import dataclasses

    from sweep.engine import bem as solver
    monkeypatch.setattr(solver, "CHUNK_STEPS", 2)
    res = solver.simulate(SCENE, dataclasses.replace(NUMERICS, time_budget_s=1e-6))
    assert res.status == "failed"
    assert res.reason.startswith("time budget") and "time_budget_s" in res.reason
    assert res.steps <= 2 * solver.CHUNK_STEPS


def test_step_control_grows_beyond_step_max_only_where_smooth():
    from sweep.kernels.solve import EASY_STEPS, SMOOTH_STEP_FACTOR, next_step
    dd_max, da_max, tol = 1.0, 1.0, 1e-3

    def run(da, err, dd=dd_max, steps=EASY_STEPS):
        easy = 0
        for _ in range(steps):
            dd, easy = next_step(dd, easy, da, da_max, err, dd_max, tol)
        return dd
    assert run(0.1, 1e-6) == 2.0                       # smooth and slow tip: doubles
    assert run(0.1, 1e-6, steps=10 * EASY_STEPS) == SMOOTH_STEP_FACTOR   # capped
    assert run(0.1, 1e-3) == dd_max                    # predictor error too large
    assert run(0.4, 1e-6) == dd_max                    # a doubled step would move the tip too far
    assert run(0.1, np.inf) == dd_max                  # no error estimate (after a fold)
    # beyond step_max, a fast tip or a large error halves the step back at once
    assert next_step(4.0, 3, 0.7, da_max, 1e-6, dd_max, tol) == (2.0, 0)
    assert next_step(4.0, 3, 0.1, da_max, 2e-3, dd_max, tol) == (2.0, 0)
    # below step_max the step doubles after EASY_STEPS slow steps, never past step_max
    assert run(0.1, np.inf, dd=0.5) == dd_max


def test_grown_steps_keep_the_pull_off(monkeypatch):
    from sweep.engine import bem as solver
    # a large contact: the crack tip recedes slowly over hundreds of steps (~1 s per run)
    scene = Scene(n=0.6, k=0.1, mu=3.24, a0=8.0, rate=10**2.5)
    num = Numerics.preset("fast", pull_off_rtol=0.0, max_nodes=1000)
    grown = solver.simulate(scene, num)
    monkeypatch.setattr(solver, "STEP_TOL", 0.0)
    capped = solver.simulate(scene, num)
    assert grown.ok and capped.ok
    assert grown.steps < 0.9 * capped.steps
    steps = -np.diff(grown.trajectory["delta"]) / prepare(scene, num).h0
    assert steps.max() > 1.5 * num.step and np.all(steps <= 8 * num.step * (1 + 1e-9))
    assert abs(grown.pull_off / capped.pull_off - 1) < 1e-6
    assert abs(grown.crack_speed / capped.crack_speed - 1) < 1e-4


def test_predictors_are_exact_for_polynomials_of_their_order():
    # Lagrange extrapolation through the accepted states at uneven steps (the step halves
    # and doubles): the quadratic predictor reproduces a quadratic in time, the cubic one a
    # cubic, at the next step; the cubic one waits for four states
    from sweep.kernels.solve import predict, predict_cubic
    t = np.array([0.0, 0.3, 0.45, 0.55])                 # accepted times, last = now
    dt = 0.2
    x = np.linspace(1.0, 2.0, 7)                         # one gap per node, above the floor

    def gap(tau, order):
        return 3.0 + x * tau + 0.5 * x**2 * tau**2 + (0.2 * x * tau**3 if order == 3 else 0.0)

    dts = np.diff(t)[::-1]                               # dt_prev, dt_prev2, dt_prev3
    hp = np.empty_like(x)
    h, h1, h2, h3 = (gap(tau, 2) for tau in t[::-1])
    assert predict(h, h1, h2, dt, dts[0], dts[1], hp)
    np.testing.assert_allclose(hp, gap(t[-1] + dt, 2), rtol=1e-13)
    h, h1, h2, h3 = (gap(tau, 3) for tau in t[::-1])
    assert predict_cubic(h, h1, h2, h3, dt, dts[0], dts[1], dts[2], hp)
    np.testing.assert_allclose(hp, gap(t[-1] + dt, 3), rtol=1e-13)
    predict(h, h1, h2, dt, dts[0], dts[1], hp)
    assert np.max(np.abs(hp - gap(t[-1] + dt, 3))) > 1e-4  # the quadratic one is not exact
    hp[:] = -1.0
    assert not predict_cubic(h, h1, h2, h3, dt, dts[0], dts[1], 0.0, hp)
    assert np.all(hp == -1.0)                            # nothing written before four states


def _lattice_states(count, dt, T, ds, r, h0=1.0):
    """A crack tip held and released by the nodes (spacing ``ds``): it recedes one spacing
    in each period ``T`` at a speed that varies by a factor 9 within the period, the gap a
    sharp profile that travels with it plus a slow uniform opening (units of h0)."""
    def tip(t):
        return 2.0 - ds * (t / T - 0.8 * np.sin(2 * np.pi * t / T) / (2 * np.pi))

    def gap(t):
        x = (r - tip(t)) / (1.5 * ds)
        return h0 * (1.0 + np.log1p(np.exp(x)) ** 2) + 0.01 * h0 * t
    times = dt * np.arange(count)
    return times, [gap(t) for t in times], np.array([tip(t) for t in times]), gap


@pytest.mark.parametrize("count", [12, 21])           # the ring not yet full, and wrapped
def test_tip_predictor_follows_a_tip_held_by_the_nodes(count):
    # the gaps next to a tip that moves in a cycle repeated node by node: the tip predictor
    # (the change of one cycle earlier, one node along) is exact where the steps hit the
    # cycle, the cubic extrapolation at the nodes misses by tenths of h0
    from sweep.kernels.solve import (LATTICE_HISTORY, PREDICT_FLOOR, predict_cubic,
                                     predict_lattice)
    ds, T = 0.02, 1.0
    dt = T / 5
    r = ds * np.arange(200)
    times, states, tips, gap = _lattice_states(count, dt, T, ds, r)
    past, past_ta = np.empty((LATTICE_HISTORY, r.size)), np.empty((2, LATTICE_HISTORY))
    for k in range(count):
        past[k % LATTICE_HISTORY] = states[k]
        past_ta[:, k % LATTICE_HISTORY] = times[k], tips[k]
    h = states[-1]
    hp = np.empty_like(r)
    assert predict_cubic(h, states[-2], states[-3], states[-4], dt, dt, dt, dt, hp)
    exact = gap(times[-1] + dt)
    near = np.abs(r - tips[-1]) < 10 * ds
    cubic_error = np.max(np.abs(hp - exact)[near])
    assert cubic_error > 0.05
    assert predict_lattice(r, h, past, past_ta, count, dt, hp)
    assert np.max(np.abs(hp - exact)[near]) < 1e-9
    assert np.all(hp >= PREDICT_FLOOR * h)
    # a tip that has not moved one node within the ring: nothing written
    past_ta[1] = tips[-1] + 1e-3 * ds * np.arange(LATTICE_HISTORY)
    hp[:] = -1.0
    assert not predict_lattice(r, h, past, past_ta, count, dt, hp)
    assert np.all(hp == -1.0)


def test_the_two_starts_are_scored_on_the_band_around_the_tip():
    # log2 of the tip predictor's error over the cubic's, max over the band around the tip:
    # an error far from the tip does not count
    from sweep.kernels.solve import LATTICE_BAND_OUT, score_starts
    r = 0.01 * np.arange(300)
    h = np.ones_like(r)
    starts = np.ones((2, r.size))
    tip = 100
    starts[0, tip + 1] += 0.4                      # the cubic misses next to the tip
    starts[1, tip - 2] += 0.1                      # the tip predictor by a quarter of that
    starts[1, tip + LATTICE_BAND_OUT + 5] += 9.0   # beyond the band: not counted
    assert score_starts(r, starts, h, r[tip] - 0.005) == pytest.approx(-2.0)
    starts[1, tip - 2] += 0.7
    assert score_starts(r, starts, h, r[tip] - 0.005) == pytest.approx(1.0)
