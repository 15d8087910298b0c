"""Newton's linear algebra: a factorization restricted to the interacting nodes, corrected by
low rank (Numba kernels).

Each solve of the unloading needs J^-1 F for the Jacobian of
F(h) = h - g - A [C_eff sigma(h) - H] (:mod:`kernels.solve`),

    J = I - A diag(E),    E = C_eff sigma'(h)   (the *effective stiffness* of each node).

Restricted base. Far outside the contact the gap is large and E is negligible: those columns
of J are the identity. With S = [0, m) the nodes up to the last one whose
A_ii |E_i| > SUBSET_EPS (the contact and the crack-tip region, a prefix of the radial mesh)
and F the rest, the base Jacobian J_b = I - A diag(E_b) with E_b = 0 on F is block lower
triangular, so

    J_b^-1 v:  x_S = K^-1 v_S,  x_F = v_F + A_FS (E_b,S x_S),   K = I - A_SS diag(E_b,S),

and only the m x m block K is factorized (LU with partial pivoting, LAPACK's dgetrf through
:mod:`kernels.blas`; an explicit inverse cost 3.6x more at m = 380; it is kept only where S
is the whole mesh, when the cache has no room for the pivots): the cost of a
factorization falls by (m/N)^3, that of an application (two triangular solves) to (m/N)^2.

Low-rank corrections. Between factorizations the stiffness moves (the crack tip recedes
through the nodes, the step size changes C_eff). A node whose effective stiffness moved by
more than ``eta`` (relative to its Jacobian diagonal) joins the corrected set T, with one
column W_i = J_b^-1 A[:, i] kept until the next factorization, and is corrected by the
Woodbury identity

    J_c^-1 v = y + W diag(e) G y_T,   y = J_b^-1 v,   G = (I - W_TT diag(e))^-1,

with e the stiffness change it is corrected by. G, the inverse of the capacitance matrix,
is kept too and updated in O(k^2): bordered when a node joins T, a rank-1
(Sherman-Morrison) update when a node of T moved again by more than UPDATE_FRACTION eta;
never refactorized (a k x k solve per iteration cost more than the rest of the step at
k = 100). Smaller changes are left out, which makes Newton slightly inexact (linear
convergence with about that factor). A change of C_eff is one more stiffness change: a
step of another size refactorizes only when it moves the stiffness by more than ``eta``.

The cache is a tuple of arrays (Numba passes it unpacked), positions named by CACHE_*.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .blas import gemv_cols, gemv_rows, ger_rows, lu_factor, lu_solve
from .interface import lj_traction_and_stiffness

#: a node belongs to the factorized block when A_ii |E_i| exceeds this (the columns left
#: out differ from the identity by less; their effect on Newton is of this order)
SUBSET_EPS = 1e-4
#: a node joins the low-rank correction when its effective stiffness moved by more than
#: this fraction of its Jacobian diagonal, A_ii |E_i - E_b,i| / max(|J_b,ii|, 1)
WOODBURY_ETA = 0.02
#: most corrected nodes before the Jacobian is refactorized (T grows with the drift of the
#: contact interior; measured at N = 250-1000: 64 and 128 cost the same per step within the
#: noise, 256 more, the O(k^2) updates and the columns outgrowing the factorizations saved)
WOODBURY_MAX = 64
#: a corrected node is brought up to date when its stiffness moved by more than this
#: fraction of ``eta`` (a rank-1 update, O(k^2): corrected nodes stay nearly exact)
UPDATE_FRACTION = 0.1
#: an update of the capacitance inverse whose pivot (Sherman-Morrison denominator or Schur
#: complement) is below this in magnitude is taken as singular: refactorize
CAPACITANCE_PIVOT = 1e-8

CACHE_FACTOR = 0       # flat buffer (N*N): LU of K (m*m), a copy of A_FS ((N-m)*m), then
#                        the m int32 pivots; K^-1 when m = N (no room for pivots)
CACHE_E_BASE = 1       # E_b (N): effective stiffness of the factorization (0 outside S)
CACHE_COLUMNS = 2      # W (N, kmax): columns J_b^-1 A[:, i] of the corrected nodes
CACHE_SLOT_OF = 3      # slot_of (N): slot of a corrected node in W, or -1
CACHE_NODE_OF = 4      # node_of (kmax): node of each slot
CACHE_STATE = 5        # state (int64), indexed by STATE_*
CACHE_PARAMS = 6       # params (float), indexed by PARAM_*
CACHE_CAPACITANCE = 7  # G (kmax, kmax): inverse of the Woodbury capacitance matrix of T
CACHE_E_CORR = 8       # e_corr (kmax): stiffness change each slot's node is corrected by
#: state[STATE_VALID]: 1 when the cache holds a factorization, 0 to refactorize
STATE_VALID = 0
#: state[STATE_SLOTS]: slots of W in use
STATE_SLOTS = 1
#: state[STATE_SUBSET]: m, the size of the factorized block S = [0, m)
STATE_SUBSET = 2
#: params[PARAM_ETA]: relative stiffness change above which a node is corrected
PARAM_ETA = 0



def new_jacobian_cache(N, kmax=WOODBURY_MAX, eta=WOODBURY_ETA):
    """Work arrays that carry a factorized Jacobian and its low-rank corrections between steps.

    Returns (factor, E_base, W, slot_of, node_of, state, params, capacitance, e_corr),
    positions named by the CACHE_* constants, ``state`` indexed by STATE_*, ``params`` by
    PARAM_*.
    """
    kmax = min(int(kmax), N)
    return (np.empty(N * N), np.zeros(N), np.empty((N, kmax)), np.full(N, -1, np.int64),
            np.full(kmax, -1, np.int64), np.zeros(3, np.int64), np.array([eta]),
            np.empty((kmax, kmax)), np.zeros(kmax))


def invalidate(cache):
    """Mark the factorization in ``cache`` stale: the next solve refactorizes."""
    cache[CACHE_STATE][STATE_VALID] = 0


@njit(cache=True)
def _pivots(factor, N, m):
    """The LU pivots (int32, m), stored in the factor buffer after LU and A_FS (N*m floats)."""
    return factor[N * m:].view(np.int32)[:m]


@njit(cache=True)
def factorize(h, A, ceff, h0, c, factor, e_base, slot_of, state):
    """Factorize the base Jacobian at ``h`` on the interacting prefix S; clears the
    corrections. Returns m = |S|."""
    N = h.size
    sig = np.empty(N)
    d = np.empty(N)
    lj_traction_and_stiffness(h, h0, c, sig, d)
    m = 0
    for i in range(N):
        if A[i, i] * abs(ceff * d[i]) > SUBSET_EPS:
            m = i + 1
    for i in range(N):
        e_base[i] = ceff * d[i] if i < m else 0.0
    if m > 0:
        K = factor[:m * m].reshape((m, m))
        for i in range(m):
            for j in range(m):
                K[i, j] = -A[i, j] * e_base[j]
            K[i, i] += 1.0
        if m == N:       # no room for pivots: the explicit inverse (contact at the mesh edge)
            factor[:] = np.linalg.inv(K.copy()).ravel()
        elif lu_factor(K, _pivots(factor, N, m)) != 0:
            raise np.linalg.LinAlgError("the restricted Jacobian is singular")
        low = factor[m * m:m * m + (N - m) * m].reshape((N - m, m))
        for i in range(N - m):
            for j in range(m):
                low[i, j] = A[m + i, j]
    for i in range(N):
        slot_of[i] = -1
    state[STATE_VALID] = 1
    state[STATE_SLOTS] = 0
    state[STATE_SUBSET] = m
    return m


@njit(cache=True)
def apply_base(X, factor, e_base, m):
    """J_b^-1 X for X of shape (N, p), with the restricted factorization of S = [0, m)."""
    N, p = X.shape
    if m == 0:
        return X.copy()
    if m == N:
        return factor.reshape((N, N)) @ np.ascontiguousarray(X)
    B = np.ascontiguousarray(X[:m].T)
    lu_solve(factor[:m * m].reshape((m, m)), _pivots(factor, N, m), B)
    YS = B.T
    Y = np.empty((N, p))
    Y[:m] = YS
    if m < N:
        T = np.empty((m, p))
        for j in range(m):
            for b in range(p):
                T[j, b] = e_base[j] * YS[j, b]
        low = factor[m * m:m * m + (N - m) * m].reshape((N - m, m))
        Y[m:] = X[m:] + low @ T
    return Y


@njit(cache=True)
def _sherman_morrison(G, k, c, j):
    """G <- (C + c e_j^T)^-1 for G = C^-1 (leading k x k block, in place); False when the
    update is singular (the caller refactorizes)."""
    Gc = np.empty(k)
    gemv_rows(G, k, k, c, Gc, 1.0, 0.0)
    den = 1.0 + Gc[j]
    if not abs(den) > CAPACITANCE_PIVOT:
        return False
    row = G[j, :k].copy()
    ger_rows(G, k, k, -1.0 / den, Gc, row)
    return True


@njit(cache=True)
def _border(G, k, c, rr, s):
    """G <- [[C, c], [rr^T, s]]^-1 for G = C^-1 (leading k x k block, in place, grows to
    k + 1); False when the Schur complement s - rr^T C^-1 c vanishes."""
    Gc = np.empty(k)
    rG = np.empty(k)
    gemv_rows(G, k, k, c, Gc, 1.0, 0.0)
    gemv_cols(G, k, k, rr, rG, 1.0, 0.0)
    sigma = s
    for a in range(k):
        sigma -= rr[a] * Gc[a]
    if not abs(sigma) > CAPACITANCE_PIVOT:
        return False
    ger_rows(G, k, k, 1.0 / sigma, Gc, rG)
    for a in range(k):
        G[a, k] = -Gc[a] / sigma
        G[k, a] = -rG[a] / sigma
    G[k, k] = 1.0 / sigma
    return True


@njit(cache=True)
def newton_direction(F, d, A, ceff, factor, e_base, W, slot_of, node_of, state, params,
                     capacitance, e_corr, stats, stat_columns):
    """Newton step dh = -J_c^-1 F with J_c = J_b - A_T diag(e_corr_T) E_T^T, the Jacobian
    J(h) = I - A diag(ceff d) as far as the cache corrects it.

    T holds the corrected nodes, one slot each (columns W = J_b^-1 A[:, T], the stiffness
    change ``e_corr`` they are corrected by, and G = (I - W_TT diag(e_corr))^-1, the inverse
    of the Woodbury capacitance matrix, all kept between iterations and steps). A node whose
    effective stiffness E = ceff d differs from the corrected one, E_b + e_corr (E_b outside
    T), by more than params[PARAM_ETA] (relative to its Jacobian diagonal) is brought up to
    date: a node of T by a rank-1 (Sherman-Morrison) update of G, a new node by a column
    and a bordering of G, each O(k^2); smaller differences are left to the iteration
    (inexact Newton, linear convergence with about that factor). Returns (dh, ok); ok is
    False when T outgrew the cache or an update was singular (refactorize).
    ``stats[stat_columns]`` counts the new columns.
    """
    N = F.size
    kmax = W.shape[1]
    eta = params[PARAM_ETA]
    m = state[STATE_SUBSET]
    k = state[STATE_SLOTS]
    G = capacitance
    # the nodes whose stiffness left the corrected one: in T (update) or new
    upd = np.empty(N, np.int64)
    new = np.empty(N, np.int64)
    n_upd = 0
    n_new = 0
    for i in range(N):
        sl = slot_of[i]
        e_used = e_base[i] + e_corr[sl] if sl >= 0 else e_base[i]
        dev = A[i, i] * abs(ceff * d[i] - e_used) / max(abs(1.0 - A[i, i] * e_base[i]), 1.0)
        if sl >= 0:
            if dev > UPDATE_FRACTION * eta:
                upd[n_upd] = i
                n_upd += 1
        elif dev > eta:
            new[n_new] = i
            n_new += 1
    if k + n_new > kmax:
        return np.empty(0), False
    c = np.empty(kmax)
    for a in range(n_upd):
        i = upd[a]
        j = slot_of[i]
        change = ceff * d[i] - e_base[i] - e_corr[j]
        for b in range(k):
            c[b] = -W[node_of[b], j] * change
        if not _sherman_morrison(G, k, c, j):
            return np.empty(0), False
        e_corr[j] += change
    if n_new > 0:
        cols = np.empty((N, n_new))
        for r in range(N):
            for b in range(n_new):
                cols[r, b] = A[r, new[b]]
        Wn = apply_base(cols, factor, e_base, m)
        rr = np.empty(kmax)
        for b in range(n_new):
            p = new[b]
            dp = ceff * d[p] - e_base[p]
            for r in range(N):
                W[r, k] = Wn[r, b]
            for a in range(k):
                c[a] = -W[node_of[a], k] * dp
                rr[a] = -W[p, a] * e_corr[a]
            if not _border(G, k, c, rr, 1.0 - W[p, k] * dp):
                return np.empty(0), False
            slot_of[p] = k
            node_of[k] = p
            e_corr[k] = dp
            k += 1
            state[STATE_SLOTS] = k
        stats[stat_columns] += n_new
    y = apply_base(F.reshape((N, 1)), factor, e_base, m)[:, 0]
    dh = -y
    if k == 0:
        return dh, True
    yT = np.empty(k)
    for b in range(k):
        yT[b] = y[node_of[b]]
    coef = np.empty(k)
    gemv_rows(G, k, k, yT, coef, 1.0, 0.0)
    for a in range(k):
        coef[a] *= e_corr[a]
    gemv_rows(W, N, k, coef, dh, -1.0, 1.0)
    return dh, True
