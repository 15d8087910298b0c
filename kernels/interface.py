"""Lennard-Jones interface law and contact-radius detection (Numba kernels).

Dimensionless units of docs/design.md section 2. Traction is positive when compressive:

    sigma(h) = -c [ (h0/h)^3 - (h0/h)^9 ],   c = 8 mu / (3 pi^(1/3)),   h0 = 1/(pi^(2/3) mu)

The most tensile traction -sigma_0 is reached at h_m = 3^(1/6) h0.
"""
from __future__ import annotations

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
