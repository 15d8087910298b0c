"""The single-scene driver: ``simulate(scene, numerics) -> Result``.

Orchestration only; the numerical work is in the Numba kernels of ``kernels/``:

1. mesh and domain from the scene (``Numerics.domain=None``: large enough that the gap at
   the mesh edge is ``tail_gap`` h0 at the start, so the truncated LJ tail is negligible);
2. the relaxed initial state: elastic (Chat = 1) LJ solution at ``delta0``, or at the
   indentation whose max-tension contact radius is ``a0`` (secant root find on delta,
   each solve warm-started from the previous one, the first from the JKR solution);
3. the Prony series of Chat over the scene's time window (smallest step to the end of
   the unloading, with a safety factor), with ``numerics.prony_rtol``;
4. the unloading kernel (``kernels.solve.unload``) or, with ``numerics.exact``, the exact
   hereditary integral with the closed-form integrated compliance (O(steps^2 N));
5. pull-off |min P| (parabola through the three samples around the minimum), the state at
   pull-off, and the crack speed -da/dt from a local quadratic fit of a(t).

A numerical failure never raises: the ``Result`` has ``status="failed"`` and a reason.
Invalid input raises :class:`sweep.errors.InputError` when the Scene/Numerics are built.
"""
from __future__ import annotations

import math
import time
from functools import lru_cache

import numpy as np

from kernels.influence import assemble_unit, load_weights
from kernels.interface import crossing_radius, lj_traction
from kernels.solve import (N_STATS, RECOVERY, RECOVERY_FLOOR, STAT_FACTOR, STAT_ITER,
                           STATUS_DOMAIN, STATUS_DONE,
                           STATUS_NEWTON_FAILED, STATUS_STEP_LIMIT, new_jacobian_cache, newton,
                           unload)

from . import units
from .scene import Numerics, Result, Scene
from .theory import jkr_contact_radius

#: Newton iterations per solve: a good step converges in 2-5 (quadratic predictor); a solve
#: that needs more is better retried with a smaller step or taken for a fold
MAX_NEWTON_ITER = 12
#: iterations of the elastic solves of the initial state (poorer starting guesses)
MAX_NEWTON_ITER_INITIAL = 40
#: the Prony window spans [min_step/rate, WINDOW_SAFETY * estimated unloading time] ...
WINDOW_SAFETY = 10.0
#: ... widened outward to multiples of this many decades (shared by the scenes of a sweep)
WINDOW_GRID = 0.5


@lru_cache(maxsize=8)
def _unit_influence(N: int) -> np.ndarray:
    A = assemble_unit(N)
    A.setflags(write=False)
    return A


def influence_matrix(N: int, spacing: float) -> np.ndarray:
    """Influence matrix for N nodes at ``spacing`` (cached per N; it scales with spacing)."""
    return _unit_influence(int(N)) * spacing


def lj_constants(mu: float) -> tuple[float, float]:
    """(h0, c) of the LJ law sigma = -c[(h0/h)^3 - (h0/h)^9] for Tabor parameter mu."""
    return units.h0_hat(mu), units.lj_prefactor(mu)


# ----------------------------------------------------------------------------- JKR guess

def jkr_radius(delta: float) -> float:
    """JKR contact radius at indentation ``delta`` (stable branch); 0 below the fixed-grip
    fold delta = -3/4, where JKR has no contact."""
    return float(jkr_contact_radius(indentation=delta)) if delta >= -0.75 else 0.0


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


# ------------------------------------------------------------------------- relaxed state

