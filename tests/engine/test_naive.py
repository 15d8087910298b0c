"""Tests of the slow reference implementation ``tests/naive.py`` itself.

Against closed forms (uniform-disc and Hertz deflections, JKR, the LJ work of adhesion, the
MPL compliance as a Gamma average, the SLS recursion) and against the independent solver's
numbers in tests/data/independent_solutions.yaml. Quick suite ~30 s on one core;
the fine-mesh comparisons are marked slow.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
from scipy import integrate

from tests import naive as nv

from tests import reference
from sweep import Numerics, Scene
from sweep.engine.bem import simulate  # the BEM on the graded mesh (not the model dispatch)
from sweep.errors import InputError

@pytest.fixture(scope="module")
def ref():
    return reference.independent_solutions()


def _case(ref, name):
    return next(c for c in ref["viscoelastic"] if c["name"] == name)


def _elastic_ref(ref, mu):
    return next(c for c in ref["elastic"] if c["mu"] == mu)


# ----------------------------------------------------------------------------- matrix
def test_matrix_row_at_axis():
    """G(0, s) s = 2: row 0 is 2 int phi_j = 2 dr (interior), dr for the two half hats."""
    dr = 0.3
    A = nv.influence_matrix_quad(10, dr)
    expect = np.full(10, 2 * dr)
    expect[0] = expect[-1] = dr
    np.testing.assert_allclose(A[0], expect, rtol=1e-13)
    Af = nv.influence_matrix_quad(10, dr, tail="full")
    np.testing.assert_allclose(Af[:, :-1], A[:, :-1], rtol=0, atol=0)
    assert Af[0, -1] == pytest.approx(2 * dr, rel=1e-13)


def test_matrix_scales_with_dr():
    A1 = nv.influence_matrix_quad(15, 1.0)
    np.testing.assert_allclose(nv.influence_matrix_quad(15, 0.037), 0.037 * A1, rtol=1e-15)
    # a smaller N is the leading block of a larger one (except the last column's half hat)
    np.testing.assert_allclose(nv.influence_matrix_quad(8, 1.0)[:, :7], A1[:8, :7], rtol=1e-15)


def _ramp_integral(r, b):
    """R(r; b) = int_0^b U(r; c) dc: deflection under the cone load (b - s)_+ (unit slope),
    as a superposition of uniform-disc loads of radius c (closed form U)."""
    f = lambda c: float(nv.uniform_disc_deflection(r, c)[0]) if c > 0 else 0.0  # noqa: E731
    pts = [0.0] + ([r] if 0 < r < b else []) + [b]
    return sum(integrate.quad(f, pts[q], pts[q + 1], epsabs=1e-14, epsrel=1e-13, limit=200)[0]
               for q in range(len(pts) - 1))


def test_matrix_exact_against_disc_superposition():
    """Every hat is a combination of cone loads (b - s)_+ (and, for the last half hat, one
    uniform disc), each the c-integral of the closed-form uniform-disc deflection. This gives
    A exactly by a route that never touches the elliptic kernel G. Measured: 8e-14."""
    N = 12
    A = nv.influence_matrix_quad(N, 1.0)
    B = np.zeros((N, N))
    for i in range(N):
        R = [_ramp_integral(float(i), float(b)) for b in range(N + 1)]
        B[i, 0] = R[1]
        for j in range(1, N - 1):
            B[i, j] = R[j + 1] - 2 * R[j] + R[j - 1]
        B[i, N - 1] = R[N - 2] - R[N - 1] + float(nv.uniform_disc_deflection(i, N - 1)[0])
    np.testing.assert_allclose(A, B, rtol=1e-10, atol=1e-12)


def _disc_and_hertz_errors(dr, a=1.0, rmax=3.0):
    N = int(round(rmax / dr)) + 1
    r = np.arange(N) * dr
    A = nv.influence_matrix_quad(N, dr)
    inner, outer = r <= 0.5 * a, r >= 1.5 * a
    q = np.where(r < a, 1.0, 0.0)
    q[np.isclose(r, a)] = 0.5  # edge node at half the step: the interpolant keeps the load
    e_disc = np.abs(A @ q - nv.uniform_disc_deflection(r, a))
    p = np.sqrt(np.clip(1 - r**2 / a**2, 0, None))
    e_hertz = np.abs(A @ p - nv.hertz_deflection(r, a))
    return (e_disc[inner].max(), e_disc[outer].max(), e_disc.max(),
            e_hertz[inner].max(), e_hertz.max())


def test_matrix_against_closed_form_loads():
    """Measured (a = 1, dr = 0.05 -> 0.025):
    uniform disc: error O(dr^2) away from the edge (inner 1.44e-4 -> 3.60e-5, outer
    8.78e-4 -> 2.19e-4, ratio 4.0), O(dr) at the edge (6.8e-3 -> 3.3e-3, the step is smeared
    over one element); Hertz: the sqrt edge pollutes everything, O(dr^1.5) (inner 7.05e-3 ->
    2.49e-3, ratio 2.83; max 1.17e-2 -> 4.65e-3)."""
    c = _disc_and_hertz_errors(0.05)
    f = _disc_and_hertz_errors(0.025)
    ratio = np.array(c) / np.array(f)
    assert f[0] < 4e-5 and f[1] < 2.5e-4 and f[2] < 3.5e-3
    assert ratio[0] > 3.8 and ratio[1] > 3.8  # second order away from the edge
    assert ratio[2] > 1.9  # first order at the edge node
    assert f[3] < 2.6e-3 and f[4] < 5e-3
    assert ratio[3] > 2.6 and ratio[4] > 2.3  # ~dr^1.5 for the Hertz sqrt edge


def test_load_weights_exact():
    rng = np.random.default_rng(1)
    for tail in ("half", "full"):
        N, dr = 9, 0.4
        p = rng.normal(size=N)
        w = nv.load_weights(N, dr, tail)
        r = np.arange(N) * dr
        if tail == "full":
            r = np.append(r, N * dr)
            p_ext = np.append(p, 0.0)
        else:
            p_ext = p
        exact = sum(integrate.quad(lambda x: np.interp(x, r, p_ext) * x, r[e], r[e + 1])[0]
                    for e in range(len(r) - 1))
        assert np.dot(w, p) == pytest.approx(exact, rel=1e-12)


# ----------------------------------------------------------------------------- LJ law
@pytest.mark.parametrize("mu", [1.0, 3.24, 6.0])
def test_lj_law(mu):
    h0, hm = nv.lj_h0(mu), nv.lj_hm(mu)
    assert nv.lj_traction(h0, mu) == pytest.approx(0.0, abs=1e-14)
    sigma0 = 16 * mu / (9 * math.sqrt(3) * math.pi ** (1 / 3))
    assert nv.lj_traction(hm, mu) == pytest.approx(-sigma0, rel=1e-13)
    assert abs(nv.lj_dtraction(hm, mu)) < 1e-10 * sigma0 / h0
    h = np.linspace(0.8, 5, 17) * h0
    eps = 1e-6 * h0
    fd = (nv.lj_traction(h + eps, mu) - nv.lj_traction(h - eps, mu)) / (2 * eps)
    np.testing.assert_allclose(nv.lj_dtraction(h, mu), fd, rtol=1e-6)
    # work of adhesion: int_h0^inf sigma dh = -dg = -1/pi in p_ref d_ref units
    work = integrate.quad(lambda x: float(nv.lj_traction(x, mu)), h0, np.inf, epsabs=1e-13)[0]
    assert work == pytest.approx(-1 / math.pi, rel=1e-9)


def test_jkr_helpers():
    a = np.linspace(0.5, 3, 200001)
    assert -nv.jkr_load(a).min() == pytest.approx(1.5, rel=1e-8)
    for d in (-0.3, 0.5, 4.952446):
        assert float(nv.jkr_delta(nv.jkr_radius(d))) == pytest.approx(d, abs=1e-12)


# ----------------------------------------------------------------------------- compliance
@pytest.mark.parametrize("n,k", [(0.4, 0.1), (0.8, 0.1), (1.0, 0.3), (1.6, 0.1), (2.5, 0.01)])
def test_mpl_creep_is_gamma_average(n, k):
    """Chat(t) = 1 - (1-k) E[exp(-t/x)], x ~ Gamma(n, 1) (docs/design.md section 3)."""
    for t in (1e-3, 0.1, 1.0, 7.0, 50.0):
        dens = lambda x: x ** (n - 1) * math.exp(-x - t / x) / math.gamma(n)  # noqa: E731
        avg = integrate.quad(dens, 0, np.inf, epsabs=0, epsrel=1e-12, limit=200)[0]
        assert float(nv.creep_mpl(t, n, k)) == pytest.approx(1 - (1 - k) * avg, rel=1e-9)
    assert float(nv.creep_mpl(0.0, n, k)) == pytest.approx(k, rel=1e-14)
    assert float(nv.creep_mpl(1e5, n, k)) == pytest.approx(1.0, rel=1e-14)


@pytest.mark.parametrize("n,k", [(0.4, 0.1), (0.8, 0.1), (1.0, 0.3), (1.6, 0.1), (2.5, 0.01)])
def test_psi_mpl_against_quad(n, k):
    """Closed form (quad below T = 1e-3) against quad of Chat. Measured worst 1e-10 relative
    (closed form alone loses ~1e-10 at T = 1e-4 and 1e-6 at T = 1e-8: cancellation)."""
    T = np.array([1e-8, 1e-6, 1e-4, 9.99e-4, 1e-3, 0.02, 1.0, 10.0, 300.0])
    q = [integrate.quad(lambda t: float(nv.creep_mpl(t, n, k)), 0, x, epsabs=0, epsrel=1e-13,
                        limit=500)[0] for x in T]
    np.testing.assert_allclose(nv.psi_mpl(T, n, k), q, rtol=5e-10)
    assert float(nv.psi_mpl(1e-9, n, k)[0]) == pytest.approx(k * 1e-9, rel=2e-3 if n < 1 else 1e-6)


def test_sls():
    k = 0.2
    T = np.array([1e-6, 0.3, 2.0, 40.0])
    q = [integrate.quad(lambda t: float(nv.creep_sls(t, k)), 0, x, epsrel=1e-13)[0] for x in T]
    np.testing.assert_allclose(nv.psi_sls(T, k), q, rtol=1e-12)


def test_hereditary_sum_against_sls_recursion():
    """For the SLS, sum_m ... must equal sigma_n - (1-k) q_n with the exact exponential
    recursion q_n = e q_{n-1} + (1-e)/dt (sigma_n - sigma_{n-1}) (non-uniform steps)."""
    rng = np.random.default_rng(3)
    k = 0.15
    dts = rng.uniform(0.01, 0.7, size=25)
    t = np.concatenate([[0.0], np.cumsum(dts)])
    sig = rng.normal(size=(len(t), 4))
    q = np.zeros(4)
    for n in range(1, len(t)):
        e = math.exp(-dts[n - 1])
        q = e * q + (1 - e) / dts[n - 1] * (sig[n] - sig[n - 1])
        c, H = nv.hereditary_effective_traction(t[: n + 1], sig[:n], lambda T: nv.psi_sls(T, k))
        np.testing.assert_allclose(c * sig[n] + H, sig[n] - (1 - k) * q, rtol=1e-12, atol=1e-13)


def test_hereditary_sum_against_quad_mpl():
    """Direct quad of int Chat(t_n - tau) dsigma/dtau dtau for a piecewise-linear scalar history."""
    n_, k = 0.6, 0.1
    t = np.array([0.0, 0.05, 0.1, 0.4, 0.45, 1.3, 1.31, 2.0])
    sig = np.array([[1.0], [0.7], [0.2], [-0.5], [-0.2], [0.9], [0.8], [0.1]])
    n = len(t) - 1
    c, H = nv.hereditary_effective_traction(t, sig[:n], lambda T: nv.psi_mpl(T, n_, k))
    direct = sig[0, 0]
    for m in range(1, n + 1):
        slope = (sig[m, 0] - sig[m - 1, 0]) / (t[m] - t[m - 1])
        direct += slope * integrate.quad(lambda s: float(nv.creep_mpl(t[n] - s, n_, k)),
                                         t[m - 1], t[m], epsabs=1e-14, epsrel=1e-12)[0]
    assert c * sig[n, 0] + H[0] == pytest.approx(direct, rel=1e-10)


# ----------------------------------------------------------------------------- elastic solver
def test_elastic_equilibrium_residual():
    mu, N, dr = 3.24, 100, 0.05
    s = nv.naive_elastic(mu, 2.0, N, dr)
    r = s["r"]
    A = nv.influence_matrix_quad(N, dr)
    F = s["gap"] - (-2.0 + nv.lj_h0(mu) + r**2 / 2) - A @ s["sigma"]
    assert np.max(np.abs(F)) < 1e-10
    assert s["P"] == pytest.approx(2 * math.pi * nv.load_weights(N, dr) @ s["sigma"], rel=1e-14)
    assert s["a_inner"] < s["a"]
    # JKR at delta = 2: a = 2, P = 2.667; LJ at mu = 3.24 is close (measured a = 2.0017, P = 2.523)
    assert s["a"] == pytest.approx(2.0, abs=0.02)
    assert s["P"] == pytest.approx(float(nv.jkr_load(2.0)), rel=0.08)


def test_elastic_pulloff_mu324(ref):
    """Domain 5 (N = 500, dr = 0.01), step 0.2 h0. Measured 1.54607 vs 1.5459 (+1.7e-4; the
    same at step 0.1: 1.54605). Coarser meshes: dr = 0.02 -> 1.5476 (N = 125, domain 2.5)/
    1.5517..1.5546 (domain 5, with node-to-node snaps), dr = 0.05 -> 1.78 (lattice trapping,
    31 snaps: the process zone ~0.04 is not resolved). Domain 2.5 at dr = 0.01: 1.5417."""
    e = _elastic_ref(ref, 3.24)
    res = nv.naive_elastic_pulloff(3.24, 500, 0.01, 0.2)
    assert res["stop"] == "recovered"
    assert not res["snaps"]
    assert res["pull_off"] == pytest.approx(e["pull_off"], abs=5e-4)
    # the engine on the same mesh (a second method; it halves its step near the edge, so the
    # parabola through the samples around the minimum differs): measured 1.00602 vs 1.00599.
    # Without the Lennard-Jones tail beyond the mesh, as this reference and the yaml's
    fast = simulate(Scene(n=1.0, k=1.0, mu=3.24, delta0=float(nv.jkr_delta(2.0)), rate=1.0),
                    Numerics(nodes=500, domain=499 * 0.01, step=0.2, da_max=1e6, tol=1e-10,
                             lj_tail=False))
    assert res["a_pulloff"] == pytest.approx(fast.a_pulloff, abs=1e-4)
    assert res["pull_off"] == pytest.approx(fast.pull_off, abs=5e-5)  # measured 1.3e-6


def test_the_tail_beyond_the_mesh_is_the_lennard_jones_law_integrated():
    # closed form: 2 pi int_{h_end}^inf sigma dh = -2 pi c h0 (q^2/2 - q^8/8), q = h0/h_end
    mu, h_last, r_last, r_end = 1.0, 0.02, 4.95, 5.0
    h0, c = nv.lj_h0(mu), 8.0 * mu / (3.0 * math.pi ** (1.0 / 3.0))
    q = h0 / (h_last + 0.5 * (r_end**2 - r_last**2))
    closed = -2.0 * math.pi * c * h0 * (q**2 / 2.0 - q**8 / 8.0)
    assert nv.lj_tail_load(h_last, r_last, r_end, mu) == pytest.approx(closed, rel=1e-12)


def test_elastic_jkr_trend():
    """Pull-off decreases towards the JKR 1.5 as mu grows (mu = 1: 1.6675 at dr = 0.05 and
    0.025; mu = 3.24: 1.5461), and the LJ P(a) approaches the JKR curve at a = 2."""
    po1 = nv.naive_elastic_pulloff(1.0, 100, 0.05, 0.1, tail="full", lj_tail=True)
    po3 = nv.naive_elastic_pulloff(3.24, 500, 0.01, 0.2)
    assert not po1["snaps"]
    # mu = 1: the engine on the same mesh and indentation steps (the paper's full last
    # triangle, the Lennard-Jones tail beyond it) solves the same discrete equations:
    # measured 6e-12 apart (session 49; 5e-12 before the tail, on both sides)
    fast = simulate(Scene(n=1.0, k=1.0, mu=1.0, delta0=float(nv.jkr_delta(2.0)), rate=1.0),
                    Numerics(nodes=100, domain=99 * 0.05, step=0.1, da_max=1e6, tol=1e-10))
    assert po1["pull_off"] == pytest.approx(fast.pull_off, rel=1e-9)
    # and the mesh is converged: dr = 0.025 gives 1.67075, 1.8e-4 below (tolerance 5e-4;
    # without the tail 1.66743, 1.2e-4 below)
    assert po1["pull_off"] == pytest.approx(
        nv.naive_elastic_pulloff(1.0, 200, 0.025, 0.1, tail="full", lj_tail=True)["pull_off"],
        abs=5e-4)
    assert 1.5 < po3["pull_off"] < po1["pull_off"]
    dev = []
    for mu, N, dr in ((1.0, 100, 0.05), (3.24, 500, 0.01)):
        s = nv.naive_elastic(mu, float(nv.jkr_delta(2.0)), N, dr)
        dev.append(abs(s["P"] - float(nv.jkr_load(s["a"]))))
    assert dev[1] < dev[0]


@pytest.mark.slow
def test_elastic_pulloff_mu6(ref):
    """The yaml's own mesh (N = 1000, dr = 0.005), step 0.1 h0: measured 1.52272 vs 1.5225
    (+2.2e-4), about 5 min (the process zone is barely resolved: 16 node-to-node snaps, each
    relaxed by many dense N = 1000 solves). Domain 2.5/3 (N = 500/600) gives 1.5208/1.5214;
    dr = 0.01 gives 1.5814 (lattice trapping). mu = 3.24 on this mesh: 1.545916 (+1.6e-5)."""
    e = _elastic_ref(ref, 6.0)
    res = nv.naive_elastic_pulloff(6.0, 1000, 0.005, 0.1)
    assert res["pull_off"] == pytest.approx(e["pull_off"], abs=1e-3)


# ----------------------------------------------------------------------------- viscoelastic
def test_unload_k1_is_elastic():
    """k = 1 (Chat = 1): Psi(T) = T, the hereditary sum collapses to sigma_n and the unloading
    must reproduce the quasi-static elastic path at the same indentations."""
    mu, N, dr = 1.0, 60, 0.05
    vis = nv.naive_unload(0.5, 1.0, mu, 1.0, 2.0, N, dr, 0.5)
    h = None
    for d, P in zip(vis["delta"][:40], vis["P"][:40]):
        s = nv.naive_elastic(mu, float(d), N, dr, h_init=h)
        h = s["gap"]
        assert P == pytest.approx(s["P"], rel=1e-9, abs=1e-11)


def test_unload_rate_trend():
    """Faster unloading from the same relaxed state -> larger pull-off; a very slow one tends to
    the elastic value from above (mu = 1, coarse mesh without snaps)."""
    mu, N, dr, d0 = 1.0, 80, 0.05, 2.0
    el = nv.naive_elastic_pulloff(mu, N, dr, 0.1)["pull_off"]
    pos = [nv.naive_unload(0.5, 0.2, mu, d0, rate, N, dr, 0.25)["pull_off"]
           for rate in (1e-3, 0.1, 10.0)]
    assert el < pos[0] < pos[1] < pos[2]
    assert pos[0] == pytest.approx(el, rel=0.02)


def test_unload_case_F(ref):
    """Case F (n = 0.4, k = 0.1, mu = 3.24, rate 3.16), N = 500, dr = 0.01, step 0.1 h0.

    Measured pull-off (yaml 2.4297 +- 9e-4):
      dr = 0.02 : step 0.2 2.41711, 0.1 2.42157, 0.05 2.42263, 0.025 2.42289 (second order)
      dr = 0.01 : step 0.2 2.4219,  0.1 2.42657, 0.05 2.42769
      dr = 0.005: step 0.1 2.42806, 0.05 2.42920 (-5e-4 from the yaml)
    so here 2.42657, -3.1e-3 (-0.13%), a discretization error that shrinks with dr and step.
    """
    c = _case(ref, "F")
    sc = c["scene"]
    res = nv.naive_unload(sc["n"], sc["k"], sc["mu"], sc["delta0"], sc["rate"], 500, 0.01, 0.1)
    assert res["stop"] == "recovered"
    assert res["a0"] == pytest.approx(c["a0"], abs=2e-3)  # measured 2.6721
    assert res["a0_inner"] == pytest.approx(2.4700, abs=1e-3)  # measured 2.4700
    assert res["pull_off"] == pytest.approx(c["pull_off"], abs=6e-3)
    assert res["a_pulloff"] == pytest.approx(c["a_pulloff"], abs=5e-3)  # measured 1.1161
    assert res["crack_speed"] == pytest.approx(c["crack_speed"], rel=0.05)  # measured 0.2746


@pytest.mark.slow
def test_unload_case_F_fine(ref):
    """N = 1000, dr = 0.005 (the yaml's mesh), step 0.05 h0: measured 2.42920 (-5e-4),
    a0 2.6730, a at pull-off 1.1167, crack speed 0.2750. About 70-90 s."""
    c = _case(ref, "F")
    sc = c["scene"]
    res = nv.naive_unload(sc["n"], sc["k"], sc["mu"], sc["delta0"], sc["rate"], 1000, 0.005, 0.05)
    assert res["pull_off"] == pytest.approx(c["pull_off"], abs=1.5e-3)
    assert res["a0"] == pytest.approx(c["a0"], abs=5e-4)
    assert res["a_pulloff"] == pytest.approx(c["a_pulloff"], abs=3e-3)
    assert res["crack_speed"] == pytest.approx(c["crack_speed"], rel=0.05)


def test_input_errors():
    with pytest.raises(InputError):
        nv.naive_unload(0.4, 1.5, 3.24, 1.0, 1.0, 20, 0.1, 0.1)
    with pytest.raises(InputError):
        nv.naive_unload(0.4, 0.1, 3.24, 1.0, -1.0, 20, 0.1, 0.1)
    with pytest.raises(InputError):
        nv.influence_matrix_quad(1, 0.1)
    with pytest.raises(InputError):
        nv.naive_unload(0.4, 0.1, 3.24, 1.0, 1.0, 20, 0.1, 0.1, material="maxwell")
