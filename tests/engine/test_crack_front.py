"""Crack-front model: JKR limits in closed form, pinned-edge closed form, rate laws, growth
with the unloading rate, the Result row."""
import math

import numpy as np
import pytest

from sweep import Numerics, Scene
from sweep.engine.crack_front import (
    GentSchultzLaw, constant_gamma_pull_off, crack_front_load, energy_release_rate,
    pb_law_for_scene, simulate_crack, unload,
)
from sweep.engine.models import simulate_model
from sweep.errors import InputError
from sweep.theory import jkr_indentation, jkr_load, jkr_pull_off_point, pb_gamma_eff

XI = 0.4154


def test_elastic_field_is_jkr_on_g_equal_one():
    a = np.linspace(0.5, 6.0, 12)
    d = jkr_indentation(a)
    np.testing.assert_allclose(energy_release_rate(a, d), 1.0, rtol=1e-13)
    np.testing.assert_allclose(crack_front_load(a, d), jkr_load(a), rtol=1e-12, atol=1e-14)


@pytest.fixture(scope="module")
def elastic_run():
    # Gamma(v) = dg (1 + (v/v0)^xi) with v0 = 1e8 a_ref/tau0: rate independent in practice
    return unload(GentSchultzLaw(1e8, XI), rate=10.0, mu=3.24, a0=3.0, stop="separation")


def test_elastic_limit_pull_off_is_jkr_1_5_under_displacement_control(elastic_run):
    s = elastic_run
    assert s.ok
    a_f, p_f, _ = jkr_pull_off_point("force")
    # the load minimum is the load-control JKR point, reached while still stable under grips;
    # the residual rate effect is Gamma - 1 ~ (v/v0)^xi ~ 5e-4
    assert abs(s.gamma_pulloff - 1.0) < 1e-3
    assert s.pull_off == pytest.approx(-p_f * s.gamma_pulloff, rel=1e-5)
    assert s.pull_off == pytest.approx(1.5, abs=1e-3)
    assert s.a_pulloff == pytest.approx(a_f * s.gamma_pulloff ** (1 / 3), rel=1e-4)


def test_elastic_limit_fixed_grip_instability_at_minus_5_6(elastic_run):
    tr = elastic_run.trajectory
    # the contact jumps off where d delta/da = 0, i.e. delta = -3 a^2: a = 1/2, P = -5/6
    s = tr["delta"] + 3.0 * tr["a"] ** 2
    i = int(np.nonzero(s < 0)[0][0])
    f = s[i - 1] / (s[i - 1] - s[i])
    a_i = tr["a"][i - 1] + f * (tr["a"][i] - tr["a"][i - 1])
    p_i = tr["P"][i - 1] + f * (tr["P"][i] - tr["P"][i - 1])
    a_g, p_g, d_g = jkr_pull_off_point("displacement")
    assert (a_g, p_g) == (0.5, pytest.approx(-5.0 / 6.0))
    assert a_i == pytest.approx(a_g, rel=3e-3)
    assert p_i == pytest.approx(p_g, rel=3e-3)
    # the pull-off (largest tension) is NOT this load: 1.5 > 5/6
    assert elastic_run.pull_off > -p_g + 0.6


@pytest.mark.parametrize("c, a0", [(2.0, 2.0), (2.0, 1.0), (1.0, 0.8), (5.0, 0.9)])
def test_constant_gamma_closed_form(c, a0):
    # Gamma = c dg at any speed (v0 -> inf): pinned until g = c, then the JKR curve of c dg
    s = unload(GentSchultzLaw(1e9, XI, c=c), rate=10.0, mu=3.24, a0=a0)
    assert s.ok
    assert s.pull_off == pytest.approx(constant_gamma_pull_off(a0, c), rel=2e-3)


def test_constant_gamma_closed_form_branches():
    c = 3.0
    a_star = 1.0400419115259522 * c ** (1 / 3)
    assert constant_gamma_pull_off(2 * a_star, c) == 4.5
    # continuous at the switch (the depinning load equals 1.5 c there)
    assert constant_gamma_pull_off(a_star * (1 - 1e-9), c) == pytest.approx(4.5, rel=1e-9)
    with pytest.raises(InputError, match="c must be >= 1"):
        constant_gamma_pull_off(1.0, 0.5)


