"""Linear viscoelastic materials: creep, relaxation, complex moduli and Prony fits.

Conventions (docs/design.md section 3; binding for every material here)
------------------------------------------------------------------------
* ``E0`` is the RELAXED (long-time, rubbery) modulus and ``Einf`` the GLASSY (instantaneous)
  modulus, ``Einf >= E0 > 0``; ``k = E0 / Einf`` in (0, 1].  ``C0 = 1/E0`` and
  ``Cinf = 1/Einf`` are the relaxed and glassy compliances.  (Beware: some libraries call the
  glassy modulus ``E_0``; here it is always the relaxed one, as in the paper.)
* ``tau0`` is the characteristic time; physical times ``t`` and angular frequencies ``omega``
  are in the units of ``tau0`` and ``1/tau0`` (e.g. s and rad/s).  Moduli carry the units of
  ``E0`` and compliances their inverse.
* Normalized time ``that = t / tau0``.  The normalized creep compliance is
  ``Chat(that) = C(t) / C0``: ``Chat(0) = k`` and ``Chat(inf) = 1``, non-decreasing.  The
  normalized relaxation modulus is ``Rhat(that) = R(t) / E0``: ``Rhat(0) = 1/k``,
  ``Rhat(inf) = 1``.
* Integrated compliance ``Psi(T) = int_0^T Chat(s) ds`` (``T`` in units of tau0), used by the
  exact-convolution reference solver (docs/design.md section 4).
* Frequency domain (paper, appendix A): complex modulus ``E(omega) = E' + i E''`` and complex
  compliance ``C(omega) = C' - i C'' = 1 / E(omega)``, with ``E'' >= 0`` and ``C'' >= 0``
  (harmonic time factor ``exp(i omega t)``).

Models
------
``MPLRetardation``
    modified power law RETARDATION spectrum (paper eq. retspec; the model of the BEM, of the
    Persson-Brener theory; docs/design.md section 3): the retardation times, in units of tau0, are
    Gamma(n, 1) distributed, ``Chat(t) = 1 - (1-k) 2 t^(n/2) K_n(2 sqrt t) / Gamma(n)``.
    Creep and complex compliance in closed form; relaxation modulus numerical.
``MPLRelaxation``
    modified power law RELAXATION spectrum (paper eq. relspec), a DIFFERENT material with the
    same four constants: the relaxation rates, in units of 1/tau0, are Gamma(n, 1) distributed,
    ``R(t) = E0 + (Einf - E0) / (1 + t/tau0)^n``.  Relaxation and complex modulus in closed
    form; creep compliance numerical.
``SLS``
    standard linear solid in Kelvin form with RETARDATION time tau0,
    ``Chat(t) = 1 - (1-k) exp(-t/tau0)`` (its relaxation time is ``k tau0``).  All closed form.
``Prony``
    a generic table: Kelvin (retardation) ``Chat = 1 - sum c_i exp(-t/tau_i)`` or Wiechert /
    generalized Maxwell ``R = E0 + sum E_i exp(-t/tau_i)``; each is converted exactly into the
    other (partial fractions), so every method is closed form.

Every material has ``.prony(t_min, t_max, rtol)``, which returns the :class:`PronySeries` with
the fewest terms found that approximates ``Chat`` on ``[t_min, t_max]`` (units of tau0) within
the relative error ``rtol``; the series drives the O(N) hereditary recursion of docs/design.md
section 4.

"Numerical" above means: the Gamma-distributed spectrum is discretized by the trapezoidal rule
in log time (exponentially convergent, relative error ~1e-13), the far tail outside the times
requested is lumped into one mode with the same mass and mean time (second-order error), and
the resulting Maxwell/Kelvin table is converted exactly into the other form.  Accuracy about
1e-12 relative, measured in ``tests/test_materials.py`` (hereditary integral R * dC = 1 and
C(omega) E(omega) = 1 against the closed forms of the other side).

Validation: every invalid parameter raises :class:`sweep.errors.InputError` whose one-line
message names the parameter and the allowed range.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass

import numpy as np
from scipy import special
from scipy.optimize import linprog, lsq_linear, nnls

from .errors import InputError, check_choice, check_int, check_positive, check_range

__all__ = [
    "MPLRetardation",
    "MPLRelaxation",
    "SLS",
    "Prony",
    "PronySeries",
    "expint",
    "expint_scaled",
    "mpl_normalized_creep_compliance",
    "mpl_integrated_compliance",
    "sls_integrated_compliance",
    "maxwell_to_kelvin",
    "kelvin_to_maxwell",
]

N_MAX = 20.0          # largest MPL exponent accepted (tested up to 3; checked to 20)
MAX_WINDOW_DECADES = 100   # widest Prony window (a scene needs < 25 decades; 50 take ~5 s)
_EULER = 0.57721566490153286


# ============================================================================ validation

def _as_time_array(name: str, t):
    """float64 array of times >= 0 (+inf allowed), plus a flag 'input was a scalar'."""
    scalar = np.ndim(t) == 0
    try:
        arr = np.asarray(t, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{name} must be numbers (got {t!r})") from None
    if arr.size:
        if np.isnan(arr).any():
            raise InputError(f"{name} must be >= 0 and not NaN (got NaN)")
        lo = float(arr.min())
        if lo < 0.0:
            raise InputError(f"{name} must be >= 0 (got {lo:.6g})")
    return arr, scalar


def _check_moduli(E0, Einf):
    E0 = check_positive("E0", E0)
    Einf = check_positive("Einf", Einf)
    if Einf < E0:
        raise InputError(
            f"Einf must be >= E0 = {E0:.6g} (k = E0/Einf in (0, 1]) (got {Einf:.6g})"
        )
    return E0, Einf


def _check_n(n):
    return check_range("n", n, 0.0, N_MAX, lo_open=True)


# ===================================================================== special functions

def _expint_series(p: float, z: np.ndarray) -> np.ndarray:
    """E_p(z) by the ascending series, |z| <= ~2, any real p > 0.

    E_p(z) = Gamma(1-p) z^(p-1) - sum_k (-z)^k / (k! (k+1-p)); for p near an integer N >= 1
    the pole of Gamma(1-p) and the k = N-1 term are combined analytically (eps = N - p):
    (-1)^(N-1) z^(N-1)/(N-1)! * expm1(eps D)/eps, D = lnGamma(1+eps)/eps - ln z
    - sum_{j<N} log1p(-eps/j)/eps  (-> psi(N) - ln z at eps = 0).
    """
    N = int(math.floor(p + 0.5))
    out = np.zeros(z.shape, dtype=complex)
    term = np.ones(z.shape, dtype=complex)
    for k in range(40):
        if not (N >= 1 and k == N - 1):
            out -= term / (k + 1 - p)
        term = term * (-z) / (k + 1)
    if N == 0:
        out += special.gamma(1.0 - p) * z ** (p - 1.0)
        return out
    eps = N - p
    D = _lgamma1p_over(eps) - np.log(z)
    for j in range(1, N):
        D = D - (math.log1p(-eps / j) / eps if eps != 0.0 else -1.0 / j)
    f = D if eps == 0.0 else np.expm1(eps * D) / eps
    out += (-1) ** (N - 1) * z ** (N - 1) / math.factorial(N - 1) * f
    return out


def _lgamma1p_over(eps: float) -> float:
    """lnGamma(1+eps)/eps for |eps| <= 1/2, with its limit -Euler at eps = 0."""
    if eps == 0.0:
        return -_EULER
    if abs(eps) < 0.05:
        s = -_EULER
        for k in range(2, 28):
            s += (-1) ** k * special.zeta(k) * eps ** (k - 1) / k
        return s
    return special.gammaln(1.0 + eps) / eps


def _expint_cf(p: float, z: np.ndarray) -> np.ndarray:
    """exp(z) E_p(z) by the even continued fraction (modified Lentz), Re z >= 0, |z| >~ 0.5.

    exp(z) E_p(z) = 1/(z+p - 1 p/(z+p+2 - 2 (p+1)/(z+p+4 - ...))).
    """
    tiny = 1e-300
    b = z + p
    c = np.full(z.shape, 1.0 / tiny, dtype=complex)
    d = 1.0 / b
    h = d.copy()
    active = np.ones(z.shape, dtype=bool)
    for i in range(1, 4000):
        an = -i * (p - 1.0 + i)
        b = b + 2.0
        d = 1.0 / (an * d + b)
        c = b + an / c
        de = c * d
        h = np.where(active, h * de, h)
        active &= np.abs(de - 1.0) > 2e-16
        if not active.any():
            break
    return h


def _expint_asym(p: float, z: np.ndarray) -> np.ndarray:
    """exp(z) E_p(z) ~ sum_k (-1)^k (p)_k / z^(k+1), |z| >= 50 + 8 p.

    For z on the imaginary axis each term is real or imaginary, so both parts of the result
    keep full relative accuracy (the real part is O(p/|z|^2), far below the imaginary one).
    """
    s = np.zeros(z.shape, dtype=complex)
    term = 1.0 / z
    for k in range(400):
        s += term
        term = -term * (p + k) / z
        if np.all(np.abs(term) <= 1e-17 * np.abs(s)):
            break
    return s


def expint_scaled(p, z):
    """Scaled generalized exponential integral ``exp(z) E_p(z)``.

    Parameters
    ----------
    p : float
        Order, real, ``p > 0`` (non-integer and integer orders alike).
    z : complex or array of complex
        Argument with ``Re z >= 0`` and ``z != 0`` (principal branch).

    Returns
    -------
    complex or ndarray of complex
        ``exp(z) E_p(z) = exp(z) int_1^inf exp(-z t) t^(-p) dt = E[1/(x + z)]`` for
        ``x ~ Gamma(p, 1)``.

    Notes
    -----
    Ascending series for ``|z| <= 2`` (the poles of Gamma(1-p) at integer p are combined
    analytically with the matching series term, so integer and near-integer orders are
    regular), a continued fraction for ``2 < |z| < 50 + 8p`` and the asymptotic series beyond.
    Relative accuracy ~1e-14, checked against quadrature on a rotated contour in the tests.
    """
    p = check_positive("p", p)
    scalar = np.ndim(z) == 0
    z = np.asarray(z, dtype=complex)
    if np.isnan(z).any() or (z.real < 0).any() or (z == 0).any():
        raise InputError("z must have Re z >= 0, z != 0 and no NaN")
    zz = z.ravel()
    out = np.empty(zz.shape, dtype=complex)
    az = np.abs(zz)
    small = az <= 2.0
    large = az >= 50.0 + 8.0 * p
    mid = ~(small | large)
    if small.any():
        out[small] = np.exp(zz[small]) * _expint_series(p, zz[small])
    if mid.any():
        out[mid] = _expint_cf(p, zz[mid])
    if large.any():
        out[large] = _expint_asym(p, zz[large])
    out = out.reshape(z.shape)
    return out.item() if scalar else out


def expint(p, z):
    """Generalized exponential integral ``E_p(z) = int_1^inf exp(-z t) t^(-p) dt``.

    Real order ``p > 0``, complex ``z`` with ``Re z >= 0``, ``z != 0``; see
    :func:`expint_scaled` (this is ``exp(-z)`` times it).
    """
    g = expint_scaled(p, z)
    return np.exp(-np.asarray(z, dtype=complex)) * g if np.ndim(g) else complex(np.exp(-complex(z)) * g)


def _zg(p: float, w: np.ndarray) -> np.ndarray:
    """E[i w / (x + i w)], x ~ Gamma(p), for w >= 0 (0 -> 0, inf -> 1): i w exp(i w) E_p(i w)."""
    out = np.zeros(w.shape, dtype=complex)
    fin = (w > 0) & np.isfinite(w)
    if fin.any():
        z = 1j * w[fin]
        out[fin] = z * expint_scaled(p, z)
    out[np.isinf(w)] = 1.0
    return out


# ------------------------------------------------------- MPL time-domain closed forms

def _dlgamma(a: float, e: float) -> float:
    """(lnGamma(a+e) - lnGamma(a))/e for a >= 1, |e| <= 1/2; psi(a) at e = 0."""
    if e == 0.0:
        return float(special.digamma(a))
    if abs(e) < 0.05:
        s, fact = 0.0, 1.0
        for k in range(1, 24):
            fact *= k
            s += special.polygamma(k - 1, a) * e ** (k - 1) / fact
        return float(s)
    return float((special.gammaln(a + e) - special.gammaln(a)) / e)


def _mpl_series(T: np.ndarray, n: float, d: int, J: int = 40) -> np.ndarray:
    """Ascending series of F(T) = E[x h(T/x)] (d = 0) or F'(T) = 1 - E[exp(-T/x)] (d = 1).

    x ~ Gamma(n), h(u) = u - 1 + exp(-u), T > 0.  From the series of x^nu K_nu(x):
    F^(d)(T) = sum_{j>=2} (-1)^j Gamma(n+1-j)/Gamma(n) T^(j-d)/(j-d)!
             + Gamma(1-n) sum_{m>=0} T^(m+n+1-d) / (m! Gamma(m+n+2-d)).
    Near an integer N = round(n) >= 1 the term j = N+1+m of the first sum and the term m of
    the second have cancelling poles; each such pair is evaluated in closed form
    (eps = N - n):  (-1)^N pi T^q / (Gamma(n) q! m!) * T^(-eps) q!/Gamma(q+1-eps)
    * expm1(eps D)/sin(pi eps),  q = j - d,  D = ln T - dlg(1+m, eps) - dlg(q+1, -eps).
    No cancellation for small T (every term is O(T^2) or O(T^(n+1))).
    """
    lnT = np.log(T)
    out = np.zeros_like(T)
    N = int(math.floor(n + 0.5))
    lgn = special.gammaln(n)
    ratio = 1.0                                    # Gamma(n+1-j)/Gamma(n)
    jmax = J if N == 0 else N
    for j in range(2, jmax + 1):                   # unpaired terms of the first sum
        ratio /= n - (j - 1)
        out += (-1) ** j * ratio * np.exp((j - d) * lnT - special.gammaln(j - d + 1))
    if N == 0:
        g1n = special.gamma(1.0 - n)
        for m in range(J):
            out += g1n * np.exp((m + n + 1 - d) * lnT - special.gammaln(m + 1)
                                - special.gammaln(m + n + 2 - d))
        return out
    eps = N - n
    pref = 1.0 / math.pi if eps == 0.0 else eps / math.sin(math.pi * eps)
    for m in range(J):
        q = N + 1 + m - d
        D = lnT - _dlgamma(1.0 + m, eps) - _dlgamma(q + 1.0, -eps)
        f = D if eps == 0.0 else np.expm1(eps * D) / eps
        logmag = (q - eps) * lnT - lgn - special.gammaln(q + 1 - eps) - special.gammaln(m + 1)
        out += (-1) ** N * math.pi * pref * np.exp(logmag) * f
    return out


_X_MAX = 5000.0        # 2 sqrt(T) beyond which exp(-X) X^(n+1) underflows (n <= 20)


def _mpl_switch(n: float) -> float:
    """T above which the Bessel-K forms are used instead of the ascending series."""
    return 2.0 if n <= 3.0 else min(n, 10.0)


def _mpl_one_minus_phi(T: np.ndarray, n: float) -> np.ndarray:
    """1 - E[exp(-T/x)], x ~ Gamma(n): 1 - 2 T^(n/2) K_n(2 sqrt T)/Gamma(n), accurate at small T."""
    out = np.zeros_like(T)
    out[np.isinf(T)] = 1.0
    fin = (T > 0) & np.isfinite(T)
    s = fin & (T <= _mpl_switch(n))
    b = fin & ~s
    if s.any():
        out[s] = _mpl_series(T[s], n, 1)
    if b.any():
        Tb = T[b]
        Tc = np.minimum(Tb, 0.25 * _X_MAX ** 2)       # kve fails beyond ~1e9; e^-X ~ 0 there
        X = 2.0 * np.sqrt(Tc)
        with np.errstate(divide="ignore", under="ignore"):
            lg = math.log(2.0) + 0.5 * n * np.log(Tc) + np.log(special.kve(n, X)) - X - special.gammaln(n)
        out[b] = np.where(2.0 * np.sqrt(Tb) >= _X_MAX, 1.0, 1.0 - np.exp(lg))
    return out


def _mpl_F(T: np.ndarray, n: float) -> np.ndarray:
    """F(T) = int_0^T (1 - E[exp(-s/x)]) ds = T - n + 2^(-n) X^(n+1) K_{n+1}(X)/Gamma(n), X = 2 sqrt T."""
    out = np.zeros_like(T)
    out[np.isinf(T)] = np.inf
    fin = (T > 0) & np.isfinite(T)
    s = fin & (T <= _mpl_switch(n))
    b = fin & ~s
    if s.any():
        out[s] = _mpl_series(T[s], n, 0)
    if b.any():
        Tb = T[b]
        X = 2.0 * np.sqrt(np.minimum(Tb, 0.25 * _X_MAX ** 2))
        with np.errstate(divide="ignore", under="ignore"):
            lg = (-n * math.log(2.0) + (n + 1.0) * np.log(X) + np.log(special.kve(n + 1.0, X))
                  - X - special.gammaln(n))
        out[b] = (Tb - n) + np.where(2.0 * np.sqrt(Tb) >= _X_MAX, 0.0, np.exp(lg))
    return out


def mpl_normalized_creep_compliance(t, n, k):
    """Normalized creep compliance of the MPL retardation model.

    .. math:: \\hat C(t) = 1 - (1-k)\\,\\frac{2\\, t^{n/2} K_n(2\\sqrt{t})}{\\Gamma(n)}

    Parameters
    ----------
    t : float or array_like
        Time in units of tau0, ``t >= 0`` (``inf`` allowed).
    n : float
        Spectrum exponent, ``0 < n <= 20``.
    k : float
        ``E0/Einf`` in (0, 1].

    Returns
    -------
    float or ndarray
        ``Chat(t)`` in [k, 1]; ``Chat(0) = k``, ``Chat(inf) = 1``.  Computed as
        ``k + (1-k) (1 - phi)`` with ``1 - phi`` from a cancellation-free ascending series for
        ``t <= 2``, so the relative accuracy (~1e-14) holds even for tiny ``k``.
    """
    n = _check_n(n)
    k = check_range("k", k, 0.0, 1.0, lo_open=True)
    t, scalar = _as_time_array("t", t)
    T = t.ravel()
    out = (k + (1.0 - k) * _mpl_one_minus_phi(T, n)).reshape(t.shape)
    return float(out) if scalar else out


def mpl_integrated_compliance(T, n, k):
    """Integrated compliance of the MPL retardation model, ``Psi(T) = int_0^T Chat``.

    .. math:: \\Psi(T) = T - (1-k)\\left[n - \\frac{2^{-n}}{\\Gamma(n)} X^{n+1} K_{n+1}(X)\\right],
              \\quad X = 2\\sqrt{T}

    Evaluated as ``k T + (1-k) F(T)`` with ``F = E[x h(T/x)] >= 0``, ``h(u) = u - 1 + e^-u``,
    ``x ~ Gamma(n)``: an ascending series without cancellation for small ``T`` (where
    ``Psi ~ k T``) and the Bessel form above for large ``T``.  ``T`` in units of tau0, ``>= 0``.
    Relative accuracy ~1e-13.
    """
    n = _check_n(n)
    k = check_range("k", k, 0.0, 1.0, lo_open=True)
    t, scalar = _as_time_array("T", T)
    TT = t.ravel()
    with np.errstate(invalid="ignore"):
        out = np.where(np.isinf(TT), np.inf, k * TT + (1.0 - k) * _mpl_F(TT, n)).reshape(t.shape)
    return float(out) if scalar else out


def _h(u: np.ndarray) -> np.ndarray:
    """h(u) = u - 1 + exp(-u) >= 0 without cancellation (u >= 0; inf -> inf)."""
    out = np.empty_like(u)
    s = u < 0.1
    us = u[s]
    acc = np.zeros_like(us)
    term = us * us / 2.0
    for j in range(3, 16):          # u^2/2 - u^3/6 + ...
        acc += term
        term = -term * us / j
    out[s] = acc
    ub = u[~s]
    with np.errstate(invalid="ignore"):
        out[~s] = np.where(np.isinf(ub), np.inf, ub + np.expm1(-ub))
    return out


def sls_integrated_compliance(T, k):
    """Integrated compliance of the SLS, ``Psi(T) = T - (1-k)(1 - exp(-T)) = k T + (1-k) h(T)``.

    ``T >= 0`` in units of tau0 (the retardation time); ``k`` in (0, 1].  Computed without
    cancellation at small ``T`` (``Psi ~ k T``).
    """
    k = check_range("k", k, 0.0, 1.0, lo_open=True)
    t, scalar = _as_time_array("T", T)
    TT = t.ravel()
    with np.errstate(invalid="ignore"):
        out = np.where(np.isinf(TT), np.inf, k * TT + (1.0 - k) * _h(TT)).reshape(t.shape)
    return float(out) if scalar else out


# ===================================================================== Prony tables

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


# ======================================================================== PronySeries

@dataclass(frozen=True, eq=False)
class PronySeries:
    """A Prony (Kelvin) approximation of a normalized creep compliance on a time window.

    .. math:: \\hat C(t) \\approx 1 - \\sum_i c_i\\, e^{-t/\\tau_i}, \\qquad e^{-t/\\infty} = 1

    Attributes
    ----------
    weights : ndarray
        ``c_i >= 0`` (dimensionless), as required by a dissipative recursion.
    times : ndarray
        ``tau_i > 0`` in units of tau0, ascending.  ``inf`` marks the lumped glassy term: the
        modes slower than the window act as a constant ``c`` there (in the recursion of
        docs/design.md section 4 it has ``e_i = b_i = 1``).  Modes faster than the window are lumped
        as relaxed, i.e. dropped.
    max_rel_error : float
        Achieved ``max |series - Chat| / Chat`` over ``[t_min, t_max]``, measured on a log grid
        of 160 points per decade (ends included) refined at the local maxima.
    rtol : float
        Requested bound.
    converged : bool
        ``max_rel_error <= rtol``.  When the request could not be met, the best series found is
        returned with ``converged=False`` (no exception): check this flag.
    k : float
        The material's ``E0/Einf`` (for reference; the series' own value at t = 0 is ``chat0``).
    t_min, t_max : float
        The window, in units of tau0.
    elapsed : float
        Wall time of the fit, s.
    """

    weights: np.ndarray
    times: np.ndarray
    max_rel_error: float
    rtol: float
    converged: bool
    k: float
    t_min: float
    t_max: float
    elapsed: float = 0.0

    @property
    def n_terms(self) -> int:
        """Number of terms, the lumped constant (``times == inf``) included."""
        return int(self.weights.size)

    @property
    def chat0(self) -> float:
        """The series at t = 0, ``1 - sum c_i`` (>= k: fast modes were dropped)."""
        return float(1.0 - self.weights.sum())

    def __call__(self, t):
        """``1 - sum c_i exp(-t/tau_i)`` for times ``t >= 0`` in units of tau0."""
        t, scalar = _as_time_array("t", t)
        out = _kelvin_chat(t, self.weights, self.times, self.chat0)
        return float(out) if scalar else out

    normalized_creep_compliance = __call__

    def integrated_compliance(self, T):
        """``int_0^T`` of the series, closed form (the constant term integrates to ``c T``)."""
        t, scalar = _as_time_array("T", T)
        out = _kelvin_psi(t, self.weights, self.times, self.chat0)
        return float(out) if scalar else out

    def __repr__(self):
        return (f"PronySeries(n_terms={self.n_terms}, window=[{self.t_min:.3g}, {self.t_max:.3g}], "
                f"max_rel_error={self.max_rel_error:.3g}, rtol={self.rtol:.3g}, "
                f"converged={self.converged})")


# ========================================================================== materials

class _Material:
    """Shared interface.  Subclasses define ``normalized_creep_compliance`` and friends."""

    E0: float
    Einf: float
    tau0: float

    # -- constants
    @property
    def k(self) -> float:
        """``E0/Einf`` in (0, 1]: the normalized glassy compliance Chat(0)."""
        return self.E0 / self.Einf

    @property
    def C0(self) -> float:
        """Relaxed compliance ``1/E0``."""
        return 1.0 / self.E0

    @property
    def Cinf(self) -> float:
        """Glassy compliance ``1/Einf``."""
        return 1.0 / self.Einf

    # -- physical wrappers
    def creep_compliance(self, t):
        """Creep compliance ``C(t) = Chat(t/tau0)/E0`` (1/modulus units), ``t >= 0`` in tau0's units."""
        t, scalar = _as_time_array("t", t)
        out = self._chat(t / self.tau0) / self.E0
        return float(out) if scalar else out

    def relaxation_modulus(self, t):
        """Relaxation modulus ``R(t) = E0 Rhat(t/tau0)`` (modulus units), ``t >= 0``."""
        t, scalar = _as_time_array("t", t)
        out = self._rhat(t / self.tau0) * self.E0
        return float(out) if scalar else out

    def normalized_creep_compliance(self, that):
        """``Chat(that) = C(t)/C0`` at normalized times ``that = t/tau0 >= 0``; in [k, 1]."""
        t, scalar = _as_time_array("that", that)
        out = self._chat(t)
        return float(out) if scalar else out

    def normalized_relaxation_modulus(self, that):
        """``Rhat(that) = R(t)/E0`` at ``that = t/tau0 >= 0``; in [1, 1/k]."""
        t, scalar = _as_time_array("that", that)
        out = self._rhat(t)
        return float(out) if scalar else out

    def integrated_compliance(self, that):
        """``Psi(T) = int_0^T Chat(s) ds``, ``T = that >= 0`` in units of tau0."""
        t, scalar = _as_time_array("that", that)
        out = self._psi(t)
        return float(out) if scalar else out

    def complex_compliance(self, omega):
        """Complex compliance ``C(omega) = C' - i C''`` (1/modulus units), ``omega >= 0`` in rad/(tau0's unit)."""
        w, scalar = _as_time_array("omega", omega)
        out = self._cstar(w * self.tau0) / self.E0
        return complex(out) if scalar else out

    def complex_modulus(self, omega):
        """Complex modulus ``E(omega) = E' + i E''`` (modulus units), ``omega >= 0``."""
        w, scalar = _as_time_array("omega", omega)
        out = self._estar(w * self.tau0) * self.E0
        return complex(out) if scalar else out

    # default conversions between the two complex functions
    def _estar(self, w):
        return 1.0 / self._cstar(w)

    def _cstar(self, w):
        return 1.0 / self._estar(w)

    # -- Prony
    def prony(self, t_min, t_max, rtol=1e-4, max_terms=None):
        """Fewest-term Prony (Kelvin) series of ``Chat`` on ``[t_min, t_max]`` (units of tau0).

        Parameters
        ----------
        t_min, t_max : float
            Window, ``0 < t_min < t_max < inf``, in units of tau0 (normalized time).
        rtol : float
            Bound on ``max |series - Chat|/Chat`` over the window, in [1e-12, 0.5].
        max_terms : int, optional
            Cap on the number of terms (the constant included); default 120.  If the bound
            needs more, the best series within the cap comes back with ``converged=False``.

        Returns
        -------
        PronySeries
            Weights ``c_i >= 0`` and times (``inf`` = lumped glassy constant); see
            :class:`PronySeries`.  If ``rtol`` cannot be met, the best series is returned with
            ``converged=False`` and its honest ``max_rel_error``.

        Notes
        -----
        The error is measured on a log grid of 160 points per decade (ends included) and
        refined at its largest local maxima; a series counts as passing at 0.99 rtol.
        For a given number N of finite modes the log times start at the quantiles of a
        density profile (from a nonnegative least-squares fit on a dense dictionary of
        6 modes per decade: nodes where modes matter, denser where they matter more) or from
        the nearest solution already found, and are optimized by variable projection
        (Levenberg-Marquardt on log tau with NNLS weights), then by Lawson reweighting towards
        the minimax fit.  The smallest passing N is found by bracketing and secant/bisection
        on log(error) versus N.  Weights satisfy ``0 <= c_i <= 1`` and ``sum c_i <= 1`` (so
        that ``C_eff = 1 - sum c_i b_i >= 0`` in the recursion).  Exact tables (SLS, Kelvin
        or Maxwell Prony) are also offered, with modes outside the window lumped; on a tie in
        the number of terms they win.  Typical cost 0.02-0.2 s; about 1 s for 14 decades at
        rtol = 1e-7.  The result is deterministic.
        """
        t_min = check_range("t_min", t_min, 0.0, lo_open=True)
        t_max = check_range("t_max", t_max, 0.0, lo_open=True)
        if not t_max > t_min:
            raise InputError(f"t_max must be > t_min = {t_min:.6g} (got {t_max:.6g})")
        if math.log10(t_max) - math.log10(t_min) > MAX_WINDOW_DECADES:
            raise InputError(f"t_max/t_min must be at most 1e{MAX_WINDOW_DECADES:g} (got the "
                             f"window [{t_min:.3g}, {t_max:.3g}])")
        rtol = check_range("rtol", rtol, 1e-12, 0.5)
        max_terms = 120 if max_terms is None else check_int("max_terms", max_terms, 1, 120)
        return fit_prony(self._chat, t_min, t_max, rtol, self.k, exact=self._kelvin_exact(),
                         max_terms=max_terms)

    def _kelvin_exact(self):
        return None

    def __repr__(self):
        return f"{type(self).__name__}(E0={self.E0:.6g}, Einf={self.Einf:.6g}, tau0={self.tau0:.6g})"


