"""The relaxed initial state: the elastic (Chat = 1) Lennard-Jones solution at delta0, or at
the indentation whose max-tension contact radius is a0.

Units of docs/design.md section 2 (radii a_ref, gaps and indentations d_ref). A secant root find
on delta, each solve warm-started from the previous one, the first from the JKR solution;
elastic continuation where a direct solve does not converge (a coarse mesh can trap Newton
in a non-solution minimum of |F| where the contact edge sits between nodes).
"""
from __future__ import annotations

import math
from collections import OrderedDict
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..kernels.interface import TIP_GAP, crossing_radius, lennard_jones
from ..kernels.solve import N_STATS, invalidate, new_jacobian_cache, newton

from . import budget, diskcache
from .problem import jkr_radius

#: Newton iterations of the elastic solves of the initial state (poorer starting guesses)
MAX_NEWTON_ITER_INITIAL = 40
#: the elastic continuation (:func:`_walk`): the step's growth after a success and the most
#: solves of one relaxed start's walks (the longest successful one measured: 124 solves, on a
#: coarse graded mesh at mu 5; a relaxed start that cannot converge walked until its time
#: budget: 3527 solves in 630 s on a 1000-node mesh at mu 10)
WALK_GROWTH = 1.5
WALK_MAX_SOLVES = 1000
#: relaxed states kept per process: the initial state depends on the mesh, mu and a0 (or
#: delta0) only, so a sweep over materials and rates solves each one once per worker
RELAXED_CACHE_SIZE = 64
_RELAXED: OrderedDict = OrderedDict()


def jkr_gap_guess(r: np.ndarray, delta: float, h0: float) -> np.ndarray:
    """JKR gap (Hertz + flat-punch deflection) at indentation ``delta``, floored at h0."""
    a = jkr_radius(delta)
    rigid = -delta + h0 + 0.5 * r**2
    if a <= 0.0:
        return np.maximum(rigid, h0)
    inside = r <= a
    ro = np.where(inside, a, r)
    asin = np.arcsin(np.clip(a / ro, -1.0, 1.0))
    u_hertz = np.where(inside, 0.5 * (2 * a * a - r**2),
                       ((2 * a * a - r**2) * asin + a * np.sqrt(np.maximum(r**2 - a * a, 0.0))) / np.pi)
    u_punch = np.where(inside, 1.0, 2.0 / np.pi * asin)
    gap = rigid + u_hertz - math.sqrt(2.0 * a) * u_punch
    return np.maximum(gap, h0)


def set_relaxed_cache_size(size: int) -> int:
    """Keep up to ``size`` relaxed states in this process (RELAXED_CACHE_SIZE by default;
    the least recently used is dropped first); returns the previous size."""
    global RELAXED_CACHE_SIZE
    previous, RELAXED_CACHE_SIZE = RELAXED_CACHE_SIZE, int(size)
    return previous


def clear_relaxed_cache() -> None:
    """Forget this process's relaxed initial states (as a new worker starts; the states on
    disk stay, :func:`cached_state`)."""
    _RELAXED.clear()


@lru_cache(maxsize=None)
def _code_tag() -> str:
    """Hash of the code a relaxed state is solved with (the kernels and sweep/engine): a
    state on disk is used only with the code that solved it."""
    from .. import kernels

    files = [*Path(kernels.__file__).parent.glob("*.py"), *Path(__file__).parent.glob("*.py")]
    return diskcache.source_tag(*sorted(str(f) for f in files))


def _from_disk(key):
    """(h, delta, spent) of ``key`` from the disk cache, (None, reason, spent) for a start
    that failed, or None (absent, unreadable, or another key under the same digest)."""
    path = diskcache.record_path("relaxed", _code_tag, key)
    got = None if path is None else diskcache.load(path)
    if got is None or not {"key", "spent"} <= set(got):
        return None
    if str(got["key"]) != repr(key) or got["spent"].shape != (N_STATS,):
        return None
    spent = np.asarray(got["spent"], dtype=np.int64)
    if "failed" in got:
        return None, str(got["failed"]), spent
    if not {"h", "delta"} <= set(got):
        return None
    return np.asarray(got["h"], dtype=float), float(got["delta"]), spent