def test_integration_converges_with_tolerance():
    law = GentSchultzLaw(1.0, XI)
    p = [unload(law, rate=100.0, mu=3.24, a0=3.0, rtol=r).pull_off for r in (1e-6, 1e-10)]
    assert p[0] == pytest.approx(p[1], rel=1e-5)


def test_pb_law_inverts_gamma():
    law = pb_law_for_scene(0.8, 0.1, 3.24)
    g = np.array([1.0 + 1e-9, 1.0001, 1.01, 1.5, 3.0, 9.0, 9.99])
    v, dv = law.speed(g)
    np.testing.assert_allclose(law.gamma(v), g, rtol=1e-6)
    # slope: dV/dg against a centred difference of the same interpolant
    h = 1e-6 * g
    vp, vm = law.speed(g + h)[0], law.speed(g - h)[0]
    np.testing.assert_allclose(dv[1:], ((vp - vm) / (2 * h))[1:], rtol=1e-3)
    assert law.speed(0.9)[0] == 0.0


def test_pull_off_grows_with_rate_between_the_limits():
    law = pb_law_for_scene(0.8, 0.1, 3.24)
    rates = np.logspace(-3, 7, 11)
    p = np.array([unload(law, rate=r, mu=3.24, a0=3.61).pull_off for r in rates])
    assert np.all(np.diff(p) > 0)
    assert p[0] == pytest.approx(1.5, rel=5e-3)         # relaxed JKR
    assert p[-1] == pytest.approx(1.5 / 0.1, rel=5e-3)  # glassy: 1.5/k (a0 > 1.04 k^(-1/3))


def test_pull_off_at_pb_speed_matches_jkr_with_that_gamma():
    # a large contact is quasi-steady: P_po = 1.5 Gamma(v_po) (load-control JKR with Gamma)
    law = pb_law_for_scene(0.8, 0.1, 3.24)
    s = unload(law, rate=100.0, mu=3.24, a0=8.0)
    assert s.gamma_pulloff == pytest.approx(float(law.gamma(s.crack_speed)), rel=1e-6)
    assert s.pull_off == pytest.approx(1.5 * s.gamma_pulloff, rel=0.05)


def test_simulate_crack_gives_a_result_row():
    sc = Scene(n=0.8, k=0.1, mu=3.24, a0=3.61, rate=316.227766)
    res = simulate_crack(sc)
    assert res.ok and res.reason == ""
    assert res.pull_off > 1.5
    assert res.vhat == pytest.approx(res.crack_speed / (1.693 / 3.24**2), rel=2e-3)
    row = res.to_row()
    assert row["scene_id"] == res.scene_id and math.isnan(row["a_inner_pulloff"])
    assert set(res.trajectory) == {"t", "delta", "P", "a", "a_inner"}
    assert float(pb_gamma_eff(0.8, 0.1, res.vhat)) > 1.0


def test_bad_input():
    with pytest.raises(InputError, match="a0 must be >= 0.5"):
        unload(GentSchultzLaw(1.0, XI), rate=1.0, mu=3.0, a0=0.3)
    with pytest.raises(InputError, match="give exactly one of a0"):
        unload(GentSchultzLaw(1.0, XI), rate=1.0, mu=3.0)
    with pytest.raises(InputError, match="v0 must be > 0"):
        GentSchultzLaw(0.0, XI)


