"""Unloading with the exact hereditary integral (no Prony series): the validation integrator.

Same model, mesh, Newton solver and stop rule as the Prony kernel (``kernels.solve``), but the
hereditary integral is summed over the whole history with the closed-form integrated
compliance Psi(T) = int_0^T Chat: O(steps^2 N). Units of docs/design.md section 2.
"""
from __future__ import annotations

import numpy as np

from ..kernels.interface import crossing_radius, lennard_jones, lj_traction
from ..kernels.solve import (STATUS_DOMAIN, STATUS_DONE, STATUS_NEWTON_FAILED, STATUS_STEP_LIMIT,
                           invalidate, load, new_jacobian_cache, newton, stop_reached)

#: Newton iterations per solve (as in the Prony kernel's driver)
MAX_NEWTON_ITER = 12


def unload_exact(pb, h_init, delta0, material, min_travel, out, stats):
    """Unloading with the exact hereditary integral (closed-form integrated compliance).

    Fixed indentation step ``numerics.step`` h0 (halved on a Newton failure); no Prony.
    Cost O(steps^2 N): for validation on small problems.

    Parameters
    ----------
    pb : sweep.engine.problem.Problem
        The prepared problem (mesh, influence matrix, LJ constants, loading speed).
    h_init, delta0 : the relaxed gap (d_ref) and its indentation.
    material : the material object (``integrated_compliance``), None when elastic.
    min_travel : crack-tip recession after the load minimum required to stop (a_ref).
    out : the five record arrays (t, delta, P, a, a_inner); ``stats`` the solver counters.
    """
    A, r, wP, tail = pb.A, pb.mesh.r, pb.wP, pb.tail
    scene, numerics = pb.scene, pb.numerics
    h0, c, hm, stop_mode = pb.h0, pb.c, pb.hm, pb.stop_mode
    t_out, d_out, P_out, a_out, ai_out = out
    N = h_init.size
    law = lennard_jones(h0, c, N)
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
    P_out[0] = load(sigma, wP, h, tail, h0, c)
    a_out[0] = crossing_radius(h, r, hm)
    ai_out[0] = crossing_radius(h, r, h0)
    P_min, i_min, n = P_out[0], 0, 1
    dd = numerics.step * h0
    while True:
        if n > numerics.max_steps:
            return STATUS_STEP_LIMIT, n
        dt = dd / pb.scales.loading_speed
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
        ok = newton(hp, g, A, ceff, H, law, numerics.tol * h0, MAX_NEWTON_ITER, cache, stats)
        if not ok:
            invalidate(cache)
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
        P = load(sigma, wP, h, tail, h0, c)
        a_new = crossing_radius(h, r, hm)
        t_out[n], d_out[n], P_out[n], a_out[n] = t, delta, P, a_new
        ai_out[n] = crossing_radius(h, r, h0)
        if P < P_min:
            P_min, i_min = P, n
        n += 1
        if a_new >= r[N - 1]:
            return STATUS_DOMAIN, n
        if stop_reached(P_out, a_out, n, i_min, stop_mode, min_travel):
            return STATUS_DONE, n
