"""The hereditary BEM on the DMT side (mu down to 0.01): mesh from the tip zone and the LJ tail.

Independent values: the elastic quasi-static branch (sweep.engine.quasistatic, its own mesh, the
LJ tail beyond the mesh in closed form) for k = 1 and for very slow rates (the relaxed
elastic limit); the physical bounds of a viscoelastic pull-off at any rate.
"""
import math

import pytest

from sweep import units
from sweep import Numerics, Scene
from sweep.engine.bem import simulate  # the BEM on the graded mesh (not the model dispatch)
from sweep.engine import quasistatic as qs
from sweep.engine.problem import prepare, tip_zone


def test_tip_zone_is_the_process_zone_on_the_jkr_side_and_sqrt_h0_on_the_dmt_side():
    assert tip_zone(10.0) == units.l0_hat(10.0)
    assert tip_zone(3.24) == units.l0_hat(3.24)
    assert tip_zone(0.1) == pytest.approx(math.sqrt(units.h0_hat(0.1)))
    cross = 1.83
    assert tip_zone(cross) == pytest.approx(units.l0_hat(cross), rel=0.01)
    assert tip_zone(cross) == pytest.approx(math.sqrt(units.h0_hat(cross)), rel=0.01)


def test_low_mu_mesh_reaches_the_lj_tail_and_resolves_the_contact():
    """At mu = 0.01 (h0 = 47 d_ref) the mesh reaches the radius where the rigid gap is
    tail_gap h0, and the pull-off radius, about sqrt(2 (3^(1/6) - 1) h0), spans several
    fine spacings."""
    num = Numerics.preset("balanced")
    pb = prepare(Scene(n=0.8, k=0.5, mu=0.01, a0=2.0, rate=1.0), num)
    h0 = units.h0_hat(0.01)
    assert pb.mesh.domain >= math.sqrt(2 * num.tail_gap * h0)
    assert qs.pull_off_radius_guess(0.01) / pb.mesh.spacing > 5
    assert pb.mesh.nodes < 200


@pytest.mark.parametrize("mu,a0", [(0.01, 8.0), (0.1, 2.0), (0.3, 2.0)])
def test_elastic_bem_matches_the_quasi_static_branch_at_low_mu(mu, a0):
    """k = 1 through the hereditary BEM (fixed band): the quasi-static pull-off from the
    same a0 to 1e-3 (the BEM truncates the LJ tail at tail_gap h0: (1/60)^2 of the force)."""
    res = simulate(Scene(n=0.8, k=1.0, mu=mu, a0=a0, rate=1.0))
    ref = qs.elastic_pull_off(mu, a_start=a0)
    assert res.ok, res.reason
    assert res.pull_off == pytest.approx(ref.pull_off, rel=1e-3)


@pytest.mark.parametrize("mu", [0.01, 0.1])
def test_viscoelastic_low_mu_between_the_relaxed_limit_and_2_over_k(mu):
    """Very slow unloading gives the relaxed elastic value; faster ones more, never above
    2/k; a0 = 8 at k = 0.1."""
    k, a0 = 0.1, 8.0
    relaxed = qs.elastic_pull_off(mu, a_start=a0).pull_off
    slow = simulate(Scene(n=0.8, k=k, mu=mu, a0=a0, rate=1e-4))
    assert slow.ok and slow.pull_off == pytest.approx(relaxed, rel=1e-3)
    for rate in (1.0, 1e4):
        res = simulate(Scene(n=0.8, k=k, mu=mu, a0=a0, rate=rate))
        assert res.ok, res.reason
        assert relaxed * (1 - 1e-3) < res.pull_off < 2.0 / k


@pytest.mark.parametrize("a0", [0.5, 0.5016, 0.505])
def test_initial_radius_at_the_jkr_fold(a0):
    """The radius search starts from the JKR branch, whose d delta/da vanishes at a = 1/2:
    at mu = 0.033 a0 = 0.500-0.505 failed 'could not reach the initial contact radius' (a
    random sample's scene) while 0.49 and 0.51 ran; the pull-off lies between theirs."""
    from sweep import Numerics, Scene
    from sweep.engine.models import simulate

    kw = dict(n=0.1913, k=0.002652, mu=0.03253, rate=0.0003383)
    num = Numerics.preset("balanced")
    res, lo, hi = (simulate(Scene(**kw, a0=a), num) for a in (a0, 0.49, 0.51))
    assert res.ok and lo.ok and hi.ok, res.reason
    assert res.a0_result == pytest.approx(a0, rel=1e-9)
    assert lo.pull_off < res.pull_off < hi.pull_off
