"""The protocol march's own solves (:mod:`sweep.engine.protocol`; Numba kernels): a time step
held at a load, Newton on the gap and the indentation together (:func:`newton_at_load`),
Newton's start settled at the crack tip (:func:`kernels.solve.settle_tip`), and the
approach's kept factorization, its crack-tip zone ahead of an advancing tip
(:func:`factorize_ahead`).

A dwell at force (:mod:`sweep.engine.protocol`) asks, at each time step, for the indentation
delta at which the equilibrium of the step carries the preload. Solved as one system, for the
nodal gaps h and the indentation change s from a guess delta (docs/design.md section 4):

    F(h, s) = h - g + s - A [ C_eff sigma(h) - H ] = 0,     g = -delta + h0 + r^2/2,
    G(h)    = P(h) - P* = 0,     P(h) = 2 pi wP . sigma(h) + P_tail(h_N),

(dF/ds = 1 at every node). With J the Jacobian of F in h (:mod:`kernels.jacobian`, its kept
factorization), x = -J^-1 F and y = J^-1 1, the Newton update is dh = x - y ds with

    ds = (2 pi wP . (sigma' x) + P - P*) / (2 pi wP . (sigma' y))

(the bordered system eliminated: two solves with one factorization). One solve of the step
instead of a secant of two or three solves on delta. P_tail is the Lennard-Jones attraction
beyond the mesh (:func:`kernels.solve.load`); its derivative, in the last node's gap alone
and about 2 pi c / tail_gap^3, is left out of ds's denominator and numerator (Newton's
G converges with it left out: G itself includes the tail).

The march's starts (an extrapolation of the last states) are furthest off at the crack tip,
where the gap equation is most nonlinear: the node behind an advancing tip lands on the
repulsive wall, and even exact Newton from there took three iterations.
:func:`kernels.solve.settle_tip` runs Newton on the few nodes around the tip alone, the
others held, at the cost of those rows of A, before the solve of the whole; a node it opens
from deep in the wall moves as the wall's power law says (SETTLE_WALL_POWER).
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

from .history import history_vector, step_coefficients, update_modes
from .jacobian import (CACHE_STATE, STATE_SCALED, STATE_SUBSET, STATE_VALID, STATE_ZONE_HI,
                       apply_inverse, crack_tip_index, factorize, newton_direction,
                       scale_for_drift)
from .interface import (TIP_GAP, ZONE_RATE, crossing_radius, traction,
                        traction_and_stiffness)
from .solve import (LATTICE_SCORE_USE, LATTICE_SCORE_WEIGHT, STAT_FACTOR, STAT_ITER,
                    STAT_REFACTOR_SLOW, STAT_REFACTOR_ZONE, STAT_RESIDUALS, STAT_SUBSET,
                    STAT_ZONE, load, newton, positive_step, predict, predict_lattice, residual,
                    score_starts, settle_tip)

#: an iteration whose residual ``max |F|`` falls by less than this factor refactorizes before
#: the next (the unloading Newton's SLOW_CONTRACTION, :mod:`kernels.solve`)
HELD_SLOW_CONTRACTION = 0.1
#: :func:`factorize_ahead` closes the nodes ahead of the crack tip to this fraction below
#: the tip gap
CLOSED_BELOW = 1e-3
#: the march's settle at the crack tip takes a node in the repulsive wall that Newton opens
#: in (h0/h)^SETTLE_WALL_POWER, at most to h0 (:func:`kernels.solve.wall_step`). On the
#: quarter-resolution mesh of the error estimate's crossing check the dwell's starts put the
#: node at the crack tip deep in the wall, 1e6-1e8 tolerances off, where the settle's three
#: Newton steps in h barely move it: the dwells at force of ``make protocol-cost``'s bench
#: scenes took 326 / 510 / 311 Newton iterations there, 7 / 5 / 6 held steps falling back to
#: the secant of ordinary solves; with the wall step 237 / 458 / 254 and 0 / 4 / 2 (the SLS
#: scene 964 -> 835 and 7 -> 4), the fine and half-resolution solves within 1 %, every
#: row's pull-off within 2e-8. The power: 9 (the wall's own) 267 / 462 / 277 iterations,
#: 12 249 / 458 / 252, 18 the fewest fallbacks
SETTLE_WALL_POWER = 18.0
#: an iteration whose residual grows by more than this factor ends the solve unconverged
#: (the caller falls back to a secant of ordinary solves)
HELD_DIVERGENCE = 10.0


@njit(cache=True, inline='always')
def _factorize_counted(h, A, ceff, law, cache, stats):
    """The Jacobian at ``h`` factorized into ``cache`` (:func:`kernels.jacobian.factorize`),
    counted in ``stats`` (STAT_FACTOR, STAT_SUBSET)."""
    stats[STAT_SUBSET] += factorize(h, A, ceff, law.h0, law.c, law.h_old, law.zone, cache)
    stats[STAT_FACTOR] += 1


@njit(cache=True, inline='always')
def _bordered_update(h, F, A, ceff, law, P, force, wP, cache, stats, y, out):
    """The Newton update (dh into ``out``, returns (ds, ok)) of the bordered system at
    ``h`` (residual ``F``, load ``P``) with the cache's factorization, made again once where
    it no longer fits (the crack tip left its zone). ``y`` is J^-1 1, made here where its
    first entry is nan (and again with a new factorization), else kept: it only weighs
    the indentation's update, which the next iterations correct. With the drift-scaled
    chord (``state[STATE_SCALED]``) y is scaled for the drift as the direction x is
    (:func:`kernels.jacobian.scale_for_drift`): unscaled, its error times the indentation's
    update was the largest residual after a held step's first iteration, in the contact's
    interior (measured on the dwells at force of ``make protocol-cost``: Newton iterations of
    the dwells' solves, the error estimate's included, 163 / 361 / 171 -> 101 / 227 / 102 on
    the mu-5 MPL and SLS scenes and the slow bench scene, 513 / 678 -> 509 / 665 on the fast
    bench scenes, whose starts are furthest off at the crack tip; the pull-offs within
    1.5e-7)."""
    N = h.size
    sig, d, dr = np.empty(N), np.empty(N), np.empty(N)
    traction_and_stiffness(h, law.h_old, law.zone, law.h0, law.c, sig, d, dr)
    x, ok = newton_direction(F, d, dr, A, ceff, cache, stats, STAT_ZONE)
    if not ok:
        _factorize_counted(h, A, ceff, law, cache, stats)
        stats[STAT_REFACTOR_ZONE] += 1
        x, ok = newton_direction(F, d, dr, A, ceff, cache, stats, STAT_ZONE)
        if not ok:
            return 0.0, False
        y[0] = np.nan
    if np.isnan(y[0]):
        ones = apply_inverse(np.ones(N), A, cache)
        if cache[CACHE_STATE][STATE_SCALED] == 1:     # as newton_direction's x
            scale_for_drift(ones, d, A, ceff, cache)
        for i in range(N):      # a loop: a slice assignment compiles numba's shape message
            y[i] = ones[i]
    px, py = 0.0, 0.0
    for i in range(N):
        px += wP[i] * d[i] * x[i]
        py += wP[i] * d[i] * y[i]
    px *= 2.0 * np.pi
    py *= 2.0 * np.pi
    if py == 0.0 or not np.isfinite(py):
        return 0.0, False
    ds = (px + P - force) / py
    for i in range(N):
        out[i] = x[i] - y[i] * ds
    return ds, True


@njit(cache=True)
def newton_at_load(h, g, mesh, ceff, H, law, force, tols, max_iter, cache, stats):
    """Solve F(h, s) = 0 and G(h) = 0 (module docstring) in place of ``h`` from ``h`` and
    s = 0, the gap g of the guessed indentation, on the mesh ``mesh``
    (:data:`kernels.solve.MeshArrays`: the load :func:`kernels.solve.load` of its weights and
    tail, the Lennard-Jones attraction beyond the mesh included); ``tols`` = (``max |F|`` in
    units of d_ref, ``|G|`` in units of pi dg R). Returns (converged, s): the step's
    indentation is the guess plus s. The cache's factorization is kept and made again where
    its iteration contracts the residual by less than HELD_SLOW_CONTRACTION (not with the
    drift-scaled chord, ``state[STATE_SCALED]``: :func:`kernels.solve.newton`); a residual
    growing by HELD_DIVERGENCE ends the solve unconverged."""
    N, A = h.size, mesh.A
    sig, w, F, dh, y = np.empty(N), np.empty(N), np.empty(N), np.empty(N), np.full(N, np.nan)
    gs = g.copy()
    s = 0.0
    if cache[CACHE_STATE][STATE_VALID] == 0:
        _factorize_counted(h, A, ceff, law, cache, stats)
    norm = residual(h, gs, A, ceff, H, law, sig, w, F)
    stats[STAT_RESIDUALS] += 1
    for _ in range(max_iter):
        P = load(sig, mesh.wP, h, mesh.tail, law.h0, law.c)
        if norm <= tols[0] and abs(P - force) <= tols[1]:
            return True, s
        stats[STAT_ITER] += 1
        ds, ok = _bordered_update(h, F, A, ceff, law, P, force, mesh.wP, cache, stats, y, dh)
        if not ok:
            return False, s
        lam = positive_step(h, dh)
        for i in range(N):
            h[i] += lam * dh[i]
            gs[i] -= lam * ds
        s += lam * ds
        new = residual(h, gs, A, ceff, H, law, sig, w, F)
        stats[STAT_RESIDUALS] += 1
        if not new < HELD_DIVERGENCE * norm:
            return False, s
        if (new > tols[0] and new > HELD_SLOW_CONTRACTION * norm
                and cache[CACHE_STATE][STATE_SCALED] == 0):
            _factorize_counted(h, A, ceff, law, cache, stats)
            stats[STAT_REFACTOR_SLOW] += 1
            y[0] = np.nan
        norm = new
    return False, s


@njit(cache=True)
def factorize_ahead(h, A, ceff, law, ahead, least, cache, stats):
    """Factorize the Jacobian at ``h`` (Lennard-Jones law) into ``cache`` with its crack-tip
    zone placed ``ahead`` nodes further out than :func:`kernels.jacobian.factorize` places
    it, for a crack tip that advances (an approach: the contact grows), where the cache
    holds no factorization or its zone ends less than ``least`` nodes outside the crack tip
    of ``h`` (and before the factorized nodes end). Returns whether it factorized.

    :func:`kernels.jacobian.factorize` places the zone about the state's crack tip, most of
    it inside (the tip of an unloading recedes); it is given ``h`` with the ``ahead`` nodes
    outside the tip closed to just below the tip gap, so that it finds the tip there. The
    closed nodes lie in the zone (``ahead`` < ZONE_IN - ZONE_MARGIN, so that the tip of ``h``
    lies inside the zone's margin too), so the factorized interior B has the stiffness of
    ``h`` itself, and the zone's is made from the iterate at the first Newton direction
    (:func:`kernels.jacobian.newton_direction`: a factorization leaves its Schur complement
    stale). Counted in ``stats`` as any factorization. The march runs the Lennard-Jones law
    alone: the tip is where the gap crosses the tip gap."""
    N = h.size
    sig, d, dr = np.empty(N), np.empty(N), np.empty(N)
    traction_and_stiffness(h, law.h_old, law.zone, law.h0, law.c, sig, d, dr)
    tip = crack_tip_index(d, dr)
    state = cache[CACHE_STATE]
    if (state[STATE_VALID] == 1 and (state[STATE_ZONE_HI] - tip >= least
                                     or state[STATE_ZONE_HI] >= state[STATE_SUBSET])):
        return False
    closed = h.copy()
    below = TIP_GAP * law.h0 * (1.0 - CLOSED_BELOW)
    for i in range(tip, min(tip + ahead, N)):
        closed[i] = min(closed[i], below)
    _factorize_counted(closed, A, ceff, law, cache, stats)
    return True


#: :func:`dwell_steps`' outcomes: the dwell ended; ``max_steps`` tries made (the caller checks
#: its time budget and calls again); the solve of a step failed where the caller's fallback
#: takes over (the held step's secant of ordinary solves, the smallest step's relaxation of a
#: fold)
DWELL_ENDED = 0
DWELL_CHUNK = 1
DWELL_FAILED = 2
#: the entries of :data:`MarchState`'s ``clock``: the march's time, indentation, next step
#: (the dwell's time step, the approach's indentation step), last two time steps, tip
#: predictor's score, states written to its ring, contact radius of the last state, (on a
#: hand-over to the caller) the step's time step, indentation and whether the tip predictor
#: made a start, the last state's load, and the phase (1.0 the dwell, 0.0 the approach)
CLOCK_T = 0
CLOCK_DELTA = 1
CLOCK_DT = 2
CLOCK_DT_PREV = 3
CLOCK_DT_PREV2 = 4
CLOCK_TIP_SCORE = 5
CLOCK_RING = 6
CLOCK_A = 7
CLOCK_GUESS = 8
CLOCK_MADE = 9
CLOCK_P = 10
CLOCK_PHASE = 11
CLOCK_SIZE = 12
#: the rows of :data:`MarchState`'s ``recent``: the last three records' times, indentations
#: and whether each was the dwell's (1.0) or the approach's (0.0); column 2 the newest
RECENT_T = 0
RECENT_DELTA = 1
RECENT_DWELL = 2

#: the dwell's settings: hm the gap at which the contact radius is read; hold_force the load
#: held at ``force`` (else the indentation); tols Newton's (max |F| in h0 units times h0,
#: |P - force| in pi dg R); end the dwell's end (tau0); da_max the most a step may move the
#: contact radius (a_ref); dt_min the smallest step; growth the next step's factor after a
#: step that moved the radius by less than grow_below da_max; tip_nodes, tip_iter the settle
#: at the crack tip (:func:`kernels.solve.settle_tip`); max_iter Newton's iterations;
#: max_steps the tries of one call; origin the origin of the predictors' clock
#: (:func:`dwell_clock`)
DwellControl = namedtuple("DwellControl", [
    "hm", "hold_force", "force", "tols", "end", "da_max", "dt_min", "growth", "grow_below",
    "tip_nodes", "tip_iter", "max_iter", "max_steps", "origin"])
#: the march's state, in/out: the gaps h, h_prev, h_prev2 (N,) of the last three states, the
#: Prony modes q (M, N), the traction sigma (N,) of h, the tip predictor's ring past (K, N)
#: with its times and contact radii past_ta (2, K), clock (CLOCK_SIZE,) and recent (3, 3)
MarchState = namedtuple("MarchState", ["h", "h_prev", "h_prev2", "q", "sigma", "past",
                                       "past_ta", "clock", "recent"])
#: what a call writes besides the state: records (5, max_steps) the accepted steps' t, delta,
#: P, a, a_inner; starts (2, N) the predictor's two starts; h (N,) and sigma (N,) the state
#: of the step handed over (APPROACH_PASSED)
DwellOut = namedtuple("DwellOut", ["records", "starts", "h", "sigma"])


@njit(cache=True, inline='always')
def dwell_clock(t, origin):
    """The dwell's clock of the predictors at time ``t``: log(t - ``origin``), ``origin`` a
    little before the dwell's start (``sweep.engine.protocol.DWELL_LOG_SHIFT``). A contact held
    at a load or a depth creeps or relaxes as the material's compliance or modulus does, about
    as a power of the time since the hold began: smooth in its logarithm, over the dwell's
    steps that grow geometrically (DWELL_GROWTH), where a polynomial in t is not."""
    return np.log(t - origin)


@njit(cache=True, inline='always')
def predictor_steps(t, dt, dt_prev, dt_prev2, origin):
    """The three time steps the quadratic predictor (:func:`kernels.solve.predict`) takes for
    the step ``dt`` from the state at ``t`` (the last two steps ``dt_prev``, ``dt_prev2``):
    the steps themselves, or where ``origin`` lies before the oldest of the three states (a
    dwell's, :func:`dwell_clock`; nan: never), their lengths on the dwell's clock. A step
    that does not exist (0) stays 0."""
    if not origin < t - dt_prev - dt_prev2:
        return dt, dt_prev, dt_prev2
    now = dwell_clock(t, origin)
    x = dwell_clock(t + dt, origin) - now
    x_prev, x_prev2 = 0.0, 0.0
    if dt_prev > 0.0:
        before = dwell_clock(t - dt_prev, origin)
        x_prev = now - before
        if dt_prev2 > 0.0:
            x_prev2 = before - dwell_clock(t - dt_prev - dt_prev2, origin)
    return x, x_prev, x_prev2


@njit(cache=True)
def held_guess(recent, x, origin):
    """The indentation the dwell at force is expected at at time ``x``: the Lagrange
    extrapolation through the newest k records of ``recent``, k = 1 + the dwell's among the
    newest two (constant, then linear, then quadratic), in the dwell's clock
    (:func:`dwell_clock`) where ``origin`` lies before the oldest of them, else in time (the
    Python march, ``sweep.engine.protocol._held_guess``, calls this too)."""
    k = 1
    while k < 3 and recent[RECENT_DWELL, 3 - k] == 1.0:
        k += 1
    clock = np.empty(k + 1)
    logs = origin < recent[RECENT_T, 3 - k]
    for j in range(k + 1):
        t = x if j == 0 else recent[RECENT_T, 3 - j]
        clock[j] = dwell_clock(t, origin) if logs else t
    guess = 0.0
    for j in range(1, k + 1):
        weight = 1.0
        for i in range(1, k + 1):
            if i != j:
                weight *= (clock[0] - clock[i]) / (clock[j] - clock[i])
        guess += weight * recent[RECENT_DELTA, 3 - j]
    return guess


@njit(cache=True)
def dwell_steps(mesh, physics, law, control, state, out, cache, stats):
    """The dwell's time steps, as ``sweep.engine.protocol`` takes them one by one from Python
    (its ``_dwell_step``, :class:`_March`'s start, settle and accept): the same operations in
    the same order, so that the march is the same to the last bit, without Python's cost per
    step. ``mesh`` :data:`kernels.solve.MeshArrays`, ``physics`` :data:`kernels.solve.Physics`,
    ``law`` the Lennard-Jones :data:`kernels.interface.Interface`, ``control``
    :data:`DwellControl`, ``state`` :data:`MarchState` (in/out), ``out`` :data:`DwellOut`.
    Returns (outcome, records written).

    Each step dt = min(``clock[CLOCK_DT]``, end - t) is solved at the indentation held or,
    holding the load, with its indentation (:func:`newton_at_load` from :func:`held_guess`),
    from the predictor's start settled at the crack tip (:func:`_step_start`). A step whose
    solve fails or whose contact radius moves by more than ``da_max`` is halved (down to
    ``dt_min``); an accepted one is written (:func:`_accept`), and the next step grows by
    ``growth`` where the radius moved by less than ``grow_below`` ``da_max``. Ends at ``end``
    (DWELL_ENDED), after ``max_steps`` tries (DWELL_CHUNK), where the caller's fallback takes
    over (DWELL_FAILED: the held step's solve failed, or the smallest step's; the step, its
    guessed indentation and CLOCK_MADE in ``clock``, the starts in ``out``, the cache
    invalidated)."""
    N, M = state.h.size, physics.weights.size
    clock = state.clock
    e, b, H, g = np.empty(M), np.empty(M), np.empty(N), np.empty(N)
    hs, sig = np.empty(N), np.empty(N)
    n = 0
    for _ in range(control.max_steps):
        t = clock[CLOCK_T]
        if not t < control.end * (1.0 - 1e-12):
            return DWELL_ENDED, n
        dt = min(clock[CLOCK_DT], control.end - t)
        smallest = dt <= control.dt_min
        delta = (held_guess(state.recent, t + dt, control.origin) if control.hold_force
                 else clock[CLOCK_DELTA])
        clock[CLOCK_DT], clock[CLOCK_GUESS] = dt, delta
        ceff = _step_start(mesh, physics, law, control, state, out.starts, dt, delta,
                           (e, b, H, g, hs), control.origin)
        if control.hold_force:
            ok, shift = newton_at_load(hs, g, mesh, ceff, H, law, control.force, control.tols,
                                       control.max_iter, cache, stats)
            delta = delta + shift
        else:
            ok = newton(hs, g, mesh.A, ceff, H, law, control.tols[0], control.max_iter,
                        cache, stats)
        if not ok:
            cache[CACHE_STATE][STATE_VALID] = 0         # jacobian.invalidate
            if control.hold_force or smallest:
                return DWELL_FAILED, n
            clock[CLOCK_DT] = max(0.5 * dt, control.dt_min)
            continue
        a, moved = _radius_moved(mesh, law, control, clock, hs, sig)
        if moved > control.da_max and not smallest:
            clock[CLOCK_DT] = max(0.5 * dt, control.dt_min)
            continue
        _accept(mesh, law, state, out, n, e, b, hs, sig, a, dt, delta)
        n += 1
        grows = moved < control.grow_below * control.da_max
        clock[CLOCK_DT] = dt * control.growth if grows else dt
    return DWELL_CHUNK, n


@njit(cache=True, inline='always')
def _step_start(mesh, physics, law, control, state, starts, dt, delta, work, origin):
    """The step's equation (``_March._equation``; ``work`` = (e, b, H, g, hs): the Prony
    coefficients into ``e``, ``b``, the history into ``H``, the gap of the indentation
    ``delta`` into ``g``; returns C_eff) and Newton's start into ``hs`` (``_March._start``:
    the quadratic extrapolation, on the dwell's clock from ``origin`` (:func:`predictor_steps`;
    nan: in time), or the tip predictor's where made and its score says so, the two in
    ``starts``; CLOCK_MADE), settled at the last crack tip (``_March._settle``). With a
    process zone the step's law is set in ``law``: its opening rate from the last state over
    ``dt`` (``_March._equation``)."""
    e, b, H, g, hs = work
    clock, r, N = state.clock, mesh.r, hs.size
    ceff = step_coefficients(physics.weights, physics.times, dt, e, b)
    history_vector(physics.weights, e, b, state.q, state.sigma, H)
    c0 = -delta + law.h0
    for i in range(N):
        g[i] = c0 + 0.5 * r[i] ** 2
    if not np.isinf(physics.hdot_c):
        law.zone[ZONE_RATE] = 1.0 / (physics.hdot_c * dt)
        for i in range(N):
            law.h_old[i] = state.h[i]
    x, x_prev, x_prev2 = predictor_steps(clock[CLOCK_T], dt, clock[CLOCK_DT_PREV],
                                         clock[CLOCK_DT_PREV2], origin)
    predict(state.h, state.h_prev, state.h_prev2, x, x_prev, x_prev2, starts[0])
    for i in range(N):
        starts[1, i] = starts[0, i]
    made = predict_lattice(r, state.h, state.past, state.past_ta, int(clock[CLOCK_RING]), dt,
                           starts[1])
    clock[CLOCK_MADE] = 1.0 if made else 0.0
    use = 0 if not made else int(clock[CLOCK_TIP_SCORE] < LATTICE_SCORE_USE)
    for i in range(N):
        hs[i] = starts[use, i]
    tip = np.searchsorted(r, clock[CLOCK_A])
    settle_tip(hs, g, mesh.A, ceff, H, law, max(tip - control.tip_nodes, 0),
               min(tip + control.tip_nodes, N), control.tip_iter, SETTLE_WALL_POWER)
    return ceff


@njit(cache=True, inline='always')
def _radius_moved(mesh, law, control, clock, hs, sig):
    """The traction of the step's state ``hs`` into ``sig``; its contact radius and how far
    that moved from the last state's."""
    traction(hs, law.h_old, law.zone, law.h0, law.c, sig)
    a = crossing_radius(hs, mesh.r, control.hm)
    return a, abs(a - clock[CLOCK_A])


