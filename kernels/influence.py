"""Influence matrix of the axisymmetric half-space for overlapping-triangle tractions.

Pure Numba kernels on arrays. Dimensionless units of docs/design.md section 2 (E0* = 1):
the deflection at node i due to nodal tractions p_j is ``u_i = sum_j A_ij p_j`` with

    A_ij = int phi_j(s) G(r_i, s) s ds,
    G(r, s) = 4/(pi r) K(s/r)  (s < r),   4/(pi s) K(r/s)  (s > r),   G(0, s) = 2/s,

where K is the complete elliptic integral of the first kind of *modulus* k, and phi_j
is the hat function of node j (phi_0 is the half-hat on [0, r_1]; the last node has a full
hat, i.e. its traction falls to zero one element beyond the mesh). On the uniform mesh
r_j = j * dr, A scales linearly with dr, so :func:`assemble_unit` assembles it for dr = 1;
:func:`assemble_nodes` takes arbitrary (graded) node positions.

The logarithmic singularity of K at s = r always sits at an end of a piece of a hat
(the r_i are nodes), so it is integrated exactly enough by Gauss-Legendre after the
graded substitution ``s - r_i = L t^6`` on the pieces that touch r_i (error of order
n^-12 for n points); the other pieces are smooth and use plain Gauss-Legendre (16 points
next to the singularity, 8 points from three spacings on, and 6, 5 and 4 from 10, 20 and
50, FARTHER_PIECES: each where the nearest singularity is far enough that the rule is exact
to rounding).
"""
from __future__ import annotations

import numpy as np
from numba import njit


def _gauss_legendre(n: int):
    """The n-point Gauss-Legendre rule on [0, 1]: (nodes, weights)."""
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


# Gauss-Legendre rules on [0, 1]
GL4_X, GL4_W = _gauss_legendre(4)
GL5_X, GL5_W = _gauss_legendre(5)
GL6_X, GL6_W = _gauss_legendre(6)
GL8_X, GL8_W = _gauss_legendre(8)
GL16_X, GL16_W = _gauss_legendre(16)
GL32_X, GL32_W = _gauss_legendre(32)
#: exponent of the graded substitution s - r_i = L t^GRADING on the pieces that touch r_i
GRADING = 6.0
#: a smooth piece whose midpoint lies more than this many piece lengths from r_i takes the
#: 8-point rule (exact to rounding there), a nearer one the 16-point rule
FAR_PIECES = 3.0
#: ... and from these many piece lengths on the 6-, 5- and 4-point rules: the integrand is
#: analytic ever further around the piece. Against the 8-point rule on the unit matrix of
#: 600 nodes (every entry with |i - j| >= the threshold), the 6-point rule from 10 nodes
#: differs by at most 1.3e-15 relative, the 5-point one from 20 by 1.0e-15 and the 4-point
#: one from 50 by 2.2e-15 (rounding: the 4-point one from 20 differs by 2.1e-13, the
#: 3-point one from 300 by 3.8e-14); most entries are that far, so a matrix assembles in
#: about half the time (``grow_unit`` from empty to 1024 nodes: 1.14 s, against 2.03 s with
#: the 8-point rule throughout; one run each, 2026-11-26)
FARTHER_PIECES = (10.0, 20.0, 50.0)
#: the AGM of :func:`ellipk_complement` stops when its two means agree to this relative
#: difference and returns pi/(a + b): the means converge quadratically, their next
#: difference is about (a - b)^2/(8 a), so the common limit is (a + b)/2 to below rounding.
#: (It ran until the means agreed to 1e-16, i.e. were equal: a quarter of the inputs end
#: with the two one rounding apart and ran to AGM_MAX_ITER, 21 iterations on average
#: against 5; the values are the same to the bit on 40000 moduli from 1e-300 to 1, and the
#: unit matrix of 1024 nodes is the same to the bit and assembles in 0.28-0.29 s against
#: 1.13-1.14 s: ``grow_unit`` from empty, three runs each, alternating, 2026-11-26)
AGM_RTOL = 1e-8
#: ... or after this many iterations (converging inputs need at most 13, down to kc =
#: 1e-300)
AGM_MAX_ITER = 60


