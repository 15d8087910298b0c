"""Compiled variable projection for the Prony fitter (:mod:`sweep.materials.fitting`).

The fitter's Levenberg-Marquardt on the log retardation times evaluates, hundreds of
times a fit, the residual and Jacobian of a weighted least-squares fit whose weights are
eliminated by nonnegative least squares (NNLS). On matrices of a few hundred rows by
5-30 columns a NumPy/SciPy evaluation is mostly call overhead; here the whole iteration
runs in Numba: the fitter's former NumPy iteration (the same steps, damping and stopping
rules, issue 33), 2-3 times faster a fit. The NNLS is Lawson and Hanson's active-set method, started from the
previous evaluation's positive set. It solves the same problem as ``scipy.optimize.nnls``
(whose solution is unique for a design matrix of full column rank), so the two agree to
rounding; where a weight exceeds 1 (the bounded case the fitter's own weights hand to
``scipy.optimize.lsq_linear``) :func:`lm_log_times` stops and reports it.
"""
from __future__ import annotations

import numpy as np
from numba import njit

#: status of :func:`lm_log_times`
LM_DONE = 0
LM_BOUNDED = 1          # an NNLS weight exceeded 1: stopped at the last accepted point


@njit(cache=True)
def _cholesky_solve(M, g):
    """x with M x = g for a symmetric positive definite M (Cholesky); (x, False) where a
    pivot is not positive (M singular to rounding). Loops, not np.linalg.solve, whose
    compile with its checks costs about 5 s (docs/performance.md, "The first run")."""
    n = M.shape[0]
    L = np.zeros((n, n))
    for j in range(n):
        d = M[j, j]
        for k in range(j):
            d -= L[j, k] * L[j, k]
        if not d > 0.0:
            return np.zeros(n), False
        L[j, j] = np.sqrt(d)
        for i in range(j + 1, n):
            s = M[i, j]
            for k in range(j):
                s -= L[i, k] * L[j, k]
            L[i, j] = s / L[j, j]
    y = np.zeros(n)
    for i in range(n):
        s = g[i]
        for k in range(i):
            s -= L[i, k] * y[k]
        y[i] = s / L[i, i]
    x = np.zeros(n)
    for i in range(n - 1, -1, -1):
        s = y[i]
        for k in range(i + 1, n):
            s -= L[k, i] * x[k]
        x[i] = s / L[i, i]
    return x, True


@njit(cache=True)
def _solve_passive(A, b, passive):
    """Least squares on the columns of A where ``passive``: (z on all columns, zero
    elsewhere; Q of the reduced QR of those columns; their count)."""
    m, n = A.shape
    p = 0
    for j in range(n):
        if passive[j]:
            p += 1
    z = np.zeros(n)
    if p == 0:
        return z, np.zeros((m, 0)), 0
    Ap = np.empty((m, p))
    cols = np.empty(p, dtype=np.int64)
    k = 0
    for j in range(n):
        if passive[j]:
            for i in range(m):            # loops, not slices: no shape-mismatch message
                Ap[i, k] = A[i, j]        # to compile (docs/performance.md, "The first run")
            cols[k] = j
            k += 1
    Qf, R = np.linalg.qr(Ap)
    Q = np.ascontiguousarray(Qf)
    y = Q.T @ b
    sol = np.zeros(p)
    for i in range(p - 1, -1, -1):          # back substitution, R upper triangular
        s = y[i]
        for j in range(i + 1, p):
            s -= R[i, j] * sol[j]
        sol[i] = s / R[i, i] if R[i, i] != 0.0 else 0.0
    for k in range(p):
        z[cols[k]] = sol[k]
    return z, Q, p


