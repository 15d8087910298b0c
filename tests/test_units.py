"""Dimensionless <-> physical conversions (sweep.units), docs/design.md section 2."""
import math

import numpy as np
import pytest

from tests import reference
from sweep import units
from sweep.errors import InputError
from sweep.units import PhysicalScale

def _paper():
    return reference.paper_values()


# the paper's PDMS (section "Experimental adhesion tests"), SI units; the expected values
# below are re-derived independently by hand in each test, the yaml only for comparison
E0, NU, DG, R = 1.458e6, 0.5, 152.3e-3, 5.19e-3


def pdms(h0):
    return PhysicalScale.from_moduli(R=R, dg=DG, E0=E0, nu=NU, h0=h0)


SCALES = [
    pdms(30.8e-9),
    pdms(1.55e-6),
    PhysicalScale(R=1e-2, dg=0.05, E0_star=1e5, h0=1e-9),  # soft, sharp (large mu)
    PhysicalScale(R=1e-6, dg=1.0, E0_star=1e11, h0=3e-10),  # stiff, small (mu < 1)
]


def test_dimensionless_functions_of_mu():
    mu = 3.24
    assert units.h0_hat(mu) == pytest.approx(1.0 / (math.pi ** (2 / 3) * mu), rel=1e-15)
    assert units.sigma0_hat(mu) == pytest.approx(
        16 * mu / (9 * math.sqrt(3) * math.pi ** (1 / 3)), rel=1e-15
    )
    # sigma_0 is the extremum of the LJ law: pre * max_h [(h0/h)^3 - (h0/h)^9] = pre * 2/3^(3/2)
    x = np.linspace(0.3, 1.0, 200001)  # x = h0/h
    assert units.lj_prefactor(mu) * np.max(x**3 - x**9) == pytest.approx(
        units.sigma0_hat(mu), rel=1e-9
    )
    # c_l about 1.693 / mu^2 for alpha = pi/9 (docs/design.md section 2)
    assert units.l0_hat(1.0) == pytest.approx(1.693, abs=5e-4)
    assert units.l0_coefficient() == pytest.approx(243 * 81 / (256 * math.pi**3), rel=1e-14)


@pytest.mark.parametrize("scale", SCALES, ids=lambda s: f"mu={s.mu:.3g}")
def test_physical_scale_consistent_with_mu_functions(scale):
    mu = scale.mu
    # two routes to the same numbers: SI quantity / unit versus the function of mu alone
    assert scale.h0_hat == pytest.approx(units.h0_hat(mu), rel=1e-13)
    assert scale.sigma0 / scale.p_ref == pytest.approx(units.sigma0_hat(mu), rel=1e-13)
    assert scale.l0 / scale.a_ref == pytest.approx(units.l0_hat(mu), rel=1e-13)
    # l0 / h0 = c_l E0* h0 / dg (docs/design.md section 2)
    assert scale.l0 / scale.h0 == pytest.approx(
        units.l0_coefficient() * scale.E0_star * scale.h0 / scale.dg, rel=1e-13
    )
    # unit definitions
    assert scale.d_ref == pytest.approx(
        (math.pi**2 * scale.dg**2 * scale.R / scale.E0_star**2) ** (1 / 3), rel=1e-13
    )
    # traction unit x area unit = load unit, so P_hat = 2 pi int sigma_hat r_hat dr_hat
    assert scale.p_ref * scale.a_ref**2 == pytest.approx(scale.load_ref, rel=1e-13)
    # Hertz in these units: P = 4 E* a^3 / (3 R)  <->  P_hat = 4/3 a_hat^3
    a = 0.7 * scale.a_ref
    assert scale.load_hat(4 * scale.E0_star * a**3 / (3 * scale.R)) == pytest.approx(
        4 / 3 * scale.radius_hat(a) ** 3, rel=1e-13
    )
    assert scale.normal_hat(a**2 / scale.R) == pytest.approx(scale.radius_hat(a) ** 2, rel=1e-13)


