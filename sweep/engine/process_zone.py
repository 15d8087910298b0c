"""The rate-dependent process zone of the BEM: its local law's scale from the crack speed.

A scene's process zone is given on the crack-speed basis of a peel or JKR test,
``Gamma_pz(v) = dg (1 + (v/pz_v0)^pz_xi)`` (:class:`sweep.scene.Scene`, ``pz_law``
"gent-schultz"). The crack-front model takes that law as it is. The BEM's interface law acts
on each node's own opening rate hdot (:func:`sweep.kernels.interface.traction`): the tension
of the Lennard-Jones law is multiplied by m = 1 + (hdot/hdot_c)^xi, so that a node opened at
a constant rate separates with the work m dg. A crack running at speed v opens the nodes of
its process zone at hdot = v |dh/dr|; weighted with the work each part of the zone does,

    Gamma(v) / dg - 1 = (v / hdot_c)^xi  pi  int_{h0}^inf -sigma_LJ(h) |dh/dr|^xi dh
                      = (v beta / hdot_c)^xi,

so the law reproduces ``Gamma_pz(v)`` with hdot_c = pz_v0 beta, where beta (d_ref / a_ref) is
the work-weighted opening slope of the crack tip. It is measured on the relaxed elastic LJ
crack tip (:func:`slope_scale` on :class:`sweep.engine.quasistatic.ElasticBranch` states) as
a function of mu and xi and tabulated in ``process_zone_map.json`` (``make pz-map``,
:mod:`sweep.bench.process_zone_map`). The map is exact as the process zone's term goes to
zero; where the term is large the tip's tension, raised by m, steepens the zone, and the
BEM's process zone acts more than the Gent-Schultz law (measured in docs/design.md, "The
process zone in the BEM").
"""
from __future__ import annotations

import json
import math
from functools import lru_cache
from pathlib import Path

import numpy as np

from .. import units
from ..kernels.interface import smoothing_rate, zone_factor

__all__ = ["MAP", "slope_scale", "opening_rate_scale", "hdot_c", "work_of_separation"]

#: the tabulated map (package data, written by ``make pz-map``)
MAP = Path(__file__).with_name("process_zone_map.json")


def work_of_separation(q, xi, dg=1.0 / math.pi) -> float:
    """The work of separation of the BEM's law opened at the constant rate q hdot_c:
    ``dg m(q)`` (dimensionless, dg = 1/pi in the units of docs/design.md section 2), with
    m = 1 + q^xi above the smoothing rate q_s (:func:`sweep.kernels.interface.zone_factor`)."""
    m, _ = zone_factor(float(q), float(xi), smoothing_rate(float(xi)))
    return dg * m


def slope_scale(r, h, mu, xi) -> float:
    """beta = [pi int_{h > h0} -sigma_LJ(h) |dh/dr|^xi dh]^(1/xi) over the tensile zone of
    the equilibrium gap ``h`` at the nodes ``r`` (a_ref; d_ref), outside the contact: the
    work-weighted opening slope of the crack tip (d_ref / a_ref).

    The integral runs over the nodes outside the last node in contact (h <= h0) by the
    trapezoid rule in h, the slope by central differences.
    """
    r, h = np.asarray(r, float), np.asarray(h, float)
    h0, c = units.h0_hat(mu), units.lj_prefactor(mu)
    inside = np.nonzero(h <= h0)[0]
    start = int(inside[-1]) + 1 if inside.size else 0
    slope = np.abs(np.gradient(h, r))[start:]
    u = h[start:]
    x3 = (h0 / u) ** 3
    work = c * (x3 - x3**3)                  # -sigma_LJ(u), >= 0 above h0
    f = work * slope**xi
    # from h0 (the integrand vanishes there) to the first node, then node to node
    total = 0.5 * f[0] * (u[0] - h0) + float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(u)))
    return float((math.pi * total) ** (1.0 / xi))


@lru_cache(maxsize=1)
def _table():
    try:
        data = json.loads(MAP.read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise RuntimeError(f"the process zone's map {MAP.name} is missing or unreadable "
                           f"({exc}); run make pz-map") from exc
    return (np.asarray(data["mu"], float), np.asarray(data["xi"], float),
            np.asarray(data["beta"], float))


def opening_rate_scale(mu: float, xi: float) -> float:
    """beta(mu, xi) (d_ref / a_ref) from the tabulated map: bilinear in (log mu, xi) on
    log beta; outside the table's mu range, beta proportional to mu (the zone's slope in the
    JKR limit, h0 / l0 ~ mu) from its nearest end; xi clipped to the table."""
    mus, xis, beta = _table()
    lm = np.log(mus)
    x = float(np.clip(xi, xis[0], xis[-1]))
    col = np.array([np.interp(x, xis, np.log(beta[i])) for i in range(mus.size)])
    m = float(mu)
    if m <= mus[0]:
        return float(np.exp(col[0]) * m / mus[0])
    if m >= mus[-1]:
        return float(np.exp(col[-1]) * m / mus[-1])
    return float(np.exp(np.interp(math.log(m), lm, col)))


def hdot_c(scene) -> float:
    """The BEM law's opening-rate scale hdot_c = pz_v0 beta(mu, pz_xi) (d_ref / tau0) of a
    scene; inf without a process zone (the LJ law exactly)."""
    if scene.pz_law == "none":
        return math.inf
    return float(scene.pz_v0) * opening_rate_scale(scene.mu, scene.pz_xi)