@njit(cache=True)
def nnls(A, b, start, maxiter):
    """min ||A x - b|| subject to x >= 0 (Lawson-Hanson), from the positive set ``start``.

    Returns (x, Q, converged): Q (orthonormal columns) spans the columns of the final
    positive set; not converged after ``maxiter`` columns added or dropped.
    """
    m, n = A.shape
    passive = start.copy()
    x = np.zeros(n)
    # a feasible start: drop the columns whose least-squares weight is not positive
    while True:
        z, Q, p = _solve_passive(A, b, passive)
        bad = False
        for j in range(n):
            if passive[j] and z[j] <= 0.0:
                passive[j] = False
                bad = True
        if not bad:
            for j in range(n):
                x[j] = z[j]
            break
    scale = 0.0
    for i in range(m):
        for j in range(n):
            scale = max(scale, abs(A[i, j]))
    tol = 10.0 * 2.220446049250313e-16 * max(m, n) * scale * max(np.abs(b).max(), 1e-300)
    skip = np.zeros(n, dtype=np.bool_)
    it = 0
    for _ in range(maxiter):
        w = A.T @ (b - A @ x)
        j_max, w_max = -1, tol
        for j in range(n):
            if not passive[j] and not skip[j] and w[j] > w_max:
                j_max, w_max = j, w[j]
        if j_max < 0:
            return x, Q, True
        passive[j_max] = True
        z, Q, p = _solve_passive(A, b, passive)
        if z[j_max] <= 0.0:               # rounding: the column does not help after all
            passive[j_max] = False
            skip[j_max] = True
            z, Q, p = _solve_passive(A, b, passive)
            continue
        for j in range(n):
            skip[j] = False
        while True:                       # inner loop: back to feasibility
            it += 1
            if it > maxiter:
                return x, Q, False
            alpha, neg = 2.0, False
            for j in range(n):
                if passive[j] and z[j] <= 0.0:
                    neg = True
                    a = x[j] / (x[j] - z[j])
                    if a < alpha:
                        alpha = a
            if not neg:
                for j in range(n):
                    x[j] = z[j]
                break
            for j in range(n):
                if passive[j]:
                    x[j] += alpha * (z[j] - x[j])
                    if x[j] <= 0.0 or (z[j] <= 0.0 and x[j] <= tol):
                        x[j] = 0.0
                        passive[j] = False
            z, Q, p = _solve_passive(A, b, passive)
    return x, Q, False


@njit(cache=True)
def _evaluate(tg, sw, b, lt, start):
    """Residual and variable-projection Jacobian (Kaufman) at log times ``lt``: (r, J,
    the positive set, status)."""
    m, N = tg.size, lt.size
    taus = np.exp(lt)
    X = np.empty((m, N))
    E = np.empty((m, N))
    A = np.empty((m, N + 1))
    for i in range(m):
        for j in range(N):
            X[i, j] = tg[i] / taus[j]
            E[i, j] = np.exp(-X[i, j])
            A[i, j] = E[i, j] * sw[i]
        A[i, N] = sw[i]
    c, Q, ok = nnls(A, b, start, 100 * (N + 1))
    status = LM_DONE
    if not ok or c.max() > 1.0:
        status = LM_BOUNDED
    r = A @ c - b
    positive = c > 0.0
    D = np.empty((m, N))
    for i in range(m):
        for j in range(N):
            D[i, j] = E[i, j] * X[i, j] * sw[i] * c[j]
    if positive.any():
        J = D - Q @ (Q.T @ D)
    else:
        J = np.zeros((m, N))
    return r, J, positive, status


@njit(cache=True)
def lm_log_times(tg, sw, b, lt, lt_lo, lt_hi, iters):
    """Levenberg-Marquardt on sorted, clipped log times ``lt`` for the sw-weighted relative
    L2 error of a Prony fit of ``b`` on the times ``tg`` (``_Fitter.lm``'s iteration).
    Monotone: the objective at the returned log times is at most that at the start.
    Returns (log times, sorted; status: :data:`LM_DONE` or :data:`LM_BOUNDED`)."""
    N = lt.size
    start = np.zeros(N + 1, dtype=np.bool_)
    r, J, positive, status = _evaluate(tg, sw, b, lt, start)
    if status != LM_DONE:
        return np.sort(lt), status
    f = r @ r
    mu = 1e-3
    for _ in range(iters):
        g = J.T @ r
        H = J.T @ J
        dH = np.diag(H).copy()
        for j in range(N):
            if dH[j] <= 0.0:
                dH[j] = 1e-300
        step, regular = _cholesky_solve(H + mu * np.diag(dH), -g)
        if not regular:                   # singular to rounding: more damping
            mu *= 10.0
            continue
        lt2 = np.minimum(np.maximum(lt + np.minimum(np.maximum(step, -2.0), 2.0), lt_lo), lt_hi)
        r2, J2, positive2, status = _evaluate(tg, sw, b, lt2, positive)
        if status != LM_DONE:
            return np.sort(lt), status
        f2 = r2 @ r2
        if f2 < f:
            done = f - f2 <= 1e-9 * f
            lt, r, J, f, positive = lt2, r2, J2, f2, positive2
            mu = max(mu / 3.0, 1e-9)
            if done:
                break
        else:
            mu *= 4.0
            if mu > 1e6:
                break
    return np.sort(lt), LM_DONE