@njit(cache=True)
def ellipk_complement(kc):
    """K(k) from the complementary modulus kc = sqrt(1 - k^2), by the AGM (machine precision).

    Taking kc (not k) keeps full relative accuracy near the logarithmic singularity k -> 1.
    """
    a = 1.0
    b = kc
    for _ in range(AGM_MAX_ITER):
        if abs(a - b) <= AGM_RTOL * a:
            break
        a, b = 0.5 * (a + b), np.sqrt(a * b)
    return np.pi / (a + b)


@njit(cache=True)
def kernel_times_s(r, s, d):
    """G(r, s) * s, the integrand weight of the axisymmetric Boussinesq kernel.

    ``d = |s - r|`` is passed separately so that it keeps full relative accuracy when s
    is closer to r than a float can resolve (the graded quadrature samples there).
    """
    if r == 0.0:
        return 2.0
    if s == 0.0:
        return 0.0
    if s < r:
        kc = np.sqrt(d * (r + s)) / r
        return 4.0 / np.pi * ellipk_complement(kc) * s / r
    kc = np.sqrt(d * (s + r)) / s
    return 4.0 / np.pi * ellipk_complement(kc)


@njit(cache=True)
def _piece_pair(r, sa, sb, singular_at, xs_smooth, ws_smooth, xs_sing, ws_sing, xs_far,
                ws_far):
    """:func:`_piece` on [sa, sb] for the rising half hat (phi from 0 at sa to 1 at sb) and
    the falling one (1 to 0) at once: (rising, falling). The two share the quadrature points
    and so the kernel's values; each sum is the same sequence of operations as
    :func:`_piece`'s, so each is the same to the bit."""
    L = sb - sa
    rising = 0.0
    falling = 0.0
    if singular_at == 0:
        far = abs(0.5 * (sa + sb) - r)
        if far > FARTHER_PIECES[2] * L:
            xs_smooth, ws_smooth = GL4_X, GL4_W
        elif far > FARTHER_PIECES[1] * L:
            xs_smooth, ws_smooth = GL5_X, GL5_W
        elif far > FARTHER_PIECES[0] * L:
            xs_smooth, ws_smooth = GL6_X, GL6_W
        elif far > FAR_PIECES * L:
            xs_smooth = xs_far
            ws_smooth = ws_far
        for q in range(xs_smooth.size):
            s = sa + L * xs_smooth[q]
            kts = kernel_times_s(r, s, abs(s - r))
            phi_r = 0.0 + (1.0 - 0.0) * xs_smooth[q]
            phi_f = 1.0 + (0.0 - 1.0) * xs_smooth[q]
            rising += ws_smooth[q] * phi_r * kts
            falling += ws_smooth[q] * phi_f * kts
        return rising * L, falling * L
    p = GRADING
    for q in range(xs_sing.size):
        t = xs_sing[q]
        x = L * t ** p           # distance from the singular end
        jac = L * p * t ** (p - 1.0)
        if singular_at < 0:
            s = sa + x
            phi_r = 0.0 + (1.0 - 0.0) * (x / L)
            phi_f = 1.0 + (0.0 - 1.0) * (x / L)
        else:
            s = sb - x
            phi_r = 1.0 + (0.0 - 1.0) * (x / L)
            phi_f = 0.0 + (1.0 - 0.0) * (x / L)
        kts = kernel_times_s(r, s, x)
        rising += ws_sing[q] * phi_r * kts * jac
        falling += ws_sing[q] * phi_f * kts * jac
    return rising, falling