class ElasticSolver:
    """Elastic (Chat = 1) LJ solves on one mesh, with a reusable inverse Jacobian."""

    def __init__(self, A, r, h0, c, tol):
        self.A, self.r, self.h0, self.c, self.tol = A, r, h0, c, tol
        N = A.shape[0]
        self.zero = np.zeros(N)
        self.law = lennard_jones(h0, c, N)
        self.cache = new_jacobian_cache(N)
        self.stats = np.zeros(N_STATS, dtype=np.int64)

    def solve(self, delta, guess):
        """(converged, gap) of the elastic LJ equilibrium at ``delta`` by Newton from
        ``guess``. Newton reads the scene's deadline (a solve on a large mesh lasts seconds):
        one it cut short raises :class:`sweep.engine.budget.OverBudget`, not a failed solve."""
        budget.check("the relaxed start (elastic solves)")
        h = np.array(guess, dtype=float)
        g = -delta + self.h0 + 0.5 * self.r**2
        budget.arm(self.cache)
        ok = newton(h, g, self.A, 1.0, self.zero, self.law, self.tol * self.h0,
                    MAX_NEWTON_ITER_INITIAL, self.cache, self.stats)
        if not ok:
            budget.check("the relaxed start (elastic solves)")
            invalidate(self.cache)   # refactorize next time
        return ok, h

    def radius(self, h, level_factor=TIP_GAP):
        return crossing_radius(h, self.r, level_factor * self.h0)


def _walk(el: ElasticSolver, d_from: float, h_from: np.ndarray, d_to: float, spent: list):
    """Elastic continuation from a converged state at ``d_from`` to ``d_to``.

    Adaptive steps in delta (halved on a failed solve, grown by WALK_GROWTH after a
    success), each solve warm-started from the secant through the last two states (the
    first from the state shifted by the change of indentation), and where that fails from
    the shifted state, before the step is halved. The secant follows the contact edge as it
    moves, where the shift moved the whole gap: on a graded mesh at mu 5 (band resolution 6,
    a0 2) 124 solves instead of 2280, 0.3 s instead of 6 s. The shift reaches starts the
    secant alone does not: the error estimate's half-resolution mesh of the threshold grid's
    fast numerics at a0 3.5 (139 nodes; 135 solves, where the secant alone failed after
    158 and the estimate fell back to a pair at 1/sqrt 2 of the resolution, which missed a
    crossing: 4.2e-5 against a true error of 2.3e-4 at n 1.6, rate 1e6; 6.9e-4 with the
    half-resolution pair, session 33). ``spent`` (a one-item list) counts the solves
    against WALK_MAX_SOLVES, shared by the walks of one relaxed start. Returns the gap at
    ``d_to`` or None.
    """
    d, h = d_from, h_from
    d_prev = h_prev = None
    step = min(0.25, abs(d_to - d_from)) if d_to != d_from else 0.0
    while d != d_to:
        if step < 1e-6 or spent[0] >= WALK_MAX_SOLVES:
            return None
        d_next = d_to if abs(d_to - d) <= step else d + math.copysign(step, d_to - d)
        shift = np.maximum(h - (d_next - d), 0.3 * h)
        guesses = (shift,) if h_prev is None else (
            np.maximum(h + (h - h_prev) * ((d_next - d) / (d - d_prev)), 0.3 * h), shift)
        for guess in guesses:
            spent[0] += 1
            ok, h_new = el.solve(d_next, guess)
            if ok:
                break
        if ok:
            d_prev, h_prev, d, h = d, h, d_next, h_new
            step *= WALK_GROWTH
        else:
            step *= 0.5
    return h


