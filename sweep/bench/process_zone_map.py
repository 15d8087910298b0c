"""The map from a process zone's crack speed to its opening rate, measured
(``make pz-map``): the slope scale beta(mu, xi) of :mod:`sweep.engine.process_zone`.

For each Tabor parameter of :data:`MUS` the relaxed elastic LJ equilibrium at contact radius
:data:`A_PROFILE` (:class:`sweep.engine.quasistatic.ElasticBranch`, :data:`RESOLUTION`
elements per process zone) gives the crack tip's gap profile h(r); beta is its
work-weighted opening slope (:func:`sweep.engine.process_zone.slope_scale`) at each
exponent of :data:`XIS`. Written to ``sweep/engine/process_zone_map.json`` (package data)
with the resolution check: beta at half the resolution, whose relative difference is
stated per mu.

``python -m sweep.bench.process_zone_map [--out PATH]``
"""
from __future__ import annotations

import sys
import time

import numpy as np

from ..campaign.store import provenance
from ..engine.process_zone import MAP, slope_scale
from ..engine.quasistatic import ElasticBranch
from . import measurement_main

#: Tabor parameters of the table (the BEM's range, log-spaced; beta ~ mu beyond it)
MUS = (0.5, 1.0, 2.0, 3.24, 5.0, 7.0, 10.0, 15.0, 20.0, 30.0, 50.0, 100.0)
#: exponents of the table
XIS = (0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0, 1.5, 2.0, 3.0, 5.0, 10.0)
#: the contact radius of the profile (a_ref): near the elastic pull-off; at mu >= 3 beta
#: moves by less than 5 % between a = 0.8 and 1.5 (it is the crack tip's, set by G = dg)
A_PROFILE = 1.0
#: elements per process zone l0 near the tip (64 and 128 agree to 0.3 % at mu 3.24-30)
RESOLUTION = 64.0


def profile(mu: float, resolution: float = RESOLUTION):
    """(r, h): the relaxed elastic LJ equilibrium at contact radius :data:`A_PROFILE`."""
    br = ElasticBranch(mu, A_PROFILE, 0.5 * A_PROFILE, zone_resolution=resolution, zone=8.0)
    h, d = br.guess(A_PROFILE)
    h, d, ok = br.solve(A_PROFILE, h, d)
    if not ok:
        raise RuntimeError(f"no elastic equilibrium at a = {A_PROFILE} for mu = {mu}")
    return A_PROFILE * br.x, h


def measure() -> dict:
    """The table: beta[i][j] at MUS[i], XIS[j], and its resolution check."""
    beta, check = [], []
    for mu in MUS:
        t0 = time.perf_counter()
        r, h = profile(mu)
        row = [slope_scale(r, h, mu, xi) for xi in XIS]
        r2, h2 = profile(mu, RESOLUTION / 2.0)
        coarse = [slope_scale(r2, h2, mu, xi) for xi in XIS]
        diff = float(np.max(np.abs(np.array(coarse) / np.array(row) - 1.0)))
        beta.append(row)
        check.append(diff)
        print(f"mu {mu:g}: beta/mu = {row[XIS.index(0.5)] / mu:.4f} at xi 0.5; half "
              f"resolution differs by {diff:.2g} ({time.perf_counter() - t0:.1f} s)",
              flush=True)
    return {"what": "beta(mu, xi) (d_ref/a_ref): the work-weighted opening slope of the "
                    "relaxed elastic LJ crack tip; hdot_c = pz_v0 beta "
                    "(sweep.engine.process_zone)",
            "command": "make pz-map", "a_profile": A_PROFILE, "resolution": RESOLUTION,
            "mu": list(MUS), "xi": list(XIS), "beta": beta,
            "half_resolution_difference": check, "provenance": provenance()}


def main(argv=None) -> int:
    return measurement_main("python -m sweep.bench.process_zone_map", __doc__, measure, MAP,
                            argv)


if __name__ == "__main__":
    sys.exit(main())