class _MPL(_Material):
    """The four constants shared by the two MPL models (E0, Einf, n, tau0); each subclass
    is a different material built from them."""

    def __init__(self, E0, Einf, n, tau0):
        self.E0, self.Einf = _check_moduli(E0, Einf)
        self.n = _check_n(n)
        self.tau0 = check_positive("tau0", tau0)
        self._rtab = None     # numerical relaxation table (MPLRetardation)
        self._ctab = None     # numerical creep table (MPLRelaxation)

    @classmethod
    def from_k(cls, n, k, E0=1.0, tau0=1.0):
        """Build from ``(n, k)`` with ``Einf = E0/k`` (dimensionless scenes: E0 = tau0 = 1)."""
        k = check_range("k", k, 0.0, 1.0, lo_open=True)
        return cls(E0, check_positive("E0", E0) / k, n, tau0)


class MPLRetardation(_MPL):
    """Modified power law RETARDATION spectrum (paper eq. retspec).

    .. math:: L(\\tau) = \\frac{C_0 - C_\\infty}{\\Gamma(n)} (\\tau/\\tau_0)^n e^{-\\tau/\\tau_0}

    i.e. retardation times Gamma(n)-distributed in units of tau0.  Closed forms:

    * creep compliance (eq. Ctgen)
      ``C(t) = C0 - 2 (C0 - Cinf)/Gamma(n) (t/tau0)^(n/2) K_n(2 sqrt(t/tau0))``;
    * complex compliance (eq. Comega)
      ``C(omega) = Cinf + (C0 - Cinf)/(i w) exp(-i/w) E_n(-i/w)``, ``w = omega tau0``,
      with the generalized exponential integral of imaginary argument (:func:`expint`);
    * ``complex_modulus = 1/complex_compliance``;
    * integrated compliance (docs/design.md section 3), closed form.

    The relaxation modulus has no closed form: it is computed NUMERICALLY (the Gamma
    retardation spectrum discretized on a log lattice and the Kelvin table converted exactly to
    Wiechert form, see :func:`kelvin_to_maxwell`).  The table is built for the smallest
    positive time requested (at least down to 1e-16 tau0; faster modes lumped into one) and
    cached; measured accuracy ~1e-12 (hereditary-integral and 1/C(omega) checks in the tests).

    Parameters
    ----------
    E0 : float
        Relaxed modulus (> 0).
    Einf : float
        Glassy modulus (>= E0).
    n : float
        Exponent, 0 < n <= 20 (paper: 0.2 .. 1.6; PDMS 0.2207).
    tau0 : float
        Characteristic time (> 0), the unit of ``t``.
    """


    def _chat(self, t):
        T = t.ravel()
        return (self.k + (1.0 - self.k) * _mpl_one_minus_phi(T, self.n)).reshape(t.shape)

    def _psi(self, t):
        T = t.ravel()
        with np.errstate(invalid="ignore"):
            out = np.where(np.isinf(T), np.inf, self.k * T + (1.0 - self.k) * _mpl_F(T, self.n))
        return out.reshape(t.shape)

    def _cstar(self, w):
        # (C/C0) = k + (1-k) E[1/(1 + i w x)] = k + (1-k) conj(zg(1/w))
        W = w.ravel()
        with np.errstate(divide="ignore"):
            inv = np.where(W > 0, 1.0 / np.where(W > 0, W, 1.0), np.inf)
        inv[np.isinf(W)] = 0.0
        G = np.conj(_zg(self.n, inv))
        return (self.k + (1.0 - self.k) * G).reshape(w.shape)

    def _rhat(self, t):
        T = t.ravel()
        pos = T[(T > 0) & np.isfinite(T)]
        lo = float(pos.min()) if pos.size else 1.0
        tab = self._relaxation_table(lo)
        e, tau = tab
        return _maxwell_rhat(t, e, tau)

    def _relaxation_table(self, t_lo):
        """Wiechert table (e_i = E_i/E0, tau_i in tau0) accurate for times >= t_lo."""
        t_lo = min(t_lo, 1e-16)
        if self._rtab is None or self._rtab[0] > t_lo:
            if self.k == 1.0:
                self._rtab = (t_lo, (np.zeros(0), np.zeros(0)))
            else:
                m, x = _gamma_lattice(self.n, 1e-6 * t_lo)
                e, tau = kelvin_to_maxwell((1.0 - self.k) * m, x, k=self.k)
                self._rtab = (t_lo, (e, tau))
        return self._rtab[1]

    def __repr__(self):
        return (f"MPLRetardation(E0={self.E0:.6g}, Einf={self.Einf:.6g}, n={self.n:.6g}, "
                f"tau0={self.tau0:.6g})")


