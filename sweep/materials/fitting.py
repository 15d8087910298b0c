"""The Prony fitter: fewest-term Kelvin series of a compliance on a window within rtol
(variable projection + Lawson reweighting; see ``_Material.prony`` for the method)."""
from __future__ import annotations

import math
import time

import numpy as np

from .prony_series import PronySeries


FIT_PPD = 24          # fit grid, points per decade
CHECK_PPD = 160       # measurement grid, points per decade (plus local refinement)
#: attempts one term fewer at a time below a passing N while no failing N is known, before
#: bisecting from 0: the first estimate passes 0-2 terms above the fewest in most fits
STEP_DOWN = 3


def _loggrid(a: float, b: float, ppd: int) -> np.ndarray:
    m = max(int(math.ceil(math.log10(b / a) * ppd)), 2)
    g = np.logspace(math.log10(a), math.log10(b), m + 1)
    g[0], g[-1] = a, b
    return g


def _design(t: np.ndarray, taus: np.ndarray) -> np.ndarray:
    """Columns exp(-t/tau_i) and a final constant column (filled in place: a fit builds
    about 200 of them, where np.hstack's own work was a third of the time)."""
    A = np.empty((t.size, taus.size + 1))
    with np.errstate(under="ignore"):
        A[:, :-1] = np.exp(-t[:, None] / taus[None, :])
    A[:, -1] = 1.0
    return A


def _lp_weights(M: np.ndarray, b: np.ndarray):
    """min_c max |M c - b| subject to c >= 0 (HiGHS).  Returns (c, e) or (None, inf)."""
    from scipy.optimize import linprog  # lazy: not on a BEM scene's path (a Prony fit: disk-cached)
    m, p = M.shape
    cost = np.zeros(p + 1)
    cost[-1] = 1.0
    one = np.ones((m, 1))
    A_ub = np.vstack([np.hstack([M, -one]), np.hstack([-M, -one])])
    b_ub = np.concatenate([b, -b])
    try:
        res = linprog(cost, A_ub=A_ub, b_ub=b_ub, bounds=[(0, None)] * (p + 1), method="highs")
    except ValueError:
        return None, math.inf
    if res.status != 0 or res.x is None:
        return None, math.inf
    return np.clip(res.x[:p], 0.0, None), float(res.x[-1])


