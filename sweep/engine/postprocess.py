"""A computed unloading turned into a result: the refined load minimum, the state and the
crack speed there (:func:`finish`, shared by every BEM mesh)."""
from __future__ import annotations

import math

import numpy as np

from ..kernels.solve import STATUS_DOMAIN, STATUS_NEWTON_FAILED, STATUS_STEP_LIMIT, stop_reached

#: status of a run stopped by ``Numerics.time_budget_s`` (beside the kernel's STATUS_*)
STATUS_TIME_BUDGET = -1


#: a parabola refinement lowering the sampled minimum by more than this fraction must
#: also predict the neighbouring samples (see :func:`refine_minimum`)
VERTEX_RTOL = 1e-3


def refine_minimum(t, P):
    """(t*, P*) of the minimum of P(t) refined by a parabola through the 3 samples around it.

    The parabola is rejected, and the sampled minimum returned, where it is no local model
    of P (a kink or a jump of the load): where it lowers the minimum by more than
    max(P[i-1], P[i+1]) - P[i] (impossible for a parabola through equally spaced samples),
    or by more than VERTEX_RTOL |P[i]| while missing the samples i - 2, i + 2 by more than
    it lowers the minimum.
    """
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
                vertex = A * ts * ts + B * ts + C
                miss = 0.0
                for j in (i - 2, i + 2):
                    if 0 <= j < len(P):
                        miss = max(miss, abs(A * t[j] ** 2 + B * t[j] + C - P[j]))
                drop = y[1] - vertex
                smooth = (drop <= max(y[0], y[2]) - y[1]
                          and (drop <= VERTEX_RTOL * abs(y[1]) or miss <= drop))
                if x[0] <= ts <= x[2] and smooth:
                    return i, ts, min(vertex, y[1])
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


def finish(res, status: int, trajectory: dict, spacing: float, min_travel: float, scales,
           advice: str) -> None:
    """Fill ``res`` from a finished unloading, in place: ``ok`` with the pull-off, the state
    and crack speed at the pull-off instant, or a failure with its reason.

    Parameters
    ----------
    res : sweep.Result
    status : the kernel's status (or STATUS_TIME_BUDGET).
    trajectory : arrays ``t, delta, P, a, a_inner`` of the run (tau0, d_ref, pi dg R, a_ref).
    spacing : the fine node spacing (a_ref), the scale of the crack-speed fit.
    min_travel : crack-tip recession after the load minimum that counts as past the
        pull-off (a_ref, :func:`sweep.kernels.solve.stop_reached`).
    scales : the scene's :class:`sweep.engine.problem.Scales` (process zone for ``vhat``,
        loading speed for ``rhat_pb``).
    advice : what to change when no equilibrium was found before the pull-off (it depends
        on the mesh that ran).
    """
    t, delta, P, a, a_inner = (trajectory[k] for k in ("t", "delta", "P", "a", "a_inner"))
    i, t_star, P_star = refine_minimum(t, P)
    passed = stop_reached(P, a, len(P), i, 0, min_travel)
    if status == STATUS_TIME_BUDGET:
        res.reason = (f"time budget: {res.numerics.time_budget_s:g} s spent after {len(t) - 1} "
                      f"steps (a = {a[-1]:.4g}, pull-off not reached); give it more "
                      f"(numerics time_budget_s) or cheaper numerics (preset fast, fewer nodes)")
        return
    if status == STATUS_DOMAIN:
        res.reason = "contact reached the mesh edge: increase numerics.domain"
        return
    if status == STATUS_STEP_LIMIT and not passed:
        res.reason = f"step limit ({res.numerics.max_steps}) reached before pull-off"
        return
    if status == STATUS_NEWTON_FAILED and not passed:
        res.reason = (f"no equilibrium found at the minimum step before pull-off (delta="
                      f"{delta[-1]:.6g}, a={a[-1]:.4g}): the discrete path folds where the "
                      f"crack tip is under-resolved; {advice}")
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
    res.crack_speed = float(crack_speed_at(t, a, t_star, spacing))
    res.vhat = res.crack_speed / scales.process_zone
    res.rhat_pb = scales.loading_speed