class MPLRelaxation(_MPL):
    """Modified power law RELAXATION spectrum (paper eq. relspec) -- not the BEM's model.

    .. math:: H(\\tau) = \\frac{E_\\infty - E_0}{\\Gamma(n)} (\\tau_0/\\tau)^n e^{-\\tau_0/\\tau}

    i.e. relaxation RATES Gamma(n)-distributed in units of 1/tau0.  Closed forms:

    * relaxation modulus (eq. Rt3) ``R(t) = E0 + (Einf - E0)/(1 + t/tau0)^n``;
    * complex modulus (eq. Eomega) ``E(omega) = E0 + (Einf - E0) i w exp(i w) E_n(i w)``,
      ``w = omega tau0``;
    * ``complex_compliance = 1/complex_modulus``.

    The creep compliance (hence ``normalized_creep_compliance``, ``integrated_compliance`` and
    ``prony``) is computed NUMERICALLY: the Gamma relaxation spectrum is discretized on a log
    lattice (the slowest tail lumped into one arm) and the Wiechert table converted exactly to
    Kelvin form (:func:`maxwell_to_kelvin`).  The table (:meth:`creep_table`) is built for the
    largest time requested (at least 1e16 tau0) and cached; measured accuracy ~1e-12.

    Parameters are as for :class:`MPLRetardation` (same four constants, different material).
    """


    def _rhat(self, t):
        with np.errstate(divide="ignore"):
            return 1.0 + (1.0 / self.k - 1.0) * np.exp(-self.n * np.log1p(t))

    def _estar(self, w):
        W = w.ravel()
        return (1.0 + (1.0 / self.k - 1.0) * _zg(self.n, W)).reshape(w.shape)

    def creep_table(self, t_hi=1e16):
        """Kelvin table ``(c_i, theta_i)`` of this material (theta in tau0), valid for t <= t_hi."""
        t_hi = max(float(t_hi), 1e16)
        if self._ctab is None or self._ctab[0] < t_hi:
            if self.k == 1.0:
                self._ctab = (t_hi, (np.zeros(0), np.zeros(0)))
            else:
                m, y = _gamma_lattice(self.n, 1e-8 / t_hi)
                c, th = maxwell_to_kelvin((1.0 / self.k - 1.0) * m, 1.0 / y)
                self._ctab = (t_hi, (c, th))
        return self._ctab[1]

    def _table_for(self, t):
        fin = t[np.isfinite(t)]
        return self.creep_table(float(fin.max()) if fin.size else 1.0)

    def _chat(self, t):
        c, th = self._table_for(t)
        return _kelvin_chat(t, c, th, self.k)

    def _psi(self, t):
        c, th = self._table_for(t)
        with np.errstate(invalid="ignore"):
            out = _kelvin_psi(t, c, th, self.k)
        return np.where(np.isinf(t), np.inf, out)

    def __repr__(self):
        return (f"MPLRelaxation(E0={self.E0:.6g}, Einf={self.Einf:.6g}, n={self.n:.6g}, "
                f"tau0={self.tau0:.6g})")