def _nnls(M: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Least squares with 0 <= c_i <= 1.

    NNLS, and bounded-variable least squares in the rare case a weight exceeds 1: a very fast
    mode with a huge weight can shave the error at t_min, but such a series is unphysical
    (Chat(0) < 0) and ruins the hereditary recursion (C_eff = 1 - sum c_i b_i < 0).
    """
    from scipy.optimize import lsq_linear, nnls  # lazy: not on a BEM scene's path (a Prony fit: disk-cached)
    try:
        c = nnls(M, b, maxiter=100 * M.shape[1])[0]
    except RuntimeError:                       # pragma: no cover - not seen in practice
        c = np.clip(np.linalg.lstsq(M, b, rcond=None)[0], 0.0, None)
    if c.size and c.max() > 1.0:
        c = lsq_linear(M, b, bounds=(0.0, 1.0), method="bvls").x
    return c


def _constant_minimax(w: np.ndarray, b: np.ndarray):
    """min over c >= 0 of max_i |w_i c - b_i| (w > 0), in closed form: ([c], e).

    With z_i = b_i / w_i the error is max_i w_i |c - z_i|, the upper envelope of lines; its
    minimum is where a rising and a falling line cross, the largest of the crossings'
    values over the pairs z_i < z_j: e = w_i w_j (z_j - z_i)/(w_i + w_j) at
    c = (w_i z_i + w_j z_j)/(w_i + w_j); the error being convex, c < 0 moves to 0. It
    replaces the fit's linear program for the constant (one per fit, about 2 ms of HiGHS
    each, 10 % of a fit on the data set's sample)."""
    z = b / w
    gap = z[None, :] - z[:, None]
    value = np.where(gap > 0.0, gap * (w[:, None] * w[None, :]) / (w[:, None] + w[None, :]),
                     -np.inf)
    if not np.isfinite(value).any():         # every z the same: the constant fits exactly
        c = float(max(z[0], 0.0))
    else:
        i, j = np.unravel_index(int(np.argmax(value)), value.shape)
        c = float(max((w[i] * z[i] + w[j] * z[j]) / (w[i] + w[j]), 0.0))
    return np.array([c]), float(np.abs(w * c - b).max())


def _local_maxima(r: np.ndarray) -> np.ndarray:
    """Indices of the local maxima of r (ends included)."""
    left = np.concatenate([[True], r[1:] >= r[:-1]])
    right = np.concatenate([r[:-1] >= r[1:], [True]])
    return np.nonzero(left & right)[0]


class _Fitter:
    """Prony fit of a normalized creep compliance on [t_min, t_max] (see Material.prony)."""

    def __init__(self, chat, t_min, t_max, rtol):
        self.chat = chat
        self.t_min, self.t_max, self.rtol = t_min, t_max, rtol
        self.target = rtol * (1.0 - 1e-2)
        self.tg = _loggrid(t_min, t_max, FIT_PPD)
        self.yg = chat(self.tg)
        self.w = 1.0 / self.yg
        self.b = (1.0 - self.yg) * self.w
        self.tc = _loggrid(t_min, t_max, CHECK_PPD)
        self.yc = chat(self.tc)
        self.lt_lo = math.log(t_min / 8.0)       # faster modes are (nearly) relaxed in the window
        self.lt_hi = math.log(t_max * 1e3)
        self._profile = self.profile()

    def profile(self):
        """Where in log tau the window needs modes at this tolerance, and how densely.

        A dense dictionary (6 modes per decade) is fitted by NNLS; the effect of each mode
        in the window is eff = max_t c min(e^{-t/tau}, 1 - e^{-t/tau}) / Chat(t) (smoothed
        over neighbouring modes, NNLS solutions being sparse).  By the trapezoidal-rule
        estimate the node spacing needed in log tau scales as 1/ln(eff/rtol), so the node
        density is taken proportional to ln(10 eff/rtol) where positive, inside
        [t_min/8, 30 t_max].  Returns (u, rho) on the dictionary's log times.
        """
        a, b = self.t_min, self.t_max
        nd = int(6 * (math.log10(b / a) + 2.7)) + 2
        u = np.linspace(math.log(a / 50.0), math.log(b * 10.0), nd)
        taus = np.exp(u)
        c = self.nnls(taus)[:-1]
        with np.errstate(under="ignore"):
            E = np.exp(-self.tg[:, None] / taus[None, :])
        eff = (c[None, :] * np.minimum(E, 1.0 - E) / self.yg[:, None]).max(axis=0)
        sm = eff.copy()
        for sh in (1, 2):
            sm[sh:] = np.maximum(sm[sh:], eff[:-sh])
            sm[:-sh] = np.maximum(sm[:-sh], eff[sh:])
        with np.errstate(divide="ignore"):
            rho = np.clip(np.log(10.0 * sm / self.rtol), 0.0, None)
        rho[(u < self.lt_lo) | (u > math.log(b * 30.0))] = 0.0
        if not (rho > 0).any():
            rho[np.argmin(np.abs(u - 0.5 * math.log(a * b)))] = 1.0
        return u, rho

    def quantile_nodes(self, N):
        """N log times at the centres of N equal-mass cells of the density profile."""
        u, rho = self._profile
        du = u[1] - u[0]
        # piecewise-constant density on cells centred at u
        edges = np.concatenate([[u[0] - 0.5 * du], u + 0.5 * du])
        cum = np.concatenate([[0.0], np.cumsum(rho)])
        q = (np.arange(N) + 0.5) / N * cum[-1]
        return np.interp(q, cum, edges)

    # ---------------------------------------------------------------- weights, fixed taus
    def nnls(self, taus):
        return _nnls(_design(self.tg, taus) * self.w[:, None], self.b)

    def minimax(self, taus):
        """Minimax relative error with c >= 0 on the fit grid: LP with row exchange (no
        finite mode: the constant alone, :func:`_constant_minimax`)."""
        if taus.size == 0:
            return _constant_minimax(self.w, self.b)
        M = _design(self.tg, taus) * self.w[:, None]
        b = self.b
        m = b.size
        rows = np.zeros(m, dtype=bool)
        rows[:: max(1, FIT_PPD // 8)] = True
        rows[-1] = True
        c = None
        for _ in range(10):
            c, e = _lp_weights(M[rows], b[rows])
            if c is None:
                return None, math.inf
            r = np.abs(M @ c - b)
            viol = r > e * (1.0 + 1e-6) + 1e-15
            if not viol.any():
                return c, e
            add = _local_maxima(np.where(viol, r, 0.0))
            add = add[viol[add]]
            rows[add] = True
            rows[np.clip(np.concatenate([add - 1, add + 1]), 0, m - 1)] = True
        return c, float(np.abs(M @ c - b).max())

    def measure(self, taus, c):
        """Max relative error on the check grid, refined by a parabola at the largest maxima."""
        tc, yc = self.tc, self.yc
        A = _design(tc, taus)
        r = np.abs(1.0 - A @ c - yc) / yc
        best = float(r.max())
        idx = _local_maxima(r)
        idx = idx[(idx > 0) & (idx < r.size - 1)]
        if idx.size:
            idx = idx[np.argsort(r[idx])[-6:]]
            x = np.log(tc)
            x1, x2 = x[idx], x[idx + 1]
            f0, f1, f2 = r[idx - 1], r[idx], r[idx + 1]
            den = (f0 - 2.0 * f1 + f2)
            with np.errstate(divide="ignore", invalid="ignore"):
                shift = np.where(den < 0, 0.5 * (f0 - f2) / den, 0.0)
            xs = x1 + np.clip(shift, -1.0, 1.0) * (x2 - x1)
            ts = np.exp(xs)
            ys = self.chat(ts)
            rs = np.abs(1.0 - _design(ts, taus) @ c - ys) / ys
            best = max(best, float(rs.max()))
        return best

    # ------------------------------------------------------------- positions: varpro LM
    def lm(self, lt, lw=None, iters=40):
        """Levenberg-Marquardt on log taus for the (lw-weighted) relative L2 error, the
        weights eliminated by nonnegative least squares (variable projection with the Kaufman
        Jacobian on the active set; :func:`sweep.materials.varpro.lm_log_times`, compiled).
        Monotone: never returns worse L2 than the start. Where a weight would exceed 1 (an
        unphysical series; not met in the 2603 calls of the fits of 200 scenes of the data
        set's ranges) the iteration stops at its last accepted point."""
        sw = self.w if lw is None else self.w * np.sqrt(lw)
        lt = np.clip(np.sort(lt), self.lt_lo, self.lt_hi)
        if lt.size == 0:
            return lt
        from .varpro import lm_log_times   # lazy: numba, on the fitter's path only
        return lm_log_times(self.tg, sw, (1.0 - self.yg) * sw, lt, self.lt_lo, self.lt_hi,
                            iters)[0]

    def weights(self, lt, lw=None):
        """Nonnegative weights for fixed log times (lw-weighted relative least squares)."""
        sw = self.w if lw is None else self.w * np.sqrt(lw)
        M = _design(self.tg, np.exp(lt)) * sw[:, None]
        return _nnls(M, (1.0 - self.yg) * sw)

    def trial(self, lt0, lawson=8, polish_only=False):
        """Optimize N = len(lt0) log times; return (err, taus, c) with c >= 0.

        Variable projection for the relative L2 error (skipped with ``polish_only``), then,
        while the bound is not met and not hopeless, Lawson reweighting: the weights of the
        grid points grow with their residual, which drives both times and weights towards the
        minimax fit.
        """
        lt = np.sort(lt0) if polish_only else self.lm(lt0)
        lw = np.ones_like(self.tg)
        best = (math.inf, None, None)
        for it in range(lawson + 1):
            c = self.weights(lt, lw)
            taus = np.exp(lt)
            err = self.measure(taus, c) if c.sum() <= 1.0 + 1e-12 else math.inf
            if err < best[0]:
                best = (err, taus, c)
            if best[0] <= self.target or err > 30.0 * self.rtol or it == lawson:
                break
            r = np.abs(_design(self.tg, taus) @ c - (1.0 - self.yg)) * self.w
            lw = lw * (r + 1e-2 * r.max())
            lw /= lw.max()
            lt = self.lm(lt, lw, iters=12)
        return best


def _interp_nodes(lt: np.ndarray, N: int) -> np.ndarray:
    """N log-times with the same density profile as the sorted nodes lt."""
    lt = np.sort(lt)
    if N == lt.size:
        return lt.copy()
    if lt.size == 1:
        return lt[0] + np.linspace(-1.0, 1.0, N) if N > 1 else lt.copy()
    if N == 1:
        return np.array([np.median(lt)])
    return np.interp(np.linspace(0.0, lt.size - 1.0, N), np.arange(lt.size), lt)


def _finish(taus, c, err, rtol, k, t_min, t_max, t0):
    """Drop zero / negligible terms, lump the constant column as tau = inf."""
    tt = np.concatenate([taus, [np.inf]])
    keep = (c > 0) & ~(tt < t_min / 40.0)     # modes much faster than the window: relaxed
    w, tt = c[keep], tt[keep]
    order = np.argsort(tt)
    w, tt = w[order], tt[order]
    same = np.nonzero(np.diff(tt) <= 1e-12 * tt[:-1])[0] if tt.size > 1 else []
    for i in same[::-1]:                      # coalesced nodes are one mode (exact)
        w[i] += w[i + 1]
        w, tt = np.delete(w, i + 1), np.delete(tt, i + 1)
    return PronySeries(weights=np.ascontiguousarray(w, dtype=float),
                       times=np.ascontiguousarray(tt, dtype=float),
                       max_rel_error=float(err), rtol=float(rtol), converged=bool(err <= rtol),
                       k=float(k), t_min=float(t_min), t_max=float(t_max),
                       elapsed=time.perf_counter() - t0)


def _nterms(taus, c, t_min):
    tt = np.concatenate([taus, [np.inf]])
    return int(np.count_nonzero((c > 0) & ~(tt < t_min / 40.0)))


def fit_prony(chat, t_min, t_max, rtol, k, exact=None, max_terms=120):
    """Fewest-term Prony series of ``chat`` (vectorized, normalized time) on [t_min, t_max].

    See :meth:`_Material.prony`.  ``exact`` is an optional exact Kelvin table (c, tau) whose
    window-lumped versions are also considered; ``max_terms`` caps the count (constant
    included).
    """
    t0 = time.perf_counter()
    if k >= 1.0:
        return PronySeries(np.zeros(0), np.zeros(0), 0.0, rtol, True, k, t_min, t_max)
    F = _Fitter(chat, t_min, t_max, rtol)
    results = []                          # (n_terms, err, taus, c)

    def valid(c):
        # a physical series has sum c <= 1 (Chat >= 0 at t = 0, and C_eff = 1 - sum c_i b_i
        # >= 0 in the recursion): degenerate fits are rejected
        return c is not None and float(c.sum()) <= 1.0 + 1e-12

    def record(err, taus, c, rank=1):
        if taus is not None and valid(c) and _nterms(taus, c, t_min) <= max_terms:
            results.append((_nterms(taus, c, t_min), rank, err, taus, c))
        return err

    def done():
        # fewest terms; on a tie the exact (lumped) table, then the smaller error
        passing = [r for r in results if r[2] <= F.target]
        if passing:
            nt, _, err, taus, c = min(passing, key=lambda r: (r[0], r[1], r[2]))
        elif results:
            nt, _, err, taus, c = min(results, key=lambda r: (r[2], r[0]))
        else:                             # nothing within the cap: the empty series
            taus, c = np.zeros(0), np.zeros(1)
            err = F.measure(taus, c)
        return _finish(taus, c, err, rtol, k, t_min, t_max, t0)

    # exact table (SLS, Prony): the most aggressive lumping of the slow modes that passes
    if exact is not None:
        for taus, c in _lumped_candidates(*exact, t_min, t_max):
            if record(F.measure(taus, c), taus, c, rank=0) <= F.target:
                break

    # no finite mode: a constant (or nothing)
    c0, _ = F.minimax(np.zeros(0))
    if c0 is not None and record(F.measure(np.zeros(0), c0), np.zeros(0), c0) <= F.target:
        return done()

    # a passing exact candidate bounds the search: only shorter fits are of interest
    exact_nt = [r[0] for r in results if r[2] <= F.target]
    if exact_nt and min(exact_nt) <= 2:
        return done()

    target = F.target                     # 1% margin for what a finer grid might find
    tried = {}                            # N -> (err, log taus)
    u_p, rho_p = F._profile               # node density profile (dense-dictionary NNLS)

    def attempt(N):
        """Best of: N nodes at the quantiles of the density profile, and the nearest solution
        found so far re-spaced to N nodes, each as given and after variable projection;
        then Lawson polishing."""
        if N in tried:
            return tried[N][0]
        starts = [F.quantile_nodes(N)]
        if tried:
            near = min(tried, key=lambda m: (abs(m - N), -m))
            starts.append(_interp_nodes(tried[near][1], N))
        best = (math.inf, None, None)
        for lt0 in starts:
            for lt in (np.sort(lt0), F.lm(lt0)):
                c = F.weights(lt)
                err = F.measure(np.exp(lt), c)
                if valid(c) and err < best[0]:
                    best = (err, lt, c)
                    record(err, np.exp(lt), c)
        if best[0] > target and best[1] is not None:
            err, taus, c = F.trial(best[1], polish_only=True)
            if valid(c) and err < best[0]:
                best = (err, np.log(taus), c)
                record(err, taus, c)
        if best[1] is None:
            best = (math.inf, starts[0], None)
        tried[N] = (best[0], best[1])
        return best[0]

    # bracket [N_fail, N_pass], then secant/bisection (error ~ geometric in N)
    # estimate: about one node per pi^2/ln(10 eff/rtol) in ln tau (trapezoidal rule)
    n_cap = max_terms - 1                 # finite modes, the constant being one term
    if exact_nt:
        n_cap = min(n_cap, min(exact_nt) - 2)
    N = max(1, min(n_cap, int(round(rho_p.sum() * (u_p[1] - u_p[0]) / math.pi ** 2))))
    n_fail, n_pass = 0, None
    while n_pass is None and n_cap >= 1:
        if attempt(N) <= target:
            n_pass = N
        else:
            n_fail = N
            if N >= n_cap:
                break
            N = min(n_cap, int(math.ceil(1.3 * N)) + 1)
    if n_pass is not None:
        descents = 0
        while n_pass - n_fail > 1:
            lo_e = tried[n_fail][0] if n_fail else None
            hi_e = tried[n_pass][0]
            if not n_fail and descents < STEP_DOWN:
                # no failure known: the estimate is mostly within a few terms of the fewest
                # (a probe at half of it fails far off and costs a whole attempt)
                N = n_pass - 1
                descents += 1
            elif lo_e is not None and lo_e > hi_e:
                frac = math.log(lo_e / target) / math.log(lo_e / hi_e)
                N = n_fail + int(round(frac * (n_pass - n_fail)))
            else:
                N = (n_fail + n_pass) // 2
            N = min(max(N, n_fail + 1), n_pass - 1)
            if attempt(N) <= target:
                n_pass = N
            else:
                n_fail = N
    return done()


def _lumped_candidates(c, tau, t_min, t_max):
    """Exact Kelvin table lumped to the window, most aggressive first.

    Modes faster than t_min/40 are dropped (relaxed: exp(-40) ~ 4e-18 in the window); modes
    slower than f t_max, f = 1e2 ... 1e8, are lumped into the constant term (tau = inf), which
    costs at most c t_max/tau_i in Chat; the last candidate lumps nothing slow.
    """
    out = []
    fast = tau < t_min / 40.0
    for f_slow in (1e2, 1e3, 1e4, 1e6, 1e8, np.inf):
        slow = tau > t_max * f_slow
        mid = ~(fast | slow)
        out.append((tau[mid], np.concatenate([c[mid], [c[slow].sum()]])))
    return out
