"""A plain numpy/scipy solver of the same model: the baseline of ``vs_numpy`` in ``make bench``.

What a user would write instead of the engine, without Numba: a uniform radial mesh, a dense
chord-Newton solve per step (linear predictor from the last two states, one LU factorization of the Jacobian at the start of a step,
reused while the residual falls at least by half per iteration, refactorized otherwise), the
exact hereditary integral (closed-form integrated compliance, traction piecewise linear in
time, O(steps^2 N) in all; with equal steps the lags are multiples of the step and Psi is
tabulated once per lag), a fixed indentation step, and the load's Lennard-Jones tail beyond
the mesh in closed form, as the engine's (``Numerics.lj_tail``).

It shares the engine's discretization of space (the overlapping-triangle influence matrix of
``kernels.influence`` on the same domain, the same load weights), so on a fine mesh both
converge to the same pull-off: the comparison is between algorithms, not between models. The
influence matrix depends only on N (it scales with the spacing) and is assembled once per N
and cached, as a sweep would; :func:`plain_unload` reports its assembly time apart.

Units: docs/design.md section 2 (lengths a_ref, gaps and indentation d_ref, load pi dg R, time
tau0); the sign convention of :mod:`kernels.solve` (F = h - g - A (C sigma(h) - H)).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.linalg import lu_factor, lu_solve

from ..kernels.influence import assemble_unit, load_weights

from .. import units
from ..materials import SLS, MPLRetardation
from ..scene import Scene
from ..engine.initial import jkr_gap_guess
from ..engine.postprocess import crack_speed_at, refine_minimum

#: Newton tolerance on the gap, in units of h0 (max norm of the residual)
TOL = 1e-8
#: iterations per solve before the step is halved
MAX_ITER = 60
#: the chord (stale) factorization is kept while each iteration reduces |F| by this factor
CHORD_CONTRACTION = 0.5
#: step-length halvings of the line search
LINE_SEARCH_HALVINGS = 30
#: stop once the load has recovered from its tensile minimum by this fraction of |P_min| and
#: by RECOVERY_FLOOR (pi dg R), at least RECOVERY_STEPS steps after it
RECOVERY, RECOVERY_FLOOR, RECOVERY_STEPS = 0.05, 0.05, 5
#: a failed step is halved at most this many times
MAX_HALVINGS = 6


@dataclass
class PlainResult:
    """Outcome of :func:`plain_unload` (units as in :class:`sweep.Result`)."""

    status: str
    reason: str
    pull_off: float
    crack_speed: float
    steps: int
    factorizations: int
    newton_iterations: int
    wall_s: float
    influence_s: float
    nodes: int
    domain: float
    step: float


@lru_cache(maxsize=8)
def _unit_matrix(N: int) -> np.ndarray:
    return assemble_unit(int(N))


def _tail(h_last, rise, h0, c):
    """The Lennard-Jones load beyond the mesh: 2 pi int sigma r dr from the end of the last
    node's hat (r_end = N dr) to infinity, the gap continued rigidly (h = h_last + (r^2 -
    r_last^2)/2, so r dr = dh): 2 pi int_{h_end}^inf sigma dh with h_end = h_last + rise."""
    q = h0 / (h_last + rise)
    return -2.0 * math.pi * c * h0 * (q**2 / 2.0 - q**8 / 8.0)


def _lj(h, h0, c):
    """LJ traction sigma(h) (positive compressive) and its derivative d sigma / dh."""
    x3 = (h0 / h) ** 3
    x9 = x3**3
    return -c * (x3 - x9), c * (3.0 * x3 - 9.0 * x9) / h


def _crossing(h, dr, level):
    """Outermost radius where the gap equals ``level`` (0 if it never does)."""
    below = np.flatnonzero(h < level)
    if below.size == 0:
        return 0.0
    i = below[-1]
    if i == h.size - 1:
        return i * dr
    return (i + (level - h[i]) / (h[i + 1] - h[i])) * dr


def _newton(A, g, ceff, H, h, h0, c, tol, eye):
    """Chord-Newton on F(h) = h - g - A (ceff sigma(h) - H); returns (h, its, factorizations)
    or (None, its, factorizations) when it does not converge (max |F| >= tol). Backtracking
    line search on |F|_2 with a fresh Jacobian, every gap kept positive."""
    def resid(hh):
        s, d = _lj(hh, h0, c)
        return hh - g - A @ (ceff * s - H), d

    F, dsig = resid(h)
    nF, n2 = np.max(np.abs(F)), np.linalg.norm(F)
    lu, fresh, factors = None, False, 0
    for it in range(1, MAX_ITER + 1):
        if nF < tol:
            return h, it - 1, factors
        if lu is None:
            lu = lu_factor(eye - ceff * A * dsig[None, :])
            fresh, factors = True, factors + 1
        dh = lu_solve(lu, -F)
        neg = dh < 0
        alpha = min(1.0, float(np.min(-0.7 * h[neg] / dh[neg]))) if neg.any() else 1.0
        for _ in range(LINE_SEARCH_HALVINGS):
            h_new = h + alpha * dh
            F_new, dsig_new = resid(h_new)
            n2_new = np.linalg.norm(F_new)
            if n2_new < n2 or not fresh:
                break
            alpha *= 0.5
        if n2_new >= n2:
            if fresh:
                return None, it, factors     # no descent along a fresh Newton direction
            lu = None                        # stale factorization: refactorize and retry
            continue
        if n2_new > CHORD_CONTRACTION * n2:
            lu = None                        # slow contraction: a fresh Jacobian next
        h, F, n2, dsig = h_new, F_new, n2_new, dsig_new
        nF = np.max(np.abs(F))
        fresh = False
    return (h, MAX_ITER, factors) if nF < tol else (None, MAX_ITER, factors)


def _integrated_compliance(scene: Scene):
    """Psi(T) = int_0^T Chat (tau0 units), closed form for the scene's material."""
    if scene.k == 1.0:
        return lambda T: np.asarray(T, dtype=float)
    if scene.material == "sls":
        return SLS(1.0, 1.0 / scene.k, 1.0).integrated_compliance
    return MPLRetardation(1.0, 1.0 / scene.k, scene.n, 1.0).integrated_compliance