class SLS(_Material):
    """Standard linear solid, Kelvin form with RETARDATION time tau0.

    ``Chat(t) = 1 - (1-k) exp(-t/tau0)``, ``C(omega) = Cinf + (C0 - Cinf)/(1 + i omega tau0)``,
    ``R(t) = E0 + (Einf - E0) exp(-t/(k tau0))`` (relaxation time ``k tau0``),
    ``Psi(T) = k T + (1-k)(T - 1 + exp(-T))``.  All closed form.

    tau0 is the retardation (creep) time, as in the paper's dimensionless SLS
    ``Chat = 1 - (1-k) exp(-t)`` (docs/design.md section 3).
    """

    def __init__(self, E0, Einf, tau0):
        self.E0, self.Einf = _check_moduli(E0, Einf)
        self.tau0 = check_positive("tau0", tau0)

    @classmethod
    def from_k(cls, k, E0=1.0, tau0=1.0):
        """Build from ``k`` with ``Einf = E0/k``."""
        k = check_range("k", k, 0.0, 1.0, lo_open=True)
        return cls(E0, check_positive("E0", E0) / k, tau0)

    def _chat(self, t):
        return self.k - (1.0 - self.k) * np.expm1(-t)

    def _psi(self, t):
        T = t.ravel()
        with np.errstate(invalid="ignore"):
            out = np.where(np.isinf(T), np.inf, self.k * T + (1.0 - self.k) * _h(T))
        return out.reshape(t.shape)

    def _cstar(self, w):
        with np.errstate(invalid="ignore"):
            out = self.k + (1.0 - self.k) / (1.0 + 1j * w)
        return np.where(np.isinf(w), self.k, out)

    def _estar(self, w):
        with np.errstate(invalid="ignore"):
            out = (1.0 + 1j * w) / (1.0 + 1j * w * self.k)
        return np.where(np.isinf(w), 1.0 / self.k, out)

    def _rhat(self, t):
        return 1.0 + (1.0 / self.k - 1.0) * np.exp(-t / self.k)

    def _kelvin_exact(self):
        return np.array([1.0 - self.k]), np.array([1.0])


