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

and only the m x m block K is inverted: the cost of a factorization falls by (m/N)^3, that
of an application to (m/N).

Low-rank corrections. Between factorizations the stiffness moves (the crack tip recedes
through the nodes, the step size changes C_eff). Nodes whose effective stiffness moved by
more than ``eta`` (relative to their Jacobian diagonal) are corrected exactly by the
Woodbury identity, with one column J_b^-1 A[:, i] per corrected node kept until the next
factorization; smaller changes are left out, which makes Newton slightly inexact (linear
convergence with about that factor). A change of C_eff is one more stiffness change: a
step of another size refactorizes only when it moves the stiffness by more than ``eta``.

The cache is a tuple of arrays (Numba passes it unpacked), positions named by CACHE_*.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from .interface import lj_traction_and_stiffness

#: a node belongs to the factorized block when A_ii |E_i| exceeds this (the columns left
#: out differ from the identity by less; their effect on Newton is of this order)
SUBSET_EPS = 1e-4
#: a node joins the low-rank correction when its effective stiffness moved by more than
#: this fraction of its Jacobian diagonal, A_ii |E_i - E_b,i| / max(|J_b,ii|, 1)
WOODBURY_ETA = 0.02
#: most corrected nodes before the Jacobian is refactorized (the correction costs a
#: k x k solve per Newton iteration)
WOODBURY_MAX = 128

CACHE_FACTOR = 0       # flat buffer (N*N): K^-1 (m*m) then a copy of A_FS ((N-m)*m)
CACHE_E_BASE = 1       # E_b (N): effective stiffness of the factorization (0 outside S)
CACHE_COLUMNS = 2      # W (N, kmax): columns J_b^-1 A[:, i] of the corrected nodes
CACHE_SLOT_OF = 3      # slot_of (N): slot of a corrected node in W, or -1
CACHE_NODE_OF = 4      # node_of (kmax): node of each slot
CACHE_STATE = 5        # state (int64), indexed by STATE_*
CACHE_PARAMS = 6       # params (float), indexed by PARAM_*
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

    Returns (factor, E_base, W, slot_of, node_of, state, params), positions named by the
    CACHE_* constants, ``state`` indexed by STATE_*, ``params`` by PARAM_*.
    """
    kmax = min(int(kmax), N)
    return (np.empty(N * N), np.zeros(N), np.empty((N, kmax)), np.full(N, -1, np.int64),
            np.full(kmax, -1, np.int64), np.zeros(3, np.int64), np.array([eta]))


def invalidate(cache):
    """Mark the factorization in ``cache`` stale: the next solve refactorizes."""
    cache[CACHE_STATE][STATE_VALID] = 0


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
        K = np.empty((m, m))
        for i in range(m):
            for j in range(m):
                K[i, j] = -A[i, j] * e_base[j]
            K[i, i] += 1.0
        factor[:m * m] = np.linalg.inv(K).ravel()
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
    Kinv = factor[:m * m].reshape((m, m))
    Y = np.empty((N, p))
    YS = Kinv @ np.ascontiguousarray(X[:m])
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
def newton_direction(F, d, A, ceff, factor, e_base, W, slot_of, node_of, state, params, stats,
                     stat_columns):
    """Newton step dh = -J(h)^-1 F, J(h) = J_b - A_T diag(E_T - E_b,T) E_T^T.

    T holds the nodes whose effective stiffness E = ceff d moved away from the factorized
    one; the correction is exact for them (Woodbury identity), nodes outside T differ by
    less than params[PARAM_ETA]. Returns (dh, ok); ok is False when T outgrew the cache
    (refactorize: measured cheaper than correcting only the largest moves, which needs
    more iterations with a full-size correction). ``stats[stat_columns]`` counts the new
    columns.
    """
    N = F.size
    kmax = W.shape[1]
    eta = params[PARAM_ETA]
    m = state[STATE_SUBSET]
    # the nodes that moved: those already corrected (their column is kept) and new ones
    T = np.empty(N, np.int64)
    new = np.empty(N, np.int64)
    k = 0
    n_new = 0
    for i in range(N):
        dev = A[i, i] * abs(ceff * d[i] - e_base[i]) / max(abs(1.0 - A[i, i] * e_base[i]), 1.0)
        if dev > eta:
            if slot_of[i] >= 0:
                T[k] = i
                k += 1
            else:
                new[n_new] = i
                n_new += 1
    if k + n_new > kmax or state[STATE_SLOTS] + n_new > kmax:
        return np.empty(0), False
    for a in range(n_new):
        T[k] = new[a]
        k += 1
    if n_new > 0:
        cols = np.empty((N, n_new))
        for r in range(N):
            for b in range(n_new):
                cols[r, b] = A[r, new[b]]
        Wn = apply_base(cols, factor, e_base, m)
        for b in range(n_new):
            slot = state[STATE_SLOTS]
            state[STATE_SLOTS] += 1
            W[:, slot] = Wn[:, b]
            slot_of[new[b]] = slot
            node_of[slot] = new[b]
        stats[stat_columns] += n_new
    y = apply_base(F.reshape((N, 1)), factor, e_base, m)[:, 0]
    if k == 0:
        return -y, True
    K = np.empty((k, k))
    delta = np.empty(k)
    rhs = np.empty(k)
    for b in range(k):
        delta[b] = ceff * d[T[b]] - e_base[T[b]]
    for a in range(k):
        rhs[a] = y[T[a]]
        for b in range(k):
            K[a, b] = -W[T[a], slot_of[T[b]]] * delta[b]
        K[a, a] += 1.0
    z = np.linalg.solve(K, rhs)
    dh = -y
    for b in range(k):
        coef = delta[b] * z[b]
        sl = slot_of[T[b]]
        for r in range(N):
            dh[r] -= coef * W[r, sl]
    return dh, True