class _Elastic:
    """Elastic (Chat = 1) LJ solves on one mesh, with a reusable inverse Jacobian."""

    def __init__(self, A, dr, h0, c, tol):
        self.A, self.dr, self.h0, self.c, self.tol = A, dr, h0, c, tol
        N = A.shape[0]
        self.r = np.arange(N) * dr
        self.zero = np.zeros(N)
        self.cache = new_jacobian_cache(N)
        self.stats = np.zeros(N_STATS, dtype=np.int64)

    def solve(self, delta, guess):
        h = np.array(guess, dtype=float)
        g = -delta + self.h0 + 0.5 * self.r**2
        ok = newton(h, g, self.A, 1.0, self.zero, self.h0, self.c, self.tol * self.h0,
                    MAX_NEWTON_ITER_INITIAL, *self.cache, self.stats)
        if not ok:
            self.cache[5][0] = 0     # state[valid] = 0: refactorize next time
        return ok, h

    def radius(self, h, level_factor=3.0 ** (1.0 / 6.0)):
        return crossing_radius(h, self.dr, level_factor * self.h0)


def _walk(el: _Elastic, d_from: float, h_from: np.ndarray, d_to: float):
    """Elastic continuation from a converged state at ``d_from`` to ``d_to``.

    Adaptive steps in delta (halved on a failed solve, grown after successes), each solve
    warm-started from the previous gap shifted by the change of indentation.
    Returns the gap at ``d_to`` or None.
    """
    d, h = d_from, h_from
    step = min(0.25, abs(d_to - d_from)) if d_to != d_from else 0.0
    while d != d_to:
        if step < 1e-6:
            return None
        d_next = d_to if abs(d_to - d) <= step else d + math.copysign(step, d_to - d)
        guess = np.maximum(h - (d_next - d), 0.3 * h)
        ok, h_new = el.solve(d_next, guess)
        if ok:
            d, h = d_next, h_new
            step *= 1.5
        else:
            step *= 0.5
    return h


def _solve_at(el: _Elastic, delta: float) -> np.ndarray:
    """Elastic LJ solution at ``delta``: from the JKR guess, else by continuation from the
    nearest indentation that converges directly (a coarse mesh can trap Newton in a
    non-solution minimum of |F| where the contact edge sits between nodes)."""
    ok, h = el.solve(delta, jkr_gap_guess(el.r, delta, el.h0))
    if ok:
        return h
    for offset in (0.5, -0.5, 1.0, -1.0, 2.0, -2.0, 4.0, 8.0):
        d = delta + offset
        ok, h = el.solve(d, jkr_gap_guess(el.r, d, el.h0))
        if ok:
            h = _walk(el, d, h, delta)
            if h is not None:
                return h
    raise RuntimeError(f"no converged relaxed state at delta0={delta:.6g}")


def relaxed_state(el: _Elastic, delta0=None, a0=None):
    """Relaxed elastic state at ``delta0`` or at the indentation giving contact radius ``a0``.

    Returns (h, delta0) or raises RuntimeError with a reason.
    """
    if delta0 is not None:
        return _solve_at(el, float(delta0)), float(delta0)

    # find delta with a(delta) = a0: secant on delta, warm-started solves
    d1 = a0 * a0 - math.sqrt(2.0 * a0)
    h1 = _solve_at(el, d1)
    f1 = el.radius(h1) - a0
    slope = 1.0 / (2 * a0 - 0.5 ** 0.5 * a0 ** -0.5)     # JKR da/d delta
    d2 = d1 - f1 / slope
    lo = hi = None
    for _ in range(60):
        ok, h2 = el.solve(d2, np.maximum(h1 + (d1 - d2), 0.3 * h1))
        if not ok:
            h2 = _walk(el, d1, h1, d2)
            if h2 is None:
                h2 = _solve_at(el, d2)
        f2 = el.radius(h2) - a0
        if f2 < 0:
            lo = d2 if lo is None else max(lo, d2)
        else:
            hi = d2 if hi is None else min(hi, d2)
        if abs(f2) < 1e-10 * max(1.0, a0):
            return h2, float(d2)
        if f2 != f1:
            d_new = d2 - f2 * (d2 - d1) / (f2 - f1)
        else:
            d_new = d2 - f2 / slope
        if lo is not None and hi is not None and not (lo < d_new < hi):
            d_new = 0.5 * (lo + hi)
        d1, h1, f1 = d2, h2, f2
        d2 = d_new
        if lo is not None and hi is not None and hi - lo < 1e-13 * max(1.0, abs(d2)):
            return h2, float(d2)
    raise RuntimeError(f"could not reach the initial contact radius a0={a0:.6g}")


