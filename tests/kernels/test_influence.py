"""Influence matrix of overlapping triangles: second method (quad), closed forms, scaling."""
import numpy as np
import pytest
from scipy import integrate
from scipy.special import ellipe, ellipkm1

from sweep.kernels.influence import assemble_unit, ellipk_complement, load_weights
from tests.naive import _kernel_s, influence_matrix_quad


def test_ellipk_by_agm_matches_scipy():
    k = np.array([0.0, 0.1, 0.5, 0.9, 0.999, 1 - 1e-9])
    kc = np.sqrt((1 - k) * (1 + k))
    ours = np.array([ellipk_complement(x) for x in kc])
    # ellipkm1(1 - m) with 1 - m = kc^2 keeps the digits that ellipk(k^2) loses near k = 1
    np.testing.assert_allclose(ours, ellipkm1(kc**2), rtol=1e-13)


def test_ellipk_by_agm_is_accurate_to_rounding_over_the_whole_range():
    """The AGM stops once its means agree to AGM_RTOL and returns pi/(a + b) (the means
    converge quadratically): against scipy's ellipkm1 (Cephes, a second method) within a few
    roundings on moduli from kc = 1e-300 (k -> 1, the logarithmic singularity) to 1."""
    rng = np.random.default_rng(3)
    kc = np.concatenate([np.logspace(-300, 0, 3000), rng.uniform(0.0, 1.0, 3000)[1:]])
    ours = np.array([ellipk_complement(x) for x in kc])
    wide = kc > 1e-150                      # kc^2 underflows below
    np.testing.assert_allclose(ours[wide], ellipkm1(kc[wide] ** 2), rtol=2e-15, atol=0.0)
    tiny = ~wide                            # K = ln(4/kc) + O(kc^2 ln kc) there
    np.testing.assert_allclose(ours[tiny], np.log(4.0 / kc[tiny]), rtol=2e-15, atol=0.0)