class Prony(_Material):
    """A Prony-series material from a table, Kelvin (retardation) or Wiechert (relaxation).

    Parameters
    ----------
    weights : array_like
        ``kind="kelvin"``: dimensionless ``c_i >= 0`` with ``sum c_i < 1``, so that
        ``Chat(t) = 1 - sum c_i exp(-t/tau_i)`` and ``k = 1 - sum c_i``.
        ``kind="maxwell"``: arm moduli ``E_i >= 0`` (units of E0), so that
        ``R(t) = E0 + sum E_i exp(-t/tau_i)`` and ``Einf = E0 + sum E_i``.
    times : array_like
        Retardation (kelvin) or relaxation (maxwell) times ``tau_i > 0``, finite, in the units
        of ``tau0`` multiplied by nothing: physical times (same unit as ``t``).
    E0 : float
        Relaxed modulus (> 0): sets ``C0 = 1/E0`` (kelvin) or the equilibrium spring (maxwell).
    kind : {"kelvin", "maxwell"}
    tau0 : float
        Time unit used by the normalized methods (``that = t/tau0``), default 1.

    The other form is obtained exactly (:func:`maxwell_to_kelvin`, :func:`kelvin_to_maxwell`):
    ``kelvin_weights, kelvin_times`` and ``maxwell_moduli, maxwell_times`` are both available
    (times in physical units), and every method is closed form.
    """

    def __init__(self, weights, times, E0=1.0, kind="kelvin", tau0=1.0):
        self.kind = check_choice("kind", kind, ("kelvin", "maxwell"))
        self.E0 = check_positive("E0", E0)
        self.tau0 = check_positive("tau0", tau0)
        w = _check_table("weights", weights, lo=0.0)
        tau = _check_table("times", times, lo=0.0, lo_open=True)
        if w.size != tau.size:
            raise InputError(f"times must have the same length as weights ({w.size}) (got {tau.size})")
        if self.kind == "kelvin":
            s = float(w.sum())
            if not s < 1.0:
                raise InputError(f"weights must be >= 0 with sum < 1 for kind='kelvin' "
                                 f"(k = 1 - sum in (0, 1]) (got sum {s:.6g})")
            c, th = _merge_times(w, tau / self.tau0)
            self.Einf = self.E0 / (1.0 - s)
            self._c, self._th = c, th
            self._e, self._tr = kelvin_to_maxwell(c, th, k=self.k)
        else:
            e, tr = _merge_times(w / self.E0, tau / self.tau0)
            self.Einf = self.E0 * (1.0 + e.sum())
            self._e, self._tr = e, tr
            self._c, self._th = maxwell_to_kelvin(e, tr)

    @property
    def kelvin_weights(self):
        """Dimensionless Kelvin weights ``c_i`` (``Chat = 1 - sum c_i exp(-t/theta_i)``)."""
        return self._c.copy()

    @property
    def kelvin_times(self):
        """Retardation times ``theta_i`` (physical units)."""
        return self._th * self.tau0

    @property
    def maxwell_moduli(self):
        """Wiechert arm moduli ``E_i`` (units of E0)."""
        return self._e * self.E0

    @property
    def maxwell_times(self):
        """Relaxation times ``tau_i`` (physical units)."""
        return self._tr * self.tau0

    def _chat(self, t):
        return _kelvin_chat(t, self._c, self._th, self.k)

    def _psi(self, t):
        with np.errstate(invalid="ignore"):
            out = _kelvin_psi(t, self._c, self._th, self.k)
        return np.where(np.isinf(t), np.inf, out)

    def _rhat(self, t):
        return _maxwell_rhat(t, self._e, self._tr)

    def _cstar(self, w):
        if self.kind == "maxwell":
            return 1.0 / self._estar(w)
        out = np.full(w.shape, self.k, dtype=complex)
        for ci, ti in zip(self._c, self._th):
            with np.errstate(invalid="ignore"):
                out += np.where(np.isinf(w), 0.0, ci / (1.0 + 1j * w * ti))
        return out

    def _estar(self, w):
        if self.kind == "kelvin":
            return 1.0 / self._cstar(w)
        out = np.ones(w.shape, dtype=complex)
        for ei, ti in zip(self._e, self._tr):
            with np.errstate(invalid="ignore"):
                out += np.where(np.isinf(w), ei, ei * (1j * w * ti) / (1.0 + 1j * w * ti))
        return out

    def _kelvin_exact(self):
        return self._c, self._th

    def __repr__(self):
        return (f"Prony(kind={self.kind!r}, terms={self._c.size}, E0={self.E0:.6g}, "
                f"Einf={self.Einf:.6g}, tau0={self.tau0:.6g})")