# ------------------------------------------------------------------------------ material

def material_of(scene: Scene):
    """The material object of a scene, in units where E0 = 1 and tau0 = 1."""
    return _material(scene.material, scene.n, scene.k)


def _material(material: str, n: float, k: float):
    from .materials import SLS, MPLRetardation
    if material == "sls":
        return SLS(1.0, 1.0 / k, 1.0)
    return MPLRetardation(1.0, 1.0 / k, n, 1.0)


def auto_domain(scene: Scene, numerics: Numerics, delta0_estimate: float) -> float:
    """Mesh radius: the rigid gap r^2/2 - delta0 reaches ``tail_gap`` h0 at the edge."""
    h0 = units.h0_hat(scene.mu)
    r_tail = math.sqrt(2.0 * (max(delta0_estimate, 0.0) + numerics.tail_gap * h0))
    a_est = jkr_radius(delta0_estimate) if scene.a0 is None else scene.a0
    return max(r_tail, 1.3 * a_est + 0.5)


def time_window(scene: Scene, numerics: Numerics, delta0: float) -> tuple[float, float]:
    """Prony window [t_min, t_max] in tau0 for this scene's unloading.

    The window is widened outward to the grid of WINDOW_GRID decades, so that the scenes
    of a sweep share a few windows (and their cached Prony series, :func:`prony_series`).
    """
    h0 = units.h0_hat(scene.mu)
    t_min = numerics.min_step / scene.rate        # the smallest step the run may take
    travel = max(delta0, 0.0) + 3.0 + 2.0 * math.sqrt(max(delta0, 1.0))
    t_max = max(WINDOW_SAFETY * travel / (scene.rate * h0), 10 * t_min)
    lo = math.floor(math.log10(t_min) / WINDOW_GRID) * WINDOW_GRID
    hi = math.ceil(math.log10(t_max) / WINDOW_GRID) * WINDOW_GRID
    return 10.0 ** lo, 10.0 ** hi


@lru_cache(maxsize=256)
def prony_series(material: str, n: float, k: float, t_min: float, t_max: float, rtol: float):
    """The Prony series of a scene's creep compliance on [t_min, t_max] (tau0), cached.

    A fit costs 0.02-0.2 s, more than a fast scene's unloading; the scenes of a sweep
    repeat the same (material, n, k) and, through the snapped :func:`time_window`, the
    same window, so each worker fits each series once.
    """
    return _material(material, n, k).prony(t_min, t_max, rtol)


# ------------------------------------------------------------------------ post-processing

def refine_minimum(t, P):
    """(t*, P*) of the minimum of P(t) refined by a parabola through the 3 samples around it."""
    i = int(np.argmin(P))
    if 0 < i < len(P) - 1:
        x = t[i - 1:i + 2]
        y = P[i - 1:i + 2]
        denom = (x[0] - x[1]) * (x[0] - x[2]) * (x[1] - x[2])
        if denom != 0:
            A = (x[2] * (y[1] - y[0]) + x[1] * (y[0] - y[2]) + x[0] * (y[2] - y[1])) / denom
            B = (x[2] ** 2 * (y[0] - y[1]) + x[1] ** 2 * (y[2] - y[0]) + x[0] ** 2 * (y[1] - y[2])) / denom
            C = y[1] - A * x[1] ** 2 - B * x[1]
            if A > 0:
                ts = -B / (2 * A)
                if x[0] <= ts <= x[2]:
                    return i, ts, min(A * ts * ts + B * ts + C, y[1])
    return i, t[i], P[i]