def _solve_at(el: ElasticSolver, delta: float, spent: list) -> np.ndarray:
    """Elastic LJ solution at ``delta``: from the JKR guess, else by continuation from the
    nearest indentation that converges directly (a coarse mesh can trap Newton in a
    non-solution minimum of |F| where the contact edge sits between nodes), the walks'
    solves counted in ``spent`` (:func:`_walk`)."""
    ok, h = el.solve(delta, jkr_gap_guess(el.r, delta, el.h0))
    if ok:
        return h
    for offset in (0.5, -0.5, 1.0, -1.0, 2.0, -2.0, 4.0, 8.0):
        if spent[0] >= WALK_MAX_SOLVES:
            break
        d = delta + offset
        ok, h = el.solve(d, jkr_gap_guess(el.r, d, el.h0))
        if ok:
            h = _walk(el, d, h, delta, spent)
            if h is not None:
                return h
    raise RuntimeError(f"no converged relaxed state at delta0={delta:.6g}"
                       + (f" (the continuation stopped after {spent[0]} solves)"
                          if spent[0] >= WALK_MAX_SOLVES else ""))


def relaxed_state(el: ElasticSolver, delta0=None, a0=None, mesh_key=None):
    """Relaxed elastic state at ``delta0`` or at the indentation giving contact radius ``a0``.

    ``mesh_key`` (hashable, determines the mesh and its influence matrix, e.g.
    ``sweep.engine.mesh.Mesh.key`` with the spacing) keeps the solution in a per-process cache of
    RELAXED_CACHE_SIZE states, returned (copied) to the next call with the same mesh, LJ
    law, tolerance and initial state; ``el`` then solves nothing (its Jacobian cache stays
    unfactorized). Returns (h, delta0) or raises RuntimeError with a reason.
    """
    if mesh_key is None:
        return _solve_relaxed(el, delta0, a0)
    return cached_state((mesh_key, el.h0, el.c, el.tol, delta0, a0),
                        lambda: _solve_relaxed(el, delta0, a0), el.stats)


def cached_state(key, solve, stats=None):
    """The state (gap h, indentation delta) kept under ``key`` in this process's cache of
    relaxed states (RELAXED_CACHE_SIZE of them, least recently used dropped), else on disk
    (:mod:`sweep.engine.diskcache`, under a hash of ``repr(key)`` and of the code that
    solves it: a sweep's other workers and later sweeps read it), else ``solve()``'s, kept
    in both; a copy of the gap either way. ``key`` must determine the state: the mesh, the
    LJ law, the tolerance and the initial state (and the method, where two give different
    states), in numbers and strings whose repr is exact. The state read back is the one
    solved, bit for bit: a cache saves time, never changes a number.

    The relaxed start took half the time of a warm campaign of the data set's kind (its
    scenes each with their own mu and a0, their Prony series and influence matrices read
    from disk; 2.73 of 5.1 s in one process, 200 scenes, 2026-11-26).

    ``stats`` (the solver's counters, :data:`sweep.kernels.solve.N_STATS`) grows by what the
    solve counted, whether it ran now or when the state was kept: a row's Newton iterations
    and factorizations do not depend on what its process solved before.

    A start that fails (``solve()`` raises RuntimeError: no converged state, the walks'
    WALK_MAX_SOLVES spent) is kept too, with its reason, and raises again at once: it is as
    much a function of the key as a state is. A coarse mesh that cannot hold a start (the
    error estimate's half resolution at a0 3.5 on the threshold grid's fast numerics, before
    the walk's shifted-gap retry: 158 solves, 0.13 s) then costs a campaign that once, not
    every scene that asks for it. A
    start stopped by the scene's time budget (:class:`sweep.engine.budget.OverBudget`) is
    not kept: another scene's budget may let it finish."""
    hit = _RELAXED.get(key)
    if hit is not None:
        _RELAXED.move_to_end(key)
    else:
        hit = _from_disk(key)
        if hit is not None:
            _keep(key, hit)
    if hit is not None:
        if stats is not None:
            stats += hit[2]
        if hit[0] is None:
            raise RuntimeError(hit[1])
        return hit[0].copy(), hit[1]
    before = None if stats is None else stats.copy()

    def kept(state: tuple, record: dict) -> None:
        """Keep ``state`` (first two items) with the counters the solve added, in memory and
        on disk (``record``: its arrays besides the key and the counters)."""
        spent = np.zeros(N_STATS, dtype=np.int64) if stats is None else stats - before
        _keep(key, (*state, spent))
        path = diskcache.record_path("relaxed", _code_tag, key)
        if path is not None:
            diskcache.save(path, {"key": np.array(repr(key)), **record, "spent": spent})

    try:
        h, d = solve()
    except budget.OverBudget:
        raise
    except RuntimeError as exc:
        kept((None, str(exc)), {"failed": np.array(str(exc))})
        raise
    kept((h.copy(), d), {"h": h, "delta": np.array(d)})
    return h, d


