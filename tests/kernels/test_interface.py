"""The interface law with a rate-dependent process zone (kernels/interface.py, issue 35).

Checked against closed forms: at rest, closing, or without a process zone the law is the
Lennard-Jones law exactly; at a constant opening rate its work of separation is m dg (dg =
1/pi in the units of docs/design.md, the integral of the LJ tension from h0, a closed form
checked here by quadrature); the stiffness the Newton step uses is the law's derivative.
"""
import math

import numpy as np
import pytest
from scipy.integrate import quad

from sweep import units
from sweep.engine.process_zone import work_of_separation
from sweep.kernels.interface import (ZONE_RATE, ZONE_SIZE, ZONE_SMOOTH, ZONE_SMOOTH_TERM,
                                     ZONE_XI, lj_traction, lj_traction_and_stiffness,
                                     tail_load, traction, traction_and_stiffness, zone_factor)

MU = 5.0
H0, C = units.h0_hat(MU), units.lj_prefactor(MU)


def zone(rate_scale, xi):
    z = np.zeros(ZONE_SIZE)
    z[ZONE_RATE], z[ZONE_XI], z[ZONE_SMOOTH] = rate_scale, xi, ZONE_SMOOTH_TERM ** (1 / xi)
    return z


def test_the_factor_is_one_at_rest_and_on_closing():
    for q in (0.0, -1e-3, -5.0):
        assert zone_factor(q, 0.5, 1e-4) == (1.0, 0.0)


@pytest.mark.parametrize("xi", [0.2, 0.4154, 1.0, 2.0])
def test_the_factor_is_the_power_law_above_q_s_and_joins_it_smoothly(xi):
    qs = ZONE_SMOOTH_TERM ** (1 / xi)
    for q in (qs, 3 * qs, 1.0, 50.0):
        m, dm = zone_factor(q, xi, qs)
        assert m == pytest.approx(1 + q**xi, rel=1e-14)
        assert dm == pytest.approx(xi * q ** (xi - 1), rel=1e-12)
    below = zone_factor(qs * (1 - 1e-9), xi, qs)
    above = zone_factor(qs, xi, qs)
    assert below[0] == pytest.approx(above[0], rel=1e-8)      # value and slope join
    assert below[1] == pytest.approx(above[1], rel=1e-6)
    q = np.linspace(0, 2 * qs, 401)[1:]
    m = np.array([zone_factor(x, xi, qs)[0] for x in q])
    assert np.all(np.diff(m) > 0)                              # increasing
    assert np.all(np.abs(m - 1 - q**xi) <= ZONE_SMOOTH_TERM)   # the smoothing's bound


def test_the_lj_law_integrates_to_dg():
    work, _ = quad(lambda h: -(-C * ((H0 / h) ** 3 - (H0 / h) ** 9)), H0, np.inf)
    assert work == pytest.approx(1 / math.pi, rel=1e-10)


@pytest.mark.parametrize("q, xi", [(0.04, 0.5), (1.0, 0.4154), (30.0, 0.4154), (2.0, 1.0)])
def test_work_of_separation_at_a_constant_opening_rate_is_m_dg(q, xi):
    """A node opened from h0 to infinity at the constant rate q hdot_c (h_old = h - q/s at
    every h): the integral of its tension is dg (1 + q^xi)."""
    s = 1e3
    z = zone(s, xi)

    def tension(h):
        out = np.empty(1)
        traction(np.array([h]), np.array([h - q / s]), z, H0, C, out)
        return -out[0]

    work = quad(tension, H0, 20 * H0, limit=200)[0] + quad(tension, 20 * H0, np.inf)[0]
    assert work == pytest.approx((1 + q**xi) / math.pi, rel=1e-8)
    assert work_of_separation(q, xi) == pytest.approx((1 + q**xi) / math.pi, rel=1e-14)


def test_a_closing_or_compressed_gap_follows_the_lj_law_exactly():
    h = np.linspace(0.7 * H0, 6 * H0, 50)
    lj, got = np.empty(h.size), np.empty(h.size)
    lj_traction(h, H0, C, lj)
    traction(h, h + 0.1 * H0, zone(1e3, 0.5), H0, C, got)     # every gap closing
    assert np.array_equal(got, lj)
    traction(h, h - 0.1 * H0, zone(1e3, 0.5), H0, C, got)     # opening: tension raised only
    assert np.array_equal(got[h <= H0], lj[h <= H0])
    assert np.all(got[h > H0] < lj[h > H0])


def test_without_a_process_zone_the_law_is_lj_bitwise():
    h = np.linspace(0.7 * H0, 6 * H0, 50)
    a, b, da, db, rate = (np.empty(h.size) for _ in range(5))
    lj_traction_and_stiffness(h, H0, C, a, da)
    traction_and_stiffness(h, h - H0, np.zeros(ZONE_SIZE), H0, C, b, db, rate)
    assert np.array_equal(a, b) and np.array_equal(da, db) and not rate.any()


@pytest.mark.parametrize("xi", [0.4154, 1.0])
def test_the_stiffness_is_the_laws_derivative(xi):
    h = np.linspace(0.9 * H0, 5 * H0, 40)
    h_old = h - np.linspace(-0.05, 0.3, 40) * H0      # closing, slow and fast opening
    z = zone(50.0, xi)
    sig, d, rate = np.empty(h.size), np.empty(h.size), np.empty(h.size)
    traction_and_stiffness(h, h_old, z, H0, C, sig, d, rate)
    eps = 1e-7 * H0
    up, down = np.empty(h.size), np.empty(h.size)
    traction(h + eps, h_old, z, H0, C, up)
    traction(h - eps, h_old, z, H0, C, down)
    fd = (up - down) / (2 * eps)
    smooth = np.abs(h - H0) > 2 * eps                     # the LJ side switch at h0
    assert np.allclose(d[smooth], fd[smooth], rtol=1e-5, atol=1e-6 * np.max(np.abs(fd)))
    # the rate term alone: the derivative at a fixed factor m is d - rate
    m = np.where(h > H0, sig, 1.0) / np.where(h > H0, -C * ((H0 / h) ** 3 - (H0 / h) ** 9), 1.0)
    lj, dlj = np.empty(h.size), np.empty(h.size)
    lj_traction_and_stiffness(h, H0, C, lj, dlj)
    assert np.allclose(d - rate, np.where(h > H0, m, 1.0) * dlj, rtol=1e-10, atol=0)
    assert np.any(rate != 0) and not rate[h - h_old <= 0].any()


@pytest.mark.parametrize("gaps", [1.2, 3.0, 60.0, 600.0])
def test_the_tail_load_is_the_lennard_jones_law_integrated_beyond_the_mesh(gaps):
    # P_tail = 2 pi int_{h_end}^inf sigma_LJ(h) dh (the rigid gap beyond the mesh, dh = r dr),
    # the law itself integrated numerically
    h_end = gaps * H0
    sig = np.empty(1)

    def sigma(h):
        lj_traction(np.array([h]), H0, C, sig)
        return sig[0]

    value, err = quad(sigma, h_end, np.inf, epsabs=0.0, epsrel=1e-12, limit=200)
    assert tail_load(h_end, H0, C) == pytest.approx(2.0 * math.pi * value, rel=1e-10)
    assert tail_load(h_end, H0, C) < 0.0         # tensile beyond 4^(-1/6) h0


def test_no_tail_at_an_infinite_gap():
    assert tail_load(np.inf, H0, C) == 0.0