def crack_speed_at(t, a, t_star, spacing, window_nodes=3.0, min_points=5):
    """-da/dt at ``t_star`` from a quadratic least-squares fit of a(t) nearby.

    The fit uses the samples whose radius lies within ``window_nodes`` node spacings of
    a(t_star) (a(t) has kinks where it crosses nodes), widened to at least ``min_points``.
    """
    a_star = np.interp(t_star, t, a)
    sel = np.flatnonzero(np.abs(a - a_star) <= window_nodes * spacing)
    if sel.size < min_points:
        order = np.argsort(np.abs(t - t_star))
        sel = np.sort(order[:min_points])
    if sel.size < 3:
        return math.nan
    tt = t[sel] - t_star
    scale = max(np.max(np.abs(tt)), 1e-300)
    coef = np.polyfit(tt / scale, a[sel], 2)
    return -coef[1] / scale


# ---------------------------------------------------------------------------- simulate

def simulate(scene: Scene, numerics: Numerics | None = None) -> Result:
    """Simulate one scene: unload a rigid sphere from a relaxed viscoelastic half-space.

    Parameters
    ----------
    scene : Scene
        Physics: material (n, k), Tabor parameter, initial state, unloading rate.
    numerics : Numerics, optional
        Discretization; default ``Numerics.preset("balanced")``.

    Returns
    -------
    Result
        Pull-off force, state and crack speed at pull-off, counters, trajectory.
        ``status`` is "failed" (with ``reason``) if the run could not be completed.
    """
    if numerics is None:
        numerics = Numerics.preset("balanced")
    if not isinstance(scene, Scene):
        raise TypeError("scene must be a sweep.Scene")
    if not isinstance(numerics, Numerics):
        raise TypeError("numerics must be a sweep.Numerics")
    t_start = time.perf_counter()
    res = Result(scene=scene, numerics=numerics)
    try:
        _simulate(scene, numerics, res)
    except Exception as exc:  # noqa: BLE001 - a sweep must survive any single failure
        res.status = "failed"
        res.reason = f"{type(exc).__name__}: {exc}"
    res.wall_s = time.perf_counter() - t_start
    return res


