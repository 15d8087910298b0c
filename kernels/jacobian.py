"""Newton's linear algebra: a kept factorization of the contact, the crack-tip zone exact
(Numba kernels).

Each solve of the unloading needs J^-1 v for the Jacobian of
F(h) = h - g - A [C_eff sigma(h) - H] (:mod:`kernels.solve`),

    J = I - A diag(E),    E = C_eff sigma'(h)   (the *effective stiffness* of each node).

Where the stiffness changes, and how fast. Far outside the contact the gap is wide open and
E is negligible: those columns of J are the identity. Inside the contact E drifts slowly
(about 1 % per time step, as the pressure falls). Across the crack tip a node runs through
the whole Lennard-Jones curve in the few steps the tip takes to pass it: there E changes by
O(1) per step. The nodes are split accordingly (radial order, by index):

* S = [0, m), the interacting prefix: the last node of S is the last one whose
  A_ii |E_i| > SUBSET_EPS when the factorization is made (E without the process zone's
  rate term, below); beyond it (the far field, F)
  the columns are taken as the identity;
* Z = [z_lo, z_hi), the crack-tip zone: ZONE_IN nodes inside the crack tip (the last node
  where sigma' < 0) and ZONE_OUT outside it, cut to S;
* B = S minus Z: the contact interior and the weak tail outside the zone.

The approximate Jacobian is J with E frozen on B at its value when factorized (E_b), zero on
F and exact on Z (its value at the last refresh of the zone). With a process zone
(:func:`kernels.interface.traction_and_stiffness`) the crack tip is found from the stiffness
without its rate term: the rate term makes every opening node's stiffness negative, and the
zone was placed at the mesh's outer end (measured on n 0.5, k 0.1, mu 5, rate 10: 105
refactorizations for slow contraction). S, and whether a far-field node became stiff, are
judged from the stiffness without the rate term too: with it every opening node counts, and S
was the whole mesh (451 of 452 nodes against 369 without a process zone on n 0.5, k 0.1, mu 5,
a0 1.5, rate 1; the rate-100 scene's run took 0.11 s instead of 0.13 s). Inside S the
Jacobian keeps the rate term: left out of it beyond the zone, it made the first step's Newton
diverge (it dominates the opening nodes' stiffness). Block elimination of B:

    K = I - A_BB diag(E_b)             b x b, LU in single precision (LAPACK sgetrf through
                                       :mod:`kernels.blas`; see FACTOR_DTYPE)
    X = K^-1 A_BZ                      z columns, with the factorization
    C = A_ZZ + A_ZB diag(E_b) X        z x z, with the factorization
    Sigma = I - C diag(E_Z)            z x z, refactorized whenever E_Z moved (O(z^3))

    solve:  y = K^-1 v_B
            x_Z = Sigma^-1 (v_Z + A_ZB diag(E_b) y)
            x_B = y + X diag(E_Z) x_Z
            x_F = v_F + A_FS diag(E) x_S

The zone follows the crack tip exactly at the cost of a z x z factorization; the drift of
the interior makes Newton a chord iteration there, contracting by about that drift. Where the
contact is pressed (the protocol's approach and dwell) the interior stiffens fast; there the
drift is taken out of the direction as a column scaling (STATE_SCALED,
:func:`scale_for_drift`). The
factorization of K is made again when the crack tip leaves the zone's inner part (it
recedes through ZONE_IN - ZONE_MARGIN nodes between two factorizations), when a node of F
becomes stiff, or when the caller finds the iteration contracting poorly
(:func:`kernels.solve.newton`).

The cache is a tuple of arrays (passed whole to the kernels), positions named by CACHE_*.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .blas import gemv_cols, gemv_rows, lu_factor, lu_solve
from .clock import deadline_after
from .interface import traction_and_stiffness

#: a node belongs to the factorized set S when A_ii |E_i| exceeds this (the columns left
#: out differ from the identity by less; their effect on Newton is of this order)
SUBSET_EPS = 1e-4
#: a far-field node whose A_ii |E_i| grows beyond this makes the factorization stale
#: (the contact grew outward: the kept factorization does not include it)
FAR_FIELD_EPS = 1e-2
#: nodes of the crack-tip zone inside the crack tip (the tip recedes into them) ...
ZONE_IN = 48
#: ... and outside it (the cohesive zone's stiff part)
ZONE_OUT = 24
#: the factorization is made again when the crack tip comes within this many nodes of the
#: zone's inner edge (or of its outer edge, when it advances)
ZONE_MARGIN = 6
#: most zone nodes (cache size)
ZONE_MAX = ZONE_IN + ZONE_OUT
#: the zone's Schur complement is refactorized when a zone node's stiffness moved by more
#: than this fraction of its Jacobian diagonal since the last refresh (it costs O(z^3),
#: about one mat-vec of the mesh; the tip's motion refreshes it about once per step;
#: 1e-4, a refresh at nearly every iteration, cost 5-10 % more on the vs-numpy scenes
#: for the same iterations)
ZONE_ETA = 1e-2

#: precision of K's factors, X, A_ZB diag(E_b) and Sigma's factors: single. They make the
#: Newton direction, which is already off by the interior's drift since the factorization
#: (about 1e-2 per step); single precision adds cond * 6e-8, about 1e-4 at cond(K) =
#: 1e3-2e4 measured on the vs-numpy scenes, and halves the time of the factorizations and of
#: the triangular solves (bound by memory traffic and SIMD width). C, from which Sigma is
#: made at each refresh, and every residual stay double.
FACTOR_DTYPE = np.float32

CACHE_BASE = 0       # flat (N*N) FACTOR_DTYPE: LU of K (b*b)
CACHE_ZONE_COLS = 1  # flat (ZONE_MAX*N) FACTOR_DTYPE: X^T (z rows of length b)
CACHE_ZONE_ROWS = 2  # flat (ZONE_MAX*N) FACTOR_DTYPE: A_ZB diag(E_b) (z rows of length b)
CACHE_COUPLING = 3   # flat (ZONE_MAX^2): C (z*z)
CACHE_SCHUR = 4      # flat (ZONE_MAX^2) FACTOR_DTYPE: LU of Sigma (z*z)
CACHE_E = 5          # (N): the approximate Jacobian's stiffness: E_b on B, E_Z on Z, 0 on F
CACHE_BASE_NODES = 6  # (N) int64: the nodes of B, in order (rows/columns of K)
CACHE_PIVOTS = 7     # (N + ZONE_MAX) int32: pivots of K, then of Sigma
CACHE_STATE = 8      # int64, indexed by STATE_*
CACHE_CONTRACTION = 9  # (1): the chord iteration's contraction estimate (kernels.solve.newton)
CACHE_DEADLINE = 10  # (1): the time budget's deadline, kernels.clock's time (inf: none)
#: state[STATE_VALID]: 1 when the cache holds a factorization, 0 to refactorize
STATE_VALID = 0
#: state[STATE_SUBSET]: m, the size of the interacting prefix S = [0, m)
STATE_SUBSET = 1
#: state[STATE_ZONE_LO], state[STATE_ZONE_HI]: the zone Z = [lo, hi)
STATE_ZONE_LO = 2
STATE_ZONE_HI = 3
#: state[STATE_BASE]: b = |B|
STATE_BASE = 4
#: state[STATE_SCHUR_VALID]: 1 when Sigma's LU is that of the stiffness in CACHE_E
STATE_SCHUR_VALID = 5
#: state[STATE_EXACT]: 1 to refactorize at every Newton iteration (exact Newton: set by the
#: time stepper for the retries of a step whose solve failed, near a fold of the path)
STATE_EXACT = 6
#: state[STATE_SCALED]: 1 for the drift-scaled chord (:func:`newton_direction`; set by the
#: protocol's march, whose pressed contact stiffens at every step): the direction corrected for
#: the interior's drift since the factorization, and the factorization kept where an
#: iteration contracts slowly (:func:`kernels.solve.newton`)
STATE_SCALED = 7
N_STATE = 8


def new_jacobian_cache(N):
    """Work arrays that carry the factorized Jacobian between solves and steps, as one
    tuple that the kernels take whole.

    Returns (base, zone_cols, zone_rows, coupling, schur, E, base_nodes, pivots, state,
    contraction, deadline), positions named by the CACHE_* constants, ``state`` indexed by
    STATE_*; no deadline (:func:`set_deadline`).
    """
    z = min(ZONE_MAX, N)
    return (np.empty(N * N, FACTOR_DTYPE), np.empty(z * N, FACTOR_DTYPE),
            np.empty(z * N, FACTOR_DTYPE), np.empty(z * z), np.empty(z * z, FACTOR_DTYPE),
            np.zeros(N), np.zeros(N, np.int64), np.zeros(N + z, np.int32),
            np.zeros(N_STATE, np.int64), np.ones(1), np.full(1, np.inf))


def invalidate(cache):
    """Mark the factorization in ``cache`` stale: the next solve refactorizes."""
    cache[CACHE_STATE][STATE_VALID] = 0


def set_deadline(cache, seconds: float):
    """Give the solves that use ``cache`` a deadline ``seconds`` from now (inf: none): past
    it, Newton gives up and the unloading kernel ends with STATUS_TIME_BUDGET
    (:mod:`kernels.clock`; the scene's time budget, ``sweep.engine.budget``)."""
    cache[CACHE_DEADLINE][0] = deadline_after(float(seconds))


def use_drift_scaled(cache, on: bool):
    """Switch the drift-scaled chord (STATE_SCALED) of the solves that use ``cache`` on or
    off (off in a new cache)."""
    cache[CACHE_STATE][STATE_SCALED] = int(on)


@njit(cache=True)
def crack_tip_index(d, drate):
    """One past the last node whose stiffness d sigma/dh less its rate term ``drate`` (the
    process zone's, :func:`kernels.interface.traction_and_stiffness`) is negative (h < h_m:
    the crack tip lies between this node and the one before); 0 when there is none."""
    for i in range(d.size - 1, -1, -1):
        if d[i] - drate[i] < 0.0:
            return i + 1
    return 0


@njit(cache=True)
def factorize(h, A, ceff, h0, c, h_old, zone, cache):
    """Factorize the Jacobian at ``h`` into ``cache``: choose S, Z and B, factorize K, form
    X and C. Returns m = |S|. ``h_old`` and ``zone`` are the process zone's
    (:func:`kernels.interface.traction`)."""
    base, zone_cols, zone_rows, coupling, schur, E, base_nodes, pivots, state = cache[:9]
    N = h.size
    zmax = zone_cols.size // N
    sig = np.empty(N)
    d = np.empty(N)
    dr = np.empty(N)
    traction_and_stiffness(h, h_old, zone, h0, c, sig, d, dr)
    m = 0
    for i in range(N):
        if A[i, i] * abs(ceff * (d[i] - dr[i])) > SUBSET_EPS:
            m = i + 1
    tip = min(crack_tip_index(d, dr), m)
    lo = max(tip - ZONE_IN, 0)
    hi = min(tip + ZONE_OUT, m)
    if hi - lo > zmax:
        lo = hi - zmax
    z = hi - lo
    b = 0
    for i in range(m):
        if i < lo or i >= hi:
            base_nodes[b] = i
            b += 1
    for i in range(N):
        E[i] = ceff * d[i] if i < m else 0.0
    if b > 0:
        K = base[:b * b].reshape((b, b))
        for p in range(b):
            ip = base_nodes[p]
            for q in range(b):
                jq = base_nodes[q]
                K[p, q] = -A[ip, jq] * E[jq]
            K[p, p] += 1.0
        if lu_factor(K, pivots[:b]) != 0:
            raise np.linalg.LinAlgError("the restricted Jacobian is singular")
        XT = zone_cols[:z * b].reshape((z, b))
        R = zone_rows[:z * b].reshape((z, b))
        for k in range(z):
            for q in range(b):
                jq = base_nodes[q]
                XT[k, q] = A[jq, lo + k]
                R[k, q] = A[lo + k, jq] * E[jq]
        lu_solve(K, pivots[:b], XT)
    C = coupling[:z * z].reshape((z, z))
    for k in range(z):
        for l in range(z):
            C[k, l] = A[lo + k, lo + l]
    if b > 0 and z > 0:
        RX = zone_rows[:z * b].reshape((z, b)) @ zone_cols[:z * b].reshape((z, b)).T
        for k in range(z):
            for l in range(z):
                C[k, l] += RX[k, l]
    state[STATE_VALID] = 1
    state[STATE_SUBSET] = m
    state[STATE_ZONE_LO] = lo
    state[STATE_ZONE_HI] = hi
    state[STATE_BASE] = b
    state[STATE_SCHUR_VALID] = 0
    return m


@njit(cache=True)
def _refresh_zone(Ez, coupling, schur, pivots, N, z):
    """Sigma = I - C diag(Ez), factorized; False when singular."""
    if z == 0:
        return True
    C = coupling[:z * z].reshape((z, z))
    Sg = schur[:z * z].reshape((z, z))
    for k in range(z):
        for l in range(z):
            Sg[k, l] = -C[k, l] * Ez[l]
        Sg[k, k] += 1.0
    return lu_factor(Sg, pivots[N:N + z]) == 0


@njit(cache=True)
def apply_inverse(v, A, cache):
    """x = J^-1 v for the approximate Jacobian of the cache (stiffness ``E``)."""
    base, zone_cols, zone_rows, coupling, schur, E, base_nodes, pivots, state = cache[:9]
    N = v.size
    m = state[STATE_SUBSET]
    lo = state[STATE_ZONE_LO]
    hi = state[STATE_ZONE_HI]
    b = state[STATE_BASE]
    z = hi - lo
    x = v.copy()
    if m == 0:
        return x
    y = np.empty((1, b), base.dtype)
    for p in range(b):
        y[0, p] = v[base_nodes[p]]
    if b > 0:
        lu_solve(base[:b * b].reshape((b, b)), pivots[:b], y)
    if z > 0:
        rz = np.empty((1, z), base.dtype)
        for k in range(z):
            rz[0, k] = v[lo + k]
        if b > 0:
            gemv_rows(zone_rows[:z * b].reshape((z, b)), z, b, y[0], rz[0], 1.0, 1.0)
        lu_solve(schur[:z * z].reshape((z, z)), pivots[N:N + z], rz)
        w = np.empty(z, base.dtype)
        for k in range(z):
            x[lo + k] = rz[0, k]
            w[k] = E[lo + k] * rz[0, k]
        if b > 0:
            gemv_cols(zone_cols[:z * b].reshape((z, b)), z, b, w, y[0], 1.0, 1.0)
    for p in range(b):
        x[base_nodes[p]] = y[0, p]
    if m < N:
        ex = np.empty(m)
        for j in range(m):
            ex[j] = E[j] * x[j]
        gemv_rows(A[m:], N - m, m, ex, x[m:], 1.0, 1.0)
    return x


@njit(cache=True, inline='always')
def scale_for_drift(x, d, A, ceff, cache):
    """The drift-scaled chord: x = J_b^-1 v (the kept factorization, interior stiffness E_b)
    turned, in place, into an approximation of J^-1 v for the interior's stiffness now,
    ``ceff d``. The drift is taken as a scaling of B's columns, J ~ J_b diag(c) with c_i =
    (1 - A_ii E_i) / (1 - A_ii E_b,i), exact on the diagonal; hence x_i /= c_i on B. Where the
    contact is pressed (A_ii |E| of 10 and more) the columns of J are nearly -A diag(E), which
    the scaling follows. Measured: the direction's error a third of the chord's on a pressed
    contact pressed 6-28 % stiffer (tests/kernels/test_newton.py); on the approach of ``make
    protocol-cost``'s rate-100 scene the chord's contraction (spectral radius) at most 0.037
    against 0.076. Nodes where either diagonal is not positive (the cohesive zone's unstable
    branch) keep x_i."""
    E, base_nodes, state = cache[CACHE_E], cache[CACHE_BASE_NODES], cache[CACHE_STATE]
    for p in range(state[STATE_BASE]):
        i = base_nodes[p]
        then = 1.0 - A[i, i] * E[i]
        now = 1.0 - A[i, i] * ceff * d[i]
        if then > 0.0 and now > 0.0:
            x[i] *= then / now


@njit(cache=True)
def newton_direction(F, d, drate, A, ceff, cache, stats, stat_zone):
    """Newton step dh = -J^-1 F with the interior's stiffness as factorized and the crack-tip
    zone's as it is now (its Schur complement refactorized when it moved by more than
    ZONE_ETA; ``stats[stat_zone]`` counts those).

    With ``state[STATE_SCALED]`` set, the direction is corrected for the interior's drift
    (:func:`scale_for_drift`).

    Returns (dh, ok); ok is False when the factorization no longer fits the state (the crack
    tip left the zone's inner part, a far-field node became stiff, or Sigma is singular):
    the caller refactorizes.
    """
    _, _, _, coupling, schur, E, _, pivots, state = cache[:9]
    N = F.size
    m = state[STATE_SUBSET]
    lo = state[STATE_ZONE_LO]
    hi = state[STATE_ZONE_HI]
    tip = crack_tip_index(d, drate)
    if lo > 0 and tip < lo + ZONE_MARGIN:
        return np.empty(0), False
    if hi < m and tip > hi - ZONE_MARGIN:
        return np.empty(0), False
    for i in range(m, N):
        if A[i, i] * abs(ceff * (d[i] - drate[i])) > FAR_FIELD_EPS:
            return np.empty(0), False
    z = hi - lo
    moved = state[STATE_SCHUR_VALID] == 0
    for k in range(z):
        i = lo + k
        dev = A[i, i] * abs(ceff * d[i] - E[i]) / max(abs(1.0 - A[i, i] * E[i]), 1.0)
        if dev > ZONE_ETA:
            moved = True
            break
    if moved:
        for k in range(z):
            E[lo + k] = ceff * d[lo + k]
        if not _refresh_zone(E[lo:hi], coupling, schur, pivots, N, z):
            return np.empty(0), False       # (E is made again by the refactorization)
        state[STATE_SCHUR_VALID] = 1
        stats[stat_zone] += 1
    x = apply_inverse(F, A, cache)
    if state[STATE_SCALED] == 1:
        scale_for_drift(x, d, A, ceff, cache)
    for i in range(N):
        x[i] = -x[i]
    return x, True
