"""Special functions of the MPL models: the generalized exponential integral E_p(z)
for complex z (``expint``, ``expint_scaled``) and the Gamma-spectrum average ``_zg``."""
from __future__ import annotations

import math

import numpy as np

from ..errors import InputError, check_positive
from ._checks import _EULER


def _expint_series(p: float, z: np.ndarray) -> np.ndarray:
    """E_p(z) by the ascending series, |z| <= ~2, any real p > 0.

    E_p(z) = Gamma(1-p) z^(p-1) - sum_k (-z)^k / (k! (k+1-p)); for p near an integer N >= 1
    the pole of Gamma(1-p) and the k = N-1 term are combined analytically (eps = N - p):
    (-1)^(N-1) z^(N-1)/(N-1)! * expm1(eps D)/eps, D = lnGamma(1+eps)/eps - ln z
    - sum_{j<N} log1p(-eps/j)/eps  (-> psi(N) - ln z at eps = 0).
    """
    from scipy import special  # lazy: not on a BEM scene's path (docs/performance.md)
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
    from scipy import special  # lazy: not on a BEM scene's path (docs/performance.md)
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