def test_matrix_matches_quadrature_of_the_elliptic_kernel():
    # independent assembly by scipy.integrate.quad (tests/naive.py); interior columns
    N = 40
    ours = assemble_unit(N)
    ref = influence_matrix_quad(N, 1.0, tail="full")
    np.testing.assert_allclose(ours, ref, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("dr", [0.01, 0.37])
def test_matrix_scales_with_spacing(dr):
    # The engine builds the matrix once per N at unit spacing and multiplies by the spacing
    # (sweep.engine.bem.influence_matrix). Check that law against scipy quadrature done at the
    # spacing itself, in physical coordinates: A_ij = int phi_j(s) G(r_i, s) s ds over the
    # two linear pieces of the hat of node j (log singularity at s = r_i on a piece end).
    N = 30
    scaled = assemble_unit(N) * dr
    for i, j in [(0, 0), (0, 7), (3, 3), (3, 4), (5, 17), (17, 5), (29, 12), (12, 28)]:
        ri, rj = i * dr, j * dr
        pieces = [(rj - dr, rj, lambda s: (s - (rj - dr)) / dr)] if j > 0 else []
        pieces.append((rj, rj + dr, lambda s: (rj + dr - s) / dr))
        quad = sum(integrate.quad(lambda s: _kernel_s(ri, s) * phi(s), a, b, epsabs=0,
                                  epsrel=1e-12, limit=200)[0] for a, b, phi in pieces)
        assert scaled[i, j] == pytest.approx(quad, rel=1e-9), (i, j)


def test_far_entries_with_the_fewer_point_rules_match_quadrature():
    """From 10, 20 and 50 piece lengths off the diagonal the entries take the 6-, 5- and
    4-point Gauss rules (kernels.influence.FARTHER_PIECES): they equal scipy's adaptive
    quadrature of the elliptic kernel to 1e-13 (the 8-point rule everywhere agreed with
    them to 2.2e-15 on 600 nodes, measured when the rules were chosen)."""
    N = 320
    A = assemble_unit(N)
    for i, j in [(20, 24), (100, 107), (50, 62), (40, 61), (0, 15), (4, 16), (30, 55),
                 (10, 70), (200, 140), (5, 300), (310, 3),
                 (160, 319)]:
        pieces = [(j - 1.0, float(j), lambda s, j=j: s - (j - 1.0))] if j > 0 else []
        pieces.append((float(j), j + 1.0, lambda s, j=j: j + 1.0 - s))
        quad = sum(integrate.quad(lambda s: _kernel_s(float(i), s) * phi(s), a, b, epsabs=0,
                                  epsrel=1e-13, limit=200)[0] for a, b, phi in pieces)
        assert A[i, j] == pytest.approx(quad, rel=1e-13), (i, j)


def _disc_error(a_nodes):
    N = a_nodes + 12
    dr = 1.0 / a_nodes
    r = np.arange(N) * dr
    p = np.where(r < 1 - 1e-12, 1.0, 0.0)
    p[a_nodes] = 0.5                   # the step sampled at its midpoint value
    u = assemble_unit(N) @ p * dr
    exact = 4 / np.pi * ellipe(np.minimum(r, 1.0) ** 2)
    inner = r <= 0.8
    return np.max(np.abs(u[inner] / exact[inner] - 1))


def test_uniform_pressure_on_a_disc_converges_to_closed_form():
    # u(r) = (4 p a / pi) E(r/a) inside the disc; second-order convergence, 1e-6 at a/dr = 800
    e1, e2 = _disc_error(200), _disc_error(400)
    assert 3.5 < e1 / e2 < 4.5
    assert _disc_error(800) < 1.5e-6


def test_hertz_pressure_gives_parabolic_deflection():
    # p = p0 sqrt(1 - r^2/a^2) -> u = pi p0 (2 a^2 - r^2)/(4 a) inside; the sqrt edge makes the
    # nodal interpolation converge as dr^1.5; Richardson extrapolation with that order
    # reaches the closed form to 1e-6 away from the edge
    def deflection(a_nodes):
        N = a_nodes + 5
        dr = 1.0 / a_nodes
        r = np.arange(N) * dr
        p = np.sqrt(np.clip(1 - r**2, 0, None))
        u = assemble_unit(N) @ p * dr
        return r, u

    r1, u1 = deflection(200)
    r2, u2 = deflection(400)
    idx1 = np.flatnonzero(r1 <= 0.8)
    u2_on_1 = u2[2 * idx1]
    exact = np.pi * (2 - r1[idx1] ** 2) / 4
    err1 = np.max(np.abs(u1[idx1] / exact - 1))
    err2 = np.max(np.abs(u2_on_1 / exact - 1))
    assert 2.4 < err1 / err2 < 3.3                       # order 1.5: ratio 2^1.5 = 2.83
    extrapolated = (2**1.5 * u2_on_1 - u1[idx1]) / (2**1.5 - 1)
    assert np.max(np.abs(extrapolated / exact - 1)) < 1e-6


def test_load_weights_integrate_piecewise_linear_traction_exactly():
    # P = 2 pi int sigma r dr for sigma = 1 - r on [0, 1] (piecewise linear, exact): pi/3
    N, dr = 101, 0.01
    r = np.arange(N) * dr
    sigma = np.clip(1 - r, 0, None)
    assert 2 * np.pi * load_weights(N, dr) @ sigma == pytest.approx(np.pi / 3, rel=1e-12)


def _graded_quad(r):
    """A_ij of arbitrary nodes by scipy quadrature (pieces end at the log singularities)."""
    from tests.naive import _kernel_s, _quad
    ext = np.append(r, 2 * r[-1] - r[-2])
    N = r.size
    A = np.zeros((N, N))
    for i in range(N):
        for j in range(N):
            if j > 0:
                a, b = ext[j - 1], ext[j]
                A[i, j] += _quad(lambda s: _kernel_s(r[i], s) * (s - a) / (b - a), a, b)
            a, b = ext[j], ext[j + 1]
            A[i, j] += _quad(lambda s: _kernel_s(r[i], s) * (b - s) / (b - a), a, b)
    return A


def test_graded_matrix_matches_quadrature_of_the_elliptic_kernel():
    # element lengths growing by 1.25 inward and outward of a fine band, and a jump
    r = np.concatenate([[0.0, 0.9, 1.62, 2.2, 2.6], 2.6 + 0.3 * np.arange(1, 8),
                        [4.8, 5.3, 6.0, 7.0, 8.2]])
    from sweep.kernels.influence import assemble_nodes
    np.testing.assert_allclose(assemble_nodes(r), _graded_quad(r), rtol=1e-9, atol=1e-12)


def test_node_assembly_on_uniform_nodes_matches_the_uniform_quadrature():
    # the uniform mesh is the special case r_j = j dr of the node assembly
    from sweep.kernels.influence import assemble_nodes
    dr = 0.037
    np.testing.assert_allclose(assemble_nodes(np.arange(30) * dr),
                               influence_matrix_quad(30, dr, tail="full"), rtol=1e-9, atol=1e-14)


def test_lattice_combination_equals_direct_assembly_on_a_graded_mesh():
    # sweep.engine.mesh builds graded meshes on the lattice of the fine spacing and combines the
    # cached unit matrix; the direct assembly of the same nodes is a second method
    from sweep.kernels.influence import assemble_nodes
    from sweep.engine.mesh import crack_band, graded_mesh
    mesh = graded_mesh(5.0, crack_band(2.5, 0.08), 0.02, 1.15)
    d = np.diff(mesh.lattice)
    assert d.min() == 1 and d.max() >= 5                 # really graded
    np.testing.assert_allclose(mesh.influence, assemble_nodes(np.asarray(mesh.r)),
                               rtol=1e-12, atol=1e-15)


def _entrywise(r):
    """The influence matrix entry by entry (``kernels.influence._entry``: each hat's rising
    piece plus its falling one; the assembly before 2026-11-26 built every entry so)."""
    from sweep.kernels import influence as inf
    rules = (inf.GL16_X, inf.GL16_W, inf.GL32_X, inf.GL32_W, inf.GL8_X, inf.GL8_W)
    N = r.size
    ext = np.append(r, 2.0 * r[-1] - r[-2])
    return np.array([[inf._entry(ext, i, j, *rules) for j in range(N)] for i in range(N)])


@pytest.mark.parametrize("kind", ["graded", "jittered", "lattice", "unit"])
def test_the_element_by_element_assembly_is_the_entrywise_one_to_the_bit(kind):
    # assemble_nodes and grow_unit integrate each element once for the two hats that share
    # it; each entry must be the hat-by-hat sum, to the bit (not merely close): results
    # computed before the change stay what they were (both were also compared with the
    # entry-by-entry code they replaced, on 300-1024 nodes: the same to the bit)
    from sweep.kernels.influence import assemble_nodes, grow_unit
    if kind == "unit":                       # grown in two blocks, as the cache grows it
        A = grow_unit(grow_unit(np.empty((0, 0)), 30), 70)
        np.testing.assert_array_equal(A, _entrywise(np.arange(70.0)))
        return
    rng = np.random.default_rng(5)
    if kind == "graded":
        r = np.concatenate([[0.0], np.cumsum(0.4 * 1.2 ** -np.arange(12)),
                            3.0 + np.cumsum(0.03 * np.ones(40)),
                            4.2 + np.cumsum(0.03 * 1.15 ** np.arange(1, 25))])
    elif kind == "jittered":
        r = np.concatenate([[0.0], np.cumsum(rng.uniform(0.01, 0.2, 90))])
    else:
        r = np.arange(70) * 0.0125
    assert np.all(np.diff(r) > 0)
    np.testing.assert_array_equal(assemble_nodes(r), _entrywise(r))


def test_graded_load_weights_integrate_piecewise_linear_traction_exactly():
    from sweep.kernels.influence import load_weights_nodes
    # sigma = 1 - r on [0, 1] sampled on graded nodes (exact: pi/3); and int r dr = R^2/2
    r = np.array([0.0, 0.3, 0.5, 0.6, 0.65, 0.7, 0.8, 1.0, 1.4, 2.0])
    sigma = np.clip(1 - r, 0, None)
    w = load_weights_nodes(r)
    assert 2 * np.pi * w @ sigma == pytest.approx(np.pi / 3, rel=1e-12)
    # the last node's full hat: a linear traction 1 on the mesh falling to 0 one element on
    ones = np.ones_like(r)
    R, L = r[-1], r[-1] - r[-2]
    exact = R**2 / 2 + L * (2 * R + (R + L)) / 6
    assert w @ ones == pytest.approx(exact, rel=1e-12)