def _keep(key, state) -> None:
    _RELAXED[key] = state
    if len(_RELAXED) > RELAXED_CACHE_SIZE:
        _RELAXED.popitem(last=False)


#: the smallest d delta/da of the JKR branch the radius search starts from (its fold at
#: a = 1/2 has none)
MIN_JKR_DDELTA_DA = 0.25


def _solve_relaxed(el: ElasticSolver, delta0=None, a0=None):
    """The relaxed state of :func:`relaxed_state`, solved."""
    spent = [0]     # the continuation's solves (WALK_MAX_SOLVES), over every walk below
    if delta0 is not None:
        return _solve_at(el, float(delta0), spent), float(delta0)

    # find delta with a(delta) = a0: secant on delta, warm-started solves
    d1 = a0 * a0 - math.sqrt(2.0 * a0)
    h1 = _solve_at(el, d1, spent)
    f1 = el.radius(h1) - a0
    # JKR da/d delta, d delta/da = 2 a - (2 a)^(-1/2) kept from the fold at a = 1/2, where it
    # vanishes (a0 = 0.500-0.505 at mu = 0.03 sent the secant astray)
    slope = 1.0 / max(2 * a0 - 0.5 ** 0.5 * a0 ** -0.5, MIN_JKR_DDELTA_DA)
    d2 = d1 - f1 / slope
    lo = hi = None      # the bracket's ends: (delta, gap, radius - a0), radius below / above
    # the first step's start: the state at d1 plus the change of the JKR gap from d1 to d2
    # (the interior stays in contact, the edge moves). The rigid shift of the whole gap by
    # the change of indentation failed there where that step is large (mu 2.13, a0 9.58:
    # three solves of 40 Newton iterations and a walk, 114 ms; now 6 iterations, 7.9 ms;
    # 40 scenes of the data set's kind 0.42 s -> 0.09 s); it stays the start of the
    # secant's later steps, whose changes of indentation are small
    guess = np.maximum(h1 + jkr_gap_guess(el.r, d2, el.h0) - jkr_gap_guess(el.r, d1, el.h0),
                       0.3 * h1)
    for _ in range(60):
        ok, h2 = el.solve(d2, guess)
        if not ok:
            h2 = _walk(el, d1, h1, d2, spent)
            if h2 is None:
                h2 = _solve_at(el, d2, spent)
        f2 = el.radius(h2) - a0
        if f2 < 0:
            if lo is None or d2 > lo[0]:
                lo = (d2, h2, f2)
        elif hi is None or d2 < hi[0]:
            hi = (d2, h2, f2)
        if abs(f2) < 1e-10 * max(1.0, a0):
            return h2, float(d2)
        if f2 != f1:
            d_new = d2 - f2 * (d2 - d1) / (f2 - f1)
        else:
            d_new = d2 - f2 / slope
        if lo is not None and hi is not None and not (lo[0] < d_new < hi[0]):
            d_new = 0.5 * (lo[0] + hi[0])
        d1, h1, f1 = d2, h2, f2
        d2 = d_new
        guess = np.maximum(h1 + (d1 - d2), 0.3 * h1)
        if lo is not None and hi is not None and hi[0] - lo[0] < 1e-13 * max(1.0, abs(d2)):
            return _bracket_state(el, a0, d2, h1, f1, lo, hi)
    raise RuntimeError(f"could not reach the initial contact radius a0={a0:.6g}")


