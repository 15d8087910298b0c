"""Per-step Newton solve on the gap and the Prony unloading loop (Numba kernels).

Each time step solves, for the nodal gaps h (docs/design.md sections 2 and 4),

    F(h) = h - g - A [ C_eff sigma(h) - H ] = 0,     g = -delta + h0 + r^2/2,

where A is the influence matrix (already scaled by the node spacing), sigma the
Lennard-Jones law and (C_eff, H) the hereditary-integral coefficients of the step.

Newton's Jacobian J = I - C_eff A diag(sigma'(h)) is factorized on the interacting nodes
and kept from step to step, exact in the crack-tip zone (its Schur complement refreshed as
the stiffness there moves) and as factorized in the contact interior (:mod:`kernels.jacobian`);
it is refactorized when the crack tip leaves the zone, when an iteration contracts the
residual by less than SLOW_CONTRACTION, when a line search fails with a stale factorization,
and at every iteration of the retries of a step whose solve failed. The line search (on
|F|_2) keeps every gap positive. A solve whose first update is predicted, from the
contraction measured before, to leave a residual below a tenth of the tolerance ends
without evaluating it (PREDICTED_RESIDUAL).

On a coarse mesh the discrete equilibrium path can fold (the crack tip snaps from node to
node); the loop then looks for the snapped state (:func:`snap`, :func:`relax`).

Status codes returned by :func:`unload`:
0 finished (stop criterion met), 1 no equilibrium at the minimum step, 2 step limit,
3 contact reached the mesh edge (domain too small), 4 the crack tip left the fine band of a
graded mesh (the driver widens it and starts again).
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .history import history_vector, step_coefficients, update_modes
from .interface import crossing_radius, lj_traction, lj_traction_and_stiffness
# invalidate and new_jacobian_cache are re-exported: the callers of newton/unload make the cache
from .jacobian import (CACHE_CONTRACTION, CACHE_STATE, STATE_EXACT,  # noqa: F401
                       STATE_VALID, factorize, invalidate, new_jacobian_cache,
                       newton_direction)

STATUS_DONE = 0
STATUS_NEWTON_FAILED = 1
STATUS_STEP_LIMIT = 2
STATUS_DOMAIN = 3
STATUS_LEFT_BAND = 4

# stats vector layout (counters, incremented)
STAT_ITER = 0                 # Newton iterations
STAT_FACTOR = 1               # factorizations (restricted base or dense fallback)
STAT_REJECTED = 2             # steps rejected by the step control
STAT_FAILED_SOLVES = 3        # Newton solves that did not converge
STAT_ZONE = 4                 # refactorizations of the crack-tip zone's Schur complement
STAT_REFACTOR_ZONE = 5        # refactorizations: the crack tip left the zone
STAT_REFACTOR_LINESEARCH = 6  # refactorizations: a line search failed with a stale base
STAT_JUMPS = 7                # folds of the discrete path (snap / relax)
STAT_SUBSET = 8               # sum of |S| (factorized nodes) over the factorizations
STAT_RESIDUALS = 9            # residual evaluations (one N x N mat-vec each)
STAT_REFACTOR_SLOW = 10       # refactorizations: an iteration contracted poorly
STAT_REFACTOR_RETRY = 11      # refactorizations: exact Newton on the retry of a failed step
STAT_PREDICTED = 12           # solves ended on the predicted residual (no residual after)
N_STATS = 13

#: an iteration with a stale factorization that reduces |F|_2 by less than this factor
#: refactorizes before the next one (fresh, the chord iteration contracts by 1e-4 to 1e-3 on
#: the reference scenes; 0.5 let it crawl at 0.46 for ten iterations; 0.1 and 0.03 cost
#: the same on the vs-numpy scenes, 0.03 refactorizes 5x more on the fast n = 0.4 one)
SLOW_CONTRACTION = 0.1

#: a solve ends after its first update without the residual at the new point when the
#: residual predicted there, |F|_max times the contraction last measured, is at most this
#: fraction of the tolerance (the simplified-Newton stopping rule of Hairer and Wanner,
#: Solving ODEs II, section IV.8) ...
PREDICTED_RESIDUAL = 0.1
#: ... and each such solve multiplies the contraction estimate by this factor, so that
#: within a few steps a residual is computed again and the contraction measured anew
CONTRACTION_GROWTH = 2.0

#: the pull-off is past once the load has recovered by this fraction of |P_min| ...
RECOVERY = 0.05
#: ... and by at least this much (units of pi dg R; the elastic pull-off is about 1.5),
RECOVERY_FLOOR = 0.05
#: ... at least this many steps after the minimum ...
RECOVERY_STEPS = 5
#: ... and the crack tip has receded from its radius at the minimum by at least
#: ``min_travel`` (the caller gives a few node spacings: a lattice dip of the load, the
#: tip snapping by one node, cannot end the run)
#: following to separation ends when the contact is lost and |P| < this fraction of |P_min|
SEPARATION_LOAD = 1e-3


@njit(cache=True)
def stop_reached(P, a, n, i_min, stop_mode, min_travel):
    """The one stop rule, on the records P[:n], a[:n] with the load minimum at ``i_min``.

    stop_mode 0 (pull-off): past a tensile minimum by RECOVERY_STEPS steps, the load
    recovered by max(RECOVERY |P_min|, RECOVERY_FLOOR) and the tip receded by
    ``min_travel`` (a_ref); or the contact is lost after the minimum.
    stop_mode 1 (separation): contact lost and the load back to SEPARATION_LOAD |P_min|.
    """
    P_min = P[i_min]
    P_now = P[n - 1]
    a_now = a[n - 1]
    if stop_mode == 0:
        if (P_min < 0.0 and n - 1 - i_min >= RECOVERY_STEPS
                and P_now - P_min > max(RECOVERY * abs(P_min), RECOVERY_FLOOR)
                and a[i_min] - a_now >= min_travel):
            return True
        return a_now == 0.0 and n - 1 - i_min >= 1
    return a_now == 0.0 and P_now > P_min and abs(P_now) < SEPARATION_LOAD * abs(P_min)

#: a failed step is halved down to this fraction of the largest step before it is taken
#: for a fold of the discrete path (and the snapped state is looked for)
SNAP_STEP_FRACTION = 1.0 / 8.0

#: pseudo-time iterations allowed for one snap of the crack tip at a fold
RELAX_MAX_ITER = 300

@njit(cache=True)
def residual(h, g, A, ceff, H, h0, c, sig, w, F):
    """F = h - g - A (ceff sigma(h) - H); returns max |F|. sig, w are work arrays."""
    lj_traction(h, h0, c, sig)
    for j in range(h.size):
        w[j] = ceff * sig[j] - H[j]
    u = A @ w
    norm = 0.0
    for i in range(h.size):
        F[i] = h[i] - g[i] - u[i]
        if abs(F[i]) > norm:
            norm = abs(F[i])
    return norm


@njit(cache=True)
def positive_step(h, dh):
    """Largest step length <= 1 along ``dh`` that keeps every gap above 30 % of its value."""
    lam = 1.0
    for i in range(h.size):
        if dh[i] < 0.0:
            lim = -0.7 * h[i] / dh[i]
            if lim < lam:
                lam = lim
    return lam


@njit(cache=True)
def _norm2(F):
    s = 0.0
    for i in range(F.size):
        s += F[i] * F[i]
    return np.sqrt(s)


@njit(cache=True)
def _refactorize(h, A, ceff, h0, c, cache, stats, reason):
    m = factorize(h, A, ceff, h0, c, cache)
    stats[STAT_FACTOR] += 1
    stats[STAT_SUBSET] += m
    if reason >= 0:
        stats[reason] += 1


@njit(cache=True)
def newton(h, g, A, ceff, H, h0, c, tol, max_iter, cache, stats):
    """Solve F(h) = 0 in place, starting from ``h``. Returns True on convergence.

    The Jacobian factorization in the cache (:func:`kernels.jacobian.new_jacobian_cache`)
    is reused, its crack-tip zone kept exact (:func:`kernels.jacobian.newton_direction`); it
    is rebuilt when the crack tip left the zone, when a stale one contracts the residual by
    less than SLOW_CONTRACTION, when a line search fails with a stale one, and at every
    iteration while ``state[STATE_EXACT]`` is set.

    Converged means max |F| <= ``tol``: computed, or, after a first full update, predicted
    below PREDICTED_RESIDUAL ``tol`` as |F| times the contraction last measured (kept in
    ``cache[CACHE_CONTRACTION]``; each solve so ended doubles it, so the residual is
    computed again within a few solves). The prediction saves the one mat-vec of a solve
    that a single chord update converges.
    """
    state = cache[CACHE_STATE]
    theta = cache[CACHE_CONTRACTION]
    N = h.size
    sig = np.empty(N)
    d = np.empty(N)
    w = np.empty(N)
    F = np.empty(N)
    Ft = np.empty(N)
    ht = np.empty(N)
    norm = residual(h, g, A, ceff, H, h0, c, sig, w, F)
    stats[STAT_RESIDUALS] += 1
    if norm <= tol:
        return True
    fresh = False
    if state[STATE_VALID] == 0:
        _refactorize(h, A, ceff, h0, c, cache, stats, -1)
        fresh = True
    for it in range(max_iter):
        stats[STAT_ITER] += 1
        if state[STATE_EXACT] == 1 and not fresh:
            _refactorize(h, A, ceff, h0, c, cache, stats, STAT_REFACTOR_RETRY)
            fresh = True
        lj_traction_and_stiffness(h, h0, c, sig, d)
        dh, ok = newton_direction(F, d, A, ceff, cache, stats, STAT_ZONE)
        if not ok:
            _refactorize(h, A, ceff, h0, c, cache, stats, STAT_REFACTOR_ZONE)
            fresh = True
            dh, ok = newton_direction(F, d, A, ceff, cache, stats, STAT_ZONE)
            if not ok:       # singular even on a fresh factorization: give up
                return False
        lam = positive_step(h, dh)
        if (it == 0 and lam == 1.0 and state[STATE_EXACT] == 0
                and theta[0] * norm <= PREDICTED_RESIDUAL * tol):
            for i in range(N):
                h[i] += dh[i]
            theta[0] = min(CONTRACTION_GROWTH * theta[0], 1.0)
            stats[STAT_PREDICTED] += 1
            return True
        # backtracking on the merit |F|_2 (Newton directions descend it); the max norm
        # decides convergence
        accepted = False
        n2 = _norm2(F)
        nt2 = n2
        for _ls in range(16):
            for i in range(N):
                ht[i] = h[i] + lam * dh[i]
            nt = residual(ht, g, A, ceff, H, h0, c, sig, w, Ft)
            stats[STAT_RESIDUALS] += 1
            nt2 = _norm2(Ft)
            if nt2 < (1.0 - 1e-4 * lam) * n2:
                accepted = True
                break
            lam *= 0.5
        if not accepted:
            if fresh:        # a line search failed on an exact Jacobian: give up
                return False
            _refactorize(h, A, ceff, h0, c, cache, stats, STAT_REFACTOR_LINESEARCH)
            fresh = True
            continue
        theta[0] = nt / norm if lam == 1.0 else 1.0
        for i in range(N):
            h[i] = ht[i]
            F[i] = Ft[i]
        norm = nt
        if norm <= tol:
            return True
        if not fresh and nt2 > SLOW_CONTRACTION * n2:
            _refactorize(h, A, ceff, h0, c, cache, stats, STAT_REFACTOR_SLOW)
            fresh = True
        else:
            fresh = False
    return False


@njit(cache=True)
def relax(h, g, A, ceff, H, h0, c, tol, max_iter, stats):
    """Pseudo-transient continuation to a *stable* equilibrium, in place; True on success.

    Integrates the relaxation dh/dtau = -F(h) with linearly implicit Euler steps,
    (I/dtau + J) dh = -F, and the switched-evolution-relaxation rule
    dtau <- dtau |F_old| / |F_new|: small dtau follows the flow, large dtau is Newton.
    J = A K (compliance times the energy Hessian), so the flow is attracted to stable
    equilibria. Used where the discrete equilibrium path folds (the crack tip snapping
    from one node to the next), as the physical system would. One dense factorization per
    iteration: a fallback, not the main path.
    """
    N = h.size
    sig = np.empty(N)
    d = np.empty(N)
    w = np.empty(N)
    F = np.empty(N)
    Ft = np.empty(N)
    ht = np.empty(N)
    norm = residual(h, g, A, ceff, H, h0, c, sig, w, F)
    n2 = _norm2(F)
    dtau = 0.1
    J = np.empty((N, N))
    for it in range(max_iter):
        if norm <= tol:
            return True
        stats[STAT_ITER] += 1
        stats[STAT_FACTOR] += 1
        lj_traction_and_stiffness(h, h0, c, sig, d)
        for i in range(N):
            for j in range(N):
                J[i, j] = -ceff * A[i, j] * d[j]
            J[i, i] += 1.0 + 1.0 / dtau
        dh = -np.linalg.solve(J, F)
        lam = positive_step(h, dh)
        for i in range(N):
            ht[i] = h[i] + lam * dh[i]
        nt = residual(ht, g, A, ceff, H, h0, c, sig, w, Ft)
        nt2 = _norm2(Ft)
        if not np.isfinite(nt2) or nt2 > 1e3 * n2:
            dtau *= 0.1
            if dtau < 1e-10:
                return False
            continue
        for i in range(N):
            h[i] = ht[i]
            F[i] = Ft[i]
        dtau = min(dtau * min(n2 / nt2, 10.0), 1e12)
        norm, n2 = nt, nt2
    return norm <= tol


@njit(cache=True)
def snap(h, hp, g, A, ceff, H, h0, c, tol, max_iter, r, hm, cache, stats):
    """Newton from the gap profile outside the crack tip shifted inward by 1 to 6 nodes.

    Near a fold of the discrete path the stable state the tip snaps to is, locally, the
    same profile one node further in; starting Newton there finds it in a few iterations.
    Accepts only a solution whose contact radius moved inward. Solution in ``hp``.
    """
    N = h.size
    a_old = crossing_radius(h, r, hm)
    i_tip = max(int(np.searchsorted(r, a_old)) - 1, 0)
    for shift in range(1, 7):
        i0 = max(i_tip - 20, 1)
        for i in range(N):
            if i < i0:
                hp[i] = h[i]
            elif i + shift < N:
                hp[i] = h[i + shift]
            else:
                hp[i] = h[N - 1] + (h[N - 1] - h[N - 2]) * (i + shift - N + 1)
        if newton(hp, g, A, ceff, H, h0, c, tol, max_iter, cache, stats):
            if crossing_radius(hp, r, hm) < a_old:
                return True
    return False


@njit(cache=True)
def load(sigma, wP):
    """P = 2 pi sum_j w_j sigma_j (positive = compressive)."""
    return 2.0 * np.pi * np.dot(wP, sigma)


#: steps in a row whose contact-radius change is below EASY_DA_FRACTION * da_max before
#: the step doubles (steps change by factors of 2 only)
EASY_STEPS = 8
EASY_DA_FRACTION = 0.3
#: a step rejected for its radius change is halved until the change, assumed proportional
#: to the step, is below this fraction of da_max
REJECT_TARGET = 0.8
#: where the load evolves smoothly the step grows beyond step_max, up to this factor, while
#: the predictor's load error stays below step_tol and the crack tip moves by less than
#: SMOOTH_DA_FRACTION da_max per step
SMOOTH_STEP_FACTOR = 8.0
SMOOTH_DA_FRACTION = 0.6
#: the predictor never puts a gap below this fraction of the last accepted one
PREDICT_FLOOR = 0.5


@njit(cache=True)
def predict_cubic(h, h_prev, h_prev2, h_prev3, dt, dt_prev, dt_prev2, dt_prev3, hp):
    """Starting gap of Newton: cubic (Lagrange) extrapolation through the last four
    accepted states, floored at PREDICT_FLOOR of the last gap; False (nothing written)
    before four states exist."""
    if not dt_prev3 > 0.0:
        return False
    t1 = -dt_prev
    t2 = t1 - dt_prev2
    t3 = t2 - dt_prev3
    l0 = (dt - t1) * (dt - t2) * (dt - t3) / ((-t1) * (-t2) * (-t3))
    l1 = dt * (dt - t2) * (dt - t3) / (t1 * (t1 - t2) * (t1 - t3))
    l2 = dt * (dt - t1) * (dt - t3) / (t2 * (t2 - t1) * (t2 - t3))
    l3 = dt * (dt - t1) * (dt - t2) / (t3 * (t3 - t1) * (t3 - t2))
    for i in range(h.size):
        hp[i] = max(l0 * h[i] + l1 * h_prev[i] + l2 * h_prev2[i] + l3 * h_prev3[i],
                    PREDICT_FLOOR * h[i])
    return True


@njit(cache=True)
def predict(h, h_prev, h_prev2, dt, dt_prev, dt_prev2, hp):
    """Starting gap of the next solve: quadratic (Lagrange) extrapolation through the last
    three accepted states (linear after one, constant at the start), floored at
    PREDICT_FLOOR of the last gap. Returns True when the extrapolation was quadratic (its
    distance to the solution is then the step-error estimate)."""
    N = h.size
    if dt_prev2 > 0.0:
        t1 = -dt_prev
        t2 = -dt_prev - dt_prev2
        l0 = (dt - t1) * (dt - t2) / (t1 * t2)
        l1 = dt * (dt - t2) / (t1 * (t1 - t2))
        l2 = dt * (dt - t1) / (t2 * (t2 - t1))
        for i in range(N):
            hp[i] = max(l0 * h[i] + l1 * h_prev[i] + l2 * h_prev2[i], PREDICT_FLOOR * h[i])
        return True
    if dt_prev > 0.0:
        s = dt / dt_prev
        for i in range(N):
            hp[i] = max(h[i] + s * (h[i] - h_prev[i]), PREDICT_FLOOR * h[i])
        return False
    hp[:] = h
    return False


@njit(cache=True)
def next_step(dd, easy, da, da_max, err, dd_max, step_tol):
    """Step control after an accepted step: (next indentation step, easy-step count).

    Up to ``dd_max`` the step doubles after EASY_STEPS steps in a row that moved the crack
    tip by less than EASY_DA_FRACTION da_max. Beyond it (up to SMOOTH_STEP_FACTOR dd_max)
    it doubles after EASY_STEPS steps in a row while a doubled step would keep the tip
    motion below SMOOTH_DA_FRACTION da_max and the predictor's load error ``err``, 8 err
    for a doubled step (third order), below ``step_tol``; it is halved back as soon as
    either bound is exceeded.
    """
    if dd > dd_max * 1.0001:
        if da > SMOOTH_DA_FRACTION * da_max or err > step_tol:
            return max(0.5 * dd, dd_max), 0
        easy += 1
    elif da < EASY_DA_FRACTION * da_max:
        easy += 1
    else:
        easy = 0
    if easy >= EASY_STEPS:
        if dd < dd_max * 0.9999:
            return min(2.0 * dd, dd_max), 0
        if (2.0 * da < SMOOTH_DA_FRACTION * da_max and 8.0 * err < step_tol
                and dd < SMOOTH_STEP_FACTOR * dd_max * 0.9999):
            return min(2.0 * dd, SMOOTH_STEP_FACTOR * dd_max), 0
    return dd, easy


@njit(cache=True)
def unload(A, r, wP, h_init, delta0, rate, h0, c, weights, times, q, n0, step_io,
           step_max, step_min, da_max, step_tol, tol, max_iter, max_steps, stop_mode, min_travel,
           tip_lo, tip_hi, cache, t_out, d_out, P_out, a_out, ai_out, h_out, stats):
    """Unload at constant rate from the state ``h_init`` with the Prony recursion.

    Resumable: a run may be continued (in chunks of ``max_steps``, or on another mesh after
    the state arrays were carried over) by passing back its gap, modal state ``q``, step
    ``step_io`` and records.

    Parameters (dimensionless, docs/design.md section 2)
    ----------
    A : (N, N) influence matrix of the mesh.
    r : (N,) node positions (a_ref units), r[0] = 0.
    wP : (N,) load weights, P = 2 pi wP . sigma.
    h_init : (N,) gap at indentation ``delta0``: the relaxed elastic LJ solution at the
        start, the last accepted state when resuming.
    delta0 : indentation of ``h_init`` (d_ref units). Used only when ``n0 == 0``; a resumed
        run takes the time and indentation of its last record.
    rate : r-hat; d delta/dt = -rate h0.
    weights, times : Prony modes of Chat (times may be inf: lumped glassy constant).
    q : (M, N) modal history state of the hereditary integral, in/out: zeros for the
        relaxed start; on return the modes of the last accepted step.
    n0 : records already in the output arrays. 0: a new run, record 0 is the initial
        state; n0 >= 1: continue after record n0 - 1 (the stop rule sees all records).
    step_io : (1,) indentation step (units of h0), in/out: <= 0 starts at ``step_max``;
        on return the step the run would take next.
    step_max, step_min : indentation steps in units of h0.
    da_max : largest contact-radius change per step (a_ref units).
    step_tol : relative load error of the step predictor, |P(predicted) - P| / max(|P|, 1),
        below which the step may grow beyond ``step_max`` (up to SMOOTH_STEP_FACTOR
        times) where the load evolves smoothly; 0 keeps every step <= step_max.
    stop_mode : 0 stop after pull-off and load recovery, 1 follow to separation.
    min_travel : crack-tip recession after the minimum required to stop (a_ref), see
        :func:`stop_reached`.
    tip_lo, tip_hi : radii the crack tip must stay within (the well-resolved band of a
        graded mesh); leaving them ends the run with STATUS_LEFT_BAND.
    cache : tuple
        The Jacobian cache (:func:`new_jacobian_cache`); may carry the factorization of
        the initial solve.
    t_out, d_out, P_out, a_out, ai_out : output arrays (length >= max_steps + 1).
    h_out : (N,) receives the gap of the last accepted step.
    stats : int64 array of length N_STATS (incremented).

    Returns
    -------
    (status, n_records)
    """
    state = cache[CACHE_STATE]
    N = h_init.size
    M = weights.size
    hm = 3.0 ** (1.0 / 6.0) * h0
    r2half = np.empty(N)
    for i in range(N):
        r2half[i] = 0.5 * r[i] ** 2
    e = np.empty(M)
    b = np.empty(M)
    H = np.empty(N)
    g = np.empty(N)
    h = h_init.copy()
    h_prev = h_init.copy()
    h_prev2 = h_init.copy()
    h_prev3 = h_init.copy()
    hp = np.empty(N)
    h_pred = np.empty(N)
    sigma_pred = np.empty(N)
    sigma = np.empty(N)
    sig_new = np.empty(N)
    lj_traction(h, h0, c, sigma)

    a_cur = crossing_radius(h, r, hm)
    if n0 == 0:
        t_out[0] = 0.0
        d_out[0] = delta0
        P_out[0] = load(sigma, wP)
        a_out[0] = a_cur
        ai_out[0] = crossing_radius(h, r, h0)
        n = 1
    else:
        n = n0
    t = t_out[n - 1]
    delta = d_out[n - 1]
    i_min = 0
    for i in range(1, n):
        if P_out[i] < P_out[i_min]:
            i_min = i
    # units converted once: steps and tolerances in d_ref from here on
    dd_max = step_max * h0
    dd_min = step_min * h0
    tol_gap = tol * h0
    tol_step = step_tol * h0
    dd = step_io[0] * h0 if step_io[0] > 0.0 else dd_max
    dt_prev = 0.0
    dt_prev2 = 0.0
    dt_prev3 = 0.0
    easy = 0
    status = STATUS_STEP_LIMIT
    while n <= max_steps:
        # -- predict
        dt = dd / (rate * h0)
        ceff = step_coefficients(weights, times, dt, e, b)
        history_vector(weights, e, b, q, sigma, H)
        for i in range(N):
            g[i] = -(delta - dd) + h0 + r2half[i]
        quadratic = predict(h, h_prev, h_prev2, dt, dt_prev, dt_prev2, hp)
        h_pred[:] = hp
        # Newton starts from the cubic extrapolation (where four states exist): on the
        # vs-numpy scenes its residual is several times smaller, and 1.2-1.8 Newton
        # iterations per step remain instead of 1.7-2.4; the quadratic one (h_pred) stays
        # the step-error estimate
        cubic = predict_cubic(h, h_prev, h_prev2, h_prev3, dt, dt_prev, dt_prev2, dt_prev3, hp)
        # -- solve
        ok = newton(hp, g, A, ceff, H, h0, c, tol_gap, max_iter, cache, stats)
        if not ok and cubic:
            # where the path is not smooth (the tip jumping nodes on a coarse mesh) the
            # cubic start can overshoot: again from the quadratic one before the step halves
            stats[STAT_FAILED_SOLVES] += 1
            hp[:] = h_pred
            ok = newton(hp, g, A, ceff, H, h0, c, tol_gap, max_iter, cache, stats)
        if not ok:
            stats[STAT_FAILED_SOLVES] += 1
            state[STATE_VALID] = 0
            state[STATE_EXACT] = 1
            easy = 0
            if dd > max(dd_min, SNAP_STEP_FRACTION * dd_max) * 1.0001:
                dd = max(0.5 * dd, dd_min)
                continue
            # the equilibrium path folds here (the crack tip snaps to the next node): look
            # for the snapped state by Newton from the profile shifted inward by 1..6 nodes,
            # else by pseudo-transient relaxation from the last state
            stats[STAT_JUMPS] += 1
            ok = snap(h, hp, g, A, ceff, H, h0, c, tol_gap, max_iter, r, hm, cache, stats)
            if not ok:
                hp[:] = h
                ok = relax(hp, g, A, ceff, H, h0, c, tol_gap, RELAX_MAX_ITER, stats)
            if not ok:
                status = STATUS_NEWTON_FAILED
                break
            quadratic = False
        # -- control the step: the crack tip may move by da_max at most
        a_new = crossing_radius(hp, r, hm)
        da = abs(a_new - a_cur)
        if da > da_max and dd > dd_min * 1.0001:
            stats[STAT_REJECTED] += 1
            easy = 0
            da_est = da
            while da_est > REJECT_TARGET * da_max and dd > dd_min:
                dd = max(0.5 * dd, dd_min)
                da_est *= 0.5
            continue
        lj_traction(hp, h0, c, sig_new)
        P = load(sig_new, wP)
        if quadratic:
            lj_traction(h_pred, h0, c, sigma_pred)
            err = abs(load(sigma_pred, wP) - P) / max(abs(P), 1.0)
        else:
            err = np.inf
        # -- accept
        state[STATE_EXACT] = 0
        update_modes(e, b, q, sig_new, sigma)
        h_prev3[:] = h_prev2
        h_prev2[:] = h_prev
        h_prev[:] = h
        h[:] = hp
        sigma[:] = sig_new
        dt_prev3 = dt_prev2
        dt_prev2 = dt_prev
        dt_prev = dt
        t += dt
        delta -= dd
        t_out[n] = t
        d_out[n] = delta
        P_out[n] = P
        a_out[n] = a_new
        ai_out[n] = crossing_radius(h, r, h0)
        if P < P_out[i_min]:
            i_min = n
        n += 1
        a_cur = a_new
        # -- stop
        if a_new >= r[N - 1]:
            status = STATUS_DOMAIN
            break
        if a_new > tip_hi or a_new < tip_lo:
            status = STATUS_LEFT_BAND
            break
        if stop_reached(P_out, a_out, n, i_min, stop_mode, min_travel):
            status = STATUS_DONE
            break
        dd, easy = next_step(dd, easy, da, da_max, err, dd_max, tol_step)
    h_out[:] = h
    step_io[0] = dd / h0
    return status, n