def _check_table(name, values, lo=None, lo_open=False):
    try:
        arr = np.asarray(values, dtype=float).ravel()
    except (TypeError, ValueError):
        raise InputError(f"{name} must be numbers (got {values!r})") from None
    if arr.size == 0:
        raise InputError(f"{name} must have at least one entry (got an empty table)")
    bad = ~np.isfinite(arr)
    if bad.any():
        raise InputError(f"{name} must be finite numbers (got {arr[bad][0]!r})")
    m = float(arr.min())
    if lo is not None and (m < lo or (lo_open and m == lo)):
        raise InputError(f"{name} must be {'>' if lo_open else '>='} {lo:g} (got {m:.6g})")
    return arr


# ====================================================================== Prony fitting

FIT_PPD = 24          # fit grid, points per decade
CHECK_PPD = 160       # measurement grid, points per decade (plus local refinement)


def _loggrid(a: float, b: float, ppd: int) -> np.ndarray:
    m = max(int(math.ceil(math.log10(b / a) * ppd)), 2)
    g = np.logspace(math.log10(a), math.log10(b), m + 1)
    g[0], g[-1] = a, b
    return g


def _design(t: np.ndarray, taus: np.ndarray) -> np.ndarray:
    """Columns exp(-t/tau_i) and a final constant column."""
    with np.errstate(under="ignore"):
        A = np.exp(-t[:, None] / taus[None, :])
    return np.hstack([A, np.ones((t.size, 1))])


