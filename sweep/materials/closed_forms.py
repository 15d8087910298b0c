"""Time-domain closed forms: the MPL retardation creep compliance and its integral
Psi(T) (docs/design.md section 3), and the SLS integrated compliance."""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from ..errors import check_range
from ._checks import _as_time_array, _check_n


def _dlgamma(a: float, e: float) -> float:
    """(lnGamma(a+e) - lnGamma(a))/e for a >= 1, |e| <= 1/2; psi(a) at e = 0."""
    from scipy import special  # lazy: not on a BEM scene's path (docs/performance.md)
    if e == 0.0:
        return float(special.digamma(a))
    if abs(e) < 0.05:
        s, fact = 0.0, 1.0
        psi = special.polygamma(np.arange(23), a)    # one call: 12 us against 170 us
        for k in range(1, 24):
            fact *= k
            s += psi[k - 1] * e ** (k - 1) / fact
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
    The factors that do not depend on T are computed once per (n, d, J)
    (:func:`_series_factors`; a Prony fit evaluates the series hundreds of times).
    On fewer than SERIES_TERMWISE_BELOW times the terms are summed as one array
    (:func:`_series_few`), in the same order, to the same bits.
    """
    if T.size < SERIES_TERMWISE_BELOW:
        return _series_few(T, n, d, J)
    lnT = np.log(T)
    out = np.zeros_like(T)
    unpaired, tail = _series_factors(n, d, J)
    for sign_ratio, power, lg in unpaired:         # unpaired terms of the first sum
        out += sign_ratio * np.exp(power * lnT - lg)
    kind, factors = tail
    if kind == "gamma":
        for g1n, power, lg1, lg2 in factors:
            out += g1n * np.exp(power * lnT - lg1 - lg2)
        return out
    eps = factors[0]
    for scale, dl1, dl2, power, lgn, lg1, lg2 in factors[1:]:
        D = lnT - dl1 - dl2
        f = D if eps == 0.0 else np.expm1(eps * D) / eps
        logmag = power * lnT - lgn - lg1 - lg2
        out += scale * np.exp(logmag) * f
    return out


#: below this many times :func:`_mpl_series` evaluates its terms as one (times x terms)
#: array rather than a term at a time: a Prony fit's error check evaluates the compliance at
#: a few refined times about a thousand times a fit, where the 40-80 NumPy operations of the
#: term-wise sum on a few numbers cost 0.19 ms a call against 0.017 ms as one array (6
#: times; 22 % of a fit's time on the data set's sample, 2026-11-26); on the fit's grids
#: (hundreds of times) the term-wise sum is the faster, 0.33 against 1.2 ms at 900 times
SERIES_TERMWISE_BELOW = 32


def _series_few(T: np.ndarray, n: float, d: int, J: int) -> np.ndarray:
    """:func:`_mpl_series` with every term evaluated at once and the terms added in the same
    order as there (a sequential accumulation from zero: the same bits)."""
    lnT = np.log(T)[:, None]
    unpaired, (kind, tail) = _series_arrays(n, d, J)
    sign_ratio, power, lg = unpaired
    parts = [np.zeros((T.size, 1)), sign_ratio * np.exp(power * lnT - lg)]
    if kind == "gamma":
        g1n, power, lg1, lg2 = tail
        parts.append(g1n * np.exp(power * lnT - lg1 - lg2))
    else:
        eps, (scale, dl1, dl2, power, lgn, lg1, lg2) = tail
        D = lnT - dl1 - dl2
        f = D if eps == 0.0 else np.expm1(eps * D) / eps
        parts.append(scale * np.exp(power * lnT - lgn - lg1 - lg2) * f)
    return np.add.accumulate(np.concatenate(parts, axis=1), axis=1)[:, -1].copy()


@lru_cache(maxsize=256)
def _series_arrays(n: float, d: int, J: int):
    """:func:`_series_factors` as arrays, one per factor (a row of each term)."""
    unpaired, (kind, factors) = _series_factors(n, d, J)
    rows = (lambda terms, width: tuple(np.array(x, dtype=float) for x in zip(*terms))
            if terms else (np.zeros(0),) * width)
    if kind == "gamma":
        return rows(unpaired, 3), (kind, rows(factors, 4))
    return rows(unpaired, 3), (kind, (factors[0], rows(factors[1:], 7)))


@lru_cache(maxsize=256)
def _series_factors(n: float, d: int, J: int):
    """The T-independent factors of the terms of :func:`_mpl_series`, in its order of
    summation: (unpaired terms, ("gamma", terms) or ("paired", (eps, *terms)))."""
    from scipy import special  # lazy: not on a BEM scene's path (docs/performance.md)
    N = int(math.floor(n + 0.5))
    lgn = special.gammaln(n)
    ratio = 1.0                                    # Gamma(n+1-j)/Gamma(n)
    jmax = J if N == 0 else N
    unpaired = []
    for j in range(2, jmax + 1):
        ratio /= n - (j - 1)
        unpaired.append(((-1) ** j * ratio, j - d, special.gammaln(j - d + 1)))
    if N == 0:
        g1n = special.gamma(1.0 - n)
        return tuple(unpaired), ("gamma", tuple(
            (g1n, m + n + 1 - d, special.gammaln(m + 1), special.gammaln(m + n + 2 - d))
            for m in range(J)))
    eps = N - n
    pref = 1.0 / math.pi if eps == 0.0 else eps / math.sin(math.pi * eps)
    paired = [eps]
    for m in range(J):
        q = N + 1 + m - d
        paired.append(((-1) ** N * math.pi * pref, _dlgamma(1.0 + m, eps),
                       _dlgamma(q + 1.0, -eps), q - eps, lgn, special.gammaln(q + 1 - eps),
                       special.gammaln(m + 1)))
    return tuple(unpaired), ("paired", tuple(paired))


_X_MAX = 5000.0        # 2 sqrt(T) beyond which exp(-X) X^(n+1) underflows (n <= 20)


def _mpl_switch(n: float) -> float:
    """T above which the Bessel-K forms are used instead of the ascending series."""
    return 2.0 if n <= 3.0 else min(n, 10.0)


def _mpl_one_minus_phi(T: np.ndarray, n: float) -> np.ndarray:
    """1 - E[exp(-T/x)], x ~ Gamma(n): 1 - 2 T^(n/2) K_n(2 sqrt T)/Gamma(n), accurate at small T."""
    from scipy import special  # lazy: not on a BEM scene's path (docs/performance.md)
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
    from scipy import special  # lazy: not on a BEM scene's path (docs/performance.md)
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