def _simulate(scene: Scene, numerics: Numerics, res: Result) -> None:
    h0, c = lj_constants(scene.mu)
    N = numerics.nodes
    d_est = scene.delta0 if scene.delta0 is not None else scene.a0**2 - math.sqrt(2 * scene.a0)
    domain = numerics.domain if numerics.domain is not None else auto_domain(scene, numerics, d_est)
    dr = domain / (N - 1)
    res.spacing, res.domain_used = dr, domain
    zone = units.l0_hat(scene.mu) / dr
    if zone < numerics.zone_nodes:
        need = int(math.ceil(numerics.zone_nodes * domain / units.l0_hat(scene.mu))) + 1
        res.reason = (f"mesh too coarse: the process zone l0 = {units.l0_hat(scene.mu):.3g} a_ref "
                      f"spans {zone:.2g} node spacings (< zone_nodes = {numerics.zone_nodes:g}); "
                      f"use nodes >= {need} for domain {domain:.3g}")
        return
    A = influence_matrix(N, dr)
    wP = load_weights(N, dr)

    el = _Elastic(A, dr, h0, c, numerics.tol)
    try:
        h_init, delta0 = relaxed_state(el, delta0=scene.delta0, a0=scene.a0)
    except RuntimeError as exc:
        res.reason = f"initial state: {exc}"
        return
    res.delta0_result = delta0
    res.a0_result = el.radius(h_init)
    res.a0_inner = el.radius(h_init, 1.0)
    if res.a0_result >= domain - dr:
        res.reason = f"initial contact radius {res.a0_result:.4g} reaches the mesh edge (domain {domain:.4g})"
        return
    if res.a0_result <= 0.0:
        res.reason = "no contact in the initial state (delta0 below the jump-in)"
        return

    material = material_of(scene) if scene.k < 1.0 else None
    stop_mode = 0 if scene.stop == "pulloff" else 1
    max_steps = numerics.max_steps
    out = [np.empty(max_steps + 1) for _ in range(5)]
    stats = el.stats.copy()

    if numerics.exact:
        status, n = _unload_exact(A, dr, wP, h_init, delta0, scene, numerics, h0, c,
                                  material, stop_mode, out, stats)
        res.prony_terms, res.prony_error = 0, 0.0
    else:
        if scene.k == 1.0:
            weights = np.zeros(0)
            times = np.zeros(0)
            res.prony_terms, res.prony_error = 0, 0.0
        else:
            t_min, t_max = time_window(scene, numerics, delta0)
            prony = prony_series(scene.material, scene.n if scene.material == "mpl" else 0.0,
                                 scene.k, t_min, t_max, numerics.prony_rtol)
            weights = np.ascontiguousarray(prony.weights, dtype=float)
            times = np.ascontiguousarray(prony.times, dtype=float)
            res.prony_terms, res.prony_error = int(weights.size), float(prony.max_rel_error)
        h_final = np.empty(N)
        status, n = unload(A, dr, wP, h_init, delta0, scene.rate, h0, c, weights, times,
                           numerics.step, numerics.min_step, numerics.da_max * dr, numerics.tol,
                           MAX_NEWTON_ITER, max_steps, stop_mode, *el.cache, *out, h_final, stats)
        res.final_gap = h_final
    t, delta, P, a, a_inner = (x[:n].copy() for x in out)
    res.trajectory = {"t": t, "delta": delta, "P": P, "a": a, "a_inner": a_inner}
    res.steps = n - 1
    res.newton_iterations = int(stats[STAT_ITER])
    res.factorizations = int(stats[STAT_FACTOR])
    _finish(res, scene, status, t, delta, P, a, a_inner, dr)


def _past_pull_off(P) -> bool:
    """The stop criterion of the kernels: a tensile minimum, >= 5 steps before the end,
    after which the load has recovered by RECOVERY |P_min| and at least RECOVERY_FLOOR."""
    i = int(np.argmin(P))
    return (P[i] < 0 and len(P) - 1 - i >= 5
            and P[-1] - P[i] > max(RECOVERY * abs(P[i]), RECOVERY_FLOOR))


def _finish(res, scene, status, t, delta, P, a, a_inner, dr):
    i, t_star, P_star = refine_minimum(t, P)
    passed = _past_pull_off(P)
    if status == STATUS_DOMAIN:
        res.reason = "contact reached the mesh edge: increase numerics.domain"
        return
    if status == STATUS_STEP_LIMIT and not passed:
        res.reason = f"step limit ({res.numerics.max_steps}) reached before pull-off"
        return
    if status == STATUS_NEWTON_FAILED and not passed:
        res.reason = (f"no equilibrium found at the minimum step before pull-off (delta="
                      f"{delta[-1]:.6g}, a={a[-1]:.4g}): the discrete path folds where the "
                      f"crack tip is under-resolved; increase nodes or reduce domain")
        return
    if P_star >= 0:
        res.reason = "no tensile load reached"
        return
    res.status = "ok"
    if status == STATUS_NEWTON_FAILED:
        res.reason = "stopped at the jump-off instability after pull-off"
    res.pull_off = -P_star
    res.t_pulloff = t_star
    res.delta_pulloff = float(np.interp(t_star, t, delta))
    res.a_pulloff = float(np.interp(t_star, t, a))
    res.a_inner_pulloff = float(np.interp(t_star, t, a_inner))
    res.crack_speed = float(crack_speed_at(t, a, t_star, dr))
    res.vhat = res.crack_speed / units.l0_hat(scene.mu)
    res.rhat_pb = units.rhat_pb(scene.rate, scene.mu)


# ------------------------------------------------------------------ exact convolution