@njit(cache=True)
def _entry(ext, i, j, xs_smooth, ws_smooth, xs_sing, ws_sing, xs_far, ws_far):
    """A_ij alone: the deflection at node i (radius ext[i]) of the hat of node j, whose
    vertices are ext[j-1], ext[j], ext[j+1] (node 0: the half hat on [ext[0], ext[1]]): its
    rising piece, then its falling one. The assemblies below build every entry this way,
    element by element; tests/kernels/test_influence.py checks them against it, to the bit."""
    val = 0.0
    if j > 0:
        val += _piece_pair(ext[i], ext[j - 1], ext[j], _singular_end(i, j - 1), xs_smooth,
                           ws_smooth, xs_sing, ws_sing, xs_far, ws_far)[0]
    val += _piece_pair(ext[i], ext[j], ext[j + 1], _singular_end(i, j), xs_smooth, ws_smooth,
                       xs_sing, ws_sing, xs_far, ws_far)[1]
    return val


@njit(cache=True)
def _singular_end(i, k):
    """Which end of the element [ext[k], ext[k+1]] is node i, where the kernel is singular:
    -1 the inner, +1 the outer, 0 neither (or i = 0, r = 0, where it is smooth)."""
    if i == 0:
        return 0
    if i == k:
        return -1
    if i == k + 1:
        return 1
    return 0


@njit(cache=True)
def influence_matrix_nodes(r, xs_smooth, ws_smooth, xs_sing, ws_sing, xs_far, ws_far):
    """Influence matrix A (N x N) for the hats of arbitrary nodes 0 = r_0 < r_1 < ... .

    The hat of node j spans [r_{j-1}, r_{j+1}]; node 0 has the half hat on [0, r_1] and
    the last node a full hat whose outer piece is as long as the last element (the
    convention of the uniform mesh, :func:`assemble_unit`).
    Quadrature as in the uniform case; the far-piece rule applies from three piece lengths
    on, which stays exact to rounding for neighbouring elements of similar length (graded
    meshes with ratios up to about 1.3).

    Element by element: the element [r_k, r_k+1] carries the falling piece of hat k and the
    rising piece of hat k + 1, integrated together (:func:`_piece_pair`: the kernel
    evaluated once for both), each entry summed in :func:`_entry`'s order (rising piece,
    then falling), so the matrix is :func:`_entry`'s to the bit in half the kernel
    evaluations.
    """
    N = r.size
    ext = np.empty(N + 1)
    for i in range(N):      # a loop: a slice assignment compiles a shape-mismatch message
        ext[i] = r[i]
    ext[N] = 2.0 * r[N - 1] - r[N - 2]
    A = np.zeros((N, N))
    _elements_into(A, ext, 0, N, 0, N, xs_smooth, ws_smooth, xs_sing, ws_sing, xs_far,
                   ws_far)
    return A


@njit(cache=True)
def _elements_into(A, ext, i0, i1, j0, j1, xs_smooth, ws_smooth, xs_sing, ws_sing, xs_far,
                   ws_far):
    """Add to A[i0:i1, j0:j1] (zeros there) the hats of nodes j0..j1-1 at nodes i0..i1-1,
    element by element: the element [ext[k], ext[k+1]] carries the falling piece of hat k
    and the rising piece of hat k + 1 (:func:`_piece_pair`); the elements in increasing
    order, so that each entry is its rising piece plus its falling one, as :func:`_entry`."""
    for i in range(i0, i1):
        ri = ext[i]
        for k in range(max(j0 - 1, 0), j1):
            rising, falling = _piece_pair(ri, ext[k], ext[k + 1], _singular_end(i, k),
                                          xs_smooth, ws_smooth, xs_sing, ws_sing, xs_far,
                                          ws_far)
            if k >= j0:
                A[i, k] += falling
            if k + 1 < j1:
                A[i, k + 1] += rising


@njit(cache=True)
def unit_block_into(A, i0, i1, j0, j1, xs_smooth, ws_smooth, xs_sing, ws_sing, xs_far,
                    ws_far):
    """Fill A[i0:i1, j0:j1] with the unit-spacing influence matrix (r_j = j).

    Its entries depend on i and j only (every hat of the lattice is a full unit hat but
    node 0's), not on the size of the matrix, so a matrix can grow by blocks.
    """
    ext = np.arange(max(i1, j1) + 1).astype(np.float64)
    A[i0:i1, j0:j1] = 0.0
    _elements_into(A, ext, i0, i1, j0, j1, xs_smooth, ws_smooth, xs_sing, ws_sing, xs_far,
                   ws_far)