@pytest.mark.parametrize("scale", SCALES, ids=lambda s: f"mu={s.mu:.3g}")
def test_round_trips(scale):
    x = np.array([1e-3, 0.5, 2.0, 1e4])
    tau0 = 0.01876
    pairs = [
        (scale.radius_hat, scale.radius_physical),
        (scale.normal_hat, scale.normal_physical),
        (scale.load_hat, scale.load_physical),
        (scale.traction_hat, scale.traction_physical),
        (lambda q: scale.time_hat(q, tau0), lambda q: scale.time_physical(q, tau0)),
        (lambda q: scale.rate_hat(q, tau0), lambda q: scale.rate_physical(q, tau0)),
        (lambda q: scale.crack_speed_hat(q, tau0), lambda q: scale.crack_speed_physical(q, tau0)),
        (lambda q: scale.vhat_pb(q, tau0), lambda q: scale.crack_speed_from_vhat_pb(q, tau0)),
    ]
    for fwd, back in pairs:
        np.testing.assert_allclose(back(fwd(x)), x, rtol=1e-14)
        np.testing.assert_allclose(fwd(back(x)), x, rtol=1e-14)
    mu = scale.mu
    np.testing.assert_allclose(units.rate_from_rhat_pb(units.rhat_pb(x, mu), mu), x, rtol=1e-14)
    np.testing.assert_allclose(
        units.crack_speed_from_vhat(units.vhat_from_crack_speed(x, mu), mu), x, rtol=1e-14
    )
    np.testing.assert_allclose(
        units.delta0_to_h0_units(units.delta0_from_h0_units(x, mu), mu), x, rtol=1e-14
    )


@pytest.mark.parametrize("scale", SCALES, ids=lambda s: f"mu={s.mu:.3g}")
def test_rates_and_speeds_two_routes(scale):
    """The dimensionless-scene conversions (functions of mu) agree with the SI route."""
    tau0, r, v = 0.5, 3e-6, 2e-4  # s, m/s, m/s
    mu = scale.mu
    rate = scale.rate_hat(r, tau0)  # r tau0 / h0
    assert rate == pytest.approx(r * tau0 / scale.h0, rel=1e-15)
    # rhat_PB = r tau0 / d_ref = rate * h0_hat
    assert units.rhat_pb(rate, mu) == pytest.approx(scale.rhat_pb(r, tau0), rel=1e-13)
    assert units.rhat_pb(rate, mu) == pytest.approx(rate / (mu * math.pi ** (2 / 3)), rel=1e-14)
    # the unloading law d delta_hat / dt_hat = -rate * h0_hat is r tau0 / d_ref
    assert rate * scale.h0_hat == pytest.approx(r * tau0 / scale.d_ref, rel=1e-13)
    # vhat = v tau0 / l0 = v_a * a_ref / l0 with v_a in a_ref / tau0
    v_a = scale.crack_speed_hat(v, tau0)
    assert units.vhat_from_crack_speed(v_a, mu) == pytest.approx(scale.vhat_pb(v, tau0), rel=1e-13)
    # an indentation of 5 h0
    assert scale.normal_physical(units.delta0_from_h0_units(5.0, mu)) == pytest.approx(
        5 * scale.h0, rel=1e-13
    )


def test_pdms_numbers_of_the_paper():
    ref = _paper()["pdms_experiment"]
    fit = pdms(30.8e-9)
    quasi = pdms(1.55e-6)
    # E0* = E0 / (1 - nu^2)
    assert fit.E0_star / 1e6 == pytest.approx(ref["E0_star_MPa"], rel=3e-3)
    # l0 = 30.0 nm for h0 = 30.8 nm (computed: 30.03 nm)
    assert fit.l0 * 1e9 == pytest.approx(ref["l0_nm"], rel=0.01)
    # Tabor parameter 2.05 from the quasi-static h0 = 1.55 um (computed: 2.045)
    assert quasi.mu == pytest.approx(ref["tabor_mu_quasistatic"], rel=0.01)
    # l0 / h0 "about 1" for soft polymers
    assert 0.5 < fit.l0 / fit.h0 < 2
    # the paper's discussion: a0t_hat = 30.9 -> about 5.8 mm (computed with a_ref at this R)
    a0t = fit.radius_physical(ref["threshold_radius_estimate"]["a0t_hat"])
    assert a0t * 1e3 == pytest.approx(ref["threshold_radius_estimate"]["a0t_mm"], rel=0.02)


def test_validation_messages():
    with pytest.raises(InputError, match=r"^mu must be > 0"):
        units.h0_hat(0.0)
    with pytest.raises(InputError, match=r"^mu must be a number"):
        units.l0_hat("abc")
    with pytest.raises(InputError, match=r"^nu must be in \[0, 0.5\]"):
        PhysicalScale.from_moduli(R=1, dg=1, E0=1, nu=0.7, h0=1)
    with pytest.raises(InputError, match=r"^R must be > 0"):
        PhysicalScale(R=-1.0, dg=1, E0_star=1, h0=1)
    with pytest.raises(InputError, match=r"^h0 must be a finite number"):
        PhysicalScale(R=1.0, dg=1, E0_star=1, h0=float("nan"))
    with pytest.raises(InputError, match=r"^rate must be >= 0"):
        units.rhat_pb([1.0, -2.0], 3.24)
    with pytest.raises(InputError, match=r"^tau0 must be > 0"):
        SCALES[0].rate_hat(1e-6, 0.0)
