"""Kelvin (retardation) and Maxwell (relaxation) tables: evaluation, exact conversion
between the two forms (partial fractions), and the Gamma-spectrum lattice of the MPL models."""
from __future__ import annotations

import math

import numpy as np

from ..errors import InputError, check_positive
from .closed_forms import _h


def _kelvin_chat(t: np.ndarray, c: np.ndarray, tau: np.ndarray, chat0: float) -> np.ndarray:
    """chat0 + sum c_i (1 - exp(-t/tau_i)) (= 1 - sum c_i exp(-t/tau_i)); inf-tau terms constant."""
    T = t.ravel()
    out = np.full(T.shape, chat0)
    fin = np.isfinite(tau)
    cf, tf = c[fin], tau[fin]
    if cf.size:
        step = max(1, 2_000_000 // cf.size)
        for s in range(0, T.size, step):
            Ts = T[s:s + step]
            with np.errstate(invalid="ignore"):
                E = -np.expm1(-Ts[:, None] / tf[None, :])
            E[np.isinf(Ts)] = 1.0
            out[s:s + step] += E @ cf
    return out.reshape(t.shape)


def _maxwell_rhat(t: np.ndarray, e: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """1 + sum e_i exp(-t/tau_i) (normalized Wiechert relaxation modulus)."""
    T = t.ravel()
    out = np.ones(T.shape)
    if e.size:
        step = max(1, 2_000_000 // e.size)
        for s in range(0, T.size, step):
            with np.errstate(under="ignore"):
                out[s:s + step] += np.exp(-T[s:s + step, None] / tau[None, :]) @ e
    return out.reshape(t.shape)


def _kelvin_psi(T: np.ndarray, c: np.ndarray, tau: np.ndarray, chat0: float) -> np.ndarray:
    """int_0^T [chat0 + sum c_i (1 - exp(-s/tau_i))] ds = chat0 T + sum c_i tau_i h(T/tau_i)."""
    TT = T.ravel()
    out = chat0 * TT
    fin = np.isfinite(tau)
    cf, tf = c[fin], tau[fin]
    if cf.size:
        step = max(1, 2_000_000 // cf.size)
        for s in range(0, TT.size, step):
            Ts = TT[s:s + step]
            U = Ts[:, None] / tf[None, :]
            out[s:s + step] += _h(U.ravel()).reshape(U.shape) @ (cf * tf)
    return out.reshape(T.shape)


def _merge_times(w: np.ndarray, tau: np.ndarray, rtol: float = 1e-12):
    """Sort by time, drop zero weights and merge (sum) equal times."""
    keep = w > 1e-16 * w.max() if w.size else w > 0   # negligible modes would collide with poles
    w, tau = w[keep], tau[keep]
    order = np.argsort(tau)
    w, tau = w[order], tau[order]
    if tau.size < 2:
        return w, tau
    ws, ts = [w[0]], [tau[0]]
    for wi, ti in zip(w[1:], tau[1:]):
        if abs(ti - ts[-1]) <= rtol * ts[-1]:
            ts[-1] = (ws[-1] * ts[-1] + wi * ti) / (ws[-1] + wi)
            ws[-1] += wi
        else:
            ws.append(wi)
            ts.append(ti)
    return np.array(ws), np.array(ts)


def _bisect_log(fun, lo: np.ndarray, hi: np.ndarray, increasing: bool) -> np.ndarray:
    """Vectorized bisection in log x for roots of fun (monotone on each bracket)."""
    a, b = np.log(lo), np.log(hi)
    for _ in range(80):
        m = 0.5 * (a + b)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            f = fun(np.exp(m))
        right = f < 0 if increasing else f > 0       # root lies above m
        a = np.where(right, m, a)
        b = np.where(right, b, m)
        if np.all(b - a <= 4e-16 * np.maximum(1.0, np.abs(a))):
            break
    return np.exp(0.5 * (a + b))


def maxwell_to_kelvin(moduli, times, E0=1.0):
    """Convert a Wiechert (generalized Maxwell) table into the equivalent Kelvin table, exactly.

    .. math:: R(t) = E_0 + \\sum_i E_i e^{-t/\\tau_i} \\;\\Longleftrightarrow\\;
              \\hat C(t) = C(t) E_0 = 1 - \\sum_j c_j e^{-t/\\theta_j}

    The retardation rates ``1/theta_j`` are the zeros of ``s R~(s) = E0 + sum E_i s/(s + 1/tau_i)``
    on the negative real axis (one in each gap between consecutive relaxation rates and one in
    (k/tau_max, 1/tau_max)), found by bisection; the weights are the residues
    ``c_j = E0 / (theta_j^-1 d(sR~)/ds)``, all positive.

    Parameters
    ----------
    moduli, times : array_like
        Arm moduli ``E_i >= 0`` (units of E0) and relaxation times ``tau_i > 0``.
    E0 : float
        Relaxed (equilibrium spring) modulus, ``> 0``.

    Returns
    -------
    (c, theta) : ndarrays
        Dimensionless Kelvin weights (``sum c = 1 - k``) and retardation times (units of the
        input times), sorted by time.
    """
    E0 = check_positive("E0", E0)
    Ei = np.asarray(moduli, dtype=float).ravel() / E0
    tau = np.asarray(times, dtype=float).ravel()
    Ei, tau = _merge_times(Ei, tau)
    if Ei.size == 0:
        return np.zeros(0), np.zeros(0)
    lam = 1.0 / tau[::-1]                # ascending rates
    e = Ei[::-1]
    k = 1.0 / (1.0 + e.sum())

    def f(x):                           # sR~(s)/E0 at s = -x, decreasing between poles
        return 1.0 - (e[None, :] * x[:, None] / (lam[None, :] - x[:, None])).sum(axis=1)

    lo = np.concatenate([[k * lam[0]], lam[:-1]])
    hi = lam.copy()
    mu = _bisect_log(f, lo, hi, increasing=False)
    with np.errstate(divide="ignore"):
        dE = (e[None, :] * lam[None, :] / (lam[None, :] - mu[:, None]) ** 2).sum(axis=1)
    c = 1.0 / (mu * dE)                 # 0 if a root fell on a pole (negligible mode)
    c *= (1.0 - k) / c.sum()            # removes the last rounding (|correction| ~ 1e-14)
    theta = 1.0 / mu
    order = np.argsort(theta)
    return c[order], theta[order]


def kelvin_to_maxwell(weights, times, k=None):
    """Convert a Kelvin table ``Chat = 1 - sum c_j exp(-t/theta_j)`` into Wiechert form, exactly.

    Returns ``(e, tau)``: dimensionless arm moduli ``e_i = E_i/E0`` and relaxation times with
    ``R(t)/E0 = 1 + sum e_i exp(-t/tau_i)``.  The relaxation rates are the zeros of the
    complex compliance ``C0 + sum c_j x/(1/theta_j - x)`` (x = -s), one in each gap between
    consecutive retardation rates and one above the largest; ``k = 1 - sum c`` must be > 0.
    """
    c = np.asarray(weights, dtype=float).ravel()
    th = np.asarray(times, dtype=float).ravel()
    c, th = _merge_times(c, th)
    if c.size == 0:
        return np.zeros(0), np.zeros(0)
    if k is None:
        k = 1.0 - c.sum()
    if not k > 0:
        raise InputError(f"weights must be >= 0 with sum < 1 (k = 1 - sum in (0, 1]) "
                         f"(got sum {c.sum():.6g})")
    mu = 1.0 / th[::-1]                  # ascending rates
    cc = c[::-1]

    def g(x):                           # C(s)/C0 at s = -x, increasing between poles
        return 1.0 + (cc[None, :] * x[:, None] / (mu[None, :] - x[:, None])).sum(axis=1)

    lo = mu.copy()
    hi = np.concatenate([mu[1:], [mu[-1] + (cc * mu).sum() / k * 1.01]])
    lam = _bisect_log(g, lo, hi, increasing=True)
    with np.errstate(divide="ignore"):
        dC = (cc[None, :] * mu[None, :] / (mu[None, :] - lam[:, None]) ** 2).sum(axis=1)
    e = 1.0 / (lam * dC)
    e *= (1.0 / k - 1.0) / e.sum()
    tau = 1.0 / lam
    order = np.argsort(tau)
    return e[order], tau[order]


def _gamma_lattice(n: float, v_lo: float):
    """Discretize x ~ Gamma(n) on a log lattice for E[f(x)] with f = exp(-s x) or exp(-s/x).

    Nodes v_j = exp(ln v_lo + j h) up to where the density is below 1e-18, masses
    m_j = h v_j^n exp(-v_j)/Gamma(n) (trapezoidal rule in ln x: relative error
    ~ 2 |Gamma(n - 2 pi i/h)| / Gamma(n) <= 1e-15 by the choice of h), and one extra node
    carrying the lattice tail below v_lo with its exact lattice mass and mean (first-moment
    lumping, second-order error).  Returns (masses, nodes).
    """
    from scipy import special  # lazy: not on a BEM scene's path (docs/performance.md)
    # step: smallest omega with 2|Gamma(n - i omega)|/Gamma(n) < 1e-15
    om = 10.0
    lg = special.gammaln(n)
    while 2.0 * math.exp(special.loggamma(complex(n, -om)).real - lg) > 1e-15:
        om += 0.5
    h = 2.0 * math.pi / om
    u0 = math.log(v_lo)
    u_hi = math.log(n + 12.0 * math.sqrt(n) + 60.0)
    u = u0 + h * np.arange(int(math.ceil((u_hi - u0) / h)) + 1)
    v = np.exp(u)
    m = h * np.exp(n * u - v - lg)
    keep = (m >= 1e-18) | (v < n)          # far right tail: masses below 1e-18 are dropped
    u, v, m = u[keep], v[keep], m[keep]
    # lattice tail u0 - j h, j >= 1:  sum_j exp(a u_j) = exp(a u0)/expm1(a h)
    M0 = M1 = 0.0
    for kk in range(6):
        coef = (-1) ** kk / math.factorial(kk)
        M0 += coef * math.exp((n + kk) * u0 - lg) / math.expm1((n + kk) * h)
        M1 += coef * math.exp((n + 1 + kk) * u0 - lg) / math.expm1((n + 1 + kk) * h)
    M0 *= h
    M1 *= h
    if not M0 > 0.0:                    # tail mass below the smallest double: no tail node
        return m, v
    return np.concatenate([[M0], m]), np.concatenate([[M1 / M0], v])