@njit(cache=True, inline='always')
def _accept(mesh, law, state, out, n, e, b, hs, sig, a, dt, delta):
    """The step to the state ``hs`` (traction ``sig``, contact radius ``a``) accepted
    (``_March.accept`` and ``_record``): the Prony modes updated, the tip predictor's score,
    the states moved along, the clock, record ``n`` of ``out.records``, the tip predictor's
    ring and ``recent``."""
    clock, h, N = state.clock, state.h, hs.size
    update_modes(e, b, state.q, sig, state.sigma)
    if clock[CLOCK_MADE] == 1.0:
        clock[CLOCK_TIP_SCORE] += LATTICE_SCORE_WEIGHT * (
            score_starts(mesh.r, out.starts, hs, a) - clock[CLOCK_TIP_SCORE])
    for i in range(N):
        state.h_prev2[i], state.h_prev[i] = state.h_prev[i], h[i]
        h[i], state.sigma[i] = hs[i], sig[i]
    clock[CLOCK_DT_PREV2], clock[CLOCK_DT_PREV] = clock[CLOCK_DT_PREV], dt
    clock[CLOCK_DELTA], clock[CLOCK_T] = delta, clock[CLOCK_T] + dt
    rec = out.records
    clock[CLOCK_P] = load(state.sigma, mesh.wP, h, mesh.tail, law.h0, law.c)
    rec[0, n], rec[1, n], rec[2, n] = clock[CLOCK_T], delta, clock[CLOCK_P]
    rec[3, n], rec[4, n] = a, crossing_radius(h, mesh.r, law.h0)
    ring = int(clock[CLOCK_RING])
    k = ring % state.past.shape[0]
    for i in range(N):
        state.past[k, i] = h[i]
    state.past_ta[0, k], state.past_ta[1, k] = clock[CLOCK_T], a
    clock[CLOCK_RING], clock[CLOCK_A] = ring + 1, a
    recent = state.recent
    for row in range(3):
        recent[row, 0], recent[row, 1] = recent[row, 1], recent[row, 2]
    recent[RECENT_T, 2], recent[RECENT_DELTA, 2], recent[RECENT_DWELL, 2] = (
        clock[CLOCK_T], delta, clock[CLOCK_PHASE])


