"""Slow, obviously-correct reference implementation of the axisymmetric adhesive BEM.

Plain numpy/scipy (no Numba), written independently of ``kernels/`` and ``sweep/engine/bem.py``;
only ``sweep.errors`` may be imported from the package. Used by the tests to check the fast
solver on small problems (N ~ 60..200 nodes, coarse indentation steps).

Units and conventions: docs/design.md sections 1, 2, 4 (dimensionless, hats dropped, E* = 1, R = 1).

* lengths in the plane (r, a): a_ref; normal lengths (h, u, delta, h0): d_ref;
  traction sigma: p_ref (positive = compressive); load P: pi dg R; time t: tau0.
* h0 = 1 / (pi^(2/3) mu);  h_m = 3^(1/6) h0 (gap of the most tensile LJ traction).
* gap h = -delta + h0 + r^2/2 + u,  u = A sigma (elastic, Chat = 1).

Discretization
--------------
Uniform mesh r_j = j dr, j = 0..N-1 (node 0 at r = 0). The traction is piecewise linear in r
with nodal values p_j ("overlapping triangles"): phi_0 is the half hat on [0, dr], phi_j
(0 < j < N-1) the full hat on [r_{j-1}, r_{j+1}], and, by the choice made here, the LAST node
carries a half hat on [r_{N-2}, r_{N-1}]: the traction is zero for r > r_{N-1} (the mesh and the
loaded domain both end at the last node). ``tail="full"`` gives the paper's alternative (a full
triangle that falls to zero at r_N = N dr); it changes only the last column of A and the last
load weight: the elastic pull-off at mu = 3.24 (N = 500, dr = 0.01) moves by 1.3e-6.

Influence matrix A_ij = int phi_j(s) G(r_i, s) s ds by ``scipy.integrate.quad`` on each linear
piece; the log singularity of G at s = r_i sits at an end point of the pieces (which QUADPACK's
QAGS extrapolation handles), and K is evaluated through ``ellipkm1(1 - m)`` with
1 - m = (r - s)(r + s)/max(r, s)^2 formed without cancellation. A scales exactly linearly with dr
(A(dr) = dr A(1)), so the quadrature is done once per N at dr = 1 and cached in memory.

Load P = 2 pi sum_j w_j p_j with w_j = int phi_j(r) r dr EXACT for the piecewise-linear traction:
w_0 = dr^2/6, w_j = j dr^2 (interior), w_{N-1} = dr^2 ((N-2)/2 + 1/3) for the half hat
(w_{N-1} = (N-1) dr^2 for tail="full").

``lj_tail=True`` adds the Lennard-Jones attraction beyond the traction's end r_end (r_{N-1} for
tail="half", r_N for tail="full") to P, the gap continued there as the rigid sphere's,
h(r) = h_{N-1} + (r^2 - r_{N-1}^2)/2, so dh = r dr and
P_tail = 2 pi int_{h_end}^inf sigma_LJ(h) dh, h_end = h(r_end), by quad in x = h0/h on [0, h0/h_end].
It changes P only (not the equations: displacement control). Default off (the independent
references of tests/data/independent_solutions.yaml drop it); the engine has it by default
(``Numerics.lj_tail``).

Solvers
-------
Dense Newton on the gap (numpy.linalg.solve), residual
F(h) = h - (-delta + h0 + r^2/2) - A (c sigma(h) + H), Jacobian I - c A diag(sigma'(h)),
backtracking line search that keeps h > 0 and decreases ||F||_2, converged when
max|F| < 1e-10 (F in d_ref units). c = 1, H = 0 for the elastic problem.

Viscoelastic: exact hereditary integral (no Prony series) with the traction piecewise linear in
time between steps, substrate fully relaxed at t = 0 under the traction sigma_0:

    u(t_n) = A [ sigma_0 + sum_{m=1..n} (sigma_m - sigma_{m-1})/dt_m (Psi(t_n - t_{m-1}) - Psi(t_n - t_m)) ]

Psi(T) = int_0^T Chat, closed form for the MPL retardation compliance (docs/design.md section 3) and
for the SLS. The unknown sigma_n enters with weight c = Psi(dt_n)/dt_n.

Folds: on a coarse mesh (process zone ~ one element: at mu = 3.24 dr >~ 0.02, at mu = 6
dr >~ 0.005) the discrete equilibrium branch has folds where the contact edge snaps from node
to node ("lattice trapping"); Newton from the previous state then fails (the Jacobian becomes
singular). :func:`solve_gap` then finds the state the system snaps to by pseudo-transient
relaxation dh/dtau = -F(h) from the previous state (:func:`relax_gap`), and the runs list those
steps in ``snaps``. Results with snaps near the pull-off are mesh artefacts: compare fast and
naive solvers on snap-free settings (see tests/test_naive.py for measured examples).

Starting state of ``naive_unload`` (and of ``naive_elastic`` without ``h_init``): the fully
relaxed elastic (Chat = 1) LJ solution at delta0, by Newton directly from a JKR initial gap
(h = h0 inside the JKR radius a(delta0) on the stable branch, the JKR Hertz + flat-punch gap
plus h0 outside), with the relaxation above as the fallback. No continuation in delta is
needed in practice (Newton from the JKR gap converged in every case tried, mu = 1..6).

Outputs: pull-off = |min P| refined by the parabola through the three samples around the
minimum; radii a (gap = h_m) and a_inner (gap = h0), outermost crossing, linear interpolation;
crack speed -da/dt at the pull-off instant from a least-squares quadratic in t over the samples
whose a lies within 3 node spacings of a(pull-off) (at least 5 samples).
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np
from scipy import integrate, optimize, special

from sweep.errors import check_choice, check_int, check_positive, check_range

__all__ = [
    "lj_h0",
    "lj_hm",
    "lj_traction",
    "lj_dtraction",
    "influence_matrix_quad",
    "load_weights",
    "uniform_disc_deflection",
    "hertz_deflection",
    "jkr_load",
    "jkr_delta",
    "jkr_radius",
    "jkr_gap",
    "creep_mpl",
    "psi_mpl",
    "creep_sls",
    "psi_sls",
    "hereditary_effective_traction",
    "radius_at_gap",
    "newton_gap",
    "naive_elastic",
    "naive_elastic_pulloff",
    "naive_unload",
    "lj_tail_load",
]

NEWTON_TOL = 1e-10
NEWTON_MAXIT = 100


class NewtonFailure(RuntimeError):
    """The dense Newton iteration did not converge."""


# --------------------------------------------------------------------------------------------
# Lennard-Jones law
# --------------------------------------------------------------------------------------------
def lj_h0(mu: float) -> float:
    """Equilibrium distance h0 = 1 / (pi^(2/3) mu) (d_ref units)."""
    return 1.0 / (math.pi ** (2.0 / 3.0) * mu)


def lj_hm(mu: float) -> float:
    """Gap of the most tensile LJ traction, h_m = 3^(1/6) h0."""
    return 3.0 ** (1.0 / 6.0) * lj_h0(mu)


def _lj_c(mu: float) -> float:
    return 8.0 * mu / (3.0 * math.pi ** (1.0 / 3.0))


def lj_traction(h, mu: float):
    """sigma(h) = -(8 mu / (3 pi^(1/3))) [ (h0/h)^3 - (h0/h)^9 ]   (positive = compressive)."""
    x = lj_h0(mu) / np.asarray(h, dtype=float)
    return -_lj_c(mu) * (x**3 - x**9)


def lj_dtraction(h, mu: float):
    """d sigma / d h = (8 mu / (3 pi^(1/3))) [ 3 (h0/h)^3 - 9 (h0/h)^9 ] / h."""
    h = np.asarray(h, dtype=float)
    x = lj_h0(mu) / h
    return _lj_c(mu) * (3.0 * x**3 - 9.0 * x**9) / h


# --------------------------------------------------------------------------------------------
# Influence matrix
# --------------------------------------------------------------------------------------------
def _kernel_s(r: float, s: float) -> float:
    """G(r, s) * s, the integrand of u(r) = int sigma(s) G(r, s) s ds (E* = 1)."""
    if r == 0.0:
        return 2.0  # G(0, s) = 2 / s
    if s == r:
        return math.inf
    if s < r:
        p = (r - s) * (r + s) / (r * r)  # 1 - (s/r)^2
        return 4.0 * s / (math.pi * r) * float(special.ellipkm1(p))
    p = (s - r) * (s + r) / (s * s)  # 1 - (r/s)^2
    return 4.0 / math.pi * float(special.ellipkm1(p))


def _quad(f, a, b):
    val, err = integrate.quad(f, a, b, epsabs=1e-14, epsrel=1e-12, limit=200)
    return val


@lru_cache(maxsize=8)
def _unit_pieces(n_nodes: int):
    """Element integrals at dr = 1 for nodes 0..n_nodes-1 and elements 0..n_nodes-1.

    Element e = [e, e+1]. ``fall[i, e] = int_e G(i, s) s (e+1-s) ds`` (falling part of the hat of
    node e), ``rise[i, e] = int_e G(i, s) s (s-e) ds`` (rising part of the hat of node e+1).
    The element n_nodes-1 (beyond the last node) is only used by tail="full".
    """
    fall = np.zeros((n_nodes, n_nodes))
    rise = np.zeros((n_nodes, n_nodes))
    for i in range(n_nodes):
        r = float(i)
        for e in range(n_nodes):
            a, b = float(e), float(e + 1)
            fall[i, e] = _quad(lambda s: _kernel_s(r, s) * (b - s), a, b)
            rise[i, e] = _quad(lambda s: _kernel_s(r, s) * (s - a), a, b)
    return fall, rise


_PIECE_CACHE: dict = {}


def _pieces(n_nodes: int):
    """Slice the largest cached unit-piece matrices (their entries do not depend on N)."""
    for m in sorted(_PIECE_CACHE):
        if m >= n_nodes:
            fall, rise = _PIECE_CACHE[m]
            return fall[:n_nodes, :n_nodes], rise[:n_nodes, :n_nodes]
    _PIECE_CACHE[n_nodes] = _unit_pieces(n_nodes)
    return _PIECE_CACHE[n_nodes]


def influence_matrix_quad(N: int, dr: float, tail: str = "half") -> np.ndarray:
    """Dense influence matrix A (N x N), u_i = sum_j A_ij p_j, by adaptive quadrature.

    Parameters
    ----------
    N : int
        Number of nodes, r_j = j dr, j = 0..N-1.
    dr : float
        Node spacing (a_ref units).
    tail : {"half", "full"}
        Basis of the last node: half hat on [r_{N-2}, r_{N-1}] (zero traction beyond the last
        node; default) or the full triangle falling to zero at r_N.
    """
    N = check_int("N", N, lo=2)
    dr = check_positive("dr", dr)
    check_choice("tail", tail, ("half", "full"))
    fall, rise = _pieces(N)
    A = np.zeros((N, N))
    # node j: rising part on element j-1 (j >= 1), falling part on element j
    A[:, 1:] += rise[:, : N - 1]
    A[:, : N - 1] += fall[:, : N - 1]
    if tail == "full":
        A[:, N - 1] += fall[:, N - 1]
    return dr * A


def load_weights(N: int, dr: float, tail: str = "half") -> np.ndarray:
    """w_j = int phi_j(r) r dr, so that P = 2 pi sum_j w_j p_j exactly."""
    w = np.arange(N, dtype=float) * dr * dr
    w[0] = dr * dr / 6.0
    if tail == "half":
        w[N - 1] = dr * dr * ((N - 2) / 2.0 + 1.0 / 3.0)
    return w


# --------------------------------------------------------------------------------------------
# Closed forms
# --------------------------------------------------------------------------------------------
def uniform_disc_deflection(r, a: float, p: float = 1.0):
    """Deflection (E* = 1) of a uniform pressure p on the disc of radius a.

    u = (4 p a / pi) E(r/a) for r <= a, (4 p r / pi) [E(a/r) - (1 - a^2/r^2) K(a/r)] for r > a
    (moduli; scipy takes m = modulus^2).
    """
    r = np.atleast_1d(np.asarray(r, dtype=float))
    u = np.empty_like(r)
    inside = r <= a
    ri = r[inside]
    u[inside] = 4.0 * p * a / math.pi * special.ellipe((ri / a) ** 2)
    ro = r[~inside]
    m = (a / ro) ** 2
    u[~inside] = 4.0 * p * ro / math.pi * (special.ellipe(m) - (1.0 - m) * special.ellipk(m))
    return u


def hertz_deflection(r, a: float, p0: float = 1.0):
    """Deflection under p0 sqrt(1 - r^2/a^2) (E* = 1): pi p0 (2a^2 - r^2)/(4a) inside,
    (p0/(2a)) [(2a^2 - r^2) asin(a/r) + a sqrt(r^2 - a^2)] outside."""
    r = np.atleast_1d(np.asarray(r, dtype=float))
    u = np.empty_like(r)
    inside = r <= a
    u[inside] = math.pi * p0 * (2 * a * a - r[inside] ** 2) / (4 * a)
    ro = r[~inside]
    u[~inside] = p0 / (2 * a) * ((2 * a * a - ro**2) * np.arcsin(a / ro) + a * np.sqrt(ro**2 - a * a))
    return u


def jkr_load(a):
    """JKR load P = (4/3) a^3 - 2 sqrt(2) a^(3/2) (units pi dg R)."""
    a = np.asarray(a, dtype=float)
    return 4.0 / 3.0 * a**3 - 2.0 * math.sqrt(2.0) * a**1.5


def jkr_delta(a):
    """JKR indentation delta = a^2 - sqrt(2 a) (d_ref units)."""
    a = np.asarray(a, dtype=float)
    return a**2 - np.sqrt(2.0 * a)


def jkr_radius(delta: float) -> float:
    """JKR contact radius on the branch d delta/da > 0 (a > 1/2, where 2a = 1/sqrt(2a))."""
    a_min = 0.5
    if delta <= float(jkr_delta(a_min)):
        return a_min
    hi = max(1.0, math.sqrt(abs(delta)) + 2.0)
    return optimize.brentq(lambda a: float(jkr_delta(a)) - delta, a_min, hi, xtol=1e-14)


def jkr_gap(r, delta: float, mu: float):
    """JKR-like initial gap: h0 inside a_JKR(delta); outside, h0 + JKR separation
    r^2/2 - delta + u_Hertz + u_punch with p0 = 2a/pi and punch displacement -sqrt(2a)."""
    r = np.asarray(r, dtype=float)
    h0 = lj_h0(mu)
    a = jkr_radius(delta)
    d = float(jkr_delta(a))
    h = np.full_like(r, h0)
    ro = r[r > a]
    u_h = hertz_deflection(ro, a, p0=2.0 * a / math.pi)
    u_f = 2.0 / math.pi * (-math.sqrt(2.0 * a)) * np.arcsin(a / ro)
    h[r > a] = h0 + np.maximum(ro**2 / 2.0 - d + u_h + u_f, 0.0)
    return h


# --------------------------------------------------------------------------------------------
# Creep compliances
# --------------------------------------------------------------------------------------------
def creep_mpl(t, n: float, k: float):
    """Normalized MPL retardation compliance Chat(t) = 1 - (1-k) 2 t^(n/2) K_n(2 sqrt t)/Gamma(n).

    Chat(0) = k, Chat(inf) = 1 (t in tau0 units).
    """
    t = np.asarray(t, dtype=float)
    with np.errstate(invalid="ignore", over="ignore"):
        f = 2.0 * t ** (n / 2.0) * special.kv(n, 2.0 * np.sqrt(t)) / special.gamma(n)
    f = np.where(t > 0, f, 1.0)
    f = np.where(np.isfinite(f), f, 0.0)  # kv underflow at huge t
    return 1.0 - (1.0 - k) * f


def _psi_mpl_closed(T, n, k):
    X = 2.0 * np.sqrt(T)
    with np.errstate(invalid="ignore", over="ignore"):
        tail = 2.0 ** (-n) / special.gamma(n) * X ** (n + 1) * special.kv(n + 1, X)
    tail = np.where(np.isfinite(tail), tail, 0.0)
    return T - (1.0 - k) * (n - tail)


PSI_QUAD_BELOW = 1e-3


def psi_mpl(T, n: float, k: float):
    """Integrated compliance Psi(T) = int_0^T Chat = T - (1-k)[n - 2^(-n)/Gamma(n) X^(n+1) K_{n+1}(X)],
    X = 2 sqrt T. For T < 1e-3 (where the bracket cancels) it is computed by quad of Chat."""
    T = np.atleast_1d(np.asarray(T, dtype=float))
    out = np.zeros_like(T)
    big = T >= PSI_QUAD_BELOW
    out[big] = _psi_mpl_closed(T[big], n, k)
    for idx in np.nonzero((T > 0) & ~big)[0]:
        out[idx] = integrate.quad(lambda t: float(creep_mpl(t, n, k)), 0.0, T[idx],
                                  epsabs=0.0, epsrel=1e-13, limit=200)[0]
    return out


def creep_sls(t, k: float):
    """SLS: Chat(t) = 1 - (1-k) exp(-t)."""
    return 1.0 - (1.0 - k) * np.exp(-np.asarray(t, dtype=float))


def psi_sls(T, k: float):
    """SLS: Psi(T) = T - (1-k)(1 - exp(-T))."""
    T = np.atleast_1d(np.asarray(T, dtype=float))
    return T + (1.0 - k) * np.expm1(-T)


# --------------------------------------------------------------------------------------------
# Hereditary integral (exact, O(n) per step)
# --------------------------------------------------------------------------------------------
def hereditary_effective_traction(t, sigma, psi):
    """Return (c, H) with sum_m ... = c sigma_n + H, for the step ending at t[-1].

    ``t`` = [t_0 = 0, t_1, ..., t_n]; ``sigma`` = [sigma_0, ..., sigma_{n-1}] (the current
    traction sigma_n is the unknown), each row a nodal traction vector; ``psi`` = Psi(T).
    u(t_n) = A (c sigma_n + H), with c = Psi(dt_n)/dt_n and
    H = sigma_0 + sum_{m=1}^{n-1} (sigma_m - sigma_{m-1})/dt_m (Psi(t_n - t_{m-1}) - Psi(t_n - t_m))
        - c sigma_{n-1}.
    """
    t = np.asarray(t, dtype=float)
    sigma = np.asarray(sigma, dtype=float)
    n = len(t) - 1
    tn = t[n]
    dt_n = t[n] - t[n - 1]
    c = float(psi(np.array([dt_n]))[0]) / dt_n
    H = sigma[0].copy()
    if n >= 2:
        dt = np.diff(t[:n])  # dt_1..dt_{n-1}
        wts = (psi(tn - t[: n - 1]) - psi(tn - t[1:n])) / dt
        H += wts @ np.diff(sigma[:n], axis=0)
    H -= c * sigma[n - 1]
    return c, H


# --------------------------------------------------------------------------------------------
# Newton on the gap
# --------------------------------------------------------------------------------------------
def newton_gap(A, g0, mu, h_init, c=1.0, H=None, tol=NEWTON_TOL, maxit=NEWTON_MAXIT):
    """Solve F(h) = h - g0 - A (c sigma(h) + H) = 0 by dense Newton with a backtracking line search.

    Returns (h, iterations). Raises ``NewtonFailure`` if it does not converge.
    """
    N = len(g0)
    if H is None:
        H = np.zeros(N)
    h = np.array(h_init, dtype=float)
    if np.any(h <= 0):
        raise NewtonFailure("initial gap not positive")
    eye = np.eye(N)

    def resid(hh):
        return hh - g0 - A @ (c * lj_traction(hh, mu) + H)

    F = resid(h)
    nF = np.linalg.norm(F)
    for it in range(1, maxit + 1):
        J = eye - c * A * lj_dtraction(h, mu)[None, :]
        dh = np.linalg.solve(J, -F)
        alpha = 1.0
        while True:
            h_new = h + alpha * dh
            if np.all(h_new > 0):
                F_new = resid(h_new)
                nF_new = np.linalg.norm(F_new)
                if nF_new <= (1.0 - 1e-4 * alpha) * nF or nF_new < 1e-3 * tol:
                    break
            alpha *= 0.5
            if alpha < 1e-10:
                raise NewtonFailure(f"line search failed at iteration {it} (|F| = {nF:.3e})")
        h, F, nF = h_new, F_new, nF_new
        if np.max(np.abs(F)) < tol:
            return h, it
    raise NewtonFailure(f"no convergence in {maxit} iterations (|F|max = {np.max(np.abs(F)):.3e})")


def relax_gap(A, g0, mu, h_init, c=1.0, H=None, tol=NEWTON_TOL, max_iter=20000):
    """Equilibrium reached by the artificial relaxation dh/dtau = -F(h) from ``h_init``.

    Pseudo-transient continuation: backward-Euler steps (I/dtau + J) dh = -F with the
    switched-evolution-relaxation rule dtau <- dtau |F_old|/|F_new| (dtau quartered when a step
    would make a gap non-positive or grow |F| tenfold), then a Newton polish once |F| < 1e-6.
    Used only when Newton from the previous state fails, i.e. at a fold of the discrete
    equilibrium branch (on a coarse mesh the contact edge snaps from node to node, "lattice
    trapping"): the relaxation lands on the branch the system snaps to.
    Returns (h, iterations). Raises ``NewtonFailure`` if it does not settle.
    """
    N = len(g0)
    if H is None:
        H = np.zeros(N)
    h = np.array(h_init, dtype=float)
    eye = np.eye(N)

    def resid(hh):
        return hh - g0 - A @ (c * lj_traction(hh, mu) + H)

    F = resid(h)
    nF = np.linalg.norm(F)
    dtau = 0.1
    for it in range(1, max_iter + 1):
        if np.max(np.abs(F)) < 1e-6:
            try:
                hh, its = newton_gap(A, g0, mu, h, c=c, H=H, tol=tol)
                return hh, it + its
            except NewtonFailure:
                pass
        J = eye - c * A * lj_dtraction(h, mu)[None, :]
        dh = np.linalg.solve(eye / dtau + J, -F)
        h_new = h + dh
        if np.any(h_new <= 0.0):
            dtau *= 0.25
            continue
        F_new = resid(h_new)
        nF_new = np.linalg.norm(F_new)
        if nF_new > 10.0 * nF:
            dtau *= 0.25
            continue
        dtau = min(dtau * nF / max(nF_new, 1e-300), 1e6)
        h, F, nF = h_new, F_new, nF_new
    raise NewtonFailure(f"relaxation did not settle in {max_iter} iterations (|F| = {nF:.3e})")


def solve_gap(A, g0, mu, h_init, c=1.0, H=None):
    """Newton from ``h_init``; if it fails, relaxation (:func:`relax_gap`) then Newton.

    Returns (h, iterations, snapped) where ``snapped`` tells that the relaxation was needed.
    """
    try:
        h, its = newton_gap(A, g0, mu, h_init, c=c, H=H)
        return h, its, False
    except NewtonFailure:
        h, its = relax_gap(A, g0, mu, h_init, c=c, H=H)
        return h, its, True


def radius_at_gap(r, h, level: float) -> float:
    """Outermost radius where the gap crosses ``level`` (linear interpolation between nodes).

    0 if the gap exceeds ``level`` everywhere; r[-1] if it is below ``level`` at the last node.
    """
    below = np.nonzero(h < level)[0]
    if below.size == 0:
        return 0.0
    i = below[-1]
    if i == len(r) - 1:
        return float(r[-1])
    return float(r[i] + (level - h[i]) / (h[i + 1] - h[i]) * (r[i + 1] - r[i]))


def _mesh(N, dr):
    return np.arange(N, dtype=float) * dr


def _r_end(r, tail):
    """End of the traction: the last node (half hat) or one spacing beyond (full triangle)."""
    return float(r[-1]) if tail == "half" else float(2.0 * r[-1] - r[-2])


def lj_tail_load(h_last, r_last, r_end, mu):
    """2 pi int_{h_end}^inf sigma_LJ dh beyond r_end, the gap continued rigidly from the last
    node (h_end = h_last + (r_end^2 - r_last^2)/2), by quad in x = h0/h (dh = -h0 dx / x^2)."""
    h0 = lj_h0(mu)
    h_end = h_last + 0.5 * (r_end**2 - r_last**2)
    val, err = integrate.quad(lambda x: float(lj_traction(h0 / x, mu)) * h0 / x**2,
                              0.0, h0 / h_end, epsabs=0.0, epsrel=1e-13, limit=200)
    return 2.0 * math.pi * val


def _state(r, h, mu, w, sigma=None, r_end=None):
    """The state's record; ``r_end`` (not None): P with the Lennard-Jones tail beyond it."""
    if sigma is None:
        sigma = lj_traction(h, mu)
    P = float(2.0 * math.pi * np.dot(w, sigma))
    if r_end is not None:
        P += lj_tail_load(float(h[-1]), float(r[-1]), r_end, mu)
    return dict(
        gap=h,
        sigma=sigma,
        P=P,
        a=radius_at_gap(r, h, lj_hm(mu)),
        a_inner=radius_at_gap(r, h, lj_h0(mu)),
    )


def _elastic_solve(A, r, mu, delta, h_init):
    """(h, iterations, snapped) of the relaxed elastic problem at ``delta`` (see solve_gap)."""
    g0 = -delta + lj_h0(mu) + r**2 / 2.0
    return solve_gap(A, g0, mu, h_init)


def _elastic_start(A, r, mu, delta):
    """Relaxed elastic LJ solution at ``delta``: Newton from the JKR gap, relaxation if needed."""
    h, _, _ = _elastic_solve(A, r, mu, delta, jkr_gap(r, delta, mu))
    return h


def naive_elastic(mu, delta, N, dr, h_init=None, tail="half", lj_tail=False):
    """Relaxed elastic LJ equilibrium at indentation ``delta``.

    Returns dict(gap, sigma, P, a, a_inner, r). Starts from ``h_init`` if given, else from the
    JKR gap (see module docstring); :func:`solve_gap` (Newton, relaxation on failure).
    ``lj_tail``: P with the Lennard-Jones attraction beyond the mesh (module docstring).
    """
    mu = check_positive("mu", mu)
    delta = check_range("delta", delta)
    A = influence_matrix_quad(N, dr, tail)
    r = _mesh(N, dr)
    w = load_weights(N, dr, tail)
    if h_init is None:
        h = _elastic_start(A, r, mu, delta)
    else:
        h, _, _ = _elastic_solve(A, r, mu, delta, h_init)
    out = _state(r, h, mu, w, r_end=_r_end(r, tail) if lj_tail else None)
    out["r"] = r
    return out


def _recovered(P, recover):
    """Past the tensile minimum: P - Pmin > recover |Pmin| and P rising over the last 3 steps
    (a single upward jump, e.g. a node-to-node snap on a coarse mesh, does not count)."""
    pmin = min(P)
    return (pmin < 0 and P[-1] - pmin > recover * abs(pmin) and len(P) >= 4
            and P[-1] > P[-2] > P[-3] > P[-4])


def _parabola_min(x, y):
    """Vertex of the parabola through three points (falls back to the middle point)."""
    c2, c1, c0 = np.polyfit(x, y, 2)
    if c2 <= 0:
        return float(x[1]), float(y[1])
    xv = -c1 / (2 * c2)
    if not (x[0] <= xv <= x[2]):
        return float(x[1]), float(y[1])
    return float(xv), float(np.polyval([c2, c1, c0], xv))


def naive_elastic_pulloff(mu, N, dr, step, a_start=2.0, tail="half", recover=0.05,
                          lj_tail=False):
    """Quasi-static elastic (Chat = 1) unloading under displacement control.

    Starts from the LJ solution at delta = jkr_delta(a_start) and decreases delta by
    ``step * h0`` per step (Newton from the previous gap; at a fold of the discrete branch the
    relaxation of :func:`solve_gap` finds the state it snaps to, counted in ``snaps``) until P
    has passed its minimum and recovered by ``recover`` |Pmin| (rising over the last 3
    steps), or a -> 0.
    Pull-off = |min P|, refined by the parabola through the three samples around the minimum
    (as a function of delta). Returns dict(pull_off, delta_pulloff, a_pulloff, delta, P, a,
    a_inner, stop). ``lj_tail``: P with the Lennard-Jones attraction beyond the mesh.
    """
    mu = check_positive("mu", mu)
    step = check_positive("step", step)
    A = influence_matrix_quad(N, dr, tail)
    r = _mesh(N, dr)
    w = load_weights(N, dr, tail)
    h0 = lj_h0(mu)
    delta = float(jkr_delta(a_start))
    h = _elastic_start(A, r, mu, delta)
    D, P, Ar, Ai = [], [], [], []
    stop = "max_steps"
    snaps = []
    r_end = _r_end(r, tail) if lj_tail else None
    for _ in range(100000):
        s = _state(r, h, mu, w, r_end=r_end)
        D.append(delta); P.append(s["P"]); Ar.append(s["a"]); Ai.append(s["a_inner"])
        if _recovered(P, recover):
            stop = "recovered"
            break
        if s["a"] <= 0.0:
            stop = "a0"
            break
        delta -= step * h0
        try:
            h, _, snapped = _elastic_solve(A, r, mu, delta, h)
        except NewtonFailure:
            stop = "newton"
            break
        if snapped:
            snaps.append(len(D))
    D, P, Ar, Ai = map(np.array, (D, P, Ar, Ai))
    i = int(np.argmin(P))
    if 0 < i < len(P) - 1:
        d_star, p_star = _parabola_min(D[i - 1:i + 2][::-1], P[i - 1:i + 2][::-1])
    else:
        d_star, p_star = float(D[i]), float(P[i])
    a_star = float(np.interp(d_star, D[::-1], Ar[::-1]))
    return dict(pull_off=abs(p_star), delta_pulloff=d_star, a_pulloff=a_star,
                delta=D, P=P, a=Ar, a_inner=Ai, stop=stop, i_min=i, snaps=snaps)


def _crack_speed(t, a, t_star, a_star, dr, width=3.0, min_points=5):
    """-da/dt at t_star from a least-squares quadratic fit of a(t) over the contiguous samples
    around t_star whose a lies within +-width*dr of a_star (at least min_points samples)."""
    i0 = int(np.argmin(np.abs(t - t_star)))
    lo = i0
    while lo > 0 and abs(a[lo - 1] - a_star) <= width * dr:
        lo -= 1
    hi = i0
    while hi < len(t) - 1 and abs(a[hi + 1] - a_star) <= width * dr:
        hi += 1
    while hi - lo + 1 < min_points and (lo > 0 or hi < len(t) - 1):
        if lo > 0:
            lo -= 1
        if hi < len(t) - 1 and hi - lo + 1 < min_points:
            hi += 1
    ts, as_ = t[lo:hi + 1], a[lo:hi + 1]
    deg = 2 if len(ts) >= 4 else 1
    coef = np.polyfit(ts - t_star, as_, deg)
    return float(-np.polyval(np.polyder(coef), 0.0)), (lo, hi)


def naive_unload(n, k, mu, delta0, rate, N, dr, step, material="mpl", tail="half",
                 recover=0.05, max_steps=200000, min_dt_fraction=1.0 / 64, lj_tail=False):
    """Viscoelastic unloading from a fully relaxed contact at delta0 (exact hereditary integral).

    Parameters
    ----------
    n, k : MPL exponent and k = E0/Einf = Chat(0) (``n`` unused for material="sls").
    mu : Tabor parameter.  delta0 : initial indentation (d_ref).  rate : unloading rate
    (d delta/dt = -rate h0, time in tau0).  N, dr : mesh.  step : indentation step in units of
    h0 (dt = step / rate).  material : "mpl" (retardation spectrum) or "sls".

    Each step: :func:`solve_gap` (Newton from the previous gap; relaxation at a fold, step index
    recorded in ``snaps``). If that fails too, the step is retried with halved dt (down to
    ``min_dt_fraction`` of the nominal step); then the run stops with stop="newton".
    ``lj_tail``: P with the Lennard-Jones attraction beyond the mesh (module docstring).

    Returns dict(pull_off, t_pulloff, delta_pulloff, a_pulloff, a_inner_pulloff, crack_speed,
    a0, a0_inner, P0, t, delta, P, a, a_inner, stop, steps, newton_iterations).
    """
    mu = check_positive("mu", mu)
    k = check_range("k", k, lo=0.0, hi=1.0, lo_open=True)
    rate = check_positive("rate", rate)
    step = check_positive("step", step)
    check_choice("material", material, ("mpl", "sls"))
    if material == "mpl":
        n = check_positive("n", n)
        psi = lambda T: psi_mpl(T, n, k)  # noqa: E731
    else:
        psi = lambda T: psi_sls(T, k)  # noqa: E731
    A = influence_matrix_quad(N, dr, tail)
    r = _mesh(N, dr)
    w = load_weights(N, dr, tail)
    h0 = lj_h0(mu)
    base = h0 + r**2 / 2.0

    r_end = _r_end(r, tail) if lj_tail else None
    h = _elastic_start(A, r, mu, delta0)
    s0 = _state(r, h, mu, w, r_end=r_end)
    T, D, P, Ar, Ai = [0.0], [delta0], [s0["P"]], [s0["a"]], [s0["a_inner"]]
    sig = [s0["sigma"]]
    dt_nom = step / rate
    newton_its = 0
    snaps = []
    stop = "max_steps"
    while len(T) <= max_steps:
        dt = dt_nom
        while True:
            t_new = T[-1] + dt
            d_new = delta0 - rate * h0 * t_new
            c, H = hereditary_effective_traction(np.array(T + [t_new]), np.array(sig), psi)
            try:
                h_new, its, snapped = solve_gap(A, base - d_new, mu, h, c=c, H=H)
                break
            except NewtonFailure:
                dt *= 0.5
                if dt < dt_nom * min_dt_fraction:
                    h_new = None
                    break
        if h_new is None:
            stop = "newton"
            break
        newton_its += its
        if snapped:
            snaps.append(len(T))
        h = h_new
        s = _state(r, h, mu, w, r_end=r_end)
        T.append(t_new); D.append(d_new); P.append(s["P"]); Ar.append(s["a"]); Ai.append(s["a_inner"])
        sig.append(s["sigma"])
        if _recovered(P, recover):
            stop = "recovered"
            break
        if s["a"] <= 0.0:
            stop = "a0"
            break
    T, D, P, Ar, Ai = map(np.array, (T, D, P, Ar, Ai))
    i = int(np.argmin(P))
    if 0 < i < len(P) - 1:
        t_star, p_star = _parabola_min(T[i - 1:i + 2], P[i - 1:i + 2])
    else:
        t_star, p_star = float(T[i]), float(P[i])
    a_star = float(np.interp(t_star, T, Ar))
    v, window = _crack_speed(T, Ar, t_star, a_star, dr)
    return dict(
        pull_off=abs(p_star), t_pulloff=t_star,
        delta_pulloff=float(np.interp(t_star, T, D)),
        a_pulloff=a_star, a_inner_pulloff=float(np.interp(t_star, T, Ai)),
        crack_speed=v, crack_speed_window=window,
        a0=float(Ar[0]), a0_inner=float(Ai[0]), P0=float(P[0]),
        t=T, delta=D, P=P, a=Ar, a_inner=Ai, stop=stop, steps=len(T) - 1,
        newton_iterations=newton_its, i_min=i, snaps=snaps,
    )
