"""The single-scene BEM solver against independent values, limits and the paper's trends.

Reference values: tests/data/independent_solutions.yaml (an independent solver with
the exact hereditary integral, N = 1000..2000). Tolerances reflect OUR discretization
(N = 500 on the automatic domain, spacing ~0.012): measured differences are < 0.1 %.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from tests import naive, reference
from sweep import Numerics, Scene
from sweep.engine.bem import simulate  # the BEM on the graded mesh (not the model dispatch)
from sweep.errors import InputError
from sweep.theory import jkr_load

def _ref():
    return reference.independent_solutions()


def elastic(mu, a0=2.0, **num):
    # compared with independent values: the error estimate's second solve is skipped
    num = {"nodes": 1000, "domain": 5.0, "step": 0.05, "tol": 1e-9, "pull_off_rtol": 0.0, **num}
    return simulate(Scene(n=1.0, k=1.0, mu=mu, a0=a0, rate=1.0), Numerics(**num))


@pytest.mark.parametrize("case", [0, pytest.param(1, marks=pytest.mark.slow)])
def test_elastic_pull_off_matches_independent_solver(case):
    # case 1 (mu = 6): at spacing 0.005 the crack tip snaps node to node (hundreds of folds,
    # each found by the snap search): minutes, hence slow. Measured at N = 1000: 1.52267
    # (yaml 1.5225); converged (N = 1500, 2000): 1.5199, 1.5198 -- the yaml's N = 1000 value
    # is itself about 2.5e-3 above the mesh limit.
    ref = _ref()["elastic"][case]
    # the same mesh as the reference solver: N = 1000, spacing 0.005 (domain 5), and as it
    # without the Lennard-Jones attraction beyond the mesh (Numerics.lj_tail)
    res = elastic(ref["mu"], lj_tail=False)
    assert res.ok, res.reason
    assert res.pull_off == pytest.approx(ref["pull_off"], abs=ref["tol"])


def test_elastic_curve_approaches_jkr_as_mu_grows():
    # the max-tension radius tends to the JKR contact edge: distance of P(a) from JKR shrinks
    errs = []
    for mu in (1.5, 2.5, 3.5):      # snap-free at spacing 0.005 (mu = 6 needs < 0.004)
        res = elastic(mu, nodes=800, domain=4.0)
        assert res.ok, res.reason
        tr = res.trajectory
        sel = (tr["a"] > 1.1) & (tr["a"] < 1.9)
        errs.append(np.max(np.abs(tr["P"][sel] - jkr_load(tr["a"][sel]))))
    # the LJ curve departs from JKR by O(1/mu): errs * mu is nearly constant (0.64 measured)
    assert errs[0] > errs[1] > errs[2]
    scaled = np.array(errs) * np.array([1.5, 2.5, 3.5])
    assert np.ptp(scaled) < 0.1 * scaled.mean()


def test_elastic_pull_off_converges_with_mesh():
    # pull-off at mu = 3.24 on the reference domain: differences shrink with N
    p = [elastic(3.24, nodes=n).pull_off for n in (250, 500, 1000)]
    assert abs(p[1] - p[2]) < abs(p[0] - p[2])
    assert abs(p[1] - p[2]) < 3e-4


#: Pull-off error of the balanced preset against the independent solver that the README
#: states (table "Speed and accuracy": -0.02 % / +0.002 % / -0.09 %; measured -2.2e-4,
#: +2.2e-5, -8.9e-4). The tolerance is twice that claim: the margin covers the yaml's own
#: quoted uncertainty (A 6e-4, D 1e-4, F 9e-4 absolute, i.e. 7.7e-5, 6.8e-6, 3.7e-4
#: relative, each below the claim) and rounding across platforms.
BALANCED_CLAIM = {"A": 2e-4, "D": 2e-5, "F": 9e-4}


@pytest.mark.parametrize("name", ["A", "D", "F"])
def test_viscoelastic_matches_independent_solver(name):
    ref = next(c for c in _ref()["viscoelastic"] if c["name"] == name)
    # like for like: the reference drops the Lennard-Jones attraction beyond its mesh, so the
    # engine drops it too (Numerics.lj_tail; with it A / D / F move by +2.2e-5 / +1.8e-5 /
    # +9.6e-5 relative, session 49)
    res = simulate(Scene(**ref["scene"]), Numerics.preset("balanced", lj_tail=False))
    assert res.ok, res.reason
    assert res.pull_off == pytest.approx(ref["pull_off"], rel=2 * BALANCED_CLAIM[name])
    assert res.a0_result == pytest.approx(ref["a0"], abs=0.01)
    # the yaml quotes a_pulloff to 3 decimals; measured within 2.2e-3 (case D)
    assert res.a_pulloff == pytest.approx(ref["a_pulloff"], abs=5e-3)
    assert res.crack_speed == pytest.approx(ref["crack_speed"], rel=0.05)   # +-5% (yaml)
    assert res.delta0_result == ref["scene"]["delta0"]


@pytest.mark.parametrize("n, rate", [(0.4, 3.16), (1.6, 316.2)])
def test_prony_matches_exact_convolution(n, rate):
    # same step sequence (da_max off), default Prony tolerance of the balanced preset; two
    # time integrators on the same coarse mesh (the mesh error estimate is off). 90 nodes:
    # on 100 and 120 the n = 1.6 scene's jump-off, 3 steps after the pull-off, finds no
    # equilibrium for the Prony run since the zone Newton of session 17 (the old Woodbury
    # Newton converged there by another path; both agree to every printed digit up to it)
    scene = Scene(n=n, k=0.1, mu=3.24, a0=2.0, rate=rate)
    num = dict(nodes=90, step=0.2, da_max=1e6, tol=1e-9, pull_off_rtol=0.0)
    prony = simulate(scene, Numerics(**num, prony_rtol=1e-4))
    exact = simulate(scene, Numerics(**num, exact=True))
    assert prony.ok and exact.ok
    assert prony.steps == exact.steps
    assert prony.pull_off == pytest.approx(exact.pull_off, rel=2e-3)
    assert exact.prony_terms == 0 and prony.prony_terms > 0
    # every row states its error: the exact reference's says it has no estimate
    assert "exact hereditary reference: no error estimate" in exact.reason
    assert math.isnan(exact.error_estimate)


def test_prony_error_shrinks_with_rtol():
    scene = Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=100.0)
    num = dict(nodes=100, step=0.2, da_max=1e6, tol=1e-9, pull_off_rtol=0.0)
    exact = simulate(scene, Numerics(**num, exact=True)).pull_off
    errs = [abs(simulate(scene, Numerics(**num, prony_rtol=r)).pull_off / exact - 1)
            for r in (1e-2, 1e-6)]
    assert errs[1] < errs[0]
    assert errs[1] < 1e-5


def fast(**scene):
    return simulate(Scene(**{"n": 0.8, "k": 0.1, "mu": 3.24, **scene}), Numerics.preset("fast"))


def test_pull_off_grows_with_rate():
    p = [fast(a0=3.0, rate=r).pull_off for r in (1.0, 100.0, 1e4)]
    assert p[0] < p[1] < p[2]


def test_pull_off_grows_with_initial_contact_radius():
    p = [fast(n=1.6, a0=a0, rate=316.2).pull_off for a0 in (1.71, 2.47, 3.61)]
    assert p[0] < p[1] < p[2]


def test_pull_off_grows_with_n_at_fixed_rate():
    p = [fast(n=n, a0=3.61, rate=10**2.5).pull_off for n in (0.6, 0.8, 1.6)]
    assert p[0] < p[1] < p[2]


def test_slow_unloading_and_k_to_one_give_the_elastic_result():
    el = fast(k=1.0, a0=2.0, rate=1.0).pull_off
    assert fast(a0=2.0, rate=1e-4).pull_off == pytest.approx(el, rel=2e-3)
    assert fast(k=0.999, a0=2.0, rate=100.0).pull_off == pytest.approx(el, rel=2e-3)


def test_fast_unloading_reaches_the_glassy_limit():
    # rate -> infinity: the unloading takes ~1e-6 tau0, Chat stays at k, and the substrate
    # answers u = A [k sigma + (1 - k) sigma_0] whatever the spectrum. The limit is therefore
    # material independent: SLS, MPL n = 1.6 and MPL n = 3 agree to 2e-7 at rate 1e10
    # (14.71333). At rate 1e8 the MPL n = 1.6 creeps by about (1-k) t/(n-1) ~ 1e-6 during
    # the unloading: measured 14.71235, 7e-5 below the limit; tolerance 2e-4.
    # Balanced numerics: the fast preset's coarse steps differ by 2e-4 between the two
    # histories (within its 3 % pull_off_rtol, but not a test of the limit).
    balanced = Numerics.preset("balanced")
    limit = simulate(Scene(n=1.0, k=0.1, mu=3.24, a0=3.0, rate=1e10, material="sls"), balanced)
    res = simulate(Scene(n=1.6, k=0.1, mu=3.24, a0=3.0, rate=1e8), balanced)
    assert res.ok and limit.ok
    assert res.pull_off == pytest.approx(limit.pull_off, rel=2e-4)
    # and below the JKR value with the glassy work of adhesion, 1.5/k (measured 14.71)
    assert res.pull_off < 1.5 / 0.1


def test_results_are_consistent():
    res = fast(a0=2.5, rate=31.6)
    tr = res.trajectory
    assert res.ok
    assert set(tr) == {"t", "delta", "P", "a", "a_inner"}
    assert np.all(np.diff(tr["t"]) > 0) and np.all(np.diff(tr["delta"]) < 0)
    assert res.pull_off == pytest.approx(-tr["P"].min(), rel=1e-3)
    assert res.a_inner_pulloff < res.a_pulloff          # a_inner lies inside the edge
    assert res.vhat == pytest.approx(res.crack_speed * 3.24**2 * math.pi ** (1 / 3)
                                     / (243 / (256 * math.pi * (math.pi / 9) ** 2)), rel=1e-12)
    assert res.steps == len(tr["t"]) - 1
    assert res.a0_result == pytest.approx(2.5, abs=1e-8)


def test_separation_mode_follows_the_curve_past_pull_off():
    po = fast(a0=2.0, rate=10.0)
    sep = simulate(Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=10.0, stop="separation"),
                   Numerics.preset("fast"))
    assert sep.ok
    assert sep.pull_off == pytest.approx(po.pull_off, rel=1e-9)
    assert sep.trajectory["a"][-1] < 0.5 * po.a_pulloff


def test_sls_material():
    res = simulate(Scene(n=1.0, k=0.1, mu=3.24, a0=2.0, rate=10.0, material="sls"),
                   Numerics.preset("fast"))
    assert res.ok and res.prony_terms == 1


@pytest.mark.parametrize("rate", [1.0, 10.0])
def test_sls_pull_off_matches_naive_solver(rate):
    # tests/naive.py (dense quadrature matrix, exact hereditary sum) on the same small mesh
    # (mu = 1, N = 80, spacing 0.05, the paper's full last triangle, the Lennard-Jones tail
    # beyond it in the load) and the same steps. The SLS is one Prony mode, represented
    # exactly, so both solve the same discrete equations:
    # measured differences 5e-12 (pull-off) and 4e-11 (radius); tolerance 1e-8 (Newton 1e-10).
    N, dr, step, d0 = 80, 0.05, 0.1, 2.0
    ref = naive.naive_unload(1.0, 0.1, 1.0, d0, rate, N, dr, step, material="sls", tail="full",
                             lj_tail=True)
    res = simulate(Scene(n=1.0, k=0.1, mu=1.0, delta0=d0, rate=rate, material="sls"),
                   Numerics(nodes=N, domain=(N - 1) * dr, step=step, da_max=1e6, tol=1e-10))
    assert res.ok, res.reason
    assert not ref["snaps"]
    assert res.pull_off == pytest.approx(ref["pull_off"], rel=1e-8)
    assert res.a_pulloff == pytest.approx(ref["a_pulloff"], abs=1e-8)


EXTREMES = [
    dict(n=0.1, k=1e-4, rate=1e8, a0=1.0, mu=1.0),
    dict(n=2.0, k=1e-4, rate=1e8, a0=10.0, mu=1.0),
    dict(n=0.1, k=0.99, rate=1e-3, a0=10.0, mu=1.0),
    dict(n=2.0, k=1e-4, rate=1e-3, a0=1.0, mu=10.0),
    dict(n=2.0, k=1e-4, rate=1e8, a0=1.0, mu=10.0),
    dict(n=0.1, k=0.99, rate=1e8, a0=10.0, mu=10.0),
]


@pytest.mark.parametrize("scene", EXTREMES)
def test_extremes_finish_with_a_finite_result_or_a_clear_failure(scene):
    res = fast(**scene)
    if res.ok:
        assert np.isfinite(res.pull_off) and res.pull_off > 0
        assert np.isfinite(res.crack_speed) and np.isfinite(res.a_pulloff)
        assert all(np.all(np.isfinite(v)) for v in res.trajectory.values())
    else:
        assert res.reason and "nan" not in res.reason.lower()


def test_under_resolved_mesh_is_refused_with_advice():
    # uniform mesh: l0 = 0.017 at mu = 10 spans < 2 spacings of 300 nodes on the domain
    scene = Scene(n=2, k=1e-4, rate=1e-3, a0=10, mu=10)
    res = simulate(scene, Numerics.preset("fast", mesh="uniform", nodes=300))
    assert res.status == "failed" and "use nodes >=" in res.reason
    # graded mesh: the crack band from 3 to 10.5 a_ref needs ~4000 nodes at l0/9 (> 400)
    res = simulate(scene, Numerics.preset("fast"))
    assert res.status == "failed" and "max_nodes" in res.reason


@pytest.mark.parametrize("kwargs, name", [
    (dict(n=-1, a0=2, rate=1), "n"), (dict(n=1, k=0, a0=2, rate=1), "k"),
    (dict(n=1, k=1.5, a0=2, rate=1), "k"), (dict(n=1, a0=2, rate=float("nan")), "rate"),
    (dict(n=1, rate=1), "a0/delta0"), (dict(n=1, a0=2, delta0=3, rate=1), "a0/delta0"),
    (dict(n=1, a0=2, rate=1, material="foo"), "material"),
])
def test_bad_scene_input_names_the_parameter(kwargs, name):
    with pytest.raises(InputError, match=name):
        Scene(**kwargs)


@pytest.mark.parametrize("kwargs, name", [
    (dict(nodes=5), "nodes"), (dict(nodes=10.5), "nodes"), (dict(step=-1), "step"),
    (dict(prony_rtol=1.0), "prony_rtol"), (dict(exact="yes"), "exact"),
])
def test_bad_numerics_input_names_the_parameter(kwargs, name):
    with pytest.raises(InputError, match=name):
        Numerics(**kwargs)


def test_presets_and_unknown_preset():
    assert Numerics.preset("fast").band_resolution < Numerics.preset("accurate").band_resolution
    with pytest.raises(InputError, match="preset"):
        Numerics.preset("turbo")


def test_a_run_past_its_prony_window_fails_where_the_series_is_not_the_material():
    """``check_prony_window``: the material's closed-form creep compliance beyond the window
    is the independent value. A series fitted to 1e-2 tau0 is 10-40 % off the MPL's at 1-10
    tau0 (n 0.8, k 0.1), and a run that reached 10 tau0 on it fails with the reason; the
    series fitted on the scene's own window, which the MPL has crept past at 1e6 tau0, is
    within its tolerance there, and the row stays ok."""
    import dataclasses

    from sweep import Result
    from sweep.engine.bem import check_prony_window
    from sweep.engine.problem import prepare, prony_series

    scene = Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=1.0)
    num = Numerics.preset("balanced")
    pb = prepare(scene, num)
    short = prony_series("mpl", 0.8, 0.1, 1e-4, 1e-2, num.prony_rtol)
    cut = dataclasses.replace(pb, prony_weights=short.weights, prony_times=short.times,
                              prony_t_max=1e-2)

    def row(t_end):
        res = Result(scene=scene, numerics=num)
        res.status, res.pull_off, res.error_estimate = "ok", 1.0, 1e-3
        res.trajectory = {"t": np.array([0.0, t_end])}
        return res

    far = row(10.0)
    check_prony_window(cut, far)
    assert far.status == "failed" and "past the window its Prony series" in far.reason
    assert math.isnan(far.error_estimate)
    relaxed = row(1e6)
    assert pb.prony_t_max < 1e6
    check_prony_window(pb, relaxed)
    assert relaxed.status == "ok" and relaxed.error_estimate == 1e-3


def test_the_lennard_jones_tail_beyond_the_mesh_is_in_the_load():
    # the relaxed limit (rate 1e-6: the elastic pull-off of the relaxed modulus) at the
    # accurate preset against the quasi-static elastic branch at fine resolution (its own
    # mesh and solver; converged 1.54622, an independent solver 1.54622). Without the
    # attraction beyond the mesh edge the BEM gave 1.545805 (tail_gap 60) and 1.546238
    # (tail_gap 600): low by about (1/tail_gap)^2, 2.8e-4 apart; with it both agree with
    # the branch within the row's own estimate, and the domain no longer moves the pull-off
    from sweep.engine.quasistatic import elastic_pull_off
    scene = Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=1e-6)
    ref = elastic_pull_off(3.24, a_start=2.0, zone_resolution=64, coarse=0.0025)
    assert ref.converged
    assert ref.pull_off == pytest.approx(1.5462247, abs=2e-7)
    near = simulate(scene, Numerics.preset("accurate"))
    far = simulate(scene, Numerics.preset("accurate", tail_gap=600.0))
    for res in (near, far):
        assert res.status == "ok", res.reason
        assert abs(res.pull_off / ref.pull_off - 1.0) <= res.error_estimate
    assert abs(far.pull_off / near.pull_off - 1.0) <= 2e-5
    # lj_tail False: the truncated model, bitwise what the BEM computed before the tail
    # (1.5458048848394892, main 474f0b5), for references that drop the tail too
    truncated = simulate(scene, Numerics.preset("accurate", lj_tail=False))
    assert truncated.pull_off == pytest.approx(1.5458048848394892, rel=1e-12)


# ------------------------------------------------------------------ the recursion's ringing

def test_the_recursions_amplification_is_the_trapezoids_for_an_sls():
    """One SLS mode, Chat = 1 - (1 - k) exp(-t): the traction relaxes in tau_R = k, and the
    recursion's step carries an error by about the trapezoid's (1 - x/2)/(1 + x/2), x =
    dt/tau_R (the exact exponentials of b_i make it differ by less than 0.02), its other
    eigenvalue 0: the most negative of the two is min(factor, 0)."""
    from sweep.engine.bem import ringing_amplification

    for k in (3e-4, 3e-3, 0.1):
        for dt in (1e-3, 1e-2):                 # dt << tau: b = 1 - dt/2, the trapezoid's
            x = dt / k
            trapezoid = min((1 - x / 2) / (1 + x / 2), 0.0)   # the other eigenvalue is 0
            got = ringing_amplification([1 - k], [1.0], dt)
            assert abs(got - trapezoid) < 0.02, (k, dt, got, trapezoid)
        # any dt: the recursion itself, iterated at a fixed displacement from a traction
        # error, settles to that factor a step (power iteration)
        dt = 0.1
        e, b = math.exp(-dt), -math.expm1(-dt) / dt
        c, ceff = 1 - k, 1 - (1 - k) * b
        sigma, q, ratio = 1.0, 0.0, 0.0
        for _ in range(400):
            new = c * (e * q - b * sigma) / ceff
            q = e * q + b * (new - sigma)
            ratio, sigma = new / sigma, new
            if abs(sigma) < 1e-200:
                break
        assert abs(ringing_amplification([1 - k], [1.0], dt) - min(ratio, 0.0)) < 1e-6, (k, ratio)
    assert ringing_amplification([], [], 0.1) == 1.0


def test_a_stiffly_relaxing_start_does_not_ring_into_a_false_pull_off(monkeypatch):
    """An SLS of k 2.9e-4 relaxes its traction in 3e-4 tau0, and the recursion rang at the
    accurate preset's steps (factor -0.96): the load alternated step by step after the
    start, and the stop rule took the first dip for the pull-off, `ok` at 0.55 where the
    pull-off is 4.18 (session 51). With the lead-in the load falls smoothly from the start,
    and the pull-off is the one a run on steps too short to ring finds."""
    import sweep.engine.bem as bem

    scene = Scene(n=2.119, k=2.873e-4, mu=2.622, a0=1.9, rate=2.463, material="sls")
    fine = Numerics.preset("accurate", band_resolution=72.0, pull_off_rtol=0.0)
    res = simulate(scene, fine)
    assert res.ok, res.reason
    P = res.trajectory["P"][:20]
    assert np.count_nonzero(np.diff(np.sign(np.diff(P)))) <= 2      # no period-two ringing
    with monkeypatch.context() as m:
        m.setattr(bem, "RINGING_FACTOR", -math.inf)                # no lead-in: as before
        rang = simulate(scene, fine)
        # an independent run: steps short enough that the recursion does not ring
        # (factor -0.47 at 4e-3 h0), no lead-in: 4.17715
        short = simulate(scene, Numerics.preset("accurate", band_resolution=36.0, step=4e-3,
                                                pull_off_rtol=0.0))
    assert rang.ok and rang.pull_off < 1.0                          # the false pull-off
    assert short.ok and abs(short.pull_off - 4.177) < 1e-3
    assert abs(res.pull_off / short.pull_off - 1.0) < 1e-3
    # a paper scene's broad spectrum does not ring: no lead-in, as before
    from sweep.engine.problem import prepare

    paper = prepare(Scene(n=0.8, k=0.1, mu=3.24, a0=2.0, rate=10 ** 2.5),
                    Numerics.preset("balanced"))
    assert bem.ringing_lead_in(paper) == 0.0
