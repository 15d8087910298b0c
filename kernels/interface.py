"""Lennard-Jones interface law and contact-radius detection (Numba kernels).

Dimensionless units of docs/design.md section 2. Traction is positive when compressive:

    sigma(h) = -c [ (h0/h)^3 - (h0/h)^9 ],   c = 8 mu / (3 pi^(1/3)),   h0 = 1/(pi^(2/3) mu)

The most tensile traction -sigma_0 is reached at h_m = 3^(1/6) h0.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np
from numba import njit

#: the gap at the crack tip over h0: the traction is most tensile at h_m = 3^(1/6) h0, and the
#: contact radius ``a`` is where the gap equals it (docs/design.md section 2). The one place
#: this number is written; everything else reads it from here (or from
#: ``sweep.engine.problem.Scales.tip_gap``)
TIP_GAP = 3.0 ** (1.0 / 6.0)


@njit(cache=True)
def lj_traction(h, h0, c, out):
    """sigma(h) at every node into ``out``."""
    for i in range(h.size):
        x3 = (h0 / h[i]) ** 3
        out[i] = -c * (x3 - x3 * x3 * x3)


@njit(cache=True)
def lj_traction_and_stiffness(h, h0, c, sig, dsig):
    """sigma(h) and d sigma / dh at every node."""
    for i in range(h.size):
        x3 = (h0 / h[i]) ** 3
        x9 = x3 * x3 * x3
        sig[i] = -c * (x3 - x9)
        dsig[i] = c * (3.0 * x3 - 9.0 * x9) / h[i]


@njit(cache=True)
def tail_load(h_end, h0, c):
    """The load of the Lennard-Jones attraction beyond a mesh whose traction ends where the
    gap is ``h_end`` (the end of the last node's hat), the gap continued there as the rigid
    sphere's, dh = r dr:

        P_tail = 2 pi int_{h_end}^inf sigma_LJ(h) dh = -2 pi c h0 (q^2/2 - q^8/8),  q = h0/h_end

    (pi dg R units; negative: tensile). The BEM's load (:func:`kernels.solve.load`) adds
    it; the quasi-static elastic branch (``sweep.engine.quasistatic.ElasticBranch.load``),
    which had the same formula first, keeps its own order of operations (its results bitwise
    as before). Beyond the mesh the
    interface is the Lennard-Jones law: a process zone acts at the crack tip, far inside,
    and its factor m is taken as 1 there. ``h_end`` = inf gives 0 (no tail). Without it the
    BEM's pull-off was low by about (1/tail_gap)^2 relative (about 2.8e-4 at the default
    tail_gap = 60)."""
    q = h0 / h_end
    q2 = q * q
    q8 = q2 * q2 * q2 * q2
    return -2.0 * np.pi * c * h0 * (0.5 * q2 - 0.125 * q8)


@njit(cache=True)
def crossing_radius(h, r, level):
    """Outermost radius where the gap equals ``level`` (linear interpolation between nodes).

    ``r`` holds the node positions (any mesh). Returns 0 when the gap exceeds ``level``
    everywhere and the mesh radius when the gap is below ``level`` at the last node
    (contact reaching the mesh edge).
    """
    N = h.size
    if h[N - 1] < level:
        return r[N - 1]
    for i in range(N - 2, -1, -1):
        if h[i] < level:
            frac = (level - h[i]) / (h[i + 1] - h[i])
            return r[i] + frac * (r[i + 1] - r[i])
    return 0.0


# ------------------------------------------------------------------ the process zone

#: the interface law the solver kernels take whole: the LJ law's h0 and c, and the process
#: zone's state over the step, ``zone`` (ZONE_SIZE) with the last accepted gap ``h_old`` its
#: opening rate is measured from (:func:`traction`; ``zone[ZONE_RATE] = 0``: the LJ law)
Interface = namedtuple("Interface", ["h0", "c", "h_old", "zone"])


#: the process zone's state over a step, one float64 array of ZONE_SIZE:
#: zone[ZONE_RATE] = 1/(hdot_c dt), the opening rate's scale (0: no process zone, the LJ law
#: exactly), zone[ZONE_XI] = xi and zone[ZONE_SMOOTH] = q_s (:func:`zone_factor`)
ZONE_RATE = 0
ZONE_XI = 1
ZONE_SMOOTH = 2
ZONE_SIZE = 3
#: the process zone's term m - 1 below which its law is smoothed: q_s = ZONE_SMOOTH_TERM^(1/xi)
#: (:func:`zone_factor`); above it the law is the power law exactly. 0.03, not 1e-2: the
#: cubic's slope near q = 0, about q_s^(xi - 1), stalled Newton where a node opened slowly;
#: not 0.1: that moved a weak process zone's pull-off by 1.3 % (docs/design.md, "The
#: process zone in the BEM")
ZONE_SMOOTH_TERM = 3e-2


@njit(cache=True)
def smoothing_rate(xi):
    """q_s = ZONE_SMOOTH_TERM^(1/xi), the opening rate below which the process zone's law is
    smoothed (:func:`zone_factor`; zone[ZONE_SMOOTH] of a law of exponent ``xi``)."""
    return ZONE_SMOOTH_TERM ** (1.0 / xi)


@njit(cache=True)
def zone_factor(q, xi, qs):
    """m(q) and dm/dq of the process zone at the normalized opening rate q = hdot/hdot_c:

        m = 1 + q^xi                                  q >= q_s
        m = 1 + q_s^xi x^2 (3 - xi + (xi - 2) x),     x = q/q_s in (0, 1)
        m = 1                                         q <= 0 (a closing node, or at rest)

    The cubic joins 1 and the power law with value and slope (m is C1 and increasing), so
    that Newton meets no infinite slope at q = 0 (the power law's for xi < 1; with it the
    solves stalled, docs/design.md "The process zone in the BEM"); below q_s it differs from
    the power law by less than q_s^xi = ZONE_SMOOTH_TERM.

    xi = 1/2 (the paper's process-zone ratio 1 + (v/v1)^(1/2)) takes a square root for the
    power: pow costs about 16 ns a node against 2.5, and the traction is evaluated at every
    node several times a step (a tenth of a process-zone scene's time went to pow;
    docs/performance.md, "The process zone's cost")."""
    if q <= 0.0:
        return 1.0, 0.0
    if q >= qs:
        p = np.sqrt(q) if xi == 0.5 else q ** xi
        return 1.0 + p, xi * p / q
    x = q / qs
    a = qs ** xi
    return (1.0 + a * x * x * (3.0 - xi + (xi - 2.0) * x),
            a * x * (6.0 - 2.0 * xi + 3.0 * (xi - 2.0) * x) / qs)


@njit(cache=True)
def traction(h, h_old, zone, h0, c, out):
    """sigma at every node into ``out``: the Lennard-Jones law, its tension multiplied by the
    process zone (docs/design.md, "The process zone in the BEM"):

        sigma(h) = m(q) sigma_LJ(h)  for h > h0 (tension),   sigma_LJ(h) for h <= h0,

    with q = (h - h_old) zone[ZONE_RATE] the opening rate over the step (backward Euler, in
    units of hdot_c) and m from :func:`zone_factor` (1 at q <= 0: a closing gap follows the
    LJ law); at a constant opening rate the work of separation is m dg exactly. ``zone[ZONE_RATE] == 0`` is the LJ law (``h_old`` unread).
    """
    s = zone[ZONE_RATE]
    if s == 0.0:
        lj_traction(h, h0, c, out)
        return
    xi, qs = zone[ZONE_XI], zone[ZONE_SMOOTH]
    for i in range(h.size):
        x3 = (h0 / h[i]) ** 3
        sig = -c * (x3 - x3 * x3 * x3)
        if h[i] > h0:
            m, _ = zone_factor((h[i] - h_old[i]) * s, xi, qs)
            sig *= m
        out[i] = sig


@njit(cache=True)
def traction_and_stiffness(h, h_old, zone, h0, c, sig, dsig, drate):
    """sigma (:func:`traction`) and d sigma / dh at every node, the rate term included, and
    that rate term alone, sigma_LJ dm/dh, in ``drate`` (zero without a process zone; the
    Jacobian's kept factorization leaves it out beyond the crack-tip zone:
    :mod:`kernels.jacobian`)."""
    s = zone[ZONE_RATE]
    if s == 0.0:
        lj_traction_and_stiffness(h, h0, c, sig, dsig)
        for i in range(h.size):
            drate[i] = 0.0
        return
    xi, qs = zone[ZONE_XI], zone[ZONE_SMOOTH]
    for i in range(h.size):
        x3 = (h0 / h[i]) ** 3
        x9 = x3 * x3 * x3
        lj = -c * (x3 - x9)
        dlj = c * (3.0 * x3 - 9.0 * x9) / h[i]
        if h[i] > h0:
            m, dm = zone_factor((h[i] - h_old[i]) * s, xi, qs)
            sig[i] = m * lj
            drate[i] = lj * dm * s
            dsig[i] = m * dlj + drate[i]
        else:
            sig[i] = lj
            dsig[i] = dlj
            drate[i] = 0.0


def lennard_jones(h0, c, N):
    """The :data:`Interface` of the Lennard-Jones law alone, on N nodes (for the kernels'
    callers)."""
    return Interface(h0, c, np.zeros(N), np.zeros(ZONE_SIZE))