# -- the extremes: never an ok row with a compressive "pull-off" (issue 21 item 5) ------------
@pytest.mark.parametrize("kw", [
    dict(n=0.05, k=0.999, mu=10.0, a0=15.0, rate=1e-4),    # was ok with pull-off -1203
    dict(n=2.5, k=0.999, mu=100.0, a0=15.0, rate=1e9),     # was ok with pull-off -4336
    dict(n=0.05, k=0.98, mu=10.0, a0=15.0, rate=1e-4),     # stepped over the minimum: 1.452
    dict(n=0.05, k=0.9, mu=10.0, a0=15.0, rate=1e9),
    dict(n=2.5, k=0.9, mu=100.0, a0=15.0, rate=1e-4),
])
def test_pull_off_is_tensile_and_within_the_jkr_bounds(kw):
    """From a large contact the pull-off lies between the JKR values of the relaxed and the
    glassy work of adhesion, 1.5 and 1.5/k (to the event's 1e-3); a nearly elastic law
    (1/k - 1 <= NEARLY_ELASTIC) is the closed form at Gamma = dg/sqrt(k), whose error
    estimate is its bound, 1/sqrt(k) - 1."""
    from sweep.engine.crack_front import NEARLY_ELASTIC

    res = simulate_crack(Scene(**kw), Numerics.preset("balanced", time_budget_s=30.0))
    assert res.ok, res.reason
    assert 1.5 * (1 - 1e-3) <= res.pull_off <= 1.5 / kw["k"] * (1 + 1e-3), res.pull_off
    if 1 / kw["k"] - 1 <= NEARLY_ELASTIC:
        assert res.pull_off == pytest.approx(1.5 / math.sqrt(kw["k"]), rel=1e-12)
        assert res.error_estimate == pytest.approx(1 / math.sqrt(kw["k"]) - 1, rel=1e-12)


def test_the_integrator_keeps_the_time_budget():
    from sweep.engine.crack_front import PerssonBrenerLaw, unload
    from sweep.units import l0_hat

    law = PerssonBrenerLaw(2.5, 0.93, l0_hat(100.0), "mpl")
    sol = unload(law, rate=1e9, mu=100.0, a0=3.0, time_budget_s=1e-6)
    assert sol.status == "failed" and sol.reason.startswith("time budget")


def test_a_frozen_contact_opens_within_the_time_span():
    """Unloaded far faster than the crack runs (rate 1.44e9, k = 3e-4), the contact opens
    only where g nears g_max = 1/k: the integration span reaches that indentation (it ended
    before, 'no load minimum'); the pull-off lies between 1.5 and the glassy 2/k."""
    res = simulate_crack(Scene(n=3.55, k=0.000302, mu=13.72, a0=0.911, rate=1.44e9))
    assert res.ok, res.reason
    assert 1.5 < res.pull_off < 2 / 0.000302


@pytest.mark.parametrize("rate", [1e-2, 1.0, 1e4])
def test_radau_on_lapack_directly_is_radau_on_scipy_linalg(monkeypatch, rate):
    """unload gives Radau LAPACK's getrf/getrs directly (crack_front._lapack_lu,
    _lapack_solve), as scipy.linalg.lu_factor and lu_solve call them, without their per-call
    overhead: the same solution to the last bit (the same routines on the same numbers)."""
    from scipy.linalg import lu_factor, lu_solve

    from sweep.engine import crack_front

    law = pb_law_for_scene(0.3, 1e-3, 50.0)
    fast = unload(law, rate=rate, mu=50.0, a0=1.75)
    monkeypatch.setattr(crack_front, "_lapack_lu", lambda A: lu_factor(A, overwrite_a=True))
    monkeypatch.setattr(crack_front, "_lapack_solve",
                        lambda factors, b: lu_solve(factors, b, overwrite_b=True))
    plain = unload(law, rate=rate, mu=50.0, a0=1.75)
    assert fast.ok and plain.ok
    assert fast.pull_off == plain.pull_off and fast.crack_speed == plain.crack_speed
    np.testing.assert_array_equal(fast.trajectory["a"], plain.trajectory["a"])