def _unload_exact(A, dr, wP, h_init, delta0, scene, numerics, h0, c, material, stop_mode,
                  out, stats):
    """Unloading with the exact hereditary integral (closed-form integrated compliance).

    Fixed indentation step ``numerics.step`` h0 (halved on a Newton failure); no Prony.
    Cost O(steps^2 N): for validation on small problems.
    """
    t_out, d_out, P_out, a_out, ai_out = out
    N = h_init.size
    r = np.arange(N) * dr
    hm = 3.0 ** (1.0 / 6.0) * h0
    psi = (lambda T: np.asarray(T, dtype=float)) if scene.k == 1.0 else material.integrated_compliance
    sigma0 = np.empty(N)
    lj_traction(h_init, h0, c, sigma0)
    h = h_init.copy()
    sigma = sigma0.copy()
    times = [0.0]
    dsig = []          # traction increments per step
    dts = []
    cache = new_jacobian_cache(N)
    t, delta = 0.0, delta0
    t_out[0], d_out[0] = 0.0, delta
    P_out[0] = 2 * np.pi * wP @ sigma
    a_out[0] = crossing_radius(h, dr, hm)
    ai_out[0] = crossing_radius(h, dr, h0)
    P_min, i_min, n = P_out[0], 0, 1
    dd = numerics.step * h0
    while True:
        if n > numerics.max_steps:
            return STATUS_STEP_LIMIT, n
        dt = dd / (scene.rate * h0)
        t_new = t + dt
        ceff = float(psi(dt)) / dt
        hist = sigma0.copy()
        if dsig:
            tm = np.asarray(times)
            lag_hi = t_new - tm[:-1]
            lag_lo = t_new - tm[1:]
            w = (psi(lag_hi) - psi(lag_lo)) / np.asarray(dts)
            hist += w @ np.asarray(dsig)
        H = -(hist - ceff * sigma)
        g = -(delta - dd) + h0 + 0.5 * r**2
        hp = h.copy()
        ok = newton(hp, g, A, ceff, H, h0, c, numerics.tol * h0, MAX_NEWTON_ITER, *cache, stats)
        if not ok:
            cache[5][0] = 0
            if dd <= numerics.min_step * h0 * 1.0001:
                return STATUS_NEWTON_FAILED, n
            dd = max(0.5 * dd, numerics.min_step * h0)
            continue
        sig_new = np.empty(N)
        lj_traction(hp, h0, c, sig_new)
        dsig.append(sig_new - sigma)
        dts.append(dt)
        times.append(t_new)
        h, sigma, t, delta = hp, sig_new, t_new, delta - dd
        P = 2 * np.pi * wP @ sigma
        a_new = crossing_radius(h, dr, hm)
        t_out[n], d_out[n], P_out[n], a_out[n] = t, delta, P, a_new
        ai_out[n] = crossing_radius(h, dr, h0)
        if P < P_min:
            P_min, i_min = P, n
        n += 1
        if a_new >= (N - 1) * dr:
            return STATUS_DOMAIN, n
        if stop_mode == 0:
            if _past_pull_off(P_out[:n]):
                return STATUS_DONE, n
            if a_new == 0.0 and n - 1 - i_min >= 1:
                return STATUS_DONE, n
        elif a_new == 0.0 and P > P_min and abs(P) < 1e-3 * abs(P_min):
            return STATUS_DONE, n


def warm_up() -> float:
    """Compile (or load from the Numba cache) the kernels on a tiny scene; returns seconds.

    Raises RuntimeError if the warm-up scene itself fails (a broken installation).
    """
    t0 = time.perf_counter()
    scene = Scene(n=0.8, k=0.5, mu=3.24, a0=1.5, rate=10.0)
    res = simulate(scene, Numerics(nodes=80, domain=3.0, step=0.5, da_max=2.0,
                                   prony_rtol=1e-2, tol=1e-8))
    if not res.ok:
        raise RuntimeError(f"warm-up scene failed: {res.reason}")
    return time.perf_counter() - t0