def grow_unit(A_old: np.ndarray, N: int) -> np.ndarray:
    """The unit-spacing matrix of size ``N`` from its leading block ``A_old`` (any size
    <= N, may be read-only): only the new rows and columns are assembled."""
    m = A_old.shape[0]
    A = np.empty((N, N))
    A[:m, :m] = A_old
    rules = (GL16_X, GL16_W, GL32_X, GL32_W, GL8_X, GL8_W)
    if m < N:
        unit_block_into(A, 0, m, m, N, *rules)
        unit_block_into(A, m, N, 0, N, *rules)
    return A


def assemble_nodes(r: np.ndarray) -> np.ndarray:
    """Assemble the influence matrix of the nodes ``r`` with the module's quadrature rules."""
    r = np.ascontiguousarray(r, dtype=float)
    return influence_matrix_nodes(r, GL16_X, GL16_W, GL32_X, GL32_W, GL8_X, GL8_W)


@njit(cache=True)
def combine_lattice_hats(A_rows, idx):
    """Influence matrix of nodes on the integer lattice from the unit-spacing matrix.

    ``idx`` (N,) are increasing lattice indices with idx[0] = 0; ``A_rows`` (N, M) the rows
    idx of the unit-spacing matrix, M > idx[-1] + (idx[-1] - idx[-2]) - 1 columns. The hat
    of node j (vertices idx[j-1], idx[j], idx[j+1]; the last one's outer piece as long as
    its inner) is piecewise linear with kinks on lattice points, hence exactly the sum of
    the unit hats times its values there: column j = sum_k phi_j(k) A_rows[:, k].
    Multiply by the lattice spacing.
    """
    N = idx.size
    A = np.zeros((N, N))
    for j in range(N):
        c = idx[j]
        R = idx[j + 1] if j + 1 < N else 2 * idx[N - 1] - idx[N - 2]
        if j > 0:
            L = idx[j - 1]
            for k in range(L + 1, c):
                wk = (k - L) / (c - L)
                for i in range(N):
                    A[i, j] += wk * A_rows[i, k]
        for k in range(c, R):
            wk = (R - k) / (R - c)
            for i in range(N):
                A[i, j] += wk * A_rows[i, k]
    return A


def assemble_unit(N: int) -> np.ndarray:
    """Assemble the unit-spacing influence matrix (r_j = j) with the module's quadrature
    rules; multiply by dr for spacing dr."""
    return assemble_nodes(np.arange(int(N), dtype=float))


@njit(cache=True)
def load_weights(N, dr):
    """Weights w_j with P = 2 pi sum_j w_j p_j (exact for the piecewise-linear traction)."""
    w = np.empty(N)
    w[0] = dr * dr / 6.0
    for j in range(1, N):
        w[j] = j * dr * dr
    return w


@njit(cache=True)
def load_weights_nodes(r):
    """Load weights w_j = int phi_j(s) s ds of the hats of arbitrary nodes ``r``.

    Exact for piecewise-linear traction; the last node has a full hat (outer piece as
    long as the last element), as in :func:`load_weights`.
    """
    N = r.size
    w = np.zeros(N)
    for j in range(N):
        if j > 0:               # rising piece [r_{j-1}, r_j]: int x (a + L x) L dx
            a = r[j - 1]
            b = r[j]
            w[j] += (b - a) * (a + 2.0 * b) / 6.0
        a = r[j]                # falling piece [r_j, r_{j+1}]
        b = r[j + 1] if j + 1 < N else 2.0 * r[N - 1] - r[N - 2]
        w[j] += (b - a) * (2.0 * a + b) / 6.0
    return w
