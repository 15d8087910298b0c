"""The protocol march's own solves (:mod:`sweep.engine.protocol`; Numba kernels): a time step
held at a load, Newton on the gap and the indentation together (:func:`newton_at_load`),
Newton's start settled at the crack tip (:func:`kernels.solve.settle_tip`), and the
approach's kept factorization, its crack-tip zone ahead of an advancing tip
(:func:`factorize_ahead`).

A dwell at force (:mod:`sweep.engine.protocol`) asks, at each time step, for the indentation
delta at which the equilibrium of the step carries the preload. Solved as one system, for the
nodal gaps h and the indentation change s from a guess delta (docs/design.md section 4):

    F(h, s) = h - g + s - A [ C_eff sigma(h) - H ] = 0,     g = -delta + h0 + r^2/2,
    G(h)    = 2 pi wP . sigma(h) - P* = 0,

(dF/ds = 1 at every node). With J the Jacobian of F in h (:mod:`kernels.jacobian`, its kept
factorization), x = -J^-1 F and y = J^-1 1, the Newton update is dh = x - y ds with

    ds = (2 pi wP . (sigma' x) + P - P*) / (2 pi wP . (sigma' y))

(the bordered system eliminated: two solves with one factorization). One solve of the step
instead of a secant of two or three solves on delta.

The march's starts (an extrapolation of the last states) are furthest off at the crack tip,
where the gap equation is most nonlinear: the node behind an advancing tip lands on the
repulsive wall, and even exact Newton from there took three iterations.
:func:`kernels.solve.settle_tip` runs Newton on the few nodes around the tip alone, the
others held, at the cost of those rows of A, before the solve of the whole.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .jacobian import (CACHE_STATE, STATE_SCALED, STATE_SUBSET, STATE_VALID, STATE_ZONE_HI,
                       apply_inverse, crack_tip_index, factorize, newton_direction)
from .interface import TIP_GAP, traction_and_stiffness
from .solve import (STAT_FACTOR, STAT_ITER, STAT_REFACTOR_SLOW, STAT_REFACTOR_ZONE,
                    STAT_RESIDUALS, STAT_SUBSET, STAT_ZONE, positive_step, residual)

#: an iteration whose residual ``max |F|`` falls by less than this factor refactorizes before
#: the next (the unloading Newton's SLOW_CONTRACTION, :mod:`kernels.solve`)
HELD_SLOW_CONTRACTION = 0.1
#: :func:`factorize_ahead` closes the nodes ahead of the crack tip to this fraction below
#: the tip gap
CLOSED_BELOW = 1e-3
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
    the indentation's update, which the next iterations correct."""
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
def newton_at_load(h, g, A, wP, ceff, H, law, force, tols, max_iter, cache, stats):
    """Solve F(h, s) = 0 and G(h) = 0 (module docstring) in place of ``h`` from ``h`` and
    s = 0, the gap g of the guessed indentation; ``tols`` = (``max |F|`` in units of d_ref,
    ``|G|`` in units of pi dg R). Returns (converged, s): the step's indentation is the
    guess plus s. The cache's factorization is kept and made again where its iteration
    contracts the residual by less than HELD_SLOW_CONTRACTION (not with the drift-scaled chord,
    ``state[STATE_SCALED]``: :func:`kernels.solve.newton`); a residual growing by
    HELD_DIVERGENCE ends the solve unconverged."""
    N = h.size
    sig, w, F, dh, y = np.empty(N), np.empty(N), np.empty(N), np.empty(N), np.full(N, np.nan)
    gs = g.copy()
    s = 0.0
    if cache[CACHE_STATE][STATE_VALID] == 0:
        _factorize_counted(h, A, ceff, law, cache, stats)
    norm = residual(h, gs, A, ceff, H, law, sig, w, F)
    stats[STAT_RESIDUALS] += 1
    for _ in range(max_iter):
        P = 2.0 * np.pi * np.dot(wP, sig)
        if norm <= tols[0] and abs(P - force) <= tols[1]:
            return True, s
        stats[STAT_ITER] += 1
        ds, ok = _bordered_update(h, F, A, ceff, law, P, force, wP, cache, stats, y, dh)
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