def _lp_weights(M: np.ndarray, b: np.ndarray):
    """min_c max |M c - b| subject to c >= 0 (HiGHS).  Returns (c, e) or (None, inf)."""
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
    try:
        c = nnls(M, b, maxiter=100 * M.shape[1])[0]
    except RuntimeError:                       # pragma: no cover - not seen in practice
        c = np.clip(np.linalg.lstsq(M, b, rcond=None)[0], 0.0, None)
    if c.size and c.max() > 1.0:
        c = lsq_linear(M, b, bounds=(0.0, 1.0), method="bvls").x
    return c


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
        """Minimax relative error with c >= 0 on the fit grid: LP with row exchange."""
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
        Jacobian on the active set).  Monotone: never returns worse L2 than the start."""
        tg = self.tg
        sw = self.w if lw is None else self.w * np.sqrt(lw)
        b = (1.0 - self.yg) * sw
        N = lt.size
        ones = np.ones((tg.size, 1))

        def evaluate(lt):
            taus = np.exp(lt)
            with np.errstate(under="ignore"):
                X = tg[:, None] / taus[None, :]
                E = np.exp(-X)
            A = np.hstack([E, ones]) * sw[:, None]
            c = _nnls(A, b)
            r = A @ c - b
            act = (c > 0) & (c < 1.0)
            if act.any():
                Q, _ = np.linalg.qr(A[:, act])
                D = E * X * sw[:, None] * c[None, :N]
                J = D - Q @ (Q.T @ D)
            else:
                J = np.zeros((tg.size, N))
            return r, J

        lt = np.clip(np.sort(lt), self.lt_lo, self.lt_hi)
        if N == 0:
            return lt
        r, J = evaluate(lt)
        f = float(r @ r)
        mu = 1e-3
        for _ in range(iters):
            g = J.T @ r
            H = J.T @ J
            dH = np.diag(H).copy()
            dH[dH <= 0] = 1e-300
            try:
                step = np.linalg.solve(H + mu * np.diag(dH), -g)
            except np.linalg.LinAlgError:
                mu *= 10.0
                continue
            lt2 = np.clip(lt + np.clip(step, -2.0, 2.0), self.lt_lo, self.lt_hi)
            r2, J2 = evaluate(lt2)
            f2 = float(r2 @ r2)
            if f2 < f:
                done = f - f2 <= 1e-9 * f
                lt, r, J, f = lt2, r2, J2, f2
                mu = max(mu / 3.0, 1e-9)
                if done:
                    break
            else:
                mu *= 4.0
                if mu > 1e6:
                    break
        return np.sort(lt)

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
        while n_pass - n_fail > 1:
            lo_e = tried[n_fail][0] if n_fail else None
            hi_e = tried[n_pass][0]
            if lo_e is not None and lo_e > hi_e:
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