#: :func:`approach_steps`' outcomes beyond DWELL_ENDED (the load reached the preload),
#: DWELL_CHUNK, DWELL_FAILED (the smallest step's solve failed: the caller relaxes the fold)
#: and: the step's load passed the preload (the caller cuts it to end there)
APPROACH_PASSED = 4

#: the approach's settings: hm the gap at which the contact radius is read; preload (pi dg R)
#: and preload_rtol the load it ends at; speed d delta/dt (d_ref / tau0); dd_max, dd_min the
#: largest and smallest indentation steps; da_max the most a step but the smallest may move
#: the contact radius; tol Newton's (h0 units times h0), trial_iter its iterations on a step
#: that may still be halved, max_iter on the smallest; tip_nodes, tip_iter the settle at the
#: crack tip; ahead_nodes, ahead_least the factorization's zone ahead of the advancing tip
#: (:func:`factorize_ahead`); max_steps the tries of one call
ApproachControl = namedtuple("ApproachControl", [
    "hm", "preload", "preload_rtol", "speed", "dd_max", "dd_min", "da_max", "tol",
    "trial_iter", "max_iter", "tip_nodes", "tip_iter", "ahead_nodes", "ahead_least",
    "max_steps"])


@njit(cache=True)
def approach_steps(mesh, physics, law, control, state, out, cache, stats):
    """The approach's indentation steps after its first, as ``sweep.engine.protocol`` takes
    them one by one from Python (``_approach``, ``_trial``, :class:`_March`'s solve and
    accept): the same operations in the same order. Arguments as :func:`dwell_steps`'s,
    ``control`` an :data:`ApproachControl`; returns (outcome, records written).

    Each step dd = ``clock[CLOCK_DT]`` to the indentation delta + dd over dd / speed is solved
    from the predictor's start settled at the crack tip, the factorization's zone kept ahead
    of the tip, by at most ``trial_iter`` Newton iterations (``max_iter`` on the smallest
    step, dd <= ``dd_min``). A step whose solve fails or whose contact radius moves by more
    than ``da_max`` is halved (down to ``dd_min``); an accepted one is written and the next
    step doubles (up to ``dd_max``) where the radius moved by less than half ``da_max``. Ends
    where the load reaches the preload (DWELL_ENDED), after ``max_steps`` tries
    (DWELL_CHUNK), or hands the step over: its load passed the preload (APPROACH_PASSED:
    its state in ``out``), the smallest step's solve failed (DWELL_FAILED)."""
    N, M = state.h.size, physics.weights.size
    clock = state.clock
    e, b, H, g = np.empty(M), np.empty(M), np.empty(N), np.empty(N)
    hs, sig = np.empty(N), np.empty(N)
    n = 0
    for _ in range(control.max_steps):
        if not clock[CLOCK_P] < control.preload * (1.0 - control.preload_rtol):
            return DWELL_ENDED, n
        dd = clock[CLOCK_DT]
        smallest = dd <= control.dd_min
        delta, dt = clock[CLOCK_DELTA] + dd, dd / control.speed
        clock[CLOCK_GUESS] = delta
        ceff = _step_start(mesh, physics, law, control, state, out.starts, dt, delta,
                           (e, b, H, g, hs), np.nan)
        factorize_ahead(hs, mesh.A, ceff, law, control.ahead_nodes, control.ahead_least,
                        cache, stats)
        ok = newton(hs, g, mesh.A, ceff, H, law, control.tol,
                    control.max_iter if smallest else control.trial_iter, cache, stats)
        if not ok:
            cache[CACHE_STATE][STATE_VALID] = 0         # jacobian.invalidate
            if smallest:
                return DWELL_FAILED, n
            clock[CLOCK_DT] = max(0.5 * dd, control.dd_min)
            continue
        a, moved = _radius_moved(mesh, law, control, clock, hs, sig)
        if moved > control.da_max and not smallest:
            clock[CLOCK_DT] = max(0.5 * dd, control.dd_min)
            continue
        if load(sig, mesh.wP, hs, mesh.tail, law.h0, law.c) > control.preload:
            for i in range(N):
                out.h[i], out.sigma[i] = hs[i], sig[i]
            return APPROACH_PASSED, n
        _accept(mesh, law, state, out, n, e, b, hs, sig, a, dt, delta)
        n += 1
        clock[CLOCK_DT] = min(2.0 * dd, control.dd_max) if moved < 0.5 * control.da_max else dd
    return DWELL_CHUNK, n