#: the relaxed start's root find ends on a bracket shrunk to nothing; its state is returned
#: only if its radius lies within this many node spacings of a0. On a coarse mesh the radius
#: steps as the contact edge hops a node, and the state ends within a spacing of a0 (0.52
#: and 0.76 spacings: the estimate's 139-node mesh at a0 3.5, tests/engine/test_initial.py's
#: coarse mesh at a0 2); a fine mesh's secant reaches a0 within 1e-7 spacings (588 scenes of
#: the data-set samples and the threshold grid). Far beyond, the radius jumps past a0 (the
#: walk's branch folds): on the seed-11 data-set scene n 0.09, k 0.0094, mu 2.55, a0 0.571,
#: rate 0.023 asked for 1e-3, the refined mesh's start ended at radius 0.806 (32-130
#: spacings off on three meshes) and the row was ok with a pull-off 29 % off and an error
#: estimate of 2e-5 (session 33)
RADIUS_JUMP_SPACINGS = 2.0


def _bracket_state(el: ElasticSolver, a0: float, d: float, h: np.ndarray, f: float, lo, hi):
    """The relaxed start where the root find's bracket has shrunk to nothing: the last
    iterate (gap ``h``, radius a0 + ``f``) if its radius lies within RADIUS_JUMP_SPACINGS
    spacings of a0, else the bracket's other end if its radius does, else a refusal naming
    both radii. The last iterate is returned with the indentation ``d`` the root find moved
    on to, within 1e-13 of its own, as before: a start accepted before keeps its bits; the
    other end with its own.

    The ends ``lo`` and ``hi`` ((delta, gap, radius - a0), radius below and above a0) are
    equilibria at one indentation (to 1e-13): where the radius steps as the contact edge
    hops nodes, discrete equilibria of different radii coexist there (the edge pinned
    between different nodes), and the branch the last iterate lands on is decided by the
    last bits of the solves. The uniform 160-node mesh over 4 a_ref at mu 5, a0 2
    (tests/engine/test_machine_compliance.py; a0 midway between two nodes) ended at
    delta 2.0740456 with its lower end 0.18 spacings below a0 and its last iterate 2.12
    spacings above with OpenBLAS's Haswell kernels on an AMD EPYC (refused), 0.93 above with
    its Nehalem kernels (accepted); its Sandybridge and Prescott kernels ended at other
    indentations, 2.098 and 2.118, 0.40 and 0.23 spacings below. The radius jumps past a0,
    and the start is refused, only where neither end lies within the tolerance."""
    tol = RADIUS_JUMP_SPACINGS * _spacing_at(el.r, a0)
    if abs(f) <= tol:
        return h, float(d)
    other = lo if f > 0 else hi
    if abs(other[2]) <= tol:
        return other[1], float(other[0])
    raise RuntimeError(
        f"no relaxed state of contact radius a0={a0:.6g} on this mesh: the radius jumps past "
        f"it at delta0={d:.6g} (from {a0 + lo[2]:.6g} to {a0 + hi[2]:.6g})")


def _spacing_at(r: np.ndarray, a: float) -> float:
    """The node spacing of the mesh ``r`` (radii, increasing) at radius ``a``."""
    i = int(np.clip(np.searchsorted(r, a), 1, r.size - 1))
    return float(r[i] - r[i - 1])
