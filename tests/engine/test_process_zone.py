"""The map from a process zone's crack speed to the BEM law's opening rate
(sweep/engine/process_zone.py, issue 35): beta, the crack tip's work-weighted opening slope.

(a) On a profile of known slope (a straight wedge outside the contact) beta is that slope:
pi int -sigma_LJ dh from h0 is 1 (dg = 1/pi). (b) The tabulated map is what the code
measures now (one mu recomputed). (c) Without a process zone hdot_c is infinite (the LJ law).
"""
import json
import math

import numpy as np
import pytest

from sweep import Scene, units
from sweep.bench.process_zone_map import XIS, profile
from sweep.engine import process_zone as pz


@pytest.mark.parametrize("xi", [0.3, 0.5, 1.0, 2.0])
def test_a_wedge_of_slope_s_has_beta_s(xi):
    mu, slope = 5.0, 0.37
    h0 = units.h0_hat(mu)
    r = np.linspace(0.0, 40.0, 400001)          # out to h = 160 h0: the tension beyond is 5e-5
    h = np.where(r < 1.0, 0.95 * h0, h0 + slope * (r - 1.0))   # contact, then a wedge from h0
    assert pz.slope_scale(r, h, mu, xi) == pytest.approx(slope, rel=2e-3)


def test_the_tabulated_map_is_what_the_code_measures():
    data = json.loads(pz.MAP.read_text())
    assert not data.get("provisional")
    i = data["mu"].index(5.0)
    r, h = profile(5.0)
    for j in (XIS.index(0.3), XIS.index(1.0)):
        # the profile is solved to 1e-10 h0: another processor moves beta in its ninth digit
        assert pz.slope_scale(r, h, 5.0, XIS[j]) == pytest.approx(data["beta"][i][j], rel=1e-6)
        assert pz.opening_rate_scale(5.0, XIS[j]) == pytest.approx(data["beta"][i][j], rel=1e-12)
    # beyond the table beta grows as mu (the JKR limit)
    top = data["mu"][-1]
    assert pz.opening_rate_scale(2 * top, 0.5) == pytest.approx(
        2 * pz.opening_rate_scale(top, 0.5), rel=1e-12)


def test_hdot_c_is_pz_v0_beta_and_infinite_without_a_process_zone():
    plain = Scene(n=0.5, k=0.3, mu=5.0, a0=1.5, rate=1.0)
    assert math.isinf(pz.hdot_c(plain))
    with_pz = Scene(n=0.5, k=0.3, mu=5.0, a0=1.5, rate=1.0, pz_law="gent-schultz", pz_v0=2.0,
                    pz_xi=0.5)
    assert pz.hdot_c(with_pz) == pytest.approx(2.0 * pz.opening_rate_scale(5.0, 0.5), rel=1e-14)
