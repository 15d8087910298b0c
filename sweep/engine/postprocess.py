"""Curve fits on a computed unloading: the refined load minimum and the crack speed there."""
from __future__ import annotations

import math

import numpy as np


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