def test_the_lapack_lu_refuses_what_scipy_refuses():
    """A non-finite matrix or right-hand side raises scipy's ValueError (the integrator
    reports it as its failure), and the solve is the 1 x 1 system's (real and complex)."""
    from sweep.engine.crack_front import _lapack_lu, _lapack_solve

    with pytest.raises(ValueError, match="infs or NaNs"):
        _lapack_lu(np.array([[np.inf]]))
    factors = _lapack_lu(np.array([[4.0]]))
    with pytest.raises(ValueError, match="infs or NaNs"):
        _lapack_solve(factors, np.array([np.nan]))
    assert _lapack_solve(factors, np.array([2.0]))[0] == 0.5
    z = _lapack_solve(_lapack_lu(np.array([[2.0 + 2.0j]])), np.array([4.0 + 0.0j]))
    assert z[0] == pytest.approx(1.0 - 1.0j, rel=1e-15)


@pytest.mark.parametrize("a0, rate", [(2.0, 10.0), (1.0, 0.01), (2.0, 1e4)])
def test_a_run_to_separation_ends_where_the_edge_runs_away(a0, rate):
    """Past the pull-off under fixed grip, g grows as the contact shrinks; the Persson-Brener
    law's Gamma(v)/dg is bounded by the glassy 1/k, and beyond it no crack speed balances g:
    the integrator finds no step (it failed the row with SciPy's message). The row is the
    pull-off run's, followed to where g reaches 1/k (independent value: the law's bound)."""
    scene = dict(n=0.8, k=0.1, mu=3.24, a0=a0, rate=rate, model="crack")
    pulloff = simulate_model(Scene(**scene), "crack")
    res = simulate_model(Scene(**scene, stop="separation"), "crack")
    assert pulloff.ok and res.ok, res.reason
    assert res.pull_off == pulloff.pull_off
    a, d = res.trajectory["a"], res.trajectory["delta"]
    assert a[-1] < res.a_pulloff
    if "runs away" in res.reason:
        assert energy_release_rate(a[-1], d[-1]) == pytest.approx(1.0 / 0.1, rel=1e-3)
    else:                                   # followed to the run's end, a = 0.02 a0
        assert a[-1] == pytest.approx(0.02 * a0, rel=1e-9)


def test_a_nearly_elastic_run_to_separation_ends_at_the_fixed_grip_instability():
    """k = 1 (the closed form at the constant Gamma = dg): a run to separation had no
    trajectory at all. Independent value: JKR under fixed grip jumps off at a = 1/2, P = -5/6
    (Maugis), past the largest tension, the load-control pull-off 3/2."""
    res = simulate_model(Scene(n=0.8, k=1.0, mu=3.24, a0=2.0, rate=10.0, stop="separation"),
                         "crack")
    assert res.ok, res.reason
    tr = res.trajectory
    assert tr["a"][-1] == pytest.approx(0.5, rel=1e-12)
    assert tr["P"][-1] == pytest.approx(-5.0 / 6.0, rel=1e-12)
    assert -tr["P"].min() == pytest.approx(res.pull_off, rel=1e-4)   # sampled near 3/2
    assert res.pull_off == pytest.approx(1.5, rel=1e-12)
    assert np.all(np.diff(tr["t"]) >= 0.0) and tr["a"][0] == 2.0


@pytest.mark.parametrize("rate", [1e-20, 1e-30, 1e-60])
def test_an_unloading_too_slow_for_gamma_to_rise_is_the_relaxed_limit(rate):
    """Below rate ~1e-11 Gamma(v)/dg - 1 at the pull-off's crack speed is below 1e-10, and the
    integrator's g - 1 drowned in g's rounding: the edge stayed pinned below rate ~1e-29 (the
    time budget spent) or the integrator found no step. Independent value: the JKR pull-off
    at Gamma = dg, 3/2 (the rate-1e-8 integration gives 1.5000003)."""
    res = simulate_crack(Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=rate, model="crack"),
                         Numerics.preset("balanced", time_budget_s=30))
    assert res.ok, res.reason
    assert res.pull_off == pytest.approx(1.5, rel=1e-12)
    assert res.reason.startswith("the relaxed limit") and res.error_estimate <= 1e-10
    integrated = simulate_crack(Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=1e-8, model="crack"))
    assert integrated.ok and "relaxed limit" not in integrated.reason
    assert integrated.pull_off == pytest.approx(1.5, rel=1e-6)