def plain_unload(scene: Scene, nodes: int, domain: float, step: float,
                 tol: float = TOL, max_steps: int = 100_000) -> PlainResult:
    """Unload ``scene`` (given by ``delta0``) with the plain solver.

    Parameters
    ----------
    scene : Scene
        Must give ``delta0`` (d_ref units); ``stop="pulloff"`` is assumed.
    nodes : int
        Uniform mesh nodes N (node 0 at r = 0).
    domain : float
        Mesh radius (a_ref units); use the engine's ``Result.domain_used`` to compare alike.
    step : float
        Indentation step in units of h0 (halved on a failed solve, up to MAX_HALVINGS times).
    tol : float
        Newton tolerance in units of h0.
    """
    if scene.delta0 is None:
        raise ValueError("scene: the plain solver needs delta0 (initial indentation)")
    t0 = time.perf_counter()
    N = int(nodes)
    dr = domain / (N - 1)
    A = _unit_matrix(N) * dr
    t_infl = time.perf_counter() - t0
    t0 = time.perf_counter()
    wP = 2.0 * math.pi * load_weights(N, dr)
    h0, c = units.h0_hat(scene.mu), units.lj_prefactor(scene.mu)
    hm = 3.0 ** (1.0 / 6.0) * h0
    r = np.arange(N) * dr
    rise = 0.5 * ((N * dr) ** 2 - r[-1] ** 2)     # from the last node to its hat's end

    def load(sigma, h):
        return float(wP @ sigma) + _tail(float(h[-1]), rise, h0, c)
    eye = np.eye(N)
    psi = _integrated_compliance(scene)
    counts = {"factorizations": 0, "newton_iterations": 0}

    def done(status, reason, t=None, P=None, a=None):
        po, v = math.nan, math.nan
        if status == "ok":
            _, t_star, P_star = refine_minimum(t, P)
            po, v = -P_star, float(crack_speed_at(t, a, t_star, dr))
        return PlainResult(status, reason, po, v, len(T) - 1, counts["factorizations"],
                           counts["newton_iterations"], time.perf_counter() - t0, t_infl,
                           N, float(domain), float(step))

    def solve(g, ceff, H, guess):
        h, its, factors = _newton(A, g, ceff, H, guess, h0, c, tol * h0, eye)
        counts["newton_iterations"] += its
        counts["factorizations"] += factors
        return h

    delta = scene.delta0
    h = solve(-delta + h0 + 0.5 * r**2, 1.0, np.zeros(N), jkr_gap_guess(r, delta, h0))
    T = [0.0]
    if h is None:
        return done("failed", "initial state: no convergence")
    sigma = _lj(h, h0, c)[0]
    sigma0 = sigma.copy()
    P, a = [load(sigma, h)], [_crossing(h, dr, hm)]
    dsig, dts = [], []
    dd_nominal = step * h0
    h_prev, dd_prev = None, dd_nominal        # linear predictor from the last two states
    uniform, psi_table = True, [0.0]           # Psi(j dt) while every step is nominal
    while len(T) <= max_steps:
        dd = dd_nominal
        for _ in range(MAX_HALVINGS + 1):
            dt = dd / (scene.rate * h0)
            t_new = T[-1] + dt
            ceff = float(psi(dt)) / dt
            hist = sigma0.copy()
            if dsig and uniform and dd == dd_nominal:
                m = len(dsig)                # lags are multiples of dt: tabulated Psi
                while len(psi_table) < m + 2:
                    psi_table.append(float(psi(len(psi_table) * dt)))
                w = np.diff(np.asarray(psi_table[1:m + 2]))[::-1] / dt
                hist += w @ np.asarray(dsig)
            elif dsig:
                tm = np.asarray(T)
                w = (psi(t_new - tm[:-1]) - psi(t_new - tm[1:])) / np.asarray(dts)
                hist += w @ np.asarray(dsig)
            guess = h if h_prev is None else h + (h - h_prev) * (dd / dd_prev)
            h_new = solve(-(delta - dd) + h0 + 0.5 * r**2, ceff, ceff * sigma - hist,
                          np.maximum(guess, 0.5 * h))
            if h_new is not None:
                break
            dd *= 0.5
        else:
            return done("failed", f"no convergence at delta = {delta:.6g}")
        sig_new = _lj(h_new, h0, c)[0]
        dsig.append(sig_new - sigma)
        dts.append(dt)
        h_prev, dd_prev = h, dd
        uniform = uniform and dd == dd_nominal
        h, sigma, delta = h_new, sig_new, delta - dd
        T.append(t_new)
        P.append(load(sigma, h))
        a.append(_crossing(h, dr, hm))
        if a[-1] >= (N - 1) * dr:
            return done("failed", "contact reached the mesh edge")
        i = int(np.argmin(P))
        recovered = (P[i] < 0 and len(P) - 1 - i >= RECOVERY_STEPS
                     and P[-1] - P[i] > max(RECOVERY * abs(P[i]), RECOVERY_FLOOR))
        if recovered or (a[-1] == 0.0 and P[-1] > P[i]):
            return done("ok", "", np.asarray(T), np.asarray(P), np.asarray(a))
    return done("failed", f"step limit ({max_steps})")
